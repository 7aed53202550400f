//! Closest-point projection onto a surface (Newton with safeguards).

use crate::numeric::{guarded_div, TINY};
use alloc::borrow::Cow;
use alloc::boxed::Box;
use alloc::vec::Vec;
use core::cell::{Cell, OnceCell};
use glam::{DVec2, DVec3};

use super::{Surface, SurfaceDerivs};

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

/// Result of projecting a point on a curve ([`crate::NurbsCurve::project`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveProjection {
    /// Parameter of the closest point found.
    pub t: f64,
    /// The closest point found on the curve.
    pub point: DVec3,
    /// Its distance to the target.
    pub distance: f64,
}

/// Newton runs at most from the coarse search (its best distinct local minima).
const MAX_STARTS: usize = 4;

/// Parameters this fraction of the domain from a knot line are on it.
const KNOT_SNAP: f64 = 1e-12;

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
/// Steps stop at knot lines. On a closed surface (equal points along
/// opposite edges) a step out through the seam continues from the other side
/// instead of stopping at the edge; on an open edge the step continues along
/// the edge. A result near a collapsed edge (pole) is retried from around
/// the pole, in the best direction, and one near a crease (C0 knot line)
/// from the other side of the crease.
pub fn project_to_surface(
    surface: &dyn Surface,
    target: DVec3,
    hint: Option<DVec2>,
    options: &ProjectionOptions,
) -> Projection {
    project_until(surface, target, hint, options, f64::NEG_INFINITY)
}

/// As [`project_to_surface`], but it stops as soon as the point found is
/// within `enough` of `target`: each step only brings the point closer, so a
/// caller that needs only the largest distance over many points (above
/// `enough`, the largest so far) loses nothing, and a point already as close
/// as that takes one evaluation instead of a full Newton run.
pub(crate) fn project_until(
    surface: &dyn Surface,
    target: DVec3,
    hint: Option<DVec2>,
    options: &ProjectionOptions,
    enough: f64,
) -> Projection {
    project_with(surface, &SurfaceFacts::default(), target, hint, options, enough)
}

/// As [`project_until`], with what earlier projections onto the same
/// surface learnt about it (`facts`, which must belong to `surface`): a
/// caller projecting many points onto one surface pays for its knots, seams,
/// collapsed edges and search grid once. The results are the same.
pub(crate) fn project_with(
    surface: &dyn Surface,
    facts: &SurfaceFacts,
    target: DVec3,
    hint: Option<DVec2>,
    options: &ProjectionOptions,
    enough: f64,
) -> Projection {
    let [lo, hi] = surface.domain();
    let breaks = facts.breaks(surface);
    let starts = match hint {
        Some(h) if h.is_finite() => Starts::one(h.clamp(lo, hi)),
        _ => coarse_search(surface, facts, target, options.search_samples.max(2)),
    };
    let mut best: Option<Projection> = None;
    for &uv in &starts.uv[..starts.len] {
        let pr = newton(surface, target, uv, options, facts, breaks, enough);
        if best.is_none_or(|b| pr.distance < b.distance) {
            best = Some(pr);
        }
        if pr.distance <= enough {
            break;
        }
    }
    let best = best.unwrap_or_else(|| {
        let point = surface.point(lo);
        Projection { uv: lo, point, distance: point.distance(target) }
    });
    let mut best = best;
    if best.distance <= enough {
        return best;
    }
    let retries =
        off_collapsed_edge(surface, facts, target, best.uv).into_iter().chain(across_creases(surface, best.uv, breaks));
    for uv in retries {
        let pr = newton(surface, target, uv, options, facts, breaks, enough);
        if pr.distance < best.distance {
            best = pr;
        }
        if best.distance <= enough {
            break;
        }
    }
    best
}

/// A crease (C0 knot line) splits the distance into two basins, one per
/// side, that can sit closer together than any search grid resolves. For
/// each inner knot line within 5% of the domain from `uv` where the surface
/// turns a corner, returns `uv` mirrored to the other side of it, as a new start.
fn across_creases(surface: &dyn Surface, uv: DVec2, breaks: &[Vec<f64>; 2]) -> impl Iterator<Item = DVec2> {
    let [lo, hi] = surface.domain();
    let size = hi - lo;
    let mut out = [None, None];
    for axis in 0..2 {
        let x = uv[axis];
        let Some(k) = breaks[axis]
            .iter()
            .copied()
            .filter(|&k| k > lo[axis] && k < hi[axis])
            .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()))
        else {
            continue;
        };
        if (k - x).abs() > 0.05 * size[axis] {
            continue;
        }
        let eps = 1e-9 * size[axis];
        let mut below = uv;
        below[axis] = k - eps;
        let mut above = uv;
        above[axis] = k + eps;
        let (db, da) = (surface.derivs(below), surface.derivs(above));
        let (tb, ta) = if axis == 0 { (db.su, da.su) } else { (db.sv, da.sv) };
        let scale = tb.length().max(ta.length());
        // No jump (or a NaN from a broken surface): not a crease.
        let jump = tb.distance(ta);
        if jump.is_nan() || jump <= 1e-6 * scale {
            continue;
        }
        let mut q = uv;
        let gap = (k - x).abs().max(1e-6 * size[axis]);
        q[axis] = if x < k { k + gap } else { k - gap };
        out[axis] = Some(q.clamp(lo, hi));
    }
    out.into_iter().flatten()
}

/// Near a collapsed edge (a pole: the point does not move along the edge)
/// the parameters are polar-like and Newton, started on the wrong side, stalls
/// or stops on the edge. When `uv` lies within 5% of the domain of such an
/// edge, returns the best of a few parameters around the pole at the same
/// distance from the edge (just off it when `uv` is on it), as a new start.
fn off_collapsed_edge(surface: &dyn Surface, facts: &SurfaceFacts, target: DVec3, uv: DVec2) -> Option<DVec2> {
    const SAMPLES: usize = 16;
    const BAND: f64 = 0.05;
    let [lo, hi] = surface.domain();
    let size = hi - lo;
    let mut best: Option<(f64, DVec2)> = None;
    for axis in [1usize, 0] {
        let along = 1 - axis;
        for (bound, inward) in [(lo[axis], 1.0), (hi[axis], -1.0)] {
            let gap = (uv[axis] - bound).abs();
            if gap.is_nan() || gap > BAND * size[axis] {
                continue;
            }
            if !facts.is_collapsed(surface, axis, bound) {
                continue;
            }
            let off = gap.max(1e-3 * size[axis]);
            for k in 0..SAMPLES {
                let mut q = uv;
                q[axis] = bound + inward * off;
                q[along] = lo[along] + size[along] * (k as f64 + 0.5) / SAMPLES as f64;
                let dist = surface.point(q).distance_squared(target);
                if best.is_none_or(|b| dist < b.0) {
                    best = Some((dist, q));
                }
            }
        }
    }
    best.map(|b| b.1)
}

/// Safeguarded Newton iterations from `start`.
///
/// A step ends at the next knot line (`breaks`) at the latest: across a knot
/// the cell's derivatives say nothing, and on a crease (C0 knot) a step
/// across it can land in the wrong basin. On a knot line the cells on both
/// sides propose a step (their derivatives evaluated a hair inside them) and
/// the one that gets closer wins, so the search can go on or turn back there.
fn newton(
    surface: &dyn Surface,
    target: DVec3,
    start: DVec2,
    options: &ProjectionOptions,
    facts: &SurfaceFacts,
    breaks: &[Vec<f64>; 2],
    enough: f64,
) -> Projection {
    let [lo, hi] = surface.domain();
    let size = (hi - lo).max(DVec2::splat(TINY));
    let mut uv = start.clamp(lo, hi);
    let mut d = facts.kept(uv).unwrap_or_else(|| surface.derivs(uv));
    let mut point = d.point;
    let mut dist = point.distance(target);
    // Derivatives at `uv` that the last step's search already evaluated.
    let mut ready: Option<SurfaceDerivs> = None;
    for it in 0..options.max_iterations {
        if dist <= enough {
            break;
        }
        if it > 0 {
            d = ready.take().unwrap_or_else(|| surface.derivs(uv));
        }
        // The cells touching uv: the one above (what `derivs` evaluates) and,
        // on an inner knot line, the one below in that direction.
        // Knots within a hair of uv count as under it (a parameter computed
        // as `lo + (hi − lo)·f` can miss a knot by one rounding).
        let on_knot = [0, 1].map(|axis| {
            let tol = KNOT_SNAP * size[axis];
            breaks[axis].iter().copied().find(|&k| k > lo[axis] + tol && (k - uv[axis]).abs() <= tol)
        });
        // Off knot lines one cell proposes the only step: its full step's end
        // is evaluated with derivatives (the next iteration's), as it is nearly always taken.
        let single = on_knot == [None, None];
        let mut best_step: Option<Step> = None;
        let mut sides = 0;
        for (below_u, below_v) in [(false, false), (true, false), (false, true), (true, true)] {
            if (below_u && on_knot[0].is_none()) || (below_v && on_knot[1].is_none()) {
                continue;
            }
            sides += 1;
            let dd = if sides == 1 {
                d
            } else {
                let mut q = uv;
                if let (true, Some(k)) = (below_u, on_knot[0]) {
                    q.x = k - 1e-9 * size.x;
                }
                if let (true, Some(k)) = (below_v, on_knot[1]) {
                    q.y = k - 1e-9 * size.y;
                }
                surface.derivs(q)
            };
            if let Some(found) = try_step(
                surface,
                target,
                (uv, point, dist),
                &dd,
                facts,
                breaks,
                single.then_some(options.parameter_tolerance),
            ) {
                if best_step.is_none_or(|b| found.0 < b.0) {
                    best_step = Some(found);
                }
            }
        }
        let Some((dn, next, p, at_next)) = best_step else {
            break;
        };
        let moved = ((next - uv) / size).abs().max_element();
        uv = next;
        point = p;
        dist = dn;
        ready = at_next;
        if moved <= options.parameter_tolerance {
            break;
        }
    }
    Projection { uv, point, distance: dist }
}

/// A step [`try_step`] found: the new distance, parameters and point, and
/// the derivatives there when it evaluated them.
type Step = (f64, DVec2, DVec3, Option<SurfaceDerivs>);

/// One safeguarded step from `uv` (at `point`, `dist` from the target) with
/// the derivatives `d`: Newton where the Hessian of the squared distance is
/// positive definite, scaled gradient descent elsewhere, halved until the
/// distance does not grow (12 times at most). Returns the step, or `None`
/// when no step helps. With `derivs` (the caller's parameter tolerance), the
/// full step's end is evaluated with derivatives (its point is the same as
/// [`Surface::point`] gives) unless the step is within that tolerance: the
/// caller stops there, whichever halving is taken.
///
/// Only evaluations whose outcome is already known are left out, so the
/// result is the same bit for bit: an end that rounds back to `uv` is `uv`
/// itself (distance `dist`, always taken), and an end a halving leaves
/// where it was (rounding, or clamped to its cell) is rejected again.
fn try_step(
    surface: &dyn Surface,
    target: DVec3,
    (uv, point, dist): (DVec2, DVec3, f64),
    d: &SurfaceDerivs,
    facts: &SurfaceFacts,
    breaks: &[Vec<f64>; 2],
    derivs: Option<f64>,
) -> Option<Step> {
    let [lo, hi] = surface.domain();
    let size = (hi - lo).max(DVec2::splat(TINY));
    let r = point - target;
    let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
    let j00 = d.su.length_squared() + d.suu.dot(r);
    let j01 = d.su.dot(d.sv) + d.suv.dot(r);
    let j11 = d.sv.length_squared() + d.svv.dot(r);
    let det = j00 * j11 - j01 * j01;
    let step = if det > 0.0 && j00 > 0.0 {
        DVec2::new(-(j11 * g.x - j01 * g.y) / det, -(j00 * g.y - j01 * g.x) / det)
    } else {
        // Not positive definite: scaled gradient descent.
        let a = d.su.length_squared().max(TINY);
        let b = d.sv.length_squared().max(TINY);
        DVec2::new(-g.x / a, -g.y / b)
    };
    if !step.is_finite() {
        return None;
    }
    // On an edge of an open direction with the step pointing out of the
    // domain: hold that parameter and take the 1-D Newton step along the
    // edge (a clamped 2-D step would point the wrong way along it). On the
    // seam of a closed direction: continue from the other side.
    let mut from = uv;
    let mut hold = [false; 2];
    for axis in 0..2 {
        let up = step[axis] > 0.0;
        let at_end = if up { uv[axis] >= hi[axis] } else { uv[axis] <= lo[axis] };
        if at_end && step[axis] != 0.0 {
            if facts.is_closed(surface, axis) {
                from[axis] = if up { lo[axis] } else { hi[axis] };
            } else {
                hold[axis] = true;
            }
        }
    }
    let step = match hold {
        [true, true] => DVec2::ZERO,
        [true, false] => DVec2::new(0.0, if j11 > 0.0 { -g.y / j11 } else { guarded_div(-g.y, d.sv.length_squared()) }),
        [false, true] => DVec2::new(if j00 > 0.0 { -g.x / j00 } else { guarded_div(-g.x, d.su.length_squared()) }, 0.0),
        [false, false] => step,
    };
    if !step.is_finite() {
        return None;
    }
    // A step longer than half the domain is not a local model any more
    // (it comes from a vanishing derivative at a collapsed edge).
    let mut step = step.clamp(-size * 0.5, size * 0.5);
    // The cell the step heads into.
    let mut cell = [lo, hi];
    for axis in 0..2 {
        let x = from[axis];
        let tol = KNOT_SNAP * size[axis];
        if step[axis] > 0.0 {
            cell[1][axis] = breaks[axis].iter().copied().find(|&k| k > x + tol).unwrap_or(hi[axis]);
        } else if step[axis] < 0.0 {
            cell[0][axis] = breaks[axis].iter().rev().copied().find(|&k| k < x - tol).unwrap_or(lo[axis]);
        }
    }
    // From `uv` itself (not across a seam) every halving's end is at most
    // as far from `uv` as the full step's, in each coordinate.
    let in_place = from == uv;
    let mut rejected: Option<DVec2> = None;
    for halving in 0..12 {
        let next = (from + step).clamp(cell[0], cell[1]).clamp(lo, hi);
        if in_place && next == uv && !dist.is_nan() {
            // Evaluating `uv` again would give `point`, at distance `dist`.
            return Some((dist, uv, point, None));
        }
        if rejected != Some(next) {
            let full = derivs
                .is_some_and(|tol| halving == 0 && !(in_place && ((next - uv) / size).abs().max_element() <= tol));
            let at_next = full.then(|| surface.derivs(next));
            let p = at_next.map_or_else(|| surface.point(next), |e| e.point);
            let dn = p.distance(target);
            if dn <= dist {
                return Some((dn, next, p, at_next));
            }
            rejected = Some(next);
        }
        step *= 0.5;
    }
    None
}

/// What projections learn about a surface independently of the point they
/// project: its knot lines, which directions close on themselves (a full
/// circle of a revolved surface), which domain edges collapse to a point, and
/// the coarse search's grid of points. Each is found on first need. Also the
/// derivatives last asked of [`SurfaceFacts::derivs`], for a projection
/// that starts where the previous one ended.
#[derive(Debug, Clone, Default)]
pub(crate) struct SurfaceFacts {
    /// The parameters and derivatives of the last [`SurfaceFacts::derivs`]
    /// (boxed: the facts of most projections never hold any).
    last: OnceCell<Box<Cell<(DVec2, SurfaceDerivs)>>>,
    breaks: OnceCell<[Vec<f64>; 2]>,
    closed: [OnceCell<bool>; 2],
    /// `[axis][0]`: the edge at the domain's low end along `axis`, `[axis][1]` the high one.
    collapsed: [[OnceCell<bool>; 2]; 2],
    /// The coarse search's grid: its steps per direction and its points.
    grid: OnceCell<(usize, Vec<DVec3>)>,
    /// A size of the surface its owner measures once (the diagonal of its
    /// control points' box, for the IGES and STEP readers' inversions).
    size: OnceCell<f64>,
}

impl SurfaceFacts {
    /// [`Surface::derivs`] at `uv`, the same values, kept for the next call:
    /// a caller that projects samples along a curve, each from the previous
    /// one's parameters, and asks for the derivatives where each ended (the
    /// readers, to tell poles) pays for them once instead of twice.
    pub(crate) fn derivs(&self, surface: &dyn Surface, uv: DVec2) -> SurfaceDerivs {
        if let Some(d) = self.kept(uv) {
            return d;
        }
        let d = surface.derivs(uv);
        match self.last.get() {
            Some(last) => last.set((uv, d)),
            None => {
                let _ = self.last.set(Box::new(Cell::new((uv, d))));
            }
        }
        d
    }

    /// The derivatives the last [`SurfaceFacts::derivs`] found, if at `uv`.
    fn kept(&self, uv: DVec2) -> Option<SurfaceDerivs> {
        let (at, d) = self.last.get()?.get();
        (at == uv).then_some(d)
    }

    fn breaks(&self, surface: &dyn Surface) -> &[Vec<f64>; 2] {
        self.breaks.get_or_init(|| [surface.breaks(true), surface.breaks(false)])
    }

    fn is_closed(&self, surface: &dyn Surface, axis: usize) -> bool {
        *self.closed[axis].get_or_init(|| {
            let [lo, hi] = surface.domain();
            [0.0, 0.21, 0.5, 0.79, 1.0].iter().all(|&f| {
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
            })
        })
    }

    /// Whether the domain edge where coordinate `axis` equals `bound` (the
    /// domain's low or high end) is one point: three points along it agree.
    fn is_collapsed(&self, surface: &dyn Surface, axis: usize, bound: f64) -> bool {
        // u (0) or v (anything else): one index for every table below.
        let axis = usize::from(axis != 0);
        let [lo, hi] = surface.domain();
        let side = usize::from(bound != lo[axis]);
        *self.collapsed[axis][side].get_or_init(|| {
            let along = 1 - axis;
            let size = hi - lo;
            let at = |f: f64| {
                let mut q = DVec2::ZERO;
                q[axis] = bound;
                q[along] = lo[along] + size[along] * f;
                surface.point(q)
            };
            let (a, b, c) = (at(0.0), at(0.37), at(1.0));
            let eps = 1e-10 * a.abs().max_element().max(b.abs().max_element()).max(c.abs().max_element());
            // Written as the negation of "apart", so that NaN counts as collapsed.
            !(a.distance(b) > eps || a.distance(c) > eps)
        })
    }

    /// The size `measure` gives, measured on first need and kept: the same
    /// value each time, without its cost per projection.
    pub(crate) fn size(&self, measure: impl FnOnce() -> f64) -> f64 {
        *self.size.get_or_init(measure)
    }

    /// The points of the `(n+1)²` search grid ([`param`]), kept for the first `n` asked.
    fn grid(&self, surface: &dyn Surface, n: usize) -> Cow<'_, [DVec3]> {
        let make = || {
            let [lo, hi] = surface.domain();
            // `param` works per component: its u depends on `i` alone, its v on `j`.
            let us: Vec<f64> = (0..=n).map(|i| param(lo, hi, n, i, 0).x).collect();
            let vs: Vec<f64> = (0..=n).map(|j| param(lo, hi, n, 0, j).y).collect();
            surface.point_grid(&us, &vs)
        };
        let (kept, pts) = self.grid.get_or_init(|| (n, make()));
        if *kept == n {
            Cow::Borrowed(pts)
        } else {
            Cow::Owned(make())
        }
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
fn coarse_search(surface: &dyn Surface, facts: &SurfaceFacts, target: DVec3, n: usize) -> Starts {
    let [lo, hi] = surface.domain();
    let n = n.min(256);
    let m = n + 1;
    let pts = facts.grid(surface, n);
    let dist: Vec<f64> = pts.iter().map(|p| p.distance_squared(target)).collect();
    // Points closer than this are the same point (a collapsed edge evaluates
    // to its point only up to rounding).
    let eps = 1e-12 * pts.iter().fold(0.0f64, |a, p| a.max(p.abs().max_element()));
    let same = |a: DVec3, b: DVec3| a.distance(b) <= eps;
    // Grid indices bounded by construction: 0 <= i, j < m.
    let collapsed = |i: usize, j: usize| -> bool {
        let p = pts[i * m + j];
        (i + 1 < m && same(pts[(i + 1) * m + j], p))
            || (i > 0 && same(pts[(i - 1) * m + j], p))
            || (j + 1 < m && same(pts[i * m + j + 1], p))
            || (j > 0 && same(pts[i * m + j - 1], p))
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
    crate::sort::by_f64(&mut minima, |m| m.0);
    let mut starts = Starts::one(lo);
    starts.len = 0;
    let mut on_edge = false;
    for &(_, i, j) in &minima {
        if starts.len == MAX_STARTS {
            break;
        }
        let p = pts[i * m + j];
        if starts.uv[..starts.len].iter().any(|&s| same(surface.point(s), p)) {
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

/// Grid parameter `(i, j)` of `n` steps; clamped, as `lo + (hi − lo)·1` may round past `hi`.
fn param(lo: DVec2, hi: DVec2, n: usize, i: usize, j: usize) -> DVec2 {
    (lo + (hi - lo) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64)).clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::counted::Counted;
    use crate::nurbs::NurbsSurface;
    use alloc::vec;

    /// A bicubic hill over the unit square.
    fn hill() -> NurbsSurface {
        let pts: Vec<Vec<DVec3>> = (0..4)
            .map(|i| (0..4).map(|j| DVec3::new(i as f64 / 3.0, j as f64 / 3.0, ((i * j) % 3) as f64 * 0.2)).collect())
            .collect();
        let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).unwrap()
    }

    /// Newton off knot lines evaluates each point it moves to once, with
    /// derivatives: the next iteration takes those instead of evaluating the
    /// point again (done alone, each iteration would evaluate its point
    /// bare and then with derivatives: as many bare points as derivatives).
    /// Bare points remain only where a full step is refused (at the end,
    /// where rounding stops the gains). The result is unchanged.
    #[test]
    fn newton_evaluates_each_accepted_point_once() {
        let s = hill();
        let opts = ProjectionOptions::default();
        for (k, uv) in [(0.7, 0.6), (0.3, 0.8), (0.55, 0.25)].into_iter().enumerate() {
            let target = s.point(DVec2::new(uv.0, uv.1)) + DVec3::new(0.01, -0.02, 0.01 * k as f64);
            let hint = DVec2::new(uv.0 - 0.04, uv.1 + 0.03);
            let c = Counted::new(&s);
            let got = project_to_surface(&c, target, Some(hint), &opts);
            assert_eq!(got, project_to_surface(&s, target, Some(hint), &opts));
            assert!(got.distance < 0.05, "{got:?}");
            let (points, derivs) = (c.points.get(), c.derivs.get() + c.tangents.get());
            assert!(derivs >= 3 && points + 1 < derivs, "{points} points, {derivs} with derivatives");
        }
    }

    /// Samples along a curve near the surface, each projected from the
    /// previous one's parameters (as the readers invert trim edges): Newton
    /// converges to rounding, where the old loop evaluated second derivatives
    /// at the last step's end (unused: the search stops there), evaluated
    /// `uv` again when a step rounded back to it, and re-evaluated an end a
    /// halving left unchanged. None of that is done now, and every result is
    /// a stationary point of the distance (its gradient vanishes to within
    /// 1e-6 of its scale; Newton's own stopping rule, a parameter step below
    /// 1e-13 of the domain, leaves one sample here at 2e-8).
    #[test]
    fn converged_steps_skip_known_evaluations() {
        let s = hill();
        let c = Counted::new(&s);
        let opts = ProjectionOptions::default();
        let mut hint = None;
        let n = 60;
        let (mut derivs, mut total) = (0, 0);
        for i in 0..n {
            let t = 0.1 + 0.8 * i as f64 / (n - 1) as f64;
            let target = s.point(DVec2::new(t, 0.3 + 0.4 * t * t)) + DVec3::new(0.003, -0.002, 0.004);
            c.reset();
            let got = project_to_surface(&c, target, hint, &opts);
            derivs += c.derivs.get();
            total += c.total();
            let d = s.derivs(got.uv);
            let r = got.point - target;
            let scale = r.length() * (d.su.length() + d.sv.length());
            assert!(d.su.dot(r).abs() <= 1e-6 * scale && d.sv.dot(r).abs() <= 1e-6 * scale, "{got:?}");
            hint = Some(got.uv);
        }
        // The old loop took 305 evaluations with derivatives and 1008 in all here.
        assert!(2 * derivs <= 9 * n && total <= 990, "{derivs} with derivatives, {total} in all for {n} projections");
    }

    /// Projecting samples along a curve, each from where the previous one
    /// ended, and asking the facts for the derivatives there (as the readers
    /// do to tell poles): each projection starts with the derivatives already
    /// found, one evaluation fewer per sample, and the results are those of
    /// fresh projections.
    #[test]
    fn facts_keep_the_derivatives_a_projection_starts_from() {
        let s = hill();
        let c = Counted::new(&s);
        let facts = SurfaceFacts::default();
        let opts = ProjectionOptions::default();
        let mut hint = DVec2::new(0.1, 0.3);
        let n = 20;
        let (mut kept, mut fresh) = (0, 0);
        for i in 0..n {
            let t = 0.1 + 0.8 * i as f64 / (n - 1) as f64;
            let target = s.point(DVec2::new(t, 0.3 + 0.4 * t * t)) + DVec3::new(0.003, -0.002, 0.004);
            let f = Counted::new(&s);
            let alone = project_to_surface(&f, target, Some(hint), &opts);
            fresh += f.derivs.get() + 1;
            c.reset();
            let got = project_with(&c, &facts, target, Some(hint), &opts, f64::NEG_INFINITY);
            assert_eq!(facts.derivs(&c, got.uv), s.derivs(got.uv));
            kept += c.derivs.get();
            assert_eq!(got, alone);
            hint = got.uv;
        }
        assert!(kept + n - 1 <= fresh, "{kept} evaluations with derivatives kept, {fresh} fresh");
    }

    /// Below `enough` nothing changes: the same point as a full projection.
    /// Above it the search stops at the first point within `enough` (here
    /// the start itself), still an upper bound of the true distance.
    #[test]
    fn projection_stops_once_within_enough() {
        let s = hill();
        let target = s.point(DVec2::new(0.7, 0.6)) + DVec3::new(0.0, 0.0, 0.05);
        let start = DVec2::new(0.1, 0.1);
        let opts = ProjectionOptions::default();
        let full = project_to_surface(&s, target, Some(start), &opts);
        assert!(full.distance < 0.06, "{full:?}");
        let below = project_until(&s, target, Some(start), &opts, 0.5 * full.distance);
        assert_eq!(below, full);
        let from_start = s.point(start).distance(target);
        let early = project_until(&s, target, Some(start), &opts, from_start);
        assert_eq!(early.uv, start);
        assert!(early.distance >= full.distance && early.distance <= from_start);
    }
    /// Facts kept across projections change no result: a cone-like surface
    /// with a collapsed edge (u = 0) and a closed direction (v), projected on
    /// with one set of facts, with and without hints, gives what fresh
    /// projections give; and the facts did keep the search grid and the edge.
    #[test]
    fn kept_facts_give_the_same_projections() {
        let ring = |r: f64, z: f64| -> Vec<DVec3> {
            (0..5)
                .map(|j| {
                    let a = core::f64::consts::TAU * j as f64 / 4.0;
                    DVec3::new(r * libm::cos(a), r * libm::sin(a), z)
                })
                .collect()
        };
        let pts = vec![ring(0.0, 1.0), ring(0.5, 0.5), ring(1.0, 0.0)];
        let (ku, kv) = (vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], vec![0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0]);
        let s = NurbsSurface::try_new([2, 1], ku, kv, &pts, None).unwrap();
        let facts = SurfaceFacts::default();
        let opts = ProjectionOptions::default();
        for (k, t) in [(0.3, 0.2, 1.2), (0.0, 0.01, 1.1), (-0.4, 0.6, 0.4), (0.9, -0.1, -0.2)].iter().enumerate() {
            let target = DVec3::new(t.0, t.1, t.2);
            for hint in [None, Some(DVec2::new(0.02, 0.1 * k as f64))] {
                let fresh = project_to_surface(&s, target, hint, &opts);
                let kept = project_with(&s, &facts, target, hint, &opts, f64::NEG_INFINITY);
                assert_eq!(fresh, kept, "target {target} hint {hint:?}");
            }
        }
        assert!(facts.grid.get().is_some_and(|(n, p)| *n == opts.search_samples && p.len() == (n + 1) * (n + 1)));
        assert_eq!(facts.collapsed[0][0].get(), Some(&true));
    }
}
