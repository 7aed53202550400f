//! Coincident triangles that face opposite ways: two triangles of one body
//! on the same three welded points, one running them each way. They bound
//! no volume (a fold of a face onto itself, or two faces narrower than the
//! sewing distance sewn onto the same nodes), and every edge they share
//! with the rest of the body counts them twice: dropped together, they leave
//! those edges as they would be without the fold.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use glam::DVec3;

use super::sew::FaceWork;
use crate::collections::HashMap;
use crate::mesh::weld_positions;
use crate::model::body_of;

/// A triangle by its body and sorted welded corners, whether it runs them
/// the sorted way, its face and its index there.
type Keyed = ((u32, [u32; 3]), bool, u32, u32);

/// Drops the pairs of coincident triangles facing opposite ways (see the
/// module), points within `weld` being one point as in the edge counts, and
/// says per face (or pair of faces) how many it dropped. A pair is kept when
/// dropping it would leave one of its edges on one triangle (an open border
/// where there was none). Returns how many triangles it dropped.
pub(crate) fn drop_opposite_pairs(
    works: &mut [FaceWork<'_>],
    bodies: &[u32],
    weld: f64,
    warnings: &mut Vec<String>,
) -> usize {
    let mut first = Vec::with_capacity(works.len() + 1);
    let mut all: Vec<DVec3> = Vec::new();
    for w in works.iter() {
        first.push(all.len() as u32);
        all.extend_from_slice(&w.mesh.pos);
    }
    if all.is_empty() {
        return 0;
    }
    let (map, _) = weld_positions(&all, weld);
    // Per triangle: its body and welded corners, sorted, and which way it runs them.
    let mut keyed: Vec<Keyed> = Vec::new();
    let mut edges: HashMap<(u32, u32, u32), u32> = HashMap::default();
    for (f, w) in works.iter().enumerate() {
        let body = body_of(bodies, f);
        for (t, tri) in w.mesh.tris.iter().enumerate() {
            let v = tri.map(|x| map[(first[f] + x) as usize]);
            if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                *edges.entry((body, a.min(b), a.max(b))).or_insert(0) += 1;
            }
            // Rotated to start at its least corner: it runs them the sorted way or the other.
            let r = (0..3).min_by_key(|&k| v[k]).unwrap_or(0);
            let forward = v[(r + 1) % 3] < v[(r + 2) % 3];
            let mut sorted = v;
            sorted.sort_unstable();
            keyed.push(((body, sorted), forward, f as u32, t as u32));
        }
    }
    keyed.sort_unstable();
    let mut drop: Vec<(u32, u32)> = Vec::new();
    let mut said: Vec<((u32, u32), usize)> = Vec::new();
    for group in keyed.chunk_by(|a, b| a.0 == b.0) {
        let (back, fore): (Vec<&Keyed>, Vec<&Keyed>) = group.iter().partition(|x| !x.1);
        for (x, y) in back.iter().zip(&fore) {
            let (body, v) = x.0;
            let es = [(v[0], v[1]), (v[1], v[2]), (v[0], v[2])].map(|(a, b)| (body, a, b));
            if es.iter().any(|e| edges.get(e).copied().unwrap_or(0) == 3) {
                continue;
            }
            for e in &es {
                if let Some(n) = edges.get_mut(e) {
                    *n = n.saturating_sub(2);
                }
            }
            drop.push((x.2, x.3));
            drop.push((y.2, y.3));
            let faces = (x.2.min(y.2), x.2.max(y.2));
            match said.iter_mut().find(|s| s.0 == faces) {
                Some(s) => s.1 += 1,
                None => said.push((faces, 1)),
            }
        }
    }
    // Highest first, so that the triangle moved into a removed one's place
    // is never one still to be removed.
    drop.sort_unstable_by(|a, b| b.cmp(a));
    for &(f, t) in &drop {
        works[f as usize].mesh.remove_triangle(t as usize);
    }
    said.sort_unstable();
    for ((a, b), n) in said {
        warnings.push(if a == b {
            format!("face {a}: {n} pair(s) of triangles folded onto each other (the surface folds back) were dropped")
        } else {
            format!(
                "faces {a} and {b}: {n} pair(s) of their triangles lay on each other back to back (faces \
                 narrower than the sewing distance, sewn onto the same nodes) and were dropped"
            )
        });
    }
    drop.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellate::refine::{Criteria, WorkMesh};
    use glam::DVec2;

    /// The unit square of the plane z = 0 as two triangles, each run
    /// counterclockwise, or clockwise when `back`.
    fn square(back: bool) -> WorkMesh {
        let mut m = WorkMesh::default();
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        for (x, y) in corners {
            m.add_vertex(DVec3::new(x, y, 0.0), DVec3::Z);
        }
        let uv = |v: [u32; 3]| v.map(|k| DVec2::new(corners[k as usize].0, corners[k as usize].1));
        for mut v in [[0, 1, 2], [0, 2, 3]] {
            if back {
                v.swap(1, 2);
            }
            m.add_triangle(v, uv(v));
        }
        m
    }

    fn works<'a>(surface: &'a dyn crate::nurbs::Surface, meshes: Vec<WorkMesh>) -> Vec<FaceWork<'a>> {
        let crit = Criteria::PLANE_TEST;
        meshes.into_iter().map(|mesh| FaceWork { surface, curves: Vec::new(), mesh, crit }).collect()
    }

    /// Two faces on the same nodes back to back bound nothing and go; the
    /// same faces run the same way, or in different bodies, stay.
    #[test]
    fn back_to_back_triangles_go_in_pairs() {
        let plane = crate::nurbs::analytic::xy_plane(10.0);
        let mut w = works(&plane, alloc::vec![square(false), square(true)]);
        let mut said = Vec::new();
        assert_eq!(drop_opposite_pairs(&mut w, &[], 1e-9, &mut said), 4);
        assert!(w.iter().all(|f| f.mesh.tris.is_empty()));
        assert_eq!(said.len(), 1, "{said:?}");
        assert!(said[0].starts_with("faces 0 and 1: 2 pair(s)"), "{said:?}");

        let mut w = works(&plane, alloc::vec![square(false), square(false)]);
        assert_eq!(drop_opposite_pairs(&mut w, &[], 1e-9, &mut Vec::new()), 0);
        let mut w = works(&plane, alloc::vec![square(false), square(true)]);
        assert_eq!(drop_opposite_pairs(&mut w, &[0, 1], 1e-9, &mut Vec::new()), 0);
    }

    /// A pair whose dropping would leave an edge on one triangle stays: a
    /// square and one triangle back to back on half of it share the diagonal
    /// with the square's other half.
    #[test]
    fn a_pair_that_would_open_an_edge_stays() {
        let plane = crate::nurbs::analytic::xy_plane(10.0);
        let mut flap = square(true);
        flap.remove_triangle(1);
        let mut w = works(&plane, alloc::vec![square(false), flap]);
        assert_eq!(drop_opposite_pairs(&mut w, &[], 1e-9, &mut Vec::new()), 0);
        assert_eq!((w[0].mesh.tris.len(), w[1].mesh.tris.len()), (2, 1));
    }
}
