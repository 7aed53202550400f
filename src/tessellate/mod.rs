//! Tessellation of trimmed surfaces within a verified tolerance (paper 000).

#[cfg(feature = "std")]
mod cdt;
mod face;
pub(crate) mod measure;
mod options;
mod params;
mod refine;
mod sew;
#[cfg(feature = "std")]
pub mod stages;
#[cfg(feature = "std")]
mod trim;

use alloc::format;
use alloc::vec::Vec;
use glam::DVec2;

use crate::mesh::{angle_stats, edge_counts, FaceRange};
use crate::nurbs::{Aabb, Surface};
use crate::reparam::{rebuild_face, step_ratio, Rebuilt, Reparam, ReparamFace, RATIO_LIMIT};
use crate::{Error, Mesh, Model, Report};

pub use options::{MeshMode, MeshOptions, OptionsError, Tolerance};

/// A mesh and what was measured on it.
#[derive(Debug, Clone, Default)]
pub struct MeshResult {
    /// The triangles.
    pub mesh: Mesh,
    /// Measured deviation, angles, edge census, warnings.
    pub report: Report,
}

/// Meshes every face of `model` within `options`, and measures the result.
///
/// Each face gets an iso-parametric grid sized by paper 000's chord test, a
/// constrained Delaunay band along its trim loops, and refinement until every
/// triangle's measured deviation, normal turn and edge length pass.
/// With [`MeshMode::Quality`] the faces get near-equilateral triangles of
/// the size in [`MeshOptions::quality`] instead (paper 003).
///
/// # Errors
/// Invalid options, an empty model, a face whose loops cross or leave the
/// domain, or a tolerance that would need more triangles than the budget.
pub fn mesh_model(model: &Model, options: &MeshOptions) -> Result<MeshResult, Error> {
    mesh_model_with_progress(model, options, &mut |_, _| true)
}

/// As [`mesh_model`], calling `progress(faces_done, faces_total)` after each
/// face; when it returns `false` meshing stops with [`Error::Cancelled`].
/// (The core has no clock or threads: a caller that wants a time limit or a
/// cancel button decides inside the callback.)
///
/// # Errors
/// As [`mesh_model`], or [`Error::Cancelled`].
pub fn mesh_model_with_progress(
    model: &Model,
    options: &MeshOptions,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<MeshResult, Error> {
    if options.mode == MeshMode::Quality {
        return crate::quality::mesh_quality(model, options, progress);
    }
    let Setup { tol, diag, lim, crit } = setup(model, options)?;
    let aim = crit.tol;
    let mut report = Report { tolerance: tol, angle: options.angle, faces: model.faces.len(), ..Report::default() };
    report.warnings.extend(model.warnings.iter().cloned());
    // Paper 001: faces whose parameters crowd are rebuilt on even ones first.
    let rebuilt = reparameterize(model, options.reparam, tol, &mut report);
    // Mesh every face on its own.
    let mut works: Vec<sew::FaceWork<'_>> = Vec::with_capacity(model.faces.len());
    let mut outcomes: Vec<refine::Outcome> = Vec::with_capacity(model.faces.len());
    let mut fit_errors: Vec<f64> = Vec::with_capacity(model.faces.len());
    let mut used = 0usize;
    let mut first_failure: Option<Error> = None;
    for (index, original) in model.faces.iter().enumerate() {
        let (mut f, mut fit_error, cap) = match rebuilt.get(index) {
            Some(Some(r)) => (&r.face, r.fit_error, r.max_edge),
            _ => (original, 0.0, f64::INFINITY),
        };
        let budget = options.max_triangles.saturating_sub(used);
        if budget < 2 {
            report.faces_skipped += 1;
            report
                .warnings
                .push(format!("face {index}: skipped, the triangle budget {} is spent", options.max_triangles));
            push_empty(&mut works, &mut outcomes, &mut fit_errors, f);
            continue;
        }
        if !face_is_supported(f) {
            report.faces_skipped += 1;
            report.warnings.push(format!("face {index}: trimmed faces need the default `std` feature (CDT); skipped"));
            push_empty(&mut works, &mut outcomes, &mut fit_errors, f);
            continue;
        }
        // A rebuilt face is meshed within what its fit error leaves of the tolerance.
        let share = if fit_error > 0.0 { ((tol - fit_error) / tol).clamp(0.5, 1.0) } else { 1.0 };
        let face_lim = params::Limits { tol: lim.tol * share, max_edge: lim.max_edge.min(cap), ..lim };
        let face_crit = refine::Criteria { tol: crit.tol * share, max_edge: crit.max_edge.min(cap), ..crit };
        let mut fr = face::mesh_face(index, f, &face_lim, &face_crit, budget);
        if fit_error > 0.0 {
            // Paper 001's rebuild is kept where it pays: under `auto` the
            // original is meshed too and wins on more triangles or worse angles.
            let failed = !matches!(&fr, Ok(r) if !r.mesh.tris.is_empty());
            if failed || options.reparam == Reparam::Auto {
                let orig = face::mesh_face(index, original, &lim, &crit, budget);
                if let Some(why) = rebuild_loses(&fr, &orig) {
                    report.warnings.push(format!("face {index}: {why}; meshed the original"));
                    if let Some(r) = report.reparameterized.iter_mut().find(|r| r.face == index) {
                        r.rebuilt = false;
                    }
                    (f, fit_error, fr) = (original, 0.0, orig);
                }
            }
        }
        let mut fr = match fr {
            Ok(fr) => fr,
            // One face that cannot be meshed does not sink the others; a
            // model where none can is the first face's error.
            Err(Error::Mesh { face, message }) if model.faces.len() > 1 => {
                report.faces_skipped += 1;
                report.warnings.push(format!("face {index}: skipped: {message}"));
                first_failure.get_or_insert(Error::Mesh { face, message });
                push_empty(&mut works, &mut outcomes, &mut fit_errors, f);
                if !progress(index + 1, model.faces.len()) {
                    return Err(Error::Cancelled);
                }
                continue;
            }
            Err(e) => return Err(e),
        };
        if fit_error > 0.0 {
            // Reported against the original face: the mesh's distance to the new one plus the fit error.
            for m in &mut fr.outcome.measures {
                m.max += fit_error;
            }
        }
        used += fr.mesh.tris.len();
        if fr.mesh.tris.is_empty() {
            report.faces_skipped += 1;
            report.warnings.push(format!("face {index}: produced no triangles"));
        }
        if fr.outcome.unproven > 0 {
            report.warnings.push(format!(
                "face {index}: {} triangles still exceed the limits ({})",
                fr.outcome.unproven,
                if fr.outcome.budget_hit { "triangle budget reached" } else { "edges at the minimum length" }
            ));
        }
        works.push(sew::FaceWork { surface: &f.surface, curves: fr.curves, mesh: fr.mesh });
        fit_errors.push(fit_error);
        outcomes.push(fr.outcome);
        if !progress(index + 1, model.faces.len()) {
            return Err(Error::Cancelled);
        }
    }
    if let Some(e) = first_failure.filter(|_| works.iter().all(|w| w.mesh.tris.is_empty())) {
        return Err(e);
    }
    // Make shared borders conform, then measure again what sewing touched.
    let sew_tol = options.sew.unwrap_or_else(|| {
        let auto = (0.5 * tol).min(1e-4 * diag.max(tol));
        model.tolerance.filter(|t| t.is_finite() && *t > 0.0).map_or(auto, |t| auto.max(t.min(0.5 * tol)))
    });
    let mut changed = sew::conform(&mut works, sew_tol, aim + sew_tol);
    // Sewing may fold a thin triangle next to a moved or inserted border
    // vertex: unfold by interior edge flips or by moving an inner vertex,
    // which leaves the sewn borders as they are (a rebuilt face within what
    // its fit error leaves of the tolerance).
    for ((w, ch), fit_error) in works.iter_mut().zip(changed.iter_mut()).zip(&fit_errors) {
        let share = if *fit_error > 0.0 { ((tol - fit_error) / tol).clamp(0.5, 1.0) } else { 1.0 };
        ch.extend(w.mesh.repair_inverted(w.surface, &refine::Criteria { tol: crit.tol * share, ..crit }));
        ch.sort_unstable();
        ch.dedup();
    }
    for (((w, out), ch), fit_error) in works.iter().zip(outcomes.iter_mut()).zip(&changed).zip(&fit_errors) {
        out.measures.resize(w.mesh.tris.len(), Default::default());
        out.turns.resize(w.mesh.tris.len(), 0.0);
        for &t in ch {
            let (mut m, turn) = w.mesh.measure_one(w.surface, t as usize, &crit);
            m.max += fit_error;
            out.measures[t as usize] = m;
            out.turns[t as usize] = turn;
        }
    }
    let mut mesh = Mesh::default();
    let (mut dev_sum, mut dev_count) = (0.0, 0u64);
    for (w, out) in works.iter().zip(&outcomes) {
        let wm = &w.mesh;
        let first = mesh.triangle_count() as u32;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&wm.pos);
        mesh.normals.extend_from_slice(&wm.normal);
        for t in &wm.tris {
            mesh.indices.extend(t.iter().map(|&v| v + base));
        }
        mesh.face_ranges.push(FaceRange { first, count: wm.tris.len() as u32 });
        for (t, m) in out.measures.iter().enumerate() {
            report.max_deviation = report.max_deviation.max(m.max);
            dev_sum += m.sum;
            dev_count += u64::from(m.count);
            if wm.inverted(w.surface, t) {
                report.inverted_triangles += 1;
            }
        }
        for &turn in &out.turns {
            report.max_normal_turn = report.max_normal_turn.max(turn);
        }
    }
    report.mean_deviation = if dev_count > 0 { dev_sum / dev_count as f64 } else { 0.0 };
    report.triangles = mesh.triangle_count();
    report.vertices = mesh.positions.len();
    let edges = edge_counts(&mesh, (tol * 1e-3).min(sew_tol * 0.5), tol);
    report.free_edges = edges.free_edges;
    report.boundary_edges = edges.boundary_edges;
    report.nonmanifold_edges = edges.nonmanifold_edges;
    let angles = angle_stats(&mesh);
    report.min_angle_deg = angles.min_deg;
    report.p1_angle_deg = angles.p1_deg;
    Ok(MeshResult { mesh, report })
}

/// Runs paper 001's ratio test on every face (unless `mode` is off) and
/// rebuilds those it flags (every face when forced); the report lists them.
/// A rebuild that fails leaves the original face, with a warning.
fn reparameterize(model: &Model, mode: Reparam, tol: f64, report: &mut Report) -> Vec<Option<Rebuilt>> {
    if mode == Reparam::Off {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(model.faces.len());
    for (index, f) in model.faces.iter().enumerate() {
        let ratio = step_ratio(&f.surface);
        if mode == Reparam::Auto && ratio <= RATIO_LIMIT {
            out.push(None);
            continue;
        }
        match rebuild_face(f, tol) {
            Ok(r) => {
                report.warnings.push(format!(
                    "face {index}: poorly parameterized (step ratio {ratio:.1}), rebuilt from {} x {} points \
                     within {:.2e} of the original",
                    r.samples[0], r.samples[1], r.fit_error
                ));
                report.reparameterized.push(ReparamFace {
                    face: index,
                    ratio,
                    rebuilt: true,
                    samples: r.samples,
                    fit_error: r.fit_error,
                });
                out.push(Some(r));
            }
            Err(why) => {
                report.warnings.push(format!(
                    "face {index}: poorly parameterized (step ratio {ratio:.1}), meshed as it is: {why}"
                ));
                report.reparameterized.push(ReparamFace {
                    face: index,
                    ratio,
                    rebuilt: false,
                    samples: [0, 0],
                    fit_error: 0.0,
                });
                out.push(None);
            }
        }
    }
    out
}

/// Why the mesh of a rebuilt face loses to the original's, if it does: it
/// failed or is empty, is not proven where the original is, has more
/// triangles, or a smaller 1st-percentile angle. `None` keeps the rebuild.
fn rebuild_loses(
    rebuilt: &Result<face::FaceResult<'_>, Error>,
    original: &Result<face::FaceResult<'_>, Error>,
) -> Option<alloc::string::String> {
    let Some(new) = rebuilt.as_ref().ok().filter(|r| !r.mesh.tris.is_empty()) else {
        return Some("the rebuilt face did not mesh".into());
    };
    let old = original.as_ref().ok()?;
    let p1 = |m: &refine::WorkMesh| {
        let corner = |a: glam::DVec3, b: glam::DVec3, c: glam::DVec3| crate::math::angle_between(b - a, c - a);
        let mut a: Vec<f64> = m
            .tris
            .iter()
            .map(|t| {
                let [p, q, r] = t.map(|v| m.pos.get(v as usize).copied().unwrap_or_default());
                corner(p, q, r).min(corner(q, r, p)).min(corner(r, p, q))
            })
            .collect();
        a.sort_by(f64::total_cmp);
        a.get(a.len().saturating_sub(1) / 100).map_or(0.0, |x| x.to_degrees())
    };
    let (nt, ot) = (new.mesh.tris.len(), old.mesh.tris.len());
    if new.outcome.unproven > old.outcome.unproven {
        Some(format!("the rebuilt face left {} triangles unproven", new.outcome.unproven))
    } else if nt > ot {
        Some(format!("the rebuilt face took more triangles ({nt} against {ot})"))
    } else if p1(&new.mesh) < p1(&old.mesh) {
        Some(format!(
            "the rebuilt face's triangles were worse shaped (1st-percentile angle {:.1}° against {:.1}°)",
            p1(&new.mesh),
            p1(&old.mesh)
        ))
    } else {
        None
    }
}

/// What the options come to for one model.
pub(crate) struct Setup {
    /// Absolute chordal tolerance.
    tol: f64,
    /// Diagonal of the trimmed geometry's box.
    diag: f64,
    /// Limits of the grid and loop discretization (the tolerance times the safety factor).
    lim: params::Limits,
    /// Limits every triangle must meet after refinement.
    crit: refine::Criteria,
}

/// Validates `options` and turns them into the limits for `model`.
fn setup(model: &Model, options: &MeshOptions) -> Result<Setup, Error> {
    options.validate()?;
    if model.faces.is_empty() {
        return Err(Error::Model { location: "model".into(), message: "has no faces".into() });
    }
    let diag = trimmed_bbox(model).diagonal();
    let tol = match options.tolerance {
        Tolerance::Absolute(t) => t,
        Tolerance::Relative(r) => r * diag,
    };
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(Error::Model { location: "model".into(), message: "has zero size; use an absolute --tol".into() });
    }
    let min_edge = options.min_edge.unwrap_or(tol * 1e-3);
    let max_edge = options.max_edge.unwrap_or(f64::INFINITY);
    let aim = tol * options.safety;
    let lim = params::Limits { tol: aim, angle: options.angle, max_edge, min_edge };
    let crit = refine::Criteria { tol: aim, angle: options.angle, max_edge, min_edge, steps: options.measure_steps };
    Ok(Setup { tol, diag, lim, crit })
}

/// Records a face that produced nothing, so face ranges still match faces.
fn push_empty<'a>(
    works: &mut Vec<sew::FaceWork<'a>>,
    outcomes: &mut Vec<refine::Outcome>,
    fit_errors: &mut Vec<f64>,
    f: &'a crate::Face,
) {
    works.push(sew::FaceWork { surface: &f.surface, curves: Vec::new(), mesh: Default::default() });
    outcomes.push(Default::default());
    fit_errors.push(0.0);
}

fn face_is_supported(f: &crate::Face) -> bool {
    cfg!(feature = "std") || f.loops.is_empty()
}

/// Box of the trimmed geometry, from a 17×17 sample of each face's surface over
/// its loops' parameter box (points inside the region) and the loops themselves.
pub(crate) fn trimmed_bbox(model: &Model) -> Aabb {
    let mut b = Aabb::EMPTY;
    for f in &model.faces {
        let s: &dyn Surface = &f.surface;
        let [mut lo, mut hi] = s.domain();
        let mut polys: Vec<Vec<DVec2>> = Vec::new();
        if !f.loops.is_empty() {
            let (mut llo, mut lhi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for lp in &f.loops {
                let mut poly = Vec::new();
                for c in &lp.curves {
                    let (a, z) = c.domain();
                    for k in 0..16 {
                        let q = c.point(a + (z - a) * k as f64 / 16.0).truncate();
                        llo = llo.min(q);
                        lhi = lhi.max(q);
                        b.add_point(s.point(q));
                        poly.push(q);
                    }
                }
                polys.push(poly);
            }
            lo = llo.max(lo);
            hi = lhi.min(hi);
        }
        let inside = |q: DVec2| {
            if polys.is_empty() {
                return true;
            }
            let mut c = false;
            for p in &polys {
                let n = p.len();
                for i in 0..n {
                    let (a, z) = (p[i], p[(i + 1) % n]);
                    if (a.y > q.y) != (z.y > q.y) && a.x + (q.y - a.y) / (z.y - a.y) * (z.x - a.x) > q.x {
                        c = !c;
                    }
                }
            }
            c
        };
        for i in 0..=16 {
            for j in 0..=16 {
                let q = lo + (hi - lo) * DVec2::new(i as f64 / 16.0, j as f64 / 16.0);
                if inside(q) {
                    b.add_point(s.point(q));
                }
            }
        }
    }
    b
}
