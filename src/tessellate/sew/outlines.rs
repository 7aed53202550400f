//! Sewing of face outlines before they are triangulated.

use crate::collections::{CellGrid, HashMap};
use crate::numeric::{guarded_div, TINY};
use alloc::vec::Vec;
use glam::DVec3;

use super::inside::Inside;
use super::nearest_fraction;
use crate::nurbs::Surface;
use crate::tessellate::face::Outline;
use crate::tessellate::trim::Polyline;

/// Marks a candidate beyond the other border's segment, at its end.
const BEYOND: f64 = -2.0;
/// Nodes a pair of faces needs before its own gaps set its sewing distance.
const PAIR_MIN: usize = 3;
/// Share of `tight` below which a face's two sides are one however other
/// faces lie along them: a gap of the model's, as the sewing closes gaps
/// below an eighth of its distance whatever the rest of the model needs.
const GAP: f64 = 0.125;
/// Least |cos| between a node pair's offset and both nodes' surface
/// normals for the two to be layers of a wall (see [`Clusters::layers`]).
const LAYER_COS: f64 = 0.9;

/// A node of some face's outline: face, loop, index.
pub(super) type NodeRef = (u32, u32, u32);

/// Per face, per loop, per node.
pub(super) type PerNode<T> = Vec<Vec<Vec<T>>>;

/// Per segment, the nodes to add to it: (fraction, curve parameter, the node it stands for).
type Additions = PerNode<Vec<(f64, f64, NodeRef)>>;

/// Makes the outlines of all faces agree and names their nodes.
///
/// Nodes first slide along their curves onto nearby nodes of other faces
/// ([`super::slide::slide_nodes`]).
///
/// Each node has a reach: `sew`, but at most 0.3 of its shortest loop
/// segment (so two nodes of one segment are never one). A node of one
/// outline that lies on another outline's exact border within its reach,
/// where the two run side by side and no more than four times as far as
/// the nearest other face's border, is added to that border at its own
/// curve's nearest point (unless it is within reach of a node there
/// already, or a narrow face lies between: [`super::across::across_faces`]).
/// Then nodes within both reaches of each other get one id in
/// [`Outline::gids`] (never a strip's two sides where other faces run
/// along both: [`folds_across`]), and a node left alone one short segment from a
/// shared node takes its id (a trim curve shorter than the gaps). Within
/// one face (a seam) `tight` takes the place of `sew`: a face's loops meet
/// themselves exactly, and a face narrower than `sew` must not be folded
/// shut. A node or segment that its face lies all around (a seam's:
/// [`Inside`]) takes no other face's node, nor goes into another's border.
/// Returns the ids given.
///
/// `reach`: how far a node may lie from the other border's chord
/// (chordal tolerance plus `sew`). `moved`: per face, how far its border
/// may lie from where the model put it (a rebuilt face's fit error, paper
/// 001; zero for the others, and missing entries are zero).
pub(crate) fn unify(
    faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    moved: &[f64],
    sew: f64,
    tight: f64,
    reach: f64,
) -> u32 {
    let tight = tight.min(sew).max(0.0);
    let sew = if sew.is_finite() { sew.max(0.0) } else { 0.0 };
    let pos = positions(faces);
    let inside = Inside::new(faces, &pos, tight);
    let pos = super::slide::slide_nodes(faces, pos, &inside, bodies, moved, sew);
    let (mut total, mut count) = (0.0, 0usize);
    for p in pos.iter().flatten() {
        for i in 0..p.len() {
            total += p[i].distance(p[(i + 1) % p.len()]);
            count += 1;
        }
    }
    if count == 0 {
        return 0;
    }
    let mut twins: Vec<(NodeRef, NodeRef)> = Vec::new();
    let (mut sew_used, mut radius) = (tight, None);
    if sew > 0.0 && reach.is_finite() {
        let (adds, r, used) = insertions(faces, bodies, moved, &pos, &inside, sew, tight, reach, total / count as f64);
        (sew_used, radius) = (used, Some(r));
        twins = insert(faces, &adds);
    }
    let radius = radius.unwrap_or_else(|| radii(&pos, tight, tight));
    name_nodes(faces, bodies, &radius, &twins, sew_used, tight)
}

/// Each outline node's point on its face's surface.
pub(super) fn positions(faces: &[Option<(&dyn Surface, &mut Outline<'_>)>]) -> PerNode<DVec3> {
    faces
        .iter()
        .map(|item| {
            item.as_ref().map_or_else(Vec::new, |(s, o)| {
                o.loops.polys.iter().map(|p| p.uv.iter().map(|&q| s.point(q)).collect()).collect()
            })
        })
        .collect()
}

/// One `fill` per node of `pos`.
fn per_node<T: Clone>(pos: &PerNode<DVec3>, fill: T) -> PerNode<T> {
    pos.iter().map(|f| f.iter().map(|p| alloc::vec![fill.clone(); p.len()]).collect()).collect()
}

/// Each node's reach: `sew`, at most 0.3 of its shortest loop segment.
/// Segments along a pole, and those shorter than a thousandth of `tight`
/// (a trim edge far below any weld: its ends are one point), do not count.
fn radii(pos: &PerNode<DVec3>, sew: f64, tight: f64) -> PerNode<f64> {
    radii_each(pos, &|_| sew, tight)
}

/// [`radii`] with each node's own sewing distance.
fn radii_each(pos: &PerNode<DVec3>, sew_of: &dyn Fn(NodeRef) -> f64, tight: f64) -> PerNode<f64> {
    pos.iter()
        .enumerate()
        .map(|(fi, f)| {
            f.iter()
                .enumerate()
                .map(|(k, p)| {
                    let n = p.len();
                    let scale = p.iter().fold(0.0f64, |m, q| m.max(q.abs().max_element())).max(TINY);
                    let length = |i: usize| {
                        let l = p[i].distance(p[(i + 1) % n]);
                        if l <= (1e-12 * scale).max(1e-3 * tight) {
                            f64::INFINITY
                        } else {
                            l
                        }
                    };
                    (0..n)
                        .map(|i| {
                            let sew = sew_of((fi as u32, k as u32, i as u32));
                            sew.min(0.3 * length(i).min(length((i + n - 1) % n))).max(1e-12 * scale)
                        })
                        .collect()
                })
                .collect()
        })
        .collect()
}

/// A node on another border's segment, to be added there: (segment,
/// fraction, curve parameter, distance, node).
pub(super) type Candidate = (NodeRef, f64, f64, f64, NodeRef);

/// How near the borders of other faces run to each node, as the search
/// for candidates saw them: the gaps that set the sewing distances, and
/// the nearest border an addition must not pass over.
struct Nearness {
    /// Per node, its distance to the nearest segment of another face it
    /// lies beside (NaN: none seen).
    nearest: PerNode<f64>,
    /// Per node, the nearest other face seen, beyond a segment's end too,
    /// and its distance (NaN: none seen).
    nearest_face: PerNode<(u32, f64)>,
    /// Per node and face, the node's distance to that face's nearest segment.
    nearest_in: HashMap<(NodeRef, u32), f64>,
}

impl Nearness {
    fn new(pos: &PerNode<DVec3>) -> Self {
        Self {
            nearest: per_node(pos, f64::NAN),
            nearest_face: per_node(pos, (super::NONE, f64::NAN)),
            nearest_in: HashMap::default(),
        }
    }

    /// Notes node `q` at distance `d` from segment `seg`, at fraction `s`
    /// of it (`BEYOND`: past an end, which counts for the nearest face only).
    fn note(&mut self, seg: NodeRef, s: f64, d: f64, q: NodeRef) {
        let (a, b, c) = (q.0 as usize, q.1 as usize, q.2 as usize);
        if seg.0 != q.0 {
            let e = &mut self.nearest_face[a][b][c];
            if e.1.is_nan() {
                *e = (super::NONE, f64::INFINITY);
            }
            if d < e.1 {
                *e = (seg.0, d);
            }
        }
        if s == BEYOND {
            return;
        }
        if seg.0 != q.0 {
            let e = &mut self.nearest[a][b][c];
            *e = if e.is_nan() { f64::INFINITY } else { *e }.min(d);
        }
        let e = self.nearest_in.entry((q, seg.0)).or_insert(f64::INFINITY);
        *e = e.min(d);
    }
}

/// How far face `f`'s border was moved (a rebuilt face's fit error; zero
/// for the others and for a missing or non-finite entry).
fn moved_by(moved: &[f64], f: u32) -> f64 {
    moved.get(f as usize).copied().filter(|m| m.is_finite()).unwrap_or(0.0).max(0.0)
}

/// Per segment, the nodes of other borders to add to it: (fraction,
/// curve parameter, the node it stands for), in order along it; and the
/// sewing distance used.
///
/// The distance is what the model's gaps need, not `sew` blindly: four
/// times the 90th percentile of the distances from border nodes to the
/// nearest border of another face beside them, between `tight` and
/// `sew`. A file whose faces meet exactly is sewn tightly, so a face
/// pinched narrower than `sew` is not sewn across its neck; a patchwork
/// with gaps gets the distance its gaps take. Gaps below an eighth of
/// `sew` are always sewn, also where most of the model meets exactly:
/// each side moves by half the gap, by default a fortieth of the tolerance.
/// Two faces side by side with gaps of their own (a panel cut in a model
/// that otherwise meets exactly) take four times the 90th percentile of
/// theirs, counted at the nodes whose nearest other face is the other one
/// and apart from it (a node both borders have is no gap, and one beside
/// a thin face between them is nearer that face). A face whose border was
/// moved (`moved`: a rebuilt face, paper 001) widens by that much the
/// distance of every pair it is in, up to `sew`: the model's gaps were
/// measured where the border was. Returns the additions, each node's
/// reach, and the largest sewing distance used.
#[allow(clippy::too_many_arguments)]
fn insertions(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    moved: &[f64],
    pos: &PerNode<DVec3>,
    inside: &Inside,
    sew: f64,
    tight: f64,
    reach: f64,
    mean_segment: f64,
) -> (Additions, PerNode<f64>, f64) {
    let radius = radii(pos, sew, tight);
    // Nodes hashed on a grid about one loop segment long.
    let mut grid = CellGrid::new(guarded_div(1.0, mean_segment.max(reach)));
    for (fi, f) in pos.iter().enumerate() {
        for (k, p) in f.iter().enumerate() {
            for (i, &q) in p.iter().enumerate() {
                grid.insert(q, (fi as u32, k as u32, i as u32));
            }
        }
    }
    let (cands, mut near) = candidates(faces, bodies, pos, inside, &grid, &radius, tight, reach);
    // The nearest faces only set the distances: dropped before the
    // additions are made, where the mesh phase of a large assembly peaked.
    let nearest_face = core::mem::take(&mut near.nearest_face);
    let (radius, sew) = sewing_distances(pos, &near.nearest, nearest_face, moved, sew, tight);
    // A node beyond a face narrower than the sewing distance stays off the
    // border on that face's other side (a strip keeps both its sides).
    let r_of = |n: NodeRef| radius[n.0 as usize][n.1 as usize][n.2 as usize];
    let limit = |c: &Candidate| if c.0 .0 == c.4 .0 { tight.min(r_of(c.4)) } else { r_of(c.4) };
    let across =
        super::across::across_faces(faces, bodies, pos, &grid, &cands, &limit, &r_of, mean_segment.max(reach), tight);
    let cands = cands.into_iter().zip(across).filter_map(|(c, x)| (!x).then_some(c)).collect();
    let adds = additions(pos, &grid, cands, &near, &radius, moved, tight);
    (adds, radius, sew)
}

/// Every node within `reach` of another outline's segment, where that
/// outline runs along the node's own (not merely past it), at the nearest
/// point of the segment's curve; and the distances seen on the way
/// ([`Nearness`]), ends of segments included.
///
/// A node goes only onto borders about as near as the nearest other
/// face's: a face thinner than `sew` keeps its far border to itself. Of
/// one face's borders it goes onto the nearest only (and onto another as
/// near within `tight`, the other side of a seam): a face pinched narrower
/// than `sew` is not sewn across its neck. Those tests need the distances
/// noted here, so a pair that can only tell a distance is not kept (on a
/// plate of 1000 holes those were most of 12 MB of pairs).
#[allow(clippy::too_many_arguments)]
fn candidates(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    pos: &PerNode<DVec3>,
    inside: &Inside,
    grid: &CellGrid<NodeRef>,
    radius: &PerNode<f64>,
    tight: f64,
    reach: f64,
) -> (Vec<Candidate>, Nearness) {
    let at = |n: NodeRef| pos[n.0 as usize][n.1 as usize][n.2 as usize];
    let body = |f: usize| crate::model::body_of(bodies, f);
    let r_of = |n: NodeRef| radius[n.0 as usize][n.1 as usize][n.2 as usize];
    let mut near = Nearness::new(pos);
    let mut cands: Vec<Candidate> = Vec::new();
    for (fi, item) in faces.iter().enumerate() {
        let Some((surface, o)) = item else { continue };
        // Speed bounds, taken when a search is first about to run.
        let mut surface_speed: Option<Option<[f64; 2]>> = None;
        let mut curve_speed: Vec<Option<Option<DVec3>>> = alloc::vec![None; o.loops.curves.len()];
        for (k, poly) in o.loops.polys.iter().enumerate() {
            let n = poly.uv.len();
            for i in 0..n {
                let j = (i + 1) % n;
                let (na, nb) = ((fi as u32, k as u32, i as u32), (fi as u32, k as u32, j as u32));
                let (pa, pb) = (at(na), at(nb));
                let ab = pb - pa;
                let dir = ab.normalize_or_zero();
                let (curve, ta, tb) = poly.seg[i];
                let Some(c) = o.loops.curves.get(curve as usize) else { continue };
                let on_curve = |s: f64| surface.point(c.point(ta + (tb - ta) * s).truncate());
                let mut piece: Option<Option<Piece>> = None;
                // Only nodes within `reach` of the segment pass the tests below.
                for &qn in grid.near_segment(pa, pb, reach) {
                    let (g, kk, jj) = (qn.0 as usize, qn.1 as usize, qn.2 as usize);
                    if qn == na || qn == nb || body(g) != body(fi) {
                        continue;
                    }
                    // No other face meets a face inside it (a seam's inner node or segment).
                    if g != fi && (inside.at(qn) || inside.along(na)) {
                        continue;
                    }
                    let q = at(qn);
                    let limit = if g == fi { tight.min(r_of(qn)) } else { r_of(qn) };
                    let s0 = (guarded_div((q - pa).dot(ab), ab.length_squared())).clamp(0.0, 1.0);
                    if s0 <= 0.0 || s0 >= 1.0 {
                        // Beyond an end, at most as far as the end: a
                        // node the other border has too (a gap of nothing).
                        let e = q.distance(pa).min(q.distance(pb));
                        if e <= limit {
                            near.note(na, BEYOND, e, qn);
                        }
                        continue;
                    }
                    if q.distance(pa + ab * s0) > reach {
                        continue;
                    }
                    // The other border must run along this
                    // one at q, not merely pass near it.
                    let m = pos[g][kk].len();
                    let parallel = [(jj + m - 1) % m, (jj + 1) % m]
                        .iter()
                        .any(|&nb| (pos[g][kk][nb] - q).normalize_or_zero().dot(dir).abs() >= 0.8);
                    if !parallel {
                        continue;
                    }
                    // A node on an end of the segment, to a billionth of
                    // its length, is that end: the search below (about 40
                    // curve and surface evaluations) would only tell it
                    // from the end by rounding, a fraction under its 1e-9.
                    // Most nodes are such ends: the other face's copy of
                    // this border's node.
                    let at_end = q.distance(pa).min(q.distance(pb)) <= 1e-9 * ab.length();
                    let piece = piece.get_or_insert_with(|| {
                        let speed = *surface_speed.get_or_insert_with(|| surface.derivative_bounds());
                        let along = *curve_speed[curve as usize].get_or_insert_with(|| c.derivative_bound());
                        Piece::new(&on_curve, (tb - ta).abs(), speed, along)
                    });
                    // The search's distance is one of the piece's: where all
                    // of them exceed the limit, its result would be rejected.
                    let (s, d) = if at_end || piece.as_ref().is_some_and(|p| p.beyond(q, limit)) {
                        (0.0, f64::INFINITY)
                    } else {
                        nearest_fraction(&|s: f64| on_curve(s).distance(q), s0)
                    };
                    if d <= limit && s > 1e-9 && s < 1.0 - 1e-9 {
                        near.note(na, s, d, qn);
                        cands.push((na, s, ta + (tb - ta) * s, d, qn));
                    } else if q.distance(pa).min(q.distance(pb)) <= limit {
                        // At an end: noted for the gap estimate only.
                        near.note(na, -1.0, q.distance(pa).min(q.distance(pb)), qn);
                    }
                }
            }
        }
    }
    (cands, near)
}

/// A segment's curve piece (`on_curve` over `[0, 1]`): the chord between
/// its ends and how far the piece may stray from that chord, from a bound
/// of its length (the curve's and the surface's speed bounds over the
/// parameter span): a curve of length `l` between points `c` apart lies
/// within `sqrt(l² - c²) / 2` of the chord joining them.
struct Piece {
    a: DVec3,
    b: DVec3,
    stray: f64,
    /// Room for rounding in the evaluations and in the bound.
    margin: f64,
}

impl Piece {
    /// `None` where a speed bound is unknown (an offset surface, a bad weight).
    fn new(
        on_curve: &dyn Fn(f64) -> DVec3,
        span: f64,
        surface: Option<[f64; 2]>,
        curve: Option<DVec3>,
    ) -> Option<Self> {
        let ([su, sv], c) = (surface?, curve?);
        let length = span * (su * c.x.abs() + sv * c.y.abs());
        let (a, b) = (on_curve(0.0), on_curve(1.0));
        let chord = a.distance(b);
        let stray = 0.5 * (length * length - chord * chord).max(0.0).sqrt();
        let margin = 1e-9 * (a.abs().max_element() + b.abs().max_element() + length + chord);
        (stray.is_finite() && margin.is_finite()).then_some(Self { a, b, stray, margin })
    }

    /// Whether every point of the piece lies farther than `limit` from `q`.
    fn beyond(&self, q: DVec3, limit: f64) -> bool {
        let ab = self.b - self.a;
        let t = guarded_div((q - self.a).dot(ab), ab.length_squared()).clamp(0.0, 1.0);
        let to_chord = q.distance(self.a + ab * t);
        to_chord - self.stray > limit + self.margin + 1e-9 * q.abs().max_element()
    }
}

/// Each node's reach from the sewing distances the gaps ask for (see
/// [`insertions`]): the model's, and each pair of faces' side by side
/// (counted at the nodes whose nearest other face is the other); and the
/// largest distance used.
fn sewing_distances(
    pos: &PerNode<DVec3>,
    nearest: &PerNode<f64>,
    nearest_face: PerNode<(u32, f64)>,
    moved: &[f64],
    sew: f64,
    tight: f64,
) -> (PerNode<f64>, f64) {
    let q90 = |gaps: &mut Vec<f64>| {
        crate::sort::f64s(gaps);
        gaps.get((gaps.len() * 9) / 10).copied().unwrap_or(0.0)
    };
    let mut gaps: Vec<f64> = nearest.iter().flatten().flatten().copied().filter(|d| !d.is_nan()).collect();
    // Each node whose nearest other face is known, with that face and distance.
    let seen_face = || {
        nearest_face.iter().enumerate().flat_map(|(a, f)| {
            f.iter().enumerate().flat_map(move |(b, l)| {
                l.iter()
                    .enumerate()
                    .filter(|(_, e)| !e.1.is_nan())
                    .map(move |(c, &e)| ((a as u32, b as u32, c as u32), e))
            })
        })
    };
    let mut pair_gaps: HashMap<(u32, u32), Vec<f64>> = HashMap::default();
    for (q, (g, d)) in seen_face() {
        if d > tight {
            pair_gaps.entry((q.0.min(g), q.0.max(g))).or_default().push(d);
        }
    }
    let ceiling = sew.max(tight);
    let model_sew = (4.0 * q90(&mut gaps)).max(0.125 * sew).clamp(tight, ceiling);
    // The least a pair is sewn at: the model's distance, widened by how far
    // either face's border was moved.
    let floor =
        |a: u32, b: u32| (model_sew + moved_by(moved, a) + if a == b { 0.0 } else { moved_by(moved, b) }).min(ceiling);
    for (q, (g, _)) in seen_face() {
        pair_gaps.entry((q.0.min(g), q.0.max(g))).or_default();
    }
    let pair_sew: HashMap<(u32, u32), f64> = pair_gaps
        .into_iter()
        .map(|(key, mut g)| {
            let s = if g.len() >= PAIR_MIN { 4.0 * q90(&mut g) } else { 0.0 };
            (key, s.clamp(floor(key.0, key.1), ceiling))
        })
        .collect();
    let sew_of = |q: NodeRef| {
        Some(nearest_face[q.0 as usize][q.1 as usize][q.2 as usize])
            .filter(|e| !e.1.is_nan())
            .and_then(|(g, _)| pair_sew.get(&(q.0.min(g), q.0.max(g))))
            .copied()
            .unwrap_or_else(|| floor(q.0, q.0))
    };
    let radius = radii_each(pos, &sew_of, tight);
    let sew = pair_sew.values().fold(model_sew, |m, &s| m.max(s));
    (radius, sew)
}

/// The candidates kept, nearest first, per segment in order along it: one
/// within reach of the segment's ends or of a nearer node of that face
/// will be that node, one farther than the other face's nearest border
/// (four times that distance, or `tight` plus how far the borders moved)
/// would sew across a thin face, and of nodes within reach of each other
/// only the first is added.
fn additions(
    pos: &PerNode<DVec3>,
    grid: &CellGrid<NodeRef>,
    mut cands: Vec<Candidate>,
    near: &Nearness,
    radius: &PerNode<f64>,
    moved: &[f64],
    tight: f64,
) -> Additions {
    let at = |n: NodeRef| pos[n.0 as usize][n.1 as usize][n.2 as usize];
    let r_of = |n: NodeRef| radius[n.0 as usize][n.1 as usize][n.2 as usize];
    let mut adds: Additions = per_node(pos, Vec::new());
    crate::sort::by_f64(&mut cands, |c| c.3);
    for &(seg, s, t, d, q) in &cands {
        let (fi, k, i) = (seg.0 as usize, seg.1 as usize, seg.2 as usize);
        let limit = if seg.0 == q.0 { tight.min(r_of(q)) } else { r_of(q) };
        let n = pos[fi][k].len();
        let (na, nb) = (seg, (seg.0, seg.1, ((i + 1) % n) as u32));
        let qp = at(q);
        // Beyond reach, or within reach of an end (it will be that node).
        if s < 0.0
            || d > limit
            || qp.distance(at(na)) <= limit.min(r_of(na))
            || qp.distance(at(nb)) <= limit.min(r_of(nb))
        {
            continue;
        }
        // Within reach of another node of that face, nearer than this
        // border: it will be that node, and a copy here would be a second.
        let box_r = DVec3::splat(d.min(limit));
        if grid.in_box(qp - box_r, qp + box_r).any(|&m| {
            let e = qp.distance(at(m));
            m.0 == seg.0 && m != q && e < d && e <= limit.min(r_of(m))
        }) {
            continue;
        }
        // A moved border (a rebuilt face's) is as near as it was, within how far it moved.
        let nearest = near.nearest[q.0 as usize][q.1 as usize][q.2 as usize];
        let near_enough = (tight + moved_by(moved, seg.0) + moved_by(moved, q.0))
            .max(4.0 * Some(nearest).filter(|d| !d.is_nan()).unwrap_or(0.0));
        if seg.0 != q.0 && d > near_enough {
            continue;
        }
        if d > near.nearest_in.get(&(q, seg.0)).copied().unwrap_or(0.0) + tight {
            continue;
        }
        let list = &mut adds[fi][k][i];
        // Two nodes within reach of each other will be one: add one.
        if !list.iter().any(|c| at(c.2).distance(qp) <= r_of(c.2).min(r_of(q))) {
            list.push((s, t, q));
        }
    }
    for list in adds.iter_mut().flatten().flatten() {
        crate::sort::by_f64(list, |x| x.0);
    }
    adds
}

/// Adds the nodes to the outlines; returns each new node with the node
/// it stands for (both by their places in the new outlines).
fn insert(faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>], adds: &Additions) -> Vec<(NodeRef, NodeRef)> {
    let mut twins = Vec::new();
    // Where each old node went.
    let mut moved: PerNode<u32> =
        adds.iter().map(|f| f.iter().map(|p| (0..p.len() as u32).collect()).collect()).collect();
    for (fi, item) in faces.iter_mut().enumerate() {
        let Some((_, o)) = item else { continue };
        for (k, add) in adds[fi].iter().enumerate() {
            if add.iter().all(Vec::is_empty) {
                continue;
            }
            let poly = &mut o.loops.polys[k];
            let mut out = Polyline::default();
            // Twins are named by their index in the new loop, fixed below.
            let mut new_twins = Vec::new();
            for i in 0..poly.uv.len() {
                let (curve, ta, tb) = poly.seg[i];
                moved[fi][k][i] = out.uv.len() as u32;
                out.uv.push(poly.uv[i]);
                out.at.push(poly.at[i]);
                let mut from = ta;
                for &(_, t, q) in &add[i] {
                    let Some(c) = o.loops.curves.get(curve as usize) else { break };
                    new_twins.push((out.uv.len() as u32, q));
                    out.push_on_curve(curve, &mut from, t, c.point(t).truncate());
                }
                out.seg.push((curve, from, tb));
            }
            *poly = out;
            o.gids[k] = alloc::vec![u32::MAX; poly.uv.len()];
            twins.extend(new_twins.into_iter().map(|(i, q)| ((fi as u32, k as u32, i), q)));
        }
    }
    for (_, q) in &mut twins {
        q.2 = moved[q.0 as usize][q.1 as usize][q.2 as usize];
    }
    twins
}

/// Union-find over nodes, each cluster with its nodes' faces, points and reaches.
struct Clusters<'n> {
    parent: Vec<u32>,
    /// Each cluster's nodes as a ring: `next` leads from a node to the
    /// next of its cluster (4 bytes a node, where a list per node took a
    /// heap block each: 5 MB for a plate of 1000 holes).
    next: Vec<u32>,
    /// Node count, at each root.
    size: Vec<u32>,
    /// Each node's face and place, and its reach.
    nodes: &'n [(u32, DVec3)],
    reach: &'n [f64],
    tight: f64,
    /// Pairs of nodes of one face (lower index first) never in one
    /// cluster: a strip's two sides with other faces' borders on them.
    apart: crate::collections::HashSet<(u32, u32)>,
    /// Per node, whether its face lies all around it ([`Inside`]): it is
    /// never one with another face's node. Empty: none is.
    inside: Vec<bool>,
    /// Per node, its face's unit surface normal there, where a pair of
    /// faces wider apart than `tight` may need it (zero: unknown).
    normal: Vec<DVec3>,
}

impl<'n> Clusters<'n> {
    fn new(nodes: &'n [(u32, DVec3)], reach: &'n [f64], tight: f64) -> Self {
        let n = nodes.len() as u32;
        Self {
            parent: (0..n).collect(),
            next: (0..n).collect(),
            size: alloc::vec![1; n as usize],
            nodes,
            reach,
            tight,
            apart: crate::collections::HashSet::default(),
            inside: Vec::new(),
            normal: Vec::new(),
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }

    /// A node's face, place and reach.
    fn node(&self, i: u32) -> (u32, DVec3, f64) {
        let (f, p) = self.nodes[i as usize];
        (f, p, self.reach.get(i as usize).copied().unwrap_or(0.0))
    }

    /// The nodes of the cluster of root `x`, the root first.
    fn members(&self, x: u32) -> impl Iterator<Item = (u32, DVec3, f64)> + '_ {
        self.member_ids(x).map(|i| self.node(i))
    }

    /// The nodes of the cluster of root `x` by index, the root first.
    fn member_ids(&self, x: u32) -> impl Iterator<Item = u32> + '_ {
        let mut at = Some(x);
        core::iter::from_fn(move || {
            let i = at?;
            let n = self.next[i as usize];
            at = (n != x).then_some(n);
            Some(i)
        })
    }

    /// Whether node `i` lies inside its face (see `inside`).
    fn is_inside(&self, i: u32) -> bool {
        self.inside.get(i as usize).copied().unwrap_or(false)
    }

    /// Whether nodes `i` and `j` must stay apart (see `apart`).
    fn kept_apart(&self, i: u32, j: u32) -> bool {
        !self.apart.is_empty() && self.apart.contains(&(i.min(j), i.max(j)))
    }

    /// Joins the clusters of `a` and `b` unless that would make two
    /// nodes of one face one node that could not be one directly
    /// (farther apart than `tight` or than either's reach, or kept apart).
    fn union(&mut self, a: u32, b: u32) {
        let (x, y) = (self.find(a), self.find(b));
        if x == y {
            return;
        }
        if self.layers(a, b, x, y) {
            return;
        }
        let tight = self.tight;
        let clash = self.member_ids(x).any(|i| {
            let (f, p, rp) = self.node(i);
            self.member_ids(y).any(|j| {
                let (g, q, rq) = self.node(j);
                f == g && (p.distance(q) > tight.min(rp).min(rq) || self.kept_apart(i, j))
            })
        });
        if clash {
            return;
        }
        self.merge(x, y);
    }

    /// Whether joining nodes `a` and `b` (clusters with roots `x` and `y`)
    /// would fold two layers of a wall thinner than the sewing distance
    /// into one: each cluster is a join of two faces already, and `b` lies
    /// off `a` along both their normals, not beside it. The two sheets
    /// (a tube's outer and inner skins, each split at one seam) would
    /// otherwise share their seams' edges four ways.
    fn layers(&self, a: u32, b: u32, x: u32, y: u32) -> bool {
        let normal = |i: u32| self.normal.get(i as usize).copied().unwrap_or(DVec3::ZERO);
        let (na, nb) = (normal(a), normal(b));
        let (pa, pb) = (self.nodes[a as usize].1, self.nodes[b as usize].1);
        let d = pb - pa;
        let len = d.length();
        if na == DVec3::ZERO || nb == DVec3::ZERO || len <= self.tight || len <= TINY {
            return false;
        }
        let dir = d / len;
        if na.dot(dir).abs() < LAYER_COS || nb.dot(dir).abs() < LAYER_COS {
            return false;
        }
        let two_faces = |r: u32| {
            let f = self.nodes[r as usize].0;
            self.member_ids(r).any(|i| self.nodes[i as usize].0 != f)
        };
        two_faces(x) && two_faces(y)
    }

    /// Joins the lone node `a` to the cluster of `b`, its neighbour a
    /// segment away, if every node of their face there is within `tight` of it.
    fn absorb(&mut self, a: u32, b: u32) -> bool {
        let (x, y) = (self.find(a), self.find(b));
        let (f, p, _) = self.node(x);
        let far = |j: u32| {
            let (g, q, _) = self.node(j);
            g == f && (p.distance(q) > self.tight || self.kept_apart(x, j))
        };
        if x == y || self.member_ids(y).any(far) {
            return false;
        }
        self.merge(x, y);
        true
    }

    /// Merges the clusters with roots `x` and `y`: the larger's root stays,
    /// and the two rings become one by swapping the roots' successors.
    fn merge(&mut self, x: u32, y: u32) {
        let (small, big) = if self.size[x as usize] < self.size[y as usize] { (x, y) } else { (y, x) };
        self.parent[small as usize] = big;
        self.size[big as usize] += self.size[small as usize];
        self.next.swap(small as usize, big as usize);
    }

    /// The pairs of nodes of one body within `sew` (`tight` inside one
    /// face) and within both their reaches: (distance, node, node).
    fn near_pairs(&self, bodies: &[u32], sew: f64) -> Vec<(f64, u32, u32)> {
        let (nodes, reach, tight) = (self.nodes, self.reach, self.tight);
        let mut grid = CellGrid::new(1.0 / sew);
        for (i, &(_, p)) in nodes.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        let body = |f: u32| crate::model::body_of(bodies, f as usize);
        let mut pairs: Vec<(f64, u32, u32)> = Vec::new();
        for (i, &(fi, p)) in nodes.iter().enumerate() {
            for &j in grid.near(p) {
                if j as usize <= i {
                    continue;
                }
                let (fj, q) = nodes[j as usize];
                if body(fi) != body(fj) || (fi != fj && (self.is_inside(i as u32) || self.is_inside(j))) {
                    continue;
                }
                let d = p.distance(q);
                let limit = if fi == fj { tight } else { sew };
                if d <= limit.min(reach[i]).min(reach[j as usize]) {
                    pairs.push((d, i as u32, j));
                }
            }
        }
        pairs
    }

    /// Joins the pairs, nearest first, so that a chain of close nodes is
    /// cut where its nodes are farthest apart.
    fn join(&mut self, mut pairs: Vec<(f64, u32, u32)>) {
        crate::sort::by_f64(&mut pairs, |x| x.0);
        for (_, a, b) in pairs {
            self.union(a, b);
        }
    }

    /// A node no other face took, one segment shorter than `tight` from a
    /// node shared with a face within `sew` of it, is that node: there the
    /// other border has one node for this one's tiny jog. Only nodes shared
    /// before this take others in, so it does not run along a border.
    /// `index`: each outline node's place in the cluster's nodes.
    fn absorb_jogs(&mut self, index: &PerNode<u32>, sew: f64) {
        let (nodes, tight) = (self.nodes, self.tight);
        let shared_before: Vec<bool> = (0..nodes.len() as u32)
            .map(|a| {
                let r = self.find(a);
                self.size[r as usize] > 1
            })
            .collect();
        for (fi, face) in index.iter().enumerate() {
            for ring in face {
                let n = ring.len();
                for i in 0..n {
                    let a = ring[i];
                    if shared_before[a as usize] || self.is_inside(a) {
                        continue;
                    }
                    let p = nodes[a as usize].1;
                    for j in [(i + n - 1) % n, (i + 1) % n] {
                        let b = ring[j];
                        if b == a || !shared_before[b as usize] || nodes[b as usize].1.distance(p) > tight {
                            continue;
                        }
                        let rb = self.find(b);
                        let shared = self.members(rb).any(|(g, q, _)| g != fi as u32 && q.distance(p) <= sew);
                        if shared && self.absorb(a, b) {
                            break;
                        }
                    }
                }
            }
        }
    }
}

/// Gives nodes within both their reaches of each other one id (within
/// `tight` inside one face), new nodes the id of the node they stand for,
/// and a lone node one short segment from a shared one that id.
fn name_nodes(
    faces: &mut [Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    radius_before: &PerNode<f64>,
    twins: &[(NodeRef, NodeRef)],
    sew: f64,
    tight: f64,
) -> u32 {
    let (flat, index, r_flat, pos) = flat_nodes(faces, radius_before, twins);
    let mut cl = Clusters::new(&flat, &r_flat, tight);
    cl.inside = Inside::new(faces, &pos, tight).node.into_iter().flatten().flatten().collect();
    let pairs = if sew > 0.0 { cl.near_pairs(bodies, sew) } else { Vec::new() };
    cl.apart = folds_across(faces, bodies, &pos, &index, &r_flat, &pairs, sew, tight);
    cl.normal = pair_normals(faces, &index, &flat, &pairs, tight);
    // Twins first (they are one node by construction), then neighbours by distance.
    let id_of = |n: NodeRef, index: &PerNode<u32>| index[n.0 as usize][n.1 as usize].get(n.2 as usize).copied();
    for &(n, q) in twins {
        if let (Some(a), Some(b)) = (id_of(n, &index), id_of(q, &index)) {
            cl.union(a, b);
        }
    }
    if sew > 0.0 {
        cl.join(pairs);
        cl.absorb_jogs(&index, sew);
    }
    // Compact ids.
    let mut ids: HashMap<u32, u32> = HashMap::default();
    for (fi, item) in faces.iter_mut().enumerate() {
        let Some((_, o)) = item else { continue };
        for k in 0..o.gids.len() {
            for i in 0..o.gids[k].len() {
                let root = cl.find(index[fi][k][i]);
                let next = ids.len() as u32;
                o.gids[k][i] = *ids.entry(root).or_insert(next);
            }
        }
    }
    ids.len() as u32
}

/// The pairs of nodes of one face (sides of it within `tight`, wider than
/// `GAP · tight`) with another face's border between them
/// ([`super::across::between`]): a strip whose neighbours each take one of
/// its sides, the insertions that would fold it shut having been refused
/// for the same reason. Joining its sides at some nodes (directly or through
/// its neighbours' nodes) left it half folded, its neighbours overlapping
/// it there. `index`, `reach`: each outline node's place in the list the
/// `pairs` index and its reach there.
#[allow(clippy::too_many_arguments)]
fn folds_across(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    bodies: &[u32],
    pos: &PerNode<DVec3>,
    index: &PerNode<u32>,
    reach: &[f64],
    pairs: &[(f64, u32, u32)],
    sew: f64,
    tight: f64,
) -> crate::collections::HashSet<(u32, u32)> {
    let mut refs: Vec<NodeRef> = alloc::vec![(0, 0, 0); reach.len()];
    for (fi, f) in index.iter().enumerate() {
        for (k, l) in f.iter().enumerate() {
            for (i, &x) in l.iter().enumerate() {
                if let Some(r) = refs.get_mut(x as usize) {
                    *r = (fi as u32, k as u32, i as u32);
                }
            }
        }
    }
    let at = |n: NodeRef| pos[n.0 as usize][n.1 as usize][n.2 as usize];
    let one_face: Vec<(u32, u32)> = pairs
        .iter()
        .filter(|pr| pr.0 > GAP * tight && refs[pr.1 as usize].0 == refs[pr.2 as usize].0)
        .map(|pr| (pr.1, pr.2))
        .collect();
    if one_face.is_empty() {
        return crate::collections::HashSet::default();
    }
    let mut nodes = CellGrid::new(guarded_div(1.0, sew));
    for &n in &refs {
        nodes.insert(at(n), n);
    }
    // Each pair both ways: a face may lie beside either end only.
    let probes: Vec<super::across::Probe> = one_face
        .iter()
        .flat_map(|&(a, b)| [(a, b), (b, a)])
        .map(|(a, b)| {
            let (na, nb) = (refs[a as usize], refs[b as usize]);
            super::across::Probe { face: na.0, p: at(na), q: nb, d: at(na).distance(at(nb)) }
        })
        .collect();
    let reach_of = |n: NodeRef| reach[index[n.0 as usize][n.1 as usize][n.2 as usize] as usize];
    let across = super::across::between(faces, bodies, pos, &nodes, &probes, &reach_of, sew, tight);
    one_face.iter().zip(across.chunks(2)).filter(|(_, x)| x.iter().any(|&x| x)).map(|(&pr, _)| pr).collect()
}

/// Per node of `flat`, its face's unit surface normal where it is in one
/// of the `pairs` of two faces farther apart than `tight` (zero elsewhere):
/// what [`Clusters::layers`] reads.
fn pair_normals(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    index: &PerNode<u32>,
    flat: &[(u32, DVec3)],
    pairs: &[(f64, u32, u32)],
    tight: f64,
) -> Vec<DVec3> {
    let mut wanted = alloc::vec![false; flat.len()];
    for &(d, a, b) in pairs {
        if d > tight && flat[a as usize].0 != flat[b as usize].0 {
            wanted[a as usize] = true;
            wanted[b as usize] = true;
        }
    }
    let mut normal = alloc::vec![DVec3::ZERO; flat.len()];
    if !wanted.contains(&true) {
        return normal;
    }
    for (item, per_loop) in faces.iter().zip(index) {
        let Some((s, o)) = item else { continue };
        for (poly, ids) in o.loops.polys.iter().zip(per_loop) {
            for (&uv, &x) in poly.uv.iter().zip(ids) {
                if wanted.get(x as usize).copied().unwrap_or(false) {
                    let n = s.normal(uv);
                    normal[x as usize] = if n.is_finite() { n.normalize_or_zero() } else { DVec3::ZERO };
                }
            }
        }
    }
    normal
}

/// Every outline node in one list: its face and place, where each node
/// went in it, its reach after insertion (a new node has its twin's, an
/// old one keeps its own), and each node's point.
#[allow(clippy::type_complexity)]
fn flat_nodes(
    faces: &[Option<(&dyn Surface, &mut Outline<'_>)>],
    radius_before: &PerNode<f64>,
    twins: &[(NodeRef, NodeRef)],
) -> (Vec<(u32, DVec3)>, PerNode<u32>, Vec<f64>, PerNode<DVec3>) {
    let pos = positions(faces);
    let mut radius: PerNode<f64> = per_node(&pos, 0.0);
    let mut index: PerNode<u32> = per_node(&pos, 0);
    let mut flat: Vec<(u32, DVec3)> = Vec::new();
    for (fi, item) in faces.iter().enumerate() {
        let Some((_, o)) = item else { continue };
        for (k, poly) in o.loops.polys.iter().enumerate() {
            let mut old = 0usize;
            let new_here: crate::collections::HashSet<u32> =
                twins.iter().filter(|(n, _)| n.0 as usize == fi && n.1 as usize == k).map(|(n, _)| n.2).collect();
            for i in 0..poly.uv.len() {
                if !new_here.contains(&(i as u32)) {
                    radius[fi][k][i] = radius_before[fi][k].get(old).copied().unwrap_or(0.0);
                    old += 1;
                }
                index[fi][k][i] = flat.len() as u32;
                flat.push((fi as u32, pos[fi][k][i]));
            }
        }
    }
    // Twins name their node by its place in the new outlines, where the
    // loop above has just put the old nodes' reaches (reading the old
    // places instead gave a new node some other node's reach, often none).
    for &(n, q) in twins {
        let r = radius[q.0 as usize][q.1 as usize].get(q.2 as usize).copied().unwrap_or(0.0);
        radius[n.0 as usize][n.1 as usize][n.2 as usize] = r;
    }
    let r_flat: Vec<f64> = radius.iter().flatten().flatten().copied().collect();
    (flat, index, r_flat, pos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::{NurbsCurve, NurbsSurface};
    use alloc::vec;
    use glam::DVec2;

    /// A piece of a circle in (u, v) on a cylinder: wherever it is ruled
    /// out, every sampled point of it is farther than the limit, and nodes
    /// well away from the piece are ruled out.
    #[test]
    fn a_piece_ruled_out_has_no_point_within_the_limit() {
        let w = core::f64::consts::FRAC_1_SQRT_2;
        let ring = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)];
        let net: Vec<Vec<DVec3>> = ring
            .iter()
            .map(|&(x, y)| vec![DVec3::new(5.0 * x, 5.0 * y, 0.0), DVec3::new(5.0 * x, 5.0 * y, 3.0)])
            .collect();
        let wn: Vec<Vec<f64>> = [1.0, w, 1.0, w, 1.0].iter().map(|&w| vec![w, w]).collect();
        let knots = vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
        let surface =
            NurbsSurface::try_new([2, 1], knots, vec![0.0, 0.0, 1.0, 1.0], &net, Some(&wn)).expect("cylinder");
        // A circle of radius 0.3 about (0.5, 0.5) in the parameters.
        let uv: Vec<DVec3> = ring.iter().map(|&(x, y)| DVec3::new(0.5 + 0.3 * x, 0.5 + 0.3 * y, 0.0)).collect();
        let curve =
            NurbsCurve::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0], uv, Some(vec![1.0, w, 1.0, w, 1.0]))
                .expect("circle");
        // A piece as short as a loop's segments are, against nodes all over the face.
        let (ta, tb) = (0.1, 0.12);
        let on_curve = |s: f64| surface.point(curve.point(ta + (tb - ta) * s).truncate());
        let piece = Piece::new(&on_curve, tb - ta, surface.derivative_bounds(), curve.derivative_bound())
            .expect("bounds known");
        let samples: Vec<DVec3> = (0..=400).map(|i| on_curve(f64::from(i) / 400.0)).collect();
        let (mut ruled_out, limit) = (0, 0.2);
        for i in 0..=20 {
            for j in 0..=20 {
                let uv = DVec2::new(f64::from(i) / 20.0, f64::from(j) / 20.0);
                let q = surface.point(uv) + DVec3::new(0.0, 0.0, 0.1 * f64::from(i % 3));
                if piece.beyond(q, limit) {
                    ruled_out += 1;
                    let nearest = samples.iter().map(|p| p.distance(q)).fold(f64::INFINITY, f64::min);
                    assert!(nearest > limit, "{q} is {nearest} from the piece");
                }
            }
        }
        assert!(ruled_out > 200, "only {ruled_out} of 441 nodes ruled out");
    }
}
