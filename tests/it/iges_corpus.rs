//! IGES corpus: the IGES files of the test corpus (`tests/corpus`, see
//! its SOURCES.md). Every one must read; the files in [`MESHED`] must also
//! mesh at relative tolerances 1e-2 and 1e-3 with a measured deviation
//! within the tolerance, no inverted triangle, no crack between faces, and
//! (for [`CLOSED`] solids) no boundary edge at all. The others must mesh
//! within the tolerance without inverted triangles. No file's mesh may have
//! a triangle with two corners at one point. The others' cracks are
//! printed. An unoptimized build (the plain `cargo test`) meshes only the
//! files under [`DEBUG_MAX_BYTES`], to stay within CI's time;
//! `cargo test --release` meshes them all.

use std::time::Instant;

use surfmesh::{mesh_model, read_iges, MeshOptions, Model, WarningKind};

use crate::corpus_files::{corpus_bytes, corpus_names};

/// Files that must meet the whole acceptance.
const MESHED: [&str; 14] = [
    "BUC50025.igs",
    "OCC26138_Torus.igs",
    "OCC8842_cylinder_CATIA.igs",
    "PRO20358-W10.igs",
    "PRO20359-L1.igs",
    "asmo_car.igs",
    "bearing.iges",
    "bug22869_Spring.igs",
    "bug23171_tube_surf.igs",
    "cube_10x10_inventor.igs",
    "hammer.iges",
    "marsCapsule.igs",
    "nozzleAndCavity.igs",
    "ship_kcs.igs",
];

/// In a debug build, larger files are read but not meshed (meshing the
/// 1.3 MB bearing unoptimized takes most of a minute).
const DEBUG_MAX_BYTES: usize = 200_000;

/// Files whose faces make closed solids: no boundary edge may remain.
const CLOSED: [&str; 2] = ["cube_10x10_inventor.igs", "bug22869_Spring.igs"];

fn skipped_faces(model: &Model) -> usize {
    model.warnings.iter().filter(|w| matches!(w.kind, WarningKind::Skipped(_))).count()
}

#[test]
fn corpus_reads_and_meshes_within_tolerance_without_cracks() {
    let names = corpus_names(&["igs", "iges"]);
    for m in MESHED {
        assert!(names.iter().any(|n| n == m), "{m} is not in the corpus");
    }
    let mut failures = Vec::new();
    println!(
        "{:<28} {:>6} {:>5} {:>5} {:>8} {:>11} {:>11} {:>4} {:>5} {:>6} {:>7}",
        "file", "rel", "faces", "skip", "tris", "max dev", "tolerance", "inv", "free", "bound", "ms"
    );
    for name in &names {
        let bytes = corpus_bytes(name);
        let start = Instant::now();
        let model = match read_iges(&bytes) {
            Ok(m) => m,
            Err(e) => {
                failures.push(format!("{name}: read: {e}"));
                continue;
            }
        };
        let parse_ms = start.elapsed().as_secs_f64() * 1e3;
        let whole = MESHED.contains(&name.as_str());
        if cfg!(debug_assertions) && bytes.len() > DEBUG_MAX_BYTES {
            println!(
                "{name:<28} read only in a debug build: {} faces (cargo test --release meshes it)",
                model.faces.len()
            );
            continue;
        }
        for rel in [1e-2, 1e-3] {
            let start = Instant::now();
            let r = match mesh_model(&model, &MeshOptions::default().with_relative_tolerance(rel)) {
                Ok(r) => r,
                Err(e) => {
                    failures.push(format!("{name} @ {rel}: mesh: {e}"));
                    continue;
                }
            };
            let ms = start.elapsed().as_secs_f64() * 1e3 + parse_ms;
            let rep = &r.report;
            println!(
                "{:<28} {:>6} {:>5} {:>5} {:>8} {:>11.4e} {:>11.4e} {:>4} {:>5} {:>6} {:>7.0}",
                name,
                rel,
                model.faces.len(),
                skipped_faces(&model) + rep.faces_skipped,
                rep.triangles,
                rep.max_deviation,
                rep.tolerance,
                rep.inverted_triangles,
                rep.free_edges,
                rep.boundary_edges,
                ms
            );
            let mut problems = Vec::new();
            if rep.max_deviation.is_nan() || rep.max_deviation > rep.tolerance {
                problems.push(format!("max deviation {} above tolerance {}", rep.max_deviation, rep.tolerance));
            }
            if rep.inverted_triangles != 0 {
                problems.push(format!("{} inverted triangles", rep.inverted_triangles));
            }
            let points = crate::point_triangles(&r.mesh);
            if points != 0 {
                problems.push(format!("{points} triangles with two corners at one point"));
            }
            if !whole {
                // Not yet watertight: within the tolerance and unfolded is what holds.
                if !problems.is_empty() {
                    failures.push(format!("{name} @ {rel}: {}", problems.join("; ")));
                }
                continue;
            }
            if rep.free_edges != 0 {
                problems.push(format!("{} free edges (cracks)", rep.free_edges));
            }
            if CLOSED.contains(&name.as_str()) && rep.boundary_edges != 0 {
                problems.push(format!("{} boundary edges on a closed solid", rep.boundary_edges));
            }
            if rep.triangles == 0 || rep.faces_skipped != 0 || skipped_faces(&model) != 0 {
                problems.push(format!("{} triangles, faces skipped", rep.triangles));
            }
            if !problems.is_empty() {
                failures.push(format!("{name} @ {rel}: {}", problems.join("; ")));
            }
        }
    }
    assert!(failures.is_empty(), "IGES corpus failures:\n{}", failures.join("\n"));
}
