//! The model to mesh: faces made of a surface and trim loops in its (u,v).

use alloc::string::String;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::nurbs::{Aabb, NurbsCurve, NurbsSurface, Surface, SurfaceDerivs};

/// Everything read from one input file.
#[derive(Debug, Clone, Default)]
pub struct Model {
    /// Length unit name as given by the file (`"mm"` when unknown).
    pub units: String,
    /// The faces, in file order.
    pub faces: Vec<Face>,
    /// Things the reader skipped or repaired, for the report.
    pub warnings: Vec<String>,
    /// The file's own modelling tolerance, model units (IGES global section:
    /// minimum resolution), when it states one: the gaps its author accepted
    /// between faces, so sewing reaches at least that far.
    pub tolerance: Option<f64>,
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
}

impl FaceSurface {
    fn inner(&self) -> &dyn Surface {
        match self {
            Self::Nurbs(s) => s,
        }
    }
}

impl Surface for FaceSurface {
    fn domain(&self) -> [DVec2; 2] {
        self.inner().domain()
    }
    fn point(&self, uv: DVec2) -> DVec3 {
        self.inner().point(uv)
    }
    fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
        self.inner().derivs(uv)
    }
    fn breaks(&self, along_u: bool) -> Vec<f64> {
        self.inner().breaks(along_u)
    }
    fn bounding_box(&self) -> Aabb {
        self.inner().bounding_box()
    }
    fn normal(&self, uv: DVec2) -> DVec3 {
        self.inner().normal(uv)
    }
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
