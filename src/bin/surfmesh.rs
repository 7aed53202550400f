//! The `surfmesh` command line: reads a model, meshes it, writes the mesh
//! (STL, OBJ or glTF) and a JSON report. A thin door: all geometry is in the library.

#[path = "surfmesh/args.rs"]
mod args;
#[path = "surfmesh/check.rs"]
mod check;
#[path = "surfmesh/error.rs"]
mod error;
#[path = "surfmesh/fit.rs"]
mod fit;
#[path = "surfmesh/repair.rs"]
mod repair;
#[path = "surfmesh/reparam.rs"]
mod reparam;

use std::ffi::OsString;
use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use args::{Command, MeshArgs, OutputFormat};
use error::CliError;
use surfmesh::{
    mesh_model_in_units, mm_per_unit, read_model, write_glb_scaled, write_msh, write_obj, write_stl, write_unv, Error,
    Format,
};

fn main() -> ExitCode {
    match args::parse(std::env::args_os().skip(1).collect()) {
        Ok(Command::Help) => {
            print!("{}\n{}\n{}\n{}\n{}", args::USAGE, check::USAGE, repair::USAGE, fit::USAGE, reparam::USAGE);
            ExitCode::SUCCESS
        }
        Ok(Command::Version) => {
            println!("surfmesh {}", env!("CARGO_PKG_VERSION"));
            ExitCode::SUCCESS
        }
        Ok(Command::Mesh(m)) => match mesh(&m) {
            Ok(()) => ExitCode::SUCCESS,
            Err(message) => {
                eprintln!("surfmesh: {}: {}", m.input.display(), one_line(&message.to_string()));
                ExitCode::from(1)
            }
        },
        Ok(Command::Offset(a)) => finish(&a.input, repair::run_offset(&a)),
        Ok(Command::Repair(a)) => finish(&a.input, repair::run_repair(&a)),
        Ok(Command::Fit(a)) => finish(&a.input, fit::run(&a)),
        Ok(Command::Reparam(a)) => finish(&a.input, reparam::run(&a)),
        Ok(Command::Check(a)) => match check::run(&a) {
            Ok(true) => ExitCode::SUCCESS,
            Ok(false) => ExitCode::from(1),
            Err(message) => {
                eprintln!("surfmesh: {}: {}", a.dir.display(), one_line(&message.to_string()));
                ExitCode::from(1)
            }
        },
        Err(message) => {
            eprintln!("surfmesh: {}", one_line(&message.to_string()));
            ExitCode::from(2)
        }
    }
}

/// Exit status of a command run on `input`: its error, if any, on one line after the file's name.
fn finish(input: &Path, result: Result<(), CliError>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("surfmesh: {}: {}", input.display(), one_line(&message.to_string()));
            ExitCode::from(1)
        }
    }
}

/// The error contract is one line on stderr; flatten any line breaks a message carries.
fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `surfmesh mesh`: everything after the arguments; the error is the message
/// printed after the input file's name.
fn mesh(m: &MeshArgs) -> Result<(), CliError> {
    let bytes = fs::read(&m.input).map_err(CliError::read)?;
    let format = match m.format {
        Some(f) => f,
        None => input_format(&m.input, &bytes)?,
    };

    let start = Instant::now();
    let model = read_model(&bytes, format)?;
    let parse_ms = millis(start);
    let start = Instant::now();
    let mut result = mesh_model_in_units(&model, &m.options, m.units, &mut |_, _| true)?;
    let report = &mut result.report;
    report.time_ms = millis(start);
    report.parse_ms = parse_ms;
    // Reader warnings first, unless the mesher already copied them.
    let missing: Vec<surfmesh::Warning> =
        model.warnings.iter().filter(|w| !report.warnings.contains(w)).cloned().collect();
    report.warnings.splice(0..0, missing);

    let report_json = serde_json::to_string_pretty(&result.report).map_err(CliError::report)?;
    let mut files: Vec<(&Path, Vec<u8>)> = Vec::new();
    if let Some((path, kind)) = &m.output {
        let bytes = match kind {
            OutputFormat::Stl => write_stl(&result.mesh),
            OutputFormat::Obj => write_obj(&result.mesh),
            OutputFormat::Glb => {
                // glTF's lengths are metres.
                let mm = mm_per_unit(&result.report.units).unwrap_or_else(|| {
                    eprintln!(
                        "surfmesh: {}: length unit '{}' unknown: the GLB takes it as millimetres",
                        m.input.display(),
                        result.report.units
                    );
                    1.0
                });
                write_glb_scaled(&result.mesh, mm / 1000.0)
            }
            OutputFormat::Msh => write_msh(&result.mesh),
            OutputFormat::Unv => write_unv(&result.mesh),
        };
        files.push((path, bytes));
    }
    if let Some(path) = &m.report {
        files.push((path, format!("{report_json}\n").into_bytes()));
    }
    write_all_or_nothing(&files)?;
    if files.is_empty() {
        println!("{report_json}");
    }

    let r = &result.report;
    let verdict = if r.max_deviation <= r.tolerance { "<=" } else { "EXCEEDS" };
    // Faces without an exact surface are not measured: the line says so.
    let unverified = match r.faces_tessellated {
        0 => String::new(),
        n if n == r.faces => format!(" (all {n} faces tessellated: not verified)"),
        1 => " (1 tessellated face not verified)".into(),
        n => format!(" ({n} tessellated faces not verified)"),
    };
    eprintln!(
        "surfmesh: {}: {} triangles, max deviation {:.3e} {verdict} tolerance {:.3e} {}{unverified}, {:.1} ms \
         (parse {:.1} ms)",
        m.input.display(),
        r.triangles,
        r.max_deviation,
        r.tolerance,
        r.units,
        r.time_ms,
        r.parse_ms
    );
    Ok(())
}

/// Input format from the file's extension, else from its first bytes.
fn input_format(path: &Path, bytes: &[u8]) -> Result<Format, CliError> {
    let by_name = path.extension().and_then(|e| e.to_str()).and_then(|e| Format::from_name(e).ok());
    by_name.or_else(|| Format::detect(bytes)).ok_or_else(|| {
        CliError::Core(Error::Format("cannot tell the input format; give --format json, iges or step".into()))
    })
}

fn millis(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// Writes every file to a temporary name in its own directory, then renames
/// them into place, so that a failure leaves no half-written output behind.
/// A symbolic link is written through to its target. An output that exists
/// and is not a regular file (`/dev/null`, a pipe, a terminal) is written to
/// directly after the regular files are in place: renaming over it would
/// replace the device with a plain file.
fn write_all_or_nothing(files: &[(&Path, Vec<u8>)]) -> Result<(), CliError> {
    // (temporary file, file it replaces, path as the user gave it)
    let mut staged: Vec<(PathBuf, PathBuf, &Path)> = Vec::new();
    let mut streams: Vec<(&Path, &[u8])> = Vec::new();
    let result = (|| {
        for (path, bytes) in files {
            match fs::metadata(path) {
                Ok(meta) if !meta.is_file() && !meta.is_dir() => {
                    streams.push((path, bytes));
                    continue;
                }
                _ => {}
            }
            let target = real_target(path);
            let temp = temp_path(&target);
            staged.push((temp.clone(), target, path));
            let mut file = fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&temp)
                .map_err(|e| CliError::write(path, e))?;
            file.write_all(bytes).and_then(|()| file.sync_all()).map_err(|e| CliError::write(path, e))?;
        }
        for (temp, target, path) in &staged {
            fs::rename(temp, target).map_err(|e| CliError::write(path, e))?;
        }
        Ok(())
    })();
    if result.is_err() {
        for (temp, _, _) in &staged {
            let _ = fs::remove_file(temp);
        }
        return result;
    }
    for (path, bytes) in streams {
        fs::OpenOptions::new()
            .write(true)
            .open(path)
            .and_then(|mut out| out.write_all(bytes))
            .map_err(|e| CliError::write(path, e))?;
    }
    Ok(())
}

/// The file a path names: a symbolic link's target (so that writing keeps the
/// link), or the path itself when it is no link or does not exist yet.
fn real_target(path: &Path) -> PathBuf {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
        _ => path.to_path_buf(),
    }
}

/// `dir/.name.PID.tmp` next to `path`, so the final rename stays on one file system.
fn temp_path(path: &Path) -> PathBuf {
    let mut name = OsString::from(".");
    name.push(path.file_name().unwrap_or_default());
    name.push(format!(".{}.tmp", std::process::id()));
    path.with_file_name(name)
}
