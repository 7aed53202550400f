//! Test only: a surface that counts its evaluations by kind, for tests that
//! prove a step evaluates less (or not at all) while its result stays the same.

use alloc::vec::Vec;
use core::cell::Cell;

use glam::{DVec2, DVec3};

use super::{Aabb, Surface, SurfaceDerivs};

/// `s` with its evaluations counted: bare points, points with first and
/// second derivatives (`derivs`), and with first derivatives (`tangents`).
pub(crate) struct Counted<'a> {
    pub(crate) s: &'a dyn Surface,
    pub(crate) points: Cell<usize>,
    pub(crate) derivs: Cell<usize>,
    pub(crate) tangents: Cell<usize>,
}

impl<'a> Counted<'a> {
    pub(crate) fn new(s: &'a dyn Surface) -> Self {
        Self { s, points: Cell::new(0), derivs: Cell::new(0), tangents: Cell::new(0) }
    }

    /// Evaluations of every kind.
    pub(crate) fn total(&self) -> usize {
        self.points.get() + self.derivs.get() + self.tangents.get()
    }

    /// Every count back to 0.
    pub(crate) fn reset(&self) {
        for c in [&self.points, &self.derivs, &self.tangents] {
            c.set(0);
        }
    }
}

fn tick(c: &Cell<usize>) {
    c.set(c.get() + 1);
}

impl Surface for Counted<'_> {
    fn domain(&self) -> [DVec2; 2] {
        self.s.domain()
    }
    fn point(&self, uv: DVec2) -> DVec3 {
        tick(&self.points);
        self.s.point(uv)
    }
    fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
        tick(&self.derivs);
        self.s.derivs(uv)
    }
    fn tangents(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        tick(&self.tangents);
        self.s.tangents(uv)
    }
    fn breaks(&self, along_u: bool) -> Vec<f64> {
        self.s.breaks(along_u)
    }
    fn bounding_box(&self) -> Aabb {
        self.s.bounding_box()
    }
}
