//! Each face's variant: the original, or paper 001's rebuild where it pays,
//! with the limits it is meshed within and (with `std`) its outline, the
//! loops discretized and the grid inside them (paper 000 §1–§3, §5).

use alloc::vec::Vec;

#[cfg(feature = "std")]
use super::mend_loops;
use super::params::Samples;
use super::pipeline::Plan;
use super::trial::{beats_unrefined, lift_needles, outline_of, rebuild_loses, shorter_edges, tris_of, SHORTER_TRIES};
use super::{face, face_loops, params, refine};
use crate::options::Reparam;
use crate::report::Report;
use crate::warning::{Warning, WarningKind};
use crate::{Error, Face};

/// A face as it will be meshed: the variant chosen (the original or paper
/// 001's rebuild), its limits and, with `std`, its outline to sew.
pub(crate) struct Chosen<'a> {
    pub face: &'a Face,
    #[cfg(feature = "std")]
    pub outline: face::Outline<'a>,
    pub fit_error: f64,
    /// What the trial mesh of this variant measured, within these criteria.
    carried: refine::Carried,
    /// The grid's limits (with `std` they went into the outline).
    #[cfg(not(feature = "std"))]
    lim: params::Limits,
    pub crit: refine::Criteria,
}

/// A trial mesh of one face, or why it could not be made.
type TrialMesh<'a> = Result<face::FaceResult<'a>, Error>;

/// Outlines the trials made, each with its face and grid limits: the one of
/// the variant chosen is not made again.
type Made<'a> = Vec<(&'a Face, params::Limits, face::Outline<'a>)>;

/// One face's variant before its outline is made: the face, what its fit
/// took from the tolerance, and its limits.
struct Variant<'a> {
    face: &'a Face,
    fit_error: f64,
    lim: params::Limits,
    crit: refine::Criteria,
}

impl<'a> Chosen<'a> {
    /// `loops`: the face's own, or its domain's border when it has none;
    /// `ready`: its outline for `lim` when a trial already made it, else
    /// made with the grid samples its trials kept.
    fn new(
        index: usize,
        (face, loops, samples): (&'a Face, &'a [crate::TrimLoop], &params::Samples),
        (lim, crit): (params::Limits, refine::Criteria),
        (fit_error, carried): (f64, refine::Carried),
        ready: Option<face::Outline<'a>>,
    ) -> Result<Self, Error> {
        #[cfg(feature = "std")]
        let outline = match ready {
            Some(o) => o,
            None => face::outline(index, (&face.surface, samples), loops, face.loops.is_empty(), &lim, usize::MAX)?,
        };
        #[cfg(not(feature = "std"))]
        let _ = (index, loops, ready, samples);
        Ok(Self {
            face,
            #[cfg(feature = "std")]
            outline,
            fit_error,
            carried,
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
    fn mended(&self) -> Option<crate::warning::Mended> {
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
    pub fn pinched(&self) -> bool {
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

    /// The face's mesh before refinement, and the curves its trim edges
    /// follow; the mesh carries what its trial measured.
    pub fn initial(
        &mut self,
        index: usize,
        budget: usize,
    ) -> Result<(refine::WorkMesh, Vec<&'a crate::NurbsCurve>), Error> {
        #[cfg(feature = "std")]
        let (mut wm, curves) = (
            face::initial_from_outline(index, &self.face.surface, &self.outline, budget)?,
            self.outline.loops.curves.clone(),
        );
        #[cfg(not(feature = "std"))]
        let (mut wm, curves) = face::initial_face(index, self.face, &self.lim, budget)?;
        wm.carried = core::mem::take(&mut self.carried);
        Ok((wm, curves))
    }
}

impl<'m> Plan<'m> {
    /// Face `index`'s variant and outline, or `None` when it is not meshed
    /// (not in the share, or trimmed in a build without the CDT); a face
    /// that cannot be meshed is an error, which the caller may turn into a
    /// skipped face.
    pub(super) fn choose_face<'p>(&'p self, index: usize, report: &mut Report) -> Result<Option<Chosen<'p>>, Error> {
        let original = &self.model.faces[index];
        if !self.mine[index] {
            return Ok(None);
        }
        let mut v = match self.rebuilt.get(index) {
            Some(Some(r)) => {
                // A rebuilt face is meshed within what its fit error leaves of the tolerance.
                let share = ((self.tol - r.fit_error) / self.tol).clamp(0.5, 1.0);
                Variant {
                    face: &r.face,
                    fit_error: r.fit_error,
                    lim: params::Limits {
                        tol: self.lim.tol * share,
                        max_edge: self.lim.max_edge.min(r.max_edge),
                        ..self.lim
                    },
                    crit: refine::Criteria {
                        tol: self.crit.tol * share,
                        max_edge: self.crit.max_edge.min(r.max_edge),
                        ..self.crit
                    },
                }
            }
            _ => Variant { face: original, fit_error: 0.0, lim: self.lim, crit: self.crit },
        };
        if !super::face_is_supported(v.face) {
            report.faces_skipped += 1;
            report.warnings.push(Warning::face(index, WarningKind::NeedsStd));
            return Ok(None);
        }
        let mut made: Made<'p> = Vec::new();
        let mut carried = refine::Carried::default();
        // Grid samples of the original's surface and of the rebuild's, each
        // shared by its trials.
        let samples = Samples::default();
        let rebuild_samples = Samples::default();
        if v.fit_error > 0.0 {
            let cap = self.rebuilt.get(index).and_then(Option::as_ref).map_or(f64::INFINITY, |r| r.max_edge);
            let kept = (&mut made, &mut carried);
            self.judge_rebuild(index, (cap, [&samples, &rebuild_samples]), &mut v, kept, report);
        }
        let loops = self.loops_of(index, v.face);
        let ready =
            made.into_iter().find(|(g, l, _)| core::ptr::eq(*g, v.face) && l.same_as(&v.lim)).map(|(_, _, o)| o);
        let kept = if core::ptr::eq(v.face, original) { &samples } else { &rebuild_samples };
        let c = Chosen::new(index, (v.face, loops, kept), (v.lim, v.crit), (v.fit_error, carried), ready)?;
        if let Some(m) = c.mended() {
            report.warnings.push(Warning::face(index, WarningKind::LoopsMended(m)));
        }
        if let Some(along) = c.capped_grid() {
            let kind = WarningKind::GridCapped { along, cap: params::MAX_PARAMS };
            report.warnings.push(Warning::face(index, kind));
        }
        Ok(Some(c))
    }

    /// The loops face `g` (face `index` or its rebuild) is meshed by.
    fn loops_of<'p>(&'p self, index: usize, g: &'p Face) -> &'p [crate::TrimLoop] {
        let new = self.rebuilt_domain_loops.get(index).map_or(&[][..], |l| &l[..]);
        face_loops(g, &self.model.faces[index], &self.domain_loops[index], new)
    }

    /// Paper 001's rebuild is kept where it pays: under `auto` the original
    /// is meshed too and wins on more triangles or worse angles (and it wins
    /// whenever the rebuild fails to mesh). The original's first mesh goes
    /// first, so the rebuild's trial stops as soon as it takes more
    /// triangles than that (a creased face's rebuild can take 100×); a
    /// rebuild that beats that mesh ([`trial::beats_unrefined`]) is kept
    /// without refining the original, which refinement only makes larger.
    /// Otherwise the original is refined and judged as a whole, the
    /// rebuild's trial made again within the original's full count where
    /// that count ran past the first mesh's. `v` becomes the variant kept;
    /// `made` collects the outlines the trials made, and `carried` what the
    /// trial of the variant kept measured, when it was meshed within its
    /// final criteria.
    fn judge_rebuild<'p>(
        &'p self,
        index: usize,
        (cap, [orig_samples, samples]): (f64, [&Samples; 2]),
        v: &mut Variant<'p>,
        (made, carried): (&mut Made<'p>, &mut refine::Carried),
        report: &mut Report,
    ) {
        let measured =
            |r: &TrialMesh<'_>| r.as_ref().map_or_else(|_| refine::Carried::default(), |r| r.mesh.measured());
        let original = &self.model.faces[index];
        let (f, tight) = (v.face, self.auto_tight * self.scale_of(index));
        let budget = self.options.max_triangles;
        let auto = self.options.reparam == Reparam::Auto;
        let orig_loops = self.loops_of(index, original);
        let start_original = || face::start_face(index, (original, orig_loops), &self.lim, budget, tight, orig_samples);
        let started = auto.then(start_original);
        // Refinement only splits: the original's first mesh is a floor under its count.
        let floor = match &started {
            Some(Ok(s)) => Some(s.mesh.tris.len()),
            _ => None,
        };
        let within = |n: usize| budget.min(n.saturating_add(1));
        let trial = floor.map_or(budget, within);
        let f_loops = self.loops_of(index, f);
        let mesh_rebuild = |trial: usize| face::mesh_face(index, (f, f_loops), &v.lim, &v.crit, trial, tight, samples);
        let mut fr = mesh_rebuild(trial);
        let failed = !matches!(&fr, Ok(r) if !r.mesh.tris.is_empty());
        let cheap_win = matches!((&fr, &started), (Ok(r), Some(Ok(s))) if beats_unrefined(r, &s.mesh));
        if cheap_win || !(failed || auto) {
            *carried = measured(&fr);
            made.extend(outline_of(&mut fr).map(|o| (f, v.lim, o)));
            return;
        }
        let mut orig = started.unwrap_or_else(start_original).map(|s| s.finish(&original.surface, &self.crit, budget));
        // The rebuild's trial ran within the floor; the original's own count
        // is the budget it is judged within.
        let full = within(tris_of(&orig));
        if auto && full != trial && (failed || tris_of(&fr) >= trial) {
            fr = mesh_rebuild(full);
        }
        let trial = if auto { full } else { trial };
        let mut why = rebuild_loses(&fr, &orig);
        if why.is_none() {
            *carried = measured(&fr);
        }
        made.extend(outline_of(&mut fr).map(|o| (f, v.lim, o)));
        if why.is_some() && auto {
            let capped = (fr, v.lim, v.crit);
            if let Some((l, c)) = self.rescue(index, (f, f_loops, samples), &capped, &orig, (cap, trial), made) {
                (why, v.lim, v.crit) = (None, l, c);
            }
        }
        if let Some(why) = why {
            report.warnings.push(Warning::face(index, WarningKind::RebuildLost(why)));
            if let Some(r) = report.reparameterized.iter_mut().find(|r| r.face == index) {
                r.rebuilt = false;
            }
            *v = Variant { face: original, fit_error: 0.0, lim: self.lim, crit: self.crit };
            *carried = measured(&orig);
            made.extend(outline_of(&mut orig).map(|o| (original, self.lim, o)));
        }
    }

    /// Beyond paper 001: how a rebuild that loses to the original `orig`
    /// may still win. The edge cap (`cap`, set by the sharpest bend) is
    /// dropped where that bend is local; then shorter edges, starting from
    /// the capped mesh (the free one where it failed) at half its longest
    /// edge, then from the lighter of the two one step nearer its longest
    /// edge; then needles lifted. The limits it wins with, if any.
    fn rescue<'p>(
        &'p self,
        index: usize,
        (f, f_loops, samples): (&'p Face, &'p [crate::TrimLoop], &Samples),
        capped: &(TrialMesh<'p>, params::Limits, refine::Criteria),
        orig: &TrialMesh<'p>,
        (cap, trial): (f64, usize),
        made: &mut Made<'p>,
    ) -> Option<(params::Limits, refine::Criteria)> {
        let tight = self.auto_tight * self.scale_of(index);
        let mut free_run = None;
        if cap.is_finite() {
            let l = params::Limits { max_edge: self.lim.max_edge, ..capped.1 };
            let c = refine::Criteria { max_edge: self.crit.max_edge, ..capped.2 };
            let mut free = face::mesh_face(index, (f, f_loops), &l, &c, trial, tight, samples);
            made.extend(outline_of(&mut free).map(|o| (f, l, o)));
            if rebuild_loses(&free, orig).is_none() {
                return Some((l, c));
            }
            free_run = Some((free, l, c));
        }
        // The lighter of the capped and the free mesh.
        let lighter = match &free_run {
            Some(free) if tris_of(&free.0) < tris_of(&capped.0) => free,
            _ => capped,
        };
        let first = match (&capped.0, &free_run) {
            (Err(_), Some(free)) => free,
            _ => capped,
        };
        // When the two starts are the same mesh, all but the second's first
        // try repeat the tries that already failed.
        let again = if core::ptr::eq(first, lighter) { 1 } else { SHORTER_TRIES };
        let starts = [(first, 0.5, SHORTER_TRIES), (lighter, core::f64::consts::FRAC_1_SQRT_2, again)];
        for ((r, l, c), k, tries) in starts {
            let subject = (f, f_loops, samples);
            if let Some((l, c, o)) = shorter_edges(index, subject, r, orig, (l, c, k, tries), trial, tight) {
                made.extend(o.map(|o| (f, l, o)));
                return Some((l, c));
            }
        }
        let (_, l, _) = *lighter;
        let (c, o) = lift_needles(index, (f, f_loops, samples), lighter, orig, trial, tight)?;
        made.extend(o.map(|o| (f, l, o)));
        Some((l, c))
    }
}
