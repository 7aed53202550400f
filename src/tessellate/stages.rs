//! The mesher's stages one at a time, so that the criterion benches
//! (`benches/tessellate.rs`) can time each on fixed inputs: trim-loop
//! discretization, the iso-parametric grid, the CDT of the trimmed band, and
//! refinement. Not a stable API: hidden from the docs, for benches only.

use alloc::vec::Vec;
use glam::DVec2;

use super::band::Band;
use super::face::{build_full_grid, check_grid, grid};
use super::refine::WorkMesh;
use super::trim::{prepare_loops, Loops};
use super::{setup, Setup};
use crate::nurbs::Surface;
use crate::{Error, Face, MeshOptions, Model};

/// One face of a model with the limits `mesh_model` would use on it.
pub struct FaceStages<'a> {
    index: usize,
    face: &'a Face,
    setup: Setup,
    budget: usize,
}

/// A face's trim loops, discretized (or none for an untrimmed face), and the
/// parameter rectangle its grid covers.
pub struct Discretized<'a> {
    loops: Option<Loops<'a>>,
    lo: DVec2,
    hi: DVec2,
}

impl Discretized<'_> {
    /// Loop nodes in all loops (0 for an untrimmed face).
    pub fn loop_nodes(&self) -> usize {
        self.loops.as_ref().map_or(0, |l| l.polys.iter().map(|p| p.uv.len()).sum())
    }
}

/// The grid's parameter lines along u and v.
pub struct Grid {
    pu: Vec<f64>,
    pv: Vec<f64>,
}

impl Grid {
    /// Number of parameter lines `[along u, along v]`.
    pub fn size(&self) -> [usize; 2] {
        [self.pu.len(), self.pv.len()]
    }
}

/// The nodes and constraints the CDT of a trimmed face runs on.
pub struct CdtInput(Band);

impl CdtInput {
    /// Nodes to triangulate (loop nodes and kept grid nodes).
    pub fn nodes(&self) -> usize {
        self.0.nodes.len()
    }
}

/// A face's mesh before refinement (grid or grid plus CDT band), with the
/// trim curves its trim edges follow.
pub struct Initial<'a> {
    mesh: WorkMesh,
    curves: Vec<&'a crate::NurbsCurve>,
}

impl Initial<'_> {
    /// Triangles before refinement.
    pub fn triangles(&self) -> usize {
        self.mesh.tris.len()
    }
}

impl<'a> FaceStages<'a> {
    /// Face `index` of `model`, with the tolerance and limits `options` give for the whole model.
    ///
    /// # Errors
    /// Invalid options, an empty model, or no face `index`.
    pub fn new(model: &'a Model, index: usize, options: &MeshOptions) -> Result<Self, Error> {
        let setup = setup(model, options)?;
        let face = model.faces.get(index).ok_or_else(|| Error::Mesh { face: index, message: "no such face".into() })?;
        Ok(Self { index, face, setup, budget: options.max_triangles })
    }

    fn surface(&self) -> &'a dyn Surface {
        &self.face.surface
    }

    /// Stage 1, edge discretization: the trim loops to oriented, checked polylines.
    ///
    /// # Errors
    /// As `mesh_model` for bad loops.
    pub fn discretize(&self) -> Result<Discretized<'a>, Error> {
        let [dlo, dhi] = self.surface().domain();
        if self.face.loops.is_empty() {
            return Ok(Discretized { loops: None, lo: dlo, hi: dhi });
        }
        let loops = prepare_loops(self.index, self.surface(), &self.face.loops, &self.setup.lim)?;
        let (llo, lhi) = loops.bounds();
        Ok(Discretized { loops: Some(loops), lo: llo.max(dlo), hi: lhi.min(dhi) })
    }

    /// Stage 2: the iso-parametric grid over the face's (trimmed) parameter rectangle.
    pub fn grid(&self, d: &Discretized<'_>) -> Grid {
        let (pu, pv) = grid(self.surface(), d.lo, d.hi, &self.setup.lim, d.loops.as_ref(), usize::MAX);
        Grid { pu, pv }
    }

    /// Stage 3 input: loop nodes and kept grid nodes (`None` for an untrimmed face).
    pub fn cdt_input(&self, d: &Discretized<'_>, g: &Grid) -> Option<CdtInput> {
        let loops = d.loops.as_ref()?;
        Some(CdtInput(Band::new(self.surface(), loops, &g.pu, &g.pv)))
    }

    /// Stage 3: the constrained Delaunay triangulation of the band; returns the triangle count.
    ///
    /// # Errors
    /// As `mesh_model` for crossing loops.
    pub fn cdt(&self, input: &CdtInput) -> Result<usize, Error> {
        Ok(input.0.clone().triangulate(self.index)?.len())
    }

    /// Stages 1 to 3 together: the mesh refinement starts from.
    ///
    /// # Errors
    /// As `mesh_model`.
    pub fn initial(&self) -> Result<Initial<'a>, Error> {
        let d = self.discretize()?;
        let g = self.grid(&d);
        check_grid(self.index, &g.pu, &g.pv, self.budget)?;
        let mut mesh = WorkMesh::default();
        match d.loops {
            None => {
                build_full_grid(self.surface(), &g.pu, &g.pv, &mut mesh);
                Ok(Initial { mesh, curves: Vec::new() })
            }
            Some(loops) => {
                let mut band = Band::new(self.surface(), &loops, &g.pu, &g.pv);
                let tris = band.triangulate(self.index)?;
                band.build(self.surface(), &tris, &mut mesh, None);
                Ok(Initial { mesh, curves: loops.curves })
            }
        }
    }

    /// Stage 4: refinement until every triangle is within the limits; returns the triangle count.
    pub fn refine(&self, initial: Initial<'_>) -> usize {
        let Initial { mut mesh, curves } = initial;
        mesh.refine(self.surface(), &curves, &self.setup.crit, self.budget);
        mesh.tris.len()
    }
}

impl FaceStages<'_> {
    /// Debugging aid: the (u,v) corners of every triangle of `initial` (after
    /// refinement when `refined`), each with whether it is inverted.
    pub fn uv_triangles(&self, initial: Initial<'_>, refined: bool) -> Vec<([DVec2; 3], bool)> {
        let Initial { mut mesh, curves } = initial;
        if refined {
            mesh.refine(self.surface(), &curves, &self.setup.crit, self.budget);
        }
        (0..mesh.tris.len()).map(|t| (mesh.uv(t), mesh.inverted(self.surface(), t))).collect()
    }
}

/// Nanoseconds the mesher has spent measuring deviation (every triangle's
/// samples projected on its surface) in this process, with the `timing`
/// feature; `None` without it.
pub fn measure_nanos() -> Option<u64> {
    #[cfg(feature = "timing")]
    return Some(super::measure::MEASURE_NANOS.load(core::sync::atomic::Ordering::Relaxed));
    #[cfg(not(feature = "timing"))]
    None
}
