//! The `curvo` crate's adaptive tessellation on a JSON model, for the
//! side-by-side benchmark (`bench/compare.mjs`). Each face becomes a curvo
//! NURBS surface (a `TrimmedSurface` when it has loops: the loop of largest
//! area outside, the others holes) and is tessellated on its own.
//!
//! ```text
//! curvo_mesh MODEL.json --match DEV            # search norm_tolerance until the
//!                                              # measured deviation is <= DEV
//! curvo_mesh MODEL.json --norm-tol X [--runs N] [-o MESH.json]
//! ```
//!
//! `--match` measures each candidate with `surfmesh::measure_mesh` (the
//! benchmark's yardstick) and prints the largest `norm_tolerance` found that
//! reaches `DEV`. The second form times N runs (conversion = parse, and
//! tessellation = mesh, apart) and writes the last mesh as the benchmark's
//! mesh JSON. Output is one JSON object on stdout. A failure of curvo (an
//! error or a panic inside it) is reported in the JSON, not as a crash.

use std::time::Instant;

use curvo::prelude::{
    AdaptiveTessellationOptions, CompoundCurve2D, NurbsCurve2D, NurbsSurface3D, Tessellation, TrimmedSurface,
};
use glam::DVec3;
use surfmesh::{measure_mesh, read_json, FaceRange, FaceSurface, MeasureOptions, Mesh, Model, NurbsCurve};

/// Subdivision depth allowed to curvo (its default of 8 caps it at 256 cells a side).
const MAX_DEPTH: usize = 12;
/// The search gives up past this many triangles or this long (the mesh would not compare).
const SEARCH_MAX_TRIANGLES: usize = 150_000;
const SEARCH_MAX_SECONDS: f64 = 25.0;

enum CurvoFace {
    Plain(NurbsSurface3D<f64>),
    Trimmed(TrimmedSurface<f64>),
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = match run(&args) {
        Ok(v) => v,
        Err(e) => serde_json::json!({ "error": e }),
    };
    println!("{out}");
}

fn run(args: &[String]) -> Result<serde_json::Value, String> {
    let path = args.first().ok_or("usage: curvo_mesh MODEL.json (--match DEV | --norm-tol X [--runs N] [-o OUT])")?;
    let flag = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1));
    let number = |name: &str| -> Result<Option<f64>, String> {
        flag(name).map(|v| v.parse::<f64>().map_err(|_| format!("{name}: not a number: {v}"))).transpose()
    };
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    let model = read_json(&bytes).map_err(|e| format!("{path}: {e}"))?;
    if let Some(target) = number("--match")? {
        return search(&model, target);
    }
    let norm_tol = number("--norm-tol")?.ok_or("give --match DEV or --norm-tol X")?;
    let runs = number("--runs")?.map_or(5, |r| r.max(1.0) as usize);
    let (mut parse_ms, mut mesh_ms) = (Vec::new(), Vec::new());
    let mut mesh = Mesh::default();
    for _ in 0..runs {
        let start = Instant::now();
        let faces = convert(&model)?;
        parse_ms.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        mesh = tessellate(&faces, norm_tol)?;
        mesh_ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    if let Some(out) = flag("-o") {
        std::fs::write(out, mesh_json(&mesh).to_string()).map_err(|e| format!("{out}: {e}"))?;
    }
    Ok(serde_json::json!({
        "norm_tolerance": norm_tol,
        "triangles": mesh.triangle_count(),
        "parse_ms": parse_ms,
        "mesh_ms": mesh_ms,
    }))
}

/// Largest `norm_tolerance` (within about 10%) whose mesh measures within
/// `target`: down by factors of 4 until it passes, then bisection in log scale.
fn search(model: &Model, target: f64) -> Result<serde_json::Value, String> {
    let faces = convert(model)?;
    let options = MeasureOptions::default().with_coverage_samples(1000);
    let mut tried: Vec<serde_json::Value> = Vec::new();
    let mut measure = |nt: f64| -> Result<(f64, usize), String> {
        let mesh = tessellate(&faces, nt)?;
        let dev = measure_mesh(model, &mesh, &options).max_deviation;
        tried.push(
            serde_json::json!({ "norm_tolerance": nt, "triangles": mesh.triangle_count(), "max_deviation": dev }),
        );
        Ok((dev, mesh.triangle_count()))
    };
    let (mut pass, mut fail): (Option<(f64, f64, usize)>, Option<f64>) = (None, None);
    let mut nt = 0.5;
    let start = Instant::now();
    let late = || start.elapsed().as_secs_f64() > SEARCH_MAX_SECONDS;
    for _ in 0..12 {
        let (dev, tris) = measure(nt)?;
        if dev <= target {
            pass = Some((nt, dev, tris));
            break;
        }
        if tris > SEARCH_MAX_TRIANGLES || late() {
            break;
        }
        fail = Some(nt);
        nt *= 0.25;
    }
    if let (Some(mut p), Some(mut f)) = (pass, fail) {
        while f / p.0 > 1.1 && !late() {
            let mid = (p.0 * f).sqrt();
            let (dev, tris) = measure(mid)?;
            if dev <= target {
                p = (mid, dev, tris);
            } else {
                f = mid;
            }
        }
        pass = Some(p);
    }
    Ok(match pass {
        Some((nt, dev, tris)) => serde_json::json!({
            "norm_tolerance": nt, "max_deviation": dev, "triangles": tris, "reached": true, "tried": tried,
        }),
        None => serde_json::json!({
            "norm_tolerance": nt, "reached": false, "tried": tried,
            "gave_up": format!("no norm_tolerance reached it within {SEARCH_MAX_TRIANGLES} triangles and {SEARCH_MAX_SECONDS} s"),
        }),
    })
}

/// Each face as a curvo surface; trim loops as compound curves in (u,v).
fn convert(model: &Model) -> Result<Vec<CurvoFace>, String> {
    let mut out = Vec::with_capacity(model.faces.len());
    for (index, face) in model.faces.iter().enumerate() {
        let FaceSurface::Nurbs(s) = &face.surface else {
            return Err(format!("face {index}: not a NURBS surface"));
        };
        let [cu, cv] = s.counts();
        let points: Vec<Vec<_>> = (0..cu)
            .map(|i| {
                (0..cv)
                    .map(|j| {
                        let h = s.homogeneous(i, j);
                        [h.x, h.y, h.z, h.w].into()
                    })
                    .collect()
            })
            .collect();
        let [du, dv] = s.degree();
        let surface = NurbsSurface3D::new(du, dv, s.knots_u().knots().to_vec(), s.knots_v().knots().to_vec(), points);
        if face.loops.is_empty() {
            out.push(CurvoFace::Plain(surface));
            continue;
        }
        let mut loops: Vec<(f64, CompoundCurve2D<f64>)> = Vec::new();
        for (l, lp) in face.loops.iter().enumerate() {
            let spans: Vec<NurbsCurve2D<f64>> = lp.curves.iter().map(curve2d).collect::<Result<_, _>>()?;
            let area = loop_area(&lp.curves);
            let compound = CompoundCurve2D::try_new(spans).map_err(|e| format!("face {index} loop {l}: curvo: {e}"))?;
            loops.push((area, compound));
        }
        loops.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut loops = loops.into_iter().map(|(_, c)| c);
        let exterior = loops.next();
        out.push(CurvoFace::Trimmed(TrimmedSurface::new(surface, exterior, loops.collect())));
    }
    Ok(out)
}

fn curve2d(c: &NurbsCurve) -> Result<NurbsCurve2D<f64>, String> {
    let points = c.homogeneous_points().iter().map(|h| [h.x, h.y, h.w].into()).collect();
    NurbsCurve2D::try_new(c.degree(), points, c.knots().knots().to_vec()).map_err(|e| format!("curvo: {e}"))
}

/// Area enclosed by a loop (polyline of its curves), unsigned.
fn loop_area(curves: &[NurbsCurve]) -> f64 {
    let mut pts = Vec::new();
    for c in curves {
        let (a, b) = c.domain();
        pts.extend((0..32).map(|k| c.point(a + (b - a) * k as f64 / 32.0)));
    }
    let n = pts.len();
    (0..n).map(|i| pts[i].x * pts[(i + 1) % n].y - pts[(i + 1) % n].x * pts[i].y).sum::<f64>().abs() * 0.5
}

/// Tessellates every face; a curvo error or panic becomes an error message.
fn tessellate(faces: &[CurvoFace], norm_tol: f64) -> Result<Mesh, String> {
    let options = AdaptiveTessellationOptions::<f64>::default().with_norm_tolerance(norm_tol).with_max_depth(MAX_DEPTH);
    let mut mesh = Mesh::default();
    for (index, face) in faces.iter().enumerate() {
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match face {
            CurvoFace::Plain(s) => Ok(s.tessellate(Some(options.clone()))),
            CurvoFace::Trimmed(s) => s.tessellate(Some(options.clone())).map_err(|e| e.to_string()),
        }));
        let t = match result {
            Ok(Ok(t)) => t,
            Ok(Err(e)) => return Err(format!("face {index}: curvo: {e}")),
            Err(_) => return Err(format!("face {index}: curvo panicked")),
        };
        let base = mesh.positions.len() as u32;
        let first = mesh.triangle_count() as u32;
        mesh.positions.extend(t.points().iter().map(|p| DVec3::new(p.x, p.y, p.z)));
        for f in t.faces() {
            mesh.indices.extend(f.iter().map(|&i| base + i as u32));
        }
        mesh.face_ranges.push(FaceRange { first, count: t.faces().len() as u32 });
    }
    Ok(mesh)
}

fn mesh_json(mesh: &Mesh) -> serde_json::Value {
    let positions: Vec<f64> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let ranges: Vec<u32> = mesh.face_ranges.iter().flat_map(|r| [r.first, r.count]).collect();
    serde_json::json!({ "positions": positions, "indices": mesh.indices, "faceRanges": ranges })
}
