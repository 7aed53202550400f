//! The polygon net: neighbouring triangles merged into convex polygons by the
//! paper's rule (paper 004 §2 step 3).
//!
//! The triangle with the smallest corner angle starts a polygon. At the
//! polygon's corner with the smallest angle `P`, of the two unmerged
//! triangles beside the polygon's edges at `P`, the one with the smaller
//! angle at `P` is merged first; the merge is undone when the polygon,
//! projected on its plane, is no longer convex, and the other triangle is
//! tried; then the next-smallest corner. A merge that succeeds starts the
//! round again at the new polygon's smallest corner; when no corner takes a
//! triangle, the polygon is done and the smallest-angle triangle not yet
//! merged starts the next.
//!
//! "Convex" is judged as the patch construction needs it, by [`fill_polygon`]
//! itself: every projected corner angle at most `max_angle`, even polygons
//! closable, and (the project's additions) at most `max_sides` corners and
//! every corner normal within `max_tilt` of the polygon's plane normal, so
//! that the projection stays faithful on curved surfaces.

use crate::collections::HashMap;
use alloc::vec;
use alloc::vec::Vec;
use glam::DVec3;

use super::bezier::{Cubic, TriPatch};
use super::curvenet::edge_curve;
use super::patch::{fill_polygon, project, PatchError};
use super::trinet::min_angle;

/// Settings of the merge (see [`super::FitOptions`]).
pub(crate) struct PolyOptions {
    pub max_angle: f64,
    pub max_sides: usize,
    pub max_tilt: f64,
}

/// Fills polygon `corners` with its sub-patches, edges by the curve construction.
/// Triangles may have any corner angle below π; merged polygons at most `max_angle`.
pub(crate) fn fill(
    points: &[DVec3],
    normals: &[DVec3],
    corners: &[u32],
    opt: &PolyOptions,
) -> Result<Vec<TriPatch>, PatchError> {
    let n = corners.len();
    let z: Vec<DVec3> = corners.iter().map(|&c| points[c as usize]).collect();
    let nz: Vec<DVec3> = corners.iter().map(|&c| normals[c as usize]).collect();
    let mut edges: Vec<Cubic> = Vec::with_capacity(n);
    for i in 0..n {
        let j = (i + 1) % n;
        edges.push(edge_curve(z[i], nz[i], z[j], nz[j]).ok_or(PatchError::Tangent)?);
    }
    // A triangle of the net is filled whatever its angles (the limit is the merge's).
    let max_angle = if n == 3 { core::f64::consts::PI } else { opt.max_angle };
    fill_polygon(&z, &nz, &edges, max_angle)
}

/// Whether `corners` may be a polygon of the net.
fn acceptable(points: &[DVec3], normals: &[DVec3], corners: &[u32], opt: &PolyOptions) -> bool {
    if corners.len() > opt.max_sides {
        return false;
    }
    let z: Vec<DVec3> = corners.iter().map(|&c| points[c as usize]).collect();
    let Ok(proj) = project(&z, opt.max_angle) else { return false };
    let cos_tilt = libm::cos(opt.max_tilt);
    if corners.iter().any(|&c| normals[c as usize].dot(proj.normal) < cos_tilt) {
        return false;
    }
    fill(points, normals, corners, opt).is_ok()
}

/// Merges the triangles into polygons (corner lists, counter-clockwise).
pub(crate) fn merge(points: &[DVec3], normals: &[DVec3], tris: &[[u32; 3]], opt: &PolyOptions) -> Vec<Vec<u32>> {
    // Directed edge → triangle.
    let mut by_edge: HashMap<(u32, u32), usize> = HashMap::default();
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            by_edge.insert((tri[k], tri[(k + 1) % 3]), t);
        }
    }
    let angle_at = |t: usize, v: u32| -> f64 {
        let tri = tris[t];
        let k = tri.iter().position(|&x| x == v).unwrap_or(0);
        let (p, a, b) = (points[tri[k] as usize], points[tri[(k + 1) % 3] as usize], points[tri[(k + 2) % 3] as usize]);
        crate::math::angle_between(a - p, b - p)
    };
    let mut order: Vec<(f64, usize)> = tris
        .iter()
        .enumerate()
        .map(|(t, tri)| (min_angle(points[tri[0] as usize], points[tri[1] as usize], points[tri[2] as usize]), t))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

    let mut merged = vec![false; tris.len()];
    let mut polygons = Vec::new();
    for &(_, start) in &order {
        if merged[start] {
            continue;
        }
        merged[start] = true;
        let mut poly: Vec<u32> = tris[start].to_vec();
        loop {
            let angles = corner_angles(points, &poly);
            let mut by_angle: Vec<usize> = (0..poly.len()).collect();
            by_angle.sort_by(|&a, &b| angles[a].total_cmp(&angles[b]).then(a.cmp(&b)));
            let mut grown = false;
            'corners: for &k in &by_angle {
                let m = poly.len();
                let p = poly[k];
                // Triangles beside the polygon's edges (prev → p) and (p → next): they hold the reversed edge.
                let mut beside: Vec<(f64, usize, usize)> = Vec::new();
                for (a, b, at) in [(poly[(k + m - 1) % m], p, k), (p, poly[(k + 1) % m], (k + 1) % m)] {
                    if let Some(&t) = by_edge.get(&(b, a)) {
                        if !merged[t] {
                            beside.push((angle_at(t, p), t, at));
                        }
                    }
                }
                beside.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                for &(_, t, at) in &beside {
                    let tri = tris[t];
                    let Some(&w) = tri.iter().find(|&&v| !poly.contains(&v)) else { continue };
                    let mut bigger = poly.clone();
                    bigger.insert(at, w);
                    if acceptable(points, normals, &bigger, opt) {
                        poly = bigger;
                        merged[t] = true;
                        grown = true;
                        break 'corners;
                    }
                }
            }
            if !grown {
                break;
            }
        }
        polygons.push(poly);
    }
    polygons
}

/// Corner angles of a polygon, in 3-D (the order of merging needs only their ranking).
fn corner_angles(points: &[DVec3], poly: &[u32]) -> Vec<f64> {
    let m = poly.len();
    (0..m)
        .map(|k| {
            let p = points[poly[k] as usize];
            let a = points[poly[(k + m - 1) % m] as usize];
            let b = points[poly[(k + 1) % m] as usize];
            crate::math::angle_between(a - p, b - p)
        })
        .collect()
}
