//! Step 2 of paper 002: every self-intersection segment with its two
//! triangles (broad phase: k-d tree or BVH; narrow phase: [`super::tritri`]),
//! and the arrangement facts later steps share between triangles: the points
//! where segments end or cross, named by [`PointKey`], with one position each.

use alloc::format;
use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::DVec3;

use super::broad::{bvh_pairs, kd_pairs};
use super::tritri::{contact, Contact, PointKey, Tri};
use super::Bucketing;
use crate::nurbs::Aabb;
use crate::predicates::{side, side_of_crossing};
use crate::Error;

/// One intersection segment: the two triangles (lower id first) and its ends
/// (lower key first).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    pub tris: [u32; 2],
    pub ends: [PointKey; 2],
}

/// All segments, indexed by triangle and by triangle pair.
pub(crate) struct Intersections {
    pub segments: Vec<Segment>,
    /// Segments of triangle `t`: `by_tri[start[t] .. start[t + 1]]`.
    start: Vec<u32>,
    by_tri: Vec<u32>,
    by_pair: crate::collections::HashMap<(u32, u32), u32>,
    /// Pairs whose boxes overlap (narrow-phase tests).
    pub candidates: usize,
    /// Pairs that touch or overlap in a way not handled (coplanar overlap, a
    /// vertex exactly on the other's plane).
    pub degenerate: usize,
    /// Leaves of the k-d tree (0 with the BVH).
    pub leaves: usize,
}

impl Intersections {
    /// Segment ids of triangle `t`.
    pub(crate) fn of(&self, t: u32) -> &[u32] {
        let (a, b) = (self.start[t as usize] as usize, self.start[t as usize + 1] as usize);
        &self.by_tri[a..b]
    }

    /// The segment of a pair of triangles, if they cross.
    pub(crate) fn between(&self, a: u32, b: u32) -> Option<&Segment> {
        let k = if a < b { (a, b) } else { (b, a) };
        self.by_pair.get(&k).map(|&s| &self.segments[s as usize])
    }
}

/// Finds every intersection segment among the live triangles `tris`
/// (`alive[t]`); the others take part in nothing.
///
/// # Errors
/// [`Error::Limit`] when more than `max_segments` segments are found.
pub(crate) fn find_intersections(
    positions: &[DVec3],
    tris: &[[u32; 3]],
    method: Bucketing,
    capacity: usize,
    max_segments: usize,
) -> Result<Intersections, Error> {
    let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::from_points(t.map(|i| positions[i as usize]))).collect();
    let tri = |t: u32| {
        let v = tris[t as usize];
        Tri { id: t, v, p: v.map(|i| positions[i as usize]) }
    };
    let mut segments = Vec::new();
    let mut candidates = 0usize;
    let mut degenerate = 0usize;
    let mut overflow = false;
    let mut test = |a: u32, b: u32| {
        candidates += 1;
        match contact(&tri(a), &tri(b)) {
            Contact::None => {}
            Contact::Degenerate => degenerate += 1,
            Contact::Segment(p, q) => {
                if segments.len() >= max_segments {
                    overflow = true;
                    return;
                }
                let ends = if p < q { [p, q] } else { [q, p] };
                segments.push(Segment { tris: [a.min(b), a.max(b)], ends });
            }
        }
    };
    let leaves = match method {
        Bucketing::KdTree => kd_pairs(&boxes, capacity, &mut test),
        Bucketing::Bvh => {
            bvh_pairs(&boxes, &mut test);
            0
        }
    };
    if overflow {
        return Err(Error::Limit(format!("more than {max_segments} self-intersection segments")));
    }
    // Deterministic order whichever broad phase found them.
    segments.sort_unstable_by_key(|s| s.tris);
    let mut count = alloc::vec![0u32; tris.len() + 1];
    for s in &segments {
        count[s.tris[0] as usize + 1] += 1;
        count[s.tris[1] as usize + 1] += 1;
    }
    for i in 1..count.len() {
        count[i] += count[i - 1];
    }
    let start = count.clone();
    let mut by_tri = alloc::vec![0u32; 2 * segments.len()];
    let mut fill = count;
    let mut by_pair = crate::collections::HashMap::with_capacity_and_hasher(segments.len(), Default::default());
    for (i, s) in segments.iter().enumerate() {
        for t in s.tris {
            by_tri[fill[t as usize] as usize] = i as u32;
            fill[t as usize] += 1;
        }
        by_pair.insert((s.tris[0], s.tris[1]), i as u32);
    }
    Ok(Intersections { segments, start, by_tri, by_pair, candidates, degenerate, leaves })
}

/// Exact side of the plane of triangle `x` at a segment end point (Vertex
/// or EdgeTri); see [`side_of_crossing`].
pub(crate) fn side_at(positions: &[DVec3], tris: &[[u32; 3]], x: u32, p: PointKey) -> Ordering {
    let tp = |t: u32| tris[t as usize].map(|i| positions[i as usize]);
    let xp = tp(x);
    match p {
        PointKey::Vertex(v) => side(&xp, positions[v as usize]),
        PointKey::EdgeTri(a, b, t) => {
            if t == x {
                Ordering::Equal
            } else {
                side_of_crossing(&xp, positions[a as usize], positions[b as usize], &tp(t))
            }
        }
        // Segment ends are never triple points.
        PointKey::Triple(..) => Ordering::Equal,
    }
}

/// Whether a segment's two ends lie strictly on opposite sides of the plane of `x`.
fn crosses_plane(positions: &[DVec3], tris: &[[u32; 3]], s: &Segment, x: u32) -> bool {
    let a = side_at(positions, tris, x, s.ends[0]);
    let b = side_at(positions, tris, x, s.ends[1]);
    a != Ordering::Equal && b != Ordering::Equal && a != b
}

/// Whether triangles `a`, `b`, `c` meet in one point inside all three: each
/// pair's segment crosses the third's plane. Decided from the sorted triple
/// only, so all three triangles get the same answer (exact predicates make
/// any two of the conditions imply the third; all three are asked so that
/// touching cases stay consistent too).
pub(crate) fn triple_exists(positions: &[DVec3], tris: &[[u32; 3]], x: &Intersections, abc: [u32; 3]) -> bool {
    let [a, b, c] = abc;
    let (Some(ab), Some(ac), Some(bc)) = (x.between(a, b), x.between(a, c), x.between(b, c)) else {
        return false;
    };
    // Chained segments (sharing an end) meet at that end, not in a triple point.
    let share = |s: &Segment, t: &Segment| s.ends.iter().any(|e| t.ends.contains(e));
    if share(ab, ac) || share(ab, bc) || share(ac, bc) {
        return false;
    }
    crosses_plane(positions, tris, ab, c)
        && crosses_plane(positions, tris, ac, b)
        && crosses_plane(positions, tris, bc, a)
}

/// Float position of a point, computed the same way wherever it is needed.
pub(crate) fn position(positions: &[DVec3], tris: &[[u32; 3]], x: &Intersections, p: PointKey) -> DVec3 {
    match p {
        PointKey::Vertex(v) => positions[v as usize],
        PointKey::EdgeTri(a, b, t) => {
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            crossing(pa, pb, tris[t as usize].map(|i| positions[i as usize]))
        }
        PointKey::Triple(a, b, c) => match x.between(a, b) {
            Some(s) => {
                let (p0, p1) = (position(positions, tris, x, s.ends[0]), position(positions, tris, x, s.ends[1]));
                crossing(p0, p1, tris[c as usize].map(|i| positions[i as usize]))
            }
            None => positions[tris[a as usize][0] as usize],
        },
    }
}

/// Where the segment `p q` crosses the plane of `t` (clamped to the segment).
fn crossing(p: DVec3, q: DVec3, t: [DVec3; 3]) -> DVec3 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let (dp, dq) = (n.dot(p - t[0]), n.dot(q - t[0]));
    let den = dp - dq;
    let lambda = if den != 0.0 { (dp / den).clamp(0.0, 1.0) } else { 0.5 };
    p + (q - p) * lambda
}

/// Parameter in [0, 1] of the crossing of the plane of `t` along `p q`, for ordering points on a segment.
pub(crate) fn crossing_parameter(p: DVec3, q: DVec3, t: [DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let (dp, dq) = (n.dot(p - t[0]), n.dot(q - t[0]));
    let den = dp - dq;
    if den != 0.0 {
        (dp / den).clamp(0.0, 1.0)
    } else {
        0.5
    }
}
