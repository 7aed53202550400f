//! One face: iso-parametric grid (paper 000 §3.1), trimmed band by CDT
//! (§3.2), then refinement until every triangle is proven within limits.

use crate::numeric::TINY;
use alloc::format;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::params::{even_demand, grid_params, Limits, Region, Samples, MAX_PARAMS};
use super::refine::{Criteria, Outcome, WorkMesh};
use crate::model::Face;
use crate::nurbs::Surface;
use crate::Error;

/// A meshed face: its work mesh and what refinement measured.
pub(crate) struct FaceResult<'a> {
    pub mesh: WorkMesh,
    pub outcome: Outcome,
    /// The outline before its own seams were sewn (with `std`): the same
    /// as the one `mesh_model` would make for this face and limits, so the
    /// variant chosen need not discretize its loops and grid again.
    pub outline: Option<Outline<'a>>,
}

/// Without `std` there is no outline (untrimmed faces mesh from their grid).
#[cfg(not(feature = "std"))]
pub(crate) struct Outline<'a>(core::marker::PhantomData<&'a ()>);

/// Grid parameters in both directions over `[lo, hi]`, sharing the tolerance
/// between the two directions: half each, then the whole remainder to one
/// direction when the other turned out (nearly) straight, as on a cylinder.
/// On a trimmed face, `loops` limits every test to the kept region.
///
/// `cells`: the most grid cells the caller accepts (`usize::MAX`: any). A
/// grid twice over it is cut short, since the caller refuses it anyway: on
/// a surface with even parameters the chord demand both directions sum to
/// is known before any line is placed, and a direction that reaches its
/// share of lines stops there. A grid that is not cut short is the one
/// without `cells`.
pub(super) fn grid(
    (surface, samples): (&dyn Surface, &Samples),
    lo: DVec2,
    hi: DVec2,
    lim: &Limits,
    loops: Option<&TrimRegion<'_>>,
    cells: usize,
) -> (Vec<f64>, Vec<f64>) {
    let kept = (surface, samples);
    #[cfg(feature = "std")]
    let pieces = |along_u: bool, s: f64| loops.map_or_else(Vec::new, |l| l.line_pieces(along_u, s));
    #[cfg(feature = "std")]
    let region: Option<Region<'_>> = if loops.is_some() { Some(&pieces) } else { None };
    #[cfg(not(feature = "std"))]
    let region: Option<Region<'_>> = None;
    let half = Limits { tol: lim.tol * 0.5, ..*lim };
    // Twice the cells accepted: what one direction's second pass saves
    // (at most √2 of the lines, with twice the tolerance) cannot bring the grid back.
    let over = cells.saturating_mul(2);
    let limited = over < MAX_PARAMS;
    let even = |along_u: bool| if limited { even_demand(kept, lo, hi, along_u, &half, region) } else { None };
    let (du, dv) = (even(true), even(false));
    if let (Some(du), Some(dv)) = (&du, &dv) {
        let n = |d: &[f64]| crate::math::ceil(d.iter().sum::<f64>());
        if n(du) * n(dv) > over as f64 {
            let equal = |a: f64, b: f64, d: &[f64]| {
                let k = (n(d) as usize).clamp(1, MAX_PARAMS);
                (0..=k).map(|i| if i == k { b } else { a + (b - a) * i as f64 / k as f64 }).collect()
            };
            return (equal(lo.x, hi.x, du), equal(lo.y, hi.y, dv));
        }
    }
    // A direction that reaches `cap` lines ends the grid, the other left at
    // its two ends (or as it is): either way over `over` cells.
    let cap = |other: usize| if limited { over / other.saturating_sub(1).max(1) + 2 } else { MAX_PARAMS };
    let capped = |p: &[f64], c: usize| limited && p.len() >= c;
    let ends_v = alloc::vec![lo.y, hi.y];
    let (mut pu, mut su) = grid_params(kept, lo, hi, true, &half, region, cap(2), du);
    if capped(&pu, cap(2)) {
        return (pu, ends_v);
    }
    let (mut pv, mut sv) = grid_params(kept, lo, hi, false, &half, region, cap(pu.len()), dv);
    if capped(&pv, cap(pu.len())) {
        return (pu, pv);
    }
    if sv < 0.5 * half.tol && su > sv {
        let rest = Limits { tol: (lim.tol - sv).max(half.tol), ..*lim };
        (pu, su) = grid_params(kept, lo, hi, true, &rest, region, cap(pv.len()), None);
        if capped(&pu, cap(pv.len())) {
            return (pu, pv);
        }
    } else if su < 0.5 * half.tol && sv > su {
        let rest = Limits { tol: (lim.tol - su).max(half.tol), ..*lim };
        (pv, sv) = grid_params(kept, lo, hi, false, &rest, region, cap(pu.len()), None);
        if capped(&pv, cap(pu.len())) {
            return (pu, pv);
        }
    }
    // Where the iso-curves left most of the tolerance unused, a twist may use it.
    let room = lim.tol - su - sv;
    if room >= 0.5 * lim.tol {
        // 0.85: the twist estimate is exact only for bilinear cells.
        refine_twisted_cells(surface, &mut pu, &mut pv, 0.85 * room, loops);
    }
    (pu, pv)
}

/// The trim loops of a face, when it has any (without `std` no trimmed face is meshed).
#[cfg(feature = "std")]
pub(super) type TrimRegion<'a> = super::trim::Loops<'a>;
#[cfg(not(feature = "std"))]
pub(super) type TrimRegion<'a> = core::marker::PhantomData<&'a ()>;

/// Beyond paper 000: its tests run along iso-curves only, and a twisted
/// surface (a bilinear saddle, whose iso-curves are all straight) passes them
/// with a grid far too coarse. A cell's twist `(P00 + P11 − P10 − P01) / 4`,
/// taken along the surface normal, is how far its two triangles miss the
/// surface at the centre beyond the iso-curve sags; where it exceeds `room`
/// (what the sags left of the tolerance), the cell's row and column are split
/// into equal parts by the square root of the excess (twist falls with the
/// product of both steps). On a trimmed face only cells with a corner inside count.
fn refine_twisted_cells(
    surface: &dyn Surface,
    pu: &mut Vec<f64>,
    pv: &mut Vec<f64>,
    room: f64,
    loops: Option<&TrimRegion<'_>>,
) {
    for _ in 0..4 {
        let (nu, nv) = (pu.len(), pv.len());
        if nu < 2 || nv < 2 || nu * nv > 4_000_000 {
            return;
        }
        #[cfg(feature = "std")]
        let inside = loops.map(|l| l.contains_grid(pu, pv));
        #[cfg(not(feature = "std"))]
        let inside: Option<Vec<bool>> = loops.map(|_| Vec::new());
        let kept = |i: usize, j: usize| {
            inside.as_ref().is_none_or(|m| {
                [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .any(|&(a, b)| m.get((i + a) * nv + j + b).copied().unwrap_or(true))
            })
        };
        let pts: Vec<DVec3> = surface.point_grid(pu, pv);
        let mut need_u = alloc::vec![1usize; nu - 1];
        let mut need_v = alloc::vec![1usize; nv - 1];
        let mut any = false;
        for i in 0..nu - 1 {
            for j in 0..nv - 1 {
                let p = |a: usize, b: usize| pts[(i + a) * nv + j + b];
                let twist = (p(0, 0) + p(1, 1) - p(1, 0) - p(0, 1)) * 0.25;
                if twist.length() <= room || !kept(i, j) {
                    continue;
                }
                let n = surface.normal(DVec2::new(0.5 * (pu[i] + pu[i + 1]), 0.5 * (pv[j] + pv[j + 1])));
                let e = twist.dot(n).abs();
                if e > room {
                    let n = (crate::math::ceil(crate::math::sqrt(e / room)) as usize).clamp(2, 256);
                    need_u[i] = need_u[i].max(n);
                    need_v[j] = need_v[j].max(n);
                    any = true;
                }
            }
        }
        if !any {
            return;
        }
        *pu = split_by(pu, &need_u);
        *pv = split_by(pv, &need_v);
    }
}

/// Splits interval `k` of `p` into `need[k]` equal parts.
fn split_by(p: &[f64], need: &[usize]) -> Vec<f64> {
    let mut out = Vec::with_capacity(p.len() * 2);
    out.push(p[0]);
    for (k, w) in p.windows(2).enumerate() {
        let n = need[k];
        for s in 1..=n {
            out.push(if s == n { w[1] } else { w[0] + (w[1] - w[0]) * s as f64 / n as f64 });
        }
    }
    out
}

/// Meshes face `index` (its `loops`: its own, or [`domain_loops`]' when it
/// has none) on its own within `crit`, using at most `budget` triangles,
/// as `mesh_model` meshes it in a model (its seams within `tight`), so the
/// two can be compared. `samples`: the face surface's grid samples, shared
/// by its trials.
pub(crate) fn mesh_face<'a>(
    index: usize,
    (face, loops): (&'a Face, &'a [crate::TrimLoop]),
    lim: &Limits,
    crit: &Criteria,
    budget: usize,
    tight: f64,
    samples: &Samples,
) -> Result<FaceResult<'a>, Error> {
    let started = start_face(index, (face, loops), lim, budget, tight, samples)?;
    Ok(started.finish(&face.surface, crit, budget))
}

/// A trial mesh of one face before refinement ([`start_face`]); refinement
/// only adds triangles, so its count is a floor under the finished mesh's.
pub(crate) struct Started<'a> {
    pub mesh: WorkMesh,
    curves: Vec<&'a crate::NurbsCurve>,
    outline: Option<Outline<'a>>,
}

/// The first half of [`mesh_face`]: face `index`'s outline sewn to itself
/// and triangulated, not yet refined.
pub(crate) fn start_face<'a>(
    index: usize,
    (face, loops): (&'a Face, &'a [crate::TrimLoop]),
    lim: &Limits,
    budget: usize,
    tight: f64,
    samples: &Samples,
) -> Result<Started<'a>, Error> {
    #[cfg(feature = "std")]
    {
        // A grid of more cells than [`check_band_cells`] lets through need
        // not be placed line by line (a trial on a capped rebuild can ask
        // for millions).
        let cells = budget.saturating_mul(2).min(MAX_BAND_CELLS).max(budget / 2);
        let mut o = outline(index, (&face.surface, samples), loops, face.loops.is_empty(), lim, cells)?;
        // A grid [`initial_from_outline`] refuses anyway is refused before
        // sewing its many border nodes (a rebuild's trial on a folded face).
        check_band_cells(index, &o, budget)?;
        let unsewn = o.clone();
        super::sew::unify(
            &mut [Some((&face.surface as &dyn Surface, &mut o))],
            &[],
            &[],
            tight,
            tight,
            tight + lim.tol,
        );
        let mut mesh = initial_from_outline(index, &face.surface, &o, budget)?;
        mesh.log_measures();
        Ok(Started { mesh, curves: o.loops.curves, outline: Some(unsewn) })
    }
    #[cfg(not(feature = "std"))]
    {
        let _ = (tight, loops, samples);
        let (mut mesh, curves) = initial_face(index, face, lim, budget)?;
        mesh.log_measures();
        Ok(Started { mesh, curves, outline: None })
    }
}

impl<'a> Started<'a> {
    /// The second half of [`mesh_face`]: the mesh refined on `surface`
    /// within `crit` and `budget`, and (with `std`) its angles improved.
    pub(crate) fn finish(self, surface: &dyn Surface, crit: &Criteria, budget: usize) -> FaceResult<'a> {
        let Started { mesh: mut wm, curves, outline } = self;
        let outcome = wm.refine(surface, &curves, crit, budget);
        #[cfg(feature = "std")]
        {
            if wm.tris.len() >= budget {
                // Out of its budget: it loses to any mesh within it, whatever
                // its shapes; mending them (seconds on a folded face) would
                // change nothing the comparison reads.
                return FaceResult { mesh: wm, outcome, outline };
            }
            // Flipped as the model's faces are, so that the shapes compared are
            // those the model's mesh would have.
            let flipped = wm.improve_angles(surface, crit, &mut crate::collections::HashSet::default());
            wm.forget(&flipped);
            let lifted = wm.lift_angles(surface, crit);
            wm.forget(&lifted);
            let outcome = wm.outcome(surface, crit);
            FaceResult { mesh: wm, outcome, outline }
        }
        #[cfg(not(feature = "std"))]
        FaceResult { mesh: wm, outcome, outline }
    }
}

/// The mesh of face `index` before refinement without the CDT (no `std`):
/// the grid of an untrimmed face; a trimmed face is an error.
#[cfg(not(feature = "std"))]
pub(crate) fn initial_face<'a>(
    index: usize,
    face: &'a Face,
    lim: &Limits,
    budget: usize,
) -> Result<(WorkMesh, Vec<&'a crate::NurbsCurve>), Error> {
    let surface: &dyn Surface = &face.surface;
    let mut wm = WorkMesh::default();
    let curves;
    if face.loops.is_empty() {
        curves = Vec::new();
        let [lo, hi] = surface.domain();
        let (pu, pv) = grid((surface, &Samples::default()), lo, hi, lim, None, usize::MAX);
        check_grid(index, &pu, &pv, budget)?;
        build_full_grid(surface, &pu, &pv, &mut wm);
    } else {
        curves = trimmed(index, surface, face, lim, budget, &mut wm)?;
    }
    Ok((wm, curves))
}

/// A face's border, ready to be sewn to its neighbours and triangulated:
/// its loops discretized, the parameter box its grid covers, and per loop
/// node its node id across the model (`u32::MAX` until sewing names it).
#[cfg(feature = "std")]
#[derive(Clone)]
pub(crate) struct Outline<'a> {
    pub loops: super::trim::Loops<'a>,
    /// The grid's parameter lines.
    pub pu: Vec<f64>,
    pub pv: Vec<f64>,
    pub gids: Vec<Vec<u32>>,
    /// Sewing left its loops crossing after halving as many of their
    /// crossing chords as it may ([`super::sew::split_crossing_chords`]):
    /// curves that overlap along a stretch, which no halving parts.
    pub crossed: bool,
}

/// The outline of face `index`: `loops` (the face's own, or [`domain_loop`]'s
/// for an untrimmed face, `whole`) discretized by the chord test, and the
/// grid inside it. Loop pieces along an iso-line that the grid's lines cross
/// get a node at each crossing when they are the domain's border or collapse
/// to a point (a pole): the band then joins the grid's columns to the
/// border one by one, as the untrimmed grid would, instead of fanning a few
/// far nodes over many columns. A grid of more than `cells` cells may be
/// cut short (see [`grid`]).
///
/// # Errors
/// As `mesh_model` for bad loops, or loops outside the surface's domain.
#[cfg(feature = "std")]
pub(crate) fn outline<'a>(
    index: usize,
    (surface, samples): (&dyn Surface, &Samples),
    loops: &'a [crate::TrimLoop],
    whole: bool,
    lim: &Limits,
    cells: usize,
) -> Result<Outline<'a>, Error> {
    if whole {
        if let Some(o) = domain_outline((surface, samples), loops, lim, cells) {
            return Ok(o);
        }
    }
    let mut loops = super::trim::prepare_loops(index, surface, loops, lim)?;
    let [dlo, dhi] = surface.domain();
    let (llo, lhi) = loops.bounds();
    let lo = llo.max(dlo);
    let hi = lhi.min(dhi);
    if !(hi.x > lo.x && hi.y > lo.y) {
        return Err(Error::Mesh {
            face: index,
            message: "trim loops lie outside the surface's parameter domain".into(),
        });
    }
    let (pu, pv) = grid((surface, samples), lo, hi, lim, Some(&loops), cells);
    align_to_grid(surface, &mut loops, &pu, &pv, whole);
    let gids = loops.polys.iter().map(|p| alloc::vec![u32::MAX; p.uv.len()]).collect();
    Ok(Outline { loops, pu, pv, gids, crossed: false })
}

/// The outline of an untrimmed face along [`domain_loop`]'s `loops`: the
/// grid over the whole domain, and a loop node at each of its border nodes
/// (the grid tests its border iso-curves, so they need no chord test of
/// their own). `None` when `loops` is not such a loop.
#[cfg(feature = "std")]
fn domain_outline<'a>(
    (surface, samples): (&dyn Surface, &Samples),
    loops: &'a [crate::TrimLoop],
    lim: &Limits,
    cells: usize,
) -> Option<Outline<'a>> {
    use super::trim::{CurveRef, Loops, Polyline};
    let [lp] = loops else { return None };
    let [lo, hi] = surface.domain();
    let (pu, pv) = grid((surface, samples), lo, hi, lim, None, cells);
    // Border nodes as the loop runs.
    let uv = rect_border(lo, hi, &pu, &pv);
    // Each node on the loop's straight pieces: curve and parameter.
    let ends: Vec<(DVec2, DVec2)> =
        lp.curves.iter().map(|c| (c.point(0.0).truncate(), c.point(1.0).truncate())).collect();
    let mut at = Vec::with_capacity(uv.len());
    let mut k = 0usize;
    for &q in &uv {
        while k < ends.len() {
            let (a, b) = ends[k];
            let t =
                if (b - a).x.abs() >= (b - a).y.abs() { (q.x - a.x) / (b.x - a.x) } else { (q.y - a.y) / (b.y - a.y) };
            if (0.0..1.0).contains(&t) && q.distance(a.lerp(b, t)) <= 1e-12 * (1.0 + q.length()) {
                at.push(CurveRef { curve: k as u32, t });
                break;
            }
            k += 1;
        }
    }
    if at.len() != uv.len() || uv.len() < 3 {
        return None;
    }
    let n = at.len();
    // A segment follows one piece to its end at most: a node must start
    // every piece, else the segment's curve stops short of its end node.
    let pieces = lp.curves.len() as u32;
    let seg = (0..n)
        .map(|i| {
            let (a, b) = (at[i], at[(i + 1) % n]);
            if b.curve == a.curve && b.t > a.t {
                Some((a.curve, a.t, b.t))
            } else if b.curve == (a.curve + 1) % pieces && b.t == 0.0 {
                Some((a.curve, a.t, 1.0))
            } else {
                None
            }
        })
        .collect::<Option<Vec<_>>>()?;
    let loops =
        Loops { polys: alloc::vec![Polyline { uv, at, seg }], curves: lp.curves.iter().collect(), mended: None };
    let gids = alloc::vec![alloc::vec![u32::MAX; n]];
    Some(Outline { loops, pu, pv, gids, crossed: false })
}

/// See [`outline`]: nodes where grid lines cross loop pieces that run along
/// an iso-line (all of them when `whole`, else those that collapse to a point).
#[cfg(feature = "std")]
fn align_to_grid(surface: &dyn Surface, loops: &mut super::trim::Loops<'_>, pu: &[f64], pv: &[f64], whole: bool) {
    use super::trim::Polyline;
    let span = (pu.last().copied().unwrap_or(0.0) - pu.first().copied().unwrap_or(0.0)).abs()
        + (pv.last().copied().unwrap_or(0.0) - pv.first().copied().unwrap_or(0.0)).abs();
    let eps = 1e-9 * span.max(TINY);
    for poly in &mut loops.polys {
        let n = poly.uv.len();
        let mut out = Polyline { uv: Vec::with_capacity(n), at: Vec::with_capacity(n), seg: Vec::with_capacity(n) };
        for i in 0..n {
            let (a, b) = (poly.uv[i], poly.uv[(i + 1) % n]);
            let (curve, ta, tb) = poly.seg[i];
            out.uv.push(a);
            out.at.push(poly.at[i]);
            let c = loops.curves.get(curve as usize);
            let (pa, pb) = (surface.point(a), surface.point(b));
            let collapsed = pa.distance(pb) <= 1e-12 * (1.0 + pa.length());
            let mut from = ta;
            if let Some(c) = c.filter(|_| whole || collapsed) {
                // Along u (v fixed) or along v (u fixed).
                let (lines, x0, x1) = if (a.y - b.y).abs() <= eps {
                    (pu, a.x, b.x)
                } else if (a.x - b.x).abs() <= eps {
                    (pv, a.y, b.y)
                } else {
                    (&[][..], 0.0, 0.0)
                };
                let (lo, hi) = (x0.min(x1), x0.max(x1));
                let mut cross: Vec<f64> = lines.iter().copied().filter(|&x| x > lo + eps && x < hi - eps).collect();
                if x1 < x0 {
                    cross.reverse();
                }
                for x in cross {
                    let t = ta + (tb - ta) * (x - x0) / (x1 - x0);
                    let q = c.point(t).truncate();
                    // Only where the curve runs straight in (u,v).
                    if q.distance(a.lerp(b, (x - x0) / (x1 - x0))) > 1e3 * eps {
                        continue;
                    }
                    out.push_on_curve(curve, &mut from, t, q);
                }
            }
            out.seg.push((curve, from, tb));
        }
        *poly = out;
    }
}

/// The border of the rectangle `[lo, hi]` through the parameter lines `us`
/// and `vs` (each from `lo` to `hi`, ends included), counter-clockwise from
/// `lo`, each corner once.
fn rect_border(lo: DVec2, hi: DVec2, us: &[f64], vs: &[f64]) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(2 * (us.len() + vs.len()));
    out.extend(us.iter().map(|&u| DVec2::new(u, lo.y)));
    out.extend(vs.iter().skip(1).map(|&v| DVec2::new(hi.x, v)));
    out.extend(us.iter().rev().skip(1).map(|&u| DVec2::new(u, hi.y)));
    out.extend(vs.iter().rev().skip(1).map(|&v| DVec2::new(lo.x, v)));
    out.pop(); // back at the start
    out
}

/// The loops an untrimmed face is meshed by: its domain's border
/// ([`domain_loop`]), so that its borders sew like trim loops; none for a
/// trimmed face, or without `std` (no CDT).
pub(crate) fn domain_loops(face: &Face) -> Vec<crate::TrimLoop> {
    if cfg!(feature = "std") && face.loops.is_empty() {
        domain_loop(&face.surface).into_iter().collect()
    } else {
        Vec::new()
    }
}

/// Whether an untrimmed face closes on itself: each side of its domain
/// either collapses to a point (a pole) or runs along the opposite side (a
/// seam), at 33 points within `reach`. Such a face (a sphere, a torus, a
/// closed B-spline tube) has no border to share: it is a body of its own.
pub(crate) fn closed_on_itself(face: &Face, reach: f64) -> bool {
    if !face.loops.is_empty() || reach.is_nan() || reach <= 0.0 {
        return false;
    }
    let [lo, hi] = face.surface.domain();
    if !(hi.x > lo.x && hi.y > lo.y) {
        return false;
    }
    const N: usize = 33;
    let at = |along_u: bool, side: f64, k: usize| {
        let t = k as f64 / (N - 1) as f64;
        let uv = if along_u {
            DVec2::new(lo.x + t * (hi.x - lo.x), side)
        } else {
            DVec2::new(side, lo.y + t * (hi.y - lo.y))
        };
        face.surface.point(uv)
    };
    let pole = |along_u: bool, side: f64| {
        let first = at(along_u, side, 0);
        (1..N).all(|k| at(along_u, side, k).distance(first) <= reach)
    };
    let seam = |along_u: bool, a: f64, b: f64| (0..N).all(|k| at(along_u, a, k).distance(at(along_u, b, k)) <= reach);
    // The sides v = lo.y, hi.y run along u; u = lo.x, hi.x along v.
    let v_closed = seam(true, lo.y, hi.y) || (pole(true, lo.y) && pole(true, hi.y));
    let u_closed = seam(false, lo.x, hi.x) || (pole(false, lo.x) && pole(false, hi.x));
    v_closed && u_closed
}

/// The loop around a surface's whole parameter domain, a straight (u,v)
/// piece between each two knot lines (so the border has nodes where the
/// surface may kink): an untrimmed face meshed as trimmed by it can take
/// into its border the nodes of the faces it meets. `None` for an empty domain.
pub(crate) fn domain_loop(surface: &dyn Surface) -> Option<crate::TrimLoop> {
    let [lo, hi] = surface.domain();
    if !(hi.x > lo.x && hi.y > lo.y) {
        return None;
    }
    // A surface C² across its knots (a rebuilt one) kinks nowhere: its grid
    // lines ignore the knots, and so do its border's pieces, each of which
    // must start at a border node.
    let breaks = |along_u: bool| if surface.even_parameters() { Vec::new() } else { surface.breaks(along_u) };
    let bu = super::params::initial_breaks(&breaks(true), lo.x, hi.x, 16);
    let bv = super::params::initial_breaks(&breaks(false), lo.y, hi.y, 16);
    let corners = rect_border(lo, hi, &bu, &bv);
    let n = corners.len();
    let mut curves = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        let c = crate::NurbsCurve::try_new(
            1,
            alloc::vec![0.0, 0.0, 1.0, 1.0],
            alloc::vec![a.extend(0.0), b.extend(0.0)],
            None,
        )
        .ok()?;
        curves.push(c);
    }
    Some(crate::TrimLoop { curves })
}

/// The mesh of a face before refinement from its (sewn) outline: the grid
/// inside it and the CDT band along it, loop nodes of one model node welded
/// into one vertex (a seam, a pole) that carries the node's id.
///
/// # Errors
/// A grid over `budget`, or loops the triangulation finds crossing.
#[cfg(feature = "std")]
pub(crate) fn initial_from_outline(
    index: usize,
    surface: &dyn Surface,
    o: &Outline<'_>,
    budget: usize,
) -> Result<WorkMesh, Error> {
    if o.crossed {
        let message = "trim loops cross along a stretch that halving their chords cannot part".into();
        return Err(Error::Mesh { face: index, message });
    }
    // The grid's rectangle is the loops' box, which may reach far beyond
    // the region they keep (a rebuilt face's loops on its whole old domain):
    // a grid up to four times the budget is triangulated, and judged by the
    // triangles the loops keep.
    check_band_cells(index, o, budget)?;
    let mut band = super::band::Band::new(surface, &o.loops, &o.pu, &o.pv);
    let tris = band.triangulate(index)?;
    if tris.len() > budget {
        check_grid(index, &o.pu, &o.pv, budget)?;
    }
    let mut wm = WorkMesh::default();
    band.build(surface, &tris, &mut wm, Some(&o.gids));
    Ok(wm)
}

/// Without the CDT (no `std`), trimmed faces cannot be meshed.
#[cfg(not(feature = "std"))]
fn trimmed<'a>(
    index: usize,
    _surface: &dyn Surface,
    _face: &'a Face,
    _lim: &Limits,
    _budget: usize,
    _wm: &mut WorkMesh,
) -> Result<Vec<&'a crate::NurbsCurve>, Error> {
    Err(Error::Mesh { face: index, message: "trimmed faces need the `std` feature".into() })
}

/// Most cells of a grid over the budget that [`initial_from_outline`] still
/// triangulates to count what its loops keep.
#[cfg(feature = "std")]
const MAX_BAND_CELLS: usize = 1_000_000;

/// [`check_grid`] for a grid of more cells than [`initial_from_outline`]
/// triangulates to count what the loops keep.
#[cfg(feature = "std")]
fn check_band_cells(index: usize, o: &Outline<'_>, budget: usize) -> Result<(), Error> {
    let cells = o.pu.len().saturating_sub(1).saturating_mul(o.pv.len().saturating_sub(1));
    if cells > budget.saturating_mul(2).min(MAX_BAND_CELLS) {
        check_grid(index, &o.pu, &o.pv, budget)?;
    }
    Ok(())
}

pub(super) fn check_grid(index: usize, pu: &[f64], pv: &[f64], budget: usize) -> Result<(), Error> {
    let cells = pu.len().saturating_sub(1).saturating_mul(pv.len().saturating_sub(1));
    if cells.saturating_mul(2) > budget {
        return Err(Error::Limit(format!(
            "face {index}: the tolerance asks for a {}x{} grid, over the triangle budget of {budget}",
            pu.len(),
            pv.len()
        )));
    }
    Ok(())
}

/// Welds grid nodes that coincide in model space (closed seams, poles) so that
/// refinement sees one shared edge; returns the vertex of each node.
#[cfg(not(feature = "std"))]
fn weld_nodes(surface: &dyn Surface, nodes: &[DVec2], wm: &mut WorkMesh) -> (Vec<u32>, Vec<u32>) {
    let pts: Vec<DVec3> = nodes.iter().map(|&q| surface.point(q)).collect();
    let diag = crate::nurbs::Aabb::from_points(pts.iter().copied()).diagonal();
    let (map, count) = crate::mesh::weld_positions(&pts, 1e-10 * diag.max(TINY));
    let mut vert = alloc::vec![u32::MAX; count];
    let mut multiplicity = alloc::vec![0u32; count];
    let mut out = Vec::with_capacity(nodes.len());
    for (i, &m) in map.iter().enumerate() {
        let m = m as usize;
        if vert[m] == u32::MAX {
            vert[m] = wm.add_vertex(pts[i], surface.normal(nodes[i]));
        }
        multiplicity[m] += 1;
        out.push(vert[m]);
    }
    let mult = map.iter().map(|&m| multiplicity[m as usize]).collect();
    (out, mult)
}

/// Untrimmed surface: the grid's quads, each split along its shorter diagonal
/// (in model space) into two counter-clockwise triangles.
#[cfg(not(feature = "std"))]
fn build_full_grid(surface: &dyn Surface, pu: &[f64], pv: &[f64], wm: &mut WorkMesh) {
    let (nu, nv) = (pu.len(), pv.len());
    let nodes: Vec<DVec2> = (0..nu).flat_map(|i| pv.iter().map(move |&v| DVec2::new(pu[i], v))).collect();
    let (vid, mult) = weld_nodes(surface, &nodes, wm);
    let at = |i: usize, j: usize| i * nv + j;
    for i in 0..nu.saturating_sub(1) {
        for j in 0..nv.saturating_sub(1) {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let p = |k: usize| wm.pos[vid[q[k]] as usize];
            let tris = if p(0).distance_squared(p(2)) <= p(1).distance_squared(p(3)) {
                [[0, 1, 2], [0, 2, 3]]
            } else {
                [[0, 1, 3], [1, 2, 3]]
            };
            for t in tris {
                let v = [vid[q[t[0]]], vid[q[t[1]]], vid[q[t[2]]]];
                if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
                    continue; // collapsed at a pole
                }
                let mut uv = [nodes[q[t[0]]], nodes[q[t[1]]], nodes[q[t[2]]]];
                fix_pole_corners(&mut uv, [mult[q[t[0]]], mult[q[t[1]]], mult[q[t[2]]]]);
                wm.add_triangle(v, uv);
            }
        }
    }
}

/// At a pole many grid nodes are one vertex; its (u,v) in a triangle is taken
/// midway along the collapsed direction between the other two corners, so the
/// triangle's (u,v) interpolation follows the surface (better Newton hints).
#[cfg(not(feature = "std"))]
fn fix_pole_corners(uv: &mut [DVec2; 3], mult: [u32; 3]) {
    for k in 0..3 {
        if mult[k] > 4 {
            let (a, b) = (uv[(k + 1) % 3], uv[(k + 2) % 3]);
            if (a.y - uv[k].y).abs() > (a.x - uv[k].x).abs() && (b.y - uv[k].y).abs() > (b.x - uv[k].x).abs() {
                uv[k].x = 0.5 * (a.x + b.x); // collapsed along u (v = const row)
            } else {
                uv[k].y = 0.5 * (a.y + b.y);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::FaceSurface;
    use crate::nurbs::NurbsSurface;

    /// A wavy 10 × 4 bicubic sheet with even parameters (as a rebuild is).
    fn wavy() -> FaceSurface {
        let pts: Vec<Vec<DVec3>> = (0..8)
            .map(|i| (0..5).map(|j| DVec3::new(i as f64, 0.6 * j as f64, ((i + j) % 2) as f64 * 0.5)).collect())
            .collect();
        let ku = alloc::vec![0.0, 0.0, 0.0, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0];
        let kv = alloc::vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
        FaceSurface::Rebuilt(NurbsSurface::try_new([3, 3], ku, kv, &pts, None).unwrap())
    }

    /// Samples kept by one grid serve the next with other limits (a
    /// rebuild's trials differ in the edge limit and the tolerance share):
    /// each grid is the one fresh samples give, and a second grid of the
    /// same limits evaluates nothing new.
    #[test]
    fn kept_samples_give_the_grids_fresh_ones_give() {
        let s = wavy();
        let [lo, hi] = s.domain();
        let kept = Samples::default();
        let lim = |tol: f64, max_edge: f64| Limits { tol, angle: 0.5, max_edge, min_edge: 1e-6 };
        for l in [lim(1e-3, f64::INFINITY), lim(1e-3, 0.7), lim(8e-4, 0.3), lim(1e-2, f64::INFINITY)] {
            let fresh = grid((&s, &Samples::default()), lo, hi, &l, None, usize::MAX);
            assert_eq!(grid((&s, &kept), lo, hi, &l, None, usize::MAX), fresh, "{l:?}");
            let n = kept.len();
            assert!(n > 0);
            assert_eq!(grid((&s, &kept), lo, hi, &l, None, usize::MAX), fresh, "{l:?} again");
            assert_eq!(kept.len(), n, "{l:?}: evaluated again");
        }
    }

    /// The grid of an evenly parameterized surface (a rebuild) makes room
    /// in its store for each direction's fine demand before keeping its
    /// first value: no value is kept in a full store (each growth rehashed
    /// every value kept).
    #[test]
    fn an_even_grid_sizes_its_samples_at_once() {
        let s = wavy();
        let [lo, hi] = s.domain();
        let lim = Limits { tol: 1e-3, angle: 0.5, max_edge: f64::INFINITY, min_edge: 1e-6 };
        let kept = Samples::default();
        let g = grid((&s, &kept), lo, hi, &lim, None, usize::MAX);
        assert!(kept.len() > 4000, "{} values", kept.len());
        assert_eq!(kept.growths(), 0, "{} values kept", kept.len());
        let (pu, pv) = g;
        assert!(pu.len() > 2 && pv.len() > 2, "{} x {}", pu.len(), pv.len());
    }

    /// The trials of a rebuilt face place their grids within other
    /// tolerance shares and edge limits on the same fine intervals: each
    /// interval's shape is measured by the first grid only, and each grid
    /// is the one fresh samples give.
    #[test]
    fn kept_shapes_serve_the_grids_of_other_limits() {
        let s = wavy();
        let [lo, hi] = s.domain();
        let kept = Samples::default();
        let lim = |tol: f64, max_edge: f64| Limits { tol, angle: 0.5, max_edge, min_edge: 1e-6 };
        let first = lim(1e-3, f64::INFINITY);
        assert_eq!(
            grid((&s, &kept), lo, hi, &first, None, usize::MAX),
            grid((&s, &Samples::default()), lo, hi, &first, None, usize::MAX)
        );
        let measured = kept.shapes_measured();
        assert!(measured >= 2 * 5 * 256, "{measured} shapes measured");
        for l in [lim(1e-3, 0.7), lim(8e-4, 0.3), lim(1e-2, f64::INFINITY), lim(3e-4, 2.0)] {
            let fresh = grid((&s, &Samples::default()), lo, hi, &l, None, usize::MAX);
            assert_eq!(grid((&s, &kept), lo, hi, &l, None, usize::MAX), fresh, "{l:?}");
            assert_eq!(kept.shapes_measured(), measured, "{l:?}: measured again");
        }
    }

    /// A trial's cell limit (see [`grid`]): a grid within it is the grid
    /// without one, line for line; one far over it is cut short, still
    /// with more cells than the limit, so the caller's budget refuses it.
    #[test]
    fn grid_within_a_cell_limit_is_unchanged_and_far_over_it_is_cut_short() {
        let s = wavy();
        let [lo, hi] = s.domain();
        let lim = Limits { tol: 1e-3, angle: 0.5, max_edge: f64::INFINITY, min_edge: 1e-6 };
        let fresh = || Samples::default();
        let (pu, pv) = grid((&s, &fresh()), lo, hi, &lim, None, usize::MAX);
        let cells = (pu.len() - 1) * (pv.len() - 1);
        assert!(cells > 400, "{} x {}", pu.len(), pv.len());
        assert_eq!(grid((&s, &fresh()), lo, hi, &lim, None, cells), (pu.clone(), pv.clone()));
        for limit in [cells / 3, cells / 20, 1] {
            let (a, b) = grid((&s, &fresh()), lo, hi, &lim, None, limit);
            assert!((a.len() - 1) * (b.len() - 1) > limit, "{limit}: {} x {}", a.len(), b.len());
            assert!((&a, &b) != (&pu, &pv), "{limit}: not cut short");
        }
    }
}
