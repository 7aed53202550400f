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

/// The one sort of `(u64 key, index)` pairs (also pairs of other meanings:
/// every sort of two or three integers goes through it).
#[inline(never)]
pub(crate) fn sort_u64_keys(keys: &mut [(u64, u32)]) {
    keys.sort_unstable();
}

/// Sorts `v` ascending through [`sort_u64_keys`]: `key` must map `v`'s order
/// onto the keys' and `back` undo it, so that equal keys are equal items and
/// the result is that of `v.sort_unstable()`.
fn through_keys<T>(v: &mut [T], key: impl Fn(&T) -> (u64, u32), back: impl Fn((u64, u32)) -> T) {
    if v.len() < 2 {
        return;
    }
    let mut keys: Vec<(u64, u32)> = v.iter().map(key).collect();
    sort_u64_keys(&mut keys);
    for (x, k) in v.iter_mut().zip(keys) {
        *x = back(k);
    }
}

/// The two halves of a [`pair`] key.
fn unpair(k: u64) -> (u32, u32) {
    ((k >> 32) as u32, k as u32)
}

/// Sorts pairs ascending, as `v.sort_unstable()` does.
pub(crate) fn pairs(v: &mut [(u32, u32)]) {
    through_keys(v, |&(a, b)| (pair(a, b), 0), |(k, _)| unpair(k));
}

/// Sorts triples ascending, as `v.sort_unstable()` does.
pub(crate) fn triples(v: &mut [(u32, u32, u32)]) {
    through_keys(
        v,
        |&(a, b, c)| (pair(a, b), c),
        |(k, c)| {
            let (a, b) = unpair(k);
            (a, b, c)
        },
    );
}

/// Sorts `(u32, bool, u32)` ascending, as `v.sort_unstable()` does.
pub(crate) fn flagged_triples(v: &mut [(u32, bool, u32)]) {
    through_keys(
        v,
        |&(a, f, c)| (pair(a, u32::from(f)), c),
        |(k, c)| {
            let (a, f) = unpair(k);
            (a, f != 0, c)
        },
    );
}

/// Sorts indices ascending, as `v.sort_unstable()` does.
pub(crate) fn usizes(v: &mut [usize]) {
    through_keys(v, |&x| (x as u64, 0), |(k, _)| k as usize);
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
    fn tuple_sorts_match_sort_unstable() {
        let mut seed = 11;
        for n in [0usize, 1, 2, 5, 40, 700] {
            let mut r = |m: u64| (lcg(&mut seed) % m) as u32;
            let p: Vec<(u32, u32)> = (0..n).map(|_| (r(7), r(5) * 0x3000_0000)).collect();
            let t: Vec<(u32, u32, u32)> = (0..n).map(|_| (r(4) * 0x5000_0000, r(9), r(3) * 0x7000_0000)).collect();
            let f: Vec<(u32, bool, u32)> = (0..n).map(|_| (r(6), r(2) == 1, r(4))).collect();
            let u: Vec<usize> = (0..n).map(|_| r(50) as usize * 1_000_003).collect();
            let (mut pw, mut tw, mut fw, mut uw) = (p.clone(), t.clone(), f.clone(), u.clone());
            pw.sort_unstable();
            tw.sort_unstable();
            fw.sort_unstable();
            uw.sort_unstable();
            let (mut pg, mut tg, mut fg, mut ug) = (p, t, f, u);
            pairs(&mut pg);
            triples(&mut tg);
            flagged_triples(&mut fg);
            usizes(&mut ug);
            assert_eq!((pg, tg, fg, ug), (pw, tw, fw, uw), "n = {n}");
        }
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
