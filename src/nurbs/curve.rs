//! Rational B-spline curves in 2-D (z = 0) and 3-D.

use alloc::vec::Vec;
use glam::{DVec3, DVec4};

use super::knots::{BasisDers, KnotVector};
use super::{Aabb, NurbsError};

/// A (possibly rational) B-spline curve. 2-D curves (trim loops in (u,v)) keep z = 0.
///
/// Control points are stored homogeneous `(w·x, w·y, w·z, w)`.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    knots: KnotVector,
    points: Vec<DVec4>,
    rational: bool,
}

/// Point and first two derivatives of a curve at one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurveDerivs {
    /// C(t).
    pub point: DVec3,
    /// C'(t).
    pub d1: DVec3,
    /// C''(t).
    pub d2: DVec3,
}

impl NurbsCurve {
    /// Builds a curve from Euclidean control points and optional weights.
    ///
    /// # Errors
    /// Bad knots, a control point count that does not match, a non-finite
    /// coordinate, or a weight that is not positive.
    pub fn try_new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, NurbsError> {
        let knots = KnotVector::try_new(degree, knots)?;
        let expected = knots.control_count();
        if points.len() != expected {
            return Err(NurbsError::CountMismatch { what: "control points".into(), found: points.len(), expected });
        }
        for (i, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(NurbsError::NotFinite { what: "point", index: i });
            }
        }
        let rational = weights.is_some();
        let weights = match weights {
            Some(w) => {
                if w.len() != expected {
                    return Err(NurbsError::CountMismatch { what: "weights".into(), found: w.len(), expected });
                }
                for (i, &x) in w.iter().enumerate() {
                    if !x.is_finite() {
                        return Err(NurbsError::NotFinite { what: "weight", index: i });
                    }
                    if x <= 0.0 {
                        return Err(NurbsError::BadWeight { index: i, found: x });
                    }
                }
                w
            }
            None => alloc::vec![1.0; expected],
        };
        let points = points.iter().zip(&weights).map(|(p, &w)| (*p * w).extend(w)).collect();
        Ok(Self { knots, points, rational })
    }

    /// Degree of the curve.
    pub fn degree(&self) -> usize {
        self.knots.degree()
    }

    /// The knot vector.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// Whether weights were given.
    pub fn is_rational(&self) -> bool {
        self.rational
    }

    /// Homogeneous control points `(w·x, w·y, w·z, w)`.
    pub fn homogeneous_points(&self) -> &[DVec4] {
        &self.points
    }

    /// Euclidean control points.
    pub fn control_points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.points.iter().map(|h| h.truncate() / h.w)
    }

    /// Parameter range.
    pub fn domain(&self) -> (f64, f64) {
        self.knots.domain()
    }

    /// C(t); `t` is clamped into the domain.
    pub fn point(&self, t: f64) -> DVec3 {
        let mut b = BasisDers::default();
        let span = self.knots.basis_ders(t, 0, &mut b);
        let p = self.degree();
        let mut h = DVec4::ZERO;
        for j in 0..=p {
            h += self.points[span - p + j] * b.0[0][j];
        }
        h.truncate() / h.w
    }

    /// C(t), C'(t), C''(t) (rational quotient rule).
    pub fn derivs(&self, t: f64) -> CurveDerivs {
        let mut b = BasisDers::default();
        let span = self.knots.basis_ders(t, 2, &mut b);
        let p = self.degree();
        let mut h = [DVec4::ZERO; 3];
        for (k, hk) in h.iter_mut().enumerate() {
            for j in 0..=p {
                *hk += self.points[span - p + j] * b.0[k][j];
            }
        }
        let w = h[0].w;
        let point = h[0].truncate() / w;
        let d1 = (h[1].truncate() - point * h[1].w) / w;
        let d2 = (h[2].truncate() - d1 * (2.0 * h[1].w) - point * h[2].w) / w;
        CurveDerivs { point, d1, d2 }
    }

    /// The curve with knot `t` inserted once (Boehm); same shape.
    /// `t` outside the open domain, or already at full multiplicity, returns a copy.
    pub fn insert_knot(&self, t: f64) -> Self {
        let (a, b) = self.domain();
        let p = self.degree();
        if !(t > a && t < b) || self.knots.multiplicity(t) >= p {
            return self.clone();
        }
        let span = self.knots.span(t);
        let u = self.knots.knots();
        let mut pts = Vec::with_capacity(self.points.len() + 1);
        for i in 0..=span - p {
            pts.push(self.points[i]);
        }
        for i in span - p + 1..=span {
            let den = u[i + p] - u[i];
            let alpha = if den > 0.0 { (t - u[i]) / den } else { 0.0 };
            pts.push(self.points[i] * alpha + self.points[i - 1] * (1.0 - alpha));
        }
        for i in span..self.points.len() {
            pts.push(self.points[i]);
        }
        Self { knots: self.knots.with_inserted(span, t), points: pts, rational: self.rational }
    }

    /// Splits at `t` into two curves covering `[a, t]` and `[t, b]`.
    /// Returns `None` when `t` is not strictly inside the domain.
    pub fn split(&self, t: f64) -> Option<(Self, Self)> {
        let (a, b) = self.domain();
        if !(t > a && t < b) {
            return None;
        }
        let p = self.degree();
        let mut c = self.clone();
        while c.knots.multiplicity(t) < p {
            let before = c.points.len();
            c = c.insert_knot(t);
            if c.points.len() == before {
                return None;
            }
        }
        let k = c.knots.knots();
        let first = k.iter().position(|&x| x == t)?;
        let last = first + p; // index one past the run of p equal knots
        let mut k1: Vec<f64> = k[..last].to_vec();
        k1.push(t);
        let mut k2: Vec<f64> = alloc::vec![t];
        k2.extend_from_slice(&k[first..]);
        let n1 = k1.len() - p - 1;
        let p1 = c.points[..n1].to_vec();
        let p2 = c.points[n1 - 1..].to_vec();
        let left = Self { knots: KnotVector::try_new(p, k1).ok()?, points: p1, rational: self.rational };
        let right = Self { knots: KnotVector::try_new(p, k2).ok()?, points: p2, rational: self.rational };
        Some((left, right))
    }

    /// Box around the control polygon (contains the curve: convex hull property).
    pub fn bbox(&self) -> Aabb {
        Aabb::from_points(self.control_points())
    }

    /// Closest point on the curve to `target`: `(t, point, distance)`.
    ///
    /// Samples every knot span, then Newton iterations on `C'·(C − P) = 0`
    /// (a step may only decrease the distance) from up to four of the best
    /// distinct local minima of the samples (from both sides when one sits on
    /// an inner knot, where the curve may turn a corner); the closest result
    /// wins. Never
    /// leaves the domain; on a closed curve a step across the start continues
    /// from the end and vice versa.
    pub fn project(&self, target: DVec3) -> (f64, DVec3, f64) {
        const MAX_STARTS: usize = 4;
        let (a, b) = self.domain();
        let spans = self.knots.breakpoints();
        let per = 4 * self.degree() + 2;
        let mut samples: Vec<(f64, DVec3, f64)> = Vec::new();
        // Indices of samples at inner breakpoints, where the curve may have a
        // corner: Newton there sees only the derivative of the span on the right.
        let mut corners: Vec<usize> = Vec::new();
        let last_span = spans.len().saturating_sub(2);
        for (k, w) in spans.windows(2).enumerate() {
            for s in usize::from(k > 0)..=per {
                let t = w[0] + (w[1] - w[0]) * s as f64 / per as f64;
                let p = self.point(t);
                if s == per && k < last_span {
                    corners.push(samples.len());
                }
                samples.push((t, p, p.distance_squared(target)));
            }
        }
        let n = samples.len();
        // Indices stay in 0..n.
        let mut minima: Vec<usize> = (0..n)
            .filter(|&i| {
                (i == 0 || samples[i - 1].2 >= samples[i].2) && (i + 1 == n || samples[i + 1].2 >= samples[i].2)
            })
            .collect();
        minima.sort_by(|&i, &j| samples[i].2.total_cmp(&samples[j].2));
        let (pa, pb) = (self.point(a), self.point(b));
        let closed = pa.distance(pb) <= 1e-9 * (pa.length().max(pb.length()) + self.bbox().diagonal());
        let mut best: Option<(f64, DVec3, f64)> = None;
        let mut used: Vec<DVec3> = Vec::new();
        for i in minima {
            if used.len() == MAX_STARTS {
                break;
            }
            let (t0, p0, _) = samples[i];
            if used.contains(&p0) {
                continue;
            }
            used.push(p0);
            let r = self.newton(target, t0, closed);
            if best.is_none_or(|bst| r.2 < bst.2) {
                best = Some(r);
            }
            if i > 0 && corners.contains(&i) {
                // Also search the span on the left of the corner.
                let r = self.newton(target, 0.5 * (samples[i - 1].0 + t0), closed);
                if best.is_none_or(|bst| r.2 < bst.2) {
                    best = Some(r);
                }
            }
        }
        best.unwrap_or_else(|| (a, pa, pa.distance(target)))
    }

    /// Safeguarded Newton iterations from `t` (see [`NurbsCurve::project`]).
    fn newton(&self, target: DVec3, mut t: f64, closed: bool) -> (f64, DVec3, f64) {
        let (a, b) = self.domain();
        let period = b - a;
        let mut dist = self.point(t).distance(target);
        for _ in 0..32 {
            let c = self.derivs(t);
            let r = c.point - target;
            let f = c.d1.dot(r);
            let df = c.d1.length_squared() + c.d2.dot(r);
            if df.abs() < 1e-300 {
                break;
            }
            let mut step = -f / df;
            if df < 0.0 {
                // Not a minimum nearby: gradient step instead.
                step = -f / c.d1.length_squared().max(1e-300);
            }
            if !step.is_finite() {
                break;
            }
            step = step.clamp(-0.5 * period, 0.5 * period);
            let mut accepted = false;
            for _ in 0..12 {
                let mut tn = t + step;
                if closed && !(a..=b).contains(&tn) {
                    tn = if tn < a { tn + period } else { tn - period };
                }
                let tn = tn.clamp(a, b);
                let pn = self.point(tn);
                let dn = pn.distance(target);
                if dn <= dist {
                    let mut moved = (tn - t).abs();
                    if closed {
                        moved = moved.min(period - moved);
                    }
                    t = tn;
                    dist = dn;
                    accepted = true;
                    if moved <= 1e-14 * period.max(1.0) {
                        return (t, pn, dist);
                    }
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        let p = self.point(t);
        (t, p, p.distance(target))
    }
}
