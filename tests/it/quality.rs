//! Quality meshing for analysis (paper 003) and the FEA exports (Gmsh MSH 4.1, UNV).

use glam::DVec3;
use surfmesh::{read_msh, write_msh, write_unv, Error, FaceRange, Mesh, UNV_SHELL_TRIANGLE};

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
