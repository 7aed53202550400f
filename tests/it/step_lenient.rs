//! STEP input a tolerant reader accepts: each small file here is a 10 × 10
//! square face (tests/data/step_square.stp) with one flaw real writers
//! make, and must read to that face with exactly one warning naming the
//! flaw's line and instance.

use super::data;
use surfmesh::{mesh_model, read_step, Entity, MeshOptions, Model, Warning, WarningKind};

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
fn square_warnings(name: &str) -> Vec<Warning> {
    let model = read_step(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(model.faces.len(), 1, "{name}: {:?}", model.warnings);
    let area = meshed_area(&model);
    assert!((area - 100.0).abs() < 1e-9, "{name}: area {area}");
    model.warnings
}

/// The warnings' text, as the report shows them.
fn texts(w: &[Warning]) -> Vec<String> {
    w.iter().map(ToString::to_string).collect()
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
    assert_eq!(texts(&w), ["STEP line 21, #31: instance number defined twice; the first definition (line 20) is kept"]);
}

/// The face's name ends inside a `\X2\` run, and so does its shell's: what
/// decoded is kept, the file reads, one warning covers both.
#[test]
fn escapes_left_open_keep_their_text() {
    let model = read_step(&data("step_lenient_escapes.stp")).unwrap();
    assert_eq!(model.faces[0].name.as_deref(), Some("Expression: \u{3b1}*\u{3b2}\u{f7}\u{3b3}"));
    let w = square_warnings("step_lenient_escapes.stp");
    assert_eq!(
        texts(&w),
        ["STEP line 40, #74: \\X2\\ or \\X4\\ escape not closed by \\X0\\; kept as raw text (and 1 more like it)"]
    );
}

/// An unknown header entity, a `FILE_NAME` with a syntax error and the
/// `FILE_SCHEMA` after it lost to the resynchronization: one warning.
#[test]
fn a_damaged_header_is_read_past() {
    let w = square_warnings("step_lenient_header.stp");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(matches!(w[0].kind, WarningKind::Forgiven(_)), "{w:?}");
    assert_eq!(
        w[0].to_string(),
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

/// The end vertex of the square's right edge is a reference to nothing
/// (`#18446744073709551615`, a writer's -1): the top edge, next in the
/// loop, starts there, so the face is whole.
#[test]
fn a_missing_vertex_is_taken_from_the_next_edge_of_its_loop() {
    let w = square_warnings("step_lenient_dangling_vertex.stp");
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0].entity, Some(Entity::step(51, "EDGE_CURVE")));
    assert_eq!(w[0].kind, WarningKind::VertexFromNeighbour { end: true, vertex: u64::MAX, lp: 70 });
    assert_eq!(
        texts(&w),
        ["#51 EDGE_CURVE: its end vertex #18446744073709551615 is not defined; \
          the point its neighbour in loop #70 gives is used"]
    );
    // With the top edge's vertex there gone too, nothing gives the corner:
    // the face is skipped naming the reference, and with it the file.
    let text = String::from_utf8(data("step_lenient_dangling_vertex.stp")).unwrap();
    let broken = text.replace("#52=EDGE_CURVE('',#23,#22,", "#52=EDGE_CURVE('',#23,#998,");
    let m = read_step(broken.as_bytes()).unwrap_err().to_string();
    assert!(m.contains("#51") && m.contains("#18446744073709551615, which is not defined"), "{m}");
}

/// A file that parses but holds no face says what it holds instead.
#[test]
fn a_file_without_faces_says_what_it_holds() {
    let file = |data: &str| {
        format!(
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('','',(''),(''),'','','');\n\
             FILE_SCHEMA(('S'));\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n"
        )
    };
    let message = |data: &str| read_step(file(data).as_bytes()).unwrap_err().to_string();
    let lead = "STEP: no faces, shells, solids or surfaces in the file: ";
    let line = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(1.,0.,0.));\n#3=VECTOR('',#2,1.);\n\
                #4=LINE('',#1,#3);\n#5=GEOMETRIC_CURVE_SET('',(#4));";
    assert_eq!(message(line), format!("{lead}it holds only curves and points (1 curve)"));
    let csg = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=AXIS1_PLACEMENT('',#1,$);\n\
               #3=RIGHT_CIRCULAR_CYLINDER('',#2,2.,1.);\n#4=CSG_SOLID('',#3);";
    assert_eq!(
        message(csg),
        format!(
            "{lead}its solids are given by construction (2 operations: primitives, sweeps, Boolean operations), \
             which this reader does not evaluate"
        )
    );
    let assembly = "#1=PRODUCT('a','a','',());\n#2=PRODUCT_DEFINITION_FORMATION('','',#1);\n\
                    #3=PRODUCT_DEFINITION('','',#2,$);\n#4=NEXT_ASSEMBLY_USAGE_OCCURRENCE('','','',#3,#3,$);\n\
                    #5=DOCUMENT_FILE('part.stp','',$,$,'',$);";
    assert_eq!(
        message(assembly),
        format!("{lead}it holds an assembly structure (1 placed component) whose parts' geometry is in another file ('part.stp')")
    );
    assert_eq!(
        message("#1=PRODUCT('a','a','',());"),
        format!("{lead}it holds no geometry (only product data and placements)")
    );
}
