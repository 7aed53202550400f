//! Boundary nodes that neighbouring faces share (paper 003 §3 step 1: nodes
//! from the geometry and the topology found from shared boundaries).
//!
//! The model carries no edge topology, so it is found here: every trim curve
//! of every face is sampled in model space; curve ends closer than the
//! sewing distance are one vertex; a vertex lying on another curve's
//! interior splits that curve there; and pieces between the same two
//! vertices whose quarter, half and three-quarter points agree are one edge.
//! Each edge is divided once, by model-space arc length, into ceil(L/H)
//! equal parts, and every face using it gets the same 3-D points (at its own
//! curve parameters), so the faces' meshes meet node to node.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::mesh::weld_positions;
use crate::model::Face;
use crate::nurbs::{NurbsCurve, Surface};
use crate::warning::QualityError;

/// Samples of a piece of curve never exceed this (memory bound per curve).
const MAX_SAMPLES: usize = 200_000;

/// One boundary node of a face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BNode {
    /// Parameters on the face's surface.
    pub uv: DVec2,
    /// Model-space position (the same for every face sharing the node).
    pub x: DVec3,
    /// Element size wanted at the node, model units.
    pub h: f64,
}

/// A face's boundary: loop 0 is the outer loop, counter-clockwise in (u,v);
/// holes follow, clockwise.
#[derive(Debug, Clone, Default)]
pub(crate) struct FaceBoundary {
    pub loops: Vec<Vec<BNode>>,
}

/// A boundary curve of a face in its (u,v): a trim curve, or a side of the
/// parameter domain of an untrimmed face, run from `t0` to `t1`.
#[derive(Debug, Clone, Copy)]
struct Trace<'a> {
    curve: Option<&'a NurbsCurve>,
    a: DVec2,
    b: DVec2,
    t0: f64,
    t1: f64,
}

impl Trace<'_> {
    fn uv(&self, t: f64) -> DVec2 {
        match self.curve {
            Some(c) => c.point(t).truncate(),
            None => self.a + (self.b - self.a) * t,
        }
    }

    fn reversed(self) -> Self {
        Self { t0: self.t1, t1: self.t0, ..self }
    }

    /// Parameters where the curve may bend: knots (curves) or nothing (domain sides).
    fn breaks(&self) -> Vec<f64> {
        match self.curve {
            Some(c) => c.knots().breakpoints(),
            None => alloc::vec![0.0, 1.0],
        }
    }
}

/// Model-space samples of one trace, in its running direction.
#[derive(Debug, Clone, Default)]
struct Samples {
    t: Vec<f64>,
    x: Vec<DVec3>,
    /// Arc length from the first sample.
    s: Vec<f64>,
}

impl Samples {
    fn take(surface: &dyn Surface, tr: &Trace<'_>, per_span: usize, min: usize) -> Self {
        let (lo, hi) = (tr.t0.min(tr.t1), tr.t0.max(tr.t1));
        let mut ks: Vec<f64> = tr.breaks().into_iter().filter(|&k| k > lo && k < hi).collect();
        ks.insert(0, lo);
        ks.push(hi);
        let spans = ks.len() - 1;
        let per = per_span.max(min.div_ceil(spans)).clamp(2, MAX_SAMPLES / spans.max(1));
        let mut t = Vec::with_capacity(spans * per + 1);
        for w in ks.windows(2) {
            for k in 0..per {
                t.push(w[0] + (w[1] - w[0]) * k as f64 / per as f64);
            }
        }
        t.push(hi);
        if tr.t0 > tr.t1 {
            t.reverse();
        }
        let x: Vec<DVec3> = t.iter().map(|&t| surface.point(tr.uv(t))).collect();
        let mut s = Vec::with_capacity(x.len());
        let mut acc = 0.0;
        for (i, p) in x.iter().enumerate() {
            if i > 0 {
                acc += p.distance(x[i - 1]);
            }
            s.push(acc);
        }
        Self { t, x, s }
    }

    fn length(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }

    /// Trace parameter at arc length `s` (linear between samples).
    fn t_at(&self, s: f64) -> f64 {
        let i = self.s.partition_point(|&a| a < s).clamp(1, self.s.len().saturating_sub(1).max(1));
        let (s0, s1) = (self.s[i - 1], self.s[i]);
        let f = if s1 > s0 { ((s - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 0.0 };
        self.t[i - 1] + (self.t[i] - self.t[i - 1]) * f
    }

    /// Closest point of the polyline between samples `from..=to` to `p`:
    /// (distance, trace parameter, arc length).
    fn closest(&self, p: DVec3, from: usize, to: usize) -> (f64, f64, f64) {
        let mut best = (f64::INFINITY, self.t.first().copied().unwrap_or(0.0), 0.0);
        for i in from.max(1)..=to.min(self.x.len().saturating_sub(1)) {
            let (a, b) = (self.x[i - 1], self.x[i]);
            let ab = b - a;
            let l2 = ab.length_squared();
            let f = if l2 > 0.0 { ((p - a).dot(ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
            let d = (a + ab * f).distance(p);
            if d < best.0 {
                let t = self.t[i - 1] + (self.t[i] - self.t[i - 1]) * f;
                best = (d, t, self.s[i - 1] + (self.s[i] - self.s[i - 1]) * f);
            }
        }
        best
    }
}

/// A piece of a trace between two consecutive vertices on it.
#[derive(Debug, Clone)]
struct Piece {
    face: usize,
    trace: usize,
    /// Arc lengths on the trace's samples where the piece starts and ends.
    s0: f64,
    s1: f64,
    va: u32,
    vb: u32,
    /// Nodes from `va` up to, not including, `vb`: (trace parameter, position).
    nodes: Vec<(f64, DVec3)>,
}

impl Piece {
    fn len(&self) -> f64 {
        self.s1 - self.s0
    }
}

/// Discretizes the boundaries of `faces` (all of a model) with element size
/// `h`, welding at `sew`. Per face: its boundary, or why it has none.
///
/// `budget` bounds the total number of boundary nodes.
///
/// # Errors
/// A message when the boundary alone needs more than `budget` nodes.
pub(crate) fn discretize(
    faces: &[Face],
    h: f64,
    sew: f64,
    budget: usize,
) -> Result<Vec<Result<FaceBoundary, QualityError>>, QualityError> {
    let (loops_of, traces) = collect_traces(faces);
    let samples = sample_traces(faces, &traces, h, budget)?;
    // Vertices: curve ends welded.
    let ends: Vec<DVec3> = samples
        .iter()
        .flat_map(|s| [s.x.first().copied().unwrap_or(DVec3::ZERO), s.x.last().copied().unwrap_or(DVec3::ZERO)])
        .collect();
    let (vmap, nverts) = weld_positions(&ends, sew);
    let mut vpos = alloc::vec![DVec3::ZERO; nverts];
    let mut vseen = alloc::vec![false; nverts];
    for (i, &m) in vmap.iter().enumerate() {
        if !vseen[m as usize] {
            vseen[m as usize] = true;
            vpos[m as usize] = ends[i];
        }
    }
    let (mut pieces, pieces_of_trace) = split_at_vertices(&traces, &samples, &vmap, &vpos, sew);
    // Pieces that are one model edge.
    let groups = match_pieces(&pieces, &samples, sew);
    // Node counts per edge: ceil(L/H), and enough for every loop to have three nodes.
    let mut loop_pieces = alloc::vec![0usize; pieces.len()];
    for lp in loops_of.iter().flatten().flatten() {
        let count: usize = lp.iter().map(|&t| pieces_of_trace[t].len()).sum();
        for &t in lp {
            for &p in &pieces_of_trace[t] {
                loop_pieces[p] = count;
            }
        }
    }
    let divider = Divider { faces, traces: &traces, samples: &samples, vpos: &vpos, h, sew };
    for g in &groups {
        divider.divide_edge(g, &loop_pieces, &mut pieces);
    }
    // Each face's loops from its pieces' nodes.
    Ok(loops_of
        .into_iter()
        .map(|loops| loops.and_then(|l| face_boundary(&l, &traces, &pieces_of_trace, &pieces, h)))
        .collect())
}

/// What dividing the model's edges reads: the faces, their traces and
/// samples, the welded vertices, the element size and the sewing distance.
struct Divider<'a, 'f> {
    faces: &'f [Face],
    traces: &'a [(usize, Trace<'f>)],
    samples: &'a [Samples],
    vpos: &'a [DVec3],
    h: f64,
    sew: f64,
}

/// Every face's boundary traces, loops oriented (outer counter-clockwise
/// first), numbered across the model: per face, its loops as trace numbers
/// (or why it has none), and each trace with its face.
#[allow(clippy::type_complexity)]
fn collect_traces(faces: &[Face]) -> (Vec<Result<Vec<Vec<usize>>, QualityError>>, Vec<(usize, Trace<'_>)>) {
    let mut loops_of: Vec<Result<Vec<Vec<usize>>, QualityError>> = Vec::with_capacity(faces.len());
    let mut traces: Vec<(usize, Trace<'_>)> = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        loops_of.push(face_traces(fi, f).map(|loops| {
            loops
                .into_iter()
                .map(|lp| {
                    lp.into_iter()
                        .map(|tr| {
                            traces.push((fi, tr));
                            traces.len() - 1
                        })
                        .collect()
                })
                .collect()
        }));
    }
    (loops_of, traces)
}

/// Model-space samples of every trace, dense enough for the size `h`.
///
/// # Errors
/// A message when the boundary alone needs more than `budget` nodes.
fn sample_traces(
    faces: &[Face],
    traces: &[(usize, Trace<'_>)],
    h: f64,
    budget: usize,
) -> Result<Vec<Samples>, QualityError> {
    let mut samples: Vec<Samples> = Vec::with_capacity(traces.len());
    let mut total_nodes = 0usize;
    for (fi, tr) in traces {
        let s: &dyn Surface = &faces[*fi].surface;
        let mut sm = Samples::take(s, tr, 16, 64);
        let need = 4.0 * sm.length() / h;
        if need > (sm.t.len() as f64) {
            sm = Samples::take(s, tr, 16, (need.min(MAX_SAMPLES as f64)) as usize);
        }
        total_nodes = total_nodes.saturating_add(crate::math::ceil(sm.length() / h).min(1e15) as usize);
        if total_nodes > budget {
            return Err(QualityError::BoundaryBudget { budget, size: h });
        }
        samples.push(sm);
    }
    Ok(samples)
}

/// Each trace cut into pieces at the vertices (`vpos`; its own ends are
/// `vmap[2 t]` and `vmap[2 t + 1]`) that lie on its interior within `sew`:
/// the pieces, and each trace's pieces in order.
fn split_at_vertices(
    traces: &[(usize, Trace<'_>)],
    samples: &[Samples],
    vmap: &[u32],
    vpos: &[DVec3],
    sew: f64,
) -> (Vec<Piece>, Vec<Vec<usize>>) {
    let mut pieces: Vec<Piece> = Vec::new();
    let mut pieces_of_trace: Vec<Vec<usize>> = alloc::vec![Vec::new(); traces.len()];
    for (ti, sm) in samples.iter().enumerate() {
        let (va, vb) = (vmap[2 * ti], vmap[2 * ti + 1]);
        let mut cuts: Vec<(f64, u32)> = on_trace(sm, vpos, va, vb, sew);
        crate::sort::by_f64(&mut cuts, |c| c.0);
        let len = sm.length();
        let mut prev = (0.0, va);
        cuts.push((len, vb));
        for (s, v) in cuts {
            if s - prev.0 <= 0.0 && v == prev.1 {
                continue;
            }
            pieces_of_trace[ti].push(pieces.len());
            pieces.push(Piece {
                face: traces[ti].0,
                trace: ti,
                s0: prev.0,
                s1: s,
                va: prev.1,
                vb: v,
                nodes: Vec::new(),
            });
            prev = (s, v);
        }
    }
    (pieces, pieces_of_trace)
}

impl Divider<'_, '_> {
    /// Divides the model edge made of the pieces `g` (the first the master)
    /// into ceil(L/H) parts by the master's arc length (at least as many as
    /// a loop of few pieces needs, per `loop_pieces`), and gives every piece
    /// the same 3-D nodes at its own curve parameters.
    fn divide_edge(&self, g: &[usize], loop_pieces: &[usize], pieces: &mut [Piece]) {
        let (h, sew, samples) = (self.h, self.sew, self.samples);
        let master = pieces[g[0]].clone();
        let master = &master;
        let len = master.len();
        let degenerate = len <= sew;
        let mut n = if degenerate { 1 } else { (crate::math::ceil(len / h - 1e-9) as usize).max(1) };
        if !degenerate {
            for &p in g {
                n = n.max(match loop_pieces[p] {
                    0 | 1 => 3,
                    2 => 2,
                    _ => 1,
                });
            }
        }
        // The master's nodes at equal arc length; its ends are the vertices.
        let msm = &samples[master.trace];
        let tr = &self.traces[master.trace].1;
        let surface: &dyn Surface = &self.faces[master.face].surface;
        let mut xs: Vec<DVec3> = Vec::with_capacity(n);
        for k in 0..n {
            if k == 0 {
                xs.push(self.vpos[master.va as usize]);
            } else {
                let t = msm.t_at(master.s0 + len * k as f64 / n as f64);
                xs.push(surface.point(tr.uv(t)));
            }
        }
        for &p in g {
            let piece = &pieces[p];
            let sm = &samples[piece.trace];
            let same = piece.va == master.va && (piece.va != piece.vb || same_direction(piece, master, samples));
            let mut nodes = Vec::with_capacity(n);
            for k in 0..n {
                let (x, frac) = if same {
                    (xs[k], k as f64 / n as f64)
                } else if k == 0 {
                    (self.vpos[piece.va as usize], 0.0)
                } else {
                    (xs[n - k], k as f64 / n as f64)
                };
                let t = if k == 0 {
                    sm.t_at(piece.s0)
                } else if p == g[0] {
                    sm.t_at(piece.s0 + piece.len() * frac)
                } else {
                    locate(sm, piece, x, frac)
                };
                nodes.push((t, x));
            }
            pieces[p].nodes = nodes;
        }
    }
}

/// A face's boundary from its `loops` (trace numbers) and their pieces' nodes.
///
/// # Errors
/// A loop left with fewer than three nodes: it encloses no area.
fn face_boundary(
    loops: &[Vec<usize>],
    traces: &[(usize, Trace<'_>)],
    pieces_of_trace: &[Vec<usize>],
    pieces: &[Piece],
    h: f64,
) -> Result<FaceBoundary, QualityError> {
    let mut fb = FaceBoundary::default();
    for (li, lp) in loops.iter().enumerate() {
        let mut nodes: Vec<BNode> = Vec::new();
        for &ti in lp {
            let tr = &traces[ti].1;
            for &p in &pieces_of_trace[ti] {
                for &(t, x) in &pieces[p].nodes {
                    nodes.push(BNode { uv: tr.uv(t), x, h });
                }
            }
        }
        nodes.dedup_by(|a, b| a.uv == b.uv);
        while nodes.len() > 1 && nodes.first().map(|n| n.uv) == nodes.last().map(|n| n.uv) {
            nodes.pop();
        }
        if nodes.len() < 3 {
            return Err(QualityError::FewLoopNodes { lp: li, nodes: nodes.len() });
        }
        set_sizes(&mut nodes, h);
        fb.loops.push(nodes);
    }
    Ok(fb)
}

/// The face's boundary traces by loop, oriented: outer loop (largest area in
/// (u,v)) first and counter-clockwise, holes clockwise.
fn face_traces(fi: usize, f: &Face) -> Result<Vec<Vec<Trace<'_>>>, QualityError> {
    let mut loops: Vec<Vec<Trace<'_>>> = Vec::new();
    if f.loops.is_empty() {
        let [lo, hi] = f.surface.domain();
        let c = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
        loops.push((0..4).map(|k| Trace { curve: None, a: c[k], b: c[(k + 1) % 4], t0: 0.0, t1: 1.0 }).collect());
    } else {
        for lp in &f.loops {
            loops.push(
                lp.curves
                    .iter()
                    .map(|c| {
                        let (t0, t1) = c.domain();
                        Trace { curve: Some(c), a: DVec2::ZERO, b: DVec2::ZERO, t0, t1 }
                    })
                    .collect(),
            );
        }
    }
    let areas: Vec<f64> = loops
        .iter()
        .map(|lp| {
            let poly: Vec<DVec2> = lp
                .iter()
                .flat_map(|tr| (0..16).map(move |k| tr.uv(tr.t0 + (tr.t1 - tr.t0) * k as f64 / 16.0)))
                .collect();
            signed_area(&poly)
        })
        .collect();
    if let Some(li) = areas.iter().position(|a| *a == 0.0 || !a.is_finite()) {
        return Err(QualityError::LoopNoArea { face: fi, lp: li });
    }
    let outer = (0..areas.len()).max_by(|&i, &j| areas[i].abs().total_cmp(&areas[j].abs())).unwrap_or(0);
    loops.swap(0, outer);
    let mut areas = areas;
    areas.swap(0, outer);
    for (k, lp) in loops.iter_mut().enumerate() {
        if (areas[k] > 0.0) != (k == 0) {
            lp.reverse();
            for tr in lp.iter_mut() {
                *tr = tr.reversed();
            }
        }
    }
    Ok(loops)
}

pub(crate) fn signed_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    let mut a = 0.0;
    for i in 0..n {
        a += p[i].perp_dot(p[(i + 1) % n]);
    }
    0.5 * a
}

/// Vertices (other than the trace's own ends) within `sew` of the trace's
/// interior: (arc length, vertex), found by boxes of 16 samples first.
fn on_trace(sm: &Samples, vpos: &[DVec3], va: u32, vb: u32, sew: f64) -> Vec<(f64, u32)> {
    let mut out = Vec::new();
    let n = sm.x.len();
    if n < 2 {
        return out;
    }
    let len = sm.length();
    let chunk = 16;
    let boxes: Vec<(DVec3, DVec3, usize, usize)> = (0..n - 1)
        .step_by(chunk)
        .map(|i| {
            let j = (i + chunk).min(n - 1);
            let mut lo = sm.x[i];
            let mut hi = sm.x[i];
            for p in &sm.x[i..=j] {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            (lo - DVec3::splat(sew), hi + DVec3::splat(sew), i, j)
        })
        .collect();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for b in &boxes {
        lo = lo.min(b.0);
        hi = hi.max(b.1);
    }
    for (v, &p) in vpos.iter().enumerate() {
        let v = v as u32;
        if v == va || v == vb || p.cmplt(lo).any() || p.cmpgt(hi).any() {
            continue;
        }
        let mut best = (f64::INFINITY, 0.0);
        for b in &boxes {
            if p.cmplt(b.0).any() || p.cmpgt(b.1).any() {
                continue;
            }
            let (d, _, s) = sm.closest(p, b.2 + 1, b.3);
            if d < best.0 {
                best = (d, s);
            }
        }
        if best.0 <= sew && best.1 > sew && best.1 < len - sew {
            out.push((best.1, v));
        }
    }
    out
}

/// Point of `piece` at fraction `f` of its arc length.
fn point_at(piece: &Piece, samples: &[Samples], f: f64) -> DVec3 {
    let sm = &samples[piece.trace];
    let s = piece.s0 + piece.len() * f;
    let i = sm.s.partition_point(|&a| a < s).clamp(1, sm.s.len().saturating_sub(1).max(1));
    let (s0, s1) = (sm.s[i - 1], sm.s[i]);
    let g = if s1 > s0 { ((s - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 0.0 };
    sm.x[i - 1].lerp(sm.x[i], g)
}

/// Whether `a` and `b` (pieces between the same vertices) run the same way:
/// their quarter points agree better that way than reversed.
fn same_direction(a: &Piece, b: &Piece, samples: &[Samples]) -> bool {
    let fwd: f64 = [0.25, 0.5, 0.75].iter().map(|&f| point_at(a, samples, f).distance(point_at(b, samples, f))).sum();
    let rev: f64 =
        [0.25, 0.5, 0.75].iter().map(|&f| point_at(a, samples, f).distance(point_at(b, samples, 1.0 - f))).sum();
    fwd <= rev
}

/// Groups pieces that are one model edge: same two vertices and points at a
/// quarter, half and three quarters of the length within
/// max(4 sew, 2% of the length). Degenerate pieces (shorter than `sew`)
/// stay alone. The first piece of each group is its master.
fn match_pieces(pieces: &[Piece], samples: &[Samples], sew: f64) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut by_key: crate::collections::HashMap<(u32, u32), Vec<usize>> = crate::collections::HashMap::default();
    for (i, p) in pieces.iter().enumerate() {
        let len = p.len();
        if len <= sew {
            groups.push(alloc::vec![i]);
            continue;
        }
        let key = (p.va.min(p.vb), p.va.max(p.vb));
        let tol = (4.0 * sew).max(0.02 * len);
        let mut found = None;
        if let Some(cands) = by_key.get(&key) {
            for &g in cands {
                let m = &pieces[groups[g][0]];
                if (m.len() - len).abs() > tol {
                    continue;
                }
                let same = m.va == p.va && (m.va != m.vb || same_direction(p, m, samples));
                let fits = [0.25, 0.5, 0.75].iter().all(|&f| {
                    let q = point_at(m, samples, if same { f } else { 1.0 - f });
                    point_at(p, samples, f).distance(q) <= tol
                });
                if fits {
                    found = Some(g);
                    break;
                }
            }
        }
        match found {
            Some(g) => groups[g].push(i),
            None => {
                by_key.entry(key).or_default().push(groups.len());
                groups.push(alloc::vec![i]);
            }
        }
    }
    groups
}

/// Parameter on `piece` of the point closest to `x`, searched around
/// fraction `frac` of its length first, then along the whole piece.
fn locate(sm: &Samples, piece: &Piece, x: DVec3, frac: f64) -> f64 {
    let s = piece.s0 + piece.len() * frac;
    let i = sm.s.partition_point(|&a| a < s);
    let first = sm.s.partition_point(|&a| a < piece.s0).saturating_sub(1);
    let last = sm.s.partition_point(|&a| a <= piece.s1).min(sm.s.len().saturating_sub(1));
    let (d, t, _) = sm.closest(x, i.saturating_sub(8).max(first), (i + 8).min(last));
    let step = sm.s.get(i).zip(sm.s.get(i.saturating_sub(1))).map_or(0.0, |(a, b)| a - b);
    if d <= 2.0 * step.max(0.0) + 1e-12 {
        return t;
    }
    sm.closest(x, first, last).1
}

/// Element size at each node: the mean of its two boundary segments (graded
/// towards short curves), at most `h`; segments of zero length (collapsed
/// edges) are left out.
fn set_sizes(nodes: &mut [BNode], h: f64) {
    let n = nodes.len();
    let seg: Vec<f64> = (0..n).map(|i| nodes[i].x.distance(nodes[(i + 1) % n].x)).collect();
    for i in 0..n {
        let (a, b) = (seg[(i + n - 1) % n], seg[i]);
        let tiny = 1e-9 * h;
        let m = match (a > tiny, b > tiny) {
            (true, true) => 0.5 * (a + b),
            (true, false) => a,
            (false, true) => b,
            (false, false) => h,
        };
        nodes[i].h = m.min(h);
    }
}
