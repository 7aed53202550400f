//! NURBS geometry: knot vectors, basis functions, curves, surfaces, projection.

mod bbox;
mod curve;
mod error;
mod knots;
mod project;
mod surface;

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

pub use bbox::Aabb;
pub use curve::{CurveDerivs, NurbsCurve};
pub use error::NurbsError;
pub use knots::{BasisDers, KnotVector};
pub use project::{project_to_surface, Projection, ProjectionOptions};
pub use surface::NurbsSurface;

/// Highest degree accepted (basis functions use fixed-size scratch arrays).
pub const MAX_DEGREE: usize = 16;

/// Point and derivatives of a surface at one `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfaceDerivs {
    /// S(u,v).
    pub point: DVec3,
    /// ∂S/∂u.
    pub su: DVec3,
    /// ∂S/∂v.
    pub sv: DVec3,
    /// ∂²S/∂u².
    pub suu: DVec3,
    /// ∂²S/∂u∂v.
    pub suv: DVec3,
    /// ∂²S/∂v².
    pub svv: DVec3,
}

/// What the mesher needs of a surface: evaluation with derivatives over a
/// rectangular parameter domain. NURBS implement it; exact analytic surfaces
/// from IGES/STEP can too.
pub trait Surface {
    /// `[min, max]` corners of the parameter domain.
    fn domain(&self) -> [DVec2; 2];
    /// S(u,v) (parameters clamped into the domain).
    fn point(&self, uv: DVec2) -> DVec3;
    /// S and its derivatives up to second order.
    fn derivs(&self, uv: DVec2) -> SurfaceDerivs;
    /// Parameters where the surface is less smooth (knots), ascending, ends included.
    fn breaks(&self, along_u: bool) -> Vec<f64>;
    /// A box that contains the surface.
    fn bounding_box(&self) -> Aabb;

    /// Unit normal `Su × Sv`, defined also where the surface degenerates.
    ///
    /// At a collapsed edge (sphere pole) `Su × Sv` vanishes, or is made only of
    /// rounding noise in the vanishing derivative; the normal is then the limit
    /// taken from a point nudged toward the domain's centre, which is the
    /// direction every nearby facet sees.
    fn normal(&self, uv: DVec2) -> DVec3 {
        if let Some(n) = regular_normal(&self.derivs(uv)) {
            return n;
        }
        let [lo, hi] = self.domain();
        let centre = (lo + hi) * 0.5;
        let mut f = 1e-7;
        for _ in 0..6 {
            f *= 10.0;
            let q = uv + (centre - uv) * f;
            if let Some(n) = regular_normal(&self.derivs(q)) {
                return n;
            }
        }
        DVec3::Z
    }
}

/// `Su × Sv` normalized, or `None` where the surface is degenerate: the cross
/// product is below `1e-10 (|Su|² + |Sv|²)`, i.e. one derivative is ten
/// orders of magnitude shorter than the other (a collapsed edge, where what is
/// left of it is rounding noise pointing anywhere) or the two are parallel.
fn regular_normal(d: &SurfaceDerivs) -> Option<DVec3> {
    const DEGENERATE: f64 = 1e-10;
    let n = d.su.cross(d.sv);
    let len = n.length();
    let scale = d.su.length_squared() + d.sv.length_squared();
    (len.is_finite() && len > 0.0 && len > DEGENERATE * scale).then(|| n / len)
}
