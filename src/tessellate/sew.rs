//! Sewing faces into one watertight mesh (paper 000 §3.3, paper 003's
//! shared-boundary topology).
//!
//! Paper 000 splits a shared edge identically on both patches. Here every
//! face's border (its trim loops discretized, or its domain's border) takes
//! in, before anything is triangulated, the nodes of the other borders that
//! run along it, each at its own curve's nearest point; loop nodes that then
//! coincide are one node of the model, with one id. Each face is
//! triangulated on those nodes, so both sides of a shared border start with
//! the same ones. Refinement may split a shared edge; the split is made at
//! once in every face that shares it, which refines what it changed there.
//! At the end every node takes one position. Welding then leaves no crack
//! and no T-junction, and each face's triangles are proven after its last split.

use crate::collections::HashMap;
use crate::numeric::guarded_div;
use alloc::vec::Vec;
use glam::DVec3;

use super::refine::{Criteria, EdgeList, WorkMesh};
use crate::nurbs::{NurbsCurve, Surface};
use crate::Error;

const NONE: u32 = u32::MAX;

/// One face while the model is sewn.
pub(crate) struct FaceWork<'a> {
    pub surface: &'a dyn Surface,
    pub curves: Vec<&'a NurbsCurve>,
    pub mesh: WorkMesh,
    /// The limits its triangles must meet.
    pub crit: Criteria,
}

/// Golden-section search of `dist` over `[lo, hi]`: the argument of its
/// smallest value found, and that value.
fn golden(dist: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let g = 0.618_033_988_749_895;
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (dist(x1), dist(x2));
    for _ in 0..40 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = dist(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = dist(x2);
        }
        if hi - lo < 1e-12 {
            break;
        }
    }
    if f1 < f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// The fraction in `[0, 1]` nearest by `dist`, starting from the chord's
/// fraction `s0`: a segment's curve parameter need not follow its chord, so
/// a coarse scan of the whole span brackets the minimum when the window
/// about `s0` ends at its edge.
pub(super) fn nearest_fraction(dist: &dyn Fn(f64) -> f64, s0: f64) -> (f64, f64) {
    let (lo, hi) = ((s0 - 0.25).max(0.0), (s0 + 0.25).min(1.0));
    let (s, d) = golden(dist, lo, hi);
    let at_edge = (s - lo < 1e-6 && lo > 0.0) || (hi - s < 1e-6 && hi < 1.0);
    if !at_edge {
        return (s, d);
    }
    const SCAN: usize = 16;
    let mut best = (0usize, f64::INFINITY);
    for i in 0..=SCAN {
        let v = dist(i as f64 / SCAN as f64);
        if v < best.1 {
            best = (i, v);
        }
    }
    let (a, b) = (best.0.saturating_sub(1) as f64 / SCAN as f64, (best.0 + 1).min(SCAN) as f64 / SCAN as f64);
    let (s2, d2) = golden(dist, a, b);
    if d2 < d {
        (s2, d2)
    } else {
        (s, d)
    }
}

#[cfg(feature = "std")]
mod across;
#[cfg(feature = "std")]
mod inside;
#[cfg(feature = "std")]
mod outlines;
#[cfg(feature = "std")]
mod slide;
#[cfg(feature = "std")]
mod uncross;

#[cfg(feature = "std")]
pub(crate) use outlines::unify;
#[cfg(feature = "std")]
pub(crate) use uncross::split_crossing_chords;

/// Where each model edge (a pair of node ids) is used: face and local ends.
type Uses = HashMap<(u32, u32), Vec<(u32, u32, u32)>>;

fn node_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Every border edge between two different nodes, by its node pair.
fn border_uses(faces: &[FaceWork<'_>]) -> Uses {
    let mut uses: Uses = HashMap::default();
    for (fi, f) in faces.iter().enumerate() {
        for (a, b) in f.mesh.boundary_edges() {
            let (ga, gb) = (f.mesh.gid[a as usize], f.mesh.gid[b as usize]);
            if ga != NONE && gb != NONE && ga != gb {
                uses.entry(node_key(ga, gb)).or_default().push((fi as u32, a, b));
            }
        }
    }
    // Most edges have two uses: lists of exactly their size are held
    // through refinement, not room for four.
    for list in uses.values_mut() {
        list.shrink_to_fit();
    }
    uses
}

/// Where two faces share two border nodes but their borders between them
/// carry different nodes (their gap there was wider than the nodes' reach
/// when the outlines were sewn: T-junctions), each face takes the other's
/// nodes in between, within its sewing distance (`sew` of the face). Paper 000 §3.3:
/// both sides of a shared edge carry the same nodes. Returns the border
/// uses after it ([`border_uses`]).
fn close_t_junctions(faces: &mut [FaceWork<'_>], sew: &dyn Fn(usize) -> f64) -> Uses {
    let uses = border_uses(faces);
    // Every walk starts on an edge no other face uses: where there is none
    // (a closed shell), there is nothing to close, and the tables of
    // neighbours were most of the stage's time on a drilled plate.
    if uses.values().all(|l| l.len() != 1) {
        return uses;
    }
    // The planning's tables are gone before the splits, and the uses before
    // they are taken again: the peak of a large model's mesh phase is here.
    let junctions = t_junctions(faces, &uses);
    // Unchanged borders keep their uses.
    if take_their_nodes(faces, junctions, sew) {
        drop(uses);
        border_uses(faces)
    } else {
        uses
    }
}

/// A stretch of one face's border between two nodes it shares with another
/// face whose border there carries other nodes.
struct Junction {
    /// The face whose border takes the other's nodes.
    face: usize,
    /// Its border's vertices from one shared node to the next.
    run: Vec<u32>,
    /// The larger of the two faces' gaps at the shared nodes.
    gap: f64,
    /// The other face's nodes in between: id and position.
    nodes: Vec<(u32, DVec3)>,
    /// Per vertex of `run`: whether no other face holds its node.
    own: Vec<bool>,
}

/// The T-junctions of [`close_t_junctions`]: per pair of faces, each
/// stretch of border, over edges no other face shares, between two nodes
/// both faces have.
fn t_junctions(faces: &[FaceWork<'_>], uses: &Uses) -> Vec<Junction> {
    /// Border nodes walked from one shared node towards the next, at most.
    const STEPS: usize = 24;
    let lonely = |ga: u32, gb: u32| uses.get(&node_key(ga, gb)).is_some_and(|l| l.len() == 1);
    // Per (face, node id): the border neighbours' ids; per node id: (face,
    // vertex). From the border uses, in face and edge order.
    let mut edges: Vec<(u32, u32, u32)> = uses.values().flatten().copied().collect();
    crate::sort::triples(&mut edges);
    let mut around: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
    let mut holders: HashMap<u32, Vec<(u32, u32)>> = HashMap::default();
    for (fi, a, b) in edges {
        let f = &faces[fi as usize];
        let (ga, gb) = (f.mesh.gid[a as usize], f.mesh.gid[b as usize]);
        for (g, h, v) in [(ga, gb, a), (gb, ga, b)] {
            let list = around.entry((fi, g)).or_default();
            if list.is_empty() {
                holders.entry(g).or_default().push((fi, v));
            }
            list.push(h);
        }
    }
    let place = |g: u32, face: u32| holders.get(&g)?.iter().find(|h| h.0 == face).map(|h| h.1);
    // Face `f`'s border from `from` by `first`, over edges no other face
    // shares, to the first node `other` holds: the nodes passed and that node.
    let walk = |f: u32, other: u32, from: u32, first: u32| -> Option<(Vec<u32>, u32)> {
        let (mut prev, mut cur) = (from, first);
        let mut path = Vec::new();
        for _ in 0..STEPS {
            if !lonely(prev, cur) {
                return None;
            }
            if around.contains_key(&(other, cur)) {
                return Some((path, cur));
            }
            path.push(cur);
            let nb = around.get(&(f, cur)).filter(|nb| nb.len() == 2)?;
            let next = if nb[0] == prev { nb[1] } else { nb[0] };
            (prev, cur) = (cur, next);
        }
        None
    };
    let mut junctions: Vec<Junction> = Vec::new();
    let mut seen = crate::collections::HashSet::default();
    let mut starts: Vec<(u32, u32)> = around.keys().copied().collect();
    crate::sort::pairs(&mut starts);
    for (fa, ga) in starts {
        let Some(others) = holders.get(&ga) else { continue };
        for &(fb, _) in others {
            if fb == fa {
                continue;
            }
            for &first in around.get(&(fa, ga)).map_or(&[][..], |v| &v[..]) {
                let Some((mine, gb)) = walk(fa, fb, ga, first) else { continue };
                if gb == ga || !seen.insert((fa, fb, node_key(ga, gb))) {
                    continue;
                }
                let theirs =
                    around.get(&(fb, ga)).map_or(&[][..], |v| &v[..]).iter().find_map(|&t| {
                        walk(fb, fa, ga, t).filter(|(p, end)| *end == gb && !p.is_empty()).map(|(p, _)| p)
                    });
                let Some(theirs) = theirs else { continue };
                let (f, g) = (&faces[fa as usize], &faces[fb as usize]);
                let run: Option<Vec<u32>> =
                    core::iter::once(ga).chain(mine.iter().copied()).chain([gb]).map(|x| place(x, fa)).collect();
                let nodes: Option<Vec<(u32, DVec3)>> =
                    theirs.iter().map(|&x| Some((x, g.mesh.pos[place(x, fb)? as usize]))).collect();
                let gap =
                    |id: u32| Some(f.mesh.pos[place(id, fa)? as usize].distance(g.mesh.pos[place(id, fb)? as usize]));
                let own = core::iter::once(ga)
                    .chain(mine.iter().copied())
                    .chain([gb])
                    .map(|x| holders.get(&x).is_some_and(|h| h.len() == 1))
                    .collect();
                if let (Some(run), Some(nodes), Some(g0), Some(g1)) = (run, nodes, gap(ga), gap(gb)) {
                    junctions.push(Junction { face: fa as usize, run, gap: g0.max(g1), nodes, own });
                }
            }
        }
    }
    junctions
}

/// Each junction's face takes the other face's nodes on its border, where
/// all of them run along it within its sewing distance (`sew` of the face); returns
/// whether any border edge was split. A node whose nearest border point is
/// one of the face's own nodes (no other face has it) becomes that node:
/// the vertex takes its id. Split in beside it, the node would sit a
/// hair's breadth from it, and where both faces take each other's node
/// each puts the pair in its own order, so their borders cross and
/// overlap there.
fn take_their_nodes(faces: &mut [FaceWork<'_>], junctions: Vec<Junction>, sew: &dyn Fn(usize) -> f64) -> bool {
    let mut split = false;
    // Ids that a vertex gave up for another face's node: old to new.
    let mut renamed: HashMap<u32, u32> = HashMap::default();
    for Junction { face, mut run, gap, nodes, mut own } in junctions {
        let sew = sew(face);
        let f = &mut faces[face];
        // Per edge of the run from `from` on: its index, the fraction of its
        // border point nearest `p`, that point's distance and the distance
        // allowed (about as far off as the shared end nodes are).
        let near = |f: &FaceWork<'_>, run: &[u32], from: usize, p: DVec3| {
            (from..run.len() - 1)
                .filter_map(|i| {
                    let (c, d) = (run[i], run[i + 1]);
                    let frac = nearest_on_border(f, c, d, p).clamp(1e-6, 1.0 - 1e-6);
                    let (_, q) = f.mesh.boundary_point(f.surface, &f.curves, c, d, frac)?;
                    let limit = (0.1 * f.mesh.pos[c as usize].distance(f.mesh.pos[d as usize])).max(2.0 * gap).min(sew);
                    Some((i, frac, q.distance(p), limit))
                })
                .collect::<Vec<_>>()
        };
        // All the other border's nodes run along this one, or none is taken:
        // a stretch where they part is not one border.
        if !nodes.iter().all(|&(_, p)| near(f, &run, 0, p).iter().any(|e| e.2 <= e.3)) {
            continue;
        }
        let mut from = 0;
        for (g, p) in nodes {
            // A node another junction made one with a vertex of this run is here already.
            let g = renamed.get(&g).copied().unwrap_or(g);
            if run.iter().any(|&v| f.mesh.gid[v as usize] == g) {
                continue;
            }
            // The nearest of the run's edges from the last node added on.
            let Some((i, frac, e, limit)) = near(f, &run, from, p).into_iter().min_by(|x, y| x.2.total_cmp(&y.2))
            else {
                break;
            };
            if e > limit {
                continue;
            }
            // The border point at an end of the edge that is this face's own node: that node.
            let at_node = [(i, 0.0), (i + 1, 1.0)].into_iter().find(|&(j, end)| {
                let v = run[j] as usize;
                own[j] && (frac - end).abs() <= 1e-3 && f.mesh.pos[v].distance(p) <= limit
            });
            if let Some((j, _)) = at_node {
                let v = run[j] as usize;
                renamed.insert(f.mesh.gid[v], g);
                f.mesh.gid[v] = g;
                own[j] = false;
                from = j;
                split = true;
                continue;
            }
            let mut changed = Vec::new();
            let (c, d) = (run[i], run[i + 1]);
            let Some(n) = f.mesh.split_edge_at(f.surface, &f.curves, c, d, frac, None, &mut changed) else { continue };
            f.mesh.gid[n as usize] = g;
            f.mesh.forget(&changed);
            run.insert(i + 1, n);
            own.insert(i + 1, false);
            from = i + 1;
            split = true;
        }
    }
    split
}

/// The fraction from `a` of the point of the exact border under edge `a-b`
/// of face `f` nearest `q`.
fn nearest_on_border(f: &FaceWork<'_>, a: u32, b: u32, q: DVec3) -> f64 {
    let (pa, pb) = (f.mesh.pos[a as usize], f.mesh.pos[b as usize]);
    let ab = pb - pa;
    let s0 = (guarded_div((q - pa).dot(ab), ab.length_squared())).clamp(0.0, 1.0);
    let dist =
        |s: f64| f.mesh.boundary_point(f.surface, &f.curves, a, b, s).map_or(f64::INFINITY, |(_, p)| p.distance(q));
    nearest_fraction(&dist, s0).0
}

/// Refines every face until its triangles pass (or its budget or the minimum
/// edge stops it), making each split of a shared border edge in every face
/// that shares it and refining again what that split changed there. First
/// closes the T-junctions the outline sewing left, within each face's `sew`. Node ids
/// continue from `ids`. `progress(done, total)` is called as each face's
/// first refinement ends; `false` cancels. Returns whether the budget
/// stopped a face.
///
/// # Errors
/// [`Error::Cancelled`] when `progress` says so.
pub(crate) fn refine_all(
    faces: &mut [FaceWork<'_>],
    mut ids: u32,
    sew: &dyn Fn(usize) -> f64,
    budget: usize,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<bool, Error> {
    let mut uses = close_t_junctions(faces, sew);
    let mut shared: Vec<Vec<((u32, u32), ())>> = alloc::vec![Vec::new(); faces.len()];
    for list in uses.values().filter(|l| l.len() > 1) {
        for &(fi, a, b) in list {
            shared[fi as usize].push(((a.min(b), a.max(b)), ()));
        }
    }
    for (f, s) in faces.iter_mut().zip(shared) {
        f.mesh.shared = EdgeList::from_unsorted(s);
    }
    let mut total: usize = faces.iter().map(|f| f.mesh.tris.len()).sum();
    let mut pending: Vec<Vec<u32>> = faces.iter().map(|f| (0..f.mesh.tris.len() as u32).collect()).collect();
    let mut budget_hit = false;
    // First every face in order, then the faces that splits elsewhere changed.
    let mut queue: alloc::collections::VecDeque<usize> = (0..faces.len()).collect();
    let mut queued: Vec<bool> = alloc::vec![true; faces.len()];
    let mut rounds = 0usize;
    while let Some(fi) = queue.pop_front() {
        queued[fi] = false;
        rounds += 1;
        let todo = core::mem::take(&mut pending[fi]);
        let f = &mut faces[fi];
        let before = f.mesh.tris.len();
        let room = budget.saturating_sub(total - before);
        budget_hit |= f.mesh.refine_from(f.surface, &f.curves, &f.crit, room, todo);
        f.mesh.rest();
        total = total - before + f.mesh.tris.len();
        let events = core::mem::take(&mut f.mesh.events);
        for (a, b, m) in events {
            let (ga, gb) = (faces[fi].mesh.gid[a as usize], faces[fi].mesh.gid[b as usize]);
            let Some(list) = uses.remove(&node_key(ga, gb)) else { continue };
            let g = ids;
            ids += 1;
            faces[fi].mesh.gid[m as usize] = g;
            let p = faces[fi].mesh.pos[m as usize];
            let mut lo_side = alloc::vec![(fi as u32, a, m)];
            let mut hi_side = alloc::vec![(fi as u32, m, b)];
            for (gj, c, d) in list {
                let j = gj as usize;
                if j == fi && node_key(c, d) == node_key(a, b) {
                    continue;
                }
                let h = &mut faces[j];
                // Orient the other use like a→b.
                let (c, d) = if h.mesh.gid[c as usize] == ga { (c, d) } else { (d, c) };
                let frac = nearest_on_border(h, c, d, p).clamp(1e-6, 1.0 - 1e-6);
                let mut changed = Vec::new();
                let before = h.mesh.tris.len();
                // At its own border's point; where that would not split the
                // edge, at the other face's point itself.
                let n = match h.mesh.split_edge_at(h.surface, &h.curves, c, d, frac, None, &mut changed) {
                    Some(n) => n,
                    None => match h.mesh.split_edge_at(h.surface, &h.curves, c, d, frac, Some(p), &mut changed) {
                        Some(n) => n,
                        None => continue,
                    },
                };
                total += h.mesh.tris.len() - before;
                h.mesh.gid[n as usize] = g;
                h.mesh.forget(&changed);
                lo_side.push((gj, c, n));
                hi_side.push((gj, n, d));
                pending[j].extend_from_slice(&changed);
                if !queued[j] {
                    queued[j] = true;
                    queue.push_back(j);
                }
            }
            lo_side.shrink_to_fit();
            hi_side.shrink_to_fit();
            uses.insert(node_key(ga, g), lo_side);
            uses.insert(node_key(g, gb), hi_side);
        }
        if rounds <= faces.len() && !progress(rounds, faces.len()) {
            return Err(Error::Cancelled);
        }
        if rounds > 64 * faces.len() + 1024 {
            break;
        }
    }
    Ok(budget_hit)
}

/// Gives every node of the model one position, the mean of where its faces
/// put it (so each moves by half the gap between them), and returns per
/// face the triangles whose corners moved by more than `negligible` (the
/// rest keep their measures: they changed by less than that).
///
/// Also returns, per node whose faces disagreed, the places they put it,
/// for [`resettle_folds`].
pub(crate) fn settle_nodes(faces: &mut [FaceWork<'_>], negligible: f64) -> (Vec<Vec<u32>>, Places) {
    // Per node (ids are dense): sum of positions, count, its first place,
    // and whether they all agree already; a table, not a map, for memory.
    let ids = faces.iter().flat_map(|f| f.mesh.gid.iter()).filter(|&&g| g != NONE).max().map_or(0, |&g| g as usize + 1);
    let mut sum: Vec<(DVec3, f64, DVec3, bool)> = alloc::vec![(DVec3::ZERO, 0.0, DVec3::ZERO, true); ids];
    for f in faces.iter() {
        for (v, &g) in f.mesh.gid.iter().enumerate() {
            if g != NONE {
                let p = f.mesh.pos[v];
                let e = &mut sum[g as usize];
                if e.1 == 0.0 {
                    e.2 = p;
                }
                e.0 += p;
                e.1 += 1.0;
                e.3 &= e.2 == p;
            }
        }
    }
    // The places of the nodes whose faces disagree by more than a negligible
    // distance (the others cannot fold anything by moving), in face order.
    let mut wide = alloc::vec![false; ids];
    for f in faces.iter() {
        for (v, &g) in f.mesh.gid.iter().enumerate() {
            if let Some(&(s, n, _, false)) = sum.get(g as usize) {
                wide[g as usize] |= f.mesh.pos[v].distance(s / n) > negligible;
            }
        }
    }
    let mut places = Places::default();
    for (fi, f) in faces.iter().enumerate() {
        for (v, &g) in f.mesh.gid.iter().enumerate() {
            if wide.get(g as usize).copied().unwrap_or(false) {
                places.0.push((g, fi as u32, f.mesh.pos[v]));
            }
        }
    }
    places.index();
    let mut changed = Vec::with_capacity(faces.len());
    for f in faces.iter_mut() {
        let mut moved = crate::collections::HashSet::default();
        for v in 0..f.mesh.pos.len() {
            let g = f.mesh.gid[v];
            let Some(&(s, n, _, same)) = sum.get(g as usize) else { continue };
            if n > 1.0 && !same {
                let p = s / n;
                if p.distance(f.mesh.pos[v]) > negligible {
                    moved.insert(v as u32);
                }
                f.mesh.pos[v] = p;
            }
        }
        let tris: Vec<u32> = (0..f.mesh.tris.len() as u32)
            .filter(|&t| f.mesh.tris[t as usize].iter().any(|v| moved.contains(v)))
            .collect();
        changed.push(tris);
    }
    (changed, places)
}

/// Per node, the places its faces put it before settling, each with the
/// face that put it there: one flat list sorted by node (a map of small
/// lists costs several times the memory).
#[derive(Debug, Default)]
pub(crate) struct Places(Vec<(u32, u32, DVec3)>);

impl Places {
    /// Sorts by node, keeping face order (the sort is stable), and drops a
    /// face's repeated place for a node (a seam's vertices of one node).
    fn index(&mut self) {
        crate::sort::by_u64(&mut self.0, |&(g, _, _)| u64::from(g));
        self.0.dedup_by(|b, a| a.0 == b.0 && a.1 == b.1 && a.2 == b.2);
    }

    /// The entries of node `g`.
    fn of_node(&self, g: u32) -> &[(u32, u32, DVec3)] {
        let lo = self.0.partition_point(|&(n, _, _)| n < g);
        let hi = self.0.partition_point(|&(n, _, _)| n <= g);
        &self.0[lo..hi]
    }

    /// Whether node `g`'s faces disagreed.
    fn has(&self, g: u32) -> bool {
        !self.of_node(g).is_empty()
    }

    /// Where face `f` put node `g`, if its faces disagreed.
    fn by_face(&self, g: u32, f: u32) -> Option<DVec3> {
        self.of_node(g).iter().find(|e| e.1 == f).map(|e| e.2)
    }

    /// Node by node, the places of `nodes` one face put them all (every
    /// face that put each of them), each set once, in face order.
    fn sets(&self, nodes: &[u32]) -> Vec<Vec<DVec3>> {
        let first = nodes.first().map_or(&[][..], |&g| self.of_node(g));
        let mut out: Vec<Vec<DVec3>> = Vec::new();
        for &(_, f, _) in first {
            let set: Option<Vec<DVec3>> = nodes.iter().map(|&g| self.by_face(g, f)).collect();
            if let Some(set) = set.filter(|s| !out.contains(s)) {
                out.push(set);
            }
        }
        out
    }
}

/// Each use of a node (face, vertex) with the triangles around it.
type NodeUses = HashMap<u32, Vec<(usize, u32, Vec<u32>)>>;

/// Where settling a node to the mean of its faces' places folded a thin
/// triangle beside it (two faces' borders a hair apart, a sliver narrower
/// than the gap), tries the node at each place a face put it instead and
/// keeps the one that leaves fewest triangles around it, in all its faces,
/// folded or beyond the tolerance; the mean wins ties. A triangle still
/// folded with two or three such nodes then tries them together at one
/// face's places: a face whose sliver lies along its border folds when
/// either end moves off where it put them, so no node alone mends it (one
/// face's row of slivers beside a surface that rolls over just inside its
/// border). Every face still gets each node at one position, so shared
/// borders stay closed. `folded`: per face, its folded triangles. Returns
/// per face the triangles changed.
pub(crate) fn resettle_folds(faces: &mut [FaceWork<'_>], places: &Places, folded: &[Vec<u32>]) -> Vec<Vec<u32>> {
    let mut changed: Vec<Vec<u32>> = alloc::vec![Vec::new(); faces.len()];
    // The nodes of folded triangles that had more than one place, and per
    // folded triangle with more than one, those together.
    let mut nodes: Vec<u32> = Vec::new();
    // A group is its sorted nodes as a triple, 0 for a pair's third: a real
    // third follows two smaller ids, so it is never 0, and the triples sort
    // as the lists would (one shared sort, not a copy for lists of lists).
    let mut groups: Vec<(u32, u32, u32)> = Vec::new();
    for (f, ts) in faces.iter().zip(folded) {
        for &t in ts {
            let mut group: Vec<u32> =
                f.mesh.tris[t as usize].iter().map(|&v| f.mesh.gid[v as usize]).filter(|&g| places.has(g)).collect();
            group.sort_unstable();
            group.dedup();
            nodes.extend_from_slice(&group);
            if group.len() > 1 {
                groups.push((group[0], group[1], group.get(2).copied().unwrap_or(0)));
            }
        }
    }
    nodes.sort_unstable();
    nodes.dedup();
    if nodes.is_empty() {
        return changed;
    }
    crate::sort::triples(&mut groups);
    groups.dedup();
    let uses = node_uses(faces, &nodes);
    let singles = nodes.iter().map(|&g| alloc::vec![g]);
    let joint = groups.into_iter().map(|(a, b, c)| if c == 0 { alloc::vec![a, b] } else { alloc::vec![a, b, c] });
    for unit in singles.chain(joint) {
        if place_best(faces, &uses, places, &unit) {
            for g in &unit {
                for (fi, _, ts) in uses.get(g).map_or(&[][..], |l| &l[..]) {
                    changed[*fi].extend_from_slice(ts);
                }
            }
        }
    }
    for c in &mut changed {
        c.sort_unstable();
        c.dedup();
    }
    changed
}

/// Each use of `nodes` (face, vertex) and the triangles around it.
fn node_uses(faces: &[FaceWork<'_>], nodes: &[u32]) -> NodeUses {
    let wanted: crate::collections::HashSet<u32> = nodes.iter().copied().collect();
    let mut uses: NodeUses = HashMap::default();
    for (fi, f) in faces.iter().enumerate() {
        let mut ring: HashMap<u32, Vec<u32>> = HashMap::default();
        for (v, &g) in f.mesh.gid.iter().enumerate() {
            if wanted.contains(&g) {
                ring.insert(v as u32, Vec::new());
            }
        }
        if ring.is_empty() {
            continue;
        }
        for (t, tri) in f.mesh.tris.iter().enumerate() {
            for v in tri {
                if let Some(list) = ring.get_mut(v) {
                    list.push(t as u32);
                }
            }
        }
        for (v, ts) in ring {
            uses.entry(f.mesh.gid[v as usize]).or_default().push((fi, v, ts));
        }
    }
    uses
}

/// Puts `unit`'s nodes where they leave fewest triangles around them
/// failing ([`WorkMesh::failing`]): where they are, or together at the
/// places one face put them ([`Places::sets`]); where they are wins ties.
/// Returns whether they moved.
fn place_best(faces: &mut [FaceWork<'_>], uses: &NodeUses, places: &Places, unit: &[u32]) -> bool {
    let Some(lists) = unit.iter().map(|g| uses.get(g).filter(|l| !l.is_empty())).collect::<Option<Vec<_>>>() else {
        return false;
    };
    let score = |faces: &mut [FaceWork<'_>], at: &[DVec3]| -> usize {
        for (list, &p) in lists.iter().zip(at) {
            for &(fi, v, _) in list.iter() {
                faces[fi].mesh.pos[v as usize] = p;
            }
        }
        let mut bad = 0;
        for list in &lists {
            for (fi, _, ts) in list.iter() {
                let f = &faces[*fi];
                bad += f.mesh.failing(f.surface, &f.crit, ts);
            }
        }
        bad
    };
    let now: Vec<DVec3> = lists.iter().map(|l| faces[l[0].0].mesh.pos[l[0].1 as usize]).collect();
    let mut best = (score(faces, &now), now.clone());
    if best.0 == 0 {
        return false;
    }
    for set in places.sets(unit) {
        let s = score(faces, &set);
        if s < best.0 {
            best = (s, set);
        }
    }
    score(faces, &best.1);
    best.1 != now
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// The plane z = 0 over [-10, 10]², u = x and v = y.
    fn plane() -> crate::nurbs::NurbsSurface {
        crate::nurbs::analytic::xy_plane(10.0)
    }

    /// The limits the test faces are held to.
    const CRIT: Criteria = Criteria::PLANE_TEST;

    /// A face of [`plane`]: points `(x, y, node id)` (0: no node) at (u,v)
    /// = (x, y), and the triangles on them.
    fn mesh(pts: &[(f64, f64, u32)], tris: &[[u32; 3]]) -> WorkMesh {
        let mut m = WorkMesh::default();
        for &(x, y, g) in pts {
            let v = m.add_vertex(DVec3::new(x, y, 0.0), DVec3::Z);
            if g != 0 {
                m.gid[v as usize] = g;
            }
        }
        for t in tris {
            m.add_triangle(*t, t.map(|v| DVec2::new(pts[v as usize].0, pts[v as usize].1)));
        }
        m
    }

    /// One triangle on the plane z = 0 (u = x, v = y), its vertex `node` the model node 7.
    fn face(corners: [(f64, f64); 3], node: usize) -> WorkMesh {
        let mut m = WorkMesh::default();
        for (x, y) in corners {
            m.add_vertex(DVec3::new(x, y, 0.0), DVec3::Z);
        }
        m.gid[node] = 7;
        m.add_triangle([0, 1, 2], corners.map(|(x, y)| DVec2::new(x, y)));
        m
    }

    /// Two faces put node 7 0.06 apart; settled halfway, the first face's
    /// sliver (0.01 high) folds. At the first face's own place neither face
    /// folds, and both still have the node at one position.
    #[test]
    fn a_node_settled_into_a_fold_moves_to_a_place_that_folds_nothing() {
        let corner = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let plane = plane();
        let crit = CRIT;
        let work = |mesh| FaceWork { surface: &plane, curves: Vec::new(), mesh, crit };
        let mut faces = alloc::vec![
            work(face([(0.0, 0.0), (1.0, 0.0), (0.5, 0.01)], 1)),
            work(face([(1.0, 0.06), (2.0, 0.06), (1.5, 1.0)], 0)),
        ];
        let (_, places) = settle_nodes(&mut faces, 1e-9);
        assert_eq!(faces[0].mesh.pos[1], corner(1.0, 0.03));
        let folded: Vec<Vec<u32>> = faces.iter().map(|f| f.mesh.folded(&plane)).collect();
        assert_eq!(folded, [alloc::vec![0], alloc::vec![]]);
        let moved = resettle_folds(&mut faces, &places, &folded);
        assert_eq!(moved, [alloc::vec![0], alloc::vec![0]]);
        assert!(faces.iter().all(|f| f.mesh.folded(&plane).is_empty()));
        assert_eq!(faces[0].mesh.pos[1], corner(1.0, 0.0));
        assert_eq!(faces[1].mesh.pos[0], corner(1.0, 0.0));
    }

    /// Face A's sliver (0.01 high) lies along its border from node 7 to
    /// node 8; face B put both nodes 0.06 beside A's places. Settled
    /// halfway, the sliver folds, and it still folds with either node alone
    /// at either face's place; with both at A's places it unfolds, and B's
    /// triangle, at A's places, faces the surface's way too.
    #[test]
    fn two_nodes_settled_into_a_fold_move_together_to_one_faces_places() {
        let corner = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let plane = plane();
        let crit = CRIT;
        let work = |mesh| FaceWork { surface: &plane, curves: Vec::new(), mesh, crit };
        let a = mesh(&[(0.0, 0.0, 7), (1.0, 0.0, 8), (0.5, 0.01, 0)], &[[0, 1, 2]]);
        let b = mesh(&[(0.0, 0.06, 7), (1.0, 0.06, 8), (0.5, 1.0, 0)], &[[0, 1, 2]]);
        let mut faces = alloc::vec![work(a), work(b)];
        let (_, places) = settle_nodes(&mut faces, 1e-9);
        assert_eq!(faces[0].mesh.pos[0], corner(0.0, 0.03));
        let folded: Vec<Vec<u32>> = faces.iter().map(|f| f.mesh.folded(&plane)).collect();
        assert_eq!(folded, [alloc::vec![0], alloc::vec![]]);
        let moved = resettle_folds(&mut faces, &places, &folded);
        assert_eq!(moved, [alloc::vec![0], alloc::vec![0]]);
        assert!(faces.iter().all(|f| f.mesh.folded(&plane).is_empty()));
        for (v, x) in [(0, 0.0), (1, 1.0)] {
            assert_eq!(faces[0].mesh.pos[v], corner(x, 0.0));
            assert_eq!(faces[1].mesh.pos[v], corner(x, 0.0));
        }
    }

    /// A triangle clockwise on the plane folds; the same with two corners a
    /// rounding error apart (a pole's nodes), or with its three corners in a
    /// line within `negligible`, has no facet to judge, while one whose
    /// height is still well above `negligible` does.
    #[test]
    fn triangles_flat_within_negligible_distance_fold_nothing() {
        let corner = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let plane = plane();
        let triangle = |c: [(f64, f64); 3]| {
            let mut m = WorkMesh::default();
            for (x, y) in c {
                m.add_vertex(corner(x, y), DVec3::Z);
            }
            m.add_triangle([0, 1, 2], c.map(|(x, y)| DVec2::new(x, y)));
            m
        };
        // Two corners a rounding apart.
        let sliver = |gap: f64| triangle([(0.0, 0.0), (0.0, gap), (1.0, 0.0)]);
        assert!(sliver(1e-9).inverted(&plane, 0));
        assert!(!sliver(1e-9).folded_beyond(&plane, 0, 1e-7));
        assert!(sliver(1e-3).folded_beyond(&plane, 0, 1e-7));
        // Three corners in a line, every edge long: flat, not folded.
        let flat = |off: f64| triangle([(0.0, 0.0), (0.5, off), (1.0, 0.0)]);
        assert!(flat(1e-9).inverted(&plane, 0));
        assert!(!flat(1e-9).folded_beyond(&plane, 0, 1e-7));
        assert!(flat(1e-3).folded_beyond(&plane, 0, 1e-7));
    }

    /// Face A's border runs straight from node 1 to node 2; face B's, 0.02
    /// beside it, passes node 3 on the way. Within the sewing distance A
    /// takes node 3 in, its edge 1-2 becoming 1-3-2; with a sewing distance
    /// under the gap it does not.
    #[test]
    fn a_node_of_the_neighbours_border_closes_the_t_junction() {
        let plane = plane();
        let crit = CRIT;
        let gids = |f: &FaceWork<'_>| -> Vec<(u32, u32)> {
            let mut e: Vec<(u32, u32)> = f
                .mesh
                .boundary_edges()
                .into_iter()
                .map(|(a, b)| node_key(f.mesh.gid[a as usize], f.mesh.gid[b as usize]))
                .filter(|&(a, b)| a != NONE && b != NONE)
                .collect();
            crate::sort::pairs(&mut e);
            e
        };
        for (sew, closed) in [(0.1, true), (0.01, false)] {
            let a = mesh(&[(0.0, 0.0, 0), (1.0, 0.0, 1), (1.0, 1.0, 2), (0.0, 1.0, 0)], &[[0, 1, 2], [0, 2, 3]]);
            let b = mesh(
                &[(1.0, 0.0, 1), (2.0, 0.0, 0), (2.0, 1.0, 0), (1.0, 1.0, 2), (1.02, 0.5, 3)],
                &[[0, 1, 4], [1, 2, 4], [2, 3, 4]],
            );
            let mut faces = alloc::vec![
                FaceWork { surface: &plane, curves: Vec::new(), mesh: a, crit },
                FaceWork { surface: &plane, curves: Vec::new(), mesh: b, crit },
            ];
            close_t_junctions(&mut faces, &|_| sew);
            let want = if closed { alloc::vec![(1, 3), (2, 3)] } else { alloc::vec![(1, 2)] };
            assert_eq!(gids(&faces[0]), want, "sew {sew}");
            assert_eq!(gids(&faces[1]), [(1, 3), (2, 3)], "sew {sew}");
        }
    }

    /// Faces A and B share nodes 1 and 2; between them each border bends
    /// at a node of its own, A's 4 at x = 1.01, B's 3 at x = 1.03. B's node
    /// is nearest A's border at A's node: split in beside it, A's border
    /// would run 1-3-4-2 while B, taking 4, runs 1-4-3-2, the two crossing
    /// over and overlapping. A's node takes B's id instead, and B has
    /// nothing left to take: both run 1-3-2.
    #[test]
    fn a_node_nearest_a_node_of_the_other_border_becomes_it() {
        let plane = plane();
        let crit = CRIT;
        let a = mesh(
            &[(0.0, 0.0, 0), (1.0, 0.0, 1), (1.01, 0.5, 4), (1.0, 1.0, 2), (0.0, 1.0, 0)],
            &[[0, 1, 2], [0, 2, 3], [0, 3, 4]],
        );
        let b = mesh(
            &[(1.0, 0.0, 1), (2.0, 0.0, 0), (2.0, 1.0, 0), (1.0, 1.0, 2), (1.03, 0.5, 3)],
            &[[0, 1, 4], [1, 2, 4], [2, 3, 4]],
        );
        let mut faces = alloc::vec![
            FaceWork { surface: &plane, curves: Vec::new(), mesh: a, crit },
            FaceWork { surface: &plane, curves: Vec::new(), mesh: b, crit },
        ];
        close_t_junctions(&mut faces, &|_| 0.1);
        // Each face's border from node 1 to node 2, by ids.
        let path = |f: &FaceWork<'_>| -> Vec<u32> {
            let edges = f.mesh.boundary_edges();
            let start = f.mesh.gid.iter().position(|&g| g == 1).unwrap_or(0) as u32;
            let mut out = alloc::vec![1];
            let mut cur = start;
            for _ in 0..4 {
                let next = edges.iter().find_map(|&(a, b)| {
                    let n = if a == cur {
                        b
                    } else if b == cur {
                        a
                    } else {
                        return None;
                    };
                    let g = f.mesh.gid[n as usize];
                    (g != NONE && !out.contains(&g)).then_some(n)
                });
                let Some(n) = next else { break };
                out.push(f.mesh.gid[n as usize]);
                cur = n;
            }
            out
        };
        assert_eq!(path(&faces[0]), [1, 3, 2]);
        assert_eq!(path(&faces[1]), [1, 3, 2]);
        assert_eq!(faces[0].mesh.pos.len(), 5, "no vertex split in beside A's node");
    }
}
