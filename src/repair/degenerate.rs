//! Step 1 of paper 002: degenerate triangles out. A triangle whose shortest
//! edge is below the zero-length tolerance loses that edge by an edge
//! collapse; one whose smallest angle is below the zero-angle tolerance has
//! its longest edge swapped when it is a cap (a vertex on or near the
//! opposite edge, largest angle obtuse) and, as a needle (two long sides
//! nearly equal), its shortest edge collapsed: swapping a needle's longest
//! edge only makes another needle. Adjacency is kept consistent after each change.

use alloc::vec::Vec;
use glam::DVec3;

use super::topology::NONE;

/// What step 1 did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct DegenerateStats {
    /// Edge collapses (each removes two triangles).
    pub collapses: usize,
    /// Edge swaps.
    pub swaps: usize,
    /// Degenerate triangles that could be neither collapsed nor swapped
    /// without breaking the manifold (e.g. a collapse that would join two sheets).
    pub left: usize,
}

/// A closed mesh being edited: triangles, their neighbours (`3 * t + k`),
/// and which triangles are still alive.
pub(crate) struct EditMesh<'a> {
    pub positions: &'a mut Vec<DVec3>,
    pub tris: &'a mut Vec<[u32; 3]>,
    pub nbr: &'a mut Vec<[u32; 3]>,
    pub alive: Vec<bool>,
}

/// How a triangle is degenerate.
enum Defect {
    /// Collapse edge `k`.
    Collapse(usize),
    /// Swap edge `k`.
    Swap(usize),
}

impl EditMesh<'_> {
    fn corner(&self, t: usize, k: usize) -> DVec3 {
        self.positions[self.tris[t][k % 3] as usize]
    }

    fn link(&mut self, u: u32, v: u32) {
        if u != NONE {
            self.nbr[(u / 3) as usize][(u % 3) as usize] = v;
        }
        if v != NONE {
            self.nbr[(v / 3) as usize][(v % 3) as usize] = u;
        }
    }

    /// The triangles around the vertex at corner `k` of `t`, in order, or
    /// `None` when the fan is open (a free edge) or does not close within `limit` steps.
    fn fan(&self, t: usize, k: usize, limit: usize) -> Option<Vec<(usize, usize)>> {
        let v = self.tris[t][k];
        let mut out = Vec::new();
        let (mut ct, mut ck) = (t, k);
        loop {
            out.push((ct, ck));
            if out.len() > limit {
                return None;
            }
            // Leave through the edge that ends at v (from the previous corner), arriving
            // in the neighbour on its edge that starts at v.
            let u = self.nbr[ct][(ck + 2) % 3];
            if u == NONE {
                return None;
            }
            let (nt, ne) = ((u / 3) as usize, (u % 3) as usize);
            // Neighbour's edge `ne` runs v -> prev, so v is its corner `ne`.
            if self.tris[nt][ne] != v {
                return None;
            }
            (ct, ck) = (nt, ne);
            if ct == t {
                return Some(out);
            }
        }
    }

    fn classify(&self, t: usize, zero_length: f64, zero_angle: f64) -> Option<Defect> {
        let p = [self.corner(t, 0), self.corner(t, 1), self.corner(t, 2)];
        let len = [p[0].distance(p[1]), p[1].distance(p[2]), p[2].distance(p[0])];
        let shortest = (0..3).min_by(|&a, &b| len[a].total_cmp(&len[b])).unwrap_or(0);
        if len[shortest] <= zero_length {
            return Some(Defect::Collapse(shortest));
        }
        // Corner i spans the edges to i+1 and to i+2; its angle is below the
        // tolerance when the cosine is positive and |sin| < tan(tol) cos
        // (no arc tangents: this runs on every triangle).
        let tan_tol = libm::tan(zero_angle.min(1.0));
        let mut small = false;
        let mut obtuse = None;
        for i in 0..3 {
            let (u, v) = (p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]);
            let (cos, sin) = (u.dot(v), u.cross(v).length());
            if cos > 0.0 && sin < tan_tol * cos {
                small = true;
            }
            if cos < 0.0 {
                obtuse = Some(i);
            }
        }
        if !small {
            return None;
        }
        match obtuse {
            // Cap: the longest edge is opposite the obtuse corner: edge i+1.
            Some(i) => Some(Defect::Swap((i + 1) % 3)),
            None => Some(Defect::Collapse(shortest)),
        }
    }

    /// Collapses edge `k` of `t` (and removes its neighbour across it);
    /// returns the triangles around the merged vertex, or `None` if the
    /// collapse would make the mesh non-manifold.
    fn collapse(&mut self, t: usize, k: usize) -> Option<Vec<usize>> {
        let twin = self.nbr[t][k];
        if twin == NONE {
            return None;
        }
        let (t2, k2) = ((twin / 3) as usize, (twin % 3) as usize);
        let [a, b, c] = [self.tris[t][k], self.tris[t][(k + 1) % 3], self.tris[t][(k + 2) % 3]];
        let d = self.tris[t2][(k2 + 2) % 3];
        let limit = 4096;
        let fan_a = self.fan(t, k, limit)?;
        let fan_b = self.fan(t, (k + 1) % 3, limit)?;
        // Link condition: the only vertices next to both a and b are c and d.
        let ring =
            |fan: &[(usize, usize)]| -> Vec<u32> { fan.iter().map(|&(ft, fk)| self.tris[ft][(fk + 1) % 3]).collect() };
        let (ra, rb) = (ring(&fan_a), ring(&fan_b));
        let shared = ra.iter().filter(|v| rb.contains(v)).count();
        if c == d || shared != 2 || !ra.contains(&c) || !ra.contains(&d) || fan_a.len() + fan_b.len() < 7 {
            return None;
        }
        let mid = (self.positions[a as usize] + self.positions[b as usize]) * 0.5;
        for &(ft, fk) in &fan_b {
            self.tris[ft][fk] = a;
        }
        self.positions[a as usize] = mid;
        let (n1, n2) = (self.nbr[t][(k + 1) % 3], self.nbr[t][(k + 2) % 3]);
        let (m1, m2) = (self.nbr[t2][(k2 + 1) % 3], self.nbr[t2][(k2 + 2) % 3]);
        self.link(n1, n2);
        self.link(m1, m2);
        self.alive[t] = false;
        self.alive[t2] = false;
        self.nbr[t] = [NONE; 3];
        self.nbr[t2] = [NONE; 3];
        let mut touched: Vec<usize> =
            fan_a.iter().chain(&fan_b).map(|&(ft, _)| ft).filter(|&f| self.alive[f]).collect();
        touched.sort_unstable();
        touched.dedup();
        Some(touched)
    }

    /// Swaps edge `k` of `t` with its neighbour's; `None` when the new edge
    /// exists already or a new triangle would face against the old neighbour.
    fn swap(&mut self, t: usize, k: usize) -> Option<[usize; 2]> {
        let twin = self.nbr[t][k];
        if twin == NONE {
            return None;
        }
        let (t2, k2) = ((twin / 3) as usize, (twin % 3) as usize);
        let [a, b, c] = [self.tris[t][k], self.tris[t][(k + 1) % 3], self.tris[t][(k + 2) % 3]];
        let d = self.tris[t2][(k2 + 2) % 3];
        if c == d {
            return None;
        }
        let fan_c = self.fan(t, (k + 2) % 3, 4096)?;
        if fan_c.iter().any(|&(ft, fk)| self.tris[ft][(fk + 1) % 3] == d) {
            return None;
        }
        let pos = |v: u32| self.positions[v as usize];
        let normal = |x: u32, y: u32, z: u32| (pos(y) - pos(x)).cross(pos(z) - pos(x));
        let reference = normal(b, a, d);
        if normal(c, a, d).dot(reference) <= 0.0 || normal(d, b, c).dot(reference) <= 0.0 {
            return None;
        }
        let (n1, n2) = (self.nbr[t][(k + 1) % 3], self.nbr[t][(k + 2) % 3]);
        let (m1, m2) = (self.nbr[t2][(k2 + 1) % 3], self.nbr[t2][(k2 + 2) % 3]);
        self.tris[t] = [c, a, d];
        self.tris[t2] = [d, b, c];
        let (tt, tt2) = (3 * t as u32, 3 * t2 as u32);
        self.link(tt, n2);
        self.link(tt + 1, m1);
        self.link(tt2, m2);
        self.link(tt2 + 1, n1);
        self.link(tt + 2, tt2 + 2);
        Some([t, t2])
    }
}

/// Runs step 1 over every triangle until none is degenerate or nothing more
/// can be done (bounded by a budget of operations proportional to the mesh).
pub(crate) fn remove_degenerate(mesh: &mut EditMesh<'_>, zero_length: f64, zero_angle: f64) -> DegenerateStats {
    let mut stats = DegenerateStats::default();
    let n = mesh.tris.len();
    let mut queue: Vec<usize> = (0..n).rev().collect();
    let mut queued = alloc::vec![true; n];
    let mut budget = 4 * n + 64;
    let mut stuck = alloc::vec![false; n];
    while let Some(t) = queue.pop() {
        queued[t] = false;
        if !mesh.alive[t] || budget == 0 {
            continue;
        }
        let Some(defect) = mesh.classify(t, zero_length, zero_angle) else {
            stuck[t] = false;
            continue;
        };
        budget -= 1;
        let touched: Option<Vec<usize>> = match defect {
            Defect::Collapse(k) => mesh.collapse(t, k).inspect(|_| stats.collapses += 1),
            Defect::Swap(k) => mesh.swap(t, k).map(|pair| pair.to_vec()).inspect(|_| stats.swaps += 1),
        };
        match touched {
            Some(list) => {
                stuck[t] = false;
                for f in list {
                    if mesh.alive[f] && !queued[f] {
                        queued[f] = true;
                        queue.push(f);
                    }
                }
            }
            None => stuck[t] = true,
        }
    }
    stats.left =
        (0..n).filter(|&t| mesh.alive[t] && (stuck[t] || mesh.classify(t, zero_length, zero_angle).is_some())).count();
    stats
}

#[cfg(test)]
mod tests {
    use super::super::topology::adjacency;
    use super::*;

    /// The unit octahedron's outward faces.
    const OCTAHEDRON: [[u32; 3]; 8] =
        [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]];

    fn octahedron() -> Vec<DVec3> {
        alloc::vec![DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z]
    }

    fn alive_triangles(t: &[[u32; 3]], alive: &[bool]) -> Vec<[u32; 3]> {
        t.iter().zip(alive).filter(|(_, &a)| a).map(|(t, _)| *t).collect()
    }

    fn assert_closed(tris: &[[u32; 3]]) {
        assert!(adjacency(tris).iter().all(|n| n.iter().all(|&u| u != NONE)), "free edges in {tris:?}");
        for tri in tris {
            assert!(tri[0] != tri[1] && tri[1] != tri[2] && tri[2] != tri[0], "collapsed triangle {tri:?}");
        }
    }

    #[test]
    fn a_short_edge_is_collapsed_and_the_mesh_stays_closed() {
        // Vertex 6 splits edge 0-4 right next to vertex 0: two triangles with an edge of 1e-12.
        let mut p = octahedron();
        p.push(DVec3::X + (DVec3::Z - DVec3::X) * 1e-12);
        let mut t: Vec<[u32; 3]> = OCTAHEDRON.iter().copied().filter(|t| *t != [0, 1, 4] && *t != [3, 0, 4]).collect();
        t.extend([[0, 1, 6], [6, 1, 4], [3, 0, 6], [3, 6, 4]]);
        let mut nbr = adjacency(&t);
        assert_closed(&t);
        let n = t.len();
        let mut m = EditMesh { positions: &mut p, tris: &mut t, nbr: &mut nbr, alive: alloc::vec![true; n] };
        let s = remove_degenerate(&mut m, 1e-9, 1e-6);
        assert_eq!((s.collapses, s.swaps, s.left), (1, 0, 0));
        let alive = m.alive.clone();
        let kept = alive_triangles(&t, &alive);
        assert_eq!(kept.len(), 8);
        assert_closed(&kept);
    }

    #[test]
    fn a_cap_has_its_longest_edge_swapped() {
        // The top vertex pushed down next to the middle of edge 0-1: face (0, 1, 4) is a cap.
        let mut p = octahedron();
        p[4] = DVec3::new(0.5, 0.5, 1e-9);
        let mut t = OCTAHEDRON.to_vec();
        let mut nbr = adjacency(&t);
        let mut m = EditMesh { positions: &mut p, tris: &mut t, nbr: &mut nbr, alive: alloc::vec![true; 8] };
        let s = remove_degenerate(&mut m, 1e-9, 1e-6);
        assert_eq!((s.collapses, s.swaps, s.left), (0, 1, 0));
        assert_closed(&t);
        // Edge 0-1 is gone; edge 4-5 exists.
        let has = |a: u32, b: u32| t.iter().any(|x| (0..3).any(|k| x[k] == a && x[(k + 1) % 3] == b));
        assert!(!has(0, 1) && !has(1, 0));
        assert!(has(4, 5) && has(5, 4));
        // Every triangle still faces outward.
        for x in &t {
            let [a, b, c] = x.map(|i| p[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "{x:?} faces inward");
        }
    }

    #[test]
    fn collapsing_a_tetrahedron_edge_is_refused() {
        let mut p = alloc::vec![DVec3::ZERO, DVec3::new(1e-12, 0.0, 0.0), DVec3::Y, DVec3::Z];
        let mut t = alloc::vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let mut nbr = adjacency(&t);
        let mut m = EditMesh { positions: &mut p, tris: &mut t, nbr: &mut nbr, alive: alloc::vec![true; 4] };
        let s = remove_degenerate(&mut m, 1e-9, 1e-6);
        assert_eq!(s.collapses, 0);
        assert!(s.left > 0);
        assert!(m.alive.iter().all(|&a| a));
    }
}
