//! Curve entities to exact NURBS: circular arc (100), composite (102), conic
//! arc (104), copious data (106 forms 1, 2, 11, 12, 13, 63), line (110),
//! parametric spline (112) and rational B-spline (126). A composite gives
//! one piece per member, in order.

use alloc::vec::Vec;
use glam::{DAffine3, DVec2, DVec3};

use super::directory::Entity;
use super::xform::own_transform;
use super::{Ctx, MAX_CONTROL_POINTS, MAX_DEPTH};
use crate::numeric::TINY;
use crate::nurbs::analytic::{circle_arc, conic_segment, ellipse_arc, line};
use crate::nurbs::reparam::{map_points, segment};
use crate::nurbs::{NurbsCurve, MAX_DEGREE};
use crate::warning::{Warning, WarningKind};
use crate::Error;

/// The model-space pieces of curve `de`, mapped by `parent` after the
/// entity's own transformation chain.
///
/// # Errors
/// A pointer to a missing or non-curve entity, unsupported forms, invalid
/// data, or nesting deeper than [`MAX_DEPTH`].
pub(super) fn model_curve(ctx: &Ctx<'_>, de: usize, parent: DAffine3, depth: usize) -> Result<Vec<NurbsCurve>, Error> {
    let e = ctx.entity(de)?;
    if depth > MAX_DEPTH {
        return Err(e.error(alloc::format!("curves nested deeper than {MAX_DEPTH} (a reference cycle?)")));
    }
    let m = parent * own_transform(ctx.dir, de)?;
    if e.kind == 102 {
        let n = e.count(1, 1, 2)?;
        let mut out = Vec::new();
        for k in 0..n {
            let Some(child) = e.ptr(2 + k)? else { continue };
            out.extend(model_curve(ctx, child, m, depth + 1)?);
        }
        if out.is_empty() {
            return Err(e.error("composite curve without members"));
        }
        return Ok(out);
    }
    let pieces = local_curve(ctx, e)?;
    let mut out = Vec::with_capacity(pieces.len());
    for c in pieces {
        let c = if m == DAffine3::IDENTITY { Ok(c) } else { map_points(&c, |p| m.transform_point3(p)) };
        out.push(c.map_err(|err| e.error(alloc::format!("{err}")))?);
    }
    Ok(out)
}

/// The pieces of parameter-space curve `de` in (u, v) (z dropped), mapped
/// by its own transformation chain only.
///
/// # Errors
/// As [`model_curve`].
pub(super) fn param_curve(ctx: &Ctx<'_>, de: usize) -> Result<Vec<NurbsCurve>, Error> {
    let pieces = model_curve(ctx, de, DAffine3::IDENTITY, 0)?;
    let mut out = Vec::with_capacity(pieces.len());
    for c in pieces {
        let flat = map_points(&c, |p| DVec3::new(p.x, p.y, 0.0))
            .map_err(|err| ctx.entity(de).map_or_else(|e| e, |e| e.error(alloc::format!("{err}"))))?;
        out.push(flat);
    }
    Ok(out)
}

/// The curve in its definition space.
fn local_curve(ctx: &Ctx<'_>, e: &Entity) -> Result<Vec<NurbsCurve>, Error> {
    let wrap = |r: Result<NurbsCurve, crate::NurbsError>| r.map_err(|err| e.error(alloc::format!("{err}")));
    match e.kind {
        100 => Ok(alloc::vec![wrap(arc(e)?)?]),
        104 => conic(e),
        106 => Ok(alloc::vec![copious(e)?]),
        110 => {
            let (a, b) = (e.vec3(1)?, e.vec3(4)?);
            if a == b {
                return Err(e.error("line of zero length"));
            }
            if e.form != 0 {
                return Err(e.error(alloc::format!("unbounded line (form {}) cannot be meshed", e.form)));
            }
            Ok(alloc::vec![wrap(line(a, b, 0.0, 1.0))?])
        }
        112 => Ok(alloc::vec![spline(e)?]),
        126 => Ok(alloc::vec![bspline(ctx, e)?]),
        k => Err(e.error(alloc::format!("entity type {k} is not a supported curve"))),
    }
}

/// 100: centre, start and end in the plane z = ZT, counter-clockwise.
fn arc(e: &Entity) -> Result<Result<NurbsCurve, crate::NurbsError>, Error> {
    let z = e.real(1)?;
    let c = DVec2::new(e.real(2)?, e.real(3)?);
    let s = DVec2::new(e.real(4)?, e.real(5)?);
    let t = DVec2::new(e.real(6)?, e.real(7)?);
    let r = (s - c).length();
    if !(r > 0.0 && r.is_finite()) {
        return Err(e.error("circular arc of zero radius"));
    }
    let a0 = libm::atan2(s.y - c.y, s.x - c.x);
    let mut a1 = libm::atan2(t.y - c.y, t.x - c.x);
    let tau = core::f64::consts::TAU;
    while a1 <= a0 + 1e-12 {
        a1 += tau;
    }
    // Start and end that coincide: a full circle.
    if (s - t).length() <= 1e-12 * r.max(1.0) {
        a1 = a0 + tau;
    }
    Ok(circle_arc(c.extend(z), DVec3::X, DVec3::Y, r, a0, a1))
}

/// 104: `A x² + B xy + C y² + D x + E y + F = 0` in the plane z = ZT, from
/// start to end (counter-clockwise on an ellipse).
fn conic(e: &Entity) -> Result<Vec<NurbsCurve>, Error> {
    let k: Vec<f64> = (1..=6).map(|i| e.real(i)).collect::<Result<_, _>>()?;
    let (a, b, c, d, ee, f) = (k[0], k[1], k[2], k[3], k[4], k[5]);
    let z = e.real(7)?;
    let p0 = DVec2::new(e.real(8)?, e.real(9)?);
    let p2 = DVec2::new(e.real(10)?, e.real(11)?);
    let wrap = |r: Result<NurbsCurve, crate::NurbsError>| r.map_err(|err| e.error(alloc::format!("{err}")));
    let disc = b * b - 4.0 * a * c;
    let scale = a.abs().max(b.abs()).max(c.abs()).max(TINY);
    if disc < -1e-12 * scale * scale {
        // Ellipse: centre, axes from the quadratic form's eigenvectors.
        let det = 4.0 * a * c - b * b;
        let centre = DVec2::new((b * ee - 2.0 * c * d) / det, (b * d - 2.0 * a * ee) / det);
        let g = a * centre.x * centre.x
            + b * centre.x * centre.y
            + c * centre.y * centre.y
            + d * centre.x
            + ee * centre.y
            + f;
        let theta = 0.5 * libm::atan2(b, a - c);
        let (ct, st) = (libm::cos(theta), libm::sin(theta));
        let l1 = a * ct * ct + b * ct * st + c * st * st;
        let l2 = a * st * st - b * ct * st + c * ct * ct;
        if !(-g / l1 > 0.0 && -g / l2 > 0.0) {
            return Err(e.error("conic coefficients describe no real ellipse"));
        }
        let ax = DVec2::new(ct, st) * libm::sqrt(-g / l1);
        let ay = DVec2::new(-st, ct) * libm::sqrt(-g / l2);
        // Orient the frame counter-clockwise.
        let ay = if ax.perp_dot(ay) < 0.0 { -ay } else { ay };
        let angle = |p: DVec2| {
            let q = p - centre;
            let m = glam::DMat2::from_cols(ax, ay);
            let w = m.inverse() * q;
            libm::atan2(w.y, w.x)
        };
        let a0 = angle(p0);
        let mut a1 = angle(p2);
        while a1 <= a0 + 1e-12 {
            a1 += core::f64::consts::TAU;
        }
        return Ok(alloc::vec![wrap(ellipse_arc(centre.extend(z), ax.extend(0.0), ay.extend(0.0), a0, a1))?]);
    }
    // Parabola or hyperbola arc: tangent lines at the ends meet at the
    // middle control point; the weight follows from the conic point on the
    // line from the chord's midpoint to that control point.
    let grad = |p: DVec2| DVec2::new(2.0 * a * p.x + b * p.y + d, b * p.x + 2.0 * c * p.y + ee);
    let (t0, t2) = (grad(p0).perp(), grad(p2).perp());
    let den = t0.perp_dot(t2);
    if den.is_nan() || den.abs() <= 1e-14 * t0.length() * t2.length() {
        return Err(e.error("conic arc whose end tangents are parallel"));
    }
    let s = (p2 - p0).perp_dot(t2) / den;
    let p1 = p0 + t0 * s;
    let m = (p0 + p2) * 0.5;
    let dir = p1 - m;
    // Solve Q(m + λ·dir) = 0 for λ in (0, 1).
    let q = |p: DVec2| a * p.x * p.x + b * p.x * p.y + c * p.y * p.y + d * p.x + ee * p.y + f;
    let (q0, qh, q1) = (q(m), q(m + dir * 0.5), q(m + dir));
    let qa = 2.0 * (q1 - 2.0 * qh + q0);
    let qb = q1 - q0 - qa;
    let roots = if qa.abs() > TINY {
        let disc = qb * qb - 4.0 * qa * q0;
        if disc < 0.0 {
            Vec::new()
        } else {
            let r = libm::sqrt(disc);
            alloc::vec![(-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa)]
        }
    } else if qb.abs() > TINY {
        alloc::vec![-q0 / qb]
    } else {
        Vec::new()
    };
    let lambda =
        roots
            .into_iter()
            .filter(|l| *l > 0.0 && *l < 1.0)
            .fold(f64::NAN, |acc, l| if acc.is_nan() { l } else { acc.min(l) });
    if !lambda.is_finite() {
        return Err(e.error("conic arc: cannot place its shoulder point"));
    }
    // Shoulder S = (M + w·P1)/(1 + w) with S = M + λ·(P1 − M): w = λ / (1 − λ).
    let w = lambda / (1.0 - lambda);
    Ok(alloc::vec![wrap(conic_segment(p0.extend(z), p1.extend(z), p2.extend(z), w))?])
}

/// 106: copious data as a polyline (parameter: point index).
fn copious(e: &Entity) -> Result<NurbsCurve, Error> {
    let ip = e.int(1)?;
    let (per, zt) = match ip {
        1 => (2, Some(e.real(3)?)),
        2 => (3, None),
        3 => (6, None),
        _ => return Err(e.error(alloc::format!("copious data: unknown point format IP = {ip}"))),
    };
    if !matches!(e.form, 1 | 2 | 11 | 12 | 13 | 63) {
        return Err(e.error(alloc::format!("copious data form {} is not a curve", e.form)));
    }
    let from = if zt.is_some() { 4 } else { 3 };
    let n = e.count(2, per, from)?;
    if n > MAX_CONTROL_POINTS {
        return Err(e.error(alloc::format!("{n} points, more than the limit {MAX_CONTROL_POINTS}")));
    }
    let mut pts: Vec<DVec3> = Vec::with_capacity(n);
    for k in 0..n {
        let i = from + k * per;
        let p = match zt {
            Some(z) => DVec3::new(e.real(i)?, e.real(i + 1)?, z),
            None => e.vec3(i)?,
        };
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    if e.form == 63 && pts.len() > 2 && pts.first() != pts.last() {
        let first = pts[0];
        pts.push(first);
    }
    if pts.len() < 2 {
        return Err(e.error("copious data with fewer than two distinct points"));
    }
    let m = pts.len();
    let mut knots = Vec::with_capacity(m + 2);
    knots.push(0.0);
    knots.extend((0..m).map(|i| i as f64));
    knots.push((m - 1) as f64);
    NurbsCurve::try_new(1, knots, pts, None).map_err(|err| e.error(alloc::format!("{err}")))
}

/// 112: cubic polynomial segments in power form, each turned into a Bézier piece.
fn spline(e: &Entity) -> Result<NurbsCurve, Error> {
    let ndim = e.int(3)?;
    let n = e.count(4, 13, 5)?;
    if n == 0 || !(ndim == 2 || ndim == 3) {
        return Err(e.error("parametric spline curve without segments or with a bad dimension"));
    }
    let tb: Vec<f64> = (0..=n).map(|i| e.real(5 + i)).collect::<Result<_, _>>()?;
    let base = 6 + n;
    let mut knots = alloc::vec![tb[0]; 4];
    let mut pts: Vec<DVec3> = Vec::with_capacity(3 * n + 1);
    for s in 0..n {
        let h = tb[s + 1] - tb[s];
        if h.is_nan() || h <= 0.0 {
            return Err(e.error(alloc::format!("parametric spline breakpoints do not increase at segment {}", s + 1)));
        }
        let at = base + 12 * s;
        let coef = |axis: usize, k: usize| e.real(at + 4 * axis + k);
        let mut bez = [DVec3::ZERO; 4];
        for axis in 0..3 {
            let (a, b, c, d) = if axis < 2 || ndim == 3 {
                (coef(axis, 0)?, coef(axis, 1)? * h, coef(axis, 2)? * h * h, coef(axis, 3)? * h * h * h)
            } else {
                (coef(axis, 0)?, 0.0, 0.0, 0.0)
            };
            let b0 = a;
            let b1 = a + b / 3.0;
            let b2 = a + 2.0 * b / 3.0 + c / 3.0;
            let b3 = a + b + c + d;
            for (k, v) in [b0, b1, b2, b3].into_iter().enumerate() {
                bez[k][axis] = v;
            }
        }
        if s == 0 {
            pts.push(bez[0]);
        }
        pts.extend_from_slice(&bez[1..]);
        knots.extend([tb[s + 1]; 3]);
    }
    knots.push(tb[n]);
    NurbsCurve::try_new(3, knots, pts, None).map_err(|err| e.error(alloc::format!("{err}")))
}

/// 126: rational B-spline curve, restricted to its parameter range V(0)..V(1).
/// A range that is empty (`[0, 0]` is common), inverted or outside the
/// knots' domain is repaired with a note: an inverted one is read the other
/// way round, one with nothing of the domain in it gives the whole domain
/// (the curve as its knots define it).
fn bspline(ctx: &Ctx<'_>, e: &Entity) -> Result<NurbsCurve, Error> {
    let k = e.int(1)?;
    let m = e.int(2)?;
    if !(1..=MAX_DEGREE as i64).contains(&m) || k < m || k > MAX_CONTROL_POINTS as i64 {
        return Err(e.error(alloc::format!("B-spline curve with degree {m} and upper index {k} is not supported")));
    }
    let (k, m) = (k as usize, m as usize);
    let n = k + 1;
    let nk = k + m + 2;
    let need = 7 + nk + 4 * n + 2;
    if e.params.len() < need - 2 {
        return Err(e.error(alloc::format!(
            "B-spline curve needs {} parameters for {n} control points, only {} present",
            need - 2,
            e.params.len()
        )));
    }
    let polynomial = e.int(5)? == 1;
    let knots: Vec<f64> = (0..nk).map(|i| e.real(7 + i)).collect::<Result<_, _>>()?;
    let wbase = 7 + nk;
    let weights: Vec<f64> = (0..n).map(|i| e.real_or(wbase + i, 1.0)).collect::<Result<_, _>>()?;
    let pbase = wbase + n;
    let pts: Vec<DVec3> = (0..n).map(|i| e.vec3(pbase + 3 * i)).collect::<Result<_, _>>()?;
    let all_equal = weights.iter().all(|&w| (w - weights[0]).abs() <= 1e-14 * w.abs().max(TINY));
    let w = (!polynomial && !all_equal).then_some(weights);
    let c = NurbsCurve::try_new(m, knots, pts, w).map_err(|err| e.error(alloc::format!("{err}")))?;
    let (a, b) = c.domain();
    let (r0, r1) = (e.real_or(pbase + 3 * n, a)?, e.real_or(pbase + 3 * n + 1, b)?);
    let eps = 1e-9 * (b - a);
    let (v0, v1) = (r0.min(r1).max(a), r0.max(r1).min(b));
    let note = |kind: &'static str, what: alloc::string::String| {
        let m = alloc::format!("B-spline curve's parameter range [{r0}, {r1}] {what}");
        ctx.notes.borrow_mut().note(kind, e.de, || Warning::new(WarningKind::Forgiven(e.error(m))));
    };
    if (v1 - v0).is_nan() || v1 - v0 <= eps {
        note("curve-range-empty", alloc::format!("holds none of the curve; its whole domain [{a}, {b}] is used"));
        return Ok(c);
    }
    if r1 < r0 {
        note("curve-range-inverted", alloc::format!("is inverted; read as [{v0}, {v1}]"));
    } else if r0 < a - eps || r1 > b + eps {
        note("curve-range-outside", alloc::format!("runs past the knots' domain [{a}, {b}]; read as [{v0}, {v1}]"));
    }
    if v0 > a + eps || v1 < b - eps {
        return segment(&c, v0, v1).map_err(|err| e.error(alloc::format!("{err}")));
    }
    Ok(c)
}
