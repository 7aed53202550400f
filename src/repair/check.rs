//! Checks of a repaired mesh that tests, the report and users share: the
//! edge census (free, non-manifold, misoriented edges), the enclosed volume
//! and an exact search for self-intersections.

use alloc::vec::Vec;
use glam::DVec3;

use core::cmp::Ordering;

use super::broad::bvh_pairs;
use super::topology::{edge, key};
use super::tritri::{contact, Contact, Tri};
use crate::nurbs::Aabb;
use crate::predicates::orient3d;
use crate::{Error, Mesh};

/// Edge census of a triangle list (by vertex index, no welding).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct EdgeCensus {
    /// Edges used by one triangle.
    pub free_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges used by two triangles running it the same way.
    pub misoriented_edges: usize,
}

pub(crate) fn census(tris: &[[u32; 3]]) -> EdgeCensus {
    let mut uses: crate::collections::HashMap<(u32, u32), (u32, u32)> =
        crate::collections::HashMap::with_capacity_and_hasher(tris.len() * 3 / 2, Default::default());
    for t in tris {
        for k in 0..3 {
            let (a, b) = edge(t, k);
            let e = uses.entry(key(a, b)).or_insert((0, 0));
            if a < b {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
        }
    }
    let mut c = EdgeCensus::default();
    for &(f, r) in uses.values() {
        match f + r {
            1 => c.free_edges += 1,
            2 if f != 1 => c.misoriented_edges += 1,
            2 => {}
            _ => c.nonmanifold_edges += 1,
        }
    }
    c
}

/// The triangles of a mesh as index triples.
///
/// # Errors
/// [`Error::Repair`] when the index count is not a multiple of 3 or an index is out of range.
pub(crate) fn triangles(mesh: &Mesh) -> Result<Vec<[u32; 3]>, Error> {
    if mesh.indices.len() % 3 != 0 {
        return Err(Error::Repair {
            location: alloc::format!("index list ({} indices)", mesh.indices.len()),
            message: "not a multiple of 3".into(),
        });
    }
    let n = mesh.positions.len();
    mesh.indices
        .chunks_exact(3)
        .enumerate()
        .map(|(t, c)| {
            if let Some(&bad) = c.iter().find(|&&i| i as usize >= n) {
                return Err(Error::Repair {
                    location: alloc::format!("triangle {t}"),
                    message: alloc::format!("vertex index {bad} is out of range ({n} vertices)"),
                });
            }
            Ok([c[0], c[1], c[2]])
        })
        .collect()
}

/// Edge census of a mesh's triangles, by index (weld first when vertices are duplicated).
///
/// # Errors
/// As [`crate::repair_mesh`] for malformed index lists.
pub fn mesh_edge_census(mesh: &Mesh) -> Result<EdgeCensus, Error> {
    Ok(census(&triangles(mesh)?))
}

/// Volume enclosed by a closed mesh (divergence theorem); positive when its
/// triangles face outward.
///
/// # Errors
/// As [`crate::repair_mesh`] for malformed index lists.
pub fn mesh_volume(mesh: &Mesh) -> Result<f64, Error> {
    let tris = triangles(mesh)?;
    Ok(super::topology::signed_volume(&mesh.positions, tris.into_iter()))
}

/// Every pair of triangles that meet other than along a shared vertex or
/// edge: crossing, touching or overlapping, decided with exact predicates
/// (a BVH finds the candidate pairs). Pairs are `(lower, higher)` triangle
/// indices, sorted.
///
/// # Errors
/// As [`crate::repair_mesh`] for malformed index lists.
pub fn find_self_intersections(mesh: &Mesh) -> Result<Vec<[u32; 2]>, Error> {
    let tris = triangles(mesh)?;
    Ok(self_intersections(&mesh.positions, &tris))
}

pub(crate) fn self_intersections(positions: &[DVec3], tris: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(t.map(|i| positions[i as usize]))).collect();
    let tri = |t: u32| {
        let v = tris[t as usize];
        Tri { id: t, v, p: v.map(|i| positions[i as usize]) }
    };
    let mut out = Vec::new();
    bvh_pairs(&boxes, |a, b| {
        let (ta, tb) = (tri(a), tri(b));
        match contact(&ta, &tb) {
            Contact::None => {}
            // The contact test is conservative (a vertex exactly on the
            // other's plane is flagged wherever it lies): keep such pairs only
            // when the closed triangles really meet.
            Contact::Degenerate if apart(&ta, &tb) => {}
            _ => out.push([a, b]),
        }
    });
    out.sort_unstable();
    out
}

/// Whether two triangles with no vertex in common, neither lying in the
/// other's plane, are certainly apart: no edge of either meets the other
/// closed triangle (exact signs). False when unsure (shared vertices, coplanar edges).
fn apart(a: &Tri, b: &Tri) -> bool {
    if a.v.iter().any(|v| b.v.contains(v)) {
        return false;
    }
    let edge_meets = |p: DVec3, q: DVec3, t: &[DVec3; 3]| -> Option<bool> {
        let (sp, sq) = (orient3d(t[0], t[1], t[2], p), orient3d(t[0], t[1], t[2], q));
        if sp == Ordering::Equal && sq == Ordering::Equal {
            return None;
        }
        if sp != Ordering::Equal && sp == sq {
            return Some(false);
        }
        // pq reaches the plane inside the closed triangle exactly when it
        // passes no edge of it on the outside.
        let s = [orient3d(p, q, t[0], t[1]), orient3d(p, q, t[1], t[2]), orient3d(p, q, t[2], t[0])];
        Some(s.iter().all(|&x| x != Ordering::Less) || s.iter().all(|&x| x != Ordering::Greater))
    };
    for (x, y) in [(a, b), (b, a)] {
        for k in 0..3 {
            match edge_meets(x.p[k], x.p[(k + 1) % 3], &y.p) {
                Some(false) => {}
                _ => return false,
            }
        }
    }
    true
}
