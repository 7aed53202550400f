//! Binary STL writer.

use alloc::vec::Vec;
use glam::DVec3;

use crate::Mesh;

/// Header text; it must not start with `solid`, which marks ASCII STL.
const HEADER: &[u8] = b"binary STL written by surfmesh";

/// Encodes the mesh as binary STL: an 80-byte header, the triangle count, then
/// per triangle its facet normal (from the vertices, counter-clockwise), its
/// three vertices as `f32` and a zero attribute word. Triangles whose indices
/// point past the vertex list are left out.
pub fn write_stl(mesh: &Mesh) -> Vec<u8> {
    let triangles: Vec<[DVec3; 3]> = (0..mesh.triangle_count()).filter_map(|t| triangle(mesh, t)).collect();
    let count = triangles.len().min(u32::MAX as usize);
    let mut out = Vec::with_capacity(84 + 50 * count);
    out.extend_from_slice(HEADER);
    out.resize(80, b' ');
    out.extend_from_slice(&(count as u32).to_le_bytes());
    for [a, b, c] in triangles.into_iter().take(count) {
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for v in [normal, a, b, c] {
            for x in f32s(v) {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// Triangle `t` of the mesh, or `None` when one of its indices is out of range.
pub(super) fn triangle(mesh: &Mesh, t: usize) -> Option<[DVec3; 3]> {
    let i = mesh.indices.get(3 * t..3 * t + 3)?;
    let p = |k: usize| mesh.positions.get(i[k] as usize).copied();
    Some([p(0)?, p(1)?, p(2)?])
}

/// A vector as `f32` coordinates; coordinates that are not finite (which no
/// valid mesh has) become 0 so that every written file stays readable.
pub(super) fn f32s(v: DVec3) -> [f32; 3] {
    v.to_array().map(|x| {
        let x = x as f32;
        if x.is_finite() {
            x
        } else {
            0.0
        }
    })
}
