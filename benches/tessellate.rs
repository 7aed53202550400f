//! Criterion benches, one group per stage of the mesher, on fixed inputs built
//! here: a bicubic freeform patch with 4 × 4 non-uniform knot spans (the
//! surface of `tests/data/js_freeform.json`), the same patch trimmed by a
//! square with a round hole, and the exact rational sphere, whole and split
//! into two faces; relative tolerance 1e-3.
//!
//! - `evaluation`: surface points and second derivatives;
//! - `projection`: closest points, from a hint and from no hint;
//! - `variants`: each face's variant and outline, the trim loops to checked
//!   polylines and the iso-parametric grid (paper 000 §1–§3);
//! - `first_meshes`: the grid's triangles and the constrained Delaunay
//!   triangulation of the trimmed band (§4–§5);
//! - `refinement`: measuring and splitting until every triangle is proven;
//! - `sew`: two faces that share a border against one face;
//! - `tessellate`: whole-model throughput in triangles per second;
//! - `measurement`: the benchmark's yardstick (`measure_mesh`) and the mesh
//!   metrics it builds on (welding, edge census, angles).
//!
//! The stages are the mesher's own, one at a time through
//! `surfmesh::pipeline` (hidden, for benches only). `cargo bench --bench tessellate [-- GROUP]`; CI only
//! compiles them (`cargo bench --no-run`).

use std::f64::consts::FRAC_1_SQRT_2;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use glam::{DVec2, DVec3};
use surfmesh::{
    angle_stats, edge_counts, measure_mesh, mesh_model, pipeline::Plan, project_to_surface, weld_positions, Face,
    FaceSurface, MeasureOptions, MeshOptions, Model, NurbsCurve, NurbsSurface, ProjectionOptions, Surface, TrimLoop,
};

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

/// The exact rational sphere of radius 10: full circle along u, pole to pole along v.
fn sphere_surface() -> NurbsSurface {
    let w = FRAC_1_SQRT_2;
    let ring = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0), (-1.0, 1.0, w), (-1.0, 0.0, 1.0)];
    let ring: Vec<(f64, f64, f64)> =
        ring.iter().copied().chain(ring[1..].iter().map(|&(x, y, w)| (-x, -y, w))).collect();
    let profile = [(0.0, -10.0, 1.0), (10.0, -10.0, w), (10.0, 0.0, 1.0), (10.0, 10.0, w), (0.0, 10.0, 1.0)];
    let points: Vec<Vec<DVec3>> =
        ring.iter().map(|&(x, y, _)| profile.iter().map(|&(r, z, _)| DVec3::new(x * r, y * r, z)).collect()).collect();
    let weights: Vec<Vec<f64>> = ring.iter().map(|c| profile.iter().map(|p| c.2 * p.2).collect()).collect();
    let ku = vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0];
    let kv = vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    NurbsSurface::try_new([2, 2], ku, kv, &points, Some(&weights)).expect("valid sphere")
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
    let w = FRAC_1_SQRT_2;
    let weights = vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0];
    let knots = vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0];
    NurbsCurve::try_new(2, knots, points, Some(weights)).expect("valid circle")
}

fn model(faces: Vec<(NurbsSurface, Vec<TrimLoop>)>) -> Model {
    let faces =
        faces.into_iter().map(|(s, loops)| Face { name: None, surface: FaceSurface::Nurbs(s), loops }).collect();
    Model { units: "mm".into(), faces, ..Model::default() }
}

/// The freeform patch as it is.
fn freeform() -> Model {
    model(vec![(freeform_surface(), Vec::new())])
}

/// The patch inside a square loop with a round hole: exercises the trimmed (CDT band) path.
fn trimmed() -> Model {
    let outer = TrimLoop {
        curves: vec![
            line([0.05, 0.05], [0.95, 0.05]),
            line([0.95, 0.05], [0.95, 0.95]),
            line([0.95, 0.95], [0.05, 0.95]),
            line([0.05, 0.95], [0.05, 0.05]),
        ],
    };
    let hole = TrimLoop { curves: vec![circle([0.5, 0.5], 0.2)] };
    model(vec![(freeform_surface(), vec![outer, hole])])
}

/// The sphere split at u = 0.5 into two faces that share two meridians.
fn two_halves() -> Model {
    let (a, b) = sphere_surface().split(true, 0.5).expect("split inside the domain");
    model(vec![(a, Vec::new()), (b, Vec::new())])
}

/// A 33 × 33 grid of parameters over the unit square.
fn params() -> Vec<DVec2> {
    (0..33).flat_map(|i| (0..33).map(move |j| DVec2::new(i as f64 / 32.0, j as f64 / 32.0))).collect()
}

fn evaluation(c: &mut Criterion) {
    let mut group = c.benchmark_group("evaluation");
    let uv = params();
    group.throughput(Throughput::Elements(uv.len() as u64));
    for (name, s) in [("bicubic", freeform_surface()), ("rational_sphere", sphere_surface())] {
        group.bench_function(BenchmarkId::new("point", name), |b| {
            b.iter(|| uv.iter().map(|&q| s.point(black_box(q))).fold(DVec3::ZERO, |a, p| a + p))
        });
        group.bench_function(BenchmarkId::new("derivs", name), |b| {
            b.iter(|| uv.iter().map(|&q| s.derivs(black_box(q)).suv).fold(DVec3::ZERO, |a, p| a + p))
        });
    }
    group.finish();
}

fn projection(c: &mut Criterion) {
    let mut group = c.benchmark_group("projection");
    let s = freeform_surface();
    let opts = ProjectionOptions::default();
    // Targets 0.5 mm off the surface along its normal, hinted from 0.01 away in (u,v).
    let targets: Vec<(DVec3, DVec2)> =
        params().into_iter().map(|q| (s.point(q) + s.normal(q) * 0.5, (q + 0.01).min(DVec2::ONE))).collect();
    group.throughput(Throughput::Elements(targets.len() as u64));
    group.bench_function("hinted", |b| {
        b.iter(|| targets.iter().map(|&(p, h)| project_to_surface(&s, p, Some(h), &opts).distance).sum::<f64>())
    });
    group.sample_size(10);
    let few = &targets[..64];
    group.throughput(Throughput::Elements(few.len() as u64));
    group.bench_function("unhinted", |b| {
        b.iter(|| few.iter().map(|&(p, _)| project_to_surface(&s, p, None, &opts).distance).sum::<f64>())
    });
    group.finish();
}

/// The one-face models the stage benches run on.
fn stage_models() -> Vec<(&'static str, Model)> {
    vec![("freeform", freeform()), ("trimmed", trimmed()), ("sphere", model(vec![(sphere_surface(), Vec::new())]))]
}

fn stage_options() -> MeshOptions {
    MeshOptions::default().with_relative_tolerance(1e-3)
}

fn variants(c: &mut Criterion) {
    let mut group = c.benchmark_group("variants");
    let (models, options) = (stage_models(), stage_options());
    for (name, m) in &models {
        let p = Plan::new(m, &options).expect("the bench model is valid");
        let nodes = p.choose_variants(&mut p.start()).expect("the loops discretize").loop_nodes();
        group.throughput(Throughput::Elements(nodes.max(1) as u64));
        group.bench_function(*name, |b| {
            b.iter(|| black_box(&p).choose_variants(&mut p.start()).map(|v| v.grid_lines()))
        });
    }
    group.finish();
}

fn first_meshes(c: &mut Criterion) {
    let mut group = c.benchmark_group("first_meshes");
    let (models, options) = (stage_models(), stage_options());
    for (name, m) in &models {
        let p = Plan::new(m, &options).expect("the bench model is valid");
        let sewn = || {
            let mut run = p.start();
            let variants = p.choose_variants(&mut run).expect("the loops discretize");
            let sewn = p.sew_outlines(&run, variants);
            (run, sewn)
        };
        let (mut run, s) = sewn();
        group.throughput(Throughput::Elements(p.first_meshes(&mut run, s).expect("meshes").triangles() as u64));
        group.bench_function(*name, |b| {
            b.iter_batched(
                sewn,
                |(mut run, s)| p.first_meshes(&mut run, s).map(|w| w.triangles()),
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

fn refinement(c: &mut Criterion) {
    let mut group = c.benchmark_group("refinement");
    group.sample_size(20);
    let (models, options) = (stage_models(), stage_options());
    for (name, m) in &models {
        let p = Plan::new(m, &options).expect("the bench model is valid");
        let start = || {
            let mut run = p.start();
            let variants = p.choose_variants(&mut run).expect("the loops discretize");
            let sewn = p.sew_outlines(&run, variants);
            p.first_meshes(&mut run, sewn).expect("the bench model meshes")
        };
        let refine = |mut works| {
            p.refine(&mut works, &mut |_, _| true).expect("not cancelled");
            works.triangles()
        };
        group.throughput(Throughput::Elements(refine(start()) as u64));
        group.bench_function(*name, |b| b.iter_batched(start, refine, BatchSize::SmallInput));
    }
    group.finish();
}

fn sew(c: &mut Criterion) {
    let mut group = c.benchmark_group("sew");
    group.sample_size(20);
    let options = MeshOptions::default().with_relative_tolerance(1e-3);
    let halves = two_halves();
    let whole = model(vec![(sphere_surface(), Vec::new())]);
    // The difference between these two is mostly the sewing of the shared meridians.
    group.bench_function("sphere_one_face", |b| b.iter(|| mesh_model(black_box(&whole), &options)));
    group.bench_function("sphere_two_faces", |b| b.iter(|| mesh_model(black_box(&halves), &options)));
    group.finish();
}

fn tessellate(c: &mut Criterion) {
    let options = MeshOptions::default().with_relative_tolerance(1e-3);
    let mut group = c.benchmark_group("tessellate");
    group.sample_size(20);
    for (name, model) in [("freeform_rel_1e-3", freeform()), ("freeform_trimmed_rel_1e-3", trimmed())] {
        let first = mesh_model(&model, &options).expect("the bench model meshes");
        assert!(first.report.max_deviation <= first.report.tolerance, "{name}: tolerance not met");
        group.throughput(Throughput::Elements(first.report.triangles as u64));
        group.bench_function(name, |b| b.iter(|| mesh_model(black_box(&model), black_box(&options))));
    }
    group.finish();
}

fn measurement(c: &mut Criterion) {
    let mut group = c.benchmark_group("measurement");
    group.sample_size(10);
    let m = trimmed();
    let result = mesh_model(&m, &MeshOptions::default().with_relative_tolerance(1e-3)).expect("the bench model meshes");
    let mesh = &result.mesh;
    let tol = result.report.tolerance;
    group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
    let options = MeasureOptions::default().with_tolerance(tol);
    group.bench_function("measure_mesh", |b| b.iter(|| measure_mesh(black_box(&m), black_box(mesh), &options)));
    let deviation_only = MeasureOptions::default().with_tolerance(tol).with_coverage_samples(0);
    group.bench_function("measure_mesh_deviation", |b| {
        b.iter(|| measure_mesh(black_box(&m), black_box(mesh), &deviation_only))
    });
    group.sample_size(50);
    group.bench_function("weld_positions", |b| b.iter(|| weld_positions(black_box(&mesh.positions), tol * 1e-3)));
    group.bench_function("edge_counts", |b| b.iter(|| edge_counts(black_box(mesh), tol * 1e-3, tol)));
    group.bench_function("angle_stats", |b| b.iter(|| angle_stats(black_box(mesh))));
    group.finish();
}

criterion_group!(benches, evaluation, projection, variants, first_meshes, refinement, sew, tessellate, measurement);
criterion_main!(benches);
