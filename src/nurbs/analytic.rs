//! Exact rational B-spline forms of analytic curves and surfaces: lines,
//! circular and elliptic arcs of any sweep, hyperbola and parabola arcs,
//! conic segments, bilinear patches,
//! surfaces of revolution, extrusions and ruled surfaces. Importers (IGES,
//! STEP) turn their analytic entities into NURBS with these.
//!
//! Arcs are split into pieces of at most 90° (middle weight `cos(Δ/2)`), and
//! their knots are the piece boundaries' angles: the parameter equals the
//! angle at every knot and stays close to it between them; [`ArcParam`]
//! converts exactly both ways.

use alloc::vec::Vec;
use glam::{DVec3, DVec4};

use super::elevate::make_compatible;
use super::{KnotVector, NurbsCurve, NurbsError, NurbsSurface};

/// Largest sweep of one rational quadratic piece of an arc.
const MAX_PIECE: f64 = core::f64::consts::FRAC_PI_2 + 1e-9;

/// How the parameter of an arc built here relates to the angle: the arc over
/// `[start, end]` is made of `pieces` equal rational quadratic pieces, the
/// parameter is the angle at their ends, and inside piece `k` (half-sweep
/// `α`) `tan((θ − θ_mid)/2) = (2σ − 1)·tan(α/2)` where `σ ∈ [0, 1]` is the
/// parameter's fraction of the piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcParam {
    /// Angle (and parameter) at the start.
    pub start: f64,
    /// Angle (and parameter) at the end (`> start`).
    pub end: f64,
    /// Number of pieces (≥ 1).
    pub pieces: usize,
}

impl ArcParam {
    /// The piece layout used for an arc from `start` to `end` (`end > start`).
    pub fn new(start: f64, end: f64) -> Self {
        let sweep = end - start;
        let pieces = if sweep.is_finite() && sweep > 0.0 {
            (crate::math::ceil(sweep / MAX_PIECE) as usize).clamp(1, 64)
        } else {
            1
        };
        Self { start, end, pieces }
    }

    fn piece_sweep(&self) -> f64 {
        (self.end - self.start) / self.pieces as f64
    }

    /// Parameter of the arc point at angle `theta` (angles outside the
    /// sweep are extrapolated through the nearest piece).
    pub fn param_of_angle(&self, theta: f64) -> f64 {
        let d = self.piece_sweep();
        if d.is_nan() || d <= 0.0 {
            return self.start;
        }
        let k = crate::math::floor((theta - self.start) / d).clamp(0.0, (self.pieces - 1) as f64);
        let s0 = self.start + k * d;
        let mid = s0 + 0.5 * d;
        let sigma = 0.5 * (1.0 + libm::tan(0.5 * (theta - mid)) / libm::tan(0.25 * d));
        s0 + sigma * d
    }

    /// Knots (angle units) and, per control point, its `(cos, sin)`
    /// coefficients and weight: point `j` is `c + x_j·X + y_j·Y`.
    fn layout(&self) -> (Vec<f64>, Vec<(f64, f64, f64)>) {
        let n = self.pieces;
        let d = self.piece_sweep();
        let w_mid = libm::cos(0.5 * d);
        let mut knots = Vec::with_capacity(2 * n + 4);
        knots.extend([self.start; 3]);
        for k in 1..n {
            let t = self.start + k as f64 * d;
            knots.extend([t, t]);
        }
        knots.extend([self.end; 3]);
        let mut pts = Vec::with_capacity(2 * n + 1);
        for k in 0..n {
            let a0 = self.start + k as f64 * d;
            let am = a0 + 0.5 * d;
            if k == 0 {
                pts.push((libm::cos(a0), libm::sin(a0), 1.0));
            }
            // Tangent intersection: on the bisector at distance 1/cos(d/2).
            pts.push((libm::cos(am) / w_mid, libm::sin(am) / w_mid, w_mid));
            let a1 = a0 + d;
            pts.push((libm::cos(a1), libm::sin(a1), 1.0));
        }
        (knots, pts)
    }
}

/// The segment from `a` (parameter `t0`) to `b` (parameter `t1`), degree 1.
///
/// # Errors
/// `t1 <= t0` or non-finite input.
pub fn line(a: DVec3, b: DVec3, t0: f64, t1: f64) -> Result<NurbsCurve, NurbsError> {
    NurbsCurve::try_new(1, alloc::vec![t0, t0, t1, t1], alloc::vec![a, b], None)
}

/// The elliptic (circular when `x` and `y` are orthogonal and equally long)
/// arc `c + cos θ·x + sin θ·y` for `θ` from `start` to `end` (`end > start`,
/// any sweep up to a full turn and beyond). Parameter: see [`ArcParam`].
///
/// # Errors
/// An empty sweep or non-finite input.
pub fn ellipse_arc(c: DVec3, x: DVec3, y: DVec3, start: f64, end: f64) -> Result<NurbsCurve, NurbsError> {
    if end.is_nan() || start.is_nan() || end <= start {
        return Err(NurbsError::BadMultiplicity { index: 0 });
    }
    let map = ArcParam::new(start, end);
    let (knots, layout) = map.layout();
    let pts = layout.iter().map(|&(a, b, _)| c + x * a + y * b).collect();
    let weights = layout.iter().map(|&(_, _, w)| w).collect();
    NurbsCurve::try_new(2, knots, pts, Some(weights))
}

/// The circular arc of `radius` around `c` in the plane of the orthonormal
/// `x`, `y`, from angle `start` to `end` (counter-clockwise about `x × y`).
///
/// # Errors
/// As [`ellipse_arc`].
pub fn circle_arc(c: DVec3, x: DVec3, y: DVec3, radius: f64, start: f64, end: f64) -> Result<NurbsCurve, NurbsError> {
    ellipse_arc(c, x * radius, y * radius, start, end)
}

/// Largest span of the parameter `t` in one piece of a hyperbola arc: its
/// middle weight `cosh(span / 2)` stays at most `cosh 1 ≈ 1.54`.
const MAX_HYPERBOLA_PIECE: f64 = 2.0;

/// The hyperbola arc `c + cosh t·x + sinh t·y` for `t` from `start` to `end`
/// (`end > start`; `x`, `y` the semi-axes along the real and imaginary
/// axes). Exact: each piece (at most [`MAX_HYPERBOLA_PIECE`] of `t`, 1 to
/// 64 of them) is the rational quadratic from `P(t0)` to `P(t1)` whose middle
/// point is where their tangents meet, `c + (cosh m·x + sinh m·y) / cosh h`
/// with weight `cosh h` (`m` the middle and `h` the half span of `t`: the
/// ellipse's construction with `cosh`, `sinh` for `cos`, `sin`). The knots
/// are the pieces' ends in `t`.
///
/// # Errors
/// An empty span or non-finite input (a span so far out that `cosh` overflows).
pub fn hyperbola_arc(c: DVec3, x: DVec3, y: DVec3, start: f64, end: f64) -> Result<NurbsCurve, NurbsError> {
    if end.is_nan() || start.is_nan() || end <= start {
        return Err(NurbsError::BadMultiplicity { index: 0 });
    }
    let n = (crate::math::ceil((end - start) / MAX_HYPERBOLA_PIECE) as usize).clamp(1, 64);
    let d = (end - start) / n as f64;
    let h = 0.5 * d;
    let at = |t: f64| c + x * libm::cosh(t) + y * libm::sinh(t);
    let w_mid = libm::cosh(h);
    let mut knots = Vec::with_capacity(2 * n + 4);
    let mut pts = Vec::with_capacity(2 * n + 1);
    let mut weights = Vec::with_capacity(2 * n + 1);
    knots.extend([start; 3]);
    pts.push(at(start));
    weights.push(1.0);
    for k in 0..n {
        let t0 = start + k as f64 * d;
        let t1 = if k + 1 == n { end } else { t0 + d };
        let m = 0.5 * (t0 + t1);
        pts.push(c + (x * libm::cosh(m) + y * libm::sinh(m)) / w_mid);
        weights.push(w_mid);
        pts.push(at(t1));
        weights.push(1.0);
        if k + 1 < n {
            knots.extend([t1, t1]);
        }
    }
    knots.extend([end; 3]);
    NurbsCurve::try_new(2, knots, pts, Some(weights))
}

/// The parabola arc `c + t²·x + t·y` for `t` from `start` to `end` (`end >
/// start`): one polynomial quadratic Bézier piece, its parameter `t` itself.
///
/// # Errors
/// An empty span or non-finite input.
pub fn parabola_arc(c: DVec3, x: DVec3, y: DVec3, start: f64, end: f64) -> Result<NurbsCurve, NurbsError> {
    if end.is_nan() || start.is_nan() || end <= start {
        return Err(NurbsError::BadMultiplicity { index: 0 });
    }
    let at = |t: f64| c + x * (t * t) + y * t;
    // The middle point: on the tangent at the start, half the span along it.
    let p1 = at(start) + (x * (2.0 * start) + y) * (0.5 * (end - start));
    NurbsCurve::try_new(2, alloc::vec![start, start, start, end, end, end], alloc::vec![at(start), p1, at(end)], None)
}

/// The rational quadratic segment with control points `p0`, `p1`, `p2`
/// and middle weight `w` (a conic: ellipse for `w < 1`, parabola `w = 1`,
/// hyperbola `w > 1`), over the parameter range `[0, 1]`.
///
/// # Errors
/// A weight that is not positive or non-finite points.
pub fn conic_segment(p0: DVec3, p1: DVec3, p2: DVec3, w: f64) -> Result<NurbsCurve, NurbsError> {
    NurbsCurve::try_new(
        2,
        alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        alloc::vec![p0, p1, p2],
        Some(alloc::vec![1.0, w, 1.0]),
    )
}

/// The bilinear patch `(1−u)(1−v)·p00 + u(1−v)·p10 + (1−u)v·p01 + uv·p11`
/// reparameterized to `u ∈ [u0, u1]`, `v ∈ [v0, v1]` (a plane patch when the
/// four points are coplanar).
///
/// # Errors
/// An empty range or non-finite input.
pub fn bilinear(p: [[DVec3; 2]; 2], u: [f64; 2], v: [f64; 2]) -> Result<NurbsSurface, NurbsError> {
    NurbsSurface::try_new(
        [1, 1],
        alloc::vec![u[0], u[0], u[1], u[1]],
        alloc::vec![v[0], v[0], v[1], v[1]],
        &[alloc::vec![p[0][0], p[0][1]], alloc::vec![p[1][0], p[1][1]]],
        None,
    )
}

/// The plane z = 0 over [-h, h]², u = x and v = y: the flat face the meshing tests build on.
#[cfg(test)]
pub(crate) fn xy_plane(h: f64) -> NurbsSurface {
    let c = |x: f64, y: f64| DVec3::new(x, y, 0.0);
    match bilinear([[c(-h, -h), c(-h, h)], [c(h, -h), c(h, h)]], [-h, h], [-h, h]) {
        Ok(s) => s,
        Err(e) => panic!("plane of half side {h}: {e:?}"),
    }
}

/// The surface swept by `profile` turning about the axis through `origin`
/// along the unit vector `axis`, by angles from `start` to `end` (right-hand
/// rule; angle 0 is the profile itself). u: the profile's parameter; v: the
/// angle as laid out by [`ArcParam`].
///
/// Each control point `Q` of the profile becomes a circular arc about its
/// foot `O` on the axis: `O + x_j·r + y_j·(axis × r)` with `r = Q − O`, so a
/// point on the axis stays put (a pole) and the result is exact.
///
/// # Errors
/// An empty sweep, a zero axis or non-finite input.
pub fn revolve(
    profile: &NurbsCurve,
    origin: DVec3,
    axis: DVec3,
    start: f64,
    end: f64,
) -> Result<NurbsSurface, NurbsError> {
    let len = axis.length();
    if !(len > 0.0 && len.is_finite()) {
        return Err(NurbsError::NotFinite { what: "point", index: 0 });
    }
    if end.is_nan() || start.is_nan() || end <= start {
        return Err(NurbsError::BadMultiplicity { index: 0 });
    }
    let a = axis / len;
    let map = ArcParam::new(start, end);
    let (vknots, layout) = map.layout();
    let rows: Vec<DVec4> = profile.homogeneous_points().to_vec();
    let mut points = Vec::with_capacity(rows.len());
    let mut weights = Vec::with_capacity(rows.len());
    for h in &rows {
        let q = h.truncate() / h.w;
        let foot = origin + a * (q - origin).dot(a);
        let r = q - foot;
        let s = a.cross(r);
        points.push(layout.iter().map(|&(x, y, _)| foot + r * x + s * y).collect::<Vec<_>>());
        weights.push(layout.iter().map(|&(_, _, w)| w * h.w).collect::<Vec<_>>());
    }
    let ku = profile.knots().clone();
    let kv = KnotVector::try_new(2, vknots)?;
    NurbsSurface::from_parts(ku, kv, &points, Some(&weights))
}

/// The surface `C(u) + v·dir` for `v ∈ [v0, v1]` (a tabulated cylinder).
///
/// # Errors
/// An empty range or non-finite input.
pub fn extrude(curve: &NurbsCurve, dir: DVec3, v0: f64, v1: f64) -> Result<NurbsSurface, NurbsError> {
    let kv = KnotVector::try_new(1, alloc::vec![v0, v0, v1, v1])?;
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for h in curve.homogeneous_points() {
        let q = h.truncate() / h.w;
        points.push(alloc::vec![q + dir * v0, q + dir * v1]);
        weights.push(alloc::vec![h.w, h.w]);
    }
    let w = curve.is_rational().then_some(weights.as_slice());
    NurbsSurface::from_parts(curve.knots().clone(), kv, &points, w)
}

/// The ruled surface between `c0` (v = 0) and `c1` (v = 1): both are raised
/// to one degree, mapped to `u ∈ [0, 1]` and given one knot vector, then
/// joined by straight lines between corresponding control points.
///
/// # Errors
/// As [`make_compatible`].
pub fn ruled(c0: &NurbsCurve, c1: &NurbsCurve) -> Result<NurbsSurface, NurbsError> {
    let both = make_compatible(&[c0.clone(), c1.clone()])?;
    let (a, b) = (&both[0], &both[1]);
    let rational = a.is_rational() || b.is_rational();
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for (ha, hb) in a.homogeneous_points().iter().zip(b.homogeneous_points()) {
        points.push(alloc::vec![ha.truncate() / ha.w, hb.truncate() / hb.w]);
        weights.push(alloc::vec![ha.w, hb.w]);
    }
    let kv = KnotVector::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0])?;
    NurbsSurface::from_parts(a.knots().clone(), kv, &points, rational.then_some(weights.as_slice()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of `c` at `n + 1` even parameters.
    fn samples(c: &NurbsCurve, n: usize) -> Vec<DVec3> {
        let (a, b) = c.domain();
        (0..=n).map(|k| c.point(a + (b - a) * k as f64 / n as f64)).collect()
    }

    #[test]
    fn a_hyperbola_arc_lies_on_its_hyperbola_whatever_its_span() {
        let (c, a, b) = (DVec3::new(1.0, 2.0, 3.0), 3.0, 2.0);
        let (x, y) = (DVec3::X * a, DVec3::new(0.0, 0.6, 0.8) * b);
        for (t0, t1, pieces) in [(-0.5, 0.7, 1), (-3.0, 4.5, 4), (0.1, 0.2, 1)] {
            let arc = hyperbola_arc(c, x, y, t0, t1).unwrap();
            assert_eq!(arc.knots().knots().len(), 2 * pieces + 4, "pieces of at most 2 in t");
            let (s, e) = arc.domain();
            let ends = [c + x * libm::cosh(t0) + y * libm::sinh(t0), c + x * libm::cosh(t1) + y * libm::sinh(t1)];
            assert!(arc.point(s).distance(ends[0]) < 1e-12 && arc.point(e).distance(ends[1]) < 1e-9);
            let mut last_v = f64::NEG_INFINITY;
            for p in samples(&arc, 200) {
                let w = p - c;
                let (u, v) = (w.dot(x) / (a * a), w.dot(y) / (b * b));
                // In the plane of x and y, on the branch u > 0, with u² − v² = 1.
                assert!((w - x * u - y * v).length() < 1e-9, "off the plane: {p}");
                assert!(u > 0.0 && (u * u - v * v - 1.0).abs() < 1e-9 * u * u, "({u}, {v}) off the hyperbola");
                // It runs one way along the branch, from t0 to t1.
                assert!(v > last_v && v >= libm::sinh(t0) - 1e-9 && v <= libm::sinh(t1) + 1e-9);
                last_v = v;
            }
        }
        assert!(hyperbola_arc(c, x, y, 1.0, 1.0).is_err());
        assert!(hyperbola_arc(c, x, y, 0.0, 2000.0).is_err(), "cosh overflows: an error, not a curve of infinities");
    }

    #[test]
    fn a_parabola_arc_is_its_parabola_at_every_parameter() {
        let (c, x, y) = (DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.5, 0.0, 0.0), DVec3::new(0.0, 0.0, 2.0));
        let arc = parabola_arc(c, x, y, -2.0, 3.0).unwrap();
        assert_eq!(arc.domain(), (-2.0, 3.0));
        for k in 0..=50 {
            let t = -2.0 + 5.0 * k as f64 / 50.0;
            assert!(arc.point(t).distance(c + x * (t * t) + y * t) < 1e-12, "t = {t}");
        }
        assert!(parabola_arc(c, x, y, 3.0, -2.0).is_err());
    }
}
