//! Exact re-expressions of a curve that keep its shape: knot insertion at any
//! parameter (the domain ends too), clamping, reversal, affine change of
//! parameter and restriction to a sub-range. Importers use them to bring
//! curves from files (unclamped knots, sub-ranges, reversed uses) into the
//! form the mesher and the surface constructors expect.

use alloc::vec::Vec;
use glam::{DVec3, DVec4};

use super::{NurbsCurve, NurbsError};

/// A curve being edited: degree, knots and homogeneous control points.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawCurve {
    pub degree: usize,
    pub knots: Vec<f64>,
    /// Homogeneous `(w·x, w·y, w·z, w)`.
    pub points: Vec<DVec4>,
    pub rational: bool,
}

impl RawCurve {
    /// The parts of `c`.
    pub fn of(c: &NurbsCurve) -> Self {
        Self {
            degree: c.degree(),
            knots: c.knots().knots().to_vec(),
            points: c.homogeneous_points().to_vec(),
            rational: c.is_rational(),
        }
    }

    /// Validates and builds the curve.
    ///
    /// # Errors
    /// As [`NurbsCurve::try_new`].
    pub fn build(self) -> Result<NurbsCurve, NurbsError> {
        let pts: Vec<DVec3> = self.points.iter().map(|h| h.truncate() / h.w).collect();
        let weights = self.rational.then(|| self.points.iter().map(|h| h.w).collect());
        NurbsCurve::try_new(self.degree, self.knots, pts, weights)
    }

    /// `[knots[p], knots[n]]`.
    pub fn domain(&self) -> (f64, f64) {
        let n = self.knots.len() - self.degree - 1;
        (self.knots[self.degree], self.knots[n])
    }

    /// Inserts knot `t` once (Boehm), `t` anywhere in the closed domain.
    pub fn insert(&mut self, t: f64) {
        let p = self.degree;
        let n = self.points.len();
        let (a, b) = self.domain();
        if !(t >= a && t <= b) {
            return;
        }
        // Span k with knots[k] <= t < knots[k+1]; at the right end the last
        // span with knots[k] < t.
        let mut k = p;
        while k + 1 < n && self.knots[k + 1] <= t && self.knots[k + 1] < b {
            k += 1;
        }
        if t >= b {
            k = n - 1;
            while k > p && self.knots[k] >= t {
                k -= 1;
            }
        }
        let u = &self.knots;
        let mut q = Vec::with_capacity(n + 1);
        for i in 0..=n {
            let pt = if i + p <= k {
                self.points[i]
            } else if i > k {
                self.points[i - 1]
            } else {
                let den = u[i + p] - u[i];
                let alpha = if den > 0.0 { (t - u[i]) / den } else { 0.0 };
                self.points[i] * alpha + self.points[i - 1] * (1.0 - alpha)
            };
            q.push(pt);
        }
        self.knots.insert(k + 1, t);
        self.points = q;
    }

    fn multiplicity(&self, t: f64) -> usize {
        self.knots.iter().filter(|&&k| k == t).count()
    }

    /// Makes the knot vector clamped (end knots of multiplicity `p + 1`) so
    /// the ends of the curve are its first and last control points.
    pub fn clamp(&mut self) {
        self.clamp_start();
        self.reverse();
        self.clamp_start();
        self.reverse();
    }

    fn clamp_start(&mut self) {
        let p = self.degree;
        let (a, _) = self.domain();
        if self.knots[..=p].iter().all(|&k| k == a) {
            return;
        }
        for _ in 0..p.saturating_sub(self.multiplicity(a)) {
            self.insert(a);
        }
        let Some(first) = self.knots.iter().position(|&k| k == a) else { return };
        if first == 0 {
            return;
        }
        // With `a` of multiplicity p starting at `first`, C(a) = P[first - 1].
        let mut knots = Vec::with_capacity(self.knots.len() - first + 1);
        knots.push(a);
        knots.extend_from_slice(&self.knots[first..]);
        self.points.drain(..first - 1);
        self.knots = knots;
    }

    /// Same curve traversed backwards over the same domain.
    pub fn reverse(&mut self) {
        let (a, b) = self.domain();
        self.knots = self.knots.iter().rev().map(|&k| a + b - k).collect();
        self.points.reverse();
    }

    /// Changes the parameter affinely so the domain becomes `[a, b]` (`a < b`).
    pub fn reparametrize(&mut self, a: f64, b: f64) {
        let (a0, b0) = self.domain();
        let s = (b - a) / (b0 - a0);
        for k in &mut self.knots {
            *k = a + (*k - a0) * s;
        }
        // Exact ends despite rounding.
        let p = self.degree;
        let n = self.knots.len() - p - 1;
        for k in &mut self.knots[..=p] {
            if *k >= a {
                *k = a;
            }
        }
        for k in &mut self.knots[n..] {
            if *k <= b {
                *k = b;
            }
        }
    }

    /// Restricts the curve to `[t0, t1]` inside its domain (clamped result).
    pub fn segment(&mut self, t0: f64, t1: f64) {
        let (a, b) = self.domain();
        let (t0, t1) = (t0.max(a), t1.min(b));
        if t1.is_nan() || t0.is_nan() || t1 <= t0 {
            return;
        }
        self.clamp();
        let p = self.degree;
        for t in [t0, t1] {
            for _ in 0..(p + 1).saturating_sub(self.multiplicity(t)).min(p) {
                self.insert(t);
            }
        }
        // With t0 of multiplicity >= p ending at index l0, C(t0) = P[l0 - p].
        let (Some(l0), Some(_)) = (self.knots.iter().rposition(|&k| k == t0), self.knots.iter().position(|&k| k == t1))
        else {
            return;
        };
        let Some(start) = l0.checked_sub(p) else { return };
        let mut knots = Vec::with_capacity(self.knots.len());
        knots.extend(core::iter::repeat_n(t0, p + 1));
        knots.extend(self.knots.iter().copied().filter(|&k| k > t0 && k < t1));
        knots.extend(core::iter::repeat_n(t1, p + 1));
        let n = knots.len() - p - 1;
        let pts: Vec<DVec4> = self.points.iter().skip(start).take(n).copied().collect();
        if pts.len() == n {
            self.knots = knots;
            self.points = pts;
        }
    }

    /// Moves the first (`at_end == false`) or last control point to `p`
    /// (Euclidean), keeping its weight; on a clamped curve that moves the end point.
    pub fn set_end_point(&mut self, at_end: bool, p: DVec3) {
        let idx = if at_end { self.points.len() - 1 } else { 0 };
        let w = self.points[idx].w;
        self.points[idx] = (p * w).extend(w);
    }
}

/// `c` with its ends moved to `start` and `end` (the curve is clamped first,
/// so its ends are control points); small moves only change the curve near its ends.
///
/// # Errors
/// A degenerate result (cannot happen for a valid input curve).
pub fn with_end_points(c: &NurbsCurve, start: DVec3, end: DVec3) -> Result<NurbsCurve, NurbsError> {
    let mut r = RawCurve::of(c);
    r.clamp();
    r.set_end_point(false, start);
    r.set_end_point(true, end);
    r.build()
}

/// `c` traversed in the opposite direction over the same domain.
///
/// # Errors
/// Only for inputs that were not valid curves.
pub fn reversed(c: &NurbsCurve) -> Result<NurbsCurve, NurbsError> {
    let mut r = RawCurve::of(c);
    r.reverse();
    r.build()
}

/// `c` restricted to `[t0, t1]` (clamped to its domain), clamped at both ends.
///
/// # Errors
/// Only for inputs that were not valid curves.
pub fn segment(c: &NurbsCurve, t0: f64, t1: f64) -> Result<NurbsCurve, NurbsError> {
    let mut r = RawCurve::of(c);
    r.segment(t0, t1);
    r.build()
}

/// `c` with its parameter mapped affinely onto `[a, b]`.
///
/// # Errors
/// An empty or non-finite target range.
pub fn reparametrized(c: &NurbsCurve, a: f64, b: f64) -> Result<NurbsCurve, NurbsError> {
    if !(b > a && a.is_finite() && b.is_finite()) {
        return Err(NurbsError::BadMultiplicity { index: 0 });
    }
    let mut r = RawCurve::of(c);
    r.reparametrize(a, b);
    r.build()
}

/// `c` with every control point mapped by `f` (exact for affine `f`; weights kept).
///
/// # Errors
/// A non-finite mapped point.
pub fn map_points(c: &NurbsCurve, f: impl Fn(DVec3) -> DVec3) -> Result<NurbsCurve, NurbsError> {
    let mut r = RawCurve::of(c);
    for h in &mut r.points {
        let w = h.w;
        *h = (f(h.truncate() / w) * w).extend(w);
    }
    r.build()
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    fn wavy(rational: bool) -> NurbsCurve {
        // Degree 3, inner knots of multiplicity 1 and 3, unclamped start.
        let knots = vec![-0.5, -0.2, -0.1, 0.0, 0.3, 0.5, 0.5, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0];
        let pts: Vec<DVec3> = (0..9).map(|i| DVec3::new(i as f64, libm::sin(i as f64), 0.5 * i as f64)).collect();
        let w = rational.then(|| (0..9).map(|i| 1.0 + 0.3 * (i % 3) as f64).collect());
        NurbsCurve::try_new(3, knots, pts, w).unwrap()
    }

    #[test]
    fn segment_reverse_clamp_keep_the_shape() {
        for rational in [false, true] {
            let c = wavy(rational);
            let (a, b) = c.domain();
            for (t0, t1) in [(a, b), (0.1, 0.9), (0.5, 0.8), (0.3, 0.5), (0.0, 0.3), (0.31, 0.32)] {
                let s = segment(&c, t0, t1).unwrap();
                assert_eq!(s.domain(), (t0, t1));
                for k in 0..=20 {
                    let t = t0 + (t1 - t0) * k as f64 / 20.0;
                    assert!(s.point(t).distance(c.point(t)) < 1e-12, "segment [{t0}, {t1}] at {t}");
                }
            }
            let r = reversed(&c).unwrap();
            for k in 0..=20 {
                let t = a + (b - a) * k as f64 / 20.0;
                assert!(r.point(a + b - t).distance(c.point(t)) < 1e-12);
            }
            let mut raw = RawCurve::of(&c);
            raw.clamp();
            let cl = raw.build().unwrap();
            assert!(cl.control_points().next().unwrap().distance(c.point(a)) < 1e-12);
            for k in 0..=20 {
                let t = a + (b - a) * k as f64 / 20.0;
                assert!(cl.point(t).distance(c.point(t)) < 1e-12);
            }
        }
    }
}
