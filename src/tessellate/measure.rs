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
            let d = project_to_surface(surface, q, Some(hint), opts).distance;
            m.max = m.max.max(d);
            m.sum += d;
            m.count += 1;
        }
    }
    m
}
