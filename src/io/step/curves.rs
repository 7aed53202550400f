//! Points, directions, placements and curves of ISO 10303-42 as read from
//! the graph: curves become [`CurveDef`]s that know their own parameter
//! (line length, conic angle, B-spline parameter), so an edge can be cut
//! between its vertices and turned into exact NURBS pieces.

use alloc::format;
use alloc::vec::Vec;
use glam::{DAffine3, DMat3, DVec3};

use super::graph::{Ent, Graph};
use super::{MAX_CONTROL_POINTS, MAX_DEPTH};
use crate::numeric::{guarded_div, TINY};
use crate::nurbs::analytic::{ellipse_arc, hyperbola_arc, line, parabola_arc};
use crate::nurbs::join::join;
use crate::nurbs::reparam::{reversed, segment, with_end_points, RawCurve};
use crate::nurbs::{NurbsCurve, NurbsError, MAX_DEGREE};
use crate::Error;

const TAU: f64 = core::f64::consts::TAU;

/// A right-handed orthonormal frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Frame {
    pub o: DVec3,
    pub x: DVec3,
    pub y: DVec3,
    pub z: DVec3,
}

impl Frame {
    /// The map from frame coordinates to the parent's.
    pub fn matrix(&self) -> DAffine3 {
        DAffine3::from_mat3_translation(DMat3::from_cols(self.x, self.y, self.z), self.o)
    }
}

/// What reading geometry needs besides the graph: how many radians one
/// angle unit of the representation context is, and its uncertainty
/// (length units; 0 when not stated).
#[derive(Clone, Copy)]
pub(super) struct Geo<'g> {
    pub g: &'g Graph,
    pub angle: f64,
    pub uncertainty: f64,
}

/// A curve with its own parameter.
#[derive(Debug, Clone)]
pub(super) enum Curve3 {
    /// `p + t·d`.
    Line { p: DVec3, d: DVec3 },
    /// `c + cos t·x + sin t·y` (`x`, `y` orthogonal, lengths the semi-axes), `t` in radians.
    Conic { c: DVec3, x: DVec3, y: DVec3 },
    /// `c + cosh t·x + sinh t·y` (`x`, `y` orthogonal, lengths the semi-axes).
    Hyperbola { c: DVec3, x: DVec3, y: DVec3 },
    /// `c + t²·x + t·y` (`x` the focal distance along the axis, `y` twice it across).
    Parabola { c: DVec3, x: DVec3, y: DVec3 },
    /// A B-spline; `closed` when it ends where it starts.
    Nurbs { c: NurbsCurve, closed: bool },
}

/// A curve as an edge or a boundary uses it: the basis, the part of it
/// that is meant (trimmed curves) and whether it runs against the basis.
#[derive(Debug, Clone)]
pub(super) struct CurveDef {
    pub curve: Curve3,
    pub range: Option<(f64, f64)>,
    pub reversed: bool,
}

impl Geo<'_> {
    /// A `CARTESIAN_POINT` (2-D points get z = 0).
    pub fn point(&self, e: Ent<'_>) -> Result<DVec3, Error> {
        if !e.has("CARTESIAN_POINT") {
            return Err(e.error("expected a CARTESIAN_POINT"));
        }
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("CARTESIAN_POINT", 1)])?;
        let c = a.reals(1)?;
        match c.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            [x, y] => Ok(DVec3::new(*x, *y, 0.0)),
            [x] => Ok(DVec3::new(*x, 0.0, 0.0)),
            _ => Err(e.error(format!("a point with {} coordinates", c.len()))),
        }
    }

    /// A `DIRECTION`, normalized.
    pub fn direction(&self, e: Ent<'_>) -> Result<DVec3, Error> {
        if !e.has("DIRECTION") {
            return Err(e.error("expected a DIRECTION"));
        }
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("DIRECTION", 1)])?;
        let c = a.reals(1)?;
        let v = match c.as_slice() {
            [x, y, z] => DVec3::new(*x, *y, *z),
            [x, y] => DVec3::new(*x, *y, 0.0),
            _ => return Err(e.error(format!("a direction with {} components", c.len()))),
        };
        let n = v.normalize_or_zero();
        if n == DVec3::ZERO || !n.is_finite() {
            return Err(e.error("zero direction"));
        }
        Ok(n)
    }

    /// A `VECTOR`: direction times magnitude.
    pub fn vector(&self, e: Ent<'_>) -> Result<DVec3, Error> {
        if e.has("DIRECTION") {
            return self.direction(e);
        }
        if !e.has("VECTOR") {
            return Err(e.error("expected a VECTOR"));
        }
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("VECTOR", 2)])?;
        let d = self.direction(a.ent(1)?)?;
        Ok(d * a.real(2)?)
    }

    /// `AXIS2_PLACEMENT_3D` or `AXIS2_PLACEMENT_2D` (or an `AXIS1_PLACEMENT`,
    /// whose reference direction is chosen).
    pub fn placement(&self, e: Ent<'_>) -> Result<Frame, Error> {
        if !(e.has("AXIS2_PLACEMENT_3D") || e.has("AXIS2_PLACEMENT_2D") || e.has("AXIS1_PLACEMENT")) {
            return Err(e.error("expected an axis placement"));
        }
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("PLACEMENT", 1)])?;
        let o = self.point(a.ent(1)?)?;
        if e.has("AXIS2_PLACEMENT_2D") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("PLACEMENT", 1), ("AXIS2_PLACEMENT_2D", 1)])?;
            let x = match a.opt_ref(2)? {
                Some(r) => self.direction(self.g.get(r, e.id())?)?,
                None => DVec3::X,
            };
            let x = DVec3::new(x.x, x.y, 0.0).normalize_or_zero();
            let x = if x == DVec3::ZERO { DVec3::X } else { x };
            return Ok(Frame { o, x, y: DVec3::Z.cross(x), z: DVec3::Z });
        }
        let (axis, refd) = if e.has("AXIS1_PLACEMENT") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("PLACEMENT", 1), ("AXIS1_PLACEMENT", 1)])?;
            (a.opt_ref(2)?, None)
        } else if e.has("AXIS2_PLACEMENT_3D") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("PLACEMENT", 1), ("AXIS2_PLACEMENT_3D", 2)])?;
            (a.opt_ref(2)?, a.opt_ref(3)?)
        } else {
            return Err(e.error("expected an axis placement"));
        };
        let z = match axis {
            Some(r) => self.direction(self.g.get(r, e.id())?)?,
            None => DVec3::Z,
        };
        let r = match refd {
            Some(r) => Some(self.direction(self.g.get(r, e.id())?)?),
            None => None,
        };
        Ok(frame(o, z, r))
    }

    /// A transformation: a placement (its frame) or a
    /// `CARTESIAN_TRANSFORMATION_OPERATOR_3D`.
    pub fn transform(&self, e: Ent<'_>) -> Result<DAffine3, Error> {
        if e.has("CARTESIAN_TRANSFORMATION_OPERATOR") {
            let a = e.chain(&[
                ("REPRESENTATION_ITEM", 1),
                ("GEOMETRIC_REPRESENTATION_ITEM", 0),
                ("FUNCTIONALLY_DEFINED_TRANSFORMATION", 2),
                ("CARTESIAN_TRANSFORMATION_OPERATOR", 4),
            ])?;
            // Simple instances: name, axis1, axis2, origin, scale, (axis3).
            let off = if e.is_complex() { 3 } else { 1 };
            let dir = |i: usize| -> Result<Option<DVec3>, Error> {
                match a.opt_ref(i)? {
                    Some(r) => Ok(Some(self.direction(self.g.get(r, e.id())?)?)),
                    None => Ok(None),
                }
            };
            let x = dir(off)?;
            let y = dir(off + 1)?;
            let o = self.point(a.ent(off + 2)?)?;
            let s = a.real_or(off + 3, 1.0)?;
            let z = if e.has("CARTESIAN_TRANSFORMATION_OPERATOR_3D") {
                let z3 = if e.is_complex() {
                    e.part("CARTESIAN_TRANSFORMATION_OPERATOR_3D").and_then(|p| p.opt_ref(0).ok().flatten())
                } else {
                    a.opt_ref(off + 4)?
                };
                match z3 {
                    Some(r) => Some(self.direction(self.g.get(r, e.id())?)?),
                    None => None,
                }
            } else {
                None
            };
            let z = z.unwrap_or_else(|| match (x, y) {
                (Some(x), Some(y)) => x.cross(y).normalize_or_zero(),
                _ => DVec3::Z,
            });
            let f = frame(o, if z == DVec3::ZERO { DVec3::Z } else { z }, x);
            let s = if s > 0.0 && s.is_finite() { s } else { 1.0 };
            return Ok(DAffine3::from_mat3_translation(DMat3::from_cols(f.x * s, f.y * s, f.z * s), o));
        }
        Ok(self.placement(e)?.matrix())
    }

    /// The curve `e` with its parameter (`depth` guards reference chains).
    pub fn curve(&self, e: Ent<'_>, depth: usize) -> Result<CurveDef, Error> {
        if depth > MAX_DEPTH {
            return Err(e.error(format!("curves nested deeper than {MAX_DEPTH} (a reference cycle?)")));
        }
        let basis = |curve: Curve3| Ok(CurveDef { curve, range: None, reversed: false });
        if e.has("LINE") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("LINE", 2)])?;
            let p = self.point(a.ent(1)?)?;
            let d = self.vector(a.ent(2)?)?;
            if d.length().is_nan() || d.length() <= 0.0 {
                return Err(e.error("line with a zero direction"));
            }
            return basis(Curve3::Line { p, d });
        }
        if e.has("CIRCLE") || e.has("ELLIPSE") {
            let circle = e.has("CIRCLE");
            let n = if circle { 1 } else { 2 };
            let a =
                e.chain(&[("REPRESENTATION_ITEM", 1), ("CONIC", 1), (if circle { "CIRCLE" } else { "ELLIPSE" }, n)])?;
            let f = self.placement(a.ent(1)?)?;
            let r1 = a.real(2)?;
            let r2 = if circle { r1 } else { a.real(3)? };
            if !(r1 > 0.0 && r2 > 0.0) {
                return Err(e.error("conic with a radius that is not positive"));
            }
            return basis(Curve3::Conic { c: f.o, x: f.x * r1, y: f.y * r2 });
        }
        if e.has("HYPERBOLA") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("CONIC", 1), ("HYPERBOLA", 2)])?;
            let f = self.placement(a.ent(1)?)?;
            let (r1, r2) = (a.real(2)?, a.real(3)?);
            if !(r1 > 0.0 && r2 > 0.0 && r1.is_finite() && r2.is_finite()) {
                return Err(e.error("hyperbola with a semi-axis that is not positive"));
            }
            return basis(Curve3::Hyperbola { c: f.o, x: f.x * r1, y: f.y * r2 });
        }
        if e.has("PARABOLA") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("CONIC", 1), ("PARABOLA", 1)])?;
            let f = self.placement(a.ent(1)?)?;
            let focal = a.real(2)?;
            if !(focal.is_finite() && focal != 0.0) {
                return Err(e.error("parabola with a zero focal distance"));
            }
            return basis(Curve3::Parabola { c: f.o, x: f.x * focal, y: f.y * (2.0 * focal) });
        }
        if is_bspline_curve(e) {
            let c = self.bspline_curve(e)?;
            let (a, b) = c.domain();
            let closed = c.point(a).distance(c.point(b)) <= 1e-9 * c.bbox().diagonal().max(TINY);
            return basis(Curve3::Nurbs { c, closed });
        }
        if e.has("POLYLINE") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("POLYLINE", 1)])?;
            let refs = a.refs(1)?;
            if refs.len() < 2 || refs.len() > MAX_CONTROL_POINTS {
                return Err(e.error("polyline with fewer than two points"));
            }
            let mut pts = Vec::with_capacity(refs.len());
            for r in refs {
                pts.push(self.point(self.g.get(r, e.id())?)?);
            }
            let n = pts.len();
            let mut knots = alloc::vec![0.0];
            knots.extend((0..n).map(|i| i as f64));
            knots.push((n - 1) as f64);
            let c = NurbsCurve::try_new(1, knots, pts, None).map_err(|x| e.error(format!("{x}")))?;
            return basis(Curve3::Nurbs { c, closed: false });
        }
        if e.has("TRIMMED_CURVE") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("TRIMMED_CURVE", 5)])?;
            let inner = self.curve(a.ent(1)?, depth + 1)?;
            let sense = a.boolean(4, true)?;
            let prefer_param = a.enumeration(5).map(|m| m == "PARAMETER").unwrap_or(false);
            let t1 = self.trim_value(e, &inner.curve, &a, 2, prefer_param)?;
            let t2 = self.trim_value(e, &inner.curve, &a, 3, prefer_param)?;
            // The trimmed curve runs from trim_1 to trim_2, along its basis
            // when `sense` and against it otherwise (ISO 10303-42).
            let range = match (t1, t2) {
                (Some(t1), Some(t2)) => Some((t1, t2)),
                _ => None,
            };
            return Ok(CurveDef { curve: inner.curve, range, reversed: !sense ^ inner.reversed });
        }
        if e.has("SURFACE_CURVE") || e.has("SEAM_CURVE") || e.has("INTERSECTION_CURVE") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("SURFACE_CURVE", 1)])?;
            return self.curve(a.ent(1)?, depth + 1);
        }
        if e.has("COMPOSITE_CURVE") {
            let c = self.composite(e, depth)?;
            let (a, b) = c.domain();
            let closed = c.point(a).distance(c.point(b)) <= 1e-9 * c.bbox().diagonal().max(TINY);
            return basis(Curve3::Nurbs { c, closed });
        }
        Err(e.error("is not a supported curve"))
    }

    /// A trim value of a `TRIMMED_CURVE` (parameter `i`): a parameter value
    /// (angles in the context's unit) or a point projected onto the curve.
    fn trim_value(
        &self,
        e: Ent<'_>,
        curve: &Curve3,
        a: &super::graph::Attrs<'_>,
        i: usize,
        prefer_param: bool,
    ) -> Result<Option<f64>, Error> {
        let items = a.list(i)?;
        let mut param = None;
        let mut point = None;
        for v in items {
            if let Some((name, inner)) = self.g.typed(*v) {
                if name == "PARAMETER_VALUE" {
                    if let Some(x) = self.g.number(inner) {
                        param = Some(if matches!(curve, Curve3::Conic { .. }) { x * self.angle } else { x });
                    }
                }
            } else if let super::graph::Value::Ref(r) = v {
                point = Some(self.point(self.g.get(*r, e.id())?)?);
            } else if let Some(x) = self.g.number(*v) {
                param = Some(if matches!(curve, Curve3::Conic { .. }) { x * self.angle } else { x });
            }
        }
        Ok(match (param, point) {
            (Some(t), _) if prefer_param || point.is_none() => Some(t),
            (_, Some(p)) => Some(param_of(curve, p)),
            (Some(t), None) => Some(t),
            (None, None) => None,
        })
    }

    /// A B-spline curve of any form (with knots, uniform, quasi-uniform,
    /// Bézier, piecewise Bézier), rational or not.
    pub fn bspline_curve(&self, e: Ent<'_>) -> Result<NurbsCurve, Error> {
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("B_SPLINE_CURVE", 5)])?;
        let degree = a.int(1)?;
        let refs = a.refs(2)?;
        if !(1..=MAX_DEGREE as i64).contains(&degree) {
            return Err(e.error(format!("degree {degree} is not supported (1 to {MAX_DEGREE})")));
        }
        let p = degree as usize;
        if refs.len() <= p || refs.len() > MAX_CONTROL_POINTS {
            return Err(e.error(format!("{} control points for degree {p}", refs.len())));
        }
        let mut pts = Vec::with_capacity(refs.len());
        for r in &refs {
            pts.push(self.point(self.g.get(*r, e.id())?)?);
        }
        let kinds = ["B_SPLINE_CURVE_WITH_KNOTS", "UNIFORM_CURVE", "QUASI_UNIFORM_CURVE"];
        let knots = self.knots(e, p, pts.len(), kinds, (6, 0, 1))?;
        let weights = match e.part("RATIONAL_B_SPLINE_CURVE") {
            Some(r) => Some(r.reals(0)?),
            None => None,
        };
        let weights = weights.filter(|w| {
            let w0 = w.first().copied().unwrap_or(1.0);
            !w.iter().all(|&x| (x - w0).abs() <= 1e-14 * w0.abs())
        });
        let c = NurbsCurve::try_new(p, knots, pts, weights).map_err(|x| e.error(format!("{x}")))?;
        clamped(c).map_err(|m| e.error(m))
    }

    /// The knot vector of a B-spline curve or surface in one direction, for
    /// degree `p` and `n` control points. `kinds`: the entities with knots,
    /// uniform and quasi-uniform; `at`: where the with-knots attributes start
    /// in a simple instance, and the multiplicities' and knots' places among them.
    pub fn knots(
        &self,
        e: Ent<'_>,
        p: usize,
        n: usize,
        kinds: [&str; 3],
        at: (usize, usize, usize),
    ) -> Result<Vec<f64>, Error> {
        let [with_knots, uniform, quasi] = kinds;
        if e.has(with_knots) {
            let a = if e.is_complex() {
                e.part(with_knots).ok_or_else(|| e.error(format!("without {with_knots}")))?
            } else {
                let mut a = e.attrs();
                a.vals.drain(..at.0.min(a.vals.len()));
                a
            };
            let mults = a.ints(at.1)?;
            let vals = a.reals(at.2)?;
            if mults.len() != vals.len() {
                return Err(e.error(format!("{} knot multiplicities for {} knots", mults.len(), vals.len())));
            }
            let total = mults.iter().fold(0i64, |acc, &m| acc.saturating_add(m.max(0)));
            if mults.iter().any(|&m| m < 1) || total != (n + p + 1) as i64 {
                return Err(e.error(format!("knot multiplicities sum to {total}, {} expected", n + p + 1)));
            }
            let mut k = Vec::with_capacity(n + p + 1);
            for (m, v) in mults.iter().zip(&vals) {
                k.extend(core::iter::repeat_n(*v, *m as usize));
            }
            return Ok(k);
        }
        if e.has(uniform) {
            return Ok((0..n + p + 1).map(|i| i as f64 - p as f64).collect());
        }
        if e.has(quasi) {
            let mut k = alloc::vec![0.0; p + 1];
            for i in 1..n - p {
                k.push(i as f64);
            }
            k.extend(core::iter::repeat_n((n - p) as f64, p + 1));
            return Ok(k);
        }
        // Bézier (one piece) and anything else with exactly p + 1 points.
        if n == p + 1 || e.has("BEZIER_CURVE") || e.has("BEZIER_SURFACE") {
            if (n - 1) % p != 0 {
                return Err(e.error("piecewise Bézier with a control point count that does not fit the degree"));
            }
            let pieces = (n - 1) / p;
            let mut k = alloc::vec![0.0; p + 1];
            for i in 1..pieces {
                k.extend(core::iter::repeat_n(i as f64, p));
            }
            k.extend(core::iter::repeat_n(pieces as f64, p + 1));
            return Ok(k);
        }
        Err(e.error("B-spline without knots (no WITH_KNOTS, UNIFORM, QUASI_UNIFORM or BEZIER form)"))
    }

    /// A `COMPOSITE_CURVE`: its segments' bounded curves joined into one.
    fn composite(&self, e: Ent<'_>, depth: usize) -> Result<NurbsCurve, Error> {
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("COMPOSITE_CURVE", 2)])?;
        let mut pieces = Vec::new();
        for r in a.refs(1)? {
            let seg = self.g.get(r, e.id())?;
            let s = seg.attrs();
            if !seg.has("COMPOSITE_CURVE_SEGMENT") {
                return Err(seg.error("expected a COMPOSITE_CURVE_SEGMENT"));
            }
            let same = s.boolean(1, true)?;
            let def = self.curve(s.ent(2)?, depth + 1)?;
            let mut part = bounded_pieces(&def).map_err(|m| seg.error(m))?;
            if !same {
                rev_all(&mut part).map_err(|m| seg.error(m))?;
            }
            pieces.extend(part);
        }
        join(&pieces).map_err(|x| e.error(format!("{x}")))
    }
}

/// `c` restricted to `[t0, t1]` (clamped to its domain).
pub(super) fn seg(c: &NurbsCurve, t0: f64, t1: f64) -> Result<NurbsCurve, CurveError> {
    let (a, b) = c.domain();
    let (t0, t1) = (t0.max(a), t1.min(b));
    if t1.is_nan() || t0.is_nan() || t1 <= t0 {
        return Err(CurveError::EmptyRange(t0, t1));
    }
    Ok(segment(c, t0, t1)?)
}

/// Every curve of `v` run backwards, in reverse order.
pub(super) fn rev_all(v: &mut [NurbsCurve]) -> Result<(), NurbsError> {
    v.reverse();
    for c in v.iter_mut() {
        *c = reversed(c)?;
    }
    Ok(())
}

/// A clamped copy of `c` (its ends are control points).
fn clamped(c: NurbsCurve) -> Result<NurbsCurve, NurbsError> {
    let mut r = RawCurve::of(&c);
    r.clamp();
    r.build()
}

/// `c` with its ends moved to `s` and `e`.
pub(super) fn move_ends(c: &NurbsCurve, s: DVec3, e: DVec3) -> Result<NurbsCurve, NurbsError> {
    with_end_points(c, s, e)
}

/// Whether `e` is a B-spline curve of any form.
pub(super) fn is_bspline_curve(e: Ent<'_>) -> bool {
    ["B_SPLINE_CURVE", "B_SPLINE_CURVE_WITH_KNOTS", "BEZIER_CURVE", "UNIFORM_CURVE", "QUASI_UNIFORM_CURVE"]
        .iter()
        .any(|n| e.has(n))
}

/// A frame from an origin, an axis and an optional reference direction
/// (made orthogonal to the axis; any perpendicular when missing or parallel).
pub(super) fn frame(o: DVec3, z: DVec3, r: Option<DVec3>) -> Frame {
    let z = z.normalize_or_zero();
    let z = if z == DVec3::ZERO { DVec3::Z } else { z };
    let pick = |r: DVec3| {
        let x = r - z * r.dot(z);
        let len = x.length();
        (len > 1e-10 * r.length().max(TINY)).then(|| x / len)
    };
    let x = r
        .and_then(pick)
        .or_else(|| pick(DVec3::X))
        .or_else(|| pick(DVec3::Y))
        .unwrap_or_else(|| z.any_orthonormal_vector());
    Frame { o, x, y: z.cross(x), z }
}

/// The parameter of the point of `c` nearest to `p`.
pub(super) fn param_of(c: &Curve3, p: DVec3) -> f64 {
    match c {
        Curve3::Line { p: o, d } => guarded_div((p - *o).dot(*d), d.length_squared()),
        Curve3::Conic { c, x, y } => {
            let w = p - *c;
            libm::atan2(guarded_div(w.dot(*y), y.length_squared()), guarded_div(w.dot(*x), x.length_squared()))
        }
        Curve3::Hyperbola { c, y, .. } => libm::asinh(guarded_div((p - *c).dot(*y), y.length_squared())),
        Curve3::Parabola { c, y, .. } => guarded_div((p - *c).dot(*y), y.length_squared()),
        Curve3::Nurbs { c, .. } => c.project(p).t,
    }
}

/// Period of the curve's parameter, if it closes.
pub(super) fn period(c: &Curve3) -> Option<f64> {
    match c {
        Curve3::Line { .. } | Curve3::Hyperbola { .. } | Curve3::Parabola { .. } => None,
        Curve3::Conic { .. } => Some(TAU),
        Curve3::Nurbs { c, closed } => closed.then(|| {
            let (a, b) = c.domain();
            b - a
        }),
    }
}

/// Why a piece of a STEP curve could not be cut out of it.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum CurveError {
    /// The NURBS operation failed.
    Nurbs(NurbsError),
    /// A parameter range from the first to the second that holds nothing.
    EmptyRange(f64, f64),
    /// A range outside the curve's domain.
    OutsideRange {
        /// The range asked for.
        range: (f64, f64),
        /// The curve's domain.
        domain: (f64, f64),
    },
    /// A range on a closed curve that holds nothing.
    EmptyClosedRange,
    /// A line with no range (in a composite curve).
    UnboundedLine,
    /// A hyperbola or parabola with no range (in a composite curve).
    UnboundedConic,
}

impl core::fmt::Display for CurveError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Nurbs(e) => write!(f, "{e}"),
            Self::EmptyRange(t0, t1) => write!(f, "empty parameter range {t0} to {t1}"),
            Self::OutsideRange { range: (t0, t1), domain: (a, b) } => {
                write!(f, "parameter range {t0} to {t1} outside the curve's {a} to {b}")
            }
            Self::EmptyClosedRange => write!(f, "empty closed-curve range"),
            Self::UnboundedLine => write!(f, "an unbounded line in a composite curve"),
            Self::UnboundedConic => write!(f, "an unbounded hyperbola or parabola in a composite curve"),
        }
    }
}

impl From<NurbsError> for CurveError {
    fn from(e: NurbsError) -> Self {
        Self::Nurbs(e)
    }
}

/// NURBS pieces of the curve from parameter `t0` to `t1 > t0` along its
/// parameter (a closed B-spline is gone round from its end to its start).
pub(super) fn pieces_between(c: &Curve3, t0: f64, t1: f64) -> Result<Vec<NurbsCurve>, CurveError> {
    let err = CurveError::Nurbs;
    if t1.is_nan() || t0.is_nan() || t1 <= t0 {
        return Err(CurveError::EmptyRange(t0, t1));
    }
    match c {
        Curve3::Line { p, d } => Ok(alloc::vec![line(*p + *d * t0, *p + *d * t1, 0.0, 1.0).map_err(err)?]),
        Curve3::Conic { c, x, y } => Ok(alloc::vec![ellipse_arc(*c, *x, *y, t0, t1).map_err(err)?]),
        Curve3::Hyperbola { c, x, y } => Ok(alloc::vec![hyperbola_arc(*c, *x, *y, t0, t1).map_err(err)?]),
        Curve3::Parabola { c, x, y } => Ok(alloc::vec![parabola_arc(*c, *x, *y, t0, t1).map_err(err)?]),
        Curve3::Nurbs { c, closed } => {
            let (a, b) = c.domain();
            let per = b - a;
            let tiny = 1e-9 * per;
            if !*closed || (t0 >= a - tiny && t1 <= b + tiny) {
                let (s0, s1) = (t0.max(a), t1.min(b));
                if s1.is_nan() || s0.is_nan() || s1 <= s0 {
                    return Err(CurveError::OutsideRange { range: (t0, t1), domain: (a, b) });
                }
                return Ok(alloc::vec![seg(c, s0, s1)?]);
            }
            // Wraps past the end: the start brought into the domain (a start
            // at the domain's end is its beginning), then one piece or two.
            let mut s0 = a + (t0 - a) - per * crate::math::floor((t0 - a) / per);
            if b - s0 <= tiny {
                s0 = a;
            }
            let s1 = s0 + (t1 - t0).min(per);
            let mut out = Vec::new();
            if s1 <= b + tiny {
                out.push(seg(c, s0, s1.min(b))?);
            } else {
                out.push(seg(c, s0, b)?);
                if s1 - per - a > tiny {
                    out.push(seg(c, a, s1 - per)?);
                }
            }
            if out.is_empty() {
                return Err(CurveError::EmptyClosedRange);
            }
            Ok(out)
        }
    }
}

/// The bounded part of a curve as NURBS pieces in its own direction
/// (trimmed range, reversed when the trimmed curve runs against its basis).
pub(super) fn bounded_pieces(def: &CurveDef) -> Result<Vec<NurbsCurve>, CurveError> {
    let (t0, t1) = match (def.range, &def.curve) {
        (Some(r), _) => r,
        (None, Curve3::Nurbs { c, .. }) => c.domain(),
        (None, Curve3::Conic { .. }) => (0.0, TAU),
        (None, Curve3::Line { .. }) => return Err(CurveError::UnboundedLine),
        (None, Curve3::Hyperbola { .. } | Curve3::Parabola { .. }) => return Err(CurveError::UnboundedConic),
    };
    // The range runs from the start to the end of the trimmed curve; along
    // the basis parameter that is increasing unless `reversed`.
    let (lo, hi) = if def.reversed { (t1, t0) } else { (t0, t1) };
    let hi = match period(&def.curve) {
        Some(p) if hi <= lo => hi + p * crate::math::ceil((lo - hi) / p + 1e-12).max(1.0),
        _ => hi,
    };
    let mut out = pieces_between(&def.curve, lo, hi)?;
    if def.reversed {
        rev_all(&mut out)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A full circle as one B-spline over [0, 2] that starts and ends at (5, 0, 0).
    fn closed_circle() -> Curve3 {
        let x = DVec3::X * 5.0;
        let y = DVec3::Y * 5.0;
        let c = ellipse_arc(DVec3::ZERO, x, y, 0.0, core::f64::consts::TAU).unwrap();
        Curve3::Nurbs { c: crate::nurbs::reparam::reparametrized(&c, 0.0, 2.0).unwrap(), closed: true }
    }

    fn span_of(pieces: &[NurbsCurve]) -> f64 {
        pieces
            .iter()
            .map(|c| {
                let (a, b) = c.domain();
                (0..64)
                    .map(|k| {
                        c.point(a + (b - a) * k as f64 / 64.0).distance(c.point(a + (b - a) * (k + 1) as f64 / 64.0))
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    /// An edge from the curve's closing point to its middle: where the start
    /// is found at the end of the domain, the range wraps to the half after
    /// it, not the whole turn and that half again.
    #[test]
    fn a_range_starting_at_the_domain_end_wraps_to_its_beginning() {
        let c = closed_circle();
        let half = core::f64::consts::PI * 5.0;
        for (t0, t1) in [(2.0, 3.0), (0.0, 1.0), (1.5, 2.5), (2.0 - 1e-12, 3.0)] {
            let pieces = pieces_between(&c, t0, t1).unwrap();
            let len = span_of(&pieces);
            assert!((len - half).abs() < 1e-3 * half, "{t0}..{t1}: length {len}, expected {half}");
        }
        let Curve3::Nurbs { c: n, .. } = &c else { unreachable!() };
        let first = pieces_between(&c, 2.0, 3.0).unwrap();
        let (a, b) = first[0].domain();
        assert!(first[0].point(a).distance(n.point(0.0)) < 1e-9, "starts at the closing point");
        assert!(first.last().unwrap().point(b.max(a)).distance(DVec3::new(-5.0, 0.0, 0.0)) < 1e-9);
    }
}
