//! Surfaces through scattered 3-D points (paper 004). This first part reads
//! the points: [`read_points`] for xyz, csv and ply files.

mod points;

pub use points::{read_points, PointFormat, MAX_FILE_POINTS};
