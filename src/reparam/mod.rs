//! Poorly parameterized surfaces (paper 001): the step-length ratio test finds
//! them, and they are rebuilt as bicubic surfaces whose parameters follow
//! model-space distance, with their trim loops re-expressed on the new surface.
//! The rebuilt face is checked against the original, so a mesh within
//! `tolerance − fit error` of the new face is within tolerance of the original.
//!
//! Numbers ([`crate::numeric`]): the step-ratio test and the fit error are
//! floats against the tolerance (a rebuild must stay within a tenth of it);
//! no exact predicates.

mod fit;
mod interp;

use fit::{fit_within, iso_line, projection, Fit, Map1, Spacing};

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::model::{Face, FaceSurface, Model, TrimLoop};
use crate::nurbs::{project_with, NurbsCurve, ProjectionOptions, Surface, SurfaceFacts};
use crate::options::{Reparam, Tolerance};
use crate::warning::{RebuildError, Reparameterized, Warning, WarningKind};
use crate::Error;

pub(crate) use interp::{chord_params, interpolate_curve};

/// Paper 001's empirical limit `k`: a parameter step whose model-space length
/// is more than `k` times, or less than `1/k` of, the iso-line's mean step is poor.
pub const RATIO_LIMIT: f64 = 4.5;
/// Equal parameter steps per tested iso-line (paper 001 step 1).
const STEPS: usize = 50;
/// Most samples per direction of a rebuilt surface.
const MAX_SAMPLES: usize = 400;
/// Most samples along one rebuilt trim curve.
const MAX_CURVE_SAMPLES: usize = 6400;
/// Share of the tolerance the rebuilt face may take from the original (the
/// mesh of the new face gets the rest). Paper 001 leaves it open and the issue
/// allows a quarter; a tenth costs about 1.26× the samples per direction
/// (interpolation error falls as h⁴) and leaves the mesher 90% of the
/// tolerance instead of 75%, which is worth about 1.2× fewer triangles.
pub const FIT_SHARE: f64 = 0.1;
/// The most a rebuilt face may stray from the original when more samples stop
/// helping (the bound: a quarter of the tolerance).
pub const FIT_LIMIT: f64 = 0.25;
/// Longest edge of a rebuilt face's mesh, in steps the sharpest curvature
/// needs: the rebuilt face has even parameters, so its grid cells can be kept
/// close to square, where a straight direction would otherwise be one long cell.
const ASPECT_CAP: f64 = 6.0;

/// One face the ratio test flagged, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReparamFace {
    /// Face index in the model.
    pub face: usize,
    /// Worst step ratio found (`max(L/C, C/L)` over the tested iso-lines).
    pub ratio: f64,
    /// Whether the face was rebuilt (false: the rebuild failed and the
    /// original was meshed; the reason is among the warnings).
    pub rebuilt: bool,
    /// Interpolated points of the rebuilt surface along u and v.
    pub samples: [usize; 2],
    /// Largest distance found between the rebuilt and the original face, model units.
    pub fit_error: f64,
}

/// Worst step ratio over the iso-lines `v = v_min` and `u = u_min` (paper 001
/// step 1) and, beyond the paper, the opposite and middle iso-lines, since one
/// poor row can hide anywhere. Each line is cut into 50 equal parameter steps
/// of model-space lengths `L_i`; with `C` their mean, the ratio is the
/// largest `max(L_i / C, C / L_i)`. Lines of no length (poles) are left out,
/// and so are lines that turn back (`turns_back`) where they would flag
/// the face: their steps shrink to nothing at the fold however the
/// parameters run, and a rebuild, which must turn back too, cannot even them.
pub fn step_ratio(surface: &dyn Surface) -> f64 {
    let [lo, hi] = surface.domain();
    let mut lines: Vec<Vec<DVec3>> = Vec::with_capacity(6);
    let mut longest = 0.0f64;
    for along_u in [true, false] {
        for f in [0.0, 0.5, 1.0] {
            let run = |a: f64, b: f64| (0..=STEPS).map(|k| a + (b - a) * (k as f64 / STEPS as f64)).collect::<Vec<_>>();
            let pts: Vec<DVec3> = if along_u {
                surface.point_grid(&run(lo.x, hi.x), &[lo.y + (hi.y - lo.y) * f])
            } else {
                surface.point_grid(&[lo.x + (hi.x - lo.x) * f], &run(lo.y, hi.y))
            };
            let total: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
            if total.is_finite() {
                longest = longest.max(total);
                lines.push(pts);
            }
        }
    }
    let mut worst = 1.0f64;
    for pts in &lines {
        let total: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        if total <= 1e-9 * longest {
            continue;
        }
        let c = total / STEPS as f64;
        let mut line = 1.0f64;
        for w in pts.windows(2) {
            let l = w[0].distance(w[1]);
            let r = if l > 0.0 { (l / c).max(c / l) } else { 1e9 };
            line = line.max(r.min(1e9));
        }
        if line > RATIO_LIMIT && turns_back(pts, c) {
            continue;
        }
        worst = worst.max(line);
    }
    worst
}

/// Whether the polyline `pts` (an iso-line's samples, mean step `c`) turns
/// back on itself at a fold of the surface (a pleat, where the control net
/// doubles back and the normal reverses): its chord turns past a right
/// angle from one step to the next (however the fold falls between the
/// samples, the steps either side point apart, so one of the two turns at
/// it is), and it runs more than a mean step out to the turn and back
/// from it. A narrower hook (a wrinkle along a border, a fraction of a step)
/// is one a rebuild on even parameters smooths over, so its line counts.
fn turns_back(pts: &[DVec3], c: f64) -> bool {
    let steps: Vec<DVec3> = pts.windows(2).map(|w| w[1] - w[0]).filter(|d| d.length_squared() > 0.0).collect();
    (1..steps.len()).any(|k| {
        if steps[k - 1].dot(steps[k]) >= 0.0 {
            return false;
        }
        // The way it arrived, over the two steps before the turn (one may
        // be the fold's own short step, pointing aside), and how far the
        // line runs along it out to the turn and back from it.
        let way = (steps[k - 1] + if k >= 2 { steps[k - 2] } else { DVec3::ZERO }).normalize_or_zero();
        let back: f64 = steps[k..].iter().map(|d| -d.dot(way)).take_while(|&x| x > 0.0).sum();
        let out: f64 = steps[..k].iter().rev().map(|d| d.dot(way)).take_while(|&x| x > 0.0).sum();
        out.min(back) > c
    })
}

/// A model whose poorly parameterized faces were rebuilt (paper 001's output
/// is the re-parameterized geometry itself), for [`crate::write_iges`].
#[derive(Debug, Clone)]
pub struct ReparamModel {
    /// The model, rebuilt faces in place of the originals.
    pub model: Model,
    /// Every face the ratio test flagged (every face when forced), rebuilt or not.
    pub faces: Vec<ReparamFace>,
    /// Why a flagged face was left as it was, one line per face.
    pub warnings: Vec<crate::Warning>,
    /// The absolute tolerance the rebuilt faces hold against the originals'
    /// [`FIT_LIMIT`] share of it (model units).
    pub tolerance: f64,
}

/// Rebuilds the faces of `model` that `mode` selects (paper 001 steps 1–5)
/// within [`FIT_SHARE`] of `tolerance` (relative: of the trimmed geometry's
/// diagonal, as the mesher measures it); a face that cannot be rebuilt stays
/// as it is, with a warning.
///
/// # Errors
/// A tolerance that is not positive and finite, or a model of no size with a relative one.
pub fn reparameterize_model(model: &Model, mode: Reparam, tolerance: Tolerance) -> Result<ReparamModel, Error> {
    let tol = match tolerance {
        Tolerance::Absolute(t) => t,
        Tolerance::Relative(r) => r * crate::model::trimmed_bbox(model).diagonal(),
    };
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(Error::Model { location: "model".into(), message: "has zero size; use an absolute --tol".into() });
    }
    let mut out = ReparamModel { model: model.clone(), faces: Vec::new(), warnings: Vec::new(), tolerance: tol };
    if mode == Reparam::Off {
        return Ok(out);
    }
    for (index, face) in out.model.faces.iter_mut().enumerate() {
        let ratio = step_ratio(&face.surface);
        if mode == Reparam::Auto && ratio <= RATIO_LIMIT {
            continue;
        }
        match rebuild_face(face, tol) {
            Ok(r) => {
                out.faces.push(ReparamFace {
                    face: index,
                    ratio,
                    rebuilt: true,
                    samples: r.samples,
                    fit_error: r.fit_error,
                });
                *face = r.face;
            }
            Err(why) => {
                let outcome = Reparameterized::KeptAsIs(why);
                out.warnings.push(Warning::face(index, WarningKind::PoorlyParameterized { ratio, outcome }));
                out.faces.push(ReparamFace { face: index, ratio, rebuilt: false, samples: [0, 0], fit_error: 0.0 });
            }
        }
    }
    Ok(out)
}

/// A face rebuilt on an evenly parameterized surface.
#[derive(Debug, Clone)]
pub struct Rebuilt {
    /// The new face: a bicubic B-spline surface on `[0,1]²` and its loops.
    pub face: Face,
    /// Largest distance found between the new and the original face.
    pub fit_error: f64,
    /// Interpolated points along u and v.
    pub samples: [usize; 2],
    /// Longest triangle edge the mesher should allow on the new face (infinite
    /// when the face is flat): six times the chord the sharpest
    /// iso-line curvature allows at the tolerance.
    pub max_edge: f64,
}

/// Rebuilds `face` (paper 001 steps 2–5) so that the new face lies within
/// `tol · FIT_SHARE` of the original (at worst `tol · FIT_LIMIT`, when more
/// samples stop helping): sample counts from the chord bound, grown in the
/// direction whose check fails, up to 400 per direction.
///
/// # Errors
/// A reason (for the report's warning) when the interpolation is singular,
/// the check cannot be met within the sample limits, or a trim curve cannot be
/// re-expressed; the caller then meshes the original face.
pub fn rebuild_face(face: &Face, tol: f64) -> Result<Rebuilt, RebuildError> {
    let limit = FIT_LIMIT * tol;
    let mut fit = fit_within(&face.surface, tol, Spacing::Mean)?;
    // Beyond the paper: a rebuild that is itself poorly parameterized, and
    // worse than the original (one iso-line's samples bunched where the
    // others' are not), tries the geometric spacing, and the evener of the
    // two is kept.
    let ratio = step_ratio(&fit.surface);
    if ratio > RATIO_LIMIT && ratio > step_ratio(&face.surface) {
        if let Ok(g) = fit_within(&face.surface, tol, Spacing::Geometric) {
            if step_ratio(&g.surface) < ratio {
                fit = g;
            }
        }
    }
    let (n, m) = (fit.map_u.new.len() - 1, fit.map_v.new.len() - 1);
    let mut fit_error = fit.errors[0].max(fit.errors[1]);
    let new_surface = FaceSurface::Rebuilt(fit.surface.clone());
    let mut loops = Vec::with_capacity(face.loops.len());
    for (li, lp) in face.loops.iter().enumerate() {
        let lp = split_at_corners(&face.surface, lp);
        let (curves, err) = rebuild_loop(&face.surface, &new_surface, &fit, &lp, limit)
            .map_err(|e| RebuildError::Loop { index: li, why: Box::new(e) })?;
        fit_error = fit_error.max(err);
        loops.push(TrimLoop { curves });
    }
    let max_edge = edge_cap(&new_surface, tol);
    Ok(Rebuilt {
        face: Face { name: face.name.clone(), surface: new_surface, loops },
        fit_error,
        samples: [n + 1, m + 1],
        max_edge,
    })
}

/// [`ASPECT_CAP`] times the shortest chord the mesher's grid will use: with
/// `κ` the largest iso-line curvature found on the (evenly parameterized) new
/// surface, a chord of length `h` sags `κh²/8`, and the grid gives each
/// direction about 0.4 of the tolerance, so `h = sqrt(3.2·tol/κ)`. An
/// iso-line shorter than the tolerance (a pole's) needs no chord at all: the
/// curvature of what is left of it sets nothing.
fn edge_cap(surface: &FaceSurface, tol: f64) -> f64 {
    let mut kappa = 0.0f64;
    for along_u in [true, false] {
        for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let (length, k) = iso_line(surface, along_u, f, 64);
            if length > tol {
                kappa = kappa.max(k);
            }
        }
    }
    let cap = ASPECT_CAP * libm::sqrt(3.2 * tol / kappa);
    if cap.is_finite() && cap > 0.0 {
        cap
    } else {
        f64::INFINITY
    }
}

/// Model-space turn (radians) above which a trim curve's C0 knot is a
/// corner: the rebuilt loop keeps it, since one cubic through samples
/// either side would swing past it and curl in (u,v).
const CORNER: f64 = 0.35;

/// Width (in the new unit parameters) of the band along the border where a
/// trim point is kept no nearer the border than the map puts it.
const BORDER_BAND: f64 = 1e-3;

/// `lp` with each curve cut at its corners (C0 knots where the curve's
/// model-space direction on `surface` turns by more than [`CORNER`]), so that
/// every piece is smooth enough to be interpolated as one cubic.
fn split_at_corners(surface: &FaceSurface, lp: &TrimLoop) -> TrimLoop {
    let mut curves = Vec::with_capacity(lp.curves.len());
    for c in &lp.curves {
        let (a, b) = c.domain();
        let knots = c.knots();
        let h = 1e-4 * (b - a);
        let at = |x: f64| surface.point(c.point(x.clamp(a, b)).truncate());
        let cuts: Vec<f64> = knots
            .breakpoints()
            .into_iter()
            .filter(|&t| t > a && t < b && knots.multiplicity(t) >= c.degree())
            .filter(|&t| {
                let (p0, p1, p2) = (at(t - h), at(t), at(t + h));
                let turn = crate::math::angle_between(p1 - p0, p2 - p1);
                turn > CORNER && (p1 - p0).length() > 0.0 && (p2 - p1).length() > 0.0
            })
            .collect();
        let mut from = a;
        let mut pieces = Vec::with_capacity(cuts.len() + 1);
        for &t in cuts.iter().chain(core::iter::once(&b)) {
            match crate::nurbs::reparam::segment(c, from, t) {
                Ok(piece) => pieces.push(piece),
                Err(_) => {
                    pieces.clear();
                    break;
                }
            }
            from = t;
        }
        if pieces.is_empty() {
            curves.push(c.clone());
        } else {
            curves.extend(pieces);
        }
    }
    TrimLoop { curves }
}

/// Paper 001 step 5 for one loop: each model-space trim curve sampled evenly
/// by arc length (51 points at least, doubled until within `goal`), each point
/// projected onto the new surface from its mapped parameters, a cubic (u,v)
/// curve interpolated. Curves of no model-space length (along a pole) map
/// their parameters directly. Consecutive curves share their end points exactly.
fn rebuild_loop(
    old: &FaceSurface,
    new: &FaceSurface,
    fit: &Fit,
    lp: &TrimLoop,
    goal: f64,
) -> Result<(Vec<NurbsCurve>, f64), RebuildError> {
    let lander = Lander::new(old, new, fit);
    // Loop vertices landed once, so curves meet exactly.
    let mut ends: Vec<DVec2> = lp.curves.iter().map(|c| lander.land(c.point(c.domain().0).truncate())).collect();
    let stub = stubs(old, lp, &mut ends, goal);
    let mut out = Vec::with_capacity(lp.curves.len());
    let mut worst = 0.0f64;
    for (ci, c) in lp.curves.iter().enumerate() {
        if stub[ci] {
            continue;
        }
        let start = ends[ci];
        let end = ends[(ci + 1) % ends.len()];
        let mut samples = STEPS;
        loop {
            let (curve, err) = lander
                .curve_through(c, samples, (start, end), goal)
                .map_err(|e| RebuildError::Curve { index: ci, why: Box::new(e) })?;
            if err <= goal {
                worst = worst.max(err);
                out.push(curve);
                break;
            }
            if samples * 2 > MAX_CURVE_SAMPLES {
                let why = Box::new(RebuildError::CurveTooFar { error: err, goal });
                return Err(RebuildError::Curve { index: ci, why });
            }
            samples *= 2;
        }
    }
    Ok((out, worst))
}

/// The pieces of `lp` of no length in model space whose ends (`ends`, as
/// landed) lie within a millionth of the unit domain (a stub a file's loop
/// closes with; not a piece along a pole): each is left out, its
/// neighbours meeting there (its end moved to its start in `ends`), since
/// as a curve it would double back over them.
fn stubs(old: &FaceSurface, lp: &TrimLoop, ends: &mut [DVec2], goal: f64) -> Vec<bool> {
    let n = lp.curves.len();
    let mut stub = vec![false; n];
    for (ci, c) in lp.curves.iter().enumerate() {
        let next = (ci + 1) % n;
        if n - stub.iter().filter(|&&s| s).count() > 1
            && ends[ci].distance(ends[next]) <= 1e-6
            && model_length(old, c) <= 1e-3 * goal
        {
            stub[ci] = true;
            ends[next] = ends[ci];
        }
    }
    stub
}

/// Where points of the old surface's (u,v) land on the new surface.
struct Lander<'a> {
    old: &'a FaceSurface,
    new: &'a FaceSurface,
    fit: &'a Fit,
    opts: ProjectionOptions,
    /// What projections onto the new surface learn about it, for all points.
    facts: SurfaceFacts,
    /// One sample interval of the new surface, per direction.
    cell: DVec2,
    /// The old surface's domain.
    lo: DVec2,
    hi: DVec2,
}

impl<'a> Lander<'a> {
    fn new(old: &'a FaceSurface, new: &'a FaceSurface, fit: &'a Fit) -> Self {
        let cell =
            DVec2::new(1.0 / (fit.map_u.new.len().max(2) - 1) as f64, 1.0 / (fit.map_v.new.len().max(2) - 1) as f64);
        let [lo, hi] = old.domain();
        Self { old, new, fit, opts: projection(), facts: SurfaceFacts::default(), cell, lo, hi }
    }

    /// The fit's map of an old (u,v) to the new parameters.
    fn map(&self, uv: DVec2) -> DVec2 {
        DVec2::new(self.fit.map_u.to_new(uv.x), self.fit.map_v.to_new(uv.y))
    }

    /// Where an old (u,v) lands on the new surface; a coordinate on the old
    /// domain's border stays on the new one's (the map takes borders to
    /// borders, and the new border interpolates the old one's samples).
    fn land(&self, uv: DVec2) -> DVec2 {
        let edge = |x: f64, a: f64, b: f64| (x - a).abs() <= 1e-9 * (b - a) || (b - x).abs() <= 1e-9 * (b - a);
        let hint = self.map(uv);
        let p = self.old.point(uv);
        let pr = project_with(self.new, &self.facts, p, Some(hint), &self.opts, f64::NEG_INFINITY);
        let off = (pr.uv - hint).abs();
        let cell = self.cell;
        let mut at =
            if off.x <= 2.0 * cell.x && off.y <= 2.0 * cell.y && pr.distance.is_finite() { pr.uv } else { hint };
        if edge(uv.x, self.lo.x, self.hi.x) {
            at.x = hint.x;
        } else {
            at.x = inside(at.x, hint.x);
        }
        if edge(uv.y, self.lo.y, self.hi.y) {
            at.y = hint.y;
        } else {
            at.y = inside(at.y, hint.y);
        }
        at
    }

    /// The cubic (u,v) curve on the new surface through `samples + 1`
    /// points of the old trim curve `c` at equal model-space arc length,
    /// from `start` to `end`, and how far its mid-points stray from the old
    /// curve (0 for a curve of no length, whose mapped path is moved to the
    /// landed ends instead).
    fn curve_through(
        &self,
        c: &NurbsCurve,
        samples: usize,
        (start, end): (DVec2, DVec2),
        goal: f64,
    ) -> Result<(NurbsCurve, f64), RebuildError> {
        let (old, new) = (self.old, self.new);
        let (a, b) = c.domain();
        // Dense model-space polyline of the old curve, 8 points per sample interval.
        let dense = 8 * samples;
        let ts: Vec<f64> = (0..=dense).map(|k| a + (b - a) * k as f64 / dense as f64).collect();
        let pts: Vec<DVec3> = ts.iter().map(|&t| old.point(c.point(t).truncate())).collect();
        let lengths: Vec<f64> = pts.windows(2).map(|w| w[0].distance(w[1])).collect();
        let total: f64 = lengths.iter().sum();
        let degenerate = !(total > 1e-3 * goal && total.is_finite());
        let arc = chord_params(&lengths);
        // Parameters of the old curve at equal arc length (equal parameter steps when degenerate).
        let picks: Vec<f64> = (0..=samples)
            .map(|i| {
                let x = i as f64 / samples as f64;
                if degenerate {
                    a + (b - a) * x
                } else {
                    Map1::lerp(&arc, &ts, x)
                }
            })
            .collect();
        let mut st: Vec<DVec2> = picks
            .iter()
            .map(|&t| {
                let uv = c.point(t).truncate();
                if degenerate {
                    self.map(uv)
                } else {
                    self.land(uv)
                }
            })
            .collect();
        if degenerate {
            // The mapped path (along a pole) moved to the landed ends: the map
            // is only close to where projection puts them.
            let (d0, d1) = (start - st[0], end - st[samples]);
            for (i, q) in st.iter_mut().enumerate() {
                let x = i as f64 / samples as f64;
                *q += d0 * (1.0 - x) + d1 * x;
            }
        }
        st[0] = start;
        st[samples] = end;
        // The samples are equally spaced in model space: equal parameter steps keep the
        // curve from curling where (u,v) speed varies along it.
        let params: Vec<f64> = (0..=samples).map(|i| i as f64 / samples as f64).collect();
        let curve = interpolate_curve(&st, &params)?;
        // Check: mid-points of the new curve against the old polyline nearby.
        let mut err = 0.0f64;
        if !degenerate {
            for i in 0..samples {
                let q = new.point(curve.point(0.5 * (params[i] + params[i + 1])).truncate());
                // The old polyline between the two samples' arc lengths, one segment either side.
                let (x0, x1) = (i as f64 / samples as f64, (i + 1) as f64 / samples as f64);
                let k0 = arc.partition_point(|&x| x < x0).saturating_sub(1);
                let k1 = (arc.partition_point(|&x| x <= x1) + 1).min(dense);
                let d = (k0..k1).map(|k| segment_distance(q, pts[k], pts[k + 1])).fold(f64::INFINITY, f64::min);
                err = err.max(d);
            }
        }
        Ok((curve, err))
    }
}

/// A point inside the old domain stays as far inside the new one as the
/// (monotone) map puts it (`hint`), within [`BORDER_BAND`] of the border:
/// projection alone would push a curve running just inside the border onto
/// it, over the loop's own stretch along the border.
fn inside(x: f64, hint: f64) -> f64 {
    if hint > 1.0 - BORDER_BAND {
        x.min(hint)
    } else if hint < BORDER_BAND {
        x.max(hint)
    } else {
        x
    }
}

/// Length in model space of the trim curve `c` on `surface`, from 64 chords.
fn model_length(surface: &FaceSurface, c: &NurbsCurve) -> f64 {
    let (a, b) = c.domain();
    let pts: Vec<DVec3> = (0..=64).map(|k| surface.point(c.point(a + (b - a) * k as f64 / 64.0).truncate())).collect();
    pts.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// Distance from `q` to the segment `a`–`b`.
fn segment_distance(q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    let w = if len2 > 0.0 { ((q - a).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
    q.distance(a + d * w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::NurbsSurface;

    /// A bicubic over 11 by 5 control points, on even knots in u (eighths)
    /// and one inner knot at 0.5 in v.
    fn eleven_by_five(pts: &[Vec<DVec3>]) -> NurbsSurface {
        let mut ku = vec![0.0; 4];
        ku.extend((1..8).map(|k| k as f64 / 8.0));
        ku.extend([1.0; 4]);
        NurbsSurface::try_new([3, 3], ku, vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0], pts, None).unwrap()
    }

    /// A wavy sheet whose u parameter crowds: 90% of its range covers the first 5% of x.
    fn crowded() -> NurbsSurface {
        let xs = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 5.0, 10.0];
        let pts: Vec<Vec<DVec3>> = xs
            .iter()
            .map(|&x| (0..5).map(|j| DVec3::new(x, j as f64, (x * 0.6).sin() + 0.2 * j as f64)).collect())
            .collect();
        eleven_by_five(&pts)
    }

    #[test]
    fn ratio_test_flags_crowded_and_passes_even_parameters() {
        let s = FaceSurface::Nurbs(crowded());
        assert!(step_ratio(&s) > RATIO_LIMIT, "ratio {}", step_ratio(&s));
        let pts: Vec<Vec<DVec3>> =
            (0..4).map(|i| (0..4).map(|j| DVec3::new(i as f64, j as f64, ((i + j) % 2) as f64)).collect()).collect();
        let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let even = NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).unwrap();
        assert!(step_ratio(&even) < RATIO_LIMIT, "ratio {}", step_ratio(&even));
    }

    /// A strip pleated along v (its control net runs out to y = 6 and back
    /// over itself, 2e-3 higher), its u parameters crowded as
    /// [`crowded`]'s when `crowd`, else even.
    fn pleated(crowd: bool) -> NurbsSurface {
        let xs: Vec<f64> = if crowd {
            vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 5.0, 10.0]
        } else {
            (0..11).map(|i| i as f64).collect()
        };
        let (ys, zs) = ([0.0, 3.0, 6.0, 3.0, 0.0], [0.0, 0.0, 0.001, 0.002, 0.002]);
        let pts: Vec<Vec<DVec3>> = xs.iter().map(|&x| (0..5).map(|j| DVec3::new(x, ys[j], zs[j])).collect()).collect();
        eleven_by_five(&pts)
    }

    /// A pleat (as OCC131-2's face 0, where the normal reverses along the
    /// fold) slows its v lines to nothing where they turn back, which no
    /// rebuild evens out: its even u lines decide, and the face is not
    /// flagged. The same pleat with crowded u lines still is.
    #[test]
    fn ratio_test_leaves_out_lines_that_turn_back() {
        let even = pleated(false);
        let line =
            |p: fn(f64) -> DVec2| (0..=STEPS).map(|k| even.point(p(k as f64 / STEPS as f64))).collect::<Vec<_>>();
        let back = |pts: Vec<DVec3>| {
            let c = pts.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>() / STEPS as f64;
            turns_back(&pts, c)
        };
        assert!(back(line(|t| DVec2::new(0.5, t))), "the pleat's v lines turn back");
        assert!(!back(line(|t| DVec2::new(t, 0.25))), "its u lines do not");
        // Between samples too: the fold 0.3 of a step past one.
        assert!(back(line(|t| DVec2::new(0.5, (t + 0.3 / STEPS as f64).min(1.0)))));
        // A hook narrower than a step (a wrinkle the rebuild smooths over)
        // does not count, at either end (linkrods' faces 25 and 26).
        let mut hooked: Vec<DVec3> = (0..=STEPS).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        hooked[STEPS] = DVec3::new(STEPS as f64 - 1.2, 0.0, 0.0);
        assert!(!back(hooked));
        let hooked: Vec<DVec3> = (0..=STEPS).map(|k| DVec3::new(0.5 - (k as f64 - 1.0).abs(), 0.0, 0.0)).collect();
        assert!(!back(hooked));
        assert!(step_ratio(&even) <= RATIO_LIMIT, "ratio {}", step_ratio(&even));
        let crowd = pleated(true);
        assert!(step_ratio(&crowd) > RATIO_LIMIT, "ratio {}", step_ratio(&crowd));
    }

    /// A polyline loop that closes with a stub of no length on the border
    /// (asmo_car's face 5 ends its loop 1e-6 past the point it started from):
    /// the stub is left out of the rebuilt loop rather than made a curve that
    /// doubles back over its neighbours, and the rebuilt face meshes.
    #[test]
    fn loop_stub_of_no_length_is_left_out() {
        let d = 1e-7;
        let corners =
            [(1.0, 0.6 + d), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0), (1.0, 0.0), (1.0, 0.4), (0.5, 0.5), (1.0, 0.6)];
        let mut pts: Vec<DVec3> = corners.iter().map(|&(u, v)| DVec3::new(u, v, 0.0)).collect();
        pts.push(pts[0]);
        let mut knots = vec![0.0];
        knots.extend((0..pts.len()).map(|k| k as f64));
        knots.push((pts.len() - 1) as f64);
        let lp = TrimLoop { curves: vec![NurbsCurve::try_new(1, knots, pts, None).unwrap()] };
        let face = Face { name: None, surface: FaceSurface::Nurbs(crowded()), loops: vec![lp] };
        let pieces = split_at_corners(&face.surface, &face.loops[0]).curves.len();
        let r = rebuild_face(&face, 0.01).unwrap();
        assert_eq!(r.face.loops[0].curves.len(), pieces - 1);
        for c in &r.face.loops[0].curves {
            let (a, b) = c.domain();
            assert!(c.point(a).distance(c.point(b)) > 1e-3, "a curve of no extent: {:?}", c.point(a));
        }
        let model = crate::Model {
            units: "mm".into(),
            faces: vec![r.face],
            warnings: Vec::new(),
            tolerance: None,
            bodies: Vec::new(),
            ..Default::default()
        };
        let m = crate::mesh_model(&model, &crate::MeshOptions::default().with_tolerance(0.01)).unwrap();
        assert!(m.report.triangles > 0 && m.report.faces_skipped == 0, "{:?}", m.report.warnings);
    }

    /// A quarter disc whose centre is a pole that is not quite one (its
    /// control points 1e-8 apart, as trj6's corner blends): the pole's line
    /// has no length to chord, so the edge cap follows the real bends (the
    /// sampled arc nearest the pole has radius 1/4). Its 1e-8 speed made the
    /// cap 1e-4 here, and trj6 face 309's forced rebuild 1.4 million triangles.
    #[test]
    fn edge_cap_is_not_set_by_a_pole() {
        let pts: Vec<Vec<DVec3>> = (0..4)
            .map(|i| {
                (0..4)
                    .map(|j| {
                        let a = core::f64::consts::FRAC_PI_2 * j as f64 / 3.0;
                        let r = i as f64 / 3.0;
                        let r = r.max(1e-8);
                        DVec3::new(r * libm::cos(a), r * libm::sin(a), 0.0)
                    })
                    .collect()
            })
            .collect();
        let k = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let fan = FaceSurface::Rebuilt(NurbsSurface::try_new([3, 3], k.clone(), k, &pts, None).unwrap());
        let tol = 0.01;
        // The sharpest bend off the pole: the arc of radius 1/4 (curvature 4).
        let fair = ASPECT_CAP * libm::sqrt(3.2 * tol / 4.0);
        let cap = edge_cap(&fan, tol);
        assert!(cap > 0.5 * fair && cap < f64::INFINITY, "cap {cap} against {fair}");
    }

    #[test]
    fn rebuilt_surface_is_even_and_within_a_quarter_tolerance() {
        let face = Face { name: None, surface: FaceSurface::Nurbs(crowded()), loops: Vec::new() };
        let tol = 0.01;
        let r = rebuild_face(&face, tol).unwrap();
        assert!(r.fit_error <= tol * FIT_SHARE, "fit error {}", r.fit_error);
        assert!(step_ratio(&r.face.surface) < RATIO_LIMIT, "still poor: {}", step_ratio(&r.face.surface));
        // Corners are kept exactly (interpolated nodes).
        let [lo, hi] = face.surface.domain();
        for (a, b) in [(lo, DVec2::ZERO), (hi, DVec2::ONE)] {
            assert!(face.surface.point(a).distance(r.face.surface.point(b)) < 1e-9);
        }
    }
}
