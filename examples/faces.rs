//! Per-face diagnosis of a model: meshes the whole model at a relative
//! tolerance, names the faces whose triangles fold against the surface, then
//! meshes each face on its own at the model's absolute tolerance and prints
//! one row per face (triangles, folded, deviation, border edges, time), the
//! worst first.
//!
//! `cargo run --release --example faces -- FILE [REL] [FACE]`; with `FACE`,
//! `FACE_DUMP=out.txt` writes that face's loops sampled in (u,v) and
//! `UV_DUMP=out.txt` its first and refined (u,v) triangles (for plots).

use std::fmt::Write;
use std::time::Instant;

use surfmesh::{mesh_model, read_model, Face, Format, Mesh, MeshOptions, Model};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: faces FILE [REL] [FACE]");
        std::process::exit(2);
    };
    let rel: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1e-3);
    let only: Option<usize> = args.get(3).and_then(|s| s.parse().ok());
    let bytes = std::fs::read(path).expect("read");
    let model = read_model(&bytes, Format::detect(&bytes).expect("format")).expect("parse");
    let whole = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(rel)).expect("mesh");
    let tol = whole.report.tolerance;
    let rep = &whole.report;
    println!(
        "whole: {} faces, {} tris, dev {:.3e} / tol {tol:.3e}, folded {}, cracks {}, non-manifold {}",
        model.faces.len(),
        rep.triangles,
        rep.max_deviation,
        rep.inverted_triangles,
        rep.free_edges,
        rep.nonmanifold_edges
    );
    let mut folded = folded_by_face(&whole.mesh);
    folded.sort_by_key(|&(_, n)| std::cmp::Reverse(n));
    println!("folded in the whole mesh, by face: {:?}", &folded[..folded.len().min(20)]);
    if let Some(i) = only {
        if let Ok(out) = std::env::var("FACE_DUMP") {
            std::fs::write(out, loops_text(&model.faces[i])).expect("write");
        }
        if let Ok(out) = std::env::var("UV_DUMP") {
            // The face on its own at the model's tolerance, through the mesher's stages.
            let sub = Model { faces: vec![model.faces[i].clone()], ..Model::default() };
            let opts = MeshOptions::default().with_tolerance(tol);
            let plan = surfmesh::pipeline::Plan::new(&sub, &opts).expect("face");
            let mut run = plan.start();
            let variants = plan.choose_variants(&mut run).expect("outline");
            let sewn = plan.sew_outlines(&run, variants);
            let mut works = plan.first_meshes(&mut run, sewn).expect("initial");
            let mut s = String::new();
            for tag in ["i", "r"] {
                if tag == "r" {
                    plan.refine(&mut works, &mut |_, _| true).expect("refined");
                }
                for (t, inv) in works.uv_triangles(0) {
                    let [a, b, c] = t;
                    writeln!(s, "{tag} {} {} {} {} {} {} {}", a.x, a.y, b.x, b.y, c.x, c.y, u8::from(inv)).unwrap();
                }
            }
            std::fs::write(out, s).expect("write");
        }
    }
    let mut rows = Vec::new();
    for (i, f) in model.faces.iter().enumerate() {
        if only.is_some_and(|o| o != i) {
            continue;
        }
        let sub = Model { faces: vec![f.clone()], ..Model::default() };
        let start = Instant::now();
        let r = mesh_model(&sub, &MeshOptions::default().with_tolerance(tol));
        let ms = start.elapsed().as_secs_f64() * 1e3;
        rows.push(match r {
            Ok(r) => {
                let rep = &r.report;
                let row = format!(
                    "face {i:>4}: {:>7} tris, folded {:>5}, dev {:.3e}{} border {:>5} nm {:>3} loops {} {ms:>6.0} ms {}",
                    rep.triangles,
                    rep.inverted_triangles,
                    rep.max_deviation,
                    if rep.max_deviation > tol { " (!)" } else { "    " },
                    rep.boundary_edges,
                    rep.nonmanifold_edges,
                    f.loops.len(),
                    rep.warnings.iter().map(ToString::to_string).collect::<Vec<_>>().join(" | ")
                );
                (rep.inverted_triangles, ms, row)
            }
            Err(e) => (usize::MAX, ms, format!("face {i:>4}: error {e}")),
        });
    }
    rows.sort_by(|a, b| b.0.cmp(&a.0).then(b.1.total_cmp(&a.1)));
    for (_, _, line) in rows.iter().take(60) {
        println!("{line}");
    }
}

/// Faces of `m` with triangles whose facet opposes their vertex normals, and how many.
fn folded_by_face(m: &Mesh) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (fi, r) in m.face_ranges.iter().enumerate() {
        let bad = (r.first as usize..(r.first + r.count) as usize)
            .filter(|&t| {
                let i = &m.indices[3 * t..3 * t + 3];
                let p = [0, 1, 2].map(|k| m.positions[i[k] as usize]);
                let n: glam::DVec3 = i.iter().map(|&k| m.normals[k as usize]).sum();
                (p[1] - p[0]).cross(p[2] - p[0]).dot(n) < 0.0
            })
            .count();
        if bad > 0 {
            out.push((fi, bad));
        }
    }
    out
}

/// The face's domain and its loops sampled in (u,v): one point a line
/// (`u v loop curve`), loops apart by blank lines.
fn loops_text(f: &Face) -> String {
    use surfmesh::Surface;
    let mut s = String::new();
    let [lo, hi] = f.surface.domain();
    writeln!(s, "# domain {} {} {} {}", lo.x, lo.y, hi.x, hi.y).unwrap();
    for (li, l) in f.loops.iter().enumerate() {
        writeln!(s, "# loop {li}: {} curves", l.curves.len()).unwrap();
        for (ci, c) in l.curves.iter().enumerate() {
            let (a, b) = c.domain();
            for k in 0..=100 {
                let p = c.point(a + (b - a) * k as f64 / 100.0);
                writeln!(s, "{} {} {li} {ci}", p.x, p.y).unwrap();
            }
        }
        writeln!(s).unwrap();
    }
    s
}
