//! STEP input a tolerant reader accepts: each small file here is a 10 × 10
//! square face (tests/data/step_square.stp) with one flaw real writers
//! make, and must read to that face with exactly one warning naming the
//! flaw's line and instance.

use super::data;
use surfmesh::{mesh_model, read_step, MeshOptions, Model};

/// Area of the model's mesh at a relative tolerance of 1e-3.
fn meshed_area(model: &Model) -> f64 {
    let r = mesh_model(model, &MeshOptions::default().with_relative_tolerance(1e-3)).unwrap();
    assert_eq!(r.report.faces_skipped, 0, "{:?}", r.report.warnings);
    (0..r.mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = r.mesh.triangle(t);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// Reads `name`, checks it is the square, and returns its warnings.
fn square_warnings(name: &str) -> Vec<String> {
    let model = read_step(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(model.faces.len(), 1, "{name}: {:?}", model.warnings);
    let area = meshed_area(&model);
    assert!((area - 100.0).abs() < 1e-9, "{name}: area {area}");
    model.warnings
}

#[test]
fn the_square_itself_reads_without_warnings() {
    assert!(square_warnings("step_square.stp").is_empty());
}

/// The second `#31` points along x: had it replaced the first, the square's
/// right edge would run along the bottom and the loop would not close.
#[test]
fn a_duplicate_instance_number_keeps_the_first_definition() {
    let w = square_warnings("step_lenient_duplicate.stp");
    assert_eq!(w, ["STEP line 21, #31: instance number defined twice; the first definition (line 20) is kept"]);
}

/// The face's name ends inside a `\X2\` run, and so does its shell's: what
/// decoded is kept, the file reads, one warning covers both.
#[test]
fn escapes_left_open_keep_their_text() {
    let model = read_step(&data("step_lenient_escapes.stp")).unwrap();
    assert_eq!(model.faces[0].name.as_deref(), Some("Expression: \u{3b1}*\u{3b2}\u{f7}\u{3b3}"));
    let w = square_warnings("step_lenient_escapes.stp");
    assert_eq!(
        w,
        ["STEP line 40, #74: \\X2\\ or \\X4\\ escape not closed by \\X0\\; kept as raw text (and 1 more like it)"]
    );
}

/// An unknown header entity, a `FILE_NAME` with a syntax error and the
/// `FILE_SCHEMA` after it lost to the resynchronization: one warning.
#[test]
fn a_damaged_header_is_read_past() {
    let w = square_warnings("step_lenient_header.stp");
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(
        w[0],
        "STEP line 2: HEADER section: line 5: a value is missing before ','; no FILE_NAME; no FILE_SCHEMA; \
         unknown header entity SOME_WRITER_STAMP; the DATA section is read anyway"
    );
}

/// What no tolerance can read stays an error naming its place.
#[test]
fn a_string_that_never_closes_is_still_an_error() {
    let m = read_step(&data("step_unclosed_string.stp")).unwrap_err().to_string();
    assert_eq!(m, "STEP line 10, #7: string not closed by a quote");
}
