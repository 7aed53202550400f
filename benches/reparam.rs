//! Criterion benches of paper 001's parameterization test and rebuild, on the
//! surfaces of tests/data: the crowded ones (90% of a parameter range covering
//! 5% of the surface) and well-parameterized ones (sphere, torus, uniform
//! bicubic freeform).
//!
//! - `detect`: the step-ratio test of one face (six iso-lines of 50 steps);
//! - `rebuild`: one crowded face rebuilt on even parameters at relative
//!   tolerance 1e-2 (sampling, banded interpolation, the check against the original).
//!
//! `cargo bench --bench reparam [-- GROUP]`; CI runs each once in test mode.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use surfmesh::{read_json, rebuild_face, step_ratio, Model};

fn model(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    read_json(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn detect(c: &mut Criterion) {
    let mut g = c.benchmark_group("detect");
    for name in ["crowded_u.json", "crowded_tube.json", "freeform.json", "sphere.json", "torus.json"] {
        let m = model(name);
        g.bench_with_input(BenchmarkId::from_parameter(name), &m, |b, m| {
            b.iter(|| step_ratio(black_box(&m.faces[0].surface)));
        });
    }
    g.finish();
}

fn rebuild(c: &mut Criterion) {
    let mut g = c.benchmark_group("rebuild");
    g.sample_size(10);
    for name in ["crowded_u.json", "crowded_trimmed.json"] {
        let m = model(name);
        // 1e-2 of the sheet's diagonal (about 108 mm).
        let tol = 1.08;
        g.bench_with_input(BenchmarkId::from_parameter(name), &m, |b, m| {
            b.iter(|| rebuild_face(black_box(&m.faces[0]), tol).map(|r| r.samples));
        });
    }
    g.finish();
}

criterion_group!(benches, detect, rebuild);
criterion_main!(benches);
