//! The JavaScript door (wasm-bindgen): JS values in, core types through
//! [`crate::mesh_model`], typed arrays out. No algorithm lives here.
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

use js_sys::{Array, Float32Array, Function, Object, Reflect, Uint32Array, JSON};
use wasm_bindgen::prelude::*;

use crate::{fit_points, read_points, FitOptions, FitResult, PointFormat};
use crate::{mesh_model_in_units, Units};
use crate::{offset_mesh, read_mesh, repair_mesh_timed, Bucketing, MeshFormat, RepairOptions};
use crate::{read_model, read_step_parts, Error, Format, MeshMode, MeshOptions, MeshResult, QualityMethod};
// `tests/wasm_node.rs` compiles this file into a crate where `crate::` is the
// test itself, which does not import this name; take it from the library there.
#[cfg(not(test))]
use crate::Reparam;
#[cfg(test)]
use surfmesh::Reparam;

#[cfg_attr(not(test), wasm_bindgen(typescript_custom_section))]
#[cfg_attr(test, allow(dead_code))]
const TS_TYPES: &str = r#"
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
  /** "fast" (default): fewest triangles within the tolerance; "quality": near-equilateral triangles of size H (paper 003). */
  mode?: "fast" | "quality";
  /** Quality mode: element size H in model units (exclusive with sizeRel). */
  size?: number;
  /** Quality mode: element size as a fraction of the model's bounding-box diagonal (default 0.02). */
  sizeRel?: number;
  /** Quality mode: "looping" (default, paper 003), "delaunay" (spade's refinement) or "best" (both, better per face). */
  method?: "looping" | "delaunay" | "best";
  /**
   * Fast mode: [index, count] meshes only share `index` of `count` of the model's bodies, so
   * that `count` workers can mesh one model side by side; the other faces come back empty
   * (count 0 in faceRanges). Bodies share no border, so the shares together are the whole mesh.
   */
  share?: [number, number];
  /**
   * Length unit of the result: "file" (default: the file's own unit, nothing scaled), "mm", "cm",
   * "m", "in" or "ft". The mesh is scaled into it, with the report's tolerance and deviations;
   * absolute options (tolerance, maxEdge, minEdge, size) are taken in it too.
   */
  units?: "file" | "mm" | "cm" | "m" | "in" | "ft";
}

/** What `mesh` returns. */
export interface MeshOutput {
  /** x, y, z per vertex. */
  positions: Float32Array;
  /** Unit surface normal per vertex. */
  normals: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from the normal side. */
  indices: Uint32Array;
  /** Pairs (first triangle, triangle count), one pair per model face. */
  faceRanges: Uint32Array;
  /** The part of each face (the pair of the same index in `faceRanges`): an index into `parts`. */
  faceParts: Uint32Array;
  /** Red, green, blue (0 to 1) per face as the file colours it (STEP styles); NaN where it does not. */
  faceColors: Float32Array;
  /** Part names: one per part instance of a STEP assembly ("" when unnamed); one "" for other formats. */
  parts: string[];
  /** Length unit of `positions` and of the report's lengths ("mm", "in", "m", ...; also `report.units`). */
  units: string;
  /** The measured report (tolerance, triangles, max_deviation, warnings, ...); `faces_tessellated`
   * counts the faces given as triangles (STEP tessellated faces), which max_deviation does not cover. */
  report: Record<string, any>;
}

/**
 * Reads `bytes` in `format` ("json", "iges" or "igs", "step" or "stp", or "" / "auto" to detect it) and meshes the model.
 * Throws an `Error` whose message names the problem (the CLI's one-line error).
 */
export function mesh(bytes: Uint8Array, format: string, options?: MeshOptions): MeshOutput;

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

/** What `repair` returns. */
export interface RepairOutput {
  /** x, y, z per vertex. */
  positions: Float32Array;
  /** Three vertex indices per triangle, counter-clockwise seen from outside. */
  indices: Uint32Array;
  /** The report (triangles_in, triangles_out, segments, regions, census_out, time_ms, warnings, ...). */
  report: Record<string, any>;
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

/** Options of `fit`; every field is optional. */
export interface FitOptions {
  /** Absolute chordal tolerance of the mesh (exclusive with toleranceRel). */
  tolerance?: number;
  /** Tolerance as a fraction of the points' bounding-box diagonal (default 1e-3). */
  toleranceRel?: number;
  /** Largest polygon of the net, 3 to 32 (default 8; 3 keeps the triangles). */
  maxSides?: number;
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
  /** The report (points, polygons, sub_patches, sub_patches_triangular, max_g1_angle, warnings, ...). */
  report: Record<string, any>;
}

/**
 * Fits a G1 surface through the points of `bytes` in `format` ("xyz", "csv", "ply", or "" / "auto"
 * to detect it) by paper 004's polygon curve net, and meshes it within the tolerance.
 * Throws an `Error` whose message names the problem (the CLI's one-line error).
 */
export function fit(bytes: Uint8Array, format: string, options?: FitOptions): FitOutput;

/**
 * As `mesh`, calling `progress(facesDone, facesTotal)` after each face is meshed (sewing and
 * measuring follow the last call). Returning `false` stops meshing, which then throws an Error
 * whose message is "cancelled"; an exception thrown by `progress` stops it and is rethrown.
 */
export function meshWithProgress(
  bytes: Uint8Array,
  format: string,
  options: MeshOptions | undefined,
  progress: (facesDone: number, facesTotal: number) => boolean | void,
): MeshOutput;
"#;

/// Option names `mesh` accepts, in the order they are read.
const OPTION_NAMES: [&str; 13] = [
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
];

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
    let (options, units) = read_options(&options).map_err(|e| JsError::new(&e))?;
    run(bytes, format, &options, units, &mut |_, _| true).map_err(|e| JsError::new(&one_line(&e.to_string())))
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
    let (options, units) = read_options(&options).map_err(|e| JsValue::from(JsError::new(&e)))?;
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
    let result = run(bytes, format, &options, units, &mut call);
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

/// Parses, meshes (reporting each face to `progress`) and converts, timing
/// the two stages with the host clock. The input is freed once read: wasm
/// memory never shrinks, so the file need not sit beside the mesh at its peak.
fn run(
    bytes: Vec<u8>,
    format: &str,
    options: &MeshOptions,
    units: Units,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<JsValue, Error> {
    options.validate()?;
    let format = pick_format(&bytes, format)?;
    let t0 = now_ms();
    let (model, parts) = if format == Format::Step {
        let s = read_step_parts(&bytes)?;
        (s.model, Parts { names: s.parts, faces: s.face_parts, colours: s.face_colours })
    } else {
        let model = read_model(&bytes, format)?;
        let n = model.faces.len();
        (model, Parts { names: alloc::vec![String::new()], faces: alloc::vec![0; n], colours: alloc::vec![None; n] })
    };
    drop(bytes);
    let t1 = now_ms();
    let mut result = mesh_model_in_units(&model, options, units, progress)?;
    drop(model);
    let t2 = now_ms();
    if let (Some(t0), Some(t1), Some(t2)) = (t0, t1, t2) {
        result.report.parse_ms = t1 - t0;
        result.report.time_ms = t2 - t1;
    }
    to_js(&result, &parts)
}

/// Part names, each face's part and each face's colour, for the JS result.
struct Parts {
    names: Vec<String>,
    faces: Vec<u32>,
    colours: Vec<Option<[f32; 3]>>,
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

/// `performance.now()` when the host has it (browser, worker, Node), else `Date.now()`.
fn now_ms() -> Option<f64> {
    let perf = Reflect::get(&js_sys::global(), &JsValue::from_str("performance")).ok()?;
    if perf.is_object() {
        let now = Reflect::get(&perf, &JsValue::from_str("now")).ok()?;
        if let Some(f) = now.dyn_ref::<Function>() {
            if let Some(t) = f.call0(&perf).ok().and_then(|v| v.as_f64()) {
                return Some(t);
            }
        }
    }
    Some(js_sys::Date::now())
}

/// Reads the JS options object (every key must be known and every value of
/// its type) into the meshing options and the unit of the result.
fn read_options(value: &JsValue) -> Result<(MeshOptions, Units), String> {
    let mut options = MeshOptions::default();
    if value.is_undefined() || value.is_null() {
        return Ok((options, Units::File));
    }
    if !value.is_object() || Array::is_array(value) {
        return Err(format!("options: expected an object like {{ toleranceRel: 0.001 }}, found {}", type_name(value)));
    }
    let object: &Object = value.unchecked_ref();
    for key in Object::keys(object).iter() {
        let key = key.as_string().unwrap_or_default();
        if !OPTION_NAMES.contains(&key.as_str()) {
            return Err(format!("option {key}: unknown option (known: {})", OPTION_NAMES.join(", ")));
        }
    }
    let absolute = number(object, "tolerance")?;
    let relative = number(object, "toleranceRel")?;
    match (absolute, relative) {
        (Some(_), Some(_)) => return Err("option tolerance: give tolerance or toleranceRel, not both".into()),
        (Some(t), None) => options = options.with_tolerance(t),
        (None, Some(r)) => options = options.with_relative_tolerance(r),
        (None, None) => {}
    }
    if let Some(a) = number(object, "angle")? {
        options = options.with_angle(a);
    }
    if let Some(m) = number(object, "maxEdge")? {
        options = options.with_max_edge(Some(m));
    }
    if let Some(m) = number(object, "minEdge")? {
        options = options.with_min_edge(Some(m));
    }
    if let Some(n) = number(object, "maxTriangles")? {
        if !(n.is_finite() && n >= 0.0 && n.fract() == 0.0 && n <= u32::MAX as f64) {
            return Err(format!("option maxTriangles: expected a whole number, found {n}"));
        }
        options = options.with_max_triangles(n as usize);
    }
    let reparam = Reflect::get(object, &JsValue::from_str("reparam")).map_err(|_| "option reparam: cannot be read")?;
    if !(reparam.is_undefined() || reparam.is_null()) {
        let mode = match reparam.as_string().as_deref() {
            Some("auto") => Reparam::Auto,
            Some("off") => Reparam::Off,
            Some("force") => Reparam::Force,
            _ => return Err("option reparam: expected \"auto\", \"off\" or \"force\"".into()),
        };
        options = options.with_reparam(mode);
    }
    let mut quality = options.quality.clone();
    match (number(object, "size")?, number(object, "sizeRel")?) {
        (Some(_), Some(_)) => return Err("option size: give size or sizeRel, not both".into()),
        (Some(h), None) => quality = quality.with_size(h),
        (None, Some(r)) => quality = quality.with_relative_size(r),
        (None, None) => {}
    }
    if let Some(m) = word(object, "method", &["looping", "delaunay", "best"])? {
        let method = [QualityMethod::Looping, QualityMethod::Delaunay, QualityMethod::Best][m];
        quality = quality.with_method(method);
    }
    options = options.with_quality(quality);
    if let Some(m) = word(object, "mode", &["fast", "quality"])? {
        options = options.with_mode([MeshMode::Fast, MeshMode::Quality][m]);
    }
    let share = Reflect::get(object, &JsValue::from_str("share")).map_err(|_| "option share: cannot be read")?;
    if !(share.is_undefined() || share.is_null()) {
        let pair: Option<[u32; 2]> = Array::is_array(&share)
            .then(|| share.unchecked_ref::<Array>().to_vec())
            .filter(|v| v.len() == 2)
            .and_then(|v| {
                let whole = |x: &JsValue| x.as_f64().filter(|n| n.fract() == 0.0 && *n >= 0.0 && *n <= u32::MAX as f64);
                Some([whole(&v[0])? as u32, whole(&v[1])? as u32])
            });
        match pair {
            Some([i, n]) if i < n => options = options.with_share(i, n),
            _ => return Err("option share: expected [index, count] with whole numbers, index < count".into()),
        }
    }
    let units = Reflect::get(object, &JsValue::from_str("units")).map_err(|_| "option units: cannot be read")?;
    let units = match units.as_string() {
        Some(name) => Units::from_name(&name).map_err(|e| e.to_string())?,
        None if units.is_undefined() || units.is_null() => Units::File,
        None => return Err(format!("option units: expected a string, found {}", type_name(&units))),
    };
    Ok((options, units))
}

/// A string-valued option: the index of its value in `allowed`, `None` when absent.
fn word(object: &Object, name: &str, allowed: &[&str]) -> Result<Option<usize>, String> {
    let value = Reflect::get(object, &JsValue::from_str(name)).map_err(|_| format!("option {name}: cannot be read"))?;
    if value.is_undefined() || value.is_null() {
        return Ok(None);
    }
    let text = value.as_string().unwrap_or_default();
    match allowed.iter().position(|a| *a == text) {
        Some(i) => Ok(Some(i)),
        None => Err(format!("option {name}: expected one of \"{}\"", allowed.join("\", \""))),
    }
}

/// A number-valued option: `None` when absent (undefined or null).
fn number(object: &Object, name: &str) -> Result<Option<f64>, String> {
    let value = Reflect::get(object, &JsValue::from_str(name)).map_err(|_| format!("option {name}: cannot be read"))?;
    if value.is_undefined() || value.is_null() {
        return Ok(None);
    }
    match value.as_f64() {
        Some(x) if x.is_finite() => Ok(Some(x)),
        Some(x) => Err(format!("option {name}: expected a finite number, found {x}")),
        None => Err(format!("option {name}: expected a number, found {}", type_name(&value))),
    }
}

/// JS `typeof`-style name of a value, for error messages.
fn type_name(value: &JsValue) -> String {
    if value.is_null() {
        "null".into()
    } else if Array::is_array(value) {
        "an array".into()
    } else {
        value.js_typeof().as_string().unwrap_or_default()
    }
}

/// Builds `{ positions, normals, indices, faceRanges, faceParts, faceColors, parts, units, report }`.
fn to_js(result: &MeshResult, parts: &Parts) -> Result<JsValue, Error> {
    let mesh = &result.mesh;
    let flat =
        |v: &[glam::DVec3]| -> Vec<f32> { v.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect() };
    let ranges: Vec<u32> = mesh.face_ranges.iter().flat_map(|r| [r.first, r.count]).collect();
    let report_json =
        serde_json::to_string(&result.report).map_err(|e| Error::Internal(format!("report to JSON: {e}")))?;
    let report = JSON::parse(&report_json).map_err(|_| Error::Internal("report JSON rejected by JSON.parse".into()))?;

    let colours: Vec<f32> = parts.colours.iter().flat_map(|c| c.unwrap_or([f32::NAN; 3])).collect();
    let names = Array::new();
    for n in &parts.names {
        names.push(&JsValue::from_str(n));
    }
    let out = Object::new();
    // One f32 copy at a time, each freed once JS has its own.
    let positions: JsValue = Float32Array::from(flat(&mesh.positions).as_slice()).into();
    let normals: JsValue = Float32Array::from(flat(&mesh.normals).as_slice()).into();
    let fields: [(&str, JsValue); 9] = [
        ("positions", positions),
        ("normals", normals),
        ("indices", Uint32Array::from(mesh.indices.as_slice()).into()),
        ("faceRanges", Uint32Array::from(ranges.as_slice()).into()),
        ("faceParts", Uint32Array::from(parts.faces.as_slice()).into()),
        ("faceColors", Float32Array::from(colours.as_slice()).into()),
        ("parts", names.into()),
        ("units", JsValue::from_str(&result.report.units)),
        ("report", report),
    ];
    for (name, value) in fields {
        Reflect::set(&out, &JsValue::from_str(name), &value)
            .map_err(|_| Error::Internal(format!("cannot set result field {name}")))?;
    }
    Ok(out.into())
}

/// Option names `repair` accepts.
const REPAIR_OPTION_NAMES: [&str; 5] = ["bucketing", "bucketCapacity", "weldTolerance", "perturbation", "verify"];

/// Reads a mesh (`"stl"`, `"obj"`, or `""`/`"auto"` to detect it) and repairs it (paper 002).
///
/// # Errors
/// Throws a JS `Error` with the one-line message of a bad option, a reader
/// error with its line, or a mesh that cannot be repaired.
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn repair(bytes: &[u8], format: &str, options: JsValue) -> Result<JsValue, JsError> {
    let options = read_repair_options(&options).map_err(|e| JsError::new(&e))?;
    run_repair(bytes, format, &options).map_err(|e| JsError::new(&one_line(&e.to_string())))
}

/// Reads a mesh (`format` as for [`repair`]) and offsets it by `distance` along its vertex normals.
///
/// # Errors
/// Throws a JS `Error` with the reader's or the offset's one-line message.
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn offset(bytes: &[u8], format: &str, distance: f64) -> Result<JsValue, JsError> {
    let run = || -> Result<JsValue, Error> {
        let mesh = read_mesh(bytes, mesh_format(bytes, format)?)?;
        let out = offset_mesh(&mesh, distance)?;
        let positions: Vec<f32> = out.positions.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
        let obj = Object::new();
        for (name, value) in [
            ("positions", JsValue::from(Float32Array::from(positions.as_slice()))),
            ("indices", Uint32Array::from(out.indices.as_slice()).into()),
        ] {
            Reflect::set(&obj, &JsValue::from_str(name), &value)
                .map_err(|_| Error::Internal(format!("cannot set result field {name}")))?;
        }
        Ok(obj.into())
    };
    run().map_err(|e| JsError::new(&one_line(&e.to_string())))
}

/// `""` and `"auto"` detect the mesh format from the bytes; anything else is a name.
fn mesh_format(bytes: &[u8], name: &str) -> Result<MeshFormat, Error> {
    if name.is_empty() || name.eq_ignore_ascii_case("auto") {
        MeshFormat::detect(bytes).ok_or_else(|| {
            Error::Format("cannot detect the mesh format from its first bytes (expected stl or obj)".into())
        })
    } else {
        MeshFormat::from_name(name)
    }
}

fn run_repair(bytes: &[u8], format: &str, options: &RepairOptions) -> Result<JsValue, Error> {
    options.validate()?;
    let format = mesh_format(bytes, format)?;
    let t0 = now_ms().unwrap_or(0.0);
    let mesh = read_mesh(bytes, format)?;
    let t1 = now_ms().unwrap_or(0.0);
    let result = repair_mesh_timed(&mesh, options, &mut || now_ms().unwrap_or(0.0) - t1)?;
    let mut report =
        serde_json::to_value(&result.report).map_err(|e| Error::Internal(format!("report to JSON: {e}")))?;
    if let Some(o) = report.as_object_mut() {
        o.insert("parse_ms".into(), (t1 - t0).into());
    }
    let report_json = serde_json::to_string(&report).map_err(|e| Error::Internal(format!("report to JSON: {e}")))?;
    let report = JSON::parse(&report_json).map_err(|_| Error::Internal("report JSON rejected by JSON.parse".into()))?;
    let positions: Vec<f32> = result.mesh.positions.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
    let out = Object::new();
    let fields: [(&str, JsValue); 3] = [
        ("positions", Float32Array::from(positions.as_slice()).into()),
        ("indices", Uint32Array::from(result.mesh.indices.as_slice()).into()),
        ("report", report),
    ];
    for (name, value) in fields {
        Reflect::set(&out, &JsValue::from_str(name), &value)
            .map_err(|_| Error::Internal(format!("cannot set result field {name}")))?;
    }
    Ok(out.into())
}

/// Reads the JS options object of `repair`; every key must be known.
fn read_repair_options(value: &JsValue) -> Result<RepairOptions, String> {
    let mut options = RepairOptions::default();
    if value.is_undefined() || value.is_null() {
        return Ok(options);
    }
    if !value.is_object() || Array::is_array(value) {
        return Err(format!("options: expected an object like {{ bucketing: \"kd\" }}, found {}", type_name(value)));
    }
    let object: &Object = value.unchecked_ref();
    for key in Object::keys(object).iter() {
        let key = key.as_string().unwrap_or_default();
        if !REPAIR_OPTION_NAMES.contains(&key.as_str()) {
            return Err(format!("option {key}: unknown option (known: {})", REPAIR_OPTION_NAMES.join(", ")));
        }
    }
    let get = |name: &str| {
        Reflect::get(object, &JsValue::from_str(name)).map_err(|_| format!("option {name}: cannot be read"))
    };
    let b = get("bucketing")?;
    if !b.is_undefined() && !b.is_null() {
        options = options.with_bucketing(match b.as_string().as_deref() {
            Some("kd") => Bucketing::KdTree,
            Some("bvh") => Bucketing::Bvh,
            _ => return Err("option bucketing: expected \"kd\" or \"bvh\"".into()),
        });
    }
    if let Some(n) = number(object, "bucketCapacity")? {
        if !(n.fract() == 0.0 && n >= 0.0 && n <= u32::MAX as f64) {
            return Err(format!("option bucketCapacity: expected a whole number, found {n}"));
        }
        options = options.with_bucket_capacity(n as usize);
    }
    if let Some(w) = number(object, "weldTolerance")? {
        options = options.with_weld_tolerance(w);
    }
    if let Some(p) = number(object, "perturbation")? {
        options.perturbation = p;
    }
    let v = get("verify")?;
    if !v.is_undefined() && !v.is_null() {
        options = options.with_verify(
            v.as_bool().ok_or_else(|| format!("option verify: expected a boolean, found {}", type_name(&v)))?,
        );
    }
    Ok(options)
}

/// Option names `fit` accepts.
const FIT_OPTION_NAMES: [&str; 3] = ["tolerance", "toleranceRel", "maxSides"];

/// Reads points (`"xyz"`, `"csv"`, `"ply"`, or `""`/`"auto"` to detect them)
/// and fits a surface through them (paper 004).
///
/// # Errors
/// Throws a JS `Error` with the one-line message of a bad option, a reader
/// error naming its line, or points no surface passes through.
#[cfg_attr(not(test), wasm_bindgen(skip_typescript))]
pub fn fit(bytes: &[u8], format: &str, options: JsValue) -> Result<JsValue, JsError> {
    let options = read_fit_options(&options).map_err(|e| JsError::new(&e))?;
    let run = || -> Result<JsValue, Error> {
        let format = if format.is_empty() || format.eq_ignore_ascii_case("auto") {
            PointFormat::detect(bytes)
        } else {
            PointFormat::from_name(format)?
        };
        let points = read_points(bytes, format)?;
        let t0 = now_ms();
        let mut result = fit_points(&points, &options)?;
        if let (Some(t0), Some(t1)) = (t0, now_ms()) {
            result.report.time_ms = t1 - t0;
        }
        fit_to_js(&result)
    };
    run().map_err(|e| JsError::new(&one_line(&e.to_string())))
}

/// Reads the JS options object of `fit`; every key must be known and every value a number.
fn read_fit_options(value: &JsValue) -> Result<FitOptions, String> {
    let mut options = FitOptions::default();
    if value.is_undefined() || value.is_null() {
        return Ok(options);
    }
    if !value.is_object() || Array::is_array(value) {
        return Err(format!("options: expected an object like {{ toleranceRel: 0.001 }}, found {}", type_name(value)));
    }
    let object: &Object = value.unchecked_ref();
    for key in Object::keys(object).iter() {
        let key = key.as_string().unwrap_or_default();
        if !FIT_OPTION_NAMES.contains(&key.as_str()) {
            return Err(format!("option {key}: unknown option (known: {})", FIT_OPTION_NAMES.join(", ")));
        }
    }
    match (number(object, "tolerance")?, number(object, "toleranceRel")?) {
        (Some(_), Some(_)) => return Err("option tolerance: give tolerance or toleranceRel, not both".into()),
        (Some(t), None) => options = options.with_tolerance(t),
        (None, Some(r)) => options = options.with_relative_tolerance(r),
        (None, None) => {}
    }
    if let Some(n) = number(object, "maxSides")? {
        if !(n.fract() == 0.0 && (3.0..=32.0).contains(&n)) {
            return Err(format!("option maxSides: expected a whole number from 3 to 32, found {n}"));
        }
        options = options.with_max_polygon_sides(n as usize);
    }
    options.validate().map_err(|e| e.to_string())?;
    Ok(options)
}

/// Builds `{ positions, normals, indices, faceRanges, points, netEdges, patches, report }`.
fn fit_to_js(result: &FitResult) -> Result<JsValue, Error> {
    let flat =
        |v: &[glam::DVec3]| -> Vec<f32> { v.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect() };
    let mesh = &result.mesh;
    let ranges: Vec<u32> = mesh.face_ranges.iter().flat_map(|r| [r.first, r.count]).collect();
    let edges: Vec<u32> = result.surface.edges().iter().flat_map(|(a, b, _)| [*a, *b]).collect();
    let report_json =
        serde_json::to_string(&result.report).map_err(|e| Error::Internal(format!("report to JSON: {e}")))?;
    let report = JSON::parse(&report_json).map_err(|_| Error::Internal("report JSON rejected by JSON.parse".into()))?;
    let out = Object::new();
    let fields: [(&str, JsValue); 8] = [
        ("positions", Float32Array::from(flat(&mesh.positions).as_slice()).into()),
        ("normals", Float32Array::from(flat(&mesh.normals).as_slice()).into()),
        ("indices", Uint32Array::from(mesh.indices.as_slice()).into()),
        ("faceRanges", Uint32Array::from(ranges.as_slice()).into()),
        ("points", Float32Array::from(flat(&result.surface.points).as_slice()).into()),
        ("netEdges", Uint32Array::from(edges.as_slice()).into()),
        ("patches", JsValue::from_str(&result.surface.to_json())),
        ("report", report),
    ];
    for (name, value) in fields {
        Reflect::set(&out, &JsValue::from_str(name), &value)
            .map_err(|_| Error::Internal(format!("cannot set result field {name}")))?;
    }
    Ok(out.into())
}
