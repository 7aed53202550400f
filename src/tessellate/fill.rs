//! Closing the slivers sewing leaves where faces' corners miss.
//!
//! Three faces whose corners miss one another by more than the sewing
//! distance can leave a thin hole between them: each pair of borders is
//! sewn along its length, but the corners are nodes of different faces,
//! too far apart within one face to be one. The hole is a loop of three to
//! [`MAX_SIDES`] border edges, each used once in the whole model, through
//! at least two faces (which need not agree on their orientation). It is
//! closed by triangles in the faces along whose borders it lies, each kept
//! only if it faces the surface's way and passes that face's limits
//! (paper 000 §3.3: both sides of a shared border use the same nodes; here
//! a node joins the face that lacks it).

use crate::collections::HashMap;
use alloc::vec::Vec;
use glam::DVec3;

use super::sew::FaceWork;

const NONE: u32 = u32::MAX;
/// The most sides a hole closed here may have.
const MAX_SIDES: usize = 8;

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

/// Closes every hole of three to [`MAX_SIDES`] sides between faces
/// narrower than `width`; returns how many triangles it added. A hole of
/// more sides takes one triangle on its longest side per pass.
pub(crate) fn close_slivers(faces: &mut [FaceWork<'_>], width: f64) -> usize {
    if width.is_nan() || width <= 0.0 {
        return 0;
    }
    let mut added = 0;
    for _ in 0..2 * MAX_SIDES {
        let (open, at_node) = open_sides(faces);
        // Longer loops only on sides the triangles left as they were.
        let mut n = close_triangles(faces, &open, &at_node, width);
        if n == 0 {
            n = close_polygons(faces, &open, &at_node, width);
        }
        added += n;
        if n == 0 {
            break;
        }
    }
    added
}

/// Border edges used once in the whole model, and the edges at each node.
fn open_sides(faces: &[FaceWork<'_>]) -> (Vec<Side>, HashMap<u32, Vec<usize>>) {
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
    (open, at_node)
}

/// The node at the other end of `s` from `g`.
fn other(s: &Side, g: u32) -> u32 {
    if s.ga == g {
        s.gb
    } else {
        s.ga
    }
}

/// Where `s`'s face has node `g` (one of its ends).
fn pos_of(faces: &[FaceWork<'_>], s: &Side, g: u32) -> DVec3 {
    faces[s.face as usize].mesh.pos[(if s.ga == g { s.a } else { s.b }) as usize]
}

/// Twice the area over the longest side: how wide a triangle is.
fn width_of(p: [DVec3; 3]) -> f64 {
    let longest = (0..3).map(|k| p[k].distance(p[(k + 1) % 3])).fold(0.0, f64::max);
    (p[1] - p[0]).cross(p[2] - p[0]).length() / longest.max(f64::MIN_POSITIVE)
}

/// Three-sided holes.
fn close_triangles(faces: &mut [FaceWork<'_>], open: &[Side], at_node: &HashMap<u32, Vec<usize>>, width: f64) -> usize {
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
            if width_of(p) > width {
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

/// Holes of four to [`MAX_SIDES`] sides, each node on two of them: one
/// triangle on the longest side, to the nearer of the two corners beside
/// it (the shorter diagonal), if every triangle that clipping it so would
/// take is narrower than `width`; the rest is a hole of one side fewer.
fn close_polygons(faces: &mut [FaceWork<'_>], open: &[Side], at_node: &HashMap<u32, Vec<usize>>, width: f64) -> usize {
    let mut used = alloc::vec![false; open.len()];
    let mut closed = 0;
    for i in 0..open.len() {
        if used[i] {
            continue;
        }
        // Walk the loop from side i, through nodes on exactly two sides.
        let (start, mut node) = (open[i].ga, open[i].gb);
        let (mut sides, mut nodes) = (alloc::vec![i], alloc::vec![start]);
        let mut prev = i;
        while node != start && sides.len() <= MAX_SIDES {
            let Some(at) = at_node.get(&node).filter(|l| l.len() == 2) else { break };
            let next = if at[0] == prev { at[1] } else { at[0] };
            nodes.push(node);
            sides.push(next);
            node = other(&open[next], node);
            prev = next;
        }
        let n = sides.len();
        if node != start || !(4..=MAX_SIDES).contains(&n) || sides.iter().any(|&k| used[k]) {
            continue;
        }
        if sides.iter().all(|&k| open[k].face == open[i].face) {
            continue;
        }
        // Side m runs from corner m to corner m + 1.
        let p: Vec<DVec3> = (0..n).map(|m| pos_of(faces, &open[sides[m]], nodes[m])).collect();
        // Longest side first; where its face refuses the ear, the next.
        let mut by_length: Vec<usize> = (0..n).collect();
        by_length.sort_by(|&x, &y| p[y].distance(p[(y + 1) % n]).total_cmp(&p[x].distance(p[(x + 1) % n])));
        for m in by_length {
            let Some(far) = ear(&p, m, width) else { continue };
            let s = open[sides[m]];
            let f = &mut faces[s.face as usize];
            if f.mesh.close_beside(f.surface, &f.crit, s.a, s.b, p[far], nodes[far]) {
                closed += 1;
                for &k in &sides {
                    used[k] = true;
                }
                break;
            }
        }
    }
    closed
}

/// The far corner of the ear on side `first` of polygon `p` (side m runs
/// from corner m to m + 1), if that ear and every later one, each on the
/// longest side left, are narrower than `width`; an ear goes to the nearer
/// of the two corners beside its side (the shorter diagonal).
fn ear(p: &[DVec3], first: usize, width: f64) -> Option<usize> {
    let mut ring: Vec<usize> = (0..p.len()).collect();
    let mut chosen = None;
    while ring.len() >= 3 {
        let n = ring.len();
        let side = |m: usize| p[ring[m]].distance(p[ring[(m + 1) % n]]);
        let m = if chosen.is_none() { first } else { (0..n).max_by(|&x, &y| side(x).total_cmp(&side(y)))? };
        let (x, y, z, w) = (ring[m], ring[(m + 1) % n], ring[(m + 2) % n], ring[(m + n - 1) % n]);
        let (far, drop) = if n == 3 || p[x].distance(p[z]) <= p[y].distance(p[w]) { (z, (m + 1) % n) } else { (w, m) };
        if width_of([p[x], p[y], p[far]]) > width {
            return None;
        }
        chosen.get_or_insert(far);
        ring.remove(drop);
    }
    chosen
}
