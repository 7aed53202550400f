//! `surfmesh check`: meshes every model file of a folder, on every core,
//! and prints one row per file (faces meshed of the file's faces, skipped
//! faces, cracks, non-manifold edges, inverted triangles, deviation over
//! tolerance, time, the first warning) and the totals; `--json` writes the
//! rows for a later comparison (scripts/check-baseline.mjs).
//!
//! Each file is meshed by a child process (`surfmesh check --row FILE`,
//! which prints its row as JSON), so that one stuck in a single long stage
//! (the core has no clock to stop it) is killed at its time limit, and one
//! that crashes costs its own row only.

use crate::error::{CliError, IoAction};
use std::ffi::OsString;
use std::fs;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use surfmesh::{mesh_model_in_units, read_model, Error, Format, MeshOptions, Units};

/// Arguments of `surfmesh check`.
pub struct CheckArgs {
    /// The folder.
    pub dir: PathBuf,
    /// Meshing options, validated.
    pub options: MeshOptions,
    /// Length unit of the rows' lengths.
    pub units: Units,
    /// Where the rows go as JSON.
    pub json: Option<PathBuf>,
    /// A file still meshing after this many seconds stops (checked after each face).
    pub timeout: f64,
    /// Files meshed at once (default: one per core).
    pub jobs: Option<usize>,
    /// `--row FILE NAME`: mesh this one file here and print its row as JSON (the child's part).
    pub row: Option<(PathBuf, String)>,
    /// The options a child is given: the tolerance and the unit, as given.
    pub forward: Vec<OsString>,
}

/// The usage lines of `check`, printed after the main usage text.
pub const USAGE: &str = "\
Sweeping a folder:
  surfmesh check DIR [--tol X | --tol-rel R] [--units U] [--json OUT.json]
                 [--timeout S] [--jobs N]
                                           meshes every IGES, STEP and JSON file of DIR
                                           (and its folders, not hidden ones) in parallel
                                           and prints a row per file: faces meshed / faces
                                           in the file, faces the reader could not build
                                           (unread) and faces left without triangles
                                           (empty), cracks, non-manifold edges, inverted
                                           triangles, deviation / tolerance, time and the
                                           first warning, then the totals; --json writes
                                           the rows; a file still meshing after S seconds
                                           (default 120) stops and fails.
                                           Exit status 0 when every file meshed, 1 when
                                           any failed, 2 for a usage error.
";

/// Parses the arguments after `check`.
///
/// # Errors
/// A one-line message for a usage error.
pub fn parse(mut args: impl Iterator<Item = OsString>) -> Result<CheckArgs, CliError> {
    let mut dir: Option<PathBuf> = None;
    let (mut tol, mut tol_rel) = (None, None);
    let mut units = Units::File;
    let mut json = None;
    let mut timeout = 120.0;
    let mut jobs = None;
    let mut row = None;
    let mut forward = Vec::new();
    while let Some(arg) = args.next() {
        let Some(text) = arg.to_str().filter(|t| t.starts_with('-') && t.len() > 1) else {
            if dir.replace(PathBuf::from(&arg)).is_some() {
                return Err(CliError::usage(format!("more than one folder ('{}')", arg.to_string_lossy())));
            }
            continue;
        };
        let (name, inline) = match text.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n, Some(OsString::from(v))),
            _ => (text, None),
        };
        let name = name.to_owned();
        let mut value =
            || inline.clone().or_else(|| args.next()).ok_or_else(|| CliError::usage(format!("{name} needs a value")));
        match name.as_str() {
            "--tol" | "--tol-rel" | "--units" => {
                let v = value()?;
                forward.extend([OsString::from(&name), v.clone()]);
                match name.as_str() {
                    "--tol" => tol = Some(number(&name, v)?),
                    "--tol-rel" => tol_rel = Some(number(&name, v)?),
                    _ => units = Units::from_name(&v.to_string_lossy())?,
                }
            }
            "--row" => {
                let file = PathBuf::from(value()?);
                let shown = args.next().ok_or_else(|| CliError::usage("--row needs a file and its name"))?;
                row = Some((file, shown.to_string_lossy().into_owned()));
            }
            "--json" => json = Some(PathBuf::from(value()?)),
            "--timeout" => {
                timeout = number(&name, value()?)?;
                if !(timeout > 0.0 && timeout.is_finite()) {
                    return Err(CliError::usage("--timeout must be a number of seconds > 0"));
                }
            }
            "--jobs" => {
                let v = value()?;
                let n = v.to_str().and_then(|s| s.parse::<usize>().ok()).filter(|&n| n > 0);
                jobs =
                    Some(n.ok_or_else(|| {
                        CliError::usage(format!("{name}: '{}' is not a count > 0", v.to_string_lossy()))
                    })?);
            }
            _ => return Err(CliError::usage(format!("unknown option '{text}' of check; try 'surfmesh --help'"))),
        }
    }
    let dir = match (&row, dir) {
        (Some(_), None) => PathBuf::new(),
        (None, Some(d)) => d,
        (Some(_), Some(_)) => return Err(CliError::usage("--row takes one file, not a folder")),
        (None, None) => return Err(CliError::usage("check needs a folder; try 'surfmesh --help'")),
    };
    let options = match (tol, tol_rel) {
        (Some(_), Some(_)) => return Err(CliError::usage("give --tol or --tol-rel, not both")),
        (Some(t), None) => MeshOptions::default().with_tolerance(t),
        (None, Some(r)) => MeshOptions::default().with_relative_tolerance(r),
        (None, None) => MeshOptions::default(),
    };
    options.validate()?;
    Ok(CheckArgs { dir, options, units, json, timeout, jobs, row, forward })
}

fn number(name: &str, value: OsString) -> Result<f64, CliError> {
    value
        .to_str()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a number", value.to_string_lossy())))
}

/// One file's outcome; the field names are what `--json` writes, kept
/// stable so that two sweeps can be compared.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Row {
    /// Path relative to the folder, `/` between parts.
    pub file: String,
    /// `json`, `iges` or `step`.
    pub format: String,
    /// Whether the file meshed (read and meshed without an error).
    pub ok: bool,
    /// The one-line error of a file that did not mesh.
    pub error: Option<String>,
    /// Faces in the file: the model's (exact and tessellated) and those the
    /// reader could not build.
    pub faces_in_file: usize,
    /// Faces with at least one triangle.
    pub faces_meshed: usize,
    /// Faces the reader could not build (each with a warning).
    pub faces_unread: usize,
    /// Faces of the model (exact or tessellated) that produced no triangles.
    pub faces_empty: usize,
    /// Triangles.
    pub triangles: usize,
    /// Cracks: free edges after welding that are not the model's boundary.
    pub cracks: usize,
    /// Edges with more than two triangles.
    pub nonmanifold_edges: usize,
    /// Triangles whose facet normal opposes the surface normal.
    pub inverted_triangles: usize,
    /// Largest measured deviation, in `units`.
    pub max_deviation: f64,
    /// Tolerance used, in `units`.
    pub tolerance: f64,
    /// `max_deviation / tolerance` (at most 1 when the promise holds).
    pub deviation_ratio: f64,
    /// Length unit of the row's lengths.
    pub units: String,
    /// Read and mesh time, milliseconds (wall clock, with other files meshing beside it).
    pub time_ms: f64,
    /// Read time, milliseconds.
    pub parse_ms: f64,
    /// Number of warnings.
    pub warnings: usize,
    /// The first warning, if any.
    pub first_warning: Option<String>,
}

/// What `--json` writes: the settings and one row per file, sorted by name.
#[derive(Serialize)]
struct Sweep<'a> {
    /// The folder as given.
    dir: String,
    /// `"relative 0.01"` or `"absolute 0.5"`.
    tolerance: String,
    /// `file` or the unit asked for.
    units: &'a str,
    /// The rows.
    files: &'a [Row],
}

/// `surfmesh check`: the exit status is 0 when every file meshed, 1 when any failed.
///
/// # Errors
/// A folder that cannot be read, or a JSON file that cannot be written.
pub fn run(a: &CheckArgs) -> Result<bool, CliError> {
    if let Some((path, name)) = &a.row {
        // The child: this file's row on stdout.
        let format = file_format(path).unwrap_or(Format::Json);
        let row = check_file(a, path, name, format);
        println!("{}", serde_json::to_string(&row).map_err(|e| CliError::run("row to JSON", e))?);
        return Ok(true);
    }
    let files = model_files(&a.dir)?;
    let exe = std::env::current_exe().map_err(|e| CliError::run("cannot find the surfmesh executable", e))?;
    let start = Instant::now();
    let mut rows = rows_of(a, &exe, &files)?;
    rows.sort_by(|x, y| x.file.cmp(&y.file));
    let wall = start.elapsed().as_secs_f64();
    print_rows(&rows, wall);
    if let Some(out) = &a.json {
        let tolerance = match a.options.tolerance {
            surfmesh::Tolerance::Absolute(t) => format!("absolute {t}"),
            surfmesh::Tolerance::Relative(r) => format!("relative {r}"),
        };
        let units = a.units.name().unwrap_or("file");
        let sweep = Sweep { dir: a.dir.display().to_string(), tolerance, units, files: &rows };
        let text = serde_json::to_string_pretty(&sweep).map_err(|e| CliError::run("rows to JSON", e))?;
        fs::write(out, format!("{text}\n")).map_err(|e| CliError::write(out, e))?;
    }
    Ok(rows.iter().all(|r| r.ok))
}

/// Each file's row, `--jobs` files at once (one per core by default).
#[cfg(not(target_arch = "wasm32"))]
fn rows_of(a: &CheckArgs, exe: &Path, files: &[(PathBuf, String, Format)]) -> Result<Vec<Row>, CliError> {
    use rayon::prelude::*;
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = a.jobs {
        b = b.num_threads(n);
    }
    let pool = b.build().map_err(|e| CliError::run("cannot start the workers", e))?;
    Ok(pool.install(|| files.par_iter().map(|(path, name, format)| in_child(a, exe, path, name, *format)).collect()))
}

/// One file at a time: a wasm32 build of the command line (compiled only
/// because the wasm tests' harness builds the package's binaries) has no rayon.
#[cfg(target_arch = "wasm32")]
fn rows_of(a: &CheckArgs, exe: &Path, files: &[(PathBuf, String, Format)]) -> Result<Vec<Row>, CliError> {
    Ok(files.iter().map(|(path, name, format)| in_child(a, exe, path, name, *format)).collect())
}

/// The model files under `dir` (hidden files and folders left out), each
/// with its name relative to `dir` and its format: a model extension, else
/// what its first bytes say (so notes such as SOURCES.md stay out).
fn model_files(dir: &Path) -> Result<Vec<(PathBuf, String, Format)>, CliError> {
    let mut out = Vec::new();
    let mut stack = vec![(dir.to_path_buf(), String::new())];
    while let Some((d, prefix)) = stack.pop() {
        let entries =
            fs::read_dir(&d).map_err(|source| CliError::Io { action: IoAction::ReadFolder(d.clone()), source })?;
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue;
            }
            let path = entry.path();
            let rel = if prefix.is_empty() { name.clone() } else { format!("{prefix}/{name}") };
            if path.is_dir() {
                stack.push((path, rel));
                continue;
            }
            if let Some(f) = file_format(&path) {
                out.push((path, rel, f));
            }
        }
    }
    Ok(out)
}

/// A model file's format: its extension's, else what its first bytes say;
/// `None` for a file that is not a model.
fn file_format(path: &Path) -> Option<Format> {
    let by_name = path.extension().and_then(|e| e.to_str()).and_then(|e| Format::from_name(e).ok());
    by_name.or_else(|| {
        let mut head = vec![0u8; 4096];
        let n = fs::File::open(path).and_then(|mut f| f.read(&mut head)).ok()?;
        Format::detect(&head[..n])
    })
}

/// One file's row from a child process, killed at the time limit.
fn in_child(a: &CheckArgs, exe: &Path, path: &Path, name: &str, format: Format) -> Row {
    let start = Instant::now();
    let failed = |error: String| Row {
        file: name.to_string(),
        format: format_name(format).into(),
        error: Some(error),
        time_ms: start.elapsed().as_secs_f64() * 1e3,
        ..Row::default()
    };
    let mut args: Vec<OsString> = vec!["check".into(), "--row".into(), path.into(), name.into()];
    args.extend(a.forward.iter().cloned());
    args.extend(["--timeout".into(), a.timeout.to_string().into()]);
    let child = Command::new(exe).args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => return failed(format!("cannot start surfmesh: {e}")),
    };
    // The child checks its clock after each face; a stage that runs on
    // past the limit and a grace of a tenth is stopped from here.
    let limit = Duration::from_secs_f64(a.timeout * 1.1 + 1.0);
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() < limit => std::thread::sleep(Duration::from_millis(20)),
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                return failed(format!("stopped after {} s (--timeout)", a.timeout));
            }
            Err(e) => return failed(format!("cannot wait for surfmesh: {e}")),
        }
    };
    let (mut out, mut err) = (Vec::new(), String::new());
    if let Some(mut s) = child.stdout.take() {
        let _ = s.read_to_end(&mut out);
    }
    if let Some(mut s) = child.stderr.take() {
        let _ = s.read_to_string(&mut err);
    }
    match serde_json::from_slice::<Row>(&out) {
        Ok(row) if status.success() => row,
        _ => failed(format!("surfmesh crashed ({status}): {}", one_line(err.lines().next().unwrap_or("")))),
    }
}

/// Reads and meshes one file; whatever fails becomes the row's error.
fn check_file(a: &CheckArgs, path: &Path, name: &str, format: Format) -> Row {
    let mut row = Row { file: name.to_string(), format: format_name(format).into(), ..Row::default() };
    let start = Instant::now();
    let result = (|| -> Result<(), Error> {
        let bytes = fs::read(path).map_err(|e| Error::Format(format!("cannot read: {e}")))?;
        let model = read_model(&bytes, format)?;
        drop(bytes);
        row.parse_ms = start.elapsed().as_secs_f64() * 1e3;
        row.faces_unread = model.skipped.len();
        let built = model.faces.len() + model.tessellated.len();
        row.faces_in_file = built + model.skipped.len();
        let mut within = |_: usize, _: usize| start.elapsed().as_secs_f64() < a.timeout;
        let r = mesh_model_in_units(&model, &a.options, a.units, &mut within)?;
        let rep = &r.report;
        row.faces_meshed = r.mesh.face_ranges.iter().filter(|f| f.count > 0).count();
        row.faces_empty = built.saturating_sub(row.faces_meshed);
        row.triangles = rep.triangles;
        row.cracks = rep.free_edges;
        row.nonmanifold_edges = rep.nonmanifold_edges;
        row.inverted_triangles = rep.inverted_triangles;
        row.max_deviation = rep.max_deviation;
        row.tolerance = rep.tolerance;
        row.deviation_ratio = if rep.tolerance > 0.0 { rep.max_deviation / rep.tolerance } else { 0.0 };
        row.units = rep.units.clone();
        // Reader warnings first, as `mesh` reports them.
        let mut warnings: Vec<&surfmesh::Warning> = model.warnings.iter().collect();
        warnings.extend(rep.warnings.iter().filter(|w| !model.warnings.contains(w)));
        row.warnings = warnings.len();
        row.first_warning = warnings.first().map(|w| one_line(&w.to_string()));
        Ok(())
    })();
    row.time_ms = start.elapsed().as_secs_f64() * 1e3;
    match result {
        Ok(()) => row.ok = true,
        Err(Error::Cancelled) => row.error = Some(format!("stopped after {} s (--timeout)", a.timeout)),
        Err(e) => row.error = Some(one_line(&e.to_string())),
    }
    row
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Json => "json",
        Format::Iges => "iges",
        _ => "step",
    }
}

fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `text` cut to `n` characters, an ellipsis marking the cut.
fn shorten(text: &str, n: usize) -> String {
    if text.chars().count() <= n {
        text.to_string()
    } else {
        let mut s: String = text.chars().take(n - 1).collect();
        s.push('…');
        s
    }
}

/// The table and the totals line, on stdout.
fn print_rows(rows: &[Row], wall: f64) {
    let width = rows.iter().map(|r| r.file.chars().count()).max().unwrap_or(4).clamp(4, 48);
    println!(
        "{:<width$} {:>11} {:>6} {:>5} {:>6} {:>4} {:>4} {:>7} {:>8}  first warning / error",
        "file", "faces", "unread", "empty", "cracks", "nm", "inv", "dev/tol", "time s"
    );
    for r in rows {
        let file = shorten(&r.file, width);
        if let Some(e) = &r.error {
            println!("{file:<width$} {:>11} {:>8.2}  ERROR {}", "-", r.time_ms / 1e3, shorten(e, 100));
            continue;
        }
        println!(
            "{file:<width$} {:>11} {:>6} {:>5} {:>6} {:>4} {:>4} {:>7.3} {:>8.2}  {}",
            format!("{}/{}", r.faces_meshed, r.faces_in_file),
            r.faces_unread,
            r.faces_empty,
            r.cracks,
            r.nonmanifold_edges,
            r.inverted_triangles,
            r.deviation_ratio,
            r.time_ms / 1e3,
            r.first_warning.as_deref().map(|w| shorten(w, 70)).unwrap_or_default()
        );
    }
    let ok: Vec<&Row> = rows.iter().filter(|r| r.ok).collect();
    let sum = |f: fn(&Row) -> usize| ok.iter().map(|r| f(r)).sum::<usize>();
    let over = ok.iter().filter(|r| r.deviation_ratio.is_nan() || r.deviation_ratio > 1.0).count();
    println!(
        "total: {} files, {} meshed, {} failed; faces {}/{} ({} unread, {} empty); {} cracks, {} non-manifold, \
         {} inverted; {} over tolerance; {:.1} s",
        rows.len(),
        ok.len(),
        rows.len() - ok.len(),
        sum(|r| r.faces_meshed),
        sum(|r| r.faces_in_file),
        sum(|r| r.faces_unread),
        sum(|r| r.faces_empty),
        sum(|r| r.cracks),
        sum(|r| r.nonmanifold_edges),
        sum(|r| r.inverted_triangles),
        over,
        wall
    );
}
