//! Edges: an `EDGE_CURVE`'s curve cut between its two vertices, in the
//! edge's direction, as exact NURBS pieces whose ends are the vertex points
//! (so the faces on both sides start from the same points). Each edge is
//! read once and shared by the faces that use it.

use crate::collections::HashMap;
use alloc::vec::Vec;
use glam::DVec3;

use super::curves::{move_ends, param_of, period, pieces_between, rev_all, Curve3, CurveDef, CurveError, Geo};
use super::graph::Ent;
use crate::numeric::TINY;
use crate::nurbs::NurbsCurve;
use crate::warning::WarningKind;
use crate::Error;

/// An edge in its own direction (start vertex to end vertex).
#[derive(Debug, Clone)]
pub(super) struct Edge {
    /// Pieces from the start vertex to the end vertex (empty: degenerate edge).
    pub pieces: Vec<NurbsCurve>,
    /// What was repaired, if anything (reported once per edge).
    pub repaired: Option<WarningKind>,
}

/// Edges read so far, by `#id`.
#[derive(Default)]
pub(super) struct Edges {
    done: HashMap<(u64, bool), Result<Edge, Error>>,
    /// Vertices the file gives as both ends of an open B-spline (found on
    /// the first edge read): such a writer puts one vertex where the loop
    /// has two corners, so no edge's curve is cut or moved to them.
    reused: Option<crate::collections::HashSet<u64>>,
    /// Where each edge is used in the file's loops, built at the first edge
    /// whose vertex is missing.
    uses: Option<LoopUses>,
}

/// For each `EDGE_CURVE`, its uses in `EDGE_LOOP`s: the loop, the position
/// in it and the orientation, so a missing vertex can be taken from the
/// neighbouring edge that shares it.
#[derive(Default)]
struct LoopUses {
    by_edge: HashMap<u64, Vec<(u64, usize)>>,
    /// Each loop's edges with their orientations, in order.
    loops: HashMap<u64, Vec<(u64, bool)>>,
}

impl Edges {
    /// The edge `e` (an `EDGE_CURVE`); `alone`: it is the only edge of its
    /// loop, so on a closed curve it is the whole curve even where its two
    /// vertices differ by a rounding.
    pub fn get(&mut self, geo: &Geo<'_>, e: Ent<'_>, alone: bool) -> Result<Edge, Error> {
        if let Some(r) = self.done.get(&(e.id(), alone)) {
            return r.clone();
        }
        let reused = self.reused.get_or_insert_with(|| reused_vertices(geo));
        let r = read_edge(geo, e, alone, reused, &mut self.uses);
        self.done.insert((e.id(), alone), r.clone());
        r
    }
}

/// A `VERTEX_POINT`'s point.
pub(super) fn vertex(geo: &Geo<'_>, e: Ent<'_>) -> Result<DVec3, Error> {
    if !e.has("VERTEX_POINT") {
        return Err(e.error("expected a VERTEX_POINT"));
    }
    let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("VERTEX_POINT", 1)])?;
    geo.point(a.ent(1)?)
}

fn read_edge(
    geo: &Geo<'_>,
    e: Ent<'_>,
    alone: bool,
    reused: &crate::collections::HashSet<u64>,
    uses: &mut Option<LoopUses>,
) -> Result<Edge, Error> {
    if !e.has("EDGE_CURVE") {
        return Err(e.error("expected an EDGE_CURVE"));
    }
    let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("EDGE", 2), ("EDGE_CURVE", 2)])?;
    let (vs, ve) = (a.refr(1)?, a.refr(2)?);
    // A vertex the file does not define (a dangling reference) is where the
    // neighbouring edge of one of the edge's loops ends.
    let mut found = None;
    let mut end_point = |end: bool, v: u64| -> Result<DVec3, Error> {
        let missing = match geo.g.get(v, e.id()) {
            Ok(x) => return vertex(geo, x),
            Err(err) => err,
        };
        let uses = uses.get_or_insert_with(|| LoopUses::of(geo));
        let (p, lp) = uses.neighbour_vertex(geo, e.id(), end).ok_or(missing)?;
        found = Some(WarningKind::VertexFromNeighbour { end, vertex: v, lp });
        Ok(p)
    };
    let ps = end_point(false, vs)?;
    let pe = if ve == vs { ps } else { end_point(true, ve)? };
    let def = geo.curve(a.ent(3)?, 0)?;
    let same_sense = a.boolean(4, true)?;
    let ends = Ends { ps, pe, trust: [!reused.contains(&vs), !reused.contains(&ve)] };
    let (pieces, repaired) =
        cut(&def, &ends, same_sense, vs == ve || alone, geo.uncertainty).map_err(|m| e.error(m))?;
    let repaired = match (found, repaired) {
        (Some(f), Some(r)) => Some(WarningKind::Joined(alloc::vec![f, r])),
        (f, r) => f.or(r),
    };
    Ok(Edge { pieces, repaired })
}

impl LoopUses {
    /// One pass over the file's `EDGE_LOOP`s.
    fn of(geo: &Geo<'_>) -> Self {
        let mut out = Self::default();
        for lp in geo.g.all().filter(|x| x.has("EDGE_LOOP")) {
            let Some(refs) = lp.part("EDGE_LOOP").and_then(|p| {
                // A simple instance lists its name first.
                let at = usize::from(!lp.is_complex());
                p.refs(at).ok()
            }) else {
                continue;
            };
            let mut list = Vec::with_capacity(refs.len());
            for r in refs {
                let Some(oe) = geo.g.find(r) else { continue };
                let (edge, orientation) = if oe.has("ORIENTED_EDGE") {
                    let oa = oe.attrs();
                    match (oa.refr(3), oa.boolean(4, true)) {
                        (Ok(x), Ok(o)) => (x, o),
                        _ => continue,
                    }
                } else {
                    (r, true)
                };
                out.by_edge.entry(edge).or_default().push((lp.id(), list.len()));
                list.push((edge, orientation));
            }
            out.loops.insert(lp.id(), list);
        }
        out
    }

    /// The point of edge `edge`'s start (`end` false) or end vertex as the
    /// edge next to it in one of its loops gives it, and that loop's `#id`.
    fn neighbour_vertex(&self, geo: &Geo<'_>, edge: u64, end: bool) -> Option<(DVec3, u64)> {
        for &(lp, i) in self.by_edge.get(&edge)? {
            let list = self.loops.get(&lp)?;
            let n = list.len();
            let &(_, o) = list.get(i)?;
            if n < 2 {
                continue;
            }
            // Along the loop, the edge runs start to end when `o`: its end
            // meets the next edge's first vertex, its start the previous edge's last.
            let forward = end == o;
            let (other, oo) = if forward { list[(i + 1) % n] } else { list[(i + n - 1) % n] };
            // The neighbour's vertex there: its first along the loop if it comes next.
            let first_of_other = forward == oo;
            let Some(x) = geo.g.find(other) else { continue };
            let Ok(xa) = x.chain(&[("REPRESENTATION_ITEM", 1), ("EDGE", 2)]) else { continue };
            let Ok(v) = xa.ent(if first_of_other { 1 } else { 2 }) else { continue };
            if let Ok(p) = vertex(geo, v) {
                return Some((p, lp));
            }
        }
        None
    }
}

/// An edge's two vertex points, and whether each can be trusted to lie at
/// its end of the curve.
struct Ends {
    ps: DVec3,
    pe: DVec3,
    trust: [bool; 2],
}

/// The vertices some `EDGE_CURVE` gives as both its ends while its curve is
/// an open B-spline whose ends lie far apart: a writer that reuses one vertex
/// for two corners (within its uncertainty). One pass over the file's edges.
fn reused_vertices(geo: &Geo<'_>) -> crate::collections::HashSet<u64> {
    let mut out = crate::collections::HashSet::default();
    for e in geo.g.all().filter(|e| e.has("EDGE_CURVE")) {
        let Ok(a) = e.chain(&[("REPRESENTATION_ITEM", 1), ("EDGE", 2), ("EDGE_CURVE", 2)]) else { continue };
        let (Ok(vs), Ok(ve)) = (a.refr(1), a.refr(2)) else { continue };
        if vs != ve {
            continue;
        }
        let Ok(CurveDef { curve: Curve3::Nurbs { c, closed: false }, range: None, .. }) =
            a.ent(3).and_then(|x| geo.curve(x, 0))
        else {
            continue;
        };
        let (t0, t1) = c.domain();
        let gap = c.point(t0).distance(c.point(t1));
        // Ends half the curve's length apart: an open curve, however
        // coarse the file's uncertainty (one such file's equals the gap).
        if gap > 0.5 * length(&c) {
            out.insert(vs);
        }
    }
    out
}

/// Approximate length of a curve from 16 chords.
pub(super) fn length(c: &NurbsCurve) -> f64 {
    let (a, b) = c.domain();
    let mut prev = c.point(a);
    let mut len = 0.0;
    for k in 1..=16 {
        let p = c.point(a + (b - a) * k as f64 / 16.0);
        len += p.distance(prev);
        prev = p;
    }
    len
}

/// The part of the curve from `ps` to `pe`, along the curve's direction when
/// `same_sense` (against it otherwise); a whole turn when `closed`. Ends
/// within the uncertainty (or 5% of the length) of a vertex are moved onto
/// it, so the faces on both sides of the edge meet at the same points; a
/// vertex farther from the curve is reported as a repair.
///
/// A vertex that cannot be trusted (see [`reused_vertices`]) neither cuts a
/// B-spline, which then runs from its own end, nor moves the curve's end.
fn cut(
    def: &CurveDef,
    verts: &Ends,
    same_sense: bool,
    closed: bool,
    uncertainty: f64,
) -> Result<(Vec<NurbsCurve>, Option<WarningKind>), CurveError> {
    let (ps, pe) = (verts.ps, verts.pe);
    let forward = same_sense != def.reversed;
    let (a, b) = if forward { (ps, pe) } else { (pe, ps) };
    let (trust_a, trust_b) = if forward { (verts.trust[0], verts.trust[1]) } else { (verts.trust[1], verts.trust[0]) };
    let size = a.distance(b);
    let mut pieces = match &def.curve {
        Curve3::Line { .. } => {
            if size == 0.0 {
                return Ok((Vec::new(), None));
            }
            alloc::vec![crate::nurbs::analytic::line(a, b, 0.0, 1.0)?]
        }
        c => {
            let mut ta = param_of(c, a);
            let mut tb = param_of(c, b);
            let whole = closed || (size <= 1e-9 * curve_scale(c) && period(c).is_some());
            match period(c) {
                Some(p) if whole => tb = ta + p,
                // A closed edge on a curve that does not quite close (its
                // ends a rounding apart): the whole curve.
                None if closed => {
                    if let Curve3::Nurbs { c: n, .. } = c {
                        let (x, y) = n.domain();
                        (ta, tb) = (x, y);
                    }
                }
                Some(p) => {
                    tb = ta + (tb - ta) - p * crate::math::floor((tb - ta) / p);
                    if tb <= ta + 1e-12 * p {
                        tb += p;
                    }
                }
                None => {}
            }
            if let (Curve3::Nurbs { c: n, closed: false }, None) = (c, def.range) {
                let (x, y) = n.domain();
                if !trust_a {
                    ta = x;
                }
                if !trust_b {
                    tb = y;
                }
            }
            let scale = match c {
                Curve3::Nurbs { c, .. } => {
                    let (x, y) = c.domain();
                    (y - x).abs()
                }
                _ => 1.0,
            };
            if (tb - ta).abs() <= 1e-10 * scale {
                return Ok((Vec::new(), None)); // a degenerate edge (both vertices at one parameter)
            } else if tb > ta {
                pieces_between(c, ta, tb)?
            } else if ta > tb {
                // The vertices come in the other order along the curve.
                let mut v = pieces_between(c, tb, ta)?;
                rev_all(&mut v)?;
                v
            } else {
                return Ok((Vec::new(), None)); // a degenerate edge (both vertices at one parameter)
            }
        }
    };
    if !forward {
        rev_all(&mut pieces)?;
    }
    // Ends exactly at the vertices.
    let total: f64 = pieces.iter().map(length).sum();
    if total <= 1e-12 * ps.length().max(pe.length()).max(TINY) {
        return Ok((Vec::new(), None));
    }
    // Within the uncertainty, but never a fair part of the edge itself.
    let snap = (0.05 * total).max((2.0 * uncertainty).min(0.25 * total));
    let mut repaired = None;
    let ends = |c: &NurbsCurve| {
        let (t0, t1) = c.domain();
        (c.point(t0), c.point(t1))
    };
    // A vertex farther than that from the curve is wrong in the file (a
    // writer that reuses one vertex for both ends of an open curve): the
    // curve's own end is kept, and the loop bridges what gap is left.
    if let Some(first) = pieces.first_mut() {
        let (s, e) = ends(first);
        let gap = s.distance(ps);
        if !verts.trust[0] {
            if gap > uncertainty {
                repaired = Some(WarningKind::VertexOffCurve { start: true, shared: true, gap });
            }
        } else if gap <= snap {
            *first = move_ends(first, ps, e)?;
        } else {
            repaired = Some(WarningKind::VertexOffCurve { start: true, shared: false, gap });
        }
    }
    if let Some(last) = pieces.last_mut() {
        let (s, e) = ends(last);
        let gap = e.distance(pe);
        if !verts.trust[1] {
            if gap > uncertainty {
                repaired = Some(WarningKind::VertexOffCurve { start: false, shared: true, gap });
            }
        } else if gap <= snap {
            *last = move_ends(last, s, pe)?;
        } else {
            repaired = Some(WarningKind::VertexOffCurve { start: false, shared: false, gap });
        }
    }
    Ok((pieces, repaired))
}

fn curve_scale(c: &Curve3) -> f64 {
    match c {
        Curve3::Line { d, .. } => d.length(),
        Curve3::Conic { x, y, .. } | Curve3::Hyperbola { x, y, .. } | Curve3::Parabola { x, y, .. } => {
            x.length().max(y.length())
        }
        Curve3::Nurbs { c, .. } => c.bbox().diagonal(),
    }
}
