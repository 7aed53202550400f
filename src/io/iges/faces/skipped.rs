//! What is known of a face the reader skipped: the model-space curves of
//! its boundaries, read on their own (the surface or the projection of the
//! loops may be what failed). The mesh's report counts the edges its
//! neighbours leave open along them as cracks, not as the model's boundary.

use alloc::vec::Vec;

use super::super::brep::{chain_transform, loop_508};
use super::super::curves::model_curve;
use super::super::directory::Entity;
use super::super::xform::own_transform;
use super::super::Ctx;
use super::{boundary_141, curve_on_surface, Job};
use crate::nurbs::NurbsCurve;

/// The model-space border of face entity `e` read as `job` at placement
/// `base` (a subfigure instance's, else the world's): every boundary that
/// reads (a boundary given only in parameter space has none).
pub(super) fn border(ctx: &Ctx<'_>, e: &Entity, job: &Job, base: glam::DAffine3) -> Vec<NurbsCurve> {
    let parent = match job {
        Job::Brep(parents) => chain_transform(ctx, base, parents),
        _ => Ok(base),
    };
    let Ok(m) = parent.and_then(|p| own_transform(ctx.dir, e.de).map(|t| p * t)) else { return Vec::new() };
    let ptrs = |first: usize, count: Option<usize>| -> Vec<usize> {
        (0..count.unwrap_or(0)).filter_map(|k| e.ptr(first + k).ok().flatten()).collect()
    };
    let mut out = Vec::new();
    match job {
        Job::Trimmed => {
            let outer = if e.int(2).unwrap_or(0) != 0 { e.ptr(4).ok().flatten() } else { None };
            let holes = ptrs(5, e.count(3, 1, 5).ok());
            for b in outer.into_iter().chain(holes) {
                out.extend(curve_on_surface(ctx, e, b, m).map(|l| l.model).unwrap_or_default());
            }
        }
        Job::Bounded => {
            for b in ptrs(4, e.count(3, 1, 4).ok()) {
                out.extend(boundary_141(ctx, e, b, m).map(|l| l.model).unwrap_or_default());
            }
        }
        Job::Brep(_) => {
            for l in ptrs(4, e.count(2, 1, 4).ok()) {
                out.extend(loop_508(ctx, l, m).map(|l| l.model).unwrap_or_default());
            }
        }
        Job::BoundedPlane => {
            if let Ok(Some(b)) = e.ptr(5) {
                out.extend(model_curve(ctx, b, m, 1).unwrap_or_default());
            }
        }
        Job::Untrimmed => {}
    }
    out
}
