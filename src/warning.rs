//! What a reader or mesher let pass, typed: the face or file entity it
//! concerns and its kind. `Display` is the one-line text the report shows.

use alloc::boxed::Box;
use alloc::string::String;
use core::fmt;

use serde::{Serialize, Serializer};

use crate::error::Error;

/// One warning of a model or report: which face or file entity it concerns
/// (either may be absent) and what happened. Serialized as its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// Index of the model face concerned, if one.
    pub face: Option<usize>,
    /// The file entity concerned, if one.
    pub entity: Option<Entity>,
    /// What happened.
    pub kind: WarningKind,
    /// How many more of the same kind followed and were folded into this one.
    pub more: usize,
}

impl Warning {
    /// A warning of `kind` about the whole model.
    pub fn new(kind: WarningKind) -> Self {
        Self { face: None, entity: None, kind, more: 0 }
    }

    /// A warning of `kind` about model face `face`.
    pub fn face(face: usize, kind: WarningKind) -> Self {
        Self { face: Some(face), ..Self::new(kind) }
    }

    /// A warning of `kind` about file entity `entity`.
    pub fn entity(entity: Entity, kind: WarningKind) -> Self {
        Self { entity: Some(entity), ..Self::new(kind) }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(face) = self.face {
            write!(f, "face {face}: ")?;
        }
        if let Some(e) = &self.entity {
            write!(f, "{e}: ")?;
        }
        write!(f, "{}", self.kind)?;
        if self.more > 0 {
            write!(f, " (and {} more like it)", self.more)?;
        }
        Ok(())
    }
}

/// The JSON report and the JS binding carry a warning as its text.
impl Serialize for Warning {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// A file entity a warning names.
#[derive(Debug, Clone, PartialEq)]
pub enum Entity {
    /// IGES directory entry `de`, of entity type `kind`.
    Iges {
        /// Directory entry number.
        de: usize,
        /// Entity type number.
        kind: u32,
    },
    /// STEP instance `#id`, with its type name and line when given.
    Step {
        /// Instance number.
        id: u64,
        /// e.g. `ADVANCED_FACE`.
        type_name: Option<String>,
        /// 1-based line of the file.
        line: Option<usize>,
    },
}

impl Entity {
    /// STEP instance `#id` of type `type_name`.
    pub fn step(id: u64, type_name: impl Into<String>) -> Self {
        Self::Step { id, type_name: Some(type_name.into()), line: None }
    }

    /// STEP instance `#id`, its type left unsaid.
    pub fn step_id(id: u64) -> Self {
        Self::Step { id, type_name: None, line: None }
    }
}

impl fmt::Display for Entity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Iges { de, kind } => write!(f, "DE {de} (type {kind})"),
            Self::Step { id, type_name, line } => {
                write!(f, "#{id}")?;
                if let Some(t) = type_name {
                    write!(f, " {t}")?;
                }
                if let Some(l) = line {
                    write!(f, " (line {l})")?;
                }
                Ok(())
            }
        }
    }
}

/// What a warning says happened.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum WarningKind {
    // Both readers.
    /// The entity could not be read and was left out.
    Skipped(Error),
    /// A flaw the reader read past, described as the error it would have been.
    Forgiven(Error),
    /// An entity whose data is damaged (the error) was left out.
    EntityDamaged(Error),

    // IGES.
    /// No Global section.
    NoGlobal,
    /// The Global section could not be read (the error).
    BadGlobal(Error),
    /// A line shorter than a record, at the end of the file.
    TruncatedLine {
        /// 1-based line.
        line: usize,
    },
    /// No Terminate section.
    NoTerminate,
    /// The Terminate section's count of a section's lines is not the file's.
    TerminateCount {
        /// The count the Terminate section gives.
        counted: usize,
        /// The section's name.
        section: &'static str,
        /// Lines found.
        found: usize,
    },
    /// Entities of a type this reader does not read.
    Unsupported {
        /// How many.
        count: usize,
        /// Entity type number.
        kind: u32,
        /// What the type is.
        what: &'static str,
    },
    /// Hidden (blanked) surface entities, not shown by the file.
    Hidden {
        /// How many.
        count: usize,
    },
    /// Records written without line breaks, split every 80 columns.
    UnbrokenRecords {
        /// 1-based line of the file.
        line: usize,
        /// Records in it.
        records: usize,
        /// The line number the first of them was read as.
        first: usize,
    },
    /// A record pushed past column 80 by blanks before it.
    ShiftedRecord {
        /// 1-based line.
        line: usize,
    },
    /// A section letter in lower case.
    LowerCaseSection {
        /// 1-based line.
        line: usize,
    },
    /// Trim curves fitted only to within the sample limit.
    TrimFitLimit {
        /// How many.
        curves: usize,
    },
    /// Parameter-space trim curves that disagree with the model-space ones.
    TrimSpacesDisagree,
    /// A trim loop's gap between curves, closed by a line.
    TrimGapClosed {
        /// The largest gap.
        gap: f64,
    },
    /// A trim loop crossing itself where edges meet tangentially.
    TrimSelfCrossing {
        /// How many times.
        crossings: usize,
    },

    // STEP.
    /// A face that could not be moved into place (the error).
    FaceNotPlaced(crate::nurbs::NurbsError),
    /// A closed shell with edges that bound only one of its faces.
    ShellOpen {
        /// How many such edges.
        edges: usize,
    },
    /// An edge loop running along its edges both ways.
    LoopSlit,
    /// Edges used out and straight back inside a face.
    LoopSpikes {
        /// How many.
        edges: usize,
    },
    /// An edge loop's gap between edges, bridged by a line.
    LoopGapBridged {
        /// The largest gap.
        gap: f64,
    },
    /// An edge whose vertex lies off its curve; the curve's end is used.
    VertexOffCurve {
        /// The start vertex (else the end).
        start: bool,
        /// Whether the file puts the vertex at two corners.
        shared: bool,
        /// Its distance from the curve.
        gap: f64,
    },
    /// An edge's vertex the file does not define; the neighbouring edge's point is used.
    VertexFromNeighbour {
        /// The end vertex (else the start).
        end: bool,
        /// The vertex's instance number.
        vertex: u64,
        /// The loop whose neighbouring edge gave the point.
        lp: u64,
    },
    /// Several things about one entity, in one line.
    Joined(alloc::vec::Vec<WarningKind>),
    /// An assembly past the depth or instance limits.
    AssemblyLimit {
        /// Deepest level read.
        depth: usize,
        /// Most instances read.
        instances: usize,
    },
    /// A representation item that is not defined.
    ItemUndefined {
        /// Its instance number.
        item: u64,
    },
    /// A shape in no representation, read in place.
    NotInRepresentation,
    /// A length unit not understood.
    LengthUnitUnknown,
    /// Tessellated items past the face or triangle limits.
    TessellatedLimit {
        /// Most faces.
        faces: usize,
        /// Most triangles.
        triangles: usize,
    },
    /// Tessellated triangles that name one point twice.
    RepeatedPointTriangles {
        /// How many.
        count: usize,
    },
    /// A tessellated face with normals of no length or not three numbers.
    NormalsNotVectors,
    /// A tessellated face with a count of normals that fits no rule.
    NormalsCount {
        /// Normals given.
        normals: usize,
        /// Points.
        points: usize,
    },
    /// An item of a kind not supported.
    ItemUnsupported,

    // Meshing.
    /// Faces of the file the reader could not build.
    UnreadFaces {
        /// How many.
        count: usize,
        /// Open edges along their borders.
        holes: usize,
    },
    /// Loops enclosing no area, left unfilled in quality mode.
    QualityLoopsUnfilled {
        /// How many.
        loops: usize,
    },
    /// A face quality mode could not mesh.
    QualityNotMeshed(QualityError),
    /// A face the step-ratio test flagged (paper 001), and what became of it.
    PoorlyParameterized {
        /// The step ratio.
        ratio: f64,
        /// What became of it.
        outcome: Reparameterized,
    },
    /// A face that could not be meshed.
    FaceSkipped(String),
    /// A face skipped because the triangle budget was spent (the limit's text).
    BudgetSpent(String),
    /// A face that produced no triangles.
    NoTriangles {
        /// A strip narrower than the sewing distance, its sides sewn into one border.
        pinched: bool,
    },
    /// Triangles still over the limits when refinement stopped.
    Unproven {
        /// How many.
        count: usize,
        /// Stopped by the triangle budget (else by the minimum edge length).
        budget: bool,
    },
    /// Triangles turning more than the angle limit where the surface folds.
    Creased {
        /// How many.
        count: usize,
    },
    /// Two faces whose borders lie farther apart than sewing closes.
    FacesApart {
        /// The two faces.
        faces: (usize, usize),
        /// Their distance.
        width: f64,
        /// The sewing distance.
        sewing: f64,
    },
    /// A trimmed face in a build without the trimmed mesher.
    NeedsStd,
    /// Trim loops mended before meshing.
    LoopsMended(Mended),
    /// A grid direction stopped at its line cap.
    GridCapped {
        /// `"u"` or `"v"`.
        along: &'static str,
        /// The cap.
        cap: usize,
    },
    /// A rebuilt face that lost to its original (under `auto`).
    RebuildLost(RebuildLoss),
    /// Tessellated faces passed through without an exact surface.
    TessellatedFaces {
        /// How many.
        count: usize,
        /// Their triangles.
        triangles: usize,
    },
    /// Tessellated triangles dropped as malformed.
    TessellatedDropped {
        /// How many.
        count: usize,
    },

    // Mesh repair (paper 002).
    /// Welding would make the mesh non-manifold (the error); not welded.
    NotWelded {
        /// The weld tolerance, relative to the diagonal.
        tolerance: f64,
        /// Why welding fails.
        why: Error,
    },
    /// Degenerate triangles left in place.
    DegenerateLeft {
        /// How many.
        count: usize,
    },
    /// An open input, whose boundary stays open.
    OpenInput {
        /// Its free edges.
        free_edges: usize,
    },
    /// Components turned outward.
    InsideOut {
        /// How many.
        count: usize,
        /// Of how many components.
        components: usize,
    },
    /// Vertices moved to resolve coincidences.
    Perturbed {
        /// By up to this share of the diagonal.
        size: f64,
    },
    /// Triangle pairs touching in a way not handled.
    UnhandledContacts {
        /// How many pairs.
        pairs: usize,
    },
    /// Components with no triangle on the outside, left out.
    Unseeded {
        /// How many.
        components: usize,
    },
    /// Triangles kept or dropped whole (not split along their segments).
    SplitFallbacks {
        /// How many.
        triangles: usize,
    },
    /// Nothing valid was found.
    EmptyResult,
    /// The result is not a clean 2-manifold.
    NotManifold {
        /// Edges of more than two triangles.
        nonmanifold: usize,
        /// Edges whose triangles disagree.
        misoriented: usize,
    },

    // Surface fitting (paper 004).
    /// Duplicate points merged.
    DuplicatesMerged {
        /// How many.
        count: usize,
        /// Closer than this.
        distance: f64,
    },
    /// The points lie on one plane.
    Planar,
    /// Gaps of the triangle net left open.
    NetGaps {
        /// How many.
        count: usize,
    },
    /// Points in no triangle of the net.
    PointsUnused {
        /// How many.
        count: usize,
    },
    /// Polygons that could not be filled.
    PolygonsUnfilled {
        /// How many.
        count: usize,
    },
    /// Patches at the split limit.
    SplitLimit {
        /// The limit.
        level: usize,
    },
}

/// What paper 001's rebuild of a flagged face came to.
#[derive(Debug, Clone, PartialEq)]
pub enum Reparameterized {
    /// Rebuilt from this many samples, within this distance of the original.
    Rebuilt {
        /// Samples along u and v.
        samples: [usize; 2],
        /// Largest distance from the original.
        fit_error: f64,
    },
    /// Not rebuilt; meshed as it is (why).
    MeshedAsIs(RebuildError),
    /// Not rebuilt; kept as it is (why).
    KeptAsIs(RebuildError),
}

/// Why a rebuilt face lost to its original.
#[derive(Debug, Clone, PartialEq)]
pub enum RebuildLoss {
    /// It gave no triangles.
    NoTriangles,
    /// It did not mesh (the error).
    DidNotMesh(Error),
    /// It left more triangles over the limits.
    Unproven(usize),
    /// It took more triangles (the rebuild's, the original's).
    MoreTriangles(usize, usize),
    /// Its 1st-percentile angle was lower, degrees (the rebuild's, the original's).
    WorseShaped(f64, f64),
}

/// How trim loops that crossed, folded or enclosed no area were mended.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Mended {
    /// Points where two segments crossed, touched or overlapped.
    pub crossings: usize,
    /// Loops of the input that came out changed or were merged.
    pub loops_before: usize,
    /// Loops after mending.
    pub loops_after: usize,
    /// Pieces dropped for enclosing no area.
    pub dropped: usize,
    /// Whether the loops were cut and rejoined (false when only whole
    /// loops of no area were dropped).
    pub rejoined: bool,
    /// Whole loops of the file dropped before mending for enclosing no area.
    pub flat: usize,
}

impl fmt::Display for Mended {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        if self.rejoined {
            if self.crossings > 0 {
                write!(f, "trim loops crossed or touched at {} places", self.crossings)?;
            } else {
                write!(f, "trim loops folded back on themselves or lay outside the outer loop")?;
            }
            let (before, after) = (self.loops_before, self.loops_after);
            write!(f, "; mended to the region they wind round ({before} loop{} became {after}", plural(before))?;
            if self.dropped > 0 {
                write!(f, ", {} piece{} of no area dropped", self.dropped, plural(self.dropped))?;
            }
            write!(f, ")")?;
            if self.flat > 0 {
                write!(f, "; ")?;
            }
        }
        if self.flat > 0 {
            write!(f, "{} trim loop{} enclosing no area dropped", self.flat, plural(self.flat))?;
        }
        Ok(())
    }
}

impl fmt::Display for RebuildLoss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoTriangles => write!(f, "the rebuilt face gave no triangles"),
            Self::DidNotMesh(e) => write!(f, "the rebuilt face did not mesh ({e})"),
            Self::Unproven(n) => write!(f, "the rebuilt face left {n} triangles unproven"),
            Self::MoreTriangles(nt, ot) => write!(f, "the rebuilt face took more triangles ({nt} against {ot})"),
            Self::WorseShaped(a, b) => write!(
                f,
                "the rebuilt face's triangles were worse shaped (1st-percentile angle {a:.1}° against {b:.1}°)"
            ),
        }
    }
}

impl fmt::Display for WarningKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Each kind goes to the text of its stage (the groups of the enum).
        match self {
            Self::Skipped(_)
            | Self::Forgiven(_)
            | Self::EntityDamaged(_)
            | Self::NoGlobal
            | Self::BadGlobal(_)
            | Self::TruncatedLine { .. }
            | Self::NoTerminate
            | Self::TerminateCount { .. }
            | Self::Unsupported { .. }
            | Self::Hidden { .. }
            | Self::UnbrokenRecords { .. }
            | Self::ShiftedRecord { .. }
            | Self::LowerCaseSection { .. }
            | Self::TrimFitLimit { .. }
            | Self::TrimSpacesDisagree
            | Self::TrimGapClosed { .. }
            | Self::TrimSelfCrossing { .. } => self.fmt_reader(f),
            Self::FaceNotPlaced(_)
            | Self::ShellOpen { .. }
            | Self::LoopSlit
            | Self::LoopSpikes { .. }
            | Self::LoopGapBridged { .. }
            | Self::VertexOffCurve { .. }
            | Self::VertexFromNeighbour { .. }
            | Self::Joined(_)
            | Self::AssemblyLimit { .. }
            | Self::ItemUndefined { .. }
            | Self::NotInRepresentation
            | Self::LengthUnitUnknown
            | Self::TessellatedLimit { .. }
            | Self::RepeatedPointTriangles { .. }
            | Self::NormalsNotVectors
            | Self::NormalsCount { .. }
            | Self::ItemUnsupported => self.fmt_step(f),
            Self::UnreadFaces { .. }
            | Self::QualityLoopsUnfilled { .. }
            | Self::QualityNotMeshed(_)
            | Self::PoorlyParameterized { .. }
            | Self::FaceSkipped(_)
            | Self::BudgetSpent(_)
            | Self::NoTriangles { .. }
            | Self::Unproven { .. }
            | Self::Creased { .. }
            | Self::FacesApart { .. }
            | Self::NeedsStd
            | Self::LoopsMended(_)
            | Self::GridCapped { .. }
            | Self::RebuildLost(_)
            | Self::TessellatedFaces { .. }
            | Self::TessellatedDropped { .. } => self.fmt_meshing(f),
            Self::NotWelded { .. }
            | Self::DegenerateLeft { .. }
            | Self::OpenInput { .. }
            | Self::InsideOut { .. }
            | Self::Perturbed { .. }
            | Self::UnhandledContacts { .. }
            | Self::Unseeded { .. }
            | Self::SplitFallbacks { .. }
            | Self::EmptyResult
            | Self::NotManifold { .. } => self.fmt_repair(f),
            Self::DuplicatesMerged { .. }
            | Self::Planar
            | Self::NetGaps { .. }
            | Self::PointsUnused { .. }
            | Self::PolygonsUnfilled { .. }
            | Self::SplitLimit { .. } => self.fmt_fit(f),
        }
    }
}

impl WarningKind {
    /// The text of a kind both readers or the IGES reader let pass; nothing for the others, which
    /// [`fmt::Display::fmt`] routes elsewhere.
    fn fmt_reader(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Skipped(e) => write!(f, "skipped: {e}"),
            Self::Forgiven(e) => write!(f, "{e}"),
            Self::EntityDamaged(e) => write!(f, "{e}; the entity is skipped"),
            Self::NoGlobal => write!(f, "no Global section: the default delimiters, scale and unit are used"),
            Self::BadGlobal(e) => write!(f, "{e}; the default delimiters, scale and unit are used"),
            Self::TruncatedLine { line } => write!(f, "line {line} is cut short (file truncated?): ignored"),
            Self::NoTerminate => write!(f, "no Terminate section (file truncated?)"),
            Self::TerminateCount { counted, section, found } => {
                write!(f, "the Terminate section counts {counted} {section} lines, the file has {found}")
            }
            Self::Unsupported { count, kind, what } => {
                write!(f, "{count} entities of type {kind} ({what}) skipped: not supported")
            }
            Self::Hidden { count } => {
                write!(f, "{count} hidden (blanked) surface entities skipped: the file does not show them")
            }
            Self::UnbrokenRecords { line, records, first } => write!(
                f,
                "line {line}: {records} records of 80 columns with no line breaks between them; read as lines {first}..{}",
                first + records - 1
            ),
            Self::ShiftedRecord { line } => {
                write!(f, "line {line}: a record pushed past column 80 by blanks before it; read without them")
            }
            Self::LowerCaseSection { line } => {
                write!(f, "line {line}: the section letter in lower case; read as upper case")
            }
            Self::TrimFitLimit { curves } => write!(f, "{curves} trim curves fitted to within the sample limit only"),
            Self::TrimSpacesDisagree => {
                write!(f, "parameter-space trim curves disagree with the model-space ones; projected instead")
            }
            Self::TrimGapClosed { gap } => write!(f, "trim loop with a gap of {gap:.3e} between curves, closed by a line"),
            Self::TrimSelfCrossing { crossings } => {
                write!(f, "trim loop crossed itself {crossings} times (edges meeting tangentially); cut there")
            }
            _ => Ok(()),
        }
    }

    /// The text of a kind the STEP reader lets pass; nothing for the others, which
    /// [`fmt::Display::fmt`] routes elsewhere.
    fn fmt_step(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::FaceNotPlaced(e) => write!(f, "a face could not be placed: {e}"),
            Self::ShellOpen { edges } => {
                write!(f, "{edges} of its edges bound only one of its faces; it is open, its mesh will have a border")
            }
            Self::LoopSlit => write!(f, "runs along its edges both ways (a slit in the face); ignored"),
            Self::LoopSpikes { edges } => {
                write!(f, "{edges} edge(s) run out and straight back inside the face; left out")
            }
            Self::LoopGapBridged { gap } => write!(f, "a gap of {gap:.3e} between its edges, bridged by a line"),
            Self::VertexOffCurve { start, shared, gap } => write!(
                f,
                "its {} vertex{} lies {gap:.3e} from its curve; the curve's end is used",
                if *start { "start" } else { "end" },
                if *shared { ", which the file puts at two corners," } else { "" }
            ),
            Self::VertexFromNeighbour { end, vertex, lp } => write!(
                f,
                "its {} vertex #{vertex} is not defined; the point its neighbour in loop #{lp} gives is used",
                if *end { "end" } else { "start" }
            ),
            Self::Joined(kinds) => {
                for (i, k) in kinds.iter().enumerate() {
                    if i > 0 {
                        write!(f, "; ")?;
                    }
                    write!(f, "{k}")?;
                }
                Ok(())
            }
            Self::AssemblyLimit { depth, instances } => write!(
                f,
                "assembly deeper than {depth} levels or with more than {instances} instances: the rest is skipped"
            ),
            Self::ItemUndefined { item } => write!(f, "item #{item} is not defined; skipped"),
            Self::NotInRepresentation => write!(f, "not in any representation; read in place"),
            Self::LengthUnitUnknown => write!(f, "length unit not understood; millimetres assumed"),
            Self::TessellatedLimit { faces, triangles } => write!(
                f,
                "more than {faces} faces or {triangles} tessellated triangles (after assembly instancing); \
                 this placement and the rest are skipped"
            ),
            Self::RepeatedPointTriangles { count } => {
                write!(f, "{count} triangles name one point twice (no area); left out")
            }
            Self::NormalsNotVectors => {
                write!(f, "a normal of no length or not three numbers; its normals are left out")
            }
            Self::NormalsCount { normals, points } => {
                write!(f, "{normals} normals for {points} points (expected 0, 1 or {points}); its normals are left out")
            }
            Self::ItemUnsupported => write!(f, "not supported; skipped"),
            _ => Ok(()),
        }
    }

    /// The text of a kind the meshers let pass; nothing for the others, which
    /// [`fmt::Display::fmt`] routes elsewhere.
    fn fmt_meshing(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnreadFaces { count, holes: 0 } => {
                write!(f, "{count} face(s) of the file could not be read: the mesh lacks them")
            }
            Self::UnreadFaces { count, holes } => write!(
                f,
                "{count} face(s) of the file could not be read: the mesh has holes there, \
                 {holes} open edges along their borders (counted as cracks)"
            ),
            Self::QualityLoopsUnfilled { loops } => write!(f, "{loops} loops enclosing no area left unfilled"),
            Self::QualityNotMeshed(why) => write!(f, "not meshed in quality mode: {why}"),
            Self::PoorlyParameterized { ratio, outcome } => {
                write!(f, "poorly parameterized (step ratio {ratio:.1}), ")?;
                match outcome {
                    Reparameterized::Rebuilt { samples, fit_error } => write!(
                        f,
                        "rebuilt from {} x {} points within {fit_error:.2e} of the original",
                        samples[0], samples[1]
                    ),
                    Reparameterized::MeshedAsIs(why) => write!(f, "meshed as it is: {why}"),
                    Reparameterized::KeptAsIs(why) => write!(f, "kept as it is: {why}"),
                }
            }
            Self::FaceSkipped(why) => write!(f, "skipped: {why}"),
            Self::BudgetSpent(m) => write!(f, "skipped, the triangle budget is spent ({m})"),
            Self::NoTriangles { pinched: false } => write!(f, "produced no triangles"),
            Self::NoTriangles { pinched: true } => write!(
                f,
                "produced no triangles: a strip narrower than the sewing distance, \
                 its sides sewn into one border by its neighbours"
            ),
            Self::Unproven { count, budget } => write!(
                f,
                "{count} triangles still exceed the limits ({})",
                if *budget { "triangle budget reached" } else { "edges at the minimum length" }
            ),
            Self::Creased { count } => write!(
                f,
                "{count} triangles turn more than the angle limit where the surface folds or \
                 creases; not split below a tenth of the tolerance (below the tolerance where it turns \
                 past a right angle)"
            ),
            Self::FacesApart { faces: (a, b), width, sewing } => write!(
                f,
                "faces {a} and {b}: their borders lie {width:.3e} apart where they meet, farther than sewing closes \
                 ({sewing:.3e}); the crack between them is left open"
            ),
            Self::NeedsStd => write!(f, "trimmed faces need the default `std` feature (CDT); skipped"),
            Self::LoopsMended(m) => write!(f, "{m}"),
            Self::GridCapped { along, cap } => write!(
                f,
                "the grid along {along} stopped at its cap of {cap} lines (the surface's \
                 normals or sag never settle there); refinement still holds the tolerance"
            ),
            Self::RebuildLost(why) => write!(f, "{why}; meshed the original"),
            Self::TessellatedFaces { count: 1, triangles } => write!(
                f,
                "1 tessellated face ({triangles} triangles) without an exact surface: their triangles are the \
                 file's, and the deviation figures cover the other faces only"
            ),
            Self::TessellatedFaces { count, triangles } => write!(
                f,
                "{count} tessellated faces ({triangles} triangles) without an exact surface: their triangles are \
                 the file's, and the deviation figures cover the other faces only"
            ),
            Self::TessellatedDropped { count } => write!(
                f,
                "tessellated faces: {count} triangles that name a point twice, one past the points or one not \
                 finite left out"
            ),
            _ => Ok(()),
        }
    }

    /// The text of a kind mesh repair (paper 002) lets pass; nothing for the others, which
    /// [`fmt::Display::fmt`] routes elsewhere.
    fn fmt_repair(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotWelded { tolerance, why } => write!(
                f,
                "welding within {tolerance:e} of the diagonal would make the mesh non-manifold ({why}); vertices were not welded"
            ),
            Self::DegenerateLeft { count } => {
                write!(f, "{count} degenerate triangles could not be removed without breaking the manifold")
            }
            Self::OpenInput { free_edges } => write!(
                f,
                "the input is open ({free_edges} free edges): its boundary stays open and growth stops there"
            ),
            Self::InsideOut { count, components } => write!(
                f,
                "{count} of {components} components enclosed a negative volume (inside out) and were turned outward"
            ),
            Self::Perturbed { size } => write!(
                f,
                "the arrangement had unresolved coincidences; vertices were moved by up to {size:e} of the diagonal"
            ),
            Self::UnhandledContacts { pairs } => write!(
                f,
                "{pairs} triangle pairs touch or overlap in a way not handled (coplanar, or a vertex exactly on another triangle); left as they are"
            ),
            Self::Unseeded { components } => write!(
                f,
                "{components} components had no triangle on the outside of the enclosed space and were left out"
            ),
            Self::SplitFallbacks { triangles } => write!(
                f,
                "{triangles} triangles could not be split along their segments (points closer than rounding separates) and were kept or dropped whole"
            ),
            Self::EmptyResult => write!(f, "nothing valid was found: the result is empty"),
            Self::NotManifold { nonmanifold, misoriented } => write!(
                f,
                "the result is not a clean 2-manifold: {nonmanifold} edges of more than two triangles, {misoriented} edges whose triangles disagree"
            ),
            _ => Ok(()),
        }
    }

    /// The text of a kind surface fitting (paper 004) lets pass; nothing for the others, which
    /// [`fmt::Display::fmt`] routes elsewhere.
    fn fmt_fit(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DuplicatesMerged { count, distance } => {
                write!(f, "{count} duplicate point(s) merged (closer than {distance:.3e})")
            }
            Self::Planar => {
                write!(f, "the points lie on one plane: the fit is the flat region of that plane they span")
            }
            Self::NetGaps { count } => write!(f, "{count} gap(s) of the triangle net left open"),
            Self::PointsUnused { count } => {
                write!(f, "{count} point(s) are in no triangle of the net and are not interpolated")
            }
            Self::PolygonsUnfilled { count } => write!(f, "{count} polygon(s) could not be filled and leave holes"),
            Self::SplitLimit { level } => {
                write!(f, "some patches hit the split limit of {level} and may exceed the tolerance")
            }
            _ => Ok(()),
        }
    }
}

/// Why quality mode (paper 003) could not mesh a face, or the model.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum QualityError {
    /// The boundary curves alone need more nodes than the budget at this size.
    BoundaryBudget {
        /// The node budget.
        budget: usize,
        /// The element size.
        size: f64,
    },
    /// A loop divided into fewer than three nodes.
    FewLoopNodes {
        /// The loop.
        lp: usize,
        /// Its nodes.
        nodes: usize,
    },
    /// A loop that encloses no area.
    LoopNoArea {
        /// The face.
        face: usize,
        /// The loop.
        lp: usize,
    },
    /// The looping method split past its limit.
    TooManySplits,
    /// The looping method reached its node limit.
    NodeLimit {
        /// The limit.
        max: usize,
    },
    /// A loop with no splitting line inside it.
    NoSplit {
        /// Its nodes.
        nodes: usize,
    },
    /// No cut line joins a hole to the outer loop.
    NoCut,
    /// The triangulation library refused the boundary (its report).
    Triangulation(String),
    /// Boundary loops that cross.
    LoopsCross,
    /// Boundary nodes at one point.
    NodesCoincide,
    /// Delaunay refinement in a build without `std`.
    NeedsStd,
}

impl fmt::Display for QualityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BoundaryBudget { budget, size } => write!(
                f,
                "the boundary curves alone need more than {budget} nodes at size {size:.4e}; choose a larger size"
            ),
            Self::FewLoopNodes { lp, nodes } => write!(f, "loop {lp} has {nodes} boundary nodes; it encloses no area"),
            Self::LoopNoArea { face, lp } => write!(f, "face {face}: loop {lp} encloses no area"),
            Self::TooManySplits => write!(f, "the looping method did not finish (too many splits)"),
            Self::NodeLimit { max } => write!(f, "the looping method reached the limit of {max} nodes"),
            Self::NoSplit { nodes } => write!(f, "a loop of {nodes} nodes has no splitting line inside it"),
            Self::NoCut => write!(f, "no cut line joins a hole to the outer loop"),
            Self::Triangulation(e) => write!(f, "triangulation failed: {e}"),
            Self::LoopsCross => write!(f, "boundary loops cross"),
            Self::NodesCoincide => write!(f, "boundary nodes coincide"),
            Self::NeedsStd => write!(f, "Delaunay refinement needs the `std` feature"),
        }
    }
}

/// Why an interpolation could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum InterpError {
    /// Fewer than two points.
    TooFewPoints,
    /// Parameters not strictly increasing (coincident points along every row).
    Degenerate,
    /// A zero pivot: the collocation matrix is singular.
    Singular,
}

impl fmt::Display for InterpError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::TooFewPoints => "fewer than two interpolation points",
            Self::Degenerate => "interpolation points coincide (no parameter spacing)",
            Self::Singular => "the interpolation system is singular",
        })
    }
}

/// Why paper 001's rebuild of a face failed (the face is then meshed or kept as it is).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum RebuildError {
    /// The interpolation could not be built.
    Interp(InterpError),
    /// The rebuilt surface has points that are not finite.
    NotFinite,
    /// The rebuilt surface stays too far from the original at the sample limit.
    TooFar {
        /// Its distance.
        error: f64,
        /// Samples along u.
        n: usize,
        /// Samples along v.
        m: usize,
        /// The limit.
        limit: f64,
    },
    /// A trim curve's rebuild stays too far from the original curve.
    CurveTooFar {
        /// Its distance.
        error: f64,
        /// The goal.
        goal: f64,
    },
    /// In trim loop `index`.
    Loop {
        /// The loop.
        index: usize,
        /// What failed.
        why: Box<RebuildError>,
    },
    /// In trim curve `index` of a loop.
    Curve {
        /// The curve.
        index: usize,
        /// What failed.
        why: Box<RebuildError>,
    },
}

impl fmt::Display for RebuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Interp(e) => write!(f, "{e}"),
            Self::NotFinite => write!(f, "the rebuilt surface is not finite"),
            Self::TooFar { error, n, m, limit } => write!(
                f,
                "the rebuilt surface stays {error:.3e} from the original at {n} × {m} samples (limit {limit:.3e})"
            ),
            Self::CurveTooFar { error, goal } => {
                write!(f, "stays {error:.3e} from the original trim curve (goal {goal:.3e})")
            }
            Self::Loop { index, why } => write!(f, "loop {index}: {why}"),
            Self::Curve { index, why } => write!(f, "curve {index}: {why}"),
        }
    }
}

impl From<InterpError> for RebuildError {
    fn from(e: InterpError) -> Self {
        Self::Interp(e)
    }
}

#[cfg(test)]
mod tests {
    use super::WarningKind;
    use alloc::string::ToString;

    /// Each kind is routed to its stage's text: none comes out empty, and
    /// one with a count names it.
    #[test]
    fn every_stage_gives_its_kinds_a_text() {
        let plain = [
            WarningKind::NoGlobal,
            WarningKind::NoTerminate,
            WarningKind::TrimSpacesDisagree,
            WarningKind::LoopSlit,
            WarningKind::NotInRepresentation,
            WarningKind::LengthUnitUnknown,
            WarningKind::NormalsNotVectors,
            WarningKind::ItemUnsupported,
            WarningKind::NeedsStd,
            WarningKind::NoTriangles { pinched: false },
            WarningKind::EmptyResult,
            WarningKind::Planar,
        ];
        for k in plain {
            assert!(!k.to_string().is_empty(), "{k:?}");
        }
        let counted = [
            WarningKind::TruncatedLine { line: 4321 },
            WarningKind::ShellOpen { edges: 4321 },
            WarningKind::UnreadFaces { count: 4321, holes: 0 },
            WarningKind::Creased { count: 4321 },
            WarningKind::DegenerateLeft { count: 4321 },
            WarningKind::NetGaps { count: 4321 },
            WarningKind::SplitLimit { level: 4321 },
        ];
        for k in counted {
            assert!(k.to_string().contains("4321"), "{k:?}: {k}");
        }
    }
}
