//! A tangent plane at every point (paper 004 §2, step 2): the normal of the
//! neighbourhood's principal components, oriented consistently over the
//! neighbour graph, then refined by a local quadratic height fit.

use alloc::collections::BinaryHeap;
use alloc::vec;
use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::DVec3;

use super::linalg::{covariance, frame, solve, sym_eigen3};

/// The `k` nearest neighbours of every point, nearest first, `k` per point.
pub(crate) struct Neighbours {
    /// Neighbours per point.
    pub k: usize,
    /// `k` indices per point.
    pub idx: Vec<u32>,
}

impl Neighbours {
    /// The first `m` neighbours of point `i`.
    pub(crate) fn of(&self, i: usize, m: usize) -> &[u32] {
        &self.idx[i * self.k..i * self.k + m.min(self.k)]
    }
}

/// Unit normals by principal components over `k_normal` neighbours,
/// oriented consistently: a minimum spanning tree over the neighbour graph
/// weighted by `1 − |n_i · n_j|` carries the orientation from a seed (the
/// point farthest from the centroid in each connected part, its normal turned
/// away from the centroid) along the smoothest paths. Then each normal is
/// refined by a weighted least-squares fit of a quadratic height function
/// `h = a x + b y + c x² + d xy + e y²` over the same neighbours in the
/// point's tangent frame (normal `∝ (−a, −b, 1)`), kept only when it turns by
/// less than `max_turn` radians from the principal-components normal.
pub(crate) fn estimate(points: &[DVec3], nb: &Neighbours, k_normal: usize, max_turn: f64) -> Vec<DVec3> {
    let n = points.len();
    let mut normals: Vec<DVec3> = (0..n)
        .map(|i| {
            let near = nb.of(i, k_normal);
            let (c, _) = covariance(core::iter::once(points[i]).chain(near.iter().map(|&j| points[j as usize])));
            sym_eigen3(c).1[0]
        })
        .collect();
    orient(points, nb, k_normal, &mut normals);
    let cos_turn = libm::cos(max_turn);
    for i in 0..n {
        if let Some(r) = refine(points, nb.of(i, k_normal), points[i], normals[i]) {
            if r.dot(normals[i]) > cos_turn {
                normals[i] = r;
            }
        }
    }
    normals
}

/// Heap entry of Prim's algorithm: the smaller weight pops first.
#[derive(PartialEq)]
struct Edge {
    weight: f64,
    to: u32,
    from: u32,
}

impl Eq for Edge {}

impl Ord for Edge {
    fn cmp(&self, other: &Self) -> Ordering {
        other.weight.total_cmp(&self.weight).then_with(|| other.to.cmp(&self.to))
    }
}

impl PartialOrd for Edge {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Orients the normals along a minimum spanning tree of the symmetric neighbour graph.
fn orient(points: &[DVec3], nb: &Neighbours, k: usize, normals: &mut [DVec3]) {
    let n = points.len();
    // Symmetric adjacency: j in i's list or i in j's.
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
    for i in 0..n {
        for &j in nb.of(i, k) {
            adj[i].push(j);
            adj[j as usize].push(i as u32);
        }
    }
    let centroid = points.iter().copied().sum::<DVec3>() / n.max(1) as f64;
    let mut done = vec![false; n];
    let mut by_distance: Vec<u32> = (0..n as u32).collect();
    crate::sort::by_f64_desc(&mut by_distance, |&a| points[a as usize].distance_squared(centroid));
    let mut heap = BinaryHeap::new();
    for &seed in &by_distance {
        let s = seed as usize;
        if done[s] {
            continue;
        }
        if normals[s].dot(points[s] - centroid) < 0.0 {
            normals[s] = -normals[s];
        }
        done[s] = true;
        push_edges(s, &adj, normals, &done, &mut heap);
        while let Some(e) = heap.pop() {
            let t = e.to as usize;
            if done[t] {
                continue;
            }
            if normals[t].dot(normals[e.from as usize]) < 0.0 {
                normals[t] = -normals[t];
            }
            done[t] = true;
            push_edges(t, &adj, normals, &done, &mut heap);
        }
    }
}

fn push_edges(i: usize, adj: &[Vec<u32>], normals: &[DVec3], done: &[bool], heap: &mut BinaryHeap<Edge>) {
    for &j in &adj[i] {
        if !done[j as usize] {
            let weight = 1.0 - normals[i].dot(normals[j as usize]).abs();
            heap.push(Edge { weight, to: j, from: i as u32 });
        }
    }
}

/// The normal of a weighted quadratic height fit through `p` (see [`estimate`]).
fn refine(points: &[DVec3], near: &[u32], p: DVec3, n: DVec3) -> Option<DVec3> {
    if near.len() < 6 {
        return None;
    }
    let (u, v) = frame(n);
    let h2 = near.iter().map(|&j| points[j as usize].distance_squared(p)).fold(0.0, f64::max);
    if !(h2 > 0.0) {
        return None;
    }
    let mut a = [[0.0; 5]; 5];
    let mut rhs = [0.0; 5];
    for &j in near {
        let d = points[j as usize] - p;
        let (x, y, z) = (d.dot(u), d.dot(v), d.dot(n));
        let w = 1.0 / (1.0 + 4.0 * d.length_squared() / h2);
        let row = [x, y, x * x, x * y, y * y];
        for r in 0..5 {
            for c in 0..5 {
                a[r][c] += w * row[r] * row[c];
            }
            rhs[r] += w * row[r] * z;
        }
    }
    let s = solve(a, rhs)?;
    let r = (n - u * s[0] - v * s[1]).normalize_or_zero();
    (r != DVec3::ZERO).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::kdtree::KdTree;

    #[test]
    fn sphere_normals_point_outward_and_are_second_order_accurate() {
        // A Fibonacci sphere, radius 2, off the origin.
        let c = DVec3::new(3.0, -1.0, 0.5);
        let n = 400;
        let golden = core::f64::consts::PI * (3.0 - libm::sqrt(5.0));
        let pts: Vec<DVec3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = libm::sqrt(1.0 - z * z);
                let t = golden * i as f64;
                c + DVec3::new(r * libm::cos(t), r * libm::sin(t), z) * 2.0
            })
            .collect();
        let tree = KdTree::new(&pts);
        let k = 12;
        let mut idx = Vec::new();
        let mut out = Vec::new();
        for i in 0..n {
            tree.nearest(pts[i], k, Some(i as u32), &mut out);
            idx.extend(out.iter().map(|x| x.0));
        }
        let nb = Neighbours { k, idx };
        let normals = estimate(&pts, &nb, k, 0.5);
        let worst = (0..n).map(|i| normals[i].dot((pts[i] - c).normalize())).fold(1.0, f64::min);
        assert!(worst > 1.0 - 1e-5, "worst cosine {worst}");
    }
}
