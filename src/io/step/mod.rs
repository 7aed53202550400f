//! STEP reader (ISO 10303-21, AP203 / AP214 / AP242 boundary representations
//! with assemblies): bytes in, [`Model`] out.
//!
//! The exchange structure is parsed into a flat graph ([`parser`],
//! [`graph`]) whose checked accessors name the `#id` and line of any
//! problem. Representations, their items and the assembly relations between
//! them give every solid, shell and surface set with its placement and unit
//! ([`assembly`]); each face of a shell becomes a surface definition shared
//! with the IGES reader ([`surfaces`]) bounded by its edges' model-space
//! curves, cut between their vertices ([`curves`], [`edges`]), which the
//! shared face builder projects into the surface's parameters ([`shapes`]).
//! A face that cannot be read is skipped with a warning naming its `#id`; a
//! malformed file is an [`Error::Step`] naming the instance and line.
//! Nesting, counts and sizes are capped, so no input can make the reader
//! loop or allocate without bound.

mod assembly;
mod curves;
mod edges;
mod graph;
mod parser;
mod shapes;
mod styles;
mod surfaces;

use alloc::string::String;
use alloc::vec::Vec;
use core::ops::Range;

use crate::model::SkippedFace;
use crate::{Error, Model};

/// Deepest chain of references followed (composite curves, offsets,
/// trimmed curves of trimmed curves, assembly levels).
const MAX_DEPTH: usize = 32;
/// Most faces the reader produces (after assembly instancing).
const MAX_FACES: usize = 1_000_000;
/// Most control points of one curve or surface.
const MAX_CONTROL_POINTS: usize = 4_000_000;

/// A [`Error::Step`] about instance `#id` (0: none) at `line` (0: unknown).
fn step_error(id: u64, line: usize, message: impl Into<String>) -> Error {
    Error::Step { id, line, message: message.into() }
}

/// One shell (or surface set) of the model as read: which faces came from it.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct StepShell {
    /// The shell's `#id` (or the set's, for loose surfaces).
    pub id: u64,
    /// Whether the file says the shell is closed (`CLOSED_SHELL`): its mesh
    /// should have no boundary edge.
    pub closed: bool,
    /// The faces of [`Model::faces`] made from it (one shell per instance
    /// of it in an assembly).
    pub faces: Range<usize>,
    /// How many faces the file lists in the shell; fewer in `faces` means
    /// some were skipped (see [`Model::warnings`]).
    pub listed: usize,
}

/// A STEP file as read: the model, and what the file says about its faces
/// beyond their geometry.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct StepModel {
    /// The faces to mesh, their units and the reader's warnings.
    pub model: Model,
    /// Which faces came from which shell (closed shells must mesh without border).
    pub shells: Vec<StepShell>,
    /// One name per part instance, in the order of first use: the product's
    /// name (empty when the file gives none). Two placements of one product
    /// are two parts with the same name.
    pub parts: Vec<String>,
    /// For each face of [`Model::faces`], the index of its part in [`StepModel::parts`].
    pub face_parts: Vec<u32>,
    /// For each face, its colour (red, green, blue in 0..=1) from the file's
    /// `STYLED_ITEM`s: the face's own, else its shell's, else its solid's.
    pub face_colours: Vec<Option<[f32; 3]>>,
}

/// Reads a STEP file (ISO 10303-21).
///
/// Solids (`MANIFOLD_SOLID_BREP`, `BREP_WITH_VOIDS`), shells of surface
/// models and loose surfaces of geometric sets are placed by their assembly
/// relations (`NEXT_ASSEMBLY_USAGE_OCCURRENCE` through
/// `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` with an
/// `ITEM_DEFINED_TRANSFORMATION`, and `MAPPED_ITEM`s), each instance getting
/// its own transformed faces. Lengths are in the unit of the first root
/// representation ([`Model::units`]); parts in other units are scaled to it.
/// Face names are the part's product name (and the face's own, if any).
/// [`Model::tolerance`] is the largest uncertainty the file states.
///
/// # Errors
/// [`Error::Step`] for a malformed exchange structure (instance and line
/// named), or when no face at all could be read (the first face's error).
pub fn read_step(bytes: &[u8]) -> Result<Model, Error> {
    read_step_with_shells(bytes).map(|(m, _)| m)
}

/// As [`read_step`], also telling which faces came from which shell, so a
/// caller can check that closed shells mesh without boundary edges.
///
/// # Errors
/// As [`read_step`].
pub fn read_step_with_shells(bytes: &[u8]) -> Result<(Model, Vec<StepShell>), Error> {
    read_step_parts(bytes).map(|s| (s.model, s.shells))
}

/// As [`read_step`], with shells, part instances and colours ([`StepModel`]).
///
/// # Errors
/// As [`read_step`].
pub fn read_step_parts(bytes: &[u8]) -> Result<StepModel, Error> {
    let g = parser::parse(bytes)?;
    let mut warnings = Vec::new();
    let plan = assembly::plan(&g, &mut warnings)?;
    let shapes = shapes::read_shapes(&g, &plan, &mut warnings)?;
    if shapes.faces.is_empty() {
        return Err(shapes.first_error.unwrap_or_else(|| {
            step_error(0, 0, "no faces, shells, solids or surfaces in the file (only curves, points or annotations?)")
        }));
    }
    let mut faces = shapes.faces;
    for (f, &p) in faces.iter_mut().zip(&shapes.placement) {
        let part = plan.placed.get(p).and_then(|p| p.name.as_ref());
        f.name = match (part, f.name.take()) {
            (Some(part), Some(own)) => Some(alloc::format!("{part}/{own}")),
            (Some(part), None) => Some(part.clone()),
            (None, own) => own,
        };
    }
    // Part instances in the order of first use.
    let mut parts: Vec<String> = Vec::new();
    let mut index: crate::collections::HashMap<usize, u32> = crate::collections::HashMap::default();
    let mut face_parts = Vec::with_capacity(faces.len());
    for &p in &shapes.placement {
        let placed = plan.placed.get(p);
        let instance = placed.map_or(usize::MAX, |p| p.instance);
        let k = *index.entry(instance).or_insert_with(|| {
            parts.push(placed.and_then(|p| p.name.clone()).unwrap_or_default());
            (parts.len() - 1) as u32
        });
        face_parts.push(k);
    }
    // Each shell instance is a body of its own.
    let mut bodies = alloc::vec![0u32; faces.len()];
    for (k, s) in shapes.shells.iter().enumerate() {
        for f in s.faces.clone() {
            if let Some(b) = bodies.get_mut(f) {
                *b = k as u32;
            }
        }
    }
    // A skipped face is in its shell's body; it is counted, and its border kept.
    let skipped = shapes
        .skipped
        .into_iter()
        .map(|(k, border)| SkippedFace { body: if k < shapes.shells.len() { k as u32 } else { 0 }, border })
        .collect();
    let model = Model { units: plan.units.clone(), faces, warnings, tolerance: plan.tolerance, bodies, skipped };
    Ok(StepModel { model, shells: shapes.shells, parts, face_parts, face_colours: shapes.colours })
}
