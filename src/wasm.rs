//! The JavaScript door (wasm-bindgen): JS values in, core types through
//! [`crate::mesh_instanced`], typed arrays out. No algorithm lives here.
//!
//! Options come in through serde-wasm-bindgen (every key must be known,
//! every value of its type; a bad one is an [`OptionError`]); reports leave
//! as JS objects serialized straight from the core's structs, the typed
//! arrays beside them passed through as they are.
//!
//! Errors are thrown as JS `Error` objects whose message is the
//! [`crate::Error`] `Display` text, the same line the command line prints.
//!
//! `tests/wasm_node.rs` compiles this file a second time (`#[path]`) to call
//! it from Rust: there `cfg(test)` is set and the exports are left off, so the
//! two copies do not clash at link time.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use js_sys::{Array, Float32Array, Function, Uint32Array};
use serde::de::{DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::Serialize;
use wasm_bindgen::prelude::*;

use crate::{edge_lines, flatten, mesh_instanced, mm_per_unit, read_model, read_step_parts, Assembly, EdgeLines};
#[cfg(feature = "fit")]
use crate::{fit_points, read_points, FitOptions, FitReport, FitResult, PointFormat};
#[cfg(feature = "repair")]
use crate::{offset_mesh, read_mesh, repair_mesh_timed, Bucketing, MeshFormat, RepairOptions, RepairReport};
use crate::{Error, Format, InstancedResult, Mesh, MeshMode, MeshOptions, OptionsError, QualityMethod, Report, Units};
// `tests/wasm_node.rs` compiles this file into a crate where `crate::` is the
// test itself, which does not import this name; take it from the library there.
#[cfg(not(test))]
use crate::Reparam;
#[cfg(test)]
use surfmesh::Reparam;

#[cfg_attr(not(test), wasm_bindgen(typescript_custom_section))]
#[cfg_attr(test, allow(dead_code))]
const TS_MESH: &str = r#"
/** Options of `mesh`; every field is optional. Lengths are in model units, angles in radians. */
export interface MeshOptions {
  /** Absolute chordal tolerance (exclusive with toleranceRel). */
  tolerance?: number;
  /** Chordal tolerance as a fraction of the model's bounding-box diagonal (default 1e-3). */
  toleranceRel?: number;
  /** Largest normal turn across one triangle, radians (default 0.5). */
  angle?: number;
  /** Longest triangle edge allowed. */
  maxEdge?: number;
  /** Edges at or below this length are never split. */
  minEdge?: number;
  /** Triangle budget; refinement stops with a warning past it. */
  maxTriangles?: number;
  /** Rebuild poorly parameterized faces first: "auto" (default: flagged faces, a rebuild kept where it wins), "off", "force". */
  reparam?: "auto" | "off" | "force";
  /**
   * "fast" (default): fewest triangles within the tolerance; "quality": near-equilateral triangles of
   * size H (paper 003; in the full build, surfmesh/full, only).
   */
  mode?: "fast" | "quality";
  /** Quality mode: element size H in model units (exclusive with sizeRel). */
  size?: number;
  /** Quality mode: element size as a fraction of the model's bounding-box diagonal (default 0.02). */
  sizeRel?: number;
  /** Quality mode: "looping" (default, paper 003), "delaunay" (spade's refinement) or "best" (both, better per face). */
  method?: "looping" | "delaunay" | "best";
  /**
   * Fast mode: [index, count] meshes only share `index` of `count` of the work, so that `count`
   * workers can mesh one model side by side: the distinct parts of an assembly when it has at
   * least `count` of them, else the bodies of each part. What a share does not mesh comes back
   * empty (count 0 in faceRanges); the shares together are the whole mesh.
   */
  share?: [number, number];
  /**
   * Length unit of the result: "file" (default: the file's own unit, nothing scaled), "mm", "cm",
   * "m", "in" or "ft". The mesh is scaled into it, with the report's tolerance and deviations;
   * absolute options (tolerance, maxEdge, minEdge, size) are taken in it too.
   */
  units?: "file" | "mm" | "cm" | "m" | "in" | "ft";
  /**
   * false (default): each distinct part is meshed once and returned in `meshes`, placed by
   * `instances`; true: one merged mesh of every face in the file's order (FlatMeshOutput).
   */
  flatten?: boolean;
  /** Also print every warning of the report with console.warn (default false). */
  consoleWarnings?: boolean;
}

/** One face the re-parameterization test flagged (paper 001). */
export interface ReparamFace {
  /** The model's face. */
  face: number;
  /** Its step ratio: how unevenly its parameters cover it. */
  ratio: number;
  /** Whether it was rebuilt (else meshed as it is, a warning says why). */
  rebuilt: boolean;
  /** Samples of the rebuild along u and v. */
  samples: [number, number];
  /** Largest distance from the rebuild to the original surface. */
  fit_error: number;
}

/** Quality mode's own measures (paper 003). */
export interface QualityReport {
  /** Element size H used, model units. */
  size: number;
  /** Faces filled by the looping method. */
  faces_looping: number;
  /** Faces filled by Delaunay refinement. */
  faces_delaunay: number;
  /** Fraction of triangles whose smallest angle is at least 25 degrees. */
  good_angle_fraction: number;
  /** Fraction of edges between 0.7 H and 1.4 H long. */
  edge_band_fraction: number;
  /** Shortest edge over H. */
  edge_ratio_min: number;
  /** Mean edge length over H. */
  edge_ratio_mean: number;
  /** Longest edge over H. */
  edge_ratio_max: number;
}

/** What a mesh run measured (the command line's JSON report). Lengths are in `units`. */
export interface Report {
  /** Length unit of the mesh and of every length here ("mm", "in", ...). */
  units: string;
  /** Absolute chordal tolerance used. */
  tolerance: number;
  /** Angle limit used, radians. */
  angle: number;
  /** Faces in the model. */
  faces: number;
  /** Faces of the file the reader could not build (each with a warning), not in `faces`. */
  faces_unread: number;
  /** Faces that produced no triangles (each with a warning). */
  faces_skipped: number;
  /** Faces the file gives as triangles only (STEP tessellated faces); the deviations do not cover them. */
  faces_tessellated: number;
  /** Sets of faces that share no border (solids, sheets, assembly parts). */
  bodies: number;
  /** Triangles of the whole model (every instance counted). */
  triangles: number;
  /** Vertices of the whole model (every instance counted, per-face copies counted). */
  vertices: number;
  /** Largest measured distance from the mesh to the exact surfaces. */
  max_deviation: number;
  /** Mean of the measured distances. */
  mean_deviation: number;
  /** Smallest triangle angle, degrees. */
  min_angle_deg: number;
  /** 1st-percentile triangle angle, degrees. */
  p1_angle_deg: number;
  /** Cracks: one-triangle edges after welding that are not on the model's open boundary. */
  free_edges: number;
  /** All one-triangle edges after welding. */
  boundary_edges: number;
  /** Edges with more than two triangles. */
  nonmanifold_edges: number;
  /** Triangles whose facet normal opposes the surface normal. */
  inverted_triangles: number;
  /** Largest normal turn across one triangle, radians. */
  max_normal_turn: number;
  /** Meshing time, milliseconds (the host's clock). */
  time_ms: number;
  /** Parse time, milliseconds. */
  parse_ms: number;
  /** Skipped entities, repaired surfaces, incomplete refinement, ... */
  warnings: string[];
  /** Faces the re-parameterization test flagged, rebuilt or not. */
  reparameterized: ReparamFace[];
  /** Quality mode only. */
  quality?: QualityReport;
}

/** The mesh of one distinct part (the whole model when it has no assembly structure). */
export interface PartMesh {
  /** The part's product name ("" when the file gives none). */
  name: string;
  /** x, y, z per vertex, in the coordinates of the part's node (apply an instance's matrix). */
  positions: Float32Array;
  /** Unit surface normal per vertex. */
  normals: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from the normal side. */
  indices: Uint32Array;
  /** Pairs (first triangle, triangle count), one pair per face of the part. */
  faceRanges: Uint32Array;
  /** For each face of the part, the model's face it is (in the part's first instance). */
  faces: Uint32Array;
  /** Red, green, blue (0 to 1) per face as the file colours it (STEP styles); NaN where it does not. */
  faceColors: Float32Array;
  /** The B-rep edges as polylines: x, y, z per point, every point a vertex of the mesh. */
  edges: Float32Array;
  /** Pairs (first point, point count), one pair per polyline of `edges`. */
  edgeRanges: Uint32Array;
}

/** One placed copy of a part mesh. */
export interface PartInstance {
  /** Index into `meshes`. */
  part: number;
  /** 4 x 4 matrix, column-major (three.js Matrix4.fromArray order), from the mesh's coordinates to the model's. */
  matrix: number[];
  /** This instance's node index in a walk of `tree` (depth first, parents before children). */
  node: number;
}

/** A node of the assembly tree (the STEP product structure; one root node for other files). */
export interface AssemblyNode {
  /** The product's name ("" when the file gives none). */
  name: string;
  /** The occurrence's own name where the file gives one (e.g. "nut_1"). */
  occurrence?: string;
  /** 4 x 4 matrix, column-major, from this node's coordinates to its parent's. */
  matrix: number[];
  /** Sub-assemblies and parts placed here. */
  children: AssemblyNode[];
  /** The part instances at this node: indices into `instances` (with flatten, the values of `faceParts`). */
  instances: number[];
}

/** What `mesh` returns: each distinct part meshed once, and where its copies go. */
export interface MeshOutput {
  /** One mesh per distinct part. */
  meshes: PartMesh[];
  /** One per part instance: draw meshes[part] under matrix (three.js InstancedMesh). */
  instances: PartInstance[];
  /** The assembly tree: names, placements, children. */
  tree: AssemblyNode;
  /** Length unit of the positions and of the report's lengths (also `report.units`). */
  units: string;
  /** The measured report, counting every instance. */
  report: Report;
}

/** What `mesh` returns with `flatten: true`: every face of the model in one mesh, in the file's order. */
export interface FlatMeshOutput {
  /** x, y, z per vertex. */
  positions: Float32Array;
  /** Unit surface normal per vertex. */
  normals: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from the normal side. */
  indices: Uint32Array;
  /** Pairs (first triangle, triangle count), one pair per model face. */
  faceRanges: Uint32Array;
  /** The part instance of each face: an index into `parts`. */
  faceParts: Uint32Array;
  /** Red, green, blue (0 to 1) per face as the file colours it (STEP styles); NaN where it does not. */
  faceColors: Float32Array;
  /** Part names: one per part instance of a STEP assembly ("" when unnamed); one "" for other formats. */
  parts: string[];
  /** The B-rep edges as polylines: x, y, z per point, every point a vertex of the mesh. */
  edges: Float32Array;
  /** Pairs (first point, point count), one pair per polyline of `edges`. */
  edgeRanges: Uint32Array;
  /** The assembly tree; its nodes' `instances` are part indices (the values of `faceParts`). */
  tree: AssemblyNode;
  /** Length unit of `positions` and of the report's lengths. */
  units: string;
  /** The measured report. */
  report: Report;
}

/**
 * Reads `bytes` in `format` ("json", "iges" or "igs", "step" or "stp", or "" / "auto" to detect it) and meshes the model.
 * Throws an `Error` whose message names the problem (the CLI's one-line error).
 */
export function mesh(bytes: Uint8Array, format: string, options: MeshOptions & { flatten: true }): FlatMeshOutput;
export function mesh(bytes: Uint8Array, format: string, options?: MeshOptions): MeshOutput;

/**
 * As `mesh`, calling `progress(facesDone, facesTotal)` after each face is meshed (the faces of the
 * distinct parts, each once; sewing and measuring follow the last call). Returning `false` stops
 * meshing, which then throws an Error whose message is "cancelled"; an exception thrown by
 * `progress` stops it and is rethrown.
 */
export function meshWithProgress(
  bytes: Uint8Array,
  format: string,
  options: MeshOptions & { flatten: true },
  progress: (facesDone: number, facesTotal: number) => boolean | void,
): FlatMeshOutput;
export function meshWithProgress(
  bytes: Uint8Array,
  format: string,
  options: MeshOptions | undefined,
  progress: (facesDone: number, facesTotal: number) => boolean | void,
): MeshOutput;
"#;

#[cfg(feature = "repair")]
#[cfg_attr(not(test), wasm_bindgen(typescript_custom_section))]
#[cfg_attr(test, allow(dead_code))]
const TS_REPAIR: &str = r#"
/** Options of `repair`; every field is optional. Lengths are fractions of the mesh's bounding-box diagonal. */
export interface RepairOptions {
  /** Candidate-pair search: "kd" (default, the paper's k-d tree) or "bvh". */
  bucketing?: "bvh" | "kd";
  /** Triangles per k-d tree leaf (default 128). */
  bucketCapacity?: number;
  /** Vertices closer than this are welded (default 1e-9). */
  weldTolerance?: number;
  /** Size of the pseudo-random vertex moves that break exact coincidences (default 1e-9). */
  perturbation?: number;
  /** Also search the result for self-intersections (default false). */
  verify?: boolean;
}

/** Free, non-manifold and misoriented edges of a mesh. */
export interface EdgeCensus {
  free_edges: number;
  nonmanifold_edges: number;
  misoriented_edges: number;
}

/** Milliseconds per stage of a repair. */
export interface StageTimes {
  prepare: number;
  degenerate: number;
  intersect: number;
  regions: number;
  verify: number;
  total: number;
}

/** What `repair` did and measured (the command line's report). */
export interface RepairReport {
  triangles_in: number;
  vertices_in: number;
  vertices_welded: number;
  triangles_dropped: number;
  triangles_reoriented: number;
  components: number;
  free_edges_in: number;
  degenerate_collapsed: number;
  degenerate_swapped: number;
  degenerate_left: number;
  perturbation: number;
  bucketing: "kd-tree" | "bvh" | null;
  kd_leaves: number;
  candidate_pairs: number;
  segments: number;
  degenerate_contacts: number;
  regions: number;
  triangles_subdivided: number;
  subdivision_fallbacks: number;
  stitch_misses: number;
  triangles_out: number;
  vertices_out: number;
  census_out: EdgeCensus;
  volume_in: number;
  volume_out: number;
  /** With `verify`: self-intersecting triangle pairs left (0); else null. */
  self_intersections_out: number | null;
  time_ms: StageTimes;
  warnings: string[];
  /** Reading the input, milliseconds. */
  parse_ms: number;
}

/** What `repair` returns. */
export interface RepairOutput {
  /** x, y, z per vertex. */
  positions: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from outside. */
  indices: Uint32Array;
  report: RepairReport;
}

/**
 * Repairs a triangle mesh (paper 002): `bytes` in `format` ("stl", "obj", or "" / "auto" to detect it).
 * Returns a closed 2-manifold without degenerate or self-intersecting triangles.
 * Throws an `Error` whose message names the problem (the CLI's one-line error).
 */
export function repair(bytes: Uint8Array, format: string, options?: RepairOptions): RepairOutput;

/**
 * Moves every vertex of a mesh (`format` as for `repair`) by `distance` along its normal (negative =
 * inward): the kind of input `repair` is for. Returns `{ positions, indices }`.
 */
export function offset(bytes: Uint8Array, format: string, distance: number): { positions: Float32Array; indices: Uint32Array };
"#;

#[cfg(feature = "fit")]
#[cfg_attr(not(test), wasm_bindgen(typescript_custom_section))]
#[cfg_attr(test, allow(dead_code))]
const TS_FIT: &str = r#"
/** Options of `fit`; every field is optional. */
export interface FitOptions {
  /** Absolute chordal tolerance of the mesh (exclusive with toleranceRel). */
  tolerance?: number;
  /** Tolerance as a fraction of the points' bounding-box diagonal (default 1e-3). */
  toleranceRel?: number;
  /** Largest polygon of the net, 3 to 32 (default 8; 3 keeps the triangles). */
  maxSides?: number;
}

/** What `fit` measured (the command line's report). */
export interface FitReport {
  points_in: number;
  points: number;
  duplicates_merged: number;
  net_triangles: number;
  holes_filled: number;
  holes_open: number;
  borders: number;
  swaps: number;
  polygons: number;
  /** Polygons per number of sides. */
  polygon_sides: number[];
  sub_patches: number;
  sub_patches_triangular: number;
  max_g1_angle: number;
  tolerance: number;
  triangles: number;
  vertices: number;
  boundary_edges: number;
  nonmanifold_edges: number;
  time_ms: number;
  warnings: string[];
}

/** What `fit` returns: the mesh of the fitted surface, its net and its patches. */
export interface FitOutput {
  /** x, y, z per mesh vertex. */
  positions: Float32Array;
  /** Unit surface normal per mesh vertex. */
  normals: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from the normal side. */
  indices: Uint32Array;
  /** Pairs (first triangle, triangle count), one pair per polygon of the net. */
  faceRanges: Uint32Array;
  /** x, y, z per net vertex: the input points, duplicates merged. */
  points: Float32Array;
  /** Pairs of indices into `points`: the edges of the polygon net. */
  netEdges: Uint32Array;
  /** The polygon net and its quartic sub-patches as JSON text (the CLI's --patches file). */
  patches: string;
  report: FitReport;
}

/**
 * Fits a G1 surface through the points of `bytes` in `format` ("xyz", "csv", "ply", or "" / "auto"
 * to detect it) by paper 004's polygon curve net, and meshes it within the tolerance.
 * Throws an `Error` whose message names the problem (the CLI's one-line error).
 */
export function fit(bytes: Uint8Array, format: string, options?: FitOptions): FitOutput;
"#;

// ---------------------------------------------------------------------------
// Options: serde-wasm-bindgen reads an options object's entries (every own
// key, so an unknown one is caught) into one raw value per known option;
// typed getters then check the values in the order of the option names, so
// of two bad options the first named is the error, whatever the key order.
// (A derived Deserialize would not do: through serde-wasm-bindgen a derived
// struct reads only its own field names, so `deny_unknown_fields` never sees
// an unknown key, and its errors are JS objects without the option's name.)

/// Why an options object was rejected; `Display` is the one-line message.
#[derive(Debug, Clone, PartialEq)]
enum OptionError {
    /// Not an object; `example` shows one.
    NotObject { example: &'static str, found: &'static str },
    /// A key that names no option.
    Unknown { key: String, known: &'static [&'static str] },
    /// A value of the wrong kind.
    Kind { name: &'static str, expected: &'static str, found: &'static str },
    /// A number that is NaN or infinite.
    NotFinite { name: &'static str, found: f64 },
    /// A number that must be whole (and within `range`, words after "whole number").
    NotWhole { name: &'static str, range: &'static str, found: f64 },
    /// A value none of the accepted ones, which `expected` lists.
    Expected { name: &'static str, expected: &'static str },
    /// Two options that exclude each other.
    Both { name: &'static str, other: &'static str },
    /// A value the core rejects (its own option words).
    Core(OptionsError),
}

impl core::fmt::Display for OptionError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotObject { example, found } => {
                write!(f, "options: expected an object like {{ {example} }}, found {found}")
            }
            Self::Unknown { key, known } => write!(f, "option {key}: unknown option (known: {})", known.join(", ")),
            Self::Kind { name, expected, found } => write!(f, "option {name}: expected {expected}, found {found}"),
            Self::NotFinite { name, found } => write!(f, "option {name}: expected a finite number, found {found}"),
            Self::NotWhole { name, range, found } => {
                write!(f, "option {name}: expected a whole number{range}, found {found}")
            }
            Self::Expected { name, expected } => write!(f, "option {name}: expected {expected}"),
            Self::Both { name, other } => write!(f, "option {name}: give {name} or {other}, not both"),
            Self::Core(e) => write!(f, "{e}"),
        }
    }
}

impl From<OptionsError> for OptionError {
    fn from(e: OptionsError) -> Self {
        Self::Core(e)
    }
}

/// One option's value as serde-wasm-bindgen gives it, told apart only as
/// much as the getters and their errors need.
#[derive(Debug, Clone, Default)]
enum Value {
    /// Absent, undefined or null: the default.
    #[default]
    Absent,
    Number(f64),
    Text(String),
    Flag(bool),
    /// An array's first three items, each a number or not (enough to tell
    /// `[index, count]` from anything else).
    List(Vec<Option<f64>>),
    /// Any other object.
    Object,
    /// What serde-wasm-bindgen cannot read: a function, a symbol, a Set or
    /// typed array, a BigInt beyond 64 bits.
    Unsupported,
}

impl Value {
    /// The value's kind, as the errors name it.
    fn kind(&self) -> &'static str {
        match self {
            Self::Absent => "null",
            Self::Number(_) => "number",
            Self::Text(_) => "string",
            Self::Flag(_) => "boolean",
            Self::List(_) => "an array",
            Self::Object => "object",
            Self::Unsupported => "an unsupported value",
        }
    }
}

/// Reads any JS value as a [`Value`]; `Scalar` reads an array item, which
/// is a number or not (so nested arrays are never walked).
struct ValueVisitor {
    scalar: bool,
}

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("an option value")
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Absent)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Absent)
    }
    fn visit_bool<E>(self, b: bool) -> Result<Value, E> {
        Ok(Value::Flag(b))
    }
    fn visit_i64<E>(self, x: i64) -> Result<Value, E> {
        Ok(Value::Number(x as f64))
    }
    fn visit_u64<E>(self, x: u64) -> Result<Value, E> {
        Ok(Value::Number(x as f64))
    }
    fn visit_f64<E>(self, x: f64) -> Result<Value, E> {
        Ok(Value::Number(x))
    }
    fn visit_str<E>(self, s: &str) -> Result<Value, E> {
        Ok(Value::Text(s.into()))
    }
    fn visit_string<E>(self, s: String) -> Result<Value, E> {
        Ok(Value::Text(s))
    }
    fn visit_bytes<E>(self, _: &[u8]) -> Result<Value, E> {
        Ok(Value::Object)
    }
    fn visit_map<A: MapAccess<'de>>(self, _: A) -> Result<Value, A::Error> {
        Ok(Value::Object)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut items: A) -> Result<Value, A::Error> {
        if self.scalar {
            return Ok(Value::List(Vec::new()));
        }
        let mut first = Vec::new();
        while first.len() < 3 {
            match items.next_element_seed(ValueSeed { scalar: true }) {
                Ok(Some(Value::Number(x))) => first.push(Some(x)),
                Ok(Some(_)) | Err(_) => first.push(None),
                Ok(None) => break,
            }
        }
        Ok(Value::List(first))
    }
}

/// [`ValueVisitor`] as a seed: an option's value, or an array's item.
struct ValueSeed {
    scalar: bool,
}

impl<'de> DeserializeSeed<'de> for ValueSeed {
    type Value = Value;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(ValueVisitor { scalar: self.scalar })
    }
}

/// An options object's entries: one [`Value`] per name of `known`, or the
/// first key that is none of them.
struct Entries {
    known: &'static [&'static str],
}

impl<'de> Visitor<'de> for Entries {
    type Value = Result<Vec<Value>, OptionError>;

    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("an options object")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut values = alloc::vec![Value::Absent; self.known.len()];
        let mut unknown = None;
        while let Some(key) = map.next_key::<String>()? {
            match self.known.iter().position(|&n| n == key) {
                // A value serde-wasm-bindgen cannot read is kept as such, for the getter to name.
                Some(k) => values[k] = map.next_value_seed(ValueSeed { scalar: false }).unwrap_or(Value::Unsupported),
                None => {
                    map.next_value::<IgnoredAny>()?;
                    unknown.get_or_insert(key);
                }
            }
        }
        Ok(match unknown {
            Some(key) => Err(OptionError::Unknown { key, known: self.known }),
            None => Ok(values),
        })
    }
}

/// A checked options object: each getter reads one option, `None` when it
/// is absent, undefined or null, else its value or the option's error.
struct Fields {
    known: &'static [&'static str],
    values: Vec<Value>,
}

impl Fields {
    /// Reads `value` through serde-wasm-bindgen: undefined and null are the
    /// defaults; anything but a plain object, or a key not in `known`, is an
    /// error (`example` shows an options object in it).
    fn read(value: JsValue, example: &'static str, known: &'static [&'static str]) -> Result<Self, OptionError> {
        let values = alloc::vec![Value::Absent; known.len()];
        if value.is_undefined() || value.is_null() {
            return Ok(Self { known, values });
        }
        let not_object = |found| OptionError::NotObject { example, found };
        if Array::is_array(&value) {
            return Err(not_object("an array"));
        }
        if !value.is_object() {
            return Err(not_object(match value.js_typeof().as_string().as_deref() {
                Some("number") => "number",
                Some("string") => "string",
                Some("boolean") => "boolean",
                Some("bigint") => "bigint",
                Some("function") => "function",
                _ => "symbol",
            }));
        }
        // A Map, Set or typed array would be read as a list of entries.
        if js_sys::Symbol::iterator().js_in(&value) {
            return Err(not_object("an iterable"));
        }
        let values = serde_wasm_bindgen::Deserializer::from(value)
            .deserialize_map(Entries { known })
            .unwrap_or_else(|_| Err(not_object("an unreadable object")))?;
        Ok(Self { known, values })
    }

    /// The value of option `name` (one of `known`).
    fn get(&self, name: &'static str) -> &Value {
        self.known.iter().position(|&n| n == name).and_then(|k| self.values.get(k)).unwrap_or(&Value::Absent)
    }

    fn number(&self, name: &'static str) -> Result<Option<f64>, OptionError> {
        match *self.get(name) {
            Value::Absent => Ok(None),
            Value::Number(x) if x.is_finite() => Ok(Some(x)),
            Value::Number(found) => Err(OptionError::NotFinite { name, found }),
            ref v => Err(OptionError::Kind { name, expected: "a number", found: v.kind() }),
        }
    }

    fn text(&self, name: &'static str) -> Result<Option<&str>, OptionError> {
        match self.get(name) {
            Value::Absent => Ok(None),
            Value::Text(t) => Ok(Some(t)),
            v => Err(OptionError::Kind { name, expected: "a string", found: v.kind() }),
        }
    }

    fn flag(&self, name: &'static str) -> Result<Option<bool>, OptionError> {
        match *self.get(name) {
            Value::Absent => Ok(None),
            Value::Flag(b) => Ok(Some(b)),
            ref v => Err(OptionError::Kind { name, expected: "a boolean", found: v.kind() }),
        }
    }

    /// An array's first three items, each a number or not.
    fn list(&self, name: &'static str) -> Result<Option<&[Option<f64>]>, OptionError> {
        match self.get(name) {
            Value::Absent => Ok(None),
            Value::List(items) => Ok(Some(items)),
            _ => Err(share_error(name)),
        }
    }
}

/// The error of a `share` that is not `[index, count]`.
fn share_error(name: &'static str) -> OptionError {
    OptionError::Expected { name, expected: "[index, count] with whole numbers, index < count" }
}

/// `[index, count]`: whole numbers, index < count.
fn share(name: &'static str, items: &[Option<f64>]) -> Result<(u32, u32), OptionError> {
    match items {
        [Some(i), Some(n)] if whole(*i) && whole(*n) && i < n => Ok((*i as u32, *n as u32)),
        _ => Err(share_error(name)),
    }
}

/// The option's word parsed by its enum's `FromStr` (the CLI's parser
/// too); the error lists the words as `expected`.
fn word<T: core::str::FromStr>(
    text: Option<&str>,
    name: &'static str,
    expected: &'static str,
) -> Result<Option<T>, OptionError> {
    text.map(|t| t.parse().map_err(|_| OptionError::Expected { name, expected })).transpose()
}

/// `n` if it is a whole number from 0 to `u32::MAX`.
fn whole_number(n: Option<f64>, name: &'static str) -> Result<Option<usize>, OptionError> {
    match n {
        Some(n) if whole(n) => Ok(Some(n as usize)),
        Some(found) => Err(OptionError::NotWhole { name, range: "", found }),
        None => Ok(None),
    }
}

/// Whether `x` is a whole number from 0 to `u32::MAX`.
fn whole(x: f64) -> bool {
    x.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&x)
}

/// The options of `mesh`, each of its type (read in [`OPTION_NAMES`] order:
/// the first bad one is the error).
struct JsMeshOptions<'a> {
    tolerance: Option<f64>,
    tolerance_rel: Option<f64>,
    angle: Option<f64>,
    max_edge: Option<f64>,
    min_edge: Option<f64>,
    max_triangles: Option<f64>,
    reparam: Option<&'a str>,
    mode: Option<&'a str>,
    size: Option<f64>,
    size_rel: Option<f64>,
    method: Option<&'a str>,
    share: Option<&'a [Option<f64>]>,
    units: Option<&'a str>,
    flatten: Option<bool>,
    console_warnings: Option<bool>,
}

impl<'a> JsMeshOptions<'a> {
    fn read(f: &'a Fields) -> Result<Self, OptionError> {
        Ok(Self {
            tolerance: f.number("tolerance")?,
            tolerance_rel: f.number("toleranceRel")?,
            angle: f.number("angle")?,
            max_edge: f.number("maxEdge")?,
            min_edge: f.number("minEdge")?,
            max_triangles: f.number("maxTriangles")?,
            reparam: f.text("reparam")?,
            mode: f.text("mode")?,
            size: f.number("size")?,
            size_rel: f.number("sizeRel")?,
            method: f.text("method")?,
            share: f.list("share")?,
            units: f.text("units")?,
            flatten: f.flag("flatten")?,
            console_warnings: f.flag("consoleWarnings")?,
        })
    }
}

/// Option names `mesh` accepts: every key of an options object must be one.
const OPTION_NAMES: &[&str] = &[
    "tolerance",
    "toleranceRel",
    "angle",
    "maxEdge",
    "minEdge",
    "maxTriangles",
    "reparam",
    "mode",
    "size",
    "sizeRel",
    "method",
    "share",
    "units",
    "flatten",
    "consoleWarnings",
];

/// What `mesh` does besides the meshing options.
#[derive(Debug, Clone, Copy)]
struct Output {
    units: Units,
    flatten: bool,
    console_warnings: bool,
}

/// The meshing options, the unit of the result and the output's shape.
fn mesh_options(value: JsValue) -> Result<(MeshOptions, Output), OptionError> {
    let fields = Fields::read(value, "toleranceRel: 0.001", OPTION_NAMES)?;
    let js = JsMeshOptions::read(&fields)?;
    let mut o = MeshOptions::default();
    match (js.tolerance, js.tolerance_rel) {
        (Some(_), Some(_)) => return Err(OptionError::Both { name: "tolerance", other: "toleranceRel" }),
        (Some(t), None) => o = o.with_tolerance(t),
        (None, Some(r)) => o = o.with_relative_tolerance(r),
        (None, None) => {}
    }
    if let Some(a) = js.angle {
        o = o.with_angle(a);
    }
    if let Some(m) = js.max_edge {
        o = o.with_max_edge(Some(m));
    }
    if let Some(m) = js.min_edge {
        o = o.with_min_edge(Some(m));
    }
    if let Some(n) = whole_number(js.max_triangles, "maxTriangles")? {
        o = o.with_max_triangles(n);
    }
    if let Some(r) = word::<Reparam>(js.reparam, "reparam", "\"auto\", \"off\" or \"force\"")? {
        o = o.with_reparam(r);
    }
    let mut quality = o.quality.clone();
    match (js.size, js.size_rel) {
        (Some(_), Some(_)) => return Err(OptionError::Both { name: "size", other: "sizeRel" }),
        (Some(h), None) => quality = quality.with_size(h),
        (None, Some(r)) => quality = quality.with_relative_size(r),
        (None, None) => {}
    }
    if let Some(m) = word::<QualityMethod>(js.method, "method", "one of \"looping\", \"delaunay\", \"best\"")? {
        quality = quality.with_method(m);
    }
    o = o.with_quality(quality);
    if let Some(m) = word::<MeshMode>(js.mode, "mode", "one of \"fast\", \"quality\"")? {
        o = o.with_mode(m);
    }
    if let Some(items) = js.share {
        let (index, count) = share("share", items)?;
        o = o.with_share(index, count);
    }
    let units = match js.units {
        Some(name) => Units::from_name(name)?,
        None => Units::File,
    };
    let flatten = js.flatten.unwrap_or(false);
    let console_warnings = js.console_warnings.unwrap_or(false);
    Ok((o, Output { units, flatten, console_warnings }))
}

// ---------------------------------------------------------------------------
// Entry points.

/// The crate version, so a page can show which mesher produced a mesh.
#[cfg_attr(not(test), wasm_bindgen)]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Bytes of linear memory the module holds. Wasm memory only grows, so
/// read after one `mesh` call in a fresh instance it is that call's peak
/// (benchmarks compare it with the size of the mesh returned).
#[cfg_attr(not(test), wasm_bindgen(js_name = memoryBytes))]
#[cfg_attr(test, allow(dead_code))]
pub fn memory_bytes() -> f64 {
    (core::arch::wasm32::memory_size(0) * 65536) as f64
}

/// Reads `bytes` in `format` (`"json"`, `"iges"`/`"igs"`, `"step"`/`"stp"`, or `""`/`"auto"` to detect it) and
/// meshes the model with `options` (see the `MeshOptions` interface).
///
/// # Errors
/// Throws a JS `Error` whose message is the one-line text of the problem:
/// a bad option, a parse error with its line, or the face/loop/curve and field
/// that is invalid.
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn mesh(bytes: Vec<u8>, format: &str, options: JsValue) -> Result<JsValue, JsError> {
    let (options, output) = mesh_options(options).map_err(|e| JsError::new(&one_line(&e.to_string())))?;
    run(bytes, format, &options, output, &mut |_, _| true).map_err(|e| JsError::new(&one_line(&e.to_string())))
}

/// As [`mesh`], calling the JS function `progress(faces_done, faces_total)`
/// after each face, so a Web Worker can post progress events; the function
/// returning `false` stops meshing with the error "cancelled".
///
/// # Errors
/// As [`mesh`]; an exception thrown by `progress` stops meshing and is
/// rethrown as it is.
#[cfg_attr(not(test), wasm_bindgen(js_name = meshWithProgress, skip_typescript))]
#[cfg_attr(test, allow(dead_code))]
pub fn mesh_with_progress(
    bytes: Vec<u8>,
    format: &str,
    options: JsValue,
    progress: &Function,
) -> Result<JsValue, JsValue> {
    let (options, output) =
        mesh_options(options).map_err(|e| JsValue::from(JsError::new(&one_line(&e.to_string()))))?;
    let mut thrown: Option<JsValue> = None;
    let mut call = |done: usize, total: usize| -> bool {
        match progress.call2(&JsValue::NULL, &JsValue::from(done as f64), &JsValue::from(total as f64)) {
            Ok(answer) => answer.as_bool() != Some(false),
            Err(e) => {
                thrown = Some(e);
                false
            }
        }
    };
    let result = run(bytes, format, &options, output, &mut call);
    match (result, thrown) {
        (_, Some(e)) => Err(e),
        (Ok(out), None) => Ok(out),
        (Err(e), None) => Err(JsError::new(&one_line(&e.to_string())).into()),
    }
}

/// The message on one line, as the command line prints it.
fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `""` and `"auto"` detect the format from the bytes; anything else is a name.
fn pick_format(bytes: &[u8], name: &str) -> Result<Format, Error> {
    if name.is_empty() || name.eq_ignore_ascii_case("auto") {
        Format::detect(bytes).ok_or_else(|| {
            Error::Format("cannot detect the input format from its first bytes (expected json, iges or step)".into())
        })
    } else {
        Format::from_name(name)
    }
}

// Not in the test's copy of this file: the import's glue symbols would be
// defined twice at link time (the test's clock is `Date.now` under Node).
#[cfg(not(test))]
#[wasm_bindgen]
extern "C" {
    /// The global object of any host (a window, a worker, Node).
    type Host;
    /// Its `performance`, when it has one (`undefined` otherwise).
    #[wasm_bindgen(method, getter, structural)]
    fn performance(this: &Host) -> JsValue;
}

/// `performance.now()` of the host (browser, worker, Node), else `Date.now()`.
fn now_ms() -> f64 {
    let global = js_sys::global();
    let perf = if let Some(w) = global.dyn_ref::<web_sys::Window>() {
        w.performance()
    } else if let Some(w) = global.dyn_ref::<web_sys::WorkerGlobalScope>() {
        w.performance()
    } else {
        node_performance(global)
    };
    perf.map_or_else(js_sys::Date::now, |p| p.now())
}

/// Node's `performance`: the same object, not under a browser's class.
#[cfg(not(test))]
fn node_performance(global: js_sys::Object) -> Option<web_sys::Performance> {
    let p = global.unchecked_into::<Host>().performance();
    p.is_object().then(|| p.unchecked_into::<web_sys::Performance>())
}

#[cfg(test)]
fn node_performance(_: js_sys::Object) -> Option<web_sys::Performance> {
    None
}

/// What the result needs of the file besides the mesh.
struct Read {
    /// A name per part instance.
    parts: Vec<String>,
    /// A colour per face.
    colours: Vec<Option<[f32; 3]>>,
    assembly: Assembly,
    /// Result units per file unit (the tree's matrices are in the file's).
    scale: f64,
}

/// Parses, meshes (reporting each face to `progress`) and converts, timing
/// the two stages with the host clock. The input is freed once read: wasm
/// memory never shrinks, so the file need not sit beside the mesh at its peak.
fn run(
    bytes: Vec<u8>,
    format: &str,
    options: &MeshOptions,
    output: Output,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<JsValue, Error> {
    options.validate()?;
    let format = pick_format(&bytes, format)?;
    let t0 = now_ms();
    let (model, mut read) = if format == Format::Step {
        let s = read_step_parts(&bytes)?;
        (s.model, Read { parts: s.parts, colours: s.face_colours, assembly: s.assembly, scale: 1.0 })
    } else {
        let model = read_model(&bytes, format)?;
        let n = model.face_count();
        let parts = alloc::vec![String::new()];
        (model, Read { parts, colours: alloc::vec![None; n], assembly: Assembly::single("", n), scale: 1.0 })
    };
    drop(bytes);
    if let (Some(name), Some(from)) = (output.units.name(), mm_per_unit(&model.units)) {
        read.scale = from / mm_per_unit(name).unwrap_or(from);
    }
    let t1 = now_ms();
    let mut result = mesh_instanced(&model, &read.assembly, options, output.units, progress)?;
    let faces = model.face_count();
    drop(model);
    result.report.parse_ms = t1 - t0;
    result.report.time_ms = now_ms() - t1;
    if output.console_warnings {
        for w in &result.report.warnings {
            web_sys::console::warn_1(&JsValue::from_str(&w.to_string()));
        }
    }
    if output.flatten {
        flat_to_js(&result, &read, faces)
    } else {
        instanced_to_js(&result, &read)
    }
}

// ---------------------------------------------------------------------------
// Results: serialized straight to JS objects, the typed arrays as they are.

/// The serializer of every result: maps as plain objects, `None` as `null`
/// (as the command line's JSON has it).
fn serializer() -> serde_wasm_bindgen::Serializer {
    serde_wasm_bindgen::Serializer::new().serialize_maps_as_objects(true).serialize_missing_as_null(true)
}

fn to_value<T: Serialize>(value: &T) -> Result<JsValue, Error> {
    value.serialize(&serializer()).map_err(|e| Error::Internal(format!("result to JS: {e}")))
}

/// x, y, z of each point as f32.
fn floats(points: &[glam::DVec3]) -> Float32Array {
    let flat: Vec<f32> = points.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
    Float32Array::from(flat.as_slice())
}

fn ranges(mesh: &Mesh) -> Uint32Array {
    let r: Vec<u32> = mesh.face_ranges.iter().flat_map(|r| [r.first, r.count]).collect();
    Uint32Array::from(r.as_slice())
}

/// The edge polylines as points and (first, count) pairs.
fn edge_arrays(lines: &EdgeLines) -> (Float32Array, Uint32Array) {
    let r: Vec<u32> = lines.ranges.iter().flat_map(|&(a, n)| [a, n]).collect();
    (floats(&lines.points), Uint32Array::from(r.as_slice()))
}

fn colours(list: impl Iterator<Item = Option<[f32; 3]>>) -> Float32Array {
    let c: Vec<f32> = list.flat_map(|c| c.unwrap_or([f32::NAN; 3])).collect();
    Float32Array::from(c.as_slice())
}

/// A column-major 4 × 4 matrix (three.js `Matrix4.fromArray` order).
fn matrix4(m: &glam::DAffine3) -> Vec<f64> {
    glam::DMat4::from(*m).to_cols_array().to_vec()
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PartOut {
    name: String,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    positions: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    normals: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    indices: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    face_ranges: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    faces: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    face_colors: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    edges: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    edge_ranges: Uint32Array,
}

#[derive(Serialize)]
struct InstanceOut {
    part: usize,
    matrix: Vec<f64>,
    node: usize,
}

#[derive(Serialize)]
struct NodeOut {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    occurrence: Option<String>,
    matrix: Vec<f64>,
    children: Vec<NodeOut>,
    instances: Vec<usize>,
}

/// The tree from node `n` down (translations times `scale`), and each
/// node's place in a depth-first walk (`order`, counted by `next`).
fn tree(a: &Assembly, n: usize, scale: f64, order: &mut [usize], next: &mut usize, depth: usize) -> NodeOut {
    if let Some(o) = order.get_mut(n) {
        *o = *next;
    }
    *next += 1;
    let node = &a.nodes[n];
    let m = glam::DAffine3 { matrix3: node.matrix.matrix3, translation: node.matrix.translation * scale };
    // The reader caps the depth; this only guards a malformed tree.
    let children = if depth > 256 {
        Vec::new()
    } else {
        node.children
            .iter()
            .filter(|&&c| c < a.nodes.len())
            .map(|&c| tree(a, c, scale, order, next, depth + 1))
            .collect()
    };
    NodeOut {
        name: node.name.clone(),
        occurrence: node.occurrence.clone(),
        matrix: matrix4(&m),
        children,
        instances: node.instances.clone(),
    }
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct InstancedOut<'a> {
    meshes: Vec<PartOut>,
    instances: Vec<InstanceOut>,
    tree: NodeOut,
    units: &'a str,
    report: &'a Report,
}

/// `{ meshes, instances, tree, units, report }`.
fn instanced_to_js(result: &InstancedResult, read: &Read) -> Result<JsValue, Error> {
    let a = &read.assembly;
    let mut order = alloc::vec![0; a.nodes.len()];
    let root = tree(a, 0, read.scale, &mut order, &mut 0, 0);
    let mut meshes = Vec::with_capacity(result.parts.len());
    for (p, part) in result.parts.iter().enumerate() {
        let first = result.instances.iter().position(|(q, _)| *q == p);
        let name = first.and_then(|k| a.instances.get(k)).and_then(|i| a.nodes.get(i.node));
        let lines = edge_lines(&part.mesh);
        let (edges, edge_ranges) = edge_arrays(&lines);
        let faces: Vec<u32> = part.faces.iter().map(|&f| f as u32).collect();
        meshes.push(PartOut {
            name: name.map(|n| n.name.clone()).unwrap_or_default(),
            positions: floats(&part.mesh.positions),
            normals: floats(&part.mesh.normals),
            indices: Uint32Array::from(part.mesh.indices.as_slice()),
            face_ranges: ranges(&part.mesh),
            faces: Uint32Array::from(faces.as_slice()),
            face_colors: colours(part.faces.iter().map(|&f| read.colours.get(f).copied().flatten())),
            edges,
            edge_ranges,
        });
    }
    let instances = result
        .instances
        .iter()
        .enumerate()
        .map(|(k, (part, m))| {
            let node = a.instances.get(k).map_or(0, |i| order.get(i.node).copied().unwrap_or(0));
            InstanceOut { part: *part, matrix: matrix4(m), node }
        })
        .collect();
    let out = InstancedOut { meshes, instances, tree: root, units: &result.report.units, report: &result.report };
    to_value(&out)
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct FlatOut<'a> {
    #[serde(with = "serde_wasm_bindgen::preserve")]
    positions: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    normals: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    indices: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    face_ranges: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    face_parts: Uint32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    face_colors: Float32Array,
    parts: &'a [String],
    #[serde(with = "serde_wasm_bindgen::preserve")]
    edges: Float32Array,
    #[serde(with = "serde_wasm_bindgen::preserve")]
    edge_ranges: Uint32Array,
    tree: NodeOut,
    units: &'a str,
    report: &'a Report,
}

/// `{ positions, normals, indices, faceRanges, faceParts, faceColors, parts, edges, edgeRanges, tree, units, report }`.
fn flat_to_js(result: &InstancedResult, read: &Read, faces: usize) -> Result<JsValue, Error> {
    let mesh = flatten(result, &read.assembly);
    let lines = edge_lines(&mesh);
    let (edges, edge_ranges) = edge_arrays(&lines);
    drop(lines);
    let mut order = alloc::vec![0; read.assembly.nodes.len()];
    let root = tree(&read.assembly, 0, read.scale, &mut order, &mut 0, 0);
    let face_parts: Vec<u32> = match read.assembly.face_instances.len() {
        n if n == faces => read.assembly.face_instances.clone(),
        _ => alloc::vec![0; faces],
    };
    let out = FlatOut {
        // One f32 copy at a time, each freed once JS has its own.
        positions: floats(&mesh.positions),
        normals: floats(&mesh.normals),
        indices: Uint32Array::from(mesh.indices.as_slice()),
        face_ranges: ranges(&mesh),
        face_parts: Uint32Array::from(face_parts.as_slice()),
        face_colors: colours(read.colours.iter().copied()),
        parts: &read.parts,
        edges,
        edge_ranges,
        tree: root,
        units: &result.report.units,
        report: &result.report,
    };
    to_value(&out)
}

// ---------------------------------------------------------------------------
// The full build's functions: repair, offset, fit.

/// The options of `repair`, each of its type (read in
/// [`REPAIR_OPTION_NAMES`] order: the first bad one is the error).
#[cfg(feature = "repair")]
struct JsRepairOptions<'a> {
    bucketing: Option<&'a str>,
    bucket_capacity: Option<f64>,
    weld_tolerance: Option<f64>,
    perturbation: Option<f64>,
    verify: Option<bool>,
}

#[cfg(feature = "repair")]
impl<'a> JsRepairOptions<'a> {
    fn read(f: &'a Fields) -> Result<Self, OptionError> {
        Ok(Self {
            bucketing: f.text("bucketing")?,
            bucket_capacity: f.number("bucketCapacity")?,
            weld_tolerance: f.number("weldTolerance")?,
            perturbation: f.number("perturbation")?,
            verify: f.flag("verify")?,
        })
    }
}

#[cfg(feature = "repair")]
const REPAIR_OPTION_NAMES: &[&str] = &["bucketing", "bucketCapacity", "weldTolerance", "perturbation", "verify"];

/// Reads a mesh (`"stl"`, `"obj"`, or `""`/`"auto"` to detect it) and repairs it (paper 002).
///
/// # Errors
/// Throws a JS `Error` with the one-line message of a bad option, a reader
/// error with its line, or a mesh that cannot be repaired.
#[cfg(feature = "repair")]
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn repair(bytes: &[u8], format: &str, options: JsValue) -> Result<JsValue, JsError> {
    let options = repair_options(options).map_err(|e| JsError::new(&one_line(&e.to_string())))?;
    run_repair(bytes, format, &options).map_err(|e| JsError::new(&one_line(&e.to_string())))
}

#[cfg(feature = "repair")]
fn repair_options(value: JsValue) -> Result<RepairOptions, OptionError> {
    let fields = Fields::read(value, "bucketing: \"kd\"", REPAIR_OPTION_NAMES)?;
    let js = JsRepairOptions::read(&fields)?;
    let mut o = RepairOptions::default();
    if let Some(b) = word::<Bucketing>(js.bucketing, "bucketing", "\"kd\" or \"bvh\"")? {
        o = o.with_bucketing(b);
    }
    if let Some(n) = whole_number(js.bucket_capacity, "bucketCapacity")? {
        o = o.with_bucket_capacity(n);
    }
    if let Some(w) = js.weld_tolerance {
        o = o.with_weld_tolerance(w);
    }
    if let Some(p) = js.perturbation {
        o.perturbation = p;
    }
    if let Some(v) = js.verify {
        o = o.with_verify(v);
    }
    Ok(o)
}

/// Reads a mesh (`format` as for [`repair`]) and offsets it by `distance` along its vertex normals.
///
/// # Errors
/// Throws a JS `Error` with the reader's or the offset's one-line message.
#[cfg(feature = "repair")]
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn offset(bytes: &[u8], format: &str, distance: f64) -> Result<JsValue, JsError> {
    #[derive(Serialize)]
    struct Out {
        #[serde(with = "serde_wasm_bindgen::preserve")]
        positions: Float32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        indices: Uint32Array,
    }
    let run = || -> Result<JsValue, Error> {
        let mesh = read_mesh(bytes, mesh_format(bytes, format)?)?;
        let out = offset_mesh(&mesh, distance)?;
        to_value(&Out { positions: floats(&out.positions), indices: Uint32Array::from(out.indices.as_slice()) })
    };
    run().map_err(|e| JsError::new(&one_line(&e.to_string())))
}

/// `""` and `"auto"` detect the mesh format from the bytes; anything else is a name.
#[cfg(feature = "repair")]
fn mesh_format(bytes: &[u8], name: &str) -> Result<MeshFormat, Error> {
    if name.is_empty() || name.eq_ignore_ascii_case("auto") {
        MeshFormat::detect(bytes).ok_or_else(|| {
            Error::Format("cannot detect the mesh format from its first bytes (expected stl or obj)".into())
        })
    } else {
        MeshFormat::from_name(name)
    }
}

#[cfg(feature = "repair")]
fn run_repair(bytes: &[u8], format: &str, options: &RepairOptions) -> Result<JsValue, Error> {
    /// The repair's report with the parse time the binding measured.
    #[derive(Serialize)]
    struct Timed<'a> {
        #[serde(flatten)]
        report: &'a RepairReport,
        parse_ms: f64,
    }
    #[derive(Serialize)]
    struct Out<'a> {
        #[serde(with = "serde_wasm_bindgen::preserve")]
        positions: Float32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        indices: Uint32Array,
        report: Timed<'a>,
    }
    options.validate()?;
    let format = mesh_format(bytes, format)?;
    let t0 = now_ms();
    let mesh = read_mesh(bytes, format)?;
    let t1 = now_ms();
    let result = repair_mesh_timed(&mesh, options, &mut || now_ms() - t1)?;
    to_value(&Out {
        positions: floats(&result.mesh.positions),
        indices: Uint32Array::from(result.mesh.indices.as_slice()),
        report: Timed { report: &result.report, parse_ms: t1 - t0 },
    })
}

/// The options of `fit`, each of its type (read in [`FIT_OPTION_NAMES`]
/// order: the first bad one is the error).
#[cfg(feature = "fit")]
struct JsFitOptions {
    tolerance: Option<f64>,
    tolerance_rel: Option<f64>,
    max_sides: Option<f64>,
}

#[cfg(feature = "fit")]
impl JsFitOptions {
    fn read(f: &Fields) -> Result<Self, OptionError> {
        Ok(Self {
            tolerance: f.number("tolerance")?,
            tolerance_rel: f.number("toleranceRel")?,
            max_sides: f.number("maxSides")?,
        })
    }
}

#[cfg(feature = "fit")]
const FIT_OPTION_NAMES: &[&str] = &["tolerance", "toleranceRel", "maxSides"];

/// Reads points (`"xyz"`, `"csv"`, `"ply"`, or `""`/`"auto"` to detect them)
/// and fits a surface through them (paper 004).
///
/// # Errors
/// Throws a JS `Error` with the one-line message of a bad option, a reader
/// error naming its line, or points no surface passes through.
#[cfg(feature = "fit")]
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn fit(bytes: &[u8], format: &str, options: JsValue) -> Result<JsValue, JsError> {
    let options = fit_options(options).map_err(|e| JsError::new(&one_line(&e.to_string())))?;
    let run = || -> Result<JsValue, Error> {
        let format = if format.is_empty() || format.eq_ignore_ascii_case("auto") {
            PointFormat::detect(bytes)
        } else {
            PointFormat::from_name(format)?
        };
        let points = read_points(bytes, format)?;
        let t0 = now_ms();
        let mut result = fit_points(&points, &options)?;
        result.report.time_ms = now_ms() - t0;
        fit_to_js(&result)
    };
    run().map_err(|e| JsError::new(&one_line(&e.to_string())))
}

#[cfg(feature = "fit")]
fn fit_options(value: JsValue) -> Result<FitOptions, OptionError> {
    let js = JsFitOptions::read(&Fields::read(value, "toleranceRel: 0.001", FIT_OPTION_NAMES)?)?;
    let mut o = FitOptions::default();
    match (js.tolerance, js.tolerance_rel) {
        (Some(_), Some(_)) => return Err(OptionError::Both { name: "tolerance", other: "toleranceRel" }),
        (Some(t), None) => o = o.with_tolerance(t),
        (None, Some(r)) => o = o.with_relative_tolerance(r),
        (None, None) => {}
    }
    if let Some(n) = js.max_sides {
        if !(n.fract() == 0.0 && (3.0..=32.0).contains(&n)) {
            return Err(OptionError::NotWhole { name: "maxSides", range: " from 3 to 32", found: n });
        }
        o = o.with_max_polygon_sides(n as usize);
    }
    o.validate()?;
    Ok(o)
}

/// Builds `{ positions, normals, indices, faceRanges, points, netEdges, patches, report }`.
#[cfg(feature = "fit")]
fn fit_to_js(result: &FitResult) -> Result<JsValue, Error> {
    #[derive(Serialize)]
    #[serde(rename_all = "camelCase")]
    struct Out<'a> {
        #[serde(with = "serde_wasm_bindgen::preserve")]
        positions: Float32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        normals: Float32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        indices: Uint32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        face_ranges: Uint32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        points: Float32Array,
        #[serde(with = "serde_wasm_bindgen::preserve")]
        net_edges: Uint32Array,
        patches: String,
        report: &'a FitReport,
    }
    let mesh = &result.mesh;
    let edges: Vec<u32> = result.surface.edges().iter().flat_map(|(a, b, _)| [*a, *b]).collect();
    to_value(&Out {
        positions: floats(&mesh.positions),
        normals: floats(&mesh.normals),
        indices: Uint32Array::from(mesh.indices.as_slice()),
        face_ranges: ranges(mesh),
        points: floats(&result.surface.points),
        net_edges: Uint32Array::from(edges.as_slice()),
        patches: result.surface.to_json(),
        report: &result.report,
    })
}
