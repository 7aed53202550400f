//! Native integration tests, one binary.

mod cli;
mod mesh;
mod nurbs;
mod shapes;
