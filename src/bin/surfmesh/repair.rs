//! `surfmesh offset` and `surfmesh repair` (paper 002): arguments and runs.
//! Thin: the library does the geometry.

use crate::error::CliError;
use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use surfmesh::{
    mesh_model, offset_mesh, read_mesh, read_model, repair_mesh_timed, weld_mesh, write_glb, write_obj, write_stl,
    Bucketing, Error, Format, Mesh, MeshFormat, MeshOptions, RepairOptions,
};

use super::args::{output_format, OutputFormat};

/// Usage lines of the two commands, appended to the main usage text.
pub const USAGE: &str = "\
Mesh repair (paper 002):
  surfmesh offset INPUT -d DIST -o OUT     move every vertex DIST along its normal
                                           (negative = inward); INPUT a mesh
                                           (.stl, .obj) or a model (.json, .igs)
  surfmesh repair INPUT -o OUT [--report R] [--bucketing kd|bvh] [--bucket-capacity N]
                  [--weld REL] [--perturbation REL] [--verify]
                                           a closed 2-manifold without degenerate or
                                           self-intersecting triangles from INPUT (.stl, .obj)
";

/// Arguments of `surfmesh offset`.
pub struct OffsetArgs {
    pub input: PathBuf,
    pub distance: f64,
    pub output: (PathBuf, OutputFormat),
}

/// Arguments of `surfmesh repair`.
pub struct RepairArgs {
    pub input: PathBuf,
    pub options: RepairOptions,
    pub output: Option<(PathBuf, OutputFormat)>,
    pub report: Option<PathBuf>,
}

/// Splits `--name=value` / `--name value` arguments; positional ones go to `input`.
fn options(
    args: impl Iterator<Item = OsString>,
    mut each: impl FnMut(&str, &mut dyn FnMut() -> Result<OsString, CliError>) -> Result<(), CliError>,
) -> Result<Option<PathBuf>, CliError> {
    let mut args = args.peekable();
    let mut input: Option<PathBuf> = None;
    while let Some(arg) = args.next() {
        // A negative number is a value, not an option.
        let Some(text) = arg.to_str().filter(|t| t.starts_with('-') && t.len() > 1 && t.parse::<f64>().is_err()) else {
            if input.replace(PathBuf::from(&arg)).is_some() {
                return Err(CliError::usage(format!("more than one input file ('{}')", arg.to_string_lossy())));
            }
            continue;
        };
        let (name, inline) = match text.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n.to_owned(), Some(OsString::from(v))),
            _ => (text.to_owned(), None),
        };
        let mut value =
            || inline.clone().or_else(|| args.next()).ok_or_else(|| CliError::usage(format!("{name} needs a value")));
        each(&name, &mut value)?;
    }
    Ok(input)
}

fn number(name: &str, value: OsString) -> Result<f64, CliError> {
    value
        .to_str()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|x| x.is_finite())
        .ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a number", value.to_string_lossy())))
}

pub fn parse_offset(args: impl Iterator<Item = OsString>) -> Result<OffsetArgs, CliError> {
    let (mut distance, mut output) = (None, None);
    let input = options(args, |name, value| {
        match name {
            "-d" | "--distance" => distance = Some(number(name, value()?)?),
            "-o" | "--output" => {
                let path = PathBuf::from(value()?);
                output = Some((path.clone(), output_format(&path)?));
            }
            _ => return Err(CliError::usage(format!("unknown option '{name}' for offset; try 'surfmesh --help'"))),
        }
        Ok(())
    })?;
    let input = input.ok_or_else(|| CliError::usage("offset needs an INPUT file; try 'surfmesh --help'"))?;
    let distance = distance.ok_or_else(|| CliError::usage("offset needs -d DIST"))?;
    let output = output.ok_or_else(|| CliError::usage("offset needs -o OUT"))?;
    Ok(OffsetArgs { input, distance, output })
}

pub fn parse_repair(args: impl Iterator<Item = OsString>) -> Result<RepairArgs, CliError> {
    let mut opts = RepairOptions::default();
    let (mut output, mut report) = (None, None);
    let input = options(args, |name, value| {
        match name {
            "-o" | "--output" => {
                let path = PathBuf::from(value()?);
                output = Some((path.clone(), output_format(&path)?));
            }
            "--report" => report = Some(PathBuf::from(value()?)),
            "--bucketing" => opts = opts.clone().with_bucketing(super::args::word::<Bucketing>(value()?)?),
            "--bucket-capacity" => {
                let v = value()?;
                let n = v.to_str().and_then(|s| s.parse().ok());
                opts = opts.clone().with_bucket_capacity(
                    n.ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a count", v.to_string_lossy())))?,
                );
            }
            "--weld" => opts = opts.clone().with_weld_tolerance(number(name, value()?)?),
            "--perturbation" => opts.perturbation = number(name, value()?)?,
            "--verify" => opts = opts.clone().with_verify(true),
            _ => return Err(CliError::usage(format!("unknown option '{name}' for repair; try 'surfmesh --help'"))),
        }
        Ok(())
    })?;
    let input = input.ok_or_else(|| CliError::usage("repair needs an INPUT file; try 'surfmesh --help'"))?;
    opts.validate()?;
    if let (Some((out, _)), Some(rep)) = (&output, &report) {
        if out == rep {
            return Err(CliError::usage("-o and --report name the same file"));
        }
    }
    Ok(RepairArgs { input, options: opts, output, report })
}

/// Reads a mesh file, or meshes a model file with default options and welds it.
fn read_input(path: &Path, bytes: &[u8], models: bool) -> Result<Mesh, CliError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if let Ok(f) = MeshFormat::from_name(ext) {
        return read_mesh(bytes, f).map_err(CliError::from);
    }
    if models {
        if let Some(f) = Format::from_name(ext).ok().or_else(|| Format::detect(bytes)) {
            let model = read_model(bytes, f)?;
            let r = mesh_model(&model, &MeshOptions::default())?;
            let diag = surfmesh::Aabb::from_points(r.mesh.positions.iter().copied()).diagonal();
            return Ok(weld_mesh(&r.mesh, 1e-9 * diag));
        }
    }
    let f = MeshFormat::detect(bytes).ok_or_else(|| {
        CliError::Core(Error::Format("cannot tell the mesh format; name the file .stl or .obj".into()))
    })?;
    read_mesh(bytes, f).map_err(CliError::from)
}

fn encode(mesh: &Mesh, kind: OutputFormat) -> Vec<u8> {
    match kind {
        OutputFormat::Stl => write_stl(mesh),
        OutputFormat::Obj => write_obj(mesh),
        OutputFormat::Glb => write_glb(mesh),
        OutputFormat::Msh => surfmesh::write_msh(mesh),
        OutputFormat::Unv => surfmesh::write_unv(mesh),
    }
}

pub fn run_offset(a: &OffsetArgs) -> Result<(), CliError> {
    let bytes = fs::read(&a.input).map_err(CliError::read)?;
    let mesh = read_input(&a.input, &bytes, true)?;
    let start = Instant::now();
    let out = offset_mesh(&mesh, a.distance)?;
    let ms = super::millis(start);
    super::write_all_or_nothing(&[(a.output.0.as_path(), encode(&out, a.output.1))])?;
    eprintln!(
        "surfmesh: {}: offset by {} -> {} triangles, {:.1} ms",
        a.input.display(),
        a.distance,
        out.triangle_count(),
        ms
    );
    Ok(())
}

pub fn run_repair(a: &RepairArgs) -> Result<(), CliError> {
    let bytes = fs::read(&a.input).map_err(CliError::read)?;
    let start = Instant::now();
    let mesh = read_input(&a.input, &bytes, false)?;
    let parse_ms = super::millis(start);
    let t0 = Instant::now();
    let mut clock = || super::millis(t0);
    let result = repair_mesh_timed(&mesh, &a.options, &mut clock)?;
    let mut json = serde_json::to_value(&result.report).map_err(CliError::report)?;
    if let Some(o) = json.as_object_mut() {
        o.insert("parse_ms".into(), parse_ms.into());
    }
    let text = serde_json::to_string_pretty(&json).map_err(CliError::report)?;
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some((path, kind)) = &a.output {
        files.push((path, encode(&result.mesh, *kind)));
    }
    if let Some(path) = &a.report {
        files.push((path, format!("{text}\n").into_bytes()));
    }
    super::write_all_or_nothing(&files)?;
    if files.is_empty() {
        println!("{text}");
    }
    let r = &result.report;
    eprintln!(
        "surfmesh: {}: {} -> {} triangles, {} segments, {} regions, {} free / {} non-manifold edges, {:.1} ms (parse {:.1} ms)",
        a.input.display(),
        r.triangles_in,
        r.triangles_out,
        r.segments,
        r.regions,
        r.census_out.free_edges,
        r.census_out.nonmanifold_edges,
        r.time_ms.total,
        parse_ms
    );
    Ok(())
}
