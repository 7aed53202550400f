//! AP242 tessellated geometry (ISO 10303-42, tessellated items): faces
//! given as triangles over a `COORDINATES_LIST`, on their own or grouped
//! in a `TESSELLATED_SHELL` or `TESSELLATED_SOLID`.
//!
//! What the attributes mean, as ISO 10303-42 defines them:
//! - `TRIANGULATED_FACE(name, coordinates, pnmax, normals, geometric_link,
//!   pnindex, triangles)`; a `COMPLEX_TRIANGULATED_FACE` has
//!   `triangle_strips, triangle_fans` in place of `triangles`; the surface
//!   sets (`TRIANGULATED_SURFACE_SET`, `COMPLEX_TRIANGULATED_SURFACE_SET`)
//!   are the same without `geometric_link`.
//! - The face's points: `pnindex` lists, 1-based, the coordinates it uses;
//!   empty, the face uses the coordinates list itself. `pnmax` is how many
//!   points that is, and every triangle, strip and fan index is a 1-based
//!   index into those points.
//! - `normals`: none, one for the whole face (a plane), or one per point.
//! - A strip `(p1, p2, p3, p4, …)` is the triangles `(p1, p2, p3)`,
//!   `(p3, p2, p4)`, `(p3, p4, p5)`, …: every second one turned so that all
//!   face the way the first does; a fan `(p1, p2, p3, p4, …)` is `(p1, p2,
//!   p3)`, `(p1, p3, p4)`, …. A triangle that names one point twice (how
//!   strips are joined) is no triangle.
//! - `geometric_link` names the exact face or surface the triangles stand
//!   for; a `TESSELLATED_SOLID`'s names its `MANIFOLD_SOLID_BREP`. Where the
//!   file gives the exact one too, the exact one is meshed and the triangles
//!   are left out.
//!
//! Malformed lists (an index of 0, below 0 or past the points, a count that
//! does not match) skip the face with a warning naming its `#id` and line.

use crate::collections::{HashMap, HashSet};
use alloc::format;
use alloc::vec::Vec;
use core::ops::Range;
use glam::{DAffine3, DVec3};

use super::assembly::Plan;
use super::graph::{Attrs, Ent, Graph, Value};
use super::styles::{colours, Rgb};
use super::{StepShell, MAX_CONTROL_POINTS, MAX_DEPTH, MAX_FACES};
use crate::model::TessellatedFace;
use crate::warning::{Entity, Warning, WarningKind};
use crate::Error;

/// Entity names of the tessellated items this reader turns into faces.
const ITEMS: [&str; 6] = [
    "TESSELLATED_SOLID",
    "TESSELLATED_SHELL",
    "TRIANGULATED_FACE",
    "COMPLEX_TRIANGULATED_FACE",
    "TRIANGULATED_SURFACE_SET",
    "COMPLEX_TRIANGULATED_SURFACE_SET",
];

/// Most triangles the tessellated faces may have together, after assembly
/// instancing: a part of a million triangles placed a hundred times is
/// more than a page can hold, and the file gives no way to share them.
pub(crate) const MAX_TRIANGLES: usize = 50_000_000;

/// Whether `e` is a tessellated item this reader reads.
pub(super) fn is_tessellated(e: Ent<'_>) -> bool {
    ITEMS.iter().any(|n| e.has(n))
}

/// The tessellated faces of every placed item, in placement order.
#[derive(Debug, Default)]
pub(super) struct Facets {
    pub faces: Vec<TessellatedFace>,
    /// Index (in the plan read) of the placement each face comes from.
    pub placement: Vec<usize>,
    /// Each face's colour: its own style's, else its shell's or solid's.
    pub colours: Vec<Option<Rgb>>,
    /// Per face: whether it is a representation's item on its own (in no
    /// tessellated shell or solid).
    pub loose: Vec<bool>,
    /// Tessellated shells and solids, their faces as ranges of `faces`.
    pub shells: Vec<StepShell>,
}

/// The faces of one item in its own coordinates.
#[derive(Debug, Clone, Default)]
struct ItemFacets {
    faces: Vec<TessellatedFace>,
    /// The `#id` each face was read from.
    ids: Vec<u64>,
    /// `(#id, closed, faces, faces listed)` of the shell or solid the item is.
    group: Option<(u64, bool, Range<usize>, usize)>,
}

/// Reading state shared by all items.
struct Reader<'g, 'w> {
    g: &'g Graph,
    warnings: &'w mut Vec<Warning>,
    /// Coordinates lists read so far, by `#id` (many faces share one).
    coordinates: HashMap<u64, Result<Vec<DVec3>, Error>>,
    /// The exact faces and solids the file also gives.
    exact: &'w HashSet<u64>,
    /// Triangles read so far (after instancing).
    triangles: usize,
}

/// Reads every tessellated item `plan` places. `exact`: the `#id`s of the
/// exact faces, shells and solids read from the file; triangles whose
/// geometric link names one of them are left out.
pub(super) fn read(g: &Graph, plan: &Plan, exact: &HashSet<u64>, warnings: &mut Vec<Warning>) -> Facets {
    let styles = colours(g);
    // Faces a tessellated shell or solid holds are not read again where a
    // representation lists them on their own (as for exact faces).
    let mut grouped: HashSet<u64> = HashSet::default();
    for e in g.all() {
        if e.has("TESSELLATED_SHELL") || e.has("TESSELLATED_SOLID") {
            if let Ok(a) = group_attrs(e) {
                grouped.extend(a.refs(1).unwrap_or_default());
            }
        }
    }
    let mut r = Reader { g, warnings, coordinates: HashMap::default(), exact, triangles: 0 };
    let mut cache: HashMap<u64, ItemFacets> = HashMap::default();
    let mut out = Facets::default();
    for (pi, p) in plan.placed.iter().enumerate() {
        if grouped.contains(&p.item) {
            continue;
        }
        if !cache.contains_key(&p.item) {
            let item = r.item(p.item);
            cache.insert(p.item, item);
        }
        let Some(item) = cache.get(&p.item) else { continue };
        let count: usize = item.faces.iter().map(|f| f.triangles.len()).sum();
        if out.faces.len() + item.faces.len() > MAX_FACES || r.triangles + count > MAX_TRIANGLES {
            let kind = WarningKind::TessellatedLimit { faces: MAX_FACES, triangles: MAX_TRIANGLES };
            r.warnings.push(Warning::entity(Entity::step_id(p.item), kind));
            break;
        }
        r.triangles += count;
        let base = out.faces.len();
        for (f, id) in item.faces.iter().zip(&item.ids) {
            out.faces.push(place(f, &p.m));
            out.placement.push(pi);
            out.loose.push(item.group.is_none());
            let group = item.group.as_ref().map(|s| s.0);
            let colour = [Some(*id), group, Some(p.item)].into_iter().flatten().find_map(|i| styles.get(&i).copied());
            out.colours.push(colour);
        }
        if let Some((id, closed, range, listed)) = &item.group {
            let faces = base + range.start..base + range.end;
            out.shells.push(StepShell { id: *id, closed: *closed, faces, listed: *listed });
        }
    }
    out
}

/// The attributes of a tessellated shell or solid: name, items, link.
fn group_attrs(e: Ent<'_>) -> Result<Attrs<'_>, Error> {
    let own = if e.has("TESSELLATED_SOLID") { "TESSELLATED_SOLID" } else { "TESSELLATED_SHELL" };
    e.chain(&[("REPRESENTATION_ITEM", 1), (own, 2)])
}

/// The face moved by an affine map; a mirror turns its triangles back to face out.
fn place(f: &TessellatedFace, m: &DAffine3) -> TessellatedFace {
    if *m == DAffine3::IDENTITY {
        return f.clone();
    }
    let normal_map = m.matrix3.inverse().transpose();
    let mirror = m.matrix3.determinant() < 0.0;
    TessellatedFace {
        name: f.name.clone(),
        positions: f.positions.iter().map(|&p| m.transform_point3(p)).collect(),
        normals: f.normals.iter().map(|&n| (normal_map * n).normalize_or_zero()).collect(),
        triangles: f.triangles.iter().map(|&[a, b, c]| if mirror { [a, c, b] } else { [a, b, c] }).collect(),
    }
}

impl Reader<'_, '_> {
    fn skip(&mut self, e: Ent<'_>, err: &Error) {
        self.warnings.push(Warning::entity(Entity::step(e.id(), e.type_name()), WarningKind::Skipped(err.clone())));
    }

    /// The faces of one placed tessellated item.
    fn item(&mut self, id: u64) -> ItemFacets {
        let mut out = ItemFacets::default();
        let Some(e) = self.g.find(id) else { return out };
        if e.has("TESSELLATED_SOLID") || e.has("TESSELLATED_SHELL") {
            let closed = e.has("TESSELLATED_SOLID");
            let a = match group_attrs(e) {
                Ok(a) => a,
                Err(err) => {
                    self.skip(e, &err);
                    return out;
                }
            };
            // A solid whose exact solid the file gives too is that solid again.
            if closed && a.opt_ref(2).ok().flatten().is_some_and(|l| self.exact.contains(&l)) {
                return out;
            }
            let items = match a.refs(1) {
                Ok(items) => items,
                Err(err) => {
                    self.skip(e, &err);
                    return out;
                }
            };
            let mut listed = 0;
            for r in items {
                let Some(f) = self.g.find(r) else {
                    let kind = WarningKind::ItemUndefined { item: r };
                    self.warnings.push(Warning::entity(Entity::step_id(e.id()), kind));
                    continue;
                };
                if is_face(f) {
                    listed += 1;
                    self.face_into(f, &mut out);
                } else if f.has("CUBIC_BEZIER_TRIANGULATED_FACE") || f.has("TESSELLATED_FACE") {
                    let kind = WarningKind::ItemUnsupported;
                    self.warnings.push(Warning::entity(Entity::step(f.id(), f.type_name()), kind));
                }
                // Tessellated edges and vertices bound faces; they add no surface.
            }
            out.group = Some((e.id(), closed, 0..out.faces.len(), listed));
        } else if is_face(e) {
            self.face_into(e, &mut out);
        }
        out
    }

    /// Reads face `e` into `out`, or skips it with a warning.
    fn face_into(&mut self, e: Ent<'_>, out: &mut ItemFacets) {
        match self.face(e) {
            Ok(Some(f)) => {
                out.faces.push(f);
                out.ids.push(e.id());
            }
            Ok(None) => {}
            Err(err) => self.skip(e, &err),
        }
    }

    /// One tessellated face or surface set; `None` when its exact face is read instead.
    fn face(&mut self, e: Ent<'_>) -> Result<Option<TessellatedFace>, Error> {
        let set = e.has("TRIANGULATED_SURFACE_SET") || e.has("COMPLEX_TRIANGULATED_SURFACE_SET");
        let complex = e.has("COMPLEX_TRIANGULATED_FACE") || e.has("COMPLEX_TRIANGULATED_SURFACE_SET");
        let own = match (set, complex) {
            (false, false) => ("TRIANGULATED_FACE", 2),
            (false, true) => ("COMPLEX_TRIANGULATED_FACE", 3),
            (true, false) => ("TRIANGULATED_SURFACE_SET", 2),
            (true, true) => ("COMPLEX_TRIANGULATED_SURFACE_SET", 3),
        };
        let base = if set { ("TESSELLATED_SURFACE_SET", 3) } else { ("TESSELLATED_FACE", 4) };
        let a = e.chain(&[("REPRESENTATION_ITEM", 1), base, own])?;
        // Attribute places: the sets have no geometric link.
        let at = if set { 4 } else { 5 };
        if !set {
            if let Some(link) = a.opt_ref(4).ok().flatten() {
                if self.exact.contains(&link) {
                    return Ok(None);
                }
            }
        }
        let points = self.points(e, &a, at)?;
        let n = points.len();
        let (triangles, repeated) = self.triangles(e, &a, at, complex, n)?;
        if triangles.is_empty() {
            return Err(e.error("has no triangles"));
        }
        if repeated > 0 {
            let kind = WarningKind::RepeatedPointTriangles { count: repeated };
            self.warnings.push(Warning::entity(Entity::step(e.id(), e.type_name()), kind));
        }
        let normals = self.normals(e, &a, n)?;
        let name = a.string(0).unwrap_or("").trim();
        let name =
            if name.is_empty() || name.eq_ignore_ascii_case("NONE") { format!("#{}", e.id()) } else { name.into() };
        Ok(Some(TessellatedFace { name: Some(name), positions: points, normals, triangles }))
    }

    /// The face's points as its index lists see them (1-based): its
    /// coordinates list, or the points `pnindex` (attribute `at`) picks from it.
    fn points(&mut self, e: Ent<'_>, a: &Attrs<'_>, at: usize) -> Result<Vec<DVec3>, Error> {
        let coords_id = a.refr(1)?;
        let coords = self.coordinates(coords_id, e)?;
        let pnmax = a.int(2)?;
        let pnindex = if omitted(a, at) { Vec::new() } else { a.ints(at)? };
        if pnindex.is_empty() {
            if pnmax != coords.len() as i64 {
                return Err(e.error(format!(
                    "pnmax is {pnmax} but its coordinates list #{coords_id} has {} points (and pnindex is empty)",
                    coords.len()
                )));
            }
            return Ok(coords.clone());
        }
        if pnmax != pnindex.len() as i64 {
            return Err(e.error(format!("pnmax is {pnmax} but pnindex lists {} points", pnindex.len())));
        }
        let mut pts = Vec::with_capacity(pnindex.len());
        for (k, &i) in pnindex.iter().enumerate() {
            match usize::try_from(i).ok().filter(|&i| (1..=coords.len()).contains(&i)) {
                Some(i) => pts.push(coords[i - 1]),
                None => {
                    return Err(e.error(format!(
                        "pnindex entry {} is {i}, not a point of its coordinates list #{coords_id} (1 to {})",
                        k + 1,
                        coords.len()
                    )))
                }
            }
        }
        Ok(pts)
    }

    /// The face's triangles over its `n` points: its triangle list (after
    /// `at`), or for a complex face its strips and fans expanded; triangles
    /// that name one point twice are left out, and counted (a strip's or a
    /// fan's are not: they close strips by design).
    fn triangles(
        &self,
        e: Ent<'_>,
        a: &Attrs<'_>,
        at: usize,
        complex: bool,
        n: usize,
    ) -> Result<(Vec<[u32; 3]>, usize), Error> {
        let index = |what: &str, i: &Value| -> Result<u32, Error> {
            match i {
                Value::Int(x) if *x >= 1 && (*x as u64) <= n as u64 => Ok((*x - 1) as u32),
                Value::Int(x) => Err(e.error(format!("{what} names point {x}; the face has points 1 to {n}"))),
                _ => Err(e.error(format!("{what}: expected an integer"))),
            }
        };
        let lists = |i: usize| -> Result<Vec<&[Value]>, Error> {
            if omitted(a, i) {
                return Ok(Vec::new());
            }
            let outer = a.list(i)?;
            outer.iter().map(|v| self.g.list(*v).ok_or_else(|| a.error(i, "expected a list of lists"))).collect()
        };
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        let mut repeated = 0usize;
        let push = |t: [u32; 3], triangles: &mut Vec<[u32; 3]>| {
            if t[0] != t[1] && t[1] != t[2] && t[2] != t[0] {
                triangles.push(t);
                true
            } else {
                false
            }
        };
        if !complex {
            for (k, t) in lists(at + 1)?.into_iter().enumerate() {
                let what = format!("triangle {}", k + 1);
                if t.len() != 3 {
                    return Err(e.error(format!("{what} has {} indices, not 3", t.len())));
                }
                let tri = [index(&what, &t[0])?, index(&what, &t[1])?, index(&what, &t[2])?];
                if !push(tri, &mut triangles) {
                    repeated += 1;
                }
            }
            return Ok((triangles, repeated));
        }
        for (k, s) in lists(at + 1)?.into_iter().enumerate() {
            let what = format!("triangle strip {}", k + 1);
            let v: Vec<u32> = s.iter().map(|i| index(&what, i)).collect::<Result<_, _>>()?;
            if v.len() < 3 {
                return Err(e.error(format!("{what} has {} points; a strip needs 3 or more", v.len())));
            }
            for j in 2..v.len() {
                let t = if j % 2 == 0 { [v[j - 2], v[j - 1], v[j]] } else { [v[j - 1], v[j - 2], v[j]] };
                push(t, &mut triangles);
            }
        }
        for (k, s) in lists(at + 2)?.into_iter().enumerate() {
            let what = format!("triangle fan {}", k + 1);
            let v: Vec<u32> = s.iter().map(|i| index(&what, i)).collect::<Result<_, _>>()?;
            if v.len() < 3 {
                return Err(e.error(format!("{what} has {} points; a fan needs 3 or more", v.len())));
            }
            for j in 2..v.len() {
                push([v[0], v[j - 1], v[j]], &mut triangles);
            }
        }
        Ok((triangles, repeated))
    }

    /// The face's normals, one per point (`n` points): none, the one given
    /// for every point, or the file's. A count that fits neither, or a
    /// normal of no length, leaves the face without normals (with a warning).
    fn normals(&mut self, e: Ent<'_>, a: &Attrs<'_>, n: usize) -> Result<Vec<DVec3>, Error> {
        if omitted(a, 3) {
            return Ok(Vec::new());
        }
        let given = a.list(3)?;
        let mut normals = Vec::with_capacity(given.len());
        for v in given {
            let c = self.g.list(*v).unwrap_or(&[]);
            let xyz: Vec<f64> = c.iter().filter_map(|x| self.g.number(*x)).collect();
            let d = match xyz.as_slice() {
                [x, y, z] if c.len() == 3 => DVec3::new(*x, *y, *z).normalize_or_zero(),
                _ => DVec3::ZERO,
            };
            normals.push(d);
        }
        let why = if normals.contains(&DVec3::ZERO) {
            Some(WarningKind::NormalsNotVectors)
        } else if normals.len() == 1 {
            return Ok(alloc::vec![normals[0]; n]);
        } else if normals.len() == n || normals.is_empty() {
            return Ok(normals);
        } else {
            Some(WarningKind::NormalsCount { normals: normals.len(), points: n })
        };
        if let Some(why) = why {
            let at = Entity::Step { id: e.id(), type_name: Some(e.type_name()), line: Some(e.line()) };
            self.warnings.push(Warning::entity(at, why));
        }
        Ok(Vec::new())
    }

    /// The points of `COORDINATES_LIST` `#id` (read once, kept for the faces that share it).
    fn coordinates(&mut self, id: u64, from: Ent<'_>) -> Result<&Vec<DVec3>, Error> {
        if !self.coordinates.contains_key(&id) {
            let r = read_coordinates(self.g, id, from);
            self.coordinates.insert(id, r);
        }
        match self.coordinates.get(&id) {
            Some(Ok(c)) => Ok(c),
            Some(Err(e)) => Err(e.clone()),
            None => Err(from.error(format!("coordinates list #{id} could not be read"))),
        }
    }
}

/// Whether parameter `i` is left out (`$`, `*` or missing): an empty list.
fn omitted(a: &Attrs<'_>, i: usize) -> bool {
    matches!(a.vals.get(i), None | Some(Value::Omitted) | Some(Value::Derived))
}

/// Whether `e` is a tessellated face or surface set.
fn is_face(e: Ent<'_>) -> bool {
    ITEMS[2..].iter().any(|n| e.has(n))
}

/// A `COORDINATES_LIST(name, npoints, ((x, y, z), …))`.
fn read_coordinates(g: &Graph, id: u64, from: Ent<'_>) -> Result<Vec<DVec3>, Error> {
    let e = g.get(id, from.id())?;
    if !e.has("COORDINATES_LIST") {
        return Err(e.error("expected a COORDINATES_LIST"));
    }
    let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("COORDINATES_LIST", 2)])?;
    let npoints = a.int(1)?;
    let list = a.list(2)?;
    if list.len() > MAX_CONTROL_POINTS {
        return Err(e.error(format!("{} points; at most {MAX_CONTROL_POINTS} are read", list.len())));
    }
    if npoints != list.len() as i64 {
        return Err(e.error(format!("npoints is {npoints} but the list holds {} points", list.len())));
    }
    let mut out = Vec::with_capacity(list.len());
    for (k, v) in list.iter().enumerate() {
        let c = g.list(*v).unwrap_or(&[]);
        let xyz: Vec<f64> = c.iter().filter_map(|x| g.number(*x)).collect();
        match xyz.as_slice() {
            [x, y, z] if c.len() == 3 => out.push(DVec3::new(*x, *y, *z)),
            _ => return Err(e.error(format!("point {} is not three finite numbers", k + 1))),
        }
    }
    Ok(out)
}

/// The `#id`s of what the exact reading covers: each placed item and, through
/// solids, surface models and shells, every face in it.
pub(super) fn exact_ids(g: &Graph, plan: &Plan) -> HashSet<u64> {
    let mut out = HashSet::default();
    let mut stack: Vec<(u64, usize)> = plan.placed.iter().map(|p| (p.item, 0)).collect();
    while let Some((id, depth)) = stack.pop() {
        if depth > MAX_DEPTH || !out.insert(id) {
            continue;
        }
        let Some(e) = g.find(id) else { continue };
        let a = e.attrs();
        let refs = |i: usize| a.refs(i).unwrap_or_default();
        let one = |i: usize| a.opt_ref(i).ok().flatten();
        let next: Vec<u64> = if e.has("MANIFOLD_SOLID_BREP") || e.has("FACETED_BREP") {
            one(1).into_iter().collect()
        } else if e.has("BREP_WITH_VOIDS") {
            one(1).into_iter().chain(refs(2)).collect()
        } else if e.has("SHELL_BASED_SURFACE_MODEL")
            || e.has("FACE_BASED_SURFACE_MODEL")
            || e.has("CLOSED_SHELL")
            || e.has("OPEN_SHELL")
            || e.has("CONNECTED_FACE_SET")
        {
            refs(1)
        } else if e.has("ORIENTED_CLOSED_SHELL") || e.has("ORIENTED_OPEN_SHELL") || e.has("ORIENTED_FACE") {
            one(2).into_iter().collect()
        } else {
            Vec::new()
        };
        stack.extend(next.into_iter().map(|r| (r, depth + 1)));
    }
    out
}
