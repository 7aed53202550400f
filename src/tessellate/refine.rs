//! Refinement until proven: every triangle is measured against the exact
//! surface, and one that deviates too far, turns its normal too much or has an
//! edge too long is split at its longest edge (with the neighbour across that
//! edge, so the mesh stays conforming), until all pass.

use crate::collections::{HashMap, PairMap};
use alloc::vec::Vec;
use glam::{DVec2, DVec3, Vec3};

use super::measure::{measure_projection, measure_triangle, sample_count, EdgeSamples, TriMeasure};
use crate::math::angle_between;
use crate::nurbs::{project_to_surface, regular_normal, NurbsCurve, Surface};

mod check;
mod edges;
#[cfg(feature = "std")]
mod lift;
mod limits;
mod mend;

pub(crate) use check::Known;
pub(crate) use edges::EdgeList;
pub(crate) use limits::{Criteria, Lift, Outcome, FOLD_TURN};
use limits::{Packed, STALE};
pub(crate) use mend::count_folded;

pub(crate) const NONE: u32 = u32::MAX;

/// Twice the signed area of the (u,v) triangle `w`: positive when its
/// corners run counter-clockwise.
fn uv_area(w: [DVec2; 3]) -> f64 {
    (w[1] - w[0]).perp_dot(w[2] - w[0])
}

/// A trim edge: the curve it follows and the parameters at its lower- and
/// higher-numbered vertex.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TrimEdge {
    pub curve: u32,
    pub t_lo: f64,
    pub t_hi: f64,
}

/// A corner within this fraction of the tolerance of the surface point at
/// its (u,v) lies on the surface (sewing moves border nodes farther).
const ON_SURFACE: f64 = 1e-6;

/// Marks a vertex no triangle has given a (u,v) yet: a NaN with a payload
/// arithmetic does not make (it propagates only a NaN it is given).
const UV_UNSET: u64 = 0x7ff8_5eed_0000_0001;

/// Whether two (u,v) are the same bits (0.0 and -0.0 differ: a corner must
/// read back exactly what was written).
fn same_uv(a: DVec2, b: DVec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// The mesh of one face while it is refined: shared vertices, each corner of
/// a triangle with its own (u,v) (a seam or pole vertex has a different (u,v)
/// in each chart). Stored per vertex, since nearly every corner has its
/// vertex's (u,v): a triangle whose corners differ keeps its own in a side
/// table (about one in a hundred), 16 bytes a vertex instead of 48 a triangle.
#[derive(Debug, Default)]
pub(crate) struct WorkMesh {
    pub pos: Vec<DVec3>,
    /// Per vertex: its surface normal, in `f32` (what the page draws; it
    /// only judges how far a triangle's normal turns), half the room.
    normal: Vec<Vec3>,
    pub tris: Vec<[u32; 3]>,
    /// Per vertex: the (u,v) the first triangle to use it gave it.
    vuv: Vec<DVec2>,
    /// The corner (u,v)s of triangles where one differs from its vertex's.
    odd_uv: HashMap<u32, [DVec2; 3]>,
    /// The triangles on each edge, in the order they were attached, while awake.
    edges: PairMap<[u32; 2]>,
    /// Whether the face is at rest ([`WorkMesh::rest`]): no edge table, only
    /// its border edges in `rim`.
    resting: bool,
    /// At rest: each border edge (one triangle) and its triangle; what a
    /// neighbour's split of a shared edge and the border walks need.
    rim: EdgeList<u32>,
    trim: EdgeList<TrimEdge>,
    /// Per vertex: its node id across the model (`NONE` for inner vertices),
    /// so that borders of different faces can name the same node.
    pub gid: Vec<u32>,
    /// Border edges another face (or another stretch of this face's border,
    /// across a seam) shares: a split of one must be made in the other.
    pub shared: EdgeList<()>,
    /// Shared edges refinement split, as `(a, b, new vertex)`, for the caller
    /// to make the same split where the edge is shared.
    pub events: Vec<(u32, u32, u32)>,
    /// Edges of more than two triangles (sewing that passes a loop through
    /// one node twice), found as they are attached: the edge table holds
    /// two of their triangles, so a split of one halves those two and the
    /// table then lists the others on it (before, they were left on an
    /// edge no table had), and none is flipped or collapsed.
    crowded: crate::collections::HashSet<(u32, u32)>,
    /// Cached measure and normal turn of each triangle; [`STALE`] (a NaN
    /// distance) marks one changed since measured, which saves an `Option`'s
    /// tag, and the sample count follows from the grid: 12 bytes a triangle.
    measures: Vec<Packed>,
    /// Distances at edge samples whose other triangle is still to be
    /// measured; held only while a refinement or an outcome measures.
    edge_samples: EdgeSamples,
    /// Measures a trial mesh of this face took within the same criteria,
    /// by triangle ([`WorkMesh::measure_key`]): the one refinement of the
    /// model's mesh would take again where its triangles are the trial's.
    pub carried: Carried,
    /// Every measure taken, by triangle, while logging (a trial mesh's:
    /// the triangles refinement went on to split are measured again when
    /// the model's mesh is refined).
    log: Option<Carried>,
}

/// A triangle's corner points, (u,v)s and normals, bit for bit: all its
/// measure depends on, for one surface and criteria.
pub(crate) type MeasureKey = ([u64; 15], [u32; 9]);

/// Measures by [`MeasureKey`], carried from a trial mesh to the model's.
pub(crate) type Carried = HashMap<MeasureKey, Packed>;

/// One triangle of an edge being split.
#[derive(Debug, Clone, Copy)]
struct SplitSide {
    /// The triangle.
    t: u32,
    /// Its corners starting at the edge (the edge's two ends, then the third).
    corners: [u32; 3],
    /// Their (u,v) in this triangle.
    uv: [DVec2; 3],
    /// The new vertex's (u,v).
    uv_m: DVec2,
    /// The edge's own (u,v) point at the split fraction.
    guess: DVec2,
}

/// An edge's key in the tables: its two ends, lower first.
pub(crate) fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The parameter between `ta` and `tb` of trim curve `c` whose point is as
/// far from `pa` as from `pb` (bisection), or None when the ends do not
/// bracket it. Refinement halves a trim edge in model space: a curve whose
/// parameter crowds (most of its range on a short stretch) would otherwise
/// be split next to one end, again and again.
fn model_middle(surface: &dyn Surface, c: &NurbsCurve, pa: DVec3, pb: DVec3, ta: f64, tb: f64) -> Option<f64> {
    let side = |t: f64| {
        let p = surface.point(c.point(t).truncate());
        p.distance(pa) - p.distance(pb)
    };
    let (mut lo, mut hi) = (ta, tb);
    if !(side(lo) < 0.0 && side(hi) > 0.0) {
        return None;
    }
    for _ in 0..48 {
        let mid = 0.5 * (lo + hi);
        if side(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Whether a new vertex at `uv_m` on the first side of (u,v) triangle `u`
/// folds either child (or leaves it flat) where the triangle is not.
fn split_folds(u: [DVec2; 3], uv_m: DVec2) -> bool {
    let whole = uv_area(u);
    whole != 0.0 && (uv_area([u[0], uv_m, u[2]]) * whole <= 0.0 || uv_area([uv_m, u[1], u[2]]) * whole <= 0.0)
}

/// A sewing target whose (u,v) would fold the children of a split (a thin
/// triangle on a curved border) goes in at the edge's own point instead, on
/// this face's surface: the children keep their (u,v) orientation and face
/// the surface's way. Returns that place and normal, or None when no child
/// folds. Settling later moves the node halfway to where the other face
/// has it; put there at once, a node off its (u,v) folded the thin children
/// in space, and refinement split those folds down to slivers (99 on one
/// cylinder of a valve body).
fn unfold_target(surface: &dyn Surface, plan: &mut [SplitSide]) -> Option<(DVec3, DVec3)> {
    if !plan.iter().any(|s| split_folds(s.uv, s.uv_m)) {
        return None;
    }
    for s in plan.iter_mut() {
        s.uv_m = s.guess;
    }
    let uv = plan.first()?.guess;
    Some((surface.point(uv), surface.normal(uv)))
}

/// Makes room for `extra` more elements, growing by a quarter: every face's
/// mesh is held until the model is assembled, and wasm memory never shrinks,
/// so the slack of doubling (up to half of each buffer) would stay with the page.
/// The least step is small: most faces of a large model have a few dozen
/// triangles, and a step of 64 left their buffers mostly empty.
fn room<T>(v: &mut Vec<T>, extra: usize) {
    if v.capacity() - v.len() < extra {
        v.reserve_exact(v.len() / 4 + extra.max(8));
    }
}

impl WorkMesh {
    /// Room for `verts` more vertices and `tris` more triangles.
    fn room(&mut self, verts: usize, tris: usize) {
        room(&mut self.pos, verts);
        room(&mut self.normal, verts);
        room(&mut self.gid, verts);
        room(&mut self.vuv, verts);
        room(&mut self.tris, tris);
    }

    /// The (u,v) of triangle `t`'s corners.
    pub fn uv(&self, t: usize) -> [DVec2; 3] {
        if !self.odd_uv.is_empty() {
            if let Some(w) = self.odd_uv.get(&(t as u32)) {
                return *w;
            }
        }
        self.tris[t].map(|v| self.vuv[v as usize])
    }

    /// Sets the (u,v) of triangle `t`'s corners (its vertices already set):
    /// a vertex without one takes its corner's; a triangle whose corners
    /// differ from their vertices' keeps its own.
    fn set_uv(&mut self, t: usize, w: [DVec2; 3]) {
        let v = self.tris[t];
        let mut odd = false;
        for k in 0..3 {
            let x = &mut self.vuv[v[k] as usize];
            if x.x.to_bits() == UV_UNSET {
                *x = w[k];
            }
            odd |= !same_uv(*x, w[k]);
        }
        if odd {
            self.odd_uv.insert(t as u32, w);
        } else if !self.odd_uv.is_empty() {
            self.odd_uv.remove(&(t as u32));
        }
    }

    /// Moves vertex `x` to `q` in (u,v) in every triangle of `ring`, which
    /// must be all the triangles that use it.
    fn move_uv(&mut self, x: u32, ring: &[u32], q: DVec2) {
        let old: Vec<[DVec2; 3]> = ring.iter().map(|&t| self.uv(t as usize)).collect();
        self.vuv[x as usize] = q;
        for (&t, mut w) in ring.iter().zip(old) {
            let tv = self.tris[t as usize];
            for k in 0..3 {
                if tv[k] == x {
                    w[k] = q;
                }
            }
            self.set_uv(t as usize, w);
        }
    }

    /// A new vertex, without a (u,v) until a triangle uses it.
    fn push_vertex(&mut self, p: DVec3, n: DVec3) -> u32 {
        self.room(1, 0);
        self.pos.push(p);
        self.normal.push(n.as_vec3());
        self.gid.push(NONE);
        self.vuv.push(DVec2::new(f64::from_bits(UV_UNSET), f64::from_bits(UV_UNSET)));
        (self.pos.len() - 1) as u32
    }

    /// Puts the face at rest once refinement is done with it for now: the
    /// edge table (the largest part of a face's working state) is dropped,
    /// only the border edges kept, and the room kept for growth is given
    /// back. Every face is held until the model is assembled; a neighbour's
    /// split of a shared border edge works at rest, anything else wakes the
    /// face ([`WorkMesh::wake`]) first.
    pub fn rest(&mut self) {
        if !self.resting {
            let rim = self.edges.iter().filter(|(_, t)| t[1] == NONE).map(|(k, t)| (k, t[0])).collect();
            self.edges = PairMap::default();
            self.rim = EdgeList::from_unsorted(rim);
            self.resting = true;
        }
        self.edge_samples = EdgeSamples::default();
        self.pos.shrink_to_fit();
        self.normal.shrink_to_fit();
        self.gid.shrink_to_fit();
        self.vuv.shrink_to_fit();
        self.tris.shrink_to_fit();
        self.measures.shrink_to_fit();
        self.events.shrink_to_fit();
        self.rim.shrink();
        self.trim.shrink();
        self.shared.shrink();
    }

    /// Rebuilds the edge table of a face at rest from its triangles, in
    /// index order, so an edge's triangles come lowest first where the table
    /// kept up lists them as attached (that order picks which side's (u,v)
    /// places a split's point). Keeping them lowest first throughout cost the
    /// corpus survey four more folded triangles; attach order as before did not.
    pub fn wake(&mut self) {
        if !self.resting {
            return;
        }
        self.resting = false;
        let n = (3 * self.tris.len() + self.rim.0.len()) / 2;
        self.rim = EdgeList::default();
        self.edges = PairMap::with_capacity(n, [NONE, NONE]);
        self.crowded.clear();
        for t in 0..self.tris.len() {
            let v = self.tris[t];
            for k in 0..3 {
                self.attach(v[k], v[(k + 1) % 3], t as u32);
            }
        }
    }

    /// A slot in the measure cache per triangle.
    fn measure_slots(&mut self) {
        let missing = self.tris.len().saturating_sub(self.measures.len());
        room(&mut self.measures, missing);
        self.measures.resize(self.tris.len(), STALE);
    }

    /// Vertex `v`'s surface normal, of unit length again after the rounding to `f32`.
    pub fn normal_at(&self, v: usize) -> DVec3 {
        let n = self.normal[v].as_dvec3();
        let l = n.length();
        if l > 0.0 {
            n / l
        } else {
            n
        }
    }

    /// Adds a vertex with its surface normal.
    pub fn add_vertex(&mut self, p: DVec3, n: DVec3) -> u32 {
        self.push_vertex(p, n)
    }

    /// Adds a triangle (counter-clockwise in (u,v)).
    pub fn add_triangle(&mut self, v: [u32; 3], uv: [DVec2; 3]) {
        self.wake();
        let t = self.tris.len() as u32;
        self.room(0, 1);
        self.tris.push(v);
        self.set_uv(t as usize, uv);
        for k in 0..3 {
            self.attach(v[k], v[(k + 1) % 3], t);
        }
    }

    /// Marks `a-b` as following trim curve `curve` from `ta` (at a) to `tb` (at b).
    pub fn mark_trim(&mut self, a: u32, b: u32, curve: u32, ta: f64, tb: f64) {
        let (t_lo, t_hi) = if a < b { (ta, tb) } else { (tb, ta) };
        self.trim.insert(key(a, b), TrimEdge { curve, t_lo, t_hi });
    }

    /// How many triangles use edge `a-b` (at most two; at rest an inner
    /// edge is counted by a walk over the triangles).
    #[cfg(feature = "std")]
    pub fn edge_triangles(&self, a: u32, b: u32) -> usize {
        if self.resting {
            if self.rim.contains_key(&key(a, b)) {
                return 1;
            }
            return self.tris.iter().filter(|t| t.contains(&a) && t.contains(&b) && a != b).take(2).count();
        }
        self.edges.get(&key(a, b)).map_or(0, |e| e.iter().filter(|&&t| t != NONE).count())
    }

    /// Whether edge `a-b` is a border edge (one triangle), at rest as awake.
    pub fn is_border(&self, a: u32, b: u32) -> bool {
        if self.resting {
            return self.rim.contains_key(&key(a, b));
        }
        self.edges.get(&key(a, b)).is_some_and(|e| e[0] != NONE && e[1] == NONE)
    }

    fn attach(&mut self, a: u32, b: u32, t: u32) {
        if self.resting {
            return;
        }
        let e = self.edges.get_or_insert(key(a, b), [NONE, NONE]);
        if e[0] == NONE {
            e[0] = t;
        } else if e[1] == NONE {
            e[1] = t;
        } else {
            self.crowded.insert(key(a, b));
        }
    }

    /// The two triangles the edge table lists on edge `a-b` (one and
    /// `NONE` on a border edge), or None where it has none or is crowded
    /// (more than two: see `crowded`), for the flips, moves and walks that
    /// take an edge for two triangles.
    fn pair(&self, a: u32, b: u32) -> Option<&[u32; 2]> {
        if !self.crowded.is_empty() && self.crowded.contains(&key(a, b)) {
            return None;
        }
        self.edges.get(&key(a, b))
    }

    fn detach(&mut self, a: u32, b: u32, t: u32) {
        if self.resting {
            return;
        }
        if let Some(e) = self.edges.get_mut(&key(a, b)) {
            if e[0] == t {
                e[0] = e[1];
                e[1] = NONE;
            } else if e[1] == t {
                e[1] = NONE;
            }
            if e[0] == NONE {
                self.edges.remove(&key(a, b));
            }
        }
    }

    fn measure(&self, surface: &dyn Surface, t: usize, c: &Criteria) -> (TriMeasure, f64) {
        self.measure_sharing(surface, t, c, None, f64::INFINITY).unwrap_or_default()
    }

    /// As [`Self::measure`], with edge samples shared between neighbours
    /// through `shared`; `None` as soon as a sample lies farther than `limit`.
    fn measure_sharing(
        &self,
        surface: &dyn Surface,
        t: usize,
        c: &Criteria,
        shared: Option<&mut EdgeSamples>,
        limit: f64,
    ) -> Option<(TriMeasure, f64)> {
        let v = self.tris[t];
        let p = [self.pos[v[0] as usize], self.pos[v[1] as usize], self.pos[v[2] as usize]];
        let uv = self.uv(t);
        let m = measure_triangle(surface, &p, &uv, c.steps, &measure_projection(), shared, limit)?;
        let mut n = v.map(|x| self.normal_at(x as usize));
        let turn_of =
            |n: &[DVec3; 3]| angle_between(n[0], n[1]).max(angle_between(n[1], n[2])).max(angle_between(n[2], n[0]));
        let mut turn = turn_of(&n);
        if turn > c.angle {
            // A corner's own normal is one side's on a crease (a C0 knot
            // line: a zig-zag strip's every fold) and none where the surface
            // collapses (a cone's apex): a triangle there turns by what it
            // sees from its side. Else every triangle on the other side of
            // a crease was split down to the crease limit (see
            // `Criteria::short_for_angle`).
            let centre = (uv[0] + uv[1] + uv[2]) / 3.0;
            let inside: [Option<DVec3>; 3] = core::array::from_fn(|k| {
                [1e-6, 1e-4, 1e-2].iter().find_map(|f| regular_normal(&surface.derivs(uv[k] + (centre - uv[k]) * *f)))
            });
            let all = inside.iter().all(Option::is_some);
            for k in 0..3 {
                if let Some(l) = inside[k] {
                    if all || regular_normal(&surface.derivs(uv[k])).is_none() {
                        n[k] = l;
                    }
                }
            }
            turn = turn_of(&n);
        }
        Some((m, turn))
    }

    /// [`Criteria::short_for_angle`] for triangle `t` of measure `m` and
    /// normal turn `turn`, its width across the turn found only when the
    /// longest edge alone does not settle it.
    pub(crate) fn short_for_angle(
        &self,
        surface: &dyn Surface,
        c: &Criteria,
        t: usize,
        m: &TriMeasure,
        turn: f64,
    ) -> bool {
        let edge = self.longest_edge(t);
        let len = edge.2;
        if c.short_for_angle(m, turn, len, len) {
            return true;
        }
        c.short_for_angle(m, turn, len, 0.0) && c.short_for_angle(m, turn, len, self.turn_width(surface, c, t, edge))
    }

    /// How wide triangle `t` is across its normal's turn: where the ends
    /// and middle of its longest edge `edge` face alike (within the angle
    /// limit), the normal turns across the triangle (a curl or fillet
    /// running beside that edge), and splitting the edge, all refinement
    /// does to a sliver, never lowers the turn: the triangle's height over
    /// it. Elsewhere the edge's length.
    fn turn_width(&self, surface: &dyn Surface, c: &Criteria, t: usize, edge: (u32, u32, f64)) -> f64 {
        let (a, b, len) = edge;
        let v = self.tris[t];
        let uv = self.uv(t);
        let (Some(i), Some(j)) = (v.iter().position(|&x| x == a), v.iter().position(|&x| x == b)) else { return len };
        let (na, nb) = (self.normal_at(a as usize), self.normal_at(b as usize));
        if na.length_squared() == 0.0 || nb.length_squared() == 0.0 {
            return len;
        }
        let Some(nm) = regular_normal(&surface.derivs((uv[i] + uv[j]) * 0.5)) else { return len };
        if [(na, nb), (na, nm), (nm, nb)].iter().any(|&(x, y)| angle_between(x, y) > c.angle) {
            return len;
        }
        crate::math::triangle_width(v.map(|x| self.pos[x as usize])).min(len)
    }

    /// Triangle `t`'s smallest angle in space.
    pub(crate) fn least_angle(&self, t: u32) -> f64 {
        crate::mesh::min_angle(self.tris[t as usize].map(|v| self.pos[v as usize]))
    }

    fn longest_edge(&self, t: usize) -> (u32, u32, f64) {
        let v = self.tris[t];
        let mut best = (v[0], v[1], -1.0);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let l = self.pos[a as usize].distance(self.pos[b as usize]);
            if l > best.2 {
                best = (a, b, l);
            }
        }
        best
    }

    /// Splits edge `a-b` at its middle and the (one or two) triangles on it;
    /// pushes the triangles that changed or were added to `out`.
    fn split_edge(&mut self, surface: &dyn Surface, curves: &[&NurbsCurve], a: u32, b: u32, out: &mut Vec<u32>) {
        let shared = self.shared.contains_key(&key(a, b));
        if let Some(m) = self.split_edge_at(surface, curves, a, b, 0.5, None, out) {
            if shared {
                self.events.push((a, b, m));
            }
        }
    }

    /// Splits the longest edge of `t` by Rivara's longest-edge propagation:
    /// while the neighbour across it has a longer edge of its own, that
    /// neighbour's longest edge is split first. Splitting only terminal edges
    /// (longest for both triangles) keeps angles bounded away from zero, where
    /// plain bisection of whatever edge the neighbour shares breeds slivers.
    fn split_lepp(
        &mut self,
        surface: &dyn Surface,
        curves: &[&NurbsCurve],
        t: u32,
        first: (u32, u32),
        out: &mut Vec<u32>,
    ) {
        let target = key(first.0, first.1);
        for _ in 0..64 {
            if !self.edges.contains_key(&target) {
                return; // t's longest edge has been split
            }
            // Walk from t across longest edges until an edge is longest on both sides.
            let (mut a, mut b) = first;
            let mut cur = t;
            for _ in 0..64 {
                let Some(adj) = self.pair(a, b) else { break };
                let other = if adj[0] == cur { adj[1] } else { adj[0] };
                if other == NONE {
                    break;
                }
                let (c, d, _) = self.longest_edge(other as usize);
                if key(c, d) == key(a, b) {
                    break;
                }
                cur = other;
                (a, b) = (c, d);
            }
            self.split_edge(surface, curves, a, b, out);
            if key(a, b) == target {
                return;
            }
        }
    }

    /// The point of the exact boundary under edge `a-b` at fraction `frac`
    /// (from `a`): on its trim curve when it has one, else on the (u,v)
    /// segment of its only triangle (an iso-line on an untrimmed border).
    pub fn boundary_point(
        &self,
        surface: &dyn Surface,
        curves: &[&NurbsCurve],
        a: u32,
        b: u32,
        frac: f64,
    ) -> Option<(DVec2, DVec3)> {
        if let Some(te) = self.trim.get(&key(a, b)) {
            let c = curves.get(te.curve as usize)?;
            let (ta, tb) = if a < b { (te.t_lo, te.t_hi) } else { (te.t_hi, te.t_lo) };
            let uv = c.point(ta + (tb - ta) * frac).truncate();
            return Some((uv, surface.point(uv)));
        }
        let t = self.first_on(a, b)?;
        let tv = self.tris.get(t as usize)?;
        let i = (0..3).find(|&k| key(tv[k], tv[(k + 1) % 3]) == key(a, b))?;
        let tuv = self.uv(t as usize);
        let (ua, ub) = if tv[i] == a { (tuv[i], tuv[(i + 1) % 3]) } else { (tuv[(i + 1) % 3], tuv[i]) };
        let uv = ua.lerp(ub, frac);
        Some((uv, surface.point(uv)))
    }

    /// The lowest-numbered triangle on edge `a-b` (at rest, of an inner
    /// edge, by a walk over the triangles).
    fn first_on(&self, a: u32, b: u32) -> Option<u32> {
        if !self.resting {
            return self.edges.get(&key(a, b)).map(|e| e[0]);
        }
        if let Some(&t) = self.rim.get(&key(a, b)) {
            return Some(t);
        }
        let on = |t: &[u32; 3]| a != b && t.contains(&a) && t.contains(&b);
        self.tris.iter().position(on).map(|t| t as u32)
    }

    /// Edges used by exactly one triangle.
    pub fn boundary_edges(&self) -> Vec<(u32, u32)> {
        if self.resting {
            return self.rim.keys().collect();
        }
        let mut out: Vec<(u32, u32)> = self.edges.iter().filter(|(_, t)| t[1] == NONE).map(|(k, _)| k).collect();
        crate::sort::pairs(&mut out);
        out
    }

    /// Splits edge `a-b` at fraction `frac` from `a` (on the trim curve for
    /// trim edges); the new vertex goes to `target` when given (sewing to a
    /// neighbour's vertex), else onto the surface. Returns the new vertex.
    #[allow(clippy::too_many_arguments)]
    pub fn split_edge_at(
        &mut self,
        surface: &dyn Surface,
        curves: &[&NurbsCurve],
        a: u32,
        b: u32,
        frac: f64,
        target: Option<DVec3>,
        out: &mut Vec<u32>,
    ) -> Option<u32> {
        // At rest a border edge is split with the rim alone; any other wakes the face.
        let on_rim = if self.resting { self.rim.get(&key(a, b)).copied() } else { None };
        if on_rim.is_none() {
            self.wake();
        }
        let adj = match on_rim {
            Some(t) => [t, NONE],
            None => *self.edges.get(&key(a, b))?,
        };
        // A crowded edge's triangles the table does not list (found by a
        // walk: rare) keep the edge, and the table lists them on it after.
        let unlisted: Vec<u32> = if !self.crowded.is_empty() && self.crowded.contains(&key(a, b)) {
            let on = |t: &[u32; 3]| t.contains(&a) && t.contains(&b);
            let listed = |i: u32| adj.contains(&i);
            (0..self.tris.len() as u32).filter(|&i| !listed(i) && on(&self.tris[i as usize])).collect()
        } else {
            Vec::new()
        };
        let trim = self.trim.get(&key(a, b)).copied();
        // The split's (u,v) and the curve parameters at a, the split and b.
        let trim_at = trim.and_then(|te| {
            let c = curves.get(te.curve as usize)?;
            let (ta, tb) = if a < b { (te.t_lo, te.t_hi) } else { (te.t_hi, te.t_lo) };
            let halving = target.is_none() && frac == 0.5;
            let middle = if halving {
                model_middle(surface, c, self.pos[a as usize], self.pos[b as usize], ta, tb)
            } else {
                None
            };
            let tm = middle.unwrap_or(ta + (tb - ta) * frac);
            Some((c.point(tm).truncate(), ta, tm, tb))
        });
        let (mut plan, mut p, mut normal) = self.plan_split(surface, adj, a, b, frac, trim_at.map(|s| s.0), target)?;
        if target.is_some() {
            (p, normal) = unfold_target(surface, &mut plan).unwrap_or((p, normal));
        } else if self.splits_nothing(a, b, p, &plan) {
            // An inner corner beyond the curve's point moves inside, then the edge splits.
            let moved = match (trim_at, plan.as_slice()) {
                (Some(_), [side]) => self.make_room(surface, side, out),
                _ => false,
            };
            if !moved {
                return None;
            }
            (plan, p, normal) = self.plan_split(surface, adj, a, b, frac, trim_at.map(|s| s.0), None)?;
            if self.splits_nothing(a, b, p, &plan) {
                return None;
            }
        }
        let m = self.apply_split(a, b, p, normal, plan, out);
        if !unlisted.is_empty() {
            self.crowded.remove(&key(a, b));
            for t in unlisted {
                self.attach(a, b, t);
            }
        }
        if let (Some(te), Some((_, ta, tm, tb))) = (trim, trim_at) {
            self.trim.remove(&key(a, b));
            self.mark_trim(a, m, te.curve, ta, tm);
            self.mark_trim(m, b, te.curve, tm, tb);
        }
        Some(m)
    }

    /// Where the new vertex of a split of edge `a-b` goes in each triangle
    /// on it (`adj`), and its place and normal: at `trim_uv` on a trim edge,
    /// else at `target` (in each triangle's own (u,v) of it: across a seam or
    /// at a pole the charts differ), else on the surface at the edge's own
    /// (u,v) point at `frac`. None when no triangle has the edge.
    #[allow(clippy::too_many_arguments)]
    fn plan_split(
        &self,
        surface: &dyn Surface,
        adj: [u32; 2],
        a: u32,
        b: u32,
        frac: f64,
        trim_uv: Option<DVec2>,
        target: Option<DVec3>,
    ) -> Option<(Vec<SplitSide>, DVec3, DVec3)> {
        let mut plan: Vec<SplitSide> = Vec::with_capacity(2);
        let mut m_pos: Option<DVec3> = None;
        let mut m_normal = DVec3::ZERO;
        for &t in adj.iter().filter(|&&t| t != NONE) {
            let tv = self.tris[t as usize];
            let tuv = self.uv(t as usize);
            let Some(i) = (0..3).find(|&k| key(tv[k], tv[(k + 1) % 3]) == key(a, b)) else { continue };
            let (x0, x1, x2) = (tv[i], tv[(i + 1) % 3], tv[(i + 2) % 3]);
            let (u0, u1, u2) = (tuv[i], tuv[(i + 1) % 3], tuv[(i + 2) % 3]);
            let f = if x0 == a { frac } else { 1.0 - frac };
            let guess = u0.lerp(u1, f);
            let uv_m = match (trim_uv, m_pos.or(target)) {
                (Some(uv), _) => uv,
                (None, None) => guess,
                (None, Some(p)) => {
                    // Another chart (seam or pole), or a sewing target: this triangle's (u,v) of the point.
                    if surface.point(guess).distance(p) <= 1e-12 * (1.0 + p.length()) {
                        guess
                    } else {
                        project_to_surface(surface, p, Some(guess), &measure_projection()).uv
                    }
                }
            };
            if m_pos.is_none() {
                m_pos = Some(target.unwrap_or_else(|| surface.point(uv_m)));
                m_normal = surface.normal(uv_m);
            }
            plan.push(SplitSide { t, corners: [x0, x1, x2], uv: [u0, u1, u2], uv_m, guess });
        }
        Some((plan, m_pos?, m_normal))
    }

    /// Whether a split of `a-b` at `p` would split nothing and be split again
    /// forever: a point not strictly inside the edge, or on a triangle's
    /// third corner, or children that fold in (u,v) (a curve whose
    /// parameters no longer match the ends, corners of one (u,v) at a
    /// collapsed border). Such an edge stays as it is.
    fn splits_nothing(&self, a: u32, b: u32, p: DVec3, plan: &[SplitSide]) -> bool {
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let near = 1e-6 * pa.distance(pb);
        !(p.distance(pa) > near && p.distance(pb) > near)
            || plan.iter().any(|s| p.distance(self.pos[s.corners[2] as usize]) <= near || split_folds(s.uv, s.uv_m))
    }

    /// Where the curve of trim edge `side` bulges into the face past its
    /// inner third corner (a vertex split in on an inner edge between the
    /// chord and the curve: outside the face, where a surface that rolls
    /// over at its border faces the other way), so that the edge's split
    /// would fold a child in (u,v), moves that corner to the (u,v) centre of
    /// its neighbours, where the split folds nothing and every triangle
    /// round it keeps its orientation. Its triangles go to `out` to be
    /// measured again; returns whether it moved.
    fn make_room(&mut self, surface: &dyn Surface, side: &SplitSide, out: &mut Vec<u32>) -> bool {
        let x = side.corners[2];
        if self.gid[x as usize] != NONE || !split_folds(side.uv, side.uv_m) {
            return false;
        }
        self.wake();
        let Some(ring) = self.fan(side.t, x) else { return false };
        let mut centre = DVec2::ZERO;
        let mut n = 0.0;
        for &t in &ring {
            let (tv, tuv) = (self.tris[t as usize], self.uv(t as usize));
            for k in 0..3 {
                if tv[k] != x {
                    centre += tuv[k];
                    n += 1.0;
                } else if !same_uv(tuv[k], side.uv[2]) {
                    return false; // another chart: a seam or pole
                }
            }
        }
        let q = centre / n;
        if n == 0.0 || !q.is_finite() || split_folds([side.uv[0], side.uv[1], q], side.uv_m) {
            return false;
        }
        let turns = |m: &Self, t: u32, q: DVec2| {
            let (tv, mut tuv) = (m.tris[t as usize], m.uv(t as usize));
            let before = uv_area(tuv);
            for k in 0..3 {
                if tv[k] == x {
                    tuv[k] = q;
                }
            }
            uv_area(tuv) * before <= 0.0
        };
        if ring.iter().any(|&t| turns(self, t, q)) {
            return false;
        }
        let (p, normal) = (surface.point(q), surface.normal(q));
        if !p.is_finite() || !normal.is_finite() {
            return false;
        }
        self.pos[x as usize] = p;
        self.normal[x as usize] = normal.as_vec3();
        self.move_uv(x, &ring, q);
        out.extend_from_slice(&ring);
        true
    }

    /// Makes the split `plan` of edge `a-b`: a new vertex at `p`, each
    /// triangle on the edge halved, the border, shared and trim tables
    /// following. The changed triangles go to `out`; returns the vertex.
    fn apply_split(
        &mut self,
        a: u32,
        b: u32,
        p: DVec3,
        normal: DVec3,
        plan: Vec<SplitSide>,
        out: &mut Vec<u32>,
    ) -> u32 {
        self.room(1, plan.len());
        let m = self.push_vertex(p, normal);
        for SplitSide { t, corners: [x0, x1, x2], uv: [u0, u1, u2], uv_m, .. } in plan {
            // Replace t by [x0, m, x2] and add [m, x1, x2].
            self.detach(x0, x1, t);
            self.detach(x1, x2, t);
            self.tris[t as usize] = [x0, m, x2];
            self.set_uv(t as usize, [u0, uv_m, u2]);
            self.attach(x0, m, t);
            self.attach(m, x2, t);
            let t2 = self.tris.len() as u32;
            self.tris.push([m, x1, x2]);
            self.set_uv(t2 as usize, [uv_m, u1, u2]);
            self.attach(m, x1, t2);
            self.attach(x1, x2, t2);
            self.attach(x2, m, t2);
            if self.resting {
                // A border edge's one triangle: its two halves are border
                // edges, and its side x1-x2 moved to the new triangle.
                self.rim.remove(&key(a, b));
                self.rim.insert(key(x0, m), t);
                self.rim.insert(key(m, x1), t2);
                if let Some(r) = self.rim.get_mut(&key(x1, x2)).filter(|r| **r == t) {
                    *r = t2;
                }
            }
            out.push(t);
            out.push(t2);
        }
        if self.shared.remove(&key(a, b)).is_some() {
            self.shared.insert(key(a, m), ());
            self.shared.insert(key(m, b), ());
        }
        m
    }

    /// Measures every triangle and splits the failing ones until all pass or
    /// the budget is spent. `budget` is the triangle count this face may reach.
    pub fn refine(&mut self, surface: &dyn Surface, curves: &[&NurbsCurve], c: &Criteria, budget: usize) -> Outcome {
        let all = (0..self.tris.len() as u32).collect();
        self.refine_from(surface, curves, c, budget, all);
        self.outcome(surface, c)
    }

    /// Splits failing triangles, starting from `todo` (and what their splits
    /// change), until all pass, edges reach `min_edge` or the face has
    /// `budget` triangles; measures are cached, so a later call that starts
    /// from a few changed triangles costs only those. Returns whether the
    /// budget stopped it.
    pub fn refine_from(
        &mut self,
        surface: &dyn Surface,
        curves: &[&NurbsCurve],
        c: &Criteria,
        budget: usize,
        mut todo: Vec<u32>,
    ) -> bool {
        self.wake();
        let mut budget_hit = false;
        todo.reverse();
        let mut stack = todo;
        let mut changed = Vec::new();
        self.measure_slots();
        let mut fold_splits = 0usize;
        let fold_limit = 2 * stack.iter().filter(|&&t| self.inverted(surface, t as usize)).count() + 16;
        // Splits for folds of shape end as their slivers shrink; the cap
        // only bounds a surface that is not smooth at any scale.
        let (mut shape_splits, shape_limit) = (0usize, stack.len() + 64);
        let (mut waiting, mut waited) = (Vec::new(), crate::collections::HashSet::default());
        while let Some(t) = stack.pop().or_else(|| {
            waiting.reverse();
            stack.append(&mut waiting);
            stack.pop()
        }) {
            let t = t as usize;
            // A sample over the tolerance fails the triangle whatever the
            // others measure (one over it is never short for its angle).
            let measured = self.measure_unless_over(surface, t, c, c.tol);
            let (a, b, len) = self.longest_edge(t);
            let limits = measured.is_none_or(|(m, turn)| {
                (m.max > c.tol || turn > c.angle || len > c.max_edge) && !self.short_for_angle(surface, c, t, &m, turn)
            });
            // A folded sliver along a border is mended by splitting it, but
            // a fold splitting cannot mend (its corners off the surface
            // after sewing) would only breed more: such splits are rationed.
            // A fold of the triangle's shape alone is not
            // ([`Self::folds_by_shape`]): it waits until the rest is refined,
            // which mends many, then is flipped where a flip mends it (as
            // mending does, at no cost in triangles), else split. A fold on
            // a border edge refinement would never split (a side collapsed to
            // a hair on the far side of its pole) is not split at all: each
            // child keeps the hair and the fold.
            let mut folded = !limits && self.inverted(surface, t) && !self.on_hair(t, c.min_edge);
            if folded {
                if shape_splits < shape_limit
                    && measured.is_some_and(|(_, turn)| self.folds_by_shape(surface, c, t, turn))
                {
                    if waited.insert(t as u32) {
                        waiting.push(t as u32);
                        continue;
                    }
                    if self.flip_fold(surface, c, t as u32) {
                        continue;
                    }
                    shape_splits += 1;
                } else {
                    folded = fold_splits < fold_limit;
                    fold_splits += usize::from(folded);
                }
            }
            if !(limits || folded) {
                continue;
            }
            if len <= c.min_edge {
                continue;
            }
            if self.tris.len() >= budget {
                budget_hit = true;
                continue;
            }
            changed.clear();
            self.split_lepp(surface, curves, t as u32, (a, b), &mut changed);
            self.forget(&changed);
            stack.extend_from_slice(&changed);
        }
        self.edge_samples = EdgeSamples::default();
        budget_hit
    }

    /// Unfolds folded triangle `t` by flipping one of its edges where that
    /// passes [`Self::try_flip`]'s tests; whether it did.
    fn flip_fold(&mut self, surface: &dyn Surface, c: &Criteria, t: u32) -> bool {
        let v = self.tris[t as usize];
        for k in 0..3 {
            if let Some(u) = self.try_flip(surface, c, t, v[k], v[(k + 1) % 3]) {
                self.forget(&[t, u]);
                return true;
            }
        }
        false
    }

    /// Whether folded triangle `t` (normal turn `turn`) folds by its shape
    /// alone, which splitting mends: its corners lie on the surface at
    /// their (u,v) and their normals agree within the angle limit, so the
    /// surface is smooth under it, yet its facet faces away, as a sliver
    /// does whose long edge sags sideways more than its height (an edge of
    /// a thin grid cell where the surface curls across the cell and bends
    /// along it). Halving the long edge quarters its sag while the height
    /// stays, so the halves face the surface's way.
    fn folds_by_shape(&self, surface: &dyn Surface, c: &Criteria, t: usize, turn: f64) -> bool {
        let uv = self.uv(t);
        turn <= c.angle
            && self.tris[t]
                .iter()
                .zip(uv)
                .all(|(&v, q)| self.pos[v as usize].distance(surface.point(q)) <= ON_SURFACE * c.tol)
    }

    /// Whether triangle `t` has a border edge (one triangle) no longer than `hair`.
    fn on_hair(&self, t: usize, hair: f64) -> bool {
        let v = self.tris[t];
        (0..3).any(|k| {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            self.is_border(a, b) && self.pos[a as usize].distance(self.pos[b as usize]) <= hair
        })
    }

    /// Triangle `t`'s measure, from the cache while it is valid (the cache
    /// must already hold a slot per triangle).
    fn cached_measure(&mut self, surface: &dyn Surface, t: usize, c: &Criteria) -> (TriMeasure, f64) {
        self.measure_unless_over(surface, t, c, f64::INFINITY).unwrap_or_default()
    }

    /// [`Self::cached_measure`], or `None` when triangle `t` is not cached
    /// and one of its samples lies farther than `limit`: it is then left
    /// stale, to be measured in full by whatever asks next.
    fn measure_unless_over(
        &mut self,
        surface: &dyn Surface,
        t: usize,
        c: &Criteria,
        limit: f64,
    ) -> Option<(TriMeasure, f64)> {
        let x = self.measures[t];
        if !x.max.is_nan() {
            return Some(x.unpack());
        }
        if let Some(&x) = (!self.carried.is_empty()).then(|| self.carried.get(&self.measure_key(t))).flatten() {
            // As measured here: whole where within `limit`, else `None` (left
            // stale), unless packing's rounding up leaves that in doubt.
            if f64::from(x.max) <= limit {
                self.measures[t] = x;
                return Some(x.unpack());
            }
            if x.max_above() >= limit {
                return None;
            }
        }
        let mut shared = core::mem::take(&mut self.edge_samples);
        let measured = self.measure_sharing(surface, t, c, Some(&mut shared), limit);
        self.edge_samples = shared;
        let (m, turn) = measured?;
        let x = Packed::pack(m, turn);
        self.measures[t] = x;
        if self.log.is_some() {
            let key = self.measure_key(t);
            self.log.get_or_insert_with(Carried::default).insert(key, x);
        }
        Some(x.unpack())
    }

    /// Triangle `t`'s [`MeasureKey`].
    fn measure_key(&self, t: usize) -> MeasureKey {
        let (v, uv) = (self.tris[t], self.uv(t));
        let mut k = ([0u64; 15], [0u32; 9]);
        for c in 0..3 {
            let (p, n) = (self.pos[v[c] as usize], self.normal[v[c] as usize]);
            k.0[5 * c..5 * c + 5].copy_from_slice(&[p.x, p.y, p.z, uv[c].x, uv[c].y].map(f64::to_bits));
            k.1[3 * c..3 * c + 3].copy_from_slice(&[n.x, n.y, n.z].map(f32::to_bits));
        }
        k
    }

    /// Keeps every measure taken from now on for [`WorkMesh::measured`].
    pub fn log_measures(&mut self) {
        self.log.get_or_insert_with(Carried::default);
    }

    /// The measures this mesh holds and those it logged, by triangle, for
    /// the model's mesh of the same face and criteria ([`WorkMesh::carried`]).
    pub fn measured(&self) -> Carried {
        let mut out = self.log.clone().unwrap_or_default();
        for (t, x) in self.measures.iter().enumerate().take(self.tris.len()) {
            if !x.max.is_nan() {
                out.insert(self.measure_key(t), *x);
            }
        }
        out
    }

    /// Drops the cached measures of triangles `ts` (they changed).
    pub fn forget(&mut self, ts: &[u32]) {
        self.measure_slots();
        for &x in ts {
            if let Some(m) = self.measures.get_mut(x as usize) {
                *m = STALE;
            }
        }
    }

    /// The measures of every triangle (from the cache where it is still
    /// valid), summed up, and how many fail the limits: a sum, not a list, so
    /// that finished faces hold no per-triangle results.
    pub fn outcome(&mut self, surface: &dyn Surface, c: &Criteria) -> Outcome {
        let mut out = Outcome::default();
        let samples = u64::from(sample_count(c.steps));
        self.measure_slots();
        for t in 0..self.tris.len() {
            let (m, turn) = self.cached_measure(surface, t, c);
            let (_, _, len) = self.longest_edge(t);
            if self.short_for_angle(surface, c, t, &m, turn) {
                out.creased += 1;
            } else if m.max > c.tol || turn > c.angle || len > c.max_edge {
                out.unproven += 1;
            }
            out.max = out.max.max(m.max);
            out.sum += m.sum;
            out.count += samples;
            out.max_turn = out.max_turn.max(turn);
        }
        self.edge_samples = EdgeSamples::default();
        out
    }
}

#[cfg(test)]
mod tests;
