//! Native integration tests, one binary.

mod assembly;
mod cli;
mod corpus_files;
mod fit;
mod iges;
mod layers;
mod mesh;
mod nurbs;
mod quality;
mod repair;
mod reparam;
mod shapes;
mod step;
mod tessellated;

/// Triangles with two corners at one point (up to rounding): no area, a
/// NaN normal for a viewer, and the worst of every quality measure.
pub fn point_triangles(mesh: &surfmesh::Mesh) -> usize {
    (0..mesh.triangle_count())
        .filter(|&t| {
            let p = mesh.triangle(t);
            (0..3).any(|k| {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                a.distance(b) <= 1e-12 * a.abs().max(b.abs()).max_element().max(1.0)
            })
        })
        .count()
}
