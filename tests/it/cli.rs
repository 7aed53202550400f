//! The JSON reader, the mesh writers and the `surfmesh` command line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::DVec3;
use serde_json::Value;
use surfmesh::{read_json, write_glb, write_obj, write_stl, Error, FaceRange, Mesh, NurbsError};

const BIN: &str = env!("CARGO_BIN_EXE_surfmesh");

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn read_data(name: &str) -> Result<surfmesh::Model, Error> {
    read_json(&std::fs::read(data(name)).unwrap())
}

/// A fresh, empty directory for one test's output files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("surfmesh-it-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8(out.stderr.clone()).unwrap()
}

// ---------------------------------------------------------------- reader

#[test]
fn reader_builds_the_plane() {
    let model = read_data("plane.json").unwrap();
    assert_eq!(model.units, "mm");
    assert_eq!(model.faces.len(), 1);
    assert_eq!(model.faces[0].name.as_deref(), Some("square plate"));
    assert!(model.faces[0].loops.is_empty());
    let surfmesh::FaceSurface::Nurbs(s) = &model.faces[0].surface else { panic!("not a NURBS face") };
    assert_eq!(s.degree(), [1, 1]);
    assert_eq!(s.counts(), [2, 2]);
    assert!(!s.is_rational());
    // points[1][1] is the corner u = 1, v = 1.
    use surfmesh::Surface;
    assert!(s.point(glam::DVec2::new(1.0, 1.0)).distance(DVec3::new(10.0, 10.0, 0.0)) < 1e-12);
    assert!(s.point(glam::DVec2::new(0.5, 0.25)).distance(DVec3::new(5.0, 2.5, 0.0)) < 1e-12);
}

#[test]
fn reader_defaults_units_and_reads_loops_and_weights() {
    let text = br#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[0,0,2,2],[0,0,1,1]],
        "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]], "weights": [[1,2],[1,1]]},
        "loops": [{"curves": [
          {"degree": 1, "knots": [0,0,1,1], "points": [[0.5,0.2],[1.5,0.2]]},
          {"degree": 2, "knots": [0,0,0,1,1,1], "points": [[1.5,0.2],[1.5,0.8],[0.5,0.2]], "weights": [1,0.5,1]}
        ]}]}]}"#;
    let model = read_json(text).unwrap();
    assert_eq!(model.units, "mm");
    let face = &model.faces[0];
    let surfmesh::FaceSurface::Nurbs(s) = &face.surface else { panic!("not a NURBS face") };
    assert!(s.is_rational());
    assert_eq!(face.loops.len(), 1);
    let curves = &face.loops[0].curves;
    assert_eq!(curves.len(), 2);
    assert_eq!(curves[1].degree(), 2);
    assert!(curves[1].is_rational());
    let end = curves[1].point(curves[1].domain().1);
    assert!(end.distance(DVec3::new(0.5, 0.2, 0.0)) < 1e-12, "{end}");
}

fn location(e: &Error) -> &str {
    match e {
        Error::Model { location, .. } | Error::Nurbs { location, .. } => location,
        other => panic!("expected a located error, got {other:?}"),
    }
}

#[test]
fn reader_reports_malformed_json_with_line_and_column() {
    let err = read_data("bad_syntax.json").unwrap_err();
    let Error::Json { line, column, message } = &err else { panic!("{err:?}") };
    assert_eq!((*line, *column), (3, 37), "{message}");
    assert!(!message.contains("at line"), "position repeated in {message}");
}

#[test]
fn reader_rejects_short_knot_vector() {
    let err = read_data("bad_knots_short.json").unwrap_err();
    assert_eq!(location(&err), "face 0 surface knots[0]");
    assert!(matches!(err, Error::Nurbs { source: NurbsError::TooFewKnots { found: 6, needed: 8 }, .. }));
}

#[test]
fn reader_rejects_decreasing_knots_naming_face_and_direction() {
    let err = read_data("bad_knots_decreasing.json").unwrap_err();
    assert_eq!(location(&err), "face 1 surface knots[1]");
    assert!(matches!(err, Error::Nurbs { source: NurbsError::DecreasingKnots { index: 3 }, .. }));
}

#[test]
fn reader_rejects_zero_weight() {
    let err = read_data("bad_weight_zero.json").unwrap_err();
    assert_eq!(location(&err), "face 0 surface weights[1][0]");
    assert!(matches!(err, Error::Nurbs { source: NurbsError::BadWeight { .. }, .. }));
}

#[test]
fn reader_rejects_out_of_range_number() {
    let err = read_data("bad_not_finite.json").unwrap_err();
    assert!(matches!(err, Error::Json { line: 7, .. }), "{err:?}");
}

#[test]
fn reader_rejects_open_loop_naming_the_curve() {
    let err = read_data("bad_loop_open.json").unwrap_err();
    assert_eq!(location(&err), "face 0 loop 0 curve 2");
    assert!(err.to_string().contains("does not close"), "{err}");
}

#[test]
fn reader_accepts_loop_gaps_below_the_closure_tolerance() {
    // Parameter range 1000: gaps up to 1e-6 close the loop, larger ones do not.
    let make = |gap: f64| {
        format!(
            r#"{{"faces": [{{"surface": {{"degree": [1, 1], "knots": [[0,0,1000,1000],[0,0,1,1]],
            "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}},
            "loops": [{{"curves": [
              {{"degree": 1, "knots": [0,0,1,1], "points": [[100,0.2],[900,0.2]]}},
              {{"degree": 1, "knots": [0,0,1,1], "points": [[900,0.2],[500,0.8]]}},
              {{"degree": 1, "knots": [0,0,1,1], "points": [[500,0.8],[{},0.2]]}}
            ]}}]}}]}}"#,
            100.0 + gap
        )
    };
    assert!(read_json(make(0.5e-6).as_bytes()).is_ok());
    let err = read_json(make(2e-6).as_bytes()).unwrap_err();
    assert_eq!(location(&err), "face 0 loop 0 curve 2");
}

#[test]
fn reader_rejects_loop_point_with_three_coordinates() {
    let err = read_data("bad_loop_point.json").unwrap_err();
    assert!(matches!(err, Error::Model { .. }), "{err:?}");
    assert_eq!(location(&err), "face 0 loop 0 curve 1 points[0]");
}

#[test]
fn reader_rejects_shape_errors() {
    let surface = r#""surface": {"degree": [1, 1], "knots": [[0,0,1,1],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}"#;
    let cases: Vec<(String, &str)> = vec![
        (r#"{"faces": []}"#.into(), "faces"),
        (r#"{"units": "mm"}"#.into(), "faces"),
        (r#"{"faces": [{"name": "x"}]}"#.into(), "face 0"),
        (
            r#"{"faces": [{"surface": {"degree": [1], "knots": [[0,0,1,1]], "points": []}}]}"#.into(),
            "face 0 surface degree",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[0,0,1,1]], "points": []}}]}"#.into(),
            "face 0 surface knots",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[0,0,1,1],[0,0,1,1]], "points": [[[0,0,0],[0,1]],[[1,0,0],[1,1,0]]]}}]}"#.into(),
            "face 0 surface points[0][1]",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[0,0,1,1],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]]]}}]}"#.into(),
            "face 0 surface points",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [0, 1], "knots": [[0,1],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]]]}}]}"#.into(),
            "face 0 surface degree[0]",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[0,0,1,1],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]], "weights": [[1,1]]}}]}"#.into(),
            "face 0 surface weights",
        ),
        (format!(r#"{{"faces": [{{{surface}, "loops": [{{"curves": []}}]}}]}}"#), "face 0 loop 0 curves"),
        (
            format!(
                r#"{{"faces": [{{{surface}}}, {{{surface}, "loops": [{{"curves": [{{"degree": 1, "knots": [0,0,1,1], "points": [[0,0]]}}]}}]}}]}}"#
            ),
            "face 1 loop 0 curve 0 points",
        ),
        (
            format!(
                r#"{{"faces": [{{{surface}, "loops": [{{"curves": [{{"degree": 1, "knots": [0,1,0,1], "points": [[0,0],[1,1]]}}]}}]}}]}}"#
            ),
            "face 0 loop 0 curve 0 knots",
        ),
        (
            format!(
                r#"{{"faces": [{{{surface}, "loops": [{{"curves": [{{"degree": 1, "knots": [0,0,1,1], "points": [[0,0],[1,1]], "weights": [1,-1]}}]}}]}}]}}"#
            ),
            "face 0 loop 0 curve 0 weights",
        ),
        (
            r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [[-1e308,-1e308,1e308,1e308],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}}]}"#.into(),
            "face 0 surface knots",
        ),
    ];
    for (text, expected) in cases {
        let err = read_json(text.as_bytes()).unwrap_err();
        assert_eq!(location(&err), expected, "{text}\n{err}");
    }
}

#[test]
fn reader_rejects_unknown_fields_and_wrong_types() {
    for text in [
        r#"{"faces": [], "extra": 1}"#,
        r#"{"faces": [{"surface": {"degree": [1, 1], "knots": [], "points": [], "weigths": []}}]}"#,
        r#"{"faces": [{"surface": {"degree": [-1, 1], "knots": [], "points": []}}]}"#,
        r#"{"faces": {}}"#,
        "",
        "{} trailing",
    ] {
        let err = read_json(text.as_bytes()).unwrap_err();
        assert!(matches!(err, Error::Json { line: 1, .. }), "{text}: {err:?}");
    }
}

#[test]
fn reader_limits_the_number_of_faces() {
    let face = r#"{"surface": {"degree": [1, 1], "knots": [[0,0,1,1],[0,0,1,1]], "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]}}"#;
    let text = format!(r#"{{"faces": [{}]}}"#, vec![face; 100_001].join(","));
    let err = read_json(text.as_bytes()).unwrap_err();
    assert!(matches!(&err, Error::Limit(m) if m.contains("100000")), "{err}");
}

#[test]
fn reader_limits_control_points_per_surface() {
    // 1001 × 1000 control points, one more row than the limit allows.
    let row = format!("[{}]", vec!["[0,0,0]"; 1000].join(","));
    let knots = |n: usize| format!("[0,{},{n}]", (0..n).map(|k| k.to_string()).collect::<Vec<_>>().join(","));
    let text = format!(
        r#"{{"faces": [{{"surface": {{"degree": [1, 1], "knots": [{}, {}], "points": [{}]}}}}]}}"#,
        knots(1000),
        knots(999),
        vec![row.as_str(); 1001].join(",")
    );
    let err = read_json(text.as_bytes()).unwrap_err();
    assert!(matches!(&err, Error::Limit(m) if m.contains("face 0") && m.contains("1000000")), "{err}");
}

/// A one-face model whose first control point's x is written as `x`.
fn model_with_x(x: &str) -> String {
    format!(
        r#"{{"faces": [{{"name": "caf\u00e9 \ud83d\ude00", "surface": {{"degree": [1, 1],
        "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[[{x}, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]]}}}}]}}"#
    )
}

#[test]
fn reader_reads_numbers_correctly_rounded() {
    // Shortest round-trip forms (as JavaScript and Rust print doubles): each
    // must read back as the very double printed. serde_json's default float
    // parser read these one unit in the last place off.
    for x in [1.8138734630502207_f64, 9.798104955800099, 3.9030933678265853, 1.9243053591130521, 4.724074003728306e-35]
    {
        let model = read_json(model_with_x(&x.to_string()).as_bytes()).unwrap();
        let surfmesh::FaceSurface::Nurbs(s) = &model.faces[0].surface else { panic!("not a NURBS face") };
        let first = s.control_points().next().unwrap();
        assert_eq!(first.x.to_bits(), x.to_bits(), "{x} read as {}", first.x);
        assert_eq!(model.faces[0].name.as_deref(), Some("caf\u{e9} \u{1f600}"));
    }
}

#[test]
fn reader_rejects_what_json_or_the_schema_does_not_allow() {
    let good = model_with_x("0");
    assert!(read_json(good.as_bytes()).is_ok());
    for (bad, line, word) in [
        (good.replace(r#""degree": [1, 1]"#, r#""degree": [1.0, 1]"#), 1, "integer"),
        (good.replace(r#""degree": [1, 1],"#, r#""degree": [1, 1], "degree": [1, 1],"#), 1, "duplicate"),
        (good.replace(r#""degree": [1, 1],"#, ""), 2, "missing field `degree`"),
        (good.replace("[[[0, 0, 0]", "[[[01, 0, 0]"), 2, "number"),
        (good.replace("[[[0, 0, 0]", "[[[-, 0, 0]"), 2, "number"),
        (good.replace("[[[0, 0, 0]", "[[[1e400, 0, 0]"), 2, "out of range"),
        (good.replace("[[[0, 0, 0]", "[[[0, 0, 0],]"), 2, "expected"),
        (good.replace("caf", "\tcaf"), 1, "control character"),
        (good.replace(r"\u00e9", r"\u00g9"), 1, "unicode"),
        (good[..good.len() - 2].to_string(), 2, "EOF"),
    ] {
        let err = read_json(bad.as_bytes()).unwrap_err();
        let Error::Json { line: at, message, .. } = &err else { panic!("{bad}: {err:?}") };
        assert_eq!(*at, line, "{bad}: {message}");
        assert!(message.contains(word), "{bad}: {message}");
    }
}

// ---------------------------------------------------------------- writers

/// A unit square in the z = 0 plane split into two triangles, one per face,
/// with +z normals.
fn square() -> Mesh {
    Mesh {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.5),
        ],
        normals: vec![DVec3::Z; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        face_ranges: vec![FaceRange { first: 0, count: 1 }, FaceRange { first: 1, count: 1 }],
    }
}

fn f32_at(bytes: &[u8], offset: usize) -> f32 {
    f32::from_le_bytes(bytes[offset..offset + 4].try_into().unwrap())
}

fn u32_at(bytes: &[u8], offset: usize) -> u32 {
    u32::from_le_bytes(bytes[offset..offset + 4].try_into().unwrap())
}

#[test]
fn stl_has_header_count_and_facets() {
    let mesh = square();
    let stl = write_stl(&mesh);
    assert_eq!(stl.len(), 84 + 50 * 2);
    assert!(!stl.starts_with(b"solid"), "binary STL must not look like ASCII STL");
    assert_eq!(u32_at(&stl, 80), 2);
    // First facet: normal +z, then vertices 0, 1, 2.
    let facet: Vec<f32> = (0..12).map(|k| f32_at(&stl, 84 + 4 * k)).collect();
    assert_eq!(facet, [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0]);
    assert_eq!(&stl[84 + 48..84 + 50], &[0, 0]);
    // Second facet's normal is the unit normal of its tilted plane.
    let n = DVec3::new(1.0, 1.0, 0.0).cross(DVec3::new(0.0, 1.0, 0.5)).normalize();
    for k in 0..3 {
        assert!((f64::from(f32_at(&stl, 134 + 4 * k)) - n[k]).abs() < 1e-6);
    }
}

#[test]
fn stl_skips_triangles_with_bad_indices() {
    let mut mesh = square();
    mesh.indices.extend([0, 1, 9]);
    let stl = write_stl(&mesh);
    assert_eq!(u32_at(&stl, 80), 2);
    assert_eq!(stl.len(), 84 + 50 * 2);
}

#[test]
fn obj_has_vertices_normals_faces_and_groups() {
    let obj = String::from_utf8(write_obj(&square())).unwrap();
    let count = |prefix: &str| obj.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("v "), 4);
    assert_eq!(count("vn "), 4);
    assert_eq!(count("f "), 2);
    assert_eq!(count("g "), 2);
    let faces: Vec<&str> = obj.lines().filter(|l| l.starts_with("f ")).collect();
    assert_eq!(faces, ["f 1//1 2//2 3//3", "f 1//1 3//3 4//4"]);
    let last_v = obj.lines().filter(|l| l.starts_with("v ")).nth(3).unwrap();
    let xyz: Vec<f64> = last_v[2..].split(' ').map(|x| x.parse().unwrap()).collect();
    assert_eq!(xyz, [0.0, 1.0, 0.5]);
}

#[test]
fn obj_without_normals_writes_plain_faces() {
    let mut mesh = square();
    mesh.normals.clear();
    mesh.face_ranges.clear();
    let obj = String::from_utf8(write_obj(&mesh)).unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("vn")).count(), 0);
    assert_eq!(obj.lines().filter(|l| l.starts_with("g ")).count(), 1);
    assert!(obj.lines().any(|l| l == "f 1 3 4"));
}

/// Splits a GLB into its JSON document and BIN chunk, checking the container.
fn open_glb(glb: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(u32_at(glb, 4), 2);
    assert_eq!(u32_at(glb, 8) as usize, glb.len());
    let json_len = u32_at(glb, 12) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let doc: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let rest = &glb[20 + json_len..];
    if rest.is_empty() {
        return (doc, Vec::new());
    }
    let bin_len = u32_at(rest, 0) as usize;
    assert_eq!(&rest[4..8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(rest.len(), 8 + bin_len);
    (doc, rest[8..].to_vec())
}

#[test]
fn glb_is_a_valid_container_with_matching_accessors() {
    let mesh = square();
    let (doc, bin) = open_glb(&write_glb(&mesh));
    assert_eq!(doc["asset"]["version"], "2.0");
    assert_eq!(doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin.len());
    let accessors = doc["accessors"].as_array().unwrap();
    let views = doc["bufferViews"].as_array().unwrap();
    let prims = doc["meshes"][0]["primitives"].as_array().unwrap();
    assert_eq!(prims.len(), 2);
    for view in views {
        let end = view["byteOffset"].as_u64().unwrap() + view["byteLength"].as_u64().unwrap();
        assert!(end as usize <= bin.len());
    }
    // Positions: count, min/max and the values themselves.
    let pos = &accessors[prims[0]["attributes"]["POSITION"].as_u64().unwrap() as usize];
    assert_eq!(pos["count"], 4);
    assert_eq!(pos["min"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(pos["max"], serde_json::json!([1.0, 1.0, 0.5]));
    let pos_view = &views[pos["bufferView"].as_u64().unwrap() as usize];
    let start = pos_view["byteOffset"].as_u64().unwrap() as usize;
    for (k, p) in mesh.positions.iter().enumerate() {
        for c in 0..3 {
            assert_eq!(f64::from(f32_at(&bin, start + 12 * k + 4 * c)), p[c]);
        }
    }
    let normal = &accessors[prims[0]["attributes"]["NORMAL"].as_u64().unwrap() as usize];
    assert_eq!(normal["count"], 4);
    // Indices: one accessor per face, together the mesh's index list.
    let mut indices = Vec::new();
    for prim in prims {
        let acc = &accessors[prim["indices"].as_u64().unwrap() as usize];
        assert_eq!(acc["componentType"], 5125);
        assert_eq!(acc["count"], 3);
        let view = &views[acc["bufferView"].as_u64().unwrap() as usize];
        let offset = (view["byteOffset"].as_u64().unwrap() + acc["byteOffset"].as_u64().unwrap()) as usize;
        assert_eq!(offset % 4, 0);
        indices.extend((0..3).map(|k| u32_at(&bin, offset + 4 * k)));
    }
    assert_eq!(indices, mesh.indices);
}

#[test]
fn glb_of_an_empty_mesh_is_valid_and_has_no_buffers() {
    let (doc, bin) = open_glb(&write_glb(&Mesh::default()));
    assert!(bin.is_empty());
    assert_eq!(doc["asset"]["version"], "2.0");
    assert!(doc.get("buffers").is_none() && doc.get("accessors").is_none());
}

// ---------------------------------------------------------------- command line

/// Runs `surfmesh mesh` on a bad input with every output requested; checks
/// exit 1, one stderr line naming the file and `needles`, and no files left.
fn assert_rejected(input: &str, needles: &[&str]) {
    let dir = scratch(input);
    let (out_path, report_path) = (dir.join("out.stl"), dir.join("report.json"));
    let out = run(&[
        "mesh".as_ref(),
        data(input).as_os_str(),
        "-o".as_ref(),
        out_path.as_os_str(),
        "--report".as_ref(),
        report_path.as_os_str(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("surfmesh: ") && err.contains(input), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} missing in {err}");
    }
    assert!(out.stdout.is_empty());
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_rejects_malformed_json() {
    assert_rejected("bad_syntax.json", &["line 3", "column 37"]);
}

#[test]
fn cli_rejects_short_knot_vector() {
    assert_rejected("bad_knots_short.json", &["face 0", "knots[0]", "too short"]);
}

#[test]
fn cli_rejects_decreasing_knots() {
    assert_rejected("bad_knots_decreasing.json", &["face 1", "knots[1]", "decrease"]);
}

#[test]
fn cli_rejects_zero_weight() {
    assert_rejected("bad_weight_zero.json", &["face 0", "weights"]);
}

#[test]
fn cli_rejects_out_of_range_number() {
    assert_rejected("bad_not_finite.json", &["line 7", "out of range"]);
}

#[test]
fn cli_rejects_open_loop() {
    assert_rejected("bad_loop_open.json", &["face 0", "loop 0", "curve 2", "does not close"]);
}

#[test]
fn cli_rejects_loop_point_with_three_coordinates() {
    assert_rejected("bad_loop_point.json", &["face 0", "loop 0", "curve 1", "points[0]"]);
}

/// Holes that cross are mended to their union: the file meshes, and the
/// report's warning names the face.
#[test]
fn cli_mends_crossing_loops() {
    let dir = scratch("mend");
    let (out_path, report_path) = (dir.join("out.stl"), dir.join("report.json"));
    let input = data("bad_loops_cross.json");
    let args = ["mesh".as_ref(), input.as_os_str(), "-o".as_ref(), out_path.as_os_str()];
    let out = run(&[&args[..], &["--report".as_ref(), report_path.as_os_str()]].concat());
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&report_path).unwrap()).unwrap();
    let warnings = report["warnings"].as_array().expect("warnings");
    assert!(
        warnings.iter().any(|w| w.as_str().is_some_and(|w| w.starts_with("face 0: trim loops crossed"))),
        "{warnings:?}"
    );
    assert_eq!(report["faces_skipped"], 0);
    assert!(report["max_deviation"].as_f64().unwrap() <= report["tolerance"].as_f64().unwrap());
}

#[test]
fn cli_failure_keeps_an_existing_output() {
    let dir = scratch("keep");
    let out_path = dir.join("out.obj");
    std::fs::write(&out_path, b"previous").unwrap();
    let out = run(&["mesh".as_ref(), data("bad_weight_zero.json").as_os_str(), "-o".as_ref(), out_path.as_os_str()]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read(&out_path).unwrap(), b"previous");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_names_a_missing_file() {
    let out = run(&["mesh".as_ref(), data("no_such_file.json").as_os_str()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("no_such_file.json") && err.contains("cannot read"), "{err}");
}

#[test]
fn cli_usage_errors_exit_2() {
    let plane = data("plane.json");
    let p = plane.to_str().unwrap();
    for (args, needle) in [
        (vec![], "no command"),
        (vec!["frobnicate"], "unknown command"),
        (vec!["mesh"], "INPUT"),
        (vec!["mesh", p, "--bogus"], "--bogus"),
        (vec!["mesh", p, "--tol"], "--tol needs a value"),
        (vec!["mesh", p, "--tol", "abc"], "not a number"),
        (vec!["mesh", p, "--tol", "-1"], "--tol"),
        (vec!["mesh", p, "--tol", "0.1", "--tol-rel", "0.01"], "not both"),
        (vec!["mesh", p, "--angle", "7"], "--angle"),
        (vec!["mesh", p, "--size", "2"], "need --mode quality"),
        (vec!["mesh", p, "--mode", "quality", "--size", "0"], "--size"),
        (vec!["mesh", p, "--mode", "quality", "--size", "1", "--size-rel", "0.1"], "not both"),
        (vec!["mesh", p, "--mode", "quality", "--method", "fancy"], "--method must be"),
        (vec!["mesh", p, "--mode", "quality", "--weights", "1,2,3"], "four numbers"),
        (vec!["mesh", p, "--mode", "slow"], "--mode"),
        (vec!["mesh", p, "--reparam", "sometimes"], "--reparam must be auto, off or force"),
        (vec!["mesh", p, "--format", "dxf"], "--format"),
        (vec!["mesh", p, "-o", "out.ply"], ".stl, .obj, .glb, .msh or .unv"),
        (vec!["mesh", p, p], "more than one input"),
    ] {
        let out = Command::new(BIN).args(&args).output().unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("surfmesh: ") && err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn cli_help_prints_usage() {
    let out = Command::new(BIN).arg("--help").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for option in ["mesh INPUT", "--tol", "--tol-rel", "--angle", "--max-edge", "-o", "--report"] {
        assert!(text.contains(option), "{option} missing from usage");
    }
}

// ---------------------------------------------------------------- command line, success

const REPORT_FIELDS: [&str; 15] = [
    "units",
    "tolerance",
    "faces",
    "faces_unread",
    "triangles",
    "vertices",
    "max_deviation",
    "mean_deviation",
    "min_angle_deg",
    "free_edges",
    "nonmanifold_edges",
    "inverted_triangles",
    "time_ms",
    "parse_ms",
    "warnings",
];

/// Checks the report has DESIGN.md's fields and a deviation within tolerance; returns it.
fn check_report(text: &[u8]) -> Value {
    let report: Value = serde_json::from_slice(text).unwrap();
    for field in REPORT_FIELDS {
        assert!(report.get(field).is_some(), "report lacks {field}: {report}");
    }
    let num = |f: &str| report[f].as_f64().unwrap();
    assert!(num("tolerance") > 0.0);
    assert!(num("max_deviation") <= num("tolerance"), "{report}");
    assert!(num("mean_deviation") <= num("max_deviation"));
    assert!(num("triangles") >= 1.0);
    assert!(num("time_ms") >= 0.0 && num("parse_ms") >= 0.0);
    assert!(report["warnings"].is_array());
    report
}

fn mesh_ok(args: &[&std::ffi::OsStr]) -> Output {
    let out = run(args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    out
}

#[test]
fn cli_meshes_the_plane_to_every_format() {
    let dir = scratch("plane");
    let plane = data("plane.json");
    let mut triangles = None;
    for ext in ["stl", "obj", "glb"] {
        let (out_path, report_path) = (dir.join(format!("plane.{ext}")), dir.join(format!("{ext}.json")));
        let out = mesh_ok(&[
            "mesh".as_ref(),
            plane.as_os_str(),
            "--tol".as_ref(),
            "0.01".as_ref(),
            "-o".as_ref(),
            out_path.as_os_str(),
            "--report".as_ref(),
            report_path.as_os_str(),
        ]);
        assert!(out.stdout.is_empty(), "report printed although --report was given");
        let err = stderr(&out);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("triangles") && err.contains("plane.json"), "{err}");
        let report = check_report(&std::fs::read(&report_path).unwrap());
        assert_eq!(report["tolerance"], 0.01);
        assert_eq!(report["faces"], 1);
        assert_eq!(report["free_edges"], 0);
        assert_eq!(report["nonmanifold_edges"], 0);
        assert_eq!(report["inverted_triangles"], 0);
        let n = report["triangles"].as_u64().unwrap() as usize;
        assert_eq!(*triangles.get_or_insert(n), n, "same input, same mesh");
        let bytes = std::fs::read(&out_path).unwrap();
        match ext {
            "stl" => {
                assert_eq!(bytes.len(), 84 + 50 * n);
                assert_eq!(u32_at(&bytes, 80) as usize, n);
            }
            "obj" => {
                let text = String::from_utf8(bytes).unwrap();
                assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), n);
                let v = text.lines().filter(|l| l.starts_with("v ")).count();
                assert_eq!(v as u64, report["vertices"].as_u64().unwrap());
            }
            _ => {
                let (doc, _) = open_glb(&bytes);
                let accessors = doc["accessors"].as_array().unwrap();
                let prims = doc["meshes"][0]["primitives"].as_array().unwrap();
                let indices: u64 = prims
                    .iter()
                    .map(|p| accessors[p["indices"].as_u64().unwrap() as usize]["count"].as_u64().unwrap())
                    .sum();
                assert_eq!(indices as usize, 3 * n);
            }
        }
    }
    // Only the requested files, no temporaries left.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 6);
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--units` scales the mesh and the report's lengths from the file's unit
/// (the box is 2 × 1 × 0.5 inches) and names the unit; the GLB is in metres
/// whatever the unit of the mesh, as glTF defines its lengths.
#[test]
fn cli_units_scale_the_mesh_and_the_glb_is_in_metres() {
    let dir = scratch("units");
    let input = data("step_box_inch.stp");
    let mut runs = Vec::new();
    for units in ["file", "mm", "m"] {
        let (stl, glb, rep) = (dir.join(format!("{units}.stl")), dir.join(format!("{units}.glb")), dir.join("r.json"));
        for out in [&stl, &glb] {
            let os = |s: &'static str| std::ffi::OsStr::new(s);
            let mut args = vec![os("mesh"), input.as_os_str(), os("--tol-rel"), os("0.01"), os("-o"), out.as_os_str()];
            args.extend([os("--report"), rep.as_os_str()]);
            if units != "file" {
                args.extend([os("--units"), os(units)]);
            }
            mesh_ok(&args);
        }
        let report = check_report(&std::fs::read(&rep).unwrap());
        // Binary STL: the mesh's own coordinates, in the unit asked for.
        let bytes = std::fs::read(&stl).unwrap();
        let n = u32_at(&bytes, 80) as usize;
        let mut max = [f32::NEG_INFINITY; 3];
        for t in 0..n {
            for v in 0..3 {
                for (k, m) in max.iter_mut().enumerate() {
                    let at = 84 + 50 * t + 12 + 12 * v + 4 * k;
                    *m = m.max(f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()));
                }
            }
        }
        let (doc, _) = open_glb(&std::fs::read(&glb).unwrap());
        let glb_max: Vec<f64> =
            doc["accessors"][0]["max"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        runs.push((units, report, max, glb_max));
    }
    let inch_mm = 25.4;
    for (units, report, max, glb_max) in &runs {
        let (name, per_inch) = match *units {
            "file" => ("in", 1.0),
            "mm" => ("mm", inch_mm),
            _ => ("m", inch_mm / 1000.0),
        };
        assert_eq!(report["units"], name, "{units}");
        for (k, size) in [2.0, 1.0, 0.5].iter().enumerate() {
            let want = size * per_inch;
            assert!((max[k] as f64 - want).abs() <= 1e-6 * want, "{units}: box corner {k} at {} not {want}", max[k]);
            let metres = size * inch_mm / 1000.0;
            assert!((glb_max[k] - metres).abs() <= 1e-6 * metres, "{units}: GLB corner {k} at {} m", glb_max[k]);
        }
        // The tolerance scales with the mesh: the same relative tolerance of the same box.
        let tol_in = runs[0].1["tolerance"].as_f64().unwrap();
        let tol = report["tolerance"].as_f64().unwrap();
        assert!((tol - tol_in * per_inch).abs() <= 1e-9 * tol, "{units}: tolerance {tol}");
        assert_eq!(report["triangles"], runs[0].1["triangles"], "{units}: the same mesh, scaled");
    }
    let bad = run(&["mesh".as_ref(), input.as_os_str(), "--units".as_ref(), "yd".as_ref()]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("option units: expected"), "{}", stderr(&bad));
    std::fs::remove_dir_all(dir).unwrap();
}

/// `check` meshes every model file of a folder (and its folders, not hidden
/// ones; notes such as SOURCES.md are not models), one row per file sorted
/// by name: a file that fails has its error in its row and makes the exit
/// status 1; a face the reader could not build counts among the file's
/// faces, and the edges left open along it as cracks.
#[test]
fn cli_check_sweeps_a_folder_into_rows() {
    let dir = scratch("check");
    let models = dir.join("models");
    std::fs::create_dir_all(models.join("sub")).unwrap();
    std::fs::create_dir_all(models.join(".hidden")).unwrap();
    for (from, to) in [
        ("plane.json", "b_plane.json"),
        ("step_bad_face.stp", "a_box.stp"),
        ("bad_syntax.json", "c_bad.json"),
        ("iges_plate.igs", "sub/plate.igs"),
        ("plane.json", ".hidden/plane.json"),
        ("plane.json", ".dot.json"),
    ] {
        std::fs::copy(data(from), models.join(to)).unwrap();
    }
    // No extension: found by its first bytes; a note is not a model.
    std::fs::copy(data("step_box_inch.stp"), models.join("BOX")).unwrap();
    std::fs::write(models.join("SOURCES.md"), "# where the files come from\n").unwrap();
    let json = dir.join("rows.json");
    let os = |s: &'static str| std::ffi::OsStr::new(s);
    let out = run(&[os("check"), models.as_os_str(), os("--tol-rel"), os("0.01"), os("--json"), json.as_os_str()]);
    assert_eq!(out.status.code(), Some(1), "one file fails: {}", stderr(&out));
    let table = String::from_utf8(out.stdout).unwrap();
    let sweep: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(sweep["tolerance"], "relative 0.01");
    let rows = sweep["files"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["file"].as_str().unwrap()).collect();
    assert_eq!(names, ["BOX", "a_box.stp", "b_plane.json", "c_bad.json", "sub/plate.igs"], "{table}");
    let row = |name: &str| rows.iter().find(|r| r["file"] == name).unwrap();
    let bad = row("c_bad.json");
    assert_eq!(bad["ok"], false);
    assert!(bad["error"].as_str().unwrap().starts_with("JSON line 3"), "{bad}");
    assert!(table.lines().any(|l| l.starts_with("c_bad.json") && l.contains("ERROR JSON line 3")), "{table}");
    let open_box = row("a_box.stp");
    assert_eq!((open_box["faces_in_file"].as_u64(), open_box["faces_meshed"].as_u64()), (Some(6), Some(5)));
    assert_eq!(open_box["faces_unread"], 1);
    assert!(open_box["cracks"].as_u64().unwrap() >= 4, "{open_box}");
    assert!(open_box["first_warning"].as_str().unwrap().starts_with("#53 ADVANCED_FACE: skipped"), "{open_box}");
    let whole = row("BOX");
    assert_eq!((whole["ok"].as_bool(), whole["faces_meshed"].as_u64()), (Some(true), Some(6)));
    assert_eq!((whole["cracks"].as_u64(), whole["units"].as_str()), (Some(0), Some("in")));
    for r in rows.iter().filter(|r| r["ok"] == true) {
        assert!(r["deviation_ratio"].as_f64().unwrap() <= 1.0, "{r}");
        assert!(r["tolerance"].as_f64().unwrap() > 0.0 && r["time_ms"].as_f64().unwrap() >= 0.0, "{r}");
    }
    let totals = table.lines().last().unwrap();
    assert!(totals.starts_with("total: 5 files, 4 meshed, 1 failed; faces 14/15 (1 unread, 0 empty)"), "{totals}");
    // Every file meshing: exit status 0.
    std::fs::remove_file(models.join("c_bad.json")).unwrap();
    let out = run(&[os("check"), models.as_os_str(), os("--tol-rel"), os("0.01"), os("--jobs"), os("1")]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // Usage errors: exit status 2.
    assert_eq!(run(&[os("check")]).status.code(), Some(2));
    assert_eq!(run(&[os("check"), models.as_os_str(), os("--timeout"), os("0")]).status.code(), Some(2));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_prints_the_report_without_outputs_and_honours_tol_rel() {
    let out = mesh_ok(&["mesh".as_ref(), data("plane.json").as_os_str(), "--tol-rel".as_ref(), "0.001".as_ref()]);
    let report = check_report(&out.stdout);
    // The plate is 10 × 10: its diagonal is 10·√2.
    let expected = 0.001 * 10.0 * 2f64.sqrt();
    assert!((report["tolerance"].as_f64().unwrap() - expected).abs() < 1e-9 * expected, "{report}");
}

#[test]
fn cli_meshes_a_trimmed_face_with_a_hole() {
    let dir = scratch("twisted");
    let out_path = dir.join("twisted.obj");
    let out = mesh_ok(&[
        "mesh".as_ref(),
        data("twisted.json").as_os_str(),
        "--tol".as_ref(),
        "0.1".as_ref(),
        "-o".as_ref(),
        out_path.as_os_str(),
    ]);
    assert!(out.stdout.is_empty());
    // The hole, as a fine polygon in (u,v) from the model's own trim curves.
    let model = read_data("twisted.json").unwrap();
    let hole: Vec<glam::DVec2> = model.faces[0].loops[1]
        .curves
        .iter()
        .flat_map(|c| {
            let (a, b) = c.domain();
            (0..500).map(move |k| c.point(a + (b - a) * f64::from(k) / 500.0).truncate())
        })
        .collect();
    let obj = String::from_utf8(std::fs::read(&out_path).unwrap()).unwrap();
    let mut uvs = Vec::new();
    for line in obj.lines().filter(|l| l.starts_with("v ")) {
        let p: Vec<f64> = line[2..].split(' ').map(|x| x.parse().unwrap()).collect();
        // On this patch x = 10u and y = 10v.
        let uv = glam::DVec2::new(p[0] / 10.0, p[1] / 10.0);
        assert!(!strictly_inside(&hole, uv, 1e-4), "vertex {p:?} lies in the hole");
        uvs.push(uv);
    }
    // The triangles cover the unit square minus the hole, and not a point deep inside it.
    let cross = |a: glam::DVec2, b: glam::DVec2| a.perp_dot(b);
    let probe = glam::DVec2::new(0.6, 0.35);
    let mut area = 0.0;
    for line in obj.lines().filter(|l| l.starts_with("f ")) {
        let t: Vec<glam::DVec2> =
            line[2..].split(' ').map(|v| uvs[v.split("//").next().unwrap().parse::<usize>().unwrap() - 1]).collect();
        let twice = cross(t[1] - t[0], t[2] - t[0]);
        area += twice / 2.0;
        let sides = [0, 1, 2].map(|k| cross(t[(k + 1) % 3] - t[k], probe - t[k]) * twice.signum());
        assert!(sides.iter().any(|&s| s < 0.0), "triangle {t:?} covers the hole");
    }
    let hole_area: f64 = (0..hole.len()).map(|k| cross(hole[k], hole[(k + 1) % hole.len()]) / 2.0).sum();
    let expected = 1.0 - hole_area.abs();
    assert!((area.abs() - expected).abs() < 0.01 * expected, "area {area}, expected {expected}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_detects_the_format_without_an_extension() {
    let dir = scratch("detect");
    let input = dir.join("model.data");
    std::fs::copy(data("plane.json"), &input).unwrap();
    let out = mesh_ok(&["mesh".as_ref(), input.as_os_str()]);
    check_report(&out.stdout);
    let out = mesh_ok(&["mesh".as_ref(), input.as_os_str(), "--format".as_ref(), "json".as_ref()]);
    check_report(&out.stdout);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_meshes_step_by_extension_content_and_name() {
    let dir = scratch("step");
    let input = dir.join("cylinder.data");
    std::fs::copy(data("step_cylinder.stp"), &input).unwrap();
    let named = data("step_cylinder.stp");
    for args in [
        vec!["mesh".as_ref(), named.as_os_str()],
        vec!["mesh".as_ref(), input.as_os_str()],
        vec!["mesh".as_ref(), input.as_os_str(), "--format".as_ref(), "stp".as_ref()],
    ] {
        let out = mesh_ok(&args);
        let r = check_report(&out.stdout);
        assert_eq!(r["faces"], 3);
        assert_eq!(r["boundary_edges"], 0);
    }
    // Tessellated faces: counted in the report, and the summary line says
    // they are not verified.
    let out = mesh_ok(&["mesh".as_ref(), data("step_tess_mixed.stp").as_os_str()]);
    let r = check_report(&out.stdout);
    assert_eq!((r["faces"].as_u64(), r["faces_tessellated"].as_u64()), (Some(2), Some(1)));
    assert!(stderr(&out).contains("(1 tessellated face not verified)"), "{}", stderr(&out));
    let out = run(&["mesh".as_ref(), data("step_unclosed_string.stp").as_os_str()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("STEP line 10, #7: string not closed by a quote"), "{}", stderr(&out));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn cli_writes_nothing_when_one_output_fails() {
    let dir = scratch("all-or-nothing");
    let out_path = dir.join("out.stl");
    let report_path = dir.join("missing-dir").join("report.json");
    let out = run(&[
        "mesh".as_ref(),
        data("plane.json").as_os_str(),
        "-o".as_ref(),
        out_path.as_os_str(),
        "--report".as_ref(),
        report_path.as_os_str(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cannot write") && err.contains("report.json"), "{err}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "output written although the report failed");
    std::fs::remove_dir_all(dir).unwrap();
}

/// An output that is a pipe (as `/dev/null` and `/dev/stdout` are devices)
/// is written into, never renamed over: a rename would swap the device for a
/// plain file, and a later reader of `/dev/null` would read text. A symbolic
/// link stays a link and its target gets the mesh.
#[cfg(unix)]
#[test]
fn cli_writes_into_pipes_and_through_links() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("special-outputs");
    let fifo = dir.join("pipe.stl");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let target = dir.join("target.obj");
    std::fs::write(&target, b"old").unwrap();
    let link = dir.join("link.obj");
    std::os::unix::fs::symlink(&target, &link).unwrap();

    let out = run(&["mesh".as_ref(), data("plane.json").as_os_str(), "-o".as_ref(), fifo.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    let bytes = reader.join().unwrap();
    // Binary STL: an 80-byte header, a triangle count, 50 bytes per triangle.
    assert!(bytes.len() > 84, "the pipe got {} bytes", bytes.len());
    let count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert!(count > 0 && bytes.len() == 84 + 50 * count, "the pipe got {} bytes", bytes.len());

    let out = run(&["mesh".as_ref(), data("plane.json").as_os_str(), "-o".as_ref(), link.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    let obj = std::fs::read_to_string(&target).unwrap();
    assert!(obj.lines().any(|l| l.starts_with("f ")), "the link's target holds no faces");
    // Nothing but the three names: no temporary file left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Whether `p` lies inside the closed polygon and farther than `margin` from its edges.
fn strictly_inside(polygon: &[glam::DVec2], p: glam::DVec2, margin: f64) -> bool {
    let mut inside = false;
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        if p.distance(a + (b - a) * t) <= margin {
            return false;
        }
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Two processes meshing the same file write the same bytes. trj7's grid
/// cells are cocircular in many places, where the triangulation's insertion
/// order picks the diagonal; that order once came from a hash set seeded
/// afresh in each process, and each run wrote another OBJ.
#[test]
fn two_runs_write_the_same_mesh() {
    let file = crate::corpus_files::corpus_path("trj7_b1-ec-214.stp");
    let dir = scratch("two-runs");
    let outs: Vec<PathBuf> = (0..2).map(|i| dir.join(format!("run{i}.obj"))).collect();
    // Both processes at once: a debug build takes a while on this file.
    let spawned: Vec<_> = outs
        .iter()
        .map(|o| {
            Command::new(BIN)
                .args([std::ffi::OsStr::new("mesh"), file.as_os_str(), "-o".as_ref(), o.as_os_str()])
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let children: Vec<Output> = spawned.into_iter().map(|c| c.wait_with_output().unwrap()).collect();
    for c in &children {
        assert!(c.status.success(), "{}", stderr(c));
    }
    let (a, b) = (std::fs::read(&outs[0]).unwrap(), std::fs::read(&outs[1]).unwrap());
    assert!(a.len() > 100_000, "trj7's OBJ is {} bytes", a.len());
    assert!(a == b, "two runs on trj7 wrote different meshes");
}
