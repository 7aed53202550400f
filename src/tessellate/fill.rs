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

use super::refine::{key, NONE};
use super::sew::FaceWork;
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
/// more sides takes one triangle on its longest side per pass. Then two
/// faces' triangles on the same three nodes go ([`remove_shared_triangles`]).
pub(crate) fn close_slivers(faces: &mut [FaceWork<'_>], width: f64) -> usize {
    if width.is_nan() || width <= 0.0 {
        return 0;
    }
    remove_flaps(faces, width);
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
    remove_shared_triangles(faces);
    added
}

/// Removes narrow flaps: a triangle with one side inside its face and two
/// on its border, one of those used by no other face and the other by two
/// others already, whose corner between them no other triangle of its face
/// has. Such a triangle reaches past where its neighbours meet (a strip
/// narrower than the sewing distance was sewn shut beside it); without it
/// its inner side is the border, and what is left open beside that is a
/// hole the passes after close. Returns how many it removed.
fn remove_flaps(faces: &mut [FaceWork<'_>], width: f64) -> usize {
    let uses = border_uses(faces);
    let used = |m: &super::refine::WorkMesh, a: u32, b: u32| {
        let (ga, gb) = (m.gid[a as usize], m.gid[b as usize]);
        if ga == NONE || gb == NONE || ga == gb {
            return 0;
        }
        uses.get(&key(ga, gb)).copied().unwrap_or(0)
    };
    let mut removed = 0;
    for f in faces.iter_mut() {
        let m = &f.mesh;
        let mut flaps: Vec<(usize, u32, u32)> = Vec::new();
        for (t, v) in m.tris.iter().enumerate() {
            // Corner k is the apex: sides k-1→k and k→k+1 on the border.
            for k in 0..3 {
                let (prev, apex, next) = (v[(k + 2) % 3], v[k], v[(k + 1) % 3]);
                // The border sides first: at rest an inner side is counted by a walk.
                if !m.is_border(prev, apex) || !m.is_border(apex, next) || m.edge_triangles(prev, next) != 2 {
                    continue;
                }
                let (u1, u2) = (used(m, prev, apex), used(m, apex, next));
                if !((u1 == 1 && u2 >= 3) || (u1 >= 3 && u2 == 1)) {
                    continue;
                }
                let p = v.map(|x| m.pos[x as usize]);
                if crate::math::triangle_width(p) > width || m.tris.iter().filter(|w| w.contains(&apex)).count() != 1 {
                    continue;
                }
                flaps.push((t, prev, next));
                break;
            }
        }
        // Highest first: removing one moves only the last triangle.
        for &(t, prev, next) in flaps.iter().rev() {
            f.mesh.remove_triangle(t);
            // Its inner side is now the border, along the neighbours' gap.
            f.mesh.shared.insert(key(prev, next), ());
            removed += 1;
        }
    }
    removed
}

/// Removes each pair of triangles of two faces on the same three model
/// nodes where that leaves each of their sides with two triangles or none.
/// A hole closed in one face where another face's triangles already span
/// the place (a node of the other face's second loop, nearer than the
/// sewing distance, was sewn into the first face's border) lies on the
/// other face: both triangles enclose nothing, and each of their sides
/// counts four triangles, or only their two. Returns how many it removed.
fn remove_shared_triangles(faces: &mut [FaceWork<'_>]) -> usize {
    // Triangles by their three nodes, and how many triangles have each node pair.
    let mut by_nodes: HashMap<[u32; 3], Vec<(u32, u32)>> = HashMap::default();
    let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
    for (fi, f) in faces.iter().enumerate() {
        let m = &f.mesh;
        for (t, v) in m.tris.iter().enumerate() {
            let mut g = v.map(|x| m.gid[x as usize]);
            for k in 0..3 {
                let (ga, gb) = (g[k], g[(k + 1) % 3]);
                if ga != NONE && gb != NONE && ga != gb {
                    *uses.entry(key(ga, gb)).or_default() += 1;
                }
            }
            g.sort_unstable();
            if g[0] != NONE && g[2] != NONE && g[0] != g[1] && g[1] != g[2] {
                by_nodes.entry(g).or_default().push((fi as u32, t as u32));
            }
        }
    }
    let mut keys: Vec<(u32, u32, u32)> =
        by_nodes.iter().filter(|(_, l)| l.len() == 2).map(|(k, _)| (k[0], k[1], k[2])).collect();
    crate::sort::triples(&mut keys);
    let mut gone: Vec<(u32, u32)> = Vec::new();
    for (a, b, c) in keys {
        let g = [a, b, c];
        let pair = &by_nodes[&g];
        if pair[0].0 == pair[1].0 {
            continue;
        }
        let sides = [(g[0], g[1]), (g[1], g[2]), (g[0], g[2])];
        let counts = sides.map(|e| uses.get(&e).copied().unwrap_or(0));
        // Only the pair on every side is a body of two triangles: it stays.
        if !counts.iter().all(|&u| u == 2 || u == 4) || !counts.contains(&4) {
            continue;
        }
        for e in sides {
            if let Some(u) = uses.get_mut(&e) {
                *u -= 2;
            }
        }
        gone.extend_from_slice(pair);
    }
    // Highest first within each face: removing one moves only the last triangle.
    crate::sort::pairs(&mut gone);
    for &(f, t) in gone.iter().rev() {
        let m = &mut faces[f as usize].mesh;
        let v = m.tris[t as usize];
        m.remove_triangle(t as usize);
        // A side left on the border runs along the other face's.
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if m.edge_triangles(a, b) == 1 {
                m.shared.insert(key(a, b), ());
            }
        }
    }
    gone.len()
}

/// Calls `visit` with every border edge whose ends are two different model
/// nodes, face by face.
fn each_border_side(faces: &[FaceWork<'_>], mut visit: impl FnMut(Side)) {
    for (fi, f) in faces.iter().enumerate() {
        let m = &f.mesh;
        for t in &m.tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (ga, gb) = (m.gid[a as usize], m.gid[b as usize]);
                if ga == NONE || gb == NONE || ga == gb || !m.is_border(a, b) {
                    continue;
                }
                visit(Side { face: fi as u32, a, b, ga, gb });
            }
        }
    }
}

/// How often each pair of nodes is a border edge anywhere (twice: two
/// faces meet there). Counted, not listed: a list of every border edge
/// of the model was the largest thing allocated while all faces are held.
fn border_uses(faces: &[FaceWork<'_>]) -> HashMap<(u32, u32), u32> {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
    each_border_side(faces, |s| *uses.entry((s.ga.min(s.gb), s.ga.max(s.gb))).or_default() += 1);
    uses
}

/// Border edges used once in the whole model, and the edges at each node.
fn open_sides(faces: &[FaceWork<'_>]) -> (Vec<Side>, HashMap<u32, Vec<usize>>) {
    let uses = border_uses(faces);
    let mut open: Vec<Side> = Vec::new();
    each_border_side(faces, |s| {
        if uses.get(&(s.ga.min(s.gb), s.ga.max(s.gb))) == Some(&1) {
            open.push(s);
        }
    });
    drop(uses);
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
            if crate::math::triangle_width(p) > width {
                continue;
            }
            // Into the face along whose border it lies longest, else the next.
            let mut order = [(len[0], s1, p[2], n3), (len[1], s2, p[0], n1), (len[2], s3, p[1], n2)];
            crate::sort::by_f64_desc(&mut order, |o| o.0);
            for (_, s, q, g) in order {
                let f = &mut faces[s.face as usize];
                if f.mesh.close_beside(f.surface, &f.crit, s.a, s.b, q, g) {
                    closed += 1;
                    (used[i], used[j], used[k]) = (true, true, true);
                    break 'hole;
                }
            }
            // No face takes the triangle the right way up: the corner across
            // the longest side pokes over it (the two other sides overlap
            // that side's face), so that side takes the corner as its node.
            let (_, s, q, g) = order[0];
            let f = &mut faces[s.face as usize];
            if f.mesh.split_border_at(f.surface, &f.crit, s.a, s.b, q, g) {
                closed += 1;
                (used[i], used[j], used[k]) = (true, true, true);
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
        crate::sort::by_f64_desc(&mut by_length, |&x| p[x].distance(p[(x + 1) % n]));
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
        if crate::math::triangle_width([p[x], p[y], p[far]]) > width {
            return None;
        }
        chosen.get_or_insert(far);
        ring.remove(drop);
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellate::refine::{Criteria, WorkMesh};
    use glam::DVec2;

    /// The plane z = 0 over [-20, 20]², u = x and v = y.
    fn plane() -> crate::nurbs::NurbsSurface {
        crate::nurbs::analytic::xy_plane(20.0)
    }

    const CRIT: Criteria = Criteria::PLANE_TEST;

    /// A face on the plane: its points with their model node ids (`NONE`
    /// inside) and its triangles, counter-clockwise.
    fn mesh(points: &[(f64, f64, u32)], tris: &[[u32; 3]]) -> WorkMesh {
        let mut m = WorkMesh::default();
        for &(x, y, g) in points {
            let v = m.add_vertex(DVec3::new(x, y, 0.0), DVec3::Z);
            m.gid[v as usize] = g;
        }
        for t in tris {
            m.add_triangle(*t, t.map(|v| DVec2::new(points[v as usize].0, points[v as usize].1)));
        }
        m
    }

    /// The lower face's border node 3 pokes 0.03 over the upper face's
    /// border 1-2: no triangle between them faces the plane's way, so the
    /// upper face's border takes node 3, and no border edge is left unpaired.
    #[test]
    fn a_corner_poking_over_a_border_becomes_its_node() {
        let plane = plane();
        let upper =
            mesh(&[(0.0, 0.0, 1), (10.0, 0.0, 2), (10.0, 10.0, NONE), (0.0, 10.0, NONE)], &[[0, 1, 2], [0, 2, 3]]);
        let lower = mesh(
            &[(0.0, 0.0, 1), (5.0, 0.03, 3), (10.0, 0.0, 2), (0.0, -10.0, NONE), (10.0, -10.0, NONE)],
            &[[3, 4, 2], [3, 2, 1], [3, 1, 0]],
        );
        let work = |mesh| FaceWork { surface: &plane, curves: Vec::new(), mesh, crit: CRIT };
        let mut faces = alloc::vec![work(upper), work(lower)];
        assert_eq!(border_uses(&faces).get(&(1, 2)), Some(&1));
        assert_eq!(close_slivers(&mut faces, 0.1), 1);
        let uses = border_uses(&faces);
        for pair in [(1, 3), (2, 3)] {
            assert_eq!(uses.get(&pair), Some(&2), "{pair:?} is not shared");
        }
        assert!(!uses.contains_key(&(1, 2)));
        for f in &faces {
            for t in 0..f.mesh.tris.len() {
                assert!(!f.mesh.inverted(&plane, t));
            }
        }
        // Poking further over than the width allowed: left as it was.
        let upper =
            mesh(&[(0.0, 0.0, 1), (10.0, 0.0, 2), (10.0, 10.0, NONE), (0.0, 10.0, NONE)], &[[0, 1, 2], [0, 2, 3]]);
        let lower = mesh(
            &[(0.0, 0.0, 1), (5.0, 0.3, 3), (10.0, 0.0, 2), (0.0, -10.0, NONE), (10.0, -10.0, NONE)],
            &[[3, 4, 2], [3, 2, 1], [3, 1, 0]],
        );
        let mut faces = alloc::vec![work(upper), work(lower)];
        assert_eq!(close_slivers(&mut faces, 0.1), 0);
        assert_eq!(faces[0].mesh.tris.len(), 2);
    }

    /// Face A spans from its border 3-2-1 to node 5 of its second loop; the
    /// border of face B, sewn to node 5 instead of node 2, runs 3-2-5-2-1
    /// (a hole closed in it). Both have a triangle on nodes 1, 2, 5: that
    /// pair goes, and every edge between nodes has two triangles or none.
    #[test]
    fn two_faces_on_one_triangle_lose_it() {
        let plane = plane();
        let work = |mesh| FaceWork { surface: &plane, curves: Vec::new(), mesh, crit: CRIT };
        let a = mesh(
            &[(10.0, 0.0, 1), (0.0, 0.0, 2), (-10.0, 0.0, 3), (-3.0, 1.5, 4), (1.0, 0.5, 5), (8.0, 1.5, 6)],
            &[[1, 0, 4], [1, 4, 3], [2, 1, 3], [0, 5, 4]],
        );
        let b = mesh(
            &[(-10.0, 0.0, 3), (0.0, -10.0, NONE), (1.0, 0.5, 5), (10.0, 0.0, 1), (0.0, 0.0, 2), (0.0, 0.0, 2)],
            &[[0, 1, 2], [2, 1, 3], [4, 2, 0], [5, 3, 2]],
        );
        let mut faces = alloc::vec![work(a), work(b)];
        let uses = |faces: &[FaceWork<'_>], pair: (u32, u32)| {
            let mut n = 0;
            for f in faces {
                let m = &f.mesh;
                for t in &m.tris {
                    for k in 0..3 {
                        let (x, y) = (m.gid[t[k] as usize], m.gid[t[(k + 1) % 3] as usize]);
                        n += usize::from((x.min(y), x.max(y)) == pair);
                    }
                }
            }
            n
        };
        assert_eq!([(2, 5), (1, 5)].map(|p| uses(&faces, p)), [4, 4]);
        close_slivers(&mut faces, 0.1);
        assert_eq!([faces[0].mesh.tris.len(), faces[1].mesh.tris.len()], [3, 3]);
        assert_eq!([(2, 5), (1, 5), (1, 2), (2, 3)].map(|p| uses(&faces, p)), [2, 2, 0, 2]);
    }

    /// A narrow triangle reaching past its face's border: one side of it is
    /// used by no other face, the other by two faces that already meet
    /// there. It goes; a triangle whose second side only one other face uses
    /// (a proper shared border) stays.
    #[test]
    fn a_flap_over_where_two_faces_meet_is_removed() {
        let plane = plane();
        let work = |mesh| FaceWork { surface: &plane, curves: Vec::new(), mesh, crit: CRIT };
        // Square 0..10 with a flap on its right side: B (10,0) = 1, apex
        // A (10.03, 5) = 2, D (10, 10) = 3.
        let square = || {
            mesh(
                &[(0.0, 0.0, 4), (10.0, 0.0, 1), (10.03, 5.0, 2), (10.0, 10.0, 3), (0.0, 10.0, 5)],
                &[[0, 1, 3], [0, 3, 4], [1, 2, 3]],
            )
        };
        let beside = |far: f64| mesh(&[(10.03, 5.0, 2), (far, 5.0, NONE), (10.0, 10.0, 3)], &[[0, 1, 2]]);
        // The flap's two border sides are shared edges of the square's mesh.
        let mut flapped = square();
        flapped.shared.insert((1, 2), ());
        flapped.shared.insert((2, 3), ());
        let mut faces = alloc::vec![
            work(flapped),
            work(beside(15.0)),
            work(mesh(&[(10.0, 10.0, 3), (10.0, 15.0, NONE), (10.03, 5.0, 2)], &[[0, 1, 2]]))
        ];
        assert_eq!(border_uses(&faces).get(&(2, 3)), Some(&3));
        assert_eq!(remove_flaps(&mut faces, 0.1), 1);
        assert_eq!(faces[0].mesh.tris.len(), 2);
        // Its sides went with it: no shared edge is left that no triangle has.
        let m = &faces[0].mesh;
        assert!(!m.shared.contains_key(&(1, 2)) && !m.shared.contains_key(&(2, 3)));
        // Its inner side is the border now, along where the other two meet.
        assert!(m.shared.contains_key(&(1, 3)));
        let uses = border_uses(&faces);
        assert_eq!(uses.get(&(2, 3)), Some(&2));
        assert_eq!(uses.get(&(1, 3)), Some(&1));
        assert!(!uses.contains_key(&(1, 2)));
        // One other face on A-D: the flap's sides are shared as they should be.
        let mut faces = alloc::vec![work(square()), work(beside(15.0))];
        assert_eq!(remove_flaps(&mut faces, 0.1), 0);
        assert_eq!(faces[0].mesh.tris.len(), 3);
    }
}
