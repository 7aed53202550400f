//! Closest points on the model: a BVH over per-face surface samples finds the
//! faces a triangle can be nearest to, and Newton's method
//! ([`project_to_surface`]) finds the closest point on each of them.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::bvh::Bvh;
use super::region::{sample_face, FacePlan};
use crate::model::Face;
use crate::nurbs::{project_to_surface, Aabb, ProjectionOptions, Surface};

/// Faces this near each other, as a fraction of the model's size, are
/// equally near a triangle: coincident faces, as where two parts of an
/// assembly touch (projection itself is far more accurate than this).
const COINCIDENT: f64 = 1e-6;

/// One surface sample.
#[derive(Debug, Clone, Copy)]
struct Sample {
    point: DVec3,
    uv: DVec2,
    face: u32,
}

/// A candidate face for one triangle: its closest point to the centroid.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    face: u32,
    uv: DVec2,
    point: DVec3,
    su: DVec3,
    sv: DVec3,
}

/// Per-face samples of the exact geometry and a BVH over them.
pub(crate) struct SurfaceIndex<'a> {
    faces: &'a [Face],
    samples: Vec<Sample>,
    /// Per face: every surface point lies within this distance of a sample.
    radius: Vec<f64>,
    radius_max: f64,
    bvh: Bvh,
    bbox: Aabb,
    projection: ProjectionOptions,
    /// Per face scratch: nearest sample to the current centroid (distance, sample).
    nearest: Vec<(f64, u32)>,
    touched: Vec<u32>,
    candidates: Vec<Candidate>,
    /// Distances above this get a second projection from the point's own nearest sample.
    retry_above: f64,
}

impl<'a> SurfaceIndex<'a> {
    /// Samples every face at about `spacing` and builds the BVH.
    pub(crate) fn new(faces: &'a [Face], plans: &[FacePlan], spacing: f64, projection: ProjectionOptions) -> Self {
        let mut samples = Vec::new();
        let mut radius = Vec::with_capacity(faces.len());
        for (f, (face, plan)) in faces.iter().zip(plans).enumerate() {
            let fs = sample_face(face, plan, spacing, 4);
            samples.extend(fs.points.iter().map(|&(point, uv)| Sample { point, uv, face: f as u32 }));
            radius.push(if fs.radius.is_finite() { fs.radius } else { 0.0 });
        }
        let boxes: Vec<Aabb> = samples.iter().map(|s| Aabb::from_points([s.point])).collect();
        let bbox = Aabb::from_points(samples.iter().map(|s| s.point));
        let radius_max = radius.iter().copied().fold(0.0, f64::max);
        Self {
            faces,
            samples,
            radius,
            radius_max,
            bvh: Bvh::build(&boxes),
            bbox,
            projection,
            nearest: alloc::vec![(f64::INFINITY, 0); faces.len()],
            touched: Vec::new(),
            candidates: Vec::new(),
            retry_above: f64::INFINITY,
        }
    }

    /// Distances above `above` are checked again by a projection from the
    /// point's own nearest sample: on a poorly parameterized face (paper 001)
    /// Newton from the centroid's closest point can stop at a far-off point
    /// across an abrupt change of parameter speed, and over-state the deviation.
    pub(crate) fn retry_above(&mut self, above: f64) {
        self.retry_above = above;
    }

    /// Box of all samples (the trimmed geometry, as far as sampled).
    pub(crate) fn bbox(&self) -> Aabb {
        self.bbox
    }

    /// Distances from `points` (all on the triangle `corners`) to the closest
    /// point over all faces, written into `out`. Each distance is that of an
    /// actual surface point, so it can over-state but never hide a deviation.
    /// Infinite when the model has no samples. `near` gets the faces nearest
    /// the triangle's centroid: the nearest and those no more than a
    /// millionth of the model's size farther (coincident faces), on their
    /// trimmed regions as the samples tell, only those whose normal the
    /// triangle's agrees with when there are such.
    pub(crate) fn distances(
        &mut self,
        corners: &[DVec3; 3],
        points: &[DVec3],
        out: &mut Vec<f64>,
        near: &mut Vec<u32>,
    ) {
        out.clear();
        out.resize(points.len(), f64::INFINITY);
        near.clear();
        let c = (corners[0] + corners[1] + corners[2]) / 3.0;
        let reach = corners.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
        if !(c.is_finite() && reach.is_finite()) {
            return;
        }
        let samples = &self.samples;
        let Some((d0, _)) = self.bvh.nearest(c, f64::INFINITY, |i| samples[i as usize].point.distance(c)) else {
            return;
        };
        // Any face closest to some point of the triangle has a sample within this of c.
        let ball = d0 + 2.0 * reach + self.radius_max;
        let (nearest, touched) = (&mut self.nearest, &mut self.touched);
        touched.clear();
        self.bvh.within(c, ball, |i| {
            let s = &samples[i as usize];
            let d = s.point.distance(c);
            let slot = &mut nearest[s.face as usize];
            if slot.0 == f64::INFINITY {
                touched.push(s.face);
            }
            if d < slot.0 {
                *slot = (d, i);
            }
        });
        // Lower bound of the centroid's distance to each face; project the centroid in that order.
        let mut order: Vec<(f64, u32)> =
            touched.iter().map(|&f| (self.nearest[f as usize].0 - self.radius[f as usize], f)).collect();
        crate::sort::by_f64(&mut order, |o| o.0);
        self.candidates.clear();
        let mut best = f64::INFINITY;
        let mut dist_c: Vec<f64> = Vec::with_capacity(order.len());
        let mut bounds: Vec<f64> = Vec::with_capacity(order.len());
        for &(bound, f) in &order {
            // dist(q, f) >= bound - reach and dist(q, best face) <= best + reach.
            if bound - reach > best + reach {
                break;
            }
            let s: &dyn Surface = &self.faces[f as usize].surface;
            let hint = self.samples[self.nearest[f as usize].1 as usize].uv;
            let pr = project_to_surface(s, c, Some(hint), &self.projection);
            best = best.min(pr.distance);
            let d = s.derivs(pr.uv);
            self.candidates.push(Candidate { face: f, uv: pr.uv, point: pr.point, su: d.su, sv: d.sv });
            dist_c.push(pr.distance);
            bounds.push(bound);
        }
        for &f in &self.touched {
            self.nearest[f as usize] = (f64::INFINITY, 0);
        }
        // Of coincident faces, those facing the triangle's way: where two
        // parts touch, their faces there face each other. Two flush faces of
        // one plane are coincident only where their samples say both are.
        let slack = COINCIDENT * self.bbox.diagonal();
        let facet = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let nearest = || {
            let within = |(_, (&dc, &bound)): &(&Candidate, (&f64, &f64))| dc.max(bound) <= best + slack;
            self.candidates.iter().zip(dist_c.iter().zip(&bounds)).filter(within).map(|(cand, _)| cand)
        };
        near.extend(nearest().filter(|cand| cand.su.cross(cand.sv).dot(facet) > 0.0).map(|cand| cand.face));
        if near.is_empty() {
            near.extend(nearest().map(|cand| cand.face));
        }
        for (cand, &dc) in self.candidates.iter().zip(&dist_c) {
            if dc - reach > best + reach {
                continue;
            }
            let s: &dyn Surface = &self.faces[cand.face as usize].surface;
            for (q, o) in points.iter().zip(out.iter_mut()) {
                let hint = cand.uv + tangent_step(cand.su, cand.sv, *q - cand.point);
                let pr = project_to_surface(s, *q, Some(hint), &self.projection);
                *o = o.min(pr.distance).min(q.distance(cand.point));
            }
        }
        for (q, o) in points.iter().zip(out.iter_mut()) {
            if *o <= self.retry_above {
                continue;
            }
            let samples = &self.samples;
            if let Some((d, i)) = self.bvh.nearest(*q, f64::INFINITY, |i| samples[i as usize].point.distance(*q)) {
                let s = &samples[i as usize];
                let surface: &dyn Surface = &self.faces[s.face as usize].surface;
                let pr = project_to_surface(surface, *q, Some(s.uv), &self.projection);
                *o = o.min(pr.distance).min(d);
            }
        }
    }
}

/// The (u,v) step whose tangent-plane image is closest to `r`: a first-order
/// guess of where the closest point of a nearby target lies. Zero where the
/// derivatives degenerate (poles).
fn tangent_step(su: DVec3, sv: DVec3, r: DVec3) -> DVec2 {
    let (a, b, c) = (su.length_squared(), su.dot(sv), sv.length_squared());
    let det = a * c - b * b;
    if det <= 1e-12 * (a * c) || !det.is_finite() {
        return DVec2::ZERO;
    }
    let (gu, gv) = (su.dot(r), sv.dot(r));
    let step = DVec2::new((c * gu - b * gv) / det, (a * gv - b * gu) / det);
    if step.is_finite() {
        step
    } else {
        DVec2::ZERO
    }
}
