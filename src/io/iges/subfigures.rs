//! Subfigures: a 308 definition lists entities once, and each 408 singular
//! instance places them, scaled by its factor `S`, moved by its `(X, Y, Z)`,
//! then mapped by its own transformation matrix (a point `p` of the
//! definition lands at `M·(S·p + t)`); instances nest through 408s listed in
//! a definition. Entities listed in a definition that something instances
//! are read only through the instances; the shells each instance places are
//! bodies of their own.

use crate::collections::HashSet;
use alloc::vec::Vec;
use glam::{DAffine3, DVec3};

use super::directory::Entity;
use super::xform::own_transform;
use super::{Ctx, MAX_DEPTH};
use crate::Error;

/// Most entities and instances all instances place together: a file whose
/// instances nest sixty deep, ten to a level, must not expand without bound.
pub(super) const MAX_PLACED: usize = 100_000;

/// Which entities subfigures hold, found in one pass over the directory.
#[derive(Default)]
pub(super) struct Subfigures {
    /// Entities listed in a definition that some instance places.
    members: HashSet<usize>,
    /// Instances listed in a definition (placed by the instances above them).
    nested: HashSet<usize>,
}

/// What expansions have used so far: instances numbered, entities placed.
pub(super) struct Count {
    /// The last instance's number.
    pub instances: u32,
    /// How many more entities may be placed.
    pub left: usize,
}

impl Default for Count {
    fn default() -> Self {
        Self { instances: 0, left: MAX_PLACED }
    }
}

/// One entity as an instance places it.
pub(super) struct Placed {
    /// The entity's directory entry.
    pub de: usize,
    /// Definition space to the output (the Global section's scale included).
    pub m: DAffine3,
    /// Which instance (1, 2, …, one number per instance of each path).
    pub instance: u32,
}

impl Subfigures {
    /// The subfigures of the file.
    pub fn scan(ctx: &Ctx<'_>) -> Self {
        let mut out = Self::default();
        let mut instanced: HashSet<usize> = HashSet::default();
        for e in ctx.dir.entities.iter().filter(|e| e.kind == 408) {
            if let Ok(Some(d)) = e.ptr(1) {
                instanced.insert(d);
            }
        }
        for e in ctx.dir.entities.iter().filter(|e| e.kind == 308) {
            for m in members(e) {
                if ctx.dir.get(m).is_some_and(|x| x.kind == 408) {
                    out.nested.insert(m);
                } else if instanced.contains(&e.de) {
                    out.members.insert(m);
                }
            }
        }
        out
    }

    /// Whether `de` is shown only through the instances of its subfigure.
    pub fn is_member(&self, de: usize) -> bool {
        self.members.contains(&de)
    }

    /// Whether `e` is an instance at the top (placed by no other).
    pub fn is_root_instance(&self, e: &Entity) -> bool {
        e.kind == 408 && !self.nested.contains(&e.de)
    }

    /// The entities instance `de` places, with nested instances expanded
    /// (in their definitions' order), after `parent`; `count` numbers the
    /// instances and counts down the entities placed.
    ///
    /// # Errors
    /// A definition pointer that is not a 308, nesting deeper than
    /// [`MAX_DEPTH`] (a cycle), more than [`MAX_PLACED`] entities, or a
    /// transformation that cannot be read.
    pub fn expand(
        &self,
        ctx: &Ctx<'_>,
        de: usize,
        parent: DAffine3,
        depth: usize,
        count: &mut Count,
        out: &mut Vec<Placed>,
    ) -> Result<(), Error> {
        let inst = ctx.entity(de)?;
        if depth > MAX_DEPTH {
            return Err(inst.error(alloc::format!("subfigure instances nested deeper than {MAX_DEPTH} (a cycle?)")));
        }
        let def_de = inst.ptr(1)?.ok_or_else(|| inst.error("subfigure instance without a definition"))?;
        let def = ctx.entity(def_de)?;
        if def.kind != 308 {
            return Err(inst.error(alloc::format!(
                "subfigure instance pointer {def_de} names type {}, not a definition (308)",
                def.kind
            )));
        }
        let t = inst.vec3(2)?;
        let s = inst.real_or(5, 1.0)?;
        if !(s.is_finite() && s != 0.0 && t.is_finite()) {
            return Err(inst.error(alloc::format!("subfigure instance scale {s} or translation {t} unusable")));
        }
        let local = DAffine3::from_scale_rotation_translation(DVec3::splat(s), glam::DQuat::IDENTITY, t);
        let m = parent * own_transform(ctx.dir, de)? * local * own_transform(ctx.dir, def_de)?;
        // Instances count against the budget too: nested ones that place
        // nothing must not multiply without bound either.
        if count.left == 0 {
            return Err(inst.error(alloc::format!("subfigure instances place more than {MAX_PLACED} entities")));
        }
        count.left -= 1;
        count.instances += 1;
        let instance = count.instances;
        for member in members(def) {
            match ctx.dir.get(member) {
                Some(x) if x.kind == 408 => self.expand(ctx, member, m, depth + 1, count, out)?,
                Some(x) if x.kind == 308 => {}
                Some(_) => {
                    if count.left == 0 {
                        return Err(
                            inst.error(alloc::format!("subfigure instances place more than {MAX_PLACED} entities"))
                        );
                    }
                    count.left -= 1;
                    out.push(Placed { de: member, m, instance });
                }
                None => return Err(def.error(alloc::format!("member pointer {member} names no entity"))),
            }
        }
        Ok(())
    }
}

/// The entities a 308 definition lists: depth, name, count N, N pointers.
fn members(e: &Entity) -> Vec<usize> {
    let n = e.count(3, 1, 4).unwrap_or(0);
    (0..n).filter_map(|k| e.ptr(4 + k).ok().flatten()).collect()
}
