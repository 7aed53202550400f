//! STL: binary writer, binary and ASCII reader.

use alloc::string::{String, ToString};
use alloc::vec::Vec;
use glam::DVec3;

use super::meshfile::{check_point, MeshBuilder};
use crate::{Error, Mesh};

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

/// True when `bytes` have the size a binary STL with the triangle count in
/// its header must have (84 bytes of header and count, 50 per triangle).
pub(super) fn is_binary_stl(bytes: &[u8]) -> bool {
    match bytes.get(80..84) {
        Some(c) => {
            let count = u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64;
            bytes.len() as u64 == 84 + 50 * count
        }
        None => false,
    }
}

/// Reads binary or ASCII STL. A file whose size matches a binary STL's
/// triangle count is binary even when its header starts with `solid` (many
/// writers do that); otherwise it must be ASCII. Facet normals are ignored;
/// vertices with identical coordinates become one.
///
/// # Errors
/// [`Error::MeshFile`] naming the triangle (binary) or line (ASCII).
pub(super) fn read_stl(bytes: &[u8]) -> Result<Mesh, Error> {
    if is_binary_stl(bytes) {
        return read_binary(bytes);
    }
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    if bytes.len() - start >= 5 && bytes[start..start + 5].eq_ignore_ascii_case(b"solid") {
        return read_ascii(bytes);
    }
    let message = if bytes.is_empty() {
        "the file is empty".into()
    } else if bytes.len() < 84 {
        alloc::format!("{} bytes is too short for a binary STL and the text does not start with 'solid'", bytes.len())
    } else {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]);
        alloc::format!(
            "binary STL header says {count} triangles ({} bytes) but the file has {} bytes, and it is not ASCII STL \
             (no 'solid' at the start)",
            84 + 50 * count as u64,
            bytes.len()
        )
    };
    Err(Error::MeshFile { location: "STL".into(), message })
}

fn read_binary(bytes: &[u8]) -> Result<Mesh, Error> {
    let mut b = MeshBuilder::default();
    // `is_binary_stl` established that every record is present.
    for (t, rec) in bytes[84..].chunks_exact(50).enumerate() {
        let mut ids = [0u32; 3];
        for (k, id) in ids.iter_mut().enumerate() {
            let o = 12 + 12 * k;
            let f = |i: usize| f32::from_le_bytes([rec[o + i], rec[o + i + 1], rec[o + i + 2], rec[o + i + 3]]) as f64;
            let bad = |message: String| Error::MeshFile {
                location: alloc::format!("binary STL triangle {}", t + 1),
                message: alloc::format!("vertex {}: {message}", k + 1),
            };
            let p = check_point([f(0), f(4), f(8)]).map_err(|m| bad(m.to_string()))?;
            *id = b.vertex(p).map_err(|m| Error::MeshFile { location: "binary STL".into(), message: m.to_string() })?;
        }
        b.triangle(ids);
    }
    Ok(b.finish())
}

fn read_ascii(bytes: &[u8]) -> Result<Mesh, Error> {
    let at =
        |line: usize, message: String| Error::MeshFile { location: alloc::format!("ASCII STL line {line}"), message };
    let mut b = MeshBuilder::default();
    // Corners of the facet being read, and the line its `facet` keyword was on.
    let mut facet: Option<(usize, Vec<u32>)> = None;
    let mut ended = false;
    let mut last_line = 0;
    for (n, raw) in bytes.split(|&c| c == b'\n').enumerate() {
        let line = n + 1;
        last_line = line;
        let text = core::str::from_utf8(raw).map_err(|_| at(line, "not UTF-8 text".into()))?;
        let mut words = text.split_ascii_whitespace();
        let Some(word) = words.next() else { continue };
        match word.to_ascii_lowercase().as_str() {
            "solid" => ended = false,
            "endsolid" => ended = true,
            "facet" => {
                if facet.is_some() {
                    return Err(at(line, "'facet' before the previous facet's 'endfacet'".into()));
                }
                facet = Some((line, Vec::with_capacity(3)));
            }
            "outer" | "endloop" => {}
            "vertex" => {
                let Some((_, corners)) = facet.as_mut() else {
                    return Err(at(line, "'vertex' outside a facet".into()));
                };
                let mut xyz = [0.0; 3];
                for x in &mut xyz {
                    let w = words.next().ok_or_else(|| at(line, "'vertex' needs three coordinates".into()))?;
                    *x = w.parse::<f64>().map_err(|_| at(line, alloc::format!("'{w}' is not a number")))?;
                }
                let p = check_point(xyz).map_err(|m| at(line, m.to_string()))?;
                corners.push(b.vertex(p).map_err(|m| at(line, m.to_string()))?);
            }
            "endfacet" => {
                let Some((start, corners)) = facet.take() else {
                    return Err(at(line, "'endfacet' without 'facet'".into()));
                };
                if corners.len() < 3 {
                    return Err(at(start, alloc::format!("facet has {} vertices, needs 3", corners.len())));
                }
                // A polygon facet (not in the standard, but seen): a fan.
                for k in 1..corners.len() - 1 {
                    b.triangle([corners[0], corners[k], corners[k + 1]]);
                }
            }
            other => return Err(at(line, alloc::format!("unexpected '{other}'"))),
        }
    }
    if let Some((start, _)) = facet {
        return Err(at(start, "facet has no 'endfacet' (file truncated?)".into()));
    }
    if !ended {
        return Err(at(last_line, "no 'endsolid' (file truncated?)".into()));
    }
    Ok(b.finish())
}
