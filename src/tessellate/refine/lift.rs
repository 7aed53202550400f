//! Beyond paper 001: a rebuilt face whose mesh takes far fewer triangles
//! than the original's but keeps a few needles (long triangles fanned onto a
//! ring of short edges, as around a pole) spends some of the difference on
//! them, by Delaunay refinement in space (Ruppert): the thinnest triangle's
//! circumcentre, on the surface, becomes a vertex of the triangle it falls
//! in, and flips make the triangles around it Delaunay again. A needle's
//! circumcentre lies halfway along it, so the fan grades down to the short
//! edges in a few rings instead of a ladder of thin triangles.

use alloc::collections::BinaryHeap;
use alloc::vec::Vec;
use core::cmp::Reverse;
use glam::{DVec2, DVec3};

use super::{key, uv_area, Criteria, Lift, WorkMesh, NONE, STALE};
use crate::nurbs::{project_to_surface, Surface};
use crate::tessellate::measure::measure_projection;

/// The least barycentric weight, in (u,v), a new vertex keeps on each corner
/// of the triangle it splits: nearer a side it would only make a sliver.
const INSIDE: f64 = 1e-3;

/// Most triangles a walk to a circumcentre crosses.
const WALK: usize = 64;

/// An angle as a heap key (non-negative `f64`s order as their bits).
fn order(x: f64) -> u64 {
    x.max(0.0).to_bits()
}

impl WorkMesh {
    /// Raises triangles under `c.lift.goal` (see the module), thinnest
    /// first, until none is left that a vertex can mend or the face has
    /// `c.lift.most` triangles. Every change is kept only if its triangles
    /// face the surface's way and pass the limits; borders are never split,
    /// so a sewn face stays conforming. Returns the triangles changed.
    pub fn lift_angles(&mut self, surface: &dyn Surface, c: &Criteria) -> Vec<u32> {
        let Lift { goal, most } = c.lift;
        let mut changed = Vec::new();
        if goal.is_nan() || goal <= 0.0 || self.tris.len() + 2 > most {
            return changed;
        }
        self.wake();
        self.measure_slots();
        let mut heap: BinaryHeap<Reverse<(u64, u32)>> = (0..self.tris.len() as u32)
            .map(|t| (self.least_angle(t), t))
            .filter(|x| x.0 < goal)
            .map(|(a, t)| Reverse((order(a), t)))
            .collect();
        // Each insertion adds two triangles; failed tries are bounded too.
        let mut tries = 2 * most + 16;
        while let Some(Reverse((key_angle, t))) = heap.pop() {
            if self.tris.len() + 2 > most || tries == 0 {
                break;
            }
            let now = self.least_angle(t);
            if now >= goal || order(now) != key_angle {
                continue; // mended, or changed since it was queued
            }
            tries -= 1;
            let Some(around) = self.insert_circumcentre(surface, c, t) else { continue };
            let touched = self.make_delaunay(surface, c, around);
            for &x in &touched {
                let a = self.least_angle(x);
                if a < goal {
                    heap.push(Reverse((order(a), x)));
                }
            }
            changed.extend(touched);
        }
        changed.sort_unstable();
        changed.dedup();
        changed
    }

    /// Puts a vertex at triangle `t`'s circumcentre in space (the surface's
    /// point nearest it) into the triangle whose (u,v) holds it, found by a
    /// walk from `t` across inner edges; returns the three triangles around
    /// it as [`Self::split_at`] does, or `None` with the mesh as it was.
    fn insert_circumcentre(&mut self, surface: &dyn Surface, c: &Criteria, t: u32) -> Option<Vec<(u32, u32, u32)>> {
        let tv = self.tris[t as usize];
        let tuv = self.uv(t as usize);
        let p = tv.map(|v| self.pos[v as usize]);
        let (a, b) = (p[0] - p[2], p[1] - p[2]);
        let n = a.cross(b);
        let nn = n.length_squared();
        if nn.is_nan() || nn <= 0.0 {
            return None;
        }
        let centre = p[2] + (b * a.length_squared() - a * b.length_squared()).cross(n) / (2.0 * nn);
        // Its weights in the triangle's plane (outside it some are negative)
        // give the (u,v) the projection starts from.
        let w = weights(p, centre)?;
        let guess: DVec2 = tuv[0] * w[0] + tuv[1] * w[1] + tuv[2] * w[2];
        let uv = project_to_surface(surface, centre, Some(guess), &measure_projection()).uv;
        if !uv.is_finite() {
            return None;
        }
        let home = self.walk_to(t, uv)?;
        // Ruppert splits a border edge the point encroaches on (lies in its
        // diametral circle); a sewn border must stay as it is, so the point
        // is not taken: beside that edge it would leave a sliver no flip mends.
        let x = surface.point(uv);
        let hv = self.tris[home as usize];
        let encroaches = (0..3).any(|k| {
            let (a, b) = (hv[k], hv[(k + 1) % 3]);
            (self.trim.contains_key(&key(a, b)) || self.is_border(a, b))
                && (self.pos[a as usize] - x).dot(self.pos[b as usize] - x) < 0.0
        });
        if encroaches {
            return None;
        }
        self.split_at(surface, c, home, uv)
    }

    /// The triangle whose (u,v) holds `uv`, walking from `t` across inner,
    /// untrimmed edges of one chart; `None` when the walk would leave the face.
    fn walk_to(&self, mut t: u32, uv: DVec2) -> Option<u32> {
        for _ in 0..WALK {
            let tv = self.tris[t as usize];
            let w = self.uv(t as usize);
            let whole = uv_area(w);
            if whole == 0.0 {
                return None;
            }
            // The weight of each corner; the most negative names the side to cross.
            let l: [f64; 3] = core::array::from_fn(|k| uv_area([uv, w[(k + 1) % 3], w[(k + 2) % 3]]) / whole);
            let (k, least) = (0..3).map(|k| (k, l[k])).min_by(|x, y| x.1.total_cmp(&y.1))?;
            if least >= 0.0 {
                return Some(t);
            }
            let (x, y) = (tv[(k + 1) % 3], tv[(k + 2) % 3]);
            if self.trim.contains_key(&key(x, y)) {
                return None;
            }
            let adj = *self.pair(x, y)?;
            let u = if adj[0] == t { adj[1] } else { adj[0] };
            if u == NONE {
                return None;
            }
            // One chart on both sides (not across a seam).
            let uw = self.uv(u as usize);
            let uv_of = |tri: [u32; 3], w: [DVec2; 3], v: u32| (0..3).find(|&j| tri[j] == v).map(|j| w[j]);
            let ut = self.tris[u as usize];
            if uv_of(ut, uw, x) != Some(w[(k + 1) % 3]) || uv_of(ut, uw, y) != Some(w[(k + 2) % 3]) {
                return None;
            }
            t = u;
        }
        None
    }

    /// Splits triangle `t` in three at `uv` (on the surface there); returns
    /// each new triangle with its side away from the new vertex (running as
    /// the triangle does), or `None`, with the mesh as it was, when `uv` is
    /// not well inside or a new triangle folds or fails the limits.
    pub(crate) fn split_at(
        &mut self,
        surface: &dyn Surface,
        c: &Criteria,
        t: u32,
        uv: DVec2,
    ) -> Option<Vec<(u32, u32, u32)>> {
        let tv = self.tris[t as usize];
        let tuv = self.uv(t as usize);
        let sense = uv_area(tuv);
        let inside = (0..3).all(|k| {
            let mut w = tuv;
            w[k] = uv;
            uv_area(w) / sense >= INSIDE
        });
        let (x_pos, x_n): (DVec3, DVec3) = (surface.point(uv), surface.normal(uv));
        if !(sense != 0.0 && inside && x_pos.is_finite() && x_n.is_finite()) {
            return None;
        }
        let old_v = self.pos.len();
        let x = self.add_vertex(x_pos, x_n);
        let [a, b, r] = tv;
        let [ua, ub, ur] = tuv;
        for j in 0..3 {
            self.detach(tv[j], tv[(j + 1) % 3], t);
        }
        self.tris[t as usize] = [a, b, x];
        self.set_uv(t as usize, [ua, ub, uv]);
        for (v0, v1) in [(a, b), (b, x), (x, a)] {
            self.attach(v0, v1, t);
        }
        let t2 = self.tris.len() as u32;
        self.add_triangle([b, r, x], [ub, ur, uv]);
        self.add_triangle([r, a, x], [ur, ua, uv]);
        self.measure_slots();
        self.measures[t as usize] = STALE;
        let good = [t, t2, t2 + 1].iter().all(|&y| self.faces_right(surface, y, sense))
            && [t, t2, t2 + 1].iter().all(|&y| self.holds(surface, c, y, sense));
        if good {
            return Some(alloc::vec![(t, a, b), (t2, b, r), (t2 + 1, r, a)]);
        }
        self.pop_triangle();
        self.pop_triangle();
        for (v0, v1) in [(a, b), (b, x), (x, a)] {
            self.detach(v0, v1, t);
        }
        self.tris[t as usize] = tv;
        self.set_uv(t as usize, tuv);
        for j in 0..3 {
            self.attach(tv[j], tv[(j + 1) % 3], t);
        }
        self.measures[t as usize] = STALE;
        self.truncate_vertices(old_v);
        None
    }

    /// Lawson's flips around a new vertex: each side away from it (triangle,
    /// side running a→b) whose pair is not Delaunay in space is flipped when
    /// the flip passes the limits, and the two sides that brings in are
    /// checked next. Returns the triangles touched.
    fn make_delaunay(&mut self, surface: &dyn Surface, c: &Criteria, around: Vec<(u32, u32, u32)>) -> Vec<u32> {
        let mut touched: Vec<u32> = around.iter().map(|s| s.0).collect();
        let mut sides: Vec<(u32, u32, u32)> = around;
        let mut flips = 4 * self.tris.len() + 16;
        while let Some((t, a, b)) = sides.pop() {
            if flips == 0 {
                break;
            }
            let Some(&adj) = self.pair(a, b) else { continue };
            let u = if adj[0] == t { adj[1] } else { adj[0] };
            if u == NONE || (adj[0] != t && adj[1] != t) || self.trim.contains_key(&key(a, b)) {
                continue;
            }
            let Some(x) = self.tris[t as usize].into_iter().find(|&v| v != a && v != b) else { continue };
            let Some(d) = self.tris[u as usize].into_iter().find(|&v| v != a && v != b) else { continue };
            if !self.not_delaunay(a, b, x, d) {
                continue;
            }
            flips -= 1;
            if self.try_flip(surface, c, t, a, b).is_some() {
                // t is now a→d→x and u is d→b→x.
                sides.push((t, a, d));
                sides.push((u, d, b));
                touched.extend([t, u]);
            }
        }
        touched.sort_unstable();
        touched.dedup();
        touched
    }
}

/// The weights of `x` (in the plane of `p`) on the corners of `p`.
fn weights(p: [DVec3; 3], x: DVec3) -> Option<[f64; 3]> {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let nn = n.length_squared();
    if nn.is_nan() || nn <= 0.0 {
        return None;
    }
    let w: [f64; 3] = core::array::from_fn(|k| (p[(k + 2) % 3] - p[(k + 1) % 3]).cross(x - p[(k + 1) % 3]).dot(n) / nn);
    w.iter().all(|v| v.is_finite()).then_some(w)
}
