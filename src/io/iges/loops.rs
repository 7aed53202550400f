//! One face from a surface definition and its boundary loops: choose per
//! loop between the file's parameter-space curves and projecting its
//! model-space curves, make the loops continuous across seams, size the
//! surface's NURBS to them, fit the curves in its parameters and close every
//! loop exactly (end of each curve = start of the next).

use alloc::string::String;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::fit::{unwrap_near, Track};
use super::surfaces::{AxisMap, Profile, SurfDef};
use super::untangle::untangle;
use crate::model::{Face, FaceSurface, TrimLoop};
use crate::nurbs::analytic::line;
use crate::nurbs::reparam::{map_points, reversed, segment, with_end_points};
use crate::nurbs::{Aabb, NurbsCurve, Surface};

/// A closed interval `(low, high)` of one coordinate.
type Range = (f64, f64);

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
pub(in crate::io) fn build_face(src: FaceSrc, warn: &mut Vec<String>) -> Result<Face, String> {
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
    warn: &mut Vec<String>,
) -> Result<Face, String> {
    let mut def = src.def.clone();
    let periods = def.periods();
    let natural = def.natural();
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
            (Some(pc), true) if !pc.is_empty() => tracks.push(sample_loop(&def, pc.clone(), false, periods)?),
            _ if !lp.model.is_empty() => tracks.push(sample_loop(&def, lp.model.clone(), true, periods)?),
            (Some(_), false) => {
                return Err("parameter-space trim curves on a surface whose parameters are not read, \
                            and no model-space curves"
                    .into())
            }
            _ => return Err("a boundary loop without curves".into()),
        }
    }
    // Check the file's parameter curves against its model-space ones.
    if direct && !loops_2d.is_empty() {
        let (s, m) = def.build((0.0, 1.0), (0.0, 1.0))?;
        let mut k = 0;
        let mut bad = false;
        for lp in &src.loops {
            if matches!(&lp.params, Some(pc) if !pc.is_empty()) {
                if !lp.model.is_empty() && !params_match(&s, &m, &loops_2d[k], &lp.model, &src) {
                    bad = true;
                }
                k += 1;
            }
        }
        if bad {
            warn.push("parameter-space trim curves disagree with the model-space ones; projected instead".into());
            loops_2d.clear();
            tracks.clear();
            for lp in &src.loops {
                if lp.model.is_empty() {
                    return Err("parameter-space trim curves off the surface and no model-space curves".into());
                }
                tracks.push(sample_loop(&def, lp.model.clone(), true, periods)?);
            }
        }
    }
    // Each sampled loop continuous; those going round a period closed or joined.
    let windings: Vec<[i64; 2]> = tracks.iter_mut().map(|lp| chain_loop(lp, periods, left)).collect();
    resolve_windings(&def, &mut tracks, &windings, periods, natural, left)?;
    // One window of the periods for all loops; the NURBS range.
    let mut bounds: Vec<(DVec2, DVec2)> = loops_2d.iter().map(|lp| pieces_bounds(lp)).collect();
    bounds.extend(tracks.iter().map(|lp| track_bounds(lp)));
    let (surface, maps) = if bounds.is_empty() {
        let [u, v] = natural;
        let (Some(u), Some(v)) = (u, v) else {
            return Err("an unbounded surface without trim curves".into());
        };
        def.build(u, v)?
    } else {
        let (mut shifts, range) = windows(&bounds, periods, natural)?;
        if def.fixed_domain() {
            // Loops straddling the seam of a closed B-spline: move the seam.
            let [lo, hi] = def.build((0.0, 1.0), (0.0, 1.0))?.0.domain();
            for k in 0..2 {
                let (Some(p), (a, b)) = (periods[k], range[k]) else { continue };
                let eps = 1e-9 * p;
                if a >= lo[k] - eps && b <= hi[k] + eps {
                    continue;
                }
                let c = lo[k] + (a - lo[k] - p * libm::floor((a - lo[k]) / p));
                def = def
                    .rotate_seam(k == 0, c)
                    .ok_or("trim loops cross the seam of a closed surface that cannot be re-cut there")?;
                for s in &mut shifts {
                    s[k] += c - a;
                }
            }
        }
        let n2d = loops_2d.len();
        for (lp, s) in loops_2d.iter_mut().zip(&shifts) {
            if *s != DVec2::ZERO {
                for c in lp.iter_mut() {
                    *c = map_points(c, |p| p + s.extend(0.0)).map_err(|e| alloc::format!("trim curve: {e}"))?;
                }
            }
        }
        for (lp, s) in tracks.iter_mut().zip(&shifts[n2d..]) {
            for t in lp.iter_mut() {
                t.shift(*s);
            }
        }
        if let (true, [lp]) = (loops_2d.is_empty() && !src.domain_outer, tracks.as_slice()) {
            if let Some(face) = rectangle_face(&def, lp)? {
                return Ok(face);
            }
        }
        let (u, v) = if def.fixed_domain() {
            ((0.0, 1.0), (0.0, 1.0))
        } else {
            extents(&def, &tracks, periods, natural, src.domain_outer)?
        };
        def.build(u, v)?
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
        warn.push(alloc::format!("{unmet} trim curves fitted to within the sample limit only"));
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

/// Box of points along the pieces (17 per piece).
fn pieces_bounds(pieces: &[NurbsCurve]) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for c in pieces {
        let (a, b) = c.domain();
        for k in 0..=16 {
            let q = c.point(a + (b - a) * k as f64 / 16.0).truncate();
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    (lo, hi)
}

/// Box of a loop's samples.
fn track_bounds(lp: &[Track]) -> (DVec2, DVec2) {
    lp.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), t| {
        let (a, b) = t.bounds();
        (lo.min(a), hi.max(b))
    })
}

/// How good a choice of turns at a loop's pole junctions is, compared in
/// order: the loop closes, spans at most one period, has the orientation
/// asked for, and moves fewest junctions (negated).
type PoleChoice = (bool, bool, bool, i64);

/// Makes a sampled loop continuous piece to piece (each piece moved by
/// whole periods to start where the previous one ends) and returns the
/// whole turns it makes around each periodic coordinate.
///
/// Where two pieces meet at a point whose coordinate is arbitrary there (a
/// pole), the nearest period is no guide: knowing the face's side (`left`),
/// up to four such junctions are tried one period either way, and the
/// choice that closes the loop with the orientation the face asks for
/// (counter-clockwise when the face is on the left), spanning at most one
/// period, is kept.
fn chain_loop(lp: &mut [Track], periods: [Option<f64>; 2], left: Option<bool>) -> [i64; 2] {
    let n = lp.len();
    for i in 1..n {
        if let (Some(&p), Some(&f)) = (lp[i - 1].qs.last(), lp[i].qs.first()) {
            let shift = unwrap_near(f, p, periods) - f;
            lp[i].shift(shift);
        }
    }
    let mut winding = [0i64; 2];
    for k in 0..2 {
        let Some(p) = periods[k] else { continue };
        let pole_at: Vec<bool> = (0..n).map(|j| lp[(j + n - 1) % n].free_ends[1][k] || lp[j].free_ends[0][k]).collect();
        let poles: Vec<usize> = (1..n).filter(|&j| pole_at[j]).collect();
        if let (Some(left), true) = (left, !poles.is_empty() && poles.len() <= 4) {
            let want = if left { 1.0 } else { -1.0 };
            let closes_at_pole = pole_at.first().copied().unwrap_or(false);
            let mut best: Option<(PoleChoice, Vec<f64>)> = None;
            for code in 0..3usize.pow(poles.len() as u32) {
                // Extra turns at each pole junction, carried to every later piece.
                let mut extra = alloc::vec![0.0; n];
                let (mut c, mut acc, mut moved) = (code, 0.0, 0i64);
                for j in 1..n {
                    if poles.contains(&j) {
                        let turn = (c % 3) as i64 - 1;
                        c /= 3;
                        acc += turn as f64 * p;
                        moved += turn.abs();
                    }
                    extra[j] = acc;
                }
                let (area, lo, hi, first, last) = loop_shape(lp, &extra, k);
                let turns = if closes_at_pole { 0 } else { libm::round((last - first) / p) as i64 };
                let key = (turns == 0, hi - lo <= p * (1.0 + 1e-6), area * want > 0.0, -moved);
                if best.as_ref().is_none_or(|(b, _)| key > *b) {
                    best = Some((key, extra));
                }
            }
            if let Some((_, extra)) = best {
                for (t, d) in lp.iter_mut().zip(extra) {
                    let mut v = DVec2::ZERO;
                    v[k] = d;
                    t.shift(v);
                }
            }
        }
        let first = lp.first().and_then(|t| t.qs.first()).map_or(0.0, |q| q[k]);
        let last = lp.last().and_then(|t| t.qs.last()).map_or(0.0, |q| q[k]);
        // Whole turns only: a loop whose ends are apart by a fraction of a
        // turn has a gap in it (closed by a connector later), not a turn.
        let turns = libm::round((last - first) / p);
        let whole = (last - first - turns * p).abs() <= 0.01 * p;
        winding[k] = if pole_at.first().copied().unwrap_or(false) || !whole { 0 } else { turns as i64 };
    }
    winding
}

/// Signed area of the polygon through a loop's samples (piece `i` moved by
/// `extra[i]` along coordinate `k`), the range of `k`, and its first and last value.
fn loop_shape(lp: &[Track], extra: &[f64], k: usize) -> (f64, f64, f64, f64, f64) {
    let mut area = 0.0;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut first: Option<DVec2> = None;
    let mut prev: Option<DVec2> = None;
    for (t, &d) in lp.iter().zip(extra) {
        for &q in &t.qs {
            let mut q = q;
            q[k] += d;
            lo = lo.min(q[k]);
            hi = hi.max(q[k]);
            match prev {
                Some(p) => area += p.perp_dot(q),
                None => first = Some(q),
            }
            prev = Some(q);
        }
    }
    if let (Some(p), Some(f)) = (prev, first) {
        area += p.perp_dot(f);
        return (0.5 * area, lo, hi, f[k], p[k]);
    }
    (0.0, lo, hi, 0.0, 0.0)
}

/// Loops that go round a periodic coordinate bound the face only with a
/// partner: two going opposite ways are joined into one by two links along
/// the seam; a single one is closed along the pole or boundary on the
/// face's side (which `left` tells).
fn resolve_windings(
    def: &SurfDef,
    tracks: &mut Vec<Vec<Track>>,
    windings: &[[i64; 2]],
    periods: [Option<f64>; 2],
    natural: [Option<Range>; 2],
    left: Option<bool>,
) -> Result<(), String> {
    let mut windings = windings.to_vec();
    for k in 0..2 {
        let Some(p) = periods[k] else { continue };
        let idx: Vec<usize> = (0..tracks.len()).filter(|&i| windings[i][k] != 0).collect();
        match idx.as_slice() {
            [] => {}
            [i] => {
                let side = left.ok_or("a trim loop winds around the surface's seam (not supported)")?;
                let at = tracks[*i].first().and_then(|t| t.qs.first()).map_or(0.0, |q| q[1 - k]);
                close_at_bound(&mut tracks[*i], k, windings[*i][k], side, bounds_of(def, natural, 1 - k, at))?;
                windings[*i][k] = 0;
            }
            [i, j] if windings[*i][k] == -windings[*j][k] => {
                let b = tracks.remove(*j);
                let a = tracks.remove(*i);
                windings.remove(*j);
                windings.remove(*i);
                tracks.push(join_across_seam(def, a, b, k, p, periods)?);
                windings.push([0; 2]);
            }
            _ => {
                return Err(alloc::format!(
                    "{} trim loops go round the surface's periodic direction; cannot tell how they bound the face",
                    idx.len()
                ))
            }
        }
    }
    Ok(())
}

/// The range native coordinate `k` is confined to: the entity's own, or
/// for a cone's profile the side of its apex that holds `at` (a cone is
/// both its nappes, and a loop may lie on either).
fn bounds_of(def: &SurfDef, natural: [Option<Range>; 2], k: usize, at: f64) -> Option<Range> {
    if let Some(r) = natural[k] {
        return Some(r);
    }
    let mut d = def;
    while let SurfDef::Offset { base, .. } = d {
        d = base;
    }
    match d {
        SurfDef::Revolution(r) if k == 0 => match &r.profile {
            Profile::Line { p0, d } if d.x != 0.0 => {
                let apex = -p0.x / d.x;
                Some(if at > apex { (apex, f64::INFINITY) } else { (f64::NEG_INFINITY, apex) })
            }
            _ => None,
        },
        _ => None,
    }
}

/// Closes a loop going `turns` times round coordinate `k` along the bound
/// of the other coordinate on the face's side: down to it, along it, back.
fn close_at_bound(lp: &mut Vec<Track>, k: usize, turns: i64, left: bool, nat: Option<Range>) -> Result<(), String> {
    let o = 1 - k;
    // Going +k, the left side is +o for k = 0 and −o for k = 1.
    let side = if k == 0 { 1.0 } else { -1.0 } * turns.signum() as f64 * if left { 1.0 } else { -1.0 };
    let bound = nat.map(|(a, b)| if side > 0.0 { b } else { a }).filter(|x| x.is_finite());
    let Some(bound) = bound else {
        return Err("a trim loop goes round a surface that is unbounded on the face's side".into());
    };
    let (Some(s), Some(e)) =
        (lp.first().and_then(|t| t.qs.first().copied()), lp.last().and_then(|t| t.qs.last().copied()))
    else {
        return Err("an empty trim loop".into());
    };
    let (mut e2, mut s2) = (e, s);
    e2[o] = bound;
    s2[o] = bound;
    for (a, b) in [(e, e2), (e2, s2), (s2, s)] {
        if a.distance(b) > 0.0 {
            lp.push(Track::link(a, b).ok_or("a link along the surface's bound could not be made")?);
        }
    }
    Ok(())
}

/// One loop from `a` and `b`, which go round coordinate `k` opposite ways:
/// `b` is cut where it crosses `a`'s start (modulo the period) and rotated
/// to start there, then `a`, a link along the seam, `b`, and a link back.
fn join_across_seam(
    def: &SurfDef,
    mut a: Vec<Track>,
    mut b: Vec<Track>,
    k: usize,
    p: f64,
    periods: [Option<f64>; 2],
) -> Result<Vec<Track>, String> {
    let (Some(a0), Some(a1)) =
        (a.first().and_then(|t| t.qs.first().copied()), a.last().and_then(|t| t.qs.last().copied()))
    else {
        return Err("an empty trim loop".into());
    };
    let c = a0[k];
    let b_turn =
        b.last().and_then(|t| t.qs.last()).zip(b.first().and_then(|t| t.qs.first())).map_or(0.0, |(l, f)| l[k] - f[k]);
    let b_turn = libm::round(b_turn / p) * p;
    // Rotate b to start where it crosses c (mod p): at a track's first
    // sample when one lies on that line (pieces of a circle often meet
    // exactly there), else inside the first track that crosses it.
    let on_line = |q: &DVec2| {
        let r = (q[k] - c) - p * libm::floor((q[k] - c) / p);
        r.min(p - r) <= 1e-9 * p
    };
    let mut rotated: Vec<Track> = Vec::with_capacity(b.len() + 1);
    let mut shift = DVec2::ZERO;
    shift[k] = b_turn;
    if let Some(i) = b.iter().position(|t| t.qs.first().is_some_and(on_line)) {
        rotated.extend(b[i..].iter().cloned());
        for t in &b[..i] {
            let mut t = t.clone();
            t.shift(shift);
            rotated.push(t);
        }
    } else {
        let mut cut = None;
        for (i, t) in b.iter_mut().enumerate() {
            if let Some(parts) = t.split_at(def, k, c, p, periods) {
                cut = Some((i, parts));
                break;
            }
        }
        let Some((i, (head, tail))) = cut else {
            return Err("a trim loop going round the surface does not cross its partner's seam".into());
        };
        rotated.push(tail);
        rotated.extend(b.iter().skip(i + 1).cloned());
        for t in b.iter().take(i).cloned().chain(core::iter::once(head)) {
            let mut t = t;
            t.shift(shift);
            rotated.push(t);
        }
    }
    // Line b's start up with a's end.
    let b0 = rotated.first().and_then(|t| t.qs.first().copied()).unwrap_or(a1);
    let mut shift = DVec2::ZERO;
    shift[k] = libm::round((a1[k] - b0[k]) / p) * p;
    for t in &mut rotated {
        t.shift(shift);
    }
    let b0 = rotated.first().and_then(|t| t.qs.first().copied()).unwrap_or(a1);
    let b1 = rotated.last().and_then(|t| t.qs.last().copied()).unwrap_or(a0);
    if a1.distance(b0) > 0.0 {
        a.push(Track::link(a1, b0).ok_or("a link along the seam could not be made")?);
    }
    a.extend(rotated);
    if b1.distance(a0) > 0.0 {
        a.push(Track::link(b1, a0).ok_or("a link along the seam could not be made")?);
    }
    Ok(a)
}

/// A face whose only loop runs along the border of its own box in native
/// coordinates (a full cylinder between two circles, a dome closed at its
/// pole, a patch bounded by iso-curves) is that box of the surface,
/// untrimmed: made exactly over it (cut out of a B-spline surface), its
/// border is the surface's own and no trim curve runs along a pole.
fn rectangle_face(def: &SurfDef, lp: &[Track]) -> Result<Option<Face>, String> {
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
    let (area, ..) = loop_shape(lp, &extra, 0);
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
        for k in 0..2 {
            let tiny = 1e-9 * (dhi[k] - dlo[k]);
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

/// Whole-period shifts per loop that put all loops in one window of each
/// periodic coordinate (starting at the entity's natural start when that
/// works as well as any), and the loops' range after the shifts.
fn windows(
    bounds: &[(DVec2, DVec2)],
    periods: [Option<f64>; 2],
    natural: [Option<(f64, f64)>; 2],
) -> Result<(Vec<DVec2>, [Range; 2]), String> {
    let mut shifts = alloc::vec![DVec2::ZERO; bounds.len()];
    let mut range = [(0.0, 0.0); 2];
    for k in 0..2 {
        let lo_all = bounds.iter().map(|b| b.0[k]).fold(f64::INFINITY, f64::min);
        let hi_all = bounds.iter().map(|b| b.1[k]).fold(f64::NEG_INFINITY, f64::max);
        range[k] = (lo_all, hi_all);
        let Some(p) = periods[k] else { continue };
        let mut starts: Vec<f64> = Vec::new();
        if let Some((a, _)) = natural[k] {
            starts.push(a);
        }
        starts.extend(bounds.iter().map(|b| b.0[k]));
        let eps = 1e-9 * p;
        let mut best: Option<(f64, Vec<f64>, f64, f64)> = None;
        for &s in &starts {
            let mut sh = Vec::with_capacity(bounds.len());
            let (mut wlo, mut whi) = (f64::INFINITY, f64::NEG_INFINITY);
            for b in bounds {
                let d = libm::ceil((s - eps - b.0[k]) / p) * p;
                sh.push(d);
                wlo = wlo.min(b.0[k] + d);
                whi = whi.max(b.1[k] + d);
            }
            let span = whi - wlo;
            if best.as_ref().is_none_or(|x| span < x.0 - eps) {
                best = Some((span, sh, wlo, whi));
            }
        }
        if let Some((span, sh, wlo, whi)) = best {
            if span > p * (1.0 + 1e-9) {
                return Err("the trim loops span more than one turn of the surface".into());
            }
            for (s, d) in shifts.iter_mut().zip(sh) {
                s[k] = d;
            }
            range[k] = (wlo, whi);
        }
    }
    Ok((shifts, range))
}

/// The native ranges the surface must cover: the loops' range plus a
/// margin, kept within the entity's own range where it has one.
fn extents(
    def: &SurfDef,
    tracks: &[Vec<Track>],
    periods: [Option<f64>; 2],
    natural: [Option<(f64, f64)>; 2],
    domain_outer: bool,
) -> Result<(Range, Range), String> {
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
            return Err("trim loops with no extent".into());
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
            return Err("trim loops with no extent".into());
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

fn rectangle(b: [DVec2; 2]) -> Result<TrimLoop, String> {
    let [lo, hi] = b;
    let c = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let mut curves = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, z) = (c[k], c[(k + 1) % 4]);
        curves.push(line(a.extend(0.0), z.extend(0.0), 0.0, 1.0).map_err(|e| alloc::format!("outer boundary: {e}"))?);
    }
    Ok(TrimLoop { curves })
}

/// Orients, splits at corners and samples one loop's curves.
fn sample_loop(
    def: &SurfDef,
    mut pieces: Vec<NurbsCurve>,
    model: bool,
    periods: [Option<f64>; 2],
) -> Result<Vec<Track>, String> {
    orient_chain(&mut pieces);
    let mut bb = Aabb::EMPTY;
    for c in &pieces {
        bb.union(&c.bbox());
    }
    let tiny = 1e-9 * bb.diagonal().max(1e-300);
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
        return Err("a boundary loop of zero length".into());
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
    let hair = 1e-9 * bb.diagonal().max(1e-300);
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
                    best = best.min(m.project(p).2);
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
    warn: &mut Vec<String>,
) -> Result<Option<TrimLoop>, String> {
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
        warn.push(alloc::format!("trim loop with a gap of {worst_gap:.3e} between curves, closed by a line"));
    }
    let mut curves = Vec::with_capacity(2 * n);
    for (i, c) in pieces.iter().enumerate() {
        let moved = with_end_points(c, starts[i].extend(0.0), finishes[i].extend(0.0))
            .map_err(|e| alloc::format!("trim curve: {e}"))?;
        curves.push(moved);
        if let Some((a, b)) = connectors[i] {
            curves.push(line(a.extend(0.0), b.extend(0.0), 0.0, 1.0).map_err(|e| alloc::format!("connector: {e}"))?);
        }
    }
    let crossings = untangle(&mut curves);
    if crossings > 0 {
        warn.push(alloc::format!("trim loop crossed itself {crossings} times (edges meeting tangentially); cut there"));
    }
    Ok(Some(TrimLoop { curves }))
}
