//! Meshing by instances: each shape of an assembly ([`Assembly`]) is meshed
//! once, and every part instance is that mesh under its matrix.
//!
//! A shape's faces are those of its first instance (the reference), meshed
//! as a model of their own with the tolerance the whole model gives (a
//! relative tolerance is taken from the whole model's box), then moved into
//! the coordinates of the reference's node. Instances whose matrix is not a
//! rigid motion (a scaled or mirrored placement) are shapes of their own,
//! meshed where they are. Parts share no border (each is its own body), so
//! meshing them apart loses no sewing; the report adds up what every
//! instance holds, so it describes the whole model as one merged mesh
//! ([`flatten`]) would.

use alloc::vec::Vec;
use glam::DAffine3;

use crate::collections::HashMap;
use crate::model::{body_of, SkippedFace};
use crate::options::{ElementSize, MeshOptions, Tolerance};
use crate::report::{MeshResult, QualityReport, Report};
use crate::units::{mesh_model_in_units, mm_per_unit, Units};
use crate::warning::WarningKind;
use crate::{Assembly, Error, FaceRange, Mesh, Model};

/// One shape's mesh, in the coordinates of its instances' node.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct PartMesh {
    /// The triangles, one face range per face of the shape.
    pub mesh: Mesh,
    /// For each face of `mesh`, the model's face it is (in the shape's
    /// first instance).
    pub faces: Vec<usize>,
    /// How many part instances are this mesh.
    pub instances: usize,
}

/// What [`mesh_instanced`] returns.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct InstancedResult {
    /// One mesh per distinct shape.
    pub parts: Vec<PartMesh>,
    /// One per part instance of the assembly, in its order: the index of
    /// its mesh in `parts`, and the matrix from that mesh's coordinates to
    /// the model's (in the result's unit).
    pub instances: Vec<(usize, DAffine3)>,
    /// The whole model's figures, as if every instance had been meshed:
    /// counts summed over the instances, extremes over the parts.
    pub report: Report,
    /// Faces meshed: the faces of the parts, each once.
    pub faces_meshed: usize,
}

/// Largest deviation of a placement's linear part from a rotation for it
/// to count as rigid.
const RIGID: f64 = 1e-9;

/// Whether `m` moves without scaling or mirroring.
fn is_rigid(m: &DAffine3) -> bool {
    let a = m.matrix3;
    let t = a.transpose() * a;
    let id = glam::DMat3::IDENTITY;
    let off = (0..3).all(|c| (t.col(c) - id.col(c)).abs().max_element() <= RIGID);
    off && a.determinant() > 0.0 && m.translation.is_finite()
}

/// Meshes `model` by the shapes of `assembly`, each once (see the module
/// documentation). `progress` counts the faces of the shapes. With
/// `options.share`, the shapes are split among the shares (or, with fewer
/// shapes than shares, each shape's bodies are, as [`MeshOptions::share`]
/// says); the parts a share does not mesh come back with empty face ranges.
///
/// # Errors
/// As [`mesh_model_in_units`]; a face named in an error or a warning is
/// the model's face.
pub fn mesh_instanced(
    model: &Model,
    assembly: &Assembly,
    options: &MeshOptions,
    units: Units,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<InstancedResult, Error> {
    let faces = model.face_count();
    let single;
    let assembly = if assembly.face_instances.len() == faces && !assembly.instances.is_empty() {
        assembly
    } else {
        single = Assembly::single("", faces);
        &single
    };
    let plan = Plan::new(model, assembly);
    // From the file's unit to the result's.
    let k = match units.name() {
        Some(name) => match mm_per_unit(&model.units) {
            Some(from) => from / mm_per_unit(name).unwrap_or(1.0),
            // The mesher refuses it, with the message that says why.
            None => return mesh_model_in_units(model, options, units, progress).map(|r| whole(r, faces)),
        },
        None => 1.0,
    };
    let in_units = |m: &DAffine3| DAffine3 { matrix3: m.matrix3, translation: m.translation * k };
    if plan.parts.len() == 1 && plan.parts[0].instances.len() == 1 && plan.parts[0].faces.len() == faces {
        // One part: the model itself, meshed as it is.
        let r = mesh_model_in_units(model, options, units, progress)?;
        let mut result = whole(r, faces);
        let m = assembly.instances[0].matrix;
        if plan.parts[0].rigid && m != DAffine3::IDENTITY {
            move_mesh(&mut result.parts[0].mesh, &in_units(&m).inverse());
            result.instances[0].1 = in_units(&m);
        }
        return Ok(result);
    }
    let options = absolute(model, options, k);
    // Which parts this call meshes.
    let (mine, pass_share) = match options.share {
        Some((index, count)) if plan.parts.len() >= count as usize => (share_parts(&plan.parts, index, count), None),
        share => (alloc::vec![true; plan.parts.len()], share),
    };
    let total: usize = plan.parts.iter().zip(&mine).filter(|(_, m)| **m).map(|(p, _)| p.faces.len()).sum();
    let mut done_before = 0usize;
    let mut results: Vec<Option<MeshResult>> = Vec::with_capacity(plan.parts.len());
    for (p, part) in plan.parts.iter().enumerate() {
        if !mine[p] {
            results.push(None);
            continue;
        }
        let sub = plan.model_of(model, p);
        let mut o = options.clone();
        o.share = pass_share;
        let mut step = |done: usize, _: usize| progress(done_before + done, total);
        let r = mesh_model_in_units(&sub, &o, units, &mut step).map_err(|e| renumber_error(e, &part.faces))?;
        done_before += part.faces.len();
        results.push(Some(r));
    }
    let mut out = InstancedResult { faces_meshed: total, ..InstancedResult::default() };
    let mut reports: Vec<(Report, usize)> = Vec::new();
    for (part, r) in plan.parts.iter().zip(results) {
        let n = part.instances.len();
        let Some(MeshResult { mut mesh, mut report }) = r else {
            let mesh = Mesh { face_ranges: alloc::vec![FaceRange::default(); part.faces.len()], ..Mesh::default() };
            out.parts.push(PartMesh { mesh, faces: part.faces.clone(), instances: n });
            continue;
        };
        let reference = &assembly.instances[part.instances[0]];
        if part.rigid && reference.matrix != DAffine3::IDENTITY {
            move_mesh(&mut mesh, &in_units(&reference.matrix).inverse());
        }
        renumber_report(&mut report, &part.faces);
        reports.push((report, n));
        out.parts.push(PartMesh { mesh, faces: part.faces.clone(), instances: n });
    }
    out.instances = assembly
        .instances
        .iter()
        .enumerate()
        .map(|(i, inst)| {
            let p = plan.part_of[i];
            let m = if plan.parts[p].rigid { in_units(&inst.matrix) } else { DAffine3::IDENTITY };
            (p, m)
        })
        .collect();
    out.report = merge_reports(model, &reports, &options);
    Ok(out)
}

/// A single mesh result as an instanced one: one part, one instance.
fn whole(r: MeshResult, faces: usize) -> InstancedResult {
    let faces_meshed = r.mesh.face_ranges.len().min(faces);
    InstancedResult {
        parts: alloc::vec![PartMesh { mesh: r.mesh, faces: (0..faces).collect(), instances: 1 }],
        instances: alloc::vec![(0, DAffine3::IDENTITY)],
        report: r.report,
        faces_meshed,
    }
}

/// One distinct shape: the instances that are it, its reference's faces.
struct PartPlan {
    instances: Vec<usize>,
    faces: Vec<usize>,
    rigid: bool,
}

/// How the model's faces and instances come to parts.
struct Plan {
    parts: Vec<PartPlan>,
    /// Each instance's part.
    part_of: Vec<usize>,
}

impl Plan {
    fn new(model: &Model, assembly: &Assembly) -> Self {
        let n = assembly.instances.len();
        let mut faces_of: Vec<Vec<usize>> = alloc::vec![Vec::new(); n];
        for (f, &k) in assembly.face_instances.iter().enumerate() {
            if let Some(v) = faces_of.get_mut(k as usize) {
                v.push(f);
            }
        }
        let exact = model.faces.len();
        // Instances share a part when they share a shape, move rigidly and
        // have as many exact and tessellated faces.
        let mut by_key: HashMap<(usize, usize, usize), usize> = HashMap::default();
        let mut parts: Vec<PartPlan> = Vec::new();
        let mut part_of = Vec::with_capacity(n);
        for (i, inst) in assembly.instances.iter().enumerate() {
            let rigid = is_rigid(&inst.matrix);
            let tess = faces_of[i].iter().filter(|&&f| f >= exact).count();
            let key = (inst.shape, faces_of[i].len(), tess);
            let existing = if rigid { by_key.get(&key).copied() } else { None };
            let p = match existing {
                Some(p) => p,
                None => {
                    parts.push(PartPlan { instances: Vec::new(), faces: faces_of[i].clone(), rigid });
                    if rigid {
                        by_key.insert(key, parts.len() - 1);
                    }
                    parts.len() - 1
                }
            };
            parts[p].instances.push(i);
            part_of.push(p);
        }
        Self { parts, part_of }
    }

    /// The model of part `p`: its reference's faces, bodies and skipped faces.
    fn model_of(&self, model: &Model, p: usize) -> Model {
        let part = &self.parts[p];
        let exact = model.faces.len();
        let mut faces = Vec::new();
        let mut tessellated = Vec::new();
        let mut bodies = Vec::with_capacity(part.faces.len());
        for &f in &part.faces {
            if f < exact {
                faces.push(model.faces[f].clone());
            } else if let Some(t) = model.tessellated.get(f - exact) {
                tessellated.push(t.clone());
            }
        }
        // Bodies in the sub-model's face order: exact faces, then tessellated.
        let (ex, te): (Vec<usize>, Vec<usize>) = part.faces.iter().partition(|&&f| f < exact);
        for &f in ex.iter().chain(&te) {
            bodies.push(body_of(&model.bodies, f));
        }
        let skipped: Vec<SkippedFace> = model.skipped.iter().filter(|s| bodies.contains(&s.body)).cloned().collect();
        Model {
            units: model.units.clone(),
            faces,
            warnings: Vec::new(),
            tolerance: model.tolerance,
            bodies,
            tessellated,
            skipped,
        }
    }
}

/// Parts among `count` shares: the largest (most faces) first, each to the
/// share with the fewest faces so far; ties by part and by share index, so
/// that every worker computes the same split.
fn share_parts(parts: &[PartPlan], index: u32, count: u32) -> Vec<bool> {
    let mut order: Vec<usize> = (0..parts.len()).collect();
    crate::sort::by_u64(&mut order, |&a| u64::MAX - parts[a].faces.len() as u64);
    let count = count.max(1) as usize;
    let mut load = alloc::vec![0usize; count];
    let mut owner = alloc::vec![0usize; parts.len()];
    for p in order {
        let to = (0..count).min_by_key(|&i| (load[i], i)).unwrap_or(0);
        load[to] += parts[p].faces.len().max(1);
        owner[p] = to;
    }
    owner.iter().map(|&o| o == index as usize).collect()
}

/// `options` with a relative tolerance (and element size) made absolute
/// from the whole model's box, `k` result units per file unit.
fn absolute(model: &Model, options: &MeshOptions, k: f64) -> MeshOptions {
    let mut o = options.clone();
    let relative_size = matches!(o.quality.size, ElementSize::Relative(_));
    if !matches!(o.tolerance, Tolerance::Relative(_)) && !relative_size {
        return o;
    }
    let diag = crate::model::trimmed_bbox(model).diagonal() * k;
    // A model of no size keeps its relative tolerance: the mesher says why it cannot mesh.
    let usable = |x: f64| x > 0.0 && x.is_finite();
    if let Tolerance::Relative(r) = o.tolerance {
        if usable(r * diag) {
            o.tolerance = Tolerance::Absolute(r * diag);
        }
    }
    if let ElementSize::Relative(r) = o.quality.size {
        if usable(r * diag) {
            o.quality.size = ElementSize::Absolute(r * diag);
        }
    }
    o
}

/// Moves a mesh by the rigid motion `m` (positions and normals).
fn move_mesh(mesh: &mut Mesh, m: &DAffine3) {
    for p in &mut mesh.positions {
        *p = m.transform_point3(*p);
    }
    for n in &mut mesh.normals {
        *n = m.transform_vector3(*n);
    }
}

fn renumber_report(report: &mut Report, faces: &[usize]) {
    let renumber = |j: &mut usize| {
        if let Some(&f) = faces.get(*j) {
            *j = f;
        }
    };
    for w in &mut report.warnings {
        if let Some(j) = &mut w.face {
            renumber(j);
        }
        if let WarningKind::FacesApart { faces: (a, b), .. } = &mut w.kind {
            renumber(a);
            renumber(b);
        }
    }
    for r in &mut report.reparameterized {
        if let Some(&f) = faces.get(r.face) {
            r.face = f;
        }
    }
}

/// A part's meshing error with the whole model's face number.
fn renumber_error(e: Error, faces: &[usize]) -> Error {
    match e {
        Error::Mesh { face, message } => Error::Mesh { face: faces.get(face).copied().unwrap_or(face), message },
        e => e,
    }
}

/// The whole model's report from its parts' (each with its instance count).
fn merge_reports(model: &Model, parts: &[(Report, usize)], options: &MeshOptions) -> Report {
    let mut out = Report {
        faces: model.face_count(),
        faces_unread: model.skipped.len(),
        angle: options.angle,
        ..Report::default()
    };
    let mut bodies: Vec<u32> = (0..model.face_count()).map(|f| body_of(&model.bodies, f)).collect();
    bodies.sort_unstable();
    bodies.dedup();
    out.bodies = bodies.len();
    out.warnings.extend(model.warnings.iter().cloned());
    let mut deviation_sum = 0.0;
    let mut min_angle = f64::INFINITY;
    let mut p1_angle = f64::INFINITY;
    let mut quality: Option<(QualityReport, f64)> = None;
    for (r, n) in parts {
        if out.units.is_empty() {
            out.units = r.units.clone();
            out.tolerance = r.tolerance;
        }
        out.tolerance = out.tolerance.max(r.tolerance);
        out.faces_skipped += n * r.faces_skipped;
        out.faces_tessellated += n * r.faces_tessellated;
        out.triangles += n * r.triangles;
        out.vertices += n * r.vertices;
        out.free_edges += n * r.free_edges;
        out.boundary_edges += n * r.boundary_edges;
        out.nonmanifold_edges += n * r.nonmanifold_edges;
        out.inverted_triangles += n * r.inverted_triangles;
        out.max_deviation = out.max_deviation.max(r.max_deviation);
        out.max_normal_turn = out.max_normal_turn.max(r.max_normal_turn);
        deviation_sum += r.mean_deviation * (n * r.triangles) as f64;
        if r.triangles > 0 {
            min_angle = min_angle.min(r.min_angle_deg);
            p1_angle = p1_angle.min(r.p1_angle_deg);
        }
        for w in &r.warnings {
            if !out.warnings.contains(w) {
                out.warnings.push(w.clone());
            }
        }
        out.reparameterized.extend(r.reparameterized.iter().cloned());
        if let Some(q) = &r.quality {
            // Counts summed over the instances, fractions and the mean
            // weighted by triangles, extremes kept.
            let weight = (n * r.triangles) as f64;
            match &mut quality {
                None => {
                    let mut first = q.clone();
                    first.faces_looping *= n;
                    first.faces_delaunay *= n;
                    quality = Some((first, weight));
                }
                Some((acc, w)) => {
                    acc.faces_looping += n * q.faces_looping;
                    acc.faces_delaunay += n * q.faces_delaunay;
                    let total = *w + weight;
                    if total > 0.0 {
                        let mix = |a: f64, b: f64| (a * *w + b * weight) / total;
                        acc.good_angle_fraction = mix(acc.good_angle_fraction, q.good_angle_fraction);
                        acc.edge_band_fraction = mix(acc.edge_band_fraction, q.edge_band_fraction);
                        acc.edge_ratio_mean = mix(acc.edge_ratio_mean, q.edge_ratio_mean);
                    }
                    acc.edge_ratio_min = acc.edge_ratio_min.min(q.edge_ratio_min);
                    acc.edge_ratio_max = acc.edge_ratio_max.max(q.edge_ratio_max);
                    *w = total;
                }
            }
        }
    }
    out.mean_deviation = if out.triangles > 0 { deviation_sum / out.triangles as f64 } else { 0.0 };
    out.min_angle_deg = if min_angle.is_finite() { min_angle } else { 0.0 };
    out.p1_angle_deg = if p1_angle.is_finite() { p1_angle } else { 0.0 };
    out.quality = quality.map(|(q, _)| q);
    if out.units.is_empty() {
        out.units = model.units.clone();
    }
    out
}

/// The model's one merged mesh from an instanced result: every face of the
/// model in its order (faces, then tessellated faces), each instance's
/// triangles its part's under its matrix. `assembly` is the one the result
/// was meshed by.
pub fn flatten(result: &InstancedResult, assembly: &Assembly) -> Mesh {
    let faces = assembly.face_instances.len();
    if result.parts.len() == 1 && result.instances.len() <= 1 {
        let part = &result.parts[0];
        let mut mesh = part.mesh.clone();
        if let Some((_, m)) = result.instances.first().filter(|(_, m)| *m != DAffine3::IDENTITY) {
            move_mesh(&mut mesh, m);
        }
        return mesh;
    }
    // The place of each face within its instance: the same place in its part.
    let mut seen = alloc::vec![0usize; result.instances.len()];
    let mut out = Mesh::default();
    let most = result.parts.iter().map(|p| p.mesh.positions.len()).max().unwrap_or(0);
    let mut remap: Vec<u32> = alloc::vec![u32::MAX; most];
    let mut touched: Vec<u32> = Vec::new();
    for f in 0..faces {
        let k = assembly.face_instances[f] as usize;
        let Some(&(p, m)) = result.instances.get(k) else {
            out.face_ranges.push(FaceRange { first: out.triangle_count() as u32, count: 0 });
            continue;
        };
        let j = seen[k];
        seen[k] += 1;
        let first = out.triangle_count() as u32;
        let Some(part) = result.parts.get(p) else {
            out.face_ranges.push(FaceRange { first, count: 0 });
            continue;
        };
        let mesh = &part.mesh;
        let r = mesh.face_ranges.get(j).copied().unwrap_or_default();
        let tris = mesh.indices.get(3 * r.first as usize..3 * (r.first + r.count) as usize).unwrap_or_default();
        for &v in tris {
            let (Some(slot), Some(&p), Some(&n)) =
                (remap.get_mut(v as usize), mesh.positions.get(v as usize), mesh.normals.get(v as usize))
            else {
                continue;
            };
            if *slot == u32::MAX {
                *slot = out.positions.len() as u32;
                touched.push(v);
                out.positions.push(m.transform_point3(p));
                out.normals.push(m.transform_vector3(n));
            }
            out.indices.push(*slot);
        }
        for v in touched.drain(..) {
            remap[v as usize] = u32::MAX;
        }
        out.face_ranges.push(FaceRange { first, count: r.count });
    }
    out
}
