//! Paper 001 under `auto`: the trial meshes of a rebuilt face and of its
//! original, how the rebuild may spend the triangles it saves (shorter
//! edges, needles mended), and the judge that keeps one of the two.

use alloc::vec::Vec;

use super::{collapse, face, params, refine};
use crate::warning::RebuildLoss;
use crate::Error;

/// The unsewn outline a trial mesh made, taken out of it.
pub(super) fn outline_of<'x>(r: &mut Result<face::FaceResult<'x>, Error>) -> Option<face::Outline<'x>> {
    r.as_mut().ok().and_then(|r| r.outline.take())
}

/// The triangles of a trial mesh (`usize::MAX` when it failed).
pub(super) fn tris_of(r: &Result<face::FaceResult<'_>, Error>) -> usize {
    r.as_ref().map_or(usize::MAX, |r| r.mesh.tris.len())
}

/// Most meshes [`shorter_edges`] tries.
pub(super) const SHORTER_TRIES: usize = 6;

/// Beyond paper 001: a rebuilt face whose mesh `rebuilt` takes fewer
/// triangles than the original's but loses on shape (a thin face meshed by
/// few long triangles) may spend the difference on shorter edges. The edge
/// limit starts at `first` times the longest edge and falls by √2 a try (about twice
/// the triangles), for at most `tries` tries, until the mesh wins or takes
/// more triangles than the original's; the limits of the winning mesh, if
/// one does, and its unsewn outline. A mesh that loses on proof (more
/// triangles left over the limits than the original's: out of budget, or
/// at the shortest edge) is not tried: more triangles cannot win it back.
pub(super) fn shorter_edges<'x>(
    index: usize,
    (face, loops, samples): (&'x crate::Face, &'x [crate::TrimLoop], &params::Samples),
    rebuilt: &Result<face::FaceResult<'_>, Error>,
    original: &Result<face::FaceResult<'_>, Error>,
    (lim, crit, first, tries): (&params::Limits, &refine::Criteria, f64, usize),
    budget: usize,
    tight: f64,
) -> Option<(params::Limits, refine::Criteria, Option<face::Outline<'x>>)> {
    let (Ok(new), Ok(old)) = (rebuilt, original) else { return None };
    if !loses_on_shape_alone(new, old) {
        return None;
    }
    let pos = |v: u32| new.mesh.pos.get(v as usize).copied().unwrap_or_default();
    let longest = new
        .mesh
        .tris
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| pos(a).distance(pos(b)))
        .fold(0.0f64, f64::max);
    let mut edge = first * longest;
    for _ in 0..tries {
        if !(edge > crit.min_edge && edge.is_finite()) {
            return None;
        }
        let l = params::Limits { max_edge: lim.max_edge.min(edge), ..*lim };
        let c = refine::Criteria { max_edge: crit.max_edge.min(edge), ..*crit };
        let mut r = face::mesh_face(index, (face, loops), &l, &c, budget, tight, samples);
        match &r {
            Ok(m) if !m.mesh.tris.is_empty() && m.mesh.tris.len() <= old.mesh.tris.len() => {}
            _ => return None,
        }
        if rebuild_loses(&r, original).is_none() {
            return Some((l, c, outline_of(&mut r)));
        }
        edge *= core::f64::consts::FRAC_1_SQRT_2;
    }
    None
}

/// Beyond paper 001: a rebuilt face whose mesh `(rebuilt, lim, crit)`
/// takes fewer triangles than the original's but loses on shape (needles
/// fanned onto tiny edges) spends the difference on Delaunay refinement of
/// its triangles under the original's 1st-percentile angle + 1°
/// (`refine/lift.rs`); the limits of the mesh if it then wins, and its
/// unsewn outline. As in [`shorter_edges`], only a mesh that loses on
/// shape alone is lifted.
pub(super) fn lift_needles<'x>(
    index: usize,
    (face, loops, samples): (&'x crate::Face, &'x [crate::TrimLoop], &params::Samples),
    (rebuilt, lim, crit): &(Result<face::FaceResult<'_>, Error>, params::Limits, refine::Criteria),
    original: &Result<face::FaceResult<'_>, Error>,
    budget: usize,
    tight: f64,
) -> Option<(refine::Criteria, Option<face::Outline<'x>>)> {
    let (Ok(new), Ok(old)) = (rebuilt, original) else { return None };
    let most = old.mesh.tris.len();
    if !loses_on_shape_alone(new, old) {
        return None;
    }
    let goal = (p1(&old.mesh) + 1.0).to_radians();
    let c = refine::Criteria { lift: refine::Lift { goal, most }, ..*crit };
    let mut r = face::mesh_face(index, (face, loops), lim, &c, budget, tight, samples);
    rebuild_loses(&r, original).is_none().then(|| (c, outline_of(&mut r)))
}

/// Whether the mesh of a rebuilt face `new` has triangles to spend on
/// shape: fewer than the original's `old`, and no more of them left over
/// the limits. One that ran out of its trial budget (the original's count)
/// or stopped at the shortest edge with more unproven triangles loses on
/// proof, which shorter edges or lifted needles only make worse: on a
/// folded face each such try refined up to the budget again (seconds a try).
fn loses_on_shape_alone(new: &face::FaceResult<'_>, old: &face::FaceResult<'_>) -> bool {
    !new.mesh.tris.is_empty()
        && new.mesh.tris.len() < old.mesh.tris.len()
        && new.outcome.unproven <= old.outcome.unproven
}

/// The 1st-percentile smallest angle of a trial mesh, degrees, as the
/// model's mesh will have it: the edges whose ends sewing puts on one model
/// node collapsed.
pub(super) fn p1(m: &refine::WorkMesh) -> f64 {
    let mut tris = m.tris.clone();
    let pos = |v: u32| m.pos.get(v as usize).copied();
    let gid = |v: u32| m.gid.get(v as usize).copied().unwrap_or(u32::MAX);
    collapse::collapse_edges(&mut tris, |a, b| {
        (gid(a) == gid(b) && gid(a) != u32::MAX)
            || matches!((pos(a), pos(b)), (Some(p), Some(q)) if collapse::one_point(p, q))
    });
    let mut a: Vec<f64> = tris
        .iter()
        .map(|t| crate::mesh::min_angle(t.map(|v| m.pos.get(v as usize).copied().unwrap_or_default())))
        .collect();
    crate::sort::f64s(&mut a);
    a.get(a.len().saturating_sub(1) / 100).map_or(0.0, |x| x.to_degrees())
}

/// How many times the 1st-percentile angle of the original's first mesh
/// a rebuild's must be for [`beats_unrefined`]: refinement and its flips
/// move the original's either way (the fuselage's faces fell from 0.1° to
/// 0.007°; asmo_car's face 1 rose from 1.4° to 4.2°, the most in the
/// corpus survey), and the judgement made without them must agree with the
/// one made with them.
const FIRST_ANGLE_MARGIN: f64 = 3.0;

/// Whether the trial mesh of a rebuilt face, `new`, wins against the
/// original's first mesh, before refinement (`first`): what
/// [`rebuild_loses`] reads, found without refining the original. `new` is
/// proven (so no less than the original), has no more triangles than
/// `first` (refinement only adds them) and a 1st-percentile angle
/// [`FIRST_ANGLE_MARGIN`] times `first`'s. On a face whose crowded
/// parameters give the original thousands of triangles before refinement
/// (the fuselage's), refining them was most of the trial's time.
pub(super) fn beats_unrefined(new: &face::FaceResult<'_>, first: &refine::WorkMesh) -> bool {
    !new.mesh.tris.is_empty()
        && new.outcome.unproven == 0
        && new.mesh.tris.len() <= first.tris.len()
        && p1(&new.mesh) >= FIRST_ANGLE_MARGIN * p1(first)
}

/// Why the mesh of a rebuilt face loses to the original's, if it does: it
/// failed or is empty, is not proven where the original is, has more
/// triangles, or a smaller 1st-percentile angle. `None` keeps the rebuild.
pub(super) fn rebuild_loses(
    rebuilt: &Result<face::FaceResult<'_>, Error>,
    original: &Result<face::FaceResult<'_>, Error>,
) -> Option<RebuildLoss> {
    let new = match rebuilt {
        Ok(r) if !r.mesh.tris.is_empty() => r,
        Ok(_) => return Some(RebuildLoss::NoTriangles),
        Err(e) => return Some(RebuildLoss::DidNotMesh(e.clone())),
    };
    let old = original.as_ref().ok()?;
    let (nt, ot) = (new.mesh.tris.len(), old.mesh.tris.len());
    if new.outcome.unproven > old.outcome.unproven {
        Some(RebuildLoss::Unproven(new.outcome.unproven))
    } else if nt > ot {
        Some(RebuildLoss::MoreTriangles(nt, ot))
    } else if p1(&new.mesh) < p1(&old.mesh) {
        Some(RebuildLoss::WorseShaped(p1(&new.mesh), p1(&old.mesh)))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trial result of `tris` triangles, `unproven` of them over the limits.
    fn result(tris: usize, unproven: usize) -> face::FaceResult<'static> {
        let mut mesh = refine::WorkMesh::default();
        mesh.tris = alloc::vec![[0, 1, 2]; tris];
        let outcome = refine::Outcome { unproven, ..Default::default() };
        face::FaceResult { mesh, outcome, outline: None }
    }

    /// Shorter edges and lifted needles spend triangles on shape: a rebuild
    /// that is lighter and as proven as the original may try them; one out
    /// of its budget or with more triangles unproven (a folded face's
    /// rebuild, each try refined to the budget again) may not.
    #[test]
    fn only_a_lighter_proven_rebuild_spends_triangles_on_shape() {
        let old = result(100, 2);
        assert!(loses_on_shape_alone(&result(60, 2), &old));
        assert!(loses_on_shape_alone(&result(60, 0), &old));
        assert!(!loses_on_shape_alone(&result(60, 3), &old), "more unproven");
        assert!(!loses_on_shape_alone(&result(100, 0), &old), "as many triangles");
        assert!(!loses_on_shape_alone(&result(0, 0), &old), "empty");
    }

    /// A mesh of `n` triangles, each a fan corner of apex angle `deg`
    /// degrees (its smallest), apart from one another.
    fn fan(n: usize, deg: f64) -> refine::WorkMesh {
        let mut m = refine::WorkMesh::default();
        let (s, c) = (libm::sin(deg.to_radians()), libm::cos(deg.to_radians()));
        for k in 0..n {
            let o = glam::DVec3::new(10.0 * k as f64, 0.0, 0.0);
            let v = m.pos.len() as u32;
            m.pos.extend([o, o + glam::DVec3::new(1.0, 0.0, 0.0), o + glam::DVec3::new(c, s, 0.0)]);
            m.gid.extend([u32::MAX; 3]);
            m.tris.push([v, v + 1, v + 2]);
        }
        m
    }

    /// A rebuild is kept on the original's first mesh alone only when it is
    /// proven, no larger than that mesh (refinement only adds to it) and
    /// its angles beat that mesh's by the margin; anything less leaves the
    /// judgement to the original's refined mesh.
    #[test]
    fn a_rebuild_beats_the_unrefined_original_only_by_a_margin() {
        let first = fan(100, 2.0);
        let new = |n: usize, deg: f64, unproven: usize| face::FaceResult {
            mesh: fan(n, deg),
            outcome: refine::Outcome { unproven, ..Default::default() },
            outline: None,
        };
        assert!(beats_unrefined(&new(40, 6.5, 0), &first));
        assert!(beats_unrefined(&new(100, 6.5, 0), &first), "as many triangles");
        assert!(!beats_unrefined(&new(101, 6.5, 0), &first), "more triangles than the first mesh");
        assert!(!beats_unrefined(&new(40, 6.5, 1), &first), "unproven");
        assert!(!beats_unrefined(&new(40, 5.0, 0), &first), "better shaped, but within the margin");
        assert!(!beats_unrefined(&new(0, 6.5, 0), &first), "empty");
    }
}
