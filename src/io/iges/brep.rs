//! B-rep entities: manifold solid (186) → shells (514) → faces (510) →
//! loops (508) of edges (504, with vertices 502). A loop's edges carry their
//! model-space curves and, optionally, parameter-space curves.

use alloc::vec::Vec;
use glam::DAffine3;

use super::curves::{model_curve, param_curve};
use super::directory::Entity;
use super::loops::{FaceSrc, LoopSrc};
use super::surfaces::surface_def;
use super::xform::own_transform;
use super::Ctx;
use crate::nurbs::reparam::reversed;
use crate::nurbs::NurbsCurve;
use crate::Error;

/// Faces (510 entries) of a 186 solid's shells, or of one 514 shell.
///
/// # Errors
/// Bad pointers or counts.
pub(super) fn shell_faces(ctx: &Ctx<'_>, de: usize) -> Result<Vec<usize>, Error> {
    let e = ctx.entity(de)?;
    let shells: Vec<usize> = match e.kind {
        186 => {
            let mut v = Vec::new();
            if let Some(s) = e.ptr(1)? {
                v.push(s);
            }
            let n = e.count(3, 2, 4)?;
            for k in 0..n {
                if let Some(s) = e.ptr(4 + 2 * k)? {
                    v.push(s);
                }
            }
            v
        }
        _ => alloc::vec![de],
    };
    let mut faces = Vec::new();
    for s in shells {
        let sh = ctx.entity(s)?;
        if sh.kind != 514 {
            return Err(e.error(alloc::format!("pointer {s} should name a shell (514), not type {}", sh.kind)));
        }
        let n = sh.count(1, 2, 2)?;
        for k in 0..n {
            if let Some(f) = sh.ptr(2 + 2 * k)? {
                faces.push(f);
            }
        }
    }
    Ok(faces)
}

/// The transformation of the 186/514 chain a face sits in, after `base`, as `parent`.
pub(super) fn chain_transform(ctx: &Ctx<'_>, base: DAffine3, parents: &[usize]) -> Result<DAffine3, Error> {
    let mut m = base;
    for &p in parents {
        m *= own_transform(ctx.dir, p)?;
    }
    Ok(m)
}

/// A 510 face: its surface and loops.
///
/// # Errors
/// Bad pointers, counts or geometry.
pub(super) fn face_510(ctx: &Ctx<'_>, e: &Entity, parent: DAffine3) -> Result<FaceSrc, Error> {
    let m = parent * own_transform(ctx.dir, e.de)?;
    let surf = e.ptr(1)?.ok_or_else(|| e.error("face without a surface"))?;
    let (def, native) = surface_def(ctx, surf, m, 0)?;
    let n = e.count(2, 1, 4)?;
    let mut loops = Vec::with_capacity(n);
    for k in 0..n {
        let Some(l) = e.ptr(4 + k)? else { continue };
        loops.push(loop_508(ctx, l, m)?);
    }
    Ok(FaceSrc { def, native, loops, domain_outer: false, resolution: ctx.resolution })
}

/// A 508 loop: each edge's model curve oriented as the loop uses it, and
/// the parameter-space curves when every edge has them.
pub(super) fn loop_508(ctx: &Ctx<'_>, de: usize, m: DAffine3) -> Result<LoopSrc, Error> {
    let e = ctx.entity(de)?;
    if e.kind != 508 {
        return Err(e.error(alloc::format!("a face's loop pointer names type {}, not a loop (508)", e.kind)));
    }
    let n = e.count(1, 5, 2)?;
    let mut at = 2;
    let mut model: Vec<NurbsCurve> = Vec::new();
    let mut params: Vec<NurbsCurve> = Vec::new();
    let mut all_params = true;
    for _ in 0..n {
        let kind = e.int(at)?;
        let list = e.ptr(at + 1)?;
        let index = e.int(at + 2)?;
        let agrees = e.int(at + 3)? != 0;
        let k = e.count(at + 4, 2, at + 5)?;
        let pcs: Vec<usize> = (0..k).filter_map(|j| e.ptr(at + 6 + 2 * j).ok().flatten()).collect();
        at += 5 + 2 * k;
        if kind == 1 {
            continue; // a vertex: nothing to trace
        }
        let list = list.ok_or_else(|| e.error("loop edge without an edge list"))?;
        let curve = edge_curve(ctx, e, list, index)?;
        let mut pieces = model_curve(ctx, curve, m, 1)?;
        if !agrees {
            pieces = reverse_all(e, pieces)?;
        }
        model.extend(pieces);
        if pcs.is_empty() {
            all_params = false;
        } else {
            let mut p = Vec::new();
            for c in pcs {
                p.extend(param_curve(ctx, c)?);
            }
            params.extend(p);
        }
    }
    Ok(LoopSrc { model, params: (all_params && !params.is_empty()).then_some(params) })
}

/// The model curve of edge `index` (1-based) of edge list `list`.
fn edge_curve(ctx: &Ctx<'_>, owner: &Entity, list: usize, index: i64) -> Result<usize, Error> {
    let l = ctx.entity(list)?;
    if l.kind != 504 {
        return Err(owner.error(alloc::format!("edge list pointer {list} names type {}, not 504", l.kind)));
    }
    let n = l.count(1, 5, 2)?;
    let i = usize::try_from(index)
        .ok()
        .filter(|&i| i >= 1 && i <= n)
        .ok_or_else(|| owner.error(alloc::format!("edge index {index} outside the edge list's {n} edges")))?;
    l.ptr(2 + 5 * (i - 1))?.ok_or_else(|| l.error(alloc::format!("edge {i} has no curve")))
}

/// The pieces traversed backwards.
pub(super) fn reverse_all(e: &Entity, pieces: Vec<NurbsCurve>) -> Result<Vec<NurbsCurve>, Error> {
    pieces.iter().rev().map(|c| reversed(c).map_err(|err| e.error(alloc::format!("{err}")))).collect()
}
