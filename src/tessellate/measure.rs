//! Deviation of a triangle from the exact surface, as DESIGN.md defines it:
//! points on the triangle (edge points and interior samples of a barycentric
//! grid) projected onto the surface by Newton from their interpolated (u,v).

use glam::{DVec2, DVec3};

use crate::nurbs::{project_to_surface, ProjectionOptions, Surface};

/// What was measured on one triangle.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct TriMeasure {
    /// Largest sample distance.
    pub max: f64,
    /// Sum of sample distances.
    pub sum: f64,
    /// Number of samples.
    pub count: u32,
}

/// Projection settings for measuring: the hint is close, so few iterations do.
pub(crate) fn measure_projection() -> ProjectionOptions {
    ProjectionOptions { max_iterations: 8, parameter_tolerance: 1e-9, search_samples: 8 }
}

/// Samples the barycentric grid with `steps` divisions per edge (corners skipped:
/// they are surface points by construction) and measures their distance.
pub(crate) fn measure_triangle(
    surface: &dyn Surface,
    p: &[DVec3; 3],
    uv: &[DVec2; 3],
    steps: usize,
    opts: &ProjectionOptions,
) -> TriMeasure {
    let mut m = TriMeasure::default();
    let n = steps.max(2);
    let inv = 1.0 / n as f64;
    for i in 0..=n {
        for j in 0..=(n - i) {
            let k = n - i - j;
            if i == n || j == n || k == n {
                continue;
            }
            let (a, b, c) = (i as f64 * inv, j as f64 * inv, k as f64 * inv);
            let q = p[0] * a + p[1] * b + p[2] * c;
            let hint = uv[0] * a + uv[1] * b + uv[2] * c;
            let d = distance_from_hint(surface, q, hint, opts);
            m.max = m.max.max(d);
            m.sum += d;
            m.count += 1;
        }
    }
    m
}

/// Distance from `q` to the surface, starting at `hint` (the triangle's own
/// interpolated (u,v), so already close): Newton steps, each costing one
/// evaluation with derivatives, accepted only while they bring a surface point
/// closer. The result is always the distance to an actual surface point, so it
/// can only over-state the deviation, never hide it; iterations stop once a
/// step gains less than 1e-4 of the distance. Falls back to the general
/// projection if the steps cannot start.
pub(crate) fn distance_from_hint(surface: &dyn Surface, q: DVec3, hint: DVec2, opts: &ProjectionOptions) -> f64 {
    let [lo, hi] = surface.domain();
    let mut uv = hint.clamp(lo, hi);
    let mut d = surface.derivs(uv);
    let mut best = d.point.distance(q);
    for _ in 0..opts.max_iterations {
        let r = d.point - q;
        let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
        let a = d.su.length_squared();
        let b = d.su.dot(d.sv);
        let c = d.sv.length_squared();
        // Full Newton where the Hessian is positive definite, else Gauss-Newton.
        let (h00, h01, h11) = (a + d.suu.dot(r), b + d.suv.dot(r), c + d.svv.dot(r));
        let det = h00 * h11 - h01 * h01;
        let step = if det > 0.0 && h00 > 0.0 {
            DVec2::new(-(h11 * g.x - h01 * g.y) / det, -(h00 * g.y - h01 * g.x) / det)
        } else {
            let det = a * c - b * b;
            if det <= 0.0 {
                return best.min(project_to_surface(surface, q, Some(uv), opts).distance);
            }
            DVec2::new(-(c * g.x - b * g.y) / det, -(a * g.y - b * g.x) / det)
        };
        if !step.is_finite() {
            break;
        }
        let next = (uv + step).clamp(lo, hi);
        let dn = surface.derivs(next);
        let dist = dn.point.distance(q);
        if dist >= best {
            break;
        }
        let gain = best - dist;
        uv = next;
        d = dn;
        best = dist;
        if gain <= 1e-4 * best {
            break;
        }
    }
    best
}
