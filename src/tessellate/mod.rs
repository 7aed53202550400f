//! Tessellation of trimmed surfaces within a verified tolerance (paper 000).
//!
//! [`mesh_fast`] reads as the pipeline: each stage is one method of
//! [`pipeline::Plan`], with its paper section in its doc comment.
//!
//! Numbers ([`crate::numeric`]): nothing here is decided by an exact
//! predicate (spade's CDT decides its own triangulation exactly). Every test
//! takes a tolerance: deviation and normal turn against the chordal
//! tolerance and angle limit (with refinement's safety factor); sewing within
//! the sewing distance (at most 0.4 of the tolerance), seams within `tight`;
//! a triangle is folded in (u,v) by the sign of its float area (a flat one
//! counts as folded); a node is a segment's end within 1e-9 of its length,
//! and two points are one within 1e-12 of their coordinates' size.

#[cfg(feature = "std")]
mod band;
#[cfg(feature = "std")]
mod cdt;
mod collapse;
mod face;
#[cfg(feature = "std")]
mod fill;
mod holes;
pub(crate) mod measure;
#[cfg(feature = "std")]
mod mend_loops;
mod params;
pub mod pipeline;
mod refine;
mod sew;
mod tessellated;
#[cfg(feature = "std")]
mod touching;
mod trial;
#[cfg(feature = "std")]
mod trim;
mod variant;

use alloc::vec::Vec;

use crate::mesh::FaceRange;
use crate::model::{body_count, face_boxes, union_of};
#[cfg(feature = "std")]
use crate::nurbs::Surface;
use crate::options::{MeshOptions, Reparam, Tolerance};
use crate::reparam::{rebuild_face, step_ratio, Rebuilt, ReparamFace, RATIO_LIMIT};
use crate::report::{MeshResult, Report};
use crate::warning::{Reparameterized, Warning, WarningKind};
use crate::{Error, Mesh, Model};
use pipeline::{faces_of_share, Plan};
pub(crate) use tessellated::append_unsewn;
use variant::Chosen;

/// Meshes every face of `model` in fast mode (paper 000) within `options`,
/// and measures the result; `progress(faces_done, faces_total)` is called as
/// faces finish refinement, and stops meshing when it returns `false`.
///
/// Each face gets an iso-parametric grid sized by paper 000's chord test, a
/// constrained Delaunay band along its trim loops, and refinement until every
/// triangle's measured deviation, normal turn and edge length pass.
///
/// # Errors
/// Invalid options, an empty model, a face whose loops cross or leave the
/// domain, a tolerance that would need more triangles than the budget, or
/// [`Error::Cancelled`].
pub(crate) fn mesh_fast(
    model: &Model,
    options: &MeshOptions,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<MeshResult, Error> {
    // A share meshes its bodies only; the other faces stay empty (not skipped).
    let mine = faces_of_share(model, options);
    if options.share.is_some() && !mine.contains(&true) {
        return empty_share(model, options);
    }
    let plan = Plan::with_share(model, options, mine)?;
    let mut run = plan.start();
    let variants = plan.choose_variants(&mut run)?;
    let sewn = plan.sew_outlines(&run, variants);
    let mut works = plan.first_meshes(&mut run, sewn)?;
    let refined = plan.refine(&mut works, progress)?;
    plan.mend(&mut works, refined);
    plan.improve(&mut works);
    plan.close_gaps(&mut run, &mut works);
    plan.measure_faces(&mut run, &mut works);
    let mesh = plan.assemble(&mut run, works);
    Ok(plan.measure(run, mesh))
}

/// A share given no body (more shares than bodies): returned at once, without
/// the bounding box a tolerance needs (its report's tolerance stays 0).
fn empty_share(model: &Model, options: &MeshOptions) -> Result<MeshResult, Error> {
    options.validate()?;
    let mesh = Mesh { face_ranges: alloc::vec![FaceRange::default(); model.face_count()], ..Mesh::default() };
    let report = Report {
        units: model.units.clone(),
        angle: options.angle,
        faces: model.face_count(),
        faces_unread: model.skipped.len(),
        bodies: body_count(model),
        ..Report::default()
    };
    Ok(MeshResult { mesh, report })
}

/// Runs paper 001's ratio test on every face of the share `mine` (unless `mode` is off) and
/// rebuilds those it flags (every face when forced); the report lists them.
/// A rebuild that fails leaves the original face, with a warning.
fn reparameterize(model: &Model, mine: &[bool], mode: Reparam, tol: f64, report: &mut Report) -> Vec<Option<Rebuilt>> {
    if mode == Reparam::Off {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(model.faces.len());
    for (index, f) in model.faces.iter().enumerate() {
        if !mine.get(index).copied().unwrap_or(true) {
            out.push(None);
            continue;
        }
        let ratio = step_ratio(&f.surface);
        if mode == Reparam::Auto && ratio <= RATIO_LIMIT {
            out.push(None);
            continue;
        }
        match rebuild_face(f, tol) {
            Ok(r) => {
                let outcome = Reparameterized::Rebuilt { samples: r.samples, fit_error: r.fit_error };
                report.warnings.push(Warning::face(index, WarningKind::PoorlyParameterized { ratio, outcome }));
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
                let outcome = Reparameterized::MeshedAsIs(why);
                report.warnings.push(Warning::face(index, WarningKind::PoorlyParameterized { ratio, outcome }));
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

/// The loops face `g` is meshed by: its own, or its domain's border (the
/// original's `domain`, or the rebuild's `rebuilt_domain`) when it has none.
fn face_loops<'x>(
    g: &'x crate::Face,
    original: &crate::Face,
    domain: &'x [crate::TrimLoop],
    rebuilt_domain: &'x [crate::TrimLoop],
) -> &'x [crate::TrimLoop] {
    match (g.loops.is_empty(), core::ptr::eq(g, original)) {
        (false, _) => &g.loops,
        (true, true) => domain,
        (true, false) => rebuilt_domain,
    }
}

/// What the options come to for one model.
pub(crate) struct Setup {
    /// Absolute chordal tolerance.
    tol: f64,
    /// Diagonal of the trimmed geometry's box.
    diag: f64,
    /// Each face's box (exact faces, then tessellated).
    boxes: Vec<crate::nurbs::Aabb>,
    /// Limits of the grid and loop discretization (the tolerance times the safety factor).
    lim: params::Limits,
    /// Limits every triangle must meet after refinement.
    crit: refine::Criteria,
}

/// Validates `options` and turns them into the limits for `model`.
fn setup(model: &Model, options: &MeshOptions) -> Result<Setup, Error> {
    options.validate()?;
    if model.face_count() == 0 {
        return Err(Error::Model { location: "model".into(), message: "has no faces".into() });
    }
    let boxes = face_boxes(model);
    let diag = union_of(&boxes).diagonal();
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
    let crit = refine::Criteria {
        tol: aim,
        angle: options.angle,
        max_edge,
        min_edge,
        steps: options.measure_steps,
        lift: refine::Lift::NONE,
    };
    Ok(Setup { tol, diag, boxes, lim, crit })
}

/// Each face's body for sewing and for the edge counts: the file's
/// ([`Model::bodies`]), except that a face closed on itself
/// ([`face::closed_on_itself`] within `reach`) is a body of its own: it has
/// no border to sew, and where it touches another face (closed quarters of a
/// ring meeting at their end caps) the two are solids side by side, not one
/// surface with non-manifold edges.
fn own_bodies(model: &Model, mine: &[bool], reach: f64) -> Vec<u32> {
    let mut ids: Vec<u32> = (0..model.face_count()).map(|f| crate::model::body_of(&model.bodies, f)).collect();
    let mut next = ids.iter().copied().max().map_or(0, |m| m + 1);
    for (index, face) in model.faces.iter().enumerate() {
        if mine.get(index).copied().unwrap_or(false) && face::closed_on_itself(face, reach) {
            ids[index] = next;
            next += 1;
        }
    }
    ids
}

/// The coarsest tolerance, as a share of a body's own size, that its
/// sewing distances are derived from: in an assembly whose tolerance
/// exceeds a twentieth of a small part (a bolt beside a motor), the
/// model's distances span the part's features and sew them together.
const BODY_SEW_SHARE: f64 = 0.05;

/// Per face, the factor its body's sewing distances take of the model's:
/// `BODY_SEW_SHARE` of the body's size (the box of its faces, `boxes`) over
/// the tolerance `tol`, but not below the body's share of the model's size
/// `diag` (a body as large as the model keeps the model's distances, at any
/// tolerance), at most 1, rounded down to a power of two so that bodies of
/// about one size are sewn together in one pass. A body of no measurable
/// size keeps the model's distances.
fn sewing_scales(boxes: &[crate::nurbs::Aabb], bodies: &[u32], tol: f64, diag: f64) -> Vec<f64> {
    let mut body_box: crate::collections::HashMap<u32, crate::nurbs::Aabb> = crate::collections::HashMap::default();
    for (f, b) in boxes.iter().enumerate() {
        body_box.entry(crate::model::body_of(bodies, f)).or_insert(crate::nurbs::Aabb::EMPTY).union(b);
    }
    (0..boxes.len())
        .map(|f| {
            let size = body_box.get(&crate::model::body_of(bodies, f)).map_or(0.0, |b| b.diagonal());
            let k = (BODY_SEW_SHARE * size / tol).max(size / diag);
            if k.is_finite() && k > 0.0 && k < 1.0 {
                // Mantissa cleared: the power of two at or below `k` (zero if subnormal).
                let p = f64::from_bits(k.to_bits() & 0xFFF0_0000_0000_0000);
                if p > 0.0 {
                    p
                } else {
                    f64::MIN_POSITIVE
                }
            } else {
                1.0
            }
        })
        .collect()
}

/// Sews the outlines of the faces to be meshed (see [`sew::unify`]), after
/// the tessellated faces' border vertices are pinned on them, and halves the
/// sewn chords that then cross ([`sew::split_crossing_chords`]); returns the
/// node ids given. Faces are sewn in groups of one sewing scale (`scales`,
/// per face: [`sewing_scales`]), each at `sew_tol` and `tight` times its
/// scale: faces of different bodies are never sewn together, so each group
/// is sewn on its own, its node ids following the last group's.
fn unify_outlines(
    chosen: &mut [Option<Chosen<'_>>],
    bodies: &[u32],
    scales: &[f64],
    facets: &tessellated::Facets<'_>,
    sew_tol: f64,
    tight: f64,
    chord: f64,
) -> u32 {
    #[cfg(feature = "std")]
    {
        // A rebuilt face's border lies up to its fit error from its neighbours'.
        let moved: Vec<f64> = chosen.iter().map(|c| c.as_ref().map_or(0.0, |c| c.fit_error)).collect();
        let scale_of = |f: usize| scales.get(f).copied().unwrap_or(1.0);
        // The distinct scales, largest first (few: powers of two).
        let mut groups: Vec<f64> = Vec::new();
        for k in (0..chosen.len()).map(scale_of) {
            if !groups.contains(&k) {
                groups.push(k);
            }
        }
        crate::sort::f64s(&mut groups);
        let mut ids = 0u32;
        for &k in groups.iter().rev() {
            let mut faces: Vec<Option<(&dyn Surface, &mut face::Outline<'_>)>> = chosen
                .iter_mut()
                .enumerate()
                .map(|(f, c)| {
                    c.as_mut().filter(|_| scale_of(f) == k).map(|c| (&c.face.surface as &dyn Surface, &mut c.outline))
                })
                .collect();
            let (sew, tight) = (sew_tol * k, tight * k);
            tessellated::pin_outlines(&mut faces, bodies, facets, sew);
            let given = sew::unify(&mut faces, bodies, &moved, sew, tight, chord + sew);
            for (_, o) in faces.iter_mut().flatten() {
                for g in o.gids.iter_mut().flatten() {
                    *g += ids;
                }
            }
            ids += given;
        }
        let mut faces: Vec<Option<(&dyn Surface, &mut face::Outline<'_>)>> =
            chosen.iter_mut().map(|c| c.as_mut().map(|c| (&c.face.surface as &dyn Surface, &mut c.outline))).collect();
        sew::split_crossing_chords(&mut faces, ids)
    }
    #[cfg(not(feature = "std"))]
    {
        let _ = (chosen, bodies, scales, facets, sew_tol, tight, chord);
        0
    }
}

/// A face that produced nothing, so face ranges still match faces.
fn empty_work(f: &crate::Face, crit: refine::Criteria) -> sew::FaceWork<'_> {
    sew::FaceWork { surface: &f.surface, curves: Vec::new(), mesh: Default::default(), crit }
}

fn face_is_supported(f: &crate::Face) -> bool {
    cfg!(feature = "std") || f.loops.is_empty()
}
