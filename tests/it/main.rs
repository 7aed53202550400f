//! Native integration tests, one binary.

mod cli;
mod iges;
mod mesh;
mod nurbs;
mod reparam;
mod shapes;
