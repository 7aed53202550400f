//! The extent of a model: the box its trimmed geometry fills, which a
//! relative tolerance or element size is a fraction of.

use alloc::vec::Vec;
use glam::DVec2;

use super::{Face, Model};
use crate::nurbs::{Aabb, Surface};

/// Box of the trimmed geometry, from a 17×17 sample of each face's surface over
/// its loops' parameter box (points inside the region) and the loops themselves.
pub(crate) fn trimmed_bbox(model: &Model) -> Aabb {
    union_of(&face_boxes(model))
}

/// The box holding every box of `boxes` (the model's, from its faces').
pub(crate) fn union_of(boxes: &[Aabb]) -> Aabb {
    boxes.iter().fold(Aabb::EMPTY, |mut b, f| {
        b.union(f);
        b
    })
}

/// Each face's box as [`trimmed_bbox`] samples it, indexed like the mesh's
/// faces (exact, then tessellated): a body's size is its faces' box.
pub(crate) fn face_boxes(model: &Model) -> Vec<Aabb> {
    let mut boxes = Vec::with_capacity(model.face_count());
    for f in &model.faces {
        let mut b = Aabb::EMPTY;
        let s: &dyn Surface = &f.surface;
        let region = LoopSample::of(f);
        for &q in region.polys.iter().flatten() {
            b.add_point(s.point(q));
        }
        let (lo, hi) = (region.lo, region.hi);
        let steps: Vec<f64> = (0..=16).map(|i| i as f64 / 16.0).collect();
        let us: Vec<f64> = steps.iter().map(|t| lo.x + (hi.x - lo.x) * t).collect();
        let vs: Vec<f64> = steps.iter().map(|t| lo.y + (hi.y - lo.y) * t).collect();
        let points = f.surface.points_on_grid(&us, &vs);
        for (k, p) in points.into_iter().enumerate() {
            if region.inside(DVec2::new(us[k / vs.len()], vs[k % vs.len()])) {
                b.add_point(p);
            }
        }
        boxes.push(b);
    }
    for t in &model.tessellated {
        boxes.push(Aabb::from_points(t.positions.iter().copied().filter(|p| p.is_finite())));
    }
    boxes
}

/// A face's trim loops sampled in (u,v), 16 points per curve, and the part
/// of its surface's domain their box covers (the whole domain when the face
/// has no loops): what estimates of a face's extent or area sample over.
pub(crate) struct LoopSample {
    pub lo: DVec2,
    pub hi: DVec2,
    pub polys: Vec<Vec<DVec2>>,
}

impl LoopSample {
    pub(crate) fn of(f: &Face) -> Self {
        let [mut lo, mut hi] = f.surface.domain();
        let mut polys: Vec<Vec<DVec2>> = Vec::new();
        if !f.loops.is_empty() {
            let (mut llo, mut lhi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for lp in &f.loops {
                let mut poly = Vec::new();
                for c in &lp.curves {
                    let (a, z) = c.domain();
                    for k in 0..16 {
                        let q = c.point(a + (z - a) * k as f64 / 16.0).truncate();
                        llo = llo.min(q);
                        lhi = lhi.max(q);
                        poly.push(q);
                    }
                }
                polys.push(poly);
            }
            lo = llo.max(lo);
            hi = lhi.min(hi);
        }
        LoopSample { lo, hi, polys }
    }

    /// Whether `q` lies inside the sampled loops (even-odd rule); always
    /// for a face without loops.
    pub(crate) fn inside(&self, q: DVec2) -> bool {
        let mut c = self.polys.is_empty();
        for p in &self.polys {
            let n = p.len();
            for i in 0..n {
                let (a, z) = (p[i], p[(i + 1) % n]);
                if (a.y > q.y) != (z.y > q.y) && a.x + (q.y - a.y) / (z.y - a.y) * (z.x - a.x) > q.x {
                    c = !c;
                }
            }
        }
        c
    }
}
