//! Mesh repair (paper 002) on self-intersecting offset meshes of about the
//! sizes in the paper's table: 15k triangles (its Bunny: 2.45 s on a
//! 1.8 GHz Pentium 4) and 250k (its Pump, 256,672 triangles: 53.9 s), with
//! the paper's k-d tree bucketing and with the BVH.
//!
//! The input is a wavy torus (major radius 20, a tube of semi-axes 5 radial
//! and 2 in z whose size ripples around the axis), as a regular grid of
//! `nu × nv` quads split in two, offset inward by 1.5: the tube's inner and
//! outer equators have radii of curvature near 0.8, so they fold into
//! self-intersecting fins all around. `bench/repair.mjs` builds the same
//! mesh for the wasm package.
//!
//! `cargo bench --bench repair` measures 15k and 250k; `cargo test --bench
//! repair` (criterion's test mode: no `--bench` argument, as CI runs it in
//! the debug profile) runs a 2k-triangle case once, so a broken bench fails
//! there without the minutes the full sizes take unoptimized.

use std::f64::consts::TAU;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use surfmesh::{offset_mesh, repair_mesh, repair_mesh_timed, Bucketing, Mesh, RepairOptions};

/// The wavy torus grid: `2 nu nv` triangles, closed, facing outward.
fn wavy_torus(nu: usize, nv: usize) -> Mesh {
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = TAU * i as f64 / nu as f64;
        let ripple = 1.0 + 0.15 * (5.0 * u).sin();
        for j in 0..nv {
            let v = TAU * j as f64 / nv as f64;
            let r = 20.0 + 5.0 * ripple * v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), 2.0 * ripple * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut indices = Vec::with_capacity(6 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    Mesh { positions, normals: Vec::new(), indices, face_ranges: Vec::new() }
}

/// The benchmark input: the wavy torus offset inward by 1.5.
fn input(nu: usize, nv: usize) -> Mesh {
    offset_mesh(&wavy_torus(nu, nv), -1.5).expect("offset of a closed grid")
}

fn bench(c: &mut Criterion) {
    let full = std::env::args().any(|a| a == "--bench");
    let sizes = if full { vec![("15k", 122, 62), ("250k", 500, 250)] } else { vec![("2k", 44, 24)] };
    for (name, nu, nv) in sizes {
        let mesh = input(nu, nv);
        let mut group = c.benchmark_group(format!("repair_{name}"));
        group.sample_size(10);
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        for (label, b) in [("kd_tree", Bucketing::KdTree), ("bvh", Bucketing::Bvh)] {
            let options = RepairOptions::default().with_bucketing(b);
            let start = std::time::Instant::now();
            let mut clock = || start.elapsed().as_secs_f64() * 1e3;
            let r = repair_mesh_timed(&mesh, &options, &mut clock).expect("repair");
            let rep = &r.report;
            eprintln!(
                "repair_{name}/{label}: {} -> {} triangles, {} candidate pairs, {} segments, {} regions, census {:?}, ms {:?}",
                rep.triangles_in, rep.triangles_out, rep.candidate_pairs, rep.segments, rep.regions, rep.census_out, rep.time_ms
            );
            group.bench_function(label, |bencher| bencher.iter(|| repair_mesh(black_box(&mesh), &options)));
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
