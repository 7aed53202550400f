//! Welding coincident vertices.

use alloc::vec::Vec;
use glam::DVec3;

/// Maps each position to a representative index so that positions closer than
/// `tol` share one (spatial hashing, cells of size `tol`). Returns `(map, count)`.
pub fn weld_positions(positions: &[DVec3], tol: f64) -> (Vec<u32>, usize) {
    let tol = if tol > 0.0 && tol.is_finite() { tol } else { 1e-12 };
    let mut cells = crate::collections::CellGrid::new(1.0 / tol);
    let mut map = Vec::with_capacity(positions.len());
    let mut reps: Vec<DVec3> = Vec::new();
    for &p in positions {
        let found = cells.near(p).copied().find(|&r| reps[r as usize].distance_squared(p) <= tol * tol);
        let id = match found {
            Some(r) => r,
            None => {
                let r = reps.len() as u32;
                reps.push(p);
                cells.insert(p, r);
                r
            }
        };
        map.push(id);
    }
    (map, reps.len())
}

/// A copy of `mesh` with vertices closer than `tol` merged (first one's
/// position kept, unused ones dropped) and normals dropped; triangles keep
/// their order, including any that welding collapsed (two equal indices).
pub fn weld_mesh(mesh: &super::Mesh, tol: f64) -> super::Mesh {
    let (map, count) = weld_positions(&mesh.positions, tol);
    let mut positions = alloc::vec![DVec3::ZERO; count];
    let mut seen = alloc::vec![false; count];
    for (i, &m) in map.iter().enumerate() {
        if !seen[m as usize] {
            seen[m as usize] = true;
            positions[m as usize] = mesh.positions[i];
        }
    }
    let indices = mesh.indices.iter().map(|&i| map.get(i as usize).copied().unwrap_or(u32::MAX)).collect();
    super::Mesh { positions, normals: Vec::new(), indices, face_ranges: mesh.face_ranges.clone() }
}
