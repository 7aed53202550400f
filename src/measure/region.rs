//! Points of the exact geometry: samples of each face's surface inside its
//! trimmed region (even-odd rule over polylines of the trim loops) and on its
//! loops, at a chosen spacing in model space.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::model::Face;
use crate::nurbs::Surface;

/// Grid lines per direction of one face at most (bounds memory and time).
const MAX_LINES: usize = 512;
/// Points per trim curve at most.
const MAX_CURVE_POINTS: usize = 256;
/// Lines per direction of the grid that estimates a face's size.
const PROBE: usize = 8;

/// What sampling a face needs to know, computed once per face.
pub(crate) struct FacePlan {
    /// Parameter box sampled: the loops' box within the domain, or the domain.
    lo: DVec2,
    hi: DVec2,
    /// Largest model-space length of a u line and of a v line over the box.
    length: [f64; 2],
    /// Trim loops as closed (u,v) polylines (empty: the whole box).
    loops: Vec<Vec<DVec2>>,
}

impl FacePlan {
    /// Measures the face: its loops as polylines and its extent in model space.
    pub(crate) fn new(face: &Face) -> Self {
        let s: &dyn Surface = &face.surface;
        let [dlo, dhi] = s.domain();
        let mut loops: Vec<Vec<DVec2>> = Vec::with_capacity(face.loops.len());
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for lp in &face.loops {
            let mut poly = Vec::new();
            for c in &lp.curves {
                let (a, z) = c.domain();
                let spans = c.knots().breakpoints().len().max(2) - 1;
                let n = (8 + 4 * spans * c.degree()).min(MAX_CURVE_POINTS);
                for k in 0..n {
                    let q = c.point(a + (z - a) * k as f64 / n as f64).truncate();
                    if q.is_finite() {
                        lo = lo.min(q);
                        hi = hi.max(q);
                        poly.push(q);
                    }
                }
            }
            if poly.len() >= 3 {
                loops.push(poly);
            }
        }
        if loops.is_empty() {
            (lo, hi) = (dlo, dhi);
        } else {
            lo = lo.max(dlo);
            hi = hi.min(dhi).max(lo);
        }
        // Longest u line and longest v line of a coarse grid.
        let mut length = [0.0f64; 2];
        let at = |i: usize, j: usize| s.point(lo + (hi - lo) * DVec2::new(i as f64, j as f64) / PROBE as f64);
        for k in 0..=PROBE {
            let (mut lu, mut lv) = (0.0, 0.0);
            for m in 0..PROBE {
                lu += at(m, k).distance(at(m + 1, k));
                lv += at(k, m).distance(at(k, m + 1));
            }
            length[0] = length[0].max(lu);
            length[1] = length[1].max(lv);
        }
        for l in &mut length {
            if !l.is_finite() {
                *l = 0.0;
            }
        }
        Self { lo, hi, length, loops }
    }

    /// Rough area of the sampled box in model space (for choosing a spacing).
    pub(crate) fn area(&self) -> f64 {
        self.length[0] * self.length[1]
    }
}

/// Samples of one face.
#[derive(Debug, Clone, Default)]
pub(crate) struct FaceSamples {
    /// Model-space point and its (u,v), inside the trimmed region or on a loop.
    pub points: Vec<(DVec3, DVec2)>,
    /// Every point of the face's surface inside the sampled box lies within
    /// this distance of a grid point (largest grid-cell diagonal).
    pub radius: f64,
}

/// Spacing that spreads about `target` samples over faces of these total `area`.
pub(crate) fn spacing(plans: &[FacePlan], target: usize) -> f64 {
    let area: f64 = plans.iter().map(FacePlan::area).filter(|a| a.is_finite()).sum();
    let h = crate::math::sqrt(area / target.max(1) as f64);
    if h > 0.0 && h.is_finite() {
        h
    } else {
        1.0
    }
}

/// Samples `face` on a grid of about `spacing` in model space (between
/// `min_lines` and [`MAX_LINES`] lines per direction), keeping grid points inside
/// the trimmed region, plus the loops' polyline points.
pub(crate) fn sample_face(face: &Face, plan: &FacePlan, spacing: f64, min_lines: usize) -> FaceSamples {
    let s: &dyn Surface = &face.surface;
    let lines = |len: f64| {
        let n = crate::math::ceil(len / spacing);
        let n = if n.is_finite() && n > 0.0 { n as usize } else { 1 };
        n.clamp(min_lines.max(1), MAX_LINES)
    };
    let (nu, nv) = (lines(plan.length[0]), lines(plan.length[1]));
    let (lo, hi) = (plan.lo, plan.hi);
    let uv_at = |i: usize, j: usize| lo + (hi - lo) * DVec2::new(i as f64 / nu as f64, j as f64 / nv as f64);
    let mut grid: Vec<DVec3> = Vec::with_capacity((nu + 1) * (nv + 1));
    for j in 0..=nv {
        for i in 0..=nu {
            grid.push(s.point(uv_at(i, j)));
        }
    }
    let at = |i: usize, j: usize| grid[j * (nu + 1) + i];
    let mut radius = 0.0f64;
    for j in 0..nv {
        for i in 0..nu {
            radius = radius.max(at(i, j).distance(at(i + 1, j + 1))).max(at(i + 1, j).distance(at(i, j + 1)));
        }
    }
    let mut out = FaceSamples { points: Vec::new(), radius };
    let mut crossings: Vec<f64> = Vec::new();
    for j in 0..=nv {
        let v = uv_at(0, j).y;
        crossings.clear();
        for poly in &plan.loops {
            let n = poly.len();
            for k in 0..n {
                let (a, b) = (poly[k], poly[(k + 1) % n]);
                if (a.y > v) != (b.y > v) {
                    crossings.push(a.x + (v - a.y) / (b.y - a.y) * (b.x - a.x));
                }
            }
        }
        crate::sort::f64s(&mut crossings);
        for i in 0..=nu {
            let uv = uv_at(i, j);
            // Even-odd: inside when an odd number of loop crossings lie left of u.
            let inside = plan.loops.is_empty() || crossings.partition_point(|&x| x < uv.x) % 2 == 1;
            let p = at(i, j);
            if inside && p.is_finite() {
                out.points.push((p, uv));
            }
        }
    }
    for poly in &plan.loops {
        let n = poly.len();
        for k in 0..n {
            let p = s.point(poly[k]);
            if p.is_finite() {
                out.points.push((p, poly[k]));
            }
            out.radius = out.radius.max(p.distance(s.point(poly[(k + 1) % n])));
        }
    }
    out
}
