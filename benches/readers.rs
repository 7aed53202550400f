//! Criterion benches of the readers' speed in MB/s, on the largest real files
//! of the curated corpus (`../shared/corpus`, or the folder named by
//! `SURFMESH_CORPUS`; the uncompressed files of `tests/corpus` when neither
//! is there).
//!
//! - `step_text`: the STEP exchange structure parsed into its entity
//!   instances, nothing built;
//! - `step_read`: the whole STEP reader, faces with their (u, v) trim loops
//!   (edges without pcurves inverted onto their surfaces);
//! - `iges_read`: the whole IGES reader.
//!
//! `cargo bench --bench readers [-- GROUP]`; CI only compiles it.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

/// How many of the largest files of each format are timed.
const FILES_PER_FORMAT: usize = 3;

/// The folder the files come from: `SURFMESH_CORPUS`, else the shared
/// corpus beside the checkout, else the test corpus.
fn corpus_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("SURFMESH_CORPUS") {
        return PathBuf::from(d);
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/corpus");
    if shared.is_dir() {
        shared
    } else {
        root.join("tests/corpus")
    }
}

/// The `n` largest files in `dir` whose extension is one of `exts`, largest
/// first, with their bytes.
fn largest(dir: &Path, exts: &[&str], n: usize) -> Vec<(String, Vec<u8>)> {
    let mut found: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.extension().and_then(|e| e.to_str()).is_some_and(|e| exts.contains(&e.to_ascii_lowercase().as_str()))
        })
        .filter_map(|p| Some((std::fs::metadata(&p).ok()?.len(), p)))
        .collect();
    found.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    found
        .into_iter()
        .take(n)
        .filter_map(|(_, p)| {
            let name = p.file_name()?.to_string_lossy().into_owned();
            Some((name, std::fs::read(&p).ok()?))
        })
        .collect()
}

/// One group: `read` on each file, throughput in bytes read.
fn group<T>(c: &mut Criterion, name: &str, files: &[(String, Vec<u8>)], read: impl Fn(&[u8]) -> T) {
    let mut g = c.benchmark_group(name);
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
    for (file, bytes) in files {
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_with_input(BenchmarkId::from_parameter(file), bytes, |b, bytes| b.iter(|| black_box(read(bytes))));
    }
    g.finish();
}

fn readers(c: &mut Criterion) {
    let dir = corpus_dir();
    let step = largest(&dir, &["stp", "step", "p21"], FILES_PER_FORMAT);
    let iges = largest(&dir, &["igs", "iges"], FILES_PER_FORMAT);
    group(c, "step_text", &step, |b| surfmesh::count_step_instances(b).map_err(|e| e.to_string()));
    group(c, "step_read", &step, |b| surfmesh::read_step(b).map(|m| m.faces.len()).map_err(|e| e.to_string()));
    group(c, "iges_read", &iges, |b| surfmesh::read_iges(b).map(|m| m.faces.len()).map_err(|e| e.to_string()));
}

criterion_group!(benches, readers);
criterion_main!(benches);
