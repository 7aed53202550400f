//! The crate's top-level error: one variant per stage.

use alloc::string::String;
use core::fmt;

use crate::nurbs::NurbsError;
use crate::options::OptionsError;

/// Why a model could not be read or meshed. `Display` gives the one-line
/// message the CLI prints and the JS binding throws.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// The input is not valid JSON or does not have the model's shape.
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the parser said.
        message: String,
    },
    /// A value in the model is invalid; `location` names face/loop/curve and field.
    Model {
        /// e.g. `face 2 surface knots[0]` or `face 0 loop 1 curve 3`.
        location: String,
        /// What is wrong.
        message: String,
    },
    /// Invalid NURBS data at `location`.
    Nurbs {
        /// e.g. `face 2 surface knots[0]`.
        location: String,
        /// The geometric problem.
        source: NurbsError,
    },
    /// An option out of range.
    Options(OptionsError),
    /// The input format is unknown or not supported in this build.
    Format(String),
    /// The mesher could not proceed on a face (loops that cross, etc.).
    Mesh {
        /// Face index.
        face: usize,
        /// What went wrong.
        message: String,
    },
    /// The IGES file is malformed.
    Iges {
        /// Section: `"Start"`, `"Global"`, `"Directory"`, `"Parameter"` or `"Terminate"`.
        section: &'static str,
        /// 1-based line of the file (0 when the problem has no single line).
        line: usize,
        /// Directory entry number of the entity concerned (0 when none).
        entity: usize,
        /// What is wrong.
        message: String,
    },
    /// The STEP file (ISO 10303-21) is malformed.
    Step {
        /// Instance number `#id` concerned (0 when none).
        id: u64,
        /// 1-based line of the file (0 when the problem has no single line).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A mesh file (STL, OBJ) is malformed.
    MeshFile {
        /// e.g. `ASCII STL line 12`, `binary STL triangle 7`, `OBJ line 3`.
        location: String,
        /// What is wrong.
        message: String,
    },
    /// A mesh cannot be repaired as given; `location` names the triangle, edge or vertex.
    Repair {
        /// e.g. `edge between vertices 3 and 7` or `vertex 12`.
        location: String,
        /// What is wrong.
        message: String,
    },
    /// A point file is malformed.
    Points {
        /// 1-based line of the file (0 when the problem has no single line).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The points admit no fitted surface (too few, colinear, not finite).
    Fit(String),
    /// A limit guarding memory or time was hit.
    Limit(String),
    /// The caller's progress callback asked to stop.
    Cancelled,
    /// A bug in surfmesh, not in the input.
    Internal(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Json { line, column, message } => write!(f, "JSON line {line} column {column}: {message}"),
            Self::Model { location, message } => write!(f, "{location}: {message}"),
            Self::Nurbs { location, source } => write!(f, "{location}: {source}"),
            Self::Options(e) => write!(f, "{e}"),
            Self::Format(m) => write!(f, "format: {m}"),
            Self::Mesh { face, message } => write!(f, "face {face}: {message}"),
            Self::Iges { section, line, entity, message } => {
                write!(f, "IGES {section} section")?;
                if *line > 0 {
                    write!(f, " line {line}")?;
                }
                if *entity > 0 {
                    write!(f, ", entity DE {entity}")?;
                }
                write!(f, ": {message}")
            }
            Self::Step { id, line, message } => {
                write!(f, "STEP")?;
                if *line > 0 {
                    write!(f, " line {line}")?;
                }
                if *id > 0 {
                    write!(f, "{} #{id}", if *line > 0 { "," } else { "" })?;
                }
                write!(f, ": {message}")
            }
            Self::MeshFile { location, message } => write!(f, "{location}: {message}"),
            Self::Repair { location, message } => write!(f, "repair: {location}: {message}"),
            Self::Points { line: 0, message } => write!(f, "points: {message}"),
            Self::Points { line, message } => write!(f, "points line {line}: {message}"),
            Self::Fit(m) => write!(f, "fit: {m}"),
            Self::Limit(m) => write!(f, "limit: {m}"),
            Self::Cancelled => write!(f, "cancelled"),
            Self::Internal(m) => write!(f, "internal error (a bug in surfmesh): {m}"),
        }
    }
}

impl core::error::Error for Error {}

impl From<OptionsError> for Error {
    fn from(e: OptionsError) -> Self {
        Self::Options(e)
    }
}
