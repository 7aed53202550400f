//! Trim loops: discretization by the chord test, outer/hole classification,
//! crossing checks and inside tests (paper 000 §3.2).

use crate::collections::memo_by_bits;
use crate::numeric::TINY;
use alloc::format;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::mend_loops::Mended;
use super::params::{initial_breaks, subdivide, Limits, MAX_PARAMS};
use crate::model::TrimLoop;
use crate::nurbs::Surface;
use crate::Error;

/// Where a loop node sits on the exact trim geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CurveRef {
    /// Index into [`Loops::curves`].
    pub curve: u32,
    /// Curve parameter.
    pub t: f64,
}

/// One closed polyline in (u,v); node `i` joins node `i + 1` (cyclically).
#[derive(Debug, Clone, Default)]
pub(crate) struct Polyline {
    /// Node parameters.
    pub uv: Vec<DVec2>,
    /// Exact place of each node on its curve.
    pub at: Vec<CurveRef>,
    /// Segment `i` (node `i` to `i + 1`) follows curve `.0` from parameter `.1` to `.2`.
    pub seg: Vec<(u32, f64, f64)>,
}

impl Polyline {
    /// Appends a node at parameter `t` of `curve` (at `q` in (u,v)) inside the
    /// segment being built, which follows `curve` from `*from`; `*from` moves on to `t`.
    pub fn push_on_curve(&mut self, curve: u32, from: &mut f64, t: f64, q: DVec2) {
        self.seg.push((curve, *from, t));
        self.uv.push(q);
        self.at.push(CurveRef { curve, t });
        *from = t;
    }

    /// Splits segment `i` at parameter `t` of its curve, the new node (at
    /// `q` in (u,v)) becoming node `i + 1`.
    pub fn split_segment(&mut self, i: usize, t: f64, q: DVec2) {
        let (curve, ta, tb) = self.seg[i];
        self.seg[i] = (curve, ta, t);
        self.seg.insert(i + 1, (curve, t, tb));
        self.uv.insert(i + 1, q);
        self.at.insert(i + 1, CurveRef { curve, t });
    }

    /// Splits many segments at once, in one pass over the nodes: `splits`
    /// holds `(i, t, q)` as [`Self::split_segment`] takes them, by rising
    /// `i`, one per segment. Splitting one by one moves the nodes after
    /// each, which costs a loop of n nodes n moves per split.
    pub fn split_segments(&mut self, splits: &[(usize, f64, DVec2)]) {
        let mut tails = Vec::with_capacity(splits.len());
        let mut nodes = Vec::with_capacity(splits.len());
        let mut refs = Vec::with_capacity(splits.len());
        for &(i, t, q) in splits {
            let Some(s) = self.seg.get_mut(i) else { continue };
            let (curve, _, tb) = *s;
            s.2 = t;
            tails.push((i, (curve, t, tb)));
            nodes.push((i, q));
            refs.push((i, CurveRef { curve, t }));
        }
        insert_after(&mut self.seg, &tails);
        insert_after(&mut self.uv, &nodes);
        insert_after(&mut self.at, &refs);
    }
}

/// Inserts each `(i, x)` of `adds` (by rising `i`, one per `i`) right after
/// item `i` of `v`, in one pass: inserting one by one moves every later item
/// each time.
pub(crate) fn insert_after<T: Copy>(v: &mut Vec<T>, adds: &[(usize, T)]) {
    if adds.is_empty() {
        return;
    }
    let mut out = Vec::with_capacity(v.len() + adds.len());
    let mut next = adds.iter().peekable();
    for (i, &x) in v.iter().enumerate() {
        out.push(x);
        if let Some(&(_, a)) = next.next_if(|a| a.0 == i) {
            out.push(a);
        }
    }
    *v = out;
}

/// All loops of one face, discretized and oriented: outer counter-clockwise
/// first, holes clockwise after it.
#[derive(Debug, Clone, Default)]
pub(crate) struct Loops<'a> {
    /// Polylines, outer first.
    pub polys: Vec<Polyline>,
    /// The trim curves, indexed by [`CurveRef::curve`].
    pub curves: Vec<&'a crate::NurbsCurve>,
    /// Set when the file's loops crossed and were mended ([`super::mend_loops`]):
    /// the polylines are then the border of the region they wind round,
    /// possibly several counter-clockwise loops.
    pub mended: Option<Mended>,
}

impl Loops<'_> {
    /// Box around all loop nodes.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for p in &self.polys {
            for &q in &p.uv {
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo, hi)
    }

    /// Every segment as `(a, b)`.
    pub fn segments(&self) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
        self.polys.iter().flat_map(|p| {
            let n = p.uv.len();
            (0..n).map(move |i| (p.uv[i], p.uv[(i + 1) % n]))
        })
    }

    /// Inside flags for every node of the grid `pu × pv` (index `i * pv.len() + j`),
    /// by scanlines: each row `v = pv[j]` is crossed with every segment once,
    /// instead of testing every node against every segment.
    pub fn contains_grid(&self, pu: &[f64], pv: &[f64]) -> Vec<bool> {
        let nv = pv.len();
        let mut inside = alloc::vec![false; pu.len() * nv];
        let mut xs: Vec<f64> = Vec::new();
        for (j, &y) in pv.iter().enumerate() {
            xs.clear();
            for (a, b) in self.segments() {
                if (a.y > y) != (b.y > y) {
                    xs.push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
                }
            }
            crate::sort::f64s(&mut xs);
            // Node x is inside when an odd number of crossings lie to its right.
            let mut k = 0;
            for (i, &x) in pu.iter().enumerate() {
                while k < xs.len() && xs[k] <= x {
                    k += 1;
                }
                inside[i * nv + j] = (xs.len() - k) % 2 == 1;
            }
        }
        inside
    }

    /// The pieces of the iso-line at `s` (v = s when `along_u`, else u = s)
    /// inside the loops, as intervals of the line's running parameter (even-odd).
    pub fn line_pieces(&self, along_u: bool, s: f64) -> Vec<(f64, f64)> {
        let mut xs: Vec<f64> = Vec::new();
        for (a, b) in self.segments() {
            let (a, b) = if along_u { (a, b) } else { (DVec2::new(a.y, a.x), DVec2::new(b.y, b.x)) };
            if (a.y > s) != (b.y > s) {
                xs.push(a.x + (s - a.y) / (b.y - a.y) * (b.x - a.x));
            }
        }
        crate::sort::f64s(&mut xs);
        xs.chunks_exact(2).map(|c| (c[0], c[1])).collect()
    }

    /// Even-odd inside test against all loops.
    pub fn contains(&self, q: DVec2) -> bool {
        let mut inside = false;
        for (a, b) in self.segments() {
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > q.x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// Discretizes, orients and checks the loops of face `face`.
///
/// # Errors
/// A loop too small to enclose anything, a loop that crosses itself or
/// another loop, or a hole outside the outer loop.
pub(crate) fn prepare_loops<'a>(
    face: usize,
    surface: &dyn Surface,
    loops: &'a [TrimLoop],
    lim: &Limits,
) -> Result<Loops<'a>, Error> {
    let mut out = Loops::default();
    let mut areas = Vec::new();
    let (mut kept, mut flat) = (Vec::new(), Vec::new());
    for (li, lp) in loops.iter().enumerate() {
        let poly = discretize_loop(face, li, lp, surface, lim, &mut out.curves)?;
        let area = if poly.uv.len() < 3 { 0.0 } else { signed_area(&poly.uv) };
        if area == 0.0 || !area.is_finite() {
            // A loop of no area bounds nothing: dropped when others remain.
            flat.push(li);
            continue;
        }
        areas.push(area);
        kept.push(li);
        out.polys.push(poly);
    }
    if let Some(&li) = flat.first().filter(|_| out.polys.is_empty()) {
        return Err(Error::Mesh { face, message: format!("loop {li} encloses no area") });
    }
    if out.polys.is_empty() {
        return Err(Error::Mesh { face, message: "no trim loop bounds the face".into() });
    }
    let (order, file_ccw) = orient_loops(&mut out, areas, kept);
    untangle(face, &mut out, &order, &file_ccw)?;
    if !flat.is_empty() {
        let m = out.mended.get_or_insert(Mended {
            loops_before: loops.len(),
            loops_after: out.polys.len(),
            ..Mended::default()
        });
        m.flat = flat.len();
    }
    Ok(out)
}

/// Loop `li` of face `face` as a polyline in (u,v) (paper 000 §3.2): each
/// curve discretized by the chord test, its curves appended to `curves`,
/// repeated and nanometre-close nodes merged, each segment tied to the
/// stretch of curve it follows.
///
/// # Errors
/// [`Error::Limit`] when the loop takes more nodes than the grid may have.
fn discretize_loop<'a>(
    face: usize,
    li: usize,
    lp: &'a TrimLoop,
    surface: &dyn Surface,
    lim: &Limits,
    curves: &mut Vec<&'a crate::NurbsCurve>,
) -> Result<Polyline, Error> {
    let mut poly = Polyline::default();
    for c in &lp.curves {
        let ci = curves.len() as u32;
        curves.push(c);
        let ts = curve_parameters(c, surface, lim);
        // The last node of each curve is the first of the next: drop it.
        for &t in &ts[..ts.len().saturating_sub(1)] {
            poly.uv.push(c.point(t).truncate());
            poly.at.push(CurveRef { curve: ci, t });
        }
        if poly.uv.len() > MAX_PARAMS * 8 {
            return Err(Error::Limit(format!("face {face} loop {li}: more than {} boundary nodes", MAX_PARAMS * 8)));
        }
    }
    dedup_closed(&mut poly);
    merge_close(&mut poly, surface, lim.min_edge);
    let n = poly.at.len();
    poly.seg = (0..n)
        .map(|i| {
            let (a, b) = (poly.at[i], poly.at[(i + 1) % n]);
            let end = curves.get(a.curve as usize).map_or(b.t, |c| c.domain().1);
            let tb = if b.curve == a.curve && b.t > a.t { b.t } else { end };
            (a.curve, a.t, tb)
        })
        .collect();
    Ok(poly)
}

/// The parameters of trim curve `c` where its polyline has nodes: split
/// until each piece's image on the surface is within the tolerance of its
/// chord and turns less than the angle limit (by normal and by tangent),
/// then coarsened where a longer (u,v) segment still stays that close.
///
/// Both tests (by normal, by tangent) sample the same parameters, and
/// neighbouring intervals share their ends, so each parameter's point,
/// normal and tangent are evaluated once and kept (by the parameter's bits)
/// while the curve is discretized.
fn curve_parameters(c: &crate::NurbsCurve, surface: &dyn Surface, lim: &Limits) -> Vec<f64> {
    // First derivatives are all the tests use: `tangents` gives the bits
    // `derivs` gives for them without the second-order sums.
    let on_surface = memo_by_bits(|t: f64| {
        let d = c.derivs(t);
        let uv = d.point.truncate();
        let (point, su, sv) = surface.tangents(uv);
        let tangent = su * d.d1.x + sv * d.d1.y;
        (point, surface.normal_from_tangents(uv, su, sv), tangent)
    });
    let by_normal = |t: f64| {
        let (p, n, _) = on_surface(t);
        (p, n)
    };
    let by_tangent = |t: f64| {
        let (p, _, tg) = on_surface(t);
        (p, tg)
    };
    let (a, b) = c.domain();
    let evals: [&dyn Fn(f64) -> (DVec3, DVec3); 2] = [&by_normal, &by_tangent];
    // A coarse edge is a straight (u,v) segment in the mesh: its
    // image must stay as close to its chord as the curve does.
    let straight = |ta: f64, tb: f64| {
        let (ua, ub) = (c.point(ta).truncate(), c.point(tb).truncate());
        let (pa, pb) = (surface.point(ua), surface.point(ub));
        (1..8).all(|k| {
            let p = surface.point(ua.lerp(ub, k as f64 / 8.0));
            super::params::dist_to_segment(p, pa, pb) <= lim.tol
        })
    };
    let (ts, _) = if surface.even_parameters() {
        super::params::subdivide_even(&evals, a, b, lim)
    } else {
        subdivide(&evals, &initial_breaks(&c.knots().breakpoints(), a, b, 16), lim)
    };
    super::params::coarsen(&evals, &straight, &ts, lim)
}

/// Puts the outer loop (largest area) first, counter-clockwise, and the
/// holes clockwise after it. Returns the file's loop number of each
/// polyline and whether the file had it counter-clockwise.
fn orient_loops(out: &mut Loops<'_>, mut areas: Vec<f64>, kept: Vec<usize>) -> (Vec<usize>, Vec<bool>) {
    let outer = (0..areas.len()).max_by(|&i, &j| areas[i].abs().total_cmp(&areas[j].abs())).unwrap_or(0);
    out.polys.swap(0, outer);
    areas.swap(0, outer);
    let mut order = kept;
    order.swap(0, outer);
    let file_ccw: Vec<bool> = areas.iter().map(|&a| a > 0.0).collect();
    for (k, poly) in out.polys.iter_mut().enumerate() {
        let want_ccw = k == 0;
        if (areas[k] > 0.0) != want_ccw {
            poly.uv.reverse();
            poly.at.reverse();
            let n = poly.seg.len();
            poly.seg = (0..n)
                .map(|j| {
                    let (c, ta, tb) = poly.seg[(2 * n - 2 - j) % n];
                    (c, tb, ta)
                })
                .collect();
        }
    }
    (order, file_ccw)
}

/// Loops that cross, touch, or lie beside the outer loop are mended to the
/// region they wind round ([`super::mend_loops`]); `order` and `file_ccw`
/// as [`orient_loops`] gives them.
///
/// # Errors
/// [`Error::Mesh`] naming the loops when mending leaves a crossing or
/// cannot make a region of them.
fn untangle(face: usize, out: &mut Loops<'_>, order: &[usize], file_ccw: &[bool]) -> Result<(), Error> {
    if let Some(x) = split_crossings(out) {
        let mm = super::mend_loops::mend(out, file_ccw);
        match mm {
            Some(m) if first_crossing(out).is_none() => out.mended = Some(m),
            _ => return Err(crossing_error(face, &x, order)),
        }
    }
    if out.mended.is_none() {
        for k in 1..out.polys.len() {
            let probe = out.polys[k].uv[0];
            let only_outer = Loops { polys: alloc::vec![out.polys[0].clone()], ..Loops::default() };
            if !only_outer.contains(probe) {
                // A loop beside the outer one: a region of its own, or a
                // hole of nothing; mending keeps what the loops wind round.
                match super::mend_loops::mend(out, file_ccw) {
                    Some(m) if first_crossing(out).is_none() => {
                        out.mended = Some(m);
                        break;
                    }
                    _ => {
                        return Err(Error::Mesh {
                            face,
                            message: format!("loop {} lies outside the outer loop {}", order[k], order[0]),
                        })
                    }
                }
            }
        }
    }
    Ok(())
}

/// Drops a node that lies within `eps` of the next one in model space and
/// next to it in (u,v) too (a trim curve a few nanometres long that bridges
/// two others in a file): such a segment would only make slivers. The later
/// node stays, so the segment before it follows the curve that goes on; a
/// run of such nodes longer than `eps` keeps its curves' corners.
/// Nodes along a pole stay, far apart in (u,v) though one point in space.
fn merge_close(p: &mut Polyline, surface: &dyn Surface, eps: f64) {
    let [lo, hi] = surface.domain();
    let near_uv = 1e-4 * (hi - lo).length();
    let n = p.uv.len();
    if n < 4 || eps.is_nan() || eps <= 0.0 {
        return;
    }
    let pts: Vec<DVec3> = p.uv.iter().map(|&q| surface.point(q)).collect();
    let mut keep: Vec<bool> = (0..n)
        .map(|i| {
            let j = (i + 1) % n;
            !(pts[i].distance(pts[j]) < eps && p.uv[i].distance(p.uv[j]) < near_uv)
        })
        .collect();
    // A run of dropped nodes reaching `eps` or more from the node that stays
    // is a finely split curve, not a tiny one: its corners stay where the neighbours have them.
    let Some(start) = (0..n).find(|&i| keep[i]) else { return };
    let mut kept = start;
    let mut far = false;
    for step in 1..=n {
        let i = (start + n - step) % n;
        if keep[i] {
            kept = i;
            far = false;
        } else {
            far |= pts[i].distance(pts[kept]) >= eps;
            if far && keep[(i + n - 1) % n] {
                for k in (i..i + n).map(|k| k % n).take_while(|&k| k != kept) {
                    keep[k] = p.at[k].curve != p.at[(k + n - 1) % n].curve;
                }
            }
        }
    }
    if keep.iter().filter(|&&k| k).count() < 3 {
        return;
    }
    p.uv = p.uv.iter().zip(&keep).filter(|(_, &k)| k).map(|(&q, _)| q).collect();
    p.at = p.at.iter().zip(&keep).filter(|(_, &k)| k).map(|(&a, _)| a).collect();
}

/// Removes consecutive duplicate nodes, including last-equals-first.
fn dedup_closed(p: &mut Polyline) {
    let mut uv = Vec::with_capacity(p.uv.len());
    let mut at = Vec::with_capacity(p.at.len());
    for (i, &q) in p.uv.iter().enumerate() {
        if uv.last().is_some_and(|&l: &DVec2| l.distance_squared(q) == 0.0) {
            continue;
        }
        uv.push(q);
        at.push(p.at[i]);
    }
    while uv.len() > 1 && uv.first() == uv.last() {
        uv.pop();
        at.pop();
    }
    p.uv = uv;
    p.at = at;
}

/// Signed area of a closed polygon: positive when it runs counter-clockwise.
pub(super) fn signed_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    let mut a = 0.0;
    for i in 0..n {
        a += p[i].perp_dot(p[(i + 1) % n]);
    }
    0.5 * a
}

fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Whether closed segments `ab` and `cd` share a point.
fn segments_meet(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let d1 = orient(c, d, a);
    let d2 = orient(c, d, b);
    let d3 = orient(a, b, c);
    let d4 = orient(a, b, d);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2, o: f64| {
        o == 0.0 && r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

/// Whether segments `ab` and `cd` cross, each one's ends more than `noise`
/// to either side of the other's line.
fn segments_cross_by(a: DVec2, b: DVec2, c: DVec2, d: DVec2, noise: f64) -> bool {
    let side = |p: DVec2, q: DVec2, r: DVec2| {
        let o = orient(p, q, r);
        let reach = noise * p.distance(q);
        if o > reach {
            1
        } else if o < -reach {
            -1
        } else {
            0
        }
    };
    let (d1, d2, d3, d4) = (side(c, d, a), side(c, d, b), side(a, b, c), side(a, b, d));
    d1 * d2 < 0 && d3 * d4 < 0
}

/// Two loop segments that cross or touch: (loop, segment) of each, and
/// whether they are neighbours folding back onto each other.
pub(crate) struct Crossing {
    pub a: (usize, usize),
    pub b: (usize, usize),
    pub folds: bool,
}

/// Most rounds of splitting crossing chords (see [`split_crossings`]).
const MAX_CROSSING_SPLITS: usize = 64;

/// Splits chords that cross although their curves need not: two sides of a
/// strip narrower than the tolerance, discretized within the tolerance, can
/// cross as chords. Each round halves both chords of one crossing on their
/// curves. Returns the crossing left (a fold, chords too short to halve, or
/// curves that really cross after [`MAX_CROSSING_SPLITS`] rounds), if any.
fn split_crossings(loops: &mut Loops<'_>) -> Option<Crossing> {
    for _ in 0..MAX_CROSSING_SPLITS {
        let x = first_crossing(loops)?;
        if x.folds {
            return Some(x);
        }
        // The later segment first, so the earlier index stays valid.
        let (first, second) = if x.a >= x.b { (x.a, x.b) } else { (x.b, x.a) };
        for (k, i) in [first, second] {
            if !split_chord(loops, k, i) {
                // The other chord may have been halved: look again.
                return first_crossing(loops);
            }
        }
    }
    first_crossing(loops)
}

/// The shortest chord [`split_chord`] halves, as a fraction of its loop's
/// extent in (u,v): two parts of a loop that touch at a point are not
/// parted by halving, which only crowds nodes toward the point (2^-30 of
/// the face apart after 30 rounds, where the triangulation's scaled plane
/// no longer sees three of them on one line).
const SHORTEST_SPLIT: f64 = 1e-6;

/// Halves segment `i` of loop `k` at the middle of its curve parameters;
/// false when that segment is too short in parameter to halve, or shorter
/// than [`SHORTEST_SPLIT`] of its loop's extent.
fn split_chord(loops: &mut Loops<'_>, k: usize, i: usize) -> bool {
    let Some(&(c, ta, tb)) = loops.polys.get(k).and_then(|p| p.seg.get(i)) else { return false };
    let Some(curve) = loops.curves.get(c as usize) else { return false };
    let tm = 0.5 * (ta + tb);
    if !(tm != ta && tm != tb && tm.is_finite()) {
        return false;
    }
    let uv = &loops.polys[k].uv;
    let (lo, hi) = uv
        .iter()
        .fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let chord = match (uv.get(i), uv.get(i + 1).or(uv.first())) {
        (Some(&a), Some(&b)) => a.distance(b),
        _ => return false,
    };
    // Not longer (or NaN): not halved.
    if chord.partial_cmp(&(SHORTEST_SPLIT * lo.distance(hi))) != Some(core::cmp::Ordering::Greater) {
        return false;
    }
    loops.polys[k].split_segment(i, tm, curve.point(tm).truncate());
    true
}

/// The error for crossing `x` of face `face`, naming the loops as the file orders them.
fn crossing_error(face: usize, x: &Crossing, order: &[usize]) -> Error {
    let message = if x.a.0 == x.b.0 {
        format!("loop {} crosses itself", order[x.a.0])
    } else {
        format!("loop {} crosses loop {}", order[x.a.0.min(x.b.0)], order[x.a.0.max(x.b.0)])
    };
    Error::Mesh { face, message }
}

/// Finds a pair of loop segments that cross or touch (other than neighbours
/// sharing their common node), bucketed on a uniform grid.
fn first_crossing(loops: &Loops<'_>) -> Option<Crossing> {
    crossings(loops, |_| true)
}

/// One loop segment from `a` to `b` for the pair search: segment `idx` of
/// loop `lp` (of `len` segments), or, `half` set, one half of it bent out to
/// its curve's middle point.
struct Seg {
    a: DVec2,
    b: DVec2,
    lp: usize,
    idx: usize,
    len: usize,
    half: bool,
}

/// Calls `stop` with each pair of loop segments that cross or touch (a
/// pair in two grid cells may come twice) until it returns true; returns
/// that pair.
pub(crate) fn crossings(loops: &Loops<'_>, mut stop: impl FnMut(&Crossing) -> bool) -> Option<Crossing> {
    let mut segs = Vec::new();
    for (k, p) in loops.polys.iter().enumerate() {
        let n = p.uv.len();
        for i in 0..n {
            segs.push(Seg { a: p.uv[i], b: p.uv[(i + 1) % n], lp: k, idx: i, len: n, half: false });
        }
    }
    let mut found = None;
    near_pairs(&segs, loops.bounds(), |s, t| {
        if s.lp == t.lp {
            let n = s.len;
            let adjacent = (s.idx + 1) % n == t.idx || (t.idx + 1) % n == s.idx;
            if adjacent {
                // Neighbours share one node; they only conflict if they fold back.
                let (shared, p, q) = if (s.idx + 1) % n == t.idx { (s.b, s.a, t.b) } else { (s.a, s.b, t.a) };
                let folds = orient(shared, p, q) == 0.0 && (p - shared).dot(q - shared) > 0.0;
                let x = Crossing { a: (s.lp, s.idx), b: (t.lp, t.idx), folds: true };
                if folds && n > 2 && stop(&x) {
                    found = Some(x);
                    return true;
                }
                return false;
            }
        }
        if segments_meet(s.a, s.b, t.a, t.b) {
            let x = Crossing { a: (s.lp, s.idx), b: (t.lp, t.idx), folds: false };
            if stop(&x) {
                found = Some(x);
                return true;
            }
        }
        false
    });
    found
}

/// Calls `stop` with each pair of loop segments (loop, segment) where the
/// first, halved on its curve, would cross the second as it stands, until
/// it returns true. Such a chord bulges past the other: their curves come
/// closer than the chords' sagitta (a spike of the trim region narrower than
/// its sides sag), so a split of either, as refinement makes them, would
/// fold, and a triangle between them spans the region's two sides turned.
/// `middle(k, i)` is the (u,v) middle of segment `i` of loop `k` on its
/// curve, `None` where it has none to halve.
pub(crate) fn bulge_crossings(
    loops: &Loops<'_>,
    middle: impl Fn(usize, usize) -> Option<DVec2>,
    mut stop: impl FnMut((usize, usize), (usize, usize)) -> bool,
) -> bool {
    let mut segs = Vec::new();
    for (k, p) in loops.polys.iter().enumerate() {
        let n = p.uv.len();
        for i in 0..n {
            let (a, b) = (p.uv[i], p.uv[(i + 1) % n]);
            segs.push(Seg { a, b, lp: k, idx: i, len: n, half: false });
            if let Some(m) = middle(k, i).filter(|m| m.is_finite() && *m != a && *m != b) {
                segs.push(Seg { a, b: m, lp: k, idx: i, len: n, half: true });
                segs.push(Seg { a: m, b, lp: k, idx: i, len: n, half: true });
            }
        }
    }
    let (mut lo, mut hi) = loops.bounds();
    for s in &segs {
        lo = lo.min(s.b);
        hi = hi.max(s.b);
    }
    // Sides on one line that rounding zigzags do not cross.
    let noise = 1e-12 * lo.distance(hi);
    near_pairs(&segs, (lo, hi), |s, t| {
        // A half against a chord of another segment.
        let (h, c) = match (s.half, t.half) {
            (true, false) => (s, t),
            (false, true) => (t, s),
            _ => return false,
        };
        // A half meets its own chord and its neighbours at their shared
        // nodes: only a half away from a node can cross there.
        let shares = |x: DVec2| x == c.a || x == c.b;
        if (h.lp == c.lp && h.idx == c.idx) || shares(h.a) || shares(h.b) {
            return false;
        }
        segments_cross_by(h.a, h.b, c.a, c.b, noise) && stop((h.lp, h.idx), (c.lp, c.idx))
    })
}

/// Calls `visit` with each pair of segments `segs` whose boxes share a cell
/// of a uniform grid over `bounds` (a pair in two cells may come twice)
/// until it returns true; returns whether it did. A cell crowded with
/// small segments (halvings heaped near one spot or along one line) is
/// gridded again over its own segments' box, so a crowd costs about its
/// size rather than its square.
fn near_pairs(segs: &[Seg], bounds: (DVec2, DVec2), mut visit: impl FnMut(&Seg, &Seg) -> bool) -> bool {
    let all: Vec<u32> = (0..segs.len() as u32).collect();
    let side = (crate::math::sqrt(segs.len() as f64) as usize).clamp(1, 512);
    let grid = Grid::new(segs, &all, bounds, (side, side), usize::MAX, usize::MAX);
    grid.is_some_and(|g| g.pairs(segs, &all, 0, &mut visit))
}

/// Most segments a cell holds before it is gridded again: a quadratic
/// scan of that many is cheap, and well above the fullest cell of any
/// corpus part (about 120), whose pairs thus keep their order.
const CROWDED: usize = 256;

/// Most grids nested in one another's cells.
const MAX_NESTING: usize = 8;

/// Segments (by index) filed under every cell of a uniform grid that
/// their boxes touch, and those too long to file ([`Grid::finer`]).
struct Grid {
    /// Cells along x and along y.
    cells: (usize, usize),
    lo: DVec2,
    size: DVec2,
    buckets: Vec<Vec<u32>>,
    /// Segments each compared with every other of the grid instead.
    long: Vec<u32>,
}

impl Grid {
    /// `cells` over `(lo, hi)` for the segments `idx`; a segment whose box
    /// touches more than `span` cells is kept in [`Grid::long`]. `None`
    /// once more than `most` entries would be filed.
    fn new(
        segs: &[Seg],
        idx: &[u32],
        (lo, hi): (DVec2, DVec2),
        cells: (usize, usize),
        span: usize,
        most: usize,
    ) -> Option<Grid> {
        let (nx, ny) = (cells.0.max(1), cells.1.max(1));
        let size = (hi - lo).max(DVec2::splat(TINY)) / DVec2::new(nx as f64, ny as f64);
        let cell_of = |p: DVec2| {
            let c = ((p - lo) / size).floor();
            (c.x.clamp(0.0, (nx - 1) as f64) as usize, c.y.clamp(0.0, (ny - 1) as f64) as usize)
        };
        let mut buckets: Vec<Vec<u32>> = alloc::vec![Vec::new(); nx * ny];
        let (mut long, mut filed) = (Vec::new(), 0usize);
        for &s in idx {
            let seg = segs.get(s as usize)?;
            let (x0, y0) = cell_of(seg.a.min(seg.b));
            let (x1, y1) = cell_of(seg.a.max(seg.b));
            let touched = (x1 - x0 + 1) * (y1 - y0 + 1);
            if touched > span {
                long.push(s);
                continue;
            }
            filed += touched;
            if filed > most {
                return None;
            }
            for x in x0..=x1 {
                for y in y0..=y1 {
                    buckets[y * nx + x].push(s);
                }
            }
        }
        Some(Grid { cells: (nx, ny), lo, size, buckets, long })
    }

    /// A finer grid for the crowded `bucket` of cell `c`, over the part of
    /// the cell its segments cover (where two meet lies in both), with
    /// about as many cells as segments, shaped like that box (a crowd along
    /// one line is cut across it), the few long segments set apart; `None`
    /// unless it files each segment a few times and leaves an eighth of the
    /// pairs or fewer.
    fn finer(&self, segs: &[Seg], c: usize, bucket: &[u32]) -> Option<Grid> {
        let lo = self.lo + self.size * DVec2::new((c % self.cells.0) as f64, (c / self.cells.0) as f64);
        let (mut a, mut b) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &i in bucket {
            let s = segs.get(i as usize)?;
            (a, b) = (a.min(s.a).min(s.b), b.max(s.a).max(s.b));
        }
        let (a, b) = (a.max(lo), b.min(lo + self.size).max(a.max(lo)));
        let n = bucket.len() as f64;
        let e = (b - a).max(DVec2::splat(TINY));
        let aspect = e.x / e.y;
        let side = |x: f64| (crate::math::sqrt(x).min(n) as usize).clamp(1, 4096);
        let cells = (side(n * aspect), side(n / aspect));
        let n = bucket.len();
        let g = Grid::new(segs, bucket, (a, b), cells, 16, 4 * n)?;
        let pairs = g.buckets.iter().map(|b| b.len() * b.len() / 2).sum::<usize>() + g.long.len() * n;
        (pairs <= n * n / 8).then_some(g)
    }

    /// [`near_pairs`] over this grid's cells, `depth` grids deep; `idx` are
    /// the segments it was built from.
    fn pairs(&self, segs: &[Seg], idx: &[u32], depth: usize, visit: &mut impl FnMut(&Seg, &Seg) -> bool) -> bool {
        // A long segment against every other, once per pair of long ones
        // (`long` rises, as the indices it was filed from do).
        for &i in &self.long {
            for &j in idx {
                let earlier_long = j < i && self.long.binary_search(&j).is_ok();
                if j != i && !earlier_long && visit(&segs[i as usize], &segs[j as usize]) {
                    return true;
                }
            }
        }
        for (c, bucket) in self.buckets.iter().enumerate() {
            if bucket.len() > CROWDED && depth < MAX_NESTING {
                if let Some(g) = self.finer(segs, c, bucket) {
                    if g.pairs(segs, bucket, depth + 1, visit) {
                        return true;
                    }
                    continue;
                }
            }
            for (ii, &i) in bucket.iter().enumerate() {
                for &j in &bucket[ii + 1..] {
                    if visit(&segs[i as usize], &segs[j as usize]) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::counted::Counted;
    use crate::NurbsCurve;

    /// A quadratic Bézier in (u,v) from `a` over control `c` to `b`.
    fn bezier(a: DVec2, c: DVec2, b: DVec2) -> NurbsCurve {
        let pts = [a, c, b].iter().map(|p| p.extend(0.0)).collect();
        NurbsCurve::try_new(2, alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts, None).unwrap()
    }

    /// A lens between two arcs 0.02 apart at the top: coarse chords of the
    /// lower arc cross the upper arc's, though the arcs never meet between
    /// their shared ends. Splitting resolves it, every node staying on its curve.
    #[test]
    fn crossing_chords_of_a_thin_lens_are_split_apart() {
        let (p, q) = (DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0));
        let upper = bezier(p, DVec2::new(0.5, 0.4), q);
        let lower = bezier(q, DVec2::new(0.5, 0.36), p);
        let nodes = [(0u32, 0.0), (0, 0.5), (1, 0.0), (1, 0.25), (1, 0.75)];
        let curves = [&upper, &lower];
        let mut poly = Polyline::default();
        for &(c, t) in &nodes {
            poly.uv.push(curves[c as usize].point(t).truncate());
            poly.at.push(CurveRef { curve: c, t });
        }
        poly.seg = alloc::vec![(0, 0.0, 0.5), (0, 0.5, 1.0), (1, 0.0, 0.25), (1, 0.25, 0.75), (1, 0.75, 1.0)];
        let mut loops = Loops { polys: alloc::vec![poly], curves: curves.to_vec(), mended: None };
        assert!(first_crossing(&loops).is_some(), "the test's chords must cross");
        assert!(split_crossings(&mut loops).is_none());
        assert!(first_crossing(&loops).is_none());
        let poly = &loops.polys[0];
        assert!(poly.uv.len() > nodes.len());
        assert_eq!(poly.uv.len(), poly.seg.len());
        for (q, at) in poly.uv.iter().zip(&poly.at) {
            assert!(q.distance(curves[at.curve as usize].point(at.t).truncate()) < 1e-12);
        }
        // Each segment starts at its node's parameter on the same curve.
        for (s, at) in poly.seg.iter().zip(&poly.at) {
            assert_eq!((s.0, s.1), (at.curve, at.t));
        }
    }

    /// Discretizing a trim curve tests chords, normals and tangents, all of
    /// first order: it evaluates the surface without second derivatives
    /// (each costs about a third more, for nothing), to the same nodes.
    #[test]
    fn trim_curves_take_no_second_derivatives() {
        let k = alloc::vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let pts: Vec<Vec<DVec3>> = (0..4)
            .map(|i| (0..4).map(|j| DVec3::new(i as f64, j as f64, if (i + j) % 3 == 0 { 1.5 } else { 0.0 })).collect())
            .collect();
        let bump = crate::FaceSurface::Nurbs(crate::NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).unwrap());
        let counting = Counted::new(&bump);
        let c = bezier(DVec2::new(0.05, 0.1), DVec2::new(0.9, 0.2), DVec2::new(0.7, 0.95));
        let lim = Limits { tol: 1e-3, angle: 0.2, max_edge: f64::INFINITY, min_edge: 1e-6 };
        let ts = curve_parameters(&c, &counting, &lim);
        assert!(ts.len() > 8, "the curve must be split: {} nodes", ts.len());
        assert_eq!(counting.derivs.get(), 0, "evaluations with second derivatives");
        assert_eq!(ts, curve_parameters(&c, &bump, &lim));
    }

    /// No loop at all is an error naming the face, not a panic in ordering
    /// the loops (no caller passes none today; a caller that did got an
    /// index past the end).
    #[test]
    fn no_loops_is_an_error_naming_the_face() {
        let surface = crate::FaceSurface::Nurbs(crate::nurbs::analytic::xy_plane(1.0));
        let lim = Limits { tol: 1e-3, angle: 0.5, max_edge: f64::INFINITY, min_edge: 1e-6 };
        match prepare_loops(7, &surface, &[], &lim) {
            Err(Error::Mesh { face: 7, message }) => assert!(message.contains("no trim loop"), "{message}"),
            other => panic!("expected a mesh error for face 7, got {:?}", other.map(|l| l.polys.len())),
        }
    }

    /// A trim curve of a rebuilt face (paper 001: interpolated at equal arc
    /// length, its 49 knots sample sites) takes nodes at equal steps: the
    /// split per knot group and the coarsening after it left a short last
    /// segment, and a short border segment fans needles into the face.
    #[test]
    fn a_rebuilt_faces_trim_curve_takes_even_nodes() {
        let pts: Vec<Vec<DVec3>> =
            (0..2).map(|i| (0..2).map(|j| DVec3::new(i as f64, j as f64, 0.0)).collect()).collect();
        let k = alloc::vec![0.0, 0.0, 1.0, 1.0];
        let plane = crate::nurbs::NurbsSurface::try_new([1, 1], k.clone(), k, &pts, None).unwrap();
        let surface = crate::FaceSurface::Rebuilt(plane);
        let (c, r) = (DVec2::new(0.5, 0.5), 0.4);
        let n = 50;
        let arc: Vec<DVec2> =
            (0..=n).map(|i| c + r * DVec2::from_angle(core::f64::consts::PI * i as f64 / n as f64)).collect();
        let params: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        let half = crate::reparam::interpolate_curve(&arc, &params).unwrap();
        let (a, b) = (arc[n].extend(0.0), arc[0].extend(0.0));
        let line = NurbsCurve::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0], alloc::vec![a, b], None).unwrap();
        let loops = [TrimLoop { curves: alloc::vec![half, line] }];
        let lim = Limits { tol: 1e-3, angle: 0.5, max_edge: f64::INFINITY, min_edge: 1e-6 };
        let out = prepare_loops(0, &surface, &loops, &lim).unwrap();
        let poly = &out.polys[0];
        let on_arc: Vec<f64> = poly
            .seg
            .iter()
            .filter(|s| s.0 == 0)
            .map(|s| surface.point(half_uv(&out, s.1)).distance(surface.point(half_uv(&out, s.2))))
            .collect();
        assert!(on_arc.len() >= 20, "{on_arc:?}");
        let (lo, hi) = on_arc.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(lo >= 0.9 * hi, "segments from {lo} to {hi}");
        // Every segment's chord still meets the tolerance.
        for &x in &on_arc {
            assert!(r - (r * r - 0.25 * x * x).sqrt() <= lim.tol, "{x}");
        }
    }

    /// The (u,v) point of curve 0 of `loops` at `t`.
    fn half_uv(loops: &Loops<'_>, t: f64) -> DVec2 {
        loops.curves[0].point(t).truncate()
    }

    /// Arcs that really cross are left crossing (and reported), within the split limit.
    #[test]
    fn crossing_curves_stay_crossing() {
        let (p, q) = (DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0));
        let a = bezier(p, DVec2::new(0.5, 0.4), q);
        let b = bezier(q, DVec2::new(0.5, 0.2), DVec2::new(0.0, 0.3));
        let c = bezier(DVec2::new(0.0, 0.3), DVec2::new(-0.1, 0.1), p);
        let curves = [&a, &b, &c];
        let mut poly = Polyline::default();
        for (k, cv) in curves.iter().enumerate() {
            for t in [0.0, 0.5] {
                poly.uv.push(cv.point(t).truncate());
                poly.at.push(CurveRef { curve: k as u32, t });
                poly.seg.push((k as u32, t, t + 0.5));
            }
        }
        let mut loops = Loops { polys: alloc::vec![poly], curves: curves.to_vec(), mended: None };
        let left = split_crossings(&mut loops).expect("curves that cross stay crossing");
        assert!(first_crossing(&loops).is_some());
        let message = alloc::format!("{}", crossing_error(3, &left, &[0]));
        assert!(message.contains("loop 0 crosses itself"), "{message}");
        assert!(loops.polys[0].uv.len() <= 6 + 2 * MAX_CROSSING_SPLITS);
    }

    /// 20 000 short segments of one wavy curve heaped in a speck of a large
    /// loop's box. The flat grid files them in one cell and compares every
    /// pair (2·10⁸); crowded cells gridded again keep it near linear, and
    /// every touching pair (the curve's neighbours) is still met.
    #[test]
    fn a_crowd_of_segments_is_compared_in_near_linear_work() {
        let seg = |a: DVec2, b: DVec2, idx: usize| Seg { a, b, lp: 0, idx, len: 0, half: false };
        let square = [DVec2::ZERO, DVec2::new(1000.0, 0.0), DVec2::splat(1000.0), DVec2::new(0.0, 1000.0)];
        let mut segs: Vec<Seg> = (0..4).map(|i| seg(square[i], square[(i + 1) % 4], i)).collect();
        let n = 20_000;
        let at = |i: usize| {
            let t = i as f64 / n as f64;
            DVec2::new(500.0 + 1e-3 * t, 500.0 + 1e-4 * libm::sin(40.0 * t))
        };
        segs.extend((0..n).map(|i| seg(at(i), at(i + 1), 4 + i)));
        // Chords across the whole crowd, as a loop's unhalved chords lie
        // along the stretch another retraces: each meets the curve.
        let chords = 8;
        segs.extend((0..chords).map(|k| seg(at(0) - DVec2::Y * 1e-5, at(n) + DVec2::Y * (k as f64 * 1e-5), 4 + n + k)));
        let (mut visits, mut neighbours, mut across) =
            (0usize, crate::collections::HashSet::default(), crate::collections::HashSet::default());
        near_pairs(&segs, (DVec2::ZERO, DVec2::splat(1000.0)), |s, t| {
            visits += 1;
            let on_curve = |s: &Seg| (4..4 + n).contains(&s.idx);
            if s.idx.abs_diff(t.idx) == 1 && on_curve(s) && on_curve(t) {
                neighbours.insert(s.idx.min(t.idx));
            }
            if on_curve(s) != on_curve(t) && s.idx >= 4 && t.idx >= 4 && segments_meet(s.a, s.b, t.a, t.b) {
                across.insert((s.idx.min(t.idx), s.idx.max(t.idx)));
            }
            false
        });
        assert!(visits < 50 * n, "{visits} pairs compared for {n} segments");
        assert_eq!(neighbours.len(), n - 1, "every pair of touching neighbours is compared");
        let meeting = (4..4 + n)
            .flat_map(|i| (4 + n..4 + n + chords).map(move |j| (i, j)))
            .filter(|&(i, j)| segments_meet(segs[i].a, segs[i].b, segs[j].a, segs[j].b))
            .count();
        assert!(meeting > chords, "the chords cross the curve");
        assert_eq!(across.len(), meeting, "every crossing of a chord and the curve is met");
    }

    /// Splitting several segments in one pass gives the loop that splitting
    /// them one by one from the last gives.
    #[test]
    fn split_segments_at_once_equals_one_by_one() {
        let mut poly = Polyline::default();
        let mut from = 0.0;
        for i in 1..=6 {
            let t = f64::from(i);
            poly.push_on_curve(i % 2, &mut from, t, DVec2::new(t, t * t));
        }
        let splits = [(0, 0.5, DVec2::new(0.5, 0.0)), (3, 3.5, DVec2::new(3.5, 1.0)), (5, 5.5, DVec2::new(5.5, 2.0))];
        let mut one_by_one = poly.clone();
        for &(i, t, q) in splits.iter().rev() {
            one_by_one.split_segment(i, t, q);
        }
        poly.split_segments(&splits);
        assert_eq!(poly.uv, one_by_one.uv);
        assert_eq!(poly.at, one_by_one.at);
        assert_eq!(poly.seg, one_by_one.seg);
        assert_eq!(poly.uv.len(), 9);
    }
}
