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
//! Its options ([`crate::QualityOptions`]) and its part of the report
//! ([`crate::QualityReport`]) are in every build; the mesher itself is the
//! `quality` feature (the npm package's viewer build leaves it out, and a
//! quality request there is an error saying so).
//!
//! Numbers ([`crate::numeric`]): sizes and scores are floats measured in
//! model space against the element size; loop splits and cut lines are
//! accepted by float tests with tolerances relative to the loop's size;
//! the `delaunay` method's triangulation is spade's (exact predicates).

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

#[cfg(feature = "quality")]
pub(crate) use mesher::mesh_quality;

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
) -> Result<crate::report::MeshResult, crate::Error> {
    Err(crate::Error::Options(crate::options::OptionsError {
        option: "mode",
        message: "quality mode is not in this build (the npm package has it in surfmesh/full)",
    }))
}
