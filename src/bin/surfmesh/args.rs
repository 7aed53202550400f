//! Command-line parsing, by hand: the grammar is small and this keeps the
//! binary free of extra dependencies.

use crate::error::CliError;
use std::ffi::OsString;
use std::path::PathBuf;

use surfmesh::{Format, MeshMode, MeshOptions, QualityMethod, Reparam, Units};

/// What the user asked for.
pub enum Command {
    /// Print the usage text.
    Help,
    /// Print the version.
    Version,
    /// Mesh a model file.
    Mesh(MeshArgs),
    /// Offset a mesh along its vertex normals.
    Offset(crate::repair::OffsetArgs),
    /// Repair a mesh (paper 002).
    Repair(crate::repair::RepairArgs),
    /// Fit a surface through a point file.
    Fit(crate::fit::FitArgs),
    /// Rebuild poorly parameterized faces and write IGES (paper 001).
    Reparam(crate::reparam::ReparamArgs),
    /// Mesh every model file of a folder and tabulate the results.
    Check(crate::check::CheckArgs),
}

/// Arguments of `surfmesh mesh`.
pub struct MeshArgs {
    /// The model file.
    pub input: PathBuf,
    /// Input format given by `--format`; otherwise guessed from the file.
    pub format: Option<Format>,
    /// Meshing options, validated.
    pub options: MeshOptions,
    /// Length unit of the mesh and the report (and of the absolute options).
    pub units: Units,
    /// Mesh output file and its format.
    pub output: Option<(PathBuf, OutputFormat)>,
    /// Report output file.
    pub report: Option<PathBuf>,
}

/// Mesh file formats, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// Binary STL.
    Stl,
    /// Wavefront OBJ.
    Obj,
    /// Binary glTF 2.0.
    Glb,
    /// Gmsh MSH 4.1 ASCII.
    Msh,
    /// I-DEAS universal file (datasets 2411, 2412).
    Unv,
}

/// The usage text printed by `--help`.
pub const USAGE: &str = "\
surfmesh: triangle meshes of trimmed NURBS surfaces within a verified tolerance

Usage:
  surfmesh mesh INPUT [options]
  surfmesh check DIR [options]            (see Sweeping a folder, below)
  surfmesh --help | --version

Options of `mesh`:
  --tol X             absolute chordal tolerance, model units (those of --units)
  --tol-rel R         tolerance as a fraction of the model's diagonal (default 0.001)
  --angle A           largest normal turn across a triangle, radians (default 0.5)
  --max-edge L        longest triangle edge allowed, model units
  --min-edge L        edges this short are never split, model units
  --max-triangles N   triangle budget (default 4000000)
  --mode MODE         fast (default): fewest triangles within the tolerance;
                      quality: near-equilateral triangles of size H for
                      analysis (paper 003)
  --size H            quality mode: element size, model units
  --size-rel R        quality mode: element size as a fraction of the model's
                      diagonal (default 0.02)
  --method M          quality mode: looping (default, paper 003), delaunay
                      (spade's refinement) or best (both, the better kept per face)
  --weights C1,C2,C3,C4  quality mode: the splitting function's weights
                      (default 1,0.3,0.6,1)
  --passes N          quality mode: improvement rounds (default 6)
  --reparam MODE      rebuild poorly parameterized faces before meshing: auto
                      (default: faces the step-ratio test flags, each rebuild
                      kept only where its mesh wins), off, force
  --units U           length unit of the mesh, the report and the absolute
                      options: file (default: the file's own unit), mm, cm,
                      m, in or ft; the mesh is scaled into it. GLB is always
                      written in metres, as glTF defines
  --format F          input format: json, iges (igs) or step (stp, p21); default:
                      from the extension, else from the content
  -o, --output FILE   write the mesh; .stl, .obj, .glb, .msh (Gmsh 4.1) or
                      .unv (universal file) picks the format
  --report FILE       write the JSON report (printed to stdout when neither
                      -o nor --report is given)

Exit status: 0 success, 1 bad input or failed run, 2 usage error.
";

/// Parses the arguments after the program name.
///
/// # Errors
/// A one-line message for a usage error.
pub fn parse(args: Vec<OsString>) -> Result<Command, CliError> {
    let mut args = args.into_iter();
    let Some(first) = args.next() else {
        return Err(CliError::usage("no command given; try 'surfmesh --help'"));
    };
    match first.to_str() {
        Some("-h" | "--help" | "help") => Ok(Command::Help),
        Some("-V" | "--version") => Ok(Command::Version),
        Some("mesh") => parse_mesh(args),
        Some("offset") => crate::repair::parse_offset(args).map(Command::Offset),
        Some("repair") => crate::repair::parse_repair(args).map(Command::Repair),
        Some("fit") => crate::fit::parse(args).map(Command::Fit),
        Some("reparam") => crate::reparam::parse(args).map(Command::Reparam),
        Some("check") => crate::check::parse(args).map(Command::Check),
        _ => Err(CliError::usage(format!("unknown command '{}'; try 'surfmesh --help'", first.to_string_lossy()))),
    }
}

fn parse_mesh(mut args: impl Iterator<Item = OsString>) -> Result<Command, CliError> {
    let mut input: Option<PathBuf> = None;
    let mut format = None;
    let mut options = MeshOptions::default();
    let (mut tol, mut tol_rel) = (None, None);
    let (mut size, mut size_rel) = (None, None);
    let mut quality = options.quality.clone();
    let mut output = None;
    let mut report: Option<PathBuf> = None;
    let mut units = Units::File;
    while let Some(arg) = args.next() {
        let Some(text) = arg.to_str().filter(|t| t.starts_with('-') && t.len() > 1) else {
            if input.replace(PathBuf::from(&arg)).is_some() {
                return Err(CliError::usage(format!("more than one input file ('{}')", arg.to_string_lossy())));
            }
            continue;
        };
        // `--name=value` and `--name value` both work.
        let (name, inline) = match text.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n, Some(OsString::from(v))),
            _ => (text, None),
        };
        let name = name.to_owned();
        let mut value =
            || inline.clone().or_else(|| args.next()).ok_or_else(|| CliError::usage(format!("{name} needs a value")));
        match name.as_str() {
            "-h" | "--help" => return Ok(Command::Help),
            "--tol" => tol = Some(number(&name, value()?)?),
            "--tol-rel" => tol_rel = Some(number(&name, value()?)?),
            "--angle" => options = options.with_angle(number(&name, value()?)?),
            "--max-edge" => options = options.with_max_edge(Some(number(&name, value()?)?)),
            "--min-edge" => options = options.with_min_edge(Some(number(&name, value()?)?)),
            "--max-triangles" => options = options.with_max_triangles(count(&name, value()?)?),
            "--mode" => options = options.with_mode(word::<MeshMode>(value()?)?),
            "--size" => size = Some(number(&name, value()?)?),
            "--size-rel" => size_rel = Some(number(&name, value()?)?),
            "--method" => quality = quality.with_method(word::<QualityMethod>(value()?)?),
            "--weights" => quality = quality.with_weights(weights(&name, value()?)?),
            "--passes" => quality = quality.with_passes(count(&name, value()?)?),
            "--reparam" => options = options.with_reparam(word::<Reparam>(value()?)?),
            "--format" => {
                let v = value()?;
                format = Some(
                    Format::from_name(&v.to_string_lossy()).map_err(|e| CliError::usage(format!("--format: {e}")))?,
                );
            }
            "-o" | "--output" => {
                let path = PathBuf::from(value()?);
                let kind = output_format(&path)?;
                output = Some((path, kind));
            }
            "--report" => report = Some(PathBuf::from(value()?)),
            "--units" => {
                units = Units::from_name(&value()?.to_string_lossy())?;
            }
            _ => return Err(CliError::usage(format!("unknown option '{text}'; try 'surfmesh --help'"))),
        }
    }
    let input = input.ok_or_else(|| CliError::usage("mesh needs an INPUT file; try 'surfmesh --help'"))?;
    options = match (tol, tol_rel) {
        (Some(_), Some(_)) => return Err(CliError::usage("give --tol or --tol-rel, not both")),
        (Some(t), None) => options.with_tolerance(t),
        (None, Some(r)) => options.with_relative_tolerance(r),
        (None, None) => options,
    };
    quality = match (size, size_rel) {
        (Some(_), Some(_)) => return Err(CliError::usage("give --size or --size-rel, not both")),
        (Some(h), None) => quality.with_size(h),
        (None, Some(r)) => quality.with_relative_size(r),
        (None, None) => quality,
    };
    if options.mode != MeshMode::Quality && quality != options.quality {
        return Err(CliError::usage("--size, --size-rel, --method, --weights and --passes need --mode quality"));
    }
    options = options.with_quality(quality);
    options.validate()?;
    if let (Some((out, _)), Some(rep)) = (&output, &report) {
        if out == rep {
            return Err(CliError::usage("-o and --report name the same file"));
        }
    }
    Ok(Command::Mesh(MeshArgs { input, format, options, units, output, report }))
}

/// A count given to option `name`.
fn count(name: &str, value: OsString) -> Result<usize, CliError> {
    let n = value.to_str().and_then(|s| s.parse().ok());
    n.ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a count", value.to_string_lossy())))
}

/// The four weights c1..c4 given to option `name`, separated by commas.
fn weights(name: &str, value: OsString) -> Result<[f64; 4], CliError> {
    let bad =
        || CliError::usage(format!("{name}: '{}' is not four numbers separated by commas", value.to_string_lossy()));
    let c: Vec<f64> = value
        .to_str()
        .unwrap_or("")
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    c.try_into().map_err(|_| bad())
}

/// An option's value parsed by its enum's `FromStr` (the JS binding's
/// parser too); the error names the option as the CLI spells it.
pub fn word<T: std::str::FromStr<Err = surfmesh::UnknownWord>>(value: OsString) -> Result<T, CliError> {
    value.to_str().unwrap_or("").parse::<T>().map_err(|e| CliError::usage(format!("--{e}")))
}

fn number(name: &str, value: OsString) -> Result<f64, CliError> {
    value
        .to_str()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a number", value.to_string_lossy())))
}

pub fn output_format(path: &std::path::Path) -> Result<OutputFormat, CliError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "stl" => Ok(OutputFormat::Stl),
        "obj" => Ok(OutputFormat::Obj),
        "glb" => Ok(OutputFormat::Glb),
        "msh" => Ok(OutputFormat::Msh),
        "unv" => Ok(OutputFormat::Unv),
        _ => Err(CliError::usage(format!(
            "-o {}: the file name must end in .stl, .obj, .glb, .msh or .unv",
            path.display()
        ))),
    }
}
