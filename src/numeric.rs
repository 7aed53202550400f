//! The numeric policy: which decisions are exact, which use a tolerance,
//! and the guarded division every module uses where a length, area or
//! determinant may be zero.
//!
//! Exact: the signs that a combinatorial structure must agree on with
//! itself (orientation, in-circle, which side of a plane). They go through
//! [`crate::predicates`] (a float filter, then exact expansion arithmetic):
//! mesh repair's intersections and sub-triangulations (paper 002 §3) and
//! fitting's local Delaunay triangulations.
//!
//! With a tolerance: everything measured against the surface (deviation,
//! normal turn, chord tests, sewing distances, welds), which takes the
//! user's chordal tolerance or a fraction of it; and what tells two numbers
//! of the file apart (a parameter at an end, two points one, a degenerate
//! frame), which takes a fraction of the size of what is compared: the
//! literal beside each such test says which fraction, and why, where it is.
//! The one tolerance that is not relative is [`TINY`].

/// The smallest divisor, size or scale the code lets through: a length or
/// area of zero (or NaN) is raised to it, so that a quotient stays finite and
/// a tolerance relative to a size stays positive. It is far below anything
/// a model measures (its coordinates are capped near 1e30, and its smallest
/// meaningful lengths are some 1e-12 of that) and still well above the
/// smallest normal `f64` (2.2e-308), so that it divides without overflow
/// for any numerator of model size.
pub(crate) const TINY: f64 = 1e-300;

/// `a / b`, with `b` raised to [`TINY`]: the guarded division of a projection
/// fraction, a Newton step or a normalization by a squared length that may
/// be zero. Where `b >= TINY` it is the plain quotient, bit for bit.
#[inline]
pub(crate) fn guarded_div(a: f64, b: f64) -> f64 {
    a / b.max(TINY)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guarded_division_is_plain_above_tiny_and_finite_at_zero() {
        for (a, b) in [(1.0, 3.0), (-2.5, 1e-12), (7.0, 1e300), (0.1, 0.7)] {
            assert_eq!(guarded_div(a, b).to_bits(), (a / b).to_bits());
        }
        assert!(guarded_div(1e8, 0.0).is_finite());
        assert!(guarded_div(1.0, f64::NAN).is_finite());
        assert_eq!(guarded_div(0.0, 0.0), 0.0);
    }
}
