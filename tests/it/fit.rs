//! Surfaces through scattered points (paper 004): points sampled at random
//! from known surfaces, fitted, and the fit checked against what the paper
//! promises: it passes through every point, sub-patches meet G¹, an n-gon
//! takes n sub-patches, and it stays near the surface the points came from.

use glam::{DVec2, DVec3};
use surfmesh::{
    edge_counts, fit_points, project_to_surface, read_iges, read_points, Error, FitOptions, FitResult, PointFormat,
    ProjectionOptions, Surface, WarningKind,
};

/// Deterministic uniform numbers in [0, 1) (xorshift64*), fixed seeds.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Random points from `sample` (which returns candidate surface points), no
/// two closer than `min_gap`: irregular spacing without near-duplicates.
fn dart_throw(n: usize, min_gap: f64, rng: &mut Rng, mut sample: impl FnMut(&mut Rng) -> DVec3) -> Vec<DVec3> {
    let mut pts: Vec<DVec3> = Vec::with_capacity(n);
    let mut tries = 0;
    while pts.len() < n {
        tries += 1;
        assert!(tries < 200 * n, "min_gap too large for {n} points");
        let p = sample(rng);
        if pts.iter().all(|q| q.distance(p) >= min_gap) {
            pts.push(p);
        }
    }
    pts
}

/// What a fit is measured by, printed for the report and asserted on.
struct Figures {
    points: usize,
    polygons: usize,
    sides: Vec<usize>,
    sub_patches: usize,
    classic: usize,
    max_interpolation: f64,
    max_g1: f64,
    max_distance: f64,
    mean_distance: f64,
    triangles: usize,
}

/// Checks the paper's promises on `fit` of `input` and measures the distance
/// to the true surface with `distance` (points → unsigned distance) on a
/// barycentric grid of `steps` segments per sub-patch edge.
fn measure(name: &str, input: &[DVec3], fit: &FitResult, steps: usize, distance: impl Fn(DVec3) -> f64) -> Figures {
    let s = &fit.surface;
    let (lo, hi) =
        input.iter().fold((DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)), |(l, h), p| (l.min(*p), h.max(*p)));
    let diag = (hi - lo).length();

    // Interpolation: every input point is a polygon corner, and each sub-patch
    // at that corner evaluates to it.
    let mut at_corner = vec![false; s.points.len()];
    let mut max_interpolation: f64 = 0.0;
    for poly in &s.polygons {
        let n = poly.corners.len();
        assert_eq!(poly.patches.len(), n, "{name}: an n-gon has n sub-patches");
        for i in 0..n {
            let (a, b) = (poly.corners[i], poly.corners[(i + 1) % n]);
            at_corner[a as usize] = true;
            max_interpolation =
                max_interpolation.max(poly.patches[i].eval(0.0, 0.0).point.distance(s.points[a as usize]));
            max_interpolation =
                max_interpolation.max(poly.patches[i].eval(1.0, 0.0).point.distance(s.points[b as usize]));
        }
    }
    for (i, p) in input.iter().enumerate() {
        let v = fit.point_index[i] as usize;
        assert!(at_corner[v], "{name}: input point {i} is no polygon corner");
        max_interpolation = max_interpolation.max(p.distance(s.points[v]));
    }
    assert!(max_interpolation <= 1e-9 * diag, "{name}: interpolation error {max_interpolation:e}");

    // G¹ at many points of every shared border, independently of the report's sampling.
    let max_g1 = s.max_g1_angle(40);
    assert!(max_g1 <= 1e-6, "{name}: normals differ by {max_g1:e} rad across a border");

    // Sub-patch count: the sum of the polygons' sides.
    let sub_patches: usize = s.polygons.iter().map(|p| p.patches.len()).sum();
    let sides_sum: usize = s.polygons.iter().map(|p| p.corners.len()).sum();
    assert_eq!(sub_patches, sides_sum);
    assert_eq!(fit.report.sub_patches, sub_patches);
    let classic: usize = s.polygons.iter().map(|p| 3 * (p.corners.len() - 2)).sum();
    assert_eq!(fit.report.sub_patches_triangular, classic);
    let mut sides = vec![0; 9];
    for p in &s.polygons {
        let n = p.corners.len().min(8);
        sides[n] += 1;
    }

    // Distance to the true surface over a barycentric grid of every sub-patch.
    let (mut max_distance, mut sum, mut count): (f64, f64, usize) = (0.0, 0.0, 0);
    for poly in &s.polygons {
        for patch in &poly.patches {
            for a in 0..=steps {
                for b in 0..=steps - a {
                    let d = distance(patch.eval(a as f64 / steps as f64, b as f64 / steps as f64).point);
                    max_distance = max_distance.max(d);
                    sum += d;
                    count += 1;
                }
            }
        }
    }
    let f = Figures {
        points: input.len(),
        polygons: s.polygons.len(),
        sides,
        sub_patches,
        classic,
        max_interpolation,
        max_g1,
        max_distance,
        mean_distance: sum / count as f64,
        triangles: fit.mesh.triangle_count(),
    };
    eprintln!(
        "fit {name}: {} points, {} polygons (sides 3..8: {:?}), {} sub-patches vs {} for 3(n-2), \
         interpolation {:.1e}, G1 {:.1e} rad, distance to true surface max {:.3e} mean {:.3e} (diag {:.3}), \
         {} triangles, report {:?}",
        f.points,
        f.polygons,
        &f.sides[3..],
        f.sub_patches,
        f.classic,
        f.max_interpolation,
        f.max_g1,
        f.max_distance,
        f.mean_distance,
        diag,
        f.triangles,
        fit.report
    );
    f
}

fn sphere_points(n: usize, seed: u64) -> (Vec<DVec3>, DVec3, f64) {
    let (c, r) = (DVec3::new(0.4, -0.2, 1.0), 1.5);
    let mut rng = Rng(seed);
    let gap = 0.5 * r * (4.0 * std::f64::consts::PI / n as f64).sqrt();
    let pts = dart_throw(n, gap, &mut rng, |rng| {
        let z = 2.0 * rng.next() - 1.0;
        let t = std::f64::consts::TAU * rng.next();
        let s = (1.0 - z * z).sqrt();
        c + DVec3::new(s * t.cos(), s * t.sin(), z) * r
    });
    (pts, c, r)
}

#[test]
fn sphere_points_give_a_closed_g1_surface_through_every_point() {
    let (pts, c, r) = sphere_points(160, 1);
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    let f = measure("sphere", &pts, &fit, 6, |p| ((p - c).length() - r).abs());
    assert!(f.polygons < fit.net.len(), "triangles merge into fewer polygons");
    assert!(f.sub_patches < f.classic, "fewer sub-patches than the classic split");
    assert!(f.max_distance < 0.05 * r, "distance {}", f.max_distance);
    // Closed and watertight: every mesh edge has two triangles.
    let counts = edge_counts(&fit.mesh, 1e-9, 0.0);
    assert_eq!((counts.boundary_edges, counts.nonmanifold_edges), (0, 0));
    assert_eq!((fit.report.boundary_edges, fit.report.nonmanifold_edges), (0, 0));
}

#[test]
fn torus_points_give_a_closed_g1_surface_of_genus_one() {
    let (big, small) = (2.0, 0.7);
    let mut rng = Rng(2);
    let n = 420;
    let area = 4.0 * std::f64::consts::PI.powi(2) * big * small;
    let pts = dart_throw(n, 0.5 * (area / n as f64).sqrt(), &mut rng, |rng| loop {
        let (u, v) = (std::f64::consts::TAU * rng.next(), std::f64::consts::TAU * rng.next());
        // Uniform by area: accept with probability (R + r cos v) / (R + r).
        if rng.next() * (big + small) <= big + small * v.cos() {
            let w = big + small * v.cos();
            break DVec3::new(w * u.cos(), w * u.sin(), small * v.sin());
        }
    });
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    let f = measure("torus", &pts, &fit, 6, |p| {
        let q = DVec2::new(DVec2::new(p.x, p.y).length() - big, p.z);
        (q.length() - small).abs()
    });
    assert!(f.sub_patches < f.classic);
    assert!(f.max_distance < 0.1 * small, "distance {}", f.max_distance);
    // Closed, and of genus one: V − E + F = 0 on the triangle net.
    let counts = edge_counts(&fit.mesh, 1e-9, 0.0);
    assert_eq!((counts.boundary_edges, counts.nonmanifold_edges), (0, 0));
    let edges = 3 * fit.net.len() / 2;
    assert_eq!(fit.surface.points.len() as i64 - edges as i64 + fit.net.len() as i64, 0);
}

/// Uniform random points with no spacing rule: clusters and gaps of every
/// size, where the local umbrellas overlap and leave gaps ear clipping alone
/// cannot close (the gap is widened and refilled).
#[test]
fn uniformly_random_points_with_clusters_and_gaps_give_closed_g1_surfaces() {
    // The patches are what is measured; a coarse mesh of them keeps the test quick.
    let coarse = FitOptions::default().with_relative_tolerance(1e-2);
    for seed in [1, 4] {
        let mut rng = Rng(seed * 7919);
        let pts: Vec<DVec3> = (0..500)
            .map(|_| {
                let z = 2.0 * rng.next() - 1.0;
                let t = std::f64::consts::TAU * rng.next();
                let s = (1.0 - z * z).sqrt();
                DVec3::new(s * t.cos(), s * t.sin(), z)
            })
            .collect();
        let fit = fit_points(&pts, &coarse).unwrap();
        let f = measure(&format!("uniform sphere seed {seed}"), &pts, &fit, 4, |p| (p.length() - 1.0).abs());
        assert!(f.max_distance < 0.05, "distance {}", f.max_distance);
        assert_eq!((fit.report.boundary_edges, fit.report.nonmanifold_edges, fit.report.holes_open), (0, 0, 0));
        assert!(fit.report.warnings.is_empty(), "{:?}", fit.report.warnings);
    }
    // A torus uniform in its angles: twice as dense inside as outside.
    let (big, small) = (2.0, 0.7);
    let mut rng = Rng(31);
    let pts: Vec<DVec3> = (0..600)
        .map(|_| {
            let (u, v) = (std::f64::consts::TAU * rng.next(), std::f64::consts::TAU * rng.next());
            let w = big + small * v.cos();
            DVec3::new(w * u.cos(), w * u.sin(), small * v.sin())
        })
        .collect();
    let fit = fit_points(&pts, &coarse).unwrap();
    let f = measure("uniform-angle torus", &pts, &fit, 4, |p| {
        let q = DVec2::new(DVec2::new(p.x, p.y).length() - big, p.z);
        (q.length() - small).abs()
    });
    // Sparse outside: the largest deviation is where the gaps are widest.
    assert!(f.max_distance < 0.2 * small, "distance {}", f.max_distance);
    assert_eq!((fit.report.boundary_edges, fit.report.nonmanifold_edges, fit.report.holes_open), (0, 0, 0));
    assert!(fit.report.warnings.is_empty(), "{:?}", fit.report.warnings);
}

/// Two unit spheres at x = ±1.15 joined by a smooth-minimum blend (k = 3):
/// `f = −ln(e^(−k d1) + e^(−k d2)) / k`, `d_i` the distance to sphere i; the
/// surface is `f = 0`, with a neck of radius about 0.44 at x = 0.
fn blend(p: DVec3) -> (f64, DVec3) {
    let k = 3.0;
    let (c1, c2) = (DVec3::new(-1.15, 0.0, 0.0), DVec3::new(1.15, 0.0, 0.0));
    let (d1, d2) = ((p - c1).length() - 1.0, (p - c2).length() - 1.0);
    let m = d1.min(d2);
    let (e1, e2) = ((-k * (d1 - m)).exp(), (-k * (d2 - m)).exp());
    let f = m - (e1 + e2).ln() / k;
    let grad = ((p - c1).normalize() * e1 + (p - c2).normalize() * e2) / (e1 + e2);
    (f, grad)
}

#[test]
fn two_spheres_joined_by_a_blend_give_one_closed_g1_surface() {
    let mut rng = Rng(3);
    let n = 420;
    // Random points in the box, pulled onto f = 0 by Newton steps.
    let pts = dart_throw(n, 0.11, &mut rng, |rng| loop {
        let mut p = DVec3::new(4.6 * rng.next() - 2.3, 2.4 * rng.next() - 1.2, 2.4 * rng.next() - 1.2);
        for _ in 0..50 {
            let (f, g) = blend(p);
            p -= g * (f / g.length_squared());
        }
        if blend(p).0.abs() < 1e-13 && p.abs().max_element() < 3.0 {
            break p;
        }
    });
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    let f = measure("blend", &pts, &fit, 6, |p| {
        let (f, g) = blend(p);
        f.abs() / g.length()
    });
    assert!(f.sub_patches < f.classic);
    assert!(f.max_distance < 0.05, "distance {}", f.max_distance);
    let counts = edge_counts(&fit.mesh, 1e-9, 0.0);
    assert_eq!((counts.boundary_edges, counts.nonmanifold_edges), (0, 0));
    // A sphere's topology: V − E + F = 2.
    let edges = 3 * fit.net.len() / 2;
    assert_eq!(fit.surface.points.len() as i64 - edges as i64 + fit.net.len() as i64, 2);
}

#[test]
fn points_of_a_corpus_surface_give_an_open_g1_sheet_near_it() {
    let model = read_iges(&crate::corpus_files::corpus_bytes("PRO20359-L1.igs")).unwrap();
    let surface = &model.faces[0].surface;
    let [lo, hi] = surface.domain();
    let mut rng = Rng(4);
    // Dart throwing over the surface's parameters, keeping each point's (u, v).
    let (mut pts, mut kept): (Vec<DVec3>, Vec<DVec2>) = (Vec::new(), Vec::new());
    while pts.len() < 200 {
        let uv = lo + (hi - lo) * DVec2::new(rng.next(), rng.next());
        let p = surface.point(uv);
        if pts.iter().all(|q| q.distance(p) >= 11.0) {
            pts.push(p);
            kept.push(uv);
        }
    }
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    let options = ProjectionOptions::default();
    let f = measure("corpus PRO20359-L1 face 0", &pts, &fit, 3, |p| {
        // Newton from the nearest sample's parameters.
        let near = (0..pts.len()).min_by(|&a, &b| pts[a].distance(p).total_cmp(&pts[b].distance(p))).unwrap();
        project_to_surface(surface, p, Some(kept[near]), &options).distance
    });
    assert!(f.sub_patches < f.classic);
    let diag = surface.bounding_box().diagonal();
    assert!(f.max_distance < 0.02 * diag, "distance {} of diagonal {diag}", f.max_distance);
    // An open sheet: one border loop, no gaps left, no edge with three triangles.
    assert_eq!((fit.report.borders, fit.report.holes_open), (1, 0));
    assert!(fit.report.boundary_edges > 0);
    assert_eq!(fit.report.nonmanifold_edges, 0);
}

#[test]
fn points_on_one_plane_give_the_flat_region_they_span() {
    let mut rng = Rng(5);
    let (o, u, v) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 1.0, 0.0).normalize(), DVec3::new(0.0, 0.0, 1.0));
    let pts = dart_throw(80, 0.05, &mut rng, |rng| o + u * rng.next() + v * rng.next());
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    let normal = u.cross(v);
    let f = measure("plane", &pts, &fit, 6, |p| (p - o).dot(normal).abs());
    assert!(f.max_distance < 1e-12);
    assert!(fit.mesh.positions.iter().all(|p| (*p - o).dot(normal).abs() < 1e-12));
    assert!(fit.report.warnings.iter().any(|w| w.kind == WarningKind::Planar), "{:?}", fit.report.warnings);
}

#[test]
fn degenerate_inputs_are_refused_with_clear_errors() {
    let msg = |pts: &[DVec3]| fit_points(pts, &FitOptions::default()).unwrap_err().to_string();
    let line: Vec<DVec3> = (0..10).map(|i| DVec3::new(1.0, 2.0, 3.0) * i as f64).collect();
    assert!(msg(&line).starts_with("fit: the 10 points lie on one line"), "{}", msg(&line));
    let three = [DVec3::ZERO, DVec3::X, DVec3::Y];
    assert_eq!(msg(&three), "fit: at least 4 points are needed, found 3");
    let dup = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Y, DVec3::X];
    assert_eq!(msg(&dup), "fit: at least 4 distinct points are needed, found 3");
    let nan = [DVec3::ZERO, DVec3::X, DVec3::new(0.0, f64::NAN, 0.0), DVec3::Z];
    assert_eq!(msg(&nan), "fit: point 2 has a coordinate that is not finite");
    assert!(matches!(fit_points(&nan, &FitOptions::default()), Err(Error::Fit(_))));
    let bad = FitOptions::default().with_relative_tolerance(2.0);
    assert_eq!(fit_points(&line, &bad).unwrap_err().to_string(), "option tol-rel: must be in (0, 1)");
}

#[test]
fn duplicate_points_merge_with_a_warning_and_are_still_interpolated() {
    let (mut pts, c, r) = sphere_points(60, 6);
    pts.push(pts[7]);
    pts.push(pts[11] + DVec3::splat(1e-12));
    let fit = fit_points(&pts, &FitOptions::default()).unwrap();
    assert_eq!(fit.report.duplicates_merged, 2);
    assert_eq!(fit.point_index[60], fit.point_index[7]);
    let merged = |w: &&surfmesh::Warning| matches!(w.kind, WarningKind::DuplicatesMerged { count: 2, .. });
    assert!(fit.report.warnings.iter().any(|w| merged(&w)), "{:?}", fit.report.warnings);
    // The warning's text, as the report shows it.
    let text = fit.report.warnings.iter().find(merged).unwrap().to_string();
    assert!(text.starts_with("2 duplicate point(s) merged (closer than "), "{text}");
    measure("sphere with duplicates", &pts, &fit, 6, |p| ((p - c).length() - r).abs());
}

#[test]
fn point_files_read_from_tests_data() {
    let data = |name: &str| {
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
    };
    let xyz = read_points(&data("points_tetra.xyz"), PointFormat::Xyz).unwrap();
    let csv = read_points(&data("points_tetra.csv"), PointFormat::Csv).unwrap();
    let ply = read_points(&data("points_tetra.ply"), PointFormat::Ply).unwrap();
    assert_eq!(xyz.len(), 6);
    assert_eq!(xyz, csv);
    assert_eq!(xyz, ply);
    assert_eq!(PointFormat::detect(&data("points_tetra.ply")), PointFormat::Ply);
    let e = read_points(b"0 0 0\n1 0 0\n0 1\n", PointFormat::Xyz).unwrap_err();
    assert_eq!(e.to_string(), "points line 3: expected 3 numbers (x y z), found 2");
}

// ---------------------------------------------------------------- command line

const BIN: &str = env!("CARGO_BIN_EXE_surfmesh");

/// A fresh, empty directory for one test's files.
fn scratch(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("surfmesh-it-fit-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn cli_fit_writes_mesh_patches_and_report() {
    let dir = scratch("cli");
    let (pts, c, r) = sphere_points(80, 7);
    let text: String = pts.iter().map(|p| format!("{} {} {}\n", p.x, p.y, p.z)).collect();
    let input = dir.join("sphere.xyz");
    std::fs::write(&input, text).unwrap();
    let (stl, json, report) = (dir.join("s.stl"), dir.join("p.json"), dir.join("r.json"));
    let out = std::process::Command::new(BIN)
        .arg("fit")
        .arg(&input)
        .args(["--tol", "0.01", "-o"])
        .arg(&stl)
        .arg("--patches")
        .arg(&json)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("80 points") && err.contains("sub-patches"), "{err}");
    let rep: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(rep["points"], 80);
    assert_eq!(rep["tolerance"], 0.01);
    // Binary STL: 80-byte header, count, 50 bytes per triangle.
    let bytes = std::fs::read(&stl).unwrap();
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(n as u64, rep["triangles"].as_u64().unwrap());
    assert_eq!(bytes.len(), 84 + 50 * n);
    // The patches: every control net has 15 points, corners are input points, all near the sphere.
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(doc["format"], "surfmesh-fit");
    let polygons = doc["polygons"].as_array().unwrap();
    assert_eq!(polygons.len() as u64, rep["polygons"].as_u64().unwrap());
    let point =
        |v: &serde_json::Value| DVec3::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap(), v[2].as_f64().unwrap());
    for poly in polygons {
        let corners = poly["corners"].as_array().unwrap();
        let patches = poly["patches"].as_array().unwrap();
        assert_eq!(corners.len(), patches.len());
        for (k, patch) in patches.iter().enumerate() {
            let cps = patch.as_array().unwrap();
            assert_eq!(cps.len(), 15);
            let corner = &doc["points"][corners[k].as_u64().unwrap() as usize];
            assert_eq!(point(&cps[0]), point(corner));
            assert!(((point(&cps[14]) - c).length() - r).abs() < 0.2 * r);
        }
    }
    assert!(!doc["edges"].as_array().unwrap().is_empty());
}

#[test]
fn cli_fit_errors_name_the_file_and_line() {
    let dir = scratch("cli-errors");
    let input = dir.join("bad.xyz");
    std::fs::write(&input, "0 0 0\n1 0 0\n0 1\n").unwrap();
    let out = std::process::Command::new(BIN).arg("fit").arg(&input).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim(),
        format!("surfmesh: {}: points line 3: expected 3 numbers (x y z), found 2", input.display())
    );
    std::fs::write(&input, "0 0 0\n1 1 1\n2 2 2\n3 3 3\n4 4 4\n").unwrap();
    let out = std::process::Command::new(BIN).arg("fit").arg(&input).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("fit: the 5 points lie on one line"));
    let out = std::process::Command::new(BIN).args(["fit", "--tol"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stderr).trim(), "surfmesh: --tol needs a value");
    assert!(!dir.join("out.stl").exists());
}
