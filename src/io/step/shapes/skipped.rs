//! What is known of a face the reader skipped: the model-space curves of
//! its edges, read on their own (the face's surface or loops may be what
//! failed). The mesh's report counts the edges its neighbours leave open
//! along them as cracks, not as the model's boundary.

use alloc::vec::Vec;
use glam::{DAffine3, DVec3};

use super::super::curves::Geo;
use super::super::graph::Ent;
use super::Reader;
use crate::nurbs::analytic::line;
use crate::nurbs::reparam::map_points;
use crate::nurbs::NurbsCurve;

/// Most edges read for one skipped face's border (a hostile file cannot make it loop long).
const MAX_EDGES: usize = 10_000;

impl Reader<'_, '_> {
    /// The border curves of face `e` (an `ADVANCED_FACE`, `FACE_SURFACE` or
    /// `ORIENTED_FACE`): every edge of its loops that reads, in item
    /// coordinates; a poly loop's sides. Whatever fails is left out.
    pub(super) fn skipped_border(&mut self, geo: &Geo<'_>, e: Ent<'_>) -> Vec<NurbsCurve> {
        let mut out = Vec::new();
        let face = if e.has("ORIENTED_FACE") { e.attrs().ent(2).ok() } else { Some(e) };
        let Some(face) = face.filter(|f| f.has("FACE_SURFACE") || f.has("ADVANCED_FACE")) else { return out };
        let Ok(bounds) = face.chain(&[("REPRESENTATION_ITEM", 1), ("FACE", 1)]).and_then(|a| a.refs(1)) else {
            return out;
        };
        let mut budget = MAX_EDGES;
        for b in bounds {
            let bound = self.g.find(b).and_then(|b| b.chain(&[("REPRESENTATION_ITEM", 1), ("FACE_BOUND", 2)]).ok());
            let Some(lp) = bound.and_then(|a| a.ent(1).ok()) else { continue };
            if lp.has("EDGE_LOOP") {
                let uses = match lp.part("EDGE_LOOP") {
                    Some(p) if lp.is_complex() => p.refs(0),
                    _ => lp.attrs().refs(1),
                };
                let Ok(uses) = uses else { continue };
                let alone = uses.len() == 1;
                for r in uses.into_iter().take(budget) {
                    budget -= 1;
                    let Some(oe) = self.g.find(r) else { continue };
                    let edge = if oe.has("ORIENTED_EDGE") { oe.attrs().ent(3).ok() } else { Some(oe) };
                    if let Some(Ok(ed)) = edge.map(|x| self.edges.get(geo, x, alone)) {
                        out.extend(ed.pieces);
                    }
                }
            } else if lp.has("POLY_LOOP") {
                let Ok(refs) = lp.chain(&[("REPRESENTATION_ITEM", 1), ("POLY_LOOP", 1)]).and_then(|a| a.refs(1)) else {
                    continue;
                };
                let pts: Vec<DVec3> = refs
                    .into_iter()
                    .take(budget)
                    .filter_map(|r| self.g.find(r).and_then(|p| geo.point(p).ok()))
                    .collect();
                budget = budget.saturating_sub(pts.len());
                for i in 0..pts.len() {
                    let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
                    if let (true, Ok(c)) = (p != q, line(p, q, 0.0, 1.0)) {
                        out.push(c);
                    }
                }
            }
        }
        out
    }
}

/// `curves` moved by the placement `m` (control points mapped: exact for an affine map).
pub(super) fn place_border(curves: &[NurbsCurve], m: &DAffine3) -> Vec<NurbsCurve> {
    if *m == DAffine3::IDENTITY {
        return curves.to_vec();
    }
    curves.iter().filter_map(|c| map_points(c, |p| m.transform_point3(p)).ok()).collect()
}
