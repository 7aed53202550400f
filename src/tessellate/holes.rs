//! Closing the three-sided holes fill leaves, by joining a short side's ends.
//!
//! Where three faces' corners miss one another, [`super::fill`] closes the
//! sliver between them with a triangle that one of the faces takes. When
//! none can (the corners cross over, so the triangle would face against
//! every face's surface: two faces overlap there rather than part), the
//! hole stays, and the edge census counts its three sides as cracks. Such a
//! hole is closed here on the assembled mesh: its shortest side's two ends
//! become one point (one end moves onto the other, in every face that has
//! it), so its two other sides fall on one another and join. Paper 000 §6
//! joins faces vertex to vertex; this is the same join, made after the
//! faces were meshed. A move is kept only where no triangle turns over and
//! no edge gets more than two triangles, and only within what the
//! tolerance leaves above the measured deviation: every point of a
//! triangle moves at most as far as its corners do.

use alloc::vec::Vec;
use glam::DVec3;

use crate::collections::HashMap;
use crate::mesh::{FaceRange, Mesh};

/// How many times the holes are looked for again after some were closed
/// (closing one can leave a smaller one beside it).
const ROUNDS: usize = 4;

/// Closes the mesh's three-sided holes narrower than `width` that lie
/// between at least two faces of one body (`body_of(face)`), each by moving
/// its shortest side's one end onto the other, where no vertex moves
/// farther than `room` in all. Points within `weld` are one, as in the edge
/// census. `width` and `weld` are a body at the model's sewing scale's:
/// a face's are those times its `scale` (a small part in an assembly:
/// `sewing_scales`). Returns how far the farthest vertex moved,
/// which bounds what the moves add to the measured deviation.
pub(crate) fn close_short_holes(
    mesh: &mut Mesh,
    body_of: &dyn Fn(u32) -> u32,
    scale: &dyn Fn(u32) -> f64,
    weld: f64,
    width: f64,
    room: f64,
) -> f64 {
    if !(room > 0.0 && width > 0.0) || mesh.indices.is_empty() {
        return 0.0;
    }
    let mut joins = Joins::new(mesh, weld, body_of, scale);
    let mut moved_most: f64 = 0.0;
    for _ in 0..ROUNDS {
        let mut closed = false;
        for (hole, face) in joins.holes(body_of) {
            // Earlier joins of this round may have moved its corners.
            let hole = hole.map(|g| joins.find(g));
            if hole[0] == hole[1] || hole[1] == hole[2] || hole[2] == hole[0] {
                continue;
            }
            let p = hole.map(|g| joins.pos[g as usize]);
            if crate::math::triangle_width(p) > width * scale(face) {
                continue;
            }
            // The shortest side first; its ends each way round.
            let mut sides = [(0, 1), (1, 2), (2, 0)];
            crate::sort::by_f64(&mut sides[..], |&(i, j)| p[i].distance(p[j]));
            let (i, j) = sides[0];
            let (x, y) = (hole[i], hole[j]);
            for (from, to) in [(x, y), (y, x)] {
                if let Some(d) = joins.try_join(from, to, room) {
                    moved_most = moved_most.max(d);
                    closed = true;
                    break;
                }
            }
        }
        if !closed {
            break;
        }
    }
    joins.write_back(mesh);
    moved_most
}

/// The mesh's triangles over welded points, as joins change them.
struct Joins {
    /// Per mesh vertex, its welded point.
    map: Vec<u32>,
    /// Per welded point, where it is, and the point it was joined into.
    pos: Vec<DVec3>,
    parent: Vec<u32>,
    /// Per welded point, how far its vertices moved at most.
    moved: Vec<f64>,
    /// Per triangle, its points (as welded at the start), face, and whether it is kept.
    tris: Vec<[u32; 3]>,
    face: Vec<u32>,
    alive: Vec<bool>,
    /// The triangles at each welded point (those of points joined into it added).
    at: HashMap<u32, Vec<u32>>,
}

impl Joins {
    /// Points within `weld` (times their face's `scale`) are one, those of
    /// different bodies apart (as the edge census takes them: parts that
    /// touch are not joined).
    fn new(mesh: &Mesh, weld: f64, body_of: &dyn Fn(u32) -> u32, scale: &dyn Fn(u32) -> f64) -> Self {
        let count = mesh.indices.len() / 3;
        let mut face = alloc::vec![0u32; count];
        for (f, r) in mesh.face_ranges.iter().enumerate() {
            for slot in face.iter_mut().skip(r.first as usize).take(r.count as usize) {
                *slot = f as u32;
            }
        }
        let mut body = alloc::vec![0u32; mesh.positions.len()];
        for (t, c) in mesh.indices.chunks_exact(3).enumerate() {
            for &v in c {
                if let Some(b) = body.get_mut(v as usize) {
                    *b = body_of(face[t]);
                }
            }
        }
        let (welded, _) = crate::mesh::weld_scaled(mesh, &|t| face[t], scale, weld);
        let mut ids: HashMap<(u32, u32), u32> = HashMap::default();
        let map: Vec<u32> = welded
            .iter()
            .zip(&body)
            .map(|(&g, &b)| {
                let next = ids.len() as u32;
                *ids.entry((g, b)).or_insert(next)
            })
            .collect();
        let n = ids.len();
        drop(ids);
        let mut pos = alloc::vec![DVec3::ZERO; n];
        for (v, &g) in map.iter().enumerate().rev() {
            pos[g as usize] = mesh.positions[v];
        }
        let point = |v: u32| map.get(v as usize).copied().unwrap_or(0);
        let tris: Vec<[u32; 3]> =
            mesh.indices.chunks_exact(3).map(|t| [point(t[0]), point(t[1]), point(t[2])]).collect();
        let alive = tris.iter().map(|&t| three_points(t)).collect();
        Self {
            map,
            parent: (0..n as u32).collect(),
            moved: alloc::vec![0.0; n],
            pos,
            tris,
            face,
            alive,
            at: HashMap::default(),
        }
    }

    /// The point `g` was joined into, in the end.
    fn find(&self, mut g: u32) -> u32 {
        while self.parent[g as usize] != g {
            g = self.parent[g as usize];
        }
        g
    }

    /// Triangle `t`'s points now.
    fn corners(&self, t: u32) -> [u32; 3] {
        self.tris[t as usize].map(|g| self.find(g))
    }

    /// The three-sided holes: loops of three edges each used by one kept
    /// triangle, through at least two faces of one body, each once.
    fn holes(&mut self, body_of: &dyn Fn(u32) -> u32) -> Vec<([u32; 3], u32)> {
        self.index();
        let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::default();
        for t in 0..self.tris.len() as u32 {
            if !self.alive[t as usize] {
                continue;
            }
            let c = self.corners(t);
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                let e = uses.entry((a.min(b), a.max(b))).or_insert((0, self.face[t as usize]));
                e.0 += 1;
            }
        }
        let mut open: HashMap<u32, Vec<(u32, u32)>> = HashMap::default();
        for (&(a, b), &(n, f)) in &uses {
            if n == 1 {
                open.entry(a).or_default().push((b, f));
                open.entry(b).or_default().push((a, f));
            }
        }
        let mut holes = Vec::new();
        let mut firsts: Vec<u32> = open.keys().copied().collect();
        crate::sort::by_u64(&mut firsts, |&a| u64::from(a));
        for a in firsts {
            let Some(from_a) = open.get(&a) else { continue };
            for &(b, f1) in from_a {
                let Some(from_b) = open.get(&b) else { continue };
                for &(c, f2) in from_b {
                    // Each hole once: from its lowest point, its other two in order.
                    if !(a < b && b < c) {
                        continue;
                    }
                    let Some(&(_, f3)) = open.get(&c).and_then(|l| l.iter().find(|x| x.0 == a)) else { continue };
                    let one_face = f1 == f2 && f2 == f3;
                    let one_body = body_of(f1) == body_of(f2) && body_of(f2) == body_of(f3);
                    if !one_face && one_body {
                        holes.push(([a, b, c], f1));
                    }
                }
            }
        }
        holes
    }

    /// Builds the triangles at each point, for the points' current roots.
    fn index(&mut self) {
        self.at.clear();
        for t in 0..self.tris.len() as u32 {
            if self.alive[t as usize] {
                for g in self.corners(t) {
                    self.at.entry(g).or_default().push(t);
                }
            }
        }
    }

    /// Moves point `x` onto point `y` and joins them, if that turns no
    /// triangle over, gives no edge more than two triangles, leaves fewer
    /// edges with one, and moves no vertex farther than `room` in all.
    /// Returns how far `x`'s vertices have moved, in all, when it did.
    fn try_join(&mut self, x: u32, y: u32, room: f64) -> Option<f64> {
        if x == y {
            return None;
        }
        let d = self.moved[x as usize] + self.pos[x as usize].distance(self.pos[y as usize]);
        if d > room {
            return None;
        }
        let around_x: Vec<u32> = self.at.get(&x)?.iter().copied().filter(|&t| self.alive[t as usize]).collect();
        let around_y: Vec<u32> = self.at.get(&y)?.iter().copied().filter(|&t| self.alive[t as usize]).collect();
        let (gone, kept): (Vec<u32>, Vec<u32>) = around_x.iter().partition(|&&t| self.corners(t).contains(&y));
        // x-y must be an edge: its triangles lose their area and go.
        if gone.is_empty() {
            return None;
        }
        // No kept triangle turns over or loses its area.
        let py = self.pos[y as usize];
        for &t in &kept {
            let c = self.corners(t);
            let p = c.map(|g| self.pos[g as usize]);
            let q = c.map(|g| if g == x { py } else { self.pos[g as usize] });
            let (n0, n1) = (facet(p), facet(q));
            if n1.length_squared() == 0.0 || n0.dot(n1) <= 0.0 {
                return None;
            }
        }
        // The edges at y before and after: none used thrice, fewer used once.
        let relabel = |c: [u32; 3]| c.map(|g| if g == x { y } else { g });
        let before = self.edge_uses(around_x.iter().chain(&around_y).copied(), |c| c, x, y);
        let stay = around_y.iter().copied().filter(|t| !gone.contains(t));
        let after = self.edge_uses(kept.iter().copied().chain(stay), relabel, y, y);
        let open = |m: &HashMap<(u32, u32), u32>| m.values().filter(|&&n| n == 1).count();
        if after.values().any(|&n| n > 2) || open(&after) >= open(&before) {
            return None;
        }
        for &t in &gone {
            self.alive[t as usize] = false;
        }
        self.parent[x as usize] = y;
        self.moved[y as usize] = self.moved[y as usize].max(d);
        let mut moved_in = kept;
        self.at.entry(y).or_default().append(&mut moved_in);
        self.at.remove(&x);
        Some(d)
    }

    /// How many of the triangles `ts` (their points relabelled by `label`)
    /// use each edge at point `a` or `b`.
    fn edge_uses(
        &self,
        ts: impl Iterator<Item = u32>,
        label: impl Fn([u32; 3]) -> [u32; 3],
        a: u32,
        b: u32,
    ) -> HashMap<(u32, u32), u32> {
        let mut seen = crate::collections::HashSet::default();
        let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
        for t in ts {
            if !seen.insert(t) {
                continue;
            }
            let c = label(self.corners(t));
            for k in 0..3 {
                let (p, q) = (c[k], c[(k + 1) % 3]);
                if p != q && (p == a || q == a || p == b || q == b) {
                    *uses.entry((p.min(q), p.max(q))).or_default() += 1;
                }
            }
        }
        uses
    }

    /// Writes the joins into `mesh`: each moved vertex at its point's new
    /// place, the triangles that lost their area dropped, face by face.
    fn write_back(self, mesh: &mut Mesh) {
        for (v, &g) in self.map.iter().enumerate() {
            let r = self.find(g);
            if r != g {
                mesh.positions[v] = self.pos[r as usize];
            }
        }
        if self.alive.iter().all(|&a| a) {
            return;
        }
        let mut indices = Vec::with_capacity(mesh.indices.len());
        let mut ranges = Vec::with_capacity(mesh.face_ranges.len());
        for r in &mesh.face_ranges {
            let first = (indices.len() / 3) as u32;
            for t in r.first as usize..(r.first + r.count) as usize {
                // A triangle the weld already collapsed stays as it was.
                if self.alive[t] || !three_points(self.tris[t]) {
                    indices.extend_from_slice(&mesh.indices[3 * t..3 * t + 3]);
                }
            }
            ranges.push(FaceRange { first, count: (indices.len() / 3) as u32 - first });
        }
        mesh.indices = indices;
        mesh.face_ranges = ranges;
    }
}

/// Whether a triangle's corners are three welded points (not collapsed by the weld).
fn three_points(t: [u32; 3]) -> bool {
    t[0] != t[1] && t[1] != t[2] && t[2] != t[0]
}

/// The facet normal of a triangle, not normalized.
fn facet(p: [DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edge_counts;

    /// Face a, a square below y = 0, its top side one edge; face b, a
    /// square above, its bottom side bent up 0.3 through a node at x = 9.5.
    /// The sliver between them has a short side from that node to (10, 0).
    fn bent() -> Mesh {
        let pts = [(0.0, -10.0), (10.0, -10.0), (10.0, 0.0), (0.0, 0.0), (9.5, 0.3), (10.0, 10.0), (0.0, 10.0)];
        let a = [[0u32, 1, 2], [0, 2, 3]];
        let b = [[3u32, 4, 6], [4, 5, 6], [4, 2, 5]];
        Mesh {
            positions: pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect(),
            normals: alloc::vec![DVec3::Z; pts.len()],
            indices: a.iter().chain(&b).flatten().copied().collect(),
            face_ranges: alloc::vec![FaceRange { first: 0, count: 2 }, FaceRange { first: 2, count: 3 }],
        }
    }

    #[test]
    fn a_sliver_s_short_side_is_joined_and_the_hole_closes() {
        let mut m = bent();
        // The two long sides (the short one leaves face a's corner at 31 degrees).
        assert_eq!(edge_counts(&m, 1e-9, 1.0).free_edges, 2);
        let moved = close_short_holes(&mut m, &|_| 0, &|_| 1.0, 1e-9, 1.0, 1.0);
        assert!((moved - 0.5f64.hypot(0.3)).abs() < 1e-12, "{moved}");
        let c = edge_counts(&m, 1e-9, 1.0);
        assert_eq!((c.free_edges, c.nonmanifold_edges), (0, 0));
        assert_eq!(m.triangle_count(), 4, "the triangle on the short side goes");
        assert_eq!(m.face_ranges[1], FaceRange { first: 2, count: 2 });
        // Every triangle still faces +z.
        for t in m.indices.chunks_exact(3) {
            let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            assert!(facet(p).z > 0.0);
        }
    }

    #[test]
    fn a_join_farther_than_the_room_is_not_made() {
        let mut m = bent();
        assert_eq!(close_short_holes(&mut m, &|_| 0, &|_| 1.0, 1e-9, 1.0, 0.5), 0.0);
        assert_eq!(m, bent());
    }

    /// The sliver is 0.3 wide: within a width of 1, not within a body's
    /// share of it a quarter as large (a small part in an assembly whose
    /// tolerance spans its features).
    #[test]
    fn a_hole_wider_than_its_body_s_share_of_the_width_is_left() {
        let mut m = bent();
        assert_eq!(close_short_holes(&mut m, &|_| 0, &|_| 0.25, 1e-9, 1.0, 1.0), 0.0);
        assert_eq!(m, bent());
    }

    #[test]
    fn a_hole_between_two_bodies_is_left() {
        let mut m = bent();
        assert_eq!(close_short_holes(&mut m, &|f| f, &|_| 1.0, 1e-9, 1.0, 1.0), 0.0);
        assert_eq!(m, bent());
    }
}
