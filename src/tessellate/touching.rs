//! Faces that touch away from their shared border: two halves of a
//! mirrored part meeting at a degenerate corner (a fuselage's nose, a hull's
//! stem), or neighbouring faces of an assembly's part at a coarse
//! tolerance, can each cut across with an inner edge between the same two
//! border nodes, so the edge has two triangles of each face. Each face's
//! inner edge is split at its own surface's point halfway along it in
//! (u,v), which lies off the chord on that face's side, so the faces part
//! there.

use alloc::vec::Vec;
use glam::DVec3;

use super::refine::{WorkMesh, NONE};
use super::sew::FaceWork;
use crate::collections::HashMap;
use crate::nurbs::Surface;

/// An edge's two vertices in a face's mesh.
type Ends = (u32, u32);

/// One face's edge between two border nodes: the face, its ends and how
/// many of the face's triangles have it (two: an inner edge).
#[derive(Clone, Copy)]
struct Use {
    face: u32,
    ends: (u32, u32),
    triangles: u8,
}

/// Splits, in each face, every inner edge between two border nodes whose
/// pair of node ids another face's edge also joins. A pair is left as it
/// is where one border edge would be left alone on it (the split would
/// open a crack where the mesh has an edge of three triangles), where two
/// faces' split points are within `apart` (coincident surfaces: they would
/// meet again), and in a face where a triangle of the split would turn
/// against its surface. Returns how many edges were split.
pub(crate) fn part_touching(faces: &mut [FaceWork<'_>], apart: f64) -> usize {
    let mut split: Vec<(u32, Ends)> = Vec::new();
    for uses in edge_uses(faces).into_values().filter(|u| u.len() > 1) {
        if uses.iter().filter(|u| u.triangles == 1).count() == 1 {
            continue;
        }
        let mut points: Vec<(DVec3, (u32, Ends))> = Vec::new();
        for u in uses.iter().filter(|u| u.triangles == 2) {
            let w = &faces[u.face as usize];
            let Some(p) = split_point(&w.mesh, w.surface, u.ends) else { continue };
            points.push((p, (u.face, u.ends)));
        }
        let close = points.iter().enumerate().any(|(i, p)| points[i + 1..].iter().any(|q| p.0.distance(q.0) <= apart));
        if !close {
            split.extend(points.into_iter().map(|p| p.1));
        }
    }
    let mut split: Vec<(u32, u32, u32)> = split.into_iter().map(|(f, (a, b))| (f, a, b)).collect();
    crate::sort::triples(&mut split);
    let mut made = 0;
    for (f, a, b) in split {
        let w = &mut faces[f as usize];
        if w.mesh.edge_triangles(a, b) != 2 || w.mesh.is_border(a, b) {
            continue;
        }
        let mut out = Vec::new();
        if w.mesh.split_edge_at(w.surface, &w.curves, a, b, 0.5, None, &mut out).is_some() {
            made += 1;
        }
        w.mesh.rest();
    }
    made
}

/// Per pair of node ids: each face's edge between them.
fn edge_uses(faces: &[FaceWork<'_>]) -> HashMap<(u32, u32), Vec<Use>> {
    let mut seen: HashMap<(u32, u32), Vec<Use>> = HashMap::default();
    for (f, w) in faces.iter().enumerate() {
        let mut mine: HashMap<(u32, u32), Use> = HashMap::default();
        for v in &w.mesh.tris {
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                let (ga, gb) = (w.mesh.gid[a as usize], w.mesh.gid[b as usize]);
                if ga == NONE || gb == NONE || ga == gb {
                    continue;
                }
                let ends = (a.min(b), a.max(b));
                mine.entry((ga.min(gb), ga.max(gb))).or_insert(Use { face: f as u32, ends, triangles: 0 }).triangles +=
                    1;
            }
        }
        for (ids, u) in mine {
            seen.entry(ids).or_default().push(u);
        }
    }
    seen
}

/// The point halfway along inner edge `ends` in (u,v) on `surface` (in
/// its first triangle's chart), when no triangle of the split would face
/// against the surface.
fn split_point(mesh: &WorkMesh, surface: &dyn Surface, (a, b): (u32, u32)) -> Option<DVec3> {
    let mut on = (0..mesh.tris.len()).filter(|&t| mesh.tris[t].contains(&a) && mesh.tris[t].contains(&b));
    let (t0, t1) = (on.next()?, on.next()?);
    let mut first = None;
    for t in [t0, t1] {
        let (v, uv) = (mesh.tris[t], mesh.uv(t));
        let ka = v.iter().position(|&x| x == a)?;
        let kb = v.iter().position(|&x| x == b)?;
        let mid = (uv[ka] + uv[kb]) * 0.5;
        let q = surface.point(mid);
        if !q.is_finite() {
            return None;
        }
        // Each half keeps the other corners, with the new point for a or for b.
        for k in [ka, kb] {
            let (mut pts, mut w) = (v.map(|x| mesh.pos[x as usize]), uv);
            (pts[k], w[k]) = (q, mid);
            let facet = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
            if facet.dot(surface.normal((w[0] + w[1] + w[2]) / 3.0)) <= 0.0 {
                return None;
            }
        }
        first.get_or_insert(q);
    }
    first
}
