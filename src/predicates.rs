//! Exact geometric predicates: a floating-point filter first, exact expansion
//! arithmetic (Shewchuk's error-free sums and products) when the filter cannot
//! decide. Every sign these functions return is the sign of the exact value
//! for the `f64` inputs, so decisions taken in different triangles about the
//! same points always agree (paper 002 §3 needs the intersection topology to
//! be consistent, not just approximately right; a Delaunay triangulation
//! needs its in-circle tests to agree with each other to stay one).
//!
//! Inputs must be finite and well inside the `f64` range (the mesh reader and
//! `repair_mesh` reject coordinates above 1e30 in magnitude; fitting scales
//! its neighbourhoods to the unit box), so no product overflows.

use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::{DVec2, DVec3};

/// Half an ulp of 1: the relative rounding error of one operation.
const EPS: f64 = f64::EPSILON * 0.5;
/// Dekker's splitter for 53-bit mantissas: 2^27 + 1.
const SPLITTER: f64 = 134_217_729.0;
/// Shewchuk's bound for the rounding error of the plain orient2d evaluation.
const CCW_BOUND: f64 = (3.0 + 16.0 * EPS) * EPS;
/// Shewchuk's bound for the rounding error of the plain orient3d evaluation.
const O3D_BOUND: f64 = (7.0 + 56.0 * EPS) * EPS;
/// Shewchuk's bound for the rounding error of the plain incircle evaluation.
const ICC_BOUND: f64 = (10.0 + 96.0 * EPS) * EPS;

// ------------------------------------------------------------ error-free transforms

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

#[inline]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    (x, b - (x - a))
}

#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = SPLITTER * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let err = x - ah * bh - al * bh - ah * bl;
    (x, al * bl - err)
}

/// A number as a sum of non-overlapping `f64` components, smallest first
/// (Shewchuk 1997); the sum is exact.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Expansion(Vec<f64>);

impl Expansion {
    /// The exact value `x`.
    #[cfg(test)]
    pub(crate) fn from(x: f64) -> Self {
        if x == 0.0 {
            Self(Vec::new())
        } else {
            Self(alloc::vec![x])
        }
    }

    /// The exact difference `a - b` of two doubles.
    pub(crate) fn diff(a: f64, b: f64) -> Self {
        let (x, y) = two_sum(a, -b);
        let mut v = Vec::with_capacity(2);
        if y != 0.0 {
            v.push(y);
        }
        if x != 0.0 {
            v.push(x);
        }
        Self(v)
    }

    /// Adds one double (grow-expansion with zero elimination).
    fn grow(&mut self, b: f64) {
        let mut q = b;
        let mut out = Vec::with_capacity(self.0.len() + 1);
        for &e in &self.0 {
            let (s, h) = two_sum(q, e);
            if h != 0.0 {
                out.push(h);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
        self.0 = out;
    }

    /// Exact sum.
    pub(crate) fn add(&self, other: &Self) -> Self {
        let (mut big, small) =
            if self.0.len() >= other.0.len() { (self.clone(), other) } else { (other.clone(), self) };
        for &f in &small.0 {
            big.grow(f);
        }
        big
    }

    /// Exact negation.
    pub(crate) fn neg(&self) -> Self {
        Self(self.0.iter().map(|x| -x).collect())
    }

    /// Exact difference.
    pub(crate) fn sub(&self, other: &Self) -> Self {
        self.add(&other.neg())
    }

    /// Exact product with one double (scale-expansion with zero elimination).
    fn scale(&self, b: f64) -> Self {
        let mut out = Vec::with_capacity(2 * self.0.len());
        let Some((&first, rest)) = self.0.split_first() else { return Self::default() };
        let (mut q, h) = two_product(first, b);
        if h != 0.0 {
            out.push(h);
        }
        for &e in rest {
            let (p1, p0) = two_product(e, b);
            let (s, h) = two_sum(q, p0);
            if h != 0.0 {
                out.push(h);
            }
            let (s2, h2) = fast_two_sum(p1, s);
            if h2 != 0.0 {
                out.push(h2);
            }
            q = s2;
        }
        if q != 0.0 {
            out.push(q);
        }
        Self(out)
    }

    /// Exact product.
    pub(crate) fn mul(&self, other: &Self) -> Self {
        let (long, short) = if self.0.len() >= other.0.len() { (self, other) } else { (other, self) };
        let mut acc = Self::default();
        for &f in &short.0 {
            acc = acc.add(&long.scale(f));
        }
        acc
    }

    /// Sign of the exact value: that of the largest (last) non-zero component.
    pub(crate) fn sign(&self) -> Ordering {
        match self.0.last() {
            Some(&x) if x > 0.0 => Ordering::Greater,
            Some(&x) if x < 0.0 => Ordering::Less,
            _ => Ordering::Equal,
        }
    }
}

// ------------------------------------------------------------ orient2d / orient3d

fn sign_of(x: f64) -> Ordering {
    x.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// Sign of the area of `(a, b, c)`: `Greater` when counter-clockwise.
pub(crate) fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    let l = (a.x - c.x) * (b.y - c.y);
    let r = (a.y - c.y) * (b.x - c.x);
    let det = l - r;
    let bound = CCW_BOUND * (l.abs() + r.abs());
    if det > bound || -det > bound {
        return sign_of(det);
    }
    let (acx, bcy) = (Expansion::diff(a.x, c.x), Expansion::diff(b.y, c.y));
    let (acy, bcx) = (Expansion::diff(a.y, c.y), Expansion::diff(b.x, c.x));
    acx.mul(&bcy).sub(&acy.mul(&bcx)).sign()
}

/// Whether `d` lies inside the circle through `a, b, c` (counter-clockwise):
/// `Greater` inside, `Equal` on it, `Less` outside (reversed for clockwise
/// `a, b, c`).
pub(crate) fn incircle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Ordering {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (bdxcdy, cdxbdy) = (bd.x * cd.y, cd.x * bd.y);
    let (cdxady, adxcdy) = (cd.x * ad.y, ad.x * cd.y);
    let (adxbdy, bdxady) = (ad.x * bd.y, bd.x * ad.y);
    let (alift, blift, clift) = (ad.length_squared(), bd.length_squared(), cd.length_squared());
    let det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * alift
        + (cdxady.abs() + adxcdy.abs()) * blift
        + (adxbdy.abs() + bdxady.abs()) * clift;
    let bound = ICC_BOUND * permanent;
    if det > bound || -det > bound {
        return sign_of(det);
    }
    let e = |p: f64, q: f64| Expansion::diff(p, q);
    let (adx, ady) = (e(a.x, d.x), e(a.y, d.y));
    let (bdx, bdy) = (e(b.x, d.x), e(b.y, d.y));
    let (cdx, cdy) = (e(c.x, d.x), e(c.y, d.y));
    let lift = |x: &Expansion, y: &Expansion| x.mul(x).add(&y.mul(y));
    let m1 = bdx.mul(&cdy).sub(&cdx.mul(&bdy));
    let m2 = cdx.mul(&ady).sub(&adx.mul(&cdy));
    let m3 = adx.mul(&bdy).sub(&bdx.mul(&ady));
    lift(&adx, &ady).mul(&m1).add(&lift(&bdx, &bdy).mul(&m2)).add(&lift(&cdx, &cdy).mul(&m3)).sign()
}

/// Float orient3d and its error bound; `(det, bound)`.
#[inline]
fn orient3d_fast(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let bdxcdy = bd.x * cd.y;
    let cdxbdy = cd.x * bd.y;
    let cdxady = cd.x * ad.y;
    let adxcdy = ad.x * cd.y;
    let adxbdy = ad.x * bd.y;
    let bdxady = bd.x * ad.y;
    let det = ad.z * (bdxcdy - cdxbdy) + bd.z * (cdxady - adxcdy) + cd.z * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * ad.z.abs()
        + (cdxady.abs() + adxcdy.abs()) * bd.z.abs()
        + (adxbdy.abs() + bdxady.abs()) * cd.z.abs();
    (det, O3D_BOUND * permanent)
}

/// The exact value of the orient3d determinant as an expansion.
pub(crate) fn orient3d_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Expansion {
    let e = |p: f64, q: f64| Expansion::diff(p, q);
    let (adx, ady, adz) = (e(a.x, d.x), e(a.y, d.y), e(a.z, d.z));
    let (bdx, bdy, bdz) = (e(b.x, d.x), e(b.y, d.y), e(b.z, d.z));
    let (cdx, cdy, cdz) = (e(c.x, d.x), e(c.y, d.y), e(c.z, d.z));
    let m1 = bdx.mul(&cdy).sub(&cdx.mul(&bdy));
    let m2 = cdx.mul(&ady).sub(&adx.mul(&cdy));
    let m3 = adx.mul(&bdy).sub(&bdx.mul(&ady));
    adz.mul(&m1).add(&bdz.mul(&m2)).add(&cdz.mul(&m3))
}

/// Sign of the volume of the tetrahedron `(a, b, c, d)`: `Greater` when `d`
/// lies on the side of the plane `(a, b, c)` that its normal (counter-clockwise
/// order) points away from, i.e. below the plane. Use [`side`] for "which
/// side of a triangle".
pub(crate) fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ordering {
    let (det, bound) = orient3d_fast(a, b, c, d);
    if det > bound || -det > bound {
        return sign_of(det);
    }
    orient3d_exact(a, b, c, d).sign()
}

/// Which side of the plane of the triangle `t` the point `p` lies on:
/// `Greater` in front (where the counter-clockwise normal points), `Less`
/// behind, `Equal` on the plane.
#[inline]
pub(crate) fn side(t: &[DVec3; 3], p: DVec3) -> Ordering {
    orient3d(t[0], t[1], t[2], p).reverse()
}

/// A float value with a bound on its distance from the exact value.
#[derive(Debug, Clone, Copy)]
struct Approx {
    v: f64,
    e: f64,
}

impl Approx {
    fn orient(t: &[DVec3; 3], p: DVec3) -> Self {
        let (det, bound) = orient3d_fast(t[0], t[1], t[2], p);
        // The fast bound covers the evaluation; pad it for the bound's own rounding.
        Self { v: -det, e: bound * (1.0 + 8.0 * EPS) }
    }

    fn mul(self, o: Self) -> Self {
        let v = self.v * o.v;
        let e = self.v.abs() * o.e + o.v.abs() * self.e + self.e * o.e + 2.0 * EPS * v.abs();
        Self { v, e: e * (1.0 + 8.0 * EPS) }
    }

    fn sub(self, o: Self) -> Self {
        let v = self.v - o.v;
        let e = self.e + o.e + 2.0 * EPS * v.abs();
        Self { v, e: e * (1.0 + 8.0 * EPS) }
    }

    fn sign(self) -> Option<Ordering> {
        (self.v > self.e || -self.v > self.e).then(|| sign_of(self.v))
    }
}

/// Which side of the plane of triangle `x` the point where the segment
/// `p q` crosses the plane of triangle `t` lies on (`Greater` = in front of
/// `x`). `p` and `q` must lie strictly on opposite sides of the plane of `t`.
///
/// With `o_T(·)` the signed distance-like orient value of a point to plane
/// `T`, the crossing is `(o_T(p) q − o_T(q) p) / (o_T(p) − o_T(q))`; its side
/// of `X` is the sign of `o_T(p) o_X(q) − o_T(q) o_X(p)` times the sign of
/// the denominator, which is that of `o_T(p)`.
pub(crate) fn side_of_crossing(x: &[DVec3; 3], p: DVec3, q: DVec3, t: &[DVec3; 3]) -> Ordering {
    let (tp, tq) = (Approx::orient(t, p), Approx::orient(t, q));
    let (xp, xq) = (Approx::orient(x, p), Approx::orient(x, q));
    let num = tp.mul(xq).sub(tq.mul(xp));
    let den = tp.sign().unwrap_or_else(|| side(t, p));
    if let Some(s) = num.sign() {
        return if den == Ordering::Less { s.reverse() } else { s };
    }
    let o = |tri: &[DVec3; 3], pt: DVec3| orient3d_exact(tri[0], tri[1], tri[2], pt).neg();
    let exact = o(t, p).mul(&o(x, q)).sub(&o(t, q).mul(&o(x, p))).sign();
    if den == Ordering::Less {
        exact.reverse()
    } else {
        exact
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient2d_decides_exactly_collinear_and_near_collinear_points() {
        let a = DVec2::new(0.1, 0.1);
        let b = DVec2::new(0.3, 0.3);
        assert_eq!(orient2d(a, b, DVec2::new(0.7, 0.7)), Ordering::Equal);
        // The next double above 0.7 in y: a float evaluation calls this collinear or worse.
        let up = DVec2::new(0.7, f64::from_bits(0.7f64.to_bits() + 1));
        assert_eq!(orient2d(a, b, up), Ordering::Greater);
        let down = DVec2::new(0.7, f64::from_bits(0.7f64.to_bits() - 1));
        assert_eq!(orient2d(a, b, down), Ordering::Less);
    }

    #[test]
    fn incircle_decides_exactly_cocircular_and_near_cocircular_points() {
        // The unit square's corners lie on one circle.
        let (a, b, c) = (DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0));
        assert_eq!(incircle(a, b, c, DVec2::new(0.0, 1.0)), Ordering::Equal);
        assert_eq!(incircle(a, b, c, DVec2::new(0.5, 0.5)), Ordering::Greater);
        assert_eq!(incircle(a, b, c, DVec2::new(2.0, 2.0)), Ordering::Less);
        // A step far below the float evaluation's error, inside or outside, is told apart.
        let step = 2f64.powi(-60);
        assert_eq!(incircle(a, b, c, DVec2::new(step, 1.0)), Ordering::Greater);
        assert_eq!(incircle(a, b, c, DVec2::new(-step, 1.0)), Ordering::Less);
        // Scaled off the unit box: 0.1 is not representable, the circle still holds all four.
        let s = |p: DVec2| p * 0.1 + DVec2::new(0.3, 0.7);
        let on = incircle(s(a), s(b), s(c), s(DVec2::new(0.0, 1.0)));
        // A cyclic shift of the four points is an odd permutation of the determinant's rows.
        let shifted = incircle(s(b), s(c), s(DVec2::new(0.0, 1.0)), s(a));
        assert_eq!(on, shifted.reverse(), "one circle, whichever three");
    }

    #[test]
    fn orient3d_agrees_with_geometry_and_is_exact_on_the_plane() {
        let t = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        assert_eq!(side(&t, DVec3::new(0.2, 0.2, 1.0)), Ordering::Greater);
        assert_eq!(side(&t, DVec3::new(0.2, 0.2, -1e-300)), Ordering::Less);
        // Points on a tilted plane through non-representable coefficients.
        let t = [DVec3::new(0.1, 0.2, 0.3), DVec3::new(1.1, 0.7, 0.9), DVec3::new(0.4, 1.3, 0.2)];
        let on = t[0] + (t[1] - t[0]) * 2.0 + (t[2] - t[0]) * -3.0;
        let s = side(&t, on);
        let exact = orient3d_exact(t[0], t[1], t[2], on).sign().reverse();
        assert_eq!(s, exact);
        // Perturb the last bit of z: the exact sign flips consistently with the normal's z.
        let up = DVec3::new(on.x, on.y, f64::from_bits(on.z.to_bits() + 4));
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if exact == Ordering::Equal {
            assert_eq!(side(&t, up), sign_of(n.z));
        }
    }

    #[test]
    fn expansion_products_are_exact() {
        // (1 + 2^-60)^2 = 1 + 2^-59 + 2^-120: needs three components.
        let x = Expansion::from(1.0).add(&Expansion::from(libm::ldexp(1.0, -60)));
        let sq = x.mul(&x);
        let expected = Expansion::from(1.0)
            .add(&Expansion::from(libm::ldexp(1.0, -59)))
            .add(&Expansion::from(libm::ldexp(1.0, -120)));
        assert_eq!(sq.sub(&expected).sign(), Ordering::Equal);
        assert_eq!(sq.sub(&Expansion::from(1.0)).sign(), Ordering::Greater);
    }

    #[test]
    fn side_of_crossing_orders_points_along_an_edge() {
        // Edge from p to q along x; planes x = 0.3 (t) and x = 0.5 (x).
        let plane_x = |c: f64| [DVec3::new(c, 0.0, 0.0), DVec3::new(c, 1.0, 0.0), DVec3::new(c, 0.0, 1.0)];
        let (p, q) = (DVec3::new(0.0, 0.2, 0.1), DVec3::new(1.0, 0.3, 0.4));
        let t = plane_x(0.3);
        let x = plane_x(0.5);
        // Plane x = c with this winding has its normal along +x: the crossing at 0.3 is behind x = 0.5.
        assert_eq!(side(&x, DVec3::new(0.6, 0.0, 0.0)), Ordering::Greater);
        assert_eq!(side_of_crossing(&x, p, q, &t), Ordering::Less);
        assert_eq!(side_of_crossing(&t, p, q, &x), Ordering::Greater);
        assert_eq!(side_of_crossing(&t, q, p, &x), Ordering::Greater);
        // The same plane: exactly on it.
        assert_eq!(side_of_crossing(&t, p, q, &t), Ordering::Equal);
    }
}
