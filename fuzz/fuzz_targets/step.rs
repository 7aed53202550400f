//! Fuzz target: the STEP (ISO 10303-21) reader on arbitrary bytes. It must
//! return a model or an error, never panic, hang or allocate without bound;
//! a model it returns must mesh (or fail with an error) at a coarse tolerance.
#![no_main]

use libfuzzer_sys::fuzz_target;
use surfmesh::{mesh_model, read_step, MeshOptions};

fuzz_target!(|data: &[u8]| {
    if let Ok(model) = read_step(data) {
        // A small budget keeps each run short; errors are fine, panics are not.
        let options = MeshOptions::default().with_relative_tolerance(0.05).with_max_triangles(5_000);
        let _ = mesh_model(&model, &options);
    }
});
