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
//! AP242 tessellated faces are read as triangles ([`tessellated`]).
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
mod tessellated;

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use core::ops::Range;

use crate::model::{Assembly, SkippedFace};
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
    /// The faces made from it (one shell per instance of it in an
    /// assembly), numbered as the mesh's: [`Model::faces`], then
    /// [`Model::tessellated`] (a `TESSELLATED_SHELL` or `TESSELLATED_SOLID`).
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
    /// For each face of the mesh ([`Model::faces`], then
    /// [`Model::tessellated`]), the index of its part in [`StepModel::parts`].
    pub face_parts: Vec<u32>,
    /// For each face of the mesh, its colour (red, green, blue in 0..=1) from the file's
    /// `STYLED_ITEM`s: the face's own, else its shell's, else its solid's.
    pub face_colours: Vec<Option<[f32; 3]>>,
    /// The product tree (names, placements) and the part instances, numbered
    /// as [`StepModel::parts`]: instances placed from the same items of the
    /// file share a shape, so that they can be meshed once.
    pub assembly: Assembly,
}

/// Reads a STEP file (ISO 10303-21).
///
/// Solids (`MANIFOLD_SOLID_BREP`, `BREP_WITH_VOIDS`), shells of surface
/// models, loose surfaces of geometric sets and AP242 tessellated faces
/// (alone or in a `TESSELLATED_SHELL` / `TESSELLATED_SOLID`, read into
/// [`Model::tessellated`]) are placed by their assembly
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

/// The number of entity instances in an exchange structure: the text-parsing
/// stage of [`read_step`] alone, so the readers' bench can tell parsing's
/// MB/s apart from building the faces. Not a stable API.
///
/// # Errors
/// As [`read_step`], for a malformed exchange structure.
#[doc(hidden)]
pub fn count_step_instances(bytes: &[u8]) -> Result<usize, Error> {
    parser::parse(bytes).map(|g| g.all().count())
}

/// As [`read_step`], with shells, part instances and colours ([`StepModel`]).
///
/// # Errors
/// As [`read_step`].
pub fn read_step_parts(bytes: &[u8]) -> Result<StepModel, Error> {
    let g = parser::parse(bytes)?;
    let mut warnings = g.forgiven.warnings();
    let assembly::Plan { placed, nodes, units, tolerance } = assembly::plan(&g, &mut warnings)?;
    // Exact shapes and tessellated ones are read apart, each with its own
    // share of the placements.
    let (tess_placed, exact_placed): (Vec<assembly::Placed>, Vec<assembly::Placed>) =
        placed.into_iter().partition(|p| g.find(p.item).is_some_and(tessellated::is_tessellated));
    let exact_plan = assembly::Plan { placed: exact_placed, nodes: Vec::new(), units: units.clone(), tolerance };
    let tess_plan = assembly::Plan { placed: tess_placed, nodes: Vec::new(), units: units.clone(), tolerance };
    let shapes = shapes::read_shapes(&g, &exact_plan, &mut warnings)?;
    let exact = if shapes.faces.is_empty() {
        crate::collections::HashSet::default()
    } else {
        tessellated::exact_ids(&g, &exact_plan)
    };
    let facets = tessellated::read(&g, &tess_plan, &exact, &mut warnings);
    if shapes.faces.is_empty() && facets.faces.is_empty() {
        return Err(shapes.first_error.unwrap_or_else(|| step_error(0, 0, no_faces(&g))));
    }
    let part_name = |f: &mut Option<String>, placed: Option<&assembly::Placed>| {
        let part = placed.and_then(|p| p.name.as_ref());
        *f = match (part, f.take()) {
            (Some(part), Some(own)) => Some(alloc::format!("{part}/{own}")),
            (Some(part), None) => Some(part.clone()),
            (None, own) => own,
        };
    };
    let mut faces = shapes.faces;
    for (f, &p) in faces.iter_mut().zip(&shapes.placement) {
        part_name(&mut f.name, exact_plan.placed.get(p));
    }
    let mut tessellated = facets.faces;
    for (f, &p) in tessellated.iter_mut().zip(&facets.placement) {
        part_name(&mut f.name, tess_plan.placed.get(p));
    }
    // Every face's placement, exact faces first.
    let placed: Vec<Option<&assembly::Placed>> = (shapes.placement.iter().map(|&p| exact_plan.placed.get(p)))
        .chain(facets.placement.iter().map(|&p| tess_plan.placed.get(p)))
        .collect();
    // Part instances in the order of first use.
    let mut parts: Vec<String> = Vec::new();
    let mut index: crate::collections::HashMap<usize, u32> = crate::collections::HashMap::default();
    let mut face_parts = Vec::with_capacity(placed.len());
    for placed in &placed {
        let instance = placed.map_or(usize::MAX, |p| p.instance);
        let k = *index.entry(instance).or_insert_with(|| {
            parts.push(placed.and_then(|p| p.name.clone()).unwrap_or_default());
            (parts.len() - 1) as u32
        });
        face_parts.push(k);
    }
    let assembly = assembly::tree(&nodes, &placed, shapes.placement.len(), &face_parts, parts.len());
    // Each shell instance is a body of its own. A part instance whose exact
    // faces are one body (a solid, a shell) takes into it the tessellated
    // faces it lists on their own and its tessellated shells: they are the
    // rest of its surface, and are sewn to it. Tessellated solids, and the
    // tessellated faces of parts of several bodies or none, are bodies of their own.
    let offset = faces.len();
    let mut shells = shapes.shells;
    let exact_shells = shells.len();
    let mut group: Vec<usize> = (0..placed.len()).map(|f| shells.len() + f).collect();
    let mut exact_of: crate::collections::HashMap<usize, Option<usize>> = crate::collections::HashMap::default();
    for (k, s) in shells.iter().enumerate() {
        for f in s.faces.clone() {
            if let Some(b) = group.get_mut(f) {
                *b = k;
            }
            let instance = placed.get(f).copied().flatten().map_or(usize::MAX, |p| p.instance);
            let e = exact_of.entry(instance).or_insert(Some(k));
            if *e != Some(k) {
                *e = None;
            }
        }
    }
    let join = |f: usize| exact_of.get(&placed.get(f).copied().flatten().map_or(usize::MAX, |p| p.instance)).copied();
    for (f, &loose) in facets.loose.iter().enumerate() {
        if let (true, Some(Some(k))) = (loose, join(offset + f)) {
            group[offset + f] = k;
        }
    }
    for s in facets.shells {
        let faces = s.faces.start + offset..s.faces.end + offset;
        let own = join(faces.start).flatten().filter(|_| !s.closed).unwrap_or(placed.len() + shells.len());
        for f in faces.clone() {
            if let Some(b) = group.get_mut(f) {
                *b = own;
            }
        }
        shells.push(StepShell { faces, ..s });
    }
    let mut numbers: crate::collections::HashMap<usize, u32> = crate::collections::HashMap::default();
    let bodies: Vec<u32> = group
        .iter()
        .map(|b| {
            let next = numbers.len() as u32;
            *numbers.entry(*b).or_insert(next)
        })
        .collect();
    let mut face_colours = shapes.colours;
    face_colours.extend(facets.colours);
    // A skipped face is in its shell's body; it is counted, and its border kept.
    let skipped = shapes
        .skipped
        .into_iter()
        .map(|(k, border)| {
            let next = numbers.len() as u32;
            let body = if k < exact_shells { *numbers.entry(k).or_insert(next) } else { next };
            SkippedFace { body, border }
        })
        .collect();
    let model = Model { units, faces, warnings, tolerance, bodies, tessellated, skipped };
    Ok(StepModel { model, shells, parts, face_parts, face_colours, assembly })
}

/// Why a file that parsed gave no face at all: what it holds instead.
fn no_faces(g: &graph::Graph) -> String {
    let count = |names: &[&str]| g.all().filter(|e| names.iter().any(|n| e.has(n))).count();
    let lead = "no faces, shells, solids or surfaces in the file";
    let tessellated = count(&[
        "TRIANGULATED_FACE",
        "COMPLEX_TRIANGULATED_FACE",
        "TRIANGULATED_SURFACE_SET",
        "COMPLEX_TRIANGULATED_SURFACE_SET",
        "TESSELLATED_SHELL",
        "TESSELLATED_SOLID",
    ]);
    if tessellated > 0 {
        return format!(
            "{lead}: its shapes are tessellated ({}) and none of them could be read",
            plural(tessellated, "triangulated item")
        );
    }
    let csg = count(&[
        "BOOLEAN_RESULT",
        "CSG_SOLID",
        "EXTRUDED_AREA_SOLID",
        "EXTRUDED_FACE_SOLID",
        "REVOLVED_AREA_SOLID",
        "REVOLVED_FACE_SOLID",
        "SWEPT_DISK_SOLID",
        "BLOCK",
        "RIGHT_ANGULAR_WEDGE",
        "RIGHT_CIRCULAR_CONE",
        "RIGHT_CIRCULAR_CYLINDER",
        "SPHERE",
        "TORUS",
        "HALF_SPACE_SOLID",
    ]);
    if csg > 0 {
        return format!(
            "{lead}: its solids are given by construction ({}: primitives, sweeps, Boolean operations), \
             which this reader does not evaluate",
            plural(csg, "operation")
        );
    }
    let placed = count(&["NEXT_ASSEMBLY_USAGE_OCCURRENCE"]);
    if placed > 0 {
        // The parts' files, where the file names them (an external source's
        // or a document's name ending like a STEP file).
        let mut files: Vec<&str> = Vec::new();
        for e in g.all().filter(|e| e.has("EXTERNAL_SOURCE") || e.has("DOCUMENT_FILE")) {
            for v in e.attrs().vals.iter().take(2) {
                let Some(name) = g.text(*v) else { continue };
                let lower = name.trim().to_ascii_lowercase();
                let step = [".stp", ".step", ".p21"].iter().any(|x| lower.ends_with(x));
                if step && !files.contains(&name.trim()) {
                    files.push(name.trim());
                }
            }
        }
        let what = format!("{lead}: it holds an assembly structure ({})", plural(placed, "placed component"));
        return match files.as_slice() {
            [] if count(&["DOCUMENT_FILE"]) > 0 => format!("{what} whose parts' geometry is in other files"),
            [] => format!("{what} without geometry"),
            [one] => format!("{what} whose parts' geometry is in another file ('{one}')"),
            [first, rest @ ..] => {
                format!("{what} whose parts' geometry is in {} other files ('{first}', …)", rest.len() + 1)
            }
        };
    }
    let curves = count(&[
        "LINE",
        "CIRCLE",
        "ELLIPSE",
        "HYPERBOLA",
        "PARABOLA",
        "POLYLINE",
        "TRIMMED_CURVE",
        "COMPOSITE_CURVE",
        "B_SPLINE_CURVE",
        "B_SPLINE_CURVE_WITH_KNOTS",
        "BEZIER_CURVE",
    ]);
    let annotations = count(&["ANNOTATION_OCCURRENCE", "ANNOTATION_CURVE_OCCURRENCE", "ANNOTATION_TEXT_OCCURRENCE"]);
    match (curves, annotations) {
        (0, 0) => format!("{lead}: it holds no geometry (only product data and placements)"),
        (c, 0) => format!("{lead}: it holds only curves and points ({})", plural(c, "curve")),
        (c, a) => format!(
            "{lead}: it holds only curves, points and annotations ({}, {})",
            plural(c, "curve"),
            plural(a, "annotation")
        ),
    }
}

/// `n thing` or `n things`.
fn plural(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}
