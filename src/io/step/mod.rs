//! STEP reader (ISO 10303-21, AP203 / AP214 / AP242 boundary representations
//! with assemblies): bytes in, [`crate::Model`] out.
//!
//! The exchange structure is parsed into a flat graph ([`parser`],
//! [`graph`]) whose checked accessors name the `#id` and line of any
//! problem. Nesting, counts and sizes are capped, so no input can make the
//! reader loop or allocate without bound.

// The geometry reader that uses the graph lands next.
#![allow(dead_code)]

mod graph;
mod parser;

use alloc::string::String;

use crate::Error;

/// A [`Error::Step`] about instance `#id` (0: none) at `line` (0: unknown).
fn step_error(id: u64, line: usize, message: impl Into<String>) -> Error {
    Error::Step { id, line, message: message.into() }
}
