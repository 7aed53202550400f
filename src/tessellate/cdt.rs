//! Constrained Delaunay triangulation of a trimmed face's nodes (spade).
//!
//! Paper 000 §3.2 walks the trim curve through the grid and joins the kept
//! quad corners to the trim points; it notes that this breaks on sharp trim
//! curves and close loops. A CDT of the kept grid nodes plus the loop nodes,
//! with the loop segments as constraints, is the robust replacement: inside
//! the region it reproduces the grid, along the loops it fills the band.

use alloc::format;
use alloc::vec::Vec;
use glam::DVec2;
use spade::handles::{FixedFaceHandle, FixedVertexHandle};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::Error;

/// Triangulates `points` (already scaled so that Delaunay in this plane gives
/// well-shaped triangles on the surface) with `constraints` as forced edges,
/// and returns the triangles (counter-clockwise) whose crossing parity of
/// constraint edges from the hull is odd: the kept region.
pub(crate) fn triangulate_region(face: usize, points: &[DVec2], constraints: &[[usize; 2]]) -> Result<Region, Error> {
    // spade refuses non-zero coordinates nearer 0 than about 1.8e-43
    // (`TooSmall`); files do hold such values (3e-49 for 0), which are 0.
    let flush = |x: f64| if x.abs() < 1e-40 { 0.0 } else { x };
    let verts: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(flush(p.x), flush(p.y))).collect();
    // Vertices one by one in their given order, then the constraints in
    // theirs: spade's bulk loader puts the vertices it skips (those on a line
    // through its start centre, common on iso-parametric grids) back in a
    // per-process random order, and on cocircular grid cells that order picks
    // the diagonals, so the same file gave different meshes run to run.
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    for v in verts {
        cdt.insert(v).map_err(|e| Error::Mesh { face, message: format!("triangulation failed: {e:?}") })?;
    }
    if cdt.num_vertices() != points.len() {
        return Err(Error::Mesh { face, message: "trim loop nodes coincide".into() });
    }
    let mut splits = 0;
    for &[a, b] in constraints {
        if a >= points.len() || b >= points.len() || a == b {
            return Err(Error::Mesh { face, message: format!("bad trim segment {a} - {b}") });
        }
        let (a, b) = (FixedVertexHandle::from_index(a), FixedVertexHandle::from_index(b));
        if cdt.try_add_constraint(a, b).is_empty() && !cdt.exists_constraint(a, b) {
            // Loops that cross here although trimming left none crossing:
            // sewing moved the nodes of a strip narrower than its distance.
            // Both segments are split where they cross, and the parity fill
            // below keeps what the loops wind round an odd number of times.
            splits += 1;
            if splits > MAX_SPLITS || cdt.add_constraint_and_split(a, b, |p| p).is_empty() {
                return Err(Error::Mesh {
                    face,
                    message: format!("trim loops cross (segment {} - {})", a.index(), b.index()),
                });
            }
        }
    }
    // Flood fill from the hull: crossing a constraint edge flips inside/outside.
    let nfaces = cdt.num_inner_faces() + 1;
    let mut depth: Vec<u32> = alloc::vec![u32::MAX; nfaces];
    let mut queue: alloc::collections::VecDeque<(FixedFaceHandle<spade::handles::InnerTag>, u32)> =
        alloc::collections::VecDeque::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                let d = u32::from(e.is_constraint_edge());
                let idx = f.fix().index();
                if d < depth[idx] {
                    depth[idx] = d;
                    queue.push_back((f.fix(), d));
                }
            }
        }
    }
    while let Some((fh, d)) = queue.pop_front() {
        if depth[fh.index()] < d {
            continue;
        }
        let f = cdt.face(fh);
        for e in f.adjacent_edges() {
            let Some(g) = e.rev().face().as_inner() else { continue };
            let nd = d + u32::from(e.is_constraint_edge());
            let gi = g.fix().index();
            if nd < depth[gi] {
                depth[gi] = nd;
                queue.push_back((g.fix(), nd));
            }
        }
    }
    let mut out = Vec::new();
    for f in cdt.inner_faces() {
        if depth[f.fix().index()] % 2 == 1 {
            let v = f.vertices();
            out.push([v[0].fix().index() as u32, v[1].fix().index() as u32, v[2].fix().index() as u32]);
        }
    }
    let added = cdt.vertices().skip(points.len()).map(|v| DVec2::new(v.position().x, v.position().y)).collect();
    Ok(Region { tris: out, added })
}

/// Most crossing constraints split in one face: past them the loops are
/// tangled beyond a strip's sewing, and the face is skipped.
const MAX_SPLITS: usize = 64;

/// The kept triangles, and the points the triangulation added where
/// crossing constraints were split (vertex `points.len() + k`).
pub(crate) struct Region {
    pub tris: Vec<[u32; 3]>,
    pub added: Vec<DVec2>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bow tie: its two crossing sides are split at the crossing, which
    /// becomes a vertex, and both lobes (each wound round once) are kept.
    #[test]
    fn crossing_constraints_are_split_and_both_lobes_kept() {
        let pts = [DVec2::new(0.0, 0.0), DVec2::new(2.0, 2.0), DVec2::new(2.0, 0.0), DVec2::new(0.0, 2.0)];
        let r = triangulate_region(0, &pts, &[[0, 1], [1, 2], [2, 3], [3, 0]]).expect("split");
        assert_eq!(r.added.len(), 1);
        assert!(r.added[0].distance(DVec2::ONE) < 1e-12, "{:?}", r.added);
        let all: Vec<DVec2> = pts.iter().copied().chain(r.added.iter().copied()).collect();
        let area: f64 = r
            .tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| all[i as usize]);
                0.5 * (b - a).perp_dot(c - a)
            })
            .sum();
        assert!((area - 2.0).abs() < 1e-12, "two lobes of area 1: {area}");
    }
}
