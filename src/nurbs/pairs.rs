//! The tensor product's sums of [`super::surface`] in wasm with 128-bit
//! SIMD: a homogeneous point's (x, y) and (z, w) are one `f64x2` each, so a
//! weighted point costs two multiplications and two additions instead of
//! four of each. Per lane these are the scalar sums' operations in the same
//! order (wasm has no fused multiply-add), so the results are bit for bit
//! the scalar ones. Elsewhere (the native tests, which check that) a lane
//! pair is two plain numbers.

use glam::DVec4;

use super::knots::MAX_DERIV;
use lanes::{add_product, splat, split, two, Two};

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod lanes {
    use core::arch::wasm32::{f64x2, f64x2_add, f64x2_extract_lane, f64x2_mul, f64x2_splat, v128};

    pub(super) type Two = v128;

    #[inline(always)]
    pub(super) fn two(a: f64, b: f64) -> Two {
        f64x2(a, b)
    }

    #[inline(always)]
    pub(super) fn splat(a: f64) -> Two {
        f64x2_splat(a)
    }

    /// `acc + h·w` lane by lane, rounded after each operation.
    #[inline(always)]
    pub(super) fn add_product(acc: Two, h: Two, w: Two) -> Two {
        f64x2_add(acc, f64x2_mul(h, w))
    }

    #[inline(always)]
    pub(super) fn split(x: Two) -> (f64, f64) {
        (f64x2_extract_lane::<0>(x), f64x2_extract_lane::<1>(x))
    }
}

#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
mod lanes {
    pub(super) type Two = [f64; 2];

    pub(super) fn two(a: f64, b: f64) -> Two {
        [a, b]
    }

    pub(super) fn splat(a: f64) -> Two {
        [a, a]
    }

    /// `acc + h·w` lane by lane, rounded after each operation.
    pub(super) fn add_product(acc: Two, h: Two, w: Two) -> Two {
        [acc[0] + h[0] * w[0], acc[1] + h[1] * w[1]]
    }

    pub(super) fn split(x: Two) -> (f64, f64) {
        (x[0], x[1])
    }
}

/// A homogeneous point as two lanes of two.
#[derive(Clone, Copy)]
struct Pair(Two, Two);

impl Pair {
    #[inline(always)]
    fn zero() -> Self {
        Self(splat(0.0), splat(0.0))
    }

    #[inline(always)]
    fn of(h: &DVec4) -> Self {
        Self(two(h.x, h.y), two(h.z, h.w))
    }

    /// `self += h · w`, as `DVec4`'s `+=` and `*` do it lane by lane.
    #[inline(always)]
    fn add_scaled(&mut self, h: Self, w: Two) {
        self.0 = add_product(self.0, h.0, w);
        self.1 = add_product(self.1, h.1, w);
    }

    #[inline(always)]
    fn get(self) -> DVec4 {
        let ((x, y), (z, w)) = (split(self.0), split(self.1));
        DVec4::new(x, y, z, w)
    }
}

/// `A^{(k,l)}` for `k + l <= order`, as `sum_v(contract_u(…))` in
/// [`super::surface`] forms them: first, per order `k` of u and control column
/// `s <= q`, the sum over rows `r <= p` of `P[r][s]·Nu^(k)[r]` (control point
/// `(r, s)` at `first + r·nv + s`, rows past the net left out); then per `l`
/// the sum over `s` of those times `Nv^(l)[s]`. The others are zero.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn contract<const NU: usize, const NV: usize>(
    points: &[DVec4],
    nv: usize,
    first: usize,
    (p, q): (usize, usize),
    bu: &[[f64; NU]; MAX_DERIV + 1],
    bv: &[[f64; NV]; MAX_DERIV + 1],
    order: usize,
) -> [[DVec4; 3]; 3] {
    let mut temp = [[Pair::zero(); NV]; 3];
    for r in 0..=p {
        let Some(row) = points.get(first + r * nv..first + r * nv + q + 1) else {
            continue;
        };
        let mut pairs = [Pair::zero(); NV];
        for (x, h) in pairs.iter_mut().zip(row) {
            *x = Pair::of(h);
        }
        for (tk, bk) in temp.iter_mut().zip(bu).take(order + 1) {
            let w = splat(bk[r]);
            for (t, h) in tk.iter_mut().zip(&pairs).take(row.len()) {
                t.add_scaled(*h, w);
            }
        }
    }
    let mut out = [[DVec4::ZERO; 3]; 3];
    for (k, tk) in temp.iter().enumerate().take(order + 1) {
        for l in 0..=(order - k) {
            let mut acc = Pair::zero();
            for (t, b) in tk.iter().zip(&bv[l]).take(q + 1) {
                acc.add_scaled(*t, splat(*b));
            }
            out[k][l] = acc.get();
        }
    }
    out
}
