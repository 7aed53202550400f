//! Readers (bytes in, [`Model`] or [`crate::Mesh`] out) and mesh writers (bytes out).
//!
//! Numbers ([`crate::numeric`]): readers decide by tolerances relative to
//! the size of what they compare (a curve closed within 1e-9 of its box's
//! diagonal, a degenerate frame or transform by its determinant) or by the
//! file's own modelling tolerance where it gives one; no exact predicates.

#[cfg(feature = "writers")]
mod glb;
mod iges;
#[cfg(feature = "writers")]
mod iges_write;
mod json;
mod json_text;
#[cfg(feature = "repair")]
mod meshfile;
#[cfg(feature = "writers")]
mod msh;
#[cfg(feature = "writers")]
mod obj;
mod step;
#[cfg(feature = "writers")]
mod stl;
#[cfg(feature = "writers")]
mod unv;

use alloc::format;

#[cfg(feature = "writers")]
pub use glb::{write_glb, write_glb_scaled};
pub use iges::read_iges;
#[cfg(feature = "writers")]
pub use iges_write::write_iges;
pub use json::read_json;
#[cfg(feature = "repair")]
pub(crate) use meshfile::MAX_COORDINATE;
#[cfg(feature = "repair")]
pub use meshfile::{read_mesh, MeshFormat};
#[cfg(feature = "writers")]
pub use msh::{read_msh, write_msh};
#[cfg(feature = "writers")]
pub use obj::write_obj;
pub use step::{count_step_instances, read_step, read_step_parts, read_step_with_shells, StepModel, StepShell};
#[cfg(feature = "writers")]
pub use stl::write_stl;
#[cfg(feature = "writers")]
pub use unv::{write_unv, UNV_SHELL_TRIANGLE};

use crate::{Error, Model};

/// Input formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// The JSON model of DESIGN.md.
    Json,
    /// IGES 5.3, fixed 80-column ASCII form (`.igs`, `.iges`).
    Iges,
    /// STEP, ISO 10303-21 exchange structure (`.stp`, `.step`, `.p21`): AP203, AP214, AP242 B-reps.
    Step,
}

impl Format {
    /// Format from a name or file extension (`"json"`, `".igs"`, `"iges"`, case-insensitive).
    ///
    /// # Errors
    /// [`Error::Format`] for an unknown name.
    pub fn from_name(name: &str) -> Result<Self, Error> {
        let n = name.trim_start_matches('.');
        if n.eq_ignore_ascii_case("json") {
            Ok(Self::Json)
        } else if n.eq_ignore_ascii_case("igs") || n.eq_ignore_ascii_case("iges") {
            Ok(Self::Iges)
        } else if ["stp", "step", "p21"].iter().any(|x| n.eq_ignore_ascii_case(x)) {
            Ok(Self::Step)
        } else {
            Err(Error::Format(format!("unknown input format '{name}' (expected json, igs, iges, stp, step or p21)")))
        }
    }

    /// Guesses the format from the first bytes: `{` after white space is
    /// JSON; `ISO-10303-21;` after white space is STEP; a first line of at least 73 columns with `S` or `G` in column 73
    /// (and a sequence number after it, when the line is 80 columns) is IGES.
    pub fn detect(bytes: &[u8]) -> Option<Self> {
        let first = bytes.iter().find(|b| !b.is_ascii_whitespace())?;
        if *first == b'{' {
            return Some(Self::Json);
        }
        let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(0);
        if bytes.get(start..start + 13).is_some_and(|m| m == b"ISO-10303-21;") {
            return Some(Self::Step);
        }
        let line = bytes.split(|&b| b == b'\n').next()?;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let letter = *line.get(72)?;
        let seq_ok = line.get(73..).is_none_or(|s| s.iter().all(|c| c.is_ascii_digit() || *c == b' '));
        (matches!(letter, b'S' | b'G') && seq_ok && line.len() <= 80).then_some(Self::Iges)
    }
}

/// Reads a model in the given format.
///
/// # Errors
/// The reader's error, naming the location of the problem.
pub fn read_model(bytes: &[u8], format: Format) -> Result<Model, Error> {
    match format {
        Format::Json => read_json(bytes),
        Format::Iges => read_iges(bytes),
        Format::Step => read_step(bytes),
    }
}
