//! Which shapes the file holds and where: representations and their items,
//! the relations that place one representation in another (assemblies:
//! `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` with a transformed
//! `SHAPE_REPRESENTATION_RELATIONSHIP` for each
//! `NEXT_ASSEMBLY_USAGE_OCCURRENCE`, and `MAPPED_ITEM`s), the units of each
//! representation's context and the product names.
//!
//! Representations related without a transformation share one coordinate
//! system and form a group; groups that are nobody's child are roots, and
//! every path from a root down the placements is one instance of the shapes
//! below it. Everything is computed in millimetres, then expressed in the
//! unit of the first root, so parts in other units are scaled to it.

use crate::collections::{HashMap, HashSet};
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use glam::{DAffine3, DVec3};

use super::curves::Geo;
use super::graph::{Ent, Graph, Value};
use super::{MAX_DEPTH, MAX_FACES};
use crate::model::{Assembly, AssemblyNode, PartInstance};
use crate::warning::{Entity, Warning, WarningKind};
use crate::Error;

/// One shape item to read, placed.
#[derive(Debug, Clone)]
pub(super) struct Placed {
    /// The solid, shell, surface model, set or surface.
    pub item: u64,
    /// From the item's coordinates (its context's unit) to the output's.
    pub m: DAffine3,
    /// Radians per angle unit of the item's context.
    pub angle: f64,
    /// The context's uncertainty in its own length unit (0 when not stated).
    pub uncertainty: f64,
    /// Product name of the part.
    pub name: Option<String>,
    /// Which part instance the item belongs to: items placed together by
    /// one assembly path share it. It is the index of that path's node in
    /// [`Plan::nodes`].
    pub instance: usize,
}

/// One visit of the walk down the placements: a node of the product tree.
#[derive(Debug, Clone)]
pub(super) struct PlanNode {
    /// The node it was placed in (`None`: a root).
    pub parent: Option<usize>,
    /// Product name, as [`Placed::name`].
    pub name: Option<String>,
    /// The occurrence's own name (`NEXT_ASSEMBLY_USAGE_OCCURRENCE.name`).
    pub occurrence: Option<String>,
    /// From the node's coordinates to its parent's, output unit.
    pub local: DAffine3,
    /// From the node's coordinates to the output's, output unit.
    pub world: DAffine3,
}

/// What to read.
#[derive(Debug, Clone, Default)]
pub(super) struct Plan {
    pub placed: Vec<Placed>,
    /// The product tree as the walk found it; `Placed::instance` indexes it.
    pub nodes: Vec<PlanNode>,
    pub units: String,
    pub tolerance: Option<f64>,
}

/// Units of one representation context.
#[derive(Debug, Clone, Copy)]
struct Units {
    /// Millimetres per length unit.
    mm: f64,
    /// Radians per angle unit.
    rad: f64,
    /// Uncertainty in millimetres (0: none stated).
    uncertainty: f64,
}

impl Default for Units {
    fn default() -> Self {
        Self { mm: 1.0, rad: 1.0, uncertainty: 0.0 }
    }
}

/// Entity names of the items this reader turns into faces.
pub(super) const SHAPES: [&str; 12] = [
    "MANIFOLD_SOLID_BREP",
    "BREP_WITH_VOIDS",
    "FACETED_BREP",
    "SHELL_BASED_SURFACE_MODEL",
    "FACE_BASED_SURFACE_MODEL",
    "GEOMETRIC_SET",
    "GEOMETRIC_CURVE_SET",
    "CLOSED_SHELL",
    "OPEN_SHELL",
    "ADVANCED_FACE",
    "FACE_SURFACE",
    "CONNECTED_FACE_SET",
];

fn is_shape(e: Ent<'_>) -> bool {
    SHAPES.iter().any(|n| e.has(n)) || super::surfaces::is_bspline_surface(e) || super::tessellated::is_tessellated(e)
}

/// The `(name, items, context)` of a representation, if `e` is one.
fn representation<'g>(e: Ent<'g>) -> Option<(Vec<u64>, u64)> {
    let a = if e.is_complex() {
        e.part("REPRESENTATION")?
    } else {
        let n = e.name();
        if !n.ends_with("REPRESENTATION") || n == "DEFINITIONAL_REPRESENTATION" {
            return None;
        }
        e.attrs()
    };
    if a.len() != 3 {
        return None;
    }
    Some((a.refs(1).ok()?, a.refr(2).ok()?))
}

/// Union-find root.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The representations of the file: id, items and context of each, the
/// index of each id, and the units of each one's context.
struct Reps {
    list: Vec<(u64, Vec<u64>, u64)>,
    index: HashMap<u64, usize>,
    units: Vec<Units>,
}

/// A placement of one representation in another.
struct Relation {
    parent: u64,
    child: u64,
    /// From the child's coordinates to the parent's, millimetres.
    m: DAffine3,
    /// Product name.
    name: Option<String>,
    /// The occurrence's own name.
    occurrence: Option<String>,
}

/// A child group of a group: its group, its map to the parent (mm), its
/// product name and its occurrence name.
type Child = (usize, DAffine3, Option<String>, Option<String>);

/// Representations related without a transformation, joined into groups,
/// and the placements between groups.
struct Groups {
    /// Each group's child groups, placed.
    children: HashMap<usize, Vec<Child>>,
    /// Each group's representations.
    members: HashMap<usize, Vec<usize>>,
    /// Groups that are nobody's child, in group order.
    roots: Vec<usize>,
}

/// Works out every placed shape: the representations, the relations that
/// place one in another, the groups they form, the output unit, then a walk
/// down the placements from each root; solids no representation lists are
/// read in place, and faces a shell also holds are dropped.
///
/// # Errors
/// Malformed relations (bad references, placements that are not placements).
pub(super) fn plan(g: &Graph, warnings: &mut Vec<Warning>) -> Result<Plan, Error> {
    let reps = representations(g, warnings);
    let mut parent: Vec<usize> = (0..reps.list.len()).collect();
    let cdsr = cdsr_products(g);
    let product_of_rep = rep_products(g);
    let mut relations = relationships(g, &reps, &cdsr, &product_of_rep, &mut parent)?;
    relations.extend(mapped_items(g, &reps)?);
    let groups = groups(&reps, parent, &relations);
    let out_mm = output_unit(g, &reps, &groups);
    let mut plan = Plan { units: unit_name(out_mm), ..Plan::default() };
    let (emitted, tol) = walk(g, &reps, &groups, &product_of_rep, out_mm, &mut plan, warnings);
    read_unlisted_solids(g, &emitted, &mut plan, warnings);
    drop_shell_faces(g, &mut plan);
    plan.tolerance = (tol > 0.0 && tol.is_finite()).then_some(tol);
    Ok(plan)
}

/// Every representation of `g`, and the units of its context.
fn representations(g: &Graph, warnings: &mut Vec<Warning>) -> Reps {
    let mut list: Vec<(u64, Vec<u64>, u64)> = Vec::new();
    let mut index: HashMap<u64, usize> = HashMap::default();
    for e in g.all() {
        if let Some((items, ctx)) = representation(e) {
            index.insert(e.id(), list.len());
            list.push((e.id(), items, ctx));
        }
    }
    let mut unit_cache: HashMap<u64, Units> = HashMap::default();
    let units = list
        .iter()
        .map(|(_, _, ctx)| *unit_cache.entry(*ctx).or_insert_with(|| context_units(g, *ctx, warnings)))
        .collect();
    Reps { list, index, units }
}

/// The representation relationships of `g`: those without a transformation
/// join their two representations' groups in `parent`; the others are
/// placements, the child the one the product structure (`cdsr`,
/// `product_of_rep`) names, else `rep_1`.
///
/// # Errors
/// A transformation that is not one, or a reference that is not an entity.
fn relationships(
    g: &Graph,
    reps: &Reps,
    cdsr: &HashMap<u64, (Option<String>, u64, Option<String>)>,
    product_of_rep: &HashMap<u64, (u64, Option<String>)>,
    parent: &mut [usize],
) -> Result<Vec<Relation>, Error> {
    let units = &reps.units;
    let mut out = Vec::new();
    for e in g.all() {
        if !(e.has("REPRESENTATION_RELATIONSHIP") || e.has("SHAPE_REPRESENTATION_RELATIONSHIP")) {
            continue;
        }
        let a = match e.part("REPRESENTATION_RELATIONSHIP") {
            Some(a) => a,
            None => e.attrs(),
        };
        let (Ok(r1), Ok(r2)) = (a.refr(2), a.refr(3)) else { continue };
        let (Some(&i1), Some(&i2)) = (reps.index.get(&r1), reps.index.get(&r2)) else { continue };
        let Some(t) = e.part("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") else {
            let (x, y) = (root(parent, i1), root(parent, i2));
            parent[x] = y;
            continue;
        };
        let op = t.ent(0)?;
        let geo1 = Geo { g, angle: units[i1].rad, uncertainty: 0.0 };
        let geo2 = Geo { g, angle: units[i2].rad, uncertainty: 0.0 };
        let (m1, m2) = if op.has("ITEM_DEFINED_TRANSFORMATION") {
            let ia = op.attrs();
            let (p1, p2) = (ia.ent(2)?, ia.ent(3)?);
            (in_mm(geo1.transform(p1)?, units[i1].mm), in_mm(geo2.transform(p2)?, units[i2].mm))
        } else {
            (DAffine3::IDENTITY, in_mm(geo2.transform(op)?, units[i2].mm))
        };
        // rep_1 is the child unless the product structure says otherwise.
        let (child, par, m) = match cdsr.get(&e.id()) {
            Some((_, child_pd, _)) if product_of_rep.get(&r2).is_some_and(|(pd, _)| pd == child_pd) => {
                (r2, r1, m1 * m2.inverse())
            }
            _ => (r1, r2, m2 * m1.inverse()),
        };
        let name = cdsr.get(&e.id()).and_then(|(n, _, _)| n.clone());
        let occurrence = cdsr.get(&e.id()).and_then(|(_, _, o)| o.clone());
        out.push(Relation { parent: par, child, m, name, occurrence });
    }
    Ok(out)
}

/// The `MAPPED_ITEM`s among the representations' items: each places its
/// source representation in the one that lists it.
///
/// # Errors
/// A mapped item whose attributes are not the entities they must be.
fn mapped_items(g: &Graph, reps: &Reps) -> Result<Vec<Relation>, Error> {
    let units = &reps.units;
    let mut out = Vec::new();
    for (ri, (rid, items, _)) in reps.list.iter().enumerate() {
        for &it in items {
            let Some(e) = g.find(it) else { continue };
            if !e.has("MAPPED_ITEM") {
                continue;
            }
            let a = e.chain(&[("REPRESENTATION_ITEM", 1), ("MAPPED_ITEM", 2)])?;
            let map = a.ent(1)?;
            let ma = map.attrs();
            let origin = ma.ent(0)?;
            let child = ma.refr(1)?;
            let Some(&ci) = reps.index.get(&child) else { continue };
            let go = Geo { g, angle: units[ci].rad, uncertainty: 0.0 };
            let gt = Geo { g, angle: units[ri].rad, uncertainty: 0.0 };
            let m =
                in_mm(gt.transform(a.ent(2)?)?, units[ri].mm) * in_mm(go.transform(origin)?, units[ci].mm).inverse();
            out.push(Relation { parent: *rid, child, m, name: None, occurrence: None });
        }
    }
    Ok(out)
}

/// The groups `parent` joined, each group's placed children and members,
/// and the roots in group order.
fn groups(reps: &Reps, mut parent: Vec<usize>, relations: &[Relation]) -> Groups {
    let n = reps.list.len();
    let mut children: HashMap<usize, Vec<Child>> = HashMap::default();
    let mut is_child: HashSet<usize> = HashSet::default();
    for r in relations {
        let group = |parent: &mut Vec<usize>, rep: u64| reps.index.get(&rep).map(|&i| root(parent, i));
        let (Some(gp), Some(gc)) = (group(&mut parent, r.parent), group(&mut parent, r.child)) else { continue };
        if gp == gc {
            continue;
        }
        children.entry(gp).or_default().push((gc, r.m, r.name.clone(), r.occurrence.clone()));
        is_child.insert(gc);
    }
    let mut members: HashMap<usize, Vec<usize>> = HashMap::default();
    for i in 0..n {
        let r = root(&mut parent, i);
        members.entry(r).or_default().push(i);
    }
    let mut roots: Vec<usize> = (0..n).map(|i| root(&mut parent, i)).filter(|r| !is_child.contains(r)).collect();
    crate::sort::usizes(&mut roots);
    roots.dedup();
    Groups { children, members, roots }
}

impl Groups {
    /// Whether group `gi` is in the product structure: it has children or a
    /// product owns one of its representations.
    fn in_products(&self, gi: usize, reps: &Reps, product_of_rep: &HashMap<u64, (u64, Option<String>)>) -> bool {
        self.children.contains_key(&gi)
            || self.members.get(&gi).is_some_and(|ms| ms.iter().any(|&i| product_of_rep.contains_key(&reps.list[i].0)))
    }
}

/// Millimetres per output unit: the unit of the first root that holds shapes.
fn output_unit(g: &Graph, reps: &Reps, groups: &Groups) -> f64 {
    let holds_shapes = |gi: usize| {
        groups.members.get(&gi).is_some_and(|ms| {
            ms.iter().any(|&i| {
                reps.list[i].1.iter().any(|&it| g.find(it).is_some_and(|e| is_shape(e) || e.has("MAPPED_ITEM")))
            })
        }) || groups.children.contains_key(&gi)
    };
    groups
        .roots
        .iter()
        .find(|&&r| holds_shapes(r))
        .and_then(|r| groups.members.get(r))
        .and_then(|ms| ms.first())
        .map_or(1.0, |&i| reps.units[i].mm)
}

/// A node to visit: its group, its map to the output (mm), its name, its
/// depth, its parent node, its map to the parent (mm) and its occurrence name.
type Visit = (usize, DAffine3, Option<String>, usize, Option<usize>, DAffine3, Option<String>);

/// Depth-first over the placements from each root (those in the product
/// structure first: a representation no product owns, such as validation
/// properties or presentation, that lists their shapes again adds nothing),
/// the path kept to refuse cycles: the product tree into `plan.nodes` and
/// each shape item once per distinct placement into `plan.placed`, in the
/// output unit (`out_mm` millimetres). The items placed, and the largest
/// uncertainty of their contexts in the output unit.
fn walk(
    g: &Graph,
    reps: &Reps,
    groups: &Groups,
    product_of_rep: &HashMap<u64, (u64, Option<String>)>,
    out_mm: f64,
    plan: &mut Plan,
    warnings: &mut Vec<Warning>,
) -> (HashSet<u64>, f64) {
    let (members, children) = (&groups.members, &groups.children);
    let mut seen: HashSet<(u64, [u64; 12])> = HashSet::default();
    let mut emitted: HashSet<u64> = HashSet::default();
    let mut tol: f64 = 0.0;
    let scale_out = DAffine3::from_scale(DVec3::splat(1.0 / out_mm));
    let in_products = |gi: usize| groups.in_products(gi, reps, product_of_rep);
    let mut roots = groups.roots.clone();
    crate::sort::by_u64(&mut roots, |&r| u64::from(!in_products(r)));
    // The output unit's view of a map between millimetre coordinates.
    let out_map = |m: DAffine3| scale_out * m * scale_out.inverse();
    let mut stack: Vec<Visit> =
        roots.iter().rev().map(|&r| (r, DAffine3::IDENTITY, None, 0, None, DAffine3::IDENTITY, None)).collect();
    let mut visits = 0usize;
    while let Some((gi, m, name, depth, up, local, occurrence)) = stack.pop() {
        visits += 1;
        if depth > MAX_DEPTH || visits > MAX_FACES {
            warnings.push(Warning::new(WarningKind::AssemblyLimit { depth: MAX_DEPTH, instances: MAX_FACES }));
            break;
        }
        let orphan = depth == 0 && !in_products(gi);
        let own_name = members
            .get(&gi)
            .and_then(|ms| ms.iter().find_map(|&i| product_of_rep.get(&reps.list[i].0).and_then(|(_, n)| n.clone())));
        let name = own_name.or(name);
        let node = plan.nodes.len();
        plan.nodes.push(PlanNode {
            parent: up,
            name: name.clone(),
            occurrence,
            local: out_map(local),
            world: out_map(m),
        });
        for &i in members.get(&gi).map_or(&[][..], Vec::as_slice) {
            let u = reps.units[i];
            for &it in &reps.list[i].1 {
                let Some(e) = g.find(it) else {
                    warnings.push(Warning::entity(
                        Entity::step_id(reps.list[i].0),
                        WarningKind::ItemUndefined { item: it },
                    ));
                    continue;
                };
                if !is_shape(e) || (orphan && emitted.contains(&it)) {
                    continue;
                }
                let full = scale_out * m * DAffine3::from_scale(DVec3::splat(u.mm));
                let key = (it, matrix_key(&full));
                if !seen.insert(key) {
                    continue;
                }
                emitted.insert(it);
                tol = tol.max(u.uncertainty / out_mm);
                plan.placed.push(Placed {
                    item: it,
                    m: full,
                    angle: u.rad,
                    uncertainty: u.uncertainty / u.mm,
                    name: name.clone(),
                    instance: node,
                });
            }
        }
        if let Some(kids) = children.get(&gi) {
            for (c, cm, cname, occ) in kids.iter().rev() {
                stack.push((*c, m * *cm, cname.clone().or(name.clone()), depth + 1, Some(node), *cm, occ.clone()));
            }
        }
    }
    (emitted, tol)
}

/// Solids and surface models no representation lists (none of the items
/// `emitted` and not inside one of them): read in place, each a root node.
fn read_unlisted_solids(g: &Graph, emitted: &HashSet<u64>, plan: &mut Plan, warnings: &mut Vec<Warning>) {
    let mut nested: HashSet<u64> = HashSet::default();
    for p in &plan.placed {
        if let Some(e) = g.find(p.item) {
            if e.has("SHELL_BASED_SURFACE_MODEL") || e.has("MANIFOLD_SOLID_BREP") || e.has("BREP_WITH_VOIDS") {
                if let Ok(a) = e.chain(&[("REPRESENTATION_ITEM", 1)]) {
                    for v in &a.vals {
                        if let Value::Ref(r) = v {
                            nested.insert(*r);
                        }
                    }
                }
            }
        }
    }
    for e in g.all() {
        let top = ["MANIFOLD_SOLID_BREP", "BREP_WITH_VOIDS", "FACETED_BREP", "SHELL_BASED_SURFACE_MODEL"];
        if top.iter().any(|n| e.has(n)) && !emitted.contains(&e.id()) && !nested.contains(&e.id()) {
            let kind = WarningKind::NotInRepresentation;
            warnings.push(Warning::entity(Entity::step(e.id(), e.type_name()), kind));
            let node = plan.nodes.len();
            plan.nodes.push(PlanNode {
                parent: None,
                name: None,
                occurrence: None,
                local: DAffine3::IDENTITY,
                world: DAffine3::IDENTITY,
            });
            plan.placed.push(Placed {
                item: e.id(),
                m: DAffine3::IDENTITY,
                angle: 1.0,
                uncertainty: 0.0,
                name: None,
                instance: node,
            });
        }
    }
}

/// Faces that a representation lists on their own but that a shell also
/// holds are references (annotations, PMI), not more geometry: dropped.
fn drop_shell_faces(g: &Graph, plan: &mut Plan) {
    let mut in_shells: HashSet<u64> = HashSet::default();
    for e in g.all() {
        if e.has("CLOSED_SHELL") || e.has("OPEN_SHELL") || e.has("CONNECTED_FACE_SET") {
            if let Ok(a) = e.chain(&[("REPRESENTATION_ITEM", 1), ("CONNECTED_FACE_SET", 1)]) {
                in_shells.extend(a.refs(1).unwrap_or_default());
            }
        }
    }
    plan.placed.retain(|p| {
        let face = g.find(p.item).is_some_and(|e| e.has("ADVANCED_FACE") || e.has("FACE_SURFACE"));
        !(face && in_shells.contains(&p.item))
    });
}

/// The product tree and the part instances of the read faces. `placed`
/// gives each face's placement (the first `exact` faces are exact, the
/// rest tessellated), `face_parts` its part instance. Two instances share a
/// shape when their faces come from the same items, in the same order and
/// numbers; nodes without an instance below them are left out, and several
/// roots get a common unnamed root.
pub(super) fn tree(
    nodes: &[PlanNode],
    placed: &[Option<&Placed>],
    exact: usize,
    face_parts: &[u32],
    parts: usize,
) -> Assembly {
    // Each instance's node, and its faces' items run by run.
    type Run = (bool, u64, u64, u64, u32);
    let mut node_of = alloc::vec![usize::MAX; parts];
    let mut runs: Vec<Vec<Run>> = alloc::vec![Vec::new(); parts];
    for (f, (p, &k)) in placed.iter().zip(face_parts).enumerate() {
        let k = k as usize;
        let Some(p) = p else { continue };
        node_of[k] = p.instance;
        let key = (f >= exact, p.item, p.angle.to_bits(), p.uncertainty.to_bits());
        match runs[k].last_mut() {
            Some(r) if (r.0, r.1, r.2, r.3) == key => r.4 += 1,
            _ => runs[k].push((key.0, key.1, key.2, key.3, 1)),
        }
    }
    let mut shape_of: HashMap<Vec<Run>, usize> = HashMap::default();
    let shapes: Vec<usize> = runs
        .into_iter()
        .map(|r| {
            let next = shape_of.len();
            *shape_of.entry(r).or_insert(next)
        })
        .collect();
    // Nodes that hold an instance, or have one below them.
    let mut keep = alloc::vec![false; nodes.len()];
    for &n in &node_of {
        let mut at = (n < nodes.len()).then_some(n);
        while let Some(i) = at {
            if keep[i] {
                break;
            }
            keep[i] = true;
            at = nodes[i].parent;
        }
    }
    let roots: Vec<usize> = (0..nodes.len()).filter(|&i| keep[i] && nodes[i].parent.is_none()).collect();
    let shared_root = roots.len() != 1;
    let mut out: Vec<AssemblyNode> = Vec::new();
    if shared_root {
        out.push(AssemblyNode::new(""));
    }
    let mut index = alloc::vec![usize::MAX; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        if !keep[i] {
            continue;
        }
        index[i] = out.len();
        let mut a = AssemblyNode::new(n.name.clone().unwrap_or_default());
        a.occurrence = n.occurrence.clone();
        a.matrix = n.local;
        out.push(a);
    }
    // Children in the walk's order (a parent is always visited before its children).
    for (i, n) in nodes.iter().enumerate() {
        if !keep[i] {
            continue;
        }
        let parent = match n.parent {
            Some(p) => index[p],
            None if shared_root => 0,
            None => continue,
        };
        if let Some(p) = out.get_mut(parent) {
            p.children.push(index[i]);
        }
    }
    let root_world = |n: usize| nodes.get(n).map_or(DAffine3::IDENTITY, |n| n.world);
    let mut instances = Vec::with_capacity(parts);
    for (k, &n) in node_of.iter().enumerate() {
        let node = index.get(n).copied().unwrap_or(0);
        if let Some(a) = out.get_mut(node) {
            a.instances.push(k);
        }
        instances.push(PartInstance { node, shape: shapes[k], matrix: root_world(n) });
    }
    let mut assembly = Assembly::single("", 0);
    assembly.nodes = out;
    assembly.instances = instances;
    assembly.face_instances = face_parts.to_vec();
    assembly
}

/// The affine map with its translation turned from `mm` per unit into millimetres.
fn in_mm(m: DAffine3, mm: f64) -> DAffine3 {
    DAffine3 { matrix3: m.matrix3, translation: m.translation * mm }
}

fn matrix_key(m: &DAffine3) -> [u64; 12] {
    let c = m.to_cols_array();
    let mut k = [0u64; 12];
    for (o, x) in k.iter_mut().zip(c) {
        *o = x.to_bits();
    }
    k
}

/// A short unit name for `mm` millimetres.
fn unit_name(mm: f64) -> String {
    let close = |x: f64| (mm / x - 1.0).abs() < 1e-9;
    let known = [
        (1.0, "mm"),
        (10.0, "cm"),
        (1000.0, "m"),
        (1e6, "km"),
        (1e-3, "um"),
        (25.4, "in"),
        (304.8, "ft"),
        (0.0254, "mil"),
    ];
    for (f, n) in known {
        if close(f) {
            return n.into();
        }
    }
    format!("{mm} mm")
}

/// Units and uncertainty of a representation context.
fn context_units(g: &Graph, ctx: u64, warnings: &mut Vec<Warning>) -> Units {
    let mut u = Units::default();
    let Some(c) = g.find(ctx) else { return u };
    if let Some(a) = c.part("GLOBAL_UNIT_ASSIGNED_CONTEXT") {
        for r in a.refs(0).unwrap_or_default() {
            let Some(e) = g.find(r) else { continue };
            if e.has("LENGTH_UNIT") {
                match unit_factor(e, 0) {
                    Some(f) => u.mm = f,
                    None => warnings.push(Warning::entity(Entity::step_id(r), WarningKind::LengthUnitUnknown)),
                }
            } else if e.has("PLANE_ANGLE_UNIT") {
                if let Some(f) = unit_factor(e, 0) {
                    u.rad = f;
                }
            }
        }
    }
    if let Some(a) = c.part("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT") {
        for r in a.refs(0).unwrap_or_default() {
            let Some(e) = g.find(r) else { continue };
            let m = e.attrs();
            let (Ok(v), Ok(unit)) = (m.real(0), m.ent(1)) else { continue };
            let f = if unit.has("LENGTH_UNIT") { unit_factor(unit, 0).unwrap_or(u.mm) } else { continue };
            let x = v.abs() * f;
            if x.is_finite() {
                u.uncertainty = u.uncertainty.max(x);
            }
        }
    }
    u
}

/// Millimetres (length units) or radians (angle units) per unit.
fn unit_factor(e: Ent<'_>, depth: usize) -> Option<f64> {
    if depth > 8 {
        return None;
    }
    if let Some(si) = e.part("SI_UNIT") {
        let prefix = match si.enumeration(0).ok() {
            Some(p) => si_prefix(p)?,
            None => 1.0,
        };
        return match si.enumeration(1).ok()? {
            "METRE" => Some(1000.0 * prefix),
            "RADIAN" => Some(prefix),
            _ => None,
        };
    }
    let conv = e.part("CONVERSION_BASED_UNIT")?;
    let m = conv.ent(1).ok()?;
    let ma = if m.is_complex() { m.part("MEASURE_WITH_UNIT")? } else { m.attrs() };
    let value = ma.real(0).ok()?;
    let base = unit_factor(ma.ent(1).ok()?, depth + 1)?;
    let f = value * base;
    (f > 0.0 && f.is_finite()).then_some(f)
}

fn si_prefix(p: &str) -> Option<f64> {
    Some(match p {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}

/// Product definition and name of each representation a
/// `SHAPE_DEFINITION_REPRESENTATION` ties to a product.
fn rep_products(g: &Graph) -> HashMap<u64, (u64, Option<String>)> {
    let mut out = HashMap::default();
    for e in g.all() {
        if !e.has("SHAPE_DEFINITION_REPRESENTATION") {
            continue;
        }
        let a = e.attrs();
        let (Ok(pds), Ok(rep)) = (a.ent(0), a.refr(1)) else { continue };
        let Ok(pd) = pds.attrs().ent(2) else { continue };
        if !pd.has("PRODUCT_DEFINITION") {
            continue;
        }
        out.insert(rep, (pd.id(), product_name(pd)));
    }
    out
}

/// For each transformed relation a `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION`
/// names: the child part's name and product definition, and the occurrence's name.
fn cdsr_products(g: &Graph) -> HashMap<u64, (Option<String>, u64, Option<String>)> {
    let mut out = HashMap::default();
    for e in g.all() {
        if !e.has("CONTEXT_DEPENDENT_SHAPE_REPRESENTATION") {
            continue;
        }
        let a = e.attrs();
        let (Ok(rel), Ok(pds)) = (a.refr(0), a.ent(1)) else { continue };
        let Ok(nauo) = pds.attrs().ent(2) else { continue };
        if !nauo.has("NEXT_ASSEMBLY_USAGE_OCCURRENCE") && !nauo.has("PRODUCT_DEFINITION_USAGE") {
            continue;
        }
        let na = nauo.attrs();
        let Ok(child) = na.ent(4) else { continue };
        let occurrence = na.string(1).ok().map(|s| String::from(s.trim())).filter(|s| !s.is_empty());
        out.insert(rel, (product_name(child), child.id(), occurrence));
    }
    out
}

/// `PRODUCT.name` (or its id) of a product definition.
fn product_name(pd: Ent<'_>) -> Option<String> {
    let pdf = pd.attrs().ent(2).ok()?;
    let prod = pdf.attrs().ent(2).ok()?;
    let a = prod.attrs();
    let name = a.string(1).ok().filter(|s| !s.trim().is_empty()).or_else(|| a.string(0).ok())?;
    let name = name.trim();
    (!name.is_empty()).then(|| name.into())
}
