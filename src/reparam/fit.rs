//! The rebuilt surface itself (paper 001 steps 2–4): sample counts, samples
//! spaced evenly in model space, the bicubic interpolation, and its check
//! against the original (distance, folds), grown until it holds.

use alloc::vec;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::interp::{self, chord_params, interpolate_surface};
use super::{FIT_LIMIT, FIT_SHARE, MAX_SAMPLES};
use crate::model::FaceSurface;
use crate::nurbs::{project_with, NurbsSurface, ProjectionOptions, Surface, SurfaceDerivs, SurfaceFacts};
use crate::warning::RebuildError;

/// Piecewise-linear monotone map between the original parameters of the
/// grid nodes and the new ones (`s_i ↔ u_i`), both ascending.
pub(super) struct Map1 {
    pub(super) old: Vec<f64>,
    pub(super) new: Vec<f64>,
}

impl Map1 {
    pub(super) fn lerp(from: &[f64], to: &[f64], x: f64) -> f64 {
        let n = from.len();
        if n == 0 {
            return x;
        }
        if x <= from[0] {
            return to[0];
        }
        if x >= from[n - 1] {
            return to[n - 1];
        }
        let i = from.partition_point(|&f| f <= x).clamp(1, n - 1);
        let (a, b) = (from[i - 1], from[i]);
        let w = if b > a { (x - a) / (b - a) } else { 0.0 };
        to[i - 1] + (to[i] - to[i - 1]) * w
    }
    pub(super) fn to_new(&self, x: f64) -> f64 {
        Self::lerp(&self.old, &self.new, x)
    }
    fn to_old(&self, x: f64) -> f64 {
        Self::lerp(&self.new, &self.old, x)
    }
    /// As [`Map1::to_old`] at the nodes, and between two nodes at the old
    /// parameter that splits their arc length (by `arc`) in the ratio `x`
    /// splits their new parameters: where the old parameters crowd within
    /// one interval, the straight map lands far from the point the new
    /// surface passes, and a projection started there needs many steps.
    fn to_old_along(&self, arc: &ArcTable, x: f64) -> f64 {
        let n = self.new.len();
        if n < 2 || x <= self.new[0] || x >= self.new[n - 1] {
            return self.to_old(x);
        }
        let i = self.new.partition_point(|&f| f <= x).clamp(1, n - 1);
        let (a, b) = (self.new[i - 1], self.new[i]);
        let (u0, u1) = (self.old[i - 1], self.old[i]);
        let w = if b > a { (x - a) / (b - a) } else { 0.0 };
        let (l0, l1) = (Self::lerp(&arc.params, &arc.arc, u0), Self::lerp(&arc.params, &arc.arc, u1));
        if l1 > l0 {
            Self::lerp(&arc.arc, &arc.params, l0 + (l1 - l0) * w).clamp(u0.min(u1), u0.max(u1))
        } else {
            u0 + (u1 - u0) * w
        }
    }
}

/// Normalized arc length (mean over the iso-lines [`even_params`] measures)
/// at dense, ascending old parameters.
struct ArcTable {
    params: Vec<f64>,
    arc: Vec<f64>,
}

/// The parameters at fraction `a` along the iso-line at fraction `f` across
/// the domain `[lo, hi]`, running along u (`along_u`) or v.
fn iso_uv([lo, hi]: [DVec2; 2], along_u: bool, f: f64, a: f64) -> DVec2 {
    let (x, y) = if along_u { (a, f) } else { (f, a) };
    DVec2::new(lo.x + (hi.x - lo.x) * x, lo.y + (hi.y - lo.y) * y)
}

/// Curvature of the iso-line along u (`along_u`) or v at `d`; `None` where
/// the line stops (a pole) or the value is not finite.
fn iso_curvature(d: &SurfaceDerivs, along_u: bool) -> Option<f64> {
    let (d1, d2) = if along_u { (d.su, d.suu) } else { (d.sv, d.svv) };
    let speed = d1.length();
    let k = d1.cross(d2).length() / (speed * speed * speed);
    (speed > 1e-12 && k.is_finite()).then_some(k)
}

/// Length and largest curvature of the iso-line at fraction `f` across the
/// domain, running along u (`along_u`) or v, over `steps` equal parameter
/// steps (points where the line stops, at a pole, give no curvature).
pub(super) fn iso_line(surface: &FaceSurface, along_u: bool, f: f64, steps: usize) -> (f64, f64) {
    let domain = surface.domain();
    let (mut length, mut kappa) = (0.0, 0.0f64);
    let mut prev: Option<DVec3> = None;
    for k in 0..=steps {
        let d = surface.derivs(iso_uv(domain, along_u, f, k as f64 / steps as f64));
        if let Some(c) = iso_curvature(&d, along_u) {
            kappa = kappa.max(c);
        }
        if let Some(q) = prev {
            length += d.point.distance(q);
        }
        prev = Some(d.point);
    }
    (length, kappa)
}

/// Samples along u (`along_u`) or v: paper 001 step 2's chord count
/// `n = (b − a)·sqrt(sup‖S''‖ / 8ε)` taken in the arc-length parameter the
/// samples are spaced in (so `b − a` is the iso-line's length and `‖S''‖` its
/// curvature), averaged over five iso-lines; `(control points − degree)·3`
/// for a B-spline of degree ≤ 2 in that direction.
fn sample_count(surface: &FaceSurface, along_u: bool, eps: f64) -> usize {
    if let FaceSurface::Nurbs(n) = surface {
        let (deg, count) = if along_u { (n.degree()[0], n.counts()[0]) } else { (n.degree()[1], n.counts()[1]) };
        if deg <= 2 {
            return ((count - deg) * 3).clamp(3, MAX_SAMPLES);
        }
    }
    let (mut sum, mut used) = (0.0, 0usize);
    for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
        let (length, kappa) = iso_line(surface, along_u, f, 100);
        if length > 0.0 && length.is_finite() {
            sum += length * libm::sqrt(kappa / (8.0 * eps));
            used += 1;
        }
    }
    let n = if used > 0 { sum / used as f64 } else { 3.0 };
    if !n.is_finite() {
        return MAX_SAMPLES;
    }
    (crate::math::ceil(n) as usize).clamp(3, MAX_SAMPLES)
}

/// How [`even_params`] joins the spacing of its five iso-lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Spacing {
    /// Their normalized arc lengths averaged (paper 001).
    Mean,
    /// The geometric mean of their parameter speeds (normalized): where one
    /// line's stretch is ten times shorter than the others' (a hull's
    /// stern, where the keel's bend closes up), the mean leaves that line's
    /// steps seven times uneven and its cubic slows to a near cusp; the
    /// geometric mean splits the unevenness, about √10 each way.
    Geometric,
}

/// `n + 1` parameters along u (or v) spaced as evenly as possible in model
/// space (paper 001 step 3) over five iso-lines joined by `spacing`,
/// inverted at `i / n`.
fn even_params(surface: &FaceSurface, along_u: bool, n: usize, spacing: Spacing) -> (Vec<f64>, Option<ArcTable>) {
    let [lo, hi] = surface.domain();
    let (a0, a1) = if along_u { (lo.x, hi.x) } else { (lo.y, hi.y) };
    let dense = (16 * n).max(400);
    let xs: Vec<f64> = (0..=dense).map(|k| a0 + (a1 - a0) * k as f64 / dense as f64).collect();
    let mut avg = vec![0.0; dense + 1];
    // Per dense interval, the sum over the lines of the log of its share of
    // the line's length (relative to an even share).
    let mut log_speed = vec![0.0; dense];
    let mut used = 0usize;
    for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
        let pts: Vec<DVec3> = if along_u {
            surface.point_grid(&xs, &[lo.y + (hi.y - lo.y) * f])
        } else {
            surface.point_grid(&[lo.x + (hi.x - lo.x) * f], &xs)
        };
        let lengths: Vec<f64> = pts.windows(2).map(|w| w[0].distance(w[1])).collect();
        let total: f64 = lengths.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            continue;
        }
        match spacing {
            Spacing::Mean => {
                for (a, t) in avg.iter_mut().zip(chord_params(&lengths)) {
                    *a += t;
                }
            }
            Spacing::Geometric => {
                let even = total / dense as f64;
                for (d, l) in log_speed.iter_mut().zip(&lengths) {
                    *d += libm::log((l / even).max(SPEED_FLOOR));
                }
            }
        }
        used += 1;
    }
    if used == 0 {
        return ((0..=n).map(|i| a0 + (a1 - a0) * i as f64 / n as f64).collect(), None);
    }
    match spacing {
        Spacing::Mean => {
            for a in &mut avg {
                *a /= used as f64;
            }
        }
        Spacing::Geometric => {
            let speed: Vec<f64> = log_speed.iter().map(|d| libm::exp(d / used as f64)).collect();
            avg = chord_params(&speed);
        }
    }
    let mut out: Vec<f64> = (0..=n).map(|i| Map1::lerp(&avg, &xs, i as f64 / n as f64)).collect();
    let table = Some(ArcTable { params: xs, arc: avg });
    out[0] = a0;
    out[n] = a1;
    // Strictly increasing even where the surface has no length.
    let min_gap = (a1 - a0) * 1e-9;
    for i in 1..=n {
        if out[i] <= out[i - 1] + min_gap {
            out[i] = out[i - 1] + min_gap;
        }
    }
    if out[n] > a1 {
        // Squeezed by the nudges: fall back to equal steps.
        return ((0..=n).map(|i| a0 + (a1 - a0) * i as f64 / n as f64).collect(), table);
    }
    (out, table)
}

/// Normal turn (radians) between the rebuilt surface and the original at
/// one checked point above which the rebuild folds: a cubic through few
/// samples across a bend far tighter than their spacing (a hull's keel
/// closing up at the stern) can loop back within the distance check, and
/// the mesher then splits the loop's flipped triangles down to a tenth of
/// the tolerance (180 of them on one hull face).
const FOLD: f64 = 0.5;

/// Smallest share of an even step one dense interval of a line counts as
/// under [`Spacing::Geometric`] (a line that stops, at a pole or a
/// collapsed stretch, would otherwise zero the mean).
const SPEED_FLOOR: f64 = 1e-3;

/// Most times a fit within the goal that folds is sampled 1.5× denser to
/// unfold it, in the directions [`Fit::folds`] and the errors pick (5× at
/// most: the hull's keel took 4×), and the most samples it may grow to: a
/// fold that more samples do not undo (one found where the original itself
/// turns sharply) costs little.
const UNFOLD_STEPS: usize = 4;
const UNFOLD_SAMPLES: usize = 4096;

/// Along one direction of a fit, the new parameters its check visits (node
/// `i` at `2i`, the mid-point after it at `2i + 1`) and the original's
/// parameters each maps to: a line of checked points shares one parameter,
/// so the map is read once per line instead of once per point.
struct CheckLine {
    new: Vec<f64>,
    old: Vec<f64>,
}

impl CheckLine {
    /// The check's parameters along `map`, mapped back along `arc` (the
    /// arc-length table the samples were spaced by) when there is one.
    fn new(map: &Map1, arc: Option<&ArcTable>) -> Self {
        let mut new = Vec::with_capacity(2 * map.new.len());
        for (i, &s) in map.new.iter().enumerate() {
            new.push(s);
            if let Some(&b) = map.new.get(i + 1) {
                new.push(0.5 * (s + b));
            }
        }
        let old = new
            .iter()
            .map(|&x| match arc {
                Some(a) => map.to_old_along(a, x),
                None => map.to_old(x),
            })
            .collect();
        Self { new, old }
    }
}

/// The rebuilt surface with its parameter maps and the largest distance
/// found from it to the original, split by direction (`[along u, along v]`).
pub(super) struct Fit {
    pub(super) surface: crate::nurbs::NurbsSurface,
    pub(super) map_u: Map1,
    pub(super) map_v: Map1,
    /// The checked parameters per direction, with the original's.
    line_u: CheckLine,
    line_v: CheckLine,
    pub(super) errors: [f64; 2],
}

impl Fit {
    /// Checked point `key` by key `3 × node + direction` (0: u-edge
    /// mid-points, 1: v-edge ones, 2: cell centres): its new parameters,
    /// and the original's it maps to (where a projection onto the original starts).
    fn check_point(&self, key: usize) -> Option<(DVec2, DVec2)> {
        let (nu, nv) = (self.map_u.new.len(), self.map_v.new.len());
        let (node, dir) = (key / 3, key % 3);
        if node >= nu * nv {
            return None;
        }
        let (i, j) = (node / nv, node % nv);
        let (a, b) = [(2 * i + 1, 2 * j), (2 * i, 2 * j + 1), (2 * i + 1, 2 * j + 1)][dir];
        let (u, v) = (&self.line_u, &self.line_v);
        Some((DVec2::new(*u.new.get(a)?, *v.new.get(b)?), DVec2::new(*u.old.get(a)?, *v.old.get(b)?)))
    }

    /// The number of keys [`Fit::check_point`] takes.
    fn check_keys(&self) -> usize {
        3 * self.map_u.new.len() * self.map_v.new.len()
    }

    /// Per direction (`[along u, along v]`), whether the new surface's
    /// normal turns more than [`FOLD`] from the original's at the mid-point
    /// of an edge along it (a cell centre folds with its edges). A start
    /// whose normal is off is checked again at the projection (`facts`
    /// belong to `old`), since across a tight bend the mapped start can lie
    /// past it. The normals are taken a row of checked points at a time
    /// ([`Surface::iso_point_normal`]: the same values, the row's own sums once).
    fn folds(&self, old: &FaceSurface, facts: &SurfaceFacts) -> [bool; 2] {
        let opts = projection();
        let mut out = [false; 2];
        let (lu, lv) = (&self.line_u, &self.line_v);
        // Edge mid-points along u sit on the odd rows at even columns, those
        // along v on the even rows at odd columns.
        for (a, (&su, &ou)) in lu.new.iter().zip(&lu.old).enumerate() {
            let dir = if a % 2 == 1 { 0 } else { 1 };
            if out[dir] {
                continue;
            }
            let (new_row, old_row) = (self.surface.iso_point_normal(false, su), old.iso_point_normal(false, ou));
            for (&sv, &ov) in lv.new.iter().zip(&lv.old).skip(dir).step_by(2) {
                let n = new_row(sv).1;
                if crate::math::angle_between(n, old_row(ov).1) <= FOLD {
                    continue;
                }
                let (st, start) = (DVec2::new(su, sv), DVec2::new(ou, ov));
                let p = self.surface.point(st);
                let at = project_with(old, facts, p, Some(start), &opts, f64::NEG_INFINITY).uv;
                if crate::math::angle_between(n, old.normal(at)) > FOLD {
                    out[dir] = true;
                    break;
                }
            }
            if out == [true; 2] {
                break;
            }
        }
        out
    }

    /// The largest distance to the original per key direction ([`Fit::check_point`])
    /// over `checks` (distances at the starts with their keys, farthest
    /// first), and how many points were projected.
    ///
    /// Every distance to an actual point of the original bounds the true
    /// one (Newton can stall where the original's parameter speed jumps, so
    /// the start's distance stays a bound too). A point whose bound is no
    /// farther than the worst found so far cannot raise it: the far starts
    /// go first and the rest are not projected, and a projection stops once
    /// it is no farther than the worst. Before projecting, a point tries the
    /// step (from start to projection) of a neighbour already checked: the
    /// map's error changes slowly between neighbours, so the original's
    /// point one borrowed step from the start is usually as close as the
    /// projection's, and one evaluation proves what Newton's two or more would.
    fn worst_distances(&self, old: &FaceSurface, facts: &SurfaceFacts, checks: &[(f64, u32)]) -> ([f64; 3], usize) {
        let opts = projection();
        let [lo, hi] = old.domain();
        let row = 3 * self.map_v.new.len();
        // Per key, the step from its start to the point that bounded it.
        let mut moved: Vec<Option<DVec2>> = vec![None; self.check_keys()];
        let (mut worst, mut projected) = ([0.0f64; 3], 0);
        for &(near, key) in checks {
            let (k, dir) = (key as usize, key as usize % 3);
            let Some((st, start)) = self.check_point(k).filter(|_| near > worst[dir]) else { continue };
            let p = self.surface.point(st);
            // The node's other points, then the same point of the nodes beside it.
            let beside = [k - dir, k - dir + 1, k - dir + 2, k.wrapping_sub(3), k + 3, k.wrapping_sub(row), k + row];
            let borrowed = beside.into_iter().filter(|&b| b != k).find_map(|b| moved.get(b).copied().flatten());
            if let Some(at) = borrowed.map(|step| (start + step).clamp(lo, hi)) {
                if old.point(at).distance(p) <= worst[dir] {
                    moved[k] = Some(at - start);
                    continue;
                }
            }
            let pr = project_with(old, facts, p, Some(start), &opts, worst[dir]);
            projected += 1;
            moved[k] = Some(pr.uv - start);
            worst[dir] = worst[dir].max(pr.distance.min(near));
        }
        (worst, projected)
    }

    /// Per checked point by key ([`Fit::check_point`]), in key order: the
    /// distance between the new surface's point and the original's at the
    /// start its parameters map to, with the key. The points are evaluated
    /// on grids a few node rows at a time ([`Surface::point_grid`]: the same
    /// values, each row's and column's basis found once).
    fn start_distances(&self, old: &FaceSurface) -> Vec<(f64, u32)> {
        /// Node rows per block: the grids stay small (two surfaces, about
        /// 32 rows of 801 points at 400 × 400 samples).
        const BLOCK: usize = 16;
        let (lu, lv) = (&self.line_u, &self.line_v);
        let (nu, nv) = (self.map_u.new.len(), self.map_v.new.len());
        let odd = |x: &[f64]| -> Vec<f64> { x.iter().skip(1).step_by(2).copied().collect() };
        let (odd_new, odd_old) = (odd(&lv.new), odd(&lv.old));
        let mut out = Vec::with_capacity(self.check_keys());
        for i0 in (0..nu).step_by(BLOCK) {
            let i1 = (i0 + BLOCK).min(nu);
            // Grid rows 2i + 1 at every column, rows 2i at the odd ones.
            let rows = |x: &[f64], first: usize| -> Vec<f64> {
                (i0..i1).filter_map(|i| x.get(2 * i + first).copied()).collect()
            };
            let full_new = self.surface.point_grid(&rows(&lu.new, 1), &lv.new);
            let full_old = old.point_grid(&rows(&lu.old, 1), &lv.old);
            let half_new = self.surface.point_grid(&rows(&lu.new, 0), &odd_new);
            let half_old = old.point_grid(&rows(&lu.old, 0), &odd_old);
            let (wf, wh) = (lv.new.len(), odd_new.len());
            for i in i0..i1 {
                let r = i - i0;
                for j in 0..nv {
                    let node = i * nv + j;
                    // Keys 3 × node + 0, 1, 2: (2i + 1, 2j), (2i, 2j + 1), (2i + 1, 2j + 1).
                    let at = [(r * wf + 2 * j, true), (r * wh + j, false), (r * wf + 2 * j + 1, true)];
                    for (dir, (k, full)) in at.into_iter().enumerate() {
                        let (new, old) = if full { (&full_new, &full_old) } else { (&half_new, &half_old) };
                        let inside = if full { 2 * i + 1 < lu.new.len() } else { true };
                        let inside = inside && (if dir == 0 { 2 * j } else { 2 * j + 1 }) < lv.new.len();
                        if let (true, Some(p), Some(q)) = (inside, new.get(k), old.get(k)) {
                            out.push((p.distance(*q), (3 * node + dir) as u32));
                        }
                    }
                }
            }
        }
        out
    }
}

/// How points are projected between a rebuild and its original (the fit
/// check, the fold check, the trim curves): started close, so 12 Newton
/// steps are plenty.
pub(super) fn projection() -> ProjectionOptions {
    ProjectionOptions { max_iterations: 12, ..ProjectionOptions::default() }
}

/// Share of a rebuild's first sample interval over which the original's
/// border direction leaving a corner is taken, as a chord. At a nearly
/// degenerate corner the derivative itself is tiny (trj6's face 387: speed
/// 0.013 against 0.83 across) and holds only for the border's first
/// hundredth: a border turned along it strayed 1.2e-2 from the original's,
/// beyond the reach of sewing (3 cracks in the model). Along an eighth of
/// the interval, the rebuild lost the face's mesh trial.
const CORNER_STEP: f64 = 1.0 / 16.0;

/// `new` with each border tangent at a corner that points against the
/// original's border there turned to the original's direction (its length
/// kept), or `None` when none does. Where one border's parameter speed
/// differs from the averaged parameters (a short border of a blend, moving
/// slowly at its start), its interpolating cubic leaves the corner
/// backwards in a small loop: within the distance check, but the normal
/// there flips and the mesher splits the corner down (4 × 4 samples meshed
/// in 189 triangles where the original takes 40). The fit check that
/// follows judges the result.
fn unreverse_corners(new: &NurbsSurface, old: &FaceSurface, us: &[f64], vs: &[f64]) -> Option<NurbsSurface> {
    let [nu, nv] = new.counts();
    let (Some(&u0), Some(&u1), Some(&v0), Some(&v1)) = (us.first(), us.last(), vs.first(), vs.last()) else {
        return None;
    };
    if nu < 2 || nv < 2 || us.len() != nu || vs.len() != nv {
        return None;
    }
    let flat: Vec<DVec3> = new.control_points().collect();
    let mut pts: Vec<Vec<DVec3>> = flat.chunks(nv).map(<[DVec3]>::to_vec).collect();
    let mut changed = false;
    for (i, j) in [(0, 0), (nu - 1, 0), (0, nv - 1), (nu - 1, nv - 1)] {
        // The original's border directions leaving the corner: chords to its
        // points a [`CORNER_STEP`] of the first intervals along.
        let (cu, cv) = (if i == 0 { u0 } else { u1 }, if j == 0 { v0 } else { v1 });
        let (nu1, nv1) = (if i == 0 { us[1] } else { us[nu - 2] }, if j == 0 { vs[1] } else { vs[nv - 2] });
        let corner = old.point(DVec2::new(cu, cv));
        let su = old.point(DVec2::new(cu + (nu1 - cu) * CORNER_STEP, cv)) - corner;
        let sv = old.point(DVec2::new(cu, cv + (nv1 - cv) * CORNER_STEP)) - corner;
        let next = [(if i == 0 { 1 } else { nu - 2 }, j, su), (i, if j == 0 { 1 } else { nv - 2 }, sv)];
        let c = pts[i][j];
        for (a, b, dir) in next {
            let p = pts[a][b];
            let (len, unit) = ((p - c).length(), dir.normalize_or_zero());
            if len > 0.0 && unit != DVec3::ZERO && (p - c).dot(unit) < 0.0 {
                pts[a][b] = c + unit * len;
                changed = true;
            }
        }
    }
    if !changed {
        return None;
    }
    NurbsSurface::from_parts(new.knots_u().clone(), new.knots_v().clone(), &pts, None).ok()
}

/// Samples, interpolates (paper 001 steps 3–4) and checks one rebuild at
/// `n × m` intervals: the new surface at mid-points of grid edges and cells
/// is projected onto the original from the mapped parameters (`facts`
/// belong to the original).
fn fit_once(
    surface: &FaceSurface,
    facts: &SurfaceFacts,
    (n, m): (usize, usize),
    spacing: Spacing,
) -> Result<Fit, RebuildError> {
    let (us, arc_u) = even_params(surface, true, n, spacing);
    let (vs, arc_v) = even_params(surface, false, m, spacing);
    let flat = surface.point_grid(&us, &vs);
    let grid: Vec<Vec<DVec3>> = (0..us.len()).map(|i| flat[i * vs.len()..(i + 1) * vs.len()].to_vec()).collect();
    let cols: Vec<Vec<DVec3>> = (0..vs.len()).map(|j| grid.iter().map(|r| r[j]).collect()).collect();
    let s = interp::averaged_params(cols.iter().map(Vec::as_slice), us.len());
    let t = interp::averaged_params(grid.iter().map(Vec::as_slice), vs.len());
    let mut new = interpolate_surface(&grid, &s, &t)?;
    if let Some(fixed) = unreverse_corners(&new, surface, &us, &vs) {
        new = fixed;
    }
    let (map_u, map_v) = (Map1 { old: us, new: s }, Map1 { old: vs, new: t });
    let (line_u, line_v) = (CheckLine::new(&map_u, arc_u.as_ref()), CheckLine::new(&map_v, arc_v.as_ref()));
    let mut fit = Fit { surface: new, map_u, map_v, line_u, line_v, errors: [0.0; 2] };
    // Each point with its distance to the original's point at the start
    // (kept small: a 400 × 400 rebuild checks half a million points).
    let mut checks = fit.start_distances(surface);
    crate::sort::by_f64_desc(&mut checks, |c| c.0);
    let (worst, _) = fit.worst_distances(surface, facts, &checks);
    let (mut errors, centre) = ([worst[0], worst[1]], worst[2]);
    // A cell centre off the original is charged to the direction whose edges are worse.
    if errors[0] >= errors[1] {
        errors[0] = errors[0].max(centre);
    } else {
        errors[1] = errors[1].max(centre);
    }
    if !(errors[0].is_finite() && errors[1].is_finite()) {
        return Err(RebuildError::NotFinite);
    }
    fit.errors = errors;
    Ok(fit)
}

/// Paper 001 steps 3–4 with `spacing`, sampled until the fit is within
/// `tol · FIT_SHARE` of `surface` (see [`super::rebuild_face`]).
pub(super) fn fit_within(surface: &FaceSurface, tol: f64, spacing: Spacing) -> Result<Fit, RebuildError> {
    let goal = FIT_SHARE * tol;
    let limit = FIT_LIMIT * tol;
    let mut n = sample_count(surface, true, tol);
    let mut m = sample_count(surface, false, tol);
    let mut best: Option<Fit> = None;
    // What the projections onto the original learn about it, for all fits.
    let facts = SurfaceFacts::default();
    // The first fit within the goal that folds, kept while more samples try
    // to unfold it; if they cannot, it is used (the mesh trial judges it).
    let mut folded: Option<Fit> = None;
    let mut unfold_steps = 0;
    let fit = loop {
        let fit = fit_once(surface, &facts, (n, m), spacing)?;
        let [eu, ev] = fit.errors;
        if eu <= goal && ev <= goal {
            let folds = fit.folds(surface, &facts);
            if folds == [false; 2] {
                break fit;
            }
            let first = folded.take().unwrap_or(fit);
            // The geometric spacing is a second try after the mean's: its
            // folds are left to the mesh trial, not sampled away.
            if unfold_steps >= UNFOLD_STEPS || n.saturating_mul(m) >= UNFOLD_SAMPLES || spacing == Spacing::Geometric {
                break first;
            }
            // A fold found on edges of one direction may come of too few
            // samples in either: the direction it is found along grows, and
            // so does the other unless its fit is already far within the
            // goal (a sixteenth: 1.5× the samples gain about 5×).
            let grow = |k: usize, fold: bool, e: f64| {
                if fold || e > goal / 16.0 {
                    (k + k.div_ceil(2)).min(MAX_SAMPLES)
                } else {
                    k
                }
            };
            let (n2, m2) = (grow(n, folds[0], eu), grow(m, folds[1], ev));
            if (n2, m2) == (n, m) {
                break first;
            }
            (n, m) = (n2, m2);
            folded = Some(first);
            unfold_steps += 1;
            continue;
        }
        // At the sample limit (a feature far smaller than the samples, such as
        // the sharp bend an abrupt change of knot spacing leaves, makes the
        // error fall slowly and unevenly) keep the best fit if it is within
        // the hard limit, the mesher getting what it leaves.
        let err = eu.max(ev);
        if best.as_ref().is_none_or(|b| err < b.errors[0].max(b.errors[1])) {
            best = Some(fit);
        }
        if (eu > goal && n >= MAX_SAMPLES) || (ev > goal && m >= MAX_SAMPLES) {
            match (folded, best) {
                (Some(f), _) => break f,
                (None, Some(b)) if b.errors[0].max(b.errors[1]) <= limit => break b,
                _ => return Err(RebuildError::TooFar { error: err, n, m, limit }),
            }
        }
        // Interpolation error falls as h⁴: grow by the fourth root of the excess, at least 1.25×.
        let grow = |k: usize, e: f64| {
            let f = libm::pow(e / goal, 0.25).clamp(1.25, 4.0);
            (crate::math::ceil(k as f64 * f) as usize).min(MAX_SAMPLES)
        };
        if eu > goal {
            n = grow(n, eu);
        }
        if ev > goal {
            m = grow(m, ev);
        }
    };
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bicubic net over the unit square in z = 0 (`[i][j]` at `(i/3, j/3)`).
    fn net() -> Vec<Vec<DVec3>> {
        (0..4).map(|i| (0..4).map(|j| DVec3::new(i as f64 / 3.0, j as f64 / 3.0, 0.0)).collect()).collect()
    }

    fn bicubic(pts: &[Vec<DVec3>]) -> NurbsSurface {
        let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        NurbsSurface::try_new([3, 3], k.clone(), k, pts, None).unwrap()
    }

    /// A wavy bicubic over 7 by 5 control points whose u parameter crowds
    /// (most of its range covers the first tenth of x), as rebuilds get.
    fn crowded_wave() -> FaceSurface {
        let xs = [0.0, 0.05, 0.1, 0.15, 0.2, 4.0, 10.0];
        let pts: Vec<Vec<DVec3>> = xs
            .iter()
            .map(|&x| (0..5).map(|j| DVec3::new(x, j as f64, libm::sin(0.6 * x) + 0.3 * libm::cos(j as f64))).collect())
            .collect();
        let ku = vec![0.0, 0.0, 0.0, 0.0, 0.2, 0.5, 0.7, 1.0, 1.0, 1.0, 1.0];
        let kv = vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 1.0];
        FaceSurface::Nurbs(NurbsSurface::try_new([3, 3], ku, kv, &pts, None).unwrap())
    }

    /// The fold check point by point, as it read before it went by rows.
    fn folds_one_by_one(fit: &Fit, old: &FaceSurface) -> [bool; 2] {
        let mut out = [false; 2];
        for k in (0..fit.check_keys()).filter(|k| k % 3 < 2) {
            let Some((st, start)) = fit.check_point(k) else { continue };
            let n = fit.surface.normal(st);
            if crate::math::angle_between(n, old.normal(start)) <= FOLD {
                continue;
            }
            let at = crate::nurbs::project_to_surface(old, fit.surface.point(st), Some(start), &projection()).uv;
            out[k % 3] |= crate::math::angle_between(n, old.normal(at)) > FOLD;
        }
        out
    }

    /// The check's distances from grids are, bit for bit and key by key,
    /// those of each point evaluated alone; the fold check by rows finds
    /// what it finds point by point, on a rebuild that does not fold and
    /// on one turned over (its v reversed, so every normal flips).
    #[test]
    fn grid_and_row_checks_match_the_pointwise_ones() {
        let old = crowded_wave();
        let facts = SurfaceFacts::default();
        for (n, m) in [(7, 5), (16, 3), (40, 21)] {
            let mut fit = fit_once(&old, &facts, (n, m), Spacing::Mean).unwrap();
            let want: Vec<(u64, u32)> = (0..fit.check_keys())
                .filter_map(|k| {
                    let (st, start) = fit.check_point(k)?;
                    Some((fit.surface.point(st).distance(old.point(start)).to_bits(), k as u32))
                })
                .collect();
            let got: Vec<(u64, u32)> = fit.start_distances(&old).iter().map(|&(d, k)| (d.to_bits(), k)).collect();
            assert_eq!(got, want, "{n} x {m}");
            assert_eq!(fit.folds(&old, &facts), folds_one_by_one(&fit, &old));
            assert_eq!(fit.folds(&old, &facts), [false; 2], "{n} x {m}");
            // Turned over: S'(u, v) = S(u, 1 - v).
            let [_, cv] = fit.surface.counts();
            let net: Vec<DVec3> = fit.surface.control_points().collect();
            let pts: Vec<Vec<DVec3>> = net.chunks(cv).map(|row| row.iter().rev().copied().collect()).collect();
            let kv: Vec<f64> = fit.surface.knots_v().knots().iter().rev().map(|k| 1.0 - k).collect();
            let ku = fit.surface.knots_u().knots().to_vec();
            fit.surface = NurbsSurface::try_new([3, 3], ku, kv, &pts, None).unwrap();
            assert_eq!(fit.folds(&old, &facts), folds_one_by_one(&fit, &old));
            assert_eq!(fit.folds(&old, &facts), [true; 2], "{n} x {m} turned over");
        }
    }

    /// The check's worst distances are those of projecting every point in
    /// full, yet it projects fewer of the points whose start is farther than
    /// the worst than there are (the check by starts alone projects each),
    /// under half of them along a finely sampled direction: the others take
    /// a neighbour's step and are proven by one evaluation.
    #[test]
    fn borrowed_steps_prove_most_points_without_projecting() {
        let old = crowded_wave();
        let facts = SurfaceFacts::default();
        for (n, m) in [(40, 21), (60, 60), (200, 16)] {
            let fit = fit_once(&old, &facts, (n, m), Spacing::Mean).unwrap();
            let mut checks = fit.start_distances(&old);
            crate::sort::by_f64_desc(&mut checks, |c| c.0);
            let (worst, projected) = fit.worst_distances(&old, &facts, &checks);
            let mut full = [0.0f64; 3];
            let mut far = 0;
            for &(near, key) in &checks {
                let (st, start) = fit.check_point(key as usize).unwrap();
                let pr = crate::nurbs::project_to_surface(&old, fit.surface.point(st), Some(start), &projection());
                let dir = key as usize % 3;
                full[dir] = full[dir].max(pr.distance.min(near));
            }
            for &(near, key) in &checks {
                far += usize::from(near > full[key as usize % 3]);
            }
            for dir in 0..3 {
                let (a, b) = (worst[dir], full[dir]);
                assert!((a - b).abs() <= 1e-12 * b.max(1e-300), "{n} x {m}, direction {dir}: {a} against {b}");
            }
            // The check by starts alone projects every far start; along a
            // direction sampled finely (as PRO20359's 17 × 400) neighbours'
            // steps agree best.
            let share = if n >= 10 * m { 2 } else { 1 };
            assert!(far > 20 && share * projected < far, "{n} x {m}: {projected} projected of {far} far starts");
        }
    }

    /// A border that leaves its corner backwards is turned to the original's
    /// direction with its length kept; nothing else moves, and a net with
    /// no such border is left alone.
    #[test]
    fn a_border_leaving_its_corner_backwards_is_turned() {
        let old = FaceSurface::Nurbs(bicubic(&net()));
        let even = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];
        let (us, vs) = (even, even);
        assert!(unreverse_corners(&bicubic(&net()), &old, &us, &vs).is_none());
        let mut bad = net();
        // Along v from the corner (0, 0): backwards and a little up.
        bad[0][1] = DVec3::new(0.0, -0.2, 0.1);
        let len = bad[0][1].length();
        let fixed = unreverse_corners(&bicubic(&bad), &old, &us, &vs).expect("turned");
        let pts: Vec<DVec3> = fixed.control_points().collect();
        let turned = pts[1];
        assert!((turned.length() - len).abs() < 1e-12, "{turned:?}");
        assert!(turned.normalize().distance(DVec3::Y) < 1e-12, "{turned:?}");
        let before: Vec<DVec3> = bicubic(&bad).control_points().collect();
        for (k, (a, b)) in before.iter().zip(&pts).enumerate() {
            assert!(k == 1 || a == b, "control point {k} moved: {a:?} -> {b:?}");
        }
        // The normal at the corner is the original's again.
        let n = fixed.normal(DVec2::ZERO);
        assert!(n.distance(old.normal(DVec2::ZERO)) < 1e-9, "{n:?}");
    }
}
