//! Meshing acceptance: deviation within tolerance (the project's own
//! measurement and, for analytic shapes, the exact distance), no inverted
//! triangles, watertight closed surfaces, trimmed vertices inside the kept
//! region, triangle counts that follow the tolerance, and errors for bad loops.

use glam::{DVec2, DVec3};
use surfmesh::{
    mesh_model, project_to_surface, Error, Face, FaceSurface, Mesh, MeshOptions, MeshResult, Model, NurbsCurve,
    NurbsSurface, ProjectionOptions, Surface, TrimLoop, Warning, WarningKind,
};

use crate::shapes;

const RELS: [f64; 3] = [1e-1, 1e-2, 1e-3];

fn mesh(model: &Model, rel: f64) -> MeshResult {
    mesh_model(model, &MeshOptions::default().with_relative_tolerance(rel)).expect("meshes")
}

/// Largest exact distance over vertices, edge midpoints and interior points of every triangle.
fn exact_deviation(m: &Mesh, dist: impl Fn(DVec3) -> f64) -> f64 {
    let mut worst: f64 = 0.0;
    let bary = [
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [0.6, 0.3, 0.1],
        [0.1, 0.6, 0.3],
        [0.3, 0.1, 0.6],
        [1.0, 0.0, 0.0],
    ];
    for t in 0..m.triangle_count() {
        let p = m.triangle(t);
        for b in bary {
            worst = worst.max(dist(p[0] * b[0] + p[1] * b[1] + p[2] * b[2]));
        }
    }
    worst
}

/// Checks every promise of one mesh result; returns the triangle count.
fn check_common(name: &str, r: &MeshResult, rel: f64) -> usize {
    let rep = &r.report;
    assert!(rep.triangles > 0, "{name} @ {rel}: no triangles");
    assert!(
        rep.max_deviation <= rep.tolerance,
        "{name} @ {rel}: measured deviation {} above tolerance {}",
        rep.max_deviation,
        rep.tolerance
    );
    assert_eq!(rep.inverted_triangles, 0, "{name} @ {rel}: inverted triangles");
    assert_eq!(rep.free_edges, 0, "{name} @ {rel}: cracks");
    assert_eq!(rep.nonmanifold_edges, 0, "{name} @ {rel}: non-manifold edges");
    assert!(rep.warnings.is_empty(), "{name} @ {rel}: warnings {:?}", rep.warnings);
    assert_eq!(r.mesh.indices.len(), 3 * rep.triangles);
    assert_eq!(r.mesh.positions.len(), rep.vertices);
    assert_eq!(r.mesh.normals.len(), rep.vertices);
    let mut used = vec![false; rep.vertices];
    for &i in &r.mesh.indices {
        used[i as usize] = true;
    }
    assert!(used.iter().all(|&u| u), "{name}: a vertex no triangle uses");
    for n in &r.mesh.normals {
        assert!((n.length() - 1.0).abs() < 1e-9, "{name}: normal not unit");
    }
    // Facets agree with the stored vertex normals (no flipped triangle).
    for t in 0..r.mesh.triangle_count() {
        let p = r.mesh.triangle(t);
        let f = (p[1] - p[0]).cross(p[2] - p[0]);
        let i = &r.mesh.indices[3 * t..3 * t + 3];
        let n: DVec3 = i.iter().map(|&k| r.mesh.normals[k as usize]).sum();
        assert!(
            f.dot(n) >= 0.0,
            "{name} @ {rel}: triangle {t} faces against the surface normals {p:?} {:?}",
            i.iter().map(|&k| r.mesh.normals[k as usize]).collect::<Vec<_>>()
        );
    }
    rep.triangles
}

fn counts_follow_tolerance(name: &str, counts: &[usize]) {
    for w in counts.windows(2) {
        assert!(
            w[1] as f64 <= 12.0 * w[0] as f64,
            "{name}: 10x tighter tolerance gave more than 12x the triangles {counts:?}"
        );
    }
}

#[test]
fn mesh_freeform_within_tolerance() {
    let model = shapes::freeform();
    let counts: Vec<usize> = RELS.iter().map(|&rel| check_common("freeform", &mesh(&model, rel), rel)).collect();
    counts_follow_tolerance("freeform", &counts);
}

#[test]
fn mesh_sphere_exact_and_closed() {
    let model = shapes::sphere(shapes::SPHERE_RADIUS);
    let mut counts = Vec::new();
    for rel in RELS {
        let r = mesh(&model, rel);
        counts.push(check_common("sphere", &r, rel));
        assert_eq!(r.report.boundary_edges, 0, "sphere @ {rel}: open edges");
        let exact = exact_deviation(&r.mesh, shapes::sphere_distance);
        assert!(exact <= r.report.tolerance, "sphere @ {rel}: exact deviation {exact} > {}", r.report.tolerance);
    }
    counts_follow_tolerance("sphere", &counts);
}

#[test]
fn mesh_torus_exact_and_closed() {
    let model = shapes::torus(shapes::TORUS_MAJOR, shapes::TORUS_MINOR);
    let mut counts = Vec::new();
    for rel in RELS {
        let r = mesh(&model, rel);
        counts.push(check_common("torus", &r, rel));
        assert_eq!(r.report.boundary_edges, 0, "torus @ {rel}: free edges on a closed surface");
        let exact = exact_deviation(&r.mesh, shapes::torus_distance);
        assert!(exact <= r.report.tolerance, "torus @ {rel}: exact deviation {exact} > {}", r.report.tolerance);
    }
    counts_follow_tolerance("torus", &counts);
}

/// A face closed on itself has no border to share: it is a body of its
/// own. Two copies of one torus (as closed quarters of a ring meet at their
/// end caps) are two solids in one place, each closed, not one surface whose
/// every edge is non-manifold.
#[test]
fn mesh_closed_faces_that_touch_are_bodies_of_their_own() {
    let mut model = shapes::torus(shapes::TORUS_MAJOR, shapes::TORUS_MINOR);
    model.faces.push(model.faces[0].clone());
    let r = mesh(&model, 1e-2);
    let e = (r.report.nonmanifold_edges, r.report.boundary_edges, r.report.free_edges);
    assert_eq!(e, (0, 0, 0), "two tori in one place: non-manifold, boundary, free edges");
    let counts: Vec<u32> = r.mesh.face_ranges.iter().map(|f| f.count).collect();
    assert!(counts[0] > 0 && counts[0] == counts[1], "both copies meshed alike: {counts:?}");
}

#[test]
fn mesh_cylinder_exact() {
    let model = shapes::cylinder();
    let mut counts = Vec::new();
    for rel in RELS {
        let r = mesh(&model, rel);
        counts.push(check_common("cylinder", &r, rel));
        let exact = exact_deviation(&r.mesh, shapes::cylinder_distance);
        assert!(exact <= r.report.tolerance, "cylinder @ {rel}: exact deviation {exact}");
    }
    counts_follow_tolerance("cylinder", &counts);
}

#[test]
fn mesh_pole_surface() {
    let model = shapes::pole();
    let counts: Vec<usize> = RELS.iter().map(|&rel| check_common("pole", &mesh(&model, rel), rel)).collect();
    counts_follow_tolerance("pole", &counts);
}

#[test]
fn mesh_trimmed_two_holes_vertices_inside() {
    let model = shapes::trimmed_holes();
    let region = shapes::trimmed_holes_regions();
    let surface = shapes::first_surface(&model);
    let mut counts = Vec::new();
    for rel in RELS {
        let r = mesh(&model, rel);
        counts.push(check_common("trimmed_holes", &r, rel));
        for (i, &p) in r.mesh.positions.iter().enumerate() {
            let pr = project_to_surface(surface, p, None, &ProjectionOptions::default());
            assert!(pr.distance < 1e-9 * (1.0 + p.length()), "vertex {i} is off the surface by {}", pr.distance);
            assert!(
                region.contains(pr.uv, 1e-7),
                "trimmed_holes @ {rel}: vertex {i} at {:?} lies {} outside the kept region",
                pr.uv,
                region.outside_by(pr.uv)
            );
        }
        // The holes really are holes: no triangle centroid inside either circle.
        for t in 0..r.mesh.triangle_count() {
            let p = r.mesh.triangle(t);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            let uv = project_to_surface(surface, c, None, &ProjectionOptions::default()).uv;
            for &(centre, radius) in &region.holes {
                assert!(uv.distance(centre) > radius * 0.9, "triangle {t} covers a hole");
            }
        }
    }
    counts_follow_tolerance("trimmed_holes", &counts);
}

#[test]
fn mesh_angle_and_max_edge_limits_hold() {
    let model = shapes::freeform();
    let coarse = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-2)).expect("meshes");
    let limited = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-2).with_max_edge(Some(5.0)))
        .expect("meshes");
    assert!(limited.report.triangles > coarse.report.triangles);
    let m = &limited.mesh;
    for t in 0..m.triangle_count() {
        let p = m.triangle(t);
        for k in 0..3 {
            assert!(p[k].distance(p[(k + 1) % 3]) <= 5.0 + 1e-9, "edge longer than max_edge");
        }
    }
    let tight =
        mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-1).with_angle(0.1)).expect("meshes");
    assert!(tight.report.max_normal_turn <= 0.1 + 1e-12, "normal turn {}", tight.report.max_normal_turn);
}

fn uv_polygon(pts: &[(f64, f64)]) -> TrimLoop {
    let n = pts.len();
    let curves = (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            NurbsCurve::try_new(
                1,
                vec![0.0, 0.0, 1.0, 1.0],
                vec![DVec3::new(a.0, a.1, 0.0), DVec3::new(b.0, b.1, 0.0)],
                None,
            )
            .expect("segment")
        })
        .collect();
    TrimLoop { curves }
}

fn face_with_loops(loops: Vec<TrimLoop>) -> Model {
    let surface = shapes::first_surface(&shapes::freeform()).clone();
    Model {
        units: "mm".into(),
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(surface), loops }],
        ..Model::default()
    }
}

/// A flat 10 × 10 square patch (x = 10u, y = 10v) with `loops`, so areas in
/// (u,v) scale by 100 into the mesh.
fn flat_face_with_loops(loops: Vec<TrimLoop>) -> Model {
    let points = vec![
        vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 10.0, 0.0)],
        vec![DVec3::new(10.0, 0.0, 0.0), DVec3::new(10.0, 10.0, 0.0)],
    ];
    let surface = NurbsSurface::try_new([1, 1], vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0], &points, None)
        .expect("bilinear patch");
    Model {
        units: "mm".into(),
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(surface), loops }],
        ..Model::default()
    }
}

fn mesh_area(mesh: &Mesh) -> f64 {
    mesh.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// Loops that cross are mended, as industrial readers mend wires: split at
/// the crossings and keep the region the loops wind round, with a warning
/// naming the face (paper 000 §3.1 needs loops that neither cross nor touch).
#[test]
fn mesh_mends_crossing_loops_to_the_region_they_wind_round() {
    let outer = uv_polygon(&[(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)]);
    let a = uv_polygon(&[(0.3, 0.3), (0.3, 0.6), (0.6, 0.6), (0.6, 0.3)]);
    let b = uv_polygon(&[(0.5, 0.5), (0.5, 0.8), (0.8, 0.8), (0.8, 0.5)]);
    let r = mesh_model(&flat_face_with_loops(vec![outer.clone(), a, b]), &MeshOptions::default()).expect("mended");
    let w = &r.report.warnings;
    let crossed = |w: &Warning| matches!(w.kind, WarningKind::LoopsMended(m) if m.crossings > 0 && m.rejoined);
    assert!(w.iter().any(|w| w.face == Some(0) && crossed(w)), "{w:?}");
    // The square less the union of the two holes (0.09 + 0.09 - 0.01).
    let area = mesh_area(&r.mesh);
    assert!((area - 100.0 * (0.64 - 0.17)).abs() < 1e-6, "area {area}");
    for t in r.mesh.indices.chunks_exact(3) {
        let c = t.iter().map(|&i| r.mesh.positions[i as usize]).sum::<DVec3>() / 30.0;
        let in_hole = |lo: f64, hi: f64| c.x > lo && c.x < hi && c.y > lo && c.y < hi;
        assert!(!in_hole(0.3, 0.6) && !in_hole(0.5, 0.8), "triangle in a hole at {c}");
    }
    assert_eq!(r.report.inverted_triangles, 0);

    // A bow tie: the lobe that runs counter-clockwise is the region.
    let bow = uv_polygon(&[(0.1, 0.1), (0.9, 0.9), (0.9, 0.1), (0.1, 0.9)]);
    let r = mesh_model(&flat_face_with_loops(vec![bow]), &MeshOptions::default()).expect("one lobe");
    let mended = |w: &Warning| matches!(w.kind, WarningKind::LoopsMended(m) if m.rejoined);
    assert!(r.report.warnings.iter().any(mended), "{:?}", r.report.warnings);
    let area = mesh_area(&r.mesh);
    assert!((area - 16.0).abs() < 1e-6, "one lobe of 0.16 in (u,v): area {area}");

    // A hole of no area (a line gone out and back) bounds nothing.
    let flat = uv_polygon(&[(0.3, 0.3), (0.6, 0.6), (0.45, 0.45)]);
    let r = mesh_model(&flat_face_with_loops(vec![outer.clone(), flat]), &MeshOptions::default()).expect("meshes");
    let w = &r.report.warnings;
    // The warning's text, as the report shows it.
    assert!(w.iter().any(|w| w.to_string() == "face 0: 1 trim loop enclosing no area dropped"), "{w:?}");
    let flat = |w: &Warning| matches!(w.kind, WarningKind::LoopsMended(m) if m.flat == 1 && !m.rejoined);
    assert!(w.iter().any(|w| w.face == Some(0) && flat(w)), "{w:?}");
    assert!((mesh_area(&r.mesh) - 64.0).abs() < 1e-6);

    // A clockwise loop beside the outer loop is a hole of nothing; a
    // counter-clockwise one is a second region of the face.
    let cw = [(0.92, 0.3), (0.92, 0.6), (0.98, 0.6), (0.98, 0.3)];
    let ccw: Vec<(f64, f64)> = cw.iter().rev().copied().collect();
    for (beside, want) in [(cw.to_vec(), 64.0), (ccw, 64.0 + 1.8)] {
        let loops = vec![outer.clone(), uv_polygon(&beside)];
        let r = mesh_model(&flat_face_with_loops(loops), &MeshOptions::default()).expect("meshes");
        assert!(r.report.warnings.iter().any(mended), "{:?}", r.report.warnings);
        let area = mesh_area(&r.mesh);
        assert!((area - want).abs() < 1e-6, "area {area}, want {want}");
    }
}

/// One face whose loop encloses nothing does not sink a model of several: it is
/// skipped with a warning naming it, its face range stays (empty) so ranges
/// still match faces, and the others mesh. When no face meshes, the first
/// face's error is the model's.
#[test]
fn mesh_skips_a_bad_face_among_good_ones() {
    let outer = uv_polygon(&[(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)]);
    let flat = uv_polygon(&[(0.1, 0.1), (0.5, 0.5), (0.9, 0.9)]);
    let bad = face_with_loops(vec![flat]).faces.remove(0);
    let good = face_with_loops(vec![outer]).faces.remove(0);
    let mut model = face_with_loops(vec![]);
    model.faces = vec![good.clone(), bad.clone(), good];
    let r = mesh_model(&model, &MeshOptions::default()).expect("the good faces mesh");
    assert_eq!(r.report.faces_skipped, 1);
    assert!(
        r.report
            .warnings
            .iter()
            .any(|w| w.face == Some(1) && matches!(&w.kind, WarningKind::FaceSkipped(why) if why.contains("area"))),
        "{:?}",
        r.report.warnings
    );
    let counts: Vec<u32> = r.mesh.face_ranges.iter().map(|f| f.count).collect();
    assert_eq!(counts.len(), 3);
    assert!(counts[0] > 0 && counts[1] == 0 && counts[2] == counts[0], "{counts:?}");
    assert_eq!(r.report.triangles as u32, counts[0] + counts[2]);

    model.faces = vec![bad.clone(), bad];
    let err = mesh_model(&model, &MeshOptions::default()).expect_err("no face meshes");
    assert!(matches!(err, Error::Mesh { face: 0, .. }), "{err}");
}

/// A right circular cone whose apex is a collapsed edge of its NURBS (radius
/// 10, height 10: the normal jumps at the apex). The triangles round the
/// apex are judged by the normals next to it on their own side, so they
/// meet the angle limit instead of being split down to the minimum edge.
#[test]
fn mesh_cone_apex_meets_the_angle_limit() {
    let (circle, cw) = shapes::unit_circle();
    let points: Vec<Vec<DVec3>> =
        circle.iter().map(|c| vec![DVec3::new(0.0, 0.0, 10.0), DVec3::new(10.0 * c.x, 10.0 * c.y, 0.0)]).collect();
    let weights: Vec<Vec<f64>> = cw.iter().map(|&w| vec![w, w]).collect();
    let surface =
        NurbsSurface::try_new([2, 1], shapes::CIRCLE_KNOTS.to_vec(), vec![0.0, 0.0, 1.0, 1.0], &points, Some(&weights))
            .expect("cone");
    let mut model = face_with_loops(vec![]);
    model.faces[0].surface = FaceSurface::Nurbs(surface);
    for rel in RELS {
        let r = mesh(&model, rel);
        let rep = &r.report;
        assert!(
            rep.warnings.iter().all(|w| !matches!(w.kind, WarningKind::Unproven { .. })),
            "{rel}: {:?}",
            rep.warnings
        );
        assert!(rep.max_deviation <= rep.tolerance, "{rel}: {} > {}", rep.max_deviation, rep.tolerance);
        assert_eq!(rep.inverted_triangles, 0);
        // A cone is flat along its rulings: a fan of a few dozen to a few hundred triangles, not thousands.
        assert!(rep.triangles < 400, "{rel}: {} triangles", rep.triangles);
        // Exact distance to the cone's side: (ρ + z − 10)/√2 for ρ = |(x, y)|.
        let dev = exact_deviation(&r.mesh, |p| ((p.x.hypot(p.y) + p.z - 10.0) / 2f64.sqrt()).abs());
        assert!(dev <= rep.tolerance, "{rel}: exact deviation {dev} > {}", rep.tolerance);
    }
}

/// Files hold coordinates like 3.8e-49 for 0; the triangulator refuses
/// non-zero values that small, so they are taken as 0 and the face meshes.
#[test]
fn mesh_takes_vanishing_trim_coordinates_as_zero() {
    let lp = uv_polygon(&[(0.2, 3.7569948658334295e-49), (0.8, 0.0), (0.8, 0.8), (0.2, 0.8)]);
    let r = mesh(&face_with_loops(vec![lp]), 1e-2);
    assert!(r.report.triangles > 0 && r.report.faces_skipped == 0, "{:?}", r.report.warnings);
    assert!(r.report.max_deviation <= r.report.tolerance);
}

#[test]
fn mesh_rejects_bad_options() {
    let model = shapes::freeform();
    for opts in [
        MeshOptions::default().with_tolerance(0.0),
        MeshOptions::default().with_tolerance(f64::NAN),
        MeshOptions::default().with_relative_tolerance(2.0),
        MeshOptions::default().with_angle(-1.0),
        MeshOptions::default().with_max_edge(Some(0.0)),
    ] {
        assert!(matches!(mesh_model(&model, &opts), Err(Error::Options(_))));
    }
}

#[test]
fn mesh_budget_is_respected_with_a_warning() {
    let model = shapes::freeform();
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-3).with_max_triangles(20));
    match r {
        Err(Error::Limit(msg)) => assert!(msg.contains("budget"), "{msg}"),
        Ok(r) => {
            assert!(r.report.triangles <= 22, "{}", r.report.triangles);
            assert!(!r.report.warnings.is_empty());
        }
        Err(e) => panic!("unexpected error {e}"),
    }
}

#[test]
fn mesh_uv_hint_helper_agrees_with_surface() {
    // The sphere's collapsed edge still has a unit normal that points away from the centre.
    let s = shapes::sphere_surface(shapes::SPHERE_RADIUS);
    let [lo, hi] = s.domain();
    for uv in [lo, DVec2::new(hi.x, lo.y), DVec2::new(0.3, lo.y), DVec2::new(0.3, hi.y)] {
        let p = s.point(uv);
        let n = s.normal(uv);
        assert!((n.dot(p.normalize()).abs() - 1.0).abs() < 1e-6, "pole normal {n:?} at {p:?}");
    }
}

/// A bicubic Bézier patch from a height function over `[x0, x1] × [0, 10]`.
fn height_patch(x0: f64, x1: f64, h: impl Fn(f64, f64) -> f64) -> surfmesh::NurbsSurface {
    let pts: Vec<Vec<DVec3>> = (0..4)
        .map(|i| {
            let x = x0 + (x1 - x0) * i as f64 / 3.0;
            (0..4).map(|j| DVec3::new(x, 10.0 * j as f64 / 3.0, h(x, j as f64 / 3.0))).collect()
        })
        .collect();
    let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    surfmesh::NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).expect("patch")
}

/// Mesh edges on the plane x = 10 used by one triangle only (positions keyed at 1e-6).
fn open_edges_on_x10(m: &Mesh) -> usize {
    let mut uses = std::collections::HashMap::new();
    let key = |p: DVec3| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64, (p.z * 1e6).round() as i64);
    for t in m.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (key(m.positions[t[k] as usize]), key(m.positions[t[(k + 1) % 3] as usize]));
            *uses.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
        }
    }
    let on_seam = |k: &(i64, i64, i64)| (k.0 - 10_000_000).abs() <= 1;
    uses.iter().filter(|(e, &n)| n == 1 && on_seam(&e.0) && on_seam(&e.1)).count()
}

/// A flat face and a wavy one that meet along the straight line x = 10.
fn flat_and_wavy() -> Model {
    let flat = height_patch(0.0, 10.0, |_, _| 0.0);
    let wavy = height_patch(10.0, 20.0, |x, t| if x > 10.0 { 8.0 * (t * 6.0).sin() } else { 0.0 });
    let face = |s| Face { name: None, surface: FaceSurface::Nurbs(s), loops: vec![] };
    Model {
        units: "mm".into(),
        faces: vec![face(flat), face(wavy)],
        warnings: vec![],
        tolerance: None,
        bodies: vec![],
        ..Default::default()
    }
}

#[test]
fn mesh_two_faces_share_their_border_without_cracks() {
    // A flat face and a wavy one meet along the straight line x = 10: the wavy
    // face needs many more border nodes than the flat one.
    let model = flat_and_wavy();
    for rel in RELS {
        let r = mesh(&model, rel);
        check_common("two faces", &r, rel);
        assert_eq!(open_edges_on_x10(&r.mesh), 0, "rel {rel}: open edges on the shared border");
        // The outer border of the two faces stays open, and is not reported as a crack.
        assert!(r.report.boundary_edges > 0);
        // Without sewing the same model has T-junctions there, and they count as cracks.
        let unsewn = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(rel).with_sew(Some(1e-12)))
            .expect("meshes");
        assert!(open_edges_on_x10(&unsewn.mesh) > 0, "rel {rel}: the test shape no longer needs sewing");
        assert!(unsewn.report.free_edges > 0, "rel {rel}: T-junctions not reported as cracks");
    }
}

#[test]
fn mesh_saddle_refines_without_slivers() {
    // A bilinear saddle: every iso-line is straight, so only refinement sees
    // the twist. Plain bisection bred slivers here whose facets flipped, and
    // refinement never ended.
    let json = br#"{"faces":[{"surface":{"degree":[1,1],"knots":[[0,0,1,1],[0,0,1,1]],
        "points":[[[0,0,0],[0,10,0]],[[10,0,0],[10,10,4]]]}}]}"#;
    let model = surfmesh::read_json(json).expect("reads");
    let mut counts = Vec::new();
    // (At 0.1 the angle limit, not the tolerance, sets the count.)
    for tol in [0.01, 0.001] {
        let r = mesh_model(&model, &MeshOptions::default().with_tolerance(tol)).expect("meshes");
        counts.push(check_common("saddle", &r, tol));
        assert!(r.report.min_angle_deg > 10.0, "tol {tol}: min angle {}", r.report.min_angle_deg);
    }
    counts_follow_tolerance("saddle", &counts);
}

#[test]
fn mesh_reports_progress_and_stops_when_asked() {
    let model = flat_and_wavy();
    let mut seen = Vec::new();
    let r = surfmesh::mesh_model_with_progress(&model, &MeshOptions::default(), &mut |done, total| {
        seen.push((done, total));
        true
    });
    assert!(r.is_ok());
    assert_eq!(seen, vec![(1, 2), (2, 2)]);
    let mut calls = 0;
    let r = surfmesh::mesh_model_with_progress(&model, &MeshOptions::default(), &mut |_, _| {
        calls += 1;
        false
    });
    assert!(matches!(r, Err(Error::Cancelled)));
    assert_eq!(calls, 1, "meshing went on after the callback said stop");
}

#[test]
fn mesh_split_surface_halves_reproduce_the_original() {
    // Splitting (knot insertion to full multiplicity) in both directions keeps
    // the shape: each half evaluates to the original at the same parameters,
    // and the halves mesh into one crack-free model.
    let s = shapes::first_surface(&shapes::sphere(shapes::SPHERE_RADIUS)).clone();
    for along_u in [true, false] {
        let (left, right) = s.split(along_u, 0.3).expect("splits");
        for k in 0..=20 {
            for l in 0..=20 {
                let (a, b) = (k as f64 / 20.0, l as f64 / 20.0);
                let uv = if along_u { DVec2::new(a, b) } else { DVec2::new(b, a) };
                let half = if (if along_u { uv.x } else { uv.y }) <= 0.3 { &left } else { &right };
                assert!(half.point(uv).distance(s.point(uv)) < 1e-9, "split changed the surface at {uv:?}");
            }
        }
        let face = |x: surfmesh::NurbsSurface| Face { name: None, surface: FaceSurface::Nurbs(x), loops: vec![] };
        let model = Model {
            units: "mm".into(),
            faces: vec![face(left), face(right)],
            warnings: vec![],
            tolerance: None,
            bodies: vec![],
            ..Default::default()
        };
        let r = mesh(&model, 1e-3);
        check_common("split sphere", &r, 1e-3);
        assert_eq!(r.report.boundary_edges, 0, "the two halves of a sphere close up");
    }
    assert!(s.split(true, 0.0).is_none() && s.split(false, 1.0).is_none());
}

/// A row of patches that meet exactly, every other one wavy inside (so the
/// two sides of a border take different nodes), and one more at its end
/// `gap` apart.
fn row_with_one_gap(gap: f64) -> Model {
    let patch = |x0: f64, wavy: bool| {
        height_patch(x0, x0 + 10.0, move |x, t| {
            let inside = x > x0 + 1.0 && x < x0 + 9.0;
            (0.3 * x).sin() * (t * 5.0).sin() + if wavy && inside { 6.0 * (t * 9.0).sin() } else { 0.0 }
        })
    };
    let face = |s| Face { name: None, surface: FaceSurface::Nurbs(s), loops: vec![] };
    let mut faces: Vec<Face> = (0..30).map(|i| face(patch(10.0 * i as f64, i % 2 == 1))).collect();
    faces.push(face(patch(300.0 + gap, false)));
    Model { units: "mm".into(), faces, warnings: vec![], tolerance: None, bodies: vec![], ..Default::default() }
}

#[test]
fn mesh_sews_one_gapped_border_in_a_model_that_otherwise_meets_exactly() {
    // Nearly every border node lies on its neighbour's border, so the model's
    // gaps are nothing; the last pair's own gap (0.3 of the tolerance, within
    // the sewing distance) still gets sewn.
    // (A tolerance of a hundredth of the diagonal: far above the seam weld.)
    let tol = 1.0;
    let opts = MeshOptions::default().with_tolerance(tol);
    let r = mesh_model(&row_with_one_gap(0.3 * tol), &opts).expect("meshes");
    let rep = &r.report;
    assert!(rep.max_deviation <= tol, "deviation {} above tolerance {tol}", rep.max_deviation);
    assert_eq!((rep.free_edges, rep.nonmanifold_edges, rep.inverted_triangles), (0, 0, 0));
    // The row's outer border stays open; wider than the sewing distance, the gap does too.
    let open = |gap: f64| mesh_model(&row_with_one_gap(gap), &opts).expect("meshes").report.boundary_edges;
    assert!(open(1.5 * tol) > r.report.boundary_edges, "a gap of 1.5 tolerances was sewn");
}

/// A gap wider than the sewing distance (0.4 of the tolerance) but within
/// the tolerance is a crack the file has, not one the mesher left: the
/// report names the two faces and the measured width.
#[test]
fn mesh_names_a_gap_wider_than_sewing_and_its_width() {
    let tol = 1.0;
    let r = mesh_model(&row_with_one_gap(0.7 * tol), &MeshOptions::default().with_tolerance(tol)).expect("meshes");
    assert!(r.report.free_edges > 0, "the gap is a crack");
    let gaps: Vec<(usize, usize, f64)> = r
        .report
        .warnings
        .iter()
        .filter_map(|w| match w.kind {
            WarningKind::FacesApart { faces: (a, b), width, .. } => Some((a, b, width)),
            _ => None,
        })
        .collect();
    assert_eq!(gaps.len(), 1, "{:?}", r.report.warnings);
    let (a, b, width) = gaps[0];
    assert_eq!((a, b), (29, 30));
    assert!(width >= 0.7 * tol - 1e-9 && width < tol, "{width}");
    // The text names both faces and the width, rounded as the report shows it.
    let text = r.report.warnings.iter().find(|w| matches!(w.kind, WarningKind::FacesApart { .. })).unwrap().to_string();
    assert!(text.starts_with(&format!("faces 29 and 30: their borders lie {width:.3e} apart")), "{text}");
    // Sewn gaps leave no such warning.
    let sewn = mesh_model(&row_with_one_gap(0.3 * tol), &MeshOptions::default().with_tolerance(tol)).expect("meshes");
    let apart = |w: &Warning| matches!(w.kind, WarningKind::FacesApart { .. });
    assert!(!sewn.report.warnings.iter().any(apart), "{:?}", sewn.report.warnings);
}

/// Three flat faces round a corner that misses: the right face's corner
/// stops `miss` short of the others', leaving a sliver between its top
/// border and the face above.
fn missed_corner(miss: f64) -> Model {
    let quad = |p: [[f64; 2]; 4]| {
        format!(
            r#"{{"surface":{{"degree":[1,1],"knots":[[0,0,1,1],[0,0,1,1]],
            "points":[[[{},{},0],[{},{},0]],[[{},{},0],[{},{},0]]]}}}}"#,
            p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1], p[3][0], p[3][1]
        )
    };
    let faces = [
        quad([[0.0, 0.0], [0.0, 10.0], [10.0, 0.0], [10.0, 10.0]]),
        quad([[10.0, 0.0], [10.0, 10.0 - miss], [20.0, 0.0], [20.0, 10.0]]),
        quad([[0.0, 10.0], [0.0, 20.0], [20.0, 10.0], [20.0, 20.0]]),
    ];
    surfmesh::read_json(format!(r#"{{"faces":[{}]}}"#, faces.join(",")).as_bytes()).expect("reads")
}

#[test]
fn mesh_closes_the_sliver_where_three_corners_miss() {
    // The miss is beyond the sewing distance (0.4 of the tolerance) but
    // within the tolerance: the sliver is closed by one triangle.
    let tol = 0.1;
    let r = mesh_model(&missed_corner(0.7 * tol), &MeshOptions::default().with_tolerance(tol)).expect("meshes");
    check_common("missed corner", &r, tol);
    // A miss far beyond the tolerance stays open.
    let outer = r.report.boundary_edges;
    // Edges at most 3 long: the sliver's sides take more nodes, and what
    // sewing leaves of it has four sides.
    let short = MeshOptions::default().with_tolerance(tol).with_max_edge(Some(3.0));
    let r = mesh_model(&missed_corner(0.7 * tol), &short).expect("meshes");
    check_common("missed corner, short edges", &r, tol);
    let wide = mesh_model(&missed_corner(3.0 * tol), &MeshOptions::default().with_tolerance(tol)).expect("meshes");
    assert!(wide.report.boundary_edges > outer, "a miss of 3 tolerances was closed");
}

/// A quarter of a torus tube (spine radius 20, tube radius 1, a quarter turn
/// each way) trimmed by a slanted quadrilateral: a fillet. The angle limit
/// sets the cells across it, the tolerance or the angle those along it; the
/// CDT of the trimmed band, laid along the grid, must stay near that grid
/// (it fanned across the tube and took 375 triangles at 1e-2, 7.8× the grid).
#[test]
fn mesh_trimmed_fillet_stays_near_the_grid_its_bends_need() {
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
    let (big, small) = (20.0, 1.0);
    let w = FRAC_1_SQRT_2;
    let around = [((1.0, 0.0), 1.0), ((1.0, 1.0), w), ((0.0, 1.0), 1.0)];
    let profile = [((big + small, 0.0), 1.0), ((big + small, small), w), ((big, small), 1.0)];
    let points: Vec<Vec<DVec3>> = around
        .iter()
        .map(|&((cx, cy), _)| profile.iter().map(|&((rho, z), _)| DVec3::new(rho * cx, rho * cy, z)).collect())
        .collect();
    let weights: Vec<Vec<f64>> =
        around.iter().map(|&(_, wa)| profile.iter().map(|&(_, wp)| wa * wp).collect()).collect();
    let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let surface = NurbsSurface::try_new([2, 2], knots.clone(), knots, &points, Some(&weights)).expect("surface");
    let corners = [DVec2::new(0.02, 0.03), DVec2::new(0.97, 0.01), DVec2::new(0.95, 0.98), DVec2::new(0.03, 0.97)];
    let curves = (0..4)
        .map(|i| {
            let (a, b) = (corners[i], corners[(i + 1) % 4]);
            NurbsCurve::try_new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a.extend(0.0), b.extend(0.0)], None).expect("line")
        })
        .collect();
    let model = Model {
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(surface), loops: vec![TrimLoop { curves }] }],
        ..Model::default()
    };
    let torus = |p: DVec3| ((DVec2::new(p.x, p.y).length() - big).hypot(p.z) - small).abs();
    for rel in [1e-2, 3e-3] {
        let options = MeshOptions::default().with_relative_tolerance(rel);
        let r = mesh_model(&model, &options).expect("meshes");
        let rep = &r.report;
        check_common("fillet", &r, rel);
        assert!(exact_deviation(&r.mesh, torus) <= rep.tolerance, "rel {rel}: exact deviation");
        // The grid the bends need: a quarter turn each way at the angle
        // limit, and the spine's chord at the tolerance the mesher aims at.
        let aim = rep.tolerance * options.safety;
        let across = (FRAC_PI_2 / rep.angle).ceil();
        let chord = (8.0 * (big + small) * aim).sqrt();
        let along = (FRAC_PI_2 / rep.angle).max(FRAC_PI_2 * (big + small) / chord).ceil();
        let grid = 2.0 * across * along;
        assert!(
            (rep.triangles as f64) <= 2.0 * grid,
            "rel {rel}: {} triangles where the bends need a grid of {grid}",
            rep.triangles
        );
    }
}

/// A strip folded at right angles along its degree-1 knots (as trj3's
/// zig-zag band is): each flat panel takes a few triangles. A corner on a
/// fold has the normal of one panel only, so a triangle of the other panel
/// was judged to turn 90° and split down to a tenth of the tolerance
/// (trj3's band: 15k triangles, 2,200 of them flat).
#[test]
fn mesh_folded_strip_keeps_its_panels_flat_and_few() {
    let corners = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (8.0, 4.0), (8.0, 8.0)];
    let pts: Vec<Vec<DVec3>> =
        corners.iter().map(|&(x, y)| vec![DVec3::new(x, y, 0.0), DVec3::new(x, y, 1.0)]).collect();
    let ku = vec![0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0];
    let kv = vec![0.0, 0.0, 1.0, 1.0];
    let strip = NurbsSurface::try_new([1, 1], ku, kv, &pts, None).expect("strip");
    let model = Model {
        units: "mm".into(),
        faces: vec![Face { name: None, surface: FaceSurface::Nurbs(strip), loops: vec![] }],
        warnings: vec![],
        tolerance: None,
        bodies: vec![],
        ..Default::default()
    };
    for rel in RELS {
        let r = mesh(&model, rel);
        check_common("folded strip", &r, rel);
        // Four flat panels: two triangles each would do; eight each is slack.
        assert!(r.report.triangles <= 32, "rel {rel}: {} triangles for four flat panels", r.report.triangles);
    }
}

/// A quarter cylinder, its arc along v: clean, or with the arc's knot
/// vector starting on a sliver (0.25 written once rounded and once exactly,
/// three control points rounding the arc's first point, the rounding
/// opposite at the two ends), as a surface split next to its own knot comes
/// out of a reader.
fn quarter_cylinder(sliver: bool) -> Model {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let a = 0.25 - 5e-16;
    let corner = DVec3::new(1.0, 1.0, 0.0);
    let (kv, w) = if sliver {
        (vec![a, a, a, 0.25, 0.25, 0.5, 0.5, 0.5], vec![1.0, 1.0, 1.0, h, 1.0])
    } else {
        (vec![0.25, 0.25, 0.25, 0.5, 0.5, 0.5], vec![1.0, h, 1.0])
    };
    let rows: Vec<Vec<DVec3>> = [(0.0, 1.0), (3.0, -1.0)]
        .iter()
        .map(|&(z, sign)| {
            let arc = if sliver {
                vec![DVec3::X, DVec3::new(1.0 + sign * 4.4e-16, sign * 1e-16, 0.0), DVec3::X, corner, DVec3::Y]
            } else {
                vec![DVec3::X, corner, DVec3::Y]
            };
            arc.iter().map(|p| *p + DVec3::Z * z).collect()
        })
        .collect();
    let weights = vec![w.clone(), w];
    let s = NurbsSurface::try_new([1, 2], vec![0.0, 0.0, 1.0, 1.0], kv, &rows, Some(&weights)).expect("surface");
    Model { faces: vec![Face { name: None, surface: FaceSurface::Nurbs(s), loops: vec![] }], ..Default::default() }
}

/// A sliver knot span is evaluated as the one knot it stands for: its
/// derivatives were the rounding of its control points over 5e-16, the
/// normals along the face's first line turned over where that rounding
/// changes sign, and the grid split the straight direction down to its cap
/// of 20 000 lines.
#[test]
fn mesh_sliver_knot_span_meshes_like_its_clean_twin() {
    for rel in [1e-2, 1e-3] {
        let clean = check_common("clean quarter cylinder", &mesh(&quarter_cylinder(false), rel), rel);
        let r = mesh(&quarter_cylinder(true), rel);
        let rep = &r.report;
        assert!(rep.max_deviation <= rep.tolerance, "{rel}: deviation {} over {}", rep.max_deviation, rep.tolerance);
        assert_eq!(rep.inverted_triangles, 0, "{rel}");
        assert!(
            rep.triangles <= clean + clean / 4,
            "{rel}: {} triangles against {clean} without the sliver",
            rep.triangles
        );
    }
}

/// A grid direction that reaches its cap of lines says so: a strip whose
/// edge limit asks for five times the cap along its length gets a warning
/// naming the face and the direction. (The budget then skips the strip, so
/// that the test does not refine its 40 000 triangles; a speck of a face
/// first keeps the model meshable.)
#[test]
fn mesh_warns_when_a_grid_direction_reaches_its_cap() {
    let square = |o: DVec3, w: f64, h: f64| {
        let pts =
            vec![vec![o, o + DVec3::new(0.0, h, 0.0)], vec![o + DVec3::new(w, 0.0, 0.0), o + DVec3::new(w, h, 0.0)]];
        let s = NurbsSurface::try_new([1, 1], vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0], &pts, None)
            .expect("square");
        Face { name: None, surface: FaceSurface::Nurbs(s), loops: vec![] }
    };
    let speck = square(DVec3::new(5.0, 0.0, 0.0), 5e-6, 5e-6);
    let strip = square(DVec3::ZERO, 1.0, 1e-4);
    let model = Model { faces: vec![speck, strip], ..Default::default() };
    // A tolerance far below the edge limit: sewing then looks at a few of
    // the border's 40 000 nodes at a time, not at thousands.
    let opts = MeshOptions::default().with_relative_tolerance(1e-6).with_max_edge(Some(1e-5)).with_max_triangles(1000);
    let r = mesh_model(&model, &opts).expect("meshes");
    let capped: Vec<&Warning> =
        r.report.warnings.iter().filter(|w| matches!(w.kind, WarningKind::GridCapped { .. })).collect();
    assert_eq!(capped.len(), 1, "{:?}", r.report.warnings);
    assert!(matches!(capped[0].kind, WarningKind::GridCapped { along: "u", .. }), "{:?}", capped[0]);
    assert_eq!(capped[0].face, Some(1));
    assert_eq!(r.report.faces_skipped, 1, "{:?}", r.report.warnings);
}

/// A tube whose wall (0.2) is thinner than the sewing distance at 2e-2
/// and 4e-2, each skin a cylinder split into two halves at one seam: the
/// outer seam's nodes are one with the outer halves', the inner's with the
/// inner halves', and the two pairs lie off each other along the normals.
/// Joined, the seam edges each had four triangles.
#[test]
fn mesh_thin_tube_keeps_its_two_skins_seams_apart() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/thin_tube_halves.json");
    let model = surfmesh::read_json(&std::fs::read(path).unwrap()).unwrap();
    for rel in [2e-2, 4e-2] {
        let rep = mesh(&model, rel).report;
        assert!(rep.max_deviation <= rep.tolerance, "@ {rel}: deviation {} > {}", rep.max_deviation, rep.tolerance);
        let edges = (rep.free_edges, rep.nonmanifold_edges, rep.inverted_triangles);
        assert_eq!(edges, (0, 0, 0), "@ {rel}: cracks, non-manifold edges, inverted triangles");
    }
}

/// Two domes 0.5 apart (a wall thinner than the sewing distance at 1e-2,
/// 0.72) closed by a rim at their equators: their seams run side by side.
/// A seam's inner nodes are no border another face meets, so the seams
/// stay apart; sewn together, every edge along them had four triangles.
#[test]
fn mesh_thin_wall_keeps_the_seams_of_its_two_sides_apart() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/thin_dome.json");
    let model = surfmesh::read_json(&std::fs::read(path).unwrap()).unwrap();
    for rel in [1e-2, 1e-3] {
        let rep = mesh(&model, rel).report;
        assert!(rep.max_deviation <= rep.tolerance, "@ {rel}: deviation {} > {}", rep.max_deviation, rep.tolerance);
        let edges = (rep.free_edges, rep.boundary_edges, rep.nonmanifold_edges, rep.inverted_triangles);
        assert_eq!(edges, (0, 0, 0, 0), "@ {rel}: cracks, open, non-manifold edges, inverted triangles");
    }
}
