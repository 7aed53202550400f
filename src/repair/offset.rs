//! Vertex-normal offset of a triangle mesh: the paper's kind of input (an
//! offset of a closed mesh, with degenerate and self-intersecting triangles
//! wherever the distance exceeds the local radius of curvature).

use alloc::vec::Vec;
use glam::DVec3;

use super::check::{census, triangles};
use super::topology::{adjacency, components, signed_volume, NONE};
use crate::{weld_positions, Error, Mesh};

/// Moves every vertex by `distance` along its normal (the angle-weighted
/// average of the facet normals around it; positive = the side the
/// counter-clockwise triangles face, except that a closed component facing
/// inward, enclosing a negative volume, is offset as if turned outward: a
/// negative distance always goes inside a closed mesh). Coincident vertices (within 1e-9 of the
/// bounding-box diagonal, as a meshed model's faces share their borders) are
/// welded first so the offset stays closed, unless that would make an edge of
/// more than two triangles. Triangles collapsed by welding are dropped;
/// normals are not carried over.
///
/// # Errors
/// [`Error::Repair`] for a distance or coordinate that is not finite, a
/// malformed index list, or no triangles.
pub fn offset_mesh(mesh: &Mesh, distance: f64) -> Result<Mesh, Error> {
    if !distance.is_finite() {
        return Err(Error::Repair {
            location: "offset distance".into(),
            message: alloc::format!("{distance} is not a finite number"),
        });
    }
    let tris = triangles(mesh)?;
    if tris.is_empty() {
        return Err(Error::Repair { location: "mesh".into(), message: "it has no triangles to offset".into() });
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::Repair {
            location: alloc::format!("vertex {i}"),
            message: "a coordinate is not a finite number".into(),
        });
    }
    let diag = crate::nurbs::Aabb::from_points(mesh.positions.iter().copied()).diagonal();
    let (map, count) = weld_positions(&mesh.positions, (1e-9 * diag).max(f64::MIN_POSITIVE));
    let welded: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| t.map(|i| map[i as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    // Distinct vertices that touch (a pinch a repair left) stay apart: welding
    // them would join two sheets at one edge.
    let (positions, tris) = if census(&welded).nonmanifold_edges > census(&tris).nonmanifold_edges {
        (mesh.positions.clone(), tris)
    } else {
        let mut positions = alloc::vec![DVec3::ZERO; count];
        for (i, &m) in map.iter().enumerate() {
            positions[m as usize] = mesh.positions[i];
        }
        (positions, welded)
    };
    let count = positions.len();
    // A closed component that encloses a negative volume faces inward: its
    // normals are turned so that a negative distance still goes inside.
    let nbr = adjacency(&tris);
    let (comp, ncomp) = components(&nbr);
    let mut volume = alloc::vec![0.0; ncomp];
    let mut closed = alloc::vec![true; ncomp];
    for (t, tri) in tris.iter().enumerate() {
        let c = comp[t] as usize;
        volume[c] += signed_volume(&positions, core::iter::once(*tri));
        closed[c] &= nbr[t].iter().all(|&u| u != NONE);
    }
    let sign: Vec<f64> = volume.iter().zip(&closed).map(|(&v, &c)| if c && v < 0.0 { -1.0 } else { 1.0 }).collect();
    let mut normals = alloc::vec![DVec3::ZERO; count];
    for (ti, t) in tris.iter().enumerate() {
        let p = t.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero() * sign[comp[ti] as usize];
        for k in 0..3 {
            let angle = crate::math::angle_between(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            normals[t[k] as usize] += n * angle;
        }
    }
    let moved = positions.iter().zip(&normals).map(|(p, n)| *p + n.normalize_or_zero() * distance).collect();
    Ok(Mesh {
        positions: moved,
        normals: Vec::new(),
        indices: tris.into_iter().flatten().collect(),
        face_ranges: Vec::new(),
    })
}
