//! The benchmark's yardstick as a command: measures any triangle mesh of a
//! model with `surfmesh::measure_mesh` and prints the result as JSON, so the
//! meshes of every program in `bench/compare.mjs` are judged by the same code.
//!
//! ```text
//! cargo run --release --example measure -- MODEL MESH [--tol T] [--steps N] [--weld W]
//! cargo run --release --example measure -- formats
//! cargo run --release --example measure -- info MODEL
//! ```
//!
//! `MODEL` is any file `surfmesh::read_model` reads (format from its
//! extension). `MESH` is a binary STL, an OBJ (`g` lines start faces), or JSON
//! `{"positions": [x, y, z, ...], "indices": [i, j, k, ...], "faceRanges": [first, count, ...]}`
//! (`faceRanges` optional: without it cracks cannot be told from the open
//! boundary). `formats` prints which model extensions this build reads; `info`
//! prints a model's units, face count, trimmed-face count and reader warnings.

use std::process::ExitCode;

use glam::DVec3;
use serde::Deserialize;
use surfmesh::{measure_mesh, read_model, FaceRange, Format, MeasureOptions, Mesh, Model};

/// Extensions the benchmark looks for in the corpus.
const EXTENSIONS: [&str; 6] = ["json", "igs", "iges", "stp", "step", "brep"];

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct MeshJson {
    positions: Vec<f64>,
    indices: Vec<u32>,
    #[serde(default)]
    face_ranges: Vec<u32>,
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("measure: {message}");
            ExitCode::from(1)
        }
    }
}

fn run(args: &[String]) -> Result<String, String> {
    if args.first().map(String::as_str) == Some("formats") {
        let known: Vec<&str> = EXTENSIONS.iter().copied().filter(|e| Format::from_name(e).is_ok()).collect();
        return serde_json::to_string(&known).map_err(|e| e.to_string());
    }
    if args.first().map(String::as_str) == Some("info") {
        let path = args.get(1).ok_or("usage: measure info MODEL")?;
        let model = load(path)?;
        let trimmed = model.faces.iter().filter(|f| !f.loops.is_empty()).count();
        let info = serde_json::json!({
            "units": model.units, "faces": model.faces.len(), "trimmed_faces": trimmed, "warnings": model.warnings.len(),
        });
        return Ok(info.to_string());
    }
    let mut files = Vec::new();
    let mut options = MeasureOptions::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| -> Result<f64, String> {
            it.next().and_then(|v| v.parse().ok()).ok_or_else(|| format!("{name} needs a number"))
        };
        match a.as_str() {
            "--tol" => options = options.with_tolerance(value("--tol")?),
            "--steps" => options = options.with_steps(value("--steps")? as usize),
            "--weld" => options = options.with_weld(value("--weld")?),
            "--coverage-samples" => options = options.with_coverage_samples(value("--coverage-samples")? as usize),
            _ if a.starts_with("--") => return Err(format!("unknown option {a}")),
            _ => files.push(a.clone()),
        }
    }
    let [model_path, mesh_path] = files.as_slice() else {
        return Err("usage: measure MODEL MESH [--tol T] [--steps N] [--weld W] | measure formats".into());
    };
    let model = load(model_path)?;
    let mesh_bytes = std::fs::read(mesh_path).map_err(|e| format!("{mesh_path}: {e}"))?;
    let mesh = if mesh_path.ends_with(".json") {
        mesh_from_json(&mesh_bytes)
    } else if mesh_path.ends_with(".obj") {
        mesh_from_obj(&mesh_bytes)
    } else {
        mesh_from_stl(&mesh_bytes)
    }
    .map_err(|e| format!("{mesh_path}: {e}"))?;
    let start = std::time::Instant::now();
    let measure = measure_mesh(&model, &mesh, &options);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let mut value = serde_json::to_value(&measure).map_err(|e| e.to_string())?;
    value["measure_ms"] = ms.into();
    Ok(value.to_string())
}

/// Reads a model, its format from the file's extension.
fn load(path: &str) -> Result<Model, String> {
    let ext = std::path::Path::new(path).extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = Format::from_name(ext).map_err(|e| format!("{path}: {e}"))?;
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    read_model(&bytes, format).map_err(|e| format!("{path}: {e}"))
}

fn mesh_from_json(bytes: &[u8]) -> Result<Mesh, String> {
    let m: MeshJson = serde_json::from_slice(bytes).map_err(|e| e.to_string())?;
    let positions = m.positions.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect();
    let face_ranges = m.face_ranges.chunks_exact(2).map(|r| FaceRange { first: r[0], count: r[1] }).collect();
    Ok(Mesh { positions, indices: m.indices, face_ranges, ..Mesh::default() })
}

/// OBJ as surfmesh writes it: `v` lines, triangles `f a b c` (or `a//a`,
/// `a/t/n`), and a `g` line starting each model face (its face ranges).
fn mesh_from_obj(bytes: &[u8]) -> Result<Mesh, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| e.to_string())?;
    let mut mesh = Mesh::default();
    let mut group_start: Option<u32> = None;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let bad = || format!("line {}: {line}", n + 1);
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map(|w| w.parse().map_err(|_| bad())).collect::<Result<_, _>>()?;
                let [x, y, z] = c[..] else { return Err(bad()) };
                mesh.positions.push(DVec3::new(x, y, z));
            }
            Some("f") => {
                let v: Vec<u32> = words
                    .map(|w| w.split('/').next().and_then(|i| i.parse::<u32>().ok()).filter(|&i| i > 0).ok_or_else(bad))
                    .collect::<Result<_, _>>()?;
                if v.len() != 3 {
                    return Err(format!("{}: only triangles are read", bad()));
                }
                mesh.indices.extend(v.iter().map(|i| i - 1));
            }
            Some("g") => {
                let t = mesh.triangle_count() as u32;
                if let Some(first) = group_start.replace(t) {
                    mesh.face_ranges.push(FaceRange { first, count: t - first });
                }
            }
            _ => {}
        }
    }
    if let Some(first) = group_start {
        let t = mesh.triangle_count() as u32;
        mesh.face_ranges.push(FaceRange { first, count: t - first });
    }
    Ok(mesh)
}

/// Binary STL: every triangle gets its own three vertices (welding happens in the measure).
fn mesh_from_stl(bytes: &[u8]) -> Result<Mesh, String> {
    let count = bytes.get(80..84).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let count = count.ok_or("shorter than a binary STL header")?;
    if bytes.len() < 84 + 50 * count {
        return Err(format!("binary STL announces {count} triangles but is {} bytes", bytes.len()));
    }
    let f = |at: usize| f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as f64;
    let mut mesh = Mesh::default();
    for t in 0..count {
        let base = 84 + 50 * t + 12;
        for k in 0..3 {
            let at = base + 12 * k;
            mesh.positions.push(DVec3::new(f(at), f(at + 4), f(at + 8)));
            mesh.indices.push((3 * t + k) as u32);
        }
    }
    Ok(mesh)
}
