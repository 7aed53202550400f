//! Sewing faces into one watertight mesh (paper 000 §3.3, paper 003's
//! shared-boundary topology).
//!
//! Paper 000 splits a shared edge identically on both patches. Faces here are
//! meshed one by one, so their borders are made to agree afterwards: every
//! border vertex of one face that lies on another face's exact border (within
//! the sewing distance) is inserted into that border, splitting the triangle
//! behind it, and border vertices that coincide are snapped to one position.
//! Both sides then hold the same nodes, so welding leaves no crack and no
//! T-junction, whichever face refined its border more.

use alloc::vec::Vec;
use glam::DVec3;
use hashbrown::HashMap;

use super::refine::WorkMesh;
use crate::nurbs::{NurbsCurve, Surface};

/// One face while the model is sewn.
pub(crate) struct FaceWork<'a> {
    pub surface: &'a dyn Surface,
    pub curves: Vec<&'a NurbsCurve>,
    pub mesh: WorkMesh,
}

struct Candidate {
    s: f64,
    q: DVec3,
}

type Cell = (i64, i64, i64);

fn cell_of(p: DVec3, inv: f64) -> Cell {
    let c = p * inv;
    (crate::math::floor(c.x) as i64, crate::math::floor(c.y) as i64, crate::math::floor(c.z) as i64)
}

/// Makes the faces' borders conform; returns, per face, the triangles that changed.
///
/// `sew`: how far apart two borders may be and still be one edge; `reach`:
/// how far a border vertex may lie from the other face's chord (chordal
/// tolerance plus `sew`).
pub(crate) fn conform(faces: &mut [FaceWork<'_>], sew: f64, reach: f64) -> Vec<Vec<u32>> {
    let mut changed: Vec<Vec<u32>> = faces.iter().map(|_| Vec::new()).collect();
    if faces.is_empty() || sew.is_nan() || sew <= 0.0 || !reach.is_finite() {
        return changed;
    }
    // Border vertices of every face, hashed on a grid about one border edge long.
    let borders: Vec<Vec<(u32, u32)>> = faces.iter().map(|f| f.mesh.boundary_edges()).collect();
    let mut total_len = 0.0;
    let mut count = 0usize;
    for (f, edges) in faces.iter().zip(&borders) {
        for &(a, b) in edges {
            total_len += f.mesh.pos[a as usize].distance(f.mesh.pos[b as usize]);
            count += 1;
        }
    }
    if count == 0 {
        return changed;
    }
    let h = (total_len / count as f64).max(reach).max(1e-300);
    let inv = 1.0 / h;
    let mut grid: HashMap<Cell, Vec<(u32, u32)>> = HashMap::new();
    for (fi, (f, edges)) in faces.iter().zip(&borders).enumerate() {
        let mut seen = hashbrown::HashSet::new();
        for &(a, b) in edges {
            for v in [a, b] {
                if seen.insert(v) {
                    grid.entry(cell_of(f.mesh.pos[v as usize], inv)).or_default().push((fi as u32, v));
                }
            }
        }
    }
    // Phase 1: for every border edge, the other faces' border vertices on it.
    let mut plans: Vec<Vec<(u32, u32, Vec<Candidate>)>> = faces.iter().map(|_| Vec::new()).collect();
    for (fi, f) in faces.iter().enumerate() {
        for &(a, b) in &borders[fi] {
            let (pa, pb) = (f.mesh.pos[a as usize], f.mesh.pos[b as usize]);
            let lo = cell_of(pa.min(pb) - DVec3::splat(reach), inv);
            let hi = cell_of(pa.max(pb) + DVec3::splat(reach), inv);
            let mut found: Vec<Candidate> = Vec::new();
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    for z in lo.2..=hi.2 {
                        let Some(list) = grid.get(&(x, y, z)) else { continue };
                        for &(g, v) in list {
                            if g as usize == fi && (v == a || v == b) {
                                continue;
                            }
                            let q = faces[g as usize].mesh.pos[v as usize];
                            if let Some(s) = on_border(f, a, b, q, sew, reach) {
                                if !found.iter().any(|c| c.q.distance(q) <= sew) {
                                    found.push(Candidate { s, q });
                                }
                            }
                        }
                    }
                }
            }
            if !found.is_empty() {
                found.sort_by(|x, y| x.s.total_cmp(&y.s));
                plans[fi].push((a, b, found));
            }
        }
    }
    // Phase 2: split the edges at those vertices.
    for (fi, plan) in plans.into_iter().enumerate() {
        let f = &mut faces[fi];
        for (a, b, cands) in plan {
            let mut from = a;
            let mut done = 0.0;
            for c in cands {
                let frac = ((c.s - done) / (1.0 - done)).clamp(1e-6, 1.0 - 1e-6);
                match f.mesh.split_edge_at(f.surface, &f.curves, from, b, frac, Some(c.q), &mut changed[fi]) {
                    Some(m) => {
                        from = m;
                        done = c.s;
                    }
                    None => break,
                }
            }
        }
    }
    snap(faces, sew, &mut changed);
    for c in &mut changed {
        c.sort_unstable();
        c.dedup();
    }
    changed
}

/// Where `q` lies on the exact border under edge `a-b` of face `f`: the
/// fraction from `a`, when it is within `sew` of that border and not at its ends.
fn on_border(f: &FaceWork<'_>, a: u32, b: u32, q: DVec3, sew: f64, reach: f64) -> Option<f64> {
    let (pa, pb) = (f.mesh.pos[a as usize], f.mesh.pos[b as usize]);
    if q.distance(pa) <= sew || q.distance(pb) <= sew {
        return None;
    }
    let ab = pb - pa;
    let l2 = ab.length_squared();
    if l2 <= 0.0 {
        return None;
    }
    let s0 = ((q - pa).dot(ab) / l2).clamp(0.0, 1.0);
    if q.distance(pa + ab * s0) > reach || s0 <= 0.0 || s0 >= 1.0 {
        return None;
    }
    // Golden-section search of the distance to the exact border around s0.
    let dist =
        |s: f64| f.mesh.boundary_point(f.surface, &f.curves, a, b, s).map_or(f64::INFINITY, |(_, p)| p.distance(q));
    let (mut lo, mut hi) = ((s0 - 0.25).max(0.0), (s0 + 0.25).min(1.0));
    let g = 0.618_033_988_749_895;
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (dist(x1), dist(x2));
    for _ in 0..40 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = dist(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = dist(x2);
        }
        if hi - lo < 1e-12 {
            break;
        }
    }
    let (s, d) = if f1 < f2 { (x1, f1) } else { (x2, f2) };
    (d <= sew && s > 1e-9 && s < 1.0 - 1e-9).then_some(s)
}

/// Snaps border vertices that lie within `sew` of each other to one position
/// (the first one's), so welding joins them exactly: across faces, and within
/// one face along a seam its loop runs up on one side and down on the other.
fn snap(faces: &mut [FaceWork<'_>], sew: f64, changed: &mut [Vec<u32>]) {
    let inv = 1.0 / sew;
    let mut grid: HashMap<Cell, Vec<(u32, u32)>> = HashMap::new();
    let mut moved: Vec<Vec<u32>> = faces.iter().map(|_| Vec::new()).collect();
    for fi in 0..faces.len() {
        let edges = faces[fi].mesh.boundary_edges();
        let mut verts: Vec<u32> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
        verts.sort_unstable();
        verts.dedup();
        for v in verts {
            let p = faces[fi].mesh.pos[v as usize];
            let (kx, ky, kz) = cell_of(p, inv);
            let mut target = None;
            'look: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(list) = grid.get(&(kx + dx, ky + dy, kz + dz)) else { continue };
                        for &(g, w) in list {
                            if g as usize != fi || w != v {
                                let q = faces[g as usize].mesh.pos[w as usize];
                                if q.distance(p) <= sew {
                                    target = Some(q);
                                    break 'look;
                                }
                            }
                        }
                    }
                }
            }
            match target {
                Some(q) => {
                    if q != p {
                        faces[fi].mesh.pos[v as usize] = q;
                        moved[fi].push(v);
                    }
                }
                None => grid.entry((kx, ky, kz)).or_default().push((fi as u32, v)),
            }
        }
    }
    for (fi, vs) in moved.iter().enumerate() {
        if vs.is_empty() {
            continue;
        }
        let set: hashbrown::HashSet<u32> = vs.iter().copied().collect();
        for (t, tri) in faces[fi].mesh.tris.iter().enumerate() {
            if tri.iter().any(|v| set.contains(v)) {
                changed[fi].push(t as u32);
            }
        }
    }
}
