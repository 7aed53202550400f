//! Wavefront OBJ writer.

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt::Write;
use core::ops::Range;

use super::stl::f32s;
use crate::Mesh;

/// Encodes the mesh as OBJ text: `v` lines (full `f64` precision), `vn` lines
/// (when there is one normal per vertex), then one group `g face_N` per face range holding its
/// `f` lines (1-based, `f a//a b//b c//c` with normals). Triangles whose
/// indices point past the vertex list are left out.
pub fn write_obj(mesh: &Mesh) -> Vec<u8> {
    let with_normals = mesh.normals.len() == mesh.positions.len();
    let mut s = String::with_capacity(40 * mesh.positions.len() + 30 * mesh.triangle_count());
    // Writing into a String cannot fail; the `fmt::Result`s are ignored below.
    let _ = writeln!(s, "# surfmesh: {} vertices, {} triangles", mesh.positions.len(), mesh.triangle_count());
    for p in &mesh.positions {
        // Full f64 precision: OBJ is text, and tight tolerances need it.
        let [x, y, z] = p.to_array().map(|x| if x.is_finite() { x } else { 0.0 });
        let _ = writeln!(s, "v {x} {y} {z}");
    }
    if with_normals {
        for n in &mesh.normals {
            let [x, y, z] = f32s(*n);
            let _ = writeln!(s, "vn {x} {y} {z}");
        }
    }
    let vertex_count = mesh.positions.len();
    for (face, range) in face_ranges(mesh).into_iter().enumerate() {
        let _ = writeln!(s, "g face_{face}");
        for t in range {
            let i = &mesh.indices[3 * t..3 * t + 3];
            if i.iter().any(|&k| k as usize >= vertex_count) {
                continue;
            }
            let [a, b, c] = [i[0] + 1, i[1] + 1, i[2] + 1];
            let _ =
                if with_normals { writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}") } else { writeln!(s, "f {a} {b} {c}") };
        }
    }
    s.into_bytes()
}

/// Triangle ranges of the faces, clamped to the triangles the mesh has; a
/// mesh without face ranges is one face.
pub(super) fn face_ranges(mesh: &Mesh) -> Vec<Range<usize>> {
    let n = mesh.triangle_count();
    if mesh.face_ranges.is_empty() {
        return alloc::vec![0..n];
    }
    mesh.face_ranges
        .iter()
        .map(|r| {
            let first = (r.first as usize).min(n);
            first..first.saturating_add(r.count as usize).min(n)
        })
        .collect()
}
