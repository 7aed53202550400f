//! Broad phase of the self-intersection search: which triangle pairs have
//! overlapping bounding boxes. Two ways: the k-d tree bucketing of paper 002
//! §3 and a bounding-volume hierarchy. Each reports every overlapping pair once.

use alloc::vec::Vec;
use glam::DVec3;

use crate::nurbs::Aabb;

/// Deepest k-d tree split; a box still over capacity there becomes a leaf.
const KD_MAX_DEPTH: usize = 40;
/// Items per BVH leaf.
const BVH_LEAF: usize = 4;

#[inline]
fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Paper 002 §3: start from the model's box; split the box in half across
/// its longest side; put each triangle in every child it touches (here: its
/// bounding box overlaps the child); shrink each child to fit its
/// triangles; recurse while a box holds more than `capacity` triangles. Pairs
/// are tested only inside a leaf. A pair that lands in several leaves is
/// reported by exactly one: the leaf whose cell (the half-open partition the
/// splits make) holds the low corner of the pair's box overlap.
///
/// Returns the number of leaves.
pub(crate) fn kd_pairs(boxes: &[Aabb], capacity: usize, mut report: impl FnMut(u32, u32)) -> usize {
    let capacity = capacity.max(2);
    let all: Vec<u32> = (0..boxes.len() as u32).filter(|&i| !boxes[i as usize].is_empty()).collect();
    let infinite = (DVec3::splat(f64::NEG_INFINITY), DVec3::splat(f64::INFINITY));
    // (items, cell low, cell high, depth); cells are [lo, hi) per axis.
    let mut stack: Vec<(Vec<u32>, DVec3, DVec3, usize)> = alloc::vec![(all, infinite.0, infinite.1, 0)];
    let mut leaves = 0;
    while let Some((items, lo, hi, depth)) = stack.pop() {
        // Shrink: the items' boxes, clipped to the cell.
        let mut shrunk = Aabb::EMPTY;
        for &i in &items {
            shrunk.union(&boxes[i as usize]);
        }
        shrunk.min = shrunk.min.max(lo);
        shrunk.max = shrunk.max.min(hi);
        let ext = shrunk.max - shrunk.min;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = 0.5 * (shrunk.min[axis] + shrunk.max[axis]);
        let mut split = None;
        if items.len() > capacity && depth < KD_MAX_DEPTH && mid > shrunk.min[axis] && mid < shrunk.max[axis] {
            let left: Vec<u32> = items.iter().copied().filter(|&i| boxes[i as usize].min[axis] < mid).collect();
            let right: Vec<u32> = items.iter().copied().filter(|&i| boxes[i as usize].max[axis] >= mid).collect();
            // A split that leaves every triangle in both halves gains nothing.
            if left.len() < items.len() || right.len() < items.len() {
                split = Some((left, right));
            }
        }
        match split {
            Some((left, right)) => {
                let (mut lhi, mut rlo) = (hi, lo);
                lhi[axis] = mid;
                rlo[axis] = mid;
                stack.push((left, lo, lhi, depth + 1));
                stack.push((right, rlo, hi, depth + 1));
            }
            None => {
                leaves += 1;
                for (n, &i) in items.iter().enumerate() {
                    let bi = &boxes[i as usize];
                    for &j in &items[n + 1..] {
                        let bj = &boxes[j as usize];
                        if !overlap(bi, bj) {
                            continue;
                        }
                        let corner = bi.min.max(bj.min);
                        if corner.cmpge(lo).all() && corner.cmplt(hi).all() {
                            report(i.min(j), i.max(j));
                        }
                    }
                }
            }
        }
    }
    leaves
}

/// A bounding-volume hierarchy over boxes (median split of centres across the
/// widest extent), queried once per box for the boxes after it that overlap.
pub(crate) fn bvh_pairs(boxes: &[Aabb], mut report: impl FnMut(u32, u32)) {
    #[derive(Clone, Copy)]
    struct Node {
        bbox: Aabb,
        /// Leaf: first item; inner: left child (right child is `start + 1`... stored in `right`).
        start: u32,
        count: u32,
        right: u32,
    }
    let mut items: Vec<u32> = (0..boxes.len() as u32).filter(|&i| !boxes[i as usize].is_empty()).collect();
    if items.len() < 2 {
        return;
    }
    let centre = |i: u32| {
        let b = &boxes[i as usize];
        b.min + b.max
    };
    let mut nodes: Vec<Node> = Vec::with_capacity(2 * items.len() / BVH_LEAF + 2);
    nodes.push(Node { bbox: Aabb::EMPTY, start: 0, count: items.len() as u32, right: 0 });
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
        if range.len() <= BVH_LEAF {
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
        nodes.push(Node { bbox: Aabb::EMPTY, start: node.start, count: mid as u32, right: 0 });
        nodes.push(Node {
            bbox: Aabb::EMPTY,
            start: node.start + mid as u32,
            count: (range.len() - mid) as u32,
            right: 0,
        });
        let inner = &mut nodes[n as usize];
        inner.count = 0;
        inner.start = left;
        inner.right = left + 1;
        stack.push(left);
        stack.push(left + 1);
    }
    let mut stack: Vec<u32> = Vec::with_capacity(64);
    for i in 0..boxes.len() as u32 {
        let b = &boxes[i as usize];
        if b.is_empty() {
            continue;
        }
        stack.clear();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &nodes[n as usize];
            if !overlap(&node.bbox, b) {
                continue;
            }
            if node.count == 0 {
                stack.push(node.start);
                stack.push(node.right);
                continue;
            }
            for &j in &items[node.start as usize..(node.start + node.count) as usize] {
                if j > i && overlap(b, &boxes[j as usize]) {
                    report(i, j);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Boxes of a jittered grid of small cubes, some overlapping.
    fn boxes() -> Vec<Aabb> {
        let mut out = Vec::new();
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..600 {
            let c = DVec3::new(rnd(), rnd(), rnd()) * 10.0;
            let s = DVec3::new(rnd(), rnd(), rnd()) * 0.8 + 0.05;
            out.push(Aabb { min: c - s, max: c + s });
        }
        // A few long, thin ones that cross many cells.
        out.push(Aabb { min: DVec3::new(0.0, 5.0, 5.0), max: DVec3::new(10.0, 5.1, 5.1) });
        out.push(Aabb { min: DVec3::new(3.0, 0.0, 3.0), max: DVec3::new(3.0, 10.0, 3.0) });
        out
    }

    fn brute(boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if overlap(&boxes[i], &boxes[j]) {
                    out.push((i as u32, j as u32));
                }
            }
        }
        out
    }

    #[test]
    fn kd_tree_and_bvh_report_each_overlapping_pair_once() {
        let b = boxes();
        let expected = brute(&b);
        assert!(expected.len() > 500, "the test needs overlaps: {}", expected.len());
        for capacity in [2, 7, 40, 10_000] {
            let mut kd = Vec::new();
            let leaves = kd_pairs(&b, capacity, |i, j| kd.push((i, j)));
            assert!(capacity < 1000 || leaves == 1);
            kd.sort_unstable();
            assert_eq!(kd, expected, "k-d tree, capacity {capacity}");
        }
        let mut bvh = Vec::new();
        bvh_pairs(&b, |i, j| bvh.push((i, j)));
        bvh.sort_unstable();
        assert_eq!(bvh, expected);
    }
}
