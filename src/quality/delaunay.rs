//! The baseline the looping method is compared with: spade's constrained
//! Delaunay refinement (Ruppert-style, with an angle limit and a largest
//! area) of the same boundary nodes in the same plane. Boundary segments are
//! kept whole, so the faces still meet node to node.

use crate::warning::QualityError;
use alloc::format;
use alloc::vec::Vec;
use glam::DVec2;
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};

use super::looping::Filled;

/// Smallest angle spade's refinement aims at, degrees.
pub(crate) const ANGLE_LIMIT_DEG: f64 = 30.0;

/// Triangulates the region bounded by `loops` (indices into `pos`) and
/// refines it until no triangle has an angle below [`ANGLE_LIMIT_DEG`] or
/// an area above the equilateral triangle of the median boundary size,
/// adding at most `max_nodes − pos.len()` nodes (their size is that median).
///
/// # Errors
/// A message when the loops cross or nodes coincide.
pub(crate) fn fill(pos: &[DVec2], h: &[f64], loops: &[Vec<u32>], max_nodes: usize) -> Result<Filled, QualityError> {
    let verts: Vec<Point2<f64>> = pos.iter().map(|p| Point2::new(p.x, p.y)).collect();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    for lp in loops {
        let n = lp.len();
        for k in 0..n {
            edges.push([lp[k] as usize, lp[(k + 1) % n] as usize]);
        }
    }
    let mut conflict = false;
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(verts, edges, |_| conflict = true)
        .map_err(|e| QualityError::Triangulation(format!("{e:?}")))?;
    if conflict {
        return Err(QualityError::LoopsCross);
    }
    if cdt.num_vertices() != pos.len() {
        return Err(QualityError::NodesCoincide);
    }
    let mut sizes: Vec<f64> = h.to_vec();
    sizes.sort_unstable_by(f64::total_cmp);
    let size = sizes.get(sizes.len() / 2).copied().unwrap_or(1.0);
    let area = 0.25 * libm::sqrt(3.0) * size * size;
    let params = RefinementParameters::<f64>::new()
        .with_angle_limit(AngleLimit::from_deg(ANGLE_LIMIT_DEG))
        .with_max_allowed_area(area)
        .keep_constraint_edges()
        .exclude_outer_faces(true)
        .with_max_additional_vertices(max_nodes.saturating_sub(pos.len()));
    let result = cdt.refine(params);
    let excluded: crate::collections::HashSet<usize> = result.excluded_faces.iter().map(|f| f.index()).collect();
    let mut out = Filled { pos: pos.to_vec(), h: h.to_vec(), ..Filled::default() };
    for v in cdt.vertices().skip(pos.len()) {
        let p = v.position();
        out.pos.push(DVec2::new(p.x, p.y));
        out.h.push(size);
    }
    for f in cdt.inner_faces() {
        if excluded.contains(&f.fix().index()) {
            continue;
        }
        let v = f.vertices();
        out.tris.push([v[0].fix().index() as u32, v[1].fix().index() as u32, v[2].fix().index() as u32]);
    }
    Ok(out)
}
