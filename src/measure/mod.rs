//! The yardstick: one measure for any triangle mesh of a model, whoever made
//! it (this crate's mesher or another program), so meshes can be compared on
//! equal terms.
//!
//! - **Deviation**: points of a barycentric grid on every triangle (corners,
//!   edge points, interior points) are projected onto the model: a BVH over
//!   samples of each face's trimmed region picks the faces a triangle can be
//!   closest to, and Newton's method ([`crate::project_to_surface`]) finds the
//!   closest point on each. The distance is to the face's *untrimmed* base
//!   surface, so a point beside a face, over the surface's continuation past
//!   the trim, measures to that continuation; every distance is that of an
//!   actual surface point, so Newton stopping early can only over-state it.
//! - **Coverage**: the largest distance from samples of the exact geometry
//!   (a grid inside each face's trim loops, by the even-odd rule over their
//!   polylines, and points on the loops) to the mesh, through a BVH over the
//!   triangles. Holes and dropped faces show up here and nowhere else.
//! - **Edges** after welding coincident vertices, a face's inner ones never
//!   with its own ([`crate::edge_counts`]; one census for every mesher's mesh),
//!   per body of the model as the mesher's own report counts them: each face
//!   range's body is found from the model faces nearest its triangles
//!   (`bodies.rs`), since another program numbers its faces its own way.
//! - **Angles** ([`crate::angle_stats`]).
//!
//! Numbers ([`crate::numeric`]): distances are floats from Newton
//! projections (their own stopping tolerance); vertices weld within a
//! thousandth of the tolerance unless given; no exact predicates.

mod bodies;
mod bvh;
mod index;
mod region;
#[cfg(test)]
mod tests;

use crate::numeric::TINY;
use alloc::vec::Vec;
use glam::DVec3;
use serde::Serialize;

use crate::mesh::{angle_stats, edge_counts_around_skipped, weld_positions, FaceRange, Mesh};
use crate::model::Model;
use crate::nurbs::{Aabb, ProjectionOptions};
use bodies::BodyVotes;
use bvh::{closest_on_triangle, Bvh};
use index::SurfaceIndex;
use region::{sample_face, spacing, FacePlan};

/// Settings for [`measure_mesh`]; the defaults suit comparing meshes made at
/// relative tolerances down to about 1e-4.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MeasureOptions {
    /// Reference tolerance, model units: how far apart unconnected borders of
    /// different faces may be to count as a crack, and how far a coverage
    /// sample may be from the mesh before it counts as uncovered.
    /// Default: 1e-3 × the diagonal of the trimmed geometry's box.
    pub tolerance: Option<f64>,
    /// Divisions per triangle edge of the barycentric sample grid (1 to 64).
    /// Default 4, as the mesher verifies: 15 points per triangle.
    pub steps: usize,
    /// About how many surface samples the closest-face search spreads over the
    /// model (at least a 5 × 5 grid per face). Default 20,000.
    pub index_samples: usize,
    /// About how many exact-geometry samples coverage is measured at (at least
    /// a 9 × 9 grid per face, plus the loops). Default 100,000.
    pub coverage_samples: usize,
    /// Vertices closer than this are welded before the edge census, model
    /// units. Default: 1e-3 × the tolerance.
    pub weld: Option<f64>,
    /// Newton settings for the closest points.
    pub projection: ProjectionOptions,
}

impl Default for MeasureOptions {
    fn default() -> Self {
        Self {
            tolerance: None,
            steps: 4,
            index_samples: 20_000,
            coverage_samples: 100_000,
            weld: None,
            projection: ProjectionOptions { max_iterations: 16, parameter_tolerance: 1e-11, search_samples: 8 },
        }
    }
}

impl MeasureOptions {
    /// Sets the reference tolerance (crack reach, coverage threshold).
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = Some(tolerance);
        self
    }

    /// Sets the divisions per triangle edge of the deviation samples.
    pub fn with_steps(mut self, steps: usize) -> Self {
        self.steps = steps;
        self
    }

    /// Sets the number of coverage samples aimed at.
    pub fn with_coverage_samples(mut self, samples: usize) -> Self {
        self.coverage_samples = samples;
        self
    }

    /// Sets the weld distance for the edge census.
    pub fn with_weld(mut self, weld: f64) -> Self {
        self.weld = Some(weld);
        self
    }
}

/// What [`measure_mesh`] found; serialized as the benchmark's JSON.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct MeshMeasure {
    /// Reference tolerance used (given, or 1e-3 × `diagonal`).
    pub tolerance: f64,
    /// Diagonal of the box of the sampled trimmed geometry.
    pub diagonal: f64,
    /// Triangles measured.
    pub triangles: usize,
    /// Vertices after welding.
    pub vertices: usize,
    /// Triangles left out: an index past the vertex list or a non-finite corner.
    pub invalid_triangles: usize,
    /// Largest distance from a triangle sample to the model.
    pub max_deviation: f64,
    /// Mean distance over all triangle samples.
    pub mean_deviation: f64,
    /// Number of triangle samples.
    pub deviation_samples: usize,
    /// Largest distance from an exact-geometry sample to the mesh (infinite,
    /// `null` in JSON, when the mesh has no triangles).
    pub coverage: f64,
    /// Number of exact-geometry samples.
    pub coverage_samples: usize,
    /// Exact-geometry samples farther than the tolerance from the mesh.
    pub uncovered_samples: usize,
    /// Edges with one triangle after welding (open boundary and cracks).
    pub boundary_edges: usize,
    /// Cracks: boundary edges along another face's border (needs face
    /// ranges; without them only the next kind counts, see
    /// `boundary_edges`), or along a face the reader skipped.
    pub free_edges: usize,
    /// Edges with more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges whose two triangles run the same way.
    pub misoriented_edges: usize,
    /// Smallest triangle angle, degrees.
    pub min_angle_deg: f64,
    /// 1st percentile of the triangles' smallest angles, degrees.
    pub p1_angle_deg: f64,
    /// Whether the mesh's face ranges were usable (cracks told apart from the open boundary).
    pub face_ranges: bool,
}

/// Measures `mesh` against the exact geometry of `model`: deviation, coverage,
/// edge census and angles (see the module documentation for how).
///
/// Any mesh is accepted: triangles with an index past the vertex list or a
/// non-finite corner are left out and counted; face ranges that do not tile
/// the triangles in order are ignored (then `free_edges` is 0 and
/// `boundary_edges` tells the story).
pub fn measure_mesh(model: &Model, mesh: &Mesh, options: &MeasureOptions) -> MeshMeasure {
    let (mesh, invalid) = sanitize(mesh);
    let steps = options.steps.clamp(1, 64);
    let plans: Vec<FacePlan> = model.faces.iter().map(FacePlan::new).collect();
    let mut index = SurfaceIndex::new(&model.faces, &plans, spacing(&plans, options.index_samples), options.projection);
    let diagonal = index.bbox().diagonal();
    let tolerance = options.tolerance.filter(|t| *t > 0.0 && t.is_finite()).unwrap_or(1e-3 * diagonal);
    index.retry_above(0.5 * tolerance);
    let mut out = MeshMeasure {
        tolerance,
        diagonal,
        triangles: mesh.triangle_count(),
        invalid_triangles: invalid,
        face_ranges: !mesh.face_ranges.is_empty(),
        ..MeshMeasure::default()
    };

    // Deviation: a barycentric grid on every triangle.
    let inv = 1.0 / steps as f64;
    let mut points: Vec<DVec3> = Vec::new();
    let mut dist: Vec<f64> = Vec::new();
    let mut sum = 0.0;
    // Per triangle, the model faces nearest its centroid: which body it is on.
    let mut near: Vec<u32> = Vec::new();
    let mut votes = BodyVotes::new(model, &mesh);
    for t in 0..mesh.triangle_count() {
        let corners = mesh.triangle(t);
        points.clear();
        for i in 0..=steps {
            for j in 0..=(steps - i) {
                let (b, c) = (i as f64 * inv, j as f64 * inv);
                points.push(corners[0] * (1.0 - b - c) + corners[1] * b + corners[2] * c);
            }
        }
        index.distances(&corners, &points, &mut dist, &mut near);
        votes.add(t, &near);
        for &d in &dist {
            out.max_deviation = out.max_deviation.max(d);
            sum += d;
        }
        out.deviation_samples += dist.len();
    }
    if model.faces.is_empty() && out.triangles > 0 {
        out.max_deviation = f64::INFINITY;
    }
    out.mean_deviation = if out.deviation_samples > 0 { sum / out.deviation_samples as f64 } else { 0.0 };

    coverage(model, &plans, &mesh, options.coverage_samples, &mut out);

    let weld = options.weld.filter(|w| *w > 0.0 && w.is_finite()).unwrap_or(1e-3 * tolerance);
    // Edges along faces the reader skipped are cracks, as the mesher counts them.
    let bodies = votes.bodies(&mesh, weld);
    let edges = edge_counts_around_skipped(&mesh, &bodies, &model.skipped, weld, tolerance);
    out.boundary_edges = edges.boundary_edges;
    out.free_edges = edges.free_edges;
    out.nonmanifold_edges = edges.nonmanifold_edges;
    out.misoriented_edges = edges.misoriented_edges;
    out.vertices = weld_positions(&mesh.positions, weld).1;
    let angles = angle_stats(&mesh);
    out.min_angle_deg = angles.min_deg;
    out.p1_angle_deg = angles.p1_deg;
    out
}

/// Coverage: distance from samples of every face's trimmed region to the mesh.
fn coverage(model: &Model, plans: &[FacePlan], mesh: &Mesh, target: usize, out: &mut MeshMeasure) {
    let h = spacing(plans, target);
    let boxes: Vec<Aabb> = (0..mesh.triangle_count()).map(|t| Aabb::from_points(mesh.triangle(t))).collect();
    let bvh = Bvh::build(&boxes);
    let tri_distance = |t: u32, p: DVec3| {
        let [a, b, c] = mesh.triangle(t as usize);
        closest_on_triangle(p, a, b, c).distance(p)
    };
    let mut last: Option<u32> = None;
    for (face, plan) in model.faces.iter().zip(plans) {
        for &(p, _) in &sample_face(face, plan, h, 9).points {
            out.coverage_samples += 1;
            // The previous sample's triangle bounds the search (samples come in order).
            let seed = last.map(|t| (tri_distance(t, p), t));
            let limit = seed.map_or(f64::INFINITY, |(d, _)| d * (1.0 + 1e-12) + TINY);
            let found = bvh.nearest(p, limit, |t| tri_distance(t, p)).or(seed);
            let d = match found {
                Some((d, t)) => {
                    last = Some(t);
                    d
                }
                None => f64::INFINITY,
            };
            out.coverage = out.coverage.max(d);
            if d > out.tolerance || d.is_nan() {
                out.uncovered_samples += 1;
            }
        }
    }
}

/// The mesh with bad triangles left out (and their count); face ranges kept
/// only when they tile the triangles in order.
fn sanitize(mesh: &Mesh) -> (Mesh, usize) {
    let n = mesh.positions.len();
    let finite: Vec<bool> = mesh.positions.iter().map(|p| p.is_finite()).collect();
    let good = |t: &[u32]| t.iter().all(|&i| (i as usize) < n && finite[i as usize]);
    let tiles = {
        let mut next = 0u64;
        mesh.face_ranges.iter().all(|r| {
            let ok = u64::from(r.first) == next;
            next += u64::from(r.count);
            ok
        }) && next == (mesh.indices.len() / 3) as u64
    };
    let mut clean = Mesh { positions: mesh.positions.clone(), ..Mesh::default() };
    let mut invalid = 0;
    let tris: Vec<&[u32]> = mesh.indices.chunks_exact(3).collect();
    let ranges: Vec<FaceRange> = if tiles && !mesh.face_ranges.is_empty() {
        mesh.face_ranges.clone()
    } else {
        alloc::vec![FaceRange { first: 0, count: tris.len() as u32 }]
    };
    for r in &ranges {
        let first = (clean.indices.len() / 3) as u32;
        for t in &tris[r.first as usize..r.first as usize + r.count as usize] {
            if good(t) {
                clean.indices.extend_from_slice(t);
            } else {
                invalid += 1;
            }
        }
        clean.face_ranges.push(FaceRange { first, count: (clean.indices.len() / 3) as u32 - first });
    }
    if !tiles || mesh.face_ranges.is_empty() {
        clean.face_ranges.clear();
    }
    (clean, invalid)
}
