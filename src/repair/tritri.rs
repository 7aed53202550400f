//! Exact triangle–triangle intersection (paper 002 step 2): for two
//! triangles of the mesh, the segment where they cross, with its end points
//! named by what makes them (an edge of one through the other, or a shared
//! vertex), so that every triangle that meets the same point names it the same
//! way. Touching and coplanar contacts are recognised exactly and told apart
//! from legitimate adjacency (a shared vertex or edge and nothing more).

use core::cmp::Ordering;
use glam::{DVec2, DVec3};

use super::topology::key;
use crate::predicates::{orient2d, orient3d, side};

/// A point of the intersection arrangement, named by how it arises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum PointKey {
    /// A vertex of the mesh.
    Vertex(u32),
    /// The edge between two vertices (lower id first) crossing a triangle's plane.
    EdgeTri(u32, u32, u32),
    /// Three triangles' planes meeting (ids ascending).
    Triple(u32, u32, u32),
}

/// How two triangles meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Contact {
    /// Apart, or only along what they share (a vertex or an edge).
    None,
    /// Crossing along a segment between two points.
    Segment(PointKey, PointKey),
    /// Coplanar overlap, touching without crossing, or a vertex exactly on the
    /// other's plane while crossing: not handled, counted.
    Degenerate,
}

/// A triangle: vertex ids and positions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tri {
    pub id: u32,
    pub v: [u32; 3],
    pub p: [DVec3; 3],
}

/// 2-D coordinates for points on the plane with normal `n`: drop the
/// coordinate of `n`'s largest component. Exact for orientation signs of
/// points that lie exactly on one plane (only the sign of that component
/// scales them, and it is the same for all).
pub(crate) fn drop_axis(n: DVec3) -> usize {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

#[inline]
pub(crate) fn project(p: DVec3, axis: usize) -> DVec2 {
    match axis {
        0 => DVec2::new(p.y, p.z),
        1 => DVec2::new(p.z, p.x),
        _ => DVec2::new(p.x, p.y),
    }
}

/// Whether two coplanar point sets (1 to 3 points each: a point, a segment
/// or a triangle, ids alongside) meet anywhere other than at the points they
/// share by id. Exact (orient2d on the coordinates, all on one plane).
fn meet_beyond_shared(a: &[(u32, DVec2)], b: &[(u32, DVec2)]) -> bool {
    let shared = |id: u32, other: &[(u32, DVec2)]| other.iter().any(|&(j, _)| j == id);
    for &(id, p) in a {
        if !shared(id, b) && inside_closed(p, b) {
            return true;
        }
    }
    for &(id, p) in b {
        if !shared(id, a) && inside_closed(p, a) {
            return true;
        }
    }
    // Sides: a segment has one, a triangle three, a point none.
    let edges = |s: &[(u32, DVec2)]| -> ([[(u32, DVec2); 2]; 3], usize) {
        let none = (0, DVec2::ZERO);
        match s.len() {
            2 => ([[s[0], s[1]], [none, none], [none, none]], 1),
            3 => ([[s[0], s[1]], [s[1], s[2]], [s[2], s[0]]], 3),
            _ => ([[none, none]; 3], 0),
        }
    };
    let (ea, na) = edges(a);
    let (eb, nb) = edges(b);
    ea[..na].iter().any(|&x| eb[..nb].iter().any(|&y| segments_meet_beyond_shared(x, y)))
}

/// Whether `p` lies in the closed convex hull of 1 to 3 points.
fn inside_closed(p: DVec2, s: &[(u32, DVec2)]) -> bool {
    match s.len() {
        1 => p == s[0].1,
        2 => on_segment(p, s[0].1, s[1].1),
        3 => {
            let o = orient2d(s[0].1, s[1].1, s[2].1);
            if o == Ordering::Equal {
                // A degenerate triangle: the union of its sides.
                return on_segment(p, s[0].1, s[1].1) || on_segment(p, s[1].1, s[2].1) || on_segment(p, s[2].1, s[0].1);
            }
            (0..3).all(|k| orient2d(s[k].1, s[(k + 1) % 3].1, p) != o.reverse())
        }
        _ => false,
    }
}

/// `p` on the closed segment `a b` (exactly).
fn on_segment(p: DVec2, a: DVec2, b: DVec2) -> bool {
    orient2d(a, b, p) == Ordering::Equal
        && p.x >= a.x.min(b.x)
        && p.x <= a.x.max(b.x)
        && p.y >= a.y.min(b.y)
        && p.y <= a.y.max(b.y)
}

fn segments_meet_beyond_shared(a: [(u32, DVec2); 2], b: [(u32, DVec2); 2]) -> bool {
    let mut common = [0u32; 2];
    let mut n = 0;
    for x in &a {
        if b.iter().any(|y| y.0 == x.0) {
            common[n] = x.0;
            n += 1;
        }
    }
    match n {
        2 => false,
        1 => {
            // They meet at the shared end; beyond it only if they run the same way along one line.
            let v = common[0];
            let (pv, pa) = if a[0].0 == v { (a[0].1, a[1].1) } else { (a[1].1, a[0].1) };
            let pb = if b[0].0 == v { b[1].1 } else { b[0].1 };
            orient2d(pv, pa, pb) == Ordering::Equal && (pa - pv).dot(pb - pv) > 0.0
        }
        _ => {
            let (p, q, r, s) = (a[0].1, a[1].1, b[0].1, b[1].1);
            let (o1, o2) = (orient2d(p, q, r), orient2d(p, q, s));
            let (o3, o4) = (orient2d(r, s, p), orient2d(r, s, q));
            if o1 != o2
                && o3 != o4
                && o1 != Ordering::Equal
                && o2 != Ordering::Equal
                && o3 != Ordering::Equal
                && o4 != Ordering::Equal
            {
                return true;
            }
            on_segment(r, p, q) || on_segment(s, p, q) || on_segment(p, r, s) || on_segment(q, r, s)
        }
    }
}

/// Whether the line through `p q` passes through the triangle `t`: `Some(true)`
/// strictly inside, `Some(false)` strictly outside, `None` through its boundary.
fn line_through_triangle(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> Option<bool> {
    let s = [orient3d(p, q, t[0], t[1]), orient3d(p, q, t[1], t[2]), orient3d(p, q, t[2], t[0])];
    if s.contains(&Ordering::Equal) {
        // Zero with the other two agreeing is the boundary; disagreeing is outside.
        let pos = s.contains(&Ordering::Greater);
        let neg = s.contains(&Ordering::Less);
        return if pos && neg { Some(false) } else { None };
    }
    Some(s[0] == s[1] && s[1] == s[2])
}

/// Classifies how triangles `a` and `b` meet. Both must have non-zero area.
pub(crate) fn contact(a: &Tri, b: &Tri) -> Contact {
    let shared_a = a.v.map(|x| b.v.contains(&x));
    let shared_b = b.v.map(|x| a.v.contains(&x));
    let nshared = shared_a.iter().filter(|&&s| s).count();
    if nshared == 3 {
        return Contact::Degenerate;
    }
    let mut sa = [Ordering::Equal; 3];
    for k in 0..3 {
        if !shared_a[k] {
            sa[k] = side(&b.p, a.p[k]);
        }
    }
    if sa.iter().all(|&s| s == Ordering::Equal) {
        // Coplanar.
        let axis = drop_axis((a.p[1] - a.p[0]).cross(a.p[2] - a.p[0]));
        let pa: [(u32, DVec2); 3] = core::array::from_fn(|k| (a.v[k], project(a.p[k], axis)));
        let pb: [(u32, DVec2); 3] = core::array::from_fn(|k| (b.v[k], project(b.p[k], axis)));
        return if meet_beyond_shared(&pa, &pb) { Contact::Degenerate } else { Contact::None };
    }
    if let Some(c) = one_sided(a, &sa, b) {
        return c;
    }
    let mut sb = [Ordering::Equal; 3];
    for k in 0..3 {
        if !shared_b[k] {
            sb[k] = side(&a.p, b.p[k]);
        }
    }
    if let Some(c) = one_sided(b, &sb, a) {
        return c;
    }
    // Both straddle the other's plane.
    if nshared == 1 {
        let i = (0..3).find(|&k| shared_a[k]).unwrap_or(0);
        let j = (0..3).find(|&k| shared_b[k]).unwrap_or(0);
        let (a1, a2) = ((i + 1) % 3, (i + 2) % 3);
        let (b1, b2) = ((j + 1) % 3, (j + 2) % 3);
        let x_in_b = line_through_triangle(a.p[a1], a.p[a2], &b.p);
        let y_in_a = line_through_triangle(b.p[b1], b.p[b2], &a.p);
        let (Some(x_in_b), Some(y_in_a)) = (x_in_b, y_in_a) else { return Contact::Degenerate };
        let v = PointKey::Vertex(a.v[i]);
        let x = edge_point(a.v[a1], a.v[a2], b.id);
        let y = edge_point(b.v[b1], b.v[b2], a.id);
        return match (x_in_b, y_in_a) {
            (true, false) => Contact::Segment(v, x),
            (false, true) => Contact::Segment(v, y),
            (false, false) => Contact::None,
            (true, true) => Contact::Degenerate,
        };
    }
    if sa.contains(&Ordering::Equal) || sb.contains(&Ordering::Equal) {
        return Contact::Degenerate;
    }
    let mut ends: [Option<PointKey>; 4] = [None; 4];
    let mut n = 0;
    for (t, s, other) in [(a, &sa, b), (b, &sb, a)] {
        for k in 0..3 {
            let (i, j) = (k, (k + 1) % 3);
            if s[i] == s[j] {
                continue;
            }
            match line_through_triangle(t.p[i], t.p[j], &other.p) {
                None => return Contact::Degenerate,
                Some(false) => {}
                Some(true) => {
                    if n < 4 {
                        ends[n] = Some(edge_point(t.v[i], t.v[j], other.id));
                    }
                    n += 1;
                }
            }
        }
    }
    match (n, ends[0], ends[1]) {
        (0, _, _) => Contact::None,
        (2, Some(p), Some(q)) => Contact::Segment(p, q),
        _ => Contact::Degenerate,
    }
}

/// When `t` lies on one side of the plane of `other` (its vertices there or
/// on the plane), the contact is where its on-plane vertices meet `other`:
/// nothing beyond shared vertices is no contact, anything else is touching.
/// `None` when `t` straddles the plane.
fn one_sided(t: &Tri, s: &[Ordering; 3], other: &Tri) -> Option<Contact> {
    let pos = s.contains(&Ordering::Greater);
    let neg = s.contains(&Ordering::Less);
    if pos && neg {
        return None;
    }
    let axis = drop_axis((other.p[1] - other.p[0]).cross(other.p[2] - other.p[0]));
    let mut on = [(0u32, DVec2::ZERO); 3];
    let mut n = 0;
    for k in 0..3 {
        if s[k] == Ordering::Equal {
            on[n] = (t.v[k], project(t.p[k], axis));
            n += 1;
        }
    }
    let on = &on[..n];
    let tri: [(u32, DVec2); 3] = core::array::from_fn(|k| (other.v[k], project(other.p[k], axis)));
    Some(if meet_beyond_shared(on, &tri) { Contact::Degenerate } else { Contact::None })
}

fn edge_point(p: u32, q: u32, tri: u32) -> PointKey {
    let (lo, hi) = key(p, q);
    PointKey::EdgeTri(lo, hi, tri)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(id: u32, v: [u32; 3], p: [[f64; 3]; 3]) -> Tri {
        Tri { id, v, p: p.map(DVec3::from_array) }
    }

    #[test]
    fn crossing_triangles_give_a_segment_named_by_edges() {
        // a in z = 0, b vertical through it along x = 0.3.
        let a = tri(0, [0, 1, 2], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let b = tri(1, [3, 4, 5], [[0.3, -1.0, -1.0], [0.3, 2.0, -1.0], [0.3, 0.2, 1.0]]);
        let ends = sorted(contact(&a, &b));
        // The plane x = 0.3 cuts a's edges 0-1 and 1-2, both inside b.
        assert_eq!(ends, [PointKey::EdgeTri(0, 1, 1), PointKey::EdgeTri(1, 2, 1)]);
        assert_eq!(sorted(contact(&b, &a)), ends);
    }

    fn sorted(c: Contact) -> [PointKey; 2] {
        let Contact::Segment(p, q) = c else { panic!("no segment: {c:?}") };
        if p < q {
            [p, q]
        } else {
            [q, p]
        }
    }

    #[test]
    fn a_triangle_piercing_another_ends_inside_it() {
        let a = tri(0, [0, 1, 2], [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]]);
        // b pokes through a's interior with its edge 3-5 and 4-5 (5 below, 3 and 4 above).
        let b = tri(1, [3, 4, 5], [[1.0, 1.0, 1.0], [1.5, 1.0, 1.0], [1.2, 1.3, -1.0]]);
        assert_eq!(sorted(contact(&a, &b)), [PointKey::EdgeTri(3, 5, 0), PointKey::EdgeTri(4, 5, 0)]);
    }

    #[test]
    fn neighbours_sharing_an_edge_or_a_vertex_do_not_intersect() {
        let a = tri(0, [0, 1, 2], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let flat = tri(1, [1, 0, 3], [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, -1.0, 0.0]]);
        assert_eq!(contact(&a, &flat), Contact::None);
        let bent = tri(2, [1, 0, 3], [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, -1.0, 0.7]]);
        assert_eq!(contact(&a, &bent), Contact::None);
        let fan = tri(3, [0, 2, 4], [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.5, 0.0]]);
        assert_eq!(contact(&a, &fan), Contact::None);
        let vertex_only = tri(4, [0, 5, 6], [[0.0, 0.0, 0.0], [-1.0, -1.0, 0.0], [-1.0, -2.0, 0.0]]);
        assert_eq!(contact(&a, &vertex_only), Contact::None);
    }

    #[test]
    fn a_fold_at_a_shared_vertex_gives_a_segment_from_that_vertex() {
        let a = tri(0, [0, 1, 2], [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        // b shares vertex 0 and cuts down through a's interior: its edge 3-4 crosses a.
        let b = tri(1, [0, 3, 4], [[0.0, 0.0, 0.0], [1.0, 0.5, 1.0], [0.5, 1.0, -1.0]]);
        assert_eq!(sorted(contact(&a, &b)), [PointKey::Vertex(0), PointKey::EdgeTri(3, 4, 0)]);
    }

    #[test]
    fn coplanar_overlap_and_touching_are_degenerate() {
        let a = tri(0, [0, 1, 2], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let overlap = tri(1, [3, 4, 5], [[0.2, 0.2, 0.0], [1.2, 0.2, 0.0], [0.2, 1.2, 0.0]]);
        assert_eq!(contact(&a, &overlap), Contact::Degenerate);
        let apart = tri(2, [3, 4, 5], [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]]);
        assert_eq!(contact(&a, &apart), Contact::None);
        // A vertex resting on a's interior from above.
        let touch = tri(3, [3, 4, 5], [[0.2, 0.2, 0.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0]]);
        assert_eq!(contact(&a, &touch), Contact::Degenerate);
        // The same vertex just outside a: no contact.
        let near = tri(4, [3, 4, 5], [[0.6, 0.6, 0.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0]]);
        assert_eq!(contact(&a, &near), Contact::None);
        // A flat fold: the neighbour across edge 0-1 folded back onto a.
        let folded = tri(5, [1, 0, 6], [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.3, 0.3, 0.0]]);
        assert_eq!(contact(&a, &folded), Contact::Degenerate);
    }
}
