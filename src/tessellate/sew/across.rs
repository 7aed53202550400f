//! Insertions that would sew a border across a face (see [`across_faces`]).

use alloc::vec::Vec;
use core::cell::RefCell;
use glam::DVec3;

use super::nearest_fraction;
use super::outlines::{Candidate, NodeRef, PerNode};
use crate::collections::CellGrid;
use crate::numeric::guarded_div;
use crate::nurbs::Surface;
use crate::tessellate::face::Outline;

/// Share of a candidate's distance within which a third face's border
/// beside its point counts as lying between the node and that point.
const BETWEEN: f64 = 0.5;

/// Per candidate (a node `q` of one face to be added to another face's
/// border at point `P`, `d` apart), whether the border of some third face of
/// their body, or another piece of `q`'s own face's border, runs within
/// `BETWEEN · d` of `P` but not as near `q`: that face lies between them,
/// a strip narrower than the sewing distance, and `q` on the border would
/// lay the border's face over it (the two overlap on the strip, and the
/// strip's sides become a crack no join can close the right way up). A
/// piece of `q`'s own face counts within `d` of `P` where it is farther
/// than `d` from `q`: `P` lies as near that face's other side as `q` is
/// (a fitted face's border halfway across a strip). Where
/// both faces at `P` fold shut there by themselves (each has a node of its
/// own at `q` within `tight` and its `reach` of `P`: a loop that doubles
/// back on itself), all of them take `q` and the insertion stands.
/// Candidates farther than `limit` (they are refused anyway) and those at
/// nothing are not looked at. `cell`: the side of the grid's cubes.
#[allow(clippy::too_many_arguments)]
pub(super) fn across_faces(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    pos: &PerNode<DVec3>,
    nodes: &CellGrid<NodeRef>,
    cands: &[Candidate],
    limit: &dyn Fn(&Candidate) -> f64,
    reach: &dyn Fn(NodeRef) -> f64,
    cell: f64,
    tight: f64,
) -> Vec<bool> {
    let mut probes: Vec<Probe> = Vec::new();
    let mut looked: Vec<usize> = Vec::new();
    for (ci, c) in cands.iter().enumerate() {
        let &(seg, _, t, d, q) = c;
        let at_q = pos[q.0 as usize][q.1 as usize][q.2 as usize];
        if d > limit(c) || d <= 1e-9 * at_q.abs().max_element() {
            continue;
        }
        let Some((surface, o)) = &faces[seg.0 as usize] else { continue };
        let Some(poly) = o.loops.polys.get(seg.1 as usize) else { continue };
        let Some(curve) = poly.seg.get(seg.2 as usize).and_then(|s| o.loops.curves.get(s.0 as usize)) else {
            continue;
        };
        probes.push(Probe { face: seg.0, p: surface.point(curve.point(t).truncate()), q, d });
        looked.push(ci);
    }
    let mut across = alloc::vec![false; cands.len()];
    for (ci, x) in looked.into_iter().zip(between(faces, bodies, pos, nodes, &probes, reach, cell, tight)) {
        across[ci] = x;
    }
    across
}

/// A node `q` to become one with point `p` of face `face`'s border, `d` apart.
#[derive(Clone, Copy)]
pub(super) struct Probe {
    pub face: u32,
    pub p: DVec3,
    pub q: NodeRef,
    pub d: f64,
}

/// Per probe, whether a third face's border (or another piece of `q`'s
/// own face's) lies between `q` and `p`, as [`across_faces`] tells it.
/// Probes at nothing (`d` a rounding) are not looked at.
#[allow(clippy::too_many_arguments)]
pub(super) fn between(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    pos: &PerNode<DVec3>,
    nodes: &CellGrid<NodeRef>,
    all: &[Probe],
    reach: &dyn Fn(NodeRef) -> f64,
    cell: f64,
    tight: f64,
) -> Vec<bool> {
    let mut across = alloc::vec![false; all.len()];
    let at = |n: NodeRef| pos[n.0 as usize][n.1 as usize][n.2 as usize];
    let body = |f: u32| crate::model::body_of(bodies, f as usize);
    // Whether face `f` folds shut at `p` by itself: a node of its own
    // within `r` of `q` goes onto its border at `p` (no farther than
    // `tight` and its reach), so every face there takes `q`.
    let pinches = |f: u32, q: DVec3, p: DVec3, r: f64| {
        let r3 = DVec3::splat(r);
        nodes
            .in_box(q - r3, q + r3)
            .any(|&m| m.0 == f && at(m).distance(q) <= r && at(m).distance(p) <= tight.min(reach(m)))
    };
    // Each probe looked at: its index and point on the border.
    let probes: Vec<(usize, DVec3)> = all
        .iter()
        .enumerate()
        .filter(|(_, pr)| pr.d > 1e-9 * at(pr.q).abs().max_element())
        .map(|(i, pr)| (i, pr.p))
        .collect();
    let Some(widest) = probes.iter().map(|&(ci, _)| all[ci].d).reduce(f64::max) else {
        return across;
    };
    let mut grid = CellGrid::new(guarded_div(1.0, cell));
    for (pi, &(_, p)) in probes.iter().enumerate() {
        grid.insert(p, pi as u32);
    }
    for (hi, item) in faces.iter().enumerate() {
        let Some((surface, o)) = item else { continue };
        let h = hi as u32;
        for (k, poly) in o.loops.polys.iter().enumerate() {
            let ring = &pos[hi][k];
            let n = ring.len();
            for i in 0..n {
                let (j, a, b) = ((i + 1) % n, ring[i], ring[(i + 1) % n]);
                // The piece strays from its chord by at most about half its
                // length (a semicircle's) as a loop is discretized: every
                // point it passes near is found near its chord with that room.
                let half = 0.5 * a.distance(b);
                let mut probes_near = grid.near_segment(a, b, widest + half).peekable();
                if probes_near.peek().is_none() {
                    continue;
                }
                let Some(&(curve, ta, tb)) = poly.seg.get(i) else { continue };
                let Some(c) = o.loops.curves.get(curve as usize) else { continue };
                let on_curve = |s: f64| surface.point(c.point(ta + (tb - ta) * s).truncate());
                // How far the piece strays from its chord: twice as far as
                // its quarter points do (the test that discretized it).
                let ab = b - a;
                let off_chord = |x: DVec3| {
                    let s0 = guarded_div((x - a).dot(ab), ab.length_squared()).clamp(0.0, 1.0);
                    x.distance(a + ab * s0)
                };
                let sag = [0.25, 0.5, 0.75].map(|s| off_chord(on_curve(s))).into_iter().fold(0.0, f64::max);
                let room = (2.0 * sag + 1e-9 * (a.abs().max_element() + b.abs().max_element())).min(half);
                // The piece's nearest points found so far, by the point
                // they are nearest to: a point is asked about at two radii,
                // and a node `q` for each border point it is to join.
                let nearest: RefCell<Vec<([u64; 3], f64)>> = RefCell::new(Vec::new());
                // Whether the piece passes within `r` of `x`: by its chord
                // where the room decides, else by the nearest point.
                let within = |x: DVec3, r: f64| {
                    let s0 = guarded_div((x - a).dot(ab), ab.length_squared()).clamp(0.0, 1.0);
                    let to_chord = x.distance(a + ab * s0);
                    if to_chord - room > r {
                        return false;
                    }
                    if to_chord + room < r {
                        return true;
                    }
                    let bits = x.to_array().map(f64::to_bits);
                    let known = nearest.borrow().iter().find(|(b, _)| *b == bits).map(|&(_, d)| d);
                    let d = known.unwrap_or_else(|| {
                        let d = nearest_fraction(&|s: f64| on_curve(s).distance(x), s0).1;
                        nearest.borrow_mut().push((bits, d));
                        d
                    });
                    d < r
                };
                for &pi in probes_near {
                    let (ci, p) = probes[pi as usize];
                    let Probe { face, q, d, .. } = all[ci];
                    let mine = q.0 == h && q.1 == k as u32 && (q.2 == i as u32 || q.2 == j as u32);
                    if across[ci] || mine || face == h || body(face) != body(h) {
                        continue;
                    }
                    // Another piece of `q`'s own face at least as near `p`
                    // as `q` is, but farther from `q` than `p`: `p` lies
                    // across that face, by its other side.
                    let r = if h == q.0 && within(p, d) && !within(at(q), d) { d } else { BETWEEN * d };
                    if within(p, r) && !within(at(q), r) && !(pinches(face, at(q), p, r) && pinches(h, at(q), p, r)) {
                        across[ci] = true;
                    }
                }
            }
        }
    }
    across
}

#[cfg(test)]
mod tests {
    use crate::nurbs::{NurbsCurve, NurbsSurface, Surface};
    use crate::tessellate::face::Outline;
    use crate::tessellate::sew::outlines::unify;
    use crate::tessellate::trim::{CurveRef, Loops, Polyline};
    use alloc::vec::Vec;
    use glam::{DVec2, DVec3};

    /// The plane z = `z` over 3 by 12, its (u,v) its (x,y).
    fn plane_at(z: f64) -> NurbsSurface {
        let pts: Vec<Vec<DVec3>> = alloc::vec![
            alloc::vec![DVec3::new(0.0, 0.0, z), DVec3::new(0.0, 12.0, z)],
            alloc::vec![DVec3::new(3.0, 0.0, z), DVec3::new(3.0, 12.0, z)],
        ];
        NurbsSurface::try_new([1, 1], alloc::vec![0.0, 0.0, 3.0, 3.0], alloc::vec![0.0, 0.0, 12.0, 12.0], &pts, None)
            .unwrap()
    }

    /// The outline of the polygon `corners` in (u,v), one straight curve and
    /// one segment per side.
    fn polygon(corners: &[(f64, f64)]) -> (Vec<NurbsCurve>, Vec<DVec2>) {
        let n = corners.len();
        let curves = (0..n)
            .map(|i| {
                let (p, q) = (corners[i], corners[(i + 1) % n]);
                let pts = alloc::vec![DVec3::new(p.0, p.1, 0.0), DVec3::new(q.0, q.1, 0.0)];
                NurbsCurve::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0], pts, None).unwrap()
            })
            .collect();
        (curves, corners.iter().map(|&(u, v)| DVec2::new(u, v)).collect())
    }

    fn outline<'a>(curves: &'a [NurbsCurve], uv: &[DVec2]) -> Outline<'a> {
        let mut poly = Polyline::default();
        for (i, &q) in uv.iter().enumerate() {
            poly.uv.push(q);
            poly.at.push(CurveRef { curve: i as u32, t: 0.0 });
            poly.seg.push((i as u32, 0.0, 1.0));
        }
        let gids = alloc::vec![alloc::vec![u32::MAX; poly.uv.len()]];
        let loops = Loops { polys: alloc::vec![poly], curves: curves.iter().collect(), mended: None };
        Outline { loops, pu: alloc::vec![0.0, 3.0], pv: alloc::vec![0.0, 12.0], gids, crossed: false }
    }

    /// Three faces of one plane side by side: `f` up to u = 1, a strip 0.3
    /// wide beyond it whose lower end is slanted, and `g` beyond the strip.
    /// `g`'s corner at the strip's far end lies 0.3 from `f`'s border, within
    /// the sewing distance and the model's precision (`tight`), but the strip
    /// lies between: `f` must not take that corner (it would run over the
    /// strip's end, the two faces overlapping there), while it does take the
    /// strip's corner that lies on its border.
    #[test]
    fn a_node_is_not_sewn_across_a_narrow_face() {
        let plane = plane_at(0.0);
        let (fc, fuv) = polygon(&[(0.0, 0.0), (1.0, 0.0), (1.0, 12.0), (0.0, 12.0)]);
        let (hc, huv) = polygon(&[(1.0, 0.8), (1.3, 1.0), (1.3, 11.0), (1.0, 11.0)]);
        let (gc, guv) = polygon(&[(1.3, 1.0), (3.0, 1.0), (3.0, 11.0), (1.3, 11.0)]);
        let (mut f, mut h, mut g) = (outline(&fc, &fuv), outline(&hc, &huv), outline(&gc, &guv));
        {
            let s = &plane as &dyn Surface;
            let mut faces = alloc::vec![Some((s, &mut f)), Some((s, &mut h)), Some((s, &mut g))];
            unify(&mut faces, &[], &[0.0; 3], 0.5, 0.4, 1.0);
        }
        let ids = |o: &Outline<'_>, far: bool| -> Vec<u32> {
            o.loops.polys[0].uv.iter().zip(&o.gids[0]).filter(|(q, _)| (q.x > 1.2) == far).map(|(_, &g)| g).collect()
        };
        let beyond: Vec<u32> = ids(&h, true).into_iter().chain(ids(&g, true)).collect();
        let mine = ids(&f, false);
        assert!(mine.iter().all(|id| !beyond.contains(id)), "f {mine:?} takes a node of {beyond:?}");
        // The strip's near corners are f's nodes too: the two are sewn.
        assert!(ids(&h, false).iter().all(|id| mine.contains(id)), "{:?} {mine:?}", ids(&h, false));
    }

    /// A plane 3 by 12 cut into `f` up to u = 1, a strip `w` wide and `g`
    /// beyond it, each border with a node every 2 along v, the strip's on
    /// both its sides beside its neighbours'. Returns the ids of `f`'s,
    /// the strip's near and far, and `g`'s nodes along the strip's long
    /// sides (ends left out), with `tight` 0.4 and `sew` 0.5.
    fn strip_ids(w: f64) -> [Vec<u32>; 4] {
        let plane = plane_at(0.0);
        let side = |u: f64, up: bool| -> Vec<(f64, f64)> {
            let v = (0..=6).map(|i| f64::from(2 * i));
            if up {
                v.map(|v| (u, v)).collect()
            } else {
                v.rev().map(|v| (u, v)).collect()
            }
        };
        let u1 = 1.0 + w;
        let fp: Vec<(f64, f64)> = [(0.0, 0.0)].into_iter().chain(side(1.0, true)).chain([(0.0, 12.0)]).collect();
        let hp: Vec<(f64, f64)> = side(1.0, true).into_iter().chain(side(u1, false)).collect();
        let gp: Vec<(f64, f64)> = side(u1, true).into_iter().chain([(3.0, 12.0), (3.0, 0.0)]).collect();
        let (fc, fuv) = polygon(&fp);
        let (hc, huv) = polygon(&hp);
        let (gc, guv) = polygon(&gp);
        let (mut f, mut h, mut g) = (outline(&fc, &fuv), outline(&hc, &huv), outline(&gc, &guv));
        {
            let s = &plane as &dyn Surface;
            let mut faces = alloc::vec![Some((s, &mut f)), Some((s, &mut h)), Some((s, &mut g))];
            unify(&mut faces, &[], &[0.0; 3], 0.5, 0.4, 1.0);
        }
        let ids = |o: &Outline<'_>, u: f64| -> Vec<u32> {
            let poly = &o.loops.polys[0];
            poly.uv
                .iter()
                .zip(&o.gids[0])
                .filter(|(q, _)| (q.x - u).abs() < 1e-9 && q.y > 1.0 && q.y < 11.0)
                .map(|(_, &g)| g)
                .collect()
        };
        [ids(&f, 1.0), ids(&h, 1.0), ids(&h, u1), ids(&g, u1)]
    }

    /// A strip narrower than `tight` but wider than a gap, with faces
    /// along both its sides, keeps its sides apart when nodes are named:
    /// folding it where its side nodes face each other (while no node of
    /// one neighbour went onto its far side) left it half folded, the
    /// neighbours overlapping it. Narrower than a gap it folds shut.
    #[test]
    fn a_strip_between_faces_keeps_its_sides_when_named() {
        let [f, near, far, g] = strip_ids(0.1);
        assert_eq!(f.len(), 5, "{f:?}");
        assert!(f.iter().all(|id| !g.contains(id) && !far.contains(id)), "f {f:?} g {g:?} far side {far:?}");
        assert!(near.iter().all(|id| f.contains(id)), "near side {near:?} f {f:?}");
        assert!(far.iter().all(|id| g.contains(id)), "far side {far:?} g {g:?}");
        let [f, _, _, g] = strip_ids(0.04);
        assert!(!f.is_empty() && f.iter().all(|id| g.contains(id)), "a gap: f {f:?} g {g:?}");
    }

    /// A strip 0.3 wide (wider than `tight`) beside a face `f` of another
    /// surface 0.2 above it, whose border runs 0.1 inside the strip (a
    /// fitted face off its neighbours): the strip's far side, its nodes
    /// between `f`'s, lies about as near `f`'s border (0.28) as its near
    /// side does (0.22). Taking a far-side node put `f` over the strip
    /// there, its border zigzagging between the strip's two sides (edges
    /// of three faces); `f` takes only near-side nodes.
    #[test]
    fn a_node_is_not_sewn_across_its_own_face() {
        let (low, high) = (plane_at(0.0), plane_at(0.2));
        let even = |u: f64| (0..=6).map(move |i| (u, f64::from(2 * i)));
        let odd: Vec<f64> = [0.0].into_iter().chain((0..6).map(|i| f64::from(2 * i + 1))).chain([12.0]).collect();
        let fp: Vec<(f64, f64)> = [(0.0, 0.0)].into_iter().chain(even(1.1)).chain([(0.0, 12.0)]).collect();
        let hp: Vec<(f64, f64)> = even(1.0).chain(odd.iter().rev().map(|&v| (1.3, v))).collect();
        let (fc, fuv) = polygon(&fp);
        let (hc, huv) = polygon(&hp);
        let (mut f, mut h) = (outline(&fc, &fuv), outline(&hc, &huv));
        {
            let (sl, sh) = (&low as &dyn Surface, &high as &dyn Surface);
            let mut faces = alloc::vec![Some((sh, &mut f)), Some((sl, &mut h))];
            unify(&mut faces, &[], &[0.0; 2], 0.5, 0.25, 1.0);
        }
        let ids = |o: &Outline<'_>, lo: f64, hi: f64| -> Vec<u32> {
            let poly = &o.loops.polys[0];
            poly.uv
                .iter()
                .zip(&o.gids[0])
                .filter(|(q, _)| q.x > lo && q.x < hi && q.y > 0.5 && q.y < 11.5)
                .map(|(_, &g)| g)
                .collect()
        };
        let (mine, near, far) = (ids(&f, 0.5, 2.0), ids(&h, 0.9, 1.1), ids(&h, 1.2, 1.4));
        assert_eq!(far.len(), 6, "{far:?}");
        assert!(mine.iter().all(|id| !far.contains(id)), "f {mine:?} takes a node of the far side {far:?}");
        // The near side is f's: the two are sewn.
        assert!(near.iter().all(|id| mine.contains(id)), "near side {near:?} f {mine:?}");
    }
}
