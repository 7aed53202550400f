//! IGES reader (5.3, fixed 80-column ASCII form): bytes in, [`Model`] out.
//!
//! Sections are split by column 73 ([`lexer`]), the Global section gives the
//! delimiters, units, scale and resolution, every directory entry and its
//! parameters are read with checked counts ([`directory`]), and faces are
//! built from trimmed, bounded and B-rep faces ([`faces`]): curves and
//! surfaces become exact NURBS ([`curves`], [`surfaces`]), trim loops come
//! from parameter-space curves or from projecting model-space ones
//! ([`loops`], [`fit`]). Malformed structure is an [`Error::Iges`] naming the
//! section, line and entity; a face that cannot be read is skipped with a
//! warning. Counts, nesting depths and sizes are capped, so no input can make
//! the reader loop or allocate without bound.

mod brep;
mod curves;
mod directory;
mod faces;
mod fit;
mod lexer;
pub(super) mod loops;
mod subfigures;
pub(super) mod surfaces;
mod untangle;
mod wrap;
mod xform;

use alloc::string::String;
use alloc::vec::Vec;
use glam::DAffine3;

use crate::warning::{Warning, WarningKind};
use crate::{Error, Model};
use directory::{Directory, Entity};
use lexer::{split_sections, Tokenizer, Value};

/// Most directory entries read (two records each).
const MAX_ENTITIES: usize = 2_000_000;
/// Most parameters of one entity (or of the Global section).
const MAX_PARAMS: usize = 20_000_000;
/// Deepest nesting of references (composite curves, transformation chains).
const MAX_DEPTH: usize = 64;
/// Most control points of one curve or surface.
const MAX_CONTROL_POINTS: usize = 4_000_000;

/// The sections of an IGES file, for error messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Global,
    Directory,
    Parameter,
    Terminate,
    Unknown,
}

impl Section {
    fn name(self) -> &'static str {
        match self {
            Self::Global => "Global",
            Self::Directory => "Directory",
            Self::Parameter => "Parameter",
            Self::Terminate => "Terminate",
            Self::Unknown => "file",
        }
    }

    fn from_letter(c: u8) -> Self {
        match c {
            b'G' => Self::Global,
            b'D' => Self::Directory,
            b'P' => Self::Parameter,
            b'T' => Self::Terminate,
            _ => Self::Unknown,
        }
    }
}

/// An [`Error::Iges`].
fn iges_error(section: Section, line: usize, entity: usize, message: impl core::fmt::Display) -> Error {
    Error::Iges { section: section.name(), line, entity, message: alloc::format!("{message}") }
}

/// What the reader forgave, one warning per kind: the first occurrence's
/// message and how many more entities of that kind followed (an entity read
/// twice, as a curve two faces share is, counts once).
#[derive(Default)]
struct Notes {
    kinds: Vec<(&'static str, Warning)>,
    seen: crate::collections::HashSet<(&'static str, usize)>,
}

impl Notes {
    /// Notes `kind` for entity `de` (0: none); `warning` is made only for the first.
    fn note(&mut self, kind: &'static str, de: usize, warning: impl FnOnce() -> Warning) {
        if de != 0 && !self.seen.insert((kind, de)) {
            return;
        }
        match self.kinds.iter_mut().find(|k| k.0 == kind) {
            Some(k) => k.1.more += 1,
            None => self.kinds.push((kind, warning())),
        }
    }

    /// One warning per kind, in the order the kinds were first met.
    fn warnings(&self) -> Vec<Warning> {
        self.kinds.iter().map(|(_, w)| w.clone()).collect()
    }
}

/// What the readers of entities share.
struct Ctx<'a> {
    dir: &'a Directory,
    /// Model space to the output (the Global section's scale).
    world: DAffine3,
    /// Minimum resolution, output units.
    resolution: Option<f64>,
    /// Repairs made while reading entities (see [`Notes`]).
    notes: core::cell::RefCell<Notes>,
}

impl Ctx<'_> {
    /// The entity at directory entry `de`.
    ///
    /// # Errors
    /// No entity there (a bad pointer), or one whose parameter data could not be read.
    fn entity(&self, de: usize) -> Result<&Entity, Error> {
        if let Some(err) = self.dir.get(de).and_then(|e| e.damage.as_ref()) {
            return Err(err.clone());
        }
        self.dir.get(de).ok_or_else(|| {
            iges_error(
                Section::Directory,
                0,
                de,
                alloc::format!(
                    "pointer to directory entry {de}, which does not exist (the file has {})",
                    2 * self.dir.entities.len()
                ),
            )
        })
    }
}

/// Why a file gave no face at all: the entity types it holds instead.
fn no_faces(dir: &Directory) -> String {
    let mut kinds: Vec<(u32, usize)> = Vec::new();
    for e in &dir.entities {
        match kinds.iter_mut().find(|k| k.0 == e.kind) {
            Some(k) => k.1 += 1,
            None => kinds.push((e.kind, 1)),
        }
    }
    crate::sort::by_u64(&mut kinds, |k| crate::sort::pair(u32::MAX - k.1.min(u32::MAX as usize) as u32, k.0));
    let shown: Vec<String> = kinds.iter().take(6).map(|(k, n)| alloc::format!("{n} of type {k}")).collect();
    let more = if kinds.len() > 6 { ", …" } else { "" };
    alloc::format!(
        "no surfaces or faces in the file, only curves, points, annotations or structure (entities: {}{more})",
        shown.join(", ")
    )
}

/// Units, scale and resolution from the Global section.
struct Global {
    param: u8,
    record: u8,
    scale: f64,
    units: String,
    resolution: Option<f64>,
}

impl Default for Global {
    /// The standard's defaults: `,` and `;`, model space scale 1, millimetres.
    fn default() -> Self {
        Self { param: b',', record: b';', scale: 1.0, units: "mm".into(), resolution: None }
    }
}

/// Reads an IGES file.
///
/// Coordinates are divided by the Global section's model space scale and
/// stay in the file's unit (named in [`Model::units`]); [`Model::tolerance`]
/// is the file's minimum resolution. Faces: 144 trimmed and 143 bounded
/// surfaces, 510 faces of 514 shells and 186 solids, bounded 108 planes and
/// surfaces no face uses, read in place or where the 408 instances of a 308
/// subfigure put them; skipped faces, unsupported entities and what was
/// repaired are listed in [`Model::warnings`].
///
/// # Errors
/// [`Error::Iges`] for a malformed file (section, line and entity named),
/// and when no face at all could be read (the first face's error).
pub fn read_iges(bytes: &[u8]) -> Result<Model, Error> {
    let mut sections = split_sections(bytes)?;
    if sections.directory.is_empty() {
        return Err(iges_error(
            Section::Directory,
            0,
            0,
            if sections.global.is_empty() {
                "no Global section and no Directory entries (not an IGES file?)"
            } else {
                "no Directory entries: the file holds no entities"
            },
        ));
    }
    let mut warnings = core::mem::take(&mut sections.notes);
    // Nothing the Global section holds is needed to read the entities: its
    // defaults (delimiters `,` and `;`, scale 1, millimetres) stand in.
    let g = if sections.global.is_empty() {
        warnings.push(Warning::new(WarningKind::NoGlobal));
        Global::default()
    } else {
        global(&sections.global).unwrap_or_else(|e| {
            warnings.push(Warning::new(WarningKind::BadGlobal(e)));
            Global::default()
        })
    };
    let mut dir = Directory::parse(&sections.directory, &sections.parameter, g.param, g.record)?;
    warnings.append(&mut dir.notes);
    if let Some(line) = sections.truncated {
        warnings.push(Warning::new(WarningKind::TruncatedLine { line }));
    }
    check_terminate(&sections, &mut warnings);
    let ctx = Ctx {
        dir: &dir,
        world: DAffine3::from_scale(glam::DVec3::splat(1.0 / g.scale)),
        resolution: g.resolution.map(|r| r / g.scale),
        notes: core::cell::RefCell::default(),
    };
    let mut skipped = Vec::new();
    let (faces, bodies, first_error) = faces::read_faces(&ctx, &mut warnings, &mut skipped);
    warnings.extend(ctx.notes.borrow().warnings());
    if faces.is_empty() {
        return Err(first_error.unwrap_or_else(|| iges_error(Section::Directory, 0, 0, no_faces(&dir))));
    }
    Ok(Model { units: g.units, faces, warnings, tolerance: ctx.resolution, bodies, tessellated: Vec::new(), skipped })
}

/// The Global section: delimiters (fields 1–2), model space scale (13),
/// units flag and name (14, 15), minimum resolution (19).
fn global(records: &[lexer::Record<'_>]) -> Result<Global, Error> {
    let line = records.first().map_or(0, |r| r.line);
    let text: Vec<u8> = records.iter().flat_map(|r| r.data.iter().copied()).collect();
    let mut tok = Tokenizer::new(&text, b',', b';');
    tok.read_delimiters().map_err(|m| iges_error(Section::Global, line, 0, m))?;
    let fields = tok.fields(1024).map_err(|m| iges_error(Section::Global, line, 0, m))?;
    // fields[0] is field 3.
    let field = |n: usize| fields.get(n - 3).cloned().unwrap_or(Value::Empty);
    let real = |n: usize, default: f64| match field(n) {
        Value::Int(i) => i as f64,
        Value::Real(x) => x,
        _ => default,
    };
    let scale = real(13, 1.0);
    let scale = if scale > 0.0 && scale.is_finite() { scale } else { 1.0 };
    let flag = match field(14) {
        Value::Int(i) => i,
        Value::Real(x) => x as i64,
        _ => 0,
    };
    let name = match field(15) {
        Value::Str(s) => Some(s),
        _ => None,
    };
    let units = unit_name(flag, name.as_deref());
    let res = real(19, 0.0);
    let resolution = (res > 0.0 && res.is_finite()).then_some(res);
    Ok(Global { param: tok.param, record: tok.record, scale, units, resolution })
}

/// The unit's short name from the units flag, or the units name when the flag is 3 or absent.
fn unit_name(flag: i64, name: Option<&str>) -> String {
    let from_flag = match flag {
        1 => Some("in"),
        2 => Some("mm"),
        4 => Some("ft"),
        5 => Some("mi"),
        6 => Some("m"),
        7 => Some("km"),
        8 => Some("mil"),
        9 => Some("um"),
        10 => Some("cm"),
        11 => Some("uin"),
        _ => None,
    };
    if let Some(u) = from_flag {
        return u.into();
    }
    let n = name.map(|s| s.trim().to_ascii_lowercase()).unwrap_or_default();
    match n.as_str() {
        "" => "mm".into(),
        "inch" | "in" => "in".into(),
        "mm" | "m" | "cm" | "km" | "ft" | "mi" | "mil" | "um" | "uin" => n,
        other => other.into(),
    }
}

/// Compares the Terminate section's counts with the records found (a
/// mismatch is reported, not fatal: the data itself was complete).
fn check_terminate(s: &lexer::Sections<'_>, warnings: &mut Vec<Warning>) {
    let Some(t) = s.terminate.first() else {
        warnings.push(Warning::new(WarningKind::NoTerminate));
        return;
    };
    let count = |letter: u8| -> Option<usize> {
        let i = t.data.chunks(8).position(|c| c.first() == Some(&letter))?;
        let c = t.data.get(8 * i + 1..8 * i + 8)?;
        core::str::from_utf8(c).ok()?.trim().parse().ok()
    };
    for (letter, found, name) in [
        (b'G', s.global.len(), "Global"),
        (b'D', s.directory.len(), "Directory"),
        (b'P', s.parameter.len(), "Parameter"),
    ] {
        if let Some(n) = count(letter) {
            if n != found {
                let kind = WarningKind::TerminateCount { counted: n, section: name, found };
                warnings.push(Warning::new(kind));
            }
        }
    }
}
