//! Collapsing a face's edges whose two ends are one point.
//!
//! A pole's loop nodes, or the two ends of a side collapsed to a hair, stay
//! two vertices while the face is built and refined (each end has its own
//! (u,v)); sewing then puts both on the one model node they name. The
//! triangle on such an edge has no area: a viewer gets a NaN normal from it
//! and it is every quality measure's worst triangle. Here each such edge is
//! collapsed and its triangles dropped, where that keeps the face a manifold.

use alloc::vec::Vec;
use glam::DVec3;

use crate::collections::HashMap;

/// Whether `a` and `b` are one point up to rounding (also how the band of a
/// trimmed face judges a loop segment's two ends).
pub(crate) fn one_point(a: DVec3, b: DVec3) -> bool {
    a.distance(b) <= 1e-12 * a.abs().max(b.abs()).max_element().max(1.0)
}

/// Collapses every edge of `tris` whose ends are one point in `pos`, in
/// place, and drops the triangles on it. An edge is left alone when its
/// collapse would join the face to itself elsewhere (its ends share a
/// neighbour that is not a corner of a triangle on the edge, or both ends
/// lie on the border while the edge does not). Returns the triangles dropped.
pub(crate) fn collapse_point_edges(pos: &[DVec3], tris: &mut Vec<[u32; 3]>) -> usize {
    let at = |v: u32| pos.get(v as usize).copied();
    collapse_edges(tris, |a, b| matches!((at(a), at(b)), (Some(p), Some(q)) if one_point(p, q)))
}

/// [`collapse_point_edges`] for the edges `same` holds for: a trial mesh,
/// not yet sewn, judges its shape by the edges sewing will make one point.
pub(crate) fn collapse_edges(tris: &mut Vec<[u32; 3]>, same: impl Fn(u32, u32) -> bool) -> usize {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for t in tris.iter() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b && same(a, b) {
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    if edges.is_empty() {
        return 0;
    }
    crate::sort::pairs(&mut edges);
    edges.dedup();
    // The triangles at each end of a candidate edge: all a collapse looks at.
    let mut around: HashMap<u32, Vec<u32>> = HashMap::default();
    for &(a, b) in &edges {
        around.entry(a).or_default();
        around.entry(b).or_default();
    }
    for (i, t) in tris.iter().enumerate() {
        for v in t {
            if let Some(list) = around.get_mut(v) {
                list.push(i as u32);
            }
        }
    }
    let mut dropped = alloc::vec![false; tris.len()];
    // Where each collapsed vertex went (chains end at a kept vertex).
    let mut moved: HashMap<u32, u32> = HashMap::default();
    let find = |moved: &HashMap<u32, u32>, mut v: u32| {
        while let Some(&w) = moved.get(&v) {
            v = w;
        }
        v
    };
    let mut count = 0;
    for &(a0, b0) in &edges {
        let (a, b) = (find(&moved, a0), find(&moved, b0));
        if a == b {
            continue;
        }
        let live = |v: u32| -> Vec<u32> {
            around.get(&v).map(|l| l.iter().copied().filter(|&i| !dropped[i as usize]).collect()).unwrap_or_default()
        };
        let (ta, tb) = (live(a), live(b));
        let on_edge: Vec<u32> = ta.iter().copied().filter(|&i| tris[i as usize].contains(&b)).collect();
        if on_edge.is_empty() || on_edge.len() > 2 {
            continue;
        }
        let apexes: Vec<u32> =
            on_edge.iter().filter_map(|&i| tris[i as usize].iter().copied().find(|&v| v != a && v != b)).collect();
        let ring = |list: &[u32], me: u32| -> Vec<u32> {
            let mut r: Vec<u32> = list.iter().flat_map(|&i| tris[i as usize]).filter(|&v| v != me).collect();
            r.sort_unstable();
            r.dedup();
            r
        };
        let (ra, rb) = (ring(&ta, a), ring(&tb, b));
        let common = ra.iter().filter(|&&v| v != b && rb.binary_search(&v).is_ok()).count();
        if common != apexes.len() {
            continue;
        }
        let border = |list: &[u32], me: u32| {
            let mut seen: Vec<(u32, u32)> = Vec::new();
            for &i in list {
                for &v in &tris[i as usize] {
                    if v != me {
                        seen.push((v, i));
                    }
                }
            }
            crate::sort::pairs(&mut seen);
            // An edge from `me` with one triangle: `me` is on the border.
            let mut k = 0;
            let mut any = false;
            while k < seen.len() {
                let n = seen[k..].iter().take_while(|s| s.0 == seen[k].0).count();
                any |= n == 1;
                k += n;
            }
            any
        };
        if on_edge.len() == 2 && border(&ta, a) && border(&tb, b) {
            continue;
        }
        for &i in &on_edge {
            dropped[i as usize] = true;
            count += 1;
        }
        for &i in &tb {
            if !dropped[i as usize] {
                for v in tris[i as usize].iter_mut() {
                    if *v == b {
                        *v = a;
                    }
                }
            }
        }
        let mut merged = ta;
        merged.extend(tb.iter().copied().filter(|&i| !dropped[i as usize]));
        around.insert(a, merged);
        moved.insert(b, a);
    }
    if count > 0 {
        let mut i = 0;
        tris.retain(|_| {
            i += 1;
            !dropped[i - 1]
        });
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fan about a pole whose two loop ends were sewn onto one point:
    /// the one triangle on that edge goes, the rest keep their corners.
    #[test]
    fn a_pole_edge_collapses_and_its_sliver_goes() {
        // 0 and 1 are the pole (one point), 2..5 a ring below it; the
        // border runs 2-0-1-5 and on around the ring.
        let pos = [
            DVec3::ZERO,
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 1.0, -1.0),
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(0.0, -1.0, -1.0),
        ];
        let mut tris = alloc::vec![[0, 2, 3], [0, 3, 4], [0, 4, 1], [1, 4, 5]];
        assert_eq!(collapse_point_edges(&pos, &mut tris), 1);
        assert_eq!(tris.len(), 3);
        assert!(tris.iter().all(|t| !t.contains(&1)), "vertex 1 folded into 0: {tris:?}");
        for t in &tris {
            let area =
                (pos[t[1] as usize] - pos[t[0] as usize]).cross(pos[t[2] as usize] - pos[t[0] as usize]).length();
            assert!(area > 0.1, "a triangle without area is left: {t:?}");
        }
    }

    /// Two border vertices at one point joined by an inner edge: collapsing
    /// it would pinch the face into two, so it stays.
    #[test]
    fn an_inner_edge_between_border_points_stays() {
        // A strip 0-1-2 / 3-4-5 whose middle column 1,4 is one point.
        let pos = [
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::ZERO,
            DVec3::new(1.0, -1.0, 0.0),
        ];
        let mut tris = alloc::vec![[0, 3, 4], [0, 4, 1], [1, 4, 5], [1, 5, 2]];
        assert_eq!(collapse_point_edges(&pos, &mut tris), 0);
        assert_eq!(tris.len(), 4);
    }

    /// Points apart by more than rounding are not one point.
    #[test]
    fn a_short_edge_is_not_a_point() {
        let pos = [DVec3::ZERO, DVec3::new(1e-9, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let mut tris = alloc::vec![[0, 1, 2]];
        assert_eq!(collapse_point_edges(&pos, &mut tris), 0);
        assert_eq!(tris.len(), 1);
    }
}
