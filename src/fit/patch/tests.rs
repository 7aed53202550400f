use super::*;
use crate::fit::curvenet::edge_curve;

/// Deterministic uniform numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Corners of an n-gon on the unit sphere around the north pole at polar
/// angle `rho`, jittered; normals radial; edges by the paper's construction.
fn sphere_polygon(n: usize, rho: f64, jitter: f64, rng: &mut Rng) -> (Vec<DVec3>, Vec<DVec3>, Vec<Cubic>) {
    let tau = core::f64::consts::TAU;
    let z: Vec<DVec3> = (0..n)
        .map(|i| {
            let phi = tau * (i as f64 + jitter * (rng.next() - 0.5)) / n as f64;
            let r = rho * (1.0 + jitter * (rng.next() - 0.5));
            DVec3::new(r.sin() * phi.cos(), r.sin() * phi.sin(), r.cos())
        })
        .collect();
    let normals = z.clone();
    let edges = (0..n).map(|i| edge_curve(z[i], normals[i], z[(i + 1) % n], normals[(i + 1) % n]).unwrap()).collect();
    (z, normals, edges)
}

/// Largest normal angle across the spokes of one filled polygon, at `samples` points per spoke.
fn spoke_angle(patches: &[TriPatch], samples: usize) -> f64 {
    let n = patches.len();
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let (left, right) = (&patches[(i + n - 1) % n], &patches[i]);
        for s in 0..=samples {
            let t = s as f64 / samples as f64 * 0.999;
            let a = left.eval(1.0 - t, t);
            let b = right.eval(0.0, t);
            assert!((a.point - b.point).length() < 1e-12);
            worst = worst.max(crate::math::angle_between(a.normal(), b.normal()));
        }
    }
    worst
}

#[test]
fn every_polygon_size_meets_g1_inside_and_interpolates_its_corners() {
    let mut rng = Rng(7);
    for n in 3..=8 {
        for trial in 0..20 {
            let (z, normals, edges) = sphere_polygon(n, 0.3, if trial == 0 { 0.0 } else { 0.3 }, &mut rng);
            let patches =
                fill_polygon(&z, &normals, &edges, 3.0).unwrap_or_else(|e| panic!("n {n} trial {trial}: {e:?}"));
            assert_eq!(patches.len(), n);
            for (i, p) in patches.iter().enumerate() {
                assert_eq!(p.eval(0.0, 0.0).point, z[i]);
                assert_eq!(p.eval(1.0, 0.0).point, z[(i + 1) % n]);
                // The corner's tangent plane is the given one.
                assert!(p.eval(0.0, 0.0).normal().dot(normals[i]) > 1.0 - 1e-12);
            }
            let angle = spoke_angle(&patches, 40);
            assert!(angle < 1e-9, "n {n} trial {trial}: spoke angle {angle}");
            // Close to the sphere: within 2 % of the radius everywhere. (The
            // centre comes from quadratic extrapolation along the spokes, eqs.
            // 11–13, whose error grows with the cube of the polygon's size:
            // about 0.5 % here, where the polygon spans 0.3 rad.)
            for p in &patches {
                for a in 0..=8 {
                    for b in 0..=8 - a {
                        let r = p.eval(a as f64 / 8.0, b as f64 / 8.0).point.length();
                        assert!((r - 1.0).abs() < 0.02, "n {n} trial {trial}: radius {r}");
                    }
                }
            }
        }
    }
}

#[test]
fn neighbouring_polygons_meet_g1_along_their_shared_edge() {
    // Two quads of a curved sheet z = 0.3 sin(x) cos(y) sharing the edge (1, 0) – (1, 1).
    let f = |x: f64, y: f64| DVec3::new(x, y, 0.3 * x.sin() * (1.3 * y).cos());
    let nrm = |x: f64, y: f64| {
        DVec3::new(-0.3 * x.cos() * (1.3 * y).cos(), 0.39 * x.sin() * (1.3 * y).sin(), 1.0).normalize()
    };
    let quad = |xs: [(f64, f64); 4]| {
        let z: Vec<DVec3> = xs.iter().map(|&(x, y)| f(x, y)).collect();
        let n: Vec<DVec3> = xs.iter().map(|&(x, y)| nrm(x, y)).collect();
        let e: Vec<Cubic> = (0..4).map(|i| edge_curve(z[i], n[i], z[(i + 1) % 4], n[(i + 1) % 4]).unwrap()).collect();
        fill_polygon(&z, &n, &e, 3.0).unwrap()
    };
    let left = quad([(0.0, 0.1), (1.0, 0.0), (1.0, 1.0), (0.1, 0.9)]);
    let right = quad([(1.0, 0.0), (2.2, 0.2), (1.9, 1.1), (1.0, 1.0)]);
    // Edge 1 of `left` runs (1,0) → (1,1); edge 3 of `right` runs (1,1) → (1,0).
    let mut worst: f64 = 0.0;
    for s in 0..=50 {
        let t = s as f64 / 50.0;
        let a = left[1].eval(t, 0.0);
        let b = right[3].eval(1.0 - t, 0.0);
        assert!((a.point - b.point).length() < 1e-14);
        worst = worst.max(crate::math::angle_between(a.normal(), b.normal()));
    }
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn a_flat_polygon_gives_flat_patches() {
    let z: Vec<DVec3> = [(0.0, 0.0), (2.0, 0.1), (2.5, 1.5), (1.0, 2.2), (-0.3, 1.1)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
    let normals = vec![DVec3::Z; 5];
    let edges: Vec<Cubic> = (0..5).map(|i| edge_curve(z[i], DVec3::Z, z[(i + 1) % 5], DVec3::Z).unwrap()).collect();
    let patches = fill_polygon(&z, &normals, &edges, 3.0).unwrap();
    assert!(patches.iter().flat_map(|p| p.points.iter()).all(|p| p.z.abs() < 1e-14));
}

#[test]
fn concave_and_degenerate_polygons_are_refused() {
    let z: Vec<DVec3> =
        [(0.0, 0.0), (2.0, 0.0), (1.0, 0.3), (1.0, 2.0)].iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    let normals = vec![DVec3::Z; 4];
    let edges: Vec<Cubic> = (0..4).map(|i| edge_curve(z[i], DVec3::Z, z[(i + 1) % 4], DVec3::Z).unwrap()).collect();
    assert_eq!(fill_polygon(&z, &normals, &edges, 3.0), Err(PatchError::NotConvex));
    assert_eq!(fill_polygon(&z[..2], &normals[..2], &edges[..2], 3.0), Err(PatchError::Shape));
}
