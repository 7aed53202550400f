//! Wavefront OBJ: writer and reader.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt::Write;
use core::ops::Range;

use super::meshfile::check_point;
use super::stl::f32s;
use crate::{Error, Mesh};

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

/// Reads the vertices (`v x y z`, extra values such as w or colour ignored)
/// and faces (`f a b c ...`, forms `v`, `v/vt`, `v//vn`, `v/vt/vn`,
/// negative indices counting back from the last vertex) of an OBJ file.
/// Polygons become fans; other statements are ignored.
///
/// # Errors
/// [`Error::MeshFile`] naming the line: a bad number, an index out of
/// range, a face with fewer than three vertices.
pub(super) fn read_obj(bytes: &[u8]) -> Result<Mesh, Error> {
    let at = |line: usize, message: String| Error::MeshFile { location: format!("OBJ line {line}"), message };
    let mut positions: Vec<glam::DVec3> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    for (n, raw) in bytes.split(|&c| c == b'\n').enumerate() {
        let line = n + 1;
        let text = core::str::from_utf8(raw).map_err(|_| at(line, "not UTF-8 text".into()))?;
        let text = text.split('#').next().unwrap_or("");
        let mut words = text.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let mut xyz = [0.0; 3];
                for x in &mut xyz {
                    let w = words.next().ok_or_else(|| at(line, "'v' needs three coordinates".into()))?;
                    *x = w.parse::<f64>().map_err(|_| at(line, format!("'{w}' is not a number")))?;
                }
                positions.push(check_point(xyz).map_err(|m| at(line, m.to_string()))?);
                if positions.len() > u32::MAX as usize {
                    return Err(at(line, "more than 2^32 vertices".into()));
                }
            }
            Some("f") => {
                corners.clear();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| at(line, format!("'{w}' is not a vertex index")))?;
                    let count = positions.len() as i64;
                    let index = if i > 0 { i - 1 } else { count + i };
                    if i == 0 || index < 0 || index >= count {
                        return Err(at(line, format!("vertex index {i} is out of range (1 to {count} so far)")));
                    }
                    corners.push(index as u32);
                }
                if corners.len() < 3 {
                    return Err(at(line, format!("face has {} vertices, needs at least 3", corners.len())));
                }
                for k in 1..corners.len() - 1 {
                    indices.extend_from_slice(&[corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(Mesh { positions, normals: Vec::new(), indices, face_ranges: Vec::new() })
}
