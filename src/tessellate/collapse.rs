//! Collapsing a face's edges whose two ends are one point.
//!
//! A pole's loop nodes, or the two ends of a side collapsed to a hair, stay
//! two vertices while the face is built and refined (each end has its own
//! (u,v)); sewing then puts both on the one model node they name. The
//! triangle on such an edge has no area: a viewer gets a NaN normal from it
//! and it is every quality measure's worst triangle. Here each such edge is
//! collapsed and its triangles dropped, where that keeps the face a manifold.

use alloc::vec::Vec;
use glam::DVec3;

use crate::collections::HashMap;

/// Whether `a` and `b` are one point up to rounding (also how the band of a
/// trimmed face judges a loop segment's two ends).
pub(crate) fn one_point(a: DVec3, b: DVec3) -> bool {
    a.distance(b) <= 1e-12 * a.abs().max(b.abs()).max_element().max(1.0)
}

/// Collapses every edge of `tris` whose ends are one point in `pos`, in
/// place, and drops the triangles on it. An edge is left alone when its
/// collapse would join the face to itself elsewhere (its ends share a
/// neighbour that is not a corner of a triangle on the edge, or both ends
/// lie on the border while the edge does not). `with` (empty, or one item
/// per triangle) drops the same items. Returns the triangles dropped.
pub(crate) fn collapse_point_edges<T>(pos: &[DVec3], tris: &mut Vec<[u32; 3]>, with: &mut Vec<T>) -> usize {
    let at = |v: u32| pos.get(v as usize).copied();
    let same = |a: u32, b: u32| matches!((at(a), at(b)), (Some(p), Some(q)) if one_point(p, q));
    collapse_edges_moving(tris, with, same, None, |_, _, _| true).0
}

/// Drops each pair of triangles on the same three vertices that face
/// opposite ways (a flap: sewing put two loop nodes of a collapsed side on
/// one vertex, so the loop runs out to a node and back, and the triangles
/// over that spike, and whatever refinement splits them into, come in such
/// pairs). A flap encloses nothing, and one of its two facets is turned
/// over whatever the surface does; it only adds two uses to each of its
/// edges. `with` (empty, or one item per triangle) drops the same items.
/// Returns the triangles dropped.
pub(crate) fn drop_flaps<T>(tris: &mut Vec<[u32; 3]>, with: &mut Vec<T>) -> usize {
    // Each triangle by its sorted corners, with whether it runs the other way round.
    let mut seen: HashMap<[u32; 3], [Vec<u32>; 2]> = HashMap::default();
    for (i, t) in tris.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let (key, turn) = if b < c { ([a, b, c], 0) } else { ([a, c, b], 1) };
        seen.entry(key).or_default()[turn].push(i as u32);
    }
    let mut gone: Vec<u32> = Vec::new();
    for [one, other] in seen.values() {
        let n = one.len().min(other.len());
        gone.extend_from_slice(&one[..n]);
        gone.extend_from_slice(&other[..n]);
    }
    if gone.is_empty() {
        return 0;
    }
    let mut dropped = alloc::vec![false; tris.len()];
    for &i in &gone {
        dropped[i as usize] = true;
    }
    drop_marked(tris, with, &dropped);
    gone.len()
}

/// Drops the flaps the mesh's edge census sees: pairs of triangles whose
/// corners, with points within `weld` taken for one, are the same three
/// facing opposite ways. Where refinement crowds points (a near-pole, a
/// pleat of the (u,v) map) two apexes across an edge land closer than the
/// weld without an edge between them; the census then counts that edge,
/// and the pair's other edges, three or four times. The pair's corners that
/// weld are joined in the face (each onto its weld group's first vertex) so
/// that the face's own triangles match what the census counts. Returns how
/// far the farthest joined vertex moved (at most `weld`).
pub(crate) fn drop_welded_flaps<T>(pos: &[DVec3], tris: &mut Vec<[u32; 3]>, weld: f64, with: &mut Vec<T>) -> f64 {
    let (map, count) = crate::mesh::weld_positions(pos, weld);
    if count == pos.len() {
        return 0.0;
    }
    let mut first = alloc::vec![u32::MAX; count];
    for (v, &g) in map.iter().enumerate() {
        if first[g as usize] == u32::MAX {
            first[g as usize] = v as u32;
        }
    }
    let rep = |v: u32| map.get(v as usize).map_or(v, |&g| first[g as usize]);
    let mut welded: Vec<[u32; 3]> = tris.iter().map(|t| t.map(rep)).collect();
    let mut kept: Vec<u32> = (0..tris.len() as u32).collect();
    if drop_flaps(&mut welded, &mut kept) == 0 {
        return 0.0;
    }
    let mut dropped = alloc::vec![true; tris.len()];
    for &i in &kept {
        dropped[i as usize] = false;
    }
    // The flaps' corners that weld onto another vertex go to it everywhere
    // in the face; a triangle that leaves without area goes too.
    let mut joined: HashMap<u32, u32> = HashMap::default();
    for (t, _) in tris.iter().zip(&dropped).filter(|(_, &d)| d) {
        for &v in t {
            if rep(v) != v {
                joined.insert(v, rep(v));
            }
        }
    }
    // A join that would turn a kept triangle over (a sliver thinner than
    // the weld) is not made: that vertex keeps its place, a slit narrower
    // than the weld, which the census closes.
    let facet = |t: [u32; 3]| {
        let p = t.map(|v| pos[v as usize]);
        (p[1] - p[0]).cross(p[2] - p[0])
    };
    let mut turns: Vec<u32> = Vec::new();
    for (t, _) in tris.iter().zip(&dropped).filter(|(_, &d)| !d) {
        let new = t.map(|v| joined.get(&v).copied().unwrap_or(v));
        if new != *t && new[0] != new[1] && new[1] != new[2] && new[2] != new[0] && facet(new).dot(facet(*t)) <= 0.0 {
            turns.extend(t.iter().copied().filter(|v| joined.contains_key(v)));
        }
    }
    for v in turns {
        joined.remove(&v);
    }
    let mut shift: f64 = 0.0;
    for (&v, &r) in joined.iter() {
        shift = shift.max(pos[v as usize].distance(pos[r as usize]));
    }
    for (t, d) in tris.iter_mut().zip(dropped.iter_mut()) {
        for v in t.iter_mut() {
            if let Some(&r) = joined.get(v) {
                *v = r;
            }
        }
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            *d = true;
        }
    }
    drop_marked(tris, with, &dropped);
    shift
}

/// Removes the triangles `dropped` marks, and the same items of `with`
/// when it has one per triangle.
fn drop_marked<T>(tris: &mut Vec<[u32; 3]>, with: &mut Vec<T>, dropped: &[bool]) {
    let mut i = 0;
    tris.retain(|_| {
        i += 1;
        !dropped[i - 1]
    });
    if with.len() == dropped.len() {
        let mut i = 0;
        with.retain(|_| {
            i += 1;
            !dropped[i - 1]
        });
    }
}

/// How far, in census welds, collapses may gather vertices into one: far
/// enough to clear the clusters refinement leaves at a near-pole (t4mec's
/// span 17 welds), short of a strip's row of points each a weld apart,
/// which would fold into one fan. Measured on both corpora at 1e-2 and
/// 1e-3: 1 weld clears few clusters, 10 most, 40 adds little and folds one
/// strip. A move this long costs at most 1% of the tolerance.
const REACH_IN_WELDS: f64 = 10.0;

/// Collapses the face's edges shorter than `weld` that have an inner end
/// (`gid` none; an outline vertex stays where sewing put it and the inner
/// end goes to it), as [`collapse_edges`] does. The mesh's edge census
/// takes points within `weld` for one: the triangles on such an edge are,
/// to it, without area, and their neighbours' edges are counted three or
/// four times. Refinement leaves them where a surface's (u,v) map crowds
/// its points (near-poles, pleats). No vertex is carried farther than
/// [`REACH_IN_WELDS`] welds. Returns how far the farthest collapsed vertex
/// moved, which bounds what the collapse adds to the measured deviation.
/// `normals` (empty, or one per triangle: the surface's normal it faces)
/// loses the dropped triangles' too.
pub(crate) fn collapse_short_inner_edges(
    pos: &[DVec3],
    gid: &[u32],
    tris: &mut Vec<[u32; 3]>,
    weld: f64,
    normals: &mut Vec<DVec3>,
) -> f64 {
    let inner = |v: u32| gid.get(v as usize) == Some(&u32::MAX);
    let near = |a: u32, b: u32| matches!((pos.get(a as usize), pos.get(b as usize)), (Some(p), Some(q)) if p.distance(*q) <= weld);
    // A triangle a move turns over (or flattens) would overlap its
    // neighbours, and one it turns against the surface (a sliver, whose
    // facet a short move swings far) folds: such a collapse is not made.
    let facet = |t: [u32; 3]| {
        let p = t.map(|v| pos[v as usize]);
        (p[1] - p[0]).cross(p[2] - p[0])
    };
    let surface_normals = normals.clone();
    let keeps = |i: usize, old: [u32; 3], new: [u32; 3]| {
        let (before, after) = (facet(old), facet(new));
        let faces = surface_normals.get(i).is_none_or(|n| after.dot(*n) > 0.0 || before.dot(*n) <= 0.0);
        after.dot(before) > 0.0 && faces
    };
    let reach = Some(Reach { pos, gid, within: weld * REACH_IN_WELDS });
    let (_, moved) = collapse_edges_moving(tris, normals, |a, b| (inner(a) || inner(b)) && near(a, b), reach, keeps);
    let mut shift: f64 = 0.0;
    for &v in moved.keys() {
        let mut w = v;
        while let Some(&x) = moved.get(&w) {
            w = x;
        }
        shift = shift.max(pos[v as usize].distance(pos[w as usize]));
    }
    shift
}

/// [`collapse_point_edges`] for the edges `same` holds for: a trial mesh,
/// not yet sewn, judges its shape by the edges sewing will make one point.
pub(crate) fn collapse_edges(tris: &mut Vec<[u32; 3]>, same: impl Fn(u32, u32) -> bool) -> usize {
    collapse_edges_moving(tris, &mut Vec::<()>::new(), same, None, |_, _, _| true).0
}

/// How far collapses may carry a vertex: every vertex gathered into a kept
/// one stays within `within` of it, however the collapses chain.
/// A vertex on the face's outline (`gid` set) stays where sewing put it:
/// an inner vertex goes to it, never the other way.
struct Reach<'p> {
    pos: &'p [DVec3],
    gid: &'p [u32],
    within: f64,
}

impl Reach<'_> {
    fn fixed(&self, v: u32) -> bool {
        self.gid.get(v as usize).is_some_and(|&g| g != u32::MAX)
    }
}

/// The edges `same` holds for, each once, lower end first, sorted.
fn candidate_edges(tris: &[[u32; 3]], same: impl Fn(u32, u32) -> bool) -> Vec<(u32, u32)> {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b && same(a, b) {
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    crate::sort::pairs(&mut edges);
    edges.dedup();
    edges
}

/// The triangles at each end of the `edges`: all a collapse looks at.
fn fans_at_ends(tris: &[[u32; 3]], edges: &[(u32, u32)]) -> HashMap<u32, Vec<u32>> {
    let mut around: HashMap<u32, Vec<u32>> = HashMap::default();
    for &(a, b) in edges {
        around.entry(a).or_default();
        around.entry(b).or_default();
    }
    for (i, t) in tris.iter().enumerate() {
        for v in t {
            if let Some(list) = around.get_mut(v) {
                list.push(i as u32);
            }
        }
    }
    around
}

/// Whether collapsing edge a-b (its live triangles `on_edge`, each end
/// with its fan) keeps the face a manifold: the two ends share no
/// neighbour but the edge's apexes (the link condition), and an inner
/// edge does not join two border vertices.
fn stays_manifold(tris: &[[u32; 3]], (a, ta): (u32, &[u32]), (b, tb): (u32, &[u32]), on_edge: &[u32]) -> bool {
    let apexes = on_edge.iter().filter(|&&i| tris[i as usize].iter().any(|&v| v != a && v != b)).count();
    let ring = |list: &[u32], me: u32| -> Vec<u32> {
        let mut r: Vec<u32> = list.iter().flat_map(|&i| tris[i as usize]).filter(|&v| v != me).collect();
        r.sort_unstable();
        r.dedup();
        r
    };
    let (ra, rb) = (ring(ta, a), ring(tb, b));
    let common = ra.iter().filter(|&&v| v != b && rb.binary_search(&v).is_ok()).count();
    if common != apexes {
        return false;
    }
    let border = |list: &[u32], me: u32| {
        let mut seen: Vec<(u32, u32)> = Vec::new();
        for &i in list {
            for &v in &tris[i as usize] {
                if v != me {
                    seen.push((v, i));
                }
            }
        }
        crate::sort::pairs(&mut seen);
        // An edge from `me` with one triangle: `me` is on the border.
        let mut k = 0;
        let mut any = false;
        while k < seen.len() {
            let n = seen[k..].iter().take_while(|s| s.0 == seen[k].0).count();
            any |= n == 1;
            k += n;
        }
        any
    };
    !(on_edge.len() == 2 && border(ta, a) && border(tb, b))
}

/// [`collapse_edges`], also returning where each collapsed vertex went
/// (a chain ends at a kept vertex); a collapse is made only where `keeps`
/// holds for each triangle it rewrites (index, before, after), and, with a
/// `reach`, only where it keeps every gathered vertex within it. `with`
/// (empty, or one item per triangle) loses the items of the triangles dropped.
fn collapse_edges_moving<T>(
    tris: &mut Vec<[u32; 3]>,
    with: &mut Vec<T>,
    same: impl Fn(u32, u32) -> bool,
    reach: Option<Reach<'_>>,
    keeps: impl Fn(usize, [u32; 3], [u32; 3]) -> bool,
) -> (usize, HashMap<u32, u32>) {
    let edges = candidate_edges(tris, same);
    if edges.is_empty() {
        return (0, HashMap::default());
    }
    let mut around = fans_at_ends(tris, &edges);
    let mut dropped = alloc::vec![false; tris.len()];
    // Where each collapsed vertex went (chains end at a kept vertex).
    let mut moved: HashMap<u32, u32> = HashMap::default();
    let find = |moved: &HashMap<u32, u32>, mut v: u32| {
        while let Some(&w) = moved.get(&v) {
            v = w;
        }
        v
    };
    // How far the farthest vertex gathered into each kept vertex lies from it.
    let mut gathered: HashMap<u32, f64> = HashMap::default();
    let mut count = 0;
    for &(a0, b0) in &edges {
        let (mut a, mut b) = (find(&moved, a0), find(&moved, b0));
        if a == b {
            continue;
        }
        if let Some(r) = reach.as_ref().filter(|r| r.fixed(b)) {
            if r.fixed(a) {
                continue;
            }
            core::mem::swap(&mut a, &mut b);
        }
        // Bounds b's gathered vertices' distance to a by the triangle
        // inequality: a line of points each a short step from the next
        // would otherwise fold into one fan.
        let spread = reach.as_ref().map(|r| {
            let d = r.pos[a as usize].distance(r.pos[b as usize]);
            d + gathered.get(&b).copied().unwrap_or(0.0)
        });
        if matches!((&reach, spread), (Some(r), Some(d)) if d > r.within) {
            continue;
        }
        let live = |v: u32| -> Vec<u32> {
            around.get(&v).map(|l| l.iter().copied().filter(|&i| !dropped[i as usize]).collect()).unwrap_or_default()
        };
        let (ta, tb) = (live(a), live(b));
        let on_edge: Vec<u32> = ta.iter().copied().filter(|&i| tris[i as usize].contains(&b)).collect();
        if on_edge.is_empty() || on_edge.len() > 2 || !stays_manifold(tris, (a, &ta), (b, &tb), &on_edge) {
            continue;
        }
        let turned = tb.iter().filter(|&&i| !on_edge.contains(&i)).any(|&i| {
            let old = tris[i as usize];
            !keeps(i as usize, old, old.map(|v| if v == b { a } else { v }))
        });
        if turned {
            continue;
        }
        for &i in &on_edge {
            dropped[i as usize] = true;
            count += 1;
        }
        for &i in &tb {
            if !dropped[i as usize] {
                for v in tris[i as usize].iter_mut() {
                    if *v == b {
                        *v = a;
                    }
                }
            }
        }
        let mut merged = ta;
        merged.extend(tb.iter().copied().filter(|&i| !dropped[i as usize]));
        around.insert(a, merged);
        moved.insert(b, a);
        if let Some(d) = spread {
            let g = gathered.entry(a).or_insert(0.0);
            *g = g.max(d);
        }
    }
    if count > 0 {
        drop_marked(tris, with, &dropped);
    }
    (count, moved)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fan about a pole whose two loop ends were sewn onto one point:
    /// the one triangle on that edge goes, the rest keep their corners.
    #[test]
    fn a_pole_edge_collapses_and_its_sliver_goes() {
        // 0 and 1 are the pole (one point), 2..5 a ring below it; the
        // border runs 2-0-1-5 and on around the ring.
        let pos = [
            DVec3::ZERO,
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 1.0, -1.0),
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(0.0, -1.0, -1.0),
        ];
        let mut tris = alloc::vec![[0, 2, 3], [0, 3, 4], [0, 4, 1], [1, 4, 5]];
        assert_eq!(collapse_point_edges(&pos, &mut tris, &mut Vec::<()>::new()), 1);
        assert_eq!(tris.len(), 3);
        assert!(tris.iter().all(|t| !t.contains(&1)), "vertex 1 folded into 0: {tris:?}");
        for t in &tris {
            let area =
                (pos[t[1] as usize] - pos[t[0] as usize]).cross(pos[t[2] as usize] - pos[t[0] as usize]).length();
            assert!(area > 0.1, "a triangle without area is left: {t:?}");
        }
    }

    /// A face's loop run out along a collapsed side to a node and back to
    /// one pole vertex (0 at both ends of the spike to 1): the first mesh
    /// spans the spike with two triangles on the same corners, and a split
    /// of their long edge at 4 gives a second such pair. Each pair goes,
    /// the fold it counted with it, and the fan beside it stays whole.
    #[test]
    fn a_flap_over_a_spike_goes_and_its_fold_with_it() {
        let pos = [
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 2e-3),
            DVec3::new(10.0, 0.0, -1.0),
            DVec3::new(10.0, 3.0, -1.0),
            DVec3::new(5.0, 0.2, -0.5),
        ];
        let up = DVec3::new(0.1, 0.0, 1.0).normalize();
        let mut tris = alloc::vec![[2, 3, 0], [0, 1, 4], [4, 2, 0], [1, 0, 4], [2, 4, 0], [0, 2, 1]];
        let mut normals = alloc::vec![up; tris.len()];
        assert!(crate::tessellate::refine::count_folded(&pos, &tris, &normals, 1e-2, 0.0) > 0);
        assert_eq!(drop_flaps(&mut tris, &mut normals), 4);
        assert_eq!(tris, [[2, 3, 0], [0, 2, 1]]);
        assert_eq!(normals.len(), 2);
        assert_eq!(crate::tessellate::refine::count_folded(&pos, &tris, &normals, 1e-2, 0.0), 0);
        // The same triangle twice the same way round is no flap.
        let mut twice = alloc::vec![[0, 2, 3], [2, 3, 0]];
        assert_eq!(drop_flaps(&mut twice, &mut Vec::<()>::new()), 0);
    }

    /// Two triangles across edge 0-1 whose apexes 2 and 3 lie closer than
    /// the weld (refinement crowding a near-pole) face opposite ways: to
    /// the census they are one flap, counting 0-1 three times with the
    /// fan's triangle 0-4-1. The pair goes, 3 joins 2 in its other
    /// triangle, and the move is reported; a weld that does not reach from 3
    /// to 2 leaves the face alone.
    #[test]
    fn a_flap_the_weld_makes_goes_and_its_apexes_join() {
        let pos = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, 1.0, 1e-7),
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(-0.5, 1.0, 0.0),
        ];
        let faces = alloc::vec![[0, 1, 2], [1, 0, 3], [0, 4, 1], [3, 0, 5]];
        let mut tris = faces.clone();
        let mut tags: Vec<u32> = (0..tris.len() as u32).collect();
        let shift = drop_welded_flaps(&pos, &mut tris, 1e-6, &mut tags);
        assert_eq!(tris, [[0, 4, 1], [2, 0, 5]]);
        assert_eq!(tags, [2, 3]);
        assert!(shift > 0.0 && shift <= 1e-6, "the join moved 3 by {shift}");
        let mut apart = faces.clone();
        assert_eq!(drop_welded_flaps(&pos, &mut apart, 1e-8, &mut Vec::<()>::new()), 0.0);
        assert_eq!(apart, faces);
    }

    /// Two border vertices at one point joined by an inner edge: collapsing
    /// it would pinch the face into two, so it stays.
    #[test]
    fn an_inner_edge_between_border_points_stays() {
        // A strip 0-1-2 / 3-4-5 whose middle column 1,4 is one point.
        let pos = [
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1.0, -1.0, 0.0),
        ];
        let mut tris = alloc::vec![[0, 3, 4], [0, 4, 1], [1, 4, 5], [1, 5, 2]];
        assert_eq!(collapse_point_edges(&pos, &mut tris, &mut Vec::<()>::new()), 0);
        assert_eq!(tris.len(), 4);
    }

    /// A fan whose two inner vertices lie closer than the weld distance:
    /// their edge goes with its two triangles, the move is reported; two
    /// border vertices as close stay apart.
    #[test]
    fn inner_edges_shorter_than_the_weld_collapse() {
        // A square 0..3 (border) round two inner vertices 4, 5 1e-6 apart.
        let pos = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1e-6, 0.0, 0.0),
        ];
        let none = u32::MAX;
        let gid = [0, 1, 2, 3, none, none];
        let mut tris = alloc::vec![[0, 1, 5], [0, 5, 4], [1, 2, 5], [2, 3, 4], [2, 4, 5], [3, 0, 4]];
        let shift = collapse_short_inner_edges(&pos, &gid, &mut tris, 1e-3, &mut Vec::new());
        assert_eq!(tris.len(), 4, "{tris:?}");
        assert!((shift - 1e-6).abs() < 1e-12, "moved {shift}");
        assert!(tris.iter().all(|t| !t.contains(&5)));
        // The same two points on the border: nothing moves.
        let gid = [0, 1, 2, 3, 4, 5];
        let mut tris = alloc::vec![[0, 1, 5], [0, 5, 4], [1, 2, 5], [2, 3, 4], [2, 4, 5], [3, 0, 4]];
        assert_eq!(collapse_short_inner_edges(&pos, &gid, &mut tris, 1e-3, &mut Vec::new()), 0.0);
        assert_eq!(tris.len(), 6);
        // Vertex 4 on the outline, 5 inner: 5 goes to 4, never 4 to 5.
        let gid = [0, 1, 2, 3, 4, none];
        let mut tris = alloc::vec![[0, 1, 5], [0, 5, 4], [1, 2, 5], [2, 3, 4], [2, 4, 5], [3, 0, 4]];
        collapse_short_inner_edges(&pos, &gid, &mut tris, 1e-3, &mut Vec::new());
        assert_eq!(tris.len(), 4, "{tris:?}");
        assert!(tris.iter().all(|t| !t.contains(&5)) && tris.iter().any(|t| t.contains(&4)), "{tris:?}");
    }

    /// A sliver whose inner corner lies a weld from an outline vertex but on
    /// the other side of its long edge's vertical plane: the move swings
    /// its facet by 60°, past the surface's side, so the collapse is refused
    /// (without the surface's normals it is made).
    #[test]
    fn a_collapse_that_turns_a_sliver_against_the_surface_is_refused() {
        let e = 1e-4;
        let (s, c) = (0.5 * e, 0.866 * e);
        // a, b the long edge; y on the outline, x inner, e apart.
        let pos = [DVec3::ZERO, DVec3::new(0.0, 1.0, 0.0), DVec3::new(s, 0.5, c), DVec3::new(-s, 0.5, c)];
        let gid = [0, 1, 2, u32::MAX];
        let fan = alloc::vec![[0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let up = |n: usize| alloc::vec![DVec3::Z; n];
        let mut tris = fan.clone();
        let mut normals = up(3);
        assert_eq!(collapse_short_inner_edges(&pos, &gid, &mut tris, 1e-3, &mut normals), 0.0);
        assert_eq!(tris, fan);
        // Only the facets judged: the move keeps the sliver within 90° of
        // its old facet, so it is made and the sliver faces down.
        let mut tris = fan.clone();
        assert!(collapse_short_inner_edges(&pos, &gid, &mut tris, 1e-3, &mut Vec::new()) > 0.0);
        assert_eq!(tris, alloc::vec![[0, 1, 2]]);
        let p = tris[0].map(|v| pos[v as usize]);
        assert!((p[1] - p[0]).cross(p[2] - p[0]).z < 0.0);
    }

    /// A row of inner points each 0.6 welds from the next, 18 welds long,
    /// between two outline corners above and below: collapses gather no
    /// vertex farther than the reach, so the row is not folded into one.
    #[test]
    fn a_row_of_close_points_is_not_gathered_into_one() {
        let weld = 1e-3;
        let n = 30u32;
        // 0 and 1 below, 2 and 3 above, the row from 4.
        let mut pos = alloc::vec![
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ];
        pos.extend((0..n).map(|i| DVec3::new(f64::from(i) * 0.6 * weld, 0.5, 0.0)));
        let gid: Vec<u32> = (0..4).chain((0..n).map(|_| u32::MAX)).collect();
        let row = |i: u32| 4 + i;
        let last = row(n - 1);
        let mut tris = alloc::vec![[3, 0, row(0)], [0, 1, last], [last, 1, 2], [3, last, 2]];
        for i in 0..n - 1 {
            tris.push([0, row(i + 1), row(i)]);
            tris.push([3, row(i), row(i + 1)]);
        }
        let shift = collapse_short_inner_edges(&pos, &gid, &mut tris, weld, &mut Vec::new());
        assert!(shift > 0.0 && shift <= REACH_IN_WELDS * weld + 1e-15, "moved {shift}");
        let mut left: Vec<u32> = tris.iter().flatten().copied().filter(|&v| v >= 4).collect();
        left.sort_unstable();
        left.dedup();
        assert!(left.len() >= 2 && left.len() < n as usize, "row vertices left: {left:?}");
        // Every triangle left keeps its area and its turn.
        for t in &tris {
            let p = t.map(|v| pos[v as usize]);
            assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0, "{t:?}");
        }
    }

    /// Points apart by more than rounding are not one point.
    #[test]
    fn a_short_edge_is_not_a_point() {
        let pos = [DVec3::ZERO, DVec3::new(1e-9, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let mut tris = alloc::vec![[0, 1, 2]];
        assert_eq!(collapse_point_edges(&pos, &mut tris, &mut Vec::<()>::new()), 0);
        assert_eq!(tris.len(), 1);
    }
}
