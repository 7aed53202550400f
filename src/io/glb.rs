//! Binary glTF 2.0 (`.glb`) writer.

use alloc::string::ToString;
use alloc::vec::Vec;
use serde_json::{json, Value};

use super::obj::face_ranges;
use super::stl::f32s;
use crate::Mesh;

/// `glTF` in little-endian order.
const MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk (`JSON`).
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
const CHUNK_BIN: u32 = 0x004E_4942;
/// glTF accessor component types and buffer view targets.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Encodes the mesh as a binary glTF 2.0 file: one mesh with one triangle
/// primitive per face range, sharing `f32` positions (with the min/max the
/// spec requires) and normals (when there is one per vertex), `u32` indices.
/// Triangles whose indices point past the vertex list are left out; a mesh
/// without triangles gives a valid file with an empty scene. glTF lengths
/// are metres: the positions are written as they are, taken as metres
/// ([`write_glb_scaled`] converts a mesh in another unit).
pub fn write_glb(mesh: &Mesh) -> Vec<u8> {
    write_glb_scaled(mesh, 1.0)
}

/// As [`write_glb`], the positions multiplied by `metres_per_unit` (the
/// size of the mesh's length unit in metres: 0.001 for millimetres,
/// 0.0254 for inches), so the file is in metres as glTF defines them.
pub fn write_glb_scaled(mesh: &Mesh, metres_per_unit: f64) -> Vec<u8> {
    let k = if metres_per_unit > 0.0 && metres_per_unit.is_finite() { metres_per_unit } else { 1.0 };
    let n = mesh.positions.len();
    let with_normals = mesh.normals.len() == n;
    // Index lists of the non-empty faces.
    let faces: Vec<Vec<u32>> = face_ranges(mesh)
        .into_iter()
        .map(|range| {
            let tri = &mesh.indices[3 * range.start..3 * range.end];
            tri.chunks_exact(3).filter(|t| t.iter().all(|&k| (k as usize) < n)).flatten().copied().collect()
        })
        .filter(|f: &Vec<u32>| !f.is_empty())
        .collect();
    if faces.is_empty() {
        let doc = json!({ "asset": asset(), "scene": 0, "scenes": [{}] });
        return container(&doc, &[]);
    }

    let mut bin = Vec::new();
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        let c = f32s(*p * k);
        for ((lo, hi), x) in min.iter_mut().zip(&mut max).zip(c) {
            *lo = lo.min(x);
            *hi = hi.max(x);
        }
        push_f32s(&mut bin, c);
    }
    let mut views = vec_of(json!({
        "buffer": 0, "byteOffset": 0, "byteLength": bin.len(), "target": ARRAY_BUFFER
    }));
    let mut accessors = vec_of(json!({
        "bufferView": 0, "componentType": FLOAT, "count": n, "type": "VEC3", "min": min, "max": max
    }));
    let mut attributes = json!({ "POSITION": 0 });
    if with_normals {
        let offset = bin.len();
        for v in &mesh.normals {
            push_f32s(&mut bin, f32s(*v));
        }
        attributes["NORMAL"] = json!(accessors.len());
        accessors.push(json!({
            "bufferView": views.len(), "componentType": FLOAT, "count": n, "type": "VEC3"
        }));
        views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": bin.len() - offset, "target": ARRAY_BUFFER
        }));
    }
    let index_view = views.len();
    let index_start = bin.len();
    let mut primitives = Vec::with_capacity(faces.len());
    for face in &faces {
        primitives.push(json!({ "attributes": attributes, "indices": accessors.len(), "mode": 4 }));
        accessors.push(json!({
            "bufferView": index_view,
            "byteOffset": bin.len() - index_start,
            "componentType": UNSIGNED_INT,
            "count": face.len(),
            "type": "SCALAR"
        }));
        for &i in face {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    views.push(json!({
        "buffer": 0, "byteOffset": index_start, "byteLength": bin.len() - index_start,
        "target": ELEMENT_ARRAY_BUFFER
    }));
    let doc = json!({
        "asset": asset(),
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": primitives }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": views,
        "accessors": accessors,
    });
    container(&doc, &bin)
}

fn asset() -> Value {
    json!({ "version": "2.0", "generator": "surfmesh" })
}

fn vec_of(v: Value) -> Vec<Value> {
    alloc::vec![v]
}

fn push_f32s(bin: &mut Vec<u8>, v: [f32; 3]) {
    for x in v {
        bin.extend_from_slice(&x.to_le_bytes());
    }
}

/// The GLB container: 12-byte header, the JSON chunk padded with spaces and,
/// when there is binary data, the BIN chunk padded with zeros (both to 4 bytes).
fn container(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = doc.to_string().into_bytes();
    text.resize(text.len().next_multiple_of(4), b' ');
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len().next_multiple_of(4) };
    let total = 12 + 8 + text.len() + bin_chunk;
    let mut out = Vec::with_capacity(total);
    for word in [MAGIC, 2, total as u32, text.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&text);
    if !bin.is_empty() {
        for word in [bin.len().next_multiple_of(4) as u32, CHUNK_BIN] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    out
}
