//! Closest-point projection onto a surface (Newton with safeguards).

use alloc::vec::Vec;
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

/// Newton runs at most from the coarse search (its best distinct local minima).
const MAX_STARTS: usize = 4;

/// Closest point of `surface` to `target`, starting from `hint` (or a coarse
/// grid search over the domain when `hint` is `None`).
///
/// Newton on `Su·(S−P) = Sv·(S−P) = 0`; a step is taken only if it does not
/// increase the distance (halved up to 12 times; a gradient step where the
/// Hessian is not positive definite), and parameters stay inside the domain,
/// so it never diverges: at worst it returns the best point it has seen.
///
/// Without a hint, Newton runs from up to four of the grid's distinct local
/// minima (plus the best sample off a collapsed edge when a start lies on one,
/// so that the direction out of a pole is found) and the closest result wins.
/// On a closed surface (equal points along opposite edges) a step across
/// the seam continues on the other side instead of stopping at the edge.
pub fn project_to_surface(
    surface: &dyn Surface,
    target: DVec3,
    hint: Option<DVec2>,
    options: &ProjectionOptions,
) -> Projection {
    let [lo, hi] = surface.domain();
    let mut seams = Seams::default();
    let starts = match hint {
        Some(h) if h.is_finite() => Starts::one(h.clamp(lo, hi)),
        _ => coarse_search(surface, target, options.search_samples.max(2)),
    };
    let mut best: Option<Projection> = None;
    for &uv in &starts.uv[..starts.len] {
        let pr = newton(surface, target, uv, options, &mut seams);
        if best.is_none_or(|b| pr.distance < b.distance) {
            best = Some(pr);
        }
    }
    best.unwrap_or_else(|| {
        let point = surface.point(lo);
        Projection { uv: lo, point, distance: point.distance(target) }
    })
}

/// Safeguarded Newton iterations from `start`.
fn newton(
    surface: &dyn Surface,
    target: DVec3,
    start: DVec2,
    options: &ProjectionOptions,
    seams: &mut Seams,
) -> Projection {
    let [lo, hi] = surface.domain();
    let size = (hi - lo).max(DVec2::splat(1e-300));
    let mut uv = start;
    let mut d = surface.derivs(uv);
    let mut point = d.point;
    let mut dist = point.distance(target);
    for it in 0..options.max_iterations {
        if it > 0 {
            d = surface.derivs(uv);
        }
        let r = d.point - target;
        let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
        let j00 = d.su.length_squared() + d.suu.dot(r);
        let j01 = d.su.dot(d.sv) + d.suv.dot(r);
        let j11 = d.sv.length_squared() + d.svv.dot(r);
        let det = j00 * j11 - j01 * j01;
        let step = if det > 0.0 && j00 > 0.0 {
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
        // A step longer than half the domain is not a local model any more
        // (it comes from a vanishing derivative at a collapsed edge).
        let mut step = step.clamp(-size * 0.5, size * 0.5);
        let mut accepted = false;
        for _ in 0..12 {
            let next = seams.wrap(surface, uv + step);
            let p = surface.point(next);
            let dn = p.distance(target);
            if dn <= dist {
                let moved = (seams.delta(surface, next - uv) / size).abs().max_element();
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

/// Which directions of the domain close on themselves (a full circle of a
/// revolved surface), found on first need.
#[derive(Default)]
struct Seams {
    closed: [Option<bool>; 2],
}

impl Seams {
    fn is_closed(&mut self, surface: &dyn Surface, axis: usize) -> bool {
        if let Some(c) = self.closed[axis] {
            return c;
        }
        let [lo, hi] = surface.domain();
        let c = [0.0, 0.21, 0.5, 0.79, 1.0].iter().all(|&f| {
            let (a, b, m) = if axis == 0 {
                let v = lo.y + (hi.y - lo.y) * f;
                (DVec2::new(lo.x, v), DVec2::new(hi.x, v), DVec2::new((lo.x + hi.x) * 0.5, v))
            } else {
                let u = lo.x + (hi.x - lo.x) * f;
                (DVec2::new(u, lo.y), DVec2::new(u, hi.y), DVec2::new(u, (lo.y + hi.y) * 0.5))
            };
            let (pa, pb, pm) = (surface.point(a), surface.point(b), surface.point(m));
            let scale = pa.length().max(pb.length()) + pa.distance(pm);
            pa.distance(pb) <= 1e-9 * scale
        });
        self.closed[axis] = Some(c);
        c
    }

    /// `uv` brought back into the domain: across the seam of a closed
    /// direction, clamped otherwise.
    fn wrap(&mut self, surface: &dyn Surface, uv: DVec2) -> DVec2 {
        let [lo, hi] = surface.domain();
        let mut q = uv;
        for axis in 0..2 {
            if (q[axis] < lo[axis] || q[axis] > hi[axis]) && self.is_closed(surface, axis) {
                let period = hi[axis] - lo[axis];
                if period > 0.0 {
                    let x = q[axis] - lo[axis];
                    q[axis] = lo[axis] + (x - crate::math::floor(x / period) * period);
                }
            }
        }
        q.clamp(lo, hi)
    }

    /// Parameter difference measured the short way round a seam.
    fn delta(&mut self, surface: &dyn Surface, d: DVec2) -> DVec2 {
        let [lo, hi] = surface.domain();
        let mut out = d;
        for axis in 0..2 {
            let period = hi[axis] - lo[axis];
            if out[axis].abs() > 0.5 * period && self.is_closed(surface, axis) {
                out[axis] -= period * out[axis].signum();
            }
        }
        out
    }
}

/// Up to [`MAX_STARTS`] + 1 starting parameters.
struct Starts {
    uv: [DVec2; MAX_STARTS + 1],
    len: usize,
}

impl Starts {
    fn one(uv: DVec2) -> Self {
        Self { uv: [uv; MAX_STARTS + 1], len: 1 }
    }
}

/// Samples an `(n+1)²` grid; returns its best distinct local minima (by
/// distance to `target`), and when one of them lies on a collapsed edge
/// (its point equals a grid neighbour's) also the best sample off such edges.
fn coarse_search(surface: &dyn Surface, target: DVec3, n: usize) -> Starts {
    let [lo, hi] = surface.domain();
    let n = n.min(256);
    let m = n + 1;
    let mut pts: Vec<DVec3> = Vec::with_capacity(m * m);
    for i in 0..m {
        for j in 0..m {
            let uv = param(lo, hi, n, i, j);
            pts.push(surface.point(uv));
        }
    }
    let dist: Vec<f64> = pts.iter().map(|p| p.distance_squared(target)).collect();
    // Grid indices bounded by construction: 0 <= i, j < m.
    let collapsed = |i: usize, j: usize| -> bool {
        let p = pts[i * m + j];
        (i + 1 < m && pts[(i + 1) * m + j] == p)
            || (i > 0 && pts[(i - 1) * m + j] == p)
            || (j + 1 < m && pts[i * m + j + 1] == p)
            || (j > 0 && pts[i * m + j - 1] == p)
    };
    let mut minima: Vec<(f64, usize, usize)> = Vec::new();
    for i in 0..m {
        for j in 0..m {
            let d = dist[i * m + j];
            let mut is_min = true;
            for (di, dj) in [(-1isize, -1isize), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)] {
                let (a, b) = (i as isize + di, j as isize + dj);
                if a >= 0 && b >= 0 && (a as usize) < m && (b as usize) < m && dist[a as usize * m + b as usize] < d {
                    is_min = false;
                    break;
                }
            }
            if is_min {
                minima.push((d, i, j));
            }
        }
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts = Starts::one(lo);
    starts.len = 0;
    let mut on_edge = false;
    for &(_, i, j) in &minima {
        if starts.len == MAX_STARTS {
            break;
        }
        let p = pts[i * m + j];
        if starts.uv[..starts.len].iter().any(|&s| surface.point(s) == p) {
            continue;
        }
        on_edge |= collapsed(i, j);
        starts.uv[starts.len] = param(lo, hi, n, i, j);
        starts.len += 1;
    }
    if on_edge {
        let mut best: Option<(f64, usize, usize)> = None;
        for i in 0..m {
            for j in 0..m {
                let d = dist[i * m + j];
                if !collapsed(i, j) && best.is_none_or(|b| d < b.0) {
                    best = Some((d, i, j));
                }
            }
        }
        if let Some((_, i, j)) = best {
            starts.uv[starts.len] = param(lo, hi, n, i, j);
            starts.len += 1;
        }
    }
    if starts.len == 0 {
        starts.len = 1;
    }
    starts
}

fn param(lo: DVec2, hi: DVec2, n: usize, i: usize, j: usize) -> DVec2 {
    lo + (hi - lo) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64)
}
