//! STEP AP242 tessellated faces: small files written for these tests
//! (tests/data/step_tess_*.stp) check each entity form against triangles
//! worked out by hand from the file, the report's count of faces without an
//! exact surface, malformed lists, and the sewing of a tessellated face to
//! an exact one; two real files (`bug33100_window.step`, `bug33638.stp`,
//! from tests/corpus or ../shared/corpus-wide) mesh through the CLI path.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use crate::corpus_files::corpus_bytes;
use surfmesh::{edge_counts, mesh_model, read_step_parts, Mesh, MeshOptions, MeshResult, StepModel, WarningKind};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("data").join(name)).unwrap()
}

fn read(name: &str) -> StepModel {
    read_step_parts(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn mesh(s: &StepModel, options: &MeshOptions) -> MeshResult {
    mesh_model(&s.model, options).unwrap()
}

/// Face `f`'s triangles as corner positions.
fn triangles(mesh: &Mesh, f: usize) -> Vec<[DVec3; 3]> {
    let r = mesh.face_ranges[f];
    (r.first as usize..(r.first + r.count) as usize).map(|t| mesh.triangle(t)).collect()
}

/// Twice the area vector of a triangle: its facet normal times twice its area.
fn area2(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0])
}

fn p(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// A triangle as its corners from the lowest (x, y, z) on, keeping their turn.
fn canonical(t: [DVec3; 3]) -> [DVec3; 3] {
    let lt = |a: DVec3, b: DVec3| (a.x, a.y, a.z).partial_cmp(&(b.x, b.y, b.z)) == Some(std::cmp::Ordering::Less);
    let k = (0..3).fold(0, |k, i| if lt(t[i], t[k]) { i } else { k });
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

fn sorted(mut ts: Vec<[DVec3; 3]>) -> Vec<[DVec3; 3]> {
    ts = ts.into_iter().map(canonical).collect();
    ts.sort_by(|a, b| {
        let key = |t: &[DVec3; 3]| t.iter().flat_map(|p| [p.x, p.y, p.z]).collect::<Vec<f64>>();
        key(a).partial_cmp(&key(b)).unwrap()
    });
    ts
}

/// The output normal at the vertex of face `f` placed at `at`.
fn normal_at(mesh: &Mesh, f: usize, at: DVec3) -> DVec3 {
    let r = mesh.face_ranges[f];
    let idx = &mesh.indices[3 * r.first as usize..3 * (r.first + r.count) as usize];
    let v = idx.iter().find(|&&v| mesh.positions[v as usize] == at).unwrap_or_else(|| panic!("no vertex at {at}"));
    mesh.normals[*v as usize]
}

/// Edges with one triangle after joining vertices at the same place.
fn open_edges(mesh: &Mesh) -> Vec<(DVec3, DVec3)> {
    let key = |p: DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut ids: HashMap<[u64; 3], usize> = HashMap::new();
    let mut place = Vec::new();
    let id: Vec<usize> = mesh
        .positions
        .iter()
        .map(|&q| {
            *ids.entry(key(q)).or_insert_with(|| {
                place.push(q);
                place.len() - 1
            })
        })
        .collect();
    let mut count: HashMap<(usize, usize), usize> = HashMap::new();
    for t in mesh.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (id[t[k] as usize], id[t[(k + 1) % 3] as usize]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    count.into_iter().filter(|&(_, n)| n == 1).map(|((a, b), _)| (place[a], place[b])).collect()
}

/// A face without normals takes its triangles' own; one with a normal per
/// point through pnindex gets its points in pnindex order and its normals
/// (of unit length) as given; one with a single normal has it at every
/// point. Each triangle keeps the file's turn.
#[test]
fn triangulated_faces_pass_through_with_and_without_normals() {
    let s = read("step_tess_faces.stp");
    let m = &s.model;
    assert!(m.faces.is_empty() && m.tessellated.len() == 3, "{:?}", m.warnings);
    let names: Vec<&str> = m.tessellated.iter().map(|f| f.name.as_deref().unwrap()).collect();
    assert_eq!(names, ["Tiles/bare", "Tiles/smooth", "Tiles/flat"]);
    let smooth = &m.tessellated[1];
    assert_eq!(smooth.positions, [p(5.0, 1.0, 1.0), p(5.0, 0.0, 1.0), p(6.0, 0.0, 1.0)]);
    assert_eq!(smooth.triangles, [[1, 2, 0]]);
    assert_eq!(smooth.normals, [p(0.0, 0.0, 1.0), p(0.6, 0.0, 0.8), p(0.0, 0.0, 1.0)]);
    assert!(m.tessellated[0].normals.is_empty());
    assert_eq!(m.tessellated[2].normals, [p(0.0, 0.0, -1.0); 3]);

    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces, r.report.faces_tessellated, r.report.triangles), (3, 3, 4));
    assert_eq!(r.report.max_deviation, 0.0, "no exact surface: nothing measured");
    let three = |w: &surfmesh::Warning| matches!(w.kind, WarningKind::TessellatedFaces { count: 3, .. });
    assert!(r.report.warnings.iter().any(three), "{:?}", r.report.warnings);
    let counts: Vec<u32> = r.mesh.face_ranges.iter().map(|f| f.count).collect();
    assert_eq!(counts, [2, 1, 1]);
    let bare = sorted(triangles(&r.mesh, 0));
    assert_eq!(
        bare,
        [
            [p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(2.0, 2.0, 0.0)],
            [p(0.0, 0.0, 0.0), p(2.0, 2.0, 0.0), p(0.0, 2.0, 0.0)]
        ]
    );
    assert!(bare.iter().all(|t| area2(t).z > 0.0));
    assert_eq!(triangles(&r.mesh, 1), [[p(5.0, 0.0, 1.0), p(6.0, 0.0, 1.0), p(5.0, 1.0, 1.0)]]);
    assert_eq!(triangles(&r.mesh, 2), [[p(10.0, 0.0, 0.0), p(10.0, 1.0, 0.0), p(11.0, 0.0, 0.0)]]);
    assert!(area2(&triangles(&r.mesh, 2)[0]).z < 0.0, "the flat face faces -z as the file turns it");
    // Normals: the facets' where the file gives none, else the file's.
    assert_eq!(normal_at(&r.mesh, 0, p(2.0, 0.0, 0.0)), p(0.0, 0.0, 1.0));
    assert_eq!(normal_at(&r.mesh, 1, p(5.0, 0.0, 1.0)), p(0.6, 0.0, 0.8));
    assert_eq!(normal_at(&r.mesh, 2, p(11.0, 0.0, 0.0)), p(0.0, 0.0, -1.0));
}

/// The strip (1..6) is (1,2,3), (3,2,4), (3,4,5), (5,4,6); the strip
/// (2,2,4) names a point twice and is no triangle; the fan (7..11) is
/// (7,8,9), (7,9,10), (7,10,11). The surface sets: one triangle, and a fan of two.
#[test]
fn strips_and_fans_read_as_triangles() {
    let s = read("step_tess_complex.stp");
    let t = &s.model.tessellated;
    assert_eq!(t[0].triangles, [[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5], [6, 7, 8], [6, 8, 9], [6, 9, 10]]);
    // pnindex reverses the stored points.
    assert_eq!(t[0].positions[0], p(0.0, 0.0, 0.0));
    assert_eq!(t[0].positions[10], p(2.5, 2.0, 0.0));
    assert_eq!(t[1].triangles, [[0, 1, 2]]);
    assert_eq!(t[2].triangles, [[0, 1, 2], [0, 2, 3]]);
}

/// The strip (1..6) is (1,2,3), (3,2,4), (3,4,5), (5,4,6); the strip
/// (2,2,4) names a point twice and is no triangle; the fan (7..11) is
/// (7,8,9), (7,9,10), (7,10,11); pnindex reverses the stored points. The
/// surface sets: one triangle, and a fan of two.
#[test]
fn strips_and_fans_face_the_way_their_first_triangle_does() {
    let s = read("step_tess_complex.stp");
    let counts: Vec<usize> = s.model.tessellated.iter().map(|f| f.triangles.len()).collect();
    assert_eq!(counts, [7, 1, 2]);
    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces_tessellated, r.report.triangles), (3, 10));
    let xy = |x: f64, y: f64| p(x, y, 0.0);
    let want = vec![
        [xy(0.0, 0.0), xy(1.0, 0.0), xy(0.0, 1.0)],
        [xy(0.0, 1.0), xy(1.0, 0.0), xy(1.0, 1.0)],
        [xy(0.0, 1.0), xy(1.0, 1.0), xy(0.0, 2.0)],
        [xy(0.0, 2.0), xy(1.0, 1.0), xy(1.0, 2.0)],
        [xy(3.0, 1.0), xy(4.0, 0.0), xy(5.0, 1.0)],
        [xy(3.0, 1.0), xy(5.0, 1.0), xy(4.0, 2.0)],
        [xy(3.0, 1.0), xy(4.0, 2.0), xy(2.5, 2.0)],
    ];
    let got = triangles(&r.mesh, 0);
    assert_eq!(sorted(got.clone()), sorted(want));
    assert!(got.iter().all(|t| area2(t).z > 0.0), "every triangle faces +z as the first does");
    let area: f64 = got.iter().map(|t| area2(t).z / 2.0).sum();
    assert!((area - 4.75).abs() < 1e-12, "{area}");
    // One normal for the face: at every vertex.
    assert_eq!(normal_at(&r.mesh, 0, xy(2.5, 2.0)), p(0.0, 0.0, 1.0));
    let z3 = |x: f64, y: f64| p(x, y, 3.0);
    assert_eq!(triangles(&r.mesh, 1), [[z3(0.0, 0.0), z3(1.0, 0.0), z3(1.0, 1.0)]]);
    assert_eq!(
        triangles(&r.mesh, 2),
        [[z3(0.0, 0.0), z3(1.0, 0.0), z3(1.0, 1.0)], [z3(0.0, 0.0), z3(1.0, 1.0), z3(0.0, 1.0)]]
    );
}

/// A tessellated solid in a product the assembly turns 90 degrees about z
/// and moves 20 along x: one closed shell and one body, its part's name and
/// the styles' colours (the solid's, the slope's own), and a closed mesh
/// facing out (volume +1/6) where the placement puts it.
#[test]
fn a_tessellated_solid_is_placed_named_and_coloured_as_a_part() {
    let s = read("step_tess_solid.stp");
    assert_eq!(s.model.tessellated.len(), 4);
    assert_eq!(s.parts, ["Tetra"]);
    assert_eq!(s.face_parts, [0, 0, 0, 0]);
    assert!(s.model.tessellated.iter().all(|f| f.name.as_deref().unwrap().starts_with("Tetra/")));
    assert_eq!(s.shells.len(), 1);
    assert!(s.shells[0].closed && s.shells[0].faces == (0..4) && s.shells[0].listed == 4);
    let red = Some([0.8f32, 0.2, 0.1]);
    assert_eq!(s.face_colours, [red, red, red, Some([0.0, 0.0, 1.0])]);
    assert_eq!(s.model.bodies, [0, 0, 0, 0]);
    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces_tessellated, r.report.triangles, r.report.bodies), (4, 4, 1));
    let c = edge_counts(&r.mesh, 1e-9, r.report.tolerance);
    assert_eq!((c.boundary_edges, c.misoriented_edges, c.nonmanifold_edges), (0, 0, 0));
    assert_eq!(r.report.free_edges, 0);
    let volume: f64 = (0..4).flat_map(|f| triangles(&r.mesh, f)).map(|t| t[0].dot(t[1].cross(t[2])) / 6.0).sum();
    assert!((volume - 1.0 / 6.0).abs() < 1e-12, "{volume}");
    // (1,0,0) turned about z is (0,1,0), moved 20 along x; (0,1,0) goes to (-1,0,0) + 20.
    let all: Vec<DVec3> = r.mesh.positions.clone();
    for q in [p(20.0, 0.0, 0.0), p(20.0, 1.0, 0.0), p(19.0, 0.0, 0.0), p(20.0, 0.0, 1.0)] {
        assert!(all.iter().any(|a| a.abs_diff_eq(q, 1e-12)), "no vertex at {q}: {all:?}");
    }
    assert!(all.iter().all(|a| (19.0 - 1e-12..=20.0 + 1e-12).contains(&a.x)));
    // The bottom's one normal, turned with the part, still points down.
    assert!(normal_at(&r.mesh, 0, all[0]).abs_diff_eq(p(0.0, 0.0, -1.0), 1e-12));
}

/// Each malformed face is skipped with a warning that names its `#id` and
/// line and what is wrong; the good face, and the one whose normals do not
/// fit (kept without them), are read.
#[test]
fn malformed_index_lists_skip_their_face_with_a_warning_naming_the_line() {
    let s = read("step_tess_bad.stp");
    let names: Vec<&str> = s.model.tessellated.iter().map(|f| f.name.as_deref().unwrap()).collect();
    assert_eq!(names, ["Bad/good", "Bad/normals"]);
    assert!(s.model.tessellated[1].normals.is_empty());
    let expect = [
        ("#21", "line 21", "names point 0"),
        ("#22", "line 22", "names point -2"),
        ("#23", "line 23", "names point 4"),
        ("#24", "line 26", "pnmax is 4"),
        ("#25", "line 27", "has 2 indices, not 3"),
        ("#26", "line 28", "a strip needs 3 or more"),
        ("#27", "line 29", "pnindex entry 2 is 7"),
        ("#28", "#11", "npoints is 5 but the list holds 3 points"),
        ("#29", "line 33", "2 normals for 3 points"),
        ("#30", "line 35", "expected a list of lists"),
        ("#31", "line 36", "has no triangles"),
    ];
    let w = &s.model.warnings;
    assert_eq!(w.len(), expect.len(), "{w:#?}");
    // The text names the instance, its line and what is wrong.
    for ((id, line, what), w) in expect.iter().zip(w) {
        let w = w.to_string();
        assert!(w.starts_with(&format!("{id} ")) && w.contains(line) && w.contains(what), "{w}");
    }
    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces_tessellated, r.report.triangles), (2, 2));
}

/// The exact plate (z = 0) and the tessellated flap (x = 10) share the edge
/// x = 10; the flap's points on it lie 1e-4 off, 2.5 apart. The plate's
/// border takes them as its nodes, and with edges of at most 1 the plate
/// refines its border between them: the flap's triangles there become fans
/// over the plate's nodes. Either way no edge is open along the shared edge,
/// no crack is counted, the flap's own points stay where the file puts them,
/// and the copy of the plate the file links to it is left out.
#[test]
fn an_exact_and_a_tessellated_face_sharing_an_edge_are_sewn_without_a_crack() {
    let s = read("step_tess_mixed.stp");
    assert_eq!((s.model.faces.len(), s.model.tessellated.len()), (1, 1), "the linked copy is left out");
    assert_eq!(s.model.tessellated[0].name.as_deref(), Some("Bracket/flap"));
    assert_eq!(s.model.bodies[0], s.model.bodies[1], "one part: one body");
    let on_shared = |q: DVec3| (q.x - 10.0).abs() <= 2e-4 && q.z == 0.0;
    for (options, refined) in [(MeshOptions::default(), false), (MeshOptions::default().with_max_edge(Some(1.0)), true)]
    {
        let r = mesh(&s, &options);
        let rep = &r.report;
        assert_eq!((rep.faces, rep.faces_tessellated), (2, 1));
        assert_eq!(rep.free_edges, 0, "cracks");
        assert_eq!((rep.inverted_triangles, rep.nonmanifold_edges), (0, 0));
        assert!(rep.max_deviation <= rep.tolerance, "{} > {}", rep.max_deviation, rep.tolerance);
        let open = open_edges(&r.mesh);
        assert!(!open.is_empty());
        assert!(open.iter().all(|&(a, b)| !(on_shared(a) && on_shared(b))), "open along the shared edge: {open:?}");
        // The flap: every point of the file still there, its triangles cut
        // only along the shared edge (the plate's nodes between its points
        // there), covering the 10 x 5 of the file.
        let flap = triangles(&r.mesh, 1);
        assert_eq!(flap.len() > 5, refined, "{flap:?}");
        let area: f64 = flap.iter().map(|t| -area2(t).x / 2.0).sum();
        assert!((area - 50.0).abs() < 1e-9, "{area}");
        for y in [0.0, 2.5, 5.0, 7.5, 10.0] {
            assert!(flap.iter().flatten().any(|&q| q == p(10.0001, y, 0.0)), "flap point at y = {y}");
        }
        assert!(flap.iter().flatten().all(|q| q.x >= 10.0 && q.x <= 10.0001));
        assert!(flap.iter().all(|t| area2(t).x < 0.0), "the flap faces -x, the plate's side");
        // The plate: its border nodes on the shared edge are the flap's vertices there.
        let plate: Vec<DVec3> = triangles(&r.mesh, 0).into_iter().flatten().filter(|&q| on_shared(q)).collect();
        let flap_edge: Vec<DVec3> = flap.iter().flatten().copied().filter(|&q| on_shared(q)).collect();
        assert!(plate.iter().all(|q| flap_edge.contains(q)) && flap_edge.iter().all(|q| plate.contains(q)));
    }
}

/// The two files of the wide corpus that hold tessellated faces only, which
/// once read as "no faces": the counts are the file's own (88 + 68 + 24 +
/// 176 triangles over four faces; a cube of six faces of two triangles,
/// its strips turned so that it faces out).
#[test]
fn corpus_tessellated_files_mesh() {
    let s = read_step_parts(&corpus_bytes("tessellated/bug33100_window.step")).unwrap();
    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces, r.report.faces_tessellated), (4, 4));
    let counts: Vec<u32> = r.mesh.face_ranges.iter().map(|f| f.count).collect();
    assert_eq!(counts, [88, 68, 24, 176]);
    assert!(s.face_colours.iter().all(Option::is_some));
    let s = read_step_parts(&corpus_bytes("tessellated/bug33638.stp")).unwrap();
    let r = mesh(&s, &MeshOptions::default());
    assert_eq!((r.report.faces_tessellated, r.report.triangles), (6, 12));
    let c = edge_counts(&r.mesh, 1e-9, r.report.tolerance);
    assert_eq!((c.boundary_edges, c.misoriented_edges), (0, 0));
    let volume: f64 = (0..6).flat_map(|f| triangles(&r.mesh, f)).map(|t| t[0].dot(t[1].cross(t[2])) / 6.0).sum();
    let want = 101.43797 * 76.14538 * 100.0;
    assert!((volume - want).abs() < 1e-6 * want, "{volume} != {want}");
    let red = Some([1.0f32, 0.0, 0.0]);
    assert_eq!(s.face_colours, [red, Some([0.0, 0.0, 1.0]), red, red, red, red]);
}

/// A coarse tessellated half disc (chords 0.76 inside the arc, far beyond
/// the sewing reach) beside an exact plate bounded by the exact arc: its
/// points on the arc are the plate's nodes, and the plate's nodes between
/// them (found along the plate's border from one to the next) go into the
/// chords, whose triangles become fans. The two then tile the rectangle
/// [-10, 10] x [0, 12] exactly, open only along its outline.
#[test]
fn a_coarse_tessellated_face_takes_the_exact_arc_it_meets() {
    let s = read("step_tess_arc.stp");
    assert_eq!((s.model.faces.len(), s.model.tessellated.len()), (1, 1));
    for options in [MeshOptions::default(), MeshOptions::default().with_relative_tolerance(1e-2)] {
        let r = mesh(&s, &options);
        let rep = &r.report;
        assert_eq!((rep.free_edges, rep.inverted_triangles, rep.nonmanifold_edges), (0, 0, 0));
        assert!(rep.max_deviation <= rep.tolerance);
        let disc = triangles(&r.mesh, 1);
        assert!(disc.len() > 4, "the chords take the arc's nodes: {}", disc.len());
        let file = s.model.tessellated[0].positions.clone();
        assert!(file.iter().all(|q| disc.iter().flatten().any(|a| a == q)), "the file's points stay");
        assert!(disc.iter().all(|t| area2(t).z > 0.0));
        let area: f64 = (0..2).flat_map(|f| triangles(&r.mesh, f)).map(|t| area2(&t).z / 2.0).sum();
        assert!((area - 240.0).abs() < 1e-9, "{area}");
        // Open: the plate's right, top and left sides and the disc's diameter.
        let outline = |q: DVec3| q.y == 0.0 || q.y == 12.0 || q.x.abs() == 10.0;
        let open = open_edges(&r.mesh);
        assert!(open.iter().all(|&(a, b)| outline(a) && outline(b)), "{open:?}");
    }
}

/// A model built by hand may name points that are not there, one point
/// twice, or points that are not finite: those triangles are left out with
/// a warning, never a panic; a face of such triangles only is empty.
#[test]
fn a_hand_built_tessellated_face_with_bad_indices_does_not_panic() {
    let face = |positions: Vec<DVec3>, triangles: Vec<[u32; 3]>| surfmesh::TessellatedFace {
        name: None,
        positions,
        normals: vec![p(0.0, 0.0, 1.0)],
        triangles,
    };
    let square = vec![p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(1.0, 1.0, 0.0), p(f64::NAN, 0.0, 0.0)];
    let model = surfmesh::Model {
        tessellated: vec![
            face(square.clone(), vec![[0, 1, 2], [0, 1, 9], [1, 1, 2], [0, 3, 2], [u32::MAX, 0, 1]]),
            face(square, vec![[0, 0, 0]]),
        ],
        ..Default::default()
    };
    for options in [MeshOptions::default(), MeshOptions::default().with_mode(surfmesh::MeshMode::Quality)] {
        let r = mesh_model(&model, &options).unwrap();
        let counts: Vec<u32> = r.mesh.face_ranges.iter().map(|f| f.count).collect();
        assert_eq!(counts, [1, 0]);
        let dropped = |w: &surfmesh::Warning| w.kind == WarningKind::TessellatedDropped { count: 5 };
        assert!(r.report.warnings.iter().any(dropped), "{:?}", r.report.warnings);
        // One normal for four points fits neither way: the facet's is taken.
        assert_eq!(r.mesh.normals, [p(0.0, 0.0, 1.0); 3]);
    }
}

/// Quality mode meshes the exact plate and passes the flap through (one
/// face range each); shares of the bodies mesh each body once, together
/// the whole model.
#[test]
fn quality_mode_and_shares_pass_tessellated_faces_through() {
    let s = read("step_tess_mixed.stp");
    let r = mesh(&s, &MeshOptions::default().with_mode(surfmesh::MeshMode::Quality));
    assert_eq!(r.mesh.face_ranges.len(), 2);
    assert_eq!(r.mesh.face_ranges[1].count, 5);
    assert_eq!((r.report.faces, r.report.faces_tessellated), (2, 1));
    assert_eq!(r.report.triangles, r.mesh.triangle_count());
    let s = read("step_tess_faces.stp");
    let whole = mesh(&s, &MeshOptions::default());
    let mut counts = vec![0u32; 3];
    for i in 0..3 {
        let r = mesh(&s, &MeshOptions::default().with_share(i, 3));
        assert_eq!(r.mesh.face_ranges.len(), 3);
        assert_eq!(r.report.faces_tessellated, 1, "one body a share");
        for (c, f) in counts.iter_mut().zip(&r.mesh.face_ranges) {
            *c += f.count;
        }
    }
    let want: Vec<u32> = whole.mesh.face_ranges.iter().map(|f| f.count).collect();
    assert_eq!(counts, want);
}
