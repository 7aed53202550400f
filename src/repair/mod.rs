//! Mesh repair (paper 002, "Extracting a regular triangular net for
//! offsetting"): a clean 2-manifold from a triangle mesh that was closed and
//! has been deformed (offset, say) into degenerate and self-intersecting
//! triangles.
//!
//! Stages: weld and orient ([`topology`]), degenerate triangles out
//! ([`degenerate`], step 1), self-intersection segments ([`intersect`], step
//! 2, with the k-d tree or BVH of [`broad`] and the exact test of
//! [`tritri`]), valid region growing from an extreme triangle with
//! sub-triangulation and stitching ([`region`], [`arrange`], [`cdt`], steps
//! 3–5). Everything is `no_std` + `alloc`: the sub-triangulation is a small
//! constrained Delaunay triangulation of its own rather than spade's, because
//! the triangles it serves carry a handful of points each (spade's set-up
//! would dominate) and because it must keep points that rounding puts on one
//! spot apart by their names, which spade would merge.
//!
//! Numbers ([`crate::numeric`]): which side of a plane, and orientation
//! in a triangle's plane, are exact ([`crate::predicates`]), so the
//! intersection topology is consistent (paper 002 §3); welding, the zero
//! length and the zero angle of degenerate triangles, and the perturbation
//! of symmetric input are tolerances of [`RepairOptions`].

mod arrange;
mod broad;
mod cdt;
mod check;
mod degenerate;
mod intersect;
mod offset;
mod region;
mod steps;
mod topology;
mod tritri;

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use serde::Serialize;

pub use check::{find_self_intersections, mesh_edge_census, mesh_volume, EdgeCensus};
pub use offset::offset_mesh;

use crate::{Error, Mesh};

/// How the self-intersection search finds candidate pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Bucketing {
    /// Paper 002 §3: k-d tree buckets, pairs tested inside each leaf.
    KdTree,
    /// A bounding-volume hierarchy queried with each triangle's box.
    Bvh,
}

impl Bucketing {
    /// The words `FromStr` takes, in declaration order.
    pub const WORDS: &'static [&'static str] = &["kd", "bvh"];
}

impl core::str::FromStr for Bucketing {
    type Err = crate::UnknownWord;
    fn from_str(s: &str) -> Result<Self, crate::UnknownWord> {
        crate::options::parse_word(s, "bucketing", Self::WORDS, &[Self::KdTree, Self::Bvh])
    }
}

/// Options of [`repair_mesh`]. Lengths are fractions of the input's
/// bounding-box diagonal.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RepairOptions {
    /// Vertices closer than this are welded first. Default 1e-9 (coincident
    /// within rounding; 0 merges only identical coordinates).
    pub weld_tolerance: f64,
    /// Zero-length tolerance ε₁ of step 1: shorter edges are collapsed. Default 1e-9.
    pub zero_length: f64,
    /// Zero-angle tolerance ε₂ of step 1, radians. Default 1e-6.
    pub zero_angle: f64,
    /// Candidate-pair search. Default [`Bucketing::KdTree`], the paper's: at
    /// 250k triangles it measured faster than the BVH (`benches/repair.rs`),
    /// at 15k about the same.
    pub bucketing: Bucketing,
    /// Triangles per k-d tree leaf before it splits. Default 128: as the
    /// paper found (its Fig. 5), the best value depends on the model; on the
    /// offset tori of `benches/repair.rs` small leaves cost more in
    /// duplicated triangles than they save in pair tests (at 250k triangles
    /// the search took 0.57 s at 32, 0.43 s at 128, 0.33 s at 256; at 15k,
    /// 128 was best).
    pub bucket_capacity: usize,
    /// Every vertex is moved by a pseudo-random vector of up to this size
    /// before step 2 (fixed seed: runs repeat), so that the exact
    /// coincidences of symmetric input (intersection curves lying exactly in a
    /// mirror plane, several segments through one point) become generic;
    /// 1e-9 of the diagonal is far below what an STL file (`f32`) keeps.
    /// When the arrangement still has unresolved contacts, the run is repeated
    /// once with 100 times the size. 0 moves nothing unless needed. Default 1e-9.
    pub perturbation: f64,
    /// Also search the result for self-intersections (costs about as much as step 2). Default false.
    pub verify: bool,
    /// Largest input accepted, triangles. Default 20,000,000.
    pub max_triangles: usize,
    /// Most intersection segments accepted. Default 20,000,000.
    pub max_segments: usize,
}

impl Default for RepairOptions {
    fn default() -> Self {
        Self {
            weld_tolerance: 1e-9,
            zero_length: 1e-9,
            zero_angle: 1e-6,
            bucketing: Bucketing::KdTree,
            bucket_capacity: 128,
            perturbation: 1e-9,
            verify: false,
            max_triangles: 20_000_000,
            max_segments: 20_000_000,
        }
    }
}

impl RepairOptions {
    /// Sets [`Self::bucketing`].
    pub fn with_bucketing(mut self, b: Bucketing) -> Self {
        self.bucketing = b;
        self
    }
    /// Sets [`Self::bucket_capacity`].
    pub fn with_bucket_capacity(mut self, n: usize) -> Self {
        self.bucket_capacity = n;
        self
    }
    /// Sets [`Self::verify`].
    pub fn with_verify(mut self, v: bool) -> Self {
        self.verify = v;
        self
    }
    /// Sets [`Self::weld_tolerance`].
    pub fn with_weld_tolerance(mut self, t: f64) -> Self {
        self.weld_tolerance = t;
        self
    }
    /// Sets [`Self::zero_length`] and [`Self::zero_angle`].
    pub fn with_zero_tolerances(mut self, length: f64, angle: f64) -> Self {
        self.zero_length = length;
        self.zero_angle = angle;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::Repair`] naming the option.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |name: &str, message: String| Err(Error::Repair { location: format!("option {name}"), message });
        for (name, v) in [
            ("weld_tolerance", self.weld_tolerance),
            ("zero_length", self.zero_length),
            ("zero_angle", self.zero_angle),
            ("perturbation", self.perturbation),
        ] {
            if !(v.is_finite() && (0.0..0.1).contains(&v)) {
                return bad(name, format!("{v} is outside [0, 0.1)"));
            }
        }
        if !(2..=1_000_000).contains(&self.bucket_capacity) {
            return bad("bucket_capacity", format!("{} is outside 2..=1000000", self.bucket_capacity));
        }
        Ok(())
    }
}

/// Milliseconds per stage, measured with the clock the caller passed (the core has none).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StageTimes {
    /// Checks, welding, orientation, adjacency.
    pub prepare: f64,
    /// Step 1: degenerate triangles.
    pub degenerate: f64,
    /// Step 2: self-intersection segments.
    pub intersect: f64,
    /// Steps 3–5: region growing, sub-triangulation, stitching, output.
    pub regions: f64,
    /// Optional search of the result for self-intersections.
    pub verify: f64,
    /// All of the above.
    pub total: f64,
}

/// What [`repair_mesh`] did and measured; serialized as the CLI's report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RepairReport {
    /// Triangles given.
    pub triangles_in: usize,
    /// Vertices given.
    pub vertices_in: usize,
    /// Vertices merged into others by welding.
    pub vertices_welded: usize,
    /// Triangles dropped before step 1: collapsed by welding, or duplicates.
    pub triangles_dropped: usize,
    /// Triangles reversed to agree with their neighbours (or whole inside-out components).
    pub triangles_reoriented: usize,
    /// Connected components of the input.
    pub components: usize,
    /// Free edges of the input (an open mesh; its boundary stays open).
    pub free_edges_in: usize,
    /// Step 1: edge collapses.
    pub degenerate_collapsed: usize,
    /// Step 1: edge swaps.
    pub degenerate_swapped: usize,
    /// Degenerate triangles step 1 could not remove.
    pub degenerate_left: usize,
    /// Size of the vertex moves used (fraction of the diagonal; see [`RepairOptions::perturbation`]).
    pub perturbation: f64,
    /// Candidate-pair search used.
    pub bucketing: Option<Bucketing>,
    /// k-d tree leaves (0 with the BVH).
    pub kd_leaves: usize,
    /// Triangle pairs whose boxes overlap (narrow-phase tests).
    pub candidate_pairs: usize,
    /// Self-intersection segments (one per crossing pair of triangles).
    pub segments: usize,
    /// Contacts not handled: coplanar overlaps, touching, vertices exactly on another triangle.
    pub degenerate_contacts: usize,
    /// Valid regions grown (areas between segments).
    pub regions: usize,
    /// Triangles sub-triangulated along their segments.
    pub triangles_subdivided: usize,
    /// Sub-triangulations that could not take their segments (near-coincident points).
    pub subdivision_fallbacks: usize,
    /// Steps across an edge or segment that found nothing to join.
    pub stitch_misses: usize,
    /// Triangles in the result.
    pub triangles_out: usize,
    /// Vertices in the result.
    pub vertices_out: usize,
    /// Edge census of the result.
    pub census_out: EdgeCensus,
    /// Volume of the input after welding and orientation.
    pub volume_in: f64,
    /// Volume of the result.
    pub volume_out: f64,
    /// Pairs of result triangles that still meet (only with `verify`).
    pub self_intersections_out: Option<usize>,
    /// Time per stage.
    pub time_ms: StageTimes,
    /// What was assumed or left undone.
    pub warnings: Vec<crate::Warning>,
}

/// A repaired mesh and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct RepairResult {
    /// The repaired mesh (no normals, one face).
    pub mesh: Mesh,
    /// What was done.
    pub report: RepairReport,
}

/// Repairs `mesh` with no clock (all times 0). See [`repair_mesh_timed`].
///
/// # Errors
/// As [`repair_mesh_timed`].
pub fn repair_mesh(mesh: &Mesh, options: &RepairOptions) -> Result<RepairResult, Error> {
    repair_mesh_timed(mesh, options, &mut || 0.0)
}

/// Repairs `mesh` (paper 002): welds, orients, removes degenerate triangles,
/// finds the self-intersections and keeps the valid regions grown from the
/// triangle at the vertex of largest x (one seed per connected component no
/// other one reached). `clock` returns milliseconds; it times the stages.
///
/// Best effort, reported in `warnings`: an open mesh keeps its open boundary
/// (growth stops there); vertices are not welded when welding would make the
/// mesh non-manifold; an inside-out closed component is turned outward;
/// contacts the exact test cannot resolve (coplanar overlaps, touching) are
/// counted and left as they are.
///
/// # Errors
/// [`Error::Repair`] for an empty mesh, a coordinate that is not finite or is
/// beyond 1e30, an index out of range, an edge shared by more than two
/// triangles (non-manifold input), or a component that cannot be oriented;
/// [`Error::Limit`] past `max_triangles` or `max_segments`.
pub fn repair_mesh_timed(
    mesh: &Mesh,
    options: &RepairOptions,
    clock: &mut dyn FnMut() -> f64,
) -> Result<RepairResult, Error> {
    options.validate()?;
    let t0 = clock();
    let mut report =
        RepairReport { triangles_in: mesh.triangle_count(), vertices_in: mesh.positions.len(), ..Default::default() };
    let (tris_in, diag) = steps::checked_input(mesh, options)?;
    let prepared = steps::weld_and_orient(mesh, tris_in, diag, options, &mut report)?;
    let t1 = clock();
    let clean = steps::remove_degenerate(prepared, diag, options, &mut report);
    let t2 = clock();
    let (x, grown) = steps::intersect_and_grow(&clean, diag, options, &mut report, clock)?;
    let t3 = clock();
    steps::report_regions(&grown, &mut report);
    let (out_pos, out_idx, out_tris) = steps::output(&grown, &mut report);
    drop((x, grown));
    let t4 = clock();
    if options.verify {
        report.self_intersections_out = Some(check::self_intersections(&out_pos, &out_tris).len());
    }
    let t5 = clock();
    report.time_ms.prepare = t1 - t0;
    report.time_ms.degenerate = t2 - t1;
    report.time_ms.regions += t4 - t3;
    report.time_ms.verify = t5 - t4;
    report.time_ms.total = t5 - t0;
    let mesh = Mesh { positions: out_pos, normals: Vec::new(), indices: out_idx, face_ranges: Vec::new() };
    Ok(RepairResult { mesh, report })
}
