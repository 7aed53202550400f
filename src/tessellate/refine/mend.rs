//! Mending a refined face: folded triangles unfolded by flips and inner
//! vertex moves, and the small changes at its border that close what
//! sewing left open (a triangle beside a hole, a border split at a corner
//! poking over it, a flap removed).

use crate::numeric::TINY;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::{key, uv_area, Criteria, TriMeasure, WorkMesh, NONE, STALE};
#[cfg(feature = "std")]
use crate::nurbs::project_to_surface;
use crate::nurbs::{regular_normal, Surface};

/// The smallest angle below which [`WorkMesh::improve_angles`] looks for a
/// better diagonal (radians, 15°): wider pairs gain little for the measuring.
const THIN: f64 = 0.26;

impl WorkMesh {
    /// Repairs folded triangles by edge flips: for each inverted triangle,
    /// its interior edges (not trim edges) are tried in turn, and a flip is
    /// kept when both new triangles face the surface's way, keep the (u,v)
    /// orientation (or, where sewing moved nodes, face the surface's way in
    /// space) and pass the deviation and angle limits. Borders are not
    /// touched, so a sewn border stays conforming. Returns the triangles
    /// changed.
    ///
    /// Also returns the triangles still folded.
    pub fn repair_inverted(&mut self, surface: &dyn Surface, c: &Criteria) -> (Vec<u32>, Vec<u32>) {
        let mut changed = Vec::new();
        let mut todo: Vec<u32> = self.folded(surface);
        if todo.is_empty() {
            return (changed, todo);
        }
        self.wake();
        for _ in 0..8 {
            let mut next = Vec::new();
            let mut flipped = false;
            for t in todo {
                if !self.inverted(surface, t as usize) {
                    continue;
                }
                let v = self.tris[t as usize];
                let mut fixed = false;
                for k in 0..3 {
                    if let Some(u) = self.try_flip(surface, c, t, v[k], v[(k + 1) % 3]) {
                        changed.push(t);
                        changed.push(u);
                        flipped = true;
                        fixed = true;
                        break;
                    }
                }
                if fixed {
                    continue;
                }
                // No flip helps: move an inner vertex of the fold to the
                // middle of its neighbours (borders stay where sewing put them).
                // Nor a move: where the (u,v) map is far from linear, the
                // fold's corners sit in space where no triangle between them
                // faces the surface's way; an inner corner goes, which
                // changes the triangles round it as a flip does.
                let mended = v.iter().find_map(|&x| self.try_smooth(surface, c, t, x)).or_else(|| {
                    let kept = v.iter().find_map(|&x| self.try_collapse(surface, c, t, x));
                    flipped |= kept.is_some();
                    kept
                });
                if let Some(ring) = mended {
                    changed.extend(ring.iter().copied());
                    next.extend(ring);
                }
            }
            // A fold of several triangles (a fan on a border) unfolds one
            // flip at a time: after a round with flips, the rest are tried again.
            if flipped {
                next.extend((0..self.tris.len() as u32).filter(|&t| self.inverted(surface, t as usize)));
                next.sort_unstable();
                next.dedup();
            }
            if next.is_empty() {
                break;
            }
            todo = next;
        }
        self.drop_dead(&mut changed);
        changed.sort_unstable();
        changed.dedup();
        let left = self.folded(surface);
        (changed, left)
    }

    /// Beyond paper 000: flips interior edges whose two triangles are not
    /// Delaunay in space (their angles facing the edge sum past 180°) when
    /// the flip raises their smaller angle and the new pair passes every
    /// limit as [`Self::repair_inverted`] judges it. Refinement splits
    /// longest edges and never flips, so its thin triangles stay thin where a
    /// flip would mend them at no cost in triangles. Returns the triangles changed.
    ///
    /// `taken` holds the model's edges between border nodes (by node id):
    /// a new edge between two border nodes that another face already has
    /// (a strip between them) would be the model's third use of it.
    pub fn improve_angles(
        &mut self,
        surface: &dyn Surface,
        c: &Criteria,
        taken: &mut crate::collections::HashSet<(u32, u32)>,
    ) -> Vec<u32> {
        let mut changed = Vec::new();
        // Only thin triangles are worth a flip; the edge table is built
        // for faces that have some.
        let mut todo: Vec<u32> = (0..self.tris.len() as u32).filter(|&t| self.least_angle(t) < THIN).collect();
        if todo.is_empty() || self.tris.len() < 2 {
            return changed;
        }
        self.wake();
        // Each flip raises the pair's smaller angle, so this ends; the cap
        // bounds the work on a mesh that keeps finding small gains.
        let mut budget = 2 * self.tris.len() + 16;
        while let Some(t) = todo.pop() {
            let v = self.tris[t as usize];
            for k in 0..3 {
                if budget == 0 {
                    break;
                }
                let Some((u, across)) = self.delaunay_gain(t, v[k], v[(k + 1) % 3], taken) else { continue };
                budget -= 1;
                if self.try_flip(surface, c, t, v[k], v[(k + 1) % 3]).is_some() {
                    if let Some(e) = across {
                        taken.insert(e);
                    }
                    changed.extend([t, u]);
                    todo.extend([t, u]);
                    break;
                }
            }
        }
        changed.sort_unstable();
        changed.dedup();
        changed
    }

    /// Adds this face's edges between two border nodes to `taken` (see
    /// [`Self::improve_angles`]).
    pub fn border_node_edges(&self, taken: &mut crate::collections::HashSet<(u32, u32)>) {
        for t in &self.tris {
            for k in 0..3 {
                let (ga, gb) = (self.gid[t[k] as usize], self.gid[t[(k + 1) % 3] as usize]);
                if ga != NONE && gb != NONE {
                    taken.insert(key(ga, gb));
                }
            }
        }
    }

    /// The triangle across interior edge `a-b` of `t` (which runs a→b) when
    /// the two are not Delaunay in space, one of them is thinner than
    /// [`THIN`], and flipping their edge would raise their smallest angle.
    /// With it, the new edge's node ids when both its ends are border nodes.
    #[allow(clippy::type_complexity)]
    fn delaunay_gain(
        &self,
        t: u32,
        a: u32,
        b: u32,
        taken: &crate::collections::HashSet<(u32, u32)>,
    ) -> Option<(u32, Option<(u32, u32)>)> {
        let &adj = self.pair(a, b)?;
        let u = if adj[0] == t { adj[1] } else { adj[0] };
        if u == NONE || (adj[0] != t && adj[1] != t) || self.trim.contains_key(&key(a, b)) {
            return None;
        }
        let cv = self.tris[t as usize].into_iter().find(|&x| x != a && x != b)?;
        let d = self.tris[u as usize].into_iter().find(|&x| x != a && x != b)?;
        let (gc, gd) = (self.gid[cv as usize], self.gid[d as usize]);
        let across = (gc != NONE && gd != NONE).then(|| key(gc, gd));
        if across.is_some_and(|e| gc == gd || taken.contains(&e)) {
            return None;
        }
        if !self.not_delaunay(a, b, cv, d) {
            return None;
        }
        let p = |x: u32| self.pos[x as usize];
        let least = |x: u32, y: u32, z: u32| crate::mesh::min_angle([p(x), p(y), p(z)]);
        let before = least(a, b, cv).min(least(b, a, d));
        if before >= THIN {
            return None;
        }
        let after = least(a, d, cv).min(least(d, b, cv));
        (after > 2.0 * before).then_some((u, across))
    }

    /// Whether the pair of triangles on edge `a-b`, with third corners `x`
    /// and `y`, is not Delaunay in space: their angles facing the edge sum
    /// past 180°.
    pub(super) fn not_delaunay(&self, a: u32, b: u32, x: u32, y: u32) -> bool {
        let p = |v: u32| self.pos[v as usize];
        let angle = |at: u32| crate::math::angle_between(p(a) - p(at), p(b) - p(at));
        let limit = core::f64::consts::PI * (1.0 + 1e-9);
        // Not "at most 180°", so that a pair with a NaN angle counts as not Delaunay.
        !matches!(
            (angle(x) + angle(y)).partial_cmp(&limit),
            Some(core::cmp::Ordering::Less | core::cmp::Ordering::Equal)
        )
    }

    /// Of triangles `ts`, how many fold against the surface or exceed the
    /// deviation limit (judging a node's place, see [`super::sew::resettle_folds`]).
    pub fn failing(&self, surface: &dyn Surface, c: &Criteria, ts: &[u32]) -> usize {
        ts.iter()
            .filter(|&&t| self.inverted(surface, t as usize) || self.measure(surface, t as usize, c).0.max > c.tol)
            .count()
    }

    /// The triangles still folded against the surface.
    pub fn folded(&self, surface: &dyn Surface) -> Vec<u32> {
        (0..self.tris.len() as u32).filter(|&t| self.inverted(surface, t as usize)).collect()
    }

    /// Flips edge `a-b` of triangle `t` (where `t` runs a→b) if the result is better; see [`Self::repair_inverted`].
    pub(super) fn try_flip(&mut self, surface: &dyn Surface, c: &Criteria, t: u32, a: u32, b: u32) -> Option<u32> {
        if self.trim.contains_key(&key(a, b)) {
            return None;
        }
        let &adj = self.pair(a, b)?;
        let u = if adj[0] == t { adj[1] } else { adj[0] };
        if u == NONE || adj[0] != t && adj[1] != t {
            return None;
        }
        let (tv, tuv) = (self.tris[t as usize], self.uv(t as usize));
        let (uv_, uuv) = (self.tris[u as usize], self.uv(u as usize));
        let i = (0..3).find(|&k| tv[k] == a && tv[(k + 1) % 3] == b)?;
        let j = (0..3).find(|&k| uv_[k] == b && uv_[(k + 1) % 3] == a)?;
        let cv = tv[(i + 2) % 3];
        let d = uv_[(j + 2) % 3];
        if cv == d || self.edges.contains_key(&key(cv, d)) {
            return None;
        }
        let (qa, qb, qc) = (tuv[i], tuv[(i + 1) % 3], tuv[(i + 2) % 3]);
        let (qb2, qa2, qd) = (uuv[j], uuv[(j + 1) % 3], uuv[(j + 2) % 3]);
        // One chart on both sides (not across a seam).
        let span = (qa - qb).length().max(TINY);
        if (qa - qa2).length() > 1e-9 * span || (qb - qb2).length() > 1e-9 * span {
            return None;
        }
        let sense = uv_area([qb2, qa2, qd]);
        let (t1, t2) = ([a, d, cv], [d, b, cv]);
        let (w1, w2) = ([qa, qd, qc], [qd, qb, qc]);
        let turns = |v: [u32; 3], w: [DVec2; 3]| {
            let area = uv_area(w);
            (area * sense > 0.0, self.uv_cannot_tell_of(v, w, area))
        };
        let ((ok1, stale1), (ok2, stale2)) = (turns(t1, w1), turns(t2, w2));
        let uv_ok = ok1 && ok2;
        // Sewing moves border nodes in space, not in (u,v): where it folded a
        // triangle, the flip that unfolds it can look folded in the stale
        // (u,v), so the new pair is judged in space against the surface's
        // normal there too. So is a pair flat in (u,v) on an iso-line. Inner
        // nodes' (u,v) are exact: a pair turned there stays refused, however
        // it faces in space where the surface itself folds over.
        if !(ok1 || stale1) || !(ok2 || stale2) {
            return None;
        }
        let space_ok = || {
            let n = surface.normal((qa + qb + qc + qd) / 4.0);
            let p = |v: u32| self.pos[v as usize];
            let facing = |t: [u32; 3]| (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).dot(n) > 0.0;
            facing(t1) && facing(t2)
        };
        if !uv_ok && !space_ok() {
            return None;
        }
        // Apply, then test; undo when worse.
        let old = (tv, tuv, uv_, uuv);
        self.retriangulate(t, u, [tv, uv_], [t1, t2], [w1, w2]);
        let good = [t, u].iter().all(|&x| {
            let (m, turn) = self.measure(surface, x as usize, c);
            !self.inverted(surface, x as usize) && m.max <= c.tol && self.turn_ok(surface, c, &m, turn, x)
        });
        if !good {
            self.retriangulate(t, u, [t1, t2], [old.0, old.2], [old.1, old.3]);
        }
        good.then_some(u)
    }

    /// The triangles round inner vertex `x`, one of them `t`, in index
    /// order: walked across the edges at `x`, so it costs the fan, not the
    /// face. `None` where the walk meets a border (or the fan passes a
    /// hundred triangles, or its turns disagree). An edge of three
    /// triangles (the table holds two) can close the walk early, so callers
    /// still check every edge at `x`.
    pub(super) fn fan(&self, t: u32, x: u32) -> Option<Vec<u32>> {
        let mut ring = alloc::vec![t];
        let mut cur = t;
        while ring.len() <= 100 {
            let tv = self.tris[cur as usize];
            let k = tv.iter().position(|&v| v == x)?;
            let z = tv[(k + 1) % 3];
            let &adj = self.pair(x, z)?;
            let next = if adj[0] == cur { adj[1] } else { adj[0] };
            if next == NONE || next == cur {
                return None;
            }
            if next == t {
                ring.sort_unstable();
                return Some(ring);
            }
            ring.push(next);
            cur = next;
        }
        None
    }

    /// Moves inner vertex `x` to the (u,v) centroid of its neighbours when
    /// that leaves every triangle around it facing the surface's way, with
    /// its (u,v) orientation, and within the limits; returns those triangles.
    fn try_smooth(&mut self, surface: &dyn Surface, c: &Criteria, t: u32, x: u32) -> Option<Vec<u32>> {
        let ring = self.fan(t, x)?;
        if ring.len() < 3 {
            return None;
        }
        let mut centre = DVec2::ZERO;
        let mut at: Option<DVec2> = None;
        let mut n = 0.0;
        for &t in &ring {
            let (tv, tuv) = (self.tris[t as usize], self.uv(t as usize));
            for k in 0..3 {
                let (a, b) = (tv[k], tv[(k + 1) % 3]);
                if (a == x || b == x) && self.edges.get(&key(a, b)).is_none_or(|e| e[1] == NONE) {
                    return None; // on a border
                }
                if tv[k] == x {
                    // One chart all around (not a seam or pole vertex).
                    if at.is_some_and(|q| q.distance(tuv[k]) > 0.0) {
                        return None;
                    }
                    at = Some(tuv[k]);
                } else {
                    centre += tuv[k];
                    n += 1.0;
                }
            }
        }
        let old_uv = at?;
        let new_uv = centre / n;
        let signs: Vec<f64> = ring.iter().map(|&t| uv_area(self.uv(t as usize))).collect();
        let sense = signs.iter().sum::<f64>();
        let (old_p, old_n) = (self.pos[x as usize], self.normal_at(x as usize));
        let set = |m: &mut Self, q: DVec2, p: DVec3, nn: DVec3| {
            m.pos[x as usize] = p;
            m.normal[x as usize] = nn.as_vec3();
            m.move_uv(x, &ring, q);
        };
        set(self, new_uv, surface.point(new_uv), surface.normal(new_uv));
        let good = ring.iter().all(|&t| self.faces_right(surface, t, sense))
            && ring.iter().all(|&t| self.holds(surface, c, t, sense));
        if good {
            Some(ring)
        } else {
            set(self, old_uv, old_p, old_n);
            None
        }
    }

    /// Collapses inner vertex `x` into a neighbour `y`, the nearest in space
    /// that works: the two triangles on edge `x-y` go (left as dead
    /// triangles `[y, y, y]` with no edges, for [`Self::drop_dead`]), and
    /// the others around `x` take `y` in its place. Kept only when each of
    /// those faces the surface's way, keeps its (u,v) orientation and passes
    /// the limits, and the face stays a manifold: `x` and `y` share no
    /// neighbour but the two across their edge, and no new edge joins two
    /// border nodes. Returns the changed triangles.
    pub(super) fn try_collapse(&mut self, surface: &dyn Surface, c: &Criteria, t: u32, x: u32) -> Option<Vec<u32>> {
        let ring = self.fan(t, x)?;
        if ring.len() < 3 || self.gid[x as usize] != NONE {
            return None;
        }
        let mut around: Vec<u32> = Vec::new();
        for &t in &ring {
            let tv = self.tris[t as usize];
            for k in 0..3 {
                let (a, b) = (tv[k], tv[(k + 1) % 3]);
                if (a == x || b == x) && self.edges.get(&key(a, b)).is_none_or(|e| e[1] == NONE) {
                    return None; // on a border
                }
                if tv[k] != x && !around.contains(&tv[k]) {
                    around.push(tv[k]);
                }
            }
        }
        let here = self.pos[x as usize];
        crate::sort::by_f64(&mut around, |&a| self.pos[a as usize].distance(here));
        let sense: f64 = ring.iter().map(|&t| uv_area(self.uv(t as usize))).sum();
        'candidates: for &y in &around {
            let &gone = self.pair(x, y)?;
            // y's (u,v), the same in both triangles of the edge (one chart).
            let at = |m: &Self, t: u32| {
                let tv = m.tris[t as usize];
                (0..3).find(|&k| tv[k] == y).map(|k| m.uv(t as usize)[k])
            };
            let (Some(q0), Some(q1)) = (at(self, gone[0]), at(self, gone[1])) else { continue };
            if !super::same_uv(q0, q1) {
                continue;
            }
            // The link condition: the common neighbours are the two apexes.
            let apexes: Vec<u32> = gone
                .iter()
                .filter_map(|&t| self.tris[t as usize].iter().copied().find(|&z| z != x && z != y))
                .collect();
            for &z in &around {
                if z == y || apexes.contains(&z) {
                    continue;
                }
                if self.edges.contains_key(&key(y, z)) {
                    continue 'candidates;
                }
                if self.gid[y as usize] != NONE && self.gid[z as usize] != NONE {
                    continue 'candidates;
                }
            }
            let kept: Vec<u32> = ring.iter().copied().filter(|t| !gone.contains(t)).collect();
            // An edge of three triangles (the table holds two): a third
            // triangle on x-y would keep y twice.
            if !gone.iter().all(|t| ring.contains(t)) || kept.iter().any(|&t| self.tris[t as usize].contains(&y)) {
                continue;
            }
            // Each kept triangle before and after (x's corner taken by y).
            let old: Vec<([u32; 3], [DVec2; 3])> =
                kept.iter().map(|&t| (self.tris[t as usize], self.uv(t as usize))).collect();
            let new: Vec<([u32; 3], [DVec2; 3])> = old
                .iter()
                .map(|&(mut tv, mut w)| {
                    let k = tv.iter().position(|&v| v == x).unwrap_or(0);
                    (tv[k], w[k]) = (y, q0);
                    (tv, w)
                })
                .collect();
            let put = |m: &mut Self, rows: &[([u32; 3], [DVec2; 3])]| {
                for (&t, &(tv, w)) in kept.iter().zip(rows) {
                    m.tris[t as usize] = tv;
                    m.set_uv(t as usize, w);
                }
            };
            put(self, &new);
            let good = kept.iter().all(|&t| self.faces_right(surface, t, sense))
                && kept.iter().all(|&t| self.holds(surface, c, t, sense));
            put(self, &old);
            if !good {
                continue;
            }
            for &t in ring.iter() {
                let tv = self.tris[t as usize];
                for k in 0..3 {
                    self.detach(tv[k], tv[(k + 1) % 3], t);
                }
            }
            for &t in &gone {
                self.tris[t as usize] = [y; 3];
                self.set_uv(t as usize, [q0; 3]);
            }
            put(self, &new);
            for (&t, &(tv, _)) in kept.iter().zip(&new) {
                for k in 0..3 {
                    self.attach(tv[k], tv[(k + 1) % 3], t);
                }
            }
            return Some(kept);
        }
        None
    }

    /// Removes the dead triangles [`Self::try_collapse`] left (`[y, y, y]`),
    /// keeping `changed` pointing at the same triangles.
    pub(super) fn drop_dead(&mut self, changed: &mut Vec<u32>) {
        let dead: Vec<usize> = (0..self.tris.len())
            .rev()
            .filter(|&t| self.tris[t][0] == self.tris[t][1] && self.tris[t][1] == self.tris[t][2])
            .collect();
        for t in dead {
            let last = (self.tris.len() - 1) as u32;
            self.remove_triangle(t);
            changed.retain(|&u| u as usize != t);
            for u in changed.iter_mut() {
                if *u == last {
                    *u = t as u32;
                }
            }
        }
    }

    /// Whether triangle `t`, just changed, keeps the (u,v) orientation
    /// `sense` (the sign of a (u,v) area), faces the surface's way and passes
    /// the deviation and turn limits.
    pub(super) fn holds(&self, surface: &dyn Surface, c: &Criteria, t: u32, sense: f64) -> bool {
        self.faces_right(surface, t, sense) && {
            let (m, turn) = self.measure(surface, t as usize, c);
            m.max <= c.tol && self.turn_ok(surface, c, &m, turn, t)
        }
    }

    /// The cheap half of [`Self::holds`]: `t` keeps the (u,v) orientation
    /// `sense` and faces the surface's way. Asked of a whole ring first, it
    /// spares measuring triangles of a change that a fold already rules out.
    pub(super) fn faces_right(&self, surface: &dyn Surface, t: u32, sense: f64) -> bool {
        uv_area(self.uv(t as usize)) * sense > 0.0 && !self.inverted(surface, t as usize)
    }

    /// Whether triangle `t`'s normal turn passes: within the angle limit, or
    /// too short to split for it ([`Criteria::short_for_angle`]), so a repair
    /// that unfolds such a triangle is not refused for a turn refinement keeps too.
    pub(super) fn turn_ok(&self, surface: &dyn Surface, c: &Criteria, m: &TriMeasure, turn: f64, t: u32) -> bool {
        turn <= c.angle || self.short_for_angle(surface, c, t as usize, m, turn)
    }

    /// Replaces triangles `t` and `u` (vertices `from`) by `to` with corner (u,v)s `uvs`.
    fn retriangulate(&mut self, t: u32, u: u32, from: [[u32; 3]; 2], to: [[u32; 3]; 2], uvs: [[DVec2; 3]; 2]) {
        for (x, tri) in [t, u].into_iter().zip(from) {
            for k in 0..3 {
                self.detach(tri[k], tri[(k + 1) % 3], x);
            }
        }
        for ((x, tri), w) in [t, u].into_iter().zip(to).zip(uvs) {
            self.tris[x as usize] = tri;
            self.set_uv(x as usize, w);
            for k in 0..3 {
                self.attach(tri[k], tri[(k + 1) % 3], x);
            }
        }
    }

    /// Whether triangle `t` folds against the surface with a facet worth
    /// judging ([`folded_facet`] against its [`Self::centroid_normal`]).
    #[cfg(test)]
    pub fn folded_beyond(&self, surface: &dyn Surface, t: usize, negligible: f64) -> bool {
        let v = self.tris[t];
        folded_facet(v.map(|x| self.pos[x as usize]), self.centroid_normal(surface, t), negligible)
    }

    /// The surface normal triangle `t`'s facet is judged against: at the
    /// centroid of its corners' (u,v).
    pub fn centroid_normal(&self, surface: &dyn Surface, t: usize) -> DVec3 {
        let uv = self.uv(t);
        surface.normal((uv[0] + uv[1] + uv[2]) / 3.0)
    }

    /// [`Self::centroid_normal`], but where the facet opposes it and the
    /// surface turns over inside the triangle (two corners' normals, seen
    /// from inside, face apart: a fold or pleat, where the control net
    /// doubles back), the normal of a corner the facet agrees with. Such a
    /// triangle has no one surface normal: it lies along one of the sheets
    /// it spans, and is turned over only if it faces away from all of them.
    pub fn judged_normal(&self, surface: &dyn Surface, t: usize) -> DVec3 {
        let n = self.centroid_normal(surface, t);
        let v = self.tris[t];
        let p = v.map(|x| self.pos[x as usize]);
        let facet = (p[1] - p[0]).cross(p[2] - p[0]);
        if facet.dot(n) >= 0.0 {
            return n;
        }
        let uv = self.uv(t);
        let centre = (uv[0] + uv[1] + uv[2]) / 3.0;
        let corners: [Option<DVec3>; 3] = core::array::from_fn(|k| {
            [1e-6, 1e-4, 1e-2].iter().find_map(|f| regular_normal(&surface.derivs(uv[k] + (centre - uv[k]) * *f)))
        });
        let [Some(a), Some(b), Some(c)] = corners else { return n };
        let turns_over = a.dot(b) < 0.0 || b.dot(c) < 0.0 || c.dot(a) < 0.0;
        match [a, b, c].into_iter().find(|m| facet.dot(*m) > 0.0) {
            Some(m) if turns_over => m,
            _ => n,
        }
    }

    /// Closes a small hole beside border edge `a-b` (run a→b by its one
    /// triangle) with the triangle `b, a, x`, `x` at `p` (another face's
    /// node `gid`, placed on this surface at its nearest point), if that
    /// triangle faces the surface's way and passes the limits; otherwise
    /// leaves the mesh as it was. Returns whether it closed it.
    #[cfg(feature = "std")]
    pub fn close_beside(&mut self, surface: &dyn Surface, c: &Criteria, a: u32, b: u32, p: DVec3, gid: u32) -> bool {
        self.wake();
        let Some(t) = self.edges.get(&key(a, b)).filter(|e| e[1] == NONE).map(|e| e[0] as usize) else {
            return false;
        };
        let Some(k) = (0..3).find(|&k| self.tris[t][k] == a && self.tris[t][(k + 1) % 3] == b) else {
            return false;
        };
        let tuv = self.uv(t);
        let (uv_a, uv_b) = (tuv[k], tuv[(k + 1) % 3]);
        let hint = (uv_a + uv_b) * 0.5;
        let uv = project_to_surface(surface, p, Some(hint), &Default::default()).uv;
        // Far from the edge in (u,v): across a seam, not beside it.
        if !uv.is_finite() || uv.distance(hint) > 2.0 * uv_a.distance(uv_b).max(TINY) {
            return false;
        }
        let old_v = self.pos.len();
        let n = surface.normal(uv);
        if !n.is_finite() {
            return false;
        }
        let x = self.add_vertex(p, n);
        self.gid[x as usize] = gid;
        self.add_triangle([b, a, x], [uv_b, uv_a, uv]);
        self.measure_slots();
        if self.fits_placed(surface, c, self.tris.len() - 1) {
            // Its two new sides run along the other faces' borders: shared.
            self.shared.insert(key(a, x), ());
            self.shared.insert(key(x, b), ());
            return true;
        }
        self.pop_triangle();
        self.truncate_vertices(old_v);
        false
    }

    /// Whether triangle `t`, just placed, passes the limits (a turn refinement
    /// keeps too passes, see [`Self::turn_ok`]) and faces the surface's way.
    #[cfg(feature = "std")]
    fn fits_placed(&mut self, surface: &dyn Surface, c: &Criteria, t: usize) -> bool {
        let (m, turn) = self.cached_measure(surface, t, c);
        m.max <= c.tol && self.turn_ok(surface, c, &m, turn, t as u32) && !self.inverted(surface, t)
    }

    /// Takes back the last triangle added.
    #[cfg(feature = "std")]
    pub(super) fn pop_triangle(&mut self) {
        self.wake();
        let Some(&v) = self.tris.last() else { return };
        let t = (self.tris.len() - 1) as u32;
        for k in 0..3 {
            self.detach(v[k], v[(k + 1) % 3], t);
        }
        self.tris.pop();
        if !self.odd_uv.is_empty() {
            self.odd_uv.remove(&t);
        }
        self.measures.truncate(self.tris.len());
    }

    /// Takes back the vertices from `n` on.
    #[cfg(feature = "std")]
    pub(super) fn truncate_vertices(&mut self, n: usize) {
        self.pos.truncate(n);
        self.normal.truncate(n);
        self.gid.truncate(n);
        self.vuv.truncate(n);
    }

    /// Splits border edge `a-b` (one triangle) at `p`, another face's node
    /// `gid` that pokes across it from beside: its triangle becomes two that
    /// meet there, kept only if neither folds in (u,v), both face the
    /// surface's way and pass the limits; otherwise the mesh stays as it was.
    #[cfg(feature = "std")]
    pub fn split_border_at(&mut self, surface: &dyn Surface, c: &Criteria, a: u32, b: u32, p: DVec3, gid: u32) -> bool {
        self.wake();
        let Some(t) = self.edges.get(&key(a, b)).filter(|e| e[1] == NONE).map(|e| e[0] as usize) else {
            return false;
        };
        let (old_t, old_uv) = (self.tris[t], self.uv(t));
        let Some(k) = (0..3).find(|&k| key(old_t[k], old_t[(k + 1) % 3]) == key(a, b)) else {
            return false;
        };
        let (x0, x1, x2) = (old_t[k], old_t[(k + 1) % 3], old_t[(k + 2) % 3]);
        let (u0, u1, u2) = (old_uv[k], old_uv[(k + 1) % 3], old_uv[(k + 2) % 3]);
        let whole = uv_area([u0, u1, u2]);
        let folds =
            |uv: DVec2| !uv.is_finite() || uv_area([u0, uv, u2]) * whole <= 0.0 || uv_area([uv, u1, u2]) * whole <= 0.0;
        // Its nearest point on this surface; where that folds the two (the
        // node lies past the surface's end), the edge's (u,v) at its chord
        // fraction, the node keeping its place for the weld.
        let (pa, pb) = (self.pos[x0 as usize], self.pos[x1 as usize]);
        let frac = (p - pa).dot(pb - pa) / pa.distance_squared(pb).max(f64::MIN_POSITIVE);
        let uv = project_to_surface(surface, p, Some(u0.lerp(u1, frac.clamp(0.0, 1.0))), &Default::default()).uv;
        let uv = if folds(uv) { u0.lerp(u1, frac) } else { uv };
        if whole == 0.0 || !(1e-3..=1.0 - 1e-3).contains(&frac) || folds(uv) {
            return false;
        }
        let n = surface.normal(uv);
        if !n.is_finite() {
            return false;
        }
        let old_v = self.pos.len();
        let m = self.add_vertex(p, n);
        self.gid[m as usize] = gid;
        let tu = t as u32;
        self.detach(x0, x1, tu);
        self.detach(x1, x2, tu);
        self.tris[t] = [x0, m, x2];
        self.set_uv(t, [u0, uv, u2]);
        self.attach(x0, m, tu);
        self.attach(m, x2, tu);
        self.add_triangle([m, x1, x2], [uv, u1, u2]);
        self.measure_slots();
        self.measures[t] = STALE;
        if self.fits_placed(surface, c, t) && self.fits_placed(surface, c, self.tris.len() - 1) {
            // Its halves run beside the other face's node: shared, as the
            // border edge they replace was (trim or shared).
            let side = key(a, b);
            if self.trim.remove(&side).is_some() | self.shared.remove(&side).is_some() {
                self.shared.insert(key(x0, m), ());
                self.shared.insert(key(m, x1), ());
            }
            return true;
        }
        self.pop_triangle();
        self.detach(x0, m, tu);
        self.detach(m, x2, tu);
        self.tris[t] = old_t;
        self.set_uv(t, old_uv);
        self.attach(x0, x1, tu);
        self.attach(x1, x2, tu);
        self.measures[t] = STALE;
        self.truncate_vertices(old_v);
        false
    }

    /// Removes triangle `t`; the last triangle takes its index. Its corners
    /// stay as vertices (one no other triangle uses is simply not drawn),
    /// and a side of it no other triangle has is no trim or shared edge any more.
    pub fn remove_triangle(&mut self, t: usize) {
        if t >= self.tris.len() {
            return;
        }
        self.wake();
        let gone = self.tris[t];
        let last = self.tris.len() - 1;
        for k in 0..3 {
            self.detach(self.tris[t][k], self.tris[t][(k + 1) % 3], t as u32);
        }
        if t != last {
            let v = self.tris[last];
            for k in 0..3 {
                self.detach(v[k], v[(k + 1) % 3], last as u32);
                self.attach(v[k], v[(k + 1) % 3], t as u32);
            }
        }
        if self.measures.len() == self.tris.len() {
            self.measures.swap_remove(t);
        } else if let Some(m) = self.measures.get_mut(t) {
            *m = STALE;
        }
        self.tris.swap_remove(t);
        if !self.odd_uv.is_empty() {
            // The last triangle's own corners, if it has them, move with it.
            self.odd_uv.remove(&(t as u32));
            if let Some(w) = self.odd_uv.remove(&(last as u32)) {
                self.odd_uv.insert(t as u32, w);
            }
        }
        self.measures.truncate(self.tris.len());
        for k in 0..3 {
            let side = key(gone[k], gone[(k + 1) % 3]);
            if !self.edges.contains_key(&side) {
                self.trim.remove(&side);
                self.shared.remove(&side);
            }
        }
    }

    /// Whether the facet normal opposes the surface normal at the centroid's (u,v).
    pub fn inverted(&self, surface: &dyn Surface, t: usize) -> bool {
        let v = self.tris[t];
        let p = [self.pos[v[0] as usize], self.pos[v[1] as usize], self.pos[v[2] as usize]];
        let facet = (p[1] - p[0]).cross(p[2] - p[0]);
        if facet.length_squared() == 0.0 {
            return false;
        }
        facet.dot(self.centroid_normal(surface, t)) < 0.0
    }
}

/// Whether the triangle on corners `p` folds against the surface normal `n`
/// with a facet worth judging: a triangle whose smallest height is within
/// `negligible` is flat (two corners one point, as a pole's nodes a rounding
/// error apart, or three in a line where a side of the surface is collapsed
/// to a hair), its facet's normal then noise.
pub(crate) fn folded_facet(p: [DVec3; 3], n: DVec3, negligible: f64) -> bool {
    let facet = (p[1] - p[0]).cross(p[2] - p[0]);
    let longest = (0..3).map(|k| p[k].distance(p[(k + 1) % 3])).fold(0.0, f64::max);
    let height = facet.length() / longest.max(f64::MIN_POSITIVE);
    height > negligible && facet.length_squared() > 0.0 && facet.dot(n) < 0.0
}

/// How many of triangles `tris` (corners in `pos`) fold against their
/// surface normals `normals` ([`folded_facet`] beyond `negligible`), the
/// triangles with two corners within `weld` left out: the edge census takes
/// those corners for one point and drops the triangle as collapsed, and
/// its facet turns on an offset the welded mesh does not resolve (two
/// outline nodes of one corner that sewing left a hair apart).
pub(crate) fn count_folded(pos: &[DVec3], tris: &[[u32; 3]], normals: &[DVec3], weld: f64, negligible: f64) -> usize {
    tris.iter()
        .zip(normals)
        .filter(|(t, n)| {
            let p = t.map(|v| pos[v as usize]);
            let shortest = (0..3).map(|k| p[k].distance(p[(k + 1) % 3])).fold(f64::INFINITY, f64::min);
            shortest > weld && folded_facet(p, **n, negligible)
        })
        .count()
}
