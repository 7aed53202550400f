//! Surfaces of ISO 10303-42 as the shared surface definitions the IGES
//! reader also builds faces from ([`SurfDef`]): planes, surfaces of
//! revolution (cylinder, cone, sphere, torus, swept curve) whose NURBS is
//! made once the face's loops are known, B-spline surfaces as they are.
//!
//! A definition's NURBS parameters need not run the STEP way: revolutions
//! are built as (profile, angle) where STEP has (angle, profile), which
//! turns their normal over. [`StepSurface::flipped`] says so, so the face
//! can be turned to the side its `same_sense` asks for.

use alloc::boxed::Box;
use alloc::format;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::curves::{bounded_pieces, Curve3, Frame, Geo};
use super::graph::{Ent, Value};
use super::{MAX_CONTROL_POINTS, MAX_DEPTH};
use crate::io::iges::surfaces::{nurbs_def, Profile, Revolution, SurfDef};
use crate::numeric::TINY;
use crate::nurbs::analytic::{extrude, line, revolve};
use crate::nurbs::join::join;
use crate::nurbs::reparam::map_points;
use crate::nurbs::{NurbsCurve, NurbsSurface, MAX_DEGREE};
use crate::Error;

const TAU: f64 = core::f64::consts::TAU;
const HALF_PI: f64 = core::f64::consts::FRAC_PI_2;

/// A STEP surface as a shared definition.
#[derive(Debug, Clone)]
pub(super) struct StepSurface {
    pub def: SurfDef,
    /// Whether the NURBS normal `Su × Sv` of the definition is opposite to the STEP surface normal.
    pub flipped: bool,
    /// Whether the definition's own coordinates are the STEP parameters (B-spline surfaces).
    pub native: bool,
}

impl Geo<'_> {
    /// The surface `e` as a definition; `points` are model-space points of
    /// the face on it (they bound the extent of extrusions, which STEP leaves
    /// unbounded); `depth` guards reference chains.
    ///
    /// # Errors
    /// Unsupported or invalid surfaces, bad references.
    pub fn surface(&self, e: Ent<'_>, points: &[DVec3], depth: usize) -> Result<StepSurface, Error> {
        if depth > MAX_DEPTH {
            return Err(e.error(format!("surfaces nested deeper than {MAX_DEPTH} (a reference cycle?)")));
        }
        let placed = |n: usize, kind: &str| -> Result<(Frame, super::graph::Attrs<'_>), Error> {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("ELEMENTARY_SURFACE", 1), (kind, n)])?;
            let f = self.placement(a.ent(1)?)?;
            Ok((f, a))
        };
        let positive = |x: f64, what: &str| {
            if x > 0.0 && x.is_finite() {
                Ok(x)
            } else {
                Err(e.error(format!("{what} must be positive, is {x}")))
            }
        };
        let rev = |f: Frame, profile: Profile| StepSurface {
            def: SurfDef::Revolution(Box::new(Revolution { origin: f.o, axis: f.z, xref: f.x, profile, angles: None })),
            flipped: true,
            native: false,
        };
        if e.has("PLANE") {
            let (f, _) = placed(0, "PLANE")?;
            let def = SurfDef::Plane { origin: f.o, x: f.x, y: f.y };
            return Ok(StepSurface { def, flipped: false, native: false });
        }
        if e.has("CYLINDRICAL_SURFACE") {
            let (f, a) = placed(1, "CYLINDRICAL_SURFACE")?;
            let r = positive(a.real(2)?, "cylinder radius")?;
            return Ok(rev(f, Profile::Line { p0: DVec2::new(r, 0.0), d: DVec2::new(0.0, 1.0) }));
        }
        if e.has("CONICAL_SURFACE") {
            let (f, a) = placed(2, "CONICAL_SURFACE")?;
            let r = a.real(2)?;
            let given = a.real(3)?;
            let mut alpha = given * self.angle;
            if alpha >= HALF_PI && self.angle == 1.0 && given < 90.0 {
                alpha = given.to_radians(); // degrees written where radians are declared
            }
            if !(r >= 0.0 && alpha > 0.0 && alpha < HALF_PI) {
                return Err(e.error(format!("cone with radius {r} and semi-angle {alpha} rad")));
            }
            return Ok(rev(f, Profile::Line { p0: DVec2::new(r, 0.0), d: DVec2::new(libm::tan(alpha), 1.0) }));
        }
        if e.has("SPHERICAL_SURFACE") {
            let (f, a) = placed(1, "SPHERICAL_SURFACE")?;
            let r = positive(a.real(2)?, "sphere radius")?;
            return Ok(rev(f, Profile::Circle { c: DVec2::ZERO, rho: r, range: Some((-HALF_PI, HALF_PI)) }));
        }
        if e.has("TOROIDAL_SURFACE") || e.has("DEGENERATE_TOROIDAL_SURFACE") {
            let (f, a) = placed(2, "TOROIDAL_SURFACE")?;
            let big = a.real(2)?;
            let small = positive(a.real(3)?, "torus minor radius")?;
            if !(big >= 0.0 && big.is_finite()) {
                return Err(e.error(format!("torus major radius {big}")));
            }
            // A torus whose tube reaches the axis turns about it only on the
            // outer arc of its tube (the lemon or apple shape).
            let range = if big < small {
                let half = libm::acos(-big / small);
                Some((-half, half))
            } else {
                None
            };
            return Ok(rev(f, Profile::Circle { c: DVec2::new(big, 0.0), rho: small, range }));
        }
        if e.has("SURFACE_OF_REVOLUTION") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("SWEPT_SURFACE", 1), ("SURFACE_OF_REVOLUTION", 1)])?;
            let curve = self.swept_curve(e, a.ent(1)?, points, None, depth)?;
            let axis = self.placement(a.ent(2)?)?;
            return revolution_of(e, curve, axis.o, axis.z);
        }
        if e.has("SURFACE_OF_LINEAR_EXTRUSION") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("SWEPT_SURFACE", 1), ("SURFACE_OF_LINEAR_EXTRUSION", 1)])?;
            let dir = self.vector(a.ent(2)?)?;
            if dir.length().is_nan() || dir.length() <= 0.0 {
                return Err(e.error("extrusion along a zero vector"));
            }
            let curve = self.swept_curve(e, a.ent(1)?, points, Some(dir), depth)?;
            return extrusion_of(e, curve, dir, points);
        }
        if is_bspline_surface(e) {
            let s = self.bspline_surface(e)?;
            return Ok(StepSurface { def: nurbs_def(s), flipped: false, native: true });
        }
        if e.has("OFFSET_SURFACE") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("OFFSET_SURFACE", 3)])?;
            let d = a.real(2)?;
            let base_points = points; // the offset face's points are within |d| of the base's
            let base = self.surface(a.ent(1)?, base_points, depth + 1)?;
            if !d.is_finite() {
                return Err(e.error("offset distance is not finite"));
            }
            // Along the STEP normal: the NURBS one where the base is not flipped.
            let distance = if base.flipped { -d } else { d };
            let def = SurfDef::Offset { base: Box::new(base.def), distance };
            return Ok(StepSurface { def, flipped: base.flipped, native: base.native });
        }
        if e.has("RECTANGULAR_TRIMMED_SURFACE") || e.has("CURVE_BOUNDED_SURFACE") {
            let name =
                if e.has("CURVE_BOUNDED_SURFACE") { "CURVE_BOUNDED_SURFACE" } else { "RECTANGULAR_TRIMMED_SURFACE" };
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), (name, 2)])?;
            return self.surface(a.ent(1)?, points, depth + 1);
        }
        Err(e.error("is not a supported surface"))
    }

    /// The swept curve of a swept surface as one NURBS. An unbounded line
    /// is cut to the face's points (projected along `dir` for extrusions).
    fn swept_curve(
        &self,
        owner: Ent<'_>,
        c: Ent<'_>,
        points: &[DVec3],
        dir: Option<DVec3>,
        depth: usize,
    ) -> Result<NurbsCurve, Error> {
        let def = self.curve(c, depth + 1)?;
        if let (Curve3::Line { p, d }, None) = (&def.curve, def.range) {
            let d2 = d.length_squared().max(TINY);
            let along = |q: DVec3| {
                let q = match dir {
                    // The point's foot on the line, moving along the extrusion.
                    Some(v) => {
                        let n = d.cross(v);
                        let w = q - *p;
                        let m = n.cross(*d);
                        let den = v.dot(m);
                        if den.abs() > TINY {
                            q - v * (w.dot(m) / den)
                        } else {
                            q
                        }
                    }
                    None => q,
                };
                (q - *p).dot(*d) / d2
            };
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for &q in points {
                let t = along(q);
                lo = lo.min(t);
                hi = hi.max(t);
            }
            if !(hi > lo && lo.is_finite() && hi.is_finite()) {
                return Err(owner.error("an unbounded line swept, and no face points to bound it"));
            }
            let m = 0.01 * (hi - lo);
            let (lo, hi) = (lo - m, hi + m);
            return line(*p + *d * lo, *p + *d * hi, lo, hi).map_err(|x| owner.error(format!("{x}")));
        }
        let pieces = bounded_pieces(&def).map_err(|m| owner.error(m))?;
        join(&pieces).map_err(|x| owner.error(format!("{x}")))
    }

    /// A B-spline surface of any form, rational or not.
    pub fn bspline_surface(&self, e: Ent<'_>) -> Result<NurbsSurface, Error> {
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("B_SPLINE_SURFACE", 7)])?;
        let (du, dv) = (a.int(1)?, a.int(2)?);
        let ok = |d: i64| (1..=MAX_DEGREE as i64).contains(&d);
        if !(ok(du) && ok(dv)) {
            return Err(e.error(format!("degrees {du}x{dv} are not supported (1 to {MAX_DEGREE})")));
        }
        let (pu, pv) = (du as usize, dv as usize);
        let rows = a.list(3)?;
        let nu = rows.len();
        let mut pts = Vec::with_capacity(nu.min(MAX_CONTROL_POINTS));
        let mut nv = 0;
        for (i, row) in rows.iter().enumerate() {
            let Some(items) = self.g.list(*row) else {
                return Err(a.error(3, format!("row {i} of the control points is not a list")));
            };
            if i == 0 {
                nv = items.len();
            }
            if items.len() != nv || nu.saturating_mul(nv) > MAX_CONTROL_POINTS {
                return Err(a.error(3, "control point rows of different lengths (or too many points)"));
            }
            let mut r = Vec::with_capacity(nv);
            for it in items {
                let Value::Ref(id) = it else {
                    return Err(a.error(3, "a control point that is not a reference"));
                };
                r.push(self.point(self.g.get(*id, e.id())?)?);
            }
            pts.push(r);
        }
        if nu <= pu || nv <= pv {
            return Err(e.error(format!("{nu}x{nv} control points for degrees {pu}x{pv}")));
        }
        let kinds = ["B_SPLINE_SURFACE_WITH_KNOTS", "UNIFORM_SURFACE", "QUASI_UNIFORM_SURFACE"];
        let ku = self.knots(e, pu, nu, kinds, (8, 0, 2))?;
        let kv = self.knots(e, pv, nv, kinds, (8, 1, 3))?;
        let weights = match e.part("RATIONAL_B_SPLINE_SURFACE") {
            Some(r) => {
                let wl = r.list(0)?;
                let mut w = Vec::with_capacity(nu);
                for row in wl {
                    let vals: Option<Vec<f64>> =
                        self.g.list(*row).map(|l| l.iter().filter_map(|v| self.g.number(*v)).collect());
                    match vals {
                        Some(v) if v.len() == nv => w.push(v),
                        _ => return Err(e.error("weights do not match the control points")),
                    }
                }
                if w.len() != nu {
                    return Err(e.error("weights do not match the control points"));
                }
                let w0 = w.first().and_then(|r| r.first()).copied().unwrap_or(1.0);
                (!w.iter().flatten().all(|&x| (x - w0).abs() <= 1e-14 * w0.abs())).then_some(w)
            }
            None => None,
        };
        NurbsSurface::try_new([pu, pv], ku, kv, &pts, weights.as_deref()).map_err(|x| e.error(format!("{x}")))
    }
}

/// Whether `e` is a B-spline surface of any form.
pub(super) fn is_bspline_surface(e: Ent<'_>) -> bool {
    ["B_SPLINE_SURFACE", "B_SPLINE_SURFACE_WITH_KNOTS", "BEZIER_SURFACE", "UNIFORM_SURFACE", "QUASI_UNIFORM_SURFACE"]
        .iter()
        .any(|n| e.has(n))
}

/// A surface of revolution of `curve` about the axis through `o` along `z`:
/// exact (profile parameter, angle) coordinates when the curve lies in one
/// half-plane bounded by the axis, otherwise the whole turn as a B-spline.
/// Either way the NURBS runs (profile, angle), the reverse of STEP's.
fn revolution_of(e: Ent<'_>, curve: NurbsCurve, o: DVec3, z: DVec3) -> Result<StepSurface, Error> {
    let radial = |p: DVec3| {
        let w = p - o;
        w - z * w.dot(z)
    };
    let far = curve.control_points().map(radial).max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
    let size = curve.bbox().diagonal().max(TINY);
    let x = far.map(|r| r.normalize_or_zero()).unwrap_or(DVec3::ZERO);
    let planar = x != DVec3::ZERO
        && curve
            .control_points()
            .map(radial)
            .all(|r| r.dot(z.cross(x)).abs() <= 1e-9 * size && r.dot(x) >= -1e-9 * size);
    if planar {
        let rev = Revolution { origin: o, axis: z, xref: x, profile: Profile::Curve(curve), angles: None };
        return Ok(StepSurface { def: SurfDef::Revolution(Box::new(rev)), flipped: true, native: false });
    }
    let s = revolve(&curve, o, z, 0.0, TAU).map_err(|x| e.error(format!("{x}")))?;
    Ok(StepSurface { def: nurbs_def(s), flipped: true, native: false })
}

/// The extrusion `curve(u) + v·dir` over the range of `v` the face's points need (plus a margin).
fn extrusion_of(e: Ent<'_>, curve: NurbsCurve, dir: DVec3, points: &[DVec3]) -> Result<StepSurface, Error> {
    let d2 = dir.length_squared();
    // v of a point: its offset along dir from the curve point it lies
    // across from, found on the curve flattened along dir.
    let flat = |p: DVec3| p - dir * (p.dot(dir) / d2);
    let flat_curve = map_points(&curve, flat).map_err(|x| e.error(format!("{x}")))?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &q in points {
        let t = flat_curve.project(flat(q)).t;
        let v = (q - curve.point(t)).dot(dir) / d2;
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !(hi > lo && lo.is_finite() && hi.is_finite()) {
        return Err(e.error("an extrusion whose face has no extent along its direction"));
    }
    let m = 0.01 * (hi - lo);
    let s = extrude(&curve, dir, lo - m, hi + m).map_err(|x| e.error(format!("{x}")))?;
    Ok(StepSurface { def: nurbs_def(s), flipped: false, native: false })
}
