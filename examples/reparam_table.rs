//! Paper 001's acceptance table: every face the parameterization test flags
//! (or every face, with `--all`) meshed on its own with `reparam` off and
//! auto at the same absolute tolerance, both meshes measured against the
//! ORIGINAL face by `surfmesh::measure_mesh`. Prints one JSON object per line
//! (bench/reparam.mjs turns them into the Markdown table).
//!
//! ```text
//! cargo run --release --example reparam_table -- MODEL... [--tol-rel R] [--tol T] [--all]
//! ```
//!
//! The absolute tolerance is `--tol`, else `R` (default 1e-3) times the
//! whole model's diagonal as the mesher measures it, so a face is meshed at
//! the tolerance it gets inside its model.

use std::process::ExitCode;
use std::time::Instant;

use surfmesh::{
    measure_mesh, mesh_model, read_model, step_ratio, Format, MeasureOptions, MeshOptions, Model, Reparam, RATIO_LIMIT,
};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut files, mut rel, mut abs, mut all, mut detect) = (Vec::new(), 1e-3, None, false, false);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--tol-rel" => rel = it.next().and_then(|v| v.parse().ok()).unwrap_or(rel),
            "--tol" => abs = it.next().and_then(|v| v.parse().ok()),
            "--all" => all = true,
            "--detect" => detect = true,
            _ => files.push(a.clone()),
        }
    }
    let mut status = ExitCode::SUCCESS;
    for file in &files {
        let done = if detect { census(file) } else { run(file, rel, abs, all) };
        if let Err(e) = done {
            eprintln!("reparam_table: {file}: {e}");
            status = ExitCode::from(1);
        }
    }
    status
}

/// Reads `file` as the CLI does (format from the extension).
fn load(file: &str) -> Result<Model, String> {
    let bytes = std::fs::read(file).map_err(|e| e.to_string())?;
    let ext = std::path::Path::new(file).extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = Format::from_name(ext).map_err(|e| e.to_string())?;
    read_model(&bytes, format).map_err(|e| e.to_string())
}

/// `--detect`: the ratio test alone on every face, timed.
fn census(file: &str) -> Result<(), String> {
    let model = load(file)?;
    let t0 = Instant::now();
    let ratios: Vec<f64> = model.faces.iter().map(|f| step_ratio(&f.surface)).collect();
    let us = t0.elapsed().as_secs_f64() * 1e6;
    let flagged: Vec<(usize, f64)> = ratios.iter().copied().enumerate().filter(|&(_, r)| r > RATIO_LIMIT).collect();
    let row = serde_json::json!({
        "file": file, "faces": model.faces.len(), "detect_us_per_face": us / model.faces.len().max(1) as f64,
        "flagged": flagged,
    });
    println!("{row}");
    Ok(())
}

fn run(file: &str, rel: f64, abs: Option<f64>, all: bool) -> Result<(), String> {
    let model = load(file)?;
    let tol = match abs {
        Some(t) => t,
        None => {
            let o = MeshOptions::default().with_relative_tolerance(rel);
            mesh_model(&model, &o).map_err(|e| e.to_string())?.report.tolerance
        }
    };
    let name = std::path::Path::new(file).file_name().and_then(|n| n.to_str()).unwrap_or(file);
    for (index, face) in model.faces.iter().enumerate() {
        let t0 = Instant::now();
        let ratio = step_ratio(&face.surface);
        let detect_us = t0.elapsed().as_secs_f64() * 1e6;
        if !all && ratio <= RATIO_LIMIT {
            continue;
        }
        let one = Model {
            units: model.units.clone(),
            faces: vec![face.clone()],
            warnings: Vec::new(),
            tolerance: None,
            bodies: Vec::new(),
            ..Default::default()
        };
        let mut row = serde_json::json!({
            "file": name, "face": index, "ratio": ratio, "tolerance": tol, "detect_us": detect_us,
            "trimmed": !face.loops.is_empty(),
        });
        for (key, mode) in [("off", Reparam::Off), ("auto", Reparam::Auto)] {
            let o = MeshOptions::default().with_tolerance(tol).with_reparam(mode);
            let t0 = Instant::now();
            match mesh_model(&one, &o) {
                Ok(r) => {
                    let ms = t0.elapsed().as_secs_f64() * 1e3;
                    let m = measure_mesh(&one, &r.mesh, &MeasureOptions::default().with_tolerance(tol));
                    let mut dense = MeasureOptions::default().with_tolerance(tol);
                    dense.index_samples = 2_000_000;
                    let md = measure_mesh(&one, &r.mesh, &dense);
                    let rebuilt = r.report.reparameterized.first().map(|f| f.rebuilt);
                    let fit = r.report.reparameterized.first().map(|f| f.fit_error);
                    let samples = r.report.reparameterized.first().map(|f| f.samples);
                    row[key] = serde_json::json!({
                        "triangles": r.report.triangles, "p1_angle": r.report.p1_angle_deg,
                        "min_angle": r.report.min_angle_deg, "reported": r.report.max_deviation,
                        "measured": m.max_deviation, "dense": md.max_deviation, "coverage": m.coverage, "ms": ms,
                        "rebuilt": rebuilt, "fit_error": fit, "samples": samples,
                        "warnings": r.report.warnings.iter().take(4).collect::<Vec<_>>(),
                    });
                }
                Err(e) => row[key] = serde_json::json!({ "error": e.to_string() }),
            }
        }
        println!("{row}");
    }
    Ok(())
}
