//! The JS binding (`src/wasm.rs`) in headless Node, through wasm-bindgen-test:
//! `cargo test --target wasm32-unknown-unknown --test wasm_node`.
//!
//! `src/wasm.rs` is compiled into this test a second time (its module is
//! private to the library); there `cfg(test)` leaves the JS exports off so the
//! two copies do not clash. The calls below are the same Rust functions the
//! exports wrap, returning the same JS values and `Error` objects.
#![cfg(all(target_arch = "wasm32", target_os = "unknown"))]

extern crate alloc;

// Names `src/wasm.rs` reaches through `crate::`.
#[allow(unused_imports)]
use surfmesh::{
    edge_lines, fit_points, flatten, mesh_instanced, mesh_model, mm_per_unit, offset_mesh, read_mesh, read_model,
    read_points, read_step_parts, repair_mesh_timed, Assembly, Bucketing, EdgeLines, Error, FitOptions, FitReport,
    FitResult, Format, InstancedResult, Mesh, MeshFormat, MeshMode, MeshOptions, OptionsError, PointFormat,
    QualityMethod, RepairOptions, RepairReport, Report, Units,
};

#[path = "../src/wasm.rs"]
mod binding;

use js_sys::{Array, Float32Array, Object, Reflect, Uint32Array};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

/// The bundled freeform patch (bicubic, non-uniform knots, wavy z), 100 × 100 mm.
const FREEFORM: &[u8] = include_bytes!("data/js_freeform.json");

/// What `mesh` returned, copied out of the typed arrays.
struct Output {
    positions: Vec<f32>,
    normals: Vec<f32>,
    indices: Vec<u32>,
    face_ranges: Vec<u32>,
    report: JsValue,
}

impl Output {
    fn number(&self, field: &str) -> f64 {
        let v = Reflect::get(&self.report, &field.into()).expect("report field");
        v.as_f64().unwrap_or_else(|| panic!("report.{field} is not a number: {v:?}"))
    }

    fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    fn vertex(&self, i: u32) -> [f64; 3] {
        let i = 3 * i as usize;
        [self.positions[i] as f64, self.positions[i + 1] as f64, self.positions[i + 2] as f64]
    }

    fn longest_edge(&self) -> f64 {
        let mut longest: f64 = 0.0;
        for t in self.indices.chunks(3) {
            for k in 0..3 {
                let (a, b) = (self.vertex(t[k]), self.vertex(t[(k + 1) % 3]));
                let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                longest = longest.max(d);
            }
        }
        longest
    }

    fn bbox_diagonal(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.positions.chunks(3) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f64);
                hi[k] = hi[k].max(p[k] as f64);
            }
        }
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
    }
}

/// A JS options object from name/value pairs.
fn options(pairs: &[(&str, JsValue)]) -> JsValue {
    let o = Object::new();
    for (k, v) in pairs {
        Reflect::set(&o, &(*k).into(), v).expect("set option");
    }
    o.into()
}

fn num(x: f64) -> JsValue {
    JsValue::from_f64(x)
}

/// `opts` with `flatten: true` added (the one merged mesh these tests read)
/// unless it says otherwise; anything but an object or undefined as it is.
fn flat(opts: JsValue) -> JsValue {
    if opts.is_undefined() {
        return options(&[("flatten", true.into())]);
    }
    let has = Reflect::has(&opts, &"flatten".into()).unwrap_or(true);
    if opts.is_object() && !Array::is_array(&opts) && !has {
        Reflect::set(&opts, &"flatten".into(), &true.into()).expect("set flatten");
    }
    opts
}

/// Calls the binding (flattened); on failure checks that what it throws is a JS `Error` and returns its message.
fn call(bytes: &[u8], format: &str, opts: JsValue) -> Result<Output, String> {
    match binding::mesh(bytes.to_vec(), format, flat(opts)) {
        Ok(v) => {
            let get = |name: &str| Reflect::get(&v, &name.into()).expect("result field");
            Ok(Output {
                positions: get("positions").dyn_into::<Float32Array>().expect("positions").to_vec(),
                normals: get("normals").dyn_into::<Float32Array>().expect("normals").to_vec(),
                indices: get("indices").dyn_into::<Uint32Array>().expect("indices").to_vec(),
                face_ranges: get("faceRanges").dyn_into::<Uint32Array>().expect("faceRanges").to_vec(),
                report: get("report"),
            })
        }
        Err(e) => {
            let value = JsValue::from(e);
            assert!(value.is_instance_of::<js_sys::Error>(), "thrown value is not an Error: {value:?}");
            Err(value.unchecked_into::<js_sys::Error>().message().into())
        }
    }
}

fn ok(bytes: &[u8], opts: JsValue) -> Output {
    call(bytes, "json", opts).unwrap_or_else(|m| panic!("mesh failed: {m}"))
}

fn err(bytes: &[u8], opts: JsValue) -> String {
    match call(bytes, "auto", opts) {
        Ok(out) => panic!("expected an error, got {} triangles", out.triangles()),
        Err(m) => m,
    }
}

/// A bicubic dome over 10 × 10 mm (4 × 4 control points, one Bézier patch),
/// with the u knots, weights and loops given as JSON text.
fn dome_with(knots_u: &str, weights: Option<&str>, loops: &str) -> Vec<u8> {
    let mut rows = Vec::new();
    for i in 0..4 {
        let row: Vec<String> = (0..4)
            .map(|j| {
                let lift = if (1..=2).contains(&i) && (1..=2).contains(&j) { 4.0 } else { 0.0 };
                format!("[{}, {}, {lift}]", 10.0 * i as f64 / 3.0, 10.0 * j as f64 / 3.0)
            })
            .collect();
        rows.push(format!("[{}]", row.join(", ")));
    }
    let weights = weights.map(|w| format!(r#", "weights": {w}"#)).unwrap_or_default();
    format!(
        r#"{{ "units": "mm", "faces": [ {{ "name": "dome",
              "surface": {{ "degree": [3, 3], "knots": [{knots_u}, [0, 0, 0, 0, 1, 1, 1, 1]],
                            "points": [{}]{weights} }},
              "loops": {loops} }} ] }}"#,
        rows.join(", ")
    )
    .into_bytes()
}

const CUBIC_KNOTS: &str = "[0, 0, 0, 0, 1, 1, 1, 1]";

fn dome() -> Vec<u8> {
    dome_with(CUBIC_KNOTS, None, "[]")
}

/// A square trim loop of four lines in (u, v); `gap` moves the third line's start.
fn square_loop(gap: f64) -> String {
    let line = |a: (f64, f64), b: (f64, f64)| {
        format!(r#"{{ "degree": 1, "knots": [0, 0, 1, 1], "points": [[{}, {}], [{}, {}]] }}"#, a.0, a.1, b.0, b.1)
    };
    format!(
        r#"[ {{ "curves": [ {}, {}, {}, {} ] }} ]"#,
        line((0.2, 0.2), (0.8, 0.2)),
        line((0.8, 0.2), (0.8, 0.8)),
        line((0.8, 0.8 + gap), (0.2, 0.8)),
        line((0.2, 0.8), (0.2, 0.2)),
    )
}

#[wasm_bindgen_test]
fn version_is_the_crate_version() {
    let v = binding::version();
    assert_eq!(v.split('.').count(), 3, "{v}");
    assert!(v.split('.').all(|p| p.parse::<u32>().is_ok()), "{v}");
}

#[wasm_bindgen_test]
fn malformed_json_names_line_and_column() {
    let m = err(b"{\n  \"faces\": [\n    { \"surface\": ,\n", JsValue::UNDEFINED);
    assert!(m.starts_with("JSON line 3 column"), "{m}");
}

#[wasm_bindgen_test]
fn truncated_input_is_an_error_not_a_trap() {
    // Every prefix is invalid JSON; none may trap the module.
    for cut in (0..FREEFORM.len() - 2).step_by(97) {
        let m = err(&FREEFORM[..cut], JsValue::UNDEFINED);
        assert!(m.starts_with("JSON line") || m.starts_with("format:"), "cut at {cut}: {m}");
    }
}

#[wasm_bindgen_test]
fn short_knot_vector_is_named() {
    let m = err(&dome_with("[0, 0, 1, 1]", None, "[]"), JsValue::UNDEFINED);
    assert!(m.contains("face 0 surface knots[0]"), "{m}");
    assert!(m.contains("too short"), "{m}");
}

#[wasm_bindgen_test]
fn decreasing_knots_are_named() {
    let m = err(&dome_with("[0, 0, 0, 0.6, 0.4, 1, 1, 1, 1]", None, "[]"), JsValue::UNDEFINED);
    assert!(m.contains("face 0 surface knots[0]"), "{m}");
    assert!(m.contains("decrease"), "{m}");
}

#[wasm_bindgen_test]
fn zero_weight_is_named() {
    let weights = "[[1, 1, 1, 1], [1, 0, 1, 1], [1, 1, 1, 1], [1, 1, 1, 1]]";
    let m = err(&dome_with(CUBIC_KNOTS, Some(weights), "[]"), JsValue::UNDEFINED);
    assert!(m.contains("face 0 surface weights[1][1]"), "{m}");
    assert!(m.contains("weight"), "{m}");
}

#[wasm_bindgen_test]
fn open_loop_is_named() {
    let m = err(&dome_with(CUBIC_KNOTS, None, &square_loop(0.05)), JsValue::UNDEFINED);
    assert!(m.contains("face 0 loop 0"), "{m}");
    assert!(m.contains("does not close"), "{m}");
}

#[wasm_bindgen_test]
fn bad_options_are_named() {
    let cases: [(JsValue, &str); 9] = [
        (options(&[("tolerance", "fine".into())]), "option tolerance: expected a number, found string"),
        (options(&[("tol", num(0.1))]), "option tol: unknown option"),
        (options(&[("tolerance", num(0.1)), ("toleranceRel", num(0.01))]), "not both"),
        (options(&[("angle", num(f64::NAN))]), "option angle: expected a finite number"),
        (options(&[("maxTriangles", num(2.5))]), "option maxTriangles"),
        (options(&[("maxEdge", num(-1.0))]), "option --max-edge"),
        (options(&[("toleranceRel", num(2.0))]), "option --tol-rel"),
        (num(5.0), "options: expected an object"),
        (options(&[("reparam", "sometimes".into())]), "option reparam: expected \"auto\", \"off\" or \"force\""),
    ];
    for (opts, expected) in cases {
        let m = err(&dome(), opts);
        assert!(m.contains(expected), "expected {expected:?} in {m:?}");
    }
}

#[wasm_bindgen_test]
fn quality_mode_gives_near_equilateral_triangles_of_the_size_asked() {
    let plane = include_bytes!("data/plane.json");
    let out = ok(plane, options(&[("mode", "quality".into()), ("size", num(2.0)), ("method", "best".into())]));
    let quality = Reflect::get(&out.report, &"quality".into()).expect("quality report");
    let field = |name: &str| Reflect::get(&quality, &name.into()).ok().and_then(|v| v.as_f64()).expect(name);
    assert_eq!(field("size"), 2.0);
    assert!(field("good_angle_fraction") >= 0.99);
    // The 10 mm square: each side in ceil(10 / 2) = 5 parts, no edge beyond 1.4 H.
    assert_eq!(out.number("boundary_edges"), 20.0);
    assert!(out.longest_edge() <= 2.8 + 1e-6, "{}", out.longest_edge());
    // Relative size: 0.1 of the diagonal 14.14 mm.
    let rel = ok(plane, options(&[("mode", "quality".into()), ("sizeRel", num(0.1))]));
    let q = Reflect::get(&rel.report, &"quality".into()).expect("quality report");
    let size = Reflect::get(&q, &"size".into()).ok().and_then(|v| v.as_f64()).expect("size");
    assert!((size - 0.1 * 200f64.sqrt()).abs() < 1e-9, "{size}");
    // Fast mode reports no quality section.
    let fast = ok(plane, JsValue::UNDEFINED);
    assert!(Reflect::get(&fast.report, &"quality".into()).expect("get").is_undefined());
    for (opts, expected) in [
        (options(&[("mode", "slow".into())]), "option mode: expected one of \"fast\", \"quality\""),
        (options(&[("mode", "quality".into()), ("size", num(1.0)), ("sizeRel", num(0.1))]), "not both"),
        (options(&[("mode", "quality".into()), ("method", "fancy".into())]), "option method"),
        (options(&[("mode", "quality".into()), ("size", num(-1.0))]), "option --size"),
        (options(&[("mode", "quality".into()), ("size", num(1e-5))]), "choose a larger size"),
    ] {
        let m = err(plane, opts);
        assert!(m.contains(expected), "expected {expected:?} in {m:?}");
    }
}

#[wasm_bindgen_test]
fn unknown_format_is_named() {
    let m = call(&dome(), "dxf", JsValue::UNDEFINED).err().expect("dxf is not supported");
    assert!(m.starts_with("format:") && m.contains("dxf"), "{m}");
    let m = err(b"hello, not a model", JsValue::UNDEFINED);
    assert!(m.starts_with("format:"), "{m}");
}

#[wasm_bindgen_test]
fn mesh_arrays_agree_with_the_report() {
    let out = ok(&dome(), JsValue::UNDEFINED);
    let vertices = out.number("vertices") as usize;
    let triangles = out.number("triangles") as usize;
    assert!(triangles >= 2, "{triangles} triangles");
    assert_eq!(out.positions.len(), 3 * vertices);
    assert_eq!(out.normals.len(), 3 * vertices);
    assert_eq!(out.indices.len(), 3 * triangles);
    assert!(out.indices.iter().all(|&i| (i as usize) < vertices), "index out of range");
    for n in out.normals.chunks(3) {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-4, "normal of length {len}");
    }
    // One (first, count) pair per face, covering every triangle in order.
    assert_eq!(out.face_ranges.len(), 2 * out.number("faces") as usize);
    let mut next = 0;
    for r in out.face_ranges.chunks(2) {
        assert_eq!(r[0], next);
        next += r[1];
    }
    assert_eq!(next as usize, triangles);
    // Default tolerance: 1e-3 of the (trimmed) model's diagonal, and the mesh meets it.
    let tolerance = out.number("tolerance");
    let expected = 1e-3 * out.bbox_diagonal();
    assert!((tolerance - expected).abs() <= 0.02 * expected, "tolerance {tolerance}, diagonal says {expected}");
    assert!(out.number("max_deviation") <= tolerance, "deviation {} > {tolerance}", out.number("max_deviation"));
    let warnings = Reflect::get(&out.report, &"warnings".into()).expect("warnings");
    assert!(js_sys::Array::is_array(&warnings));
}

#[wasm_bindgen_test]
fn format_detection_matches_the_named_format() {
    let named = ok(&dome(), JsValue::UNDEFINED);
    for format in ["", "auto", "JSON", ".json"] {
        let out = call(&dome(), format, JsValue::UNDEFINED).unwrap_or_else(|m| panic!("format {format:?}: {m}"));
        assert_eq!(out.indices, named.indices, "format {format:?}");
    }
}

#[wasm_bindgen_test]
fn tighter_tolerance_gives_more_triangles_within_it() {
    let coarse = ok(FREEFORM, options(&[("tolerance", num(0.5))]));
    let fine = ok(FREEFORM, options(&[("tolerance", num(0.02))]));
    for (out, tol) in [(&coarse, 0.5), (&fine, 0.02)] {
        assert_eq!(out.number("tolerance"), tol);
        assert!(out.number("max_deviation") <= tol, "deviation {} > {tol}", out.number("max_deviation"));
    }
    assert!(
        fine.triangles() > 2 * coarse.triangles(),
        "{} triangles at 0.02 vs {} at 0.5",
        fine.triangles(),
        coarse.triangles()
    );
}

#[wasm_bindgen_test]
fn relative_tolerance_scales_with_the_model() {
    let out = ok(FREEFORM, options(&[("toleranceRel", num(2e-3))]));
    let expected = 2e-3 * out.bbox_diagonal();
    let tolerance = out.number("tolerance");
    assert!((tolerance - expected).abs() <= 0.02 * expected, "tolerance {tolerance}, expected about {expected}");
    assert!(out.number("max_deviation") <= tolerance);
}

#[wasm_bindgen_test]
fn max_edge_bounds_every_edge() {
    let free = ok(FREEFORM, options(&[("tolerance", num(0.5))]));
    let limit = 6.0;
    assert!(free.longest_edge() > limit, "without maxEdge the longest edge is {}", free.longest_edge());
    let bounded = ok(FREEFORM, options(&[("tolerance", num(0.5)), ("maxEdge", num(limit))]));
    // f32 positions: allow their rounding.
    assert!(bounded.longest_edge() <= limit * (1.0 + 1e-5), "longest edge {}", bounded.longest_edge());
    assert!(bounded.triangles() > free.triangles());
}

#[wasm_bindgen_test]
fn smaller_angle_gives_more_triangles() {
    let wide = ok(FREEFORM, options(&[("tolerance", num(1.0)), ("angle", num(1.0))]));
    let narrow = ok(FREEFORM, options(&[("tolerance", num(1.0)), ("angle", num(0.1))]));
    assert_eq!(narrow.number("angle"), 0.1);
    assert!(narrow.triangles() > wide.triangles(), "{} vs {}", narrow.triangles(), wide.triangles());
}

#[wasm_bindgen_test]
fn reparam_force_rebuilds_and_lists_the_face() {
    let plain = ok(FREEFORM, options(&[("toleranceRel", num(1e-2))]));
    let forced = ok(FREEFORM, options(&[("toleranceRel", num(1e-2)), ("reparam", "force".into())]));
    let list = |o: &Output| Array::from(&Reflect::get(&o.report, &"reparameterized".into()).unwrap());
    assert_eq!(list(&plain).length(), 0);
    assert_eq!(list(&forced).length(), 1);
    let face = list(&forced).get(0);
    assert_eq!(Reflect::get(&face, &"face".into()).unwrap().as_f64(), Some(0.0));
    assert!(forced.number("max_deviation") <= forced.number("tolerance"));
}

#[wasm_bindgen_test]
fn min_edge_stops_refinement() {
    let free = ok(FREEFORM, options(&[("tolerance", num(0.01))]));
    let stopped = ok(FREEFORM, options(&[("tolerance", num(0.01)), ("minEdge", num(10.0))]));
    assert!(stopped.triangles() < free.triangles(), "{} vs {}", stopped.triangles(), free.triangles());
}

#[wasm_bindgen_test]
fn trimmed_dome_keeps_only_the_inside() {
    let out = ok(&dome_with(CUBIC_KNOTS, None, &square_loop(0.0)), JsValue::UNDEFINED);
    assert!(out.triangles() >= 2);
    // The loop keeps u, v in [0.2, 0.8]; on this patch x = 10 u and y = 10 v exactly
    // (linear precision of the evenly spaced control columns).
    for p in out.positions.chunks(3) {
        for c in [p[0], p[1]] {
            assert!((1.999..=8.001).contains(&c), "vertex {p:?} outside the loop");
        }
    }
}

#[wasm_bindgen_test]
fn module_keeps_working_after_errors() {
    for bad in [&b"{"[..], b"", b"{\"faces\": 3}"] {
        assert!(call(bad, "auto", JsValue::UNDEFINED).is_err());
    }
    let out = ok(&dome(), options(&[("tolerance", num(0.05))]));
    assert!(out.triangles() >= 2);
}

/// Two domes side by side, sharing the edge x = 10: a two-face model.
fn two_domes() -> Vec<u8> {
    let one: serde_json::Value = serde_json::from_slice(&dome()).expect("dome JSON");
    let mut second = one["faces"][0].clone();
    for row in second["surface"]["points"].as_array_mut().expect("points") {
        for p in row.as_array_mut().expect("row") {
            p[0] = (p[0].as_f64().expect("x") + 10.0).into();
        }
    }
    let mut two = one.clone();
    two["faces"].as_array_mut().expect("faces").push(second);
    serde_json::to_vec(&two).expect("two domes JSON")
}

/// Calls `mesh_with_progress` with a JS callback built from `body` (arguments `done`, `total`),
/// which also records every call in `globalThis.__surfmeshCalls`.
fn mesh_with_progress_js(bytes: &[u8], body: &str) -> (Result<JsValue, JsValue>, Vec<(f64, f64)>) {
    let calls = js_sys::Array::new();
    Reflect::set(&js_sys::global(), &"__surfmeshCalls".into(), &calls).expect("set global");
    let source = format!("globalThis.__surfmeshCalls.push([done, total]); {body}");
    let progress = js_sys::Function::new_with_args("done, total", &source);
    let result = binding::mesh_with_progress(bytes.to_vec(), "json", flat(JsValue::UNDEFINED), &progress);
    let seen = calls
        .iter()
        .map(|c| {
            let c: js_sys::Array = c.unchecked_into();
            (c.get(0).as_f64().expect("done"), c.get(1).as_f64().expect("total"))
        })
        .collect();
    (result, seen)
}

#[wasm_bindgen_test]
fn progress_is_reported_once_per_face() {
    let (result, calls) = mesh_with_progress_js(&two_domes(), "");
    let value = result.unwrap_or_else(|e| panic!("meshing failed: {e:?}"));
    assert_eq!(calls, vec![(1.0, 2.0), (2.0, 2.0)]);
    let ranges: Uint32Array = Reflect::get(&value, &"faceRanges".into()).expect("faceRanges").unchecked_into();
    assert_eq!(ranges.length(), 4, "two faces, two (first, count) pairs");
    // Without a callback the same model gives the same mesh.
    let plain = ok(&two_domes(), JsValue::UNDEFINED);
    assert_eq!(plain.face_ranges, ranges.to_vec());
}

#[wasm_bindgen_test]
fn progress_returning_false_cancels() {
    let (result, calls) = mesh_with_progress_js(&two_domes(), "return false;");
    let e = result.expect_err("cancelled");
    assert!(e.is_instance_of::<js_sys::Error>());
    assert_eq!(String::from(e.unchecked_into::<js_sys::Error>().message()), "cancelled");
    assert_eq!(calls, vec![(1.0, 2.0)], "meshing stops after the face in hand");
}

#[wasm_bindgen_test]
fn progress_exception_is_rethrown_as_it_is() {
    let (result, calls) = mesh_with_progress_js(&two_domes(), "throw new RangeError('stop ' + done);");
    let e = result.expect_err("the callback threw");
    assert!(e.is_instance_of::<js_sys::RangeError>(), "{e:?}");
    assert_eq!(String::from(e.unchecked_into::<js_sys::Error>().message()), "stop 1");
    assert_eq!(calls.len(), 1);
    // The module is still usable afterwards.
    assert!(ok(&dome(), JsValue::UNDEFINED).triangles() >= 2);
}

/// The bundled sphere, meshed, stretched to semi-axes 25, 15, 10 and offset
/// inward by 6: its x tips fold into self-intersecting fins. As binary STL.
fn folded_ellipsoid_stl() -> Vec<u8> {
    let model = read_model(include_bytes!("data/sphere.json"), Format::Json).expect("sphere model");
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(5e-3)).expect("sphere mesh");
    let mut m = surfmesh::weld_mesh(&r.mesh, 1e-8);
    for p in &mut m.positions {
        *p *= glam::DVec3::new(2.5, 1.5, 1.0);
    }
    let off = surfmesh::offset_mesh(&m, -6.0).expect("offset");
    assert!(!surfmesh::find_self_intersections(&off).expect("check").is_empty());
    surfmesh::write_stl(&off)
}

#[wasm_bindgen_test]
fn repair_returns_a_closed_mesh_without_self_intersections() {
    let stl = folded_ellipsoid_stl();
    let out = binding::repair(&stl, "auto", options(&[("bucketing", "kd".into()), ("verify", true.into())]))
        .unwrap_or_else(|e| panic!("repair failed: {:?}", JsValue::from(e)));
    let get = |name: &str| Reflect::get(&out, &name.into()).expect("result field");
    let positions = get("positions").dyn_into::<Float32Array>().expect("positions").to_vec();
    let indices = get("indices").dyn_into::<Uint32Array>().expect("indices").to_vec();
    let report = get("report");
    let field = |name: &str| Reflect::get(&report, &name.into()).expect("report field");
    assert!(field("segments").as_f64().unwrap() > 0.0);
    assert_eq!(field("self_intersections_out").as_f64(), Some(0.0));
    assert_eq!(field("bucketing").as_string().as_deref(), Some("kd-tree"));
    assert_eq!(field("triangles_out").as_f64(), Some((indices.len() / 3) as f64));
    assert_eq!(positions.len() % 3, 0);
    // Closed and consistently oriented: every directed edge has its reverse, once.
    let mut directed = std::collections::HashMap::new();
    for t in indices.chunks(3) {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times the same way");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
    }
}

#[wasm_bindgen_test]
fn repair_errors_are_js_errors_with_the_cli_message() {
    let message = |r: Result<JsValue, wasm_bindgen::JsError>| -> String {
        let value = JsValue::from(r.expect_err("expected an error"));
        assert!(value.is_instance_of::<js_sys::Error>());
        value.unchecked_into::<js_sys::Error>().message().into()
    };
    let m = message(binding::repair(b"solid x\nendsolid x\n", "stl", JsValue::UNDEFINED));
    assert_eq!(m, "repair: mesh: it has no triangles");
    let m = message(binding::repair(b"v 0 0 0\nf 1 2 3\n", "obj", JsValue::UNDEFINED));
    assert!(m.starts_with("OBJ line 2:"), "{m}");
    let m = message(binding::repair(&folded_ellipsoid_stl(), "stl", options(&[("bucketing", "octree".into())])));
    assert!(m.contains("bucketing"), "{m}");
    let m = message(binding::repair(b"", "auto", JsValue::UNDEFINED));
    assert!(m.starts_with("format:"), "{m}");
}

#[wasm_bindgen_test]
fn offset_moves_every_vertex_by_the_distance() {
    let model = read_model(include_bytes!("data/sphere.json"), Format::Json).expect("sphere model");
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(2e-2)).expect("sphere mesh");
    let m = surfmesh::weld_mesh(&r.mesh, 1e-8);
    let out =
        binding::offset(&surfmesh::write_obj(&m), "obj", 2.0).unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let positions = Reflect::get(&out, &"positions".into()).unwrap().dyn_into::<Float32Array>().unwrap().to_vec();
    let indices = Reflect::get(&out, &"indices".into()).unwrap().dyn_into::<Uint32Array>().unwrap().to_vec();
    assert!(!indices.is_empty() && indices.len() % 3 == 0);
    // The sphere of radius 10 becomes one of radius 12, up to how far the
    // facet-averaged vertex normals of this coarse mesh turn from the radius.
    for p in positions.chunks(3) {
        let r = ((p[0] as f64).powi(2) + (p[1] as f64).powi(2) + (p[2] as f64).powi(2)).sqrt();
        assert!((r - 12.0).abs() < 1e-2, "radius {r}");
    }
}

/// 60 points of the unit sphere (a Fibonacci spiral) as xyz text.
fn sphere_xyz() -> String {
    let n = 60;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            format!("{} {} {}\n", r * t.cos(), r * t.sin(), z)
        })
        .collect()
}

#[wasm_bindgen_test]
fn fit_returns_the_mesh_net_and_patches_of_a_surface_through_the_points() {
    let xyz = sphere_xyz();
    let out = binding::fit(xyz.as_bytes(), "auto", options(&[("toleranceRel", num(2e-3)), ("maxSides", num(6.0))]))
        .unwrap_or_else(|e| panic!("fit failed: {:?}", JsValue::from(e)));
    let get = |name: &str| Reflect::get(&out, &name.into()).expect("result field");
    let positions = get("positions").dyn_into::<Float32Array>().expect("positions").to_vec();
    let normals = get("normals").dyn_into::<Float32Array>().expect("normals").to_vec();
    let indices = get("indices").dyn_into::<Uint32Array>().expect("indices").to_vec();
    let points = get("points").dyn_into::<Float32Array>().expect("points").to_vec();
    let edges = get("netEdges").dyn_into::<Uint32Array>().expect("netEdges").to_vec();
    let report = get("report");
    let field = |name: &str| Reflect::get(&report, &name.into()).expect("report field").as_f64().expect("number");
    assert_eq!(field("points"), 60.0);
    assert_eq!(points.len(), 3 * 60);
    assert_eq!(field("triangles"), (indices.len() / 3) as f64);
    assert_eq!(positions.len(), normals.len());
    assert!(indices.iter().all(|&i| (i as usize) < positions.len() / 3));
    assert!(field("max_g1_angle") < 1e-6);
    assert!(field("sub_patches") < field("sub_patches_triangular"));
    // A closed net: V - E + F = 2 over the polygons, edges as pairs below the point count.
    assert!(edges.len() % 2 == 0 && edges.iter().all(|&i| i < 60));
    assert_eq!(60.0 - (edges.len() / 2) as f64 + field("polygons"), 2.0);
    // Every vertex near the unit sphere, every input point a mesh vertex.
    for p in positions.chunks(3) {
        let r = (p[0] as f64).hypot(p[1] as f64).hypot(p[2] as f64);
        assert!((r - 1.0).abs() < 0.1, "radius {r}");
    }
    let patches = js_sys::JSON::parse(&get("patches").as_string().expect("patches text")).expect("patches JSON");
    let polygons = Reflect::get(&patches, &"polygons".into()).unwrap().dyn_into::<Array>().unwrap();
    assert_eq!(polygons.length() as f64, field("polygons"));
}

#[wasm_bindgen_test]
fn fit_errors_are_js_errors_with_the_cli_message() {
    let message = |r: Result<JsValue, wasm_bindgen::JsError>| -> String {
        let value = JsValue::from(r.expect_err("expected an error"));
        assert!(value.is_instance_of::<js_sys::Error>());
        value.unchecked_into::<js_sys::Error>().message().into()
    };
    assert_eq!(
        message(binding::fit(b"0 0 0\n1 0 0\n0 1\n", "xyz", JsValue::UNDEFINED)),
        "points line 3: expected 3 numbers (x y z), found 2"
    );
    assert_eq!(
        message(binding::fit(b"0 0 0\n1 0 0\n0 1 0\n", "", JsValue::UNDEFINED)),
        "fit: at least 4 points are needed, found 3"
    );
    let m = message(binding::fit(sphere_xyz().as_bytes(), "xyz", options(&[("maxSides", num(2.0))])));
    assert!(m.starts_with("option maxSides"), "{m}");
    let m = message(binding::fit(sphere_xyz().as_bytes(), "xyz", options(&[("smooth", num(1.0))])));
    assert!(m.starts_with("option smooth: unknown option"), "{m}");
    let m = message(binding::fit(b"1 2 3", "las", JsValue::UNDEFINED));
    assert!(m.starts_with("format: unknown point format"), "{m}");
}

/// A STEP assembly of two placed blocks: the result names one part per
/// placement, says each face's part, and carries the styles' colours (the
/// solid's, one face's own); a JSON model is one unnamed part without colours.
#[wasm_bindgen_test]
fn step_assembly_parts_and_colours_reach_js() {
    let bytes = include_bytes!("data/step_assembly.stp");
    let v = binding::mesh(bytes.to_vec(), "step", flat(options(&[("toleranceRel", num(1e-3))])))
        .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let get = |name: &str| Reflect::get(&v, &name.into()).expect("result field");
    let parts: Vec<String> =
        get("parts").dyn_into::<Array>().expect("parts").iter().map(|p| p.as_string().expect("name")).collect();
    assert_eq!(parts, ["Block", "Block"]);
    let face_parts = get("faceParts").dyn_into::<Uint32Array>().expect("faceParts").to_vec();
    assert_eq!(face_parts, [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]);
    assert_eq!(get("faceRanges").dyn_into::<Uint32Array>().expect("faceRanges").length(), 24);
    let colours = get("faceColors").dyn_into::<Float32Array>().expect("faceColors").to_vec();
    assert_eq!(colours.len(), 36);
    assert_eq!(&colours[0..3], &[0.8, 0.25, 0.1]);
    assert_eq!(&colours[3..6], &[0.0, 0.0, 1.0]);
    assert_eq!(&colours[21..24], &[0.0, 0.0, 1.0]);

    let v = binding::mesh(FREEFORM.to_vec(), "json", flat(JsValue::UNDEFINED))
        .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let get = |name: &str| Reflect::get(&v, &name.into()).expect("result field");
    assert_eq!(get("parts").dyn_into::<Array>().expect("parts").length(), 1);
    let colours = get("faceColors").dyn_into::<Float32Array>().expect("faceColors").to_vec();
    assert!(!colours.is_empty() && colours.iter().all(|c| c.is_nan()));
    // The module's memory in whole 64 KiB pages, at least what the meshes above needed.
    let bytes = binding::memory_bytes();
    assert!(bytes >= 65536.0 && bytes % 65536.0 == 0.0, "{bytes}");
}

/// A tessellated solid placed by an assembly: its four faces pass through
/// with their part and colours, and the report counts them as tessellated.
#[wasm_bindgen_test]
fn step_tessellated_faces_reach_js_counted() {
    let bytes = include_bytes!("data/step_tess_solid.stp");
    let v = binding::mesh(bytes.to_vec(), "step", flat(JsValue::UNDEFINED))
        .unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
    let get = |name: &str| Reflect::get(&v, &name.into()).expect("result field");
    assert_eq!(get("faceRanges").dyn_into::<Uint32Array>().expect("faceRanges").to_vec(), [0, 1, 1, 1, 2, 1, 3, 1]);
    let parts: Vec<String> =
        get("parts").dyn_into::<Array>().expect("parts").iter().map(|p| p.as_string().expect("name")).collect();
    assert_eq!(parts, ["Tetra"]);
    let colours = get("faceColors").dyn_into::<Float32Array>().expect("faceColors").to_vec();
    assert_eq!(&colours[0..3], &[0.8, 0.2, 0.1]);
    assert_eq!(&colours[9..12], &[0.0, 0.0, 1.0]);
    let report = get("report");
    let field = |f: &str| Reflect::get(&report, &f.into()).unwrap().as_f64().unwrap();
    assert_eq!((field("faces"), field("faces_tessellated"), field("triangles")), (4.0, 4.0, 4.0));
}

/// The `units` option scales the inch box into millimetres (positions and
/// the report's tolerance), and the result names its unit; the default is
/// the file's own unit; a unit that is not offered throws.
#[wasm_bindgen_test]
fn units_option_scales_the_result_and_names_its_unit() {
    let bytes = include_bytes!("data/step_box_inch.stp");
    let run = |opts: JsValue| {
        let v = binding::mesh(bytes.to_vec(), "step", flat(opts)).unwrap_or_else(|e| panic!("{:?}", JsValue::from(e)));
        let get = |name: &str| Reflect::get(&v, &name.into()).expect("result field");
        let positions = get("positions").dyn_into::<Float32Array>().expect("positions").to_vec();
        let max_x = positions.chunks(3).map(|p| p[0]).fold(f32::NEG_INFINITY, f32::max);
        let report = get("report");
        let tol = Reflect::get(&report, &"tolerance".into()).unwrap().as_f64().unwrap();
        let units = get("units").as_string().expect("units");
        assert_eq!(Reflect::get(&report, &"units".into()).unwrap().as_string().as_deref(), Some(units.as_str()));
        (units, max_x, tol)
    };
    let (file_units, file_x, file_tol) = run(options(&[("toleranceRel", num(1e-2))]));
    assert_eq!((file_units.as_str(), file_x), ("in", 2.0));
    let (mm, mm_x, mm_tol) = run(options(&[("toleranceRel", num(1e-2)), ("units", "mm".into())]));
    assert_eq!(mm, "mm");
    assert!((mm_x - 50.8).abs() < 1e-4, "{mm_x}");
    assert!((mm_tol - 25.4 * file_tol).abs() < 1e-9 * mm_tol, "{mm_tol} vs {file_tol}");
    let m = match binding::mesh(bytes.to_vec(), "step", options(&[("units", "yd".into())])) {
        Ok(_) => panic!("units yd accepted"),
        Err(e) => String::from(JsValue::from(e).unchecked_into::<js_sys::Error>().message()),
    };
    assert!(m.starts_with("option units: expected"), "{m}");
}

/// Paper 001 by default: a crowded surface is flagged and rebuilt without
/// the option, and `"off"` leaves it as it is.
#[wasm_bindgen_test]
fn reparam_auto_is_the_default() {
    let crowded = include_bytes!("data/crowded_uv.json");
    let plain = ok(crowded, options(&[("toleranceRel", num(1e-2))]));
    let off = ok(crowded, options(&[("toleranceRel", num(1e-2)), ("reparam", "off".into())]));
    let list = |o: &Output| Array::from(&Reflect::get(&o.report, &"reparameterized".into()).unwrap());
    assert_eq!(list(&off).length(), 0);
    assert_eq!(list(&plain).length(), 1);
    let rebuilt = Reflect::get(&list(&plain).get(0), &"rebuilt".into()).unwrap();
    assert_eq!(rebuilt.as_bool(), Some(true));
    assert!(plain.triangles() < off.triangles(), "{} vs {}", plain.triangles(), off.triangles());
    assert!(plain.number("max_deviation") <= plain.number("tolerance"));
}

/// The message a call threw (a JS `Error`), or a panic when it returned.
fn thrown<T>(result: Result<T, wasm_bindgen::JsError>) -> String {
    match result {
        Ok(_) => panic!("expected an error"),
        Err(e) => String::from(JsValue::from(e).unchecked_into::<js_sys::Error>().message()),
    }
}

/// Every option of `mesh` with a value of the wrong kind, and each object
/// that is not an options object: a one-line error that names the option
/// (or `options`) and says what it expected and found.
#[wasm_bindgen_test]
fn each_bad_mesh_option_throws_one_line_naming_it() {
    let array = |xs: &[JsValue]| JsValue::from(xs.iter().collect::<Array>());
    let nothing = js_sys::Function::new_no_args("");
    let cases: Vec<(JsValue, &str)> = vec![
        (options(&[("tolerance", "fine".into())]), "option tolerance: expected a number, found string"),
        (options(&[("toleranceRel", true.into())]), "option toleranceRel: expected a number, found boolean"),
        (options(&[("angle", "wide".into())]), "option angle: expected a number, found string"),
        (options(&[("maxEdge", "long".into())]), "option maxEdge: expected a number, found string"),
        (options(&[("minEdge", array(&[num(1.0)]))]), "option minEdge: expected a number, found an array"),
        (options(&[("maxTriangles", Object::new().into())]), "option maxTriangles: expected a number, found object"),
        (options(&[("maxTriangles", num(-3.0))]), "option maxTriangles: expected a whole number, found -3"),
        (options(&[("reparam", num(1.0))]), "option reparam: expected a string, found number"),
        (options(&[("reparam", "sometimes".into())]), "option reparam: expected \"auto\", \"off\" or \"force\""),
        (options(&[("mode", "slow".into())]), "option mode: expected one of \"fast\", \"quality\""),
        (options(&[("size", "big".into())]), "option size: expected a number, found string"),
        (options(&[("sizeRel", num(f64::INFINITY))]), "option sizeRel: expected a finite number, found inf"),
        (options(&[("method", true.into())]), "option method: expected a string, found boolean"),
        (options(&[("share", num(2.0))]), "option share: expected [index, count]"),
        (options(&[("share", array(&[num(0.0), "2".into()]))]), "option share: expected [index, count]"),
        (options(&[("share", array(&[num(1.0)]))]), "option share: expected [index, count]"),
        (options(&[("share", array(&[num(0.0), num(1.0), num(2.0)]))]), "option share: expected [index, count]"),
        (options(&[("share", "0/2".into())]), "option share: expected [index, count]"),
        (options(&[("units", num(25.4))]), "option units: expected a string, found number"),
        (options(&[("units", "yd".into())]), "option units: expected"),
        (options(&[("flatten", "yes".into())]), "option flatten: expected a boolean, found string"),
        (options(&[("consoleWarnings", num(1.0))]), "option consoleWarnings: expected a boolean, found number"),
        (options(&[("tol", num(0.1))]), "option tol: unknown option (known: tolerance, toleranceRel"),
        (num(5.0), "options: expected an object like { toleranceRel: 0.001 }, found number"),
        ("fine".into(), "options: expected an object like { toleranceRel: 0.001 }, found string"),
        (array(&[]), "options: expected an object like { toleranceRel: 0.001 }, found an array"),
        (true.into(), "options: expected an object like { toleranceRel: 0.001 }, found boolean"),
        (nothing.clone().into(), "options: expected an object like { toleranceRel: 0.001 }, found function"),
        // A Map would be read as a list of entries: not an options object.
        (js_sys::Map::new().into(), "options: expected an object like { toleranceRel: 0.001 }, found an iterable"),
        // What serde-wasm-bindgen cannot read is named as such.
        (options(&[("angle", nothing.clone().into())]), "option angle: expected a number, found an unsupported value"),
        (
            options(&[("angle", js_sys::Set::new(&JsValue::UNDEFINED).into())]),
            "option angle: expected a number, found an unsupported value",
        ),
        // Nested arrays are not walked; a nested one is not a number.
        (options(&[("share", array(&[array(&[num(0.0)]), num(2.0)]))]), "option share: expected [index, count]"),
        (options(&[("tolerance", Object::new().into())]), "option tolerance: expected a number, found object"),
    ];
    for (opts, expected) in cases {
        let m = thrown(binding::mesh(dome(), "json", opts.clone()));
        assert!(m.starts_with(expected), "{opts:?}: expected {expected:?}, got {m:?}");
        assert!(!m.contains('\n'), "{m:?}");
    }
    // Undefined and null are the defaults, for the whole object and for one option.
    assert!(binding::mesh(dome(), "json", JsValue::NULL).is_ok());
    assert!(binding::mesh(dome(), "json", options(&[("angle", JsValue::NULL)])).is_ok());
    // A BigInt is a number too.
    let big = js_sys::BigInt::from(100_000_u64);
    assert!(binding::mesh(dome(), "json", options(&[("maxTriangles", big.into())])).is_ok());
    // Of two bad options the error names the one first in OPTION_NAMES, whatever the object's key order.
    let m = thrown(binding::mesh(dome(), "json", options(&[("units", num(1.0)), ("angle", "x".into())])));
    assert!(m.starts_with("option angle: expected a number, found string"), "{m:?}");
    // An unknown key is the error before any bad value, wherever it comes.
    let m = thrown(binding::mesh(dome(), "json", options(&[("angle", "x".into()), ("tol", num(1.0))])));
    assert!(m.starts_with("option tol: unknown option"), "{m:?}");
    // A key with a line break still gives one line.
    let m = thrown(binding::mesh(dome(), "json", options(&[("a\nb", num(1.0))])));
    assert!(m.starts_with("option a b: unknown option") && !m.contains('\n'), "{m:?}");
    // A good share with another option is read.
    assert!(binding::mesh(
        dome(),
        "json",
        options(&[("share", array(&[num(0.0), num(1.0)])), ("flatten", true.into())])
    )
    .is_ok());
}

/// The options of `repair` and `fit` are read the same way.
#[wasm_bindgen_test]
fn each_bad_repair_and_fit_option_throws_one_line_naming_it() {
    let stl = folded_ellipsoid_stl();
    for (opts, expected) in [
        (options(&[("bucketing", "grid".into())]), "option bucketing: expected \"kd\" or \"bvh\""),
        (options(&[("bucketCapacity", num(0.5))]), "option bucketCapacity: expected a whole number, found 0.5"),
        (options(&[("weldTolerance", "1e-9".into())]), "option weldTolerance: expected a number, found string"),
        (options(&[("perturbation", true.into())]), "option perturbation: expected a number, found boolean"),
        (options(&[("verify", num(1.0))]), "option verify: expected a boolean, found number"),
        (options(&[("weld", num(1.0))]), "option weld: unknown option (known: bucketing"),
        (num(1.0), "options: expected an object like { bucketing: \"kd\" }, found number"),
    ] {
        let m = thrown(binding::repair(&stl, "stl", opts));
        assert!(m.starts_with(expected), "expected {expected:?}, got {m:?}");
    }
    let xyz = sphere_xyz();
    for (opts, expected) in [
        (options(&[("tolerance", "fine".into())]), "option tolerance: expected a number, found string"),
        (options(&[("toleranceRel", true.into())]), "option toleranceRel: expected a number, found boolean"),
        (options(&[("maxSides", num(40.0))]), "option maxSides: expected a whole number from 3 to 32, found 40"),
        (options(&[("smooth", num(1.0))]), "option smooth: unknown option (known: tolerance, toleranceRel, maxSides)"),
    ] {
        let m = thrown(binding::fit(xyz.as_bytes(), "xyz", opts));
        assert!(m.starts_with(expected), "expected {expected:?}, got {m:?}");
    }
}

/// Field `name` of `v`.
fn field(v: &JsValue, name: &str) -> JsValue {
    Reflect::get(v, &name.into()).unwrap_or_else(|_| panic!("no field {name}"))
}

/// A column-major 4 × 4 matrix applied to the point `p`.
fn apply(m: &[f64], p: &[f32]) -> [f64; 3] {
    let (x, y, z) = (p[0] as f64, p[1] as f64, p[2] as f64);
    [0, 1, 2].map(|r| m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r])
}

/// The two placed blocks of a STEP assembly: meshed once (one part mesh, six
/// faces reported to progress, not twelve), placed twice; the tree has the
/// file's names and placements; each instance's mesh under its matrix is the
/// flattened mesh's faces of that instance vertex for vertex; every edge
/// polyline point is a vertex of its part mesh.
#[wasm_bindgen_test]
fn step_assembly_instances_match_the_flattened_mesh() {
    let bytes = include_bytes!("data/step_assembly.stp");
    let counted = js_sys::Function::new_with_args("done, total", "globalThis.__surfmeshTotal = total;");
    let v = binding::mesh_with_progress(bytes.to_vec(), "step", JsValue::UNDEFINED, &counted).expect("mesh");
    assert_eq!(field(&js_sys::global(), "__surfmeshTotal").as_f64(), Some(6.0));
    let meshes: Array = field(&v, "meshes").unchecked_into();
    let instances: Array = field(&v, "instances").unchecked_into();
    assert_eq!((meshes.length(), instances.length()), (1, 2));
    let tree = field(&v, "tree");
    assert_eq!(field(&tree, "name").as_string().as_deref(), Some("Assembly"));
    let children: Array = field(&tree, "children").unchecked_into();
    assert_eq!(children.length(), 2);
    // The second placement turns the block a quarter about z (its x axis along y).
    let placements = [("Block instance 1", 0.0, 1.0, 0.0), ("Block instance 2", 20.0, 0.0, 1.0)];
    for (k, (occurrence, x, c, s)) in placements.into_iter().enumerate() {
        let child = children.get(k as u32);
        assert_eq!(field(&child, "name").as_string().as_deref(), Some("Block"));
        assert_eq!(field(&child, "occurrence").as_string().as_deref(), Some(occurrence));
        let m: Vec<f64> = Array::from(&field(&child, "matrix")).iter().map(|x| x.as_f64().unwrap()).collect();
        assert_eq!(m, [c, s, 0.0, 0.0, -s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, x, 0.0, 0.0, 1.0]);
    }
    let report = field(&v, "report");
    assert_eq!(field(&report, "faces").as_f64(), Some(12.0));

    let flat = binding::mesh(bytes.to_vec(), "step", options(&[("flatten", true.into())])).expect("flat");
    let f32s = |v: &JsValue, n: &str| field(v, n).unchecked_into::<Float32Array>().to_vec();
    let u32s = |v: &JsValue, n: &str| field(v, n).unchecked_into::<Uint32Array>().to_vec();
    let (flat_pos, flat_idx, flat_ranges) =
        (f32s(&flat, "positions"), u32s(&flat, "indices"), u32s(&flat, "faceRanges"));
    let face_parts = u32s(&flat, "faceParts");
    assert_eq!(field(&field(&flat, "report"), "triangles").as_f64(), field(&report, "triangles").as_f64());
    let mut compared = 0;
    for k in 0..instances.length() {
        let inst = instances.get(k);
        let part = meshes.get(field(&inst, "part").as_f64().unwrap() as u32);
        let m: Vec<f64> = Array::from(&field(&inst, "matrix")).iter().map(|x| x.as_f64().unwrap()).collect();
        let (pos, idx, ranges) = (f32s(&part, "positions"), u32s(&part, "indices"), u32s(&part, "faceRanges"));
        let flat_faces: Vec<usize> = (0..face_parts.len()).filter(|&f| face_parts[f] == k).collect();
        assert_eq!(2 * flat_faces.len(), ranges.len());
        for (j, &f) in flat_faces.iter().enumerate() {
            let (a, n) = (ranges[2 * j] as usize, ranges[2 * j + 1] as usize);
            let (fa, fnn) = (flat_ranges[2 * f] as usize, flat_ranges[2 * f + 1] as usize);
            assert_eq!(n, fnn, "instance {k} face {j}");
            for t in 0..3 * n {
                let p = apply(&m, &pos[3 * idx[3 * a + t] as usize..]);
                let q = &flat_pos[3 * flat_idx[3 * fa + t] as usize..];
                for c in 0..3 {
                    assert!((p[c] - q[c] as f64).abs() < 1e-4, "instance {k} face {j}: {p:?} vs {q:?}");
                }
                compared += 1;
            }
        }
        // The outlines run through the mesh's vertices.
        let edges = f32s(&part, "edges");
        let edge_ranges = u32s(&part, "edgeRanges");
        assert!(edge_ranges.len() >= 2 * 12, "a block has 12 edges: {edge_ranges:?}");
        for e in edges.chunks(3) {
            assert!(pos.chunks(3).any(|p| p == e), "edge point {e:?} is not a vertex");
        }
    }
    assert_eq!(compared, flat_idx.len());
}
