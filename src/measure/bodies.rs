//! Which body of the model each face of a measured mesh lies on, whatever
//! mesher made the mesh and however it numbers its faces, so that edges are
//! welded and counted per body as the mesher's own report counts them: two
//! parts of an assembly that touch share no edge.
//!
//! Each triangle votes for the bodies of the model faces nearest its centroid
//! (more than one where faces of two bodies coincide, as where parts touch).
//! A face range goes to the body with clearly the most votes; a tie is broken
//! by the bodies of the decided face ranges it shares vertices with.

use alloc::vec::Vec;

use crate::collections::HashMap;
use crate::mesh::{weld_positions, Mesh};
use crate::model::{body_of, Model};

/// A body's votes at least this share of the leader's tie with it.
const TIE: f64 = 0.9;

/// Rounds of passing decided bodies on to tied neighbours.
const ROUNDS: usize = 8;

/// Votes per face range of a mesh, triangle by triangle.
pub(crate) struct BodyVotes<'m> {
    model: &'m Model,
    /// Per face range, (body, votes) pairs; empty when the model is one body
    /// or the mesh has no face ranges.
    votes: Vec<Vec<(u32, u32)>>,
    /// The first triangle of each face range, then the end.
    starts: Vec<u32>,
    /// The face range of the last triangle voted.
    cursor: usize,
}

impl<'m> BodyVotes<'m> {
    /// No votes yet for `mesh`'s face ranges.
    pub(crate) fn new(model: &'m Model, mesh: &Mesh) -> Self {
        let bodies = model.bodies.first().is_some_and(|b0| model.bodies.iter().any(|b| b != b0));
        let ranges = if bodies { mesh.face_ranges.len() } else { 0 };
        let mut starts: Vec<u32> = mesh.face_ranges.iter().take(ranges).map(|r| r.first).collect();
        starts.push(mesh.face_ranges.get(ranges.wrapping_sub(1)).map_or(0, |r| r.first + r.count));
        Self { model, votes: alloc::vec![Vec::new(); ranges], starts, cursor: 0 }
    }

    /// Triangle `t` (in increasing order) lies nearest the model faces `near`.
    pub(crate) fn add(&mut self, t: usize, near: &[u32]) {
        if self.votes.is_empty() {
            return;
        }
        while self.cursor + 1 < self.votes.len() && t as u32 >= self.starts[self.cursor + 1] {
            self.cursor += 1;
        }
        let Some(votes) = self.votes.get_mut(self.cursor) else { return };
        let mut seen: Vec<u32> = Vec::with_capacity(near.len());
        for &f in near {
            let body = body_of(&self.model.bodies, f as usize);
            if seen.contains(&body) {
                continue;
            }
            seen.push(body);
            match votes.iter_mut().find(|v| v.0 == body) {
                Some(v) => v.1 += 1,
                None => votes.push((body, 1)),
            }
        }
    }

    /// The body of each face range (empty: one body), its vertices welded
    /// within `weld` to find its neighbours.
    pub(crate) fn bodies(&self, mesh: &Mesh, weld: f64) -> Vec<u32> {
        if self.votes.is_empty() {
            return Vec::new();
        }
        // Per range: the bodies tied for the most votes (empty: no vote).
        let tied: Vec<Vec<u32>> = self.votes.iter().map(|v| leaders(v)).collect();
        let mut decided: Vec<Option<u32>> = tied.iter().map(|c| if c.len() == 1 { Some(c[0]) } else { None }).collect();
        if decided.iter().any(Option::is_none) {
            self.break_ties(mesh, weld, &tied, &mut decided);
        }
        decided.iter().zip(&tied).map(|(d, c)| d.or(c.first().copied()).unwrap_or(u32::MAX)).collect()
    }

    /// Decides tied face ranges by the bodies of the decided ranges they
    /// share welded vertices with, round by round.
    fn break_ties(&self, mesh: &Mesh, weld: f64, tied: &[Vec<u32>], decided: &mut [Option<u32>]) {
        let (map, _) = weld_positions(&mesh.positions, weld);
        // Per face range, its welded vertices; per welded vertex, its ranges.
        let mut vertices: Vec<Vec<u32>> = Vec::with_capacity(tied.len());
        let mut ranges_at: HashMap<u32, Vec<u32>> = HashMap::default();
        for r in 0..tied.len() {
            let (first, end) = (self.starts[r] as usize, self.starts[r + 1] as usize);
            let mut ids: Vec<u32> = mesh
                .indices
                .get(3 * first..3 * end)
                .unwrap_or(&[])
                .iter()
                .filter_map(|&v| map.get(v as usize).copied())
                .collect();
            crate::sort::by_u64(&mut ids, |&x| u64::from(x));
            ids.dedup();
            for &id in &ids {
                ranges_at.entry(id).or_default().push(r as u32);
            }
            vertices.push(ids);
        }
        for _ in 0..ROUNDS {
            let before: Vec<Option<u32>> = decided.to_vec();
            let mut progress = false;
            for r in (0..tied.len()).filter(|&r| before[r].is_none()) {
                let mut shared: Vec<(u32, u32)> = Vec::new();
                for id in &vertices[r] {
                    let others = ranges_at.get(id).map_or(&[][..], Vec::as_slice);
                    for body in others.iter().filter_map(|&o| before[o as usize]) {
                        if !tied[r].is_empty() && !tied[r].contains(&body) {
                            continue;
                        }
                        match shared.iter_mut().find(|s| s.0 == body) {
                            Some(s) => s.1 += 1,
                            None => shared.push((body, 1)),
                        }
                    }
                }
                let best = shared.iter().copied().fold(None, |b: Option<(u32, u32)>, s| match b {
                    Some(b) if b.1 > s.1 || (b.1 == s.1 && b.0 < s.0) => Some(b),
                    _ => Some(s),
                });
                if let Some((body, _)) = best {
                    decided[r] = Some(body);
                    progress = true;
                }
            }
            if !progress {
                break;
            }
        }
    }
}

/// The bodies within [`TIE`] of the most votes, lowest first.
fn leaders(votes: &[(u32, u32)]) -> Vec<u32> {
    let top = votes.iter().map(|v| v.1).max().unwrap_or(0);
    let mut out: Vec<u32> =
        votes.iter().filter(|v| top > 0 && f64::from(v.1) >= TIE * f64::from(top)).map(|v| v.0).collect();
    crate::sort::by_u64(&mut out, |&x| u64::from(x));
    out
}
