//! Loops on closed surfaces, lifted into the surface's covering space
//! (paper 000 §3.2 meshes one sheet of parameters; a cylinder, cone,
//! sphere, torus or periodic B-spline is one sheet only once cut): each
//! loop is made continuous across the seam and its turns counted; loops
//! going round are closed at a pole or bound, or joined in pairs along a cut
//! chosen where it crosses nothing else; all loops are then placed in one
//! window of the periods, wider than a period where the face wraps further.

use alloc::vec::Vec;
use glam::DVec2;

use super::fit::{unwrap_near, Track};
use super::surfaces::{Profile, SurfDef};
use crate::nurbs::NurbsError;

/// A closed interval `(low, high)` of one coordinate.
pub(super) type Range = (f64, f64);

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
pub(super) fn chain_loop(lp: &mut [Track], periods: [Option<f64>; 2], left: Option<bool>) -> [i64; 2] {
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
                let LoopShape { area, lo, hi, first, last } = loop_shape(lp, &extra, k);
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

/// What [`loop_shape`] measures of a loop along one coordinate.
pub(super) struct LoopShape {
    /// Signed area of the polygon through the loop's samples.
    pub area: f64,
    /// Smallest and largest value of the coordinate.
    pub lo: f64,
    pub hi: f64,
    /// The coordinate's value at the loop's first and last sample.
    pub first: f64,
    pub last: f64,
}

/// The shape of the polygon through a loop's samples, piece `i` moved by
/// `extra[i]` along coordinate `k`: its signed area, and the range and the
/// first and last value of `k`.
pub(super) fn loop_shape(lp: &[Track], extra: &[f64], k: usize) -> LoopShape {
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
        return LoopShape { area: 0.5 * area, lo, hi, first: f[k], last: p[k] };
    }
    LoopShape { area: 0.0, lo, hi, first: 0.0, last: 0.0 }
}

/// Loops that go round a periodic coordinate bound the face only with a
/// partner: two going opposite ways are joined into one by two links along
/// the seam; a single one is closed along the pole or boundary on the
/// face's side (which `left` tells).
pub(super) fn resolve_windings(
    def: &SurfDef,
    tracks: &mut Vec<Vec<Track>>,
    windings: &[[i64; 2]],
    periods: [Option<f64>; 2],
    natural: [Option<Range>; 2],
    left: Option<bool>,
) -> Result<(), TrimError> {
    let mut windings = windings.to_vec();
    for k in 0..2 {
        let Some(p) = periods[k] else { continue };
        let idx: Vec<usize> = (0..tracks.len()).filter(|&i| windings[i][k] != 0).collect();
        match idx.as_slice() {
            [] => {}
            [i] => {
                let side = left.ok_or(TrimError::SeamWinding)?;
                let at = tracks[*i].first().and_then(|t| t.qs.first()).map_or(0.0, |q| q[1 - k]);
                close_at_bound(&mut tracks[*i], k, windings[*i][k], side, bounds_of(def, natural, 1 - k, at))?;
                windings[*i][k] = 0;
            }
            [i, j] if windings[*i][k] == -windings[*j][k] => {
                let others: Vec<Vec<Track>> =
                    tracks.iter().enumerate().filter(|(x, _)| x != i && x != j).map(|(_, t)| t.clone()).collect();
                let b = tracks.remove(*j);
                let a = tracks.remove(*i);
                windings.remove(*j);
                windings.remove(*i);
                tracks.push(join_across_seam(def, a, b, &others, k, p, periods)?);
                windings.push([0; 2]);
            }
            _ => return Err(TrimError::PeriodicLoops(idx.len())),
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
fn close_at_bound(lp: &mut Vec<Track>, k: usize, turns: i64, left: bool, nat: Option<Range>) -> Result<(), TrimError> {
    let o = 1 - k;
    // Going +k, the left side is +o for k = 0 and −o for k = 1.
    let side = if k == 0 { 1.0 } else { -1.0 } * turns.signum() as f64 * if left { 1.0 } else { -1.0 };
    let bound = nat.map(|(a, b)| if side > 0.0 { b } else { a }).filter(|x| x.is_finite());
    let Some(bound) = bound else {
        return Err(TrimError::UnboundedSide);
    };
    let (Some(s), Some(e)) =
        (lp.first().and_then(|t| t.qs.first().copied()), lp.last().and_then(|t| t.qs.last().copied()))
    else {
        return Err(TrimError::EmptyLoop);
    };
    let (mut e2, mut s2) = (e, s);
    e2[o] = bound;
    s2[o] = bound;
    for (a, b) in [(e, e2), (e2, s2), (s2, s)] {
        if a.distance(b) > 0.0 {
            lp.push(Track::link(a, b).ok_or(TrimError::BoundLink)?);
        }
    }
    Ok(())
}

/// Where a loop crosses a line `x_k = at`: the track, the sample interval
/// (`sample`, `sample + 1`) and the crossing's other coordinate.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    track: usize,
    sample: usize,
    other: f64,
    at: f64,
}

/// The crossings of a lifted loop with the lines `x_k = c + m·p` (every
/// `m`), in loop order. A sample on a line counts once where the loop
/// passes it, twice where it touches the line from above and not at all
/// from below, so the count's parity is right.
fn crossings(lp: &[Track], k: usize, c: f64, p: f64) -> Vec<Crossing> {
    let o = 1 - k;
    let mut out = Vec::new();
    for (ti, t) in lp.iter().enumerate() {
        for j in 0..t.qs.len().saturating_sub(1) {
            let (q0, q1) = (t.qs[j], t.qs[j + 1]);
            let (lo, hi) = if q0[k] <= q1[k] { (q0[k], q1[k]) } else { (q1[k], q0[k]) };
            if hi.partial_cmp(&lo) != Some(core::cmp::Ordering::Greater) {
                continue;
            }
            let mut m = crate::math::ceil((lo - c) / p);
            while c + m * p < hi && out.len() < 4096 {
                let at = c + m * p;
                let f = (at - q0[k]) / (q1[k] - q0[k]);
                out.push(Crossing { track: ti, sample: j, other: q0[o] + (q1[o] - q0[o]) * f, at });
                m += 1.0;
            }
        }
    }
    out
}

/// Cut lines tried for joining two loops that go round: `a`'s start first
/// (where a clean cut leaves every face that meshed before unchanged), then
/// lines spread over the period.
const CUT_TRIES: usize = 48;

/// Where to cut the face between `a` and `b`, which go round coordinate `k`
/// opposite ways: a line `x_k = c` and one crossing of each loop with it,
/// next to each other along the line with no loop crossing between them, so
/// the link between the two crossings runs inside the face. A line each
/// loop crosses once is taken first; a wavy loop that no line crosses once
/// is cut where two of its crossings face the partner's.
fn choose_cut(a: &[Track], b: &[Track], others: &[Vec<Track>], k: usize, p: f64) -> Option<(Crossing, Crossing)> {
    let start = *a.first()?.qs.first()?;
    let a0 = start[k];
    let mut fallback: Option<(usize, Crossing, Crossing)> = None;
    for j in 0..CUT_TRIES {
        let c = a0 + p * j as f64 / CUT_TRIES as f64;
        let (mut xa, xb) = (crossings(a, k, c, p), crossings(b, k, c, p));
        if j == 0 {
            // `a`'s own start lies on the first line (even where the loop
            // runs along it there): cut there when nothing is in the way.
            let s = Crossing { track: 0, sample: 0, other: start[1 - k], at: a0 };
            xa.retain(|x| !(x.track == 0 && x.sample == 0));
            xa.insert(0, s);
            let xo: Vec<f64> = others.iter().flat_map(|lp| crossings(lp, k, c, p)).map(|x| x.other).collect();
            for y in &xb {
                let (lo, hi) = if s.other <= y.other { (s.other, y.other) } else { (y.other, s.other) };
                let between = |z: f64| z > lo && z < hi;
                if !(xa[1..].iter().any(|z| between(z.other))
                    || xb.iter().any(|z| between(z.other))
                    || xo.iter().any(|&z| between(z)))
                {
                    return Some((s, *y));
                }
            }
            continue;
        }
        let xo: Vec<f64> = others.iter().flat_map(|lp| crossings(lp, k, c, p)).map(|x| x.other).collect();
        let total = xa.len() + xb.len() + xo.len();
        let mut pair = None;
        'outer: for (ia, x) in xa.iter().enumerate() {
            for (ib, y) in xb.iter().enumerate() {
                let (lo, hi) = if x.other <= y.other { (x.other, y.other) } else { (y.other, x.other) };
                let between = |z: f64| z > lo && z < hi;
                let blocked = xa.iter().enumerate().any(|(i, z)| i != ia && between(z.other))
                    || xb.iter().enumerate().any(|(i, z)| i != ib && between(z.other))
                    || xo.iter().any(|&z| between(z));
                if !blocked {
                    pair = Some((*x, *y));
                    break 'outer;
                }
            }
        }
        let Some((x, y)) = pair else { continue };
        if xa.len() == 1 && xb.len() == 1 {
            return Some((x, y));
        }
        if fallback.as_ref().is_none_or(|f| total < f.0) {
            fallback = Some((total, x, y));
        }
    }
    fallback.map(|(_, x, y)| (x, y))
}

/// The loop started at crossing `x`: the rest of its track, the tracks
/// after it, then the tracks before it and the first part of its track,
/// moved by the loop's own turn `turn` so the whole stays continuous.
fn rotate_at(
    def: &SurfDef,
    mut lp: Vec<Track>,
    x: &Crossing,
    k: usize,
    turn: DVec2,
    periods: [Option<f64>; 2],
) -> Result<Vec<Track>, TrimError> {
    let i = x.track;
    let (head, tail) = {
        let t = lp.get_mut(i).ok_or(TrimError::CutOutside)?;
        let at_sample = |j: usize| t.qs.get(j).is_some_and(|q| q[k] == x.at);
        if at_sample(x.sample) {
            t.cut_at_sample(x.sample)
        } else if at_sample(x.sample + 1) {
            t.cut_at_sample(x.sample + 1)
        } else {
            t.split_in(def, x.sample, k, x.at, periods)
        }
    };
    let mut out: Vec<Track> = Vec::with_capacity(lp.len() + 1);
    out.extend(tail);
    out.extend(lp.iter().skip(i + 1).cloned());
    for t in lp.iter().take(i).cloned().chain(head) {
        let mut t = t;
        t.shift(turn);
        out.push(t);
    }
    if out.is_empty() {
        return Err(TrimError::EmptyLoop);
    }
    Ok(out)
}

/// First and last sample of a loop.
fn ends(lp: &[Track]) -> Option<(DVec2, DVec2)> {
    Some((*lp.first()?.qs.first()?, *lp.last()?.qs.last()?))
}

/// One loop from `a` and `b`, which go round coordinate `k` opposite ways:
/// both are cut where a line `x_k = c` crosses them next to each other
/// ([`choose_cut`]; `others` are the face's other loops, which the cut must
/// not cross), then `a` from its cut, a link along the line, `b` from its
/// cut, and a link back: the face cut open along the seam line.
fn join_across_seam(
    def: &SurfDef,
    a: Vec<Track>,
    b: Vec<Track>,
    others: &[Vec<Track>],
    k: usize,
    p: f64,
    periods: [Option<f64>; 2],
) -> Result<Vec<Track>, TrimError> {
    let (Some((a0, a1)), Some((b0, b1))) = (ends(&a), ends(&b)) else {
        return Err(TrimError::EmptyLoop);
    };
    let lift = |s: DVec2, e: DVec2| {
        let mut v = DVec2::ZERO;
        v[k] = libm::round((e[k] - s[k]) / p) * p;
        v
    };
    let (turn_a, turn_b) = (lift(a0, a1), lift(b0, b1));
    let (xa, xb) = choose_cut(&a, &b, others, k, p).ok_or(TrimError::NoSeamCrossing)?;
    let a = rotate_at(def, a, &xa, k, turn_a, periods)?;
    let mut b = rotate_at(def, b, &xb, k, turn_b, periods)?;
    let (Some((a0, a1)), Some((b0, _))) = (ends(&a), ends(&b)) else {
        return Err(TrimError::EmptyLoop);
    };
    // Line b's start up with a's end.
    let mut shift = DVec2::ZERO;
    shift[k] = libm::round((a1[k] - b0[k]) / p) * p;
    for t in &mut b {
        t.shift(shift);
    }
    let (Some((b0, b1)), mut out) = (ends(&b), a) else {
        return Err(TrimError::EmptyLoop);
    };
    if a1.distance(b0) > 0.0 {
        out.push(Track::link(a1, b0).ok_or(TrimError::SeamLink)?);
    }
    out.extend(b);
    if b1.distance(a0) > 0.0 {
        out.push(Track::link(b1, a0).ok_or(TrimError::SeamLink)?);
    }
    Ok(out)
}

/// Whole-period shifts per loop that put all loops in one window of each
/// periodic coordinate (starting at the entity's natural start when that
/// works as well as any), and the loops' range after the shifts. Loops that
/// span more than a period together (a face wrapping further round, a cut
/// that had to weave) are placed instead by the loop of largest area: every
/// other loop is moved to the copy of it that lies inside that one.
pub(super) fn windows(
    polys: &[Vec<DVec2>],
    periods: [Option<f64>; 2],
    natural: [Option<(f64, f64)>; 2],
) -> Result<(Vec<DVec2>, [Range; 2]), TrimError> {
    let bounds: Vec<(DVec2, DVec2)> = polys.iter().map(|q| poly_bounds(q)).collect();
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
            for b in &bounds {
                let d = crate::math::ceil((s - eps - b.0[k]) / p) * p;
                sh.push(d);
                wlo = wlo.min(b.0[k] + d);
                whi = whi.max(b.1[k] + d);
            }
            let span = whi - wlo;
            if best.as_ref().is_none_or(|x| span < x.0 - eps) {
                best = Some((span, sh, wlo, whi));
            }
        }
        let Some((span, sh, wlo, whi)) = best else { continue };
        // Rounding in a file's loops can take them a hair past one turn.
        let (sh, wlo, whi) = if span > p * (1.0 + 1e-6) {
            inside_outer(polys, &bounds, k, p).ok_or(TrimError::MoreThanOneTurn)?
        } else {
            (sh, wlo, whi)
        };
        for (s, d) in shifts.iter_mut().zip(sh) {
            s[k] = d;
        }
        range[k] = (wlo, whi);
    }
    Ok((shifts, range))
}

/// Box of a polygon.
fn poly_bounds(q: &[DVec2]) -> (DVec2, DVec2) {
    q.iter().fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), &x| (lo.min(x), hi.max(x)))
}

/// Signed area of a closed polygon.
fn poly_area(q: &[DVec2]) -> f64 {
    let n = q.len();
    0.5 * (0..n).map(|i| q[i].perp_dot(q[(i + 1) % n])).sum::<f64>()
}

/// Whether `x` lies inside the closed polygon `q` (crossing count).
fn inside(q: &[DVec2], x: DVec2) -> bool {
    let n = q.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (q[i], q[(i + 1) % n]);
        if (a.y > x.y) != (b.y > x.y) {
            let t = (x.y - a.y) / (b.y - a.y);
            if x.x < a.x + t * (b.x - a.x) {
                odd = !odd;
            }
        }
    }
    odd
}

/// Shifts along `k` that put every loop in the copy that lies inside the
/// loop of largest area (which stays put), and the range they cover: for
/// loops that together span more than one period.
fn inside_outer(polys: &[Vec<DVec2>], bounds: &[(DVec2, DVec2)], k: usize, p: f64) -> Option<(Vec<f64>, f64, f64)> {
    let outer = (0..polys.len()).max_by(|&i, &j| poly_area(&polys[i]).abs().total_cmp(&poly_area(&polys[j]).abs()))?;
    let (mut wlo, mut whi) = (bounds[outer].0[k], bounds[outer].1[k]);
    let mut out = Vec::with_capacity(polys.len());
    for (i, q) in polys.iter().enumerate() {
        if i == outer {
            out.push(0.0);
            continue;
        }
        let probe = *q.first()?;
        // Nearest copies first: the one starting in the outer loop's range.
        let base = crate::math::floor((bounds[outer].0[k] - bounds[i].0[k]) / p);
        let d = (0..8i32)
            .map(|m| base + f64::from(if m % 2 == 0 { m / 2 } else { -(m + 1) / 2 }))
            .map(|m| m * p)
            .find(|&d| {
                let mut x = probe;
                x[k] += d;
                inside(&polys[outer], x)
            })?;
        wlo = wlo.min(bounds[i].0[k] + d);
        whi = whi.max(bounds[i].1[k] + d);
        out.push(d);
    }
    Some((out, wlo, whi))
}

/// Why a face's trim loops could not be built (the reader's reason for skipping the face).
#[derive(Debug, Clone, PartialEq)]
pub(in crate::io) enum TrimError {
    /// A loop winding round a seam.
    SeamWinding,
    /// Several loops round the periodic direction (how many).
    PeriodicLoops(usize),
    /// A loop round a surface unbounded on the face's side.
    UnboundedSide,
    /// A loop of no curves.
    EmptyLoop,
    /// A link along the surface's bound that could not be made.
    BoundLink,
    /// A cut outside its loop.
    CutOutside,
    /// A loop going round that does not cross its partner's seam.
    NoSeamCrossing,
    /// A link along the seam that could not be made.
    SeamLink,
    /// Loops spanning more than one turn.
    MoreThanOneTurn,
    /// Parameter-space curves on a surface whose parameters are not read, and no model-space ones.
    UnreadParameters,
    /// A boundary loop without curves.
    NoCurves,
    /// Parameter-space curves off the surface and no model-space ones.
    OffSurface,
    /// An unbounded surface without trim curves.
    Unbounded,
    /// Loops across the seam of a closed surface that cannot be re-cut there.
    SeamRecut,
    /// Loops of no extent.
    NoExtent,
    /// A boundary loop of zero length.
    ZeroLength,
    /// A curve of the loop or a part of the surface (`part` names which) could not be built.
    Geometry {
        /// e.g. `trim curve`, `connector`, `profile`.
        part: &'static str,
        /// The NURBS error.
        error: NurbsError,
    },
}

impl core::fmt::Display for TrimError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::SeamWinding => write!(f, "a trim loop winds around the surface's seam (not supported)"),
            Self::PeriodicLoops(n) => write!(
                f,
                "{n} trim loops go round the surface's periodic direction; cannot tell how they bound the face"
            ),
            Self::UnboundedSide => write!(f, "a trim loop goes round a surface that is unbounded on the face's side"),
            Self::EmptyLoop => write!(f, "an empty trim loop"),
            Self::BoundLink => write!(f, "a link along the surface's bound could not be made"),
            Self::CutOutside => write!(f, "a cut outside its loop"),
            Self::NoSeamCrossing => write!(f, "a trim loop going round the surface does not cross its partner's seam"),
            Self::SeamLink => write!(f, "a link along the seam could not be made"),
            Self::MoreThanOneTurn => write!(f, "the trim loops span more than one turn of the surface"),
            Self::UnreadParameters => write!(
                f,
                "parameter-space trim curves on a surface whose parameters are not read, and no model-space curves"
            ),
            Self::NoCurves => write!(f, "a boundary loop without curves"),
            Self::OffSurface => write!(f, "parameter-space trim curves off the surface and no model-space curves"),
            Self::Unbounded => write!(f, "an unbounded surface without trim curves"),
            Self::SeamRecut => write!(f, "trim loops cross the seam of a closed surface that cannot be re-cut there"),
            Self::NoExtent => write!(f, "trim loops with no extent"),
            Self::ZeroLength => write!(f, "a boundary loop of zero length"),
            Self::Geometry { part, error } => write!(f, "{part}: {error}"),
        }
    }
}
