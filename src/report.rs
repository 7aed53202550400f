//! What a mesh run hands back: the mesh and the report of what was measured
//! on it, with the parts only some runs fill (the faces paper 001 rebuilt,
//! the quality mode's element figures). Both meshers, fast and quality,
//! write it; the doors serialize it.

use alloc::string::String;
use alloc::vec::Vec;
use serde::Serialize;

use crate::mesh::{angle_stats, EdgeCounts, Mesh};
use crate::reparam::ReparamFace;

/// A mesh and what was measured on it.
#[derive(Debug, Clone, Default)]
pub struct MeshResult {
    /// The triangles.
    pub mesh: Mesh,
    /// Measured deviation, angles, edge census, warnings.
    pub report: Report,
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
    pub warnings: Vec<crate::Warning>,
    /// Faces the parameterization test flagged (paper 001), rebuilt or not.
    pub reparameterized: Vec<ReparamFace>,
    /// Quality mode only: element size and how near the mesh comes to it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality: Option<QualityReport>,
}

impl Report {
    /// Takes the edge census and the triangles' angles of the finished mesh.
    pub(crate) fn take_edges_and_angles(&mut self, edges: &EdgeCounts, mesh: &Mesh) {
        self.free_edges = edges.free_edges;
        self.boundary_edges = edges.boundary_edges;
        self.nonmanifold_edges = edges.nonmanifold_edges;
        let angles = angle_stats(mesh);
        self.min_angle_deg = angles.min_deg;
        self.p1_angle_deg = angles.p1_deg;
    }
}

/// Triangles whose smallest angle reaches this count as good, degrees.
pub const GOOD_ANGLE_DEG: f64 = 25.0;
/// Edges within this band of H (model space) count as well sized.
pub const EDGE_BAND: [f64; 2] = [0.7, 1.4];

/// What the quality mesher measured, beyond the usual report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct QualityReport {
    /// Element size H used, model units.
    pub size: f64,
    /// Faces filled by the looping method.
    pub faces_looping: usize,
    /// Faces filled by Delaunay refinement.
    pub faces_delaunay: usize,
    /// Fraction of triangles whose smallest angle is at least 25°.
    pub good_angle_fraction: f64,
    /// Fraction of edges (each counted once after welding) between 0.7 H and 1.4 H long.
    pub edge_band_fraction: f64,
    /// Shortest, mean and longest edge over H.
    pub edge_ratio_min: f64,
    /// Mean edge length over H.
    pub edge_ratio_mean: f64,
    /// Longest edge over H.
    pub edge_ratio_max: f64,
}
