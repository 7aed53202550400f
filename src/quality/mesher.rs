//! The quality mesher (paper 003): boundary, mapping, filling, improvement.

use crate::numeric::TINY;
use alloc::format;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::boundary::{self, FaceBoundary};
#[cfg(feature = "std")]
use super::delaunay;
use super::improve::{self, min_angle, FaceMesh};
use super::looping;
use super::mapping::PlaneMap;
use crate::mesh::{edge_counts_around_skipped, weld_positions, FaceRange};
use crate::model::Face;
use crate::model::LoopSample;
use crate::nurbs::Surface;
use crate::nurbs::{project_to_surface, ProjectionOptions};
use crate::options::{ElementSize, MeshOptions, QualityMethod, Tolerance};
use crate::report::{MeshResult, QualityReport, Report, EDGE_BAND, GOOD_ANGLE_DEG};
use crate::warning::{QualityError, Warning, WarningKind};
use crate::{Error, Mesh, Model};

/// Quality of one face's mesh: (good-angle fraction, edge-band fraction).
fn face_score(m: &FaceMesh, size: f64) -> (f64, f64) {
    let good = m
        .tris
        .iter()
        .filter(|t| {
            min_angle(m.x[t[0] as usize], m.x[t[1] as usize], m.x[t[2] as usize]).to_degrees() >= GOOD_ANGLE_DEG
        })
        .count();
    let mut edges = 0usize;
    let mut band = 0usize;
    for t in &m.tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let l = m.x[a as usize].distance(m.x[b as usize]) / size;
            edges += 1;
            if (EDGE_BAND[0]..=EDGE_BAND[1]).contains(&l) {
                band += 1;
            }
        }
    }
    let n = m.tris.len().max(1) as f64;
    (good as f64 / n, band as f64 / edges.max(1) as f64)
}

/// Meshes every face of `model` with near-equilateral triangles of the size
/// `options.quality.size` (paper 003), faces conforming across shared
/// edges; the report carries the usual measures plus [`QualityReport`].
///
/// # Errors
/// Invalid options, an empty model, or a size so small for the model that
/// the triangle limit would be passed (checked before any work).
pub(crate) fn mesh_quality(
    model: &Model,
    options: &MeshOptions,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<MeshResult, Error> {
    options.validate()?;
    let q = &options.quality;
    q.validate()?;
    if model.faces.is_empty() {
        return Err(Error::Model { location: "model".into(), message: "has no faces".into() });
    }
    let diag = crate::model::trimmed_bbox(model).diagonal();
    let size = match q.size {
        ElementSize::Absolute(h) => h,
        ElementSize::Relative(r) => r * diag,
    };
    let tol = match options.tolerance {
        Tolerance::Absolute(t) => t,
        Tolerance::Relative(r) => r * diag,
    };
    if !(size > 0.0 && size.is_finite() && tol > 0.0 && tol.is_finite()) {
        return Err(Error::Model { location: "model".into(), message: "has zero size; use an absolute --size".into() });
    }
    // Bound the work before doing any: the area over an equilateral triangle's.
    let area: f64 = model.faces.iter().map(estimate_area).sum();
    let wanted = area / (0.25 * crate::math::sqrt(3.0) * size * size);
    if wanted.is_nan() || wanted > q.max_triangles as f64 {
        return Err(Error::Limit(format!(
            "quality mode: size {size:.4e} on a model of area {area:.4e} needs about {wanted:.3e} triangles, over \
             the limit of {}; choose a larger size",
            q.max_triangles
        )));
    }
    let sew_auto = (0.5 * tol).min(1e-4 * diag.max(tol));
    let sew = options
        .sew
        .unwrap_or_else(|| {
            model.tolerance.filter(|t| t.is_finite() && *t > 0.0).map_or(sew_auto, |t| sew_auto.max(t.min(0.5 * tol)))
        })
        .min(0.05 * size);
    let boundaries =
        boundary::discretize(&model.faces, size, sew, q.max_triangles).map_err(|e| Error::Limit(format!("{e}")))?;

    let mut report = Report { tolerance: tol, angle: options.angle, faces: model.faces.len(), ..Report::default() };
    report.warnings.extend(model.warnings.iter().cloned());
    let mut qr = QualityReport { size, ..QualityReport::default() };
    let mut mesh = Mesh::default();
    let (mut dev_sum, mut dev_count) = (0.0, 0u64);
    let mut left = q.max_triangles.saturating_mul(2);
    for (index, (face, fb)) in model.faces.iter().zip(boundaries).enumerate() {
        let first = mesh.triangle_count() as u32;
        let result = fb.and_then(|fb| mesh_face(face, &fb, options, size, left));
        match result {
            Ok((fm, looping, dropped)) => {
                if dropped > 0 {
                    report.warnings.push(Warning::face(index, WarningKind::QualityLoopsUnfilled { loops: dropped }));
                }
                if looping {
                    qr.faces_looping += 1;
                } else {
                    qr.faces_delaunay += 1;
                }
                left = left.saturating_sub(fm.uv.len());
                let s: &dyn Surface = &face.surface;
                let base = mesh.positions.len() as u32;
                for (k, &x) in fm.x.iter().enumerate() {
                    mesh.positions.push(x);
                    mesh.normals.push(s.normal(fm.uv[k]));
                }
                for t in &fm.tris {
                    let p = t.map(|v| fm.x[v as usize]);
                    if p[0] == p[1] || p[1] == p[2] || p[2] == p[0] {
                        continue; // collapsed at a pole
                    }
                    let uv = t.map(|v| fm.uv[v as usize]);
                    let (max, sum, count) = deviation(s, p, uv, options.measure_steps);
                    report.max_deviation = report.max_deviation.max(max);
                    dev_sum += sum;
                    dev_count += count;
                    let facet = (p[1] - p[0]).cross(p[2] - p[0]);
                    if facet.dot(s.normal((uv[0] + uv[1] + uv[2]) / 3.0)) <= 0.0 {
                        report.inverted_triangles += 1;
                    }
                    mesh.indices.extend(t.iter().map(|&v| v + base));
                }
            }
            Err(why) => {
                report.faces_skipped += 1;
                report.warnings.push(Warning::face(index, WarningKind::QualityNotMeshed(why)));
            }
        }
        mesh.face_ranges.push(FaceRange { first, count: mesh.triangle_count() as u32 - first });
        if !progress(index + 1, model.faces.len()) {
            return Err(Error::Cancelled);
        }
    }
    report.mean_deviation = if dev_count > 0 { dev_sum / dev_count as f64 } else { 0.0 };
    report.triangles = mesh.triangle_count();
    report.vertices = mesh.positions.len();
    let edges = edge_counts_around_skipped(&mesh, &[], &model.skipped, (sew * 0.5).min(tol * 1e-3), tol.max(sew));
    crate::mesh::holes_warning(&model.skipped, edges.hole_edges, &mut report.warnings);
    report.take_edges_and_angles(&edges, &mesh);
    fill_quality(&mesh, &mut qr, sew * 0.5);
    report.quality = Some(qr);
    Ok(MeshResult { mesh, report })
}

/// Distance from the samples of a barycentric grid of `steps` divisions on
/// a triangle (corners left out: they lie on the surface) to the face's
/// surface: Newton from the sample's interpolated (u,v); where that ends
/// farther than 2% of the triangle's longest edge (a pole or seam nearby),
/// the safeguarded projection from there (retries around poles and across
/// creases), and beyond 20% the global one; (max, sum, count).
fn deviation(s: &dyn Surface, p: [DVec3; 3], uv: [DVec2; 3], steps: usize) -> (f64, f64, u64) {
    let near = crate::tessellate::measure::measure_projection();
    let far = ProjectionOptions { max_iterations: 16, parameter_tolerance: 1e-11, search_samples: 12 };
    let longest = p[0].distance(p[1]).max(p[1].distance(p[2])).max(p[2].distance(p[0]));
    let n = steps.max(2);
    let (mut max, mut sum, mut count) = (0.0f64, 0.0, 0u64);
    for i in 0..=n {
        for j in 0..=(n - i) {
            let k = n - i - j;
            if i == n || j == n || k == n {
                continue;
            }
            let (a, b, c) = (i as f64 / n as f64, j as f64 / n as f64, k as f64 / n as f64);
            let q = p[0] * a + p[1] * b + p[2] * c;
            let hint = uv[0] * a + uv[1] * b + uv[2] * c;
            let mut d = crate::tessellate::measure::distance_from_hint(s, q, hint, &near);
            if d > 0.02 * longest {
                d = d.min(project_to_surface(s, q, Some(hint), &far).distance);
            }
            if d > 0.2 * longest {
                d = d.min(project_to_surface(s, q, None, &far).distance);
            }
            max = max.max(d);
            sum += d;
            count += 1;
        }
    }
    (max, sum, count)
}

/// Good-angle and edge-band fractions of the whole mesh, edges counted once
/// after welding vertices closer than `weld`.
fn fill_quality(mesh: &Mesh, qr: &mut QualityReport, weld: f64) {
    let n = mesh.triangle_count();
    if n == 0 {
        return;
    }
    let good = (0..n)
        .filter(|&t| {
            let [a, b, c] = mesh.triangle(t);
            min_angle(a, b, c).to_degrees() >= GOOD_ANGLE_DEG
        })
        .count();
    qr.good_angle_fraction = good as f64 / n as f64;
    let (map, _) = weld_positions(&mesh.positions, weld);
    let mut seen: crate::collections::HashSet<(u32, u32)> = crate::collections::HashSet::default();
    let (mut count, mut band, mut sum) = (0usize, 0usize, 0.0);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for t in mesh.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (ma, mb) = (map[a as usize], map[b as usize]);
            if ma == mb || !seen.insert((ma.min(mb), ma.max(mb))) {
                continue;
            }
            let r = mesh.positions[a as usize].distance(mesh.positions[b as usize]) / qr.size;
            count += 1;
            sum += r;
            lo = lo.min(r);
            hi = hi.max(r);
            if (EDGE_BAND[0]..=EDGE_BAND[1]).contains(&r) {
                band += 1;
            }
        }
    }
    if count > 0 {
        qr.edge_band_fraction = band as f64 / count as f64;
        qr.edge_ratio_min = lo;
        qr.edge_ratio_mean = sum / count as f64;
        qr.edge_ratio_max = hi;
    }
}

/// Meshes one face from its boundary: fills in its plane by the chosen
/// method (both, keeping the better, for [`QualityMethod::Best`]) and
/// improves the result on the surface. Returns the mesh, whether the
/// looping method made it, and how many degenerate loops were left unfilled.
fn mesh_face(
    face: &Face,
    fb: &FaceBoundary,
    options: &MeshOptions,
    size: f64,
    max_nodes: usize,
) -> Result<(FaceMesh, bool, usize), QualityError> {
    let q = &options.quality;
    let s: &dyn Surface = &face.surface;
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for n in fb.loops.iter().flatten() {
        lo = lo.min(n.uv);
        hi = hi.max(n.uv);
    }
    let collapsed = fb.loops.iter().any(|lp| {
        let n = lp.len();
        (0..n).any(|k| lp[k].x == lp[(k + 1) % n].x && lp[k].uv != lp[(k + 1) % n].uv)
    });
    let map = PlaneMap::new(face, lo, hi, collapsed);
    let mut bnodes: Vec<(DVec2, DVec3, f64)> = Vec::new();
    let mut pos: Vec<DVec2> = Vec::new();
    let mut hp: Vec<f64> = Vec::new();
    let mut loops: Vec<Vec<u32>> = Vec::new();
    for lp in &fb.loops {
        let mut ids = Vec::with_capacity(lp.len());
        for n in lp {
            ids.push(pos.len() as u32);
            pos.push(map.to_plane(n.uv, n.x));
            hp.push(n.h / map.stretch(s, n.uv));
            bnodes.push((n.uv, n.x, n.h));
        }
        loops.push(ids);
    }
    let hint = AffineHint::fit(&pos, &bnodes);
    let build = |filled: looping::Filled| -> (FaceMesh, usize) {
        let nb = bnodes.len();
        let mut fm = FaceMesh::default();
        for (k, &(uv, x, h)) in bnodes.iter().enumerate() {
            let _ = k;
            fm.uv.push(uv);
            fm.x.push(x);
            fm.h.push(h);
            fm.fixed.push(true);
        }
        for k in nb..filled.pos.len() {
            let p = filled.pos[k];
            let uv = map.to_uv(s, p, hint.at(p));
            fm.uv.push(uv);
            fm.x.push(s.point(uv));
            fm.h.push((filled.h[k] * map.stretch(s, uv)).min(size));
            fm.fixed.push(false);
        }
        fm.tris = filled.tris;
        (improve::improve(s, fm, q.passes, q.size_correction, max_nodes), filled.dropped)
    };
    let weights = looping::Weights { c: [q.c1, q.c2, q.c3, q.c4] };
    let by_looping = || looping::fill(pos.clone(), hp.clone(), loops.clone(), weights, max_nodes).map(&build);
    #[cfg(feature = "std")]
    let by_delaunay = || delaunay::fill(&pos, &hp, &loops, max_nodes).map(&build);
    #[cfg(not(feature = "std"))]
    let by_delaunay = || -> Result<(FaceMesh, usize), QualityError> { Err(QualityError::NeedsStd) };
    match q.method {
        QualityMethod::Looping => by_looping().map(|(m, d)| (m, true, d)),
        QualityMethod::Delaunay => by_delaunay().map(|(m, d)| (m, false, d)),
        QualityMethod::Best => match (by_looping(), by_delaunay()) {
            (Ok(a), Ok(b)) => {
                let (sa, sb) = (face_score(&a.0, size), face_score(&b.0, size));
                Ok(if sa >= sb { (a.0, true, a.1) } else { (b.0, false, b.1) })
            }
            (Ok(a), Err(_)) => Ok((a.0, true, a.1)),
            (Err(_), Ok(b)) => Ok((b.0, false, b.1)),
            (Err(e), Err(_)) => Err(e),
        },
    }
}

/// Least-squares affine map from plane coordinates to (u,v) over the
/// boundary nodes: the starting point of the planar map's Newton iteration.
struct AffineHint {
    m: [[f64; 3]; 2],
}

impl AffineHint {
    fn fit(pos: &[DVec2], nodes: &[(DVec2, DVec3, f64)]) -> Self {
        // Normal equations of [x y 1] · c = u (and v).
        let mut a = [[0.0f64; 3]; 3];
        let mut b = [[0.0f64; 3]; 2];
        for (p, n) in pos.iter().zip(nodes) {
            let r = [p.x, p.y, 1.0];
            for i in 0..3 {
                for j in 0..3 {
                    a[i][j] += r[i] * r[j];
                }
                b[0][i] += r[i] * n.0.x;
                b[1][i] += r[i] * n.0.y;
            }
        }
        let mut m = [[0.0; 3]; 2];
        for (k, rhs) in b.iter().enumerate() {
            m[k] = solve3(a, *rhs).unwrap_or([0.0, 0.0, nodes.first().map_or(0.0, |n| n.0[k])]);
        }
        Self { m }
    }

    fn at(&self, p: DVec2) -> DVec2 {
        let r = [p.x, p.y, 1.0];
        let dot = |c: &[f64; 3]| c[0] * r[0] + c[1] * r[1] + c[2] * r[2];
        DVec2::new(dot(&self.m[0]), dot(&self.m[1]))
    }
}

/// Solves a 3×3 system by Cramer's rule; `None` when singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if !(d.abs() > TINY && d.is_finite()) {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *o = det(m) / d;
    }
    Some(out)
}

/// Rough model-space area of a face: |Su × Sv| summed over the points of a
/// 24 × 24 grid of its loops' parameter box that lie inside the loops.
fn estimate_area(f: &Face) -> f64 {
    let s: &dyn Surface = &f.surface;
    let region = LoopSample::of(f);
    let (lo, hi) = (region.lo, region.hi);
    const N: usize = 24;
    let cell = (hi - lo) / N as f64;
    let mut area = 0.0;
    for i in 0..N {
        for j in 0..N {
            let q = lo + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            if region.inside(q) {
                let d = s.derivs(q);
                let a = d.su.cross(d.sv).length() * cell.x * cell.y;
                if a.is_finite() {
                    area += a;
                }
            }
        }
    }
    area
}
