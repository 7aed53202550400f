//! Quality meshing for analysis (paper 003) and the FEA exports (Gmsh MSH 4.1, UNV).

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use surfmesh::{
    measure_mesh, mesh_model, read_json, read_msh, weld_mesh, write_msh, write_unv, Error, FaceRange, MeasureOptions,
    Mesh, MeshMode, MeshOptions, MeshResult, Model, QualityMethod, QualityOptions, UNV_SHELL_TRIANGLE,
};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn shape(name: &str) -> Model {
    read_json(&std::fs::read(data(name)).unwrap()).unwrap()
}

/// A file of the test corpus (`tests/corpus`), read.
fn corpus(name: &str) -> Model {
    crate::corpus_files::corpus_model(name)
}

fn quality(q: QualityOptions) -> MeshOptions {
    MeshOptions::default().with_mode(MeshMode::Quality).with_quality(q)
}

/// Meshes in quality mode and checks issue 9's acceptance: at least 99% of
/// triangles with a smallest angle of 25° or more, 90% of the edges between
/// 0.7 H and 1.4 H, no crack, no inverted triangle, no face skipped, and a
/// deviation that is reported and small against H (measured again by the
/// project's yardstick). `closed`: no boundary edge at all.
fn accept(name: &str, model: &Model, q: QualityOptions, closed: bool) -> MeshResult {
    let r = mesh_model(model, &quality(q)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let rep = &r.report;
    let qr = rep.quality.as_ref().unwrap();
    let m = measure_mesh(model, &r.mesh, &MeasureOptions::default());
    eprintln!(
        "{name}: H {:.4} tris {} good {:.4} band {:.4} min {:.1}° free {} boundary {} dev {:.3e} (measured {:.3e}, \
         coverage {:.3e})",
        qr.size,
        rep.triangles,
        qr.good_angle_fraction,
        qr.edge_band_fraction,
        rep.min_angle_deg,
        m.free_edges,
        m.boundary_edges,
        rep.max_deviation,
        m.max_deviation,
        m.coverage
    );
    assert_eq!(rep.faces_skipped, 0, "{name}: {:?}", rep.warnings);
    assert!(qr.good_angle_fraction >= 0.99, "{name}: {} of triangles reach 25°", qr.good_angle_fraction);
    assert!(qr.edge_band_fraction >= 0.90, "{name}: {} of edges in the band", qr.edge_band_fraction);
    assert_eq!((rep.free_edges, m.free_edges), (0, 0), "{name}: cracks");
    assert_eq!(rep.inverted_triangles, 0, "{name}");
    // (Misoriented edges are left out: faces keep their surfaces' normals, as
    // in fast mode, and some files' neighbouring surfaces face opposite ways.)
    assert_eq!(m.nonmanifold_edges, 0, "{name}");
    if closed {
        assert_eq!((rep.boundary_edges, m.boundary_edges), (0, 0), "{name}: a closed solid has no boundary edge");
    }
    // The deviation reported agrees with the yardstick's.
    assert!(rep.max_deviation.is_finite(), "{name}");
    let diff = (m.max_deviation - rep.max_deviation).abs();
    assert!(diff <= 0.05 * m.max_deviation + 1e-9 * m.diagonal, "{name}: {} vs {}", rep.max_deviation, m.max_deviation);
    // No hole: every sample of the faces (inside and on the trim curves) lies
    // about as near the mesh as the mesh lies to the faces, give or take the
    // chords of curved trims (a missing triangle would leave a point 0.29 H away).
    assert!(m.coverage <= 2.0 * m.max_deviation + 0.05 * qr.size, "{name}: coverage {}", m.coverage);
    r
}

#[test]
fn quality_plane_gets_equilateral_triangles_of_size_h() {
    let model = shape("plane.json");
    let r = accept("plane", &model, QualityOptions::default().with_size(1.0), false);
    let qr = r.report.quality.unwrap();
    assert_eq!(qr.size, 1.0);
    assert_eq!(qr.faces_looping, 1);
    // Each 10 mm side in ceil(10 / 1) = 10 equal parts.
    assert_eq!(r.report.boundary_edges, 40);
    // An equilateral triangle of side 1 has area sqrt(3)/4: about 100 / 0.433 triangles.
    let n = r.report.triangles as f64;
    assert!((180.0..=280.0).contains(&n), "{n} triangles");
    assert!(qr.edge_ratio_mean > 0.9 && qr.edge_ratio_mean < 1.15, "mean edge {}", qr.edge_ratio_mean);
    assert!(r.report.max_deviation < 1e-9);
}

#[test]
fn quality_faces_meet_node_to_node_where_one_side_is_split() {
    // One face's side is two curves, the neighbour's one curve of uneven
    // speed; the shared edge must be divided alike from both sides.
    let model = shape("quality_split_edge.json");
    let r = mesh_model(&model, &quality(QualityOptions::default().with_size(1.0))).unwrap();
    let rep = &r.report;
    assert_eq!((rep.faces_skipped, rep.free_edges, rep.nonmanifold_edges), (0, 0, 0), "{:?}", rep.warnings);
    // Outer border of the 20 x 10 rectangle in ceil(10 / 1) = 10 parts a side.
    assert_eq!(rep.boundary_edges, 60);
    assert!(rep.quality.as_ref().unwrap().good_angle_fraction >= 0.99);
    let welded = weld_mesh(&r.mesh, 1e-9);
    // Nodes on the shared line x = 10: 4 parts below the split point, 6 above.
    let mut ys: Vec<f64> = welded.positions.iter().filter(|p| (p.x - 10.0).abs() < 1e-9).map(|p| p.y).collect();
    ys.sort_by(f64::total_cmp);
    assert_eq!(ys.len(), 11, "{ys:?}");
    for (k, y) in ys.iter().enumerate() {
        assert!((y - k as f64).abs() < 1e-6, "{ys:?}");
    }
}

#[test]
fn quality_closed_solids_stay_closed_with_every_method() {
    let models = [
        ("torus.json", shape("torus.json"), 0.08),
        ("cube_10x10_inventor.igs", corpus("cube_10x10_inventor.igs"), 0.08),
    ];
    for (name, model, rel) in &models {
        for method in [QualityMethod::Looping, QualityMethod::Delaunay, QualityMethod::Best] {
            let q = QualityOptions::default().with_relative_size(*rel).with_method(method);
            let r = accept(&format!("{name} {method:?}"), model, q, true);
            let qr = r.report.quality.unwrap();
            match method {
                QualityMethod::Looping => assert_eq!(qr.faces_delaunay, 0),
                QualityMethod::Delaunay => assert_eq!(qr.faces_looping, 0),
                _ => assert_eq!(qr.faces_looping + qr.faces_delaunay, model.faces.len()),
            }
        }
    }
}

#[test]
fn quality_curved_and_trimmed_faces_meet_the_acceptance() {
    // (trimmed_holes.json has a sharp outer corner: at coarser sizes its few
    // triangles there are more than 1% of all.)
    for (name, rel) in
        [("cylinder.json", 0.05), ("freeform.json", 0.05), ("trimmed_holes.json", 0.03), ("sphere.json", 0.05)]
    {
        accept(name, &shape(name), QualityOptions::default().with_relative_size(rel), name == "sphere.json");
    }
    for name in ["OCC26138_Torus.igs", "OCC8842_cylinder_CATIA.igs", "PRO20358-W10.igs"] {
        let closed = name == "OCC8842_cylinder_CATIA.igs";
        accept(name, &corpus(name), QualityOptions::default().with_relative_size(0.05), closed);
    }
}

#[test]
fn quality_size_far_too_small_is_a_clear_error_before_any_work() {
    let model = shape("torus.json");
    let e = mesh_model(&model, &quality(QualityOptions::default().with_size(1e-4))).unwrap_err();
    assert!(matches!(e, Error::Limit(_)), "{e}");
    let text = e.to_string();
    assert!(text.contains("choose a larger size") && text.contains("over the limit of 2000000"), "{text}");
    let e = mesh_model(&model, &quality(QualityOptions::default().with_size(0.0))).unwrap_err();
    assert!(e.to_string().contains("--size"), "{e}");
    let small = QualityOptions::default().with_relative_size(0.01).with_max_triangles(500);
    assert!(matches!(mesh_model(&model, &quality(small)), Err(Error::Limit(_))));
}

#[test]
fn quality_mesh_exports_load_back_as_one_connected_closed_surface() {
    let model = shape("torus.json");
    let r = mesh_model(&model, &quality(QualityOptions::default().with_relative_size(0.05))).unwrap();
    let back = read_msh(&write_msh(&r.mesh)).unwrap();
    assert_eq!(back.triangle_count(), r.mesh.triangle_count());
    // Shared nodes: a closed torus has Euler characteristic V - E + F = 0.
    let mut edges = std::collections::HashSet::new();
    for t in back.indices.chunks(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let euler = back.positions.len() as i64 - edges.len() as i64 + back.triangle_count() as i64;
    assert_eq!(euler, 0, "V {} E {} F {}", back.positions.len(), edges.len(), back.triangle_count());
    // Every edge has two triangles.
    let unv = String::from_utf8(write_unv(&r.mesh)).unwrap();
    let nodes = unv.lines().skip(2).take_while(|l| *l != "    -1").count() / 2;
    assert_eq!(nodes, back.positions.len());
}

#[test]
fn cli_quality_mode_writes_msh_and_the_quality_report() {
    let dir = std::env::temp_dir().join(format!("surfmesh-it-{}-quality-cli", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (out, rep) = (dir.join("plane.msh"), dir.join("report.json"));
    let status = Command::new(env!("CARGO_BIN_EXE_surfmesh"))
        .args(["mesh", data("plane.json").to_str().unwrap(), "--mode", "quality", "--size", "2", "--method", "best"])
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap();
    assert_eq!(report["quality"]["size"], 2.0);
    let mesh = read_msh(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(mesh.triangle_count() as u64, report["triangles"].as_u64().unwrap());
    // ceil(10 / 2) = 5 nodes per side: 20 on the border, all shared.
    assert!(mesh.positions.iter().filter(|p| p.x == 0.0 || p.x == 10.0 || p.y == 0.0 || p.y == 10.0).count() == 20);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two faces of a bent strip, each owning copies of the border vertices they
/// share (as the mesher writes them), one extra vertex no triangle uses.
fn two_faces() -> Mesh {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    Mesh {
        positions: vec![
            // face 0: unit square in z = 0
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, 1.0, 0.0),
            // face 1: its copy of the shared border x = 1, then the far side
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(2.0, 0.0, -12.5),
            p(2.0, 1.0, 1e-120),
            // unused
            p(7.0, 7.0, 7.0),
        ],
        normals: vec![DVec3::Z; 9],
        indices: vec![0, 1, 2, 0, 2, 3, 4, 6, 7, 4, 7, 5],
        face_ranges: vec![FaceRange { first: 0, count: 2 }, FaceRange { first: 2, count: 2 }],
    }
}

#[test]
fn msh_round_trip_shares_border_nodes_and_keeps_faces() {
    let mesh = two_faces();
    let bytes = write_msh(&mesh);
    let text = String::from_utf8(bytes.clone()).unwrap();
    assert!(text.starts_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"));
    let back = read_msh(&bytes).unwrap();
    // 8 used vertices, 2 shared: 6 nodes.
    assert_eq!(back.positions.len(), 6);
    assert_eq!(back.triangle_count(), 4);
    assert_eq!(back.face_ranges, vec![FaceRange { first: 0, count: 2 }, FaceRange { first: 2, count: 2 }]);
    for t in 0..4 {
        assert_eq!(back.triangle(t), mesh.triangle(t), "triangle {t}");
    }
    // The shared border is one pair of nodes used by both faces.
    let used = |f: usize| -> Vec<u32> { back.indices[6 * f..6 * f + 6].to_vec() };
    let common = used(0).iter().filter(|v| used(1).contains(v)).count();
    assert!(common >= 2, "faces share {common} node uses");
}

#[test]
fn msh_sections_count_what_they_hold() {
    let text = String::from_utf8(write_msh(&two_faces())).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let after = |marker: &str| lines[lines.iter().position(|l| *l == marker).unwrap() + 1];
    assert_eq!(after("$Entities"), "0 0 2 0");
    // Two node blocks (one per face), 6 nodes tagged 1..6.
    assert_eq!(after("$Nodes"), "2 6 1 6");
    assert_eq!(after("$Elements"), "2 4 1 4");
    // The first element block: surface 1, type 2 (3-node triangle), 2 elements.
    let e = lines.iter().position(|l| *l == "$Elements").unwrap();
    assert_eq!(lines[e + 2], "2 1 2 2");
    assert_eq!(lines[e + 3].split(' ').count(), 4);
    assert_eq!(lines.last(), Some(&"$EndElements"));
}

#[test]
fn msh_reader_names_the_line_of_bad_input() {
    let err = |text: &str| read_msh(text.as_bytes()).unwrap_err().to_string();
    assert!(err("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").contains("MSH line 2: version 2.2"));
    assert!(err("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n").contains("binary"));
    let head = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
    let nodes = "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n";
    let missing = format!("{head}{nodes}$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 9\n$EndElements\n");
    assert!(err(&missing).contains("MSH line 17: node tag 9 is not defined"), "{}", err(&missing));
    let tet = format!("{head}{nodes}$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 3\n$EndElements\n");
    assert!(err(&tet).contains("element type 4 is not read"));
    let huge = format!("{head}$Nodes\n1 99999999 1 99999999\n$EndNodes\n");
    assert!(err(&huge).contains("more than the file holds"));
    let short = format!("{head}$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n");
    assert!(err(&short).contains("the file ends"));
    let ok = format!("{head}{nodes}$Elements\n2 2 1 2\n1 1 15 1\n1 1\n2 1 2 1\n2 1 2 3\n$EndElements\n");
    let m = read_msh(ok.as_bytes()).unwrap();
    assert_eq!((m.positions.len(), m.indices.clone()), (3, vec![0, 1, 2]));
    assert!(matches!(read_msh(b"hello"), Err(Error::MeshFile { .. })));
}

/// One fixed-width field of a UNV line.
fn field(line: &str, start: usize, width: usize) -> &str {
    &line[start..start + width]
}

/// A `1PD25.16` field as a number, after checking its shape (Fortran drops
/// the `D` before a three-digit exponent).
fn d25(text: &str) -> f64 {
    let t = text.trim_start();
    let (mantissa, exp) = match t.split_once('D') {
        Some(parts) => parts,
        None => {
            let cut = t.rfind(['+', '-']).filter(|&i| i > 1).unwrap_or_else(|| panic!("no exponent in '{text}'"));
            assert_eq!(t.len() - cut, 4, "three-digit exponent in '{text}'");
            (&t[..cut], &t[cut..])
        }
    };
    let digits = mantissa.trim_start_matches('-');
    assert_eq!(digits.len(), 18, "one digit, point, 16 decimals in '{text}'");
    assert_eq!(&digits[1..2], ".");
    assert!((3..=4).contains(&exp.len()) && (exp.starts_with('+') || exp.starts_with('-')), "exponent of '{text}'");
    format!("{mantissa}e{exp}").parse().unwrap()
}

#[test]
fn unv_matches_the_documented_layout_field_by_field() {
    let mesh = two_faces();
    let text = String::from_utf8(write_unv(&mesh)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    // Dataset 2411: 6 nodes, two records each.
    assert_eq!(lines[0], "    -1");
    assert_eq!(lines[1], "  2411");
    let mut nodes = Vec::new();
    for k in 0..6 {
        let r1 = lines[2 + 2 * k];
        let r2 = lines[3 + 2 * k];
        assert_eq!(r1.len(), 40, "4I10: '{r1}'");
        assert_eq!(field(r1, 0, 10).trim().parse::<usize>().unwrap(), k + 1, "node label");
        assert_eq!(field(r1, 10, 10).trim(), "1", "export coordinate system");
        assert_eq!(field(r1, 20, 10).trim(), "1", "displacement coordinate system");
        assert_eq!(field(r1, 30, 10).trim(), "11", "colour");
        assert_eq!(r2.len(), 75, "3D25.16: '{r2}'");
        nodes.push(DVec3::new(d25(field(r2, 0, 25)), d25(field(r2, 25, 25)), d25(field(r2, 50, 25))));
    }
    assert_eq!(lines[14], "    -1");
    assert_eq!(lines[15], "    -1");
    assert_eq!(lines[16], "  2412");
    // Every used vertex is a node, to the last digit written.
    for v in &mesh.positions[..8] {
        assert!(nodes.iter().any(|n| n.distance(*v) <= 1e-15 * v.length().max(1.0)), "vertex {v} missing");
    }
    assert!(nodes.iter().any(|n| n.z == -12.5));
    assert!(text.contains("  -1.2500000000000000D+01"), "Fortran's 1PD25.16 of -12.5");
    assert!(nodes.iter().any(|n| (n.z - 1e-120).abs() < 1e-135), "three-digit exponent read back");
    // Dataset 2412: 4 triangles, two records each.
    for k in 0..4 {
        let r1 = lines[17 + 2 * k];
        let r2 = lines[18 + 2 * k];
        assert_eq!(r1.len(), 60, "6I10: '{r1}'");
        let f: Vec<u32> = (0..6).map(|i| field(r1, 10 * i, 10).trim().parse().unwrap()).collect();
        assert_eq!(f[0], k as u32 + 1, "element label");
        assert_eq!(f[1], UNV_SHELL_TRIANGLE);
        assert_eq!(f[2], if k < 2 { 1 } else { 2 }, "physical property table = face + 1");
        assert_eq!((f[3], f[4], f[5]), (1, 7, 3), "material, colour, node count");
        assert_eq!(r2.len(), 30, "8I10 with three labels: '{r2}'");
        let corners: Vec<DVec3> =
            (0..3).map(|i| nodes[field(r2, 10 * i, 10).trim().parse::<usize>().unwrap() - 1]).collect();
        assert_eq!(corners, mesh.triangle(k).to_vec(), "element {k}");
    }
    assert_eq!(lines[25], "    -1");
    assert_eq!(lines.len(), 26);
}
