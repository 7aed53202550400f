//! Triangles of the fitted surface within the chordal tolerance, watertight
//! across sub-patches and polygons.
//!
//! Each polygon gets one split level `m` (segments per sub-patch edge) from
//! the flatness bound of its sub-patches ([`TriPatch::level_for`]); each net
//! edge gets the larger level of its two polygons and is discretized once,
//! as is each spoke and each centre, so neighbours share their border
//! vertices. A sub-patch whose net edge has more segments than its own
//! level joins that edge to its first inner row by a zipper strip.

use crate::collections::HashMap;
use alloc::vec::Vec;
use glam::DVec3;

use super::bezier::TriPatch;
use crate::mesh::{FaceRange, Mesh};

/// A polygon of the fitted surface as the tessellator needs it.
pub(crate) struct PolyPatches<'a> {
    pub corners: &'a [u32],
    pub patches: &'a [TriPatch],
}

/// Where a mesh triangle's corners lie on the surface: polygon, sub-patch and
/// the barycentric `(λ1, λ2)` of each corner in that sub-patch (kept for tests).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct TriSource {
    pub polygon: u32,
    pub patch: u32,
    pub params: [(f64, f64); 3],
}

/// The mesh and, per triangle, its source.
pub(crate) struct Tessellation {
    pub mesh: Mesh,
    #[cfg_attr(not(test), allow(dead_code))]
    pub sources: Vec<TriSource>,
    /// Split level per polygon.
    pub levels: Vec<usize>,
}

/// Tessellates the polygons; `normals[v]` is the tangent-plane normal of net vertex `v`.
pub(crate) fn tessellate(
    points: &[DVec3],
    normals: &[DVec3],
    polys: &[PolyPatches],
    tol: f64,
    max_level: usize,
) -> Tessellation {
    let levels: Vec<usize> =
        polys.iter().map(|p| p.patches.iter().map(|s| s.level_for(tol, max_level)).max().unwrap_or(1).max(1)).collect();
    let mut edge_level: HashMap<(u32, u32), usize> = HashMap::default();
    for (p, poly) in polys.iter().enumerate() {
        let n = poly.corners.len();
        for i in 0..n {
            let key = key(poly.corners[i], poly.corners[(i + 1) % n]);
            let e = edge_level.entry(key).or_insert(0);
            *e = (*e).max(levels[p]);
        }
    }
    let mut b = Builder {
        mesh: Mesh::default(),
        sources: Vec::new(),
        corner_vertex: HashMap::default(),
        edge_vertices: HashMap::default(),
    };
    for (pi, poly) in polys.iter().enumerate() {
        let first = (b.mesh.indices.len() / 3) as u32;
        b.polygon(pi, poly, levels[pi], &edge_level, (points, normals));
        let last = (b.mesh.indices.len() / 3) as u32;
        b.mesh.face_ranges.push(FaceRange { first, count: last - first });
    }
    Tessellation { mesh: b.mesh, sources: b.sources, levels }
}

/// The mesh as it grows, with the vertices polygons share.
struct Builder {
    mesh: Mesh,
    sources: Vec<TriSource>,
    /// Net vertex → mesh vertex.
    corner_vertex: HashMap<u32, u32>,
    /// Net edge (low, high) → interior vertices, low to high.
    edge_vertices: HashMap<(u32, u32), Vec<u32>>,
}

impl Builder {
    fn push(&mut self, p: DVec3, n: DVec3) -> u32 {
        self.mesh.positions.push(p);
        self.mesh.normals.push(n);
        (self.mesh.positions.len() - 1) as u32
    }

    /// Triangle `v` of sub-patch `(polygon, patch)`, its corners at `params`.
    fn tri(&mut self, (polygon, patch): (usize, usize), v: [u32; 3], params: [(f64, f64); 3]) {
        self.mesh.indices.extend_from_slice(&v);
        self.sources.push(TriSource { polygon: polygon as u32, patch: patch as u32, params });
    }

    /// Polygon `pi` at level `m`: its corners (shared), centre and spokes,
    /// then each sub-patch; `(points, normals)` are the net's.
    fn polygon(
        &mut self,
        pi: usize,
        poly: &PolyPatches,
        m: usize,
        edge_level: &HashMap<(u32, u32), usize>,
        (points, normals): (&[DVec3], &[DVec3]),
    ) {
        let n = poly.corners.len();
        let corner: Vec<u32> = poly
            .corners
            .iter()
            .map(|&c| match self.corner_vertex.get(&c) {
                Some(&v) => v,
                None => {
                    let v = self.push(points[c as usize], normals[c as usize]);
                    self.corner_vertex.insert(c, v);
                    v
                }
            })
            .collect();
        // Centre.
        let c = poly.patches[0].eval(0.0, 1.0);
        let centre = self.push(c.point, c.normal());
        // Spoke i: Z_i → O, m + 1 vertices, evaluated on S_i at (0, t).
        let spokes: Vec<Vec<u32>> = (0..n)
            .map(|i| {
                let mut s = Vec::with_capacity(m + 1);
                s.push(corner[i]);
                for k in 1..m {
                    let e = poly.patches[i].eval(0.0, k as f64 / m as f64);
                    s.push(self.push(e.point, e.normal()));
                }
                s.push(centre);
                s
            })
            .collect();
        for i in 0..n {
            let j = (i + 1) % n;
            let (a, b) = (poly.corners[i], poly.corners[j]);
            let ke = edge_level.get(&key(a, b)).copied().unwrap_or(m).max(m);
            let row0 = self.net_edge(&poly.patches[i], (a, b), ke, (corner[i], corner[j]));
            self.sub_patch((pi, i), &poly.patches[i], m, row0, (&spokes[i], &spokes[j]));
        }
    }

    /// The vertices of net edge `a → b` at `ke` segments, its ends the
    /// mesh vertices `ends`: its interior discretized once for both
    /// polygons (on `patch`, low to high).
    fn net_edge(&mut self, patch: &TriPatch, (a, b): (u32, u32), ke: usize, ends: (u32, u32)) -> Vec<u32> {
        let inner = match self.edge_vertices.get(&key(a, b)) {
            Some(v) => v.clone(),
            None => {
                let mut v = Vec::with_capacity(ke.saturating_sub(1));
                for s in 1..ke {
                    let t = s as f64 / ke as f64;
                    // Evaluate in the direction low → high.
                    let e = if a < b { patch.eval(t, 0.0) } else { patch.eval(1.0 - t, 0.0) };
                    v.push(self.push(e.point, e.normal()));
                }
                self.edge_vertices.insert(key(a, b), v.clone());
                v
            }
        };
        let mut row0: Vec<u32> = Vec::with_capacity(ke + 1);
        row0.push(ends.0);
        if a < b {
            row0.extend(inner.iter().copied());
        } else {
            row0.extend(inner.iter().rev().copied());
        }
        row0.push(ends.1);
        row0
    }

    /// Sub-patch `at = (polygon, patch)` at level `m`: its grid between its
    /// two spokes `(left, right)` above the net edge's vertices `row0`,
    /// joined to them by a zipper where the edge has more segments.
    fn sub_patch(&mut self, at: (usize, usize), patch: &TriPatch, m: usize, row0: Vec<u32>, spokes: (&[u32], &[u32])) {
        let ke = row0.len() - 1;
        // Grid vertex (j, k) of this sub-patch, k ≥ 1.
        let mut grid: Vec<Vec<u32>> = Vec::with_capacity(m + 1);
        grid.push(if ke == m { row0.clone() } else { Vec::new() });
        for k in 1..=m {
            let mut row = Vec::with_capacity(m - k + 1);
            for jj in 0..=m - k {
                let v = if jj == 0 {
                    spokes.0[k]
                } else if jj == m - k {
                    spokes.1[k]
                } else {
                    let e = patch.eval(jj as f64 / m as f64, k as f64 / m as f64);
                    self.push(e.point, e.normal())
                };
                row.push(v);
            }
            grid.push(row);
        }
        let param = |jj: usize, k: usize| (jj as f64 / m as f64, k as f64 / m as f64);
        let k_start = if ke == m { 0 } else { 1 };
        for k in k_start..m {
            for jj in 0..m - k {
                self.tri(
                    at,
                    [grid[k][jj], grid[k][jj + 1], grid[k + 1][jj]],
                    [param(jj, k), param(jj + 1, k), param(jj, k + 1)],
                );
                if jj + 1 < m - k {
                    self.tri(
                        at,
                        [grid[k][jj + 1], grid[k + 1][jj + 1], grid[k + 1][jj]],
                        [param(jj + 1, k), param(jj + 1, k + 1), param(jj, k + 1)],
                    );
                }
            }
        }
        if ke != m {
            self.zipper(at, &row0, &grid[1], m);
        }
    }

    /// Zipper between row 0 (`row0`, its segments) and row 1 (`row1`, m
    /// vertices at λ1 = j/m): each row-0 segment joins the row-1 vertex whose
    /// cell [j/m, (j+1)/m] holds its middle, so every zipper edge runs
    /// between the grid directions λ2 and λ2 − λ1 and the flatness bound of
    /// the grid still holds.
    fn zipper(&mut self, at: (usize, usize), row0: &[u32], row1: &[u32], m: usize) {
        let ke = row0.len() - 1;
        let pa = |s: usize| (s as f64 / ke as f64, 0.0);
        let pb = |s: usize| (s as f64 / m as f64, 1.0 / m as f64);
        let mut ib = 0usize;
        for ia in 0..ke {
            let mid = (ia as f64 + 0.5) / ke as f64;
            let target = ((mid * m as f64) as usize).min(row1.len() - 1);
            while ib < target {
                self.tri(at, [row0[ia], row1[ib + 1], row1[ib]], [pa(ia), pb(ib + 1), pb(ib)]);
                ib += 1;
            }
            self.tri(at, [row0[ia], row0[ia + 1], row1[ib]], [pa(ia), pa(ia + 1), pb(ib)]);
        }
        while ib + 1 < row1.len() {
            self.tri(at, [row0[ke], row1[ib + 1], row1[ib]], [pa(ke), pb(ib + 1), pb(ib)]);
            ib += 1;
        }
    }
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::{fit_points, FitOptions};

    /// Points on a wavy sheet z = 0.2 sin(3x) cos(2y) over the unit square, jittered grid.
    fn sheet() -> Vec<DVec3> {
        let mut rnd = crate::testing::uniform(5u64);
        let mut pts = Vec::new();
        for i in 0..9 {
            for j in 0..9 {
                let x = (i as f64 + 0.6 * (rnd() - 0.5)) / 8.0;
                let y = (j as f64 + 0.6 * (rnd() - 0.5)) / 8.0;
                pts.push(DVec3::new(x, y, 0.2 * libm::sin(3.0 * x) * libm::cos(2.0 * y)));
            }
        }
        pts
    }

    #[test]
    fn every_triangle_stays_within_the_tolerance_of_its_patch_and_borders_are_shared() {
        let pts = sheet();
        for tol in [1e-2, 1e-3, 2e-4] {
            let fit = fit_points(&pts, &FitOptions::default().with_tolerance(tol)).unwrap();
            let s = &fit.surface;
            let polys: Vec<PolyPatches> =
                s.polygons.iter().map(|p| PolyPatches { corners: &p.corners, patches: &p.patches }).collect();
            let t = tessellate(&s.points, &s.normals, &polys, tol, 64);
            assert_eq!(t.sources.len(), t.mesh.triangle_count());
            // Levels differ between polygons, so some edges are zipped.
            assert!(t.levels.iter().any(|&l| l != t.levels[0]), "levels {:?}", t.levels);
            let mut worst: f64 = 0.0;
            for (k, src) in t.sources.iter().enumerate() {
                let patch = &s.polygons[src.polygon as usize].patches[src.patch as usize];
                let corners = t.mesh.triangle(k);
                for (c, &(l1, l2)) in corners.iter().zip(&src.params) {
                    assert!((patch.eval(l1, l2).point - *c).length() < 1e-12, "vertex off its patch");
                }
                for (w0, w1) in [(1.0 / 3.0, 1.0 / 3.0), (0.5, 0.5), (0.5, 0.0), (0.0, 0.5), (0.7, 0.2), (0.2, 0.1)] {
                    let w2 = 1.0 - w0 - w1;
                    let p = &src.params;
                    let (l1, l2) = (p[0].0 * w0 + p[1].0 * w1 + p[2].0 * w2, p[0].1 * w0 + p[1].1 * w1 + p[2].1 * w2);
                    let flat = corners[0] * w0 + corners[1] * w1 + corners[2] * w2;
                    worst = worst.max((patch.eval(l1, l2).point - flat).length());
                }
            }
            assert!(worst <= tol, "tol {tol}: deviation {worst}");
            // One sheet: the only free edges are on its border, and every triangle faces up.
            let counts = crate::mesh::edge_counts(&t.mesh, 1e-12, 0.0);
            assert_eq!(counts.nonmanifold_edges, 0);
            let border = t.mesh.positions.iter().filter(|p| p.x < 0.2 || p.x > 0.8 || p.y < 0.2 || p.y > 0.8).count();
            assert!(counts.boundary_edges > 0 && counts.boundary_edges <= border);
            for k in 0..t.mesh.triangle_count() {
                let [a, b, c] = t.mesh.triangle(k);
                let n = (b - a).cross(c - a);
                assert!(n.z > 0.0 || n.length() == 0.0, "triangle {k} faces down");
            }
        }
    }
}
