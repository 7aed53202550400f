//! The scaling bench (issue 35): is any step of the mesher super-linear in
//! the size of the part? Two shapes, each at 10, 100, 1000 and 4000 holes,
//! written here as STEP text (the same files `bench/plate.mjs` writes for the
//! Node bench):
//!
//! - `plate`: one solid, a plate drilled with a grid of through holes (its
//!   top and bottom each one face with a loop per hole);
//! - `bodies`: the same grid as one drilled block per hole, each its own solid.
//!
//! Every size is meshed at one absolute tolerance (0.02 mm: every hole meshes
//! alike, so a flat time per face and per triangle means linear), read and
//! meshed `--runs` times (the best run counts). Times are the thread's CPU
//! time (`CLOCK_THREAD_CPUTIME_ID`, on Linux), so that other processes on a
//! shared machine do not count, else wall time. The table
//! gives time per face and per output triangle, each against the smallest
//! size, triangles per second, and, built with `--features timing`, the share
//! of the mesh time spent measuring deviation (the verified report's cost).
//!
//! `cargo bench --bench scaling [--features timing] -- [--runs N]
//! [--sizes 10,100,1000,4000] [--shapes plate,bodies] [--tol T] [--write DIR]`;
//! `--write DIR` writes the files (`plate_N.stp`, `bodies_N.stp`) for the
//! command line or a profiler instead of meshing them.

use std::fmt::Write as _;
use std::time::Instant;

use surfmesh::{mesh_model, read_model, Format, MeshOptions};

/// Holes on a 10 mm pitch, radius 3 mm, 5 mm thick; a block of `bodies` is 8 mm square.
const PITCH: f64 = 10.0;
const RADIUS: f64 = 3.0;
const THICK: f64 = 5.0;

/// A STEP file being written: entity lines and the next instance number.
struct Step {
    lines: String,
    id: usize,
}

impl Step {
    fn add(&mut self, text: &str) -> String {
        self.id += 1;
        let _ = writeln!(self.lines, "#{}={};", self.id, text);
        format!("#{}", self.id)
    }

    fn point(&mut self, p: [f64; 3]) -> String {
        self.add(&format!("CARTESIAN_POINT('',({},{},{}))", num(p[0]), num(p[1]), num(p[2])))
    }

    fn dir(&mut self, d: [f64; 3]) -> String {
        self.add(&format!("DIRECTION('',({},{},{}))", num(d[0]), num(d[1]), num(d[2])))
    }

    fn axis(&mut self, o: [f64; 3], z: [f64; 3], x: [f64; 3]) -> String {
        let (o, z, x) = (self.point(o), self.dir(z), self.dir(x));
        self.add(&format!("AXIS2_PLACEMENT_3D('',{o},{z},{x})"))
    }

    fn vertex(&mut self, p: [f64; 3]) -> String {
        let p = self.point(p);
        self.add(&format!("VERTEX_POINT('',{p})"))
    }

    fn line(&mut self, a: [f64; 3], b: [f64; 3]) -> String {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let p = self.point(a);
        let u = self.dir([d[0] / l, d[1] / l, d[2] / l]);
        let v = self.add(&format!("VECTOR('',{u},{})", num(l)));
        self.add(&format!("LINE('',{p},{v})"))
    }

    fn edge(&mut self, a: &str, b: &str, curve: &str) -> String {
        self.add(&format!("EDGE_CURVE('',{a},{b},{curve},.T.)"))
    }

    fn oriented(&mut self, e: &str, sense: bool) -> String {
        self.add(&format!("ORIENTED_EDGE('',*,*,{e},{})", flag(sense)))
    }

    fn bound(&mut self, kind: &str, edges: &[String]) -> String {
        let l = self.add(&format!("EDGE_LOOP('',({}))", edges.join(",")));
        self.add(&format!("{kind}('',{l},.T.)"))
    }

    fn face(&mut self, name: &str, bounds: &[String], surface: &str, sense: bool) -> String {
        self.add(&format!("ADVANCED_FACE('{name}',({}),{surface},{})", bounds.join(","), flag(sense)))
    }

    /// One closed shell: the box `lo`..`hi` (x, y) × [0, THICK], drilled at `centres`.
    fn solid(&mut self, name: &str, lo: [f64; 2], hi: [f64; 2], centres: &[[f64; 2]]) -> String {
        let t = THICK;
        let corners = [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]];
        let at = |i: usize, z: f64| [corners[i % 4][0], corners[i % 4][1], z];
        let b: Vec<String> = (0..4).map(|i| self.vertex(at(i, 0.0))).collect();
        let u: Vec<String> = (0..4).map(|i| self.vertex(at(i, t))).collect();
        let mut eb = Vec::new();
        let mut et = Vec::new();
        let mut ev = Vec::new();
        for i in 0..4 {
            let c = self.line(at(i, 0.0), at(i + 1, 0.0));
            eb.push(self.edge(&b[i], &b[(i + 1) % 4], &c));
        }
        for i in 0..4 {
            let c = self.line(at(i, t), at(i + 1, t));
            et.push(self.edge(&u[i], &u[(i + 1) % 4], &c));
        }
        for i in 0..4 {
            let c = self.line(at(i, 0.0), at(i, t));
            ev.push(self.edge(&b[i], &u[i], &c));
        }
        // Each hole: circles at both ends (counter-clockwise about +z) and a seam.
        let mut holes = Vec::new();
        for &[cx, cy] in centres {
            let vb = self.vertex([cx + RADIUS, cy, 0.0]);
            let vt = self.vertex([cx + RADIUS, cy, t]);
            let ab = self.axis([cx, cy, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
            let circle = self.add(&format!("CIRCLE('',{ab},{})", num(RADIUS)));
            let cb = self.edge(&vb, &vb, &circle);
            let at_top = self.axis([cx, cy, t], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
            let circle = self.add(&format!("CIRCLE('',{at_top},{})", num(RADIUS)));
            let ct = self.edge(&vt, &vt, &circle);
            let l = self.line([cx + RADIUS, cy, 0.0], [cx + RADIUS, cy, t]);
            let seam = self.edge(&vb, &vt, &l);
            holes.push((cx, cy, cb, ct, seam));
        }
        let mut faces = Vec::new();
        // Top (normal +z): outer loop counter-clockwise, holes clockwise.
        let outer: Vec<String> = et.iter().map(|e| self.oriented(e, true)).collect();
        let mut bounds = vec![self.bound("FACE_OUTER_BOUND", &outer)];
        for h in &holes {
            let e = self.oriented(&h.3, false);
            bounds.push(self.bound("FACE_BOUND", &[e]));
        }
        let plane = self.axis([0.0, 0.0, t], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let plane = self.add(&format!("PLANE('',{plane})"));
        faces.push(self.face("top", &bounds, &plane, true));
        // Bottom (normal -z): the same loops seen from below.
        let outer: Vec<String> = [3, 2, 1, 0].iter().map(|&i| self.oriented(&eb[i], false)).collect();
        let mut bounds = vec![self.bound("FACE_OUTER_BOUND", &outer)];
        for h in &holes {
            let e = self.oriented(&h.2, true);
            bounds.push(self.bound("FACE_BOUND", &[e]));
        }
        let plane = self.axis([0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]);
        let plane = self.add(&format!("PLANE('',{plane})"));
        faces.push(self.face("bottom", &bounds, &plane, true));
        // Sides: outward normals, loops counter-clockwise seen from outside.
        for i in 0..4 {
            let (p, q) = (at(i, 0.0), at(i + 1, 0.0));
            let l = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
            let along = [(q[0] - p[0]) / l, (q[1] - p[1]) / l, 0.0];
            let out = [along[1], -along[0], 0.0];
            let edges = [
                self.oriented(&eb[i], true),
                self.oriented(&ev[(i + 1) % 4], true),
                self.oriented(&et[i], false),
                self.oriented(&ev[i], false),
            ];
            let bound = self.bound("FACE_OUTER_BOUND", &edges);
            let plane = self.axis(p, out, along);
            let plane = self.add(&format!("PLANE('',{plane})"));
            faces.push(self.face(&format!("side {}", i + 1), &[bound], &plane, true));
        }
        // Hole walls: the cylinder's normal points away from its axis, into
        // the material, so each face takes the opposite sense.
        for (k, (cx, cy, cb, ct, seam)) in holes.iter().enumerate() {
            let edges = [
                self.oriented(cb, true),
                self.oriented(seam, true),
                self.oriented(ct, false),
                self.oriented(seam, false),
            ];
            let bound = self.bound("FACE_OUTER_BOUND", &edges);
            let a = self.axis([*cx, *cy, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
            let surface = self.add(&format!("CYLINDRICAL_SURFACE('',{a},{})", num(RADIUS)));
            faces.push(self.face(&format!("hole {}", k + 1), &[bound], &surface, false));
        }
        let shell = self.add(&format!("CLOSED_SHELL('',({}))", faces.join(",")));
        self.add(&format!("MANIFOLD_SOLID_BREP('{name}',{shell})"))
    }
}

/// A STEP real: integers with a trailing point, zero without a sign (as JavaScript prints it).
fn num(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    if x.fract() == 0.0 {
        format!("{x}.")
    } else {
        format!("{x}")
    }
}

fn flag(b: bool) -> &'static str {
    if b {
        ".T."
    } else {
        ".F."
    }
}

/// An `nx` × `ny` grid of holes: one drilled plate, or with `bodies` one drilled block per hole.
fn plate_step(nx: usize, ny: usize, bodies: bool) -> String {
    let mut s = Step { lines: String::new(), id: 0 };
    let unit = s.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))");
    let angle = s.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))");
    let solid_angle = s.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())");
    let accuracy =
        s.add(&format!("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-06),{unit},'distance_accuracy_value','')"));
    let context = s.add(&format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT(({accuracy}))\
         GLOBAL_UNIT_ASSIGNED_CONTEXT(({unit},{angle},{solid_angle}))REPRESENTATION_CONTEXT('',''))"
    ));
    let centre = |i: usize, j: usize| [(i as f64 + 0.5) * PITCH, (j as f64 + 0.5) * PITCH];
    let mut solids = Vec::new();
    if bodies {
        let half = 0.4 * PITCH;
        for i in 0..nx {
            for j in 0..ny {
                let [cx, cy] = centre(i, j);
                let name = format!("block {}", i * ny + j + 1);
                solids.push(s.solid(&name, [cx - half, cy - half], [cx + half, cy + half], &[[cx, cy]]));
            }
        }
    } else {
        let centres: Vec<[f64; 2]> = (0..nx).flat_map(|i| (0..ny).map(move |j| centre(i, j))).collect();
        solids.push(s.solid("plate", [0.0, 0.0], [nx as f64 * PITCH, ny as f64 * PITCH], &centres));
    }
    let origin = s.axis([0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let rep = s.add(&format!("ADVANCED_BREP_SHAPE_REPRESENTATION('',({origin},{}),{context})", solids.join(",")));
    let app = s.add("APPLICATION_CONTEXT('automotive design')");
    let pc = s.add(&format!("PRODUCT_CONTEXT('',{app},'mechanical')"));
    let product = s.add(&format!("PRODUCT('Plate','Plate {nx}x{ny} holes','',({pc}))"));
    let formation = s.add(&format!("PRODUCT_DEFINITION_FORMATION('','',{product})"));
    let def_context = s.add(&format!("PRODUCT_DEFINITION_CONTEXT('part definition',{app},'design')"));
    let definition = s.add(&format!("PRODUCT_DEFINITION('design','',{formation},{def_context})"));
    let shape = s.add(&format!("PRODUCT_DEFINITION_SHAPE('','',{definition})"));
    s.add(&format!("SHAPE_DEFINITION_REPRESENTATION({shape},{rep})"));
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('surfmesh stress {} {nx}x{ny}'),'2;1');\n\
         FILE_NAME('plate.stp','2026-01-01T00:00:00',(''),(''),'','','');\n\
         FILE_SCHEMA(('AUTOMOTIVE_DESIGN {{ 1 0 10303 214 1 1 1 1 }}'));\nENDSEC;\nDATA;\n{}ENDSEC;\nEND-ISO-10303-21;\n",
        if bodies { "blocks" } else { "plate" },
        s.lines
    )
}

/// The grid for `holes` holes: near-square, as the Node bench's.
fn grid_of(holes: usize) -> (usize, usize) {
    match holes {
        10 => (5, 2),
        100 => (10, 10),
        1000 => (40, 25),
        4000 => (80, 50),
        n => {
            let nx = (n as f64).sqrt().ceil() as usize;
            (nx, n.div_ceil(nx))
        }
    }
}

/// Seconds of CPU this thread has run.
#[cfg(target_os = "linux")]
fn clock(_: Instant) -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid timespec for the call to write.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Seconds of wall time since `start` (no thread clock here).
#[cfg(not(target_os = "linux"))]
fn clock(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// The best run of one size: parse and mesh seconds, faces, triangles, and
/// the share of the mesh time spent measuring.
struct Run {
    parse: f64,
    mesh: f64,
    faces: usize,
    bodies: usize,
    triangles: usize,
    measure: Option<f64>,
    ok: bool,
}

fn run(text: &str, tol: f64, runs: usize) -> Result<Run, String> {
    let options = MeshOptions::default().with_tolerance(tol);
    let mut best: Option<Run> = None;
    let start = Instant::now();
    for _ in 0..runs {
        let t0 = clock(start);
        let model = read_model(text.as_bytes(), Format::Step).map_err(|e| e.to_string())?;
        let parse = clock(start) - t0;
        let m0 = surfmesh::pipeline::measure_nanos();
        let (t1, w1) = (clock(start), Instant::now());
        let r = mesh_model(&model, &options).map_err(|e| e.to_string())?;
        let (mesh, wall) = (clock(start) - t1, w1.elapsed().as_secs_f64());
        // The measuring is timed by the wall clock: its share is of the wall time.
        let measure = surfmesh::pipeline::measure_nanos().zip(m0).map(|(b, a)| (b - a) as f64 * 1e-9 / wall);
        let rep = &r.report;
        let ok = rep.max_deviation <= rep.tolerance && rep.free_edges == 0 && rep.inverted_triangles == 0;
        let this = Run { parse, mesh, faces: rep.faces, bodies: rep.bodies, triangles: rep.triangles, measure, ok };
        if best.as_ref().is_none_or(|b| this.mesh + this.parse < b.mesh + b.parse) {
            best = Some(this);
        }
    }
    best.ok_or_else(|| "no runs".into())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    // `cargo bench` passes `--bench`; `cargo test --bench '*'` (the test
    // suite's check that every bench still runs) does not: one run of the
    // smallest size then, as criterion's test mode does.
    let smoke = !args.iter().any(|a| a == "--bench");
    let runs: usize = opt("--runs").and_then(|s| s.parse().ok()).unwrap_or(if smoke { 1 } else { 3 }).max(1);
    let tol: f64 = opt("--tol").and_then(|s| s.parse().ok()).unwrap_or(0.02);
    let sizes: Vec<usize> = opt("--sizes")
        .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or_else(|| if smoke { vec![10] } else { vec![10, 100, 1000, 4000] });
    let shapes: Vec<String> = opt("--shapes")
        .map(|s| s.split(',').map(str::to_owned).collect())
        .unwrap_or_else(|| vec!["plate".into(), "bodies".into()]);
    if let Some(dir) = opt("--write") {
        for shape in &shapes {
            for &holes in &sizes {
                let (nx, ny) = grid_of(holes);
                let path = std::path::Path::new(&dir).join(format!("{shape}_{}.stp", nx * ny));
                if let Err(e) = std::fs::write(&path, plate_step(nx, ny, shape == "bodies")) {
                    eprintln!("{}: {e}", path.display());
                    std::process::exit(1);
                }
                println!("wrote {}", path.display());
            }
        }
        return;
    }
    let cpu = cfg!(target_os = "linux");
    println!(
        "scaling: absolute tolerance {tol} mm, best of {runs} runs (parse + mesh), {} time",
        if cpu { "CPU" } else { "wall" }
    );
    println!(
        "{:<7} {:>6} {:>6} {:>6} {:>9} {:>9} {:>10} {:>9} {:>6} {:>9} {:>6} {:>10} {:>8} {:>6}",
        "shape",
        "holes",
        "faces",
        "bodies",
        "triangles",
        "parse ms",
        "mesh ms",
        "us/face",
        "x",
        "us/tri",
        "x",
        "tri/s",
        "measure",
        "ok"
    );
    for shape in &shapes {
        let bodies = shape == "bodies";
        let mut first: Option<(f64, f64)> = None;
        for &holes in &sizes {
            let (nx, ny) = grid_of(holes);
            let text = plate_step(nx, ny, bodies);
            let r = match run(&text, tol, runs) {
                Ok(r) => r,
                Err(e) => {
                    println!("{shape:<7} {holes:>6} failed: {e}");
                    continue;
                }
            };
            let per_face = 1e6 * r.mesh / r.faces.max(1) as f64;
            let per_tri = 1e6 * r.mesh / r.triangles.max(1) as f64;
            let (f0, t0) = *first.get_or_insert((per_face, per_tri));
            let share = r.measure.map_or_else(|| "n/a".into(), |m| format!("{:.1}%", 100.0 * m));
            println!(
                "{:<7} {:>6} {:>6} {:>6} {:>9} {:>9.1} {:>10.1} {:>9.1} {:>6.2} {:>9.2} {:>6.2} {:>10.0} {:>8} {:>6}",
                shape,
                nx * ny,
                r.faces,
                r.bodies,
                r.triangles,
                1e3 * r.parse,
                1e3 * r.mesh,
                per_face,
                per_face / f0,
                per_tri,
                per_tri / t0,
                r.triangles as f64 / r.mesh,
                share,
                if r.ok { "yes" } else { "NO" }
            );
        }
    }
    if surfmesh::pipeline::measure_nanos().is_none() {
        println!("(measure: the share of mesh time spent measuring deviation needs `--features timing`)");
    }
}
