//! IGES: small files written for these tests check units, scale, trims,
//! analytic surfaces and malformed input.

use std::path::Path;

use glam::DVec3;
use surfmesh::{mesh_model, read_iges, read_model, Entity, Error, Format, Mesh, MeshOptions, WarningKind};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
}

/// Area of the triangles of face `f`.
fn face_area(m: &Mesh, f: usize) -> f64 {
    let r = m.face_ranges[f];
    (r.first as usize..(r.first + r.count) as usize)
        .map(|t| {
            let [a, b, c] = m.triangle(t);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// Vertices used by the triangles of face `f`.
fn face_vertices(m: &Mesh, f: usize) -> Vec<DVec3> {
    let r = m.face_ranges[f];
    (r.first as usize..(r.first + r.count) as usize).flat_map(|t| m.triangle(t)).collect()
}

#[test]
fn plate_reads_units_scale_names_and_trims() {
    let model = read_iges(&data("iges_plate.igs")).unwrap();
    assert_eq!(model.units, "in");
    // Resolution 0.002 in a file drawn at scale 2: 0.001 in real units.
    assert!((model.tolerance.unwrap() - 0.001).abs() < 1e-15);
    assert_eq!(model.faces.len(), 2, "warnings: {:?}", model.warnings);
    assert_eq!(model.faces[0].name, None);
    assert_eq!(model.faces[1].name.as_deref(), Some("FLANGE"));
    assert_eq!(model.faces[0].loops.len(), 2, "outer rectangle and circular hole");
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-3)).unwrap();
    let rep = &r.report;
    assert!(rep.max_deviation <= rep.tolerance);
    assert_eq!(rep.free_edges, 0, "the projected and the parameter-space trims share an edge");
    assert_eq!(rep.inverted_triangles, 0);
    // Model coordinates are halved by the scale: areas by four.
    let tol = rep.tolerance;
    let hole = std::f64::consts::PI * 16.0;
    let expect0 = (30.0 * 16.0 - hole) / 4.0;
    // The hole's polygon is inscribed: its area error is below its perimeter times the tolerance.
    assert!((face_area(&r.mesh, 0) - expect0).abs() < 2.0 * std::f64::consts::PI * 2.0 * tol + 1e-9, "plate area");
    assert!((face_area(&r.mesh, 1) - 15.0 * 16.0 / 4.0).abs() < 1e-9, "flange area");
    for p in face_vertices(&r.mesh, 0) {
        assert!(p.z.abs() < 1e-12 && p.x > 2.5 - 1e-9 && p.x < 17.5 + 1e-9 && p.y > 1.0 - 1e-9 && p.y < 9.0 + 1e-9);
        assert!(p.distance(DVec3::new(10.0, 5.0, 0.0)) > 2.0 - tol, "vertex inside the hole: {p}");
    }
}

#[test]
fn crlf_short_lines_blank_fields_and_no_final_newline_read_the_same() {
    let a = read_iges(&data("iges_plate.igs")).unwrap();
    let b = read_iges(&data("iges_plate_crlf.igs")).unwrap();
    assert_eq!(a.faces.len(), b.faces.len());
    let opts = MeshOptions::default().with_relative_tolerance(1e-2);
    let (ma, mb) = (mesh_model(&a, &opts).unwrap(), mesh_model(&b, &opts).unwrap());
    for f in 0..a.faces.len() {
        assert!((face_area(&ma.mesh, f) - face_area(&mb.mesh, f)).abs() < 1e-9);
    }
    assert_eq!(a.units, b.units);
}

#[test]
fn analytic_surfaces_are_exact() {
    let model = read_iges(&data("iges_analytic.igs")).unwrap();
    assert_eq!(model.faces.len(), 5, "warnings: {:?}", model.warnings);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-3)).unwrap();
    let rep = &r.report;
    assert!(rep.max_deviation <= rep.tolerance);
    assert_eq!(rep.inverted_triangles, 0);
    assert_eq!(rep.free_edges, 0);
    let tol = rep.tolerance;
    let mut seen = [false; 5];
    for f in 0..model.faces.len() {
        let vs = face_vertices(&r.mesh, f);
        let c = vs.iter().fold(DVec3::ZERO, |a, &p| a + p) / vs.len() as f64;
        // Which shape: by where it sits along x.
        let k = ((c.x + 10.0) / 20.0).floor() as usize;
        seen[k] = true;
        for p in vs {
            let err = match k {
                // Cylinder r = 5 about z, 0 <= z <= 10.
                0 => {
                    assert!(p.z > -tol && p.z < 10.0 + tol);
                    (p.x.hypot(p.y) - 5.0).abs()
                }
                // Cone frustum about x = 20: r = 2 + 2z/5, half a turn (y >= 0).
                1 => {
                    assert!(p.y > -tol);
                    ((p.x - 20.0).hypot(p.y) - (2.0 + 0.4 * p.z)).abs()
                }
                2 => (p.distance(DVec3::new(40.0, 0.0, 0.0)) - 3.0).abs(),
                3 => {
                    let q = p - DVec3::new(60.0, 0.0, 0.0);
                    ((q.x.hypot(q.y) - 4.0).hypot(q.z) - 1.0).abs()
                }
                _ => (p.distance(DVec3::new(80.0, 0.0, 0.0)) - 3.5).abs(),
            };
            assert!(err <= 1e-9, "face {f} (shape {k}): vertex {p} off the exact surface by {err}");
        }
    }
    assert_eq!(seen, [true; 5]);
}

/// A file cut off in its Parameter section: the entities whose data is
/// there read (the plate with its hole), those past the cut are skipped
/// with one warning naming the first; cut before any face is whole, the
/// file is an error naming an entity.
#[test]
fn truncated_file_reads_what_is_there() {
    let m = read_iges(&data("iges_truncated.igs")).unwrap();
    assert_eq!(m.faces.len(), 1, "{:?}", m.warnings);
    assert_eq!(m.faces[0].loops.len(), 2, "outer rectangle and circular hole");
    let skipped: Vec<&Error> = m
        .warnings
        .iter()
        .filter_map(|w| match &w.kind {
            WarningKind::EntityDamaged(e) => Some(e),
            _ => None,
        })
        .collect();
    assert_eq!(skipped.len(), 1, "{:?}", m.warnings);
    assert!(matches!(skipped[0], Error::Iges { entity: 31, .. }), "{}", skipped[0]);
    assert!(skipped[0].to_string().contains("(file truncated?)"), "{}", skipped[0]);
    let text = String::from_utf8(data("iges_truncated.igs")).unwrap();
    let cut: String = text.lines().take(53).map(|l| format!("{l}\n")).collect();
    let (section, _, entity, message) = match read_iges(cut.as_bytes()) {
        Err(Error::Iges { section, line, entity, message }) => (section, line, entity, message),
        other => panic!("expected an IGES error, got {other:?}"),
    };
    assert!(entity > 0, "{message}");
    assert!(section == "Directory" || section == "Parameter", "{section}: {message}");
    assert!(message.contains("truncated"), "{message}");
}

/// A parameter pointer past the section: that entity (a trimmed face) is
/// skipped with one warning naming it and the pointer, and the other face
/// reads. With the other face's pointer bad too, nothing is left: an error.
#[test]
fn bad_parameter_pointer_skips_its_entity() {
    let m = read_iges(&data("iges_bad_pointer.igs")).unwrap();
    assert_eq!(m.faces.len(), 1);
    assert_eq!(m.faces[0].name.as_deref(), Some("FLANGE"));
    // The warning's text, as the report shows it.
    assert_eq!(
        m.warnings.iter().map(ToString::to_string).collect::<Vec<_>>(),
        ["IGES Directory section, entity DE 19: parameter data pointer 999 is outside the Parameter section's \
          26 lines (file truncated?); the entity is skipped"]
    );
    let text = String::from_utf8(data("iges_bad_pointer.igs")).unwrap();
    let both = text.replace("     144      25       0", "     144     998       0");
    let (section, _, entity, message) = match read_iges(both.as_bytes()) {
        Err(Error::Iges { section, line, entity, message }) => (section.to_string(), line, entity, message),
        other => panic!("expected an IGES error, got {other:?}"),
    };
    assert_eq!(section, "Directory");
    assert!(entity % 2 == 1 && entity > 1, "entity {entity}");
    assert!(message.contains("999") || message.contains("998"), "{message}");
}

/// A directory record pushed one column right by a blank before it reads
/// without the blank (one warning naming the line); pushed by anything
/// else, the record is refused naming its line.
#[test]
fn shifted_columns_are_read_when_blanks_shifted_them() {
    let text = String::from_utf8(data("iges_shifted.igs")).unwrap();
    let shifted = text.lines().position(|l| l.len() > 80).unwrap() + 1;
    let m = read_iges(text.as_bytes()).unwrap();
    assert_eq!(m.faces.len(), 2, "{:?}", m.warnings);
    assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
    assert_eq!(m.warnings[0].kind, WarningKind::ShiftedRecord { line: shifted });
    assert_eq!(m.warnings[0].more, 0);
    let junk: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == shifted { format!("x{}\n", &l[1..]) } else { format!("{l}\n") })
        .collect();
    let (_, line, _, message) = match read_iges(junk.as_bytes()) {
        Err(Error::Iges { section, line, entity, message }) => (section, line, entity, message),
        other => panic!("expected an IGES error, got {other:?}"),
    };
    assert_eq!(line, shifted, "{message}");
    let shown = Error::Iges { section: "file", line, entity: 0, message: message.clone() }.to_string();
    assert!(shown.contains(&format!("line {shifted}")), "{shown}");
}

#[test]
fn huge_counts_and_reference_cycles_skip_the_face_with_a_reason() {
    let m = read_iges(&data("iges_huge_count.igs")).unwrap();
    assert_eq!(m.faces.len(), 1, "the other face still reads");
    let skipped =
        |w: &surfmesh::Warning, why: &str| matches!(&w.kind, WarningKind::Skipped(e) if e.to_string().contains(why));
    assert!(m.warnings.iter().any(|w| skipped(w, "999999999")), "{:?}", m.warnings);
    let m = read_iges(&data("iges_cycle.igs")).unwrap();
    assert_eq!(m.faces.len(), 1);
    assert!(m.warnings.iter().any(|w| skipped(w, "cycle")), "{:?}", m.warnings);
}

/// The corpus cube (a B-rep solid: 186, 514, six 510 faces) with its first
/// face's surface pointer turned to the edge list (not a surface): the face
/// is skipped with a warning, counted, and the edges the four faces beside
/// it leave open along its border are cracks, not the solid's boundary.
#[test]
fn a_skipped_brep_face_leaves_free_edges_along_its_border() {
    let text = String::from_utf8(crate::corpus_files::corpus_bytes("cube_10x10_inventor.igs")).unwrap();
    let record = "510,53,1,1,17;";
    assert_eq!(text.matches(record).count(), 1);
    // Pointer 67 is the 504 edge list: same width, columns unchanged.
    let broken = text.replace(record, "510,67,1,1,17;");
    let model = read_iges(broken.as_bytes()).unwrap();
    assert_eq!((model.faces.len(), model.skipped.len()), (5, 1));
    let de5 = Some(Entity::Iges { de: 5, kind: 510 });
    assert!(
        model.warnings.iter().any(|w| w.entity == de5 && matches!(w.kind, WarningKind::Skipped(_))),
        "{:?}",
        model.warnings
    );
    // Its border: the face's loop, four straight edges 10 mm long.
    let border = &model.skipped[0].border;
    assert_eq!(border.len(), 4);
    for c in border {
        let (a, b) = c.domain();
        assert!((c.point(a).distance(c.point(b)) - 10.0).abs() < 1e-6);
    }
    let whole = mesh_model(&read_iges(text.as_bytes()).unwrap(), &MeshOptions::default()).unwrap();
    assert_eq!((whole.report.boundary_edges, whole.report.free_edges), (0, 0));
    let r = mesh_model(&model, &MeshOptions::default()).unwrap();
    let rep = &r.report;
    assert_eq!((rep.faces, rep.faces_unread), (5, 1));
    assert!(rep.boundary_edges >= 4, "{} boundary edges", rep.boundary_edges);
    assert_eq!(rep.free_edges, rep.boundary_edges, "every open edge runs round the hole");
    assert!(rep.warnings.iter().any(|w| matches!(w.kind, WarningKind::UnreadFaces { count: 1, holes } if holes > 0)));
}

/// An 80-column record: `data` in columns 1-72, the section letter, the sequence number.
fn record(data: &str, letter: char, seq: usize) -> String {
    format!("{data:<72}{letter}{seq:>7}\n")
}

#[test]
fn a_file_without_faces_is_an_error() {
    // Only the Global section and a point.
    let text = [
        record("", 'S', 1),
        record("1H,,1H;,4Htest,4Htest,4Htest,4Htest,32,38,6,308,15,4Htest,1.0,2,2HMM,1,", 'G', 1),
        record("0.1,15H20240101.000000,0.001,10.0,4Htest,4Htest,11,0;", 'G', 2),
        record("     116       1       0       0       0       0       0       000000000", 'D', 1),
        record("     116       0       0       1       0                               0", 'D', 2),
        format!("{:<64}{:>8}P{:>7}\n", "116,1.0,2.0,3.0;", 1, 1),
        record("S      1G      2D      2P      1", 'T', 1),
    ]
    .concat();
    match read_iges(text.as_bytes()) {
        Err(Error::Iges { message, .. }) => assert!(message.contains("no surfaces"), "{message}"),
        other => panic!("expected an error, got {other:?}"),
    }
}

#[test]
fn mutated_files_never_panic() {
    // Deterministic byte-level damage of a valid file: replaced, deleted and
    // duplicated bytes, and truncation. Every outcome is Ok or Err.
    let base = data("iges_plate.igs");
    let alphabet = b",;0123456789H .DPE-\n";
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    let mut outcomes = [0usize; 2];
    for _ in 0..400 {
        let mut b = base.clone();
        for _ in 0..1 + next(4) {
            let at = next(b.len());
            match next(4) {
                0 => b[at] = alphabet[next(alphabet.len())],
                1 => {
                    b.remove(at);
                }
                2 => {
                    let c = b[at];
                    b.insert(at, c);
                }
                _ => b.truncate(at),
            }
            if b.is_empty() {
                break;
            }
        }
        outcomes[usize::from(read_iges(&b).is_ok())] += 1;
    }
    assert_eq!(outcomes.iter().sum::<usize>(), 400);
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "some mutants read, some fail: {outcomes:?}");
}

/// Found by fuzzing (a timeout): a mutated copy of the analytic file whose
/// trim curve lies far off its sphere made every trim sample run a futile
/// global projection; now the search is given up once it fails for a curve.
/// The file still reads, and the face whose loop the damage tangled is
/// mended to the region its loop winds round, with a warning naming it.
#[test]
fn fuzz_timeout_off_surface_trim_curve_reads_and_fails_cleanly() {
    let model = read_iges(&data("iges_fuzz_timeout_off_surface.igs")).unwrap();
    assert_eq!(model.faces.len(), 5, "{:?}", model.warnings);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(0.05)).expect("the other faces mesh");
    assert_eq!(r.report.faces_skipped, 0, "{:?}", r.report.warnings);
    let w = &r.report.warnings;
    let mended = |w: &surfmesh::Warning| matches!(w.kind, WarningKind::LoopsMended(m) if m.crossings > 0 && m.rejoined);
    assert!(w.iter().any(|w| w.face == Some(1) && mended(w)), "{w:?}");
    assert_eq!(r.mesh.face_ranges.len(), 5);
    assert!(r.report.max_deviation <= r.report.tolerance, "{} > {}", r.report.max_deviation, r.report.tolerance);
    assert!(r.mesh.face_ranges.iter().enumerate().all(|(i, f)| i == 1 || f.count > 0));
}

/// Found by fuzzing (a debug build's invariant check): a mutated B-spline
/// sheet whose surface folds over itself. Mending flipped an edge between
/// inner nodes into a pair that turns clockwise in (u,v), because the pair
/// happened to face the surface's normal in space at the quad's middle. An
/// inner node's (u,v) is exact, so such a flip is refused; the debug build
/// checks every triangle's turn after each stage.
#[test]
fn fuzz_folded_sheet_keeps_inner_triangles_counter_clockwise() {
    let model = read_iges(&data("iges_fuzz_folded_flip.igs")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(0.05).with_max_triangles(5_000);
    let r = mesh_model(&model, &options).expect("meshes");
    assert!(r.report.triangles > 0, "{:?}", r.report.warnings);
    assert!(r.report.max_deviation <= r.report.tolerance, "{} > {}", r.report.max_deviation, r.report.tolerance);
}

/// Found by fuzzing (3.6 s natively, 61 s under the sanitizer): a mutated
/// B-spline face whose trim loop runs over itself along a stretch. Sewing
/// halved the crossing chords there round after round, and each halving
/// crossed again, doubling the loop's nodes up to some 15 000 whose pair
/// search was quadratic. Halvings of crossings are now bounded per face,
/// and a face still crossing after them fails, naming itself.
#[test]
fn fuzz_overlapping_trim_loop_is_not_halved_without_end() {
    let model = read_iges(&data("iges_fuzz_slow_sewing.igs")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(0.05).with_max_triangles(5_000);
    let plan = surfmesh::pipeline::Plan::new(&model, &options).unwrap();
    let mut run = plan.start();
    let variants = plan.choose_variants(&mut run).unwrap();
    let nodes = variants.loop_nodes();
    assert!(nodes > 0);
    let sewn = plan.sew_outlines(&run, variants);
    // A face halves as many crossings as it has nodes (at least 64), so the
    // ids stay within a small multiple of the loops' nodes (unbounded, the
    // halvings ran to thousands).
    assert!((sewn.ids() as usize) <= 2 * nodes + 2 * 64, "{} ids for {nodes} loop nodes", sewn.ids());
    match mesh_model(&model, &options) {
        Err(Error::Mesh { face: 0, message }) => assert!(message.contains("trim loops"), "{message}"),
        other => panic!("face 0 fails: {:?}", other.map(|r| r.report)),
    }
}

/// Found by fuzzing (20 s natively): a mutated sheet whose trim loop, a
/// conic gone wild, crosses itself at tens of thousands of places. Mending
/// cut it into some 150 000 pieces crowded where the crossings are, and the
/// winding ray from each met most of them (4·10⁹ steps). Mending's steps
/// are now bounded by the loop's nodes, and the face fails, naming its loop.
#[test]
fn fuzz_loop_crossing_itself_everywhere_is_not_mended_without_end() {
    let model = read_iges(&data("iges_fuzz_slow_loop_mending.igs")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(0.05).with_max_triangles(5_000);
    let before = surfmesh::pipeline::mend_steps();
    let result = mesh_model(&model, &options);
    let steps = surfmesh::pipeline::mend_steps() - before;
    // A few thousand loop nodes take a few million steps (unbounded, billions).
    assert!(steps < 20_000_000, "{steps} mending steps");
    match result {
        Err(Error::Mesh { face: 0, message }) => assert!(message.contains("loop 0 crosses itself"), "{message}"),
        other => panic!("face 0 fails: {:?}", other.map(|r| r.report)),
    }
}

#[test]
fn format_from_extension_and_first_line() {
    assert_eq!(Format::from_name("igs").unwrap(), Format::Iges);
    assert_eq!(Format::from_name(".IGES").unwrap(), Format::Iges);
    assert!(Format::from_name("stp2").is_err());
    let bytes = data("iges_plate.igs");
    assert_eq!(Format::detect(&bytes), Some(Format::Iges));
    assert_eq!(Format::detect(&data("iges_plate_crlf.igs")), Some(Format::Iges));
    assert_eq!(Format::detect(b"  {\"faces\": []}"), Some(Format::Json));
    assert_eq!(Format::detect(b"hello"), None);
    let m = read_model(&bytes, Format::Iges).unwrap();
    assert_eq!(m.faces.len(), 2);
}

#[test]
fn command_line_meshes_an_iges_file_by_its_extension() {
    let out_dir = std::env::temp_dir().join(format!("surfmesh-iges-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).unwrap();
    let report = out_dir.join("report.json");
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/iges_plate.igs");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_surfmesh"))
        .arg("mesh")
        .arg(&input)
        .arg("--tol-rel")
        .arg("1e-2")
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert!(json["triangles"].as_u64().unwrap() > 0);
    assert_eq!(json["faces"].as_u64().unwrap(), 2);
    let _ = std::fs::remove_dir_all(&out_dir);
}

/// The test corpus (`tests/corpus`), in a file of its own.
#[path = "iges_corpus.rs"]
mod corpus;

/// Flaws a tolerant reader forgives, in a file of their own.
#[path = "iges_lenient.rs"]
mod lenient;

/// Conic arcs (104) of hyperbolic and parabolic form, each closed by a
/// chord on a plane: the border follows the exact conic (every vertex in the
/// exact region, up to the trim fit) and the areas are the closed forms'.
#[test]
fn hyperbola_and_parabola_conic_arcs_are_exact() {
    let model = read_iges(&data("iges_conic_arcs.igs")).unwrap();
    assert_eq!(model.faces.len(), 2, "{:?}", model.warnings);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(1e-4)).unwrap();
    let tol = r.report.tolerance;
    assert!(r.report.max_deviation <= tol);
    // x²/16 − y²/9 = 1 from t = −1 to 1, closed by x = 4 cosh 1.
    let (a, b, ch, sh) = (4.0_f64, 3.0_f64, 1f64.cosh(), 1f64.sinh());
    let want = a * b * (ch * sh - 1.0);
    assert!((face_area(&r.mesh, 0) - want).abs() < 30.0 * tol, "hyperbola: {} vs {want}", face_area(&r.mesh, 0));
    for p in face_vertices(&r.mesh, 0) {
        let gap = a * (1.0 + (p.y / b).powi(2)).sqrt() - p.x;
        assert!(gap <= 0.1 * tol && p.x <= a * ch + 1e-9, "vertex {p} outside the hyperbola's segment");
    }
    // y² = 6 (x − 20), closed by x = 21.5: area 2/3 of the 6 × 1.5 rectangle.
    assert!((face_area(&r.mesh, 1) - 6.0).abs() < 30.0 * tol, "parabola: {}", face_area(&r.mesh, 1));
    for p in face_vertices(&r.mesh, 1) {
        let gap = 20.0 + p.y * p.y / 6.0 - p.x;
        assert!(gap <= 0.1 * tol && p.x <= 21.5 + 1e-9, "vertex {p} outside the parabola's segment");
    }
}

/// Found by fuzzing (a debug build's invariant check): the triangulation
/// split two nearly parallel loop segments where they cross, and the
/// crossing, computed far less exactly across one of them than along it,
/// lay 10⁻⁷ of its length off that segment. It was not taken for a piece
/// of it, and the piece was left unmarked as a trim edge. The debug build
/// checks every border edge after each stage.
#[test]
fn fuzz_nearly_parallel_crossing_pieces_stay_trim_edges() {
    let model = read_iges(&data("iges_fuzz_near_parallel_crossing.igs")).unwrap();
    let options = MeshOptions::default().with_relative_tolerance(0.05).with_max_triangles(5_000);
    let r = mesh_model(&model, &options).expect("meshes");
    assert!(r.report.triangles > 0, "{:?}", r.report.warnings);
    assert!(r.report.max_deviation <= r.report.tolerance, "{} > {}", r.report.max_deviation, r.report.tolerance);
}
