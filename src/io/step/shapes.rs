//! From placed shape items to faces: solids, shells and surface models
//! give their faces (each face's bounds made of oriented edges), geometric
//! sets give their surfaces (whole or rectangular-trimmed). Each item is read
//! once in its own coordinates and then transformed for every placement.
//!
//! A face's loops are its edges' model-space curves in loop order; they are
//! projected into the surface's parameters (paper 001 §3.4) by the face
//! builder the IGES reader shares ([`build_face`]), and the finished face is
//! turned (u and v swapped) when its NURBS normal is not the side the face's
//! `same_sense` says is outside. A face that cannot be read is skipped with
//! a warning naming its `#id`; the others go on.

mod skipped;

use crate::collections::{HashMap, HashSet};
use alloc::boxed::Box;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use glam::{DAffine3, DVec3};

use super::assembly::{Placed, Plan};
use super::curves::{bounded_pieces, rev_all, Geo};
use super::edges::Edges;
use super::graph::{Ent, Graph};
use super::styles::{colours, Rgb};
use super::surfaces::{is_bspline_surface, StepSurface};
use super::{step_error, StepShell, MAX_FACES};
use crate::io::iges::loops::{build_face_oriented, FaceSrc, LoopSrc};
use crate::io::iges::surfaces::{map_surface, SurfDef};
use crate::model::{Face, FaceSurface};
use crate::nurbs::analytic::line;
use crate::nurbs::reparam::map_points;
use crate::nurbs::{NurbsCurve, NurbsError, NurbsSurface};
use crate::warning::{Entity, Warning, WarningKind};
use crate::Error;

/// The faces of one item, in its own coordinates, and its shells as face ranges.
#[derive(Debug, Clone, Default)]
struct ItemFaces {
    faces: Vec<Face>,
    /// The `#id` each face was read from (a face, or a loose surface).
    ids: Vec<u64>,
    /// `(#id, closed, faces, faces listed)` per shell.
    shells: Vec<(u64, bool, core::ops::Range<usize>, usize)>,
    /// Faces skipped: the index their shell gets in `shells`, and their border.
    skipped: Vec<(usize, Vec<NurbsCurve>)>,
}

/// Reading state shared by all items.
struct Reader<'g, 'w> {
    g: &'g Graph,
    edges: Edges,
    warnings: &'w mut Vec<Warning>,
    first_error: Option<Error>,
    /// Edges whose repair was reported.
    repaired: HashSet<u64>,
    /// Edges the loops read so far use, one entry per use.
    edge_uses: Vec<u64>,
}

/// The faces of every placed item, the shells they form, and the first face
/// error (for a file where nothing could be read).
pub(super) struct Shapes {
    pub faces: Vec<Face>,
    /// Index of the placement each face comes from.
    pub placement: Vec<usize>,
    /// Each face's colour: its own style's, else its shell's, else its solid's or set's.
    pub colours: Vec<Option<Rgb>>,
    pub shells: Vec<StepShell>,
    /// Faces skipped, placed: the index of their shell in `shells`, and their border.
    pub skipped: Vec<(usize, Vec<NurbsCurve>)>,
    pub first_error: Option<Error>,
}

/// Reads every placed item.
///
/// # Errors
/// The face limit.
pub(super) fn read_shapes(g: &Graph, plan: &Plan, warnings: &mut Vec<Warning>) -> Result<Shapes, Error> {
    let mut r = Reader {
        g,
        edges: Edges::default(),
        warnings,
        first_error: None,
        repaired: HashSet::default(),
        edge_uses: Vec::new(),
    };
    let mut cache: HashMap<(u64, u64, u64), ItemFaces> = HashMap::default();
    let styles = colours(g);
    let mut out = Shapes {
        faces: Vec::new(),
        placement: Vec::new(),
        colours: Vec::new(),
        shells: Vec::new(),
        skipped: Vec::new(),
        first_error: None,
    };
    let key_of = |p: &Placed| (p.item, p.angle.to_bits(), p.uncertainty.to_bits());
    // How many placements of each item are still ahead: the last one takes
    // the item's faces instead of copying them, so that a part placed once
    // is not held twice while the rest is read.
    let mut ahead: HashMap<(u64, u64, u64), usize> = HashMap::default();
    for p in &plan.placed {
        *ahead.entry(key_of(p)).or_default() += 1;
    }
    for (pi, p) in plan.placed.iter().enumerate() {
        let key = key_of(p);
        if !cache.contains_key(&key) {
            let f = r.item(p);
            cache.insert(key, f);
        }
        let last = ahead.get_mut(&key).is_none_or(|n| {
            *n = n.saturating_sub(1);
            *n == 0
        });
        let mut owned = if last { cache.remove(&key) } else { None };
        let taken: Vec<Face> = owned.as_mut().map(|i| core::mem::take(&mut i.faces)).unwrap_or_default();
        let Some(item) = owned.as_ref().or_else(|| cache.get(&key)) else { continue };
        let count = if owned.is_some() { taken.len() } else { item.faces.len() };
        if out.faces.len() + count > MAX_FACES {
            return Err(step_error(
                p.item,
                g.line_of(p.item),
                format!("more than {MAX_FACES} faces (after assembly instancing)"),
            ));
        }
        let base = out.faces.len();
        let mut taken = taken.into_iter();
        for (k, id) in item.ids.iter().enumerate().take(count) {
            let placed = match taken.next() {
                Some(f) if p.m == DAffine3::IDENTITY => Ok(f),
                Some(f) => place_face(&f, &p.m),
                None => match item.faces.get(k) {
                    Some(f) => place_face(f, &p.m),
                    None => continue,
                },
            };
            match placed {
                Ok(f) => {
                    out.faces.push(f);
                    out.placement.push(pi);
                    let shell = item.shells.iter().find(|s| s.2.contains(&k)).map(|s| s.0);
                    let colour =
                        [Some(*id), shell, Some(p.item)].into_iter().flatten().find_map(|i| styles.get(&i).copied());
                    out.colours.push(colour);
                }
                Err(m) => r.warnings.push(Warning::entity(Entity::step_id(p.item), WarningKind::FaceNotPlaced(m))),
            }
        }
        let placed = out.faces.len() - base;
        let shell_base = out.shells.len();
        for (k, border) in &item.skipped {
            out.skipped.push((shell_base + k, skipped::place_border(border, &p.m)));
        }
        for (id, closed, range, listed) in &item.shells {
            // Faces that could not be placed shorten the ranges (rarely: a non-finite transform).
            let s = (base + range.start).min(base + placed);
            let e = (base + range.end).min(base + placed);
            out.shells.push(StepShell { id: *id, closed: *closed, faces: s..e, listed: *listed });
        }
    }
    out.first_error = r.first_error;
    Ok(out)
}

impl Reader<'_, '_> {
    fn skip(&mut self, e: Ent<'_>, err: Error) {
        if self.first_error.is_none() {
            self.first_error = Some(err.clone());
        }
        self.warnings.push(Warning::entity(Entity::step(e.id(), e.type_name()), WarningKind::Skipped(err)));
    }

    /// The faces of one shape item.
    fn item(&mut self, p: &Placed) -> ItemFaces {
        let mut out = ItemFaces::default();
        let Some(e) = self.g.find(p.item) else { return out };
        let geo = Geo { g: self.g, angle: p.angle, uncertainty: p.uncertainty };
        if let Err(err) = self.item_into(&geo, e, &mut out, 0) {
            self.skip(e, err);
        }
        out
    }

    fn item_into(&mut self, geo: &Geo<'_>, e: Ent<'_>, out: &mut ItemFaces, depth: usize) -> Result<(), Error> {
        if depth > super::MAX_DEPTH {
            return Err(e.error("shapes nested too deeply (a reference cycle?)"));
        }
        if e.has("MANIFOLD_SOLID_BREP") || e.has("FACETED_BREP") || e.has("BREP_WITH_VOIDS") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("MANIFOLD_SOLID_BREP", 1)])?;
            self.shell(geo, a.ent(1)?, false, out)?;
            if e.has("BREP_WITH_VOIDS") {
                let voids = match e.part("BREP_WITH_VOIDS") {
                    Some(v) if e.is_complex() => v.refs(0)?,
                    _ => e.attrs().refs(2)?,
                };
                for v in voids {
                    self.shell(geo, self.g.get(v, e.id())?, false, out)?;
                }
            }
            return Ok(());
        }
        if e.has("SHELL_BASED_SURFACE_MODEL") || e.has("FACE_BASED_SURFACE_MODEL") {
            let kind = if e.has("SHELL_BASED_SURFACE_MODEL") {
                "SHELL_BASED_SURFACE_MODEL"
            } else {
                "FACE_BASED_SURFACE_MODEL"
            };
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), (kind, 1)])?;
            for s in a.refs(1)? {
                let s = self.g.get(s, e.id())?;
                if let Err(err) = self.shell(geo, s, false, out) {
                    self.skip(s, err);
                }
            }
            return Ok(());
        }
        if e.has("CLOSED_SHELL")
            || e.has("OPEN_SHELL")
            || e.has("CONNECTED_FACE_SET")
            || e.has("ORIENTED_CLOSED_SHELL")
            || e.has("ORIENTED_OPEN_SHELL")
        {
            return self.shell(geo, e, false, out);
        }
        if e.has("GEOMETRIC_SET") || e.has("GEOMETRIC_CURVE_SET") {
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("GEOMETRIC_SET", 1)])?;
            let start = out.faces.len();
            let mut listed = 0;
            for r in a.refs(1)? {
                let s = self.g.get(r, e.id())?;
                if is_face(s)
                    || is_bspline_surface(s)
                    || s.has("RECTANGULAR_TRIMMED_SURFACE")
                    || s.has("CURVE_BOUNDED_SURFACE")
                    || is_surface(s)
                {
                    listed += 1;
                    self.face_or_surface(geo, s, out);
                } else if s.has("SHELL_BASED_SURFACE_MODEL") || s.has("CLOSED_SHELL") || s.has("OPEN_SHELL") {
                    self.item_into(geo, s, out, depth + 1)?;
                }
            }
            if listed > 0 {
                out.shells.push((e.id(), false, start..out.faces.len(), listed));
            }
            return Ok(());
        }
        // A face or surface on its own.
        let start = out.faces.len();
        self.face_or_surface(geo, e, out);
        out.shells.push((e.id(), false, start..out.faces.len(), 1));
        Ok(())
    }

    /// A face, or a loose surface (whole or rectangular-trimmed).
    fn face_or_surface(&mut self, geo: &Geo<'_>, s: Ent<'_>, out: &mut ItemFaces) {
        let r = if is_face(s) { self.face(geo, s, false) } else { self.loose_surface(geo, s) };
        match r {
            Ok(f) => {
                out.faces.push(f);
                out.ids.push(s.id());
            }
            Err(err) => {
                self.skip(s, err);
                let border = self.skipped_border(geo, s);
                out.skipped.push((out.shells.len(), border));
            }
        }
    }

    /// A shell's faces; `flip` turns every face over (oriented shells).
    fn shell(&mut self, geo: &Geo<'_>, s: Ent<'_>, flip: bool, out: &mut ItemFaces) -> Result<(), Error> {
        if s.has("ORIENTED_CLOSED_SHELL") || s.has("ORIENTED_OPEN_SHELL") {
            let a = s.attrs();
            let inner = a.ent(2)?;
            let orientation = a.boolean(3, true)?;
            if inner.has("ORIENTED_CLOSED_SHELL") || inner.has("ORIENTED_OPEN_SHELL") {
                return Err(s.error("oriented shell of an oriented shell"));
            }
            return self.shell(geo, inner, flip ^ !orientation, out);
        }
        let closed = s.has("CLOSED_SHELL");
        if !(closed || s.has("OPEN_SHELL") || s.has("CONNECTED_FACE_SET")) {
            return Err(s.error("expected a shell"));
        }
        let a = s.chain(&[("REPRESENTATION_ITEM", 1), ("CONNECTED_FACE_SET", 1)])?;
        let list = a.refs(1)?;
        let start = out.faces.len();
        self.edge_uses.clear();
        for f in &list {
            let fe = self.g.get(*f, s.id())?;
            match self.face(geo, fe, flip) {
                Ok(face) => {
                    out.faces.push(face);
                    out.ids.push(fe.id());
                }
                Err(err) => {
                    self.skip(fe, err);
                    let border = self.skipped_border(geo, fe);
                    out.skipped.push((out.shells.len(), border));
                }
            }
        }
        // A closed shell uses each of its edges twice; one whose faces leave
        // edges used once is open whatever the file calls it.
        let mut count: HashMap<u64, u32> = HashMap::default();
        for &e in &self.edge_uses {
            *count.entry(e).or_default() += 1;
        }
        let once = count.values().filter(|&&c| c == 1).count();
        let closed = if closed && once > 0 && out.faces.len() - start == list.len() {
            let open = WarningKind::ShellOpen { edges: once };
            self.warnings.push(Warning::entity(Entity::step(s.id(), "CLOSED_SHELL"), open));
            false
        } else {
            closed
        };
        out.shells.push((s.id(), closed, start..out.faces.len(), list.len()));
        Ok(())
    }

    /// One face of a shell.
    fn face(&mut self, geo: &Geo<'_>, e: Ent<'_>, flip: bool) -> Result<Face, Error> {
        if e.has("ORIENTED_FACE") {
            let a = e.attrs();
            let inner = a.ent(2)?;
            if inner.has("ORIENTED_FACE") {
                return Err(e.error("oriented face of an oriented face"));
            }
            return self.face(geo, inner, flip ^ !a.boolean(3, true)?);
        }
        if !(e.has("FACE_SURFACE") || e.has("ADVANCED_FACE")) {
            return Err(e.error("expected a face with a surface (ADVANCED_FACE or FACE_SURFACE)"));
        }
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("FACE", 1), ("FACE_SURFACE", 2)])?;
        let mut loops = Vec::new();
        for b in a.refs(1)? {
            let be = self.g.get(b, e.id())?;
            if let Some(lp) = self.bound(geo, be)? {
                loops.push(lp);
            }
        }
        let points: Vec<DVec3> = loops.iter().flat_map(|l| l.model.iter()).flat_map(sample3).collect();
        let surf = geo.surface(a.ent(2)?, &points, 0)?;
        let same_sense = a.boolean(3, true)? != flip;
        let face = self.build(geo, e, surf, loops, same_sense, false)?;
        Ok(named(face, a.string(0).unwrap_or(""), e.id()))
    }

    /// Builds the face and turns it to the side `same_sense` asks for.
    fn build(
        &mut self,
        geo: &Geo<'_>,
        e: Ent<'_>,
        surf: StepSurface,
        loops: Vec<LoopSrc>,
        same_sense: bool,
        domain_outer: bool,
    ) -> Result<Face, Error> {
        let resolution = (geo.uncertainty > 0.0).then_some(geo.uncertainty);
        let src = FaceSrc { def: surf.def, native: surf.native, loops, domain_outer, resolution };
        let mut local = Vec::new();
        // The face lies on the left of its (oriented) loops, seen from its
        // normal; in the definition's coordinates that is the left when its
        // normal is the face's.
        let r = build_face_oriented(src, Some(surf.flipped != same_sense), &mut local);
        for w in local {
            self.warnings.push(Warning::entity(Entity::step(e.id(), e.type_name()), w));
        }
        let mut face = r.map_err(|m| e.error(m))?;
        // The NURBS normal is the STEP surface's unless flipped; the face's
        // outside is the surface's when same_sense.
        if surf.flipped == same_sense {
            transpose_face(&mut face).map_err(|m| e.error(format!("{m}")))?;
        }
        Ok(face)
    }

    /// A `FACE_BOUND` / `FACE_OUTER_BOUND`: its edges' curves in loop order;
    /// `None` for a vertex loop (a single point bounds nothing).
    fn bound(&mut self, geo: &Geo<'_>, b: Ent<'_>) -> Result<Option<LoopSrc>, Error> {
        if !b.has("FACE_BOUND") && !b.has("FACE_OUTER_BOUND") {
            return Err(b.error("expected a FACE_BOUND"));
        }
        let a = b.chain(&[("REPRESENTATION_ITEM", 1), ("FACE_BOUND", 2)])?;
        let lp = a.ent(1)?;
        let forward = a.boolean(2, true)?;
        let mut model: Vec<NurbsCurve> = Vec::new();
        if lp.has("EDGE_LOOP") {
            let la = match lp.part("EDGE_LOOP") {
                Some(p) if lp.is_complex() => p,
                _ => {
                    let mut x = lp.attrs();
                    x.vals.drain(..1.min(x.vals.len()));
                    x
                }
            };
            let mut uses = Vec::new();
            for r in la.refs(0)? {
                let oe = self.g.get(r, lp.id())?;
                let (edge, orientation) = if oe.has("ORIENTED_EDGE") {
                    let oa = oe.attrs();
                    (oa.ent(3)?, oa.boolean(4, true)?)
                } else {
                    (oe, true)
                };
                uses.push((oe, edge, orientation));
            }
            // A loop that runs along each of its edges both ways is a slit
            // (a cut the face's region is on both sides of): it bounds nothing.
            let slit = !uses.is_empty()
                && uses.iter().all(|(_, e, o)| uses.iter().any(|(_, f, p)| f.id() == e.id() && p != o));
            if slit {
                self.warnings.push(Warning::entity(Entity::step(lp.id(), "EDGE_LOOP"), WarningKind::LoopSlit));
                return Ok(None);
            }
            // An edge used out and straight back (a dangling edge inside the
            // face) encloses nothing: both uses go.
            let mut spikes = 0;
            while uses.len() > 2 {
                let n = uses.len();
                let Some(i) =
                    (0..n).find(|&i| uses[i].1.id() == uses[(i + 1) % n].1.id() && uses[i].2 != uses[(i + 1) % n].2)
                else {
                    break;
                };
                let j = (i + 1) % n;
                uses.remove(i.max(j));
                uses.remove(i.min(j));
                spikes += 1;
            }
            if spikes > 0 {
                let kind = WarningKind::LoopSpikes { edges: spikes };
                self.warnings.push(Warning::entity(Entity::step(lp.id(), "EDGE_LOOP"), kind));
            }
            let alone = uses.len() == 1;
            for (oe, edge, orientation) in uses {
                self.edge_uses.push(edge.id());
                let ed = self.edges.get(geo, edge, alone)?;
                if let Some(m) = &ed.repaired {
                    if self.repaired.insert(edge.id()) {
                        self.warnings.push(Warning::entity(Entity::step(edge.id(), "EDGE_CURVE"), m.clone()));
                    }
                }
                let mut pieces = ed.pieces.clone();
                if !orientation {
                    rev_all(&mut pieces).map_err(|m| oe.error(m))?;
                }
                model.extend(pieces);
            }
        } else if lp.has("POLY_LOOP") {
            let pa = lp.chain(&[("REPRESENTATION_ITEM", 1), ("POLY_LOOP", 1)])?;
            let mut pts = Vec::new();
            for r in pa.refs(1)? {
                pts.push(geo.point(self.g.get(r, lp.id())?)?);
            }
            for i in 0..pts.len() {
                let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
                if p != q {
                    model.push(line(p, q, 0.0, 1.0).map_err(|x| lp.error(format!("{x}")))?);
                }
            }
        } else if lp.has("VERTEX_LOOP") {
            return Ok(None);
        } else {
            return Err(lp.error("is not a supported loop (EDGE_LOOP, POLY_LOOP or VERTEX_LOOP)"));
        }
        if model.is_empty() {
            return Ok(None);
        }
        bridge_gaps(&mut model, lp, self.warnings).map_err(|m| lp.error(m))?;
        if !forward {
            rev_all(&mut model).map_err(|m| b.error(m))?;
        }
        Ok(Some(LoopSrc { model, params: None }))
    }

    /// A surface outside any face: whole or rectangular-trimmed.
    fn loose_surface(&mut self, geo: &Geo<'_>, s: Ent<'_>) -> Result<Face, Error> {
        // The boundary first: a surface of unbounded extent (an extrusion)
        // takes its range from the points of the curves that bound it.
        let mut bounds = Vec::new();
        let mut domain_outer = false;
        if s.has("CURVE_BOUNDED_SURFACE") {
            let a = s.chain(&[("REPRESENTATION_ITEM", 1), ("CURVE_BOUNDED_SURFACE", 3)])?;
            domain_outer = a.boolean(3, false)?;
            for b in a.refs(2)? {
                bounds.push(self.boundary_curve(geo, self.g.get(b, s.id())?)?);
            }
        }
        let points: Vec<DVec3> = bounds.iter().flat_map(|l| l.model.iter()).flat_map(sample3).collect();
        let surf = geo.surface(s, &points, 0)?;
        let mut loops = Vec::new();
        if s.has("RECTANGULAR_TRIMMED_SURFACE") {
            let a = s.chain(&[("REPRESENTATION_ITEM", 1), ("RECTANGULAR_TRIMMED_SURFACE", 7)])?;
            let (mut u1, mut u2, v1, v2) = (a.real(2)?, a.real(3)?, a.real(4)?, a.real(5)?);
            let revolution = matches!(surf.def, SurfDef::Revolution(_));
            if revolution {
                u1 *= geo.angle;
                u2 *= geo.angle;
            }
            // STEP (u, v) in the definition's own coordinates: revolutions run (profile, angle).
            let at = |u: f64, v: f64| if revolution { DVec3::new(v, u, 0.0) } else { DVec3::new(u, v, 0.0) };
            let c = [at(u1, v1), at(u2, v1), at(u2, v2), at(u1, v2)];
            let mut params = Vec::new();
            for k in 0..4 {
                params.push(line(c[k], c[(k + 1) % 4], 0.0, 1.0).map_err(|x| s.error(format!("{x}")))?);
            }
            loops.push(LoopSrc { model: Vec::new(), params: Some(params) });
        }
        loops.extend(bounds);
        let mut surf = surf;
        if s.has("RECTANGULAR_TRIMMED_SURFACE") {
            surf.native = true;
        }
        let face = self.build(geo, s, surf, loops, true, domain_outer)?;
        let name = s.chain(&[("REPRESENTATION_ITEM", 1)]).ok().and_then(|a| a.string(0).ok().map(String::from));
        Ok(named(face, name.as_deref().unwrap_or(""), s.id()))
    }
}

impl Reader<'_, '_> {
    /// A `BOUNDARY_CURVE` of a curve-bounded surface: its segments' model
    /// curves in order (a `SURFACE_CURVE`'s 3-D curve), or their parameter
    /// curves when every segment is a `PCURVE` alone.
    fn boundary_curve(&mut self, geo: &Geo<'_>, b: Ent<'_>) -> Result<LoopSrc, Error> {
        let a = b.chain(&[("REPRESENTATION_ITEM", 1), ("COMPOSITE_CURVE", 2)])?;
        let (mut model, mut params) = (Vec::new(), Vec::new());
        for r in a.refs(1)? {
            let seg = self.g.get(r, b.id())?;
            if !seg.has("COMPOSITE_CURVE_SEGMENT") {
                return Err(seg.error("expected a COMPOSITE_CURVE_SEGMENT"));
            }
            let sa = seg.attrs();
            let same = sa.boolean(1, true)?;
            let parent = sa.ent(2)?;
            let (def, two_d) =
                if parent.has("PCURVE") { (pcurve_2d(geo, parent)?, true) } else { (geo.curve(parent, 0)?, false) };
            let mut pieces = bounded_pieces(&def).map_err(|m| parent.error(m))?;
            if !same {
                rev_all(&mut pieces).map_err(|m| seg.error(m))?;
            }
            if two_d {
                params.extend(pieces)
            } else {
                model.extend(pieces)
            }
        }
        match (model.is_empty(), params.is_empty()) {
            (false, true) => {
                bridge_gaps(&mut model, b, self.warnings).map_err(|m| b.error(m))?;
                Ok(LoopSrc { model, params: None })
            }
            (true, false) => Ok(LoopSrc { model, params: Some(params) }),
            _ => Err(b.error("a boundary mixing parameter curves and model curves")),
        }
    }
}

/// The 2-D curve of a `PCURVE`: the first curve of its definitional representation.
fn pcurve_2d(geo: &Geo<'_>, e: Ent<'_>) -> Result<super::curves::CurveDef, Error> {
    let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("PCURVE", 2)])?;
    let rep = a.ent(2)?;
    let items = rep.chain(&[("REPRESENTATION", 3)])?.refs(1)?;
    for r in items {
        let item = geo.g.get(r, rep.id())?;
        if item.has("CARTESIAN_POINT") || item.has("AXIS2_PLACEMENT_2D") {
            continue;
        }
        return geo.curve(item, 1);
    }
    Err(e.error("its definitional representation holds no curve"))
}

/// Joins consecutive curves of a loop whose ends are apart (a file whose
/// loop skips from one vertex to another) by straight model-space pieces,
/// which are then projected like the edges.
fn bridge_gaps(model: &mut Vec<NurbsCurve>, lp: Ent<'_>, warnings: &mut Vec<Warning>) -> Result<(), NurbsError> {
    let mut bb = crate::nurbs::Aabb::EMPTY;
    for c in model.iter() {
        bb.union(&c.bbox());
    }
    let hair = 1e-7 * bb.diagonal();
    let ends = |c: &NurbsCurve| {
        let (a, b) = c.domain();
        (c.point(a), c.point(b))
    };
    let n = model.len();
    let mut out = Vec::with_capacity(n + 1);
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let c = model[i].clone();
        let (_, e) = ends(&c);
        let (s, _) = ends(&model[(i + 1) % n]);
        out.push(c);
        let gap = e.distance(s);
        if gap > hair {
            worst = worst.max(gap);
            out.push(line(e, s, 0.0, 1.0)?);
        }
    }
    if worst > 0.0 {
        let kind = WarningKind::LoopGapBridged { gap: worst };
        warnings.push(Warning::entity(Entity::step(lp.id(), "EDGE_LOOP"), kind));
    }
    *model = out;
    Ok(())
}

/// Whether the loose surface `e` is one this reader can mesh on its own.
fn is_surface(e: Ent<'_>) -> bool {
    [
        "PLANE",
        "CYLINDRICAL_SURFACE",
        "CONICAL_SURFACE",
        "SPHERICAL_SURFACE",
        "TOROIDAL_SURFACE",
        "SURFACE_OF_REVOLUTION",
    ]
    .iter()
    .any(|n| e.has(n))
        && e.has("RECTANGULAR_TRIMMED_SURFACE")
}

fn is_face(e: Ent<'_>) -> bool {
    e.has("ADVANCED_FACE") || e.has("FACE_SURFACE") || e.has("ORIENTED_FACE")
}

/// The face named by the file, or by its `#id` where the name is empty or a placeholder.
fn named(mut face: Face, name: &str, id: u64) -> Face {
    let name = name.trim();
    face.name = Some(if name.is_empty() || name.eq_ignore_ascii_case("NONE") { format!("#{id}") } else { name.into() });
    face
}

/// Nine points along a curve, for the extent of the surface under it.
fn sample3(c: &NurbsCurve) -> impl Iterator<Item = DVec3> + '_ {
    let (a, b) = c.domain();
    (0..=8).map(move |k| c.point(a + (b - a) * k as f64 / 8.0))
}

/// Swaps the surface's u and v (which turns its normal over) and the loops' coordinates.
fn transpose_face(face: &mut Face) -> Result<(), NurbsError> {
    face.surface = transpose(&face.surface)?;
    for lp in &mut face.loops {
        for c in &mut lp.curves {
            *c = map_points(c, |p| DVec3::new(p.y, p.x, 0.0))?;
        }
    }
    Ok(())
}

fn transpose(s: &FaceSurface) -> Result<FaceSurface, NurbsError> {
    match s {
        FaceSurface::Nurbs(n) => Ok(FaceSurface::Nurbs(transpose_nurbs(n)?)),
        FaceSurface::Rebuilt(n) => Ok(FaceSurface::Rebuilt(transpose_nurbs(n)?)),
        // The transposed base's normal is the opposite one: the offset keeps its side.
        FaceSurface::Offset { base, distance } => {
            Ok(FaceSurface::Offset { base: Box::new(transpose(base)?), distance: -*distance })
        }
    }
}

fn transpose_nurbs(s: &NurbsSurface) -> Result<NurbsSurface, NurbsError> {
    let [nu, nv] = s.counts();
    let mut pts = Vec::with_capacity(nv);
    let mut ws = Vec::with_capacity(nv);
    for j in 0..nv {
        let mut row = Vec::with_capacity(nu);
        let mut wrow = Vec::with_capacity(nu);
        for i in 0..nu {
            let h = s.homogeneous(i, j);
            row.push(h.truncate() / h.w);
            wrow.push(h.w);
        }
        pts.push(row);
        ws.push(wrow);
    }
    let w = s.is_rational().then_some(ws.as_slice());
    NurbsSurface::from_parts(s.knots_v().clone(), s.knots_u().clone(), &pts, w)
}

/// The face moved by an affine map: control points mapped (exact), offsets
/// scaled; a mirror turns the surface's normal, so the face is turned back.
fn place_face(f: &Face, m: &DAffine3) -> Result<Face, NurbsError> {
    if *m == DAffine3::IDENTITY {
        return Ok(f.clone());
    }
    let scale = libm::cbrt(m.matrix3.determinant().abs());
    let mut out =
        Face { name: f.name.clone(), surface: map_face_surface(&f.surface, m, scale)?, loops: f.loops.clone() };
    if m.matrix3.determinant() < 0.0 {
        transpose_face(&mut out)?;
    }
    Ok(out)
}

fn map_face_surface(s: &FaceSurface, m: &DAffine3, scale: f64) -> Result<FaceSurface, NurbsError> {
    match s {
        FaceSurface::Nurbs(n) => Ok(FaceSurface::Nurbs(map_surface(n, m)?)),
        FaceSurface::Rebuilt(n) => Ok(FaceSurface::Rebuilt(map_surface(n, m)?)),
        // Under a mirror the mapped base's normal is the mirror image's
        // opposite; the offset follows the base, so its sign turns too.
        FaceSurface::Offset { base, distance } => {
            let d = if m.matrix3.determinant() < 0.0 { -*distance * scale } else { *distance * scale };
            Ok(FaceSurface::Offset { base: Box::new(map_face_surface(base, m, scale)?), distance: d })
        }
    }
}
