//! Helpers shared by the unit tests.

/// Uniform numbers in `[0, 1)` from a xorshift generator started at `seed`
/// (not zero): the same sequence on every run, so a failing case repeats.
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
