//! The work mesh's invariants, checked in one place (as spade's sanity check
//! does for its triangulation). [`WorkMesh::check_invariants`] holds a face to
//! all of them, as the tests below do; the fast mesher's pipeline runs the
//! same check on every face after each stage in debug builds, so that every
//! real file a test meshes goes through it. Some later stages still break
//! some invariants on real files: [`Known`] names those a stage may leave,
//! with the files that show them, and any other break fails at once.
// Only debug builds run the checks; release builds keep the stages' sets.
#![cfg_attr(not(debug_assertions), allow(dead_code))]

use alloc::vec::Vec;
use core::fmt;

use glam::DVec2;

use super::{key, WorkMesh, NONE, UV_UNSET};
use crate::collections::HashMap;
use crate::nurbs::Surface;

/// A triangle's doubled (u,v) area within this fraction of its longest
/// side squared is flat: rounding's share of the cross product, not a turn.
const FLAT_UV: f64 = 1e-12;

/// An invariant of a [`WorkMesh`] found broken.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Broken {
    /// The per-vertex tables differ in length.
    VertexTables { positions: usize, normals: usize, ids: usize, uvs: usize },
    /// A triangle names a vertex twice or one that does not exist.
    Triangle { t: usize, v: [u32; 3] },
    /// A triangle's vertex has no (u,v).
    NoUv { t: usize, vertex: u32 },
    /// The odd corners' table names a triangle past the last.
    OddUv { t: u32 },
    /// An edge has more than two triangles, which the edge table cannot
    /// hold (seen where sewing passes a loop through one node twice).
    NonManifold { edge: (u32, u32), triangles: Vec<u32> },
    /// The awake edge table does not list an edge's triangles as they are.
    EdgeTable { edge: (u32, u32), listed: [u32; 2], found: Vec<u32> },
    /// The awake edge table has another number of edges than the triangles.
    EdgeCount { found: usize, listed: usize },
    /// A face at rest kept its edge table, or an awake face its rim.
    State { resting: bool },
    /// The rim has another number of edges than the border.
    RimCount { border: usize, rim: usize },
    /// A rim edge is not a border edge of its triangle.
    Rim { edge: (u32, u32), t: u32 },
    /// A triangle does not run counter-clockwise in (u,v) (seen after
    /// mending and improving: flips and moves that fold or flatten a
    /// triangle in (u,v), mostly at poles and seams).
    Clockwise { t: usize, twice_area: f64 },
    /// A border edge neither follows a trim curve nor is shared (seen where
    /// closing slivers adds a triangle between faces).
    LooseBorder { edge: (u32, u32), t: u32 },
    /// A trim or shared edge is no edge of the mesh.
    StaleEdge { edge: (u32, u32) },
}

impl fmt::Display for Broken {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::VertexTables { positions, normals, ids, uvs } => {
                write!(f, "{positions} positions but {normals} normals, {ids} node ids, {uvs} (u,v)")
            }
            Self::Triangle { t, v } => write!(f, "triangle {t} {v:?} does not name three vertices"),
            Self::NoUv { t, vertex } => write!(f, "vertex {vertex} of triangle {t} has no (u,v)"),
            Self::OddUv { t } => write!(f, "odd (u,v) of triangle {t}, past the last triangle"),
            Self::NonManifold { edge, triangles } => {
                write!(f, "edge {edge:?} has more than two triangles: {triangles:?}")
            }
            Self::EdgeTable { edge, listed, found } => {
                write!(f, "edge {edge:?} lists triangles {listed:?}, its triangles are {found:?}")
            }
            Self::EdgeCount { found, listed } => {
                write!(f, "{found} edges of triangles but {listed} in the edge table")
            }
            Self::State { resting: true } => write!(f, "a face at rest kept its edge table"),
            Self::State { resting: false } => write!(f, "an awake face kept its rim"),
            Self::RimCount { border, rim } => write!(f, "{border} border edges but {rim} in the rim"),
            Self::Rim { edge, t } => write!(f, "rim edge {edge:?} is not a border edge of triangle {t}"),
            Self::Clockwise { t, twice_area } => {
                write!(f, "triangle {t} runs clockwise in (u,v) (twice its area {twice_area:e})")
            }
            Self::LooseBorder { edge, t } => {
                write!(f, "border edge {edge:?} of triangle {t} is neither trim nor shared")
            }
            Self::StaleEdge { edge } => write!(f, "trim or shared edge {edge:?} is no edge of the mesh"),
        }
    }
}

/// The breaks of the full invariants a stage of the fast mesher may leave,
/// as the sweeps of both corpora (1e-2 and 1e-3) found them; each later
/// stage's set holds the earlier ones', since no stage mends what an
/// earlier one broke. No set lets the tables ([`WorkMesh::check_tables`])
/// disagree.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Known {
    /// Edges of more than two triangles: the first meshes of a surface
    /// that folds back over itself, where sewing passes one loop through a
    /// node twice (OCC131-2 and OCC131-3 of the wide corpus). A split of
    /// such an edge halves the two triangles the edge table lists and the
    /// table then lists the third on it; none is flipped or collapsed.
    pub non_manifold: bool,
    /// Triangles folded against the surface in space, which mending could
    /// not unfold and the report counts as inverted (next to border nodes
    /// sewing moved; no corpus part has one now, hostile input may).
    pub folds: bool,
}

impl Known {
    /// Nothing: every invariant holds.
    pub(crate) const NONE: Self = Self { non_manifold: false, folds: false };
    /// From the first meshes to settling the nodes.
    pub(crate) const SEWN: Self = Self { non_manifold: true, ..Self::NONE };
    /// From mending on.
    pub(crate) const MENDED: Self = Self { folds: true, ..Self::SEWN };
}

/// The triangles on each edge, from the triangles themselves.
type EdgeUses = HashMap<(u32, u32), Vec<u32>>;

impl WorkMesh {
    /// Every invariant: the tables agree ([`WorkMesh::check_tables`]), no
    /// edge has more than two triangles, every triangle runs
    /// counter-clockwise in (u,v), every border edge (one triangle) follows a
    /// trim curve or is shared with another face, and every trim or shared
    /// edge is an edge of the mesh. The first found broken.
    #[cfg(test)]
    pub(crate) fn check_invariants(&self) -> Result<(), Broken> {
        self.check_invariants_with(None, Known::NONE)
    }

    /// [`WorkMesh::check_invariants`] with the face's surface, for the breaks
    /// `known` lets pass. Sewing moves border nodes in space but keeps their
    /// (u,v), and three corners on an iso-line are flat in (u,v) while the
    /// surface curves between them: where the (u,v) cannot tell
    /// ([`WorkMesh::uv_cannot_tell`]), a triangle passes while it faces the
    /// surface's way in space ([`WorkMesh::inverted`], what the report counts).
    pub(crate) fn check_invariants_on(&self, surface: &dyn Surface, known: Known) -> Result<(), Broken> {
        self.check_invariants_with(Some(surface), known)
    }

    fn check_invariants_with(&self, surface: Option<&dyn Surface>, known: Known) -> Result<(), Broken> {
        let uses = self.edge_uses();
        if let Some((&edge, ts)) = uses.iter().find(|(_, ts)| ts.len() > 2).filter(|_| !known.non_manifold) {
            return Err(Broken::NonManifold { edge, triangles: ts.clone() });
        }
        self.check_tables_with(&uses)?;
        for t in 0..self.tris.len() {
            let twice_area = super::uv_area(self.uv(t));
            // Not counter-clockwise: zero, negative or NaN.
            if twice_area.partial_cmp(&0.0) == Some(core::cmp::Ordering::Greater) {
                continue;
            }
            let folded = surface.map(|s| self.inverted(s, t));
            let excused = match folded {
                Some(false) => self.uv_cannot_tell(t, twice_area),
                Some(true) => known.folds,
                None => false,
            };
            if !excused {
                return Err(Broken::Clockwise { t, twice_area });
            }
        }
        for (&edge, ts) in &uses {
            if ts.len() == 1 && !self.trim.contains_key(&edge) && !self.shared.contains_key(&edge) {
                return Err(Broken::LooseBorder { edge, t: ts[0] });
            }
        }
        match self.trim.keys().chain(self.shared.keys()).find(|e| !uses.contains_key(e)) {
            Some(edge) => Err(Broken::StaleEdge { edge }),
            None => Ok(()),
        }
    }

    /// Whether triangle `t`'s (u,v) cannot say which way it faces: a
    /// corner is a border node (a model node id), whose (u,v) sewing left
    /// where it was when it moved the node in space, or its corners lie on
    /// one line in (u,v) (`twice_area` within rounding of zero), as on an
    /// iso-line, where the surface curves between them.
    fn uv_cannot_tell(&self, t: usize, twice_area: f64) -> bool {
        self.uv_cannot_tell_of(self.tris[t], self.uv(t), twice_area)
    }

    /// [`WorkMesh::uv_cannot_tell`] for corners `v` at (u,v) `w`, before
    /// they are a triangle of the mesh (a flip's candidates).
    pub(super) fn uv_cannot_tell_of(&self, v: [u32; 3], w: [DVec2; 3], twice_area: f64) -> bool {
        let longest = (0..3).map(|k| w[k].distance_squared(w[(k + 1) % 3])).fold(0.0, f64::max);
        v.iter().any(|&v| self.gid[v as usize] != NONE) || twice_area.abs() <= FLAT_UV * longest
    }

    /// The tables agree: the per-vertex tables (position, normal, node id,
    /// (u,v)) have one entry a vertex; every triangle names three different
    /// vertices, each with a (u,v); the odd corners' table names triangles
    /// that exist; awake, the edge table lists exactly the triangles on each
    /// edge, and at rest it is empty and the rim lists exactly the border
    /// edges with their triangles. An edge of more than two triangles, which
    /// no table can hold, is left to [`WorkMesh::check_invariants`].
    #[cfg(test)]
    pub(crate) fn check_tables(&self) -> Result<(), Broken> {
        self.check_tables_with(&self.edge_uses())
    }

    /// [`WorkMesh::check_tables`] with the triangles on each edge given.
    fn check_tables_with(&self, uses: &EdgeUses) -> Result<(), Broken> {
        let n = self.pos.len();
        if self.normal.len() != n || self.gid.len() != n || self.vuv.len() != n {
            let (normals, ids, uvs) = (self.normal.len(), self.gid.len(), self.vuv.len());
            return Err(Broken::VertexTables { positions: n, normals, ids, uvs });
        }
        for (t, &v) in self.tris.iter().enumerate() {
            if v.iter().any(|&x| x as usize >= n) || v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
                return Err(Broken::Triangle { t, v });
            }
            if let Some(&vertex) = v.iter().find(|&&x| self.vuv[x as usize].x.to_bits() == UV_UNSET) {
                return Err(Broken::NoUv { t, vertex });
            }
        }
        if let Some(&t) = self.odd_uv.keys().find(|&&t| t as usize >= self.tris.len()) {
            return Err(Broken::OddUv { t });
        }
        if uses.values().any(|ts| ts.len() > 2) {
            return Ok(());
        }
        if self.resting {
            self.check_rim(uses)
        } else {
            self.check_edge_table(uses)
        }
    }

    fn edge_uses(&self) -> EdgeUses {
        let mut uses = EdgeUses::default();
        for (t, v) in self.tris.iter().enumerate() {
            for k in 0..3 {
                uses.entry(key(v[k], v[(k + 1) % 3])).or_default().push(t as u32);
            }
        }
        uses
    }

    /// At rest: no edge table, and the rim lists exactly the border edges.
    fn check_rim(&self, uses: &EdgeUses) -> Result<(), Broken> {
        if self.edges.iter().next().is_some() {
            return Err(Broken::State { resting: true });
        }
        let border = uses.values().filter(|ts| ts.len() == 1).count();
        if border != self.rim.0.len() {
            return Err(Broken::RimCount { border, rim: self.rim.0.len() });
        }
        for &(edge, t) in &self.rim.0 {
            if uses.get(&edge).is_none_or(|ts| ts.as_slice() != [t]) {
                return Err(Broken::Rim { edge, t });
            }
        }
        Ok(())
    }

    /// Awake: no rim, and the edge table lists exactly each edge's triangles.
    fn check_edge_table(&self, uses: &EdgeUses) -> Result<(), Broken> {
        if !self.rim.0.is_empty() {
            return Err(Broken::State { resting: false });
        }
        let mut listed = 0usize;
        for (edge, ts) in self.edges.iter() {
            listed += 1;
            let mut mine: Vec<u32> = ts.iter().copied().filter(|&t| t != NONE).collect();
            mine.sort_unstable();
            let mut found = uses.get(&edge).cloned().unwrap_or_default();
            found.sort_unstable();
            if ts[0] == NONE || mine != found {
                return Err(Broken::EdgeTable { edge, listed: *ts, found });
            }
        }
        if listed != uses.len() {
            return Err(Broken::EdgeCount { found: uses.len(), listed });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Criteria, TrimEdge};
    use super::*;
    use crate::nurbs::{analytic, NurbsCurve};
    use glam::{DVec2, DVec3};

    /// A 4 × 4 grid of squares over (u,v) in [0, 4]² on the plane z = 0 (u = x,
    /// v = y), two triangles each, its border marked as following the four
    /// sides (`sides`, each a line over [0, 1]).
    fn trimmed_grid() -> (WorkMesh, Vec<NurbsCurve>) {
        let mut m = WorkMesh::default();
        for j in 0..5 {
            for i in 0..5 {
                m.add_vertex(DVec3::new(f64::from(i), f64::from(j), 0.0), DVec3::Z);
            }
        }
        let v = |i: u32, j: u32| 5 * j + i;
        let w = |i: u32, j: u32| DVec2::new(f64::from(i), f64::from(j));
        for j in 0..4 {
            for i in 0..4 {
                m.add_triangle([v(i, j), v(i + 1, j), v(i + 1, j + 1)], [w(i, j), w(i + 1, j), w(i + 1, j + 1)]);
                m.add_triangle([v(i, j), v(i + 1, j + 1), v(i, j + 1)], [w(i, j), w(i + 1, j + 1), w(i, j + 1)]);
            }
        }
        let corners = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)];
        let sides: Vec<NurbsCurve> = (0..4)
            .map(|s| {
                let (a, b) = (corners[s], corners[(s + 1) % 4]);
                analytic::line(DVec3::new(a.0, a.1, 0.0), DVec3::new(b.0, b.1, 0.0), 0.0, 1.0).unwrap()
            })
            .collect();
        for k in 0..4u32 {
            let t = |x: u32| f64::from(x) / 4.0;
            m.mark_trim(v(k, 0), v(k + 1, 0), 0, t(k), t(k + 1));
            m.mark_trim(v(4, k), v(4, k + 1), 1, t(k), t(k + 1));
            m.mark_trim(v(4 - k, 4), v(3 - k, 4), 2, t(k), t(k + 1));
            m.mark_trim(v(0, 4 - k), v(0, 3 - k), 3, t(k), t(k + 1));
        }
        (m, sides)
    }

    /// Refinement, rest, a split at rest and waking keep every invariant.
    #[test]
    fn refinement_rest_and_wake_keep_every_invariant() {
        let s = analytic::xy_plane(10.0);
        let (mut m, sides) = trimmed_grid();
        assert_eq!(m.check_invariants(), Ok(()));
        let curves: Vec<&NurbsCurve> = sides.iter().collect();
        let c = Criteria { max_edge: 0.3, ..Criteria::PLANE_TEST };
        m.refine(&s, &curves, &c, 100_000);
        assert!(m.tris.len() > 4 * 32, "refinement split nothing: {} triangles", m.tris.len());
        assert_eq!(m.check_invariants(), Ok(()));
        m.rest();
        assert_eq!(m.check_invariants(), Ok(()));
        let (a, b) = m.boundary_edges()[0];
        m.shared.insert(key(a, b), ());
        assert!(m.split_edge_at(&s, &curves, a, b, 0.5, None, &mut Vec::new()).is_some());
        assert_eq!(m.check_invariants(), Ok(()));
        m.wake();
        assert_eq!(m.check_invariants(), Ok(()));
    }

    /// An edge of three triangles (sewing passed a loop through one node
    /// twice), which the edge table holds two of, keeps the tables through
    /// a split and refinement: a split of the two listed triangles left the
    /// third on an edge no table had, and the rim came out a border edge short.
    #[test]
    fn an_edge_of_three_triangles_keeps_the_tables() {
        let s = analytic::xy_plane(10.0);
        let (mut m, sides) = trimmed_grid();
        let curves: Vec<&NurbsCurve> = sides.iter().collect();
        let v = m.tris[0];
        m.add_vertex(DVec3::new(0.5, -1.0, 0.0), DVec3::Z);
        m.add_vertex(DVec3::new(0.5, -2.0, 0.0), DVec3::Z);
        let uv = [DVec2::new(1.0, 0.0), DVec2::new(0.0, 0.0), DVec2::new(0.5, -1.0)];
        m.add_triangle([v[1], v[0], 25], uv);
        m.add_triangle([v[1], v[0], 26], [uv[0], uv[1], DVec2::new(0.5, -2.0)]);
        assert!(matches!(m.check_invariants(), Err(Broken::NonManifold { .. })));
        assert_eq!(m.check_tables(), Ok(()));
        let mut out = Vec::new();
        let mid = m.split_edge_at(&s, &curves, v[0], v[1], 0.5, None, &mut out);
        assert_eq!(m.check_tables(), Ok(()), "after the split");
        assert!(mid.is_some(), "the edge was split");
        m.rest();
        assert_eq!(m.check_tables(), Ok(()), "at rest");
        let c = Criteria { max_edge: 0.3, ..Criteria::PLANE_TEST };
        m.refine(&s, &curves, &c, 100_000);
        assert_eq!(m.check_tables(), Ok(()), "after refinement");
        m.rest();
        assert_eq!(m.check_tables(), Ok(()), "refined, at rest");
        // The added triangles' sides are loose borders by construction; no
        // trim or shared edge may be stale.
        let stale = m.trim.keys().chain(m.shared.keys()).find(|e| m.edge_triangles(e.0, e.1) == 0);
        assert_eq!(stale, None, "refined, at rest");
    }

    /// Each invariant, broken on purpose, is the one reported.
    #[test]
    fn each_broken_invariant_is_named() {
        let (m, _) = trimmed_grid();
        let broken = |f: &dyn Fn(&mut WorkMesh)| {
            let mut m = trimmed_grid().0;
            f(&mut m);
            m.check_invariants().err()
        };
        assert_eq!(m.check_invariants(), Ok(()));
        assert!(matches!(broken(&|m| m.gid.push(NONE)), Some(Broken::VertexTables { .. })));
        assert!(matches!(
            broken(&|m| m.tris[3][1] = m.tris[3][0]),
            Some(Broken::NonManifold { .. } | Broken::Triangle { .. })
        ));
        assert!(matches!(broken(&|m| m.tris.swap(0, 1)), Some(Broken::EdgeTable { .. })));
        let clockwise = |m: &mut WorkMesh| {
            let w = m.uv(5);
            m.set_uv(5, [w[0], w[2], w[1]]);
        };
        assert!(matches!(broken(&clockwise), Some(Broken::Clockwise { t: 5, .. })));
        let plane = analytic::xy_plane(10.0);
        // Inner nodes' (u,v) is exact: turned, it breaks, though the
        // triangle faces the surface's way in space.
        let mut turned = trimmed_grid().0;
        clockwise(&mut turned);
        assert!(matches!(turned.check_invariants_on(&plane, Known::MENDED), Err(Broken::Clockwise { t: 5, .. })));
        // With a border node, whose (u,v) sewing leaves stale, it passes.
        let corner = turned.tris[5][0] as usize;
        turned.gid[corner] = 7;
        assert_eq!(turned.check_invariants_on(&plane, Known::NONE), Ok(()));
        assert!(matches!(turned.check_invariants(), Err(Broken::Clockwise { t: 5, .. })), "no surface to judge by");
        // Flat in (u,v), three corners on one line, facing the surface: passes.
        let mut flat = trimmed_grid().0;
        let w = flat.uv(5);
        flat.set_uv(5, [w[0], w[1], w[0] + (w[1] - w[0]) * 1.5]);
        assert!(matches!(flat.check_invariants(), Err(Broken::Clockwise { t: 5, .. })));
        assert_eq!(flat.check_invariants_on(&plane, Known::NONE), Ok(()));
        // Folded in space too: only where mending may leave it (reported).
        let mut folded = trimmed_grid().0;
        folded.tris[5].swap(1, 2);
        let r = folded.check_invariants_on(&plane, Known::SEWN);
        assert!(matches!(r, Err(Broken::Clockwise { t: 5, .. })), "{r:?}");
        assert_eq!(folded.check_invariants_on(&plane, Known::MENDED), Ok(()));
        let (a, b) = m.boundary_edges()[0];
        let loose = |m: &mut WorkMesh| {
            m.trim.remove(&key(a, b));
        };
        assert!(matches!(broken(&loose), Some(Broken::LooseBorder { .. })));
        let stale = |m: &mut WorkMesh| m.trim.insert(key(0, 24), TrimEdge { curve: 0, t_lo: 0.0, t_hi: 1.0 });
        assert!(matches!(broken(&stale), Some(Broken::StaleEdge { edge: (0, 24) })));
        let rested = |m: &mut WorkMesh| {
            m.rest();
            m.rim.0.pop();
        };
        assert!(matches!(broken(&rested), Some(Broken::RimCount { .. })));
        let mut pinched = trimmed_grid().0;
        let v = pinched.tris[0];
        pinched.add_vertex(DVec3::new(0.5, -1.0, 0.0), DVec3::Z);
        let uv = [DVec2::new(1.0, 0.0), DVec2::new(0.0, 0.0), DVec2::new(0.5, -1.0)];
        pinched.add_triangle([v[1], v[0], 25], uv);
        pinched.add_triangle([v[0], v[1], 25], [uv[1], uv[0], uv[2]]);
        assert!(matches!(pinched.check_invariants(), Err(Broken::NonManifold { .. })));
        assert_eq!(pinched.check_invariants_on(&plane, Known::MENDED), Ok(()), "stages that may leave both");
        assert_eq!(pinched.check_tables(), Ok(()), "an edge of three triangles is left to the full check");
    }
}
