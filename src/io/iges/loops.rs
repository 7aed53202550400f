//! One face from a surface definition and its boundary loops: choose per
//! loop between the file's parameter-space curves and projecting its
//! model-space curves, make the loops continuous across seams, size the
//! surface's NURBS to them, fit the curves in its parameters and close every
//! loop exactly (end of each curve = start of the next).

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::fit::Track;
use super::surfaces::{AxisMap, SurfDef};
use super::untangle::untangle;
use super::wrap::{chain_loop, loop_shape, resolve_windings, windows, Range, TrimError};
use crate::model::{Face, FaceSurface, TrimLoop};
use crate::numeric::TINY;
use crate::nurbs::analytic::line;
use crate::nurbs::reparam::{map_points, reversed, segment, with_end_points};
use crate::nurbs::{Aabb, NurbsCurve, Surface};
use crate::warning::WarningKind;

/// One boundary loop as the file gives it.
#[derive(Debug, Clone, Default)]
pub(in crate::io) struct LoopSrc {
    /// Model-space curves in loop order (may be empty).
    pub model: Vec<NurbsCurve>,
    /// Parameter-space curves in the surface's IGES parameters, when the
    /// file gives them and prefers (or does not disfavour) them.
    pub params: Option<Vec<NurbsCurve>>,
}

/// What a face is made of.
#[derive(Debug, Clone)]
pub(in crate::io) struct FaceSrc {
    pub def: SurfDef,
    /// Whether the definition's native coordinates are the IGES parameters.
    pub native: bool,
    pub loops: Vec<LoopSrc>,
    /// The outer boundary is the surface's own (IGES 144 with N1 = 0).
    pub domain_outer: bool,
    /// The file's minimum resolution, model units.
    pub resolution: Option<f64>,
}

/// Builds the face. Warnings about repairs go to `warn`.
///
/// # Errors
/// A message for the caller's "skipped" warning: loops that cannot be put in
/// the surface's parameters, an unbounded surface without loops, bad geometry.
pub(in crate::io) fn build_face(src: FaceSrc, warn: &mut Vec<WarningKind>) -> Result<Face, TrimError> {
    build_face_oriented(src, None, warn)
}

/// As [`build_face`], knowing on which side of its loops the face lies:
/// `left` is `Some(true)` when the face is on the left of every loop's
/// direction in the definition's native coordinates (seen from the side of
/// `Su × Sv`), as a B-rep's oriented loops say. With it, loops that go
/// round a periodic coordinate are closed along the pole or boundary on the
/// face's side, or joined in pairs along the seam, and loops through a pole
/// meet there on the side that gives them the orientation asked for.
///
/// # Errors
/// As [`build_face`].
pub(in crate::io) fn build_face_oriented(
    src: FaceSrc,
    left: Option<bool>,
    warn: &mut Vec<WarningKind>,
) -> Result<Face, TrimError> {
    let mut def = src.def.clone();
    let periods = def.periods();
    let natural = def.natural();
    let (mut loops_2d, mut tracks) = read_loops(&src, &def, warn)?;
    // Each sampled loop continuous; those going round a period closed or joined.
    let windings: Vec<[i64; 2]> = tracks.iter_mut().map(|lp| chain_loop(lp, periods, left)).collect();
    resolve_windings(&def, &mut tracks, &windings, periods, natural, left)?;
    let (surface, maps) = match place_loops(&src, &mut def, &mut loops_2d, &mut tracks)? {
        Placed::Face(face) => return Ok(face),
        Placed::Surface(surface, maps) => (surface, maps),
    };
    // Fit the sampled loops.
    let size = model_size(&surface, &tracks, &loops_2d, &maps);
    let tol = (1e-5 * size).max(0.1 * src.resolution.unwrap_or(0.0)).max(1e-12);
    let mut unmet = 0usize;
    for lp in &mut tracks {
        let mut pieces = Vec::with_capacity(lp.len());
        for tr in lp.iter_mut() {
            let (c, met) = tr.fit(&def, &surface, &maps, periods, tol);
            if !met {
                unmet += 1;
            }
            if let Some(c) = c {
                pieces.push(c);
            }
        }
        loops_2d.push(pieces);
    }
    if unmet > 0 {
        warn.push(WarningKind::TrimFitLimit { curves: unmet });
    }
    let [lo, hi] = surface.domain();
    let mut loops: Vec<TrimLoop> = Vec::new();
    if src.domain_outer && !loops_2d.is_empty() {
        loops.push(rectangle(natural_box(&def, lo, hi, &maps))?);
    }
    for pieces in loops_2d {
        if let Some(lp) = close_loop(pieces, &surface, lo, hi, tol, warn)? {
            loops.push(lp);
        }
    }
    if loops.is_empty() {
        // Untrimmed: the entity's own rectangle when smaller than the domain.
        let b = natural_box(&def, lo, hi, &maps);
        if b[0].x > lo.x || b[0].y > lo.y || b[1].x < hi.x || b[1].y < hi.y {
            loops.push(rectangle(b)?);
        }
    }
    Ok(Face { name: None, surface, loops })
}

/// The face's loops as read: the file's parameter curves where they are in
/// a B-spline surface's own parameters and agree with its model-space
/// curves (`loops_2d`), else sampled tracks to fit (from the parameter
/// curves, or from the model-space ones, projected).
///
/// # Errors
/// A loop without curves, or one only in parameters that are not read.
#[allow(clippy::type_complexity)]
fn read_loops(
    src: &FaceSrc,
    def: &SurfDef,
    warn: &mut Vec<WarningKind>,
) -> Result<(Vec<Vec<NurbsCurve>>, Vec<Vec<Track>>), TrimError> {
    let periods = def.periods();
    // Parameter curves on a B-spline surface in its own parameters need no fitting.
    let direct = def.fixed_domain() && src.native;
    let mut loops_2d: Vec<Vec<NurbsCurve>> = Vec::new();
    let mut tracks: Vec<Vec<Track>> = Vec::new();
    for lp in &src.loops {
        match (&lp.params, src.native) {
            (Some(pc), true) if !pc.is_empty() && direct => {
                let mut pieces = pc.clone();
                orient_chain(&mut pieces);
                loops_2d.push(pieces);
            }
            (Some(pc), true) if !pc.is_empty() => tracks.push(sample_loop(def, pc.clone(), false, periods)?),
            _ if !lp.model.is_empty() => tracks.push(sample_loop(def, lp.model.clone(), true, periods)?),
            (Some(_), false) => return Err(TrimError::UnreadParameters),
            _ => return Err(TrimError::NoCurves),
        }
    }
    // Check the file's parameter curves against its model-space ones.
    if direct && !loops_2d.is_empty() {
        let (s, m) = def.build((0.0, 1.0), (0.0, 1.0))?;
        let mut k = 0;
        let mut bad = false;
        for lp in &src.loops {
            if matches!(&lp.params, Some(pc) if !pc.is_empty()) {
                if !lp.model.is_empty() && !params_match(&s, &m, &loops_2d[k], &lp.model, src) {
                    bad = true;
                }
                k += 1;
            }
        }
        if bad {
            warn.push(WarningKind::TrimSpacesDisagree);
            loops_2d.clear();
            tracks.clear();
            for lp in &src.loops {
                if lp.model.is_empty() {
                    return Err(TrimError::OffSurface);
                }
                tracks.push(sample_loop(def, lp.model.clone(), true, periods)?);
            }
        }
    }
    Ok((loops_2d, tracks))
}

/// What placing the loops on the surface gave: a face already (a single
/// loop round the rectangle of a plane), or the surface to fit them to.
enum Placed {
    Face(Face),
    Surface(FaceSurface, [AxisMap; 2]),
}

/// One window of the periods for all loops (the loops shifted into it; the
/// seam of a closed B-spline moved, or the surface unrolled, where they
/// straddle or wrap past it), then the surface over the NURBS range they need.
///
/// # Errors
/// An unbounded surface without loops, a seam that cannot be re-cut, or
/// loops the surface cannot be built under.
fn place_loops(
    src: &FaceSrc,
    def: &mut SurfDef,
    loops_2d: &mut [Vec<NurbsCurve>],
    tracks: &mut [Vec<Track>],
) -> Result<Placed, TrimError> {
    let (periods, natural) = (def.periods(), def.natural());
    let mut polys: Vec<Vec<DVec2>> = loops_2d.iter().map(|lp| pieces_poly(lp)).collect();
    polys.extend(tracks.iter().map(|lp| lp.iter().flat_map(|t| t.qs.iter().copied()).collect()));
    if polys.is_empty() {
        let [u, v] = natural;
        let (Some(u), Some(v)) = (u, v) else {
            return Err(TrimError::Unbounded);
        };
        let (surface, maps) = def.build(u, v)?;
        return Ok(Placed::Surface(surface, maps));
    }
    let (mut shifts, range) = windows(&polys, periods, natural)?;
    if def.fixed_domain() {
        // Loops straddling the seam of a closed B-spline: move the seam,
        // or unroll the surface over more than a period where they wrap further.
        let whole = def.build((0.0, 1.0), (0.0, 1.0))?.0;
        let [lo, hi] = whole.domain();
        for k in 0..2 {
            let (Some(p), (a, b)) = (periods[k], range[k]) else { continue };
            let eps = 1e-9 * p;
            if a >= lo[k] - eps && b <= hi[k] + eps {
                continue;
            }
            // Cuts a rounding off a knot line are made on it (see `snap_to_knot`).
            let knots = knot_lines(&whole, k);
            let cannot = TrimError::SeamRecut;
            if b - a > p * (1.0 + 1e-6) {
                let (a, b) = (snap_to_knot(&knots, Some(p), a, eps), snap_to_knot(&knots, Some(p), b, eps));
                *def = def.unroll(k == 0, a, b).ok_or(cannot)?;
                continue;
            }
            let c = lo[k] + (a - lo[k] - p * crate::math::floor((a - lo[k]) / p));
            let snapped = snap_to_knot(&knots, Some(p), c, eps);
            let c = if snapped > lo[k] && snapped < hi[k] { snapped } else { c };
            *def = def.rotate_seam(k == 0, c).ok_or(cannot)?;
            for s in &mut shifts {
                s[k] += c - a;
            }
        }
    }
    let n2d = loops_2d.len();
    for (lp, s) in loops_2d.iter_mut().zip(&shifts) {
        if *s != DVec2::ZERO {
            for c in lp.iter_mut() {
                *c = map_points(c, |p| p + s.extend(0.0))
                    .map_err(|error| TrimError::Geometry { part: "trim curve", error })?;
            }
        }
    }
    for (lp, s) in tracks.iter_mut().zip(&shifts[n2d..]) {
        for t in lp.iter_mut() {
            t.shift(*s);
        }
    }
    if let (true, [lp]) = (loops_2d.is_empty() && !src.domain_outer, &*tracks) {
        if let Some(face) = rectangle_face(def, lp)? {
            return Ok(Placed::Face(face));
        }
    }
    let (u, v) = if def.fixed_domain() {
        ((0.0, 1.0), (0.0, 1.0))
    } else {
        extents(def, tracks, periods, natural, src.domain_outer)?
    };
    let (surface, maps) = def.build(u, v)?;
    Ok(Placed::Surface(surface, maps))
}

/// Points along the pieces (17 per piece), a polygon of the loop.
fn pieces_poly(pieces: &[NurbsCurve]) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(17 * pieces.len());
    for c in pieces {
        let (a, b) = c.domain();
        out.extend((0..=16).map(|k| c.point(a + (b - a) * k as f64 / 16.0).truncate()));
    }
    out
}

/// Box of a loop's samples.
fn track_bounds(lp: &[Track]) -> (DVec2, DVec2) {
    lp.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), t| {
        let (a, b) = t.bounds();
        (lo.min(a), hi.max(b))
    })
}

/// A face whose only loop runs along the border of its own box in native
/// coordinates (a full cylinder between two circles, a dome closed at its
/// pole, a patch bounded by iso-curves) is that box of the surface,
/// untrimmed: made exactly over it (cut out of a B-spline surface), its
/// border is the surface's own and no trim curve runs along a pole.
fn rectangle_face(def: &SurfDef, lp: &[Track]) -> Result<Option<Face>, TrimError> {
    let (lo, hi) = track_bounds(lp);
    let span = hi - lo;
    if !(span.x > 0.0 && span.y > 0.0 && span.is_finite()) {
        return Ok(None);
    }
    let eps = 1e-9 * span + DVec2::splat(1e-12) * (lo.abs() + hi.abs());
    let on_border = |q: DVec2| {
        (q.x - lo.x).abs() <= eps.x
            || (q.x - hi.x).abs() <= eps.x
            || (q.y - lo.y).abs() <= eps.y
            || (q.y - hi.y).abs() <= eps.y
    };
    if !lp.iter().flat_map(|t| t.qs.iter()).all(|&q| on_border(q)) {
        return Ok(None);
    }
    // The loop must go round the whole border, not along part of it and back.
    let extra = alloc::vec![0.0; lp.len()];
    let area = loop_shape(lp, &extra, 0).area;
    if area.abs() < 0.999 * span.x * span.y {
        return Ok(None);
    }
    let surface = if def.fixed_domain() {
        let (whole, maps) = def.build((0.0, 1.0), (0.0, 1.0))?;
        if maps != [AxisMap::Identity; 2] {
            return Ok(None);
        }
        let FaceSurface::Nurbs(mut n) = whole else { return Ok(None) };
        let [dlo, dhi] = n.domain();
        let (mut lo, mut hi) = (lo, hi);
        for k in 0..2 {
            let tiny = 1e-9 * (dhi[k] - dlo[k]);
            let knots = n.breaks(k == 0);
            lo[k] = snap_to_knot(&knots, None, lo[k], tiny);
            hi[k] = snap_to_knot(&knots, None, hi[k], tiny);
            if lo[k] > dlo[k] + tiny {
                let Some((_, b)) = n.split(k == 0, lo[k]) else { return Ok(None) };
                n = b;
            }
            if hi[k] < dhi[k] - tiny {
                let Some((a, _)) = n.split(k == 0, hi[k]) else { return Ok(None) };
                n = a;
            }
        }
        FaceSurface::Nurbs(n)
    } else {
        def.build((lo.x, hi.x), (lo.y, hi.y))?.0
    };
    Ok(Some(Face { name: None, surface, loops: Vec::new() }))
}

/// The knot line nearest `t` when within `tiny` of it, else `t`: one of
/// `knots`, or one a whole number of `period`s from one. A loop's range comes
/// from projected samples a rounding off the knot line it runs along (a
/// sphere's quarter meridian); a cut there would leave a sliver span whose
/// derivatives are rounding noise, and the mesh would change with the rounding.
fn snap_to_knot(knots: &[f64], period: Option<f64>, t: f64, tiny: f64) -> f64 {
    let (mut best, mut off) = (t, tiny);
    for &k in knots {
        let turns = match period {
            Some(p) if p > 0.0 => crate::math::floor((t - k) / p + 0.5),
            _ => 0.0,
        };
        let x = k + turns * period.unwrap_or(0.0);
        if (x - t).abs() <= off {
            (best, off) = (x, (x - t).abs());
        }
    }
    best
}

/// The distinct knots along direction `k` (0: u) of a B-spline face surface
/// (an offset's base's), empty for any other.
fn knot_lines(s: &FaceSurface, k: usize) -> Vec<f64> {
    match s {
        FaceSurface::Nurbs(n) | FaceSurface::Rebuilt(n) => n.breaks(k == 0),
        FaceSurface::Offset { base, .. } => knot_lines(base, k),
    }
}

/// The native ranges the surface must cover: the loops' range plus a
/// margin, kept within the entity's own range where it has one.
fn extents(
    def: &SurfDef,
    tracks: &[Vec<Track>],
    periods: [Option<f64>; 2],
    natural: [Option<(f64, f64)>; 2],
    domain_outer: bool,
) -> Result<(Range, Range), TrimError> {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for lp in tracks {
        let (a, b) = track_bounds(lp);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let mut out = [(0.0, 0.0); 2];
    for k in 0..2 {
        let (lo, hi) = (lo[k], hi[k]);
        let span = hi - lo;
        if !span.is_finite() {
            return Err(TrimError::NoExtent);
        }
        let margin = if def.fixed_domain() { 0.0 } else { 0.01 * span + 1e-9 * (lo.abs() + hi.abs()).max(1e-9) };
        let (mut a, mut b) = (lo - margin, hi + margin);
        if let Some(p) = periods[k] {
            if b - a > p {
                let extra = (p - span).max(0.0);
                a = lo - 0.5 * extra;
                b = hi + 0.5 * extra;
            }
        } else if let Some((na, nb)) = natural[k] {
            // Stay within the entity's range unless the loops leave it.
            a = a.max(na).min(lo);
            b = b.min(nb).max(hi);
            if domain_outer {
                a = a.min(na);
                b = b.max(nb);
            }
        }
        if b.is_nan() || a.is_nan() || b <= a {
            return Err(TrimError::NoExtent);
        }
        out[k] = (a, b);
    }
    Ok((out[0], out[1]))
}

/// The entity's natural parameter rectangle in the NURBS parameters, within the domain.
fn natural_box(def: &SurfDef, lo: DVec2, hi: DVec2, maps: &[AxisMap; 2]) -> [DVec2; 2] {
    let nat = def.natural();
    let mut b = [lo, hi];
    for k in 0..2 {
        if let Some((a, z)) = nat[k] {
            b[0][k] = maps[k].apply(a).max(lo[k]);
            b[1][k] = maps[k].apply(z).min(hi[k]);
        }
    }
    b
}

fn rectangle(b: [DVec2; 2]) -> Result<TrimLoop, TrimError> {
    let [lo, hi] = b;
    let c = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let mut curves = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, z) = (c[k], c[(k + 1) % 4]);
        curves.push(
            line(a.extend(0.0), z.extend(0.0), 0.0, 1.0)
                .map_err(|error| TrimError::Geometry { part: "outer boundary", error })?,
        );
    }
    Ok(TrimLoop { curves })
}

/// Orients, splits at corners and samples one loop's curves.
fn sample_loop(
    def: &SurfDef,
    mut pieces: Vec<NurbsCurve>,
    model: bool,
    periods: [Option<f64>; 2],
) -> Result<Vec<Track>, TrimError> {
    orient_chain(&mut pieces);
    let mut bb = Aabb::EMPTY;
    for c in &pieces {
        bb.union(&c.bbox());
    }
    let tiny = 1e-9 * bb.diagonal().max(TINY);
    let mut out: Vec<Track> = Vec::new();
    for c in pieces {
        for part in split_at_corners(&c) {
            if model && curve_length(&part) <= tiny {
                continue; // a degenerate edge: the loop's closing joins its neighbours
            }
            let start = out.last().and_then(|t| t.qs.last().copied());
            out.push(Track::sample(def, part, model, start, periods));
        }
    }
    if out.is_empty() {
        return Err(TrimError::ZeroLength);
    }
    Ok(out)
}

/// Approximate length from 16 chords.
fn curve_length(c: &NurbsCurve) -> f64 {
    let (a, b) = c.domain();
    let mut len = 0.0;
    let mut prev = c.point(a);
    for k in 1..=16 {
        let p = c.point(a + (b - a) * k as f64 / 16.0);
        len += p.distance(prev);
        prev = p;
    }
    len
}

/// Splits a curve at inner knots of multiplicity ≥ degree (possible corners).
fn split_at_corners(c: &NurbsCurve) -> Vec<NurbsCurve> {
    let p = c.degree();
    let (a, b) = c.domain();
    let mut cuts = alloc::vec![a];
    for t in c.knots().breakpoints() {
        if t > a && t < b && c.knots().multiplicity(t) >= p {
            cuts.push(t);
        }
    }
    cuts.push(b);
    if cuts.len() == 2 || cuts.len() > 2048 {
        return alloc::vec![c.clone()];
    }
    let mut out = Vec::with_capacity(cuts.len() - 1);
    for w in cuts.windows(2) {
        match segment(c, w[0], w[1]) {
            Ok(s) => out.push(s),
            Err(_) => return alloc::vec![c.clone()],
        }
    }
    out
}

/// Reverses pieces whose far end continues the chain clearly better.
pub(super) fn orient_chain(pieces: &mut [NurbsCurve]) {
    let ends = |c: &NurbsCurve| {
        let (a, b) = c.domain();
        (c.point(a), c.point(b))
    };
    let n = pieces.len();
    if n < 2 {
        return;
    }
    let flip = |c: &mut NurbsCurve| {
        if let Ok(r) = reversed(c) {
            *c = r;
        }
    };
    // Gaps below this are rounding: a closed piece (a full circle) or an
    // exact joint gives no reason to flip.
    let mut bb = Aabb::EMPTY;
    for c in pieces.iter() {
        bb.union(&c.bbox());
    }
    let hair = 1e-9 * bb.diagonal().max(TINY);
    // First piece: the orientation whose end meets the second piece best.
    let (s0, e0) = ends(&pieces[0]);
    let (s1, e1) = ends(&pieces[1]);
    let keep = e0.distance(s1).min(e0.distance(e1));
    let swap = s0.distance(s1).min(s0.distance(e1));
    if keep > hair && swap < 0.5 * keep {
        flip(&mut pieces[0]);
    }
    for i in 1..n {
        let (_, prev_end) = ends(&pieces[i - 1]);
        let (s, e) = ends(&pieces[i]);
        let keep = prev_end.distance(s);
        if keep > hair && prev_end.distance(e) < 0.5 * keep {
            flip(&mut pieces[i]);
        }
    }
}

/// Do the parameter curves, on the surface, follow the model curves?
fn params_match(
    surface: &FaceSurface,
    maps: &[AxisMap; 2],
    pieces: &[NurbsCurve],
    model: &[NurbsCurve],
    src: &FaceSrc,
) -> bool {
    let mut bb = Aabb::EMPTY;
    for c in model {
        bb.union(&c.bbox());
    }
    let tol = (1e-3 * bb.diagonal()).max(10.0 * src.resolution.unwrap_or(0.0));
    let boxes: Vec<Aabb> = model.iter().map(NurbsCurve::bbox).collect();
    for c in pieces {
        let (a, b) = c.domain();
        for k in 0..5 {
            let t = a + (b - a) * (k as f64 + 0.5) / 5.0;
            let q = c.point(t).truncate();
            let p = surface.point(DVec2::new(maps[0].apply(q.x), maps[1].apply(q.y)));
            let mut best = f64::INFINITY;
            for (m, bx) in model.iter().zip(&boxes) {
                let gap = (bx.min - p).max(p - bx.max).max(DVec3::ZERO).length();
                if gap < best {
                    best = best.min(m.project(p).distance);
                }
            }
            if best.is_nan() || best > tol {
                return false;
            }
        }
    }
    true
}

/// A size for the fitting tolerance: the diagonal of the loops on the surface.
fn model_size(surface: &FaceSurface, tracks: &[Vec<Track>], direct: &[Vec<NurbsCurve>], maps: &[AxisMap; 2]) -> f64 {
    let mut bb = Aabb::EMPTY;
    for lp in tracks {
        for t in lp {
            let step = (t.qs.len() / 16).max(1);
            for q in t.qs.iter().step_by(step) {
                bb.add_point(surface.point(DVec2::new(maps[0].apply(q.x), maps[1].apply(q.y))));
            }
        }
    }
    for lp in direct {
        for c in lp {
            let (a, b) = c.domain();
            for k in 0..=8 {
                bb.add_point(surface.point(c.point(a + (b - a) * k as f64 / 8.0).truncate()));
            }
        }
    }
    if bb.is_empty() {
        surface.bounding_box().diagonal()
    } else {
        bb.diagonal()
    }
}

/// Joins the pieces into a closed loop: ends closer than a hair are made
/// equal, larger gaps get a straight connector (a degenerate edge at a pole
/// or a gap in the file).
fn close_loop(
    pieces: Vec<NurbsCurve>,
    surface: &FaceSurface,
    lo: DVec2,
    hi: DVec2,
    tol: f64,
    warn: &mut Vec<WarningKind>,
) -> Result<Option<TrimLoop>, TrimError> {
    // Pieces and gaps below a millionth of the domain are noise in the
    // file (a degenerate edge overshooting a corner): dropped and closed.
    let snap = 1e-6 * (hi - lo).max_element();
    let pieces: Vec<NurbsCurve> = pieces.into_iter().filter(|c| curve_length(c) > snap).collect();
    if pieces.is_empty() {
        return Ok(None);
    }
    let ends = |c: &NurbsCurve| {
        let (a, b) = c.domain();
        (c.point(a).truncate(), c.point(b).truncate())
    };
    let n = pieces.len();
    // New end points per piece, and connectors after each piece.
    let mut starts: Vec<DVec2> = pieces.iter().map(|c| ends(c).0).collect();
    let mut finishes: Vec<DVec2> = pieces.iter().map(|c| ends(c).1).collect();
    let mut connectors: Vec<Option<(DVec2, DVec2)>> = alloc::vec![None; n];
    let mut worst_gap: f64 = 0.0;
    for i in 0..n {
        let j = (i + 1) % n;
        let (e, s) = (finishes[i], starts[j]);
        let gap = e.distance(s);
        if gap <= snap {
            let m = (e + s) * 0.5;
            finishes[i] = m;
            starts[j] = m;
        } else {
            let model_gap = surface.point(e).distance(surface.point(s));
            if model_gap > 10.0 * tol {
                worst_gap = worst_gap.max(model_gap);
            }
            connectors[i] = Some((e, s));
        }
    }
    if worst_gap > 0.0 {
        warn.push(WarningKind::TrimGapClosed { gap: worst_gap });
    }
    let mut curves = Vec::with_capacity(2 * n);
    for (i, c) in pieces.iter().enumerate() {
        let moved = with_end_points(c, starts[i].extend(0.0), finishes[i].extend(0.0))
            .map_err(|error| TrimError::Geometry { part: "trim curve", error })?;
        curves.push(moved);
        if let Some((a, b)) = connectors[i] {
            curves.push(
                line(a.extend(0.0), b.extend(0.0), 0.0, 1.0)
                    .map_err(|error| TrimError::Geometry { part: "connector", error })?,
            );
        }
    }
    let crossings = untangle(&mut curves);
    if crossings > 0 {
        warn.push(WarningKind::TrimSelfCrossing { crossings });
    }
    Ok(Some(TrimLoop { curves }))
}
