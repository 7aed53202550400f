//! Surface entities as definitions that know their own coordinates.
//!
//! Each surface keeps "native" coordinates (the IGES parameters where the
//! standard defines them: B-spline parameters for 128, (generatrix
//! parameter, angle) for 120, and so on), can invert a model-space point
//! into them, and builds its exact NURBS over whatever range the face's trim
//! loops need: planes, cylinders and cones are unbounded and surfaces of
//! revolution may be cut anywhere around their axis, so their NURBS is made
//! only once the loops are known. [`AxisMap`] then carries native
//! coordinates to the NURBS parameters (the angle of a rational arc is not
//! its parameter).

use alloc::boxed::Box;
use alloc::vec::Vec;
use glam::{DAffine3, DVec2, DVec3};

use super::curves::model_curve;
use super::directory::Entity;
use super::wrap::TrimError;
use super::xform::{own_transform, similarity_scale};
use super::{Ctx, MAX_CONTROL_POINTS, MAX_DEPTH};
use crate::model::FaceSurface;
use crate::numeric::{guarded_div, TINY};
use crate::nurbs::analytic::{bilinear, circle_arc, extrude, revolve, ruled, ArcParam};
use crate::nurbs::join::join;
use crate::nurbs::reparam::{reparametrized, segment};
use crate::nurbs::seam::{rotate_seam, unroll};
use crate::nurbs::{project_with, NurbsCurve, NurbsSurface, ProjectionOptions, Surface, SurfaceFacts, MAX_DEGREE};
use crate::Error;

const TAU: f64 = core::f64::consts::TAU;

/// A surface as read, before its NURBS is fixed.
#[derive(Debug, Clone)]
pub(in crate::io) enum SurfDef {
    /// A B-spline surface whose parameters are its native coordinates.
    Nurbs {
        surface: NurbsSurface,
        /// Periods along u and v when the surface closes on itself.
        periods: [Option<f64>; 2],
        /// The parameter rectangle the entity asks for, when smaller than the knots' domain.
        natural: Option<[DVec2; 2]>,
        /// What projections onto `surface` learnt about it (its loops' samples
        /// are projected one by one); boxed, as it holds their last derivatives.
        facts: Box<SurfaceFacts>,
    },
    /// `origin + a·x + b·y`, native coordinates `(a, b)`.
    Plane { origin: DVec3, x: DVec3, y: DVec3 },
    /// A profile turned about an axis, native coordinates `(profile parameter, angle)`.
    Revolution(Box<Revolution>),
    /// The base surface moved along its normal.
    Offset { base: Box<SurfDef>, distance: f64 },
}

/// A surface of revolution: `profile` lies in the half-plane spanned by
/// `axis` and `xref` (angle 0); angles turn right-handed about `axis`.
#[derive(Debug, Clone)]
pub(in crate::io) struct Revolution {
    pub origin: DVec3,
    pub axis: DVec3,
    pub xref: DVec3,
    pub profile: Profile,
    /// Angle range of the entity (`None`: whole turns allowed).
    pub angles: Option<(f64, f64)>,
}

/// The meridian curve of a [`Revolution`], in half-plane coordinates
/// `(r, h)` = (distance from the axis, height along it).
#[derive(Debug, Clone)]
pub(in crate::io) enum Profile {
    /// `p0 + t·d`, `t` unbounded (cylinder, cone).
    Line { p0: DVec2, d: DVec2 },
    /// `c + ρ·(cos φ, sin φ)`; `range` bounds φ (`None`: whole turns).
    Circle { c: DVec2, rho: f64, range: Option<(f64, f64)> },
    /// A model-space curve lying in the half-plane at angle 0.
    Curve(NurbsCurve),
}

/// How a native coordinate becomes the NURBS parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::io) enum AxisMap {
    Identity,
    Arc(ArcParam),
}

impl AxisMap {
    pub fn apply(&self, x: f64) -> f64 {
        match self {
            Self::Identity => x,
            Self::Arc(a) => a.param_of_angle(x),
        }
    }
}

/// A point's native coordinates, and which of them are arbitrary there
/// (the angle on the axis, the parameter along a collapsed edge).
#[derive(Debug, Clone, Copy)]
pub(in crate::io) struct Native {
    pub q: DVec2,
    pub free: [bool; 2],
}

impl SurfDef {
    /// Periods of the native coordinates.
    pub fn periods(&self) -> [Option<f64>; 2] {
        match self {
            Self::Nurbs { periods, .. } => *periods,
            Self::Plane { .. } => [None, None],
            Self::Revolution(r) => {
                let pu = match &r.profile {
                    Profile::Circle { range: None, .. } => Some(TAU),
                    _ => None,
                };
                let pv = match r.angles {
                    None => Some(TAU),
                    Some((a, b)) if b - a >= TAU - 1e-9 => Some(TAU),
                    _ => None,
                };
                [pu, pv]
            }
            Self::Offset { base, .. } => base.periods(),
        }
    }

    /// The range each native coordinate is confined to (`None`: free).
    pub fn natural(&self) -> [Option<(f64, f64)>; 2] {
        match self {
            Self::Nurbs { surface, natural, .. } => {
                let [lo, hi] = natural.unwrap_or_else(|| surface.domain());
                [Some((lo.x, hi.x)), Some((lo.y, hi.y))]
            }
            Self::Plane { .. } => [None, None],
            Self::Revolution(r) => {
                let u = match &r.profile {
                    Profile::Line { .. } => None,
                    Profile::Circle { range, .. } => Some(range.unwrap_or((0.0, TAU))),
                    Profile::Curve(c) => Some(c.domain()),
                };
                [u, Some(r.angles.unwrap_or((0.0, TAU)))]
            }
            Self::Offset { base, .. } => base.natural(),
        }
    }

    /// Whether the NURBS is fixed (its domain cannot follow the loops).
    pub fn fixed_domain(&self) -> bool {
        match self {
            Self::Nurbs { .. } => true,
            Self::Offset { base, .. } => base.fixed_domain(),
            _ => false,
        }
    }

    /// The closed B-spline surface with its seam along u (`along_u`) or v
    /// moved to native coordinate `c` (see [`rotate_seam`]).
    pub fn rotate_seam(&self, along_u: bool, c: f64) -> Option<Self> {
        match self {
            Self::Nurbs { surface, periods, .. } => {
                let s = rotate_seam(surface, along_u, c)?;
                Some(Self::Nurbs { surface: s, periods: *periods, natural: None, facts: Box::default() })
            }
            Self::Offset { base, distance } => {
                Some(Self::Offset { base: Box::new(base.rotate_seam(along_u, c)?), distance: *distance })
            }
            _ => None,
        }
    }

    /// The closed B-spline surface unrolled along u (`along_u`) or v over
    /// native range `[a, b]`, which may exceed its period (see [`unroll`]).
    pub fn unroll(&self, along_u: bool, a: f64, b: f64) -> Option<Self> {
        match self {
            Self::Nurbs { surface, periods, .. } => {
                let s = unroll(surface, along_u, a, b)?;
                Some(Self::Nurbs { surface: s, periods: *periods, natural: None, facts: Box::default() })
            }
            Self::Offset { base, distance } => {
                Some(Self::Offset { base: Box::new(base.unroll(along_u, a, b)?), distance: *distance })
            }
            _ => None,
        }
    }

    /// Native coordinates of the surface point closest to `p` (`hint`: the
    /// coordinates of a nearby point, to stay on the same branch). `retry`
    /// allows a global search when Newton from the hint ends far off, and
    /// is cleared when that search does not come close either: the curve
    /// itself is off the surface, and every further sample would pay for a
    /// futile search (a fuzzed file took seconds that way).
    pub fn invert(&self, p: DVec3, hint: Option<DVec2>, retry: &mut bool) -> Native {
        match self {
            Self::Nurbs { surface, facts, .. } => {
                let opts = ProjectionOptions::default();
                let mut pr = project_with(surface, facts, p, hint, &opts, f64::NEG_INFINITY);
                // Newton from a hint can stall (next to the domain's edge);
                // a result far off the surface is retried by the global search.
                let far = 1e-4 * facts.size(|| surface.bbox().diagonal());
                if *retry && hint.is_some() && pr.distance > far {
                    let g = project_with(surface, facts, p, None, &opts, f64::NEG_INFINITY);
                    if g.distance < pr.distance {
                        pr = g;
                    }
                    if pr.distance > far {
                        *retry = false;
                    }
                }
                // Kept for the next sample's projection, which starts here.
                let d = facts.derivs(surface, pr.uv);
                let (su, sv) = (d.su, d.sv);
                let (lu, lv) = (su.length(), sv.length());
                // A collapsed edge written with control points a hair apart
                // (3e-8 against 4.4 across it, in one STEP file) is a pole too.
                let tiny = 1e-6 * (lu + lv);
                Native { q: pr.uv, free: [lu <= tiny, lv <= tiny] }
            }
            Self::Plane { origin, x, y } => {
                let w = p - *origin;
                let (a, b, c) = (x.dot(*x), x.dot(*y), y.dot(*y));
                let (r, s) = (w.dot(*x), w.dot(*y));
                let det = a * c - b * b;
                let q = if det.abs() > 0.0 {
                    DVec2::new((r * c - s * b) / det, (s * a - r * b) / det)
                } else {
                    DVec2::ZERO
                };
                Native { q, free: [false, false] }
            }
            Self::Revolution(r) => r.invert(p, hint),
            Self::Offset { base, .. } => base.invert(p, hint, retry),
        }
    }

    /// The face surface over native ranges `u` × `v` (ignored where the
    /// domain is fixed), and the maps from native coordinates to its parameters.
    ///
    /// # Errors
    /// Invalid geometry (a profile crossing the axis, zero extents).
    pub fn build(&self, u: (f64, f64), v: (f64, f64)) -> Result<(FaceSurface, [AxisMap; 2]), TrimError> {
        match self {
            Self::Nurbs { surface, .. } => Ok((FaceSurface::Nurbs(surface.clone()), [AxisMap::Identity; 2])),
            Self::Plane { origin, x, y } => {
                let at = |a: f64, b: f64| *origin + *x * a + *y * b;
                let s = bilinear([[at(u.0, v.0), at(u.0, v.1)], [at(u.1, v.0), at(u.1, v.1)]], [u.0, u.1], [v.0, v.1])
                    .map_err(|error| TrimError::Geometry { part: "plane", error })?;
                Ok((FaceSurface::Nurbs(s), [AxisMap::Identity; 2]))
            }
            Self::Revolution(r) => r.build(u, v),
            Self::Offset { base, distance } => {
                let (s, maps) = base.build(u, v)?;
                Ok((FaceSurface::Offset { base: Box::new(s), distance: *distance }, maps))
            }
        }
    }
}

impl Revolution {
    fn frame(&self) -> (DVec3, DVec3) {
        (self.xref, self.axis.cross(self.xref))
    }

    fn invert(&self, p: DVec3, hint: Option<DVec2>) -> Native {
        let w = p - self.origin;
        let h = w.dot(self.axis);
        let radial = w - self.axis * h;
        let (x, y) = self.frame();
        let r = radial.length();
        let scale = self.origin.length() + w.length() + TINY;
        // A vertex meant to lie on the axis (a sphere's pole, a cone's apex)
        // is written a few digits short of it: within 1e-7 of its distance
        // from the origin its angle is noise, not a direction.
        let on_axis = r <= 1e-10 * scale + 1e-7 * w.length();
        let mut theta = if on_axis { hint.map_or(0.0, |q| q.y) } else { libm::atan2(radial.dot(y), radial.dot(x)) };
        let t = match &self.profile {
            Profile::Line { p0, d } => {
                // A cone is both its nappes: past the apex the profile's
                // radius is negative, the point half a turn round.
                let foot = |q: DVec2| {
                    let t = guarded_div((q - *p0).dot(*d), d.length_squared());
                    (t, q.distance(*p0 + *d * t))
                };
                let (t, e) = foot(DVec2::new(r, h));
                let (t2, e2) = foot(DVec2::new(-r, h));
                if on_axis && d.x != 0.0 {
                    // On the axis means at the apex, exactly: the loop's
                    // corner is then the pole, not a hair beside it.
                    -p0.x / d.x
                } else if e2 < e && !on_axis {
                    theta += if theta > 0.0 { -core::f64::consts::PI } else { core::f64::consts::PI };
                    t2
                } else {
                    t
                }
            }
            Profile::Circle { c, rho, .. } => {
                let t = libm::atan2(h - c.y, r - c.x);
                // On the axis: exactly where the circle crosses it (a sphere's pole).
                let cross = guarded_div(-c.x, *rho);
                if on_axis && cross.abs() <= 1.0 {
                    let pole = libm::acos(cross);
                    if t < 0.0 {
                        -pole
                    } else {
                        pole
                    }
                } else {
                    t
                }
            }
            Profile::Curve(curve) => {
                let q = self.origin + self.axis * h + x * r;
                curve.project(q).t
            }
        };
        Native { q: DVec2::new(t, theta), free: [false, on_axis] }
    }

    fn build(&self, u: (f64, f64), v: (f64, f64)) -> Result<(FaceSurface, [AxisMap; 2]), TrimError> {
        let (x, _) = self.frame();
        let to3 = |q: DVec2| self.origin + x * q.x + self.axis * q.y;
        let (profile, umap) = match &self.profile {
            Profile::Line { p0, d } => {
                let c = crate::nurbs::analytic::line(to3(*p0 + *d * u.0), to3(*p0 + *d * u.1), u.0, u.1)
                    .map_err(|error| TrimError::Geometry { part: "profile", error })?;
                (c, AxisMap::Identity)
            }
            Profile::Circle { c, rho, .. } => {
                let arc = circle_arc(to3(*c), x, self.axis, *rho, u.0, u.1)
                    .map_err(|error| TrimError::Geometry { part: "profile", error })?;
                (arc, AxisMap::Arc(ArcParam::new(u.0, u.1)))
            }
            Profile::Curve(curve) => {
                let (a, b) = curve.domain();
                let c = if u.0 > a || u.1 < b { segment(curve, u.0, u.1) } else { Ok(curve.clone()) };
                (c.map_err(|error| TrimError::Geometry { part: "profile", error })?, AxisMap::Identity)
            }
        };
        let s = revolve(&profile, self.origin, self.axis, v.0, v.1)
            .map_err(|error| TrimError::Geometry { part: "revolution", error })?;
        Ok((FaceSurface::Nurbs(s), [umap, AxisMap::Arc(ArcParam::new(v.0, v.1))]))
    }
}

/// Entity types this module reads as surfaces.
pub(super) fn is_surface(kind: u32) -> bool {
    matches!(kind, 108 | 114 | 118 | 120 | 122 | 128 | 140 | 190 | 192 | 194 | 196 | 198)
}

/// The definition of surface `de`, in model space (`parent` after the
/// entity's own transformation chain), and whether its native coordinates
/// are the IGES parameters (so parameter-space trim curves can be used).
///
/// # Errors
/// Unsupported types or forms, invalid data, bad pointers.
pub(super) fn surface_def(ctx: &Ctx<'_>, de: usize, parent: DAffine3, depth: usize) -> Result<(SurfDef, bool), Error> {
    let e = ctx.entity(de)?;
    if depth > MAX_DEPTH {
        return Err(e.error(alloc::format!("surfaces nested deeper than {MAX_DEPTH} (a reference cycle?)")));
    }
    let m = parent * own_transform(ctx.dir, de)?;
    let geo = |r: Result<NurbsSurface, crate::NurbsError>| r.map_err(|err| e.error(alloc::format!("{err}")));
    match e.kind {
        128 => Ok((bspline_surface(e, &m)?, true)),
        114 => {
            let s = spline_surface(e)?;
            Ok((nurbs_def(geo(map_surface(&s, &m))?), true))
        }
        118 => {
            let c0 = joined(ctx, e, e.ptr(1)?, m, depth)?;
            let c1 = joined(ctx, e, e.ptr(2)?, m, depth)?;
            let c1 = if e.int(3)? == 1 {
                crate::nurbs::reparam::reversed(&c1).map_err(|x| e.error(alloc::format!("{x}")))?
            } else {
                c1
            };
            Ok((nurbs_def(geo(ruled(&c0, &c1))?), e.form == 1))
        }
        122 => {
            let native = ctx.entity(e.ptr(1)?.unwrap_or(0)).is_ok_and(|d| d.kind != 102);
            let c = joined(ctx, e, e.ptr(1)?, m, depth)?;
            let c = reparametrized(&c, 0.0, 1.0).map_err(|x| e.error(alloc::format!("{x}")))?;
            let end = m.transform_point3(e.vec3(2)?);
            let dir = end - c.point(0.0);
            Ok((nurbs_def(geo(extrude(&c, dir, 0.0, 1.0))?), native))
        }
        120 => revolution_120(ctx, e, m, depth),
        140 => {
            let d = e.real(4)?;
            let base = e.ptr(5)?.ok_or_else(|| e.error("offset surface without a base surface"))?;
            let s = similarity_scale(&m).ok_or_else(|| e.error("offset surface under a non-uniform scaling"))?;
            let (b, native) = surface_def(ctx, base, m, depth + 1)?;
            // 192-198 are parameterized (angle about the axis, profile
            // parameter), the reverse of their native coordinates here, so
            // their IGES normal is the opposite of the NURBS one.
            let swapped = ctx.entity(base).is_ok_and(|b| matches!(b.kind, 192 | 194 | 196 | 198));
            let d = if swapped { -d } else { d };
            Ok((SurfDef::Offset { base: Box::new(b), distance: d * s }, native))
        }
        108 => {
            let n = e.vec3(1)?;
            let d = e.real(4)?;
            let len2 = n.length_squared();
            if !(len2 > 0.0 && len2.is_finite()) {
                return Err(e.error("plane with a zero normal"));
            }
            let (x, y) = n.normalize().any_orthonormal_pair();
            let o = n * (d / len2);
            Ok((plane(&m, o, x, y), false))
        }
        190 => {
            let o = point(ctx, e, e.ptr(1)?, &m)?;
            let n = direction(ctx, e, e.ptr(2)?, &m)?;
            let r = if e.form == 1 { Some(direction(ctx, e, e.ptr(3)?, &m)?) } else { None };
            let x = r.map(|r| (r - n * r.dot(n)).normalize_or_zero()).filter(|x| *x != DVec3::ZERO);
            let x = x.unwrap_or_else(|| n.any_orthonormal_vector());
            Ok((SurfDef::Plane { origin: o, x, y: n.cross(x) }, false))
        }
        192 | 194 | 196 | 198 => Ok((solid_surface(ctx, e, &m)?, false)),
        k => Err(e.error(alloc::format!("entity type {k} (form {}) is not a supported surface", e.form))),
    }
}

fn plane(m: &DAffine3, o: DVec3, x: DVec3, y: DVec3) -> SurfDef {
    SurfDef::Plane { origin: m.transform_point3(o), x: m.transform_vector3(x), y: m.transform_vector3(y) }
}

/// A B-spline surface definition, with its closedness detected.
pub(in crate::io) fn nurbs_def(surface: NurbsSurface) -> SurfDef {
    let periods = closed_periods(&surface);
    SurfDef::Nurbs { surface, periods, natural: None, facts: Box::default() }
}

/// Periods of a surface whose opposite edges coincide.
fn closed_periods(s: &NurbsSurface) -> [Option<f64>; 2] {
    let [lo, hi] = s.domain();
    let tol = 1e-7 * s.bbox().diagonal().max(TINY);
    let mut out = [None, None];
    for axis in 0..2 {
        let other = 1 - axis;
        let closed = (0..=8).all(|k| {
            let t = lo[other] + (hi[other] - lo[other]) * k as f64 / 8.0;
            let mut a = DVec2::ZERO;
            let mut b = DVec2::ZERO;
            a[axis] = lo[axis];
            b[axis] = hi[axis];
            a[other] = t;
            b[other] = t;
            s.point(a).distance(s.point(b)) <= tol
        });
        if closed {
            out[axis] = Some(hi[axis] - lo[axis]);
        }
    }
    out
}

/// 128, control points mapped by `m`.
fn bspline_surface(e: &Entity, m: &DAffine3) -> Result<SurfDef, Error> {
    let (k1, k2, m1, m2) = (e.int(1)?, e.int(2)?, e.int(3)?, e.int(4)?);
    let deg_ok = |d: i64| (1..=MAX_DEGREE as i64).contains(&d);
    if !(deg_ok(m1) && deg_ok(m2)) || k1 < m1 || k2 < m2 {
        return Err(e.error(alloc::format!(
            "B-spline surface with degrees {m1}x{m2} and upper indices {k1}, {k2} is not supported"
        )));
    }
    let (nu, nv) = ((k1 + 1) as u64, (k2 + 1) as u64);
    let total = nu.saturating_mul(nv);
    let (nku, nkv) = ((k1 + m1 + 2) as u64, (k2 + m2 + 2) as u64);
    let need = 10u64.saturating_add(nku).saturating_add(nkv).saturating_add(total.saturating_mul(4));
    if total > MAX_CONTROL_POINTS as u64 || need > e.params.len() as u64 {
        return Err(e.error(alloc::format!(
            "B-spline surface with {nu}x{nv} control points needs {need} parameters, {} present",
            e.params.len()
        )));
    }
    let (nu, nv, nku, nkv) = (nu as usize, nv as usize, nku as usize, nkv as usize);
    let polynomial = e.int(7)? == 1;
    let ku: Vec<f64> = (0..nku).map(|i| e.real(10 + i)).collect::<Result<_, _>>()?;
    let kv: Vec<f64> = (0..nkv).map(|i| e.real(10 + nku + i)).collect::<Result<_, _>>()?;
    let wb = 10 + nku + nkv;
    let pb = wb + nu * nv;
    let mut pts = alloc::vec![alloc::vec![DVec3::ZERO; nv]; nu];
    let mut ws = alloc::vec![alloc::vec![1.0; nv]; nu];
    for j in 0..nv {
        for i in 0..nu {
            let k = j * nu + i; // first index varies fastest
            ws[i][j] = e.real_or(wb + k, 1.0)?;
            pts[i][j] = m.transform_point3(e.vec3(pb + 3 * k)?);
        }
    }
    let w0 = ws[0][0];
    let all_equal = ws.iter().flatten().all(|&w| (w - w0).abs() <= 1e-14 * w0.abs().max(TINY));
    let weights = (!polynomial && !all_equal).then_some(ws.as_slice());
    let s = NurbsSurface::try_new([m1 as usize, m2 as usize], ku, kv, &pts, weights)
        .map_err(|err| e.error(alloc::format!("{err}")))?;
    let [lo, hi] = s.domain();
    let r = pb + 3 * nu * nv;
    let (u0, u1, v0, v1) =
        (e.real_or(r, lo.x)?, e.real_or(r + 1, hi.x)?, e.real_or(r + 2, lo.y)?, e.real_or(r + 3, hi.y)?);
    let nlo = DVec2::new(u0.min(u1).max(lo.x), v0.min(v1).max(lo.y));
    let nhi = DVec2::new(u0.max(u1).min(hi.x), v0.max(v1).min(hi.y));
    let eps = (hi - lo) * 1e-9;
    let smaller = nlo.x > lo.x + eps.x || nlo.y > lo.y + eps.y || nhi.x < hi.x - eps.x || nhi.y < hi.y - eps.y;
    let natural = (smaller && nhi.x > nlo.x && nhi.y > nlo.y).then_some([nlo, nhi]);
    let periods = closed_periods(&s);
    Ok(SurfDef::Nurbs { surface: s, periods, natural, facts: Box::default() })
}

/// 114: bicubic patches in power form, each turned into Bézier form.
/// Patch `(i, j)` (i along u) holds 48 coefficients, x then y then z, each
/// as `Σ c[4b + a]·s^a·t^b`; patches are listed with i varying slowest.
fn spline_surface(e: &Entity) -> Result<NurbsSurface, Error> {
    let (mu, nv) = (e.int(3)?, e.int(4)?);
    if !(1..=4096).contains(&mu) || !(1..=4096).contains(&nv) {
        return Err(e.error("parametric spline surface with a bad patch count"));
    }
    let (mu, nv) = (mu as usize, nv as usize);
    let tu: Vec<f64> = (0..=mu).map(|i| e.real(5 + i)).collect::<Result<_, _>>()?;
    let tv: Vec<f64> = (0..=nv).map(|i| e.real(6 + mu + i)).collect::<Result<_, _>>()?;
    let base = 7 + mu + nv;
    let need = base + 48 * mu * nv;
    if need > e.params.len() {
        return Err(
            e.error(alloc::format!("parametric spline surface needs {need} parameters, {} present", e.params.len()))
        );
    }
    let (cu, cv) = (3 * mu + 1, 3 * nv + 1);
    let mut pts = alloc::vec![alloc::vec![DVec3::ZERO; cv]; cu];
    for i in 0..mu {
        let hu = tu[i + 1] - tu[i];
        for j in 0..nv {
            let hv = tv[j + 1] - tv[j];
            if !(hu > 0.0 && hv > 0.0) {
                return Err(e.error("parametric spline surface breakpoints do not increase"));
            }
            let at = base + 48 * (i * nv + j);
            for axis in 0..3 {
                let mut c = [[0.0; 4]; 4]; // c[a][b]: s^a t^b, scaled to unit steps
                for b in 0..4 {
                    for a in 0..4 {
                        let raw = e.real(at + 16 * axis + 4 * b + a)?;
                        c[a][b] = raw * libm::pow(hu, a as f64) * libm::pow(hv, b as f64);
                    }
                }
                let bez = power_to_bezier_2d(&c);
                for a in 0..4 {
                    for b in 0..4 {
                        pts[3 * i + a][3 * j + b][axis] = bez[a][b];
                    }
                }
            }
        }
    }
    let knots = |t: &[f64]| {
        let mut k = alloc::vec![t[0]; 4];
        for &x in &t[1..t.len() - 1] {
            k.extend([x; 3]);
        }
        k.extend([t[t.len() - 1]; 4]);
        k
    };
    NurbsSurface::try_new([3, 3], knots(&tu), knots(&tv), &pts, None).map_err(|err| e.error(alloc::format!("{err}")))
}

/// Cubic power coefficients on [0, 1] to Bézier ordinates.
fn power_to_bezier(a: [f64; 4]) -> [f64; 4] {
    [a[0], a[0] + a[1] / 3.0, a[0] + 2.0 * a[1] / 3.0 + a[2] / 3.0, a[0] + a[1] + a[2] + a[3]]
}

fn power_to_bezier_2d(c: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut rows = [[0.0; 4]; 4];
    for b in 0..4 {
        let col = power_to_bezier([c[0][b], c[1][b], c[2][b], c[3][b]]);
        for a in 0..4 {
            rows[a][b] = col[a];
        }
    }
    let mut out = [[0.0; 4]; 4];
    for a in 0..4 {
        out[a] = power_to_bezier(rows[a]);
    }
    out
}

/// A NURBS surface with control points mapped by `m` (exact: affine).
pub(in crate::io) fn map_surface(s: &NurbsSurface, m: &DAffine3) -> Result<NurbsSurface, crate::NurbsError> {
    let [nu, nv] = s.counts();
    let mut pts = Vec::with_capacity(nu);
    let mut ws = Vec::with_capacity(nu);
    for i in 0..nu {
        let mut row = Vec::with_capacity(nv);
        let mut wrow = Vec::with_capacity(nv);
        for j in 0..nv {
            let h = s.homogeneous(i, j);
            row.push(m.transform_point3(h.truncate() / h.w));
            wrow.push(h.w);
        }
        pts.push(row);
        ws.push(wrow);
    }
    let w = s.is_rational().then_some(ws.as_slice());
    NurbsSurface::from_parts(s.knots_u().clone(), s.knots_v().clone(), &pts, w)
}

/// The curve `de` as one piece (a composite is joined).
fn joined(ctx: &Ctx<'_>, owner: &Entity, de: Option<usize>, m: DAffine3, depth: usize) -> Result<NurbsCurve, Error> {
    let de = de.ok_or_else(|| owner.error("missing curve pointer"))?;
    let pieces = model_curve(ctx, de, m, depth + 1)?;
    join(&pieces).map_err(|err| owner.error(alloc::format!("{err}")))
}

fn point(ctx: &Ctx<'_>, owner: &Entity, de: Option<usize>, m: &DAffine3) -> Result<DVec3, Error> {
    let de = de.ok_or_else(|| owner.error("missing point pointer"))?;
    let p = ctx.entity(de)?;
    if p.kind != 116 {
        return Err(owner.error(alloc::format!("pointer {de} should name a point (116), not type {}", p.kind)));
    }
    let own = own_transform(ctx.dir, de)?;
    Ok(m.transform_point3(own.transform_point3(p.vec3(1)?)))
}

fn direction(ctx: &Ctx<'_>, owner: &Entity, de: Option<usize>, m: &DAffine3) -> Result<DVec3, Error> {
    let de = de.ok_or_else(|| owner.error("missing direction pointer"))?;
    let d = ctx.entity(de)?;
    if d.kind != 123 {
        return Err(owner.error(alloc::format!("pointer {de} should name a direction (123), not type {}", d.kind)));
    }
    let own = own_transform(ctx.dir, de)?;
    let v = m.transform_vector3(own.transform_vector3(d.vec3(1)?));
    let n = v.normalize_or_zero();
    if n == DVec3::ZERO {
        return Err(owner.error(alloc::format!("direction {de} is zero")));
    }
    Ok(n)
}

/// 192–198: cylinder, cone, sphere and torus as revolutions.
fn solid_surface(ctx: &Ctx<'_>, e: &Entity, m: &DAffine3) -> Result<SurfDef, Error> {
    let s = similarity_scale(m).ok_or_else(|| e.error("analytic surface under a non-uniform scaling"))?;
    if m.matrix3.determinant() < 0.0 {
        return Err(e.error("analytic surface under a mirroring transformation is not supported"));
    }
    let origin = point(ctx, e, e.ptr(1)?, m)?;
    let positive = |x: f64, what: &str| {
        if x > 0.0 && x.is_finite() {
            Ok(x * s)
        } else {
            Err(e.error(alloc::format!("{what} must be positive, is {x}")))
        }
    };
    let (axis, refdir_at, profile) = match e.kind {
        192 => {
            let axis = direction(ctx, e, e.ptr(2)?, m)?;
            let r = positive(e.real(3)?, "cylinder radius")?;
            (axis, 4, Profile::Line { p0: DVec2::new(r, 0.0), d: DVec2::new(0.0, 1.0) })
        }
        194 => {
            let axis = direction(ctx, e, e.ptr(2)?, m)?;
            let r = e.real(3)? * s;
            let angle = e.real(4)?.to_radians();
            if !(r >= 0.0 && angle > 0.0 && angle < core::f64::consts::FRAC_PI_2) {
                return Err(e.error("cone with a negative radius or a semi-angle outside (0°, 90°)"));
            }
            (axis, 5, Profile::Line { p0: DVec2::new(r, 0.0), d: DVec2::new(libm::tan(angle), 1.0) })
        }
        196 => {
            let r = positive(e.real(2)?, "sphere radius")?;
            let axis =
                if e.form == 1 { direction(ctx, e, e.ptr(3)?, m)? } else { m.transform_vector3(DVec3::Z).normalize() };
            let h = core::f64::consts::FRAC_PI_2;
            (axis, 4, Profile::Circle { c: DVec2::ZERO, rho: r, range: Some((-h, h)) })
        }
        _ => {
            let axis = direction(ctx, e, e.ptr(2)?, m)?;
            let big = positive(e.real(3)?, "torus major radius")?;
            let small = positive(e.real(4)?, "torus minor radius")?;
            (axis, 5, Profile::Circle { c: DVec2::new(big, 0.0), rho: small, range: None })
        }
    };
    let refdir = if e.form == 1 { Some(direction(ctx, e, e.ptr(refdir_at)?, m)?) } else { None };
    let xref = refdir.map(|r| (r - axis * r.dot(axis)).normalize_or_zero()).filter(|x| *x != DVec3::ZERO);
    let xref = xref.unwrap_or_else(|| axis.any_orthonormal_vector());
    Ok(SurfDef::Revolution(Box::new(Revolution { origin, axis, xref, profile, angles: None })))
}

/// 120: the generatrix turned about the axis line from SA to TA. Native
/// coordinates (generatrix parameter, angle) are exact when the generatrix
/// lies in a half-plane bounded by the axis; otherwise the surface is
/// turned into a B-spline over its whole range.
fn revolution_120(ctx: &Ctx<'_>, e: &Entity, m: DAffine3, depth: usize) -> Result<(SurfDef, bool), Error> {
    let axis_de = e.ptr(1)?.ok_or_else(|| e.error("surface of revolution without an axis"))?;
    let axis_line = model_curve(ctx, axis_de, m, depth + 1)?;
    let (a0, a1) = match axis_line.as_slice() {
        [l] if l.degree() == 1 => {
            let (t0, t1) = l.domain();
            (l.point(t0), l.point(t1))
        }
        _ => return Err(e.error("the axis of a surface of revolution must be a line")),
    };
    let axis = (a1 - a0).normalize_or_zero();
    if axis == DVec3::ZERO {
        return Err(e.error("the axis of a surface of revolution has zero length"));
    }
    let gen_de = e.ptr(2)?.ok_or_else(|| e.error("surface of revolution without a generatrix"))?;
    let native_params = ctx.entity(gen_de).is_ok_and(|g| matches!(g.kind, 110 | 126));
    let profile = joined(ctx, e, Some(gen_de), m, depth)?;
    let (sa, ta) = (e.real(3)?, e.real(4)?);
    if ta.is_nan() || sa.is_nan() || ta <= sa {
        return Err(e.error(alloc::format!("surface of revolution from {sa} to {ta} rad sweeps nothing")));
    }
    let ta = ta.min(sa + TAU);
    // The half-plane of the profile: the radial direction of its control
    // point farthest from the axis; every control point must lie in it.
    let radial = |p: DVec3| {
        let w = p - a0;
        w - axis * w.dot(axis)
    };
    let far = profile.control_points().map(radial).max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
    let size = profile.bbox().diagonal().max(TINY);
    let xref = far.map(|r| r.normalize_or_zero()).unwrap_or(DVec3::ZERO);
    let planar = xref != DVec3::ZERO
        && profile
            .control_points()
            .map(radial)
            .all(|r| r.dot(axis.cross(xref)).abs() <= 1e-9 * size && r.dot(xref) >= -1e-9 * size);
    if planar {
        let rev = Revolution { origin: a0, axis, xref, profile: Profile::Curve(profile), angles: Some((sa, ta)) };
        return Ok((SurfDef::Revolution(Box::new(rev)), native_params));
    }
    let s = revolve(&profile, a0, axis, sa, ta).map_err(|err| e.error(alloc::format!("{err}")))?;
    Ok((nurbs_def(s), false))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle-like bilinear patch whose edge u = 0 is collapsed to a
    /// point up to `hair` (control points that far apart).
    fn wedge(hair: f64) -> SurfDef {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let surface = crate::nurbs::analytic::bilinear(
            [[p(0.0, 0.0), p(0.0, hair)], [p(4.0, -2.0), p(4.0, 2.0)]],
            [0.0, 1.0],
            [0.0, 1.0],
        )
        .unwrap();
        SurfDef::Nurbs { surface, periods: [None; 2], natural: None, facts: Box::default() }
    }

    /// At a pole written with control points a hair apart (3e-8 against
    /// 4.4 across it in a STEP file) v is as free as at an exact one, so a
    /// trim curve reaching it keeps its own v instead of the projection's.
    #[test]
    fn a_pole_a_hair_wide_leaves_its_coordinate_free() {
        for hair in [0.0, 3e-8] {
            let n = wedge(hair).invert(DVec3::new(0.0, 0.5 * hair, 0.0), Some(DVec2::new(0.1, 0.9)), &mut true);
            assert!(n.q.x.abs() < 1e-6, "{hair}: {:?}", n.q);
            assert_eq!(n.free, [false, true], "{hair}");
        }
        // Beside the pole both coordinates are fixed.
        let n = wedge(3e-8).invert(DVec3::new(0.04, 0.0, 0.0), None, &mut true);
        assert_eq!(n.free, [false, false]);
    }

    /// A cone's face may lie past its apex (a STEP cone is both nappes):
    /// there the profile's radius is negative, and the point found must be
    /// the one given, not its mirror on the near nappe.
    #[test]
    fn a_point_past_the_cone_apex_inverts_to_itself() {
        let cone = Revolution {
            origin: DVec3::new(1.0, 2.0, 3.0),
            axis: DVec3::Z,
            xref: DVec3::X,
            profile: Profile::Line { p0: DVec2::new(10.0, 0.0), d: DVec2::new(1.0, 1.0) },
            angles: None,
        };
        let at = |t: f64, theta: f64| {
            let radius = 10.0 + t;
            cone.origin + (DVec3::X * libm::cos(theta) + DVec3::Y * libm::sin(theta)) * radius + DVec3::Z * t
        };
        // Before the apex (t = -10) and past it, on both sides of the seam.
        for (t, theta) in [(5.0, 0.3), (-4.0, 2.0), (-20.0, 0.3), (-35.0, -2.5), (-12.0, 3.0)] {
            let p = at(t, theta);
            let n = cone.invert(p, None);
            assert!(at(n.q.x, n.q.y).distance(p) < 1e-9, "t {t} theta {theta}: {:?}", n.q);
            assert!((n.q.x - t).abs() < 1e-9, "t {t}: {:?}", n.q);
        }
    }
}
