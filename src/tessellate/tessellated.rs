//! Faces the file gives as triangles (STEP AP242 tessellated geometry):
//! their triangles pass to the mesh as they are, and where they meet exact
//! faces of their body the two are sewn.
//!
//! The file's triangles are fixed; the exact side can refine. So the exact
//! side takes the tessellated border's vertices: before its faces are
//! triangulated, every tessellated border vertex that lies on an exact
//! face's trim curve becomes a node of that curve's discretization
//! ([`pin_outlines`]), and once the exact faces are triangulated each
//! tessellated border vertex takes the exact border node nearest it, which
//! moves onto it ([`snap_borders`]; where no node is near, the exact border
//! edge is split there). Refinement then proves the exact side with those
//! nodes in place. Last ([`split_rims`]), every exact border node that
//! refinement added between two of them goes into the tessellated edge
//! there, whose triangle is cut into a fan: the tessellated vertices stay
//! where the file put them, and both sides end with one set of border
//! vertices, so welding leaves no crack.

use crate::collections::{CellGrid, HashMap};
use crate::numeric::guarded_div;
use alloc::vec::Vec;
use glam::DVec3;

use super::refine::WorkMesh;
use super::sew::FaceWork;
use crate::mesh::{FaceRange, Mesh};
use crate::model::{body_of, Model, TessellatedFace};
use crate::report::Report;
use crate::warning::{Warning, WarningKind};

const NONE: u32 = u32::MAX;

/// Border nodes walked along an exact face from one tessellated vertex to the next, at most.
const WALK: usize = 256;

/// The tessellated faces of the model being meshed, and those sewing cut.
pub(crate) struct Facets<'a> {
    faces: &'a [TessellatedFace],
    /// Per tessellated face: whether the share meshes it, and its body.
    mine: Vec<bool>,
    bodies: Vec<u32>,
    /// The faces sewing cut, by index: their meshes now.
    cut: HashMap<usize, FacetMesh>,
}

/// One tessellated face's mesh: points, normals (one per point, or none)
/// and triangles whose indices [`usable`] has checked.
#[derive(Debug, Clone)]
struct FacetMesh {
    pos: Vec<DVec3>,
    normals: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
}

/// The border of a body's tessellated faces: edges that one triangle of
/// them uses, their vertices as one point each where faces share it.
struct Rim {
    body: u32,
    /// The border vertices' places.
    points: Vec<DVec3>,
    /// Each border edge.
    edges: Vec<RimEdge>,
}

/// A rim edge: its two points (in the order its triangle runs them), face and triangle.
type RimEdge = (u32, u32, u32, u32);

/// Per tessellated triangle (face, triangle), the points to put into each of its edges.
type Cuts = Vec<((u32, u32), [Vec<DVec3>; 3])>;

/// Bit pattern of a point, to find equal points.
fn bits(p: DVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// Whether triangle `t` names three different points of `pos`, all finite:
/// the file reader checks its indices, a model built by hand may not.
fn usable(t: &[u32; 3], pos: &[DVec3]) -> bool {
    let ok = |v: u32| pos.get(v as usize).is_some_and(|p| p.is_finite());
    t[0] != t[1] && t[1] != t[2] && t[2] != t[0] && t.iter().all(|&v| ok(v))
}

impl<'a> Facets<'a> {
    /// The tessellated faces of `model`; `mine` (indexed by model face,
    /// empty: all) selects those meshed.
    pub fn new(model: &'a Model, mine: &[bool]) -> Self {
        let first = model.faces.len();
        let n = model.tessellated.len();
        Self {
            faces: &model.tessellated,
            mine: (0..n).map(|k| mine.get(first + k).copied().unwrap_or(true)).collect(),
            bodies: (0..n).map(|k| body_of(&model.bodies, first + k)).collect(),
            cut: HashMap::default(),
        }
    }

    /// Face `k`'s points, normals (one per point, or none) and triangles.
    fn parts(&self, k: usize) -> (&[DVec3], &[DVec3], &[[u32; 3]]) {
        match self.cut.get(&k) {
            Some(m) => (&m.pos, &m.normals, &m.tris),
            None => {
                let f = &self.faces[k];
                let normals = if f.normals.len() == f.positions.len() { &f.normals[..] } else { &[] };
                (&f.positions, normals, &f.triangles)
            }
        }
    }

    /// The rims of the bodies in `with` (the bodies of the exact faces:
    /// nothing else is sewn).
    fn rims(&self, with: &crate::collections::HashSet<u32>) -> Vec<Rim> {
        let mut by_body: HashMap<u32, Vec<usize>> = HashMap::default();
        for (k, &b) in self.bodies.iter().enumerate() {
            if self.mine[k] && with.contains(&b) {
                by_body.entry(b).or_default().push(k);
            }
        }
        let mut bodies: Vec<(u32, Vec<usize>)> = by_body.into_iter().collect();
        // Each body once, so its number alone orders them.
        crate::sort::by_u64(&mut bodies, |b| u64::from(b.0));
        bodies.into_iter().map(|(b, faces)| self.rim(b, &faces)).collect()
    }

    /// The rim of body `body`, whose tessellated faces are `faces`.
    fn rim(&self, body: u32, faces: &[usize]) -> Rim {
        let mut index: HashMap<[u64; 3], u32> = HashMap::default();
        let mut places: Vec<DVec3> = Vec::new();
        // Per edge (lower point first): its uses, and the last one's (points as run, face, triangle).
        let mut uses: HashMap<(u32, u32), (u32, RimEdge)> = HashMap::default();
        for &f in faces {
            let (pos, _, tris) = self.parts(f);
            let ids: Vec<u32> = pos
                .iter()
                .map(|&p| {
                    let next = places.len() as u32;
                    *index.entry(bits(p)).or_insert_with(|| {
                        places.push(p);
                        next
                    })
                })
                .collect();
            for (t, tri) in tris.iter().enumerate() {
                if !usable(tri, pos) {
                    continue;
                }
                for k in 0..3 {
                    let (a, b) = (ids[tri[k] as usize], ids[tri[(k + 1) % 3] as usize]);
                    if a == b {
                        continue;
                    }
                    let e = uses.entry((a.min(b), a.max(b))).or_insert((0, (a, b, f as u32, t as u32)));
                    e.0 += 1;
                    e.1 = (a, b, f as u32, t as u32);
                }
            }
        }
        let mut edges: Vec<RimEdge> = uses.into_values().filter(|u| u.0 == 1).map(|u| u.1).collect();
        crate::sort::by_u64(&mut edges, |e| crate::sort::pair(e.0, e.1));
        crate::sort::by_u64(&mut edges, |e| crate::sort::pair(e.2, e.3));
        // Only the border's points are kept, renumbered.
        let mut keep = alloc::vec![NONE; places.len()];
        let mut points = Vec::new();
        for e in &mut edges {
            for x in [&mut e.0, &mut e.1] {
                if keep[*x as usize] == NONE {
                    keep[*x as usize] = points.len() as u32;
                    points.push(places[*x as usize]);
                }
                *x = keep[*x as usize];
            }
        }
        Rim { body, points, edges }
    }

    /// The rims' points with their bodies, for [`pin_outlines`] (`with`: as for [`Facets::rims`]).
    #[cfg(feature = "std")]
    pub fn rim_points(&self, with: &crate::collections::HashSet<u32>) -> Vec<(u32, DVec3)> {
        self.rims(with).into_iter().flat_map(|r| r.points.into_iter().map(move |p| (r.body, p))).collect()
    }

    /// Appends every tessellated face's triangles to `mesh` (one face range
    /// each, empty for a face not meshed), with the file's normals or,
    /// where it gives none, the mean of the triangles' own around each
    /// vertex. Returns how many triangles were left out for bad indices or points.
    pub fn append_to(&self, mesh: &mut Mesh) -> usize {
        let mut dropped = 0;
        for k in 0..self.faces.len() {
            let first = mesh.triangle_count() as u32;
            if !self.mine[k] {
                mesh.face_ranges.push(FaceRange { first, count: 0 });
                continue;
            }
            let (pos, normals, tris) = self.parts(k);
            let kept: Vec<[u32; 3]> = tris.iter().copied().filter(|t| usable(t, pos)).collect();
            dropped += tris.len() - kept.len();
            let own;
            let normals = if normals.len() == pos.len() && normals.iter().all(|n| n.is_finite()) {
                normals
            } else {
                own = facet_normals(pos, &kept);
                &own[..]
            };
            // Vertices no triangle uses are left out.
            let mut index = alloc::vec![NONE; pos.len()];
            for t in &kept {
                for &v in t {
                    index[v as usize] = 0;
                }
            }
            let mut next = mesh.positions.len() as u32;
            for (v, slot) in index.iter_mut().enumerate() {
                if *slot == 0 {
                    *slot = next;
                    next += 1;
                    mesh.positions.push(pos[v]);
                    mesh.normals.push(normals[v]);
                }
            }
            for t in &kept {
                mesh.indices.extend(t.iter().map(|&v| index[v as usize]));
            }
            mesh.face_ranges.push(FaceRange { first, count: kept.len() as u32 });
        }
        dropped
    }

    /// Face `k`'s mesh, to be cut (copied from the model the first time).
    fn cut_mesh(&mut self, k: usize) -> Option<&mut FacetMesh> {
        if !self.cut.contains_key(&k) {
            let (pos, normals, tris) = self.parts(k);
            let m = FacetMesh { pos: pos.to_vec(), normals: normals.to_vec(), tris: tris.to_vec() };
            self.cut.insert(k, m);
        }
        self.cut.get_mut(&k)
    }
}

/// Unit normal per vertex: the area-weighted mean of its triangles' normals
/// (`+z` for a vertex whose triangles have no area).
fn facet_normals(pos: &[DVec3], tris: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sum = alloc::vec![DVec3::ZERO; pos.len()];
    for t in tris {
        let [a, b, c] = t.map(|v| pos[v as usize]);
        let n = (b - a).cross(c - a);
        for &v in t {
            sum[v as usize] += n;
        }
    }
    sum.into_iter().map(|n| n.try_normalize().unwrap_or(DVec3::Z)).collect()
}

/// The tessellated faces of `model` appended to `mesh` unsewn (quality
/// mode), and what the report says of them.
pub(crate) fn append_unsewn(model: &Model, mesh: &mut Mesh, report: &mut Report) {
    let dropped = Facets::new(model, &[]).append_to(mesh);
    finish_report(model, &[], mesh, dropped, report);
}

/// What the report says of the tessellated faces of `model` in `mine`
/// (empty: all) once `mesh` holds them: the face counts, the mesh's size,
/// and a warning that the deviation figures do not cover them (and one for
/// the `dropped` triangles, if any).
pub(crate) fn finish_report(model: &Model, mine: &[bool], mesh: &Mesh, dropped: usize, report: &mut Report) {
    let first = model.faces.len();
    let count = (0..model.tessellated.len()).filter(|&k| mine.get(first + k).copied().unwrap_or(true)).count();
    report.faces = model.face_count();
    report.faces_tessellated = count;
    report.triangles = mesh.triangle_count();
    report.vertices = mesh.positions.len();
    if count > 0 {
        let triangles: usize = mesh.face_ranges.get(first..).map_or(0, |r| r.iter().map(|r| r.count as usize).sum());
        report.warnings.push(Warning::new(WarningKind::TessellatedFaces { count, triangles }));
    }
    if dropped > 0 {
        report.warnings.push(Warning::new(WarningKind::TessellatedDropped { count: dropped }));
    }
}

/// The items of `grid` (cubes `reach` long) near the segment `pa`-`pb`:
/// those about points along it a reach apart (at most 4097 of them), each once.
fn near_segment(grid: &CellGrid<u32>, pa: DVec3, pb: DVec3, reach: f64) -> Vec<u32> {
    let steps = (crate::math::ceil(pa.distance(pb) / reach) as usize).clamp(1, 4096);
    let mut out: Vec<u32> = Vec::new();
    for j in 0..=steps {
        out.extend(grid.near(pa.lerp(pb, j as f64 / steps as f64)).copied());
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The bodies that hold exact faces with triangles.
fn exact_bodies(works: &[FaceWork<'_>], bodies: &[u32]) -> crate::collections::HashSet<u32> {
    (0..works.len()).filter(|&f| !works[f].mesh.tris.is_empty()).map(|f| body_of(bodies, f)).collect()
}

#[cfg(feature = "std")]
pub(crate) use pin::pin_outlines;

#[cfg(feature = "std")]
mod pin {
    use super::*;
    use crate::nurbs::Surface;
    use crate::tessellate::face::Outline;
    use crate::tessellate::sew::nearest_fraction;
    use crate::tessellate::trim::Polyline;

    /// Puts every tessellated border vertex (`rim`: body and place) that lies
    /// on an exact face's trim curve, within `reach` of it and farther than
    /// `reach` from the curve's nodes, into that face's outline as a node of
    /// the curve (at the curve's point nearest it), before the outlines are
    /// sewn and triangulated. `faces`: per exact face, its surface and outline.
    pub(crate) fn pin_outlines(
        faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>],
        bodies: &[u32],
        facets: &Facets<'_>,
        reach: f64,
    ) {
        if !(reach > 0.0 && reach.is_finite()) {
            return;
        }
        let with = (0..faces.len()).filter(|&f| faces[f].is_some()).map(|f| body_of(bodies, f)).collect();
        let rim = facets.rim_points(&with);
        if rim.is_empty() {
            return;
        }
        let mut grid = CellGrid::new(1.0 / reach);
        for (i, &(_, p)) in rim.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        for (fi, item) in faces.iter_mut().enumerate() {
            let Some((surface, o)) = item else { continue };
            let body = body_of(bodies, fi);
            for k in 0..o.loops.polys.len() {
                let poly = &o.loops.polys[k];
                let n = poly.uv.len();
                // Per segment: (fraction, curve parameter) of each node to add.
                let mut adds: Vec<Vec<(f64, f64)>> = alloc::vec![Vec::new(); n];
                let mut any = false;
                for i in 0..n {
                    let (curve, ta, tb) = poly.seg[i];
                    let Some(c) = o.loops.curves.get(curve as usize) else { continue };
                    let (pa, pb) = (surface.point(poly.uv[i]), surface.point(poly.uv[(i + 1) % n]));
                    let ab = pb - pa;
                    let on_curve = |s: f64| surface.point(c.point(ta + (tb - ta) * s).truncate());
                    for q in near_segment(&grid, pa, pb, reach) {
                        let (b, p) = rim[q as usize];
                        if b != body || p.distance(pa) <= reach || p.distance(pb) <= reach {
                            continue;
                        }
                        let s0 = (guarded_div((p - pa).dot(ab), ab.length_squared())).clamp(0.0, 1.0);
                        let (s, d) = nearest_fraction(&|s: f64| on_curve(s).distance(p), s0);
                        if d <= reach && s > 1e-9 && s < 1.0 - 1e-9 {
                            adds[i].push((s, ta + (tb - ta) * s));
                            any = true;
                        }
                    }
                }
                if !any {
                    continue;
                }
                let mut out = Polyline::default();
                for i in 0..n {
                    let (curve, ta, tb) = poly.seg[i];
                    out.uv.push(poly.uv[i]);
                    out.at.push(poly.at[i]);
                    let mut from = ta;
                    crate::sort::by_f64(&mut adds[i], |x| x.0);
                    let Some(c) = o.loops.curves.get(curve as usize) else {
                        out.seg.push((curve, from, tb));
                        continue;
                    };
                    let mut last: Option<DVec3> = None;
                    for &(_, t) in &adds[i] {
                        let uv = c.point(t).truncate();
                        let p = surface.point(uv);
                        // Two vertices within reach of each other would be one node: the first is kept.
                        if last.is_some_and(|l| l.distance(p) <= reach) {
                            continue;
                        }
                        last = Some(p);
                        out.push_on_curve(curve, &mut from, t, uv);
                    }
                    out.seg.push((curve, from, tb));
                }
                o.gids[k] = alloc::vec![NONE; out.uv.len()];
                o.loops.polys[k] = out;
            }
        }
    }
}

/// The exact faces' border vertices of each body: place, face, vertex, node id.
fn border_vertices(works: &[FaceWork<'_>], bodies: &[u32]) -> Vec<(u32, DVec3, u32, u32, u32)> {
    let mut out = Vec::new();
    for (fi, w) in works.iter().enumerate() {
        let body = body_of(bodies, fi);
        let mut vs: Vec<u32> = w.mesh.boundary_edges().into_iter().flat_map(|(a, b)| [a, b]).collect();
        vs.sort_unstable();
        vs.dedup();
        for v in vs {
            out.push((body, w.mesh.pos[v as usize], fi as u32, v, w.mesh.gid[v as usize]));
        }
    }
    out
}

/// Gives each tessellated border vertex the exact border node (of a face
/// of its body) nearest it within `reach`, each node to one vertex at most,
/// nearest pairs first: the node moves onto the vertex, in every face that
/// has it. A vertex no node is near but that lies within `reach` of an exact
/// border edge splits that edge there. Moved and split triangles are
/// measured again.
pub(crate) fn snap_borders(works: &mut [FaceWork<'_>], facets: &Facets<'_>, bodies: &[u32], reach: f64) {
    if works.is_empty() || !(reach > 0.0 && reach.is_finite()) {
        return;
    }
    let rims = facets.rims(&exact_bodies(works, bodies));
    if rims.iter().all(|r| r.points.is_empty()) {
        return;
    }
    let matched = snap(works, &rims, bodies, reach);
    // Vertices left alone: split the exact border edge they lie on.
    let mut lone: Vec<(u32, DVec3)> = Vec::new();
    for (r, m) in rims.iter().zip(&matched) {
        lone.extend(r.points.iter().zip(m).filter(|(_, &m)| !m).map(|(&p, _)| (r.body, p)));
    }
    if lone.is_empty() {
        return;
    }
    // Exact border edges shared by two faces are theirs, not this border.
    let mut pairs: HashMap<(u32, u32), u32> = HashMap::default();
    for w in works.iter() {
        for (a, b) in w.mesh.boundary_edges() {
            let (ga, gb) = (w.mesh.gid[a as usize], w.mesh.gid[b as usize]);
            if ga != NONE && gb != NONE {
                *pairs.entry((ga.min(gb), ga.max(gb))).or_default() += 1;
            }
        }
    }
    let mut grid = CellGrid::new(1.0 / reach);
    for (i, &(_, p)) in lone.iter().enumerate() {
        grid.insert(p, i as u32);
    }
    let mut taken = alloc::vec![false; lone.len()];
    for (fi, w) in works.iter_mut().enumerate() {
        let body = body_of(bodies, fi);
        let mut split = false;
        for (a, b) in w.mesh.boundary_edges() {
            let (ga, gb) = (w.mesh.gid[a as usize], w.mesh.gid[b as usize]);
            if ga != NONE && gb != NONE && pairs.get(&(ga.min(gb), ga.max(gb))).is_some_and(|&n| n > 1) {
                continue;
            }
            let (pa, pb) = (w.mesh.pos[a as usize], w.mesh.pos[b as usize]);
            let ab = pb - pa;
            // The vertices on this edge, in order along it.
            let mut on: Vec<(f64, u32)> = near_segment(&grid, pa, pb, reach)
                .into_iter()
                .filter(|&q| !taken[q as usize] && lone[q as usize].0 == body)
                .filter_map(|q| {
                    let p = lone[q as usize].1;
                    let s = guarded_div((p - pa).dot(ab), ab.length_squared());
                    let d = p.distance(pa + ab * s.clamp(0.0, 1.0));
                    (s > 0.0 && s < 1.0 && d <= reach).then_some((s, q))
                })
                .collect();
            crate::sort::by_f64(&mut on, |x| x.0);
            // Split from the far end back, so the edge from `a` keeps its name.
            let mut end = b;
            let mut changed = Vec::new();
            for &(_, q) in on.iter().rev() {
                let p = lone[q as usize].1;
                let (ps, pe) = (pa, w.mesh.pos[end as usize]);
                let frac = (guarded_div((p - ps).dot(pe - ps), ps.distance_squared(pe))).clamp(1e-6, 1.0 - 1e-6);
                let Some(m) = w.mesh.split_edge_at(w.surface, &w.curves, a, end, frac, Some(p), &mut changed) else {
                    continue;
                };
                w.mesh.pos[m as usize] = p;
                taken[q as usize] = true;
                end = m;
            }
            if !changed.is_empty() {
                w.mesh.forget(&changed);
                split = true;
            }
        }
        if split {
            w.mesh.rest();
        }
    }
}

/// The matching of [`snap_borders`]: per rim, per point, whether a node took it.
fn snap(works: &mut [FaceWork<'_>], rims: &[Rim], bodies: &[u32], reach: f64) -> Vec<Vec<bool>> {
    let verts = border_vertices(works, bodies);
    let mut grid = CellGrid::new(1.0 / reach);
    for (i, v) in verts.iter().enumerate() {
        grid.insert(v.1, i as u32);
    }
    // Candidate pairs: (distance, rim, point, border vertex).
    let mut pairs: Vec<(f64, u32, u32, u32)> = Vec::new();
    for (ri, r) in rims.iter().enumerate() {
        for (pi, &p) in r.points.iter().enumerate() {
            for &v in grid.near(p) {
                let (body, q, ..) = verts[v as usize];
                let d = p.distance(q);
                if body == r.body && d <= reach {
                    pairs.push((d, ri as u32, pi as u32, v));
                }
            }
        }
    }
    // Stable passes, last key first: by (distance, rim, point, vertex).
    crate::sort::by_u64(&mut pairs, |x| u64::from(x.3));
    crate::sort::by_u64(&mut pairs, |x| crate::sort::pair(x.1, x.2));
    crate::sort::by_f64(&mut pairs, |x| x.0);
    // A node is its id where it has one (all its faces' vertices), else its vertex.
    let node = |v: u32| {
        let (_, _, f, x, g) = verts[v as usize];
        if g != NONE {
            (NONE, g)
        } else {
            (f, x)
        }
    };
    let mut holders: HashMap<u32, Vec<(u32, u32)>> = HashMap::default();
    for &(_, _, f, x, g) in &verts {
        if g != NONE {
            holders.entry(g).or_default().push((f, x));
        }
    }
    let mut matched: Vec<Vec<bool>> = rims.iter().map(|r| alloc::vec![false; r.points.len()]).collect();
    let mut used: crate::collections::HashSet<(u32, u32)> = crate::collections::HashSet::default();
    let mut moved: Vec<Vec<u32>> = alloc::vec![Vec::new(); works.len()];
    for (_, ri, pi, v) in pairs {
        let n = node(v);
        if matched[ri as usize][pi as usize] || used.contains(&n) {
            continue;
        }
        matched[ri as usize][pi as usize] = true;
        used.insert(n);
        let p = rims[ri as usize].points[pi as usize];
        let all: Vec<(u32, u32)> =
            if n.0 == NONE { holders.get(&n.1).cloned().unwrap_or_default() } else { alloc::vec![n] };
        for (f, x) in all {
            let w = &mut works[f as usize];
            if w.mesh.pos[x as usize] != p {
                w.mesh.pos[x as usize] = p;
                moved[f as usize].push(x);
            }
        }
    }
    for (w, vs) in works.iter_mut().zip(moved) {
        if vs.is_empty() {
            continue;
        }
        let vs: crate::collections::HashSet<u32> = vs.into_iter().collect();
        let ts: Vec<u32> =
            (0..w.mesh.tris.len() as u32).filter(|&t| w.mesh.tris[t as usize].iter().any(|v| vs.contains(v))).collect();
        w.mesh.forget(&ts);
    }
    matched
}

/// Puts into every tessellated border edge the exact border nodes that lie
/// along it, so both sides have the same vertices there: first each
/// tessellated border vertex takes its nearest exact node again (as
/// [`snap_borders`]; refinement may have left one apart), then, for each
/// tessellated border edge whose two ends an exact face's border has, that
/// face's border nodes between them (a walk along its border); where no
/// face has both ends, the exact border nodes within `reach` of the edge.
/// The edge's triangle becomes a fan over them; the file's vertices stay.
pub(crate) fn split_rims(works: &mut [FaceWork<'_>], facets: &mut Facets<'_>, bodies: &[u32], reach: f64) {
    if works.is_empty() || !(reach > 0.0 && reach.is_finite()) {
        return;
    }
    let rims = facets.rims(&exact_bodies(works, bodies));
    if rims.iter().all(|r| r.points.is_empty()) {
        return;
    }
    snap(works, &rims, bodies, reach);
    let verts = border_vertices(works, bodies);
    // Exact border vertices by place, and each face's border neighbours.
    let mut at: HashMap<[u64; 3], Vec<u32>> = HashMap::default();
    let mut grid = CellGrid::new(1.0 / reach);
    for (i, v) in verts.iter().enumerate() {
        at.entry(bits(v.1)).or_default().push(i as u32);
        grid.insert(v.1, i as u32);
    }
    let mut around: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
    for (fi, w) in works.iter().enumerate() {
        for (a, b) in w.mesh.boundary_edges() {
            around.entry((fi as u32, a)).or_default().push(b);
            around.entry((fi as u32, b)).or_default().push(a);
        }
    }
    // Per tessellated face, per triangle: the points to put into each of its edges.
    let mut cuts: HashMap<(u32, u32), [Vec<DVec3>; 3]> = HashMap::default();
    for r in &rims {
        let is_rim: crate::collections::HashSet<[u64; 3]> = r.points.iter().map(|&p| bits(p)).collect();
        for &(a, b, f, t) in &r.edges {
            let (pa, pb) = (r.points[a as usize], r.points[b as usize]);
            let mut pts = walked(works, &verts, &at, &around, &is_rim, r.body, pa, pb);
            if pts.is_none() {
                let ab = pb - pa;
                let found: Vec<DVec3> = near_segment(&grid, pa, pb, reach)
                    .into_iter()
                    .map(|v| verts[v as usize])
                    .filter(|v| v.0 == r.body && !is_rim.contains(&bits(v.1)))
                    .filter(|v| {
                        let s = guarded_div((v.1 - pa).dot(ab), ab.length_squared());
                        s > 1e-9 && s < 1.0 - 1e-9 && v.1.distance(pa + ab * s) <= reach
                    })
                    .map(|v| v.1)
                    .collect();
                pts = Some(found);
            }
            let Some(mut pts) = pts.filter(|p| !p.is_empty()) else { continue };
            let ab = pb - pa;
            crate::sort::by_f64(&mut pts, |x| (*x - pa).dot(ab));
            pts.dedup_by(|x, y| bits(*x) == bits(*y));
            let (pos, _, tris) = facets.parts(f as usize);
            let Some(tri) = tris.get(t as usize) else { continue };
            // Which edge of the triangle runs from `a` to `b`.
            let Some(k) = (0..3).find(|&k| pos[tri[k] as usize] == pa && pos[tri[(k + 1) % 3] as usize] == pb) else {
                continue;
            };
            cuts.entry((f, t)).or_insert_with(Default::default)[k] = pts;
        }
    }
    let mut cuts: Cuts = cuts.into_iter().collect();
    crate::sort::by_u64(&mut cuts, |c| crate::sort::pair(c.0 .0, c.0 .1));
    for ((f, t), pts) in cuts {
        if let Some(m) = facets.cut_mesh(f as usize) {
            m.cut(t as usize, &pts);
        }
    }
}

/// The exact border nodes between `pa` and `pb` along the border of a face
/// of `body` that has both as nodes, in order; `None` when no face has
/// both within [`WALK`] nodes of each other along a path about as long as
/// the chord (a border that leaves the edge and comes back is not along it).
#[allow(clippy::too_many_arguments)]
fn walked(
    works: &[FaceWork<'_>],
    verts: &[(u32, DVec3, u32, u32, u32)],
    at: &HashMap<[u64; 3], Vec<u32>>,
    around: &HashMap<(u32, u32), Vec<u32>>,
    is_rim: &crate::collections::HashSet<[u64; 3]>,
    body: u32,
    pa: DVec3,
    pb: DVec3,
) -> Option<Vec<DVec3>> {
    let (from, to) = (at.get(&bits(pa))?, at.get(&bits(pb))?);
    let chord = pa.distance(pb);
    let mut best: Option<(f64, Vec<DVec3>)> = None;
    for &i in from {
        let (b, _, f, va, _) = verts[i as usize];
        if b != body {
            continue;
        }
        let Some(&vb) = to.iter().map(|&j| &verts[j as usize]).find(|v| v.2 == f).map(|v| &v.3) else { continue };
        let mesh: &WorkMesh = &works[f as usize].mesh;
        for &first in around.get(&(f, va)).map_or(&[][..], |v| &v[..]) {
            let (mut prev, mut cur) = (va, first);
            let mut path = Vec::new();
            let mut length = mesh.pos[va as usize].distance(mesh.pos[first as usize]);
            let mut ok = false;
            for _ in 0..WALK {
                if cur == vb {
                    ok = true;
                    break;
                }
                let p = mesh.pos[cur as usize];
                if is_rim.contains(&bits(p)) || length > 2.0 * chord {
                    break;
                }
                path.push(p);
                let Some(nb) = around.get(&(f, cur)).filter(|n| n.len() == 2) else { break };
                let next = if nb[0] == prev { nb[1] } else { nb[0] };
                length += p.distance(mesh.pos[next as usize]);
                (prev, cur) = (cur, next);
            }
            if ok && best.as_ref().is_none_or(|b| length < b.0) {
                best = Some((length, path));
            }
        }
    }
    best.map(|b| b.1)
}

impl FacetMesh {
    /// Cuts triangle `t` at `pts[k]`, points along its edge `k` (from corner
    /// `k` to corner `k + 1`, in order): a fan from the opposite corner when
    /// one edge has points, else from the triangle's centre.
    fn cut(&mut self, t: usize, pts: &[Vec<DVec3>; 3]) {
        let Some(&tri) = self.tris.get(t) else { return };
        let with_normals = self.normals.len() == self.pos.len();
        // The polygon: each corner, then the points of the edge it starts.
        let mut ring: Vec<u32> = Vec::new();
        for k in 0..3 {
            ring.push(tri[k]);
            let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
            for &p in &pts[k] {
                let v = self.pos.len() as u32;
                self.pos.push(p);
                if with_normals {
                    let (pa, pb) = (self.pos[a], self.pos[b]);
                    let s = (guarded_div((p - pa).dot(pb - pa), pa.distance_squared(pb))).clamp(0.0, 1.0);
                    let n = self.normals[a].lerp(self.normals[b], s).try_normalize().unwrap_or(self.normals[a]);
                    self.normals.push(n);
                }
                ring.push(v);
            }
        }
        let cut_edges: Vec<usize> = (0..3).filter(|&k| !pts[k].is_empty()).collect();
        let mut out: Vec<[u32; 3]> = Vec::new();
        if let [k] = cut_edges[..] {
            // Fan from the corner opposite edge k: the ring starts after it.
            let apex = tri[(k + 2) % 3];
            let start = ring.iter().position(|&v| v == apex).unwrap_or(0);
            let n = ring.len();
            for i in 1..n - 1 {
                out.push([apex, ring[(start + i) % n], ring[(start + i + 1) % n]]);
            }
        } else {
            let c = self.pos.len() as u32;
            let [p0, p1, p2] = tri.map(|v| self.pos[v as usize]);
            self.pos.push((p0 + p1 + p2) / 3.0);
            if with_normals {
                let n = tri.iter().map(|&v| self.normals[v as usize]).sum::<DVec3>();
                self.normals.push(n.try_normalize().unwrap_or(self.normals[tri[0] as usize]));
            }
            let n = ring.len();
            for i in 0..n {
                out.push([c, ring[i], ring[(i + 1) % n]]);
            }
        }
        let mut out = out.into_iter();
        if let Some(first) = out.next() {
            self.tris[t] = first;
            self.tris.extend(out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_face(tris: Vec<[u32; 3]>, pos: Vec<DVec3>) -> Model {
        let f = TessellatedFace { name: None, positions: pos, normals: Vec::new(), triangles: tris };
        Model { tessellated: alloc::vec![f], ..Model::default() }
    }

    /// Two triangles sharing an edge: the rim is the square's four sides, run as the triangles run them.
    #[test]
    fn the_rim_is_the_edges_one_triangle_uses() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let m = one_face(
            alloc::vec![[0, 1, 2], [0, 2, 3]],
            alloc::vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
        );
        let f = Facets::new(&m, &[true]);
        let r = f.rim(0, &[0]);
        assert_eq!(r.points.len(), 4);
        let mut sides: Vec<(DVec3, DVec3)> =
            r.edges.iter().map(|e| (r.points[e.0 as usize], r.points[e.1 as usize])).collect();
        sides.sort_by(|x, y| x.0.x.total_cmp(&y.0.x).then(x.0.y.total_cmp(&y.0.y)));
        assert_eq!(
            sides,
            [
                (p(0.0, 0.0), p(1.0, 0.0)),
                (p(0.0, 1.0), p(0.0, 0.0)),
                (p(1.0, 0.0), p(1.0, 1.0)),
                (p(1.0, 1.0), p(0.0, 1.0))
            ]
        );
    }

    /// A triangle cut at two points of one edge becomes a fan of three from
    /// the opposite corner, all facing the way it did; cut on two edges, a
    /// fan of five around its centre.
    #[test]
    fn a_cut_triangle_keeps_its_area_and_side() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let area = |m: &FacetMesh| -> f64 {
            m.tris
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| m.pos[v as usize]);
                    (b - a).cross(c - a).z / 2.0
                })
                .sum()
        };
        let fresh = || FacetMesh {
            pos: alloc::vec![p(0.0, 0.0), p(3.0, 0.0), p(0.0, 3.0)],
            normals: Vec::new(),
            tris: alloc::vec![[0, 1, 2]],
        };
        let mut m = fresh();
        m.cut(0, &[alloc::vec![p(1.0, 0.0), p(2.0, 0.0)], Vec::new(), Vec::new()]);
        assert_eq!(m.tris.len(), 3);
        assert!(m.tris.iter().all(|t| t.contains(&2)));
        assert!((area(&m) - 4.5).abs() < 1e-12);
        let mut m = fresh();
        m.cut(0, &[alloc::vec![p(1.5, 0.0)], alloc::vec![p(1.5, 1.5)], Vec::new()]);
        assert_eq!(m.tris.len(), 5);
        assert!((area(&m) - 4.5).abs() < 1e-12);
        assert!(m.tris.iter().all(|t| {
            let [a, b, c] = t.map(|v| m.pos[v as usize]);
            (b - a).cross(c - a).z > 0.0
        }));
    }
}
