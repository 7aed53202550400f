//! Topology and shape measures of a mesh: free, crack and non-manifold edges; angles.

use crate::warning::{Warning, WarningKind};
use alloc::vec::Vec;
use glam::DVec3;

use super::{weld::weld_positions, FaceRange, Mesh};
use crate::model::SkippedFace;
use crate::nurbs::{Aabb, NurbsCurve};

/// Edge census after welding coincident vertices (see [`edge_counts`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EdgeCounts {
    /// Edges with exactly one triangle.
    pub boundary_edges: usize,
    /// Boundary edges that run along the border of another face within the
    /// sewing distance without being connected to it (unwelded borders,
    /// T-junctions): cracks. A face's border that meets no other face is the
    /// model's open boundary, not a crack.
    pub free_edges: usize,
    /// Edges with more than two triangles.
    pub nonmanifold_edges: usize,
    /// Edges whose two triangles run the same way (orientation flips).
    pub misoriented_edges: usize,
    /// Of the free edges, those that run along the border of a face the
    /// reader skipped: the hole it leaves.
    pub hole_edges: usize,
}

/// Counts boundary, crack and non-manifold edges after welding vertices
/// closer than `weld_tol` (a face's inner vertices never with its own nor
/// with a border: its triangles join them); `sew_tol` is how close
/// unconnected borders must be to count as a crack.
pub fn edge_counts(mesh: &Mesh, weld_tol: f64, sew_tol: f64) -> EdgeCounts {
    edge_counts_in_bodies(mesh, &[], weld_tol, sew_tol)
}

/// As [`edge_counts`], with faces in bodies (`bodies[face]`, empty: one
/// body): vertices of different bodies are never welded, and a border is a
/// crack only next to another border of its own body, so parts of an
/// assembly that touch are counted each on its own.
pub fn edge_counts_in_bodies(mesh: &Mesh, bodies: &[u32], weld_tol: f64, sew_tol: f64) -> EdgeCounts {
    edge_counts_around_skipped(mesh, bodies, &[], weld_tol, sew_tol)
}

/// As [`edge_counts_in_bodies`], where `skipped` are the faces the reader
/// could not build: a boundary edge that runs along one's border (its
/// quarter, half and three-quarter points within twice `sew_tol` of it, in
/// the same body) is a crack too, the hole the missing face leaves, and not
/// the model's own boundary.
pub fn edge_counts_around_skipped(
    mesh: &Mesh,
    bodies: &[u32],
    skipped: &[SkippedFace],
    weld_tol: f64,
    sew_tol: f64,
) -> EdgeCounts {
    edge_census(mesh, bodies, &[], skipped, weld_tol, sew_tol).0
}

/// Where two faces' borders run side by side unjoined (see [`edge_census`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gap {
    /// The two faces, the lower index first.
    pub faces: (u32, u32),
    /// The widest distance, over their cracks, from a point of a crack edge
    /// (its quarter, half or three-quarter point) to the nearest border point
    /// of the other face beside it.
    pub width: f64,
}

/// As [`edge_counts_around_skipped`], with the gaps of the cracks: per pair
/// of faces whose borders crack apart, how far apart they lie. A face's
/// vertices weld within `weld_tol` times its `scale` (empty: 1 for all),
/// the share of the sewing distances its body took.
pub(crate) fn edge_census(
    mesh: &Mesh,
    bodies: &[u32],
    scale: &[f64],
    skipped: &[SkippedFace],
    weld_tol: f64,
    sew_tol: f64,
) -> (EdgeCounts, Vec<Gap>) {
    let face_of = face_lookup(mesh);
    let scale_of = |f: u32| scale.get(f as usize).copied().unwrap_or(1.0);
    let (mut map, mut nverts) = weld_borders(mesh, &face_of, &scale_of, scale.iter().all(|&k| k == 1.0), weld_tol);
    let body_of_face = |f: u32| crate::model::body_of(bodies, f as usize);
    if !bodies.is_empty() {
        split_by_body(mesh, body_of_face, &face_of, &mut map, &mut nverts);
    }
    // Each welded vertex's last position stands for it.
    let mut rep = alloc::vec![0u32; nverts];
    for (i, &m) in map.iter().enumerate() {
        rep[m as usize] = i as u32;
    }
    let pos = |m: u32| mesh.positions[rep[m as usize] as usize];
    // The triangles at each welded vertex (offsets, then the list): 16
    // bytes a triangle where a table of the edges took 40.
    let tri = |ti: usize| {
        let t = &mesh.indices[3 * ti..3 * ti + 3];
        [map[t[0] as usize], map[t[1] as usize], map[t[2] as usize]]
    };
    let count = mesh.indices.len() / 3;
    let live = |v: &[u32; 3]| v[0] != v[1] && v[1] != v[2] && v[2] != v[0]; // not collapsed by welding (pole)
    let mut start = alloc::vec![0u32; nverts + 1];
    for ti in 0..count {
        let v = tri(ti);
        if live(&v) {
            for x in v {
                start[x as usize + 1] += 1;
            }
        }
    }
    for i in 0..nverts {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut at = alloc::vec![0u32; start[nverts] as usize];
    for ti in 0..count {
        let v = tri(ti);
        if live(&v) {
            for x in v {
                at[fill[x as usize] as usize] = ti as u32;
                fill[x as usize] += 1;
            }
        }
    }
    drop(fill);
    let mut out = EdgeCounts::default();
    let mut free: Vec<(u32, u32, u32)> = Vec::new();
    // Each edge from its lower end: the higher end, whether a triangle runs
    // it high to low, and the triangle.
    let mut around: Vec<(u32, bool, u32)> = Vec::new();
    for a in 0..nverts as u32 {
        around.clear();
        for &ti in &at[start[a as usize] as usize..start[a as usize + 1] as usize] {
            let v = tri(ti as usize);
            for k in 0..3 {
                let (p, q) = (v[k], v[(k + 1) % 3]);
                if p == a && q > a {
                    around.push((q, false, ti));
                } else if q == a && p > a {
                    around.push((p, true, ti));
                }
            }
        }
        crate::sort::flagged_triples(&mut around);
        for run in around.chunk_by(|x, y| x.0 == y.0) {
            let back = run.iter().filter(|x| x.1).count();
            match run.len() {
                1 => free.push((a, run[0].0, face_of(run[0].2 as usize))),
                2 => {
                    if back != 1 {
                        out.misoriented_edges += 1;
                    }
                }
                _ => out.nonmanifold_edges += 1,
            }
        }
    }
    drop((at, start, around));
    out.boundary_edges = free.len();
    let (cracks, holes) = find_cracks(&free, &pos, sew_tol, &body_of_face, skipped);
    out.free_edges = cracks.len() + holes;
    out.hole_edges = holes;
    let mut gaps: Vec<Gap> = Vec::new();
    for (faces, width) in cracks {
        match gaps.iter_mut().find(|g| g.faces == faces) {
            Some(g) => g.width = g.width.max(width),
            None => gaps.push(Gap { faces, width }),
        }
    }
    crate::sort::by_u64(&mut gaps, |g| crate::sort::pair(g.faces.0, g.faces.1));
    (out, gaps)
}

/// The census's weld: [`weld_scaled`] over the vertices on their face's
/// border ([`on_face_border`]) and, apart, over the inner ones, where two
/// inner vertices of one face stay two. Only borders can be joined to
/// another face's or left open beside it (a crack). A face's inner
/// vertices are joined by its own triangles: welding two of one face joins
/// layers of a face that passes near itself (a pleated or self-touching
/// surface) into edges of four triangles that neither layer has, and one
/// on another face's border is a layer touching that border, not a join.
/// Inner vertices of two faces still weld: faces that lie on each other
/// stay non-manifold. `one_scale`: every face's scale is 1.
fn weld_borders(
    mesh: &Mesh,
    face_of: &dyn Fn(usize) -> u32,
    scale: &dyn Fn(u32) -> f64,
    one_scale: bool,
    weld: f64,
) -> (Vec<u32>, usize) {
    let border = on_face_border(mesh);
    if border.iter().all(|&b| b) {
        return if one_scale { weld_positions(&mesh.positions, weld) } else { weld_scaled(mesh, face_of, scale, weld) };
    }
    let of_vertex = if one_scale { Vec::new() } else { vertex_scales(mesh, face_of, scale) };
    let scale_at = |v: usize| of_vertex.get(v).copied().unwrap_or(1.0);
    let mut scales: Vec<f64> = if one_scale { alloc::vec![1.0] } else { of_vertex.clone() };
    crate::sort::f64s(&mut scales);
    scales.dedup();
    let mut map = alloc::vec![u32::MAX; mesh.positions.len()];
    let mut count = 0usize;
    for on_border in [true, false] {
        for &k in &scales {
            let members: Vec<usize> =
                (0..border.len()).filter(|&v| border[v] == on_border && scale_at(v) == k).collect();
            let points: Vec<DVec3> = members.iter().map(|&v| mesh.positions[v]).collect();
            let (sub, n) = weld_positions(&points, weld * k);
            for (&v, &m) in members.iter().zip(&sub) {
                map[v] = (count + m as usize) as u32;
            }
            count += n;
        }
    }
    count = split_layers(mesh, face_of, &border, &mut map, count);
    (map, count)
}

/// Of the welded inner vertices (`border` false, `map` to `count` ids),
/// those welded with another of their face's get ids of their own (see
/// [`weld_borders`]). Returns the new count.
fn split_layers(
    mesh: &Mesh,
    face_of: &dyn Fn(usize) -> u32,
    border: &[bool],
    map: &mut [u32],
    mut count: usize,
) -> usize {
    let mut face = alloc::vec![u32::MAX; mesh.positions.len()];
    for (ti, t) in mesh.indices.chunks_exact(3).enumerate() {
        for &v in t {
            if let Some(x) = face.get_mut(v as usize) {
                *x = face_of(ti);
            }
        }
    }
    let mut inner: Vec<(u64, u32)> =
        (0..map.len()).filter(|&v| !border[v]).map(|v| (crate::sort::pair(map[v], face[v]), v as u32)).collect();
    crate::sort::sort_u64_keys(&mut inner);
    for run in inner.chunk_by(|x, y| x.0 == y.0).filter(|r| r.len() > 1) {
        for &(_, v) in &run[1..] {
            map[v as usize] = count as u32;
            count += 1;
        }
    }
    count
}

/// Each vertex's scale: that of the face of the last triangle using it (1
/// for a vertex no triangle uses).
fn vertex_scales(mesh: &Mesh, face_of: &dyn Fn(usize) -> u32, scale: &dyn Fn(u32) -> f64) -> Vec<f64> {
    let mut of_vertex = alloc::vec![1.0f64; mesh.positions.len()];
    for (ti, t) in mesh.indices.chunks_exact(3).enumerate() {
        let k = scale(face_of(ti));
        for &v in t {
            if let Some(x) = of_vertex.get_mut(v as usize) {
                *x = k;
            }
        }
    }
    of_vertex
}

/// Per vertex, whether it lies on its face's border by index: on an edge
/// that one triangle of its face uses (or more than two), or on no
/// triangle with three corners. Faces are the mesh's face ranges (none: the mesh is one face);
/// a vertex two faces share by index is on both borders.
fn on_face_border(mesh: &Mesh) -> Vec<bool> {
    let mut border = alloc::vec![false; mesh.positions.len()];
    let count = mesh.indices.len() / 3;
    let whole = [FaceRange { first: 0, count: count as u32 }];
    let ranges = if mesh.face_ranges.is_empty() { &whole[..] } else { &mesh.face_ranges[..] };
    let mut used = alloc::vec![false; mesh.positions.len()];
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for r in ranges {
        edges.clear();
        let (lo, hi) = (r.first as usize, (r.first as usize + r.count as usize).min(count));
        for t in mesh.indices.get(3 * lo..3 * hi).unwrap_or(&[]).chunks_exact(3) {
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.push((a.min(b), a.max(b)));
                if let Some(u) = used.get_mut(a as usize) {
                    *u = true;
                }
            }
        }
        crate::sort::pairs(&mut edges);
        for run in edges.chunk_by(|x, y| x == y) {
            if run.len() == 2 {
                continue;
            }
            for v in [run[0].0, run[0].1] {
                if let Some(b) = border.get_mut(v as usize) {
                    *b = true;
                }
            }
        }
    }
    for (b, u) in border.iter_mut().zip(used) {
        *b |= !u;
    }
    border
}

/// [`weld_positions`] within `weld` times the scale of each vertex's face
/// (`face_of` triangle, `scale` of face; 1 for a vertex no triangle uses):
/// each scale's vertices welded on their own, their ids following the last
/// scale's. One scale throughout is one weld of all positions.
pub(crate) fn weld_scaled(
    mesh: &Mesh,
    face_of: &dyn Fn(usize) -> u32,
    scale: &dyn Fn(u32) -> f64,
    weld: f64,
) -> (Vec<u32>, usize) {
    let of_vertex = vertex_scales(mesh, face_of, scale);
    if of_vertex.iter().all(|&k| k == 1.0) {
        return weld_positions(&mesh.positions, weld);
    }
    let mut scales = of_vertex.clone();
    crate::sort::f64s(&mut scales);
    scales.dedup();
    let mut map = alloc::vec![0u32; mesh.positions.len()];
    let mut count = 0usize;
    for k in scales {
        let members: Vec<usize> = (0..of_vertex.len()).filter(|&v| of_vertex[v] == k).collect();
        let points: Vec<DVec3> = members.iter().map(|&v| mesh.positions[v]).collect();
        let (sub, n) = weld_positions(&points, weld * k);
        for (&v, &m) in members.iter().zip(&sub) {
            map[v] = (count + m as usize) as u32;
        }
        count += n;
    }
    (map, count)
}

/// Welded vertices (`map`, `nverts` of them) split by body: one keeps its
/// id (the body of its first position), the few that touch another body get
/// new ones. Each vertex's body comes from the triangles that use it (faces
/// own their vertices).
fn split_by_body(
    mesh: &Mesh,
    body_of_face: impl Fn(u32) -> u32,
    face_of: impl Fn(usize) -> u32,
    map: &mut [u32],
    nverts: &mut usize,
) {
    let mut body_of_vertex = alloc::vec![0u32; mesh.positions.len()];
    for (ti, t) in mesh.indices.chunks_exact(3).enumerate() {
        for &v in t {
            if let Some(b) = body_of_vertex.get_mut(v as usize) {
                *b = body_of_face(face_of(ti));
            }
        }
    }
    let mut home = alloc::vec![u32::MAX; *nverts];
    let mut extra: crate::collections::HashMap<(u32, u32), u32> = crate::collections::HashMap::default();
    for (v, m) in map.iter_mut().enumerate() {
        let b = body_of_vertex[v];
        let h = &mut home[*m as usize];
        if *h == u32::MAX {
            *h = b;
        } else if *h != b {
            let next = (*nverts + extra.len()) as u32;
            *m = *extra.entry((*m, b)).or_insert(next);
        }
    }
    *nverts += extra.len();
}

/// The report's line about faces the reader skipped, if any: how many, and
/// how many edges of the mesh run open along them (`holes`).
pub(crate) fn holes_warning(skipped: &[SkippedFace], holes: usize, warnings: &mut Vec<Warning>) {
    if skipped.is_empty() {
        return;
    }
    warnings.push(Warning::new(WarningKind::UnreadFaces { count: skipped.len(), holes }));
}

/// Face index of each triangle, from the mesh's face ranges (0 when absent).
fn face_lookup(mesh: &Mesh) -> impl Fn(usize) -> u32 + '_ {
    move |t: usize| {
        let i = mesh.face_ranges.partition_point(|r| (r.first as usize + r.count as usize) <= t);
        i.min(mesh.face_ranges.len().saturating_sub(1)) as u32
    }
}

/// A free edge is a crack when a vertex of a free edge of another face of
/// its body, or a point along one running beside it, lies within `sew` (and within a fifth of
/// the edge's length) of its quarter, half or three-quarter point. A vertex
/// on the edge's own face's border too is not: the two faces are joined
/// there, and the edge passes it where its own face is narrower than `sew`
/// (a strip whose far side comes near a corner it shares with a
/// neighbour). The points along an edge lie at most half of `sew` apart, so
/// a long border beside a short crack is seen wherever it passes, not only
/// near its ends and middle (a sliver hole whose sides are long beside its
/// width). A free edge that runs along the border of a skipped face of its
/// body ([`Holes::along`]) is a crack too, the missing face's hole.
/// Returns, per crack between two faces, the faces (lower first) and how
/// far apart they lie there: the largest, over the three points, of the
/// distance to the nearest border point of the other face; and how many
/// cracks run along skipped faces.
fn find_cracks(
    free: &[(u32, u32, u32)],
    pos: &dyn Fn(u32) -> DVec3,
    sew: f64,
    body: &dyn Fn(u32) -> u32,
    skipped: &[SkippedFace],
) -> (Vec<Crack>, usize) {
    let mut cracks = Vec::new();
    if free.is_empty() || !(sew > 0.0 && sew.is_finite()) {
        return (cracks, 0);
    }
    // Points of interest: free-edge vertices (tag = vertex id) and points along the edges.
    #[derive(Clone, Copy)]
    enum Tag {
        Vertex(u32),
        /// A point along an edge, with the edge's direction.
        Along(DVec3),
    }
    let length: f64 = free.iter().map(|&(a, b, _)| pos(a).distance(pos(b))).sum();
    // Half the sewing distance apart, but no more than ALONG_POINTS in all
    // (a tolerance far below the model's size along long open borders).
    let spacing = (0.5 * sew).max(length / ALONG_POINTS as f64);
    let mut grid = crate::collections::CellGrid::new(1.0 / sew);
    let mut seen = crate::collections::HashSet::default();
    for &(a, b, f) in free {
        for v in [a, b] {
            if seen.insert((v, f)) {
                let p = pos(v);
                grid.insert(p, (p, Tag::Vertex(v), f));
            }
        }
        let (pa, pb) = (pos(a), pos(b));
        let dir = (pb - pa).normalize_or_zero();
        // At least the midpoint; the fraction of ALONG_POINTS this edge's length earns.
        let n = (crate::math::ceil(pa.distance(pb) / spacing) as usize).clamp(2, ALONG_POINTS);
        for k in 1..n {
            let m = pa.lerp(pb, k as f64 / n as f64);
            grid.insert(m, (m, Tag::Along(dir), f));
        }
    }
    let holes = Holes::new(skipped, 2.0 * sew);
    let mut along = 0;
    for &(a, b, face) in free {
        let (pa, pb) = (pos(a), pos(b));
        // Relative to the edge too: an open border's own neighbours sit half an edge away.
        let reach = sew.min(0.2 * pa.distance(pb));
        let dir = (pb - pa).normalize_or_zero();
        // Per point of the edge, the nearest other face's border point beside it, and that face.
        let mut hit: Option<(f64, u32)> = None;
        let mut width: f64 = 0.0;
        for q in [0.25, 0.5, 0.75].map(|f| pa.lerp(pb, f)) {
            let mut nearest: Option<(f64, u32)> = None;
            for &(p, tag, f) in grid.near(q) {
                let other = f != face
                    && body(f) == body(face)
                    && match tag {
                        Tag::Vertex(v) => v != a && v != b && !seen.contains(&(v, face)),
                        // Side by side, not two borders leaving a corner apart.
                        Tag::Along(d) => d.dot(dir).abs() >= SIDE_BY_SIDE,
                    };
                let d = p.distance(q);
                if other && d < reach && nearest.is_none_or(|h| d < h.0) {
                    nearest = Some((d, f));
                }
            }
            if let Some((d, f)) = nearest {
                width = width.max(d);
                if hit.is_none_or(|h| d < h.0) {
                    hit = Some((d, f));
                }
            }
        }
        if let Some((_, f)) = hit {
            cracks.push(((face.min(f), face.max(f)), width));
        } else if holes.along(pa, pb, body(face)) {
            along += 1;
        }
    }
    (cracks, along)
}

/// The least cosine of the angle between two free edges that
/// [`find_cracks`] takes to run side by side (10 degrees): borders of two
/// faces that leave a corner they share at a wider angle are an open
/// boundary's, however near each other they start (a notch of 25 degrees
/// between two walls was taken for a crack at 0.9). A sliver between faces
/// narrows to a few degrees.
const SIDE_BY_SIDE: f64 = 0.985;

/// The most points [`find_cracks`] places along the free edges in all.
const ALONG_POINTS: usize = 200_000;

/// The border curves of skipped faces, each with its body and its box, for [`Holes::along`].
struct Holes<'a> {
    curves: Vec<(&'a NurbsCurve, u32, Aabb)>,
    reach: f64,
}

impl<'a> Holes<'a> {
    fn new(skipped: &'a [SkippedFace], reach: f64) -> Self {
        let mut curves = Vec::new();
        for s in skipped {
            for c in &s.border {
                let b = c.bbox();
                if !b.is_empty() {
                    curves.push((c, s.body, b));
                }
            }
        }
        Self { curves, reach }
    }

    /// Whether the edge `pa`–`pb` of body `body` runs along one skipped
    /// face's border: its quarter, half and three-quarter points all lie
    /// within the reach of one of that face's curves (an edge that only
    /// meets the border at a corner has at least one of them farther).
    fn along(&self, pa: DVec3, pb: DVec3, body: u32) -> bool {
        let points = [0.25, 0.5, 0.75].map(|f| pa.lerp(pb, f));
        self.curves.iter().any(|(c, b, bbox)| {
            *b == body
                && points.iter().all(|&q| bbox.contains(q, self.reach))
                && points.iter().all(|&q| c.project(q).distance <= self.reach)
        })
    }
}

/// A crack between two faces: the faces (lower first) and its width.
type Crack = ((u32, u32), f64);

/// Triangle angle distribution.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AngleStats {
    /// Smallest angle of any triangle, degrees.
    pub min_deg: f64,
    /// 1st percentile of the triangles' smallest angles, degrees.
    pub p1_deg: f64,
}

/// Smallest and 1st-percentile triangle angles (of each triangle's smallest angle).
/// Triangles of zero area count as 0°.
pub fn angle_stats(mesh: &Mesh) -> AngleStats {
    let n = mesh.triangle_count();
    if n == 0 {
        return AngleStats::default();
    }
    let mut mins: Vec<f64> = (0..n).map(|t| min_angle(mesh.triangle(t))).collect();
    crate::sort::f64s(&mut mins);
    let p1 = mins[(n - 1) / 100];
    AngleStats { min_deg: mins[0].to_degrees(), p1_deg: p1.to_degrees() }
}

/// Smallest interior angle of a triangle, radians.
pub(crate) fn min_angle(t: [DVec3; 3]) -> f64 {
    let mut m = f64::INFINITY;
    for k in 0..3 {
        let a = t[(k + 1) % 3] - t[k];
        let b = t[(k + 2) % 3] - t[k];
        let ang = crate::math::angle_between(a, b);
        if a.length_squared() == 0.0 || b.length_squared() == 0.0 {
            return 0.0;
        }
        m = m.min(ang);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::FaceRange;

    /// Two faces on the plane z = 0: `a`'s triangles, then `b`'s.
    fn two_faces(pts: &[(f64, f64)], a: &[[u32; 3]], b: &[[u32; 3]]) -> Mesh {
        let indices: Vec<u32> = a.iter().chain(b).flatten().copied().collect();
        Mesh {
            positions: pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect(),
            normals: Vec::new(),
            indices,
            face_ranges: alloc::vec![
                FaceRange { first: 0, count: a.len() as u32 },
                FaceRange { first: a.len() as u32, count: b.len() as u32 }
            ],
        }
    }

    /// A T-junction: face b's border has a node in the middle of face a's
    /// edge, which a lacks. That edge is a crack.
    #[test]
    fn a_node_of_another_face_along_a_free_edge_is_a_crack() {
        let pts = [(0.0, 0.0), (4.0, 0.0), (2.0, -2.0), (2.0, 0.0), (1.0, 2.0), (3.0, 2.0)];
        let m = two_faces(&pts, &[[0, 2, 1]], &[[0, 3, 4], [3, 1, 5], [3, 5, 4]]);
        // Face a's edge, and face b's two halves of it, which run along it.
        assert_eq!(edge_counts(&m, 1e-9, 1.0).free_edges, 3);
        // The node lies on the edge: a gap of nothing between faces 0 and 1.
        assert_eq!(edge_census(&m, &[], &[], &[], 1e-9, 1.0).1, [Gap { faces: (0, 1), width: 0.0 }]);
        // Lifted 0.3 off it, the node is the nearest of face 1's border
        // points to the edge's middle: the faces lie 0.3 apart there.
        let mut lifted = m.clone();
        lifted.positions[3].z = 0.3;
        let gaps = edge_census(&lifted, &[], &[], &[], 1e-9, 1.0).1;
        assert!(gaps.len() == 1 && (gaps[0].width - 0.3).abs() < 1e-12, "{gaps:?}");
    }

    /// A sliver hole whose sides are long beside the sewing distance: face
    /// b's border bends 0.05 off face a's straight edge at a node 4 units
    /// along it, and neither face's vertices nor its edges' midpoints come
    /// within the sewing distance (0.2) of the other's edges. All three
    /// sides are cracks, and the faces lie about 0.04 apart at the edge's
    /// middle.
    #[test]
    fn a_long_sided_sliver_between_two_faces_is_a_crack() {
        let pts = [(0.0, 0.0), (10.0, 0.0), (5.0, -3.0), (4.0, 0.05), (5.0, 3.0)];
        let m = two_faces(&pts, &[[0, 2, 1]], &[[0, 3, 4], [3, 1, 4]]);
        assert_eq!(edge_counts(&m, 1e-9, 0.2).free_edges, 3);
        let gaps = edge_census(&m, &[], &[], &[], 1e-9, 0.2).1;
        assert!(gaps.len() == 1 && gaps[0].width > 0.03 && gaps[0].width < 0.05, "{gaps:?}");
    }

    /// A strip 0.5 wide (face a, its top border through node 4) that face b
    /// touches at node 4 alone: the strip's bottom edge passes node 4 at
    /// half a unit, within the sewing distance, yet the two faces are
    /// joined there, and nothing is missing.
    #[test]
    fn a_corner_both_faces_have_is_no_crack_of_a_narrow_face() {
        let pts = [(0.0, 0.0), (10.0, 0.0), (10.0, 0.5), (0.0, 0.5), (5.0, 0.5), (4.0, 3.0), (6.0, 3.0)];
        let m = two_faces(&pts, &[[0, 1, 4], [1, 2, 4], [0, 4, 3]], &[[4, 6, 5]]);
        let c = edge_counts(&m, 1e-9, 1.0);
        assert_eq!(c.boundary_edges, 8);
        assert_eq!(c.free_edges, 0);
    }

    /// A 4 x 4 grid of points `(x0 + i, j, z(i, j))`, two triangles a
    /// cell, appended to `m` as a face of its own.
    fn grid(m: &mut Mesh, x0: f64, z: impl Fn(usize, usize) -> f64) {
        let base = m.positions.len() as u32;
        for j in 0..4 {
            for i in 0..4 {
                m.positions.push(DVec3::new(x0 + i as f64, j as f64, z(i, j)));
            }
        }
        let first = (m.indices.len() / 3) as u32;
        let at = |i: u32, j: u32| base + 4 * j + i;
        for j in 0..3 {
            for i in 0..3 {
                m.indices.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        m.face_ranges.push(FaceRange { first, count: 18 });
    }

    /// A pleat: one face whose two layers pass through the same points
    /// inside it (the four inner vertices of two grids coincide to 1e-12,
    /// their borders bent a unit apart). Its triangles join no layer to the
    /// other, and the census welds only borders: no edge has four triangles.
    #[test]
    fn layers_of_one_face_touching_inside_it_are_not_welded() {
        let mut m = Mesh::default();
        grid(&mut m, 0.0, |_, _| 0.0);
        grid(&mut m, 0.0, |i, j| if (1..3).contains(&i) && (1..3).contains(&j) { 1e-12 } else { -1.0 });
        // The two grids one face.
        m.face_ranges = alloc::vec![FaceRange { first: 0, count: 36 }];
        let c = edge_counts(&m, 1e-9, 0.1);
        assert_eq!(c.nonmanifold_edges, 0, "{c:?}");
        assert_eq!(c.boundary_edges, 24);
        // Two faces so placed lie on each other: their inner vertices still
        // weld, and the grids' five inner edges have four triangles each.
        m.face_ranges = alloc::vec![FaceRange { first: 0, count: 18 }, FaceRange { first: 18, count: 18 }];
        assert_eq!(edge_counts(&m, 1e-9, 0.1).nonmanifold_edges, 5);
    }

    /// Two faces side by side: the second's first column on the first's
    /// last, to 1e-12, joins (no crack); moved 0.05 off it, within the
    /// sewing distance, it is a crack on both sides. Borders weld as before.
    #[test]
    fn borders_of_two_faces_still_weld_and_crack() {
        let mut m = Mesh::default();
        grid(&mut m, 0.0, |_, _| 0.0);
        grid(&mut m, 3.0, |i, _| if i == 0 { 1e-12 } else { 0.0 });
        let c = edge_counts(&m, 1e-9, 0.1);
        assert_eq!((c.boundary_edges, c.free_edges, c.nonmanifold_edges), (18, 0, 0), "{c:?}");
        let mut cracked = Mesh::default();
        grid(&mut cracked, 0.0, |_, _| 0.0);
        grid(&mut cracked, 3.0, |i, _| if i == 0 { 0.05 } else { 0.0 });
        let c = edge_counts(&cracked, 1e-9, 0.1);
        assert_eq!((c.boundary_edges, c.free_edges), (24, 6), "{c:?}");
    }
}
