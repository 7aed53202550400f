//! Quality meshing for analysis (paper 003): near-equilateral triangles of a
//! chosen size H instead of the fewest triangles within a tolerance.
//!
//! 1. Boundary nodes shared across faces: each model edge divided once by
//!    arc length into ceil(L/H) equal parts ([`boundary`]).
//! 2. Per face, the plane to mesh in: the face's own plane, or the double
//!    mapping of a curved face ([`mapping`], paper 003 §3).
//! 3. Filling: the looping method ([`looping`], §2), or spade's Delaunay
//!    refinement as the baseline ([`delaunay`]), or both and the better kept.
//! 4. Improvement on the exact surface in model space ([`improve`]).

//!
//! The options and the report are always here; the mesher itself is the
//! `quality` feature (the npm package's viewer build leaves it out, and a
//! quality request there is an error saying so).

#[cfg(feature = "quality")]
mod boundary;
#[cfg(all(feature = "quality", feature = "std"))]
mod delaunay;
#[cfg(feature = "quality")]
mod improve;
#[cfg(feature = "quality")]
mod looping;
#[cfg(feature = "quality")]
mod mapping;
#[cfg(feature = "quality")]
mod mesher;

use serde::Serialize;

#[cfg(feature = "quality")]
pub(crate) use mesher::mesh_quality;

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

/// Without the `quality` feature: quality mode is refused with an error
/// that names the build that has it.
///
/// # Errors
/// Always [`crate::Error::Options`].
#[cfg(not(feature = "quality"))]
pub(crate) fn mesh_quality(
    _model: &crate::Model,
    _options: &crate::options::MeshOptions,
    _progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<crate::tessellate::MeshResult, crate::Error> {
    Err(crate::Error::Options(crate::options::OptionsError {
        option: "mode",
        message: "quality mode is not in this build (the npm package has it in surfmesh/full)",
    }))
}
