//! Steps 3–5 of paper 002: from an initial valid triangle at an extreme
//! vertex, grow the valid region across edges until intersection segments;
//! sub-triangulate the triangles that carry segments and keep growing inside
//! them up to the segments; cross each segment into the other triangle's
//! sub-triangle that keeps the orientation consistent (it runs the shared
//! piece the other way), and continue. What is never reached is invalid and
//! dropped; the kept sub-triangles share the segment's points, which stitches
//! them.

use alloc::collections::VecDeque;
use alloc::vec::Vec;
use glam::DVec3;

use super::arrange::{build, Geometry, Points, Sub};
use super::topology::NONE;

/// A piece of the surface: a whole triangle, or one sub-triangle of one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cell {
    Whole(u32),
    Sub(u32, u32),
}

/// What region growing kept and how it went.
pub(crate) struct Grown {
    /// Triangles of point ids.
    pub tris: Vec<[u32; 3]>,
    pub points: Points,
    /// Valid regions found (areas bounded by segments, each entered once).
    pub regions: usize,
    /// Triangles that were sub-triangulated.
    pub subdivided: usize,
    /// Sub-triangulations that had to leave their segments out.
    pub fallbacks: usize,
    /// Moves across an edge or segment that found nothing to connect to.
    pub stitch_misses: usize,
    /// Components left out: no valid seed found (wholly inside another, or inside out).
    pub unseeded: usize,
    /// Whether every edge of the result has exactly two triangles running it opposite ways.
    pub closed: bool,
}

struct Flood<'a> {
    g: &'a Geometry<'a>,
    points: Points,
    /// Sub-triangulation index per triangle, [`NONE`] if not built.
    sub_of: Vec<u32>,
    subs: Vec<Sub>,
    /// Per triangle: 0 unknown, 1 whole, 2 needs a sub-triangulation.
    kind: Vec<u8>,
    whole_seen: Vec<bool>,
    stitch_misses: usize,
}

impl Flood<'_> {
    fn needs_sub(&mut self, t: u32) -> bool {
        let ti = t as usize;
        if self.kind[ti] == 0 {
            let mut needs = !self.g.x.of(t).is_empty();
            if !needs {
                let tv = self.g.tris[ti];
                for k in 0..3 {
                    let u = self.g.nbr[ti][k];
                    if u == NONE {
                        continue;
                    }
                    let (lo, hi) = super::topology::key(tv[k], tv[(k + 1) % 3]);
                    needs |= self.g.x.of(u / 3).iter().any(|&s| {
                        self.g.x.segments[s as usize]
                            .ends
                            .iter()
                            .any(|e| matches!(*e, super::tritri::PointKey::EdgeTri(a, b, _) if (a, b) == (lo, hi)))
                    });
                }
            }
            self.kind[ti] = if needs { 2 } else { 1 };
        }
        self.kind[ti] == 2
    }

    fn sub(&mut self, t: u32) -> &mut Sub {
        if self.sub_of[t as usize] == NONE {
            let s = build(self.g, &mut self.points, t);
            self.sub_of[t as usize] = self.subs.len() as u32;
            self.subs.push(s);
        }
        let i = self.sub_of[t as usize] as usize;
        &mut self.subs[i]
    }

    /// The cell of triangle `t` that runs the edge `u -> v` (global point ids).
    fn cell_with_edge(&mut self, t: u32, u: u32, v: u32) -> Option<Cell> {
        if self.needs_sub(t) {
            self.sub(t).find(u, v).map(|s| Cell::Sub(t, s))
        } else {
            Some(Cell::Whole(t))
        }
    }

    fn seen(&mut self, c: Cell) -> bool {
        match c {
            Cell::Whole(t) => self.whole_seen[t as usize],
            Cell::Sub(t, s) => self.sub(t).visited[s as usize],
        }
    }

    fn mark(&mut self, c: Cell) {
        match c {
            Cell::Whole(t) => self.whole_seen[t as usize] = true,
            Cell::Sub(t, s) => self.sub(t).visited[s as usize] = true,
        }
    }

    /// Neighbouring cells: `(cell, across a segment)`.
    fn neighbours(&mut self, c: Cell, out: &mut Vec<(Cell, bool)>) {
        out.clear();
        match c {
            Cell::Whole(t) => {
                let tv = self.g.tris[t as usize];
                for k in 0..3 {
                    let u = self.g.nbr[t as usize][k];
                    if u == NONE {
                        continue;
                    }
                    match self.cell_with_edge(u / 3, tv[(k + 1) % 3], tv[k]) {
                        Some(n) => out.push((n, false)),
                        None => self.stitch_misses += 1,
                    }
                }
            }
            Cell::Sub(t, s) => {
                let (tri, nbr, fixed, partner, base) = {
                    let sub = self.sub(t);
                    let si = s as usize;
                    let tri = sub.cdt.tris[si].map(|i| sub.pts[i as usize]);
                    (tri, sub.cdt.nbr[si], sub.cdt.fixed[si], sub.partner[si], sub.base_edge[si])
                };
                for k in 0..3 {
                    let (u, v) = (tri[k], tri[(k + 1) % 3]);
                    if fixed[k] {
                        let b = partner[k];
                        if b == NONE {
                            self.stitch_misses += 1;
                            continue;
                        }
                        match self.cell_with_edge(b, v, u) {
                            Some(n) => out.push((n, true)),
                            None => self.stitch_misses += 1,
                        }
                    } else if nbr[k] != NONE {
                        out.push((Cell::Sub(t, nbr[k] / 3), false));
                    } else {
                        let e = base[k] as usize;
                        let bn = if e < 3 { self.g.nbr[t as usize][e] } else { NONE };
                        if bn == NONE {
                            if e >= 3 {
                                self.stitch_misses += 1;
                            }
                            continue;
                        }
                        match self.cell_with_edge(bn / 3, v, u) {
                            Some(n) => out.push((n, false)),
                            None => self.stitch_misses += 1,
                        }
                    }
                }
            }
        }
    }

    /// Whether `cell` bounds the enclosed space from outside: winding number
    /// about 0 a little in front of its centre, at least 1 a little behind.
    fn encloses(&mut self, cell: Cell) -> bool {
        let (p, base) = match cell {
            Cell::Whole(t) => (self.g.tris[t as usize].map(|i| self.g.positions[i as usize]), t),
            Cell::Sub(t, s) => {
                let sub = self.sub(t);
                let ids = sub.cdt.tris[s as usize].map(|i| sub.pts[i as usize]);
                (ids.map(|i| self.points.pos[i as usize]), t)
            }
        };
        let n = {
            let b = self.g.tris[base as usize].map(|i| self.g.positions[i as usize]);
            (b[1] - b[0]).cross(b[2] - b[0]).normalize_or_zero()
        };
        let c = (p[0] + p[1] + p[2]) / 3.0;
        let size = crate::math::sqrt((p[1] - p[0]).cross(p[2] - p[0]).length());
        if n == DVec3::ZERO || size <= 0.0 {
            return false;
        }
        let eps = 1e-3 * size;
        let front = winding(self.g.positions, self.g.tris, c + n * eps);
        let back = winding(self.g.positions, self.g.tris, c - n * eps);
        libm::round(front) == 0.0 && libm::round(back) >= 1.0
    }

    /// The seed cell at vertex `v` of triangle `t` (paper 002 step 3).
    fn seed(&mut self, t: u32, v: u32) -> Option<Cell> {
        if !self.needs_sub(t) {
            return Some(Cell::Whole(t));
        }
        let sub = self.sub(t);
        let local = sub.pts.iter().position(|&p| p == v)? as u32;
        sub.cdt.tris.iter().position(|x| x.contains(&local)).map(|s| Cell::Sub(t, s as u32))
    }
}

/// Generalized winding number of the closed triangle set around `p`: the
/// sum of the solid angles its triangles subtend (Van Oosterom–Strackee),
/// over 4π. An integer away from the surface: 1 inside once, 0 outside.
pub(crate) fn winding(positions: &[DVec3], tris: &[[u32; 3]], p: DVec3) -> f64 {
    let mut sum = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|i| positions[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * libm::atan2(num, den);
    }
    sum / (4.0 * core::f64::consts::PI)
}

/// Seeds to try for one component, best first (paper 002 step 3): the
/// triangle at the component's vertex of largest x that faces +x most, then
/// the same at the other five extremes, then triangles spread over the
/// component. Each is `(triangle, vertex)`; the seed cell is the triangle, or
/// its sub-triangle at that vertex.
fn candidates(g: &Geometry<'_>, members: &[u32]) -> Vec<(u32, u32)> {
    let dirs = [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z];
    let mut out = Vec::new();
    for d in dirs {
        let mut best_v: Option<(u32, f64)> = None;
        for &t in members {
            for &v in &g.tris[t as usize] {
                let h = g.positions[v as usize].dot(d);
                if best_v.is_none_or(|(_, b)| h > b) {
                    best_v = Some((v, h));
                }
            }
        }
        let Some((v, _)) = best_v else { continue };
        let mut best_t: Option<(u32, f64)> = None;
        for &t in members {
            let tri = g.tris[t as usize];
            if !tri.contains(&v) {
                continue;
            }
            let [a, b, c] = tri.map(|i| g.positions[i as usize]);
            let score = (b - a).cross(c - a).normalize_or_zero().dot(d);
            if best_t.is_none_or(|(_, s)| score > s) {
                best_t = Some((t, score));
            }
        }
        if let Some((t, _)) = best_t {
            if !out.contains(&(t, v)) {
                out.push((t, v));
            }
        }
    }
    let clear: Vec<u32> = members.iter().copied().filter(|&t| g.x.of(t).is_empty()).collect();
    let step = (clear.len() / SPREAD_SEEDS).max(1);
    for &t in clear.iter().step_by(step).take(SPREAD_SEEDS) {
        out.push((t, g.tris[t as usize][0]));
    }
    out
}

/// Triangles spread over a component tried as seeds after its six extremes.
const SPREAD_SEEDS: usize = 24;

/// Grows the valid regions and collects the kept triangles. Each connected
/// component that no earlier one reached gets a seed: the first candidate
/// ([`candidates`]) on the boundary of the space the mesh encloses (winding
/// number 0 just in front of it, at least 1 just behind). The paper takes the
/// extreme triangle as valid, which holds for outward offsets; an inward
/// offset's swallowtails stick out past the valid surface, hence the check.
/// Open meshes have no winding number: there the extreme triangle is taken.
pub(crate) fn grow(g: &Geometry<'_>, components: &[u32], ncomp: usize, closed: bool) -> Grown {
    let n = g.tris.len();
    let mut f = Flood {
        g,
        points: Points::new(g.positions),
        sub_of: alloc::vec![NONE; n],
        subs: Vec::new(),
        kind: alloc::vec![0; n],
        whole_seen: alloc::vec![false; n],
        stitch_misses: 0,
    };
    let mut members: Vec<Vec<u32>> = alloc::vec![Vec::new(); ncomp];
    for t in 0..n {
        members[components[t] as usize].push(t as u32);
    }
    let top = |c: usize| {
        members[c]
            .iter()
            .flat_map(|&t| g.tris[t as usize])
            .map(|v| g.positions[v as usize].x)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let mut order: Vec<(usize, f64)> = (0..ncomp).map(|c| (c, top(c))).collect();
    order.sort_unstable_by(|a, b| b.1.total_cmp(&a.1));
    let order: Vec<usize> = order.into_iter().map(|(c, _)| c).collect();
    let mut comp_reached = alloc::vec![false; ncomp];
    let mut regions = 0;
    let mut inner: VecDeque<Cell> = VecDeque::new();
    let mut cross: VecDeque<Cell> = VecDeque::new();
    let mut around = Vec::new();
    let mut unseeded = 0;
    for c in order {
        if comp_reached[c] {
            continue;
        }
        let mut start = None;
        for (t, v) in candidates(g, &members[c]) {
            let Some(cell) = f.seed(t, v) else { continue };
            if !closed || f.encloses(cell) {
                start = Some(cell);
                break;
            }
        }
        let Some(start) = start else {
            unseeded += 1;
            continue;
        };
        cross.push_back(start);
        while let Some(next) = cross.pop_front() {
            if f.seen(next) {
                continue;
            }
            regions += 1;
            f.mark(next);
            inner.push_back(next);
            while let Some(cell) = inner.pop_front() {
                let base = match cell {
                    Cell::Whole(t) | Cell::Sub(t, _) => t,
                };
                comp_reached[components[base as usize] as usize] = true;
                f.neighbours(cell, &mut around);
                for &(nc, across) in around.iter() {
                    if f.seen(nc) {
                        continue;
                    }
                    if across {
                        cross.push_back(nc);
                    } else {
                        f.mark(nc);
                        inner.push_back(nc);
                    }
                }
            }
        }
    }
    let mut tris = Vec::new();
    for (t, &seen) in f.whole_seen.iter().enumerate() {
        if seen {
            tris.push(g.tris[t]);
        }
    }
    for sub in &f.subs {
        for (s, &seen) in sub.visited.iter().enumerate() {
            if seen {
                tris.push(sub.cdt.tris[s].map(|i| sub.pts[i as usize]));
            }
        }
    }
    let fallbacks = f.subs.iter().filter(|s| s.fallback).count();
    let census = super::check::census(&tris);
    let closed = census == super::check::EdgeCensus::default();
    Grown {
        tris,
        points: f.points,
        regions,
        subdivided: f.subs.len(),
        fallbacks,
        stitch_misses: f.stitch_misses,
        unseeded,
        closed,
    }
}

/// Positions and triangles of the kept cells with unused points dropped.
pub(crate) fn compact(points: &[DVec3], tris: &[[u32; 3]]) -> (Vec<DVec3>, Vec<u32>) {
    let mut map = alloc::vec![NONE; points.len()];
    let mut pos = Vec::new();
    let mut indices = Vec::with_capacity(3 * tris.len());
    for t in tris {
        for &i in t {
            let m = &mut map[i as usize];
            if *m == NONE {
                *m = pos.len() as u32;
                pos.push(points[i as usize]);
            }
            indices.push(*m);
        }
    }
    (pos, indices)
}
