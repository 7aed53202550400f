//! The fitted surface as JSON, for other programs and the page:
//!
//! ```json
//! {
//!   "format": "surfmesh-fit",
//!   "degree": 4,
//!   "points":  [[x, y, z], …],            // net vertices (input points, duplicates merged)
//!   "normals": [[x, y, z], …],            // their tangent-plane normals
//!   "polygons": [
//!     { "corners": [i, j, k, …],          // counter-clockwise about the normals
//!       "patches": [[[x, y, z] × 15], …]  // one quartic triangle per side
//!     }, …
//!   ],
//!   "edges": [ { "ends": [a, b], "cubic": [[x, y, z] × 4] }, … ]   // the curve net, a < b
//! }
//! ```
//!
//! Patch `i` of a polygon has corners `corners[i]`, `corners[i+1]` and the
//! polygon's centre; its 15 control points run row by row from the net edge:
//! `b(j, k)` for `k = 0..4`, `j = 0..4−k`, weighted by
//! `4!/(i! j! k!) λ0^i λ1^j λ2^k` with `i = 4 − j − k`.

use alloc::string::String;
use alloc::vec::Vec;
use serde::Serialize;

use super::FitSurface;

#[derive(Serialize)]
struct Doc<'a> {
    format: &'a str,
    degree: usize,
    points: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    polygons: Vec<Polygon<'a>>,
    edges: Vec<Edge>,
}

#[derive(Serialize)]
struct Polygon<'a> {
    corners: &'a [u32],
    patches: Vec<Vec<[f64; 3]>>,
}

#[derive(Serialize)]
struct Edge {
    ends: [u32; 2],
    cubic: [[f64; 3]; 4],
}

/// See the module documentation.
pub(crate) fn to_json(s: &FitSurface) -> String {
    let doc = Doc {
        format: "surfmesh-fit",
        degree: super::bezier::DEGREE,
        points: s.points.iter().map(|p| p.to_array()).collect(),
        normals: s.normals.iter().map(|p| p.to_array()).collect(),
        polygons: s
            .polygons
            .iter()
            .map(|p| Polygon {
                corners: &p.corners,
                patches: p.patches.iter().map(|t| t.points.iter().map(|q| q.to_array()).collect()).collect(),
            })
            .collect(),
        edges: s.edges().into_iter().map(|(a, b, c)| Edge { ends: [a, b], cubic: c.map(|p| p.to_array()) }).collect(),
    };
    // Serializing plain numbers and arrays cannot fail; non-finite numbers
    // (never produced: patches are checked) would become null.
    serde_json::to_string(&doc).unwrap_or_default()
}
