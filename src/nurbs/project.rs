//! Closest-point projection onto a surface (Newton with safeguards).

use glam::{DVec2, DVec3};

use super::Surface;

/// Settings for [`project_to_surface`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ProjectionOptions {
    /// Newton iterations at most.
    pub max_iterations: usize,
    /// Stop when the parameter step is below this fraction of the domain size.
    pub parameter_tolerance: f64,
    /// Samples per direction of the coarse search used when no hint is given.
    pub search_samples: usize,
}

impl Default for ProjectionOptions {
    fn default() -> Self {
        Self { max_iterations: 24, parameter_tolerance: 1e-13, search_samples: 24 }
    }
}

/// Result of a projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Parameters of the closest point found.
    pub uv: DVec2,
    /// The closest point found on the surface.
    pub point: DVec3,
    /// Its distance to the target.
    pub distance: f64,
}

/// Closest point of `surface` to `target`, starting from `hint` (or a coarse
/// grid search over the domain when `hint` is `None`).
///
/// Newton on `Su·(S−P) = Sv·(S−P) = 0`; a step is taken only if it does not
/// increase the distance (halved up to 12 times, then a gradient step is tried),
/// and parameters stay inside the domain, so it never diverges: at worst it
/// returns the best point it has seen.
pub fn project_to_surface(
    surface: &dyn Surface,
    target: DVec3,
    hint: Option<DVec2>,
    options: &ProjectionOptions,
) -> Projection {
    let [lo, hi] = surface.domain();
    let size = (hi - lo).max(DVec2::splat(1e-300));
    let mut uv = match hint {
        Some(h) if h.is_finite() => h.clamp(lo, hi),
        _ => coarse_search(surface, target, options.search_samples.max(2)),
    };
    let mut point = surface.point(uv);
    let mut dist = point.distance(target);
    for _ in 0..options.max_iterations {
        let d = surface.derivs(uv);
        let r = d.point - target;
        let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
        let j00 = d.su.length_squared() + d.suu.dot(r);
        let j01 = d.su.dot(d.sv) + d.suv.dot(r);
        let j11 = d.sv.length_squared() + d.svv.dot(r);
        let det = j00 * j11 - j01 * j01;
        let mut step = if det > 0.0 && j00 > 0.0 {
            DVec2::new(-(j11 * g.x - j01 * g.y) / det, -(j00 * g.y - j01 * g.x) / det)
        } else {
            // Not positive definite: scaled gradient descent.
            let a = d.su.length_squared().max(1e-300);
            let b = d.sv.length_squared().max(1e-300);
            DVec2::new(-g.x / a, -g.y / b)
        };
        if !step.is_finite() {
            break;
        }
        let mut accepted = false;
        for _ in 0..12 {
            let next = (uv + step).clamp(lo, hi);
            let p = surface.point(next);
            let dn = p.distance(target);
            if dn <= dist {
                let moved = ((next - uv) / size).abs().max_element();
                uv = next;
                point = p;
                dist = dn;
                accepted = true;
                if moved <= options.parameter_tolerance {
                    return Projection { uv, point, distance: dist };
                }
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    Projection { uv, point, distance: dist }
}

fn coarse_search(surface: &dyn Surface, target: DVec3, n: usize) -> DVec2 {
    let [lo, hi] = surface.domain();
    let mut best = (lo, f64::INFINITY);
    for i in 0..=n {
        for j in 0..=n {
            let uv = lo + (hi - lo) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64);
            let d = surface.point(uv).distance_squared(target);
            if d < best.1 {
                best = (uv, d);
            }
        }
    }
    best.0
}
