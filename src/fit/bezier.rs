//! Bézier pieces of the fitted surface: the cubic edge curves of the curve net
//! and the quartic triangular sub-patches that fill its polygons (paper 004 §3, §4).

use glam::DVec3;

/// A cubic Bézier curve `V0..V3` (paper 004 §3).
pub type Cubic = [DVec3; 4];

/// Point of a cubic at `t` ∈ [0, 1] (de Casteljau).
#[cfg(test)]
pub fn cubic_point(c: &Cubic, t: f64) -> DVec3 {
    let s = 1.0 - t;
    let a = c[0] * s + c[1] * t;
    let b = c[1] * s + c[2] * t;
    let d = c[2] * s + c[3] * t;
    let e = a * s + b * t;
    let f = b * s + d * t;
    e * s + f * t
}

/// The quartic with the same shape (paper 004 eq. 3: `Z, A, X, C, Z'`).
pub fn elevate(c: &Cubic) -> [DVec3; 5] {
    [c[0], c[0] * 0.25 + c[1] * 0.75, (c[1] + c[2]) * 0.5, c[2] * 0.75 + c[3] * 0.25, c[3]]
}

/// Degree of the sub-patches.
pub const DEGREE: usize = 4;
/// Control points of a quartic triangle.
pub const POINTS: usize = 15;

/// Index of control point `b(j, k)` in [`TriPatch::points`]: `k` is the row
/// (0 on the edge from corner 0 to corner 1, 4 at corner 2), `j` the position
/// along the row (0 ≤ j ≤ 4 − k); its Bernstein weight is `λ0^(4−j−k) λ1^j λ2^k`.
pub const fn index(j: usize, k: usize) -> usize {
    5 * k - k * (k.saturating_sub(1)) / 2 + j
}

/// A quartic triangular Bézier patch over barycentric `(λ0, λ1, λ2)`; corner 0
/// and 1 are polygon corners `Z_i, Z_i+1`, corner 2 is the polygon's centre `O`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriPatch {
    /// Control points, row by row (ordered by the `index` function of this module).
    pub points: [DVec3; POINTS],
}

/// A point of a patch with its tangent plane.
#[derive(Debug, Clone, Copy)]
pub struct PatchPoint {
    /// Position.
    pub point: DVec3,
    /// Derivative along λ1 − λ0 (towards corner 1).
    pub d1: DVec3,
    /// Derivative along λ2 − λ0 (towards corner 2).
    pub d2: DVec3,
}

impl PatchPoint {
    /// Unit normal `d1 × d2`, zero where the patch is singular.
    pub fn normal(&self) -> DVec3 {
        self.d1.cross(self.d2).normalize_or_zero()
    }
}

impl TriPatch {
    /// Control point `b(j, k)`.
    pub fn at(&self, j: usize, k: usize) -> DVec3 {
        self.points[index(j, k)]
    }

    /// Point and first derivatives at barycentric `(l0, l1, l2)` (de Casteljau down to degree 1).
    pub fn eval(&self, l1: f64, l2: f64) -> PatchPoint {
        let l0 = 1.0 - l1 - l2;
        let mut net = self.points;
        // Level `deg` holds points b(j, k) with j + k ≤ deg at index(j, k) of a degree-`deg` net.
        for deg in (1..=DEGREE).rev() {
            let mut next = [DVec3::ZERO; POINTS];
            for k in 0..deg {
                for j in 0..deg - k {
                    let p = net[idx(deg, j, k)] * l0 + net[idx(deg, j + 1, k)] * l1 + net[idx(deg, j, k + 1)] * l2;
                    next[idx(deg - 1, j, k)] = p;
                }
            }
            if deg == 2 {
                // `next` is the degree-1 net: q0 = b(0,0), q1 = b(1,0), q2 = b(0,1).
                let (q0, q1, q2) = (next[idx(1, 0, 0)], next[idx(1, 1, 0)], next[idx(1, 0, 1)]);
                return PatchPoint {
                    point: q0 * l0 + q1 * l1 + q2 * l2,
                    d1: (q1 - q0) * DEGREE as f64,
                    d2: (q2 - q0) * DEGREE as f64,
                };
            }
            net = next;
        }
        PatchPoint { point: net[0], d1: DVec3::ZERO, d2: DVec3::ZERO }
    }

    /// Largest second difference of the control net along the three edge
    /// directions: with it, [`Self::level_for`] bounds the flatness of a uniform split.
    pub fn second_difference(&self) -> f64 {
        let mut m: f64 = 0.0;
        for k in 0..=DEGREE {
            for j in 0..=DEGREE - k {
                // Along λ1 (row), along λ2 (column), along λ2 − λ1.
                if j + 2 + k <= DEGREE {
                    m = m.max((self.at(j, k) - self.at(j + 1, k) * 2.0 + self.at(j + 2, k)).length());
                }
                if j + k + 2 <= DEGREE {
                    m = m.max((self.at(j, k) - self.at(j, k + 1) * 2.0 + self.at(j, k + 2)).length());
                }
                if j >= 2 {
                    m = m.max((self.at(j, k) - self.at(j - 1, k + 1) * 2.0 + self.at(j - 2, k + 2)).length());
                }
            }
        }
        m
    }

    /// The number of segments per edge of a uniform split whose flat triangles
    /// stay within `tol` of the patch: for a polynomial of degree d the
    /// linear interpolant on a triangle with barycentric edge steps `1/m`
    /// errs by at most `(1/2)(1/3) d(d−1) Δ / m²`, with `Δ` the largest second
    /// difference of the control net (the interpolation error is
    /// `−½ Σ μi μj D²f(vi − vj)` and `Σ μi μj ≤ 1/3`).
    pub fn level_for(&self, tol: f64, max_level: usize) -> usize {
        let d = DEGREE as f64;
        let bound = d * (d - 1.0) * self.second_difference() / 6.0;
        if bound <= 0.0 || !(tol > 0.0) {
            return 1;
        }
        let m = crate::math::ceil(crate::math::sqrt(bound / tol));
        if m.is_finite() && m >= 1.0 {
            (m as usize).min(max_level)
        } else {
            max_level
        }
    }
}

/// Index of `b(j, k)` in a net of degree `deg` (same row layout as [`index`]).
const fn idx(deg: usize, j: usize, k: usize) -> usize {
    (deg + 1) * k - k * (k.saturating_sub(1)) / 2 + j
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bernstein_eval(p: &TriPatch, l1: f64, l2: f64) -> DVec3 {
        let l0 = 1.0 - l1 - l2;
        let fact = [1.0, 1.0, 2.0, 6.0, 24.0];
        let mut s = DVec3::ZERO;
        for k in 0..=4 {
            for j in 0..=4 - k {
                let i = 4 - j - k;
                let c = 24.0 / (fact[i] * fact[j] * fact[k]);
                s += p.at(j, k) * (c * l0.powi(i as i32) * l1.powi(j as i32) * l2.powi(k as i32));
            }
        }
        s
    }

    fn wavy() -> TriPatch {
        let mut points = [DVec3::ZERO; POINTS];
        for k in 0..=4 {
            for j in 0..=4 - k {
                let (x, y) = (j as f64 / 4.0, k as f64 / 4.0);
                points[index(j, k)] = DVec3::new(x, y, (3.0 * x).sin() * (2.0 * y + 0.3).cos());
            }
        }
        TriPatch { points }
    }

    #[test]
    fn de_casteljau_matches_bernstein_and_derivatives_match_differences() {
        let p = wavy();
        for &(l1, l2) in &[(0.2, 0.3), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.45, 0.1)] {
            let e = p.eval(l1, l2);
            assert!((e.point - bernstein_eval(&p, l1, l2)).length() < 1e-14);
            let h = 1e-6;
            let fd1 = (bernstein_eval(&p, l1 + h, l2) - bernstein_eval(&p, l1 - h, l2)) / (2.0 * h);
            let fd2 = (bernstein_eval(&p, l1, l2 + h) - bernstein_eval(&p, l1, l2 - h)) / (2.0 * h);
            assert!((e.d1 - fd1).length() < 1e-7, "{:?} {:?}", e.d1, fd1);
            assert!((e.d2 - fd2).length() < 1e-7);
        }
    }

    #[test]
    fn elevation_keeps_the_curve() {
        let c = [DVec3::ZERO, DVec3::new(1.0, 2.0, 0.0), DVec3::new(3.0, -1.0, 1.0), DVec3::new(4.0, 0.0, 0.0)];
        let q = elevate(&c);
        let mut points = [DVec3::ZERO; POINTS];
        for j in 0..5 {
            points[index(j, 0)] = q[j];
        }
        let p = TriPatch { points };
        for t in [0.0, 0.3, 0.7, 1.0] {
            assert!((p.eval(t, 0.0).point - cubic_point(&c, t)).length() < 1e-14);
        }
    }

    #[test]
    fn level_bound_holds_on_samples() {
        let p = wavy();
        let tol = 1e-3;
        let m = p.level_for(tol, 1000);
        // Largest distance between the patch and the flat triangles of the level-m split.
        let mut worst: f64 = 0.0;
        for a in 0..m {
            for b in 0..m - a {
                let corners = [(a, b), (a + 1, b), (a, b + 1)];
                let pts = corners.map(|(i, j)| p.eval(i as f64 / m as f64, j as f64 / m as f64).point);
                for (w0, w1) in [(1.0 / 3.0, 1.0 / 3.0), (0.5, 0.5), (0.5, 0.0), (0.0, 0.5), (0.2, 0.6)] {
                    let w2 = 1.0 - w0 - w1;
                    let (l1, l2) = (
                        (a as f64 * w2 + (a + 1) as f64 * w0 + a as f64 * w1) / m as f64,
                        (b as f64 * w2 + b as f64 * w0 + (b + 1) as f64 * w1) / m as f64,
                    );
                    let flat = pts[0] * w2 + pts[1] * w0 + pts[2] * w1;
                    worst = worst.max((p.eval(l1, l2).point - flat).length());
                }
            }
        }
        assert!(worst <= tol, "{worst} > {tol} at level {m}");
        assert!(worst > tol / 50.0, "bound far too loose: {worst} at level {m}");
    }
}
