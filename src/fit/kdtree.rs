//! A static k-d tree over the points: the k nearest neighbours of a point,
//! which the normal estimate and the local triangulations both start from.

use alloc::vec::Vec;
use glam::DVec3;

/// Points at or below this count in a node are scanned, not split.
const LEAF: usize = 8;

/// A balanced k-d tree built once over a point slice (indices into it).
pub(crate) struct KdTree<'a> {
    points: &'a [DVec3],
    /// Point indices, arranged so every node is a contiguous range.
    order: Vec<u32>,
    nodes: Vec<Node>,
}

struct Node {
    /// Range of `order` this node covers.
    start: u32,
    end: u32,
    /// Split axis and value, with the two children; `u32::MAX` for a leaf.
    axis: u8,
    split: f64,
    left: u32,
    right: u32,
}

impl<'a> KdTree<'a> {
    /// Builds the tree (median splits on the widest axis; the depth is about log2(n / 8)).
    pub(crate) fn new(points: &'a [DVec3]) -> Self {
        let order: Vec<u32> = (0..points.len() as u32).collect();
        let mut tree = Self { points, order, nodes: Vec::new() };
        if !points.is_empty() {
            tree.build(0, points.len());
        }
        tree
    }

    fn build(&mut self, start: usize, end: usize) -> u32 {
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            start: start as u32,
            end: end as u32,
            axis: 0,
            split: 0.0,
            left: u32::MAX,
            right: u32::MAX,
        });
        if end - start <= LEAF {
            return id;
        }
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &i in &self.order[start..end] {
            lo = lo.min(self.points[i as usize]);
            hi = hi.max(self.points[i as usize]);
        }
        let ext = hi - lo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = (start + end) / 2;
        let pts = self.points;
        self.order[start..end]
            .select_nth_unstable_by(mid - start, |&a, &b| pts[a as usize][axis].total_cmp(&pts[b as usize][axis]));
        let split = pts[self.order[mid] as usize][axis];
        let left = self.build(start, mid);
        let right = self.build(mid, end);
        let node = &mut self.nodes[id as usize];
        node.axis = axis as u8;
        node.split = split;
        node.left = left;
        node.right = right;
        id
    }

    /// The `k` points nearest to `q` (excluding index `skip`), nearest first, as (index, squared distance).
    pub(crate) fn nearest(&self, q: DVec3, k: usize, skip: Option<u32>, out: &mut Vec<(u32, f64)>) {
        out.clear();
        if self.nodes.is_empty() || k == 0 {
            return;
        }
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, 0.0));
        while let Some((id, bound)) = stack.pop() {
            if out.len() == k && bound >= out[k - 1].1 {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.left == u32::MAX {
                for &i in &self.order[node.start as usize..node.end as usize] {
                    if Some(i) == skip {
                        continue;
                    }
                    let d = self.points[i as usize].distance_squared(q);
                    if out.len() < k {
                        out.push((i, d));
                    } else if d < out[k - 1].1 {
                        out[k - 1] = (i, d);
                    } else {
                        continue;
                    }
                    // Keep `out` sorted by insertion.
                    let mut j = out.len() - 1;
                    while j > 0 && out[j - 1].1 > out[j].1 {
                        out.swap(j - 1, j);
                        j -= 1;
                    }
                }
                continue;
            }
            let diff = q[node.axis as usize] - node.split;
            let (near, far) = if diff < 0.0 { (node.left, node.right) } else { (node.right, node.left) };
            stack.push((far, bound.max(diff * diff)));
            stack.push((near, bound));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_matches_brute_force() {
        let mut rnd = crate::testing::uniform(12345u64);
        let pts: Vec<DVec3> = (0..500).map(|_| DVec3::new(rnd(), rnd(), rnd() * 0.1)).collect();
        let tree = KdTree::new(&pts);
        let mut out = Vec::new();
        for q in 0..50u32 {
            tree.nearest(pts[q as usize], 10, Some(q), &mut out);
            let mut brute: Vec<(u32, f64)> = (0..pts.len() as u32)
                .filter(|&i| i != q)
                .map(|i| (i, pts[i as usize].distance_squared(pts[q as usize])))
                .collect();
            brute.sort_by(|a, b| a.1.total_cmp(&b.1));
            assert_eq!(
                out.iter().map(|x| x.1).collect::<Vec<_>>(),
                brute[..10].iter().map(|x| x.1).collect::<Vec<_>>()
            );
        }
    }
}
