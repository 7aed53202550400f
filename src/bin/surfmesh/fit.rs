//! `surfmesh fit`: a G¹ surface through the points of an xyz, csv or ply
//! file (paper 004), written as a mesh and, on request, its patches as JSON.

use crate::error::CliError;
use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use surfmesh::{fit_points, read_points, write_glb, write_obj, write_stl, FitOptions, PointFormat};

use crate::args::{output_format, OutputFormat};

/// Arguments of `surfmesh fit`.
pub struct FitArgs {
    /// The point file.
    pub input: PathBuf,
    /// Input format given by `--format`; otherwise from the extension or the content.
    pub format: Option<PointFormat>,
    /// Fit options, validated.
    pub options: FitOptions,
    /// Mesh output file and its format.
    pub output: Option<(PathBuf, OutputFormat)>,
    /// Patch (JSON) output file.
    pub patches: Option<PathBuf>,
    /// Report output file.
    pub report: Option<PathBuf>,
}

/// The usage lines of `fit`, printed after the main usage text.
pub const USAGE: &str = "\
Surfaces through scattered points (paper 004):
  surfmesh fit POINTS [-o OUT] [--patches P.json] [--report R] [--tol X | --tol-rel R]
                  [--max-sides N] [--format xyz|csv|ply]
                                           a G1 surface through every point of POINTS
                                           (.xyz, .csv or .ply), meshed within the
                                           tolerance (default 0.001 of the diagonal);
                                           --patches writes its polygon net and quartic
                                           sub-patches as JSON; --max-sides caps the
                                           polygons (3 to 32, default 8)
";

/// Parses the arguments after `fit`.
///
/// # Errors
/// A one-line message for a usage error.
pub fn parse(mut args: impl Iterator<Item = OsString>) -> Result<FitArgs, CliError> {
    let mut input: Option<PathBuf> = None;
    let mut format = None;
    let mut options = FitOptions::default();
    let (mut tol, mut tol_rel) = (None, None);
    let (mut output, mut patches, mut report) = (None, None, None);
    while let Some(arg) = args.next() {
        let Some(text) = arg.to_str().filter(|t| t.starts_with('-') && t.len() > 1) else {
            if input.replace(PathBuf::from(&arg)).is_some() {
                return Err(CliError::usage(format!("more than one input file ('{}')", arg.to_string_lossy())));
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
            "--tol" => tol = Some(number(&name, value()?)?),
            "--tol-rel" => tol_rel = Some(number(&name, value()?)?),
            "--max-sides" => {
                let v = value()?;
                let n = v.to_str().and_then(|s| s.parse().ok());
                options = options.with_max_polygon_sides(
                    n.ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a count", v.to_string_lossy())))?,
                );
            }
            "--format" => {
                let v = value()?;
                format = Some(
                    PointFormat::from_name(&v.to_string_lossy())
                        .map_err(|e| CliError::usage(format!("--format: {e}")))?,
                );
            }
            "-o" | "--output" => {
                let path = PathBuf::from(value()?);
                let kind = output_format(&path)?;
                output = Some((path, kind));
            }
            "--patches" => patches = Some(PathBuf::from(value()?)),
            "--report" => report = Some(PathBuf::from(value()?)),
            _ => return Err(CliError::usage(format!("unknown option '{text}' for fit; try 'surfmesh --help'"))),
        }
    }
    let input = input.ok_or_else(|| CliError::usage("fit needs a POINTS file; try 'surfmesh --help'"))?;
    options = match (tol, tol_rel) {
        (Some(_), Some(_)) => return Err(CliError::usage("give --tol or --tol-rel, not both")),
        (Some(t), None) => options.with_tolerance(t),
        (None, Some(r)) => options.with_relative_tolerance(r),
        (None, None) => options,
    };
    options.validate()?;
    let names: Vec<&PathBuf> = output.iter().map(|(p, _)| p).chain(patches.iter()).chain(report.iter()).collect();
    if names.iter().enumerate().any(|(i, a)| names[..i].contains(a)) {
        return Err(CliError::usage("-o, --patches and --report must name different files"));
    }
    Ok(FitArgs { input, format, options, output, patches, report })
}

fn number(name: &str, value: OsString) -> Result<f64, CliError> {
    value
        .to_str()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a number", value.to_string_lossy())))
}

/// Runs the fit; the error is the message printed after the input file's name.
pub fn run(a: &FitArgs) -> Result<(), CliError> {
    let bytes = fs::read(&a.input).map_err(CliError::read)?;
    let format = match a.format {
        Some(f) => f,
        None => input_format(&a.input, &bytes),
    };
    let points = read_points(&bytes, format)?;
    let start = Instant::now();
    let mut result = fit_points(&points, &a.options)?;
    result.report.time_ms = start.elapsed().as_secs_f64() * 1e3;

    let report_json = serde_json::to_string_pretty(&result.report).map_err(CliError::report)?;
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some((path, kind)) = &a.output {
        let bytes = match kind {
            OutputFormat::Stl => write_stl(&result.mesh),
            OutputFormat::Obj => write_obj(&result.mesh),
            OutputFormat::Glb => write_glb(&result.mesh),
            OutputFormat::Msh => surfmesh::write_msh(&result.mesh),
            OutputFormat::Unv => surfmesh::write_unv(&result.mesh),
        };
        files.push((path, bytes));
    }
    if let Some(path) = &a.patches {
        files.push((path, format!("{}\n", result.surface.to_json()).into_bytes()));
    }
    if let Some(path) = &a.report {
        files.push((path, format!("{report_json}\n").into_bytes()));
    }
    crate::write_all_or_nothing(&files)?;
    if files.is_empty() {
        println!("{report_json}");
    }
    let r = &result.report;
    eprintln!(
        "surfmesh: {}: {} points, {} polygons, {} sub-patches (3(n-2) would be {}), G1 within {:.1e} rad, \
         {} triangles within {:.3e}, {:.1} ms",
        a.input.display(),
        r.points,
        r.polygons,
        r.sub_patches,
        r.sub_patches_triangular,
        r.max_g1_angle,
        r.triangles,
        r.tolerance,
        r.time_ms
    );
    for w in &r.warnings {
        eprintln!("surfmesh: {}: warning: {w}", a.input.display());
    }
    Ok(())
}

/// Point format from the file's extension, else from its first bytes.
fn input_format(path: &Path, bytes: &[u8]) -> PointFormat {
    path.extension()
        .and_then(|e| e.to_str())
        .and_then(|e| PointFormat::from_name(e).ok())
        .unwrap_or_else(|| PointFormat::detect(bytes))
}
