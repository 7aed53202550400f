//! Sorting through a few shared instantiations. Every `sort_by` with its own
//! closure is a monomorphized copy of the standard library's sorts, 2 to 8 KB
//! of wasm each (about 200 KB over the crate); here a slice is sorted by a
//! key paired with each item's index, through one sort per key type, and then
//! put in that order. The index breaks ties, so every sort here is stable.

use alloc::vec::Vec;
use core::cmp::Ordering;

/// Sorts `v` by `key` ascending ([`f64::total_cmp`] order), stably.
pub(crate) fn by_f64<T>(v: &mut [T], key: impl Fn(&T) -> f64) {
    if v.len() < 2 {
        return;
    }
    let mut keys: Vec<(f64, u32)> = v.iter().enumerate().map(|(i, x)| (key(x), i as u32)).collect();
    sort_f64_keys(&mut keys);
    permute(v, |k| keys.get(k).map(|x| x.1));
}

/// Sorts `v` by `key` descending ([`f64::total_cmp`] order), stably.
pub(crate) fn by_f64_desc<T>(v: &mut [T], key: impl Fn(&T) -> f64) {
    // Negation reverses the total order exactly (it flips the sign bit).
    by_f64(v, |x| -key(x));
}

/// Sorts `v` by `key` ascending, stably.
pub(crate) fn by_u64<T>(v: &mut [T], key: impl Fn(&T) -> u64) {
    if v.len() < 2 {
        return;
    }
    let mut keys: Vec<(u64, u32)> = v.iter().enumerate().map(|(i, x)| (key(x), i as u32)).collect();
    sort_u64_keys(&mut keys);
    permute(v, |k| keys.get(k).map(|x| x.1));
}

/// Sorts floats ascending in [`f64::total_cmp`] order.
#[inline(never)]
pub(crate) fn f64s(v: &mut [f64]) {
    v.sort_unstable_by(f64::total_cmp);
}

/// Two `u32` as one key that orders as the pair `(a, b)`.
pub(crate) fn pair(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

/// The one sort of `(f64 key, index)` pairs.
#[inline(never)]
fn sort_f64_keys(keys: &mut [(f64, u32)]) {
    keys.sort_unstable_by(|a, b| match a.0.total_cmp(&b.0) {
        Ordering::Equal => a.1.cmp(&b.1),
        o => o,
    });
}

/// The one sort of `(u64 key, index)` pairs.
#[inline(never)]
fn sort_u64_keys(keys: &mut [(u64, u32)]) {
    keys.sort_unstable();
}

/// Reorders `v` so that its item `k` is the old item `order(k)`, by following
/// the permutation's cycles with swaps (items need not be `Copy`).
fn permute<T>(v: &mut [T], order: impl Fn(usize) -> Option<u32>) {
    let mut done = alloc::vec![false; v.len()];
    for start in 0..v.len() {
        if done[start] {
            continue;
        }
        let mut k = start;
        loop {
            done[k] = true;
            let j = order(k).map_or(start, |j| j as usize);
            if j == start || j >= v.len() {
                break;
            }
            v.swap(k, j);
            k = j;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    /// A small deterministic generator, so the tests need no crate.
    fn lcg(seed: &mut u64) -> u64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        *seed >> 33
    }

    #[test]
    fn by_f64_matches_a_stable_sort() {
        let mut seed = 7;
        for n in [0usize, 1, 2, 3, 17, 100, 1000] {
            let v: Vec<(f64, usize)> = (0..n).map(|i| ((lcg(&mut seed) % 13) as f64 - 6.0, i)).collect();
            let mut want = v.clone();
            want.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut got = v.clone();
            by_f64(&mut got, |x| x.0);
            assert_eq!(got, want, "n = {n}");
            let mut want = v.clone();
            want.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut got = v;
            by_f64_desc(&mut got, |x| x.0);
            assert_eq!(got, want, "descending, n = {n}");
        }
    }

    #[test]
    fn signed_zeros_and_nans_keep_total_order() {
        let v = [0.0, -0.0, f64::NAN, -f64::NAN, 1.0, f64::NEG_INFINITY];
        let mut want = v.to_vec();
        want.sort_by(|a, b| b.total_cmp(a));
        let mut got = v.to_vec();
        by_f64_desc(&mut got, |&x| x);
        let bits = |s: &[f64]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&want));
        let mut got = v.to_vec();
        f64s(&mut got);
        want.reverse();
        assert_eq!(bits(&got), bits(&want));
    }

    #[test]
    fn by_u64_is_stable_and_moves_owned_items() {
        let mut seed = 3;
        let v: Vec<(u32, u32, Vec<u8>)> =
            (0..500).map(|i| ((lcg(&mut seed) % 5) as u32, (lcg(&mut seed) % 3) as u32, vec![i as u8])).collect();
        let mut want = v.clone();
        want.sort_by_key(|x| (x.0, x.1));
        let mut got = v;
        by_u64(&mut got, |x| pair(x.0, x.1));
        assert_eq!(got, want);
    }
}
