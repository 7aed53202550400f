//! Improvement of a face's mesh on its exact surface, judged in model
//! space: edge swaps that raise the smallest angle and Laplacian smoothing
//! constrained to the face (paper 003 after filling), plus, beyond the
//! paper, splits of long and collapses of short interior edges (the
//! re-mapped plane of a curved face cannot keep lengths exactly).
//!
//! Boundary nodes never move and boundary edges are never split, so the
//! faces keep meeting node to node. Every change is checked: each triangle
//! touched stays counter-clockwise in (u,v) (so nodes stay inside the face's
//! region) and its facet normal stays on the surface normal's side.

use crate::numeric::TINY;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::nurbs::Surface;

/// A face's mesh while it is improved.
#[derive(Debug, Clone, Default)]
pub(crate) struct FaceMesh {
    pub uv: Vec<DVec2>,
    pub x: Vec<DVec3>,
    /// Element size wanted at each node, model units.
    pub h: Vec<f64>,
    /// Boundary nodes, which never move.
    pub fixed: Vec<bool>,
    /// Triangles, counter-clockwise in (u,v).
    pub tris: Vec<[u32; 3]>,
}

/// Smallest angle of a triangle in model space, radians (0 when
/// degenerate): the angle opposite the shortest side, by the law of cosines.
pub(crate) fn min_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (x, y, z) = (b.distance_squared(c), c.distance_squared(a), a.distance_squared(b));
    // Opposite side s, adjacent sides p and q.
    let (s, p, q) = if x <= y && x <= z {
        (x, y, z)
    } else if y <= z {
        (y, z, x)
    } else {
        (z, x, y)
    };
    let den = 2.0 * libm::sqrt(p * q);
    if !(den > 0.0 && den.is_finite()) {
        return 0.0;
    }
    libm::acos(((p + q - s) / den).clamp(-1.0, 1.0))
}

fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

struct Work<'a> {
    s: &'a dyn Surface,
    m: FaceMesh,
    /// Unit surface normal at each node.
    nrm: Vec<DVec3>,
    alive: Vec<bool>,
    /// Triangles around each node.
    vt: Vec<Vec<u32>>,
    /// Longest size wanted anywhere.
    hmax: f64,
    /// Tolerance of (u,v) areas.
    tiny: f64,
    /// Nodes at most (bounds splits).
    max_nodes: usize,
}

/// Improves `mesh` on `surface` in `passes` rounds (size correction first
/// when `resize`), never holding more than `max_nodes` nodes.
pub(crate) fn improve(
    surface: &dyn Surface,
    mesh: FaceMesh,
    passes: usize,
    resize: bool,
    max_nodes: usize,
) -> FaceMesh {
    if mesh.tris.is_empty() || passes == 0 {
        return compact(mesh, None);
    }
    let n = mesh.uv.len();
    let mut vt: Vec<Vec<u32>> = alloc::vec![Vec::new(); n];
    for (t, tri) in mesh.tris.iter().enumerate() {
        for &v in tri {
            vt[v as usize].push(t as u32);
        }
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for q in &mesh.uv {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    let span = (hi - lo).max_element().max(TINY);
    let hmax = mesh.h.iter().copied().fold(0.0, f64::max);
    let alive = alloc::vec![true; mesh.tris.len()];
    let nrm = mesh.uv.iter().map(|&q| surface.normal(q)).collect();
    let mut w = Work { s: surface, m: mesh, nrm, alive, vt, hmax, tiny: 1e-16 * span * span, max_nodes };
    for _ in 0..passes {
        if resize {
            w.split_long();
            w.collapse_short();
        }
        w.swap_all();
        w.smooth_all();
        w.smooth_all();
    }
    w.swap_all();
    let alive = core::mem::take(&mut w.alive);
    compact(w.m, Some(&alive))
}

/// Drops dead triangles and unused nodes.
fn compact(m: FaceMesh, alive: Option<&[bool]>) -> FaceMesh {
    let mut used = alloc::vec![u32::MAX; m.uv.len()];
    let mut out = FaceMesh::default();
    for (t, tri) in m.tris.iter().enumerate() {
        if alive.is_some_and(|a| !a[t]) {
            continue;
        }
        let mut nt = [0u32; 3];
        for k in 0..3 {
            let v = tri[k] as usize;
            if used[v] == u32::MAX {
                used[v] = out.uv.len() as u32;
                out.uv.push(m.uv[v]);
                out.x.push(m.x[v]);
                out.h.push(m.h[v]);
                out.fixed.push(m.fixed[v]);
            }
            nt[k] = used[v];
        }
        out.tris.push(nt);
    }
    out
}

impl Work<'_> {
    fn tri_ok(&self, t: [u32; 3]) -> bool {
        let [a, b, c] = t.map(|v| v as usize);
        let m = &self.m;
        if orient(m.uv[a], m.uv[b], m.uv[c]) <= self.tiny {
            return false;
        }
        let facet = (m.x[b] - m.x[a]).cross(m.x[c] - m.x[a]);
        facet.dot(self.nrm[a] + self.nrm[b] + self.nrm[c]) > 0.0
    }

    fn angle_of(&self, t: [u32; 3]) -> f64 {
        let m = &self.m;
        min_angle(m.x[t[0] as usize], m.x[t[1] as usize], m.x[t[2] as usize])
    }

    /// Alive triangles holding both `a` and `b`.
    fn edge_tris(&self, a: u32, b: u32) -> ([u32; 2], usize) {
        let mut out = [u32::MAX; 2];
        let mut n = 0;
        for &t in &self.vt[a as usize] {
            if self.alive[t as usize] && self.m.tris[t as usize].contains(&b) {
                if n < 2 {
                    out[n] = t;
                }
                n += 1;
            }
        }
        (out, n)
    }

    /// For an interior edge: (t1 with a→b, c opposite in t1, t2 with b→a, d opposite in t2).
    fn around(&self, a: u32, b: u32) -> Option<(u32, u32, u32, u32)> {
        let ([t1, t2], n) = self.edge_tris(a, b);
        if n != 2 {
            return None;
        }
        let runs = |t: u32, p: u32, q: u32| {
            let tri = self.m.tris[t as usize];
            (0..3).any(|k| tri[k] == p && tri[(k + 1) % 3] == q)
        };
        let (t1, t2) = if runs(t1, a, b) { (t1, t2) } else { (t2, t1) };
        if !runs(t1, a, b) || !runs(t2, b, a) {
            return None;
        }
        let third = |t: u32| self.m.tris[t as usize].iter().copied().find(|&v| v != a && v != b);
        Some((t1, third(t1)?, t2, third(t2)?))
    }

    fn edges(&self) -> Vec<(u32, u32)> {
        let mut e = Vec::new();
        for (t, tri) in self.m.tris.iter().enumerate() {
            if !self.alive[t] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a < b {
                    e.push((a, b));
                } else if self.edge_tris(a, b).1 == 1 {
                    e.push((b, a)); // a boundary edge seen once
                }
            }
        }
        e
    }

    fn target(&self, a: u32, b: u32) -> f64 {
        (0.5 * (self.m.h[a as usize] + self.m.h[b as usize])).min(self.hmax)
    }

    fn set_tri(&mut self, t: u32, tri: [u32; 3]) {
        let old = self.m.tris[t as usize];
        for v in old {
            if !tri.contains(&v) {
                self.vt[v as usize].retain(|&x| x != t);
            }
        }
        for v in tri {
            if !old.contains(&v) {
                self.vt[v as usize].push(t);
            }
        }
        self.m.tris[t as usize] = tri;
    }

    fn new_tri(&mut self, tri: [u32; 3]) {
        let t = self.m.tris.len() as u32;
        self.m.tris.push(tri);
        self.alive.push(true);
        for v in tri {
            self.vt[v as usize].push(t);
        }
    }

    /// Splits interior edges longer than 4/3 of the wanted size at their (u,v) midpoint.
    fn split_long(&mut self) {
        let mut edges: Vec<(f64, u32, u32)> = self
            .edges()
            .into_iter()
            .filter_map(|(a, b)| {
                let l = self.m.x[a as usize].distance(self.m.x[b as usize]);
                let r = l / self.target(a, b);
                (r > 4.0 / 3.0).then_some((r, a, b))
            })
            .collect();
        edges.sort_unstable_by(|p, q| q.0.total_cmp(&p.0));
        for (_, a, b) in edges {
            if self.m.uv.len() >= self.max_nodes {
                return;
            }
            let Some((t1, c, t2, d)) = self.around(a, b) else { continue };
            let uv = (self.m.uv[a as usize] + self.m.uv[b as usize]) * 0.5;
            let x = self.s.point(uv);
            let mid = self.m.uv.len() as u32;
            let new = [[a, mid, c], [mid, b, c], [b, mid, d], [mid, a, d]];
            self.m.uv.push(uv);
            self.m.x.push(x);
            self.m.h.push(0.5 * (self.m.h[a as usize] + self.m.h[b as usize]));
            self.m.fixed.push(false);
            self.vt.push(Vec::new());
            self.nrm.push(self.s.normal(uv));
            if !new.iter().all(|&t| self.tri_ok(t)) {
                self.m.uv.pop();
                self.m.x.pop();
                self.m.h.pop();
                self.m.fixed.pop();
                self.vt.pop();
                self.nrm.pop();
                continue;
            }
            self.set_tri(t1, new[0]);
            self.new_tri(new[1]);
            self.set_tri(t2, new[2]);
            self.new_tri(new[3]);
        }
    }

    /// Collapses interior edges shorter than 4/5 of the wanted size: the
    /// free end moves onto the other (at the midpoint when both are free)
    /// when the result stays valid, no new edge is longer than 4/3 of its
    /// size, and the smallest angle around does not fall below 20° or its old value.
    fn collapse_short(&mut self) {
        let mut edges: Vec<(f64, u32, u32)> = self
            .edges()
            .into_iter()
            .filter_map(|(a, b)| {
                let l = self.m.x[a as usize].distance(self.m.x[b as usize]);
                let r = l / self.target(a, b);
                (r < 0.8).then_some((r, a, b))
            })
            .collect();
        edges.sort_unstable_by(|p, q| p.0.total_cmp(&q.0));
        for (_, a, b) in edges {
            let (fa, fb) = (self.m.fixed[a as usize], self.m.fixed[b as usize]);
            if fa && fb {
                continue;
            }
            let Some((t1, c, t2, d)) = self.around(a, b) else { continue };
            // Link condition: a and b share exactly the neighbours c and d.
            let ring = |v: u32| -> Vec<u32> {
                let mut r: Vec<u32> = self.vt[v as usize]
                    .iter()
                    .filter(|&&t| self.alive[t as usize])
                    .flat_map(|&t| self.m.tris[t as usize])
                    .filter(|&x| x != v)
                    .collect();
                r.sort_unstable();
                r.dedup();
                r
            };
            let (ra, rb) = (ring(a), ring(b));
            let common = ra.iter().filter(|v| rb.binary_search(v).is_ok()).count();
            if common != 2 {
                continue;
            }
            // Where the merged node goes: onto the fixed end, else the midpoint.
            let (keep, gone, uv, x) = if fa {
                (a, b, self.m.uv[a as usize], self.m.x[a as usize])
            } else if fb {
                (b, a, self.m.uv[b as usize], self.m.x[b as usize])
            } else {
                let uv = (self.m.uv[a as usize] + self.m.uv[b as usize]) * 0.5;
                (b, a, uv, self.s.point(uv))
            };
            let old_uv = (self.m.uv[keep as usize], self.m.x[keep as usize], self.nrm[keep as usize]);
            let mut before = f64::INFINITY;
            let touched: Vec<u32> = self.vt[a as usize]
                .iter()
                .chain(&self.vt[b as usize])
                .copied()
                .filter(|&t| self.alive[t as usize] && t != t1 && t != t2)
                .collect();
            for &t in &touched {
                before = before.min(self.angle_of(self.m.tris[t as usize]));
            }
            before = before.min(self.angle_of(self.m.tris[t1 as usize])).min(self.angle_of(self.m.tris[t2 as usize]));
            self.m.uv[keep as usize] = uv;
            self.m.x[keep as usize] = x;
            self.nrm[keep as usize] = if fa || fb { old_uv.2 } else { self.s.normal(uv) };
            let mut ok = true;
            let mut after = f64::INFINITY;
            for &t in &touched {
                let tri = self.m.tris[t as usize].map(|v| if v == gone { keep } else { v });
                if !self.tri_ok(tri) {
                    ok = false;
                    break;
                }
                after = after.min(self.angle_of(tri));
                for k in 0..3 {
                    let (p, q) = (tri[k], tri[(k + 1) % 3]);
                    if (p == keep || q == keep)
                        && self.m.x[p as usize].distance(self.m.x[q as usize]) > 4.0 / 3.0 * self.target(p, q)
                    {
                        ok = false;
                    }
                }
            }
            if !ok || after < before.min(20f64.to_radians()) {
                self.m.uv[keep as usize] = old_uv.0;
                self.m.x[keep as usize] = old_uv.1;
                self.nrm[keep as usize] = old_uv.2;
                continue;
            }
            let _ = (c, d);
            self.alive[t1 as usize] = false;
            self.alive[t2 as usize] = false;
            for &t in &touched {
                let tri = self.m.tris[t as usize].map(|v| if v == gone { keep } else { v });
                self.set_tri(t, tri);
            }
            self.m.h[keep as usize] = 0.5 * (self.m.h[a as usize] + self.m.h[b as usize]);
            self.vt[gone as usize].clear();
        }
    }

    /// Swaps interior edges whose two triangles gain a larger smallest angle.
    fn swap_all(&mut self) {
        for _ in 0..4 {
            let mut changed = 0;
            for (a, b) in self.edges() {
                let Some((t1, c, t2, d)) = self.around(a, b) else { continue };
                if c == d || self.edge_tris(c, d).1 > 0 {
                    continue;
                }
                let old = self.angle_of(self.m.tris[t1 as usize]).min(self.angle_of(self.m.tris[t2 as usize]));
                let (n1, n2) = ([c, a, d], [d, b, c]);
                if !(self.tri_ok(n1) && self.tri_ok(n2)) {
                    continue;
                }
                let new = self.angle_of(n1).min(self.angle_of(n2));
                if new > old + 1e-9 {
                    self.set_tri(t1, n1);
                    self.set_tri(t2, n2);
                    changed += 1;
                }
            }
            if changed == 0 {
                break;
            }
        }
    }

    /// Laplacian smoothing on the surface: each free node moves to the mean
    /// of its neighbours, taken to the surface through its (u,v) by two
    /// Gauss-Newton steps; kept when every triangle around stays valid and
    /// the smallest angle around does not fall below 30° or its old value.
    fn smooth_all(&mut self) {
        for v in 0..self.m.uv.len() {
            if self.m.fixed[v] || self.vt[v].is_empty() {
                continue;
            }
            let tris: Vec<[u32; 3]> =
                self.vt[v].iter().filter(|&&t| self.alive[t as usize]).map(|&t| self.m.tris[t as usize]).collect();
            if tris.is_empty() {
                continue;
            }
            let mut sum = DVec3::ZERO;
            let mut count = 0.0;
            for t in &tris {
                for &u in t {
                    if u as usize != v {
                        sum += self.m.x[u as usize];
                        count += 1.0;
                    }
                }
            }
            let target = sum / count;
            let (old_uv, old_x) = (self.m.uv[v], self.m.x[v]);
            let before = tris.iter().map(|&t| self.angle_of(t)).fold(f64::INFINITY, f64::min);
            let [lo, hi] = self.s.domain();
            let mut uv = old_uv;
            for _ in 0..2 {
                let d = self.s.derivs(uv);
                let r = target - d.point;
                let (a, b, c) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
                let det = a * c - b * b;
                if !(det > 0.0 && det.is_finite()) {
                    break;
                }
                let (ru, rv) = (d.su.dot(r), d.sv.dot(r));
                uv = (uv + DVec2::new(c * ru - b * rv, a * rv - b * ru) / det).clamp(lo, hi);
            }
            if !uv.is_finite() {
                continue;
            }
            let old_n = self.nrm[v];
            self.m.uv[v] = uv;
            self.m.x[v] = self.s.point(uv);
            self.nrm[v] = self.s.normal(uv);
            let ok = tris.iter().all(|&t| self.tri_ok(t));
            let after = tris.iter().map(|&t| self.angle_of(t)).fold(f64::INFINITY, f64::min);
            if !ok || after < before.min(30f64.to_radians()) {
                self.m.uv[v] = old_uv;
                self.m.x[v] = old_x;
                self.nrm[v] = old_n;
            }
        }
    }
}
