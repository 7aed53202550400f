//! The plane a face is meshed in (paper 003 §3): a planar face's own plane,
//! or, for a curved face, the double mapping — parameters to a global
//! parameterization whose patches have shares proportional to their
//! model-space lengths (eq. 5), then a bilinear map (eqs. 6, 7) whose four
//! corners make the sides as long as the face's four model-space sides.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::model::{Face, FaceSurface};
use crate::nurbs::Surface;

/// Sub-intervals per knot span of the length-proportional parameterization.
const PIECES_PER_SPAN: usize = 8;
/// Sub-intervals of the whole parameter range at most.
const MAX_PIECES: usize = 256;

/// How points of a face go to its meshing plane and back.
#[derive(Debug, Clone)]
pub(crate) enum PlaneMap {
    /// A planar face: coordinates in an orthonormal frame of its plane
    /// (`e1 × e2` along the surface normal, so orientation is kept).
    Plane { origin: DVec3, e1: DVec3, e2: DVec3 },
    /// A curved face: the double mapping.
    Double(Box2),
}

/// The double mapping of paper 003 §3: `u → ug`, `v → vg` piecewise linear
/// (eq. 5), then the bilinear map of the unit square onto the quadrilateral
/// `corners` (eq. 6 with shape functions eq. 7), corner k at
/// (ug, vg) = (0,0), (0,1), (1,1), (1,0).
#[derive(Debug, Clone)]
pub(crate) struct Box2 {
    /// Breakpoints in u and their global values ug (ascending, 0 to 1).
    u: (Vec<f64>, Vec<f64>),
    v: (Vec<f64>, Vec<f64>),
    corners: [DVec2; 4],
}

impl PlaneMap {
    /// The map for `face`, whose boundary nodes span the parameter box
    /// `lo..hi`; `collapsed` tells that some boundary nodes at different
    /// parameters are one point (a collapsed side), which the plane of a
    /// planar face would merge, so the double mapping is used then.
    pub(crate) fn new(face: &Face, lo: DVec2, hi: DVec2, collapsed: bool) -> Self {
        let s: &dyn Surface = &face.surface;
        if let Some((origin, n)) = planar(&face.surface, lo, hi).filter(|_| !collapsed) {
            let c = (lo + hi) * 0.5;
            let d = s.derivs(c);
            let mut e1 = d.su - n * d.su.dot(n);
            if e1.length_squared() <= 0.0 || !e1.is_finite() {
                e1 = n.any_orthonormal_vector();
            }
            let e1 = e1.normalize();
            let e2 = n.cross(e1);
            return Self::Plane { origin, e1, e2 };
        }
        Self::Double(Box2::new(s, lo, hi))
    }

    /// Plane coordinates of the surface point `x` at parameters `uv`.
    pub(crate) fn to_plane(&self, uv: DVec2, x: DVec3) -> DVec2 {
        match self {
            Self::Plane { origin, e1, e2 } => DVec2::new((x - *origin).dot(*e1), (x - *origin).dot(*e2)),
            Self::Double(b) => b.forward(uv),
        }
    }

    /// Parameters of plane point `p`; `hint` is a nearby parameter pair
    /// (used by the planar map's Newton iteration).
    pub(crate) fn to_uv(&self, surface: &dyn Surface, p: DVec2, hint: DVec2) -> DVec2 {
        match self {
            Self::Plane { origin, e1, e2 } => plane_to_uv(surface, *origin + *e1 * p.x + *e2 * p.y, hint),
            Self::Double(b) => b.inverse(p),
        }
    }

    /// Model length per plane length at `uv` (square root of the area ratio):
    /// the element size wanted in model space divided by this is the size
    /// wanted in the plane.
    pub(crate) fn stretch(&self, surface: &dyn Surface, uv: DVec2) -> f64 {
        match self {
            Self::Plane { .. } => 1.0,
            Self::Double(b) => {
                let d = surface.derivs(uv);
                let model = d.su.cross(d.sv).length();
                let plane = b.jacobian(uv).abs();
                if model > 0.0 && plane > 0.0 && model.is_finite() {
                    crate::math::sqrt(model / plane)
                } else {
                    1.0
                }
            }
        }
    }
}

/// The plane of a planar surface over `lo..hi`: (a point, the unit normal
/// along `Su × Sv`) when every control point lies within 1e-9 of the
/// control net's size from the plane through the box centre.
fn planar(surface: &FaceSurface, lo: DVec2, hi: DVec2) -> Option<(DVec3, DVec3)> {
    let FaceSurface::Nurbs(n) = surface else { return None };
    let c = (lo + hi) * 0.5;
    let origin = n.point(c);
    let normal = n.normal(c);
    let size = n.bbox().diagonal();
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    n.control_points().all(|p| (p - origin).dot(normal).abs() <= 1e-9 * size).then_some((origin, normal))
}

/// Newton on `S(u,v) = target` (least squares through `[Su Sv]`), from `hint`.
fn plane_to_uv(surface: &dyn Surface, target: DVec3, hint: DVec2) -> DVec2 {
    let [lo, hi] = surface.domain();
    let mut uv = hint.clamp(lo, hi);
    for _ in 0..24 {
        let d = surface.derivs(uv);
        let r = target - d.point;
        let (a, b, c) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
        let det = a * c - b * b;
        if !(det > 0.0 && det.is_finite()) {
            break;
        }
        let (ru, rv) = (d.su.dot(r), d.sv.dot(r));
        let step = DVec2::new(c * ru - b * rv, a * rv - b * ru) / det;
        let next = (uv + step).clamp(lo, hi);
        let moved = (next - uv).abs().max_element();
        uv = next;
        if moved <= 1e-14 * (hi - lo).max_element() {
            break;
        }
    }
    uv
}

impl Box2 {
    fn new(s: &dyn Surface, lo: DVec2, hi: DVec2) -> Self {
        let u = global_axis(s, lo, hi, true);
        let v = global_axis(s, lo, hi, false);
        // Side lengths: l1 along u = lo, l2 along v = hi, l3 along u = hi,
        // l4 along v = lo; diagonals l5 (lo to hi) and l6 (the other).
        let line = |a: DVec2, b: DVec2| curve_length(s, a, b);
        let l1 = line(lo, DVec2::new(lo.x, hi.y));
        let l2 = line(DVec2::new(lo.x, hi.y), hi);
        let l3 = line(DVec2::new(hi.x, lo.y), hi);
        let l4 = line(lo, DVec2::new(hi.x, lo.y));
        let l5 = line(lo, hi);
        let l6 = line(DVec2::new(lo.x, hi.y), DVec2::new(hi.x, lo.y));
        let corners = fit_corners([l1, l2, l3, l4], l5, l6);
        Self { u, v, corners }
    }

    /// Bilinear map of (ug, vg) (eqs. 6, 7).
    fn bilinear(&self, g: DVec2) -> DVec2 {
        let [p1, p2, p3, p4] = self.corners;
        let n1 = (1.0 - g.x) * (1.0 - g.y);
        let n2 = (1.0 - g.x) * g.y;
        let n3 = g.x * g.y;
        let n4 = g.x * (1.0 - g.y);
        p1 * n1 + p2 * n2 + p3 * n3 + p4 * n4
    }

    /// Columns d/dug and d/dvg of the bilinear map.
    fn bilinear_d(&self, g: DVec2) -> (DVec2, DVec2) {
        let [p1, p2, p3, p4] = self.corners;
        let du = (p4 - p1) * (1.0 - g.y) + (p3 - p2) * g.y;
        let dv = (p2 - p1) * (1.0 - g.x) + (p3 - p4) * g.x;
        (du, dv)
    }

    fn forward(&self, uv: DVec2) -> DVec2 {
        self.bilinear(DVec2::new(map_axis(&self.u, uv.x), map_axis(&self.v, uv.y)))
    }

    /// Inverse of [`Box2::forward`]: Newton on the bilinear map from the
    /// centre, then the piecewise-linear axes backwards.
    fn inverse(&self, p: DVec2) -> DVec2 {
        let mut g = DVec2::splat(0.5);
        for _ in 0..30 {
            let r = p - self.bilinear(g);
            let (du, dv) = self.bilinear_d(g);
            let det = du.perp_dot(dv);
            if !(det.abs() > 0.0 && det.is_finite()) {
                break;
            }
            let step = DVec2::new(r.perp_dot(dv), du.perp_dot(r)) / det;
            g = (g + step).clamp(DVec2::splat(-0.5), DVec2::splat(1.5));
            if step.abs().max_element() < 1e-15 {
                break;
            }
        }
        let g = g.clamp(DVec2::ZERO, DVec2::ONE);
        DVec2::new(unmap_axis(&self.u, g.x), unmap_axis(&self.v, g.y))
    }

    /// Determinant of d(plane)/d(u,v) at `uv`.
    fn jacobian(&self, uv: DVec2) -> f64 {
        let g = DVec2::new(map_axis(&self.u, uv.x), map_axis(&self.v, uv.y));
        let (du, dv) = self.bilinear_d(g);
        du.perp_dot(dv) * slope(&self.u, uv.x) * slope(&self.v, uv.y)
    }
}

/// The length-proportional global coordinate along one direction (eq. 5):
/// the parameter range is cut at the knots (each span into
/// [`PIECES_PER_SPAN`] equal parts, the project's refinement of the paper's
/// patches), and each part's share of [0, 1] is its model-space length,
/// averaged over the iso-curves at the start, middle and end of the other direction.
fn global_axis(s: &dyn Surface, lo: DVec2, hi: DVec2, along_u: bool) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = if along_u { (lo.x, hi.x) } else { (lo.y, hi.y) };
    let mut ks: Vec<f64> = s.breaks(along_u).into_iter().filter(|&k| k > a && k < b).collect();
    ks.insert(0, a);
    ks.push(b);
    let per = (MAX_PIECES / (ks.len() - 1)).clamp(1, PIECES_PER_SPAN);
    let mut ts = Vec::with_capacity((ks.len() - 1) * per + 1);
    for w in ks.windows(2) {
        for k in 0..per {
            ts.push(w[0] + (w[1] - w[0]) * k as f64 / per as f64);
        }
    }
    ts.push(b);
    let others = if along_u { [lo.y, 0.5 * (lo.y + hi.y), hi.y] } else { [lo.x, 0.5 * (lo.x + hi.x), hi.x] };
    let at = |t: f64, o: f64| if along_u { DVec2::new(t, o) } else { DVec2::new(o, t) };
    let mut lens: Vec<f64> = ts
        .windows(2)
        .map(|w| others.iter().map(|&o| curve_length(s, at(w[0], o), at(w[1], o))).sum::<f64>() / 3.0)
        .collect();
    let total: f64 = lens.iter().sum();
    let floor = if total > 0.0 && total.is_finite() { 1e-6 * total / lens.len() as f64 } else { 1.0 };
    for l in &mut lens {
        if !(*l > floor && l.is_finite()) {
            *l = floor;
        }
    }
    let total: f64 = lens.iter().sum();
    let mut g = Vec::with_capacity(ts.len());
    let mut acc = 0.0;
    g.push(0.0);
    for l in &lens {
        acc += l / total;
        g.push(acc);
    }
    if let Some(last) = g.last_mut() {
        *last = 1.0;
    }
    (ts, g)
}

/// `t` through a piecewise-linear axis map.
fn map_axis(axis: &(Vec<f64>, Vec<f64>), t: f64) -> f64 {
    let (ts, gs) = axis;
    let i = ts.partition_point(|&a| a < t).clamp(1, ts.len() - 1);
    let (t0, t1) = (ts[i - 1], ts[i]);
    let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    gs[i - 1] + (gs[i] - gs[i - 1]) * f
}

/// Slope dg/dt of the axis map at `t`.
fn slope(axis: &(Vec<f64>, Vec<f64>), t: f64) -> f64 {
    let (ts, gs) = axis;
    let i = ts.partition_point(|&a| a < t).clamp(1, ts.len() - 1);
    let dt = ts[i] - ts[i - 1];
    if dt > 0.0 {
        (gs[i] - gs[i - 1]) / dt
    } else {
        0.0
    }
}

fn unmap_axis(axis: &(Vec<f64>, Vec<f64>), g: f64) -> f64 {
    let (ts, gs) = axis;
    let i = gs.partition_point(|&a| a < g).clamp(1, gs.len() - 1);
    let (g0, g1) = (gs[i - 1], gs[i]);
    let f = if g1 > g0 { ((g - g0) / (g1 - g0)).clamp(0.0, 1.0) } else { 0.0 };
    ts[i - 1] + (ts[i] - ts[i - 1]) * f
}

/// Model-space length of the surface curve over the straight parameter segment `a..b` (32 chords).
fn curve_length(s: &dyn Surface, a: DVec2, b: DVec2) -> f64 {
    let mut prev = s.point(a);
    let mut len = 0.0;
    for k in 1..=32 {
        let p = s.point(a + (b - a) * (k as f64 / 32.0));
        len += p.distance(prev);
        prev = p;
    }
    len
}

/// The four corners of the re-mapped quadrilateral (paper 003 §3, Fig. 7):
/// P1 at the origin, P2 above it at distance l1; P4 at distance l4 from P1
/// at an angle chosen, and P3 where the circles of radius l2 about P2 and
/// l3 about P4 meet (on the far side), so three sides are exact; the angle
/// is the one whose diagonals come closest to the model-space diagonals
/// l5, l6 (a scan of 181 angles, then a golden-section search). Side
/// lengths below a fifth of the longest are raised to it (a collapsed side,
/// a pole, would make the map singular). Without a convex solution the
/// rectangle of the mean side lengths is used.
fn fit_corners(l: [f64; 4], l5: f64, l6: f64) -> [DVec2; 4] {
    let top = l.iter().copied().fold(0.0, f64::max);
    let top = if top > 0.0 && top.is_finite() { top } else { 1.0 };
    let [l1, l2, l3, l4] = l.map(|x| if x.is_finite() { x.max(0.2 * top) } else { top });
    let rect = {
        let (w, h) = (0.5 * (l2 + l4), 0.5 * (l1 + l3));
        [DVec2::ZERO, DVec2::new(0.0, h), DVec2::new(w, h), DVec2::new(w, 0.0)]
    };
    let p1 = DVec2::ZERO;
    let p2 = DVec2::new(0.0, l1);
    let quad = |theta: f64| -> Option<[DVec2; 4]> {
        let p4 = DVec2::new(libm::cos(theta), libm::sin(theta)) * l4;
        let p3 = circles(p2, l2, p4, l3)?;
        let q = [p1, p2, p3, p4];
        convex_ccw(&[q[0], q[3], q[2], q[1]]).then_some(q)
    };
    let error = |theta: f64| -> f64 {
        match quad(theta) {
            Some(q) => {
                let a = q[2].distance(q[0]) - l5;
                let b = q[3].distance(q[1]) - l6;
                a * a + b * b
            }
            None => f64::INFINITY,
        }
    };
    let (lo, hi) = (-1.4, 1.4);
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..=180 {
        let th = lo + (hi - lo) * k as f64 / 180.0;
        let e = error(th);
        if e < best.0 {
            best = (e, th);
        }
    }
    if !best.0.is_finite() {
        return rect;
    }
    let step = (hi - lo) / 180.0;
    let (mut a, mut b) = (best.1 - step, best.1 + step);
    let phi = 0.5 * (libm::sqrt(5.0) - 1.0);
    for _ in 0..40 {
        let c = b - phi * (b - a);
        let d = a + phi * (b - a);
        if error(c) < error(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let th = 0.5 * (a + b);
    let th = if error(th) <= best.0 { th } else { best.1 };
    quad(th).unwrap_or(rect)
}

/// Where the circles (c1, r1) and (c2, r2) meet: of the two points, the one
/// farther from the origin (P1), so that P3 is the quadrilateral's far corner.
fn circles(c1: DVec2, r1: f64, c2: DVec2, r2: f64) -> Option<DVec2> {
    let d = c2 - c1;
    let dist = d.length();
    if !(dist > 0.0 && dist.is_finite()) || dist > r1 + r2 || dist < (r1 - r2).abs() {
        return None;
    }
    let a = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
    let h = libm::sqrt((r1 * r1 - a * a).max(0.0));
    let m = c1 + d * (a / dist);
    let perp = DVec2::new(d.y, -d.x) / dist;
    let (x, y) = (m + perp * h, m - perp * h);
    Some(if x.length_squared() >= y.length_squared() { x } else { y })
}

/// Whether the polygon is convex and counter-clockwise with every turn strictly positive.
fn convex_ccw(p: &[DVec2]) -> bool {
    let n = p.len();
    (0..n).all(|i| {
        let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
        (b - a).perp_dot(c - b) > 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_of_a_rectangle_are_a_rectangle() {
        let (w, h) = (3.0, 2.0);
        let d = libm::sqrt(w * w + h * h);
        let q = fit_corners([h, w, h, w], d, d);
        let want = [DVec2::ZERO, DVec2::new(0.0, h), DVec2::new(w, h), DVec2::new(w, 0.0)];
        for k in 0..4 {
            assert!(q[k].distance(want[k]) < 1e-6, "corner {k}: {:?}", q[k]);
        }
    }

    #[test]
    fn corners_keep_three_sides_of_a_trapezoid() {
        // Bottom 4, top 2, slanted sides sqrt(2).
        let s = libm::sqrt(2.0);
        let q = fit_corners([s, 2.0, s, 4.0], libm::sqrt(10.0), libm::sqrt(10.0));
        assert!((q[1].distance(q[0]) - s).abs() < 1e-9);
        assert!((q[2].distance(q[1]) - 2.0).abs() < 1e-9);
        assert!((q[3].distance(q[2]) - s).abs() < 1e-9);
        assert!((q[3].distance(q[0]) - 4.0).abs() < 1e-9);
        assert!((q[2].distance(q[0]) - libm::sqrt(10.0)).abs() < 1e-3);
    }

    #[test]
    fn axis_maps_invert() {
        let axis = (alloc::vec![0.0, 0.5, 2.0], alloc::vec![0.0, 0.8, 1.0]);
        for t in [0.0, 0.1, 0.5, 1.3, 2.0] {
            let g = map_axis(&axis, t);
            assert!((unmap_axis(&axis, g) - t).abs() < 1e-12);
        }
        assert!((slope(&axis, 0.2) - 1.6).abs() < 1e-12);
    }
}
