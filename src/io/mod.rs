//! Readers (bytes in, [`Model`] out) and mesh writers (bytes out).

mod glb;
mod json;
mod obj;
mod stl;

use alloc::format;

pub use glb::write_glb;
pub use json::read_json;
pub use obj::write_obj;
pub use stl::write_stl;

use crate::{Error, Model};

/// Input formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// The JSON model of DESIGN.md.
    Json,
}

impl Format {
    /// Format from a name or file extension (`"json"`, `".json"`, case-insensitive).
    ///
    /// # Errors
    /// [`Error::Format`] for an unknown name.
    pub fn from_name(name: &str) -> Result<Self, Error> {
        let n = name.trim_start_matches('.');
        if n.eq_ignore_ascii_case("json") {
            Ok(Self::Json)
        } else {
            Err(Error::Format(format!("unknown input format '{name}' (expected json)")))
        }
    }

    /// Guesses the format from the first bytes (`{` after white space: JSON).
    pub fn detect(bytes: &[u8]) -> Option<Self> {
        let first = bytes.iter().find(|b| !b.is_ascii_whitespace())?;
        (*first == b'{').then_some(Self::Json)
    }
}

/// Reads a model in the given format.
///
/// # Errors
/// The reader's error, naming the location of the problem.
pub fn read_model(bytes: &[u8], format: Format) -> Result<Model, Error> {
    match format {
        Format::Json => read_json(bytes),
    }
}
