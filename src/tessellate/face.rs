//! One face: iso-parametric grid (paper 000 §3.1), trimmed band by CDT
//! (§3.2), then refinement until every triangle is proven within limits.

use alloc::format;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::params::{grid_params, Limits};
use super::refine::{Criteria, Outcome, WorkMesh};
use crate::model::Face;
use crate::nurbs::Surface;
use crate::Error;

/// A meshed face: its work mesh and what refinement measured.
pub(crate) struct FaceResult<'a> {
    pub mesh: WorkMesh,
    pub outcome: Outcome,
    /// The face's trim curves, as its trim edges index them.
    pub curves: Vec<&'a crate::NurbsCurve>,
}

/// Grid parameters in both directions over `[lo, hi]`, sharing the tolerance
/// between the two directions: half each, then the whole remainder to one
/// direction when the other turned out (nearly) straight, as on a cylinder.
pub(super) fn grid(surface: &dyn Surface, lo: DVec2, hi: DVec2, lim: &Limits) -> (Vec<f64>, Vec<f64>) {
    let half = Limits { tol: lim.tol * 0.5, ..*lim };
    let (mut pu, mut su) = grid_params(surface, lo, hi, true, &half);
    let (mut pv, mut sv) = grid_params(surface, lo, hi, false, &half);
    if sv < 0.5 * half.tol && su > sv {
        let rest = Limits { tol: (lim.tol - sv).max(half.tol), ..*lim };
        (pu, su) = grid_params(surface, lo, hi, true, &rest);
    } else if su < 0.5 * half.tol && sv > su {
        let rest = Limits { tol: (lim.tol - su).max(half.tol), ..*lim };
        (pv, sv) = grid_params(surface, lo, hi, false, &rest);
    }
    // Where the iso-curves left most of the tolerance unused, a twist may use it.
    let room = lim.tol - su - sv;
    if room >= 0.5 * lim.tol {
        // 0.85: the twist estimate is exact only for bilinear cells.
        refine_twisted_cells(surface, &mut pu, &mut pv, 0.85 * room);
    }
    (pu, pv)
}

/// Beyond paper 000: its tests run along iso-curves only, and a twisted
/// surface (a bilinear saddle, whose iso-curves are all straight) passes them
/// with a grid far too coarse. A cell's twist `(P00 + P11 − P10 − P01) / 4`,
/// taken along the surface normal, is how far its two triangles miss the
/// surface at the centre beyond the iso-curve sags; where it exceeds `room`
/// (what the sags left of the tolerance), the cell's row and column are split
/// into equal parts by the square root of the excess (twist falls with the
/// product of both steps).
fn refine_twisted_cells(surface: &dyn Surface, pu: &mut Vec<f64>, pv: &mut Vec<f64>, room: f64) {
    for _ in 0..4 {
        let (nu, nv) = (pu.len(), pv.len());
        if nu < 2 || nv < 2 || nu * nv > 4_000_000 {
            return;
        }
        let pts: Vec<DVec3> = (0..nu)
            .flat_map(|i| pv.iter().map(move |&v| (i, v)))
            .map(|(i, v)| surface.point(DVec2::new(pu[i], v)))
            .collect();
        let mut need_u = alloc::vec![1usize; nu - 1];
        let mut need_v = alloc::vec![1usize; nv - 1];
        let mut any = false;
        for i in 0..nu - 1 {
            for j in 0..nv - 1 {
                let p = |a: usize, b: usize| pts[(i + a) * nv + j + b];
                let twist = (p(0, 0) + p(1, 1) - p(1, 0) - p(0, 1)) * 0.25;
                if twist.length() <= room {
                    continue;
                }
                let n = surface.normal(DVec2::new(0.5 * (pu[i] + pu[i + 1]), 0.5 * (pv[j] + pv[j + 1])));
                let e = twist.dot(n).abs();
                if e > room {
                    let n = (crate::math::ceil(crate::math::sqrt(e / room)) as usize).clamp(2, 256);
                    need_u[i] = need_u[i].max(n);
                    need_v[j] = need_v[j].max(n);
                    any = true;
                }
            }
        }
        if !any {
            return;
        }
        *pu = split_by(pu, &need_u);
        *pv = split_by(pv, &need_v);
    }
}

/// Splits interval `k` of `p` into `need[k]` equal parts.
fn split_by(p: &[f64], need: &[usize]) -> Vec<f64> {
    let mut out = Vec::with_capacity(p.len() * 2);
    out.push(p[0]);
    for (k, w) in p.windows(2).enumerate() {
        let n = need[k];
        for s in 1..=n {
            out.push(if s == n { w[1] } else { w[0] + (w[1] - w[0]) * s as f64 / n as f64 });
        }
    }
    out
}

/// Meshes face `index` within `crit`, using at most `budget` triangles.
pub(crate) fn mesh_face<'a>(
    index: usize,
    face: &'a Face,
    lim: &Limits,
    crit: &Criteria,
    budget: usize,
) -> Result<FaceResult<'a>, Error> {
    let surface: &dyn Surface = &face.surface;
    let mut wm = WorkMesh::default();
    let curves;
    if face.loops.is_empty() {
        curves = Vec::new();
        let [lo, hi] = surface.domain();
        let (pu, pv) = grid(surface, lo, hi, lim);
        check_grid(index, &pu, &pv, budget)?;
        build_full_grid(surface, &pu, &pv, &mut wm);
    } else {
        curves = trimmed(index, surface, face, lim, budget, &mut wm)?;
    }
    let outcome = wm.refine(surface, &curves, crit, budget);
    Ok(FaceResult { mesh: wm, outcome, curves })
}

/// Trimmed face: loops, grid over their box, CDT band; returns the trim curves.
#[cfg(feature = "std")]
fn trimmed<'a>(
    index: usize,
    surface: &dyn Surface,
    face: &'a Face,
    lim: &Limits,
    budget: usize,
    wm: &mut WorkMesh,
) -> Result<Vec<&'a crate::NurbsCurve>, Error> {
    let loops = super::trim::prepare_loops(index, surface, &face.loops, lim)?;
    let [dlo, dhi] = surface.domain();
    let (llo, lhi) = loops.bounds();
    let lo = llo.max(dlo);
    let hi = lhi.min(dhi);
    if !(hi.x > lo.x && hi.y > lo.y) {
        return Err(Error::Mesh {
            face: index,
            message: "trim loops lie outside the surface's parameter domain".into(),
        });
    }
    let (pu, pv) = grid(surface, lo, hi, lim);
    check_grid(index, &pu, &pv, budget)?;
    build_trimmed(index, surface, &loops, &pu, &pv, wm)?;
    Ok(loops.curves)
}

/// Without the CDT (no `std`), trimmed faces cannot be meshed.
#[cfg(not(feature = "std"))]
fn trimmed<'a>(
    index: usize,
    _surface: &dyn Surface,
    _face: &'a Face,
    _lim: &Limits,
    _budget: usize,
    _wm: &mut WorkMesh,
) -> Result<Vec<&'a crate::NurbsCurve>, Error> {
    Err(Error::Mesh { face: index, message: "trimmed faces need the `std` feature".into() })
}

pub(super) fn check_grid(index: usize, pu: &[f64], pv: &[f64], budget: usize) -> Result<(), Error> {
    let cells = pu.len().saturating_sub(1).saturating_mul(pv.len().saturating_sub(1));
    if cells.saturating_mul(2) > budget {
        return Err(Error::Limit(format!(
            "face {index}: the tolerance asks for a {}x{} grid, over the triangle budget of {budget}",
            pu.len(),
            pv.len()
        )));
    }
    Ok(())
}

/// Welds grid nodes that coincide in model space (closed seams, poles) so that
/// refinement sees one shared edge; returns the vertex of each node.
fn weld_nodes(surface: &dyn Surface, nodes: &[DVec2], wm: &mut WorkMesh) -> (Vec<u32>, Vec<u32>) {
    let pts: Vec<DVec3> = nodes.iter().map(|&q| surface.point(q)).collect();
    let diag = crate::nurbs::Aabb::from_points(pts.iter().copied()).diagonal();
    let (map, count) = crate::mesh::weld_positions(&pts, 1e-10 * diag.max(1e-300));
    let mut vert = alloc::vec![u32::MAX; count];
    let mut multiplicity = alloc::vec![0u32; count];
    let mut out = Vec::with_capacity(nodes.len());
    for (i, &m) in map.iter().enumerate() {
        let m = m as usize;
        if vert[m] == u32::MAX {
            vert[m] = wm.add_vertex(pts[i], surface.normal(nodes[i]));
        }
        multiplicity[m] += 1;
        out.push(vert[m]);
    }
    let mult = map.iter().map(|&m| multiplicity[m as usize]).collect();
    (out, mult)
}

/// Untrimmed surface: the grid's quads, each split along its shorter diagonal
/// (in model space) into two counter-clockwise triangles.
pub(super) fn build_full_grid(surface: &dyn Surface, pu: &[f64], pv: &[f64], wm: &mut WorkMesh) {
    let (nu, nv) = (pu.len(), pv.len());
    let nodes: Vec<DVec2> = (0..nu).flat_map(|i| pv.iter().map(move |&v| DVec2::new(pu[i], v))).collect();
    let (vid, mult) = weld_nodes(surface, &nodes, wm);
    let at = |i: usize, j: usize| i * nv + j;
    for i in 0..nu.saturating_sub(1) {
        for j in 0..nv.saturating_sub(1) {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let p = |k: usize| wm.pos[vid[q[k]] as usize];
            let tris = if p(0).distance_squared(p(2)) <= p(1).distance_squared(p(3)) {
                [[0, 1, 2], [0, 2, 3]]
            } else {
                [[0, 1, 3], [1, 2, 3]]
            };
            for t in tris {
                let v = [vid[q[t[0]]], vid[q[t[1]]], vid[q[t[2]]]];
                if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
                    continue; // collapsed at a pole
                }
                let mut uv = [nodes[q[t[0]]], nodes[q[t[1]]], nodes[q[t[2]]]];
                fix_pole_corners(&mut uv, [mult[q[t[0]]], mult[q[t[1]]], mult[q[t[2]]]]);
                wm.add_triangle(v, uv);
            }
        }
    }
}

/// At a pole many grid nodes are one vertex; its (u,v) in a triangle is taken
/// midway along the collapsed direction between the other two corners, so the
/// triangle's (u,v) interpolation follows the surface (better Newton hints).
fn fix_pole_corners(uv: &mut [DVec2; 3], mult: [u32; 3]) {
    for k in 0..3 {
        if mult[k] > 4 {
            let (a, b) = (uv[(k + 1) % 3], uv[(k + 2) % 3]);
            if (a.y - uv[k].y).abs() > (a.x - uv[k].x).abs() && (b.y - uv[k].y).abs() > (b.x - uv[k].x).abs() {
                uv[k].x = 0.5 * (a.x + b.x); // collapsed along u (v = const row)
            } else {
                uv[k].y = 0.5 * (a.y + b.y);
            }
        }
    }
}

#[cfg(feature = "std")]
/// Trimmed face: kept grid nodes plus loop nodes, constrained Delaunay in a
/// plane scaled by the surface's mean first derivatives, region by parity.
fn build_trimmed(
    index: usize,
    surface: &dyn Surface,
    loops: &super::trim::Loops<'_>,
    pu: &[f64],
    pv: &[f64],
    wm: &mut WorkMesh,
) -> Result<(), Error> {
    let band = Band::new(surface, loops, pu, pv);
    let tris = band.triangulate(index)?;
    band.build(surface, &tris, wm);
    Ok(())
}

#[cfg(feature = "std")]
/// What the CDT of a trimmed face works on: loop nodes first (with their
/// segments as constraints), then the grid nodes inside the region and not too
/// close to a loop, and the scale of the plane the triangulation runs in.
pub(super) struct Band {
    pub nodes: Vec<DVec2>,
    pub constraints: Vec<[usize; 2]>,
    /// Per loop segment: its two nodes, its curve and the curve's parameters at them.
    pub segs: Vec<(usize, usize, u32, f64, f64)>,
    pub scale: DVec2,
}

#[cfg(feature = "std")]
impl Band {
    pub fn new(surface: &dyn Surface, loops: &super::trim::Loops<'_>, pu: &[f64], pv: &[f64]) -> Self {
        let lo = DVec2::new(pu[0], pv[0]);
        let hi = DVec2::new(pu[pu.len() - 1], pv[pv.len() - 1]);
        let scale = mean_scale(surface, lo, hi);
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
        Self { nodes, constraints, segs, scale }
    }

    /// The kept triangles (indices into `nodes`), counter-clockwise.
    pub fn triangulate(&self, index: usize) -> Result<Vec<[u32; 3]>, Error> {
        let scaled: Vec<DVec2> = self.nodes.iter().map(|&q| q * self.scale).collect();
        super::cdt::triangulate_region(index, &scaled, &self.constraints)
    }

    /// Puts the nodes on the surface and the triangles `tris` into `wm`, loop segments marked as trim edges.
    pub fn build(&self, surface: &dyn Surface, tris: &[[u32; 3]], wm: &mut WorkMesh) {
        let mut vid = Vec::with_capacity(self.nodes.len());
        for &q in &self.nodes {
            vid.push(wm.add_vertex(surface.point(q), surface.normal(q)));
        }
        for t in tris {
            let uv = [self.nodes[t[0] as usize], self.nodes[t[1] as usize], self.nodes[t[2] as usize]];
            wm.add_triangle([vid[t[0] as usize], vid[t[1] as usize], vid[t[2] as usize]], uv);
        }
        for &(a, b, curve, ta, tb) in &self.segs {
            wm.mark_trim(vid[a], vid[b], curve, ta, tb);
        }
    }
}

#[cfg(feature = "std")]
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

#[cfg(feature = "std")]
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
