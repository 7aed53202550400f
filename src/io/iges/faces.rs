//! Which entities are faces, and how each becomes one: trimmed surfaces
//! (144 with 142 boundaries), bounded surfaces (143 with 141 boundaries),
//! B-rep faces (510 in 514 shells in 186 solids), bounded planes (108 form
//! 1) and surfaces no face uses (untrimmed).
//!
//! A face that cannot be read is skipped with a warning naming its directory
//! entry and type.

mod skipped;

use crate::collections::HashSet;
use alloc::string::String;
use alloc::vec::Vec;
use glam::DAffine3;

use super::brep::{chain_transform, face_510, reverse_all, shell_faces};
use super::curves::{model_curve, param_curve};
use super::directory::Entity;
use super::loops::{build_face, FaceSrc, LoopSrc};
use super::subfigures::{Count, Subfigures};
use super::surfaces::{is_surface, surface_def};
use super::xform::own_transform;
use super::Ctx;
use crate::model::{Face, SkippedFace};
use crate::warning::{Entity as WarningEntity, Warning, WarningKind};
use crate::Error;

/// The faces of the file, in directory order, with warnings for what was
/// skipped; the first skip's error is kept for files where nothing is left.
/// Also each face's body: the B-rep shell (514, or 186's) it belongs to, 0
/// for faces outside any; and the faces skipped, with their borders.
pub(super) fn read_faces(
    ctx: &Ctx<'_>,
    warnings: &mut Vec<Warning>,
    skipped: &mut Vec<SkippedFace>,
) -> (Vec<Face>, Vec<u32>, Option<Error>) {
    let dir = ctx.dir;
    let (used, in_shell, shell_in_solid) = uses(ctx);
    let subfigures = Subfigures::scan(ctx);
    let shells = Shells { used: &used, in_shell: &in_shell, shell_in_solid: &shell_in_solid };
    // Hidden (blanked) faces are not part of what the file shows, unless
    // the file shows nothing else.
    let face_entity = |e: &Entity| match e.kind {
        144 | 143 | 186 => true,
        514 => !shell_in_solid.contains(&e.de),
        510 => !in_shell.contains(&e.de),
        108 => !used.contains(&e.de),
        k => is_surface(k) && !used.contains(&e.de) && e.subordinate & 1 == 0,
    };
    let any_shown = dir.entities.iter().any(|e| face_entity(e) && !e.blanked);
    let mut hidden = 0usize;
    let mut r = FaceReader {
        ctx,
        out: Vec::new(),
        bodies: Vec::new(),
        shell_body: crate::collections::HashMap::default(),
        first_error: None,
        unsupported: Vec::new(),
        count: Count::default(),
        warnings,
        skipped,
    };
    for e in &dir.entities {
        if any_shown && e.blanked && (face_entity(e) || subfigures.is_root_instance(e)) {
            hidden += 1;
            continue;
        }
        if subfigures.is_member(e.de) {
            continue; // read where its subfigure's instances place it
        }
        let Some(jobs) = r.jobs(e, &subfigures, &shells) else { continue };
        for (de, job, at) in jobs {
            r.read(e, de, &job, at);
        }
    }
    let FaceReader { out, mut bodies, first_error, unsupported, warnings, skipped, .. } = r;
    if hidden > 0 {
        warnings.push(Warning::new(WarningKind::Hidden { count: hidden }));
    }
    for (kind, n) in unsupported {
        let what = if kind == 402 { "perforated planes" } else { "array or network subfigure instances" };
        warnings.push(Warning::new(WarningKind::Unsupported { count: n, kind, what }));
    }
    if bodies.iter().all(|&b| b == 0) && skipped.iter().all(|s| s.body == 0) {
        bodies.clear();
    }
    (out, bodies, first_error)
}

/// The surfaces that faces (or offsets) use, which are not faces
/// themselves; the faces in a shell; the shells in a solid.
fn uses(ctx: &Ctx<'_>) -> (HashSet<usize>, HashSet<usize>, HashSet<usize>) {
    let mut used: HashSet<usize> = HashSet::default();
    let mut in_shell: HashSet<usize> = HashSet::default();
    let mut shell_in_solid: HashSet<usize> = HashSet::default();
    for e in &ctx.dir.entities {
        let at = match e.kind {
            144 | 510 => Some(1),
            143 | 142 => Some(2),
            141 => Some(3),
            140 => Some(5),
            _ => None,
        };
        if let Some(Ok(Some(s))) = at.map(|i| e.ptr(i)) {
            used.insert(s);
        }
        if e.kind == 186 || e.kind == 514 {
            if e.kind == 186 {
                if let Ok(Some(s)) = e.ptr(1) {
                    shell_in_solid.insert(s);
                }
            }
            if let Ok(faces) = shell_faces(ctx, e.de) {
                in_shell.extend(faces);
            }
        }
    }
    (used, in_shell, shell_in_solid)
}

/// The faces read so far, and what reading them left to say.
struct FaceReader<'c, 'r> {
    ctx: &'c Ctx<'c>,
    out: Vec<Face>,
    bodies: Vec<u32>,
    /// Each B-rep shell's body, by subfigure instance and shell entity.
    shell_body: crate::collections::HashMap<(u32, usize), u32>,
    first_error: Option<Error>,
    /// Entity types not supported, and how many of each.
    unsupported: Vec<(u32, usize)>,
    /// Subfigure instances expanded so far.
    count: Count,
    warnings: &'r mut Vec<Warning>,
    skipped: &'r mut Vec<SkippedFace>,
}

impl FaceReader<'_, '_> {
    /// The faces entity `e` makes, each with where it is read (a subfigure
    /// instance's members where it places them); `None` when it makes none
    /// (not supported, or skipped with a warning).
    fn jobs(&mut self, e: &Entity, subfigures: &Subfigures, shells: &Shells<'_>) -> Option<Vec<(usize, Job, At)>> {
        let ctx = self.ctx;
        let mut jobs: Vec<(usize, Job, At)> = Vec::new();
        if subfigures.is_root_instance(e) {
            let mut placed = Vec::new();
            if let Err(err) = subfigures.expand(ctx, e.de, ctx.world, 0, &mut self.count, &mut placed) {
                skip(self.warnings, &mut self.first_error, e, err);
                return None;
            }
            for p in placed {
                let Some(member) = ctx.dir.get(p.de) else { continue };
                match shells.jobs(ctx, member, true) {
                    Ok(j) => jobs.extend(j.into_iter().map(|(de, job)| (de, job, At { m: p.m, instance: p.instance }))),
                    Err(err) => skip(self.warnings, &mut self.first_error, member, err),
                }
            }
            return Some(jobs);
        }
        if matches!(e.kind, 402 | 412 | 414 | 420) && (e.kind != 402 || e.form == 9) {
            match self.unsupported.iter_mut().find(|(k, _)| *k == e.kind) {
                Some(x) => x.1 += 1,
                None => self.unsupported.push((e.kind, 1)),
            }
            return None;
        }
        let top = At { m: ctx.world, instance: 0 };
        match shells.jobs(ctx, e, false) {
            Ok(j) => Some(j.into_iter().map(|(de, job)| (de, job, top)).collect()),
            Err(err) => {
                skip(self.warnings, &mut self.first_error, e, err);
                None
            }
        }
    }

    /// Reads entity `de` as a face by `job`, placed by `at`, for entity
    /// `e` (named when it is skipped): the face and its body, or a warning
    /// and the skipped face's border.
    fn read(&mut self, e: &Entity, de: usize, job: &Job, at: At) {
        let ctx = self.ctx;
        let fe = match ctx.entity(de) {
            Ok(fe) => fe,
            // Damaged parameter data: the directory's warning named it already.
            Err(err) if ctx.dir.get(de).is_some_and(|x| x.damage.is_some()) => {
                self.first_error.get_or_insert(err);
                return;
            }
            Err(err) => {
                skip(self.warnings, &mut self.first_error, e, err);
                return;
            }
        };
        let mut local = Vec::new();
        let result =
            face_source(ctx, fe, job, at.m).and_then(|src| build_face(src, &mut local).map_err(|m| fe.error(m)));
        for w in local {
            self.warnings.push(Warning::entity(WarningEntity::Iges { de: fe.de, kind: fe.kind }, w));
        }
        let body = match job {
            Job::Brep(parents) if !parents.is_empty() => {
                let next = self.shell_body.len() as u32 + 1;
                *self.shell_body.entry((at.instance, parents[0])).or_insert(next)
            }
            _ => 0,
        };
        match result {
            Ok(mut face) => {
                face.name = name_of(ctx, fe, job);
                self.out.push(face);
                self.bodies.push(body);
            }
            Err(err) => {
                skip(self.warnings, &mut self.first_error, fe, err);
                self.skipped.push(SkippedFace { body, border: skipped::border(ctx, fe, job, at.m) });
            }
        }
    }
}

/// Where a face is read: the map of its definition space to the output, and
/// the subfigure instance placing it (0: none).
#[derive(Clone, Copy)]
struct At {
    m: DAffine3,
    instance: u32,
}

/// What decides which entities are faces: surfaces something uses, faces
/// in shells, shells in solids.
struct Shells<'s> {
    used: &'s HashSet<usize>,
    in_shell: &'s HashSet<usize>,
    shell_in_solid: &'s HashSet<usize>,
}

impl Shells<'_> {
    /// The faces entity `e` stands for (none when it is not a face or is
    /// part of another's); `member`: listed in a subfigure, where a surface
    /// is a face whatever its subordinate switch says.
    fn jobs(&self, ctx: &Ctx<'_>, e: &Entity, member: bool) -> Result<Vec<(usize, Job)>, Error> {
        Ok(match e.kind {
            144 => alloc::vec![(e.de, Job::Trimmed)],
            143 => alloc::vec![(e.de, Job::Bounded)],
            186 => shell_faces(ctx, e.de)?.into_iter().map(|f| (f, Job::Brep(alloc::vec![e.de]))).collect(),
            514 if !self.shell_in_solid.contains(&e.de) => {
                shell_faces(ctx, e.de)?.into_iter().map(|f| (f, Job::Brep(alloc::vec![e.de]))).collect()
            }
            510 if !self.in_shell.contains(&e.de) => alloc::vec![(e.de, Job::Brep(Vec::new()))],
            108 if e.form == 1 && !self.used.contains(&e.de) => alloc::vec![(e.de, Job::BoundedPlane)],
            k if is_surface(k) && k != 108 && !self.used.contains(&e.de) && (member || e.subordinate & 1 == 0) => {
                alloc::vec![(e.de, Job::Untrimmed)]
            }
            _ => Vec::new(),
        })
    }
}

/// How one face is read.
#[derive(Debug, Clone)]
enum Job {
    Trimmed,
    Bounded,
    /// A 510 face and the solid/shell entities above it.
    Brep(Vec<usize>),
    BoundedPlane,
    Untrimmed,
}

fn skip(warnings: &mut Vec<Warning>, first: &mut Option<Error>, e: &Entity, err: Error) {
    if first.is_none() {
        *first = Some(err.clone());
    }
    warnings.push(Warning::entity(WarningEntity::Iges { de: e.de, kind: e.kind }, WarningKind::Skipped(err)));
}

/// The source of face `e` read as `job` says, its definition space mapped
/// to the output by `base` (the Global scale, and a subfigure's placement).
fn face_source(ctx: &Ctx<'_>, e: &Entity, job: &Job, base: DAffine3) -> Result<FaceSrc, Error> {
    let m = base * own_transform(ctx.dir, e.de)?;
    match job {
        Job::Trimmed => trimmed_144(ctx, e, m),
        Job::Bounded => bounded_143(ctx, e, m),
        Job::Brep(parents) => {
            if e.kind != 510 {
                return Err(e.error(alloc::format!("a shell lists type {} as a face (expected 510)", e.kind)));
            }
            let parent = chain_transform(ctx, base, parents)?;
            face_510(ctx, e, parent)
        }
        Job::BoundedPlane => {
            let (def, native) = surface_def(ctx, e.de, base, 0)?;
            let boundary = e.ptr(5)?.ok_or_else(|| e.error("bounded plane without a boundary curve"))?;
            let model = model_curve(ctx, boundary, m, 1)?;
            let loops = alloc::vec![LoopSrc { model, params: None }];
            Ok(FaceSrc { def, native, loops, domain_outer: false, resolution: ctx.resolution })
        }
        Job::Untrimmed => {
            let (def, native) = surface_def(ctx, e.de, base, 0)?;
            Ok(FaceSrc { def, native, loops: Vec::new(), domain_outer: false, resolution: ctx.resolution })
        }
    }
}

/// 144: surface, N1 (0: the outer boundary is the surface's), N2 holes,
/// outer 142, inner 142s.
fn trimmed_144(ctx: &Ctx<'_>, e: &Entity, m: DAffine3) -> Result<FaceSrc, Error> {
    let surf = e.ptr(1)?.ok_or_else(|| e.error("trimmed surface without a surface"))?;
    let (def, native) = surface_def(ctx, surf, m, 0)?;
    let n1 = e.int(2)?;
    let n2 = e.count(3, 1, 5)?;
    let mut loops = Vec::with_capacity(n2 + 1);
    let outer = if n1 != 0 { e.ptr(4)? } else { None };
    if let Some(o) = outer {
        loops.push(curve_on_surface(ctx, e, o, m)?);
    }
    for k in 0..n2 {
        if let Some(h) = e.ptr(5 + k)? {
            loops.push(curve_on_surface(ctx, e, h, m)?);
        }
    }
    Ok(FaceSrc { def, native, loops, domain_outer: outer.is_none(), resolution: ctx.resolution })
}

/// 142: creation flag, surface, parameter curve B, model curve C, preference
/// (0 none, 1 B, 2 C, 3 both).
fn curve_on_surface(ctx: &Ctx<'_>, owner: &Entity, de: usize, m: DAffine3) -> Result<LoopSrc, Error> {
    let e = ctx.entity(de)?;
    if e.kind != 142 {
        return Err(owner.error(alloc::format!("boundary pointer {de} names type {}, not 142", e.kind)));
    }
    let m = m * own_transform(ctx.dir, de)?;
    let b = e.ptr(3)?;
    let c = e.ptr(4)?;
    let pref = e.int(5)?;
    let model = match c {
        Some(c) => model_curve(ctx, c, m, 1)?,
        None => Vec::new(),
    };
    let want_params = pref != 2 || model.is_empty();
    let params = match b {
        Some(b) if want_params => Some(param_curve(ctx, b)?),
        _ => None,
    };
    Ok(LoopSrc { model, params })
}

/// 143: type, surface, boundaries (141 each).
fn bounded_143(ctx: &Ctx<'_>, e: &Entity, m: DAffine3) -> Result<FaceSrc, Error> {
    let surf = e.ptr(2)?.ok_or_else(|| e.error("bounded surface without a surface"))?;
    let (def, native) = surface_def(ctx, surf, m, 0)?;
    let n = e.count(3, 1, 4)?;
    let mut loops = Vec::with_capacity(n);
    for k in 0..n {
        let Some(b) = e.ptr(4 + k)? else { continue };
        loops.push(boundary_141(ctx, e, b, m)?);
    }
    Ok(FaceSrc { def, native, loops, domain_outer: false, resolution: ctx.resolution })
}

/// 141: type, preference (1 model space, 2 parameter space), surface, N
/// curves each with its sense (1 agrees, 2 reversed) and parameter curves.
fn boundary_141(ctx: &Ctx<'_>, owner: &Entity, de: usize, m: DAffine3) -> Result<LoopSrc, Error> {
    let e = ctx.entity(de)?;
    if e.kind != 141 {
        return Err(owner.error(alloc::format!("boundary pointer {de} names type {}, not 141", e.kind)));
    }
    let m = m * own_transform(ctx.dir, de)?;
    let with_params = e.int(1)? == 1;
    let pref = e.int(2)?;
    let n = e.count(4, 3, 5)?;
    let mut at = 5;
    let mut model = Vec::new();
    let mut params = Vec::new();
    let mut all = with_params;
    for _ in 0..n {
        let c = e.ptr(at)?;
        let sense = e.int(at + 1)?;
        let k = e.count(at + 2, 1, at + 3)?;
        if let Some(c) = c {
            let pieces = model_curve(ctx, c, m, 1)?;
            model.extend(if sense == 2 { reverse_all(e, pieces)? } else { pieces });
        }
        if k == 0 {
            all = false;
        }
        for j in 0..k {
            if let Some(p) = e.ptr(at + 3 + j)? {
                params.extend(param_curve(ctx, p)?);
            }
        }
        at += 3 + k;
    }
    let use_params = all && !params.is_empty() && (pref != 1 || model.is_empty());
    Ok(LoopSrc { model, params: use_params.then_some(params) })
}

/// A 406 form 15 name property attached to the face entity.
fn name_of(ctx: &Ctx<'_>, e: &Entity, job: &Job) -> Option<String> {
    let used = match (job, e.kind) {
        (Job::Trimmed, _) => 5 + usize::try_from(e.int(3).ok()?).ok()?,
        (Job::Bounded, _) | (Job::Brep(_), 510) => {
            let at = if e.kind == 510 { 2 } else { 3 };
            4 + usize::try_from(e.int(at).ok()?).ok()?
        }
        _ => return None,
    };
    for p in e.properties(used.min(e.params.len())) {
        if let Ok(prop) = ctx.entity(p) {
            if prop.kind == 406 && prop.form == 15 {
                if let Some(s) = prop.string(2) {
                    let s = s.trim();
                    if !s.is_empty() {
                        return Some(s.into());
                    }
                }
            }
        }
    }
    None
}
