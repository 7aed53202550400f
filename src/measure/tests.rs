//! The yardstick against meshes whose answer is known by construction.

use alloc::vec::Vec;
use core::f64::consts::FRAC_1_SQRT_2;
use glam::DVec3;

use super::{measure_mesh, MeasureOptions};
use crate::mesh::{FaceRange, Mesh};
use crate::model::{Face, FaceSurface, Model, TrimLoop};
use crate::nurbs::{NurbsCurve, NurbsSurface};
use crate::{mesh_model, read_json, MeshOptions, MeshResult};

fn model(json: &str) -> Model {
    read_json(json.as_bytes()).unwrap()
}

fn one_face(surface: NurbsSurface, loops: Vec<TrimLoop>) -> Model {
    Model {
        units: "mm".into(),
        faces: alloc::vec![Face { name: None, surface: FaceSurface::Nurbs(surface), loops }],
        ..Model::default()
    }
}

/// The exact rational sphere of radius 10 about the origin: a full circle
/// (nine points) along u times a half circle from pole to pole along v.
fn sphere_surface() -> NurbsSurface {
    let w = FRAC_1_SQRT_2;
    let circle = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0), (-1.0, 1.0, w), (-1.0, 0.0, 1.0)];
    let circle: Vec<(f64, f64, f64)> =
        circle.iter().copied().chain(circle[1..].iter().map(|&(x, y, w)| (-x, -y, w))).collect();
    let profile = [(0.0, -10.0, 1.0), (10.0, -10.0, w), (10.0, 0.0, 1.0), (10.0, 10.0, w), (0.0, 10.0, 1.0)];
    let points: Vec<Vec<DVec3>> = circle
        .iter()
        .map(|&(x, y, _)| profile.iter().map(|&(r, z, _)| DVec3::new(x * r, y * r, z)).collect())
        .collect();
    let weights: Vec<Vec<f64>> = circle.iter().map(|c| profile.iter().map(|p| c.2 * p.2).collect()).collect();
    let ku = alloc::vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0];
    let kv = alloc::vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    NurbsSurface::try_new([2, 2], ku, kv, &points, Some(&weights)).unwrap()
}

fn sphere() -> Model {
    one_face(sphere_surface(), Vec::new())
}

/// The freeform patch of `js_freeform.json` inside a square loop with a round hole.
fn trimmed_freeform() -> Model {
    let base = model(include_str!("../../tests/data/js_freeform.json"));
    let Some(FaceSurface::Nurbs(surface)) = base.faces.first().map(|f| f.surface.clone()) else {
        panic!("js_freeform.json holds one NURBS face")
    };
    let line = |a: [f64; 2], b: [f64; 2]| {
        let points = alloc::vec![DVec3::new(a[0], a[1], 0.0), DVec3::new(b[0], b[1], 0.0)];
        NurbsCurve::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0], points, None).unwrap()
    };
    let w = FRAC_1_SQRT_2;
    let ring = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let circle = NurbsCurve::try_new(
        2,
        alloc::vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0],
        ring.iter().map(|&(x, y)| DVec3::new(0.5 + 0.2 * x, 0.45 + 0.2 * y, 0.0)).collect(),
        Some(alloc::vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0]),
    )
    .unwrap();
    let outer = TrimLoop {
        curves: alloc::vec![
            line([0.05, 0.05], [0.95, 0.05]),
            line([0.95, 0.05], [0.95, 0.95]),
            line([0.95, 0.95], [0.05, 0.95]),
            line([0.05, 0.95], [0.05, 0.05]),
        ],
    };
    one_face(surface, alloc::vec![outer, TrimLoop { curves: alloc::vec![circle] }])
}

fn mesh(model: &Model, options: &MeshOptions) -> MeshResult {
    mesh_model(model, options).unwrap()
}

/// Lighter sampling than the default: the tests run unoptimized.
fn options() -> MeasureOptions {
    MeasureOptions { index_samples: 5_000, coverage_samples: 20_000, ..MeasureOptions::default() }
}

#[test]
fn own_mesh_reproduces_the_mesher_report() {
    let models = [
        ("js_freeform", model(include_str!("../../tests/data/js_freeform.json"))),
        ("twisted", model(include_str!("../../tests/data/twisted.json"))),
        ("trimmed_freeform", trimmed_freeform()),
        ("sphere", sphere()),
    ];
    for (name, m) in models {
        let r = mesh(&m, &MeshOptions::default().with_relative_tolerance(1e-3));
        let got = measure_mesh(&m, &r.mesh, &options().with_tolerance(r.report.tolerance));
        let want = r.report.max_deviation;
        assert!(want > 0.0, "{name}: the mesher measured nothing");
        assert!(
            (got.max_deviation - want).abs() <= 0.05 * want,
            "{name}: measured {} vs report {want}",
            got.max_deviation
        );
        assert_eq!(got.triangles, r.report.triangles, "{name}");
        assert_eq!(got.boundary_edges, r.report.boundary_edges, "{name}");
        assert_eq!(got.free_edges, r.report.free_edges, "{name}");
        assert_eq!(got.invalid_triangles, 0, "{name}");
        assert!(got.face_ranges, "{name}");
        // A mesh within the tolerance covers the surface within about the tolerance.
        assert!(
            got.coverage <= 1.5 * r.report.tolerance,
            "{name}: coverage {} > tol {}",
            got.coverage,
            r.report.tolerance
        );
        assert!((got.min_angle_deg - r.report.min_angle_deg).abs() < 1e-9, "{name}");
    }
}

#[test]
fn deleted_triangle_shows_as_a_hole() {
    let m = sphere();
    let r = mesh(&m, &MeshOptions::default().with_relative_tolerance(1e-3));
    let opts = options().with_tolerance(r.report.tolerance);
    let whole = measure_mesh(&m, &r.mesh, &opts);
    assert_eq!(whole.boundary_edges, 0, "the sphere's mesh is closed");
    assert_eq!(whole.uncovered_samples, 0);

    // Delete the largest triangle.
    let area = |t: [DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).length();
    let n = r.mesh.triangle_count();
    let big = (0..n).max_by(|&a, &b| area(r.mesh.triangle(a)).total_cmp(&area(r.mesh.triangle(b)))).unwrap();
    let mut holed = r.mesh.clone();
    holed.indices.drain(3 * big..3 * big + 3);
    holed.face_ranges = alloc::vec![FaceRange { first: 0, count: n as u32 - 1 }];
    let got = measure_mesh(&m, &holed, &opts);
    assert_eq!(got.boundary_edges, 3);
    assert!(got.coverage > 2.0 * r.report.tolerance, "coverage {} vs tol {}", got.coverage, r.report.tolerance);
    assert!(got.coverage > 2.0 * whole.coverage);
    assert!(got.uncovered_samples > 0);
    // The remaining triangles are as close to the surface as before.
    assert!(got.max_deviation <= whole.max_deviation);
}

#[test]
fn dropped_face_shows_in_coverage_only() {
    // A sphere split into two faces; the mesh of the second face is dropped.
    let (a, b) = sphere_surface().split(true, 0.5).unwrap();
    let face = |surface| Face { name: None, surface: FaceSurface::Nurbs(surface), loops: Vec::new() };
    let m = Model { units: "mm".into(), faces: alloc::vec![face(a), face(b)], ..Model::default() };
    let r = mesh(&m, &MeshOptions::default().with_relative_tolerance(1e-3));
    assert_eq!(r.mesh.face_ranges.len(), 2);
    let opts = options().with_tolerance(r.report.tolerance);
    let whole = measure_mesh(&m, &r.mesh, &opts);
    assert_eq!(whole.boundary_edges, 0);
    assert_eq!(whole.free_edges, 0);

    let keep = r.mesh.face_ranges[0].count as usize;
    let mut half = r.mesh.clone();
    half.indices.truncate(3 * keep);
    half.face_ranges.truncate(1);
    let got = measure_mesh(&m, &half, &opts);
    assert!(got.max_deviation <= whole.max_deviation * 1.0001, "what is left is still on the surface");
    assert!(got.coverage > 10.0, "half a sphere of radius 10 is missing: coverage {}", got.coverage);
    assert!(got.boundary_edges > 0);
    assert!(got.uncovered_samples * 3 > got.coverage_samples, "about half the samples are uncovered");
}

#[test]
fn shifted_mesh_measures_the_shift() {
    // Every vertex moved 0.1 outward along the exact normal of a sphere of
    // radius 10: the vertices are exactly 0.1 away; points inside a triangle
    // are closer by at most the chordal deviation (below the 0.02 tolerance).
    let m = sphere();
    let r = mesh(&m, &MeshOptions::default().with_tolerance(0.02));
    let mut shifted = r.mesh.clone();
    for (p, n) in shifted.positions.iter_mut().zip(&r.mesh.normals) {
        *p += *n * 0.1;
    }
    let got = measure_mesh(&m, &shifted, &options().with_tolerance(0.02));
    assert!((got.max_deviation - 0.1).abs() < 1e-6, "max {}", got.max_deviation);
    assert!(got.mean_deviation > 0.1 - 0.02 && got.mean_deviation < 0.1, "mean {}", got.mean_deviation);
    assert!((got.coverage - 0.1).abs() < 0.005, "coverage {}", got.coverage);
    assert_eq!(got.uncovered_samples, got.coverage_samples, "0.1 is beyond the 0.02 tolerance everywhere");
    // Shifting moves nothing else.
    assert_eq!(got.boundary_edges, 0);
    assert!((got.min_angle_deg - r.report.min_angle_deg).abs() < 1e-6);
}

#[test]
fn peer_mesh_without_face_ranges_or_with_bad_indices() {
    let m = model(include_str!("../../tests/data/js_freeform.json"));
    let r = mesh(&m, &MeshOptions::default().with_relative_tolerance(1e-2));
    let opts = options().with_tolerance(r.report.tolerance);
    let mut peer = Mesh { positions: r.mesh.positions.clone(), indices: r.mesh.indices.clone(), ..Mesh::default() };
    let plain = measure_mesh(&m, &peer, &opts);
    assert!(!plain.face_ranges);
    assert_eq!(plain.free_edges, 0);
    assert_eq!(plain.boundary_edges, r.report.boundary_edges, "an open patch: its border");
    assert!((plain.max_deviation - r.report.max_deviation).abs() <= 0.05 * r.report.max_deviation);

    // Garbage from a peer is counted, not trusted, and does not panic.
    peer.indices.extend_from_slice(&[0, 1, u32::MAX]);
    peer.positions.push(DVec3::new(f64::NAN, 0.0, 0.0));
    let last = (peer.positions.len() - 1) as u32;
    peer.indices.extend_from_slice(&[0, 1, last]);
    peer.indices.push(7); // a dangling index: not a triangle
    peer.face_ranges = alloc::vec![FaceRange { first: 5, count: 1 }];
    let got = measure_mesh(&m, &peer, &opts);
    assert_eq!(got.invalid_triangles, 2);
    assert_eq!(got.triangles, r.report.triangles);
    assert!(!got.face_ranges);
    assert_eq!(got.max_deviation, plain.max_deviation);

    // An empty mesh covers nothing; an empty model measures nothing.
    let none = measure_mesh(&m, &Mesh::default(), &opts);
    assert_eq!(none.coverage, f64::INFINITY);
    assert_eq!(none.uncovered_samples, none.coverage_samples);
    let empty = measure_mesh(&Model::default(), &r.mesh, &opts);
    assert_eq!(empty.coverage_samples, 0);
    assert_eq!(empty.max_deviation, f64::INFINITY);
}
