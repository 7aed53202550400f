//! NURBS geometry: knot vectors, basis functions, curves, surfaces, projection.
//!
//! Numbers ([`crate::numeric`]): evaluation is plain floating point;
//! projection stops by [`ProjectionOptions::parameter_tolerance`] (a
//! fraction of the domain), knot and weight checks compare with fractions
//! of the values' size, and divisions by a derivative's length are guarded.

pub(crate) mod analytic;
mod bbox;
#[cfg(test)]
pub(crate) mod counted;
mod curve;
pub(crate) mod elevate;
mod error;
pub(crate) mod join;
mod knots;
#[cfg(any(test, all(target_arch = "wasm32", target_feature = "simd128")))]
mod pairs;
mod project;
pub(crate) mod reparam;
pub(crate) mod seam;
mod speed;
mod surface;

use alloc::boxed::Box;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

pub use bbox::Aabb;
pub use curve::{CurveDerivs, NurbsCurve};
pub use error::NurbsError;
pub use knots::{BasisDers, KnotVector};
pub use project::{project_to_surface, CurveProjection, Projection, ProjectionOptions};
pub(crate) use project::{project_with, SurfaceFacts};
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
    /// `S(u, v)` at every `(us[i], vs[j])`, `u` outer: the same values as
    /// [`Surface::point`] at each, which a surface may find faster by rows.
    fn point_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        us.iter().flat_map(|&u| vs.iter().map(move |&v| self.point(DVec2::new(u, v)))).collect()
    }
    /// [`Surface::point_normal`] along the iso-curve where the other
    /// parameter is `s` (`along_u`: `v = s` and the argument is `u`): the
    /// same values, which a surface may find faster with what the fixed parameter shares.
    fn iso_point_normal(&self, along_u: bool, s: f64) -> Box<dyn Fn(f64) -> (DVec3, DVec3) + '_> {
        Box::new(move |t| self.point_normal(if along_u { DVec2::new(t, s) } else { DVec2::new(s, t) }))
    }
    /// Parameters where the surface is less smooth (knots), ascending, ends included.
    fn breaks(&self, along_u: bool) -> Vec<f64>;
    /// A box that contains the surface.
    fn bounding_box(&self) -> Aabb;
    /// Bounds of `|S_u|` and `|S_v|` over the whole domain, where known:
    /// how far a curve on the surface can stray from its chord.
    fn derivative_bounds(&self) -> Option<[f64; 2]> {
        None
    }
    /// Whether parameters follow model-space length and the surface is C²
    /// across its knots (paper 001's rebuild): its knots then mark no feature
    /// the mesher's grid must start from.
    fn even_parameters(&self) -> bool {
        false
    }

    /// `(S, Su, Sv)`: what a normal needs. The default takes them from
    /// [`Surface::derivs`]; a surface that can skip the second derivatives
    /// should, with the same values.
    fn tangents(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        let d = self.derivs(uv);
        (d.point, d.su, d.sv)
    }

    /// `S(uv)` and [`Surface::normal`] at `uv`, the same values, from one
    /// evaluation with first derivatives where the surface is regular.
    fn point_normal(&self, uv: DVec2) -> (DVec3, DVec3) {
        let (p, su, sv) = self.tangents(uv);
        (p, self.normal_from_tangents(uv, su, sv))
    }

    /// [`Surface::normal`] at `uv` given `Su` and `Sv` there (already
    /// evaluated): their cross product where regular, else the normal's own limit.
    fn normal_from_tangents(&self, uv: DVec2, su: DVec3, sv: DVec3) -> DVec3 {
        regular_cross(su, sv).unwrap_or_else(|| self.normal(uv))
    }

    /// Unit normal `Su × Sv`, defined also where the surface degenerates.
    ///
    /// At a collapsed edge (sphere pole) `Su × Sv` vanishes, or is made only of
    /// rounding noise in the vanishing derivative; the normal is then the limit
    /// taken from a point nudged toward the domain's centre, which is the
    /// direction every nearby facet sees.
    fn normal(&self, uv: DVec2) -> DVec3 {
        let (_, su, sv) = self.tangents(uv);
        if let Some(n) = regular_cross(su, sv) {
            return n;
        }
        let d = self.derivs(uv);
        let [lo, hi] = self.domain();
        let centre = (lo + hi) * 0.5;
        let mut f = 1e-7;
        for _ in 0..6 {
            f *= 10.0;
            let q = uv + (centre - uv) * f;
            let (_, su, sv) = self.tangents(q);
            if let Some(n) = regular_cross(su, sv) {
                // The exact limit where it exists, on the side the nudge found.
                return match collapsed_normal(&d) {
                    Some(exact) if exact.dot(n) > 0.0 => exact,
                    Some(exact) if exact.dot(n) < 0.0 => -exact,
                    _ => n,
                };
            }
        }
        DVec3::Z
    }
}

/// The normal's limit at a collapsed edge, up to sign: where `Sv` vanishes,
/// `Sv ≈ Suv·Δu` next to it, so the normal is along `Su × Suv` (and
/// `Suv × Sv` where `Su` vanishes). Exact at a sphere's pole, where the
/// nudged normal is only close; an offset surface needs it exact, or its
/// pole would open into a small loop.
fn collapsed_normal(d: &SurfaceDerivs) -> Option<DVec3> {
    let (lu, lv) = (d.su.length_squared(), d.sv.length_squared());
    let n = if lv < 1e-20 * lu {
        d.su.cross(d.suv)
    } else if lu < 1e-20 * lv {
        d.suv.cross(d.sv)
    } else {
        return None;
    };
    let len = n.length();
    let scale = libm::sqrt(lu.max(lv)) * d.suv.length();
    (len.is_finite() && len > 1e-6 * scale).then(|| n / len)
}

/// `Su × Sv` normalized, or `None` where the surface is degenerate: the cross
/// product is below `1e-10 (|Su|² + |Sv|²)`, i.e. one derivative is ten
/// orders of magnitude shorter than the other (a collapsed edge, where what is
/// left of it is rounding noise pointing anywhere) or the two are parallel.
pub(crate) fn regular_normal(d: &SurfaceDerivs) -> Option<DVec3> {
    regular_cross(d.su, d.sv)
}

/// [`regular_normal`] from the two first derivatives alone.
fn regular_cross(su: DVec3, sv: DVec3) -> Option<DVec3> {
    const DEGENERATE: f64 = 1e-10;
    let n = su.cross(sv);
    let len = n.length();
    let scale = su.length_squared() + sv.length_squared();
    (len.is_finite() && len > 0.0 && len > DEGENERATE * scale).then(|| n / len)
}
