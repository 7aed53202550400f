//! Sliding border nodes of faces that share a border onto one another
//! before the outlines are sewn (see [`slide_nodes`]).

use glam::DVec3;

use super::inside::Inside;
use super::outlines::PerNode;
use crate::collections::CellGrid;
use crate::nurbs::Surface;
use crate::tessellate::face::Outline;

/// Share of a node's shorter segment within which it slides along its
/// curve onto another face's node (see [`slide_nodes`]).
const SNAP_SHARE: f64 = 0.3;

/// Two faces discretize the border they share each on its own (a rebuilt
/// face, paper 001, on its new curves; any two faces whose curves run at
/// different speeds), so sewn together each would add a node beside each
/// of the other's, and the short segments between fan needles into both.
/// Before sewing, each inner node of a curve that has another face's node
/// within [`SNAP_SHARE`] of its shorter segment slides along its curve to
/// the point nearest that node when that point lies within `sew` of it, no
/// segment of its own shrinks below `1 - SNAP_SHARE` of the shorter one,
/// and no other node of its face lies within `sew` of that node (a strip
/// narrower than that would be sewn shut). The two are then one node. A
/// rebuilt face (`moved` > 0) slides onto the others and never the others
/// onto it; of two faces not rebuilt the earlier slides; two rebuilt faces
/// keep their own nodes. A node inside its face ([`Inside`]: a seam's) neither
/// slides nor is slid onto. `pos`: each node's point on its face's surface
/// ([`super::outlines::positions`]), returned as it is after the slides.
pub(super) fn slide_nodes(
    faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>],
    mut pos: PerNode<DVec3>,
    inside: &Inside,
    bodies: &[u32],
    moved: &[f64],
    sew: f64,
) -> PerNode<DVec3> {
    // A face alone (a trial mesh) has no other face to slide onto.
    if sew <= 0.0 || faces.iter().flatten().nth(1).is_none() {
        return pos;
    }
    let body = |f: usize| crate::model::body_of(bodies, f);
    let is_moved = |f: usize| moved.get(f).is_some_and(|&m| m > 0.0);
    // Nodes hashed on a grid about one loop segment long: a cube as long as
    // the longest segment held most of a model's nodes, and every node
    // looked at all of them.
    let (total, count) = pos
        .iter()
        .flatten()
        .flat_map(|p| (0..p.len()).map(move |i| p[i].distance(p[(i + 1) % p.len()])))
        .fold((0.0, 0usize), |(t, c), l| (t + l, c + 1));
    let mean = total / count.max(1) as f64;
    if !(mean > 0.0 && mean.is_finite()) {
        return pos;
    }
    let mut grid = CellGrid::new(1.0 / mean);
    for (fi, f) in pos.iter().enumerate() {
        for (k, p) in f.iter().enumerate() {
            for (i, &q) in p.iter().enumerate() {
                grid.insert(q, (fi as u32, k as u32, i as u32));
            }
        }
    }
    for (fi, item) in faces.iter_mut().enumerate() {
        let Some((surface, o)) = item else { continue };
        for (k, poly) in o.loops.polys.iter_mut().enumerate() {
            let n = poly.uv.len();
            if n < 3 {
                continue;
            }
            for i in 0..n {
                let h = (i + n - 1) % n;
                let ((cb, tp, ti), (ca, ti2, tn)) = (poly.seg[h], poly.seg[i]);
                // Inner nodes of one curve only: a curve's end is a corner.
                if cb != ca || ca != poly.at[i].curve || ti != ti2 || inside.at((fi as u32, k as u32, i as u32)) {
                    continue;
                }
                let Some(c) = o.loops.curves.get(ca as usize) else { continue };
                let here = pos[fi][k][i];
                let shorter = here.distance(pos[fi][k][h]).min(here.distance(pos[fi][k][(i + 1) % n]));
                let reach = SNAP_SHARE * shorter;
                // A node on its neighbour (a pole's) has nowhere to slide:
                // that neighbour stays within sewing distance of it.
                if reach.is_nan() || reach <= 0.0 {
                    continue;
                }
                let r = DVec3::splat(reach);
                let Some((_, q)) = grid
                    .in_box(here - r, here + r)
                    .filter(|m| {
                        let g = m.0 as usize;
                        g != fi && body(g) == body(fi) && !is_moved(g) && (g > fi || is_moved(fi)) && !inside.at(**m)
                    })
                    .map(|m| {
                        let q = pos[m.0 as usize][m.1 as usize][m.2 as usize];
                        (q.distance(here), q)
                    })
                    .filter(|(d, _)| *d <= reach)
                    .min_by(|x, y| x.0.total_cmp(&y.0))
                else {
                    continue;
                };
                // The point of the curve between its neighbours nearest q.
                let on = |s: f64| surface.point(c.point(tp + (tn - tp) * s).truncate());
                let s0 = if tn != tp { (ti - tp) / (tn - tp) } else { 0.5 };
                let (s, d) = super::nearest_fraction(&|s: f64| on(s).distance(q), s0);
                let p = on(s);
                let after = p.distance(pos[fi][k][h]).min(p.distance(pos[fi][k][(i + 1) % n]));
                if !(d <= sew && after >= (1.0 - SNAP_SHARE) * shorter) {
                    continue;
                }
                // A node of this face's other side within sewing distance
                // of q (a strip narrower than that) would be sewn to it too.
                let w = DVec3::splat(sew);
                if grid.in_box(q - w, q + w).any(|m| {
                    m.0 as usize == fi
                        && (m.1 as usize, m.2 as usize) != (k, i)
                        && pos[fi][m.1 as usize][m.2 as usize].distance(q) <= sew
                }) {
                    continue;
                }
                let t = tp + (tn - tp) * s;
                poly.uv[i] = c.point(t).truncate();
                poly.at[i].t = t;
                poly.seg[h].2 = t;
                poly.seg[i].1 = t;
                pos[fi][k][i] = p;
                // Found where it is now by the nodes after it (its entry at
                // the old place no longer passes their distance tests).
                grid.insert(p, (fi as u32, k as u32, i as u32));
            }
        }
    }
    pos
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::{NurbsCurve, NurbsSurface};
    use crate::tessellate::sew::outlines::unify;
    use crate::tessellate::trim::Polyline;
    use crate::tessellate::trim::{CurveRef, Loops};
    use alloc::vec::Vec;

    /// A line in (u,v) from `p` to `q`, parameter 0 to 1.
    fn line(p: (f64, f64), q: (f64, f64)) -> NurbsCurve {
        let pts = alloc::vec![DVec3::new(p.0, p.1, 0.0), DVec3::new(q.0, q.1, 0.0)];
        NurbsCurve::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0], pts, None).unwrap()
    }

    /// The outline of a loop of `curves`, with nodes at the parameters `ts` of each.
    fn outline<'a>(curves: &'a [NurbsCurve], ts: &[&[f64]]) -> Outline<'a> {
        let mut poly = Polyline::default();
        for (c, list) in ts.iter().enumerate() {
            for (i, &t) in list.iter().enumerate() {
                poly.uv.push(curves[c].point(t).truncate());
                poly.at.push(CurveRef { curve: c as u32, t });
                poly.seg.push((c as u32, t, list.get(i + 1).copied().unwrap_or(1.0)));
            }
        }
        let gids = alloc::vec![alloc::vec![u32::MAX; poly.uv.len()]];
        let loops = Loops { polys: alloc::vec![poly], curves: curves.iter().collect(), mended: None };
        Outline { loops, pu: alloc::vec![0.0, 2.0], pv: alloc::vec![0.0, 1.0], gids, crossed: false }
    }

    /// Nodes of `o` on the line u = 1 (the shared border), by v.
    fn on_shared(o: &Outline<'_>) -> Vec<(f64, u32)> {
        let p = &o.loops.polys[0];
        let mut v: Vec<(f64, u32)> =
            p.uv.iter().zip(&o.gids[0]).filter(|(q, _)| (q.x - 1.0).abs() < 1e-12).map(|(q, &g)| (q.y, g)).collect();
        crate::sort::by_f64(&mut v, |x| x.0);
        v
    }

    /// Two faces whose border nodes along the border they share sit 0.05
    /// apart: a rebuilt face (paper 001) slides its nodes onto the other's,
    /// whichever comes first; of two faces not rebuilt the first slides. The
    /// shared border keeps five nodes, where sewing alone gave it eight.
    #[test]
    fn shared_border_nodes_slide_onto_one_faces() {
        let pts = [[DVec3::ZERO, DVec3::Y], [DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 0.0)]];
        let pts: Vec<Vec<DVec3>> = pts.iter().map(|r| r.to_vec()).collect();
        let plane =
            NurbsSurface::try_new([1, 1], alloc::vec![0.0, 0.0, 2.0, 2.0], alloc::vec![0.0, 0.0, 1.0, 1.0], &pts, None)
                .unwrap();
        let a_curves = [
            line((0.0, 0.0), (1.0, 0.0)),
            line((1.0, 0.0), (1.0, 1.0)),
            line((1.0, 1.0), (0.0, 1.0)),
            line((0.0, 1.0), (0.0, 0.0)),
        ];
        let b_curves = [
            line((1.0, 0.0), (2.0, 0.0)),
            line((2.0, 0.0), (2.0, 1.0)),
            line((2.0, 1.0), (1.0, 1.0)),
            line((1.0, 1.0), (1.0, 0.0)),
        ];
        let b_nodes: &[&[f64]] = &[&[0.0], &[0.0], &[0.0], &[0.0, 0.2, 0.45, 0.8]];
        let (a_ys, b_ys) = ([0.0, 0.25, 0.5, 0.75, 1.0], [0.0, 0.2, 0.55, 0.8, 1.0]);
        // (A first, A rebuilt, the border A's)
        for (a_first, rebuilt, keeps_a) in [(false, true, false), (true, false, false), (false, false, true)] {
            let mut a = outline(&a_curves, &[&[0.0], &[0.0, 0.25, 0.5, 0.75], &[0.0], &[0.0]]);
            let mut b = outline(&b_curves, b_nodes);
            let moved = if rebuilt { 1e-3 } else { 0.0 };
            let (sa, sb) = {
                let fa = Some((&plane as &dyn Surface, &mut a));
                let fb = Some((&plane as &dyn Surface, &mut b));
                let (mut faces, moved) =
                    if a_first { (alloc::vec![fa, fb], [moved, 0.0]) } else { (alloc::vec![fb, fa], [0.0, moved]) };
                unify(&mut faces, &[], &moved, 0.01, 1e-6, 0.02);
                drop(faces);
                (on_shared(&a), on_shared(&b))
            };
            let want = if keeps_a { a_ys } else { b_ys };
            assert_eq!(sa.len(), 5, "{sa:?}");
            for (((va, ga), (vb, gb)), w) in sa.iter().zip(&sb).zip(want) {
                assert!((va - w).abs() < 1e-9 && (vb - w).abs() < 1e-9, "{sa:?} {sb:?}");
                assert!(ga == gb && *ga != u32::MAX, "{sa:?} {sb:?}");
            }
        }
    }
}
