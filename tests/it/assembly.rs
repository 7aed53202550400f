//! Assemblies: the STEP product tree as the file gives it, each distinct
//! part meshed once and placed by its instances' matrices, and the edge
//! polylines along the faces' borders.

use std::collections::{HashMap, HashSet};

use glam::{DAffine3, DMat3, DVec3};
use surfmesh::{
    edge_lines, flatten, measure_mesh, mesh_instanced, mesh_model, read_model, read_step_parts, Assembly, EdgeLines,
    FaceRange, Format, MeasureOptions, Mesh, MeshOptions, Units,
};

use crate::corpus_files::{corpus_bytes, corpus_names};

/// A placement as STEP's `AXIS2_PLACEMENT_3D` gives it: origin, axis (z) and ref direction (x).
fn placement(origin: [f64; 3], z: [f64; 3], x: [f64; 3]) -> DAffine3 {
    let (z, x) = (DVec3::from(z), DVec3::from(x));
    DAffine3 { matrix3: DMat3::from_cols(x, z.cross(x), z), translation: DVec3::from(origin) }
}

fn close(a: &DAffine3, b: &DAffine3) -> bool {
    a.to_cols_array().iter().zip(b.to_cols_array()).all(|(p, q)| (p - q).abs() <= 1e-9)
}

/// The node reached from the root by a path of occurrence names.
fn node_at(a: &Assembly, path: &[&str]) -> usize {
    let mut at = 0;
    for name in path {
        at = *a.nodes[at]
            .children
            .iter()
            .find(|&&c| a.nodes[c].occurrence.as_deref() == Some(*name))
            .unwrap_or_else(|| panic!("no child {name} under {:?}", a.nodes[at].name));
    }
    at
}

/// as1-oc-214.stp's product structure, read off the file by hand: the
/// `NEXT_ASSEMBLY_USAGE_OCCURRENCE`s (occurrence name, parent, child), the
/// products' names and the `AXIS2_PLACEMENT_3D` each
/// `ITEM_DEFINED_TRANSFORMATION` maps the child's origin onto.
#[test]
fn the_as1_tree_has_the_files_names_and_placements() {
    let s = read_step_parts(&corpus_bytes("as1-oc-214.stp")).unwrap();
    let a = &s.assembly;
    assert_eq!(a.nodes[0].name, "as1");
    assert_eq!(a.nodes[0].matrix, DAffine3::IDENTITY);
    let kids: HashSet<&str> = a.nodes[0].children.iter().filter_map(|&c| a.nodes[c].occurrence.as_deref()).collect();
    let want: HashSet<&str> = ["rod-assembly_1", "l-bracket-assembly_1", "plate_1", "l-bracket-assembly_2"].into();
    assert_eq!(kids, want);
    let id = [0.0, 0.0, 1.0];
    let ex = [1.0, 0.0, 0.0];
    let cases: [(&[&str], &str, DAffine3); 11] = [
        (&["rod-assembly_1"], "rod-assembly", placement([-10.0, 75.0, 60.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0])),
        (&["rod-assembly_1", "nut_1"], "nut", placement([-10.0, -7.5, 185.0], id, ex)),
        (&["rod-assembly_1", "nut_2"], "nut", placement([-10.0, -7.5, 12.0], id, ex)),
        (&["rod-assembly_1", "rod_1"], "rod", DAffine3::IDENTITY),
        (&["l-bracket-assembly_1"], "l-bracket-assembly", placement([5.0, 125.0, 20.0], id, ex)),
        (&["l-bracket-assembly_1", "nut-bolt-assembly_1"], "nut-bolt-assembly", placement([27.5, -40.0, 0.0], id, ex)),
        (
            &["l-bracket-assembly_1", "nut-bolt-assembly_2"],
            "nut-bolt-assembly",
            placement([50.0, -52.99038106, 0.0], id, ex),
        ),
        (
            &["l-bracket-assembly_2", "nut-bolt-assembly_3"],
            "nut-bolt-assembly",
            placement([50.0, -27.00961894, 0.0], id, ex),
        ),
        (
            &["l-bracket-assembly_1", "nut-bolt-assembly_1", "bolt_1"],
            "bolt",
            placement([-7.5, -10.0, 13.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]),
        ),
        (
            &["l-bracket-assembly_2", "nut-bolt-assembly_1", "nut_3"],
            "nut",
            placement([2.5, -17.5, -20.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]),
        ),
        (&["l-bracket-assembly_2"], "l-bracket-assembly", placement([175.0, 25.0, 20.0], id, [-1.0, 0.0, 0.0])),
    ];
    for (path, name, matrix) in cases {
        let n = &a.nodes[node_at(a, path)];
        assert_eq!(n.name, name, "{path:?}");
        assert!(close(&n.matrix, &matrix), "{path:?}: {:?} is not {:?}", n.matrix, matrix);
    }
    // Every instance's matrix is the product of the matrices down to its node.
    let mut parent = vec![usize::MAX; a.nodes.len()];
    for (i, n) in a.nodes.iter().enumerate() {
        for &c in &n.children {
            parent[c] = i;
        }
    }
    let mut names: HashMap<String, usize> = HashMap::new();
    for (k, inst) in a.instances.iter().enumerate() {
        let (mut m, mut at) = (DAffine3::IDENTITY, inst.node);
        while at != usize::MAX {
            m = a.nodes[at].matrix * m;
            at = parent[at];
        }
        assert!(close(&m, &inst.matrix), "instance {k}");
        assert!(a.nodes[inst.node].instances.contains(&k));
        *names.entry(a.nodes[inst.node].name.clone()).or_default() += 1;
    }
    // nut: 2 in the rod assembly, 1 in each of 3 nut-bolt assemblies of each of 2 brackets.
    let want: HashMap<String, usize> =
        [("nut", 8), ("bolt", 6), ("l-bracket", 2), ("rod", 1), ("plate", 1)].map(|(n, c)| (n.into(), c)).into();
    assert_eq!(names, want);
    // Copies of one product share a shape, and different products do not.
    let mut shape_names: HashMap<usize, HashSet<String>> = HashMap::new();
    for inst in &a.instances {
        shape_names.entry(inst.shape).or_default().insert(a.nodes[inst.node].name.clone());
    }
    assert_eq!(shape_names.len(), 5);
    assert!(shape_names.values().all(|n| n.len() == 1));
    assert_eq!(a.face_instances, s.face_parts);
}

/// Faces of one instance of each product, from the reader's part numbering.
fn distinct_faces(s: &surfmesh::StepModel) -> usize {
    let mut per_instance: HashMap<u32, usize> = HashMap::new();
    for &k in &s.face_parts {
        *per_instance.entry(k).or_default() += 1;
    }
    let mut per_name: HashMap<&str, usize> = HashMap::new();
    for (k, n) in per_instance {
        let old = per_name.insert(&s.parts[k as usize], n);
        assert!(old.is_none_or(|o| o == n), "two instances of {} differ", s.parts[k as usize]);
    }
    per_name.values().sum()
}

#[test]
fn each_distinct_part_of_as1_is_meshed_once_and_the_instances_cover_the_file() {
    let s = read_step_parts(&corpus_bytes("as1-oc-214.stp")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(1e-2);
    let mut calls = 0usize;
    let mut totals: HashSet<usize> = HashSet::new();
    let mut last = 0;
    let mut progress = |done: usize, total: usize| {
        calls += 1;
        totals.insert(total);
        last = done;
        true
    };
    let r = mesh_instanced(&s.model, &s.assembly, &options, Units::File, &mut progress).unwrap();
    let distinct = distinct_faces(&s);
    let all = s.model.faces.len() + s.model.tessellated.len();
    // The five products' faces, each once: far fewer than the file places.
    assert_eq!(totals, [distinct].into());
    assert_eq!((calls, last, r.faces_meshed), (distinct, distinct, distinct));
    assert!(3 * distinct < all, "{distinct} of {all}");
    assert_eq!(r.parts.len(), 5);
    assert_eq!(r.instances.len(), 18);
    let part_faces: usize = r.parts.iter().map(|p| p.mesh.face_ranges.len()).sum();
    assert_eq!(part_faces, distinct);
    // The report is the whole model's, as the merged mesh has it.
    let flat = flatten(&r, &s.assembly);
    assert_eq!(flat.face_ranges.len(), all);
    assert_eq!(r.report.faces, all);
    assert_eq!(r.report.triangles, flat.triangle_count());
    assert_eq!(r.report.vertices, flat.positions.len());
    let per_part: usize = r.parts.iter().map(|p| p.instances * p.mesh.triangle_count()).sum();
    assert_eq!(per_part, flat.triangle_count());
    assert_eq!((r.report.free_edges, r.report.nonmanifold_edges, r.report.inverted_triangles), (0, 0, 0));
    // Measured against every placed face of the file: within the tolerance,
    // and no exact sample farther than it from the mesh (every instance is there).
    let m = measure_mesh(&s.model, &flat, &MeasureOptions::default().with_tolerance(r.report.tolerance));
    assert!(m.max_deviation <= r.report.tolerance, "{} > {}", m.max_deviation, r.report.tolerance);
    assert_eq!(m.uncovered_samples, 0, "coverage {}", m.coverage);
    // Meshing every placement as the file has it gives as many triangles.
    let direct = mesh_model(&s.model, &options).unwrap();
    let ratio = direct.report.triangles as f64 / flat.triangle_count() as f64;
    assert!(
        (0.9..=1.1).contains(&ratio),
        "direct {} against instanced {}",
        direct.report.triangles,
        flat.triangle_count()
    );
}

/// Segments of a mesh's face borders: triangle edges used once within their
/// face, vertices of equal position taken as one.
fn border_segments(mesh: &Mesh) -> Vec<([u64; 3], [u64; 3])> {
    let key = |p: DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut out = Vec::new();
    for r in &mesh.face_ranges {
        let mut uses: HashMap<([u64; 3], [u64; 3]), usize> = HashMap::new();
        for t in r.first..r.first + r.count {
            let p = mesh.triangle(t as usize);
            for k in 0..3 {
                let (a, b) = (key(p[k]), key(p[(k + 1) % 3]));
                if a != b {
                    *uses.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
                }
            }
        }
        out.extend(uses.into_iter().filter(|(_, n)| *n == 1).map(|(e, _)| e));
    }
    out
}

/// Every polyline point is a mesh vertex, and every border segment of every
/// face is a step of some polyline.
fn check_lines(name: &str, mesh: &Mesh, lines: &EdgeLines) {
    let key = |p: DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let vertices: HashSet<[u64; 3]> = mesh.positions.iter().map(|&p| key(p)).collect();
    let mut steps: HashSet<([u64; 3], [u64; 3])> = HashSet::new();
    for &(first, count) in &lines.ranges {
        assert!(count >= 2, "{name}: a line of {count} points");
        let pts = &lines.points[first as usize..(first + count) as usize];
        for p in pts {
            assert!(vertices.contains(&key(*p)), "{name}: line point {p} is not a vertex");
        }
        for w in pts.windows(2) {
            let (a, b) = (key(w[0]), key(w[1]));
            steps.insert(if a < b { (a, b) } else { (b, a) });
        }
    }
    let borders = border_segments(mesh);
    let missing = borders.iter().filter(|e| !steps.contains(e)).count();
    assert_eq!(missing, 0, "{name}: {missing} of {} border segments on no line", borders.len());
}

#[test]
fn edge_lines_run_through_the_mesh_border_vertices_on_the_corpus() {
    let mut checked = 0;
    for name in corpus_names(&["igs", "iges", "stp", "step"]) {
        let bytes = corpus_bytes(&name);
        let format = Format::detect(&bytes).unwrap();
        let Ok(model) = read_model(&bytes, format) else { continue };
        // Coarse: the borders are what is checked, and there are as many kinds of them.
        let options = MeshOptions::default().with_relative_tolerance(2e-2);
        let Ok(r) = mesh_model(&model, &options) else { continue };
        let lines = edge_lines(&r.mesh);
        check_lines(&name, &r.mesh, &lines);
        checked += 1;
    }
    assert!(checked >= 25, "{checked} corpus files meshed");
}

#[test]
fn edge_lines_of_the_as1_parts_placed_are_the_flattened_meshs_borders() {
    let s = read_step_parts(&corpus_bytes("as1-oc-214.stp")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(1e-2);
    let r = mesh_instanced(&s.model, &s.assembly, &options, Units::File, &mut |_, _| true).unwrap();
    for (p, part) in r.parts.iter().enumerate() {
        check_lines(&format!("part {p}"), &part.mesh, &edge_lines(&part.mesh));
    }
}

/// The mesh with its faces in reverse order, as another mesher might number
/// them: each face's triangles kept together, the ranges renumbered.
fn faces_reversed(mesh: &Mesh) -> Mesh {
    let mut out = Mesh { positions: mesh.positions.clone(), ..Mesh::default() };
    for r in mesh.face_ranges.iter().rev() {
        let first = out.indices.len() as u32 / 3;
        let (a, b) = (3 * r.first as usize, 3 * (r.first + r.count) as usize);
        out.indices.extend_from_slice(&mesh.indices[a..b]);
        out.face_ranges.push(FaceRange { first, count: r.count });
    }
    out
}

#[test]
fn the_yardstick_counts_edges_per_body_where_two_parts_touch() {
    // Two blocks of one part, the second stacked on the first: the top of
    // one lies on the bottom of the other, border on border.
    let bytes = include_bytes!("../data/step_touching_blocks.stp");
    let mut model = read_model(bytes, Format::Step).unwrap();
    let bodies: HashSet<u32> = model.bodies.iter().copied().collect();
    assert_eq!((model.faces.len(), bodies.len()), (12, 2));
    let r = mesh_model(&model, &MeshOptions::default()).unwrap();
    assert_eq!((r.report.free_edges, r.report.nonmanifold_edges), (0, 0));
    let options = MeasureOptions::default().with_tolerance(r.report.tolerance);
    // In the mesher's own face order and in another, the same count as
    // the mesher's report: no edge shared across the contact.
    for mesh in [r.mesh.clone(), faces_reversed(&r.mesh)] {
        let m = measure_mesh(&model, &mesh, &options);
        assert_eq!((m.free_edges, m.nonmanifold_edges, m.boundary_edges), (0, 0, 0));
        assert!(m.max_deviation <= r.report.tolerance);
    }
    // Welded as one body, the contact's borders are edges of four triangles.
    model.bodies.clear();
    let m = measure_mesh(&model, &r.mesh, &options);
    assert!(m.nonmanifold_edges >= 4, "{} non-manifold edges", m.nonmanifold_edges);
}

/// as1's parts beside a plate a thousand times their size, as another body:
/// at a hundredth of the whole, the tolerance (about 4 m) is far wider
/// than a nut (15 mm across). Each small body is sewn, welded and its holes
/// closed at distances from its own size, not the plate's: the model's
/// distances took a nut's rings for gaps and sewed them into one another
/// (non-manifold edges and cracks, as in an assembly of a motor and bolts).
#[test]
fn small_parts_beside_a_large_one_are_sewn_at_their_own_scale() {
    let mut model = read_model(&corpus_bytes("as1-oc-214.stp"), Format::Step).unwrap();
    let plate = read_model(include_bytes!("../data/plate_far.json"), Format::Json).unwrap();
    let next = model.bodies.iter().copied().max().unwrap() + 1;
    assert_eq!(model.bodies.len(), model.faces.len());
    model.faces.extend(plate.faces);
    model.bodies.push(next);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-2)).unwrap();
    assert!(r.report.tolerance > 1000.0, "tolerance {}", r.report.tolerance);
    assert_eq!((r.report.free_edges, r.report.nonmanifold_edges), (0, 0), "{:?}", r.report.warnings);
    assert!(r.report.max_deviation <= r.report.tolerance);
}
