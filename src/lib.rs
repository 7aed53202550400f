//! surfmesh: triangle meshes of trimmed NURBS surfaces within a verified tolerance.
//!
//! The core is `no_std` + `alloc`. Read a model ([`read_model`]), mesh it
//! ([`mesh_model`]); every mesh comes with a [`Report`] of what was measured on
//! it against the exact surfaces. See `ARCHITECTURE.md` for the data flow.
#![no_std]
#![warn(missing_docs)]
// Numerical kernels index several arrays with one counter, as the textbook algorithms do.
#![allow(clippy::needless_range_loop)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod collections;
mod edges;
mod error;
#[cfg(feature = "fit")]
mod fit;
mod instances;
mod io;
mod math;
mod measure;
mod mesh;
mod meshing;
mod model;
mod numeric;
mod nurbs;
mod options;
#[cfg(any(feature = "repair", feature = "fit"))]
mod predicates;
mod quality;
#[cfg(feature = "repair")]
mod repair;
mod reparam;
mod report;
mod sort;
mod tessellate;
#[cfg(test)]
mod testing;
mod units;
mod warning;
#[cfg(all(target_arch = "wasm32", target_os = "unknown"))]
mod wasm;

pub use edges::{edge_lines, EdgeLines};
pub use error::Error;
#[cfg(feature = "fit")]
pub use fit::{
    fit_points, read_points, Cubic, FitOptions, FitPolygon, FitReport, FitResult, FitSurface, PatchPoint, PointFormat,
    TriPatch, MAX_FILE_POINTS,
};
pub use instances::{flatten, mesh_instanced, InstancedResult, PartMesh};
/// The STEP reader's text parsing alone, for the readers' bench; not a stable API.
#[doc(hidden)]
pub use io::count_step_instances;
pub use io::{
    read_iges, read_json, read_model, read_step, read_step_parts, read_step_with_shells, Format, StepModel, StepShell,
};
#[cfg(feature = "repair")]
pub use io::{read_mesh, MeshFormat};
#[cfg(feature = "writers")]
pub use io::{
    read_msh, write_glb, write_glb_scaled, write_iges, write_msh, write_obj, write_stl, write_unv, UNV_SHELL_TRIANGLE,
};
pub use measure::{measure_mesh, MeasureOptions, MeshMeasure};
pub use mesh::{
    angle_stats, edge_counts, edge_counts_around_skipped, edge_counts_in_bodies, weld_mesh, weld_positions, AngleStats,
    EdgeCounts, FaceRange, Mesh,
};
pub use meshing::{mesh_model, mesh_model_with_progress};
pub use model::{
    share_of_faces, Assembly, AssemblyNode, Face, FaceSurface, Model, PartInstance, SkippedFace, TessellatedFace,
    TrimLoop,
};
pub use nurbs::{
    project_to_surface, Aabb, BasisDers, CurveDerivs, CurveProjection, KnotVector, NurbsCurve, NurbsError,
    NurbsSurface, Projection, ProjectionOptions, Surface, SurfaceDerivs, MAX_DEGREE,
};
pub use options::{
    ElementSize, MeshMode, MeshOptions, OptionsError, QualityMethod, QualityOptions, Reparam, Tolerance, UnknownWord,
};
#[cfg(feature = "repair")]
pub use repair::{
    find_self_intersections, mesh_edge_census, mesh_volume, offset_mesh, repair_mesh, repair_mesh_timed, Bucketing,
    EdgeCensus, RepairOptions, RepairReport, RepairResult, StageTimes,
};
pub use reparam::{
    rebuild_face, reparameterize_model, step_ratio, Rebuilt, ReparamFace, ReparamModel, FIT_LIMIT, FIT_SHARE,
    RATIO_LIMIT,
};
pub use report::{MeshResult, QualityReport, Report, EDGE_BAND, GOOD_ANGLE_DEG};
/// The fast mesher's stages one at a time, for the criterion benches; not a stable API.
#[doc(hidden)]
pub use tessellate::pipeline;
pub use units::{mesh_model_in_units, mm_per_unit, Units};
pub use warning::{
    Entity, InterpError, Mended, QualityError, RebuildError, RebuildLoss, Reparameterized, Warning, WarningKind,
};

/// Reads `bytes` in `format` and meshes the model: the one call both doors use.
///
/// # Errors
/// Any reader, option or mesher error, with its location.
pub fn mesh_bytes(bytes: &[u8], format: Format, options: &MeshOptions) -> Result<MeshResult, Error> {
    options.validate()?;
    let model = read_model(bytes, format)?;
    mesh_model(&model, options)
}
