//! Closing the slivers sewing leaves where three faces almost meet.
//!
//! Three faces whose corners miss one another by less than the sewing
//! distance can leave a thin triangular hole between them: each pair of
//! borders is sewn along its length, but the corners are nodes of
//! different faces, too far apart within one face to be one. The hole is
//! three border edges, each used once in the whole model, that close a
//! loop (faces need not agree on their orientation). It is closed by one triangle in the face along whose
//! border it lies longest, if that triangle passes that face's limits
//! (paper 000 §3.3: both sides of a shared border use the same nodes; here
//! the third node joins the face that lacks it).

use crate::collections::HashMap;
use alloc::vec::Vec;
use glam::DVec3;

use super::sew::FaceWork;

const NONE: u32 = u32::MAX;

/// One border edge of a face: face, local ends (run a→b by its triangle),
/// and their model node ids.
#[derive(Clone, Copy)]
struct Side {
    face: u32,
    a: u32,
    b: u32,
    ga: u32,
    gb: u32,
}

/// Closes every triangular hole between faces narrower than `width`;
/// returns how many it closed.
pub(crate) fn close_slivers(faces: &mut [FaceWork<'_>], width: f64) -> usize {
    if width.is_nan() || width <= 0.0 {
        return 0;
    }
    // Border edges whose ends are model nodes, and how often each pair of
    // nodes is a border edge anywhere (twice: two faces meet there).
    let mut sides: Vec<Side> = Vec::new();
    let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
    for (fi, f) in faces.iter().enumerate() {
        let m = &f.mesh;
        for t in &m.tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (ga, gb) = (m.gid[a as usize], m.gid[b as usize]);
                if ga == NONE || gb == NONE || ga == gb || m.edge_triangles(a, b) != 1 {
                    continue;
                }
                sides.push(Side { face: fi as u32, a, b, ga, gb });
                *uses.entry((ga.min(gb), ga.max(gb))).or_default() += 1;
            }
        }
    }
    let open: Vec<Side> =
        sides.into_iter().filter(|s| uses.get(&(s.ga.min(s.gb), s.ga.max(s.gb))) == Some(&1)).collect();
    // Faces need not agree on orientation, so the hole's sides are joined
    // by their nodes, whichever way each runs.
    let mut at_node: HashMap<u32, Vec<usize>> = HashMap::default();
    for (i, s) in open.iter().enumerate() {
        at_node.entry(s.ga).or_default().push(i);
        at_node.entry(s.gb).or_default().push(i);
    }
    let other = |s: &Side, g: u32| if s.ga == g { s.gb } else { s.ga };
    let pos_of = |faces: &[FaceWork<'_>], s: &Side, g: u32| -> DVec3 {
        faces[s.face as usize].mesh.pos[(if s.ga == g { s.a } else { s.b }) as usize]
    };
    let mut used = alloc::vec![false; open.len()];
    let mut closed = 0;
    for i in 0..open.len() {
        let s1 = open[i];
        let (n1, n2) = (s1.ga.min(s1.gb), s1.ga.max(s1.gb));
        let Some(next) = at_node.get(&n2) else { continue };
        'hole: for &j in next {
            // Each hole once: from its lowest node, by its side there.
            let n3 = other(&open[j], n2);
            if used[i] || j == i || used[j] || n3 <= n1 {
                continue;
            }
            let Some(k) = at_node
                .get(&n3)
                .and_then(|l| l.iter().copied().find(|&k| k != j && !used[k] && other(&open[k], n3) == n1))
            else {
                continue;
            };
            let (s2, s3) = (open[j], open[k]);
            if s1.face == s2.face && s2.face == s3.face {
                continue; // a hole in one face is its own
            }
            let p = [pos_of(faces, &s1, n1), pos_of(faces, &s2, n2), pos_of(faces, &s3, n3)];
            let len = [p[0].distance(p[1]), p[1].distance(p[2]), p[2].distance(p[0])];
            let longest = len.iter().copied().fold(0.0, f64::max);
            let area2 = (p[1] - p[0]).cross(p[2] - p[0]).length();
            if area2 / longest.max(f64::MIN_POSITIVE) > width {
                continue;
            }
            // Into the face along whose border it lies longest, else the next.
            let mut order = [(len[0], s1, p[2], n3), (len[1], s2, p[0], n1), (len[2], s3, p[1], n2)];
            order.sort_by(|x, y| y.0.total_cmp(&x.0));
            for (_, s, q, g) in order {
                let f = &mut faces[s.face as usize];
                if f.mesh.close_beside(f.surface, &f.crit, s.a, s.b, q, g) {
                    closed += 1;
                    (used[i], used[j], used[k]) = (true, true, true);
                    break 'hole;
                }
            }
        }
    }
    closed
}
