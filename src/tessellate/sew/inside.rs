//! Border nodes that their own face lies all around (see [`Inside`]).

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::outlines::{NodeRef, PerNode};
use crate::collections::CellGrid;
use crate::numeric::TINY;
use crate::nurbs::Surface;
use crate::tessellate::face::Outline;

/// How much farther than two nodes lie apart the surface point between
/// their parameters must lie for them to be a seam's two sides: a strip
/// narrower than `tight` has that point between them, a closed surface
/// half way round.
const ROUND: f64 = 4.0;

/// Which outline nodes and segments lie inside their own face in space.
///
/// A segment runs along a seam when another segment of its face joins the
/// same two points (each end within `tight` of the other's) and at one end
/// the two nodes are a seam's two sides: the surface at the middle of
/// their parameters lies far from both ([`ROUND`] times their distance),
/// the way round a closed surface, not across a strip. A node lies inside
/// its face when every segment at its point (its own and those of its
/// face's nodes within `tight`, which become one node with it) runs along
/// a seam or collapses to a point (a pole's segments, as short as the
/// sewing radii leave out), and one runs along a seam: a
/// seam's inner node or a pole on it. No other face can meet the face
/// there, so no other face's node is sewn to such a node nor added to such
/// a segment: a wall thinner than the sewing distance has the seams of its
/// two sides side by side, and sewn they gave every edge along them four
/// triangles.
pub(super) struct Inside {
    /// Per node, whether its face lies all around it.
    pub node: PerNode<bool>,
    /// Per segment (node `i` to `i + 1`), whether it runs along a seam.
    pub seam: PerNode<bool>,
}

impl Inside {
    /// The nodes and segments of `faces` (their points `pos`) inside their
    /// faces; none where `tight` is no distance.
    pub fn new(faces: &[Option<(&dyn Surface, &mut Outline<'_>)>], pos: &PerNode<DVec3>, tight: f64) -> Self {
        let none = || pos.iter().map(|f| f.iter().map(|l| alloc::vec![false; l.len()]).collect()).collect();
        let mut out = Self { node: none(), seam: none() };
        if !(tight > 0.0 && tight.is_finite()) {
            return out;
        }
        for (fi, item) in faces.iter().enumerate() {
            let (Some((surface, o)), Some(p)) = (item, pos.get(fi)) else { continue };
            let uv: Vec<&[DVec2]> = o.loops.polys.iter().map(|l| l.uv.as_slice()).collect();
            if uv.len() != p.len() || uv.iter().zip(p).any(|(a, b)| a.len() != b.len()) {
                continue;
            }
            let (node, seam) = face_inside(*surface, &uv, p, tight);
            out.node[fi] = node;
            out.seam[fi] = seam;
        }
        out
    }

    /// Whether node `n` lies inside its face.
    pub fn at(&self, n: NodeRef) -> bool {
        flag(&self.node, n)
    }

    /// Whether segment `n` (node `n` to the next) runs along a seam.
    pub fn along(&self, n: NodeRef) -> bool {
        flag(&self.seam, n)
    }
}

/// Node `n`'s entry of a per-node table; `false` for a node it lacks.
fn flag(table: &PerNode<bool>, n: NodeRef) -> bool {
    table.get(n.0 as usize).and_then(|f| f.get(n.1 as usize)).and_then(|l| l.get(n.2 as usize)) == Some(&true)
}

/// [`Inside`] for one face: its loops' parameters `uv` and points `p`.
fn face_inside(
    surface: &dyn Surface,
    uv: &[&[DVec2]],
    p: &[Vec<DVec3>],
    tight: f64,
) -> (Vec<Vec<bool>>, Vec<Vec<bool>>) {
    let mut grid: CellGrid<(u32, u32)> = CellGrid::new(1.0 / tight);
    for (k, l) in p.iter().enumerate() {
        for (i, &q) in l.iter().enumerate() {
            grid.insert(q, (k as u32, i as u32));
        }
    }
    let at = |n: (u32, u32)| p[n.0 as usize][n.1 as usize];
    // A segment whose ends are one point (a pole's, as the sewing radii
    // take it): a small circle narrower than `tight` is still a border.
    let scale = p.iter().flatten().fold(0.0f64, |m, q| m.max(q.abs().max_element())).max(TINY);
    let point = (1e-12 * scale).max(1e-3 * tight);
    let next = |n: (u32, u32)| (n.0, ((n.1 as usize + 1) % p[n.0 as usize].len()) as u32);
    let prev = |n: (u32, u32)| {
        let m = p[n.0 as usize].len();
        (n.0, ((n.1 as usize + m - 1) % m) as u32)
    };
    // The face's other nodes within `tight` of node `n`.
    let close = |n: (u32, u32)| {
        let q = at(n);
        grid.near(q).copied().filter(move |&m| m != n && at(m).distance(q) <= tight)
    };
    // Whether nodes `a` and `b` (within `tight`) are a seam's two sides.
    let sides = |a: (u32, u32), b: (u32, u32)| {
        let mid = surface.point(0.5 * (uv[a.0 as usize][a.1 as usize] + uv[b.0 as usize][b.1 as usize]));
        mid.distance(at(a)) > ROUND * at(a).distance(at(b)) + 1e-9 * at(a).abs().max_element()
    };
    let seam: Vec<Vec<bool>> = p
        .iter()
        .enumerate()
        .map(|(k, l)| {
            (0..l.len())
                .map(|i| {
                    let (a, b) = ((k as u32, i as u32), next((k as u32, i as u32)));
                    if at(a).distance(at(b)) <= point {
                        return false;
                    }
                    // Another segment from a node at `a` to one at `b`, either way round.
                    close(a).any(|c| {
                        [next(c), prev(c)].into_iter().any(|d| {
                            d != c
                                && (c, d) != (a, b)
                                && at(d).distance(at(b)) <= tight
                                && (sides(a, c) || (d != b && sides(b, d)))
                        })
                    })
                })
                .collect()
        })
        .collect();
    let node = p
        .iter()
        .enumerate()
        .map(|(k, l)| {
            (0..l.len())
                .map(|i| {
                    let n = (k as u32, i as u32);
                    let mut any = false;
                    let all = core::iter::once(n).chain(close(n)).all(|m| {
                        [prev(m), m].into_iter().all(|s| {
                            let along = seam[s.0 as usize][s.1 as usize];
                            any |= along;
                            along || at(s).distance(at(next(s))) <= point
                        })
                    });
                    all && any
                })
                .collect()
        })
        .collect();
    (node, seam)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::{analytic, NurbsSurface};
    use crate::tessellate::params::Limits;
    use alloc::vec;
    use core::f64::consts::FRAC_PI_2;

    /// The surface `profile` (a curve in the xz plane) sweeps about the z axis, a whole turn.
    fn revolved(profile: &crate::NurbsCurve) -> NurbsSurface {
        analytic::revolve(profile, DVec3::ZERO, DVec3::Z, 0.0, core::f64::consts::TAU).expect("surface")
    }

    /// Inside flags of an untrimmed surface's outline, with each node's point.
    fn flags(surface: &NurbsSurface, tol: f64, tight: f64) -> Vec<(DVec3, bool)> {
        let lim = Limits { tol, angle: 0.5, max_edge: f64::INFINITY, min_edge: 0.0 };
        let border = [crate::tessellate::face::domain_loop(surface).expect("domain")];
        let mut o =
            crate::tessellate::face::outline(0, (surface, &Default::default()), &border, true, &lim, usize::MAX)
                .expect("outline");
        let faces = vec![Some((surface as &dyn Surface, &mut o))];
        let pos = super::super::outlines::positions(&faces);
        let inside = Inside::new(&faces, &pos, tight);
        pos[0].iter().flatten().copied().zip(inside.node[0].iter().flatten().copied()).collect()
    }

    /// A dome's seam runs from its rim to its pole: the seam's inner nodes
    /// and the pole lie inside the dome, the rim's nodes (the seam's end
    /// among them) do not.
    #[test]
    fn a_domes_seam_and_pole_lie_inside_it_and_its_rim_does_not() {
        let quarter = analytic::circle_arc(DVec3::ZERO, DVec3::X, DVec3::Z, 10.0, 0.0, FRAC_PI_2).expect("arc");
        let dome = revolved(&quarter);
        let nodes = flags(&dome, 0.05, 1e-3);
        let (mut seam, mut rim) = (0, 0);
        for (p, inside) in nodes {
            if p.z.abs() < 1e-9 {
                assert!(!inside, "rim node {p} inside");
                rim += 1;
            } else {
                assert!(inside, "seam node {p} not inside");
                seam += 1;
            }
        }
        assert!(seam > 4 && rim > 8, "{seam} seam, {rim} rim nodes");
    }

    /// A tube narrower than `tight` keeps its end circles as borders: their
    /// segments are shorter than `tight` but are no pole's.
    #[test]
    fn a_circle_narrower_than_tight_is_no_pole() {
        let side = analytic::line(DVec3::new(0.02, 0.0, 0.0), DVec3::new(0.02, 0.0, 10.0), 0.0, 1.0).expect("line");
        let tube = revolved(&side);
        let nodes = flags(&tube, 1e-3, 0.1);
        assert!(nodes.len() > 8 && nodes.iter().all(|n| !n.1), "{nodes:?}");
    }
}
