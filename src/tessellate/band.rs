//! The band of a trimmed face: its loop nodes and the grid nodes inside
//! them, triangulated together (cdt.rs) in a plane scaled so that Delaunay
//! there is well shaped on the surface, then put on the surface.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::refine::WorkMesh;
use crate::nurbs::Surface;
use crate::Error;

/// What the CDT of a trimmed face works on: loop nodes first (with their
/// segments as constraints), then the grid nodes inside the region and not too
/// close to a loop, and the scale of the plane the triangulation runs in.
#[derive(Clone)]
pub(super) struct Band {
    pub nodes: Vec<DVec2>,
    pub constraints: Vec<[usize; 2]>,
    /// Per loop segment: its two nodes, its curve and the curve's parameters at them.
    pub segs: Vec<(usize, usize, u32, f64, f64)>,
    pub scale: DVec2,
    /// The first node the triangulation added (crossings it split), or
    /// `nodes.len()` when it added none.
    pub added_from: usize,
}

impl Band {
    pub fn new(surface: &dyn Surface, loops: &super::trim::Loops<'_>, pu: &[f64], pv: &[f64]) -> Self {
        let scale = band_scale(surface, pu, pv);
        let mut nodes: Vec<DVec2> = Vec::new();
        let mut constraints: Vec<[usize; 2]> = Vec::new();
        let mut segs = Vec::new();
        for poly in &loops.polys {
            let base = nodes.len();
            let n = poly.uv.len();
            nodes.extend_from_slice(&poly.uv);
            for i in 0..n {
                let j = (i + 1) % n;
                constraints.push([base + i, base + j]);
                let (curve, ta, tb) = poly.seg[i];
                segs.push((base + i, base + j, curve, ta, tb));
            }
        }
        let loop_segs: Vec<(DVec2, DVec2)> = loops.segments().collect();
        let near = near_loop_mask(&loop_segs, pu, pv, scale);
        let inside = loops.contains_grid(pu, pv);
        for (i, &u) in pu.iter().enumerate() {
            for (j, &v) in pv.iter().enumerate() {
                let k = i * pv.len() + j;
                if inside[k] && !near[k] {
                    nodes.push(DVec2::new(u, v));
                }
            }
        }
        let added_from = nodes.len();
        Self { nodes, constraints, segs, scale, added_from }
    }

    /// The kept triangles (indices into `nodes`), counter-clockwise. Where
    /// the triangulation split crossing segments, the crossing points are
    /// added to `nodes` (a strip narrower than the sewing distance).
    pub fn triangulate(&mut self, index: usize) -> Result<Vec<[u32; 3]>, Error> {
        let scaled: Vec<DVec2> = self.nodes.iter().map(|&q| q * self.scale).collect();
        let r = super::cdt::triangulate_region(index, &scaled, &self.constraints)?;
        self.added_from = self.nodes.len();
        self.nodes.extend(r.added.iter().map(|&q| q / self.scale));
        Ok(r.tris)
    }

    /// Puts the nodes on the surface and the triangles `tris` into `wm`, loop
    /// segments marked as trim edges. With `gids` (per loop, per node), loop
    /// nodes of one id become one vertex carrying it, and triangles that
    /// collapse by that (at a pole) are left out; a segment that then has a
    /// triangle on both sides (a seam) is an inner edge, not a trim edge.
    pub fn build(&self, surface: &dyn Surface, tris: &[[u32; 3]], wm: &mut WorkMesh, gids: Option<&[Vec<u32>]>) {
        let flat: Vec<u32> = gids.map(|g| g.iter().flatten().copied().collect()).unwrap_or_default();
        let points: Vec<DVec3> = self.nodes.iter().map(|&q| surface.point(q)).collect();
        // The two ends of a loop segment that are one node but not one point
        // (a side collapsed to a hair, not to a pole) stay two vertices: one
        // vertex would stand for both ends of a segment the surface spans.
        let mut apart = alloc::vec![false; self.nodes.len()];
        for &(a, b, ..) in &self.segs {
            let (ga, gb) = (flat.get(a).copied(), flat.get(b).copied());
            if ga.is_some() && ga == gb && ga != Some(u32::MAX) && !super::collapse::one_point(points[a], points[b]) {
                apart[a] = true;
                apart[b] = true;
            }
        }
        let mut by_gid: crate::collections::HashMap<u32, u32> = crate::collections::HashMap::default();
        let mut vid = Vec::with_capacity(self.nodes.len());
        for (k, &q) in self.nodes.iter().enumerate() {
            let g = flat.get(k).copied().unwrap_or(u32::MAX);
            if g != u32::MAX && !apart[k] {
                if let Some(&v) = by_gid.get(&g) {
                    vid.push(v);
                    continue;
                }
            }
            let v = wm.add_vertex(points[k], surface.normal(q));
            if g != u32::MAX {
                if !apart[k] {
                    by_gid.insert(g, v);
                }
                wm.gid[v as usize] = g;
            }
            vid.push(v);
        }
        for t in tris {
            let v = [vid[t[0] as usize], vid[t[1] as usize], vid[t[2] as usize]];
            if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
                continue;
            }
            let uv = [self.nodes[t[0] as usize], self.nodes[t[1] as usize], self.nodes[t[2] as usize]];
            wm.add_triangle(v, uv);
        }
        for &(a, b, curve, ta, tb) in &self.segs {
            let whole = wm.edge_triangles(vid[a], vid[b]) > 0 || self.added_from == self.nodes.len();
            let joined = |x: usize, y: usize| wm.edge_triangles(vid[x], vid[y]) > 0;
            let pieces = if whole { alloc::vec![(a, b, 0.0, 1.0)] } else { self.pieces(a, b, joined) };
            for (x, y, fx, fy) in pieces {
                let (vx, vy) = (vid[x], vid[y]);
                if vx != vy && wm.edge_triangles(vx, vy) == 1 {
                    wm.mark_trim(vx, vy, curve, ta + fx * (tb - ta), ta + fy * (tb - ta));
                }
            }
        }
    }

    /// Loop segment `a-b` as the triangulation keeps it: whole, or in pieces
    /// where it split the segment at crossings it added (nodes past the
    /// loops'), each piece with its ends' fractions along the segment, so
    /// that every piece is marked a trim edge. A crossing of two nearly
    /// parallel segments is computed far less exactly across them than
    /// along: nodes within 10⁻⁶ of the segment's length count, taken in
    /// order along it where the triangulation `joined` them to the last.
    fn pieces(&self, a: usize, b: usize, joined: impl Fn(usize, usize) -> bool) -> Vec<(usize, usize, f64, f64)> {
        let added = self.nodes.get(self.added_from..).unwrap_or(&[]);
        let (pa, pb) = (self.nodes[a], self.nodes[b]);
        let d = pb - pa;
        let len2 = d.length_squared();
        let mut cuts: Vec<(f64, usize)> = Vec::new();
        if len2 > 0.0 {
            for (k, &q) in added.iter().enumerate() {
                let f = (q - pa).dot(d) / len2;
                if f > 0.0 && f < 1.0 && (pa + d * f).distance_squared(q) <= 1e-12 * len2 {
                    cuts.push((f, self.added_from + k));
                }
            }
        }
        crate::sort::by_f64(&mut cuts, |c| c.0);
        let mut out = Vec::with_capacity(cuts.len() + 1);
        let (mut prev, mut fp) = (a, 0.0);
        for (f, k) in cuts {
            if joined(prev, k) {
                out.push((prev, k, fp, f));
                (prev, fp) = (k, f);
            }
        }
        out.push((prev, b, fp, 1.0));
        out
    }
}

/// Most the band's plane may stretch one direction against the surface:
/// a bound on how thin [`band_scale`] lets the first triangles be.
const BAND_ASPECT: f64 = 32.0;

/// The scale of the plane a trimmed face's CDT runs in: the surface's, with
/// one direction stretched (at most [`BAND_ASPECT`] times) until the grid's
/// mean cell is square. The grid lines sit where the limits need them in each
/// direction (paper 000 §3.1.3), so Delaunay there lays triangles along a
/// bend (a fillet's run along it) where the surface's own plane fans them
/// across it, and refinement then splits long edges that do not bend: the
/// corpus at 1e-3 and 1e-2 took 0.61× the triangles.
fn band_scale(surface: &dyn Surface, pu: &[f64], pv: &[f64]) -> DVec2 {
    let (Some(&u0), Some(&u1), Some(&v0), Some(&v1)) = (pu.first(), pu.last(), pv.first(), pv.last()) else {
        return DVec2::ONE;
    };
    let (lo, hi) = (DVec2::new(u0, v0), DVec2::new(u1, v1));
    let mut scale = mean_scale(surface, lo, hi);
    if pu.len() > 1 && pv.len() > 1 {
        // The mean cell's sides on the surface.
        let cu = (hi.x - lo.x) / (pu.len() - 1) as f64 * scale.x;
        let cv = (hi.y - lo.y) / (pv.len() - 1) as f64 * scale.y;
        let stretch = cv / cu;
        if stretch.is_finite() && stretch > 0.0 {
            scale.x *= stretch.clamp(1.0 / BAND_ASPECT, BAND_ASPECT);
        }
    }
    scale
}

/// Mean |Su| and |Sv| over a 5×5 sample of the rectangle: the scale that makes
/// a parameter-space Delaunay triangulation well shaped on the surface.
fn mean_scale(surface: &dyn Surface, lo: DVec2, hi: DVec2) -> DVec2 {
    let mut s = DVec2::ZERO;
    let mut n = 0.0;
    for i in 0..5 {
        for j in 0..5 {
            let q = lo + (hi - lo) * DVec2::new(i as f64 / 4.0, j as f64 / 4.0);
            let d = surface.derivs(q);
            s += DVec2::new(d.su.length(), d.sv.length());
            n += 1.0;
        }
    }
    let s = s / n;
    let fallback = s.max_element().max(1.0);
    DVec2::new(if s.x > 0.0 { s.x } else { fallback }, if s.y > 0.0 { s.y } else { fallback })
}

/// Grid nodes closer to a loop segment than 0.35 of their cell size (in the
/// scaled plane) are dropped so the band has no slivers.
fn near_loop_mask(segs: &[(DVec2, DVec2)], pu: &[f64], pv: &[f64], scale: DVec2) -> Vec<bool> {
    let (nu, nv) = (pu.len(), pv.len());
    let mut near = alloc::vec![false; nu * nv];
    let cell = |p: &[f64], i: usize| {
        let a = if i > 0 { p[i] - p[i - 1] } else { f64::INFINITY };
        let b = if i + 1 < p.len() { p[i + 1] - p[i] } else { f64::INFINITY };
        let m = a.min(b);
        if m.is_finite() {
            m
        } else {
            0.0
        }
    };
    let lower = |p: &[f64], x: f64| p.partition_point(|&t| t < x);
    for &(a, b) in segs {
        let smin = a.min(b);
        let smax = a.max(b);
        // Widest reach: one cell on each side.
        let i0 = lower(pu, smin.x).saturating_sub(1);
        let i1 = (lower(pu, smax.x) + 1).min(nu);
        let j0 = lower(pv, smin.y).saturating_sub(1);
        let j1 = (lower(pv, smax.y) + 1).min(nv);
        let (sa, sb) = (a * scale, b * scale);
        for i in i0..i1 {
            for j in j0..j1 {
                let q = DVec2::new(pu[i], pv[j]) * scale;
                let h = (cell(pu, i) * scale.x).min(cell(pv, j) * scale.y);
                let d = super::params::dist_to_segment(q.extend(0.0), sa.extend(0.0), sb.extend(0.0));
                if d < 0.35 * h {
                    near[i * nv + j] = true;
                }
            }
        }
    }
    near
}
