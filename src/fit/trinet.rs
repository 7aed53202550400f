//! The triangle net over the points, without a projection domain (paper 004
//! §2 steps 1–2, after Choi et al.): triangles come from each point's view of
//! its neighbourhood in its own tangent plane, are joined into one oriented
//! 2-manifold, small gaps are closed, and edges are swapped where that makes
//! the net smoother.
//!
//! The paper leaves the triangulation to Choi's method; the project's reading:
//! 1. every point triangulates its neighbours projected on its tangent plane
//!    (2-D Delaunay) and proposes the triangles around itself (its umbrella);
//! 2. a triangle proposed by all three of its corners is surer than one
//!    proposed by two or one; triangles are accepted in that order (then by
//!    their smallest angle), each only if it keeps the net an oriented
//!    2-manifold: no directed edge twice, and at each of its corners it does
//!    not overlap the triangles already there in that corner's tangent plane;
//! 3. gaps left between accepted triangles (boundary loops that turn
//!    clockwise about their normal, up to `max_hole_edges` edges) are filled
//!    by ear clipping in their plane; a gap no ear clipping closes (the
//!    triangles around it overlap) loses the triangles at its corners and is
//!    filled again, with the points left bare, by a 2-D Delaunay triangulation
//!    checked to close it exactly; loops that turn counter-clockwise are the
//!    open boundary of a sheet and stay;
//! 4. the smoothness criterion: an interior edge is swapped when the two
//!    triangles after the swap agree clearly better with their corners'
//!    tangent planes and stay well shaped.

use crate::collections::{HashMap, HashSet};
use alloc::vec::Vec;
use core::f64::consts::{PI, TAU};
use glam::{DVec2, DVec3};

use super::delaunay::{orient, triangulate};
use super::linalg::frame;
use super::normals::Neighbours;

/// Settings of the triangle net (see [`super::FitOptions`]).
pub(crate) struct NetOptions {
    /// Neighbours each point triangulates.
    pub neighbours: usize,
    /// Largest angle between a triangle's normal and its corners' normals.
    pub max_normal_angle: f64,
    /// Largest boundary loop closed as a gap.
    pub max_hole_edges: usize,
}

/// The oriented triangle net and what closing it took.
pub(crate) struct TriNet {
    /// Counter-clockwise seen from the side the normals point to.
    pub tris: Vec<[u32; 3]>,
    /// Gaps closed by ear clipping or the Delaunay fallback.
    pub holes_filled: usize,
    /// Boundary loops left open that turn like gaps (too large, or no ear found).
    pub holes_open: usize,
    /// Open boundary loops of the sheet.
    pub borders: usize,
    /// Edges swapped by the smoothness criterion.
    pub swaps: usize,
}

/// A proposed triangle and its votes.
struct Candidate {
    tri: [u32; 3],
    votes: u8,
    quality: f64,
}

/// Per-vertex tangent frames and the angle of every neighbour in them.
struct Frames<'a> {
    points: &'a [DVec3],
    axes: Vec<(DVec3, DVec3)>,
}

impl Frames<'_> {
    /// Angle of `a` about `v` in `v`'s tangent plane (always computed the same
    /// way, so touching arcs share their end exactly).
    fn theta(&self, v: u32, a: u32) -> f64 {
        let d = self.points[a as usize] - self.points[v as usize];
        let (u, w) = self.axes[v as usize];
        libm::atan2(d.dot(w), d.dot(u))
    }
}

/// Counter-clockwise turn from angle `from` to angle `to` (both from
/// `atan2`, in [−π, π]), in [0, 2π].
fn ccw_gap(from: f64, to: f64) -> f64 {
    let g = to - from;
    if g < 0.0 {
        g + TAU
    } else {
        g
    }
}

/// Smallest interior angle of a 3-D triangle, radians.
pub(crate) fn min_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let ang = |p: DVec3, q: DVec3, r: DVec3| crate::math::angle_between(q - p, r - p);
    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
}

fn max_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let ang = |p: DVec3, q: DVec3, r: DVec3| crate::math::angle_between(q - p, r - p);
    ang(a, b, c).max(ang(b, c, a)).max(ang(c, a, b))
}

/// Builds the net (see the module documentation).
pub(crate) fn build(points: &[DVec3], normals: &[DVec3], nb: &Neighbours, opt: &NetOptions) -> TriNet {
    let frames = Frames { points, axes: normals.iter().map(|n| frame(*n)).collect() };
    let cos_normal = libm::cos(opt.max_normal_angle);
    let mut cands = propose(points, normals, nb, opt, &frames, cos_normal);
    cands.sort_by(|a, b| b.votes.cmp(&a.votes).then(b.quality.total_cmp(&a.quality)).then(a.tri.cmp(&b.tri)));

    let mut net = Net { directed: HashSet::default(), arcs: alloc::vec![Vec::new(); points.len()], tris: Vec::new() };
    for c in &cands {
        net.try_add(c.tri, &frames);
    }
    let (holes_filled, holes_open, borders) = fill_holes(points, normals, &mut net, &frames, opt.max_hole_edges);
    let mut tris = net.tris;
    let swaps = swap_edges(points, normals, &mut tris);
    TriNet { tris, holes_filled, holes_open, borders, swaps }
}

/// Every point's umbrella from the Delaunay triangulation of its projected neighbours.
fn propose(
    points: &[DVec3],
    normals: &[DVec3],
    nb: &Neighbours,
    opt: &NetOptions,
    frames: &Frames,
    cos_normal: f64,
) -> Vec<Candidate> {
    let mut map: HashMap<[u32; 3], usize> = HashMap::default();
    let mut cands: Vec<Candidate> = Vec::new();
    let mut local: Vec<u32> = Vec::new();
    let mut flat: Vec<DVec2> = Vec::new();
    for i in 0..points.len() {
        let (p, n) = (points[i], normals[i]);
        let (u, w) = frames.axes[i];
        local.clear();
        flat.clear();
        local.push(i as u32);
        flat.push(DVec2::ZERO);
        for &j in nb.of(i, opt.neighbours) {
            let q = points[j as usize];
            // Same side of the surface, and not steeply off this tangent plane.
            if normals[j as usize].dot(n) <= cos_normal {
                continue;
            }
            let d = q - p;
            let along = DVec2::new(d.dot(u), d.dot(w));
            if d.dot(n).abs() > 1.5 * along.length() {
                continue;
            }
            local.push(j);
            flat.push(along);
        }
        for t in triangulate(&flat) {
            let Some(k) = t.iter().position(|&x| x == 0) else { continue };
            let (a, b) = (local[t[(k + 1) % 3]], local[t[(k + 2) % 3]]);
            let tri = [i as u32, a, b];
            let (pa, pb) = (points[a as usize], points[b as usize]);
            let tn = (pa - p).cross(pb - p).normalize_or_zero();
            if tri.iter().any(|&v| tn.dot(normals[v as usize]) <= cos_normal) || max_angle(p, pa, pb) > MAX_ANGLE {
                continue;
            }
            let key = canonical(tri);
            match map.get(&key) {
                Some(&c) => cands[c].votes = cands[c].votes.saturating_add(1),
                None => {
                    map.insert(key, cands.len());
                    cands.push(Candidate { tri: key, votes: 1, quality: min_angle(p, pa, pb) });
                }
            }
        }
    }
    cands
}

/// Triangles with an angle above this (about 162°) are the slivers a local
/// triangulation leaves along its hull; a real gap they leave is filled later.
const MAX_ANGLE: f64 = 0.9 * PI;

/// The triple rotated to start at its smallest index (orientation kept).
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

/// The net under construction.
struct Net {
    directed: HashSet<(u32, u32)>,
    /// Per vertex, the arcs `(start, length)` its triangles cover in its tangent plane.
    arcs: Vec<Vec<(f64, f64)>>,
    tris: Vec<[u32; 3]>,
}

impl Net {
    /// Adds `t` when it keeps the net an oriented 2-manifold locally embedded at its corners.
    fn try_add(&mut self, t: [u32; 3], frames: &Frames) -> bool {
        let edges = [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
        if edges.iter().any(|e| self.directed.contains(e)) {
            return false;
        }
        let mut arcs = [(0.0, 0.0); 3];
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let s = frames.theta(v, a);
            let len = ccw_gap(s, frames.theta(v, b));
            if !(len > 0.0 && len < PI) {
                return false;
            }
            for &(s2, len2) in &self.arcs[v as usize] {
                if ccw_gap(s, s2) < len || ccw_gap(s2, s) < len2 {
                    return false;
                }
            }
            arcs[k] = (s, len);
        }
        self.add(t, Some(arcs));
        true
    }

    fn add(&mut self, t: [u32; 3], arcs: Option<[(f64, f64); 3]>) {
        for k in 0..3 {
            self.directed.insert((t[k], t[(k + 1) % 3]));
            if let Some(a) = arcs {
                self.arcs[t[k] as usize].push(a[k]);
            }
        }
        self.tris.push(t);
    }
}

/// Traces the boundary loops and fills those that are gaps. A gap no ear
/// clipping can close (its diagonals already edges elsewhere: the triangles
/// around it overlap) is widened by removing the triangles at its corners and
/// filled again, up to [`HOLE_RETRIES`] times. Returns (filled, left open, borders).
fn fill_holes(
    points: &[DVec3],
    normals: &[DVec3],
    net: &mut Net,
    frames: &Frames,
    max_edges: usize,
) -> (usize, usize, usize) {
    let mut filled = 0;
    let mut pass = 0;
    // Points the widening left without triangles: they go back in with the gap around them.
    let mut orphans: Vec<u32> = Vec::new();
    loop {
        let (mut open, mut borders) = (0, 0);
        let mut widen: HashSet<u32> = HashSet::default();
        for lp in boundary_loops(net, frames) {
            match classify(points, normals, &lp, max_edges) {
                LoopKind::Border => borders += 1,
                LoopKind::TooLarge => open += 1,
                LoopKind::Gap(axis) => {
                    let inner = inside_loop(points, normals, &lp, &orphans, axis);
                    let tris =
                        if inner.is_empty() { ear_clip(points, normals, &net.directed, &lp, axis) } else { None };
                    match tris.or_else(|| delaunay_fill(points, normals, &net.directed, &lp, &inner, axis)) {
                        Some(tris) => {
                            tris.into_iter().for_each(|t| net.add(t, None));
                            filled += 1;
                        }
                        None => {
                            open += 1;
                            widen.extend(lp.iter().copied());
                        }
                    }
                }
            }
        }
        if widen.is_empty() || pass == HOLE_RETRIES {
            return (filled, open, borders);
        }
        pass += 1;
        net.tris.retain(|t| !t.iter().any(|v| widen.contains(v)));
        net.directed = net.tris.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
        let used: HashSet<u32> = net.tris.iter().flatten().copied().collect();
        orphans.retain(|v| !used.contains(v));
        orphans.extend(widen.iter().copied().filter(|v| !used.contains(v)));
        orphans.sort_unstable();
        orphans.dedup();
    }
}

/// Times a stuck gap is widened and filled again.
const HOLE_RETRIES: usize = 3;

/// The closed boundary loops of the net (vertex lists in the direction of
/// their boundary edges), split where a loop passes a vertex twice.
fn boundary_loops(net: &Net, frames: &Frames) -> Vec<Vec<u32>> {
    let mut out: HashMap<u32, Vec<u32>> = HashMap::default();
    let mut boundary: Vec<(u32, u32)> =
        net.directed.iter().filter(|(a, b)| !net.directed.contains(&(*b, *a))).copied().collect();
    boundary.sort_unstable();
    for &(a, b) in &boundary {
        out.entry(a).or_default().push(b);
    }
    let mut seen: HashSet<(u32, u32)> = HashSet::default();
    let mut loops: Vec<Vec<u32>> = Vec::new();
    for &start in &boundary {
        if seen.contains(&start) {
            continue;
        }
        let mut lp = Vec::new();
        let mut e = start;
        let mut closed = false;
        for _ in 0..=boundary.len() {
            seen.insert(e);
            lp.push(e.0);
            let (a, b) = e;
            // Next: the boundary edge out of b that starts the first arc counter-clockwise after b→a.
            let from = frames.theta(b, a);
            let next = out.get(&b).and_then(|cs| {
                cs.iter()
                    .min_by(|&&x, &&y| ccw_gap(from, frames.theta(b, x)).total_cmp(&ccw_gap(from, frames.theta(b, y))))
                    .copied()
            });
            match next {
                Some(c) if (b, c) == start => {
                    closed = true;
                    break;
                }
                Some(c) if !seen.contains(&(b, c)) => e = (b, c),
                _ => break,
            }
        }
        if closed {
            split_repeats(lp, &mut loops);
        }
    }
    loops
}

/// Splits a closed vertex loop that passes a vertex twice into simple loops.
fn split_repeats(mut lp: Vec<u32>, loops: &mut Vec<Vec<u32>>) {
    'again: loop {
        for i in 0..lp.len() {
            for j in i + 1..lp.len() {
                if lp[i] == lp[j] {
                    let inner: Vec<u32> = lp.drain(i..j).collect();
                    if inner.len() >= 3 {
                        loops.push(inner);
                    }
                    continue 'again;
                }
            }
        }
        break;
    }
    if lp.len() >= 3 {
        loops.push(lp);
    }
}

enum LoopKind {
    /// The sheet's open boundary (turns counter-clockwise about its normal).
    Border,
    /// A gap, with the axis to project it along.
    Gap(DVec3),
    /// Turns like a gap but is longer than allowed, or its normals disagree.
    TooLarge,
}

fn classify(points: &[DVec3], normals: &[DVec3], lp: &[u32], max_edges: usize) -> LoopKind {
    let sum: DVec3 = lp.iter().map(|&v| normals[v as usize]).sum();
    let axis = sum.normalize_or_zero();
    let coherent =
        sum.length() > 0.5 * lp.len() as f64 && lp.iter().all(|&v| normals[v as usize].dot(axis) > COS_HOLE_TILT);
    if !coherent {
        return LoopKind::Border;
    }
    let mut area = 0.0;
    for i in 0..lp.len() {
        let (p, q) = (points[lp[i] as usize], points[lp[(i + 1) % lp.len()] as usize]);
        area += p.cross(q).dot(axis);
    }
    if area >= 0.0 {
        LoopKind::Border
    } else if lp.len() > max_edges {
        LoopKind::TooLarge
    } else {
        LoopKind::Gap(axis)
    }
}

/// A gap's corner normals must lie within about 70° of the gap's mean normal.
const COS_HOLE_TILT: f64 = 0.34;

/// Fills the gap bounded by `lp` (clockwise about `axis`) by ear clipping in
/// the plane normal to `axis`, best-shaped ear first; an ear whose closing
/// edge exists elsewhere in the net is never cut. The triangles, or `None`
/// when it gets stuck.
fn ear_clip(
    points: &[DVec3],
    normals: &[DVec3],
    directed: &HashSet<(u32, u32)>,
    lp: &[u32],
    axis: DVec3,
) -> Option<Vec<[u32; 3]>> {
    let (u, w) = frame(axis);
    // Counter-clockwise about the axis.
    let mut poly: Vec<u32> = lp.iter().rev().copied().collect();
    let flat = |v: u32| DVec2::new(points[v as usize].dot(u), points[v as usize].dot(w));
    let mut tris = Vec::with_capacity(lp.len());
    // Diagonals cut so far: an ear may not cut one again.
    let mut cut: Vec<(u32, u32)> = Vec::new();
    while poly.len() > 3 {
        let m = poly.len();
        let mut best: Option<(usize, f64)> = None;
        for i in 0..m {
            let (a, b, c) = (poly[(i + m - 1) % m], poly[i], poly[(i + 1) % m]);
            let (fa, fb, fc) = (flat(a), flat(b), flat(c));
            if orient(fa, fb, fc) <= 0.0 {
                continue;
            }
            if directed.contains(&(c, a))
                || directed.contains(&(a, c))
                || cut.contains(&(a, c))
                || cut.contains(&(c, a))
            {
                continue;
            }
            let inside = poly.iter().any(|&v| {
                v != a && v != b && v != c && {
                    let f = flat(v);
                    orient(fa, fb, f) > 0.0 && orient(fb, fc, f) > 0.0 && orient(fc, fa, f) > 0.0
                }
            });
            if inside || !faces_like_normals(points, normals, [a, b, c]) {
                continue;
            }
            let q = min_angle(points[a as usize], points[b as usize], points[c as usize]);
            if best.is_none_or(|(_, bq)| q > bq) {
                best = Some((i, q));
            }
        }
        let (i, _) = best?;
        let (a, b, c) = (poly[(i + m - 1) % m], poly[i], poly[(i + 1) % m]);
        tris.push([a, b, c]);
        cut.push((a, c));
        poly.remove(i);
    }
    let t = [poly[0], poly[1], poly[2]];
    if orient(flat(t[0]), flat(t[1]), flat(t[2])) <= 0.0 || !faces_like_normals(points, normals, t) {
        return None;
    }
    tris.push(t);
    Some(tris)
}

/// Whether triangle `t` faces the side its corners' normals point to.
fn faces_like_normals(points: &[DVec3], normals: &[DVec3], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| points[v as usize]);
    let n = (b - a).cross(c - a);
    t.iter().all(|&v| n.dot(normals[v as usize]) > 0.0)
}

/// The `candidates` that lie inside loop `lp` seen along `axis` (even-odd
/// rule), facing like the loop and within its reach (a point on the far side
/// of a closed surface also projects inside).
fn inside_loop(points: &[DVec3], normals: &[DVec3], lp: &[u32], candidates: &[u32], axis: DVec3) -> Vec<u32> {
    if candidates.is_empty() || lp.is_empty() {
        return Vec::new();
    }
    let (u, w) = frame(axis);
    let flat = |v: u32| DVec2::new(points[v as usize].dot(u), points[v as usize].dot(w));
    let poly: Vec<DVec2> = lp.iter().map(|&v| flat(v)).collect();
    let centre = lp.iter().map(|&v| points[v as usize]).sum::<DVec3>() / lp.len() as f64;
    let reach = lp.iter().map(|&v| points[v as usize].distance(centre)).fold(0.0, f64::max);
    candidates
        .iter()
        .copied()
        .filter(|&v| {
            !lp.contains(&v)
                && normals[v as usize].dot(axis) > COS_HOLE_TILT
                && points[v as usize].distance(centre) <= reach
                && point_in_polygon(flat(v), &poly)
        })
        .collect()
}

/// Even-odd test of `p` against the closed polygon `poly`.
fn point_in_polygon(p: DVec2, poly: &[DVec2]) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Fills the gap bounded by `lp` together with the points `inner` inside it:
/// the 2-D Delaunay triangulation of them all, seen along `axis`, keeping the
/// triangles inside the loop. `None` unless it closes the gap exactly: every
/// loop edge matched, every inner point used, no edge that exists elsewhere
/// in the net, every triangle facing like its corners' normals.
fn delaunay_fill(
    points: &[DVec3],
    normals: &[DVec3],
    directed: &HashSet<(u32, u32)>,
    lp: &[u32],
    inner: &[u32],
    axis: DVec3,
) -> Option<Vec<[u32; 3]>> {
    let (u, w) = frame(axis);
    let flat = |v: u32| DVec2::new(points[v as usize].dot(u), points[v as usize].dot(w));
    let verts: Vec<u32> = lp.iter().chain(inner).copied().collect();
    let pts: Vec<DVec2> = verts.iter().map(|&v| flat(v)).collect();
    let poly: Vec<DVec2> = pts[..lp.len()].to_vec();
    let mut tris = Vec::new();
    for t in triangulate(&pts) {
        let c = (pts[t[0]] + pts[t[1]] + pts[t[2]]) / 3.0;
        if point_in_polygon(c, &poly) {
            tris.push([verts[t[0]], verts[t[1]], verts[t[2]]]);
        }
    }
    let mut made: HashSet<(u32, u32)> = HashSet::default();
    for t in &tris {
        if !faces_like_normals(points, normals, *t) {
            return None;
        }
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if directed.contains(&e) || !made.insert(e) {
                return None;
            }
        }
    }
    // Every loop edge a→b (a boundary edge of the net) is closed by b→a; the
    // other edges made are inner ones, each with its twin.
    let m = lp.len();
    let closes = (0..m).all(|i| made.contains(&(lp[(i + 1) % m], lp[i])));
    let twins = made.iter().all(|&(a, b)| made.contains(&(b, a)) || directed.contains(&(b, a)));
    let used: HashSet<u32> = tris.iter().flatten().copied().collect();
    (closes && twins && inner.iter().all(|v| used.contains(v))).then_some(tris)
}

/// The smoothness criterion (see the module documentation). Returns the number of swaps.
fn swap_edges(points: &[DVec3], normals: &[DVec3], tris: &mut [[u32; 3]]) -> usize {
    let deviation = |t: [u32; 3]| -> f64 {
        let [a, b, c] = t.map(|v| points[v as usize]);
        let tn = (b - a).cross(c - a);
        t.iter().map(|&v| crate::math::angle_between(tn, normals[v as usize])).fold(0.0, f64::max)
    };
    let quality = |t: [u32; 3]| min_angle(points[t[0] as usize], points[t[1] as usize], points[t[2] as usize]);
    let mut swaps = 0;
    for _pass in 0..SWAP_PASSES {
        let mut edges: HashMap<(u32, u32), usize> = HashMap::default();
        for (i, t) in tris.iter().enumerate() {
            for k in 0..3 {
                edges.insert((t[k], t[(k + 1) % 3]), i);
            }
        }
        let mut touched = alloc::vec![false; tris.len()];
        let mut changed = 0;
        for i in 0..tris.len() {
            for k in 0..3 {
                if touched[i] {
                    break;
                }
                let t1 = tris[i];
                let (a, b, c) = (t1[k], t1[(k + 1) % 3], t1[(k + 2) % 3]);
                let Some(&j) = edges.get(&(b, a)) else { continue };
                if touched[j] || j == i {
                    continue;
                }
                let t2 = tris[j];
                let Some(d) = t2.iter().copied().find(|&v| v != a && v != b) else { continue };
                if d == c || edges.contains_key(&(c, d)) || edges.contains_key(&(d, c)) {
                    continue;
                }
                let old = deviation([a, b, c]).max(deviation([b, a, d]));
                if old < SWAP_MIN_DEVIATION {
                    continue;
                }
                let (n1, n2) = ([a, d, c], [d, b, c]);
                // The quad must stay convex seen along its corners' mean normal.
                let axis: DVec3 = [a, b, c, d].iter().map(|&v| normals[v as usize]).sum::<DVec3>().normalize_or_zero();
                let (u, w) = frame(axis);
                let f = |v: u32| DVec2::new(points[v as usize].dot(u), points[v as usize].dot(w));
                if orient(f(a), f(d), f(c)) <= 0.0 || orient(f(d), f(b), f(c)) <= 0.0 {
                    continue;
                }
                let new = deviation(n1).max(deviation(n2));
                let q_old = quality([a, b, c]).min(quality([b, a, d]));
                let q_new = quality(n1).min(quality(n2));
                if new < SWAP_GAIN * old && q_new >= 0.5 * q_old {
                    tris[i] = n1;
                    tris[j] = n2;
                    touched[i] = true;
                    touched[j] = true;
                    changed += 1;
                }
            }
        }
        swaps += changed;
        if changed == 0 {
            break;
        }
    }
    swaps
}

/// Swap passes at most.
const SWAP_PASSES: usize = 8;
/// Pairs whose triangles already agree with their tangent planes within this (about 3°) are left.
const SWAP_MIN_DEVIATION: f64 = 0.05;
/// A swap must cut the disagreement by at least a quarter.
const SWAP_GAIN: f64 = 0.75;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::kdtree::KdTree;
    use crate::fit::normals::estimate;
    use alloc::vec;

    fn net_of(points: &[DVec3], k: usize) -> (TriNet, Vec<DVec3>) {
        let tree = KdTree::new(points);
        let (mut idx, mut out) = (Vec::new(), Vec::new());
        for (i, p) in points.iter().enumerate() {
            tree.nearest(*p, k, Some(i as u32), &mut out);
            idx.extend(out.iter().map(|x| x.0));
        }
        let nb = Neighbours { k, idx };
        let normals = estimate(points, &nb, 12, 0.5);
        let opt = NetOptions { neighbours: k, max_normal_angle: PI / 3.0, max_hole_edges: 24 };
        (build(points, &normals, &nb, &opt), normals)
    }

    #[test]
    fn a_jittered_grid_gives_one_oriented_sheet_with_one_border() {
        let mut rnd = crate::testing::uniform(3u64);
        let mut pts = Vec::new();
        for i in 0..12 {
            for j in 0..10 {
                let (x, y) = (i as f64 + 0.7 * (rnd() - 0.5), j as f64 + 0.7 * (rnd() - 0.5));
                pts.push(DVec3::new(x, y, 0.1 * x * y / 10.0));
            }
        }
        let (net, normals) = net_of(&pts, 16);
        assert_eq!((net.borders, net.holes_open), (1, 0));
        // Every directed edge once, every point used, triangles facing like the normals.
        let mut directed = HashSet::default();
        let mut used = vec![false; pts.len()];
        for t in &net.tris {
            for k in 0..3 {
                assert!(directed.insert((t[k], t[(k + 1) % 3])), "directed edge twice");
                used[t[k] as usize] = true;
            }
            let [a, b, c] = t.map(|v| pts[v as usize]);
            assert!((b - a).cross(c - a).dot(normals[t[0] as usize]) > 0.0);
        }
        assert!(used.iter().all(|u| *u));
        // Euler for a disc: V − E + F = 1.
        let edges = directed.iter().filter(|(a, b)| a < b || !directed.contains(&(*b, *a))).count();
        assert_eq!(pts.len() as i64 - edges as i64 + net.tris.len() as i64, 1);
    }

    #[test]
    fn a_sphere_gives_a_closed_net() {
        let n = 200;
        let golden = PI * (3.0 - libm::sqrt(5.0));
        let pts: Vec<DVec3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = libm::sqrt(1.0 - z * z);
                let t = golden * i as f64;
                DVec3::new(r * libm::cos(t), r * libm::sin(t), z)
            })
            .collect();
        let (net, _) = net_of(&pts, 16);
        assert_eq!((net.borders, net.holes_open), (0, 0));
        assert_eq!(net.tris.len(), 2 * n - 4, "a closed net of genus 0 has 2V − 4 triangles");
    }
}
