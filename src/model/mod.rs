//! The model to mesh: faces made of a surface and trim loops in its (u,v).
//!
//! Numbers ([`crate::numeric`]): boxes and bodies are found with tolerances
//! relative to the model's size; no exact predicates.

use crate::numeric::TINY;
use alloc::boxed::Box;
use alloc::string::String;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::nurbs::{Aabb, NurbsCurve, NurbsSurface, Surface, SurfaceDerivs};

mod assembly;
mod bodies;
mod extent;
pub use assembly::{Assembly, AssemblyNode, PartInstance};
pub(crate) use bodies::body_count;
pub use bodies::share_of_faces;
#[cfg(all(feature = "std", feature = "quality"))]
pub(crate) use extent::LoopSample;
pub(crate) use extent::{face_boxes, trimmed_bbox, union_of};

/// Everything read from one input file.
#[derive(Debug, Clone, Default)]
pub struct Model {
    /// Length unit name as given by the file (`"mm"` when unknown).
    pub units: String,
    /// The faces, in file order.
    pub faces: Vec<Face>,
    /// Things the reader skipped or repaired, for the report.
    pub warnings: Vec<crate::Warning>,
    /// The file's own modelling tolerance, model units (IGES global section:
    /// minimum resolution), when it states one: the gaps its author accepted
    /// between faces, so sewing reaches at least that far.
    pub tolerance: Option<f64>,
    /// Per face, the body (shell, solid, part instance) it belongs to, when
    /// the file says: faces of different bodies are never sewn together,
    /// and each body's edges are counted on their own. Empty: one body.
    /// Indexed like the mesh's faces: [`Model::faces`], then [`Model::tessellated`].
    pub bodies: Vec<u32>,
    /// Faces the file gives as triangles only (STEP AP242 tessellated
    /// geometry), in file order. They follow the exact faces: tessellated
    /// face `k` is face `faces.len() + k` of the mesh, its bodies and its report.
    pub tessellated: Vec<TessellatedFace>,
    /// Faces the file has that the reader could not build (each skipped
    /// with a warning): not in [`Model::faces`], but counted, and their
    /// borders make the edges their neighbours leave open there cracks.
    pub skipped: Vec<SkippedFace>,
}

/// A face of the file the reader could not build: what is known of it.
#[derive(Debug, Clone, Default)]
pub struct SkippedFace {
    /// The body it belongs to (as in [`Model::bodies`]).
    pub body: u32,
    /// The model-space curves of its border, as far as they could be read
    /// (empty when none could): where a face beside it ends along them,
    /// the mesh has a hole, not the model's own boundary.
    pub border: Vec<NurbsCurve>,
}

impl Model {
    /// The body face `face` belongs to (0 when the model has no bodies).
    pub fn body(&self, face: usize) -> u32 {
        body_of(&self.bodies, face)
    }

    /// Faces of the mesh: the exact ones, then the tessellated ones.
    pub fn face_count(&self) -> usize {
        self.faces.len() + self.tessellated.len()
    }
}

/// A face given as triangles, without an exact surface: its triangles pass
/// to the mesh as they are, so its deviation cannot be measured.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TessellatedFace {
    /// Optional name from the file.
    pub name: Option<String>,
    /// Vertex positions, model units.
    pub positions: Vec<DVec3>,
    /// Unit normals, one per position, as the file gives them; empty when it
    /// gives none (the mesh then takes the triangles' own).
    pub normals: Vec<DVec3>,
    /// Three indices into `positions` per triangle, counter-clockwise seen
    /// from the face's outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The body of face `face` by [`Model::bodies`] (0 past its end, as for a model without bodies).
pub(crate) fn body_of(bodies: &[u32], face: usize) -> u32 {
    bodies.get(face).copied().unwrap_or(0)
}

/// A surface restricted to the region its loops enclose.
#[derive(Debug, Clone)]
pub struct Face {
    /// Optional name from the file.
    pub name: Option<String>,
    /// The untrimmed base surface.
    pub surface: FaceSurface,
    /// Trim loops in (u,v); empty means the whole parameter domain.
    /// The mesher decides which loop is outer and orients them itself.
    pub loops: Vec<TrimLoop>,
}

/// A closed chain of parameter-space curves (z = 0), each ending where the next starts.
#[derive(Debug, Clone)]
pub struct TrimLoop {
    /// The curves in order.
    pub curves: Vec<NurbsCurve>,
}

/// The base surface of a face.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum FaceSurface {
    /// A (rational) B-spline surface.
    Nurbs(NurbsSurface),
    /// A bicubic B-spline rebuilt on even parameters (paper 001): C² across
    /// its simple knots, so they do not bound the mesher's first intervals.
    Rebuilt(NurbsSurface),
    /// The surface at signed `distance` along the unit normal of `base`
    /// (`S + d·N`, IGES 140), evaluated exactly (first derivatives by the Weingarten equations).
    Offset {
        /// The surface offset.
        base: Box<FaceSurface>,
        /// Offset distance along `Su × Sv` normalized, model units.
        distance: f64,
    },
}

impl FaceSurface {
    /// The B-spline surface under any offsets: it defines the domain and knots.
    fn base_nurbs(&self) -> &NurbsSurface {
        let mut s = self;
        loop {
            match s {
                Self::Nurbs(n) | Self::Rebuilt(n) => return n,
                Self::Offset { base, .. } => s = base,
            }
        }
    }
}

impl FaceSurface {
    /// `S(u, v)` at every `(us[i], vs[j])`, `u` outer; NURBS faces evaluate
    /// the grid by rows and columns ([`NurbsSurface::points_on_grid`]).
    pub fn points_on_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.points_on_grid(us, vs),
            Self::Offset { .. } => {
                us.iter().flat_map(|&u| vs.iter().map(move |&v| self.point(DVec2::new(u, v)))).collect()
            }
        }
    }
}

impl Surface for FaceSurface {
    fn domain(&self) -> [DVec2; 2] {
        self.base_nurbs().domain()
    }
    fn point(&self, uv: DVec2) -> DVec3 {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.point(uv),
            Self::Offset { base, distance } => base.point(uv) + base.normal(uv) * *distance,
        }
    }
    fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.derivs(uv),
            Self::Offset { base, distance } => offset_derivs(base, *distance, uv),
        }
    }
    fn point_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => Surface::point_grid(s, us, vs),
            Self::Offset { .. } => {
                us.iter().flat_map(|&u| vs.iter().map(move |&v| self.point(DVec2::new(u, v)))).collect()
            }
        }
    }
    fn iso_point_normal(&self, along_u: bool, s: f64) -> Box<dyn Fn(f64) -> (DVec3, DVec3) + '_> {
        match self {
            Self::Nurbs(n) | Self::Rebuilt(n) => Surface::iso_point_normal(n, along_u, s),
            Self::Offset { .. } => {
                Box::new(move |t| self.point_normal(if along_u { DVec2::new(t, s) } else { DVec2::new(s, t) }))
            }
        }
    }
    fn tangents(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.tangents(uv),
            Self::Offset { .. } => {
                let d = self.derivs(uv);
                (d.point, d.su, d.sv)
            }
        }
    }
    fn breaks(&self, along_u: bool) -> Vec<f64> {
        match self {
            // Every 8th knot: where breaks still start intervals (the border
            // loop of an untrimmed face, projection, quality mode) they follow
            // the samples, spaced by model-space length, without forcing
            // rows at coarse tolerances. The grid ignores them ([`Surface::even_parameters`]).
            Self::Rebuilt(s) => {
                let b = s.breaks(along_u);
                let last = b.len().saturating_sub(1);
                b.iter().enumerate().filter(|&(i, _)| i % 8 == 0 || i == last).map(|(_, &t)| t).collect()
            }
            _ => self.base_nurbs().breaks(along_u),
        }
    }
    fn even_parameters(&self) -> bool {
        matches!(self, Self::Rebuilt(_))
    }
    fn bounding_box(&self) -> Aabb {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.bounding_box(),
            Self::Offset { base, distance } => {
                let mut b = base.bounding_box();
                if !b.is_empty() {
                    let d = DVec3::splat(distance.abs());
                    b.min -= d;
                    b.max += d;
                }
                b
            }
        }
    }
    fn derivative_bounds(&self) -> Option<[f64; 2]> {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.derivative_bounds(),
            // The offset's speed also turns with the base's curvature.
            Self::Offset { .. } => None,
        }
    }
    fn point_normal(&self, uv: DVec2) -> (DVec3, DVec3) {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.point_normal(uv),
            Self::Offset { .. } => (self.point(uv), self.normal(uv)),
        }
    }
    fn normal_from_tangents(&self, uv: DVec2, su: DVec3, sv: DVec3) -> DVec3 {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.normal_from_tangents(uv, su, sv),
            Self::Offset { .. } => self.normal(uv),
        }
    }
    fn normal(&self, uv: DVec2) -> DVec3 {
        match self {
            Self::Nurbs(s) | Self::Rebuilt(s) => s.normal(uv),
            // Parallel to the base's normal wherever the offset is regular.
            Self::Offset { base, .. } => base.normal(uv),
        }
    }
}

/// First derivatives of the offset surface `O = S + d·N` exactly, second
/// derivatives by central differences.
///
/// `O_u = S_u + d·N_u`, `O_v = S_v + d·N_v`, with the normal's derivatives
/// from the Weingarten equations: with `E, F, G` the first and `L, M, N` the
/// second fundamental form of the base and `D = EG − F²`,
/// `N_u = ((FM − GL)·S_u + (FL − EM)·S_v) / D` and
/// `N_v = ((FN − GM)·S_u + (FM − EN)·S_v) / D`. They need the base's second
/// derivatives, so the offset's second derivatives would need its third:
/// instead they are central differences of `O_u` and `O_v` over a step of
/// 1e-5 of the domain (one-sided next to the domain's edges), which is what
/// the mesher's curvature estimates need. Where the base degenerates
/// (`D ≈ 0`, a pole) the normal's derivatives are taken as zero.
fn offset_derivs(base: &FaceSurface, d: f64, uv: DVec2) -> SurfaceDerivs {
    let first = |q: DVec2| -> (DVec3, DVec3, DVec3) {
        let b = base.derivs(q);
        let n = base.normal(q);
        let (e, f, g) = (b.su.dot(b.su), b.su.dot(b.sv), b.sv.dot(b.sv));
        let (l, m, nn) = (b.suu.dot(n), b.suv.dot(n), b.svv.dot(n));
        let den = e * g - f * f;
        let (nu, nv) = if den > 1e-24 * (e * g).max(TINY) && den.is_finite() {
            (
                (b.su * (f * m - g * l) + b.sv * (f * l - e * m)) / den,
                (b.su * (f * nn - g * m) + b.sv * (f * m - e * nn)) / den,
            )
        } else {
            (DVec3::ZERO, DVec3::ZERO)
        };
        (b.point + n * d, b.su + nu * d, b.sv + nv * d)
    };
    let (point, su, sv) = first(uv);
    let [lo, hi] = base.domain();
    let h = (hi - lo) * 1e-5;
    // Step inside the domain: centred where possible.
    let pair = |x: f64, lo: f64, hi: f64, h: f64| -> (f64, f64) {
        let a = (x - h).max(lo);
        let b = (a + 2.0 * h).min(hi);
        let a = (b - 2.0 * h).max(lo);
        (a, b)
    };
    let (u0, u1) = pair(uv.x, lo.x, hi.x, h.x);
    let (v0, v1) = pair(uv.y, lo.y, hi.y, h.y);
    let (_, su_a, sv_a) = first(DVec2::new(u0, uv.y));
    let (_, su_b, sv_b) = first(DVec2::new(u1, uv.y));
    let (_, _, sv_c) = first(DVec2::new(uv.x, v0));
    let (_, _, sv_d) = first(DVec2::new(uv.x, v1));
    let du = u1 - u0;
    let dv = v1 - v0;
    let suu = if du > 0.0 { (su_b - su_a) / du } else { DVec3::ZERO };
    let suv = if du > 0.0 { (sv_b - sv_a) / du } else { DVec3::ZERO };
    let svv = if dv > 0.0 { (sv_d - sv_c) / dv } else { DVec3::ZERO };
    SurfaceDerivs { point, su, sv, suu, suv, svv }
}

impl Model {
    /// Box around all base surfaces' control nets (a cheap upper bound; the
    /// mesher measures the trimmed geometry itself for relative tolerances).
    pub fn control_bbox(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for f in &self.faces {
            b.union(&f.surface.bounding_box());
        }
        b
    }
}
