//! Mending trim loops that cross (paper 000 §3.2 needs simple loops). Real
//! files carry loops that cross themselves at a twist, fold back along a
//! line (an edge that overshoots its corner and returns), holes that poke
//! out of their outer loop or lie beside it. As industrial readers mend
//! wires, the face is taken to be where its loops wind positively (outer
//! loops counter-clockwise, holes clockwise, by how deep each is nested):
//! every segment is cut where another crosses or touches it, the pieces
//! that bound that region are kept, linked into simple loops, and loops of
//! no area are dropped.
//!
//! Decisions use a snapping distance of a billionth of the loops' size:
//! nodes closer than that are one, and a node that near a segment lies on
//! it. Winding numbers are counted exactly along axis-parallel rays.

use crate::numeric::TINY;
use alloc::vec::Vec;
use glam::DVec2;

use super::trim::{signed_area, CurveRef, Loops, Polyline};
use crate::collections::HashMap;

/// What mending changed, for the face's warning (a warning's payload).
pub(crate) use crate::warning::Mended;

/// Most segments mended at once: the work grows with their square in the
/// worst case, and a face with more is skipped as before.
const MAX_SEGMENTS: usize = 50_000;

/// Most steps mending may take per loop node: segment pairs tested for
/// crossings, and pieces the winding rays meet. A loop crossing itself at a
/// share of all its segment pairs (a fuzzed file's) is cut into
/// quadratically many pieces crowded where the crossings are, and every ray
/// meets them all; such a face is skipped like one with too many segments.
/// Real loops take tens of steps per node, some hundreds at the segment limit.
const STEPS_PER_NODE: usize = 2_000;

/// Snapping distance as a share of the loops' size.
const SNAP: f64 = 1e-9;

/// A piece of a loop segment between two cut points.
#[derive(Debug, Clone, Copy)]
struct Piece {
    /// Its ends, as [`Points`] ids.
    a: u32,
    b: u32,
    /// Source: loop, segment, and the fractions of the segment at `a` and `b`.
    lp: usize,
    seg: usize,
    fa: f64,
    fb: f64,
}

impl Piece {
    fn reversed(self) -> Self {
        Self { a: self.b, b: self.a, fa: self.fb, fb: self.fa, ..self }
    }
}

/// Points closer than the snapping distance `g` as one: a point takes the
/// id of an earlier one that near (found in the neighbouring cells of a
/// hash grid), else a new id at its own place, so nodes away from any
/// crossing keep their places exactly.
struct Points {
    g: f64,
    cells: HashMap<(i64, i64), Vec<u32>>,
    at: Vec<DVec2>,
}

impl Points {
    fn id(&mut self, q: DVec2) -> u32 {
        let c = ((q.x / self.g).floor() as i64, (q.y / self.g).floor() as i64);
        for dx in -1..=1 {
            for dy in -1..=1 {
                let near = self.cells.get(&(c.0 + dx, c.1 + dy)).into_iter().flatten();
                if let Some(&i) = near.into_iter().find(|&&i| self.at[i as usize].distance(q) <= self.g) {
                    return i;
                }
            }
        }
        let i = self.at.len() as u32;
        self.at.push(q);
        self.cells.entry(c).or_default().push(i);
        i
    }

    fn get(&self, i: u32) -> DVec2 {
        self.at[i as usize]
    }
}

std::thread_local! {
    /// Steps mending took on this thread ([`steps`]).
    static STEPS: core::cell::Cell<u64> = const { core::cell::Cell::new(0) };
}

/// Adds `n` to this thread's count of mending steps.
fn count_steps(n: usize) {
    STEPS.with(|s| s.set(s.get().saturating_add(n as u64)));
}

/// Steps mending has taken on this thread: segment pairs tested and pieces
/// winding rays met, a measure of its work that does not depend on the machine.
pub(crate) fn steps() -> u64 {
    STEPS.with(|s| s.get())
}

/// Where a segment is cut: at another segment's end, or at a crossing point.
#[derive(Debug, Clone, Copy)]
enum Cut {
    Node(u32),
    At(DVec2),
}

/// Mends `loops` in place so that they neither cross nor touch: returns
/// what changed, or `None` when there was nothing to mend or it could not
/// be done (too many segments or steps, nothing left); the loops are then
/// unchanged.
/// `file_ccw` says per loop whether the file ran it counter-clockwise: that
/// decides whether a loop beside the outer one is a region or nothing.
pub(crate) fn mend(loops: &mut Loops<'_>, file_ccw: &[bool]) -> Option<Mended> {
    let total: usize = loops.polys.iter().map(|p| p.uv.len()).sum();
    if !(3..=MAX_SEGMENTS).contains(&total) {
        return None;
    }
    let (lo, hi) = loops.bounds();
    let size = (hi - lo).max_element();
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let g = SNAP * size.max(lo.abs().max_element()).max(hi.abs().max_element());
    let mut pts = Points { g, cells: HashMap::default(), at: Vec::with_capacity(total) };
    let signs = nesting_signs(&loops.polys, file_ccw, g);
    // Segments between snapped nodes, oriented so the face is on their left.
    let mut segs: Vec<Piece> = Vec::with_capacity(total);
    for (k, p) in loops.polys.iter().enumerate() {
        let ids: Vec<u32> = p.uv.iter().map(|&q| pts.id(q)).collect();
        let n = ids.len();
        for i in 0..n {
            let (a, b) = (ids[i], ids[(i + 1) % n]);
            if a == b {
                continue;
            }
            let piece = Piece { a, b, lp: k, seg: i, fa: 0.0, fb: 1.0 };
            segs.push(if signs[k] { piece } else { piece.reversed() });
        }
    }
    let budget = STEPS_PER_NODE.saturating_mul(total);
    let (cuts, crossings) = cut_points(&segs, &pts, budget)?;
    // Every segment split at its cuts, pieces grouped by their two ends.
    let mut groups: HashMap<(u32, u32), (i32, Piece)> = HashMap::default();
    for (s, seg) in segs.iter().enumerate() {
        let mut fs: Vec<(f64, u32)> = cuts[s]
            .iter()
            .map(|&(f, c)| match c {
                Cut::Node(i) => (f, i),
                Cut::At(q) => (f, pts.id(q)),
            })
            .collect();
        fs.push((1.0, seg.b));
        crate::sort::by_f64(&mut fs, |x| x.0);
        let mut prev = (seg.a, 0.0);
        for &(f, at) in &fs {
            if at == prev.0 {
                continue;
            }
            let frac = |x: f64| seg.fa + (seg.fb - seg.fa) * x;
            let piece = Piece { a: prev.0, b: at, lp: seg.lp, seg: seg.seg, fa: frac(prev.1), fb: frac(f) };
            let (key, dir) = if piece.a < piece.b { ((piece.a, piece.b), 1) } else { ((piece.b, piece.a), -1) };
            groups.entry(key).or_insert((0, piece)).0 += dir;
            prev = (at, f);
        }
    }
    // Net pieces: the direction that remains once overlaps cancel.
    let mut net: Vec<(i32, Piece)> = groups
        .into_values()
        .filter(|(n, _)| *n != 0)
        .map(|(n, p)| (n.abs(), if (n > 0) == (p.a < p.b) { p } else { p.reversed() }))
        .collect();
    crate::sort::by_u64(&mut net, |(_, p)| crate::sort::pair(p.a, p.b));
    let kept = boundary(&net, &pts, budget)?;
    let out = link(&kept, &pts);
    let before = loops.polys.len();
    let mut polys: Vec<Polyline> = Vec::new();
    let mut dropped = 0;
    // A sliver between two chains a snapping distance apart has no area to mesh.
    let tiny = 4.0 * g * size;
    for chain in out {
        let p = polyline(loops, &chain, &pts);
        if p.uv.len() < 3 || signed_area(&p.uv).abs() <= tiny {
            dropped += 1;
            continue;
        }
        polys.push(p);
    }
    if polys.is_empty() {
        return None;
    }
    crate::sort::by_f64_desc(&mut polys, |p| signed_area(&p.uv).abs());
    loops.polys = polys;
    Some(Mended { crossings, loops_before: before, loops_after: loops.polys.len(), dropped, rejoined: true, flat: 0 })
}

/// Per loop, whether it bounds the face on its left as it runs (true) or
/// must be turned: loops nested an even number of times (the outer loop
/// `polys[0]`, islands in holes) run counter-clockwise, the others
/// clockwise, and a loop beside the outer one keeps the file's direction
/// (a second region, or a hole of nothing). A loop with any node inside the
/// outer loop, farther than `g` from its border, is nested in it (a hole
/// that pokes out is still its hole; a copy of a shared edge a rounding
/// inside is on the border, so a region beside stays one);
/// among the other loops, one is nested in another only if it lies wholly
/// inside it, so holes that cross each other stay holes and are joined.
fn nesting_signs(polys: &[Polyline], file_ccw: &[bool], g: f64) -> Vec<bool> {
    let areas: Vec<f64> = polys.iter().map(|p| signed_area(&p.uv)).collect();
    let boxes: Vec<(DVec2, DVec2)> = polys
        .iter()
        .map(|p| p.uv.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), &q| (lo.min(q), hi.max(q))))
        .collect();
    let within = |k: usize, j: usize| {
        let ((lo, hi), (jlo, jhi)) = (boxes[k], boxes[j]);
        let pad = DVec2::splat(g);
        areas[j].abs() > areas[k].abs()
            && lo.cmpge(jlo - pad).all()
            && hi.cmple(jhi + pad).all()
            && sample(&polys[k].uv).all(|q| contains(&polys[j].uv, q) || near_boundary(&polys[j].uv, q, g))
            && sample(&polys[k].uv).any(|q| contains(&polys[j].uv, q) && !near_boundary(&polys[j].uv, q, g))
    };
    (0..polys.len())
        .map(|k| {
            let depth = if k == 0 {
                0
            } else {
                let outer = &polys[0].uv;
                let in_outer = polys[k].uv.iter().any(|&q| contains(outer, q) && !near_boundary(outer, q, g));
                usize::from(in_outer) + (1..polys.len()).filter(|&j| j != k && within(k, j)).count()
            };
            let ccw = if k > 0 && depth == 0 { file_ccw.get(k).copied().unwrap_or(false) } else { depth % 2 == 0 };
            (areas[k] > 0.0) == ccw
        })
        .collect()
}

/// At most 64 of a loop's nodes, evenly spread: enough to tell a loop
/// wholly inside another from one that crosses it, at a bounded cost.
fn sample(p: &[DVec2]) -> impl Iterator<Item = DVec2> + '_ {
    p.iter().step_by(p.len().div_ceil(64).max(1)).copied()
}

/// Whether `q` lies within `g` of the closed polygon `p`'s boundary.
fn near_boundary(p: &[DVec2], q: DVec2, g: f64) -> bool {
    let n = p.len();
    (0..n).any(|i| {
        let (a, b) = (p[i], p[(i + 1) % n]);
        let d = b - a;
        let t = if d.length_squared() > 0.0 { ((q - a).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
        (a + d * t).distance(q) <= g
    })
}

/// Even-odd inside test of a closed polygon.
fn contains(p: &[DVec2], q: DVec2) -> bool {
    let n = p.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// One segment's cuts: the fraction along it, and the point.
type SegCuts = Vec<(f64, Cut)>;

/// Where each segment must be cut (fractions along it, strictly inside):
/// at proper crossings (one point for both segments), and where an end of
/// another segment lies on it (touching, overlapping: cut at that end, so
/// overlapping pieces end at the same points). Returns the cuts and how
/// many places they make; `None` when there are more than `budget` pairs to test.
fn cut_points(segs: &[Piece], pts: &Points, budget: usize) -> Option<(Vec<SegCuts>, usize)> {
    let g = pts.g;
    let mut cuts: Vec<SegCuts> = alloc::vec![Vec::new(); segs.len()];
    let mut points = 0;
    let ends: Vec<(DVec2, DVec2)> = segs.iter().map(|s| (pts.get(s.a), pts.get(s.b))).collect();
    for (i, j) in candidate_pairs(&ends, budget)? {
        let ((a, b), (c, d)) = (ends[i], ends[j]);
        let (ab, cd) = (b - a, d - c);
        let (lab, lcd) = (ab.length(), cd.length());
        if lab == 0.0 || lcd == 0.0 {
            continue;
        }
        // Signed distances of each end from the other segment's line.
        let (dc, dd) = (ab.perp_dot(c - a) / lab, ab.perp_dot(d - a) / lab);
        let (da, db) = (cd.perp_dot(a - c) / lcd, cd.perp_dot(b - c) / lcd);
        let zero = |x: f64| x.abs() <= g;
        let mut found = false;
        if !zero(dc) && !zero(dd) && !zero(da) && !zero(db) && (dc > 0.0) != (dd > 0.0) && (da > 0.0) != (db > 0.0) {
            let f = da / (da - db);
            let q = a.lerp(b, f);
            cuts[i].push((f, Cut::At(q)));
            cuts[j].push((dc / (dc - dd), Cut::At(q)));
            found = true;
        }
        // An end of one lying on the other (strictly between its ends).
        let (si, sj) = (segs[i], segs[j]);
        let tests = [
            (sj.a, c, dc, i, a, ab, lab),
            (sj.b, d, dd, i, a, ab, lab),
            (si.a, a, da, j, c, cd, lcd),
            (si.b, b, db, j, c, cd, lcd),
        ];
        for (id, p, dist, into, from, dir, len) in tests {
            if zero(dist) {
                let f = (p - from).dot(dir) / (len * len);
                if f * len > g && (1.0 - f) * len > g {
                    cuts[into].push((f, Cut::Node(id)));
                    found = true;
                }
            }
        }
        points += usize::from(found);
    }
    Some((cuts, points))
}

/// Pairs of segments whose boxes meet, found through a uniform grid;
/// `None` when the grid's cells hold more than `budget` pairs.
fn candidate_pairs(pts: &[(DVec2, DVec2)], budget: usize) -> Option<Vec<(usize, usize)>> {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for &(a, b) in pts {
        lo = lo.min(a.min(b));
        hi = hi.max(a.max(b));
    }
    let cells = (crate::math::sqrt(pts.len() as f64) as usize).clamp(1, 256);
    let size = ((hi - lo) / cells as f64).max(DVec2::splat(TINY));
    let cell = |p: DVec2| {
        let c = ((p - lo) / size).floor();
        (c.x.clamp(0.0, (cells - 1) as f64) as usize, c.y.clamp(0.0, (cells - 1) as f64) as usize)
    };
    let mut grid: Vec<Vec<usize>> = alloc::vec![Vec::new(); cells * cells];
    for (s, &(a, b)) in pts.iter().enumerate() {
        let ((x0, y0), (x1, y1)) = (cell(a.min(b)), cell(a.max(b)));
        for x in x0..=x1 {
            for y in y0..=y1 {
                grid[y * cells + x].push(s);
            }
        }
    }
    let steps = grid.iter().fold(0usize, |s, b| s.saturating_add(b.len() * b.len().saturating_sub(1) / 2));
    if steps > budget {
        return None;
    }
    count_steps(steps);
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(steps);
    for bucket in &grid {
        for (k, &i) in bucket.iter().enumerate() {
            for &j in &bucket[k + 1..] {
                pairs.push((i.min(j) as u32, i.max(j) as u32));
            }
        }
    }
    crate::sort::pairs(&mut pairs);
    pairs.dedup();
    Some(pairs.into_iter().map(|(i, j)| (i as usize, j as usize)).collect())
}

/// The net pieces that bound the region of positive winding, each turned
/// so that region is on its left; `None` when the rays would meet more than
/// `budget` pieces.
fn boundary(net: &[(i32, Piece)], pts: &Points, budget: usize) -> Option<Vec<Piece>> {
    let ends: Vec<(DVec2, DVec2)> = net.iter().map(|(_, p)| (pts.get(p.a), pts.get(p.b))).collect();
    let bands = Bands::new(&ends);
    // A ray from each piece's middle into its left side, along an axis.
    let rays: Vec<(DVec2, Ray)> = ends
        .iter()
        .map(|&(a, b)| {
            let d = b - a;
            let ray = if d.y.abs() >= d.x.abs() {
                if d.y > 0.0 {
                    Ray::NegX
                } else {
                    Ray::PosX
                }
            } else if d.x > 0.0 {
                Ray::PosY
            } else {
                Ray::NegY
            };
            (0.5 * (a + b), ray)
        })
        .collect();
    let steps = rays.iter().fold(0usize, |s, &(m, ray)| s.saturating_add(bands.list(m, ray).len()));
    if steps > budget {
        return None;
    }
    count_steps(steps);
    let mut out = Vec::new();
    for (k, (&(n, p), &(m, ray))) in net.iter().zip(&rays).enumerate() {
        let left = bands.winding(net, &ends, k, m, ray);
        let right = left - n;
        if (left > 0) != (right > 0) {
            out.push(if left > 0 { p } else { p.reversed() });
        }
    }
    Some(out)
}

/// An axis-parallel ray direction.
#[derive(Clone, Copy)]
enum Ray {
    PosX,
    NegX,
    PosY,
    NegY,
}

impl Ray {
    /// `q` turned (a rotation, which keeps winding numbers) so the ray runs along +x.
    fn turn(self, q: DVec2) -> DVec2 {
        match self {
            Self::PosX => q,
            Self::NegX => -q,
            Self::PosY => DVec2::new(q.y, -q.x),
            Self::NegY => DVec2::new(-q.y, q.x),
        }
    }
}

/// The pieces by horizontal and vertical bands, so a ray meets only those
/// of its own band.
struct Bands {
    lo: DVec2,
    step: DVec2,
    count: usize,
    rows: Vec<Vec<usize>>,
    cols: Vec<Vec<usize>>,
}

impl Bands {
    fn new(ends: &[(DVec2, DVec2)]) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &(a, b) in ends {
            lo = lo.min(a.min(b));
            hi = hi.max(a.max(b));
        }
        let count = (crate::math::sqrt(ends.len() as f64) as usize).clamp(1, 1024);
        let step = ((hi - lo) / count as f64).max(DVec2::splat(TINY));
        let (mut rows, mut cols) = (alloc::vec![Vec::new(); count], alloc::vec![Vec::new(); count]);
        let band = |x: f64, lo: f64, step: f64| (((x - lo) / step).floor().max(0.0) as usize).min(count - 1);
        for (k, &(a, b)) in ends.iter().enumerate() {
            for r in band(a.y.min(b.y), lo.y, step.y)..=band(a.y.max(b.y), lo.y, step.y) {
                rows[r].push(k);
            }
            for c in band(a.x.min(b.x), lo.x, step.x)..=band(a.x.max(b.x), lo.x, step.x) {
                cols[c].push(k);
            }
        }
        Self { lo, step, count, rows, cols }
    }

    /// The pieces a ray from `m` may meet: those of its band.
    fn list(&self, m: DVec2, ray: Ray) -> &[usize] {
        let band = |x: f64, lo: f64, step: f64| (((x - lo) / step).floor().max(0.0) as usize).min(self.count - 1);
        match ray {
            Ray::PosX | Ray::NegX => &self.rows[band(m.y, self.lo.y, self.step.y)],
            Ray::PosY | Ray::NegY => &self.cols[band(m.x, self.lo.x, self.step.x)],
        }
    }

    /// Winding number of the point just beside `m` on the ray's side, from
    /// the pieces other than `own` (with their multiplicities).
    fn winding(&self, net: &[(i32, Piece)], ends: &[(DVec2, DVec2)], own: usize, m: DVec2, ray: Ray) -> i32 {
        let list = self.list(m, ray);
        let q = ray.turn(m);
        let mut w = 0;
        for &k in list {
            if k == own {
                continue;
            }
            let (a, b) = (ray.turn(ends[k].0), ray.turn(ends[k].1));
            let n = net[k].0;
            // Upward crossings right of q count +1, downward ones −1 (half-open in y).
            if a.y <= q.y && b.y > q.y {
                if (b - a).perp_dot(q - a) > 0.0 {
                    w += n;
                }
            } else if b.y <= q.y && a.y > q.y && (b - a).perp_dot(q - a) < 0.0 {
                w -= n;
            }
        }
        w
    }
}

/// The kept pieces linked into closed chains: at a node where several
/// continue, the one turning most to the left, so that regions touching at
/// one point come out as separate loops. A chain ends where it started.
fn link(pieces: &[Piece], pts: &Points) -> Vec<Vec<Piece>> {
    let mut from: HashMap<u32, Vec<usize>> = HashMap::default();
    for (k, p) in pieces.iter().enumerate() {
        from.entry(p.a).or_default().push(k);
    }
    let mut used = alloc::vec![false; pieces.len()];
    let mut out = Vec::new();
    for start in 0..pieces.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut chain = alloc::vec![pieces[start]];
        let closed = loop {
            let Some(&p) = chain.last() else { break false };
            if p.b == pieces[start].a {
                break true;
            }
            let din = pts.get(p.b) - pts.get(p.a);
            let next = from.get(&p.b).and_then(|list| {
                list.iter()
                    .copied()
                    .filter(|&k| !used[k])
                    .max_by(|&x, &y| turn(din, &pieces[x], pts).total_cmp(&turn(din, &pieces[y], pts)))
            });
            let Some(k) = next else { break false };
            used[k] = true;
            chain.push(pieces[k]);
        };
        if closed {
            out.push(chain);
        }
    }
    out
}

/// How far `p` turns left from direction `din`, in (−π, π); straight back is −π.
fn turn(din: DVec2, p: &Piece, pts: &Points) -> f64 {
    let d = pts.get(p.b) - pts.get(p.a);
    let a = libm::atan2(din.perp_dot(d), din.dot(d));
    if a >= core::f64::consts::PI {
        -core::f64::consts::PI
    } else {
        a
    }
}

/// The polyline of a chain: its nodes at the pieces' starts, each on the
/// curve its source segment follows.
fn polyline(loops: &Loops<'_>, chain: &[Piece], pts: &Points) -> Polyline {
    let mut p = Polyline::default();
    for piece in chain {
        let Some(&(c, ta, tb)) = loops.polys.get(piece.lp).and_then(|q| q.seg.get(piece.seg)) else { continue };
        let t = |f: f64| ta + (tb - ta) * f;
        p.uv.push(pts.get(piece.a));
        p.at.push(CurveRef { curve: c, t: t(piece.fa) });
        p.seg.push((c, t(piece.fa), t(piece.fb)));
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NurbsCurve;

    /// A loop through `pts`, one line curve per segment (curve i from node i to i + 1).
    fn lines(pts: &[(f64, f64)]) -> Vec<NurbsCurve> {
        let n = pts.len();
        (0..n)
            .map(|i| {
                let (a, b) = (pts[i], pts[(i + 1) % n]);
                crate::nurbs::analytic::line(glam::DVec3::new(a.0, a.1, 0.0), glam::DVec3::new(b.0, b.1, 0.0), 0.0, 1.0)
                    .unwrap()
            })
            .collect()
    }

    fn poly(pts: &[(f64, f64)], first_curve: u32) -> Polyline {
        let mut p = Polyline::default();
        for (i, &(x, y)) in pts.iter().enumerate() {
            let c = first_curve + i as u32;
            p.uv.push(DVec2::new(x, y));
            p.at.push(CurveRef { curve: c, t: 0.0 });
            p.seg.push((c, 0.0, 1.0));
        }
        p
    }

    fn areas(l: &Loops<'_>) -> Vec<f64> {
        l.polys.iter().map(|p| signed_area(&p.uv)).collect()
    }

    /// Every node of the mended loops on its curve, and every segment's
    /// ends where its curve has them.
    /// Loops on the straight sides of `a` and of `b`, both kept open to
    /// mending; `inspect` sees them mended, and their areas come back.
    fn mend_pair(a: &[(f64, f64)], b: &[(f64, f64)], inspect: impl FnOnce(&Loops<'_>)) -> Vec<f64> {
        let mut curves = lines(a);
        curves.extend(lines(b));
        let first_of_b = u32::try_from(a.len()).expect("a few corners");
        let mut l = Loops {
            polys: alloc::vec![poly(a, 0), poly(b, first_of_b)],
            curves: curves.iter().collect(),
            mended: None,
        };
        mend(&mut l, &[true, true]).expect("mended");
        inspect(&l);
        areas(&l)
    }

    fn on_curves(l: &Loops<'_>) {
        for p in &l.polys {
            for (q, at) in p.uv.iter().zip(&p.at) {
                let c = l.curves[at.curve as usize];
                assert!(c.point(at.t).truncate().distance(*q) < 1e-9, "{q} off its curve");
            }
        }
    }

    /// A figure eight (a square whose top edge is crossed by a twist): the
    /// lobe that runs the loop's way stays, the twisted lobe goes.
    #[test]
    fn a_twisted_loop_keeps_the_lobe_of_its_orientation() {
        // Counter-clockwise square 0..4 whose top runs through a small
        // clockwise lobe above it (crossing at (1.5, 4) and (2.5, 4)... as a bow tie).
        let pts = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (1.0, 4.0), (3.0, 5.0), (3.0, 3.0)];
        let curves = lines(&pts);
        let mut l = Loops { polys: alloc::vec![poly(&pts, 0)], curves: curves.iter().collect(), mended: None };
        let m = mend(&mut l, &[true]).expect("mended");
        assert!(m.crossings >= 1);
        assert_eq!(l.polys.len(), 1, "{:?}", areas(&l));
        let a = areas(&l)[0];
        assert!(a > 0.0, "counter-clockwise");
        // The lobe above y = 4 is gone; the notch below the crossing stays.
        assert!(l.polys[0].uv.iter().all(|q| q.y <= 4.0 + 1e-12), "{:?}", l.polys[0].uv);
        on_curves(&l);
    }

    /// An edge that overshoots its corner and comes straight back: the
    /// spike along the line has no area and goes.
    #[test]
    fn a_spike_back_along_a_line_is_dropped() {
        let pts = [(0.0, 0.0), (2.0, 0.0), (2.0, 3.0), (2.0, 2.0), (0.0, 2.0)];
        let curves = lines(&pts);
        let mut l = Loops { polys: alloc::vec![poly(&pts, 0)], curves: curves.iter().collect(), mended: None };
        mend(&mut l, &[true]).expect("mended");
        assert_eq!(l.polys.len(), 1);
        assert!((areas(&l)[0] - 4.0).abs() < 1e-6, "{:?}", areas(&l));
        assert!(l.polys[0].uv.iter().all(|q| q.y <= 2.0 + 1e-12), "{:?}", l.polys[0].uv);
        on_curves(&l);
    }

    /// A hole that pokes out of its outer loop takes its bite out of the
    /// face; a loop wholly beside the outer one is a region of its own when
    /// the file ran it counter-clockwise, and nothing when clockwise.
    #[test]
    fn holes_crossing_or_beside_the_outer_loop() {
        let outer = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)];
        let hole = [(3.0, 1.0), (3.0, 3.0), (5.0, 3.0), (5.0, 1.0)]; // clockwise, crossing x = 4
        let beside = [(6.0, 0.0), (6.0, 1.0), (7.0, 1.0), (7.0, 0.0)]; // clockwise, outside
        let mut curves = lines(&outer);
        curves.extend(lines(&hole));
        curves.extend(lines(&beside));
        let loops = || Loops {
            polys: alloc::vec![poly(&outer, 0), poly(&hole, 4), poly(&beside, 8)],
            curves: curves.iter().collect(),
            mended: None,
        };
        let mut l = loops();
        mend(&mut l, &[true, false, true]).expect("mended");
        let a = areas(&l);
        assert_eq!(a.len(), 2, "{a:?}");
        assert!((a[0] - 14.0).abs() < 1e-6, "the square less the bite: {a:?}");
        assert!((a[1] - 1.0).abs() < 1e-6, "the loop beside, turned counter-clockwise: {a:?}");
        on_curves(&l);

        let mut l = loops();
        let m = mend(&mut l, &[true, false, false]).expect("mended");
        let a = areas(&l);
        assert_eq!(a.len(), 1, "{a:?}");
        assert!((a[0] - 14.0).abs() < 1e-6, "the square less the bite: {a:?}");
        assert_eq!((m.loops_before, m.loops_after), (3, 1));
    }

    /// Two holes of one size that cross each other: neither is nested in
    /// the other, and the face loses their union.
    #[test]
    fn crossing_holes_of_one_size_are_joined() {
        let outer = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)];
        let a = [(3.0, 3.0), (3.0, 6.0), (6.0, 6.0), (6.0, 3.0)];
        let b = [(5.0, 5.0), (5.0, 8.0), (8.0, 8.0), (8.0, 5.0)];
        let mut curves = lines(&outer);
        curves.extend(lines(&a));
        curves.extend(lines(&b));
        let mut l = Loops {
            polys: alloc::vec![poly(&outer, 0), poly(&a, 4), poly(&b, 8)],
            curves: curves.iter().collect(),
            mended: None,
        };
        mend(&mut l, &[true, false, false]).expect("mended");
        let total: f64 = areas(&l).iter().sum();
        assert!((total - (100.0 - 17.0)).abs() < 1e-6, "{:?}", areas(&l));
        on_curves(&l);
    }

    /// A region beside the outer loop sharing an edge whose copy bulges a
    /// rounding into the outer loop: still beside it, so the two regions
    /// are joined along the edge rather than the second taken for a hole.
    #[test]
    fn a_region_sharing_an_edge_a_rounding_inside_is_joined() {
        let a = [(1.0, 0.0), (3.0, 0.0), (3.0, 1.0), (1.0, 1.0)];
        let b = [(0.0, 0.0), (1.0, 0.0), (1.0 + 1e-14, 0.5), (1.0, 1.0), (0.0, 1.0)];
        let ar = mend_pair(&a, &b, on_curves);
        assert_eq!(ar.len(), 1, "{ar:?}");
        assert!((ar[0] - 3.0).abs() < 1e-6, "both regions: {ar:?}");
    }

    /// A star loop whose every chord crosses most others (as fuzzed files'
    /// loops do) is cut into quadratically many pieces: mending gives up
    /// within its steps per node, leaving the loop as it was.
    #[test]
    fn a_loop_crossing_itself_everywhere_is_refused_within_its_steps() {
        let n = 101;
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let a = core::f64::consts::TAU * ((i * 50) % n) as f64 / n as f64;
                (libm::cos(a), libm::sin(a))
            })
            .collect();
        let curves = lines(&pts);
        let mut l = Loops { polys: alloc::vec![poly(&pts, 0)], curves: curves.iter().collect(), mended: None };
        let before = steps();
        let m = mend(&mut l, &[true]);
        let taken = steps() - before;
        assert!(taken <= (STEPS_PER_NODE * n) as u64, "{taken} steps for {n} nodes");
        assert!(m.is_none());
        assert_eq!(l.polys[0].uv.len(), n, "unchanged");
    }

    /// Nodes a rounding apart and two loops touching at a corner: the
    /// regions stay apart, each a simple loop.
    #[test]
    fn squares_touching_at_a_corner_stay_two_loops() {
        let a = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let b = [(1.0, 1.0 + 1e-15), (2.0, 1.0), (2.0, 2.0), (1.0, 2.0)];
        let ar = mend_pair(&a, &b, |_| ());
        assert_eq!(ar.len(), 2, "{ar:?}");
        assert!(ar.iter().all(|&x| (x - 1.0).abs() < 1e-6), "{ar:?}");
    }
}
