//! Border chords that cross once the outlines are sewn.
//!
//! Each face's loops are freed of crossing chords before sewing
//! ([`crate::tessellate::trim`], paper 000 §3.2), but sewing then adds the
//! neighbours' nodes to them. A node added on a curve moves that chord out
//! to the curve, and on a face narrower than its chords' sagitta (a ring a
//! millimetre wide between two cylinders, at a coarse tolerance) it can move
//! one border's chord across the other's. The triangulation cannot keep
//! both, and the triangles between them go missing: a crack. Here such
//! chords are halved again, in every face that shares them, so the sewn
//! borders stay one.
//!
//! So are chords that do not cross yet but would once refinement splits
//! one on its curve: two sides of a spike narrower than their chords'
//! sagitta. A triangle between such chords spans the spike turned over,
//! and no split can mend it, as each would fold in (u,v).

use alloc::vec::Vec;
use glam::DVec3;

use super::nearest_fraction;
use crate::collections::{HashMap, HashSet};
use crate::nurbs::Surface;
use crate::tessellate::face::Outline;
use crate::tessellate::trim::{bulge_crossings, crossings, insert_after};

/// Most rounds of halving; curves that really cross stay crossing after it.
const MAX_ROUNDS: usize = 16;

/// Most chords one round halves, so a face whose loops really cross
/// everywhere costs a bounded amount.
const MAX_CUTS: usize = 4096;

/// Fewest crossings a face may halve over all rounds, however few its nodes
/// (a thin lens of two chords takes a few rounds to part).
const MIN_CROSSING_CUTS: usize = 64;

/// Halves, on their curves, the sewn border segments that cross another
/// segment of their face's loops, in every face that has that segment (by
/// its two end ids); `ids` is the count of node ids given so far, and the
/// count after the new nodes is returned. Each face's new node lies at its
/// own curve's point nearest the first face's middle point, under one id.
/// A segment that another's halving would cross ([`bulge_crossings`]) is
/// halved too, and that other with it, where every face along them has
/// them under the same ids.
pub(crate) fn split_crossing_chords(faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>], mut ids: u32) -> u32 {
    // Per face, how many more chords may be halved for bulging: as many
    // as it has nodes, so curves that run closer than their own sag
    // anywhere (nearly one curve twice) cannot double its nodes each round.
    let mut allowance: Vec<usize> =
        faces.iter().map(|f| f.as_ref().map_or(0, |(_, o)| o.gids.iter().map(Vec::len).sum())).collect();
    // As many for crossing, at least `MIN_CROSSING_CUTS`: curves that
    // overlap along a stretch (a fuzzed loop retracing itself) cross again
    // at every halving, and would double the face's nodes each round.
    let mut crossing: Vec<usize> = allowance.iter().map(|&n| n.max(MIN_CROSSING_CUTS)).collect();
    for _ in 0..MAX_ROUNDS {
        let mut cuts: Vec<((u32, u32), DVec3)> = Vec::new();
        let (pairs, alone) = border_uses(faces);
        for ((surface, o), (allowance, crossing)) in
            faces.iter().zip(allowance.iter_mut().zip(crossing.iter_mut())).filter_map(|(f, a)| Some((f.as_ref()?, a)))
        {
            let note = |k: usize, i: usize, cuts: &mut Vec<((u32, u32), DVec3)>| {
                let (Some(poly), Some(g)) = (o.loops.polys.get(k), o.gids.get(k)) else { return };
                let n = poly.uv.len();
                let (Some(&(c, ta, tb)), Some(&ga), Some(&gb)) = (poly.seg.get(i), g.get(i), g.get((i + 1) % n)) else {
                    return;
                };
                let Some(curve) = o.loops.curves.get(c as usize) else { return };
                let tm = 0.5 * (ta + tb);
                if ga == gb || ga == u32::MAX || gb == u32::MAX || tm == ta || tm == tb || !tm.is_finite() {
                    return;
                }
                cuts.push(((ga.min(gb), ga.max(gb)), surface.point(curve.point(tm).truncate())));
            };
            crossings(&o.loops, |x| {
                if !x.folds && *crossing > 0 {
                    *crossing -= 1;
                    note(x.a.0, x.a.1, &mut cuts);
                    note(x.b.0, x.b.1, &mut cuts);
                }
                cuts.len() >= MAX_CUTS || *crossing == 0
            });
            // A chord its neighbour's split would cross: both halved, so
            // each side keeps to its curve closer than the two come.
            let middle = |k: usize, i: usize| {
                let &(c, ta, tb) = o.loops.polys.get(k)?.seg.get(i)?;
                let tm = 0.5 * (ta + tb);
                (tm != ta && tm != tb).then(|| o.loops.curves.get(c as usize).map(|c| c.point(tm).truncate()))?
            };
            // Only where every face along the segment takes its node: one
            // that sewing left beside another face's border under other ids
            // would open a crack there.
            let cuttable = |k: usize, i: usize| {
                let Some(g) = o.gids.get(k) else { return false };
                let n = g.len();
                let (ga, gb) = (g[i % n.max(1)], g[(i + 1) % n.max(1)]);
                pairs.get(&(ga.min(gb), ga.max(gb))).is_some_and(|&c| c > 1)
                    || (alone.contains(&ga) && alone.contains(&gb))
            };
            bulge_crossings(&o.loops, middle, |h, c| {
                // The crossed chord is halved first: the bulging one alone
                // would put its node past the other, a crossing of chords.
                if *allowance > 0 && cuttable(c.0, c.1) {
                    *allowance -= 1;
                    note(c.0, c.1, &mut cuts);
                    if cuttable(h.0, h.1) {
                        note(h.0, h.1, &mut cuts);
                    }
                }
                cuts.len() >= MAX_CUTS
            });
        }
        if cuts.is_empty() {
            break;
        }
        // One new id per segment, the first face's middle point for all.
        crate::sort::by_u64(&mut cuts, |c| (u64::from(c.0 .0) << 32) | u64::from(c.0 .1));
        cuts.dedup_by_key(|c| c.0);
        for (surface, o) in faces.iter_mut().flatten() {
            cut_face(*surface, o, &cuts, ids);
        }
        ids += cuts.len() as u32;
    }
    // A face that spent its halvings of crossings and still crosses fails.
    for (item, &left) in faces.iter_mut().zip(&crossing) {
        if let (Some((_, o)), 0) = (item, left) {
            o.crossed = crossings(&o.loops, |x| !x.folds).is_some();
        }
    }
    ids
}

/// How many faces have each border segment (by its end ids, lower first),
/// and the ids of nodes on one face's border only.
fn border_uses(faces: &[Option<(&dyn Surface, &mut Outline<'_>)>]) -> (HashMap<(u32, u32), u32>, HashSet<u32>) {
    let mut pairs: HashMap<(u32, u32), u32> = HashMap::default();
    let mut face_of: HashMap<u32, Option<usize>> = HashMap::default();
    for (f, (_, o)) in faces.iter().enumerate().filter_map(|(f, x)| x.as_ref().map(|x| (f, x))) {
        let mut mine: Vec<(u32, u32)> = Vec::new();
        for g in &o.gids {
            let n = g.len();
            for i in 0..n {
                let (ga, gb) = (g[i], g[(i + 1) % n]);
                mine.push((ga.min(gb), ga.max(gb)));
                face_of.entry(ga).and_modify(|x| *x = x.filter(|&x| x == f)).or_insert(Some(f));
            }
        }
        crate::sort::pairs(&mut mine);
        mine.dedup();
        for p in mine {
            *pairs.entry(p).or_insert(0) += 1;
        }
    }
    let alone = face_of.into_iter().filter(|(g, f)| f.is_some() && *g != u32::MAX).map(|(g, _)| g).collect();
    (pairs, alone)
}

/// Adds the new node of every segment of `o` whose end ids are in `cuts`
/// (sorted by them): id `first + ` its place in `cuts`.
fn cut_face(surface: &dyn Surface, o: &mut Outline<'_>, cuts: &[((u32, u32), DVec3)], first: u32) {
    for k in 0..o.loops.polys.len() {
        let poly = &mut o.loops.polys[k];
        let gids = &mut o.gids[k];
        let n = poly.uv.len();
        if gids.len() != n || poly.seg.len() != n || poly.at.len() != n {
            continue;
        }
        let mut splits = Vec::new();
        let mut ids = Vec::new();
        for i in 0..n {
            let (ga, gb) = (gids[i], gids[(i + 1) % n]);
            let Ok(at) = cuts.binary_search_by_key(&(ga.min(gb), ga.max(gb)), |c| c.0) else { continue };
            let (c, ta, tb) = poly.seg[i];
            let Some(curve) = o.loops.curves.get(c as usize) else { continue };
            let target = cuts[at].1;
            let on_curve = |s: f64| surface.point(curve.point(ta + (tb - ta) * s).truncate());
            let (s, _) = nearest_fraction(&|s: f64| on_curve(s).distance(target), 0.5);
            let s = if s > 1e-9 && s < 1.0 - 1e-9 { s } else { 0.5 };
            let t = ta + (tb - ta) * s;
            splits.push((i, t, curve.point(t).truncate()));
            ids.push((i, first + at as u32));
        }
        if splits.is_empty() {
            continue;
        }
        poly.split_segments(&splits);
        insert_after(gids, &ids);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::NurbsCurve;
    use crate::tessellate::trim::{CurveRef, Loops, Polyline};
    use alloc::vec::Vec;
    use glam::DVec2;

    /// A line in (u,v) from `p` to `q`, parameter 0 to 1.
    fn line(p: DVec2, q: DVec2) -> NurbsCurve {
        NurbsCurve::try_new(1, alloc::vec![0.0, 0.0, 1.0, 1.0], alloc::vec![p.extend(0.0), q.extend(0.0)], None)
            .unwrap()
    }

    /// A quadratic Bézier in (u,v) from `p` over control `c` to `q`.
    fn arc(p: DVec2, c: DVec2, q: DVec2) -> NurbsCurve {
        let pts = alloc::vec![p.extend(0.0), c.extend(0.0), q.extend(0.0)];
        NurbsCurve::try_new(2, alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts, None).unwrap()
    }

    /// One loop per entry, each of whole curves (one chord each) with their node ids.
    fn outline<'a>(curves: &'a [NurbsCurve], loops: &[&[(usize, u32)]]) -> Outline<'a> {
        let mut polys = Vec::new();
        let mut gids = Vec::new();
        for l in loops {
            let mut poly = Polyline::default();
            for &(c, _) in l.iter() {
                poly.uv.push(curves[c].point(0.0).truncate());
                poly.at.push(CurveRef { curve: c as u32, t: 0.0 });
                poly.seg.push((c as u32, 0.0, 1.0));
            }
            polys.push(poly);
            gids.push(l.iter().map(|x| x.1).collect());
        }
        let loops = Loops { polys, curves: curves.iter().collect(), mended: None };
        Outline { loops, pu: Vec::new(), pv: Vec::new(), gids, crossed: false }
    }

    /// A face below an arc, with a hole that pokes up through the arc's
    /// chord but not through the arc; the face above shares the arc. The
    /// arc is halved in both faces under one new id, after which nothing
    /// crosses. The two hole sides it crossed are halved too (in one round:
    /// three new ids), which changes nothing on a line.
    #[test]
    fn a_chord_crossing_a_hole_is_halved_in_both_faces() {
        let plane = crate::nurbs::analytic::xy_plane(10.0);
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let below = [
            line(p(-1.0, -1.0), p(1.0, -1.0)),
            line(p(1.0, -1.0), p(1.0, 0.0)),
            arc(p(1.0, 0.0), p(0.0, 2.0), p(-1.0, 0.0)),
            line(p(-1.0, 0.0), p(-1.0, -1.0)),
            // The hole, clockwise.
            line(p(-0.2, -0.2), p(0.0, 0.4)),
            line(p(0.0, 0.4), p(0.2, -0.2)),
            line(p(0.2, -0.2), p(-0.2, -0.2)),
        ];
        let above = [
            arc(p(-1.0, 0.0), p(0.0, 2.0), p(1.0, 0.0)),
            line(p(1.0, 0.0), p(1.0, 3.0)),
            line(p(1.0, 3.0), p(-1.0, 3.0)),
            line(p(-1.0, 3.0), p(-1.0, 0.0)),
        ];
        let mut a = outline(&below, &[&[(0, 0), (1, 1), (2, 2), (3, 3)], &[(4, 4), (5, 5), (6, 6)]]);
        let mut b = outline(&above, &[&[(0, 3), (1, 2), (2, 7), (3, 8)]]);
        assert!(crossings(&a.loops, |_| true).is_some(), "the test's chords must cross");
        let ids = {
            let mut faces = alloc::vec![Some((&plane as &dyn Surface, &mut a)), Some((&plane as &dyn Surface, &mut b))];
            split_crossing_chords(&mut faces, 9)
        };
        assert_eq!(ids, 12, "the arc and the two hole sides it crossed, once each");
        assert!(crossings(&a.loops, |_| true).is_none());
        // The arc's node (the first segment by ids) sits on its top in
        // both faces, under id 9.
        for (o, k) in [(&a, 3), (&b, 1)] {
            let at = o.gids[0].iter().position(|&g| g == 9).expect("the new node");
            assert_eq!(at, k, "{:?}", o.gids[0]);
            assert!(o.loops.polys[0].uv[at].distance(p(0.0, 1.0)) < 1e-9, "{:?}", o.loops.polys[0].uv);
        }
    }

    /// A crescent between two arcs from one tip `T`, as one face: at the
    /// tip the left side's curve bends past the right side's chord, though
    /// the three chords make a triangle. Both are halved until no halving
    /// of one would cross the other, and the loop crosses nowhere.
    fn crescent() -> [NurbsCurve; 3] {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        [
            arc(p(0.0, 0.0), p(2.0, 5.0), p(0.0, 10.0)),
            line(p(0.0, 10.0), p(-1.0, 10.0)),
            arc(p(-1.0, 10.0), p(1.6, 5.0), p(0.0, 0.0)),
        ]
    }

    /// Each segment's (u,v) middle on its curve.
    fn middles<'a>(o: &'a Outline<'_>) -> impl Fn(usize, usize) -> Option<DVec2> + 'a {
        |k, i| {
            let (c, ta, tb) = o.loops.polys[k].seg[i];
            Some(o.loops.curves[c as usize].point(0.5 * (ta + tb)).truncate())
        }
    }

    #[test]
    fn chords_of_a_spike_narrower_than_their_sag_are_halved() {
        let plane = crate::nurbs::analytic::xy_plane(20.0);
        let curves = crescent();
        let mut a = outline(&curves, &[&[(0, 0), (1, 1), (2, 2)]]);
        assert!(crossings(&a.loops, |_| true).is_none(), "the test's chords must not cross");
        assert!(
            bulge_crossings(&a.loops, middles(&a), |_, _| true),
            "the left arc's halves must cross the right chord"
        );
        let ids = {
            let mut faces = alloc::vec![Some((&plane as &dyn Surface, &mut a))];
            split_crossing_chords(&mut faces, 3)
        };
        assert!(ids > 3, "both arcs are halved");
        assert!(!bulge_crossings(&a.loops, middles(&a), |_, _| true), "{:?}", a.loops.polys[0].uv);
        assert!(crossings(&a.loops, |_| true).is_none());
        assert_eq!(a.gids[0].len(), a.loops.polys[0].uv.len());
    }

    /// The crescent's right arc runs along a neighbour whose border there
    /// has other ids (a tip sewing did not join): the neighbour would not
    /// take a node on it, so neither arc is halved for bulging.
    #[test]
    fn a_bulging_chord_beside_another_faces_border_is_kept() {
        let plane = crate::nurbs::analytic::xy_plane(20.0);
        let curves = crescent();
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let beside = [
            line(p(0.0, 0.0), p(5.0, 0.0)),
            line(p(5.0, 0.0), p(5.0, 12.0)),
            arc(p(5.0, 12.0), p(2.0, 5.0), p(0.0, 0.0)),
        ];
        let mut a = outline(&curves, &[&[(0, 0), (1, 1), (2, 2)]]);
        let mut b = outline(&beside, &[&[(0, 0), (1, 7), (2, 8)]]);
        let before = a.loops.polys[0].uv.clone();
        let ids = {
            let mut faces = alloc::vec![Some((&plane as &dyn Surface, &mut a)), Some((&plane as &dyn Surface, &mut b))];
            split_crossing_chords(&mut faces, 9)
        };
        assert_eq!(ids, 9);
        assert_eq!(a.loops.polys[0].uv, before);
    }
}
