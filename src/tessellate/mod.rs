//! Tessellation of trimmed surfaces within a verified tolerance (paper 000).

#[cfg(feature = "std")]
mod band;
#[cfg(feature = "std")]
mod cdt;
mod collapse;
mod face;
#[cfg(feature = "std")]
mod fill;
pub(crate) mod measure;
#[cfg(feature = "std")]
mod mend_loops;
mod params;
mod refine;
mod sew;
#[cfg(feature = "std")]
pub mod stages;
mod tessellated;
mod trial;
#[cfg(feature = "std")]
mod trim;

use alloc::format;
use alloc::vec::Vec;

use crate::mesh::{angle_stats, edge_census, holes_warning, FaceRange};
use crate::model::{body_count, share_of_faces, trimmed_bbox};
#[cfg(feature = "std")]
use crate::nurbs::Surface;
use crate::options::{MeshOptions, Reparam, Tolerance};
use crate::reparam::{rebuild_face, step_ratio, Rebuilt, ReparamFace, RATIO_LIMIT};
use crate::report::{MeshResult, Report};
use crate::{Error, Mesh, Model};
pub(crate) use tessellated::append_unsewn;
use trial::{lift_needles, outline_of, rebuild_loses, shorter_edges, tris_of, SHORTER_TRIES};

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
    let bodies = body_count(model);
    // A share meshes its bodies only; the other faces stay empty (not skipped).
    let mine = match options.share {
        Some((index, count)) => share_of_faces(&model.bodies, model.face_count(), index, count),
        None => alloc::vec![true; model.face_count()],
    };
    if options.share.is_some() && !mine.contains(&true) {
        // More shares than bodies: this one returns at once, without the
        // bounding box a tolerance needs (its report's tolerance stays 0).
        options.validate()?;
        let mesh = Mesh { face_ranges: alloc::vec![FaceRange::default(); model.face_count()], ..Mesh::default() };
        let report = Report {
            units: model.units.clone(),
            angle: options.angle,
            faces: model.face_count(),
            faces_unread: model.skipped.len(),
            bodies,
            ..Report::default()
        };
        return Ok(MeshResult { mesh, report });
    }
    let Setup { tol, diag, lim, crit } = setup(model, options)?;
    let aim = crit.tol;
    let mut report = Report {
        units: model.units.clone(),
        tolerance: tol,
        angle: options.angle,
        faces: model.face_count(),
        faces_unread: model.skipped.len(),
        bodies,
        ..Report::default()
    };
    report.warnings.extend(model.warnings.iter().cloned());
    let mut facets = tessellated::Facets::new(model, &mine);
    // Paper 001: faces whose parameters crowd are rebuilt on even ones first.
    let rebuilt = reparameterize(model, &mine, options.reparam, tol, &mut report);
    // Untrimmed faces are meshed as trimmed by their domain's border, so
    // that their borders can be sewn like trim loops.
    let domain_loops: Vec<Vec<crate::TrimLoop>> = model.faces.iter().map(face::domain_loops).collect();
    let rebuilt_domain_loops: Vec<Vec<crate::TrimLoop>> =
        rebuilt.iter().map(|r| r.as_ref().map_or_else(Vec::new, |r| face::domain_loops(&r.face))).collect();
    // Within one face (a seam) borders meet within a rounding, or the file's
    // own modelling tolerance.
    let auto_tight = {
        let auto = (0.5 * tol).min(1e-4 * diag.max(tol));
        model.tolerance.filter(|t| t.is_finite() && *t > 0.0).map_or(auto, |t| auto.max(t.min(0.5 * tol)))
    };
    // Each face's variant and outline (its loops discretized), on its own.
    let mut chosen: Vec<Option<Chosen<'_>>> = Vec::with_capacity(model.faces.len());
    let mut first_failure: Option<Error> = None;
    for (index, original) in model.faces.iter().enumerate() {
        if !mine[index] {
            chosen.push(None);
            continue;
        }
        let (mut f, mut fit_error, cap) = match rebuilt.get(index) {
            Some(Some(r)) => (&r.face, r.fit_error, r.max_edge),
            _ => (original, 0.0, f64::INFINITY),
        };
        if !face_is_supported(f) {
            report.faces_skipped += 1;
            report.warnings.push(format!("face {index}: trimmed faces need the default `std` feature (CDT); skipped"));
            chosen.push(None);
            continue;
        }
        let (own, new) = (&domain_loops[index], rebuilt_domain_loops.get(index).map_or(&[][..], |l| &l[..]));
        let loops_of = |g| face_loops(g, original, own, new);
        // A rebuilt face is meshed within what its fit error leaves of the tolerance.
        let share = if fit_error > 0.0 { ((tol - fit_error) / tol).clamp(0.5, 1.0) } else { 1.0 };
        let mut face_lim = params::Limits { tol: lim.tol * share, max_edge: lim.max_edge.min(cap), ..lim };
        let mut face_crit = refine::Criteria { tol: crit.tol * share, max_edge: crit.max_edge.min(cap), ..crit };
        // Outlines the trials below made, each with its face and limits: the
        // one of the variant chosen is not made again.
        let mut made: Vec<(&crate::Face, params::Limits, face::Outline<'_>)> = Vec::new();
        if fit_error > 0.0 {
            // Paper 001's rebuild is kept where it pays: under `auto` the
            // original is meshed too and wins on more triangles or worse angles.
            // The original goes first, so the rebuild's trial stops as soon
            // as it takes more triangles (a creased face's rebuild can take 100×).
            let budget = options.max_triangles;
            let auto = options.reparam == Reparam::Auto;
            let orig_loops = loops_of(original);
            let mesh_original = || face::mesh_face(index, original, orig_loops, &lim, &crit, budget, auto_tight);
            let mut orig = auto.then(mesh_original);
            let trial = match &orig {
                Some(Ok(o)) => budget.min(o.mesh.tris.len().saturating_add(1)),
                _ => budget,
            };
            let f_loops = loops_of(f);
            let mut fr = face::mesh_face(index, f, f_loops, &face_lim, &face_crit, trial, auto_tight);
            let failed = !matches!(&fr, Ok(r) if !r.mesh.tris.is_empty());
            if failed || auto {
                let mut orig = orig.take().unwrap_or_else(mesh_original);
                let mut why = rebuild_loses(&fr, &orig);
                made.extend(outline_of(&mut fr).map(|o| (f, face_lim, o)));
                let capped = (fr, face_lim, face_crit);
                let mut free_run = None;
                if why.is_some() && auto && cap.is_finite() {
                    // The edge cap follows the sharpest bend; where that bend
                    // is local, the rebuild may pay without it.
                    let l = params::Limits { max_edge: lim.max_edge, ..face_lim };
                    let c = refine::Criteria { max_edge: crit.max_edge, ..face_crit };
                    let mut free = face::mesh_face(index, f, f_loops, &l, &c, trial, auto_tight);
                    made.extend(outline_of(&mut free).map(|o| (f, l, o)));
                    if rebuild_loses(&free, &orig).is_none() {
                        (why, face_lim, face_crit) = (None, l, c);
                    } else {
                        free_run = Some((free, l, c));
                    }
                }
                // The lighter of the capped and the free mesh.
                let lighter = match &free_run {
                    Some(free) if tris_of(&free.0) < tris_of(&capped.0) => free,
                    _ => &capped,
                };
                if why.is_some() && auto {
                    // Shorter edges start from the capped mesh (the free one
                    // where it failed) at half its longest edge, then from
                    // the lighter of the two one step nearer its longest edge.
                    // When that is the same mesh, all but its first try
                    // repeat the tries that already failed.
                    let first = match (&capped.0, &free_run) {
                        (Err(_), Some(free)) => free,
                        _ => &capped,
                    };
                    let again = if core::ptr::eq(first, lighter) { 1 } else { SHORTER_TRIES };
                    let starts = [(first, 0.5, SHORTER_TRIES), (lighter, core::f64::consts::FRAC_1_SQRT_2, again)];
                    for ((r, l, c), k, tries) in starts {
                        let won = shorter_edges(index, (f, f_loops), r, &orig, (l, c, k, tries), trial, auto_tight);
                        if let Some((l, c, o)) = won {
                            (why, face_lim, face_crit) = (None, l, c);
                            made.extend(o.map(|o| (f, l, o)));
                            break;
                        }
                    }
                }
                if why.is_some() && auto {
                    let (_, l, _) = *lighter;
                    if let Some((c, o)) = lift_needles(index, (f, f_loops), lighter, &orig, trial, auto_tight) {
                        (why, face_lim, face_crit) = (None, l, c);
                        made.extend(o.map(|o| (f, l, o)));
                    }
                }
                if let Some(why) = why {
                    report.warnings.push(format!("face {index}: {why}; meshed the original"));
                    if let Some(r) = report.reparameterized.iter_mut().find(|r| r.face == index) {
                        r.rebuilt = false;
                    }
                    (f, fit_error, face_lim, face_crit) = (original, 0.0, lim, crit);
                    made.extend(outline_of(&mut orig).map(|o| (original, lim, o)));
                }
            } else {
                made.extend(outline_of(&mut fr).map(|o| (f, face_lim, o)));
            }
        }
        let loops = loops_of(f);
        let ready = made.into_iter().find(|(g, l, _)| core::ptr::eq(*g, f) && l.same_as(&face_lim)).map(|(_, _, o)| o);
        match Chosen::new(index, f, loops, face_lim, face_crit, fit_error, ready) {
            Ok(c) => {
                if let Some(m) = c.mended() {
                    report.warnings.push(format!("face {index}: {m}"));
                }
                if let Some(along) = c.capped_grid() {
                    report.warnings.push(format!(
                        "face {index}: the grid along {along} stopped at its cap of {} lines (the surface's \
                         normals or sag never settle there); refinement still holds the tolerance",
                        params::MAX_PARAMS
                    ));
                }
                chosen.push(Some(c));
            }
            // One face that cannot be meshed does not sink the others; a
            // model where none can is the first face's error.
            Err(Error::Mesh { face, message }) if model.faces.len() > 1 => {
                report.faces_skipped += 1;
                report.warnings.push(format!("face {index}: skipped: {message}"));
                first_failure.get_or_insert(Error::Mesh { face, message });
                chosen.push(None);
            }
            Err(e) => return Err(e),
        }
    }
    // Shared borders get the same nodes before anything is triangulated.
    // Borders of different faces are sewn as far apart as the model's gaps
    // need, up to 0.4 of the tolerance: each side then moves by half the
    // gap, within what the 0.8 safety leaves of the tolerance. A sewing
    // distance the caller sets holds for seams too.
    let (sew_tol, tight) = match options.sew {
        Some(s) => (s, auto_tight.min(s)),
        None => (0.4 * tol, auto_tight),
    };
    // Closed as built (a sphere, a torus, a ring's closed quarter): its
    // seams and poles meet to a rounding. A side that shrinks to a small
    // circle within the sewing distance is a border that another face can
    // close, not a pole.
    let body_ids = own_bodies(model, &mine, 1e-9 * diag.max(tol));
    let ids = unify_outlines(&mut chosen, &body_ids, &facets, sew_tol, tight, aim + sew_tol);
    // Every face's first mesh (grid and trim band) on those nodes; each
    // outline is freed once its mesh is built (only whether it is pinched
    // is asked later).
    let mut works: Vec<sew::FaceWork<'_>> = Vec::with_capacity(model.faces.len());
    let mut fit_errors: Vec<f64> = Vec::with_capacity(model.faces.len());
    let mut pinched: Vec<bool> = Vec::with_capacity(model.faces.len());
    let mut used = 0usize;
    for (index, c) in chosen.into_iter().enumerate() {
        let f = &model.faces[index];
        pinched.push(c.as_ref().is_some_and(Chosen::pinched));
        let Some(c) = c else {
            works.push(empty_work(f, crit));
            fit_errors.push(0.0);
            continue;
        };
        let budget = options.max_triangles.saturating_sub(used);
        let why = match c.initial(index, budget) {
            Ok((mut mesh, curves)) => {
                used += mesh.tris.len();
                mesh.rest();
                works.push(sew::FaceWork { surface: &c.face.surface, curves, mesh, crit: c.crit });
                fit_errors.push(c.fit_error);
                continue;
            }
            Err(Error::Mesh { face, message }) if model.faces.len() > 1 => {
                let why = format!("face {index}: skipped: {message}");
                first_failure.get_or_insert(Error::Mesh { face, message });
                why
            }
            Err(Error::Limit(m)) if model.faces.len() > 1 && budget < options.max_triangles => {
                format!("face {index}: skipped, the triangle budget is spent ({m})")
            }
            Err(e) => return Err(e),
        };
        report.faces_skipped += 1;
        report.warnings.push(why);
        works.push(empty_work(f, crit));
        fit_errors.push(0.0);
    }
    if let Some(e) = first_failure.filter(|_| works.iter().all(|w| w.mesh.tris.is_empty())) {
        return Err(e);
    }
    // Borders along tessellated faces take their vertices before refinement.
    tessellated::snap_borders(&mut works, &facets, &body_ids, sew_tol);
    // Refinement keeps shared borders shared: a split of a shared edge is
    // made on every side; then every node takes one position.
    let budget_hit = sew::refine_all(&mut works, ids, sew_tol, options.max_triangles, progress)?;
    let (settled, places) = sew::settle_nodes(&mut works, 1e-6 * tol);
    for (w, moved) in works.iter_mut().zip(&settled) {
        w.mesh.forget(moved);
    }
    // Refinement may leave a thin triangle folded next to a border node it
    // cannot move: unfold by interior edge flips or by moving an inner
    // vertex, which leaves the shared borders as they are. What is still
    // folded may unfold with a node at another face's place for it, and
    // then by flips.
    let mut folded: Vec<Vec<u32>> = Vec::with_capacity(works.len());
    for w in works.iter_mut() {
        let (changed, left) = w.mesh.repair_inverted(w.surface, &w.crit);
        w.mesh.forget(&changed);
        w.mesh.rest();
        folded.push(left);
    }
    if folded.iter().any(|f| !f.is_empty()) {
        let moved = sew::resettle_folds(&mut works, &places, &folded);
        for (w, moved) in works.iter_mut().zip(&moved) {
            if !moved.is_empty() {
                w.mesh.forget(moved);
                let (changed, _) = w.mesh.repair_inverted(w.surface, &w.crit);
                w.mesh.forget(&changed);
                w.mesh.rest();
            }
        }
    }
    let mut taken = crate::collections::HashSet::default();
    for w in &works {
        w.mesh.border_node_edges(&mut taken);
    }
    for w in works.iter_mut() {
        let changed = w.mesh.improve_angles(w.surface, &w.crit, &mut taken);
        w.mesh.forget(&changed);
        #[cfg(feature = "std")]
        {
            let lifted = w.mesh.lift_angles(w.surface, &w.crit);
            w.mesh.forget(&lifted);
        }
        w.mesh.rest();
    }
    drop(taken);
    // Three faces' corners that sewing left apart: a sliver between them.
    #[cfg(feature = "std")]
    fill::close_slivers(&mut works, tol);
    for w in works.iter_mut() {
        w.mesh.rest();
    }
    // The tessellated faces take the exact borders' nodes along theirs.
    tessellated::split_rims(&mut works, &mut facets, &body_ids, sew_tol);
    let (mut dev_sum, mut dev_count) = (0.0, 0u64);
    for (index, (w, fit_error)) in works.iter_mut().zip(&fit_errors).enumerate() {
        let out = w.mesh.outcome(w.surface, &w.crit);
        // Reported against the original face: the mesh's distance to the new one plus the fit error.
        if !w.mesh.tris.is_empty() {
            report.max_deviation = report.max_deviation.max(out.max + fit_error);
        }
        dev_sum += out.sum;
        dev_count += out.count;
        report.max_normal_turn = report.max_normal_turn.max(out.max_turn);
        // Corners a millionth of the tolerance apart are one point of the
        // welded mesh (far inside the edge counts' weld distance).
        report.inverted_triangles +=
            (0..w.mesh.tris.len()).filter(|&t| w.mesh.folded_beyond(w.surface, t, 1e-6 * tol)).count();
        if w.mesh.tris.is_empty() {
            if mine[index] && !report.warnings.iter().any(|x| x.starts_with(&format!("face {index}: "))) {
                report.faces_skipped += 1;
                // A loop that passes one node twice: a strip narrower than
                // the sewing distance, its two sides sewn into one border.
                report.warnings.push(if pinched[index] {
                    format!(
                        "face {index}: produced no triangles: a strip narrower than the sewing distance, \
                         its sides sewn into one border by its neighbours"
                    )
                } else {
                    format!("face {index}: produced no triangles")
                });
            }
        } else if out.unproven > 0 {
            report.warnings.push(format!(
                "face {index}: {} triangles still exceed the limits ({})",
                out.unproven,
                if budget_hit { "triangle budget reached" } else { "edges at the minimum length" }
            ));
        }
        if out.creased > 0 {
            report.warnings.push(format!(
                "face {index}: {} triangles turn more than the angle limit where the surface folds or creases; \
                 not split below a tenth of the tolerance",
                out.creased
            ));
        }
    }
    // The model's mesh, each face's working state freed as soon as it is
    // copied, the mesh growing by what each face adds: presized in full,
    // it sat next to every face's full working state (wasm memory never
    // shrinks, so the peak is what a page keeps).
    drop((places, folded, settled));
    let mut mesh = Mesh { face_ranges: Vec::with_capacity(works.len()), ..Mesh::default() };
    for w in &mut works {
        let mut wm = core::mem::take(&mut w.mesh);
        collapse::collapse_point_edges(&wm.pos, &mut wm.tris);
        let first = mesh.triangle_count() as u32;
        let base = mesh.positions.len() as u32;
        // Vertices no triangle kept (a removed flap's corner, a collapsed
        // sliver's) are left out: a stray point would still widen the
        // bounding box a viewer fits its camera to.
        let mut index = alloc::vec![u32::MAX; wm.pos.len()];
        for t in &wm.tris {
            for &v in t {
                index[v as usize] = 0;
            }
        }
        let kept = index.iter().filter(|&&x| x == 0).count();
        grow(&mut mesh.positions, kept);
        grow(&mut mesh.normals, kept);
        grow(&mut mesh.indices, 3 * wm.tris.len());
        let mut next = base;
        for (v, slot) in index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = next;
                next += 1;
                mesh.positions.push(wm.pos[v]);
                mesh.normals.push(wm.normal_at(v));
            }
        }
        for t in &wm.tris {
            mesh.indices.extend(t.iter().map(|&v| index[v as usize]));
        }
        mesh.face_ranges.push(FaceRange { first, count: wm.tris.len() as u32 });
    }
    let dropped = facets.append_to(&mut mesh);
    // The room the last growth left, given back before the mesh is measured.
    mesh.positions.shrink_to_fit();
    mesh.normals.shrink_to_fit();
    mesh.indices.shrink_to_fit();
    report.mean_deviation = if dev_count > 0 { dev_sum / dev_count as f64 } else { 0.0 };
    report.triangles = mesh.triangle_count();
    report.vertices = mesh.positions.len();
    let (edges, gaps) = edge_census(&mesh, &body_ids, &model.skipped, (tol * 1e-3).min(tight * 0.5), tol);
    holes_warning(&model.skipped, edges.hole_edges, &mut report.warnings);
    // A crack wider than sewing reaches is the file's own gap: say where.
    for g in gaps.iter().filter(|g| g.width > sew_tol) {
        report.warnings.push(format!(
            "faces {} and {}: their borders lie {:.3e} apart where they meet, farther than sewing closes \
             ({sew_tol:.3e}); the crack between them is left open",
            g.faces.0, g.faces.1, g.width
        ));
    }
    report.free_edges = edges.free_edges;
    report.boundary_edges = edges.boundary_edges;
    report.nonmanifold_edges = edges.nonmanifold_edges;
    let angles = angle_stats(&mesh);
    report.min_angle_deg = angles.min_deg;
    report.p1_angle_deg = angles.p1_deg;
    tessellated::finish_report(model, &mine, &mesh, dropped, &mut report);
    Ok(MeshResult { mesh, report })
}

/// Makes room for `extra` more elements, growing by an eighth: the model's
/// mesh grows face by face as the faces' working state is freed, and the
/// slack of doubling would be up to half of it.
fn grow<T>(v: &mut Vec<T>, extra: usize) {
    if v.capacity() - v.len() < extra {
        v.reserve_exact(v.len() / 8 + extra);
    }
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
    let crit = refine::Criteria {
        tol: aim,
        angle: options.angle,
        max_edge,
        min_edge,
        steps: options.measure_steps,
        lift: refine::Lift::NONE,
    };
    Ok(Setup { tol, diag, lim, crit })
}

/// A face as it will be meshed: the variant chosen (the original or paper
/// 001's rebuild), its limits and, with `std`, its outline to sew.
struct Chosen<'a> {
    face: &'a crate::Face,
    #[cfg(feature = "std")]
    outline: face::Outline<'a>,
    fit_error: f64,
    /// The grid's limits (with `std` they went into the outline).
    #[cfg(not(feature = "std"))]
    lim: params::Limits,
    crit: refine::Criteria,
}

impl<'a> Chosen<'a> {
    /// `loops`: the face's own, or its domain's border when it has none;
    /// `ready`: its outline for `lim` when a trial already made it.
    fn new(
        index: usize,
        face: &'a crate::Face,
        loops: &'a [crate::TrimLoop],
        lim: params::Limits,
        crit: refine::Criteria,
        fit_error: f64,
        ready: Option<face::Outline<'a>>,
    ) -> Result<Self, Error> {
        #[cfg(feature = "std")]
        let outline = match ready {
            Some(o) => o,
            None => face::outline(index, &face.surface, loops, face.loops.is_empty(), &lim, usize::MAX)?,
        };
        #[cfg(not(feature = "std"))]
        let _ = (index, loops, ready);
        Ok(Self {
            face,
            #[cfg(feature = "std")]
            outline,
            fit_error,
            #[cfg(not(feature = "std"))]
            lim,
            crit,
        })
    }

    /// What mending its crossing trim loops changed, if they crossed.
    #[cfg(feature = "std")]
    fn mended(&self) -> Option<mend_loops::Mended> {
        self.outline.loops.mended
    }

    /// Without the trimmed mesher there are no loops to mend.
    #[cfg(not(feature = "std"))]
    fn mended(&self) -> Option<&'static str> {
        None
    }

    /// The direction (`"u"` or `"v"`) whose grid lines reached
    /// [`params::MAX_PARAMS`], where the interval tests stopped splitting
    /// before they passed.
    fn capped_grid(&self) -> Option<&'static str> {
        #[cfg(feature = "std")]
        {
            let capped = |p: &[f64]| p.len() >= params::MAX_PARAMS;
            if capped(&self.outline.pu) {
                return Some("u");
            }
            if capped(&self.outline.pv) {
                return Some("v");
            }
        }
        None
    }

    /// Whether a loop of the sewn outline passes one node twice.
    fn pinched(&self) -> bool {
        #[cfg(feature = "std")]
        {
            self.outline.gids.iter().any(|g| {
                let mut ids: Vec<u32> = g.iter().copied().filter(|&x| x != u32::MAX).collect();
                let n = ids.len();
                ids.sort_unstable();
                ids.dedup();
                ids.len() < n
            })
        }
        #[cfg(not(feature = "std"))]
        false
    }

    /// The face's mesh before refinement, and the curves its trim edges follow.
    fn initial(&self, index: usize, budget: usize) -> Result<(refine::WorkMesh, Vec<&'a crate::NurbsCurve>), Error> {
        #[cfg(feature = "std")]
        {
            let wm = face::initial_from_outline(index, &self.face.surface, &self.outline, budget)?;
            Ok((wm, self.outline.loops.curves.clone()))
        }
        #[cfg(not(feature = "std"))]
        face::initial_face(index, self.face, &self.lim, budget)
    }
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

/// Sews the outlines of the faces to be meshed (see [`sew::unify`]), after
/// the tessellated faces' border vertices are pinned on them; returns the node ids given.
fn unify_outlines(
    chosen: &mut [Option<Chosen<'_>>],
    bodies: &[u32],
    facets: &tessellated::Facets<'_>,
    sew_tol: f64,
    tight: f64,
    reach: f64,
) -> u32 {
    #[cfg(feature = "std")]
    {
        // A rebuilt face's border lies up to its fit error from its neighbours'.
        let moved: Vec<f64> = chosen.iter().map(|c| c.as_ref().map_or(0.0, |c| c.fit_error)).collect();
        let mut faces: Vec<Option<(&dyn Surface, &mut face::Outline<'_>)>> =
            chosen.iter_mut().map(|c| c.as_mut().map(|c| (&c.face.surface as &dyn Surface, &mut c.outline))).collect();
        tessellated::pin_outlines(&mut faces, bodies, facets, sew_tol);
        sew::unify(&mut faces, bodies, &moved, sew_tol, tight, reach)
    }
    #[cfg(not(feature = "std"))]
    {
        let _ = (chosen, bodies, facets, sew_tol, tight, reach);
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
