//! Rational B-spline curves in 2-D (z = 0) and 3-D.

use crate::numeric::guarded_div;
use alloc::collections::BinaryHeap;
use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::{DVec3, DVec4};

use super::knots::{KnotVector, MAX_DERIV};
use super::speed::speed_bound;
use super::{Aabb, CurveProjection, NurbsError, MAX_DEGREE};

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
        // Basis scratch sized for the degree class, as for surfaces: zeroing
        // the full 17-wide tables cost more than a cubic's arithmetic.
        match self.degree() {
            0..=3 => self.point_n::<4>(t),
            4..=7 => self.point_n::<8>(t),
            _ => self.point_n::<{ MAX_DEGREE + 1 }>(t),
        }
    }

    fn point_n<const N: usize>(&self, t: f64) -> DVec3 {
        let mut b = [[0.0; N]; MAX_DERIV + 1];
        let span = self.knots.basis_fast(None, t, 0, &mut b);
        let p = self.degree();
        let mut h = DVec4::ZERO;
        for j in 0..=p {
            h += self.points[span - p + j] * b[0][j];
        }
        h.truncate() / h.w
    }

    /// C(t), C'(t), C''(t) (rational quotient rule).
    pub fn derivs(&self, t: f64) -> CurveDerivs {
        match self.degree() {
            0..=3 => self.derivs_n::<4>(None, t),
            4..=7 => self.derivs_n::<8>(None, t),
            _ => self.derivs_n::<{ MAX_DEGREE + 1 }>(None, t),
        }
    }

    /// As [`NurbsCurve::derivs`] with the polynomial piece of knot span
    /// `span`, also at its ends (one-sided limits at the knots).
    fn derivs_in(&self, span: usize, t: f64) -> CurveDerivs {
        match self.degree() {
            0..=3 => self.derivs_n::<4>(Some(span), t),
            4..=7 => self.derivs_n::<8>(Some(span), t),
            _ => self.derivs_n::<{ MAX_DEGREE + 1 }>(Some(span), t),
        }
    }

    /// Derivatives at `t` in the span holding it, or in `span` when given.
    fn derivs_n<const N: usize>(&self, span: Option<usize>, t: f64) -> CurveDerivs {
        let mut b = [[0.0; N]; MAX_DERIV + 1];
        let span = self.knots.basis_fast(span, t, 2, &mut b);
        let p = self.degree();
        let mut h = [DVec4::ZERO; 3];
        for (k, hk) in h.iter_mut().enumerate() {
            for j in 0..=p {
                *hk += self.points[span - p + j] * b[k][j];
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

    /// Per coordinate, a bound of `|C'(t)|` over the whole domain (`None`
    /// for a non-positive or non-finite weight): lets a caller rule a curve
    /// piece out from its length without sampling it (`speed_bound`).
    pub fn derivative_bound(&self) -> Option<DVec3> {
        speed_bound(&self.knots, &self.points, 1, 1)
    }

    /// Box around the control polygon (contains the curve: convex hull property).
    pub fn bbox(&self) -> Aabb {
        Aabb::from_points(self.control_points())
    }

    /// Closest point on the curve to `target`: its parameter, the point and
    /// its distance, found by a branch and bound over the curve's Bézier
    /// pieces finished by Newton's method; never leaves the domain.
    pub fn project(&self, target: DVec3) -> CurveProjection {
        let (t, point, distance) = self.closest(target);
        CurveProjection { t, point, distance }
    }

    /// Closest point on the curve to `target`: `(t, point, distance)`.
    ///
    /// Branch and bound over Bézier pieces: every knot span is converted to
    /// its Bézier form, and a piece lies in the box of its control points
    /// (convex hull property, weights positive), whose distance to `target`
    /// bounds the piece's from below. The piece with the lowest bound is
    /// split in two until it is ruled out by the best distance found so far
    /// or is 1/256 of its span, where Newton iterations on `C'·(C − P) = 0`
    /// (a step may only decrease the distance) finish it. So sharp turns
    /// of rational spans, corners at knots and seams of closed curves are all
    /// searched; the work is capped at a few thousand pieces. Never leaves
    /// the domain.
    fn closest(&self, target: DVec3) -> (f64, DVec3, f64) {
        let (a, _) = self.domain();
        let p = self.degree();
        let pa = self.point(a);
        // (t, point, distance, span).
        let mut best = (a, pa, pa.distance(target), self.knots.span(a));
        // Best-first: a heap ordered by the bound (ties by age), not a scan
        // of every waiting piece per step, which made long curves quadratic.
        let mut pieces: BinaryHeap<Queued> = BinaryHeap::new();
        let mut seq = 0usize;
        let mut queue = |heap: &mut BinaryHeap<Queued>, piece: Piece| {
            heap.push(Queued { piece, seq });
            seq += 1;
        };
        for w in self.knots.breakpoints().windows(2) {
            let span = self.knots.span(0.5 * (w[0] + w[1]));
            let ctrl = self.bezier_of_span(span);
            let piece = Piece::new(ctrl, span, w[0], w[1], w[0], w[1], target);
            for (t, h) in [(w[0], piece.ctrl[0]), (w[1], piece.ctrl[p])] {
                let q = h.truncate() / h.w;
                let d = q.distance(target);
                if d < best.2 {
                    best = (t, q, d, span);
                }
            }
            queue(&mut pieces, piece);
        }
        let mut examined = 0;
        while examined < MAX_PIECES {
            let Some(next) = pieces.peek() else {
                break;
            };
            if next.piece.bound >= best.2 * best.2 {
                break;
            }
            let Some(Queued { piece, .. }) = pieces.pop() else {
                break;
            };
            examined += 1;
            if piece.t1 - piece.t0 <= LEAF * (piece.span_hi - piece.span_lo) {
                let mid = 0.5 * (piece.t0 + piece.t1);
                let r = self.newton_in_span(target, piece.span, piece.t0, piece.t1, mid);
                if r.2 < best.2 {
                    best = (r.0, r.1, r.2, piece.span);
                }
                continue;
            }
            let (left, right) = piece.split(target);
            let h = right.ctrl[0];
            let q = h.truncate() / h.w;
            let d = q.distance(target);
            if d < best.2 {
                best = (right.t0, q, d, right.span);
            }
            queue(&mut pieces, left);
            queue(&mut pieces, right);
        }
        // Polish within the span (a best found at a piece's end, or after the cap).
        let (lo, hi) = (self.knots.knots()[best.3], self.knots.knots()[best.3 + 1]);
        let r = self.newton_in_span(target, best.3, lo, hi, best.0);
        if r.2 < best.2 {
            r
        } else {
            (best.0, best.1, best.2)
        }
    }

    /// Homogeneous Bézier control points of knot span `span` (which must
    /// satisfy `degree <= span < control_count()`), by blossoming: point `k`
    /// is the blossom at `(a, …, a, b, …, b)` with `k` copies of the span's
    /// end `b` (The NURBS Book §5.6; de Boor's recursion with one argument per level).
    fn bezier_of_span(&self, span: usize) -> Vec<DVec4> {
        let p = self.degree();
        let u = self.knots.knots();
        let (a, b) = (u[span], u[span + 1]);
        (0..=p)
            .map(|k| {
                let mut d = [DVec4::ZERO; super::MAX_DEGREE + 1];
                d[..=p].copy_from_slice(&self.points[span - p..=span]);
                for r in 1..=p {
                    let t = if r <= p - k { a } else { b };
                    for j in (r..=p).rev() {
                        let g = span - p + j;
                        let den = u[g + p + 1 - r] - u[g];
                        let alpha = if den > 0.0 { (t - u[g]) / den } else { 0.0 };
                        d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
                    }
                }
                d[p]
            })
            .collect()
    }

    /// Safeguarded Newton iterations from `t` on the polynomial piece of
    /// `span`, staying inside its parameter range `[lo, hi]`.
    fn newton_in_span(&self, target: DVec3, span: usize, lo: f64, hi: f64, mut t: f64) -> (f64, DVec3, f64) {
        // Derivatives at `t`, kept from the evaluation that accepted it.
        let mut c = self.derivs_in(span, t);
        let mut point = c.point;
        let mut dist = point.distance(target);
        let stop = 1e-14 * (hi - lo).max(1.0);
        for _ in 0..32 {
            let r = c.point - target;
            let f = c.d1.dot(r);
            let df = c.d1.length_squared() + c.d2.dot(r);
            // Newton where the model has a minimum, a gradient step elsewhere.
            let mut step = if df > 0.0 { -f / df } else { guarded_div(-f, c.d1.length_squared()) };
            if !step.is_finite() {
                break;
            }
            // Converged: a move this short ends the search whether it is
            // taken or not (trying it only compares rounding noise, halving twelve times).
            if ((t + step).clamp(lo, hi) - t).abs() <= stop {
                break;
            }
            let mut accepted = false;
            for _ in 0..12 {
                let tn = (t + step).clamp(lo, hi);
                let cn = self.derivs_in(span, tn);
                let dn = cn.point.distance(target);
                if dn <= dist {
                    let moved = (tn - t).abs();
                    t = tn;
                    point = cn.point;
                    dist = dn;
                    c = cn;
                    accepted = true;
                    if moved <= stop {
                        return (t, point, dist);
                    }
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        (t, point, dist)
    }
}

/// Most Bézier pieces [`NurbsCurve::project`] examines (bounds its time).
const MAX_PIECES: usize = 2048;

/// A piece this fraction of its knot span long is finished by Newton, not split.
const LEAF: f64 = 1.0 / 256.0;

/// A waiting [`Piece`] in [`NurbsCurve::project`]'s heap: the greatest is
/// the one of the lowest bound, the earliest queued among equal bounds.
struct Queued {
    piece: Piece,
    seq: usize,
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        other.piece.bound.total_cmp(&self.piece.bound).then(other.seq.cmp(&self.seq))
    }
}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Queued {}

/// A Bézier piece of one knot span, with the lower bound of its squared
/// distance to the target.
struct Piece {
    ctrl: Vec<DVec4>,
    span: usize,
    span_lo: f64,
    span_hi: f64,
    t0: f64,
    t1: f64,
    bound: f64,
}

impl Piece {
    fn new(ctrl: Vec<DVec4>, span: usize, span_lo: f64, span_hi: f64, t0: f64, t1: f64, target: DVec3) -> Self {
        let hull = Aabb::from_points(ctrl.iter().map(|h| h.truncate() / h.w));
        let gap = (hull.min - target).max(target - hull.max).max(DVec3::ZERO);
        Self { ctrl, span, span_lo, span_hi, t0, t1, bound: gap.length_squared() }
    }

    /// Halves by de Casteljau in homogeneous coordinates.
    fn split(self, target: DVec3) -> (Self, Self) {
        let n = self.ctrl.len();
        let mut left = Vec::with_capacity(n);
        let mut right = Vec::with_capacity(n);
        let mut work = self.ctrl;
        left.push(work[0]);
        right.push(work[n - 1]);
        for r in 1..n {
            for j in 0..n - r {
                work[j] = (work[j] + work[j + 1]) * 0.5;
            }
            left.push(work[0]);
            right.push(work[n - 1 - r]);
        }
        right.reverse();
        let mid = 0.5 * (self.t0 + self.t1);
        (
            Self::new(left, self.span, self.span_lo, self.span_hi, self.t0, mid, target),
            Self::new(right, self.span, self.span_lo, self.span_hi, mid, self.t1, target),
        )
    }
}
