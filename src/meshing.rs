//! Meshing a model: the mode chosen once, at the top. Fast mode is the
//! tessellator (paper 000), quality mode the quality mesher (paper 003);
//! neither knows of the other, and both hand back a [`MeshResult`].

use crate::model::body_count;
use crate::options::{MeshMode, MeshOptions};
use crate::report::MeshResult;
use crate::{quality, tessellate, Error, Model};

/// Meshes every face of `model` within `options`, and measures the result.
///
/// Each face gets an iso-parametric grid sized by paper 000's chord test, a
/// constrained Delaunay band along its trim loops, and refinement until every
/// triangle's measured deviation, normal turn and edge length pass.
/// With [`MeshMode::Quality`] the faces get near-equilateral triangles of
/// the size in [`MeshOptions::quality`] instead (paper 003).
///
/// # Errors
/// Invalid options, an empty model, a face whose loops cross or leave the
/// domain, or a tolerance that would need more triangles than the budget.
pub fn mesh_model(model: &Model, options: &MeshOptions) -> Result<MeshResult, Error> {
    mesh_model_with_progress(model, options, &mut |_, _| true)
}

/// As [`mesh_model`], calling `progress(faces_done, faces_total)` after each
/// face; when it returns `false` meshing stops with [`Error::Cancelled`].
/// (The core has no clock or threads: a caller that wants a time limit or a
/// cancel button decides inside the callback.)
///
/// # Errors
/// As [`mesh_model`], or [`Error::Cancelled`].
pub fn mesh_model_with_progress(
    model: &Model,
    options: &MeshOptions,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<MeshResult, Error> {
    // A model of tessellated faces only has nothing to mesh in quality mode:
    // the fast path passes them through.
    if options.mode == MeshMode::Quality && !model.faces.is_empty() {
        let mut r = quality::mesh_quality(model, options, progress)?;
        // Tessellated faces are passed through unsewn.
        tessellate::append_unsewn(model, &mut r.mesh, &mut r.report);
        r.report.bodies = body_count(model);
        r.report.units = model.units.clone();
        r.report.faces_unread = model.skipped.len();
        return Ok(r);
    }
    tessellate::mesh_fast(model, options, progress)
}
