//! Tessellation of trimmed surfaces within a verified tolerance (paper 000).

mod options;

use crate::{Error, Mesh, Model, Report};

pub use options::{MeshOptions, OptionsError, Tolerance};

/// A mesh and what was measured on it.
#[derive(Debug, Clone, Default)]
pub struct MeshResult {
    /// The triangles.
    pub mesh: Mesh,
    /// Measured deviation, angles, edge census, warnings.
    pub report: Report,
}

/// Meshes every face of `model`.
///
/// # Errors
/// Invalid options, or a face whose loops cross.
pub fn mesh_model(_model: &Model, options: &MeshOptions) -> Result<MeshResult, Error> {
    options.validate()?;
    Err(Error::Internal("mesher not written yet".into()))
}
