//! Poorly parameterized surfaces (paper 001): the detector flags crowded
//! parameters and leaves good ones alone; rebuilt faces mesh with
//! better-shaped triangles within tolerance of the *original* surface.

use glam::DVec3;

use crate::shapes::{unit_circle, CIRCLE_KNOTS};
use surfmesh::{
    measure_mesh, mesh_model, read_json, step_ratio, Face, FaceSurface, MeasureOptions, MeshOptions, MeshResult, Model,
    NurbsCurve, NurbsSurface, Reparam, TrimLoop, RATIO_LIMIT,
};

/// A wavy sheet whose u parameter crowds: the first 80% of the u range (8 of
/// 10 control columns) covers x ∈ [0, 0.7], the last 20% x ∈ [0.7, 12].
fn crowded_surface() -> NurbsSurface {
    let xs = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 6.0, 12.0];
    let pts: Vec<Vec<DVec3>> = xs
        .iter()
        .map(|&x| {
            (0..6).map(|j| DVec3::new(x, 1.2 * j as f64, 1.5 * (0.5 * x).sin() + 0.3 * (j as f64).cos())).collect()
        })
        .collect();
    let mut ku = vec![0.0; 4];
    ku.extend((1..7).map(|k| k as f64 / 7.0));
    ku.extend([1.0; 4]);
    let kv = vec![0.0, 0.0, 0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0, 1.0, 1.0];
    NurbsSurface::try_new([3, 3], ku, kv, &pts, None).unwrap()
}

/// An exact ellipse in (u,v): the rational unit circle, affinely scaled.
fn ellipse(cu: f64, cv: f64, ru: f64, rv: f64) -> TrimLoop {
    let (unit, w) = unit_circle();
    let pts = unit.iter().map(|p| DVec3::new(cu + ru * p.x, cv + rv * p.y, 0.0)).collect();
    TrimLoop { curves: vec![NurbsCurve::try_new(2, CIRCLE_KNOTS.to_vec(), pts, Some(w)).unwrap()] }
}

fn model(loops: Vec<TrimLoop>) -> Model {
    Model {
        units: "mm".into(),
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(crowded_surface()), loops }],
        warnings: Vec::new(),
        tolerance: None,
    }
}

fn mesh(m: &Model, rel: f64, mode: Reparam) -> MeshResult {
    mesh_model(m, &MeshOptions::default().with_relative_tolerance(rel).with_reparam(mode)).unwrap()
}

fn area(r: &MeshResult) -> f64 {
    (0..r.mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = r.mesh.triangle(t);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// Auto against off on one model: flagged and rebuilt (triangle counts and
/// angles are printed: the mesher does not yet turn even parameters into
/// fewer triangles every time), and within tolerance of the original
/// surface by the independent yardstick (deviation and coverage).
fn auto_against_off(m: &Model, rel: f64) -> (MeshResult, MeshResult) {
    let off = mesh(m, rel, Reparam::Off);
    let auto = mesh(m, rel, Reparam::Auto);
    let rep = &auto.report;
    assert_eq!(rep.reparameterized.len(), 1, "{:?}", rep.warnings);
    let flagged = &rep.reparameterized[0];
    println!(
        "rel {rel}: off {} tris p1 {:.1}°, auto {} tris p1 {:.1}° ({} x {} points, fit {:.2e}), deviation {:.3e} <= {:.3e}",
        off.report.triangles,
        off.report.p1_angle_deg,
        rep.triangles,
        rep.p1_angle_deg,
        flagged.samples[0],
        flagged.samples[1],
        flagged.fit_error,
        measure_mesh(m, &auto.mesh, &MeasureOptions::default().with_tolerance(rep.tolerance)).max_deviation,
        rep.tolerance
    );
    assert!(flagged.rebuilt && flagged.ratio > RATIO_LIMIT, "{flagged:?} {:?}", rep.warnings);
    assert!(flagged.fit_error <= rep.tolerance / 4.0, "{flagged:?}");
    assert!(rep.warnings.iter().any(|w| w.contains("poorly parameterized")), "{:?}", rep.warnings);
    assert!(off.report.reparameterized.is_empty());
    assert!(rep.max_deviation <= rep.tolerance);
    assert_eq!(rep.inverted_triangles, 0);
    assert_eq!(rep.free_edges, 0);
    let opts = MeasureOptions::default().with_tolerance(rep.tolerance);
    let yard = measure_mesh(m, &auto.mesh, &opts);
    assert!(
        yard.max_deviation <= rep.tolerance,
        "rel {rel}: measured {} against the original, tolerance {}",
        yard.max_deviation,
        rep.tolerance
    );
    assert!(yard.coverage <= rep.tolerance, "rel {rel}: coverage {} (a hole or a lost region)", yard.coverage);
    (off, auto)
}

#[test]
fn reparam_crowded_sheet_meshes_within_tolerance_of_the_original() {
    let m = model(Vec::new());
    assert!(step_ratio(&m.faces[0].surface) > RATIO_LIMIT);
    for rel in [1e-2, 1e-3] {
        auto_against_off(&m, rel);
    }
}

#[test]
fn reparam_trimmed_crowded_face_keeps_its_hole() {
    // The hole sits in the stretched part: u ∈ [0.85, 0.95] spans several model units.
    let m = model(vec![ellipse(0.9, 0.5, 0.05, 0.2)]);
    let (off, auto) = auto_against_off(&m, 1e-3);
    let (a, b) = (area(&off), area(&auto));
    assert!((a - b).abs() < 2e-3 * a, "areas differ: off {a}, auto {b}");
}

#[test]
fn reparam_leaves_well_parameterized_surfaces_alone() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for name in ["sphere.json", "torus.json", "freeform.json", "cylinder.json", "twisted.json"] {
        let m = read_json(&std::fs::read(dir.join(name)).unwrap()).unwrap();
        for f in &m.faces {
            let r = step_ratio(&f.surface);
            assert!(r <= RATIO_LIMIT, "{name}: ratio {r}");
        }
        let r = mesh(&m, 1e-2, Reparam::Auto);
        assert!(r.report.reparameterized.is_empty(), "{name}: {:?}", r.report.warnings);
    }
}

#[test]
fn reparam_force_on_degenerate_faces_falls_back_or_holds_tolerance() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    // Poles (zero-length iso-lines): forced rebuilds either hold the tolerance or fall back with a warning.
    for name in ["pole.json", "sphere.json"] {
        let m = read_json(&std::fs::read(dir.join(name)).unwrap()).unwrap();
        let r = mesh(&m, 1e-2, Reparam::Force);
        assert_eq!(r.report.reparameterized.len(), 1, "{name}");
        let opts = MeasureOptions::default().with_tolerance(r.report.tolerance);
        let yard = measure_mesh(&m, &r.mesh, &opts);
        assert!(yard.max_deviation <= r.report.tolerance, "{name}: {} > {}", yard.max_deviation, r.report.tolerance);
        assert!(yard.coverage <= r.report.tolerance, "{name}: coverage {}", yard.coverage);
    }
    // A surface collapsed to a segment: nothing to interpolate; meshed as it is, with a warning.
    let pts: Vec<Vec<DVec3>> = (0..4).map(|i| vec![DVec3::new(i as f64, 0.0, 0.0); 4]).collect();
    let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let flat = NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).unwrap();
    let m = Model {
        units: "mm".into(),
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(flat), loops: Vec::new() }],
        warnings: Vec::new(),
        tolerance: None,
    };
    let r = mesh_model(&m, &MeshOptions::default().with_tolerance(0.01).with_reparam(Reparam::Force));
    let r = r.unwrap();
    assert_eq!(r.report.reparameterized.len(), 1);
    assert!(!r.report.reparameterized[0].rebuilt, "{:?}", r.report.warnings);
    assert!(r.report.warnings.iter().any(|w| w.contains("meshed")), "{:?}", r.report.warnings);
    assert!(r.report.max_deviation <= r.report.tolerance);
}
