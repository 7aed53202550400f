//! The quality mode's comparison table (issue 9): every model meshed with
//! the looping method, with spade's Delaunay refinement alone (the
//! baseline, no improvement rounds), with Delaunay refinement plus the same
//! improvement rounds, and with the better of both per face; every mesh
//! measured by `surfmesh::measure_mesh`. Prints a Markdown table.
//!
//! ```text
//! cargo run --release --example quality_table -- [MODEL[@SIZE] ...] [--size-rel R]
//! ```
//!
//! `MODEL@SIZE` gives the element size H in model units; otherwise H is
//! R × the model's diagonal (default R = 0.02). Without models, the
//! acceptance set of issue 9 is used (corpus files and shapes of tests/data).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use surfmesh::{
    measure_mesh, mesh_model, read_model, Format, MeasureOptions, MeshMode, MeshOptions, Model, QualityMethod,
    QualityOptions,
};

const DEFAULT_MODELS: [&str; 9] = [
    "../shared/corpus/cube_10x10_inventor.igs",
    "../shared/corpus/PRO20358-W10.igs",
    "../shared/corpus/bearing.iges",
    "../shared/corpus/OCC26138_Torus.igs",
    "../shared/corpus/OCC8842_cylinder_CATIA.igs",
    "tests/data/cylinder.json",
    "tests/data/torus.json",
    "tests/data/trimmed_holes.json",
    "tests/data/freeform.json",
];

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("quality_table: {e}");
            ExitCode::from(1)
        }
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut rel = 0.02;
    let mut models: Vec<(PathBuf, Option<f64>)> = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--size-rel" {
            rel = it.next().and_then(|v| v.parse().ok()).ok_or("--size-rel needs a number")?;
        } else if let Some((path, h)) = a.rsplit_once('@') {
            models.push((PathBuf::from(path), Some(h.parse().map_err(|_| format!("bad size in '{a}'"))?)));
        } else {
            models.push((PathBuf::from(a), None));
        }
    }
    if models.is_empty() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        models = DEFAULT_MODELS.iter().map(|m| (root.join(m), None)).collect();
    }
    println!(
        "| model | H | method | tris | ≥25° % | edges in [0.7H,1.4H] % | min ° | p1 ° | free | boundary | \
         max dev | dev/H | ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (path, size) in models {
        let model = load(&path)?;
        let name = path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let variants: [(&str, QualityMethod, Option<usize>); 4] = [
            ("looping", QualityMethod::Looping, None),
            ("spade refine", QualityMethod::Delaunay, Some(0)),
            ("spade + improve", QualityMethod::Delaunay, None),
            ("best", QualityMethod::Best, None),
        ];
        for (label, method, passes) in variants {
            let mut q = QualityOptions::default().with_method(method);
            q = match size {
                Some(h) => q.with_size(h),
                None => q.with_relative_size(rel),
            };
            if let Some(p) = passes {
                q = q.with_passes(p);
            }
            let options = MeshOptions::default().with_mode(MeshMode::Quality).with_quality(q);
            let start = Instant::now();
            let result = match mesh_model(&model, &options) {
                Ok(r) => r,
                Err(e) => {
                    println!("| {name} | | {label} | error: {e} |||||||||");
                    continue;
                }
            };
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let qr = result.report.quality.clone().unwrap_or_default();
            let m = measure_mesh(&model, &result.mesh, &MeasureOptions::default());
            println!(
                "| {name} | {:.4} | {label} | {} | {:.2} | {:.2} | {:.1} | {:.1} | {} | {} | {:.3e} | {:.2e} | {:.0} |",
                qr.size,
                m.triangles,
                100.0 * qr.good_angle_fraction,
                100.0 * qr.edge_band_fraction,
                m.min_angle_deg,
                m.p1_angle_deg,
                m.free_edges,
                m.boundary_edges,
                m.max_deviation,
                m.max_deviation / qr.size,
                ms
            );
            if result.report.faces_skipped > 0 {
                eprintln!(
                    "{name} {label}: {} faces skipped: {:?}",
                    result.report.faces_skipped, result.report.warnings
                );
            }
        }
    }
    Ok(())
}

fn load(path: &Path) -> Result<Model, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = Format::from_name(ext)
        .ok()
        .or_else(|| Format::detect(&bytes))
        .ok_or_else(|| format!("{}: unknown format", path.display()))?;
    read_model(&bytes, format).map_err(|e| format!("{}: {e}", path.display()))
}
