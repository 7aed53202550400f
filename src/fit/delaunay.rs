//! A small 2-D Delaunay triangulation (Bowyer–Watson) for one point's
//! neighbourhood projected on its tangent plane: the local view of the
//! surface from which the triangle net takes that point's umbrella.
//!
//! Numbers: the in-circle and orientation decisions are exact
//! ([`crate::predicates`]), so the cavities of one insertion agree and the
//! result is a triangulation even for cocircular points (a grid); only the
//! merging of near-duplicate points uses a tolerance (1e-9 of the spread).

use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::DVec2;

use crate::predicates::{incircle, orient2d};

/// Delaunay triangles (counter-clockwise index triples into `pts`) of at most
/// a few dozen points. Points closer than `1e-9` × the spread to an earlier one
/// are left out. Quadratic time: meant for neighbourhoods only.
pub(crate) fn triangulate(pts: &[DVec2]) -> Vec<[usize; 3]> {
    let n = pts.len();
    if n < 3 {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in pts {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let span = (hi - lo).max_element();
    if !(span > 0.0) || !span.is_finite() {
        return Vec::new();
    }
    // Work in coordinates scaled to the unit box, so the predicates see numbers of size 1.
    let mut v: Vec<DVec2> = pts.iter().map(|p| (*p - lo) / span).collect();
    // Super-triangle far outside.
    v.push(DVec2::new(-20.0, -20.0));
    v.push(DVec2::new(40.0, -20.0));
    v.push(DVec2::new(0.5, 40.0));
    let mut tris: Vec<[usize; 3]> = alloc::vec![[n, n + 1, n + 2]];
    let mut bad: Vec<usize> = Vec::new();
    let mut hole: Vec<[usize; 2]> = Vec::new();
    'points: for i in 0..n {
        let p = v[i];
        for j in 0..i {
            if v[j].distance_squared(p) < 1e-18 {
                continue 'points;
            }
        }
        bad.clear();
        for (t, tri) in tris.iter().enumerate() {
            if incircle(v[tri[0]], v[tri[1]], v[tri[2]], p) == Ordering::Greater {
                bad.push(t);
            }
        }
        if bad.is_empty() {
            continue;
        }
        // Boundary of the cavity: edges of bad triangles not shared by two bad triangles.
        hole.clear();
        for &t in &bad {
            let tri = tris[t];
            for k in 0..3 {
                let e = [tri[k], tri[(k + 1) % 3]];
                if let Some(pos) = hole.iter().position(|h| h[0] == e[1] && h[1] == e[0]) {
                    hole.swap_remove(pos);
                } else {
                    hole.push(e);
                }
            }
        }
        for &t in bad.iter().rev() {
            tris.swap_remove(t);
        }
        for e in &hole {
            if orient2d(v[e[0]], v[e[1]], p) == Ordering::Greater {
                tris.push([e[0], e[1], i]);
            }
        }
    }
    tris.retain(|t| t.iter().all(|&k| k < n));
    tris
}

/// Twice the signed area of `abc` (positive when counter-clockwise).
pub(crate) fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_with_a_centre_gives_four_triangles_around_it() {
        let pts = [DVec2::new(0.5, 0.5), DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let t = triangulate(&pts);
        assert_eq!(t.len(), 4);
        assert!(t.iter().all(|t| t.contains(&0)));
        assert!(t.iter().all(|t| orient(pts[t[0]], pts[t[1]], pts[t[2]]) > 0.0));
    }

    /// A grid's points lie four on a circle: exact tests still give a
    /// triangulation of the square, two triangles a cell, every circle empty.
    #[test]
    fn a_grid_of_cocircular_points_gives_two_triangles_a_cell() {
        let pts: Vec<DVec2> = (0..25).map(|k| DVec2::new(f64::from(k % 5), f64::from(k / 5)) * 0.1).collect();
        let t = triangulate(&pts);
        assert_eq!(t.len(), 32);
        let area: f64 = t.iter().map(|t| orient(pts[t[0]], pts[t[1]], pts[t[2]]) / 2.0).sum();
        assert!((area - 0.16).abs() < 1e-12, "area {area}");
        for tri in &t {
            assert_eq!(orient2d(pts[tri[0]], pts[tri[1]], pts[tri[2]]), Ordering::Greater);
            for p in &pts {
                assert_ne!(incircle(pts[tri[0]], pts[tri[1]], pts[tri[2]], *p), Ordering::Greater);
            }
        }
    }

    #[test]
    fn random_points_give_an_empty_circle_triangulation_of_the_hull() {
        let mut rnd = crate::testing::uniform(99u64);
        let pts: Vec<DVec2> = (0..30).map(|_| DVec2::new(rnd() * 3.0, rnd())).collect();
        let t = triangulate(&pts);
        let area: f64 = t.iter().map(|t| orient(pts[t[0]], pts[t[1]], pts[t[2]]) / 2.0).sum();
        // Euler: 2n − 2 − h triangles; the area is the hull's, every circle empty.
        assert!(area > 0.0 && t.len() >= 30);
        for tri in &t {
            for (i, p) in pts.iter().enumerate() {
                if !tri.contains(&i) {
                    assert_ne!(incircle(pts[tri[0]], pts[tri[1]], pts[tri[2]], *p), Ordering::Greater);
                }
            }
        }
    }
}
