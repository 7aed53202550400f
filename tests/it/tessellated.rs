//! STEP AP242 tessellated faces: small files written for these tests
//! (tests/data/step_tess_*.stp) check that each entity form reads into
//! the triangles worked out by hand from the file, with its part, placement
//! and colours, and that malformed lists skip their face with a warning.

use std::path::Path;

use glam::DVec3;
use surfmesh::{read_step_parts, StepModel};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("data").join(name)).unwrap()
}

fn read(name: &str) -> StepModel {
    read_step_parts(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn p(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Face points through pnindex, normals one per point (made of unit
/// length), one for the face, or none.
#[test]
fn triangulated_faces_read_with_and_without_normals() {
    let s = read("step_tess_faces.stp");
    let m = &s.model;
    assert!(m.faces.is_empty() && m.tessellated.len() == 3, "{:?}", m.warnings);
    let names: Vec<&str> = m.tessellated.iter().map(|f| f.name.as_deref().unwrap()).collect();
    assert_eq!(names, ["Tiles/bare", "Tiles/smooth", "Tiles/flat"]);
    assert_eq!(m.tessellated[0].triangles, [[0, 1, 2], [0, 2, 3]]);
    let smooth = &m.tessellated[1];
    assert_eq!(smooth.positions, [p(5.0, 1.0, 1.0), p(5.0, 0.0, 1.0), p(6.0, 0.0, 1.0)]);
    assert_eq!(smooth.triangles, [[1, 2, 0]]);
    assert_eq!(smooth.normals, [p(0.0, 0.0, 1.0), p(0.6, 0.0, 0.8), p(0.0, 0.0, 1.0)]);
    assert!(m.tessellated[0].normals.is_empty());
    assert_eq!(m.tessellated[2].normals, [p(0.0, 0.0, -1.0); 3]);
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

/// A tessellated solid in a product the assembly turns 90 degrees about z
/// and moves 20 along x: one closed shell, one body, its part's name and the
/// styles' colours (the solid's, the slope's own).
#[test]
fn a_tessellated_solid_reads_placed_named_and_coloured_as_a_part() {
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
    // The bottom (1, 3, 2): (0,0,0), (0,1,0), (1,0,0) turned and moved.
    let bottom = &s.model.tessellated[0];
    let want = [p(20.0, 0.0, 0.0), p(19.0, 0.0, 0.0), p(20.0, 1.0, 0.0)];
    assert!(bottom.positions.iter().zip(want).all(|(a, b)| a.abs_diff_eq(b, 1e-12)), "{:?}", bottom.positions);
    assert!(bottom.normals.iter().all(|n| n.abs_diff_eq(p(0.0, 0.0, -1.0), 1e-12)));
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
    for ((id, line, what), w) in expect.iter().zip(w) {
        assert!(w.starts_with(&format!("{id} ")) && w.contains(line) && w.contains(what), "{w}");
    }
}

/// An exact plate and a tessellated flap listed by one part are one body;
/// the tessellated copy of the plate the file links to it is left out.
#[test]
fn a_part_of_exact_and_tessellated_faces_is_one_body() {
    let s = read("step_tess_mixed.stp");
    assert_eq!((s.model.faces.len(), s.model.tessellated.len()), (1, 1), "the linked copy is left out");
    assert_eq!(s.model.tessellated[0].name.as_deref(), Some("Bracket/flap"));
    assert_eq!(s.model.bodies[0], s.model.bodies[1]);
    assert_eq!(s.face_parts, [0, 0]);
}
