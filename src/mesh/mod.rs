//! Triangle meshes and what is measured on them.

mod metrics;
mod weld;

use alloc::string::String;
use alloc::vec::Vec;
use glam::DVec3;
use serde::Serialize;

pub use metrics::{
    angle_stats, edge_counts, edge_counts_around_skipped, edge_counts_in_bodies, AngleStats, EdgeCounts,
};
pub(crate) use metrics::{edge_census, holes_warning, min_angle};
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

/// What a mesh run measured; serialized as the CLI's JSON report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Report {
    /// Length unit of the mesh and of every length here (the file's own
    /// unit, or the one asked for: see [`crate::mesh_model_in_units`]).
    pub units: String,
    /// Absolute chordal tolerance used, model units.
    pub tolerance: f64,
    /// Angle limit used, radians.
    pub angle: f64,
    /// Faces in the model.
    pub faces: usize,
    /// Faces of the file the reader could not build (skipped with a
    /// warning), not in `faces`: the file has `faces + faces_unread`. The
    /// edges their neighbours leave open along them count in `free_edges`.
    pub faces_unread: usize,
    /// Faces that produced no triangles (skipped with a warning).
    pub faces_skipped: usize,
    /// Faces the file gives as triangles only (STEP tessellated faces): no
    /// exact surface, so their triangles are passed through as they are and
    /// the deviation figures do not cover them.
    pub faces_tessellated: usize,
    /// Bodies in the model: sets of faces that share no border with each
    /// other (solids, sheets, assembly parts); the `share` option splits by them.
    pub bodies: usize,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Vertices in the mesh (per-face copies counted).
    pub vertices: usize,
    /// Largest measured distance from the mesh to the exact surface (over
    /// the faces that have one: not the tessellated faces).
    pub max_deviation: f64,
    /// Mean of the measured distances over all samples.
    pub mean_deviation: f64,
    /// Smallest triangle angle, degrees.
    pub min_angle_deg: f64,
    /// 1st-percentile triangle angle, degrees.
    pub p1_angle_deg: f64,
    /// Cracks: free edges after welding that are not on the model's open
    /// boundary, among them those along faces the reader skipped.
    pub free_edges: usize,
    /// All edges with one triangle after welding (cracks plus open boundary).
    pub boundary_edges: usize,
    /// Edges with more than two triangles after welding.
    pub nonmanifold_edges: usize,
    /// Triangles whose facet normal opposes the surface normal.
    pub inverted_triangles: usize,
    /// Largest normal turn across one triangle, radians.
    pub max_normal_turn: f64,
    /// Core meshing time in milliseconds (filled by the caller: the core has no clock).
    pub time_ms: f64,
    /// Parse time in milliseconds (filled by the caller).
    pub parse_ms: f64,
    /// Skipped entities, repaired surfaces, incomplete refinement.
    pub warnings: Vec<String>,
    /// Faces the parameterization test flagged (paper 001), rebuilt or not.
    pub reparameterized: Vec<crate::reparam::ReparamFace>,
    /// Quality mode only: element size and how near the mesh comes to it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality: Option<crate::quality::QualityReport>,
}
