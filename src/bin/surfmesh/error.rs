//! Why a command stopped: one kind per cause, its `Display` the one line
//! printed after the program's name (and the input's, for a run).

use std::fmt;
use std::path::PathBuf;

use surfmesh::{Error, OptionsError};

/// A command's failure.
#[derive(Debug)]
pub enum CliError {
    /// The library's error: reading, options, meshing, repair, fitting.
    Core(Error),
    /// The command line is wrong: what is, and how to fix it (exit status 2).
    Usage(String),
    /// A file or folder that could not be read or written, and the system's reason.
    Io { action: IoAction, source: std::io::Error },
    /// What this machine could not give the run (its executable's path,
    /// worker threads, a row's JSON), and why.
    Run { what: &'static str, reason: String },
}

/// What was done to a file when it failed.
#[derive(Debug)]
pub enum IoAction {
    /// Reading the input.
    Read,
    /// Listing a folder.
    ReadFolder(PathBuf),
    /// Writing an output.
    Write(PathBuf),
}

impl CliError {
    /// A usage error with this message.
    pub fn usage(message: impl Into<String>) -> Self {
        Self::Usage(message.into())
    }

    /// A failure to read the input.
    pub fn read(source: std::io::Error) -> Self {
        Self::Io { action: IoAction::Read, source }
    }

    /// A failure to write `path`.
    pub fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io { action: IoAction::Write(path.into()), source }
    }

    /// What the run could not have, and why.
    pub fn run(what: &'static str, reason: impl fmt::Display) -> Self {
        Self::Run { what, reason: reason.to_string() }
    }

    /// A report that could not be written as JSON: the library's internal error.
    pub fn report(e: impl fmt::Display) -> Self {
        Self::Core(Error::Internal(format!("report: {e}")))
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Core(e) => write!(f, "{e}"),
            Self::Usage(m) => write!(f, "{m}"),
            Self::Io { action: IoAction::Read, source } => write!(f, "cannot read: {source}"),
            Self::Io { action: IoAction::ReadFolder(p), source } => {
                write!(f, "cannot read the folder {}: {source}", p.display())
            }
            Self::Io { action: IoAction::Write(p), source } => write!(f, "cannot write {}: {source}", p.display()),
            Self::Run { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl std::error::Error for CliError {}

impl From<Error> for CliError {
    fn from(e: Error) -> Self {
        Self::Core(e)
    }
}

impl From<OptionsError> for CliError {
    fn from(e: OptionsError) -> Self {
        Self::Core(e.into())
    }
}
