//! Native integration tests, one binary.

mod cli;
mod fit;
mod iges;
mod mesh;
mod nurbs;
mod quality;
mod repair;
mod reparam;
mod shapes;
mod step;
