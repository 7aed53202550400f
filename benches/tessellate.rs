//! Tessellation throughput (triangles per second) on a fixed freeform patch:
//! bicubic, 4 × 4 non-uniform knot spans, wavy z, 100 × 100 mm, meshed at a
//! relative tolerance of 1e-3. The same surface as `tests/data/js_freeform.json`,
//! which `bench/verb_compare.mjs` meshes with surfmesh and verb side by side.
//!
//! `cargo bench --bench tessellate`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use surfmesh::{mesh_model, Face, FaceSurface, MeshOptions, Model, NurbsCurve, NurbsSurface, TrimLoop};

const KNOTS_U: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.1, 0.35, 0.6, 1.0, 1.0, 1.0, 1.0];
const KNOTS_V: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.2, 0.45, 0.85, 1.0, 1.0, 1.0, 1.0];

/// Greville abscissa of control point `i` of a cubic: keeps the parameterization close to uniform speed.
fn greville(knots: &[f64], i: usize) -> f64 {
    (knots[i + 1] + knots[i + 2] + knots[i + 3]) / 3.0
}

/// The 7 × 7 control net of the freeform patch (the formula that wrote js_freeform.json).
fn freeform_surface() -> NurbsSurface {
    let points: Vec<Vec<DVec3>> = (0..7)
        .map(|i| {
            (0..7)
                .map(|j| {
                    let (fi, fj) = (i as f64, j as f64);
                    let z = 6.0 * (1.7 * fi + 0.4).sin() * (1.3 * fj).cos() + 3.0 * (2.3 * fj + 0.5 * fi).cos();
                    DVec3::new(100.0 * greville(&KNOTS_U, i), 100.0 * greville(&KNOTS_V, j), z)
                })
                .collect()
        })
        .collect();
    NurbsSurface::try_new([3, 3], KNOTS_U.to_vec(), KNOTS_V.to_vec(), &points, None).expect("valid freeform patch")
}

fn line(a: [f64; 2], b: [f64; 2]) -> NurbsCurve {
    let points = vec![DVec3::new(a[0], a[1], 0.0), DVec3::new(b[0], b[1], 0.0)];
    NurbsCurve::try_new(1, vec![0.0, 0.0, 1.0, 1.0], points, None).expect("valid line")
}

/// A full circle in (u, v) as one rational quadratic (nine control points).
fn circle(centre: [f64; 2], radius: f64) -> NurbsCurve {
    let corners =
        [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0), (1.0, -1.0)];
    let mut points: Vec<DVec3> =
        corners.iter().map(|(x, y)| DVec3::new(centre[0] + radius * x, centre[1] + radius * y, 0.0)).collect();
    points.push(points[0]);
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let weights = vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0];
    let knots = vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0];
    NurbsCurve::try_new(2, knots, points, Some(weights)).expect("valid circle")
}

fn model(loops: Vec<TrimLoop>) -> Model {
    let face = Face { name: Some("freeform".into()), surface: FaceSurface::Nurbs(freeform_surface()), loops };
    Model { units: "mm".into(), faces: vec![face], ..Model::default() }
}

/// The patch inside a square loop with a round hole: exercises the trimmed (CDT band) path.
fn trimmed_model() -> Model {
    let outer = TrimLoop {
        curves: vec![
            line([0.05, 0.05], [0.95, 0.05]),
            line([0.95, 0.05], [0.95, 0.95]),
            line([0.95, 0.95], [0.05, 0.95]),
            line([0.05, 0.95], [0.05, 0.05]),
        ],
    };
    let hole = TrimLoop { curves: vec![circle([0.5, 0.5], 0.2)] };
    model(vec![outer, hole])
}

fn tessellate(c: &mut Criterion) {
    let options = MeshOptions::default().with_relative_tolerance(1e-3);
    let mut group = c.benchmark_group("tessellate");
    group.sample_size(20);
    for (name, model) in [("freeform_rel_1e-3", model(Vec::new())), ("freeform_trimmed_rel_1e-3", trimmed_model())] {
        let first = mesh_model(&model, &options).expect("the bench model meshes");
        assert!(first.report.max_deviation <= first.report.tolerance, "{name}: tolerance not met");
        group.throughput(Throughput::Elements(first.report.triangles as u64));
        group.bench_function(name, |b| b.iter(|| mesh_model(black_box(&model), black_box(&options))));
    }
    group.finish();
}

criterion_group!(benches, tessellate);
criterion_main!(benches);
