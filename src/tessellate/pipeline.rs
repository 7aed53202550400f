//! The fast mesher's stages, one method each, in the order `mesh_fast` runs
//! them: choose each face's variant, sew the outlines, first meshes, refine,
//! mend, improve, close the gaps, measure the faces, assemble, measure the
//! model. A [`Plan`] holds what every stage
//! reads (the model, the limits, paper 001's rebuilds); a [`Run`] what they
//! write (the report, the tessellated faces sewing cuts). The criterion
//! benches time the same stages (`surfmesh::pipeline`, hidden from the docs;
//! not a stable API).

use alloc::vec::Vec;

#[cfg(feature = "std")]
use super::fill;
use super::refine::{Known, WorkMesh};
use super::sew::{self, FaceWork, Places};
use super::variant::Chosen;
use super::{
    collapse, empty_work, own_bodies, reparameterize, setup, sewing_scales, tessellated, unify_outlines, Setup,
};
use super::{face, params, refine};
use crate::mesh::{edge_census, holes_warning, FaceRange};
use crate::model::{body_count, share_of_faces};
use crate::options::MeshOptions;
use crate::reparam::Rebuilt;
use crate::report::{MeshResult, Report};
use crate::warning::{Warning, WarningKind};
use crate::{Error, Mesh, Model, TrimLoop};

/// What every stage reads: the model, the options and the limits they come
/// to, the faces paper 001 rebuilt, and the distances sewing works within.
pub struct Plan<'m> {
    pub(super) model: &'m Model,
    pub(super) options: &'m MeshOptions,
    /// Which faces this share meshes (all without `options.share`).
    pub(super) mine: Vec<bool>,
    /// Absolute chordal tolerance.
    pub(super) tol: f64,
    /// Limits of the grid and loop discretization.
    pub(super) lim: params::Limits,
    /// Limits every triangle must meet after refinement.
    pub(super) crit: refine::Criteria,
    /// Per face, its rebuild (paper 001), if it has one.
    pub(super) rebuilt: Vec<Option<Rebuilt>>,
    /// Per face, its domain's border (untrimmed faces are meshed as trimmed
    /// by it, so that their borders are sewn like trim loops), and its rebuild's.
    pub(super) domain_loops: Vec<Vec<TrimLoop>>,
    pub(super) rebuilt_domain_loops: Vec<Vec<TrimLoop>>,
    /// Within one face (a seam) borders meet within a rounding, or the
    /// file's own modelling tolerance.
    pub(super) auto_tight: f64,
    /// Borders of different faces closer than this are sewn.
    sew_tol: f64,
    /// Borders within one face closer than this are sewn.
    tight: f64,
    /// Each face's body for sewing and the edge counts ([`own_bodies`]).
    body_ids: Vec<u32>,
    /// Per face, the factor its body takes of `sew_tol`, `tight` and the
    /// weld (1 but for bodies far smaller than the tolerance: `sewing_scales`);
    /// empty where all are 1.
    sew_scale: Vec<f64>,
    /// The report as the stages start it (reparameterized faces listed).
    report: Report,
}

/// What the stages write: the report, and the tessellated faces that sewing cuts.
pub struct Run<'m> {
    report: Report,
    facets: tessellated::Facets<'m>,
    /// The first face that could not be meshed: the model's error when no face meshes.
    first_failure: Option<Error>,
    /// Sum and count of the deviation samples measured.
    deviation: (f64, u64),
    /// Tessellated triangles left out as unusable.
    dropped: usize,
}

/// Stage 1's output: each face's variant with its outline (`None`: not meshed).
pub struct Variants<'p> {
    faces: Vec<Option<Chosen<'p>>>,
}

/// Stage 2's output: the variants with their outlines sewn, and how many
/// model nodes sewing named.
pub struct Sewn<'p> {
    faces: Vec<Option<Chosen<'p>>>,
    ids: u32,
}

/// The faces' meshes from stage 3 on, with what later stages need of their variants.
pub struct Works<'p> {
    faces: Vec<FaceWork<'p>>,
    fit_errors: Vec<f64>,
    pinched: Vec<bool>,
    ids: u32,
    /// Whether refinement stopped at the triangle budget.
    budget_hit: bool,
}

/// Stage 4's output for stage 5: where each shared node's faces put it.
pub struct Refined {
    places: Places,
}

impl Variants<'_> {
    /// Loop nodes of every outline (0 without `std`, where there are none).
    pub fn loop_nodes(&self) -> usize {
        #[cfg(feature = "std")]
        {
            let nodes = |c: &Chosen<'_>| c.outline.loops.polys.iter().map(|p| p.uv.len()).sum::<usize>();
            self.faces.iter().flatten().map(nodes).sum()
        }
        #[cfg(not(feature = "std"))]
        0
    }

    /// Grid lines `[along u, along v]` summed over the outlines.
    pub fn grid_lines(&self) -> [usize; 2] {
        #[cfg(feature = "std")]
        {
            let mut n = [0, 0];
            for c in self.faces.iter().flatten() {
                n[0] += c.outline.pu.len();
                n[1] += c.outline.pv.len();
            }
            n
        }
        #[cfg(not(feature = "std"))]
        [0, 0]
    }
}

impl Sewn<'_> {
    /// Model node ids sewing named (the loops' nodes, shared ones once, and
    /// those halving crossing chords added).
    pub fn ids(&self) -> u32 {
        self.ids
    }
}

impl Works<'_> {
    /// Debug builds: every face's work mesh keeps its invariants
    /// ([`WorkMesh::check_invariants`]) after `stage`, but for the breaks
    /// `known` to that stage; another is the mesher's bug, named with its
    /// face and stage.
    fn check(&self, stage: &str, known: Known) {
        #[cfg(debug_assertions)]
        for (i, w) in self.faces.iter().enumerate() {
            if let Err(e) = w.mesh.check_invariants_on(w.surface, known) {
                debug_assert!(false, "face {i} after {stage}: {e}");
            }
        }
        let _ = (stage, known);
    }

    /// Triangles over all faces.
    pub fn triangles(&self) -> usize {
        self.faces.iter().map(|w| w.mesh.tris.len()).sum()
    }

    /// Debugging aid: the (u,v) corners of every triangle of face `index`,
    /// each with whether it is inverted against the surface.
    pub fn uv_triangles(&self, index: usize) -> Vec<([glam::DVec2; 3], bool)> {
        let Some(w) = self.faces.get(index) else { return Vec::new() };
        (0..w.mesh.tris.len()).map(|t| (w.mesh.uv(t), w.mesh.inverted(w.surface, t))).collect()
    }
}

impl<'m> Plan<'m> {
    /// The plan for meshing `model` within `options` (its share of the
    /// bodies, with `options.share`): validated options, the tolerance and
    /// limits, and the faces paper 001 rebuilds.
    ///
    /// # Errors
    /// Invalid options, an empty model or one of no size.
    pub fn new(model: &'m Model, options: &'m MeshOptions) -> Result<Self, Error> {
        Self::with_share(model, options, faces_of_share(model, options))
    }

    /// As [`Plan::new`], for the faces `mine` (indexed by model face).
    pub(super) fn with_share(model: &'m Model, options: &'m MeshOptions, mine: Vec<bool>) -> Result<Self, Error> {
        let Setup { tol, diag, boxes, lim, crit } = setup(model, options)?;
        let mut report = Report {
            units: model.units.clone(),
            tolerance: tol,
            angle: options.angle,
            faces: model.face_count(),
            faces_unread: model.skipped.len(),
            bodies: body_count(model),
            ..Report::default()
        };
        report.warnings.extend(model.warnings.iter().cloned());
        // Paper 001: faces whose parameters crowd are rebuilt on even ones first.
        let rebuilt = reparameterize(model, &mine, options.reparam, tol, &mut report);
        let domain_loops = model.faces.iter().map(face::domain_loops).collect();
        let rebuilt_domain_loops =
            rebuilt.iter().map(|r| r.as_ref().map_or_else(Vec::new, |r| face::domain_loops(&r.face))).collect();
        let auto_tight = {
            let auto = (0.5 * tol).min(1e-4 * diag.max(tol));
            model.tolerance.filter(|t| t.is_finite() && *t > 0.0).map_or(auto, |t| auto.max(t.min(0.5 * tol)))
        };
        // Borders of different faces are sewn as far apart as the model's
        // gaps need, up to 0.4 of the tolerance: each side then moves by half
        // the gap, within what the 0.8 safety leaves of the tolerance. A
        // sewing distance the caller sets holds for seams too.
        let (sew_tol, tight) = match options.sew {
            Some(s) => (s, auto_tight.min(s)),
            None => (0.4 * tol, auto_tight),
        };
        // Closed as built (a sphere, a torus, a ring's closed quarter): its
        // seams and poles meet to a rounding. A side that shrinks to a small
        // circle within the sewing distance is a border that another face can
        // close, not a pole.
        let body_ids = own_bodies(model, &mine, 1e-9 * diag.max(tol));
        // A sewing distance the caller sets holds for every body; none kept
        // where every body is at the model's scale (most models).
        let mut sew_scale =
            if options.sew.is_some() { Vec::new() } else { sewing_scales(&boxes, &body_ids, tol, diag) };
        if sew_scale.iter().all(|&k| k == 1.0) {
            sew_scale = Vec::new();
        }
        drop(boxes);
        Ok(Self {
            model,
            options,
            mine,
            tol,
            lim,
            crit,
            rebuilt,
            domain_loops,
            rebuilt_domain_loops,
            auto_tight,
            sew_tol,
            tight,
            body_ids,
            sew_scale,
            report,
        })
    }

    /// A run of the stages: the report as they start it, the tessellated faces uncut.
    pub fn start(&self) -> Run<'m> {
        Run {
            report: self.report.clone(),
            facets: tessellated::Facets::new(self.model, &self.mine),
            first_failure: None,
            deviation: (0.0, 0),
            dropped: 0,
        }
    }

    /// Stage 1, each face's variant (paper 001: the original or its rebuild,
    /// see [`Plan::choose_face`]) and its outline: the loops discretized by
    /// the chord test and the grid inside them (paper 000 §1–§3, §5). One
    /// face that cannot be meshed is skipped with a warning.
    ///
    /// # Errors
    /// A face that cannot be meshed in a model of one face, or any error
    /// other than a face's.
    pub fn choose_variants<'p>(&'p self, run: &mut Run<'m>) -> Result<Variants<'p>, Error> {
        let mut faces = Vec::with_capacity(self.model.faces.len());
        for index in 0..self.model.faces.len() {
            let chosen = match self.choose_face(index, &mut run.report) {
                Ok(c) => c,
                // One face that cannot be meshed does not sink the others; a
                // model where none can is the first face's error.
                Err(Error::Mesh { face, message }) if self.model.faces.len() > 1 => {
                    run.report.faces_skipped += 1;
                    run.report.warnings.push(Warning::face(index, WarningKind::FaceSkipped(message.clone())));
                    run.first_failure.get_or_insert(Error::Mesh { face, message });
                    None
                }
                Err(e) => return Err(e),
            };
            faces.push(chosen);
        }
        Ok(Variants { faces })
    }

    /// Stage 2, paper 000 §6: shared borders get the same nodes before
    /// anything is triangulated ([`sew::unify`]), after the tessellated
    /// faces' border vertices are pinned on them.
    pub fn sew_outlines<'p>(&self, run: &Run<'m>, variants: Variants<'p>) -> Sewn<'p> {
        let Variants { mut faces } = variants;
        let (bodies, scales) = (&self.body_ids, &self.sew_scale);
        let ids = unify_outlines(&mut faces, bodies, scales, &run.facets, self.sew_tol, self.tight, self.crit.tol);
        Sewn { faces, ids }
    }

    /// Stage 3, paper 000 §4–§5: every face's first mesh on the sewn nodes,
    /// the grid inside and the CDT band along its loops; each outline is
    /// freed once its mesh is built. Then the borders along tessellated
    /// faces take their vertices.
    ///
    /// # Errors
    /// As stage 1, and the first face's error when no face has a mesh.
    pub fn first_meshes<'p>(&'p self, run: &mut Run<'m>, sewn: Sewn<'p>) -> Result<Works<'p>, Error> {
        let n = self.model.faces.len();
        let mut works = Works {
            faces: Vec::with_capacity(n),
            fit_errors: Vec::with_capacity(n),
            pinched: Vec::with_capacity(n),
            ids: sewn.ids,
            budget_hit: false,
        };
        let mut used = 0usize;
        for (index, c) in sewn.faces.into_iter().enumerate() {
            let f = &self.model.faces[index];
            works.pinched.push(c.as_ref().is_some_and(Chosen::pinched));
            let Some(mut c) = c else {
                works.faces.push(empty_work(f, self.crit));
                works.fit_errors.push(0.0);
                continue;
            };
            let budget = self.options.max_triangles.saturating_sub(used);
            let why = match c.initial(index, budget) {
                Ok((mut mesh, curves)) => {
                    used += mesh.tris.len();
                    mesh.rest();
                    works.faces.push(FaceWork { surface: &c.face.surface, curves, mesh, crit: c.crit });
                    works.fit_errors.push(c.fit_error);
                    continue;
                }
                Err(Error::Mesh { face, message }) if n > 1 => {
                    let why = WarningKind::FaceSkipped(message.clone());
                    run.first_failure.get_or_insert(Error::Mesh { face, message });
                    why
                }
                Err(Error::Limit(m)) if n > 1 && budget < self.options.max_triangles => WarningKind::BudgetSpent(m),
                Err(e) => return Err(e),
            };
            run.report.faces_skipped += 1;
            run.report.warnings.push(Warning::face(index, why));
            works.faces.push(empty_work(f, self.crit));
            works.fit_errors.push(0.0);
        }
        if let Some(e) = run.first_failure.take().filter(|_| works.faces.iter().all(|w| w.mesh.tris.is_empty())) {
            return Err(e);
        }
        works.check("first meshes", Known::SEWN);
        tessellated::snap_borders(&mut works.faces, &run.facets, &self.body_ids, self.sew_tol);
        works.check("snapping to tessellated borders", Known::SEWN);
        Ok(works)
    }

    /// Stage 4, beyond paper 000 §1–§3, whose chord tests only predict the
    /// deviation: every triangle is measured on the exact surface and split
    /// until it passes the limits (Rivara bisection). As §6 asks of a shared
    /// edge, a split of a shared border edge is made on every side; then
    /// every model node takes one position. `progress(done, total)` is
    /// called as faces finish.
    ///
    /// # Errors
    /// [`Error::Cancelled`] when `progress` says so.
    pub fn refine(
        &self,
        works: &mut Works<'_>,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<Refined, Error> {
        let sew = |f: usize| self.sew_tol * self.scale_of(f);
        works.budget_hit = sew::refine_all(&mut works.faces, works.ids, &sew, self.options.max_triangles, progress)?;
        for w in works.faces.iter_mut() {
            w.mesh.carried = Default::default();
        }
        let (settled, places) = sew::settle_nodes(&mut works.faces, 1e-6 * self.tol);
        works.check("refinement", Known::SEWN);
        for (w, moved) in works.faces.iter_mut().zip(&settled) {
            w.mesh.forget(moved);
        }
        works.check("settling the nodes", Known::SEWN);
        Ok(Refined { places })
    }

    /// Stage 5, beyond paper 000 (its §4 grid triangles cannot fold,
    /// refined ones can): refinement may leave a thin triangle folded next
    /// to a border node it cannot move: unfold by interior edge flips or by
    /// moving an inner vertex, which leaves the shared borders as they are.
    /// What is still folded may unfold with a node at another face's place
    /// for it, and then by flips.
    pub fn mend(&self, works: &mut Works<'_>, refined: Refined) {
        let mut folded: Vec<Vec<u32>> = Vec::with_capacity(works.faces.len());
        for w in works.faces.iter_mut() {
            let (changed, left) = w.mesh.repair_inverted(w.surface, &w.crit);
            w.mesh.forget(&changed);
            w.mesh.rest();
            folded.push(left);
        }
        if folded.iter().any(|f| !f.is_empty()) {
            let moved = sew::resettle_folds(&mut works.faces, &refined.places, &folded);
            for (w, moved) in works.faces.iter_mut().zip(&moved) {
                if !moved.is_empty() {
                    w.mesh.forget(moved);
                    let (changed, _) = w.mesh.repair_inverted(w.surface, &w.crit);
                    w.mesh.forget(&changed);
                    w.mesh.rest();
                }
            }
        }
        works.check("mending", Known::MENDED);
    }

    /// Stage 6, paper 000's uniform, well-shaped triangles kept after
    /// refinement (its §4 splits each quad along its shorter diagonal):
    /// interior edges flipped where that lifts a small angle (never to an
    /// edge between border nodes a face already joins) and, with `std`, a
    /// rebuild kept for its shape (paper 001) has its needles lifted by
    /// Delaunay refinement in space.
    pub fn improve(&self, works: &mut Works<'_>) {
        let mut taken = crate::collections::HashSet::default();
        for w in &works.faces {
            w.mesh.border_node_edges(&mut taken);
        }
        for w in works.faces.iter_mut() {
            let changed = w.mesh.improve_angles(w.surface, &w.crit, &mut taken);
            w.mesh.forget(&changed);
            #[cfg(feature = "std")]
            {
                let lifted = w.mesh.lift_angles(w.surface, &w.crit);
                w.mesh.forget(&lifted);
            }
            w.mesh.rest();
        }
        #[cfg(feature = "std")]
        super::touching::part_touching(&mut works.faces, self.weld());
        works.check("improving", Known::MENDED);
    }

    /// Stage 7, paper 000 §6's vertex-to-vertex joins where sewing left a
    /// gap: three faces' corners that missed each other leave a sliver
    /// between them, closed by a triangle (with `std`); the tessellated
    /// faces take the exact borders' nodes along theirs.
    pub fn close_gaps(&self, run: &mut Run<'m>, works: &mut Works<'_>) {
        #[cfg(feature = "std")]
        fill::close_slivers(&mut works.faces, self.tol);
        for w in works.faces.iter_mut() {
            w.mesh.rest();
        }
        works.check("closing slivers", Known::MENDED);
        tessellated::split_rims(&mut works.faces, &mut run.facets, &self.body_ids, self.sew_tol);
        works.check("splitting tessellated rims", Known::MENDED);
    }

    /// Stage 8, the verification paper 000 leaves to its chord test: each
    /// face's triangles measured against its exact surface (deviation,
    /// normal turn; folds are counted once assembly's collapses are made),
    /// with a warning for a face left empty and for triangles still over
    /// the limits.
    pub fn measure_faces(&self, run: &mut Run<'m>, works: &mut Works<'_>) {
        let report = &mut run.report;
        for (index, (w, fit_error)) in works.faces.iter_mut().zip(&works.fit_errors).enumerate() {
            let out = w.mesh.outcome(w.surface, &w.crit);
            // Reported against the original face: the mesh's distance to the new one plus the fit error.
            if !w.mesh.tris.is_empty() {
                report.max_deviation = report.max_deviation.max(out.max + fit_error);
            }
            run.deviation.0 += out.sum;
            run.deviation.1 += out.count;
            report.max_normal_turn = report.max_normal_turn.max(out.max_turn);
            if w.mesh.tris.is_empty() {
                if self.mine[index] && !report.warnings.iter().any(|x| x.face == Some(index)) {
                    report.faces_skipped += 1;
                    let pinched = works.pinched[index];
                    report.warnings.push(Warning::face(index, WarningKind::NoTriangles { pinched }));
                }
            } else if out.unproven > 0 {
                let kind = WarningKind::Unproven { count: out.unproven, budget: works.budget_hit };
                report.warnings.push(Warning::face(index, kind));
            }
            if out.creased > 0 {
                report.warnings.push(Warning::face(index, WarningKind::Creased { count: out.creased }));
            }
        }
    }

    /// The distance within which the edge census takes two points for one
    /// (of a body at the model's sewing scale).
    fn weld(&self) -> f64 {
        (self.tol * 1e-3).min(self.tight * 0.5)
    }

    /// Face `f`'s sewing scale (`sewing_scales`; 1 past the end).
    pub(super) fn scale_of(&self, f: usize) -> f64 {
        self.sew_scale.get(f).copied().unwrap_or(1.0)
    }

    /// Stage 9, paper 000 §4's last step (the triangles in model space, one
    /// mesh for all faces): each face's working state freed as soon as it is
    /// copied, the mesh growing by what each face adds: presized in
    /// full, it sat next to every face's full working state (wasm memory
    /// never shrinks, so the peak is what a page keeps). Flaps (two
    /// triangles on one corner set, facing apart) go, an edge whose two
    /// ends sewing put on one point is collapsed, and the triangles left that
    /// fold against the surface are counted; the tessellated faces follow.
    pub fn assemble(&self, run: &mut Run<'m>, works: Works<'_>) -> Mesh {
        let mut mesh = Mesh { face_ranges: Vec::with_capacity(works.faces.len()), ..Mesh::default() };
        let mut shift: f64 = 0.0;
        for (index, mut w) in works.faces.into_iter().enumerate() {
            let weld = self.weld() * self.scale_of(index);
            let mut wm = core::mem::take(&mut w.mesh);
            // Folds are counted on the triangles the mesh keeps (a collapse
            // takes away folded slivers), each judged against the normal at
            // its (u,v) centroid as refined (or, across a fold of the
            // surface, the corner normal it lies along: `judged_normal`): a
            // collapse moves a corner by a hundredth of the tolerance at
            // most, and never turns a facet over or against that normal.
            let mut normals: Vec<glam::DVec3> = (0..wm.tris.len()).map(|t| wm.judged_normal(w.surface, t)).collect();
            collapse::drop_flaps(&mut wm.tris, &mut normals);
            collapse::collapse_point_edges(&wm.pos, &mut wm.tris, &mut normals);
            shift = shift.max(collapse::collapse_short_inner_edges(&wm.pos, &wm.gid, &mut wm.tris, weld, &mut normals));
            shift = shift.max(collapse::drop_welded_flaps(&wm.pos, &mut wm.tris, weld, &mut normals));
            run.report.inverted_triangles += refine::count_folded(&wm.pos, &wm.tris, &normals, weld, 1e-6 * self.tol);
            append_face(&mut mesh, &wm);
        }
        // The faces were measured before: a collapse moves a triangle's
        // points by at most `shift`, so the promise holds with it added.
        if shift > 0.0 {
            run.report.max_deviation += shift;
        }
        run.dropped = run.facets.append_to(&mut mesh);
        // The room the last growth left, given back before the mesh is measured.
        mesh.positions.shrink_to_fit();
        mesh.normals.shrink_to_fit();
        mesh.indices.shrink_to_fit();
        mesh
    }

    /// Stage 10, paper 000 §6's promise checked: the model's mesh measured
    /// as a whole, the edge census after welding (cracks, with a warning
    /// where a crack is the file's own gap; a three-sided hole between
    /// faces closed first where its short side's ends can join), angles,
    /// and what the report says of the tessellated faces.
    pub fn measure(&self, run: Run<'m>, mut mesh: Mesh) -> MeshResult {
        let Run { mut report, deviation: (dev_sum, dev_count), dropped, .. } = run;
        let tol = self.tol;
        report.mean_deviation = if dev_count > 0 { dev_sum / dev_count as f64 } else { 0.0 };
        report.triangles = mesh.triangle_count();
        report.vertices = mesh.positions.len();
        let weld = self.weld();
        let (mut edges, mut gaps) = edge_census(&mesh, &self.body_ids, &self.sew_scale, &self.model.skipped, weld, tol);
        // Three-sided holes no face took a triangle for: a short side's ends
        // joined, within what the tolerance leaves above the deviation (only
        // where the census found cracks: the pass holds the whole mesh's
        // points once more).
        if edges.free_edges > edges.hole_edges {
            let body_of = |f: u32| crate::model::body_of(&self.body_ids, f as usize);
            let room = tol - report.max_deviation;
            let scale = |f: u32| self.scale_of(f as usize);
            let moved = super::holes::close_short_holes(&mut mesh, &body_of, &scale, weld, self.sew_tol, room);
            if moved > 0.0 {
                report.max_deviation += moved;
                report.triangles = mesh.triangle_count();
                (edges, gaps) = edge_census(&mesh, &self.body_ids, &self.sew_scale, &self.model.skipped, weld, tol);
            }
        }
        holes_warning(&self.model.skipped, edges.hole_edges, &mut report.warnings);
        // A crack wider than sewing reaches is the file's own gap: say where.
        for g in gaps.iter() {
            let sewing = self.sew_tol * self.scale_of(g.faces.0 as usize);
            if g.width <= sewing {
                continue;
            }
            let kind =
                WarningKind::FacesApart { faces: (g.faces.0 as usize, g.faces.1 as usize), width: g.width, sewing };
            report.warnings.push(Warning::new(kind));
        }
        report.take_edges_and_angles(&edges, &mesh);
        tessellated::finish_report(self.model, &self.mine, &mesh, dropped, &mut report);
        MeshResult { mesh, report }
    }
}

/// Which faces of `model` the share in `options` meshes (all without one).
pub(super) fn faces_of_share(model: &Model, options: &MeshOptions) -> Vec<bool> {
    match options.share {
        Some((index, count)) => share_of_faces(&model.bodies, model.face_count(), index, count),
        None => alloc::vec![true; model.face_count()],
    }
}

/// Appends one face's mesh `wm` to `mesh` as its next face range.
/// Vertices no triangle kept (a removed flap's corner, a collapsed sliver's)
/// are left out: a stray point would still widen the bounding box a viewer
/// fits its camera to.
fn append_face(mesh: &mut Mesh, wm: &WorkMesh) {
    let first = mesh.triangle_count() as u32;
    let base = mesh.positions.len() as u32;
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

/// Makes room for `extra` more elements, growing by an eighth: the model's
/// mesh grows face by face as the faces' working state is freed, and the
/// slack of doubling would be up to half of it.
fn grow<T>(v: &mut Vec<T>, extra: usize) {
    if v.capacity() - v.len() < extra {
        v.reserve_exact(v.len() / 8 + extra);
    }
}

/// Steps trim-loop mending has taken on this thread (segment pairs tested
/// for crossings, pieces winding rays met): a measure of its work that does
/// not depend on the machine, for tests; 0 without `std`.
pub fn mend_steps() -> u64 {
    #[cfg(feature = "std")]
    return super::mend_loops::steps();
    #[cfg(not(feature = "std"))]
    0
}

/// Nanoseconds the mesher has spent measuring deviation (every triangle's
/// samples projected on its surface) in this process, with the `timing`
/// feature; `None` without it.
pub fn measure_nanos() -> Option<u64> {
    #[cfg(feature = "timing")]
    return Some(super::measure::MEASURE_NANOS.load(core::sync::atomic::Ordering::Relaxed));
    #[cfg(not(feature = "timing"))]
    None
}
