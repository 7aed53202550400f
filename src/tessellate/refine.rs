//! Refinement until proven: every triangle is measured against the exact
//! surface, and one that deviates too far, turns its normal too much or has an
//! edge too long is split at its longest edge (with the neighbour across that
//! edge, so the mesh stays conforming), until all pass.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};
use hashbrown::HashMap;

use super::measure::{measure_projection, measure_triangle, TriMeasure};
use crate::math::angle_between;
use crate::nurbs::{project_to_surface, NurbsCurve, Surface};

const NONE: u32 = u32::MAX;

/// A trim edge: the curve it follows and the parameters at its lower- and
/// higher-numbered vertex.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TrimEdge {
    pub curve: u32,
    pub t_lo: f64,
    pub t_hi: f64,
}

/// The mesh of one face while it is refined: shared vertices, per-corner (u,v)
/// (a seam or pole vertex has a different (u,v) in each triangle).
#[derive(Debug, Default)]
pub(crate) struct WorkMesh {
    pub pos: Vec<DVec3>,
    pub normal: Vec<DVec3>,
    pub tris: Vec<[u32; 3]>,
    pub uvs: Vec<[DVec2; 3]>,
    edges: HashMap<(u32, u32), [u32; 2]>,
    trim: HashMap<(u32, u32), TrimEdge>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Limits a triangle must meet.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Criteria {
    pub tol: f64,
    pub angle: f64,
    pub max_edge: f64,
    pub min_edge: f64,
    pub steps: usize,
}

/// Per-triangle results after refinement.
#[derive(Debug, Default)]
pub(crate) struct Outcome {
    pub measures: Vec<TriMeasure>,
    pub turns: Vec<f64>,
    /// Triangles left failing because the budget ran out or their edges hit `min_edge`.
    pub unproven: usize,
    pub budget_hit: bool,
}

impl WorkMesh {
    /// Adds a vertex with its surface normal.
    pub fn add_vertex(&mut self, p: DVec3, n: DVec3) -> u32 {
        self.pos.push(p);
        self.normal.push(n);
        (self.pos.len() - 1) as u32
    }

    /// Adds a triangle (counter-clockwise in (u,v)).
    pub fn add_triangle(&mut self, v: [u32; 3], uv: [DVec2; 3]) {
        let t = self.tris.len() as u32;
        self.tris.push(v);
        self.uvs.push(uv);
        for k in 0..3 {
            self.attach(v[k], v[(k + 1) % 3], t);
        }
    }

    /// Marks `a-b` as following trim curve `curve` from `ta` (at a) to `tb` (at b).
    pub fn mark_trim(&mut self, a: u32, b: u32, curve: u32, ta: f64, tb: f64) {
        let (t_lo, t_hi) = if a < b { (ta, tb) } else { (tb, ta) };
        self.trim.insert(key(a, b), TrimEdge { curve, t_lo, t_hi });
    }

    fn attach(&mut self, a: u32, b: u32, t: u32) {
        let e = self.edges.entry(key(a, b)).or_insert([NONE, NONE]);
        if e[0] == NONE {
            e[0] = t;
        } else if e[1] == NONE {
            e[1] = t;
        }
    }

    fn detach(&mut self, a: u32, b: u32, t: u32) {
        if let Some(e) = self.edges.get_mut(&key(a, b)) {
            if e[0] == t {
                e[0] = e[1];
                e[1] = NONE;
            } else if e[1] == t {
                e[1] = NONE;
            }
            if e[0] == NONE {
                self.edges.remove(&key(a, b));
            }
        }
    }

    fn measure(&self, surface: &dyn Surface, t: usize, c: &Criteria) -> (TriMeasure, f64) {
        let v = self.tris[t];
        let p = [self.pos[v[0] as usize], self.pos[v[1] as usize], self.pos[v[2] as usize]];
        let m = measure_triangle(surface, &p, &self.uvs[t], c.steps, &measure_projection());
        let n = [self.normal[v[0] as usize], self.normal[v[1] as usize], self.normal[v[2] as usize]];
        let turn = angle_between(n[0], n[1]).max(angle_between(n[1], n[2])).max(angle_between(n[2], n[0]));
        (m, turn)
    }

    fn longest_edge(&self, t: usize) -> (u32, u32, f64) {
        let v = self.tris[t];
        let mut best = (v[0], v[1], -1.0);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let l = self.pos[a as usize].distance(self.pos[b as usize]);
            if l > best.2 {
                best = (a, b, l);
            }
        }
        best
    }

    /// Splits edge `a-b` and the (one or two) triangles on it; returns the
    /// triangles that changed or were added.
    fn split_edge(&mut self, surface: &dyn Surface, curves: &[&NurbsCurve], a: u32, b: u32, out: &mut Vec<u32>) {
        let Some(&adj) = self.edges.get(&key(a, b)) else { return };
        let trim = self.trim.get(&key(a, b)).copied();
        let mut mid_uv_trim = None;
        if let Some(te) = trim {
            if let Some(c) = curves.get(te.curve as usize) {
                let tm = 0.5 * (te.t_lo + te.t_hi);
                mid_uv_trim = Some((c.point(tm).truncate(), tm));
            }
        }
        let m = self.pos.len() as u32;
        let mut m_pos = None;
        for &t in adj.iter().filter(|&&t| t != NONE) {
            let tv = self.tris[t as usize];
            let tuv = self.uvs[t as usize];
            let Some(i) = (0..3).find(|&k| key(tv[k], tv[(k + 1) % 3]) == key(a, b)) else { continue };
            let (x0, x1, x2) = (tv[i], tv[(i + 1) % 3], tv[(i + 2) % 3]);
            let (u0, u1, u2) = (tuv[i], tuv[(i + 1) % 3], tuv[(i + 2) % 3]);
            let uv_m = match (mid_uv_trim, m_pos) {
                (Some((uv, _)), _) => uv,
                (None, None) => (u0 + u1) * 0.5,
                (None, Some(p)) => {
                    // Another chart (seam or pole): find this triangle's (u,v) of the shared point.
                    let guess = (u0 + u1) * 0.5;
                    if surface.point(guess).distance(p) <= 1e-12 * (1.0 + p.length()) {
                        guess
                    } else {
                        project_to_surface(surface, p, Some(guess), &measure_projection()).uv
                    }
                }
            };
            if m_pos.is_none() {
                let p = surface.point(uv_m);
                m_pos = Some(p);
                self.pos.push(p);
                self.normal.push(surface.normal(uv_m));
            }
            // Replace t by [x0, m, x2] and add [m, x1, x2].
            self.detach(x0, x1, t);
            self.detach(x1, x2, t);
            self.tris[t as usize] = [x0, m, x2];
            self.uvs[t as usize] = [u0, uv_m, u2];
            self.attach(x0, m, t);
            self.attach(m, x2, t);
            let t2 = self.tris.len() as u32;
            self.tris.push([m, x1, x2]);
            self.uvs.push([uv_m, u1, u2]);
            self.attach(m, x1, t2);
            self.attach(x1, x2, t2);
            self.attach(x2, m, t2);
            out.push(t);
            out.push(t2);
        }
        if let (Some(te), Some((_, tm))) = (trim, mid_uv_trim) {
            self.trim.remove(&key(a, b));
            let (ta, tb) = if a < b { (te.t_lo, te.t_hi) } else { (te.t_hi, te.t_lo) };
            self.mark_trim(a, m, te.curve, ta, tm);
            self.mark_trim(m, b, te.curve, tm, tb);
        }
    }

    /// Measures every triangle and splits the failing ones until all pass or
    /// the budget is spent. `budget` is the triangle count this face may reach.
    pub fn refine(&mut self, surface: &dyn Surface, curves: &[&NurbsCurve], c: &Criteria, budget: usize) -> Outcome {
        let mut out = Outcome::default();
        let mut stack: Vec<u32> = (0..self.tris.len() as u32).rev().collect();
        let mut changed = Vec::new();
        let mut measures: Vec<Option<(TriMeasure, f64)>> = alloc::vec![None; self.tris.len()];
        while let Some(t) = stack.pop() {
            let t = t as usize;
            let (m, turn) = self.measure(surface, t, c);
            measures[t] = Some((m, turn));
            let (a, b, len) = self.longest_edge(t);
            let fails = m.max > c.tol || turn > c.angle || len > c.max_edge || self.inverted(surface, t);
            if !fails {
                continue;
            }
            if len <= c.min_edge {
                continue;
            }
            if self.tris.len() >= budget {
                out.budget_hit = true;
                continue;
            }
            changed.clear();
            self.split_edge(surface, curves, a, b, &mut changed);
            measures.resize(self.tris.len(), None);
            for &x in &changed {
                measures[x as usize] = None;
                stack.push(x);
            }
        }
        for (t, m) in measures.iter().enumerate() {
            let (m, turn) = m.unwrap_or_else(|| self.measure(surface, t, c));
            let (_, _, len) = self.longest_edge(t);
            if m.max > c.tol || turn > c.angle || len > c.max_edge {
                out.unproven += 1;
            }
            out.measures.push(m);
            out.turns.push(turn);
        }
        out
    }

    /// Whether the facet normal opposes the surface normal at the centroid's (u,v).
    pub fn inverted(&self, surface: &dyn Surface, t: usize) -> bool {
        let v = self.tris[t];
        let p = [self.pos[v[0] as usize], self.pos[v[1] as usize], self.pos[v[2] as usize]];
        let facet = (p[1] - p[0]).cross(p[2] - p[0]);
        if facet.length_squared() == 0.0 {
            return false;
        }
        let uv = self.uvs[t];
        let n = surface.normal((uv[0] + uv[1] + uv[2]) / 3.0);
        facet.dot(n) < 0.0
    }
}
