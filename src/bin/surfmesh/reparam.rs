//! `surfmesh reparam`: poorly parameterized faces rebuilt on even parameters
//! (paper 001) and the model written back as IGES, so other programs get the
//! repaired geometry too.

use crate::error::CliError;
use std::ffi::OsString;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use surfmesh::{read_model, reparameterize_model, write_iges, Format, Reparam, Tolerance};

/// Arguments of `surfmesh reparam`.
pub struct ReparamArgs {
    /// The model file.
    pub input: PathBuf,
    /// Input format given by `--format`; otherwise guessed from the file.
    pub format: Option<Format>,
    /// Which faces are rebuilt.
    pub mode: Reparam,
    /// Tolerance the rebuilt faces are checked against.
    pub tolerance: Tolerance,
    /// The IGES file written.
    pub output: PathBuf,
    /// Report output file.
    pub report: Option<PathBuf>,
}

/// The usage lines of `reparam`, printed after the main usage text.
pub const USAGE: &str = "\
Poorly parameterized surfaces (paper 001):
  surfmesh reparam INPUT -o OUT.igs [--reparam auto|force|off] [--tol X | --tol-rel R]
                  [--report R.json] [--format json|iges]
                                           rebuilds the faces the step-ratio test flags
                                           (auto, the default; force: every face; off:
                                           none, a plain conversion) as bicubic surfaces
                                           on even parameters within a tenth of the
                                           tolerance (default 0.001 of the diagonal), and
                                           writes every face as IGES (128, 144/142/102/126)
";

/// Parses the arguments after `reparam`.
///
/// # Errors
/// A one-line message for a usage error.
pub fn parse(mut args: impl Iterator<Item = OsString>) -> Result<ReparamArgs, CliError> {
    let mut input: Option<PathBuf> = None;
    let (mut format, mut mode) = (None, Reparam::Auto);
    let (mut tol, mut tol_rel) = (None, None);
    let (mut output, mut report): (Option<PathBuf>, Option<PathBuf>) = (None, None);
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
            "--reparam" => mode = crate::args::word::<Reparam>(value()?)?,
            "--format" => {
                let v = value()?;
                format = Some(
                    Format::from_name(&v.to_string_lossy()).map_err(|e| CliError::usage(format!("--format: {e}")))?,
                );
            }
            "-o" | "--output" => {
                let path = PathBuf::from(value()?);
                let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
                if ext != "igs" && ext != "iges" {
                    return Err(CliError::usage(format!(
                        "-o {}: the file name must end in .igs or .iges",
                        path.display()
                    )));
                }
                output = Some(path);
            }
            "--report" => report = Some(PathBuf::from(value()?)),
            _ => return Err(CliError::usage(format!("unknown option '{text}' for reparam; try 'surfmesh --help'"))),
        }
    }
    let input = input.ok_or_else(|| CliError::usage("reparam needs an INPUT file; try 'surfmesh --help'"))?;
    let output = output.ok_or_else(|| CliError::usage("reparam needs -o OUT.igs"))?;
    let tolerance = match (tol, tol_rel) {
        (Some(_), Some(_)) => return Err(CliError::usage("give --tol or --tol-rel, not both")),
        (Some(t), None) => Tolerance::Absolute(t),
        (None, Some(r)) => Tolerance::Relative(r),
        (None, None) => Tolerance::Relative(1e-3),
    };
    let t = match tolerance {
        Tolerance::Absolute(t) | Tolerance::Relative(t) => t,
    };
    if !(t > 0.0 && t.is_finite()) {
        return Err(CliError::usage("the tolerance must be a positive number"));
    }
    if report.as_ref() == Some(&output) {
        return Err(CliError::usage("-o and --report name the same file"));
    }
    Ok(ReparamArgs { input, format, mode, tolerance, output, report })
}

fn number(name: &str, value: OsString) -> Result<f64, CliError> {
    value
        .to_str()
        .and_then(|s| s.parse::<f64>().ok())
        .ok_or_else(|| CliError::usage(format!("{name}: '{}' is not a number", value.to_string_lossy())))
}

/// Runs the rebuild; the error is the message printed after the input file's name.
pub fn run(a: &ReparamArgs) -> Result<(), CliError> {
    let bytes = fs::read(&a.input).map_err(CliError::read)?;
    let format = match a.format {
        Some(f) => f,
        None => crate::input_format(&a.input, &bytes)?,
    };
    let model = read_model(&bytes, format)?;
    let start = Instant::now();
    let out = reparameterize_model(&model, a.mode, a.tolerance)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let rebuilt = out.faces.iter().filter(|f| f.rebuilt).count();
    let mut warnings = model.warnings.clone();
    warnings.extend(out.warnings.iter().cloned());
    let report = serde_json::json!({
        "tolerance": out.tolerance,
        "faces": model.faces.len(),
        "flagged": out.faces.len(),
        "rebuilt": rebuilt,
        "time_ms": ms,
        "reparameterized": out.faces,
        "warnings": warnings,
    });
    let report_json = serde_json::to_string_pretty(&report).map_err(CliError::report)?;
    let mut files: Vec<(&Path, Vec<u8>)> = vec![(&a.output, write_iges(&out.model))];
    if let Some(path) = &a.report {
        files.push((path, format!("{report_json}\n").into_bytes()));
    }
    crate::write_all_or_nothing(&files)?;
    eprintln!(
        "surfmesh: {}: {} faces, {} flagged, {} rebuilt within {:.3e} {} of the originals, {:.1} ms",
        a.input.display(),
        model.faces.len(),
        out.faces.len(),
        rebuilt,
        out.faces.iter().map(|f| f.fit_error).fold(0.0, f64::max),
        model.units,
        ms
    );
    for w in &out.warnings {
        eprintln!("surfmesh: {}: warning: {w}", a.input.display());
    }
    Ok(())
}
