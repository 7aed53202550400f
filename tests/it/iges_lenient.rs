//! IGES input a tolerant reader accepts: each small file here is a 10 × 10
//! square surface (tests/data/iges_square.igs) with one flaw real files
//! have, and must read to that face with exactly one warning naming it.
//! What no tolerance reads stays an error naming its place.

use super::data;
use surfmesh::{mesh_model, read_iges, Entity, Error, MeshOptions, Model, Warning, WarningKind};

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

/// Reads `bytes`, checks it is the square, and returns its warnings.
fn square_warnings(name: &str, bytes: &[u8]) -> Vec<Warning> {
    one_face_warnings(name, bytes, 100.0)
}

/// Reads `bytes`, checks it is one face of area `area`, and returns its warnings.
fn one_face_warnings(name: &str, bytes: &[u8], area: f64) -> Vec<Warning> {
    let model = read_iges(bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(model.faces.len(), 1, "{name}: {:?}", model.warnings);
    let meshed = meshed_area(&model);
    assert!((meshed - area).abs() < 1e-9, "{name}: area {meshed}, {area} expected");
    model.warnings
}

/// The warnings' text, as the report shows them.
fn texts(w: &[Warning]) -> Vec<String> {
    w.iter().map(ToString::to_string).collect()
}

#[test]
fn the_square_itself_reads_without_warnings() {
    assert!(square_warnings("iges_square.igs", &data("iges_square.igs")).is_empty());
}

/// The directory entry says 20 parameter lines where the section has 2: the
/// data is whole up to its `;`, so it is read.
#[test]
fn a_parameter_count_past_the_section_reads_what_is_there() {
    let w = square_warnings("overrun", &data("iges_lenient_overrun.igs"));
    assert_eq!(
        texts(&w),
        ["IGES Directory section, entity DE 1: parameter data lines 1..20 run past the Parameter section's 2 lines; \
          read up to the entity's ';'"]
    );
    // Data really cut short (no ';' before the section ends): that entity is
    // skipped, and with nothing else in the file, the file is an error naming it.
    let text = String::from_utf8(data("iges_lenient_overrun.igs")).unwrap().replace("0,1,0,1;", "0,1,0,1,");
    match read_iges(text.as_bytes()) {
        Err(Error::Iges { entity: 1, message, .. }) => {
            assert!(message.contains("without the record delimiter"), "{message}")
        }
        other => panic!("expected an error naming DE 1, got {other:?}"),
    }
}

/// All records on one line, with no line breaks (the file Disc.igs of the
/// OpenCASCADE tests is written so).
#[test]
fn records_without_line_breaks_are_split_at_80_columns() {
    let w = square_warnings("unbroken", &data("iges_lenient_unbroken.igs"));
    assert_eq!(texts(&w), ["line 1: 9 records of 80 columns with no line breaks between them; read as lines 1..9"]);
    assert_eq!(w[0].kind, WarningKind::UnbrokenRecords { line: 1, records: 9, first: 1 });
}

#[test]
fn a_missing_global_section_takes_the_defaults() {
    let w = square_warnings("no global", &data("iges_lenient_no_global.igs"));
    assert_eq!(w.iter().map(|w| &w.kind).collect::<Vec<_>>(), [&WarningKind::NoGlobal]);
    // A Global section that cannot be read: the same, naming what is wrong.
    let text = String::from_utf8(data("iges_square.igs")).unwrap().replacen("1H,,1H;,", "2H,,1H;,", 1);
    let w = square_warnings("bad global", text.as_bytes());
    assert_eq!(w.len(), 1, "{w:?}");
    match &w[0].kind {
        WarningKind::BadGlobal(Error::Iges { section: "Global", line: 2, message, .. }) => {
            assert!(message.starts_with("field 1"), "{message}")
        }
        other => panic!("expected the Global section's error, got {other:?}"),
    }
}

/// Section letters in lower case: read as upper case.
#[test]
fn lower_case_section_letters_are_read() {
    let text: String = String::from_utf8(data("iges_square.igs"))
        .unwrap()
        .lines()
        .map(|l| format!("{}{}{}\n", &l[..72], l[72..73].to_ascii_lowercase(), &l[73..]))
        .collect();
    let w = square_warnings("lower case", text.as_bytes());
    assert_eq!(texts(&w), ["line 1: the section letter in lower case; read as upper case (and 8 more like it)"]);
    assert_eq!((&w[0].kind, w[0].more), (&WarningKind::LowerCaseSection { line: 1 }, 8));
}

/// The square trimmed to [2, 8]² by four 126 lines whose parameter ranges
/// are all [0, 0]: each curve is read over its knots' whole domain, one
/// warning for the four.
#[test]
fn an_empty_curve_range_is_read_as_the_whole_curve() {
    let w = one_face_warnings("empty range", &data("iges_lenient_empty_range.igs"), 36.0);
    assert_eq!(
        texts(&w),
        ["IGES Parameter section line 23, entity DE 3: B-spline curve's parameter range [0, 0] holds none of the \
          curve; its whole domain [0, 1] is used (and 3 more like it)"]
    );
    // Inverted ranges, [1, 0]: read the other way round, the same face.
    let text = String::from_utf8(data("iges_lenient_empty_range.igs")).unwrap().replace(",0,0,0,0,1;", ",1,0,0,0,1;");
    let w = one_face_warnings("inverted range", text.as_bytes(), 36.0);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(matches!(&w[0].kind, WarningKind::Forgiven(Error::Iges { entity: 3, .. })), "{w:?}");
    assert_eq!(w[0].more, 3, "{w:?}");
    assert!(w[0].to_string().contains("range [1, 0] is inverted; read as [0, 1] (and 3 more like it)"), "{w:?}");
}

/// A 308 definition holding the 10 × 10 square, placed by three 408
/// instances: moved by (20, 0, 0) and scaled 2; moved by (0, 30, 0) then
/// turned a quarter about z by the instance's matrix; and through a second
/// definition that raises it by 5, moved by (100, 0, 0). The square itself
/// is not a face of its own.
#[test]
fn subfigure_instances_place_their_definitions() {
    let model = read_iges(&data("iges_subfigures.igs")).unwrap();
    assert_eq!(model.faces.len(), 3, "{:?}", model.warnings);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-3)).unwrap();
    let boxes: Vec<([f64; 3], [f64; 3], f64)> = r
        .mesh
        .face_ranges
        .iter()
        .map(|fr| {
            let (mut lo, mut hi, mut area) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 0.0);
            for t in fr.first as usize..(fr.first + fr.count) as usize {
                let [a, b, c] = r.mesh.triangle(t);
                area += 0.5 * (b - a).cross(c - a).length();
                for p in [a, b, c] {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
            (lo, hi, area)
        })
        .collect();
    let want = [
        ([20.0, 0.0, 0.0], [40.0, 20.0, 0.0], 400.0),
        ([-40.0, 0.0, 0.0], [-30.0, 10.0, 0.0], 100.0),
        ([100.0, 0.0, 5.0], [110.0, 10.0, 5.0], 100.0),
    ];
    for (got, want) in boxes.iter().zip(&want) {
        for k in 0..3 {
            assert!((got.0[k] - want.0[k]).abs() < 1e-9 && (got.1[k] - want.1[k]).abs() < 1e-9, "{got:?} vs {want:?}");
        }
        assert!((got.2 - want.2).abs() < 1e-9, "{got:?} vs {want:?}");
    }
    // A definition that instances itself: that instance is skipped naming the cycle, the others read.
    let text = String::from_utf8(data("iges_subfigures.igs")).unwrap().replace("408,3,0,0,5; ", "408,11,0,0,5;");
    let model = read_iges(text.as_bytes()).unwrap();
    assert_eq!(model.faces.len(), 2, "{:?}", model.warnings);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    let w = &model.warnings[0];
    assert_eq!(w.entity, Some(Entity::Iges { de: 15, kind: 408 }), "{w:?}");
    assert!(matches!(&w.kind, WarningKind::Skipped(e) if e.to_string().contains("(a cycle?)")), "{w:?}");
}
