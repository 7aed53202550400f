//! Peak heap of reading and meshing a file, natively, by a counting
//! allocator: what the wasm module's linear memory has to hold.
//!
//! `cargo run --release --example memprobe -- FILE [REL]`

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use surfmesh::{mesh_model, read_model, Format, MeshOptions};

struct Counting;
static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let n = NOW.fetch_add(l.size(), Relaxed) + l.size();
        PEAK.fetch_max(n, Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        NOW.fetch_sub(l.size(), Relaxed);
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        if new > l.size() {
            let n = NOW.fetch_add(new - l.size(), Relaxed) + new - l.size();
            PEAK.fetch_max(n, Relaxed);
        } else {
            NOW.fetch_sub(l.size() - new, Relaxed);
        }
        System.realloc(p, l, new)
    }
}

#[global_allocator]
static A: Counting = Counting;

fn mb(n: usize) -> f64 {
    n as f64 / 1e6
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = &args[1];
    let rel: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1e-3);
    let bytes = std::fs::read(path).expect("read");
    let base = NOW.load(Relaxed);
    PEAK.store(base, Relaxed);
    let model = read_model(&bytes, Format::detect(&bytes).expect("format")).expect("parse");
    let after_parse = NOW.load(Relaxed);
    println!(
        "input {:.2} MB; parse peak {:.2} MB, model {:.2} MB",
        mb(bytes.len()),
        mb(PEAK.load(Relaxed) - base),
        mb(after_parse - base)
    );
    let parse_peak = PEAK.load(Relaxed) - base;
    PEAK.store(after_parse, Relaxed);
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(rel)).expect("mesh");
    let out = r.mesh.positions.len() * 24 + r.mesh.indices.len() * 4;
    let mesh_peak = PEAK.load(Relaxed) - base;
    println!(
        "mesh peak {:.2} MB over the model ({:.2} MB over the input); {} tris, output (f32 pos + normals + u32 idx) {:.2} MB",
        mb(mesh_peak - (after_parse - base)),
        mb(mesh_peak),
        r.report.triangles,
        mb(out)
    );
    // The wasm binding holds the input bytes through the whole call.
    let total = bytes.len() + parse_peak.max(mesh_peak);
    println!("total peak {:.2} MB = {:.1} x the output", mb(total), total as f64 / out.max(1) as f64);
}
