//! Paper 002 §4.2: the sub-triangulation of one intersected triangle. Its
//! edges are split at the points where other triangles cross them, its
//! intersection segments are split where they cross each other (triple
//! points), and a constrained Delaunay triangulation ([`super::cdt`]) of all
//! that is made in the triangle's plane. Every fact shared with another
//! triangle (which points lie on an edge and in what order, where a segment is
//! split) is computed from data both triangles see identically, so the
//! sub-triangles of neighbours and of the two triangles of a segment meet
//! edge to edge.

use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::{DVec2, DVec3};

use super::cdt::{triangulate, Cdt, Conflict};
use super::intersect::{crossing_parameter, position, side_at, triple_exists, Intersections};
use super::topology::{key, NONE};
use super::tritri::{drop_axis, project, PointKey};
use crate::predicates::{orient2d, side};

/// How close (as a fraction of the triangle) a point may come to its edges
/// in the 2-D picture; closer ones are pushed in (the 3-D position is kept).
const MARGIN: f64 = 1e-10;

/// The points of the arrangement: mesh vertices first (same ids), then the
/// others as triangles that need them are sub-triangulated.
pub(crate) struct Points {
    pub pos: Vec<DVec3>,
    ids: crate::collections::HashMap<PointKey, u32>,
}

impl Points {
    pub(crate) fn new(vertices: &[DVec3]) -> Self {
        Self { pos: vertices.to_vec(), ids: crate::collections::HashMap::default() }
    }

    fn id(&mut self, k: PointKey, g: &Geometry<'_>) -> u32 {
        if let PointKey::Vertex(v) = k {
            return v;
        }
        if let Some(&i) = self.ids.get(&k) {
            return i;
        }
        let i = self.pos.len() as u32;
        self.pos.push(position(g.positions, g.tris, g.x, k));
        self.ids.insert(k, i);
        i
    }
}

/// The mesh and its intersections, read-only.
pub(crate) struct Geometry<'a> {
    pub positions: &'a [DVec3],
    pub tris: &'a [[u32; 3]],
    /// Neighbour across each edge, `3 * t + k`.
    pub nbr: &'a [[u32; 3]],
    pub x: &'a Intersections,
}

/// One triangle's sub-triangulation.
pub(crate) struct Sub {
    /// Global point id of each local point.
    pub pts: Vec<u32>,
    pub cdt: Cdt,
    /// For a constraint edge, the other triangle of its segment; else [`NONE`].
    pub partner: Vec<[u32; 3]>,
    /// For an edge on the triangle's boundary, which of its edges (0..3); else 3.
    pub base_edge: Vec<[u8; 3]>,
    pub visited: Vec<bool>,
    /// Whether the constraints had to be left out (see [`build`]).
    pub fallback: bool,
}

impl Sub {
    /// The sub-triangle with the edge running `u -> v` (global ids).
    pub(crate) fn find(&self, u: u32, v: u32) -> Option<u32> {
        self.cdt
            .tris
            .iter()
            .position(|t| (0..3).any(|k| self.pts[t[k] as usize] == u && self.pts[t[(k + 1) % 3] as usize] == v))
            .map(|s| s as u32)
    }
}

/// Edge points of base edge `k` of triangle `t`: every segment end on that
/// edge, from `t`'s segments and its neighbour's, ordered from the edge's
/// lower vertex id to its higher one (exactly), ties by triangle id.
fn edge_points(g: &Geometry<'_>, t: u32, k: usize) -> Vec<PointKey> {
    let tv = g.tris[t as usize];
    let (lo, hi) = key(tv[k], tv[(k + 1) % 3]);
    let mut out: Vec<PointKey> = Vec::new();
    let mut add = |s: u32| {
        for e in g.x.segments[s as usize].ends {
            if let PointKey::EdgeTri(a, b, _) = e {
                if (a, b) == (lo, hi) && !out.contains(&e) {
                    out.push(e);
                }
            }
        }
    };
    for &s in g.x.of(t) {
        add(s);
    }
    let u = g.nbr[t as usize][k];
    if u != NONE {
        for &s in g.x.of(u / 3) {
            add(s);
        }
    }
    let plo = g.positions[lo as usize];
    let tri = |i: u32| g.tris[i as usize].map(|v| g.positions[v as usize]);
    // Insertion sort: the lists are short, and a hand-written sort cannot panic.
    for i in 1..out.len() {
        let mut j = i;
        while j > 0 && before(g, out[j], out[j - 1], plo, &tri) {
            out.swap(j, j - 1);
            j -= 1;
        }
    }
    out
}

/// Whether edge point `a` comes before `b` walking from `plo`.
fn before(g: &Geometry<'_>, a: PointKey, b: PointKey, plo: DVec3, tri: &dyn Fn(u32) -> [DVec3; 3]) -> bool {
    let (PointKey::EdgeTri(_, _, ta), PointKey::EdgeTri(_, _, tb)) = (a, b) else { return false };
    // a is before b when a lies on plo's side of b's plane.
    let sa = side_at(g.positions, g.tris, tb, a);
    match sa {
        Ordering::Equal => ta < tb,
        s => s == side(&tri(tb), plo),
    }
}

/// Builds the sub-triangulation of `t`. When the 2-D picture cannot carry
/// the intersection topology (points closer together than rounding can
/// separate), the triangle is triangulated with its edge points only, so its
/// neighbours still fit, and `fallback` is set.
pub(crate) fn build(g: &Geometry<'_>, points: &mut Points, t: u32) -> Sub {
    let tv = g.tris[t as usize];
    let corners = tv.map(|v| g.positions[v as usize]);
    let segs: Vec<u32> = g.x.of(t).to_vec();
    let triples = triple_points(g, t, &segs);
    // Local points: corners, edge points, then the rest.
    let mut local: Vec<PointKey> = tv.map(PointKey::Vertex).to_vec();
    let mut on_edge: [Vec<u32>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for k in 0..3 {
        let mut list = edge_points(g, t, k);
        if tv[k] > tv[(k + 1) % 3] {
            list.reverse();
        }
        for p in list {
            on_edge[k].push(local.len() as u32);
            local.push(p);
        }
    }
    let boundary_count = local.len();
    let mut pieces = segment_pieces(g, t, &segs, &triples, &mut local);
    let globals: Vec<u32> = local.iter().map(|&k| points.id(k, g)).collect();
    let built = plane_points(&corners, &local, &on_edge, boundary_count, &globals, points).and_then(|pts| {
        let inside: Vec<u32> = (boundary_count as u32..local.len() as u32).collect();
        let constraints: Vec<[u32; 2]> = pieces.iter().map(|p| p.0).collect();
        triangulate(&pts, &on_edge, &inside, &constraints).map(|cdt| (cdt, pts))
    });
    let (cdt, fallback) = match built {
        Ok((cdt, _)) => (cdt, false),
        Err(_) => {
            // Edge points only: the neighbours still fit; the segments are lost here.
            local.truncate(boundary_count);
            pieces.clear();
            let pts = plane_points(&corners, &local, &on_edge, boundary_count, &globals, points).unwrap_or_default();
            let cdt = if pts.len() == local.len() {
                triangulate(&pts, &on_edge, &[], &[]).unwrap_or_default()
            } else {
                Cdt::default()
            };
            (cdt, true)
        }
    };
    let (partner, base_edge) = edge_labels(&cdt, &pieces, &on_edge);
    let n = cdt.tris.len();
    let pts = local.iter().enumerate().map(|(i, _)| globals.get(i).copied().unwrap_or(NONE)).collect();
    Sub { pts, cdt, partner, base_edge, visited: alloc::vec![false; n], fallback }
}

/// The triangle other than `t` of segment `s`.
fn partner_of(g: &Geometry<'_>, t: u32, s: u32) -> u32 {
    let seg = &g.x.segments[s as usize];
    if seg.tris[0] == t {
        seg.tris[1]
    } else {
        seg.tris[0]
    }
}

/// Triple points on each of `t`'s segments `segs`: (other triangle, key),
/// where two of its segments meet a third triangle's plane.
fn triple_points(g: &Geometry<'_>, t: u32, segs: &[u32]) -> Vec<Vec<(u32, PointKey)>> {
    let mut triples: Vec<Vec<(u32, PointKey)>> = alloc::vec![Vec::new(); segs.len()];
    for i in 0..segs.len() {
        for j in i + 1..segs.len() {
            let (b, c) = (partner_of(g, t, segs[i]), partner_of(g, t, segs[j]));
            if b == c {
                continue;
            }
            let mut abc = [t, b, c];
            abc.sort_unstable();
            if triple_exists(g.positions, g.tris, g.x, abc) {
                let k = PointKey::Triple(abc[0], abc[1], abc[2]);
                triples[i].push((c, k));
                triples[j].push((b, k));
            }
        }
    }
    triples
}

/// The constraint pieces along each of `t`'s segments (local point ids,
/// new points added to `local`), split at its triple points in order, each
/// with the segment's other triangle.
fn segment_pieces(
    g: &Geometry<'_>,
    t: u32,
    segs: &[u32],
    triples: &[Vec<(u32, PointKey)>],
    local: &mut Vec<PointKey>,
) -> Vec<([u32; 2], u32)> {
    let local_of = |local: &mut Vec<PointKey>, p: PointKey| -> u32 {
        match local.iter().position(|&q| q == p) {
            Some(i) => i as u32,
            None => {
                local.push(p);
                (local.len() - 1) as u32
            }
        }
    };
    let mut pieces: Vec<([u32; 2], u32)> = Vec::new();
    for (i, &s) in segs.iter().enumerate() {
        let seg = g.x.segments[s as usize];
        let (p0, p1) =
            (position(g.positions, g.tris, g.x, seg.ends[0]), position(g.positions, g.tris, g.x, seg.ends[1]));
        let mut inner: Vec<(f64, u32, PointKey)> = triples[i]
            .iter()
            .map(|&(c, k)| (crossing_parameter(p0, p1, g.tris[c as usize].map(|v| g.positions[v as usize])), c, k))
            .collect();
        inner.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut chain = alloc::vec![local_of(local, seg.ends[0])];
        for &(_, _, k) in &inner {
            chain.push(local_of(local, k));
        }
        chain.push(local_of(local, seg.ends[1]));
        for w in chain.windows(2) {
            if w[0] != w[1] {
                pieces.push(([w[0], w[1]], partner_of(g, t, s)));
            }
        }
    }
    pieces
}

/// Per sub-triangle edge: the other triangle of the segment a constraint
/// edge runs along (else [`NONE`]), and which of the triangle's edges (0..3)
/// a boundary edge lies on (else 3).
#[allow(clippy::type_complexity)]
fn edge_labels(cdt: &Cdt, pieces: &[([u32; 2], u32)], on_edge: &[Vec<u32>; 3]) -> (Vec<[u32; 3]>, Vec<[u8; 3]>) {
    let n = cdt.tris.len();
    let mut partner = alloc::vec![[NONE; 3]; n];
    let mut base_edge = alloc::vec![[3u8; 3]; n];
    let membership = |i: u32| -> [bool; 3] {
        let i = i as usize;
        if i < 3 {
            let mut m = [false; 3];
            m[i] = true;
            m[(i + 2) % 3] = true;
            m
        } else {
            let mut m = [false; 3];
            for (k, list) in on_edge.iter().enumerate() {
                m[k] = list.contains(&(i as u32));
            }
            m
        }
    };
    for s in 0..n {
        for k in 0..3 {
            let (u, v) = (cdt.tris[s][k], cdt.tris[s][(k + 1) % 3]);
            if cdt.fixed[s][k] {
                partner[s][k] = pieces.iter().find(|p| p.0 == [u, v] || p.0 == [v, u]).map_or(NONE, |p| p.1);
            } else if cdt.nbr[s][k] == NONE {
                let (mu, mv) = (membership(u), membership(v));
                base_edge[s][k] = (0..3).find(|&e| mu[e] && mv[e]).unwrap_or(3) as u8;
            }
        }
    }
    (partner, base_edge)
}

/// The 2-D picture of the triangle's points: the plane is projected along
/// its normal's largest coordinate (mirrored if needed so the corners run
/// counter-clockwise); edge points are placed on their edge at their 3-D
/// fraction (kept strictly increasing), inner points by their clamped
/// barycentric coordinates, so everything lies strictly where the topology says.
fn plane_points(
    corners: &[DVec3; 3],
    local: &[PointKey],
    on_edge: &[Vec<u32>; 3],
    boundary_count: usize,
    globals: &[u32],
    points: &Points,
) -> Result<Vec<DVec2>, Conflict> {
    let axis = drop_axis((corners[1] - corners[0]).cross(corners[2] - corners[0]));
    let mut c2 = corners.map(|c| project(c, axis));
    let mirror = match orient2d(c2[0], c2[1], c2[2]) {
        Ordering::Greater => false,
        Ordering::Less => true,
        Ordering::Equal => return Err(Conflict::Outside),
    };
    if mirror {
        c2 = c2.map(|p| DVec2::new(p.y, p.x));
    }
    let mut pts = alloc::vec![DVec2::ZERO; local.len()];
    pts[..3].copy_from_slice(&c2);
    for (k, list) in on_edge.iter().enumerate() {
        let (a, b) = (corners[k], corners[(k + 1) % 3]);
        let d = b - a;
        let len2 = d.length_squared();
        let mut prev = 0.0f64;
        for &i in list {
            let p = points.pos[globals[i as usize] as usize];
            let tau = if len2 > 0.0 { (p - a).dot(d) / len2 } else { 0.5 };
            let tau = tau.max(prev + MARGIN).max(MARGIN);
            if tau >= 1.0 - MARGIN {
                return Err(Conflict::Outside);
            }
            prev = tau;
            pts[i as usize] = c2[k] + (c2[(k + 1) % 3] - c2[k]) * tau;
        }
    }
    let area = (c2[1] - c2[0]).perp_dot(c2[2] - c2[0]);
    for i in boundary_count..local.len() {
        let mut p = project(points.pos[globals[i] as usize], axis);
        if mirror {
            p = DVec2::new(p.y, p.x);
        }
        let mut w = [
            (c2[1] - p).perp_dot(c2[2] - p) / area,
            (c2[2] - p).perp_dot(c2[0] - p) / area,
            (c2[0] - p).perp_dot(c2[1] - p) / area,
        ];
        if w.iter().any(|x| !x.is_finite()) {
            return Err(Conflict::Outside);
        }
        for x in &mut w {
            *x = x.max(MARGIN);
        }
        let sum = w[0] + w[1] + w[2];
        pts[i] = (c2[0] * w[0] + c2[1] * w[1] + c2[2] * w[2]) / sum;
    }
    Ok(pts)
}
