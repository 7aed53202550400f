//! A bounding-volume hierarchy over boxes (triangles or points), with
//! nearest-item and within-radius queries, and the point–triangle distance.

use alloc::vec::Vec;
use glam::DVec3;

use crate::nurbs::Aabb;

/// Items per leaf at most.
const LEAF: usize = 4;

/// One node: a leaf holds `items[start .. start + count]`; an inner node
/// (`count == 0`) has the children `left` and `right` (indices into the node list).
#[derive(Debug, Clone, Copy)]
struct Node {
    bbox: Aabb,
    start: u32,
    count: u32,
    left: u32,
    right: u32,
}

/// Median-split BVH over item boxes; items are referred to by their index in
/// the slice the tree was built from.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

impl Bvh {
    /// Builds the tree over `boxes` (empty boxes are left out).
    pub(crate) fn build(boxes: &[Aabb]) -> Self {
        let mut items: Vec<u32> = (0..boxes.len() as u32).filter(|&i| !boxes[i as usize].is_empty()).collect();
        let mut nodes: Vec<Node> = Vec::new();
        if items.is_empty() {
            return Self { nodes, items };
        }
        let centre = |i: u32| {
            let b = &boxes[i as usize];
            (b.min + b.max) * 0.5
        };
        nodes.push(Node { bbox: Aabb::EMPTY, start: 0, count: items.len() as u32, left: 0, right: 0 });
        // Explicit stack of nodes to split: no recursion depth to worry about.
        let mut stack: Vec<u32> = alloc::vec![0];
        while let Some(n) = stack.pop() {
            let node = nodes[n as usize];
            let range = node.start as usize..(node.start + node.count) as usize;
            let mut bbox = Aabb::EMPTY;
            let mut centres = Aabb::EMPTY;
            for &i in &items[range.clone()] {
                bbox.union(&boxes[i as usize]);
                centres.add_point(centre(i));
            }
            nodes[n as usize].bbox = bbox;
            if range.len() <= LEAF {
                continue;
            }
            let ext = centres.max - centres.min;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = range.len() / 2;
            items[range.clone()].select_nth_unstable_by(mid, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
            let left = nodes.len() as u32;
            nodes.push(Node { bbox: Aabb::EMPTY, start: node.start, count: mid as u32, left: 0, right: 0 });
            nodes.push(Node {
                bbox: Aabb::EMPTY,
                start: node.start + mid as u32,
                count: (range.len() - mid) as u32,
                left: 0,
                right: 0,
            });
            let inner = &mut nodes[n as usize];
            inner.count = 0;
            inner.left = left;
            inner.right = left + 1;
            stack.push(left);
            stack.push(left + 1);
        }
        Self { nodes, items }
    }

    /// The item nearest to `p` by `dist(item)` (an exact distance that is at
    /// least the distance to the item's box), looking only closer than
    /// `limit`. Returns the distance and the item, or `None` when nothing is
    /// closer than `limit`.
    pub(crate) fn nearest(&self, p: DVec3, limit: f64, mut dist: impl FnMut(u32) -> f64) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        let mut bound = limit;
        let root = self.nodes.first()?;
        let mut stack: Vec<(f64, u32)> = alloc::vec![(box_distance(&root.bbox, p), 0)];
        while let Some((d, n)) = stack.pop() {
            if d >= bound {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.count > 0 {
                for &i in &self.items[node.start as usize..(node.start + node.count) as usize] {
                    let di = dist(i);
                    if di < bound {
                        bound = di;
                        best = Some((di, i));
                    }
                }
                continue;
            }
            let (l, r) = (node.left, node.right);
            let dl = box_distance(&self.nodes[l as usize].bbox, p);
            let dr = box_distance(&self.nodes[r as usize].bbox, p);
            // Nearer child on top of the stack: visited first, tightening the bound sooner.
            if dl <= dr {
                stack.push((dr, r));
                stack.push((dl, l));
            } else {
                stack.push((dl, l));
                stack.push((dr, r));
            }
        }
        best
    }

    /// Calls `visit` for every item whose box lies within `radius` of `p`.
    pub(crate) fn within(&self, p: DVec3, radius: f64, mut visit: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = alloc::vec![0];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if box_distance(&node.bbox, p) > radius {
                continue;
            }
            if node.count > 0 {
                for &i in &self.items[node.start as usize..(node.start + node.count) as usize] {
                    visit(i);
                }
            } else {
                stack.push(node.left);
                stack.push(node.right);
            }
        }
    }
}

/// Distance from `p` to box `b` (0 inside).
pub(crate) fn box_distance(b: &Aabb, p: DVec3) -> f64 {
    let d = (b.min - p).max(p - b.max).max(DVec3::ZERO);
    d.length()
}

/// Closest point of triangle `abc` to `p` (Voronoi regions of the vertices,
/// edges and face; degenerate triangles fall back to their edges).
pub(crate) fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let denom = va + vb + vc;
    if denom == 0.0 || !denom.is_finite() {
        // Zero area: the closest of the three edges.
        let candidates = [closest_on_segment(p, a, b), closest_on_segment(p, b, c), closest_on_segment(p, c, a)];
        let mut best = candidates[0];
        for q in candidates {
            if q.distance_squared(p) < best.distance_squared(p) {
                best = q;
            }
        }
        return best;
    }
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 <= 0.0 || len2.is_nan() {
        return a;
    }
    let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
    a + ab * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        // Above the face: straight down.
        assert!(closest_on_triangle(DVec3::new(0.2, 0.2, 3.0), a, b, c).distance(DVec3::new(0.2, 0.2, 0.0)) < 1e-15);
        // Beyond vertex b.
        assert_eq!(closest_on_triangle(DVec3::new(2.0, -1.0, 0.0), a, b, c), b);
        // Beyond the hypotenuse.
        let q = closest_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!(q.distance(DVec3::new(0.5, 0.5, 0.0)) < 1e-15);
        // A degenerate triangle (a segment) still answers.
        let q = closest_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, b, b);
        assert!(q.distance(DVec3::new(0.5, 0.0, 0.0)) < 1e-15);
    }

    #[test]
    fn nearest_matches_brute_force() {
        // Points on a twisted line; queries anywhere.
        let pts: Vec<DVec3> =
            (0..200).map(|i| DVec3::new(i as f64 * 0.37 % 5.0, (i * i) as f64 % 7.0, (i as f64).sin())).collect();
        let boxes: Vec<Aabb> = pts.iter().map(|&p| Aabb::from_points([p])).collect();
        let bvh = Bvh::build(&boxes);
        for k in 0..50 {
            let q = DVec3::new(k as f64 * 0.13, 7.0 - k as f64 * 0.11, (k as f64 * 0.7).cos() * 2.0);
            let (d, i) = bvh.nearest(q, f64::INFINITY, |i| pts[i as usize].distance(q)).unwrap();
            let brute = pts.iter().map(|p| p.distance(q)).fold(f64::INFINITY, f64::min);
            assert_eq!(d, brute);
            assert_eq!(pts[i as usize].distance(q), brute);
            let mut within = 0;
            bvh.within(q, 1.5, |i| {
                if pts[i as usize].distance(q) <= 1.5 {
                    within += 1;
                }
            });
            assert_eq!(within, pts.iter().filter(|p| p.distance(q) <= 1.5).count());
        }
    }
}
