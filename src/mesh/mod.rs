//! Triangle meshes and what is measured on them.
//!
//! Numbers ([`crate::numeric`]): welding and the edge census use the weld
//! distance they are given; angles are floats; no exact predicates.

mod metrics;
mod weld;

use alloc::vec::Vec;
use glam::DVec3;
use serde::Serialize;

pub use metrics::{
    angle_stats, edge_counts, edge_counts_around_skipped, edge_counts_in_bodies, AngleStats, EdgeCounts,
};
pub(crate) use metrics::{edge_census, holes_warning, min_angle, weld_scaled};
pub use weld::{weld_mesh, weld_positions};

/// An indexed triangle mesh. Every face owns its vertices (so normals can break
/// at face borders); watertightness is judged after welding coincident vertices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, model units.
    pub positions: Vec<DVec3>,
    /// Unit surface normals at the vertices (the exact surface's, not the facets').
    pub normals: Vec<DVec3>,
    /// Three vertex indices per triangle, counter-clockwise seen from the normal side.
    pub indices: Vec<u32>,
    /// Per face of the model, the triangles it produced.
    pub face_ranges: Vec<FaceRange>,
}

/// Triangles `first .. first + count` (in triangle units) belong to one face.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct FaceRange {
    /// First triangle.
    pub first: u32,
    /// Number of triangles.
    pub count: u32,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Triangle `t` as three positions.
    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [self.positions[i[0] as usize], self.positions[i[1] as usize], self.positions[i[2] as usize]]
    }
}
