//! Surfaces through scattered 3-D points (paper 004). So far: the point
//! readers ([`read_points`]), the triangle net with its normals, and the
//! patch construction, the cubic curve net and the n-sided G¹ patches (wired
//! into the fit in a later step, hence the dead-code allowance).
#![allow(dead_code)]
// Comparisons are written `!(x > 0.0)` on purpose: they reject NaN too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bezier;
mod curvenet;
mod delaunay;
mod kdtree;
mod linalg;
mod normals;
mod patch;
mod points;
mod trinet;

pub use points::{read_points, PointFormat, MAX_FILE_POINTS};
