//! The steps of [`super::repair_mesh_timed`], one function each, in the
//! order it calls them: the input checked, welded and oriented; step 1,
//! degenerate triangles out; steps 2–5, segments found and valid regions
//! grown (again on slightly moved vertices when coincidences defeat them);
//! the output compacted and measured.

use alloc::format;
use alloc::vec::Vec;
use glam::DVec3;

use super::intersect::Intersections;
use super::region::Grown;
use super::{arrange, check, degenerate, intersect, region, topology, RepairOptions, RepairReport};
use crate::io::MAX_COORDINATE;
use crate::nurbs::Aabb;
use crate::warning::{Warning, WarningKind};
use crate::{weld_positions, Error, Mesh};

/// A welded, consistently oriented mesh with its adjacency.
pub(super) struct Prepared {
    positions: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
    nbr: Vec<[u32; 3]>,
}

/// The mesh after step 1, with its adjacency and connected components.
pub(super) struct Clean {
    positions: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
    nbr: Vec<[u32; 3]>,
    comp: Vec<u32>,
    ncomp: usize,
}

/// The triangles of `mesh` and its bounding-box diagonal, once its size,
/// indices and coordinates pass.
///
/// # Errors
/// [`Error::Limit`] past `max_triangles`; [`Error::Repair`] for an index out
/// of range, no triangles, or a coordinate not finite or beyond 1e30.
pub(super) fn checked_input(mesh: &Mesh, options: &RepairOptions) -> Result<(Vec<[u32; 3]>, f64), Error> {
    if mesh.triangle_count() > options.max_triangles {
        return Err(Error::Limit(format!("{} triangles (at most {})", mesh.triangle_count(), options.max_triangles)));
    }
    let tris_in = check::triangles(mesh)?;
    if tris_in.is_empty() {
        return Err(Error::Repair { location: "mesh".into(), message: "it has no triangles".into() });
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE) {
        let p = mesh.positions[i];
        return Err(Error::Repair {
            location: format!("vertex {i}"),
            message: format!("coordinate {} {} {} is not a finite number within ±1e30", p.x, p.y, p.z),
        });
    }
    let diag = Aabb::from_points(mesh.positions.iter().copied()).diagonal();
    Ok((tris_in, diag))
}

/// Welding (within the weld tolerance of the diagonal `diag`), collapsed and
/// duplicate triangles dropped, every component oriented consistently and
/// inside-out closed ones turned outward. Vertices an offset brought together
/// from different sheets would join them at an edge of four triangles: then
/// the input's own indices are kept instead, and the crossing is left to step 2.
///
/// # Errors
/// [`Error::Repair`] for a mesh that stays non-manifold or cannot be
/// oriented, or that welding collapses entirely.
pub(super) fn weld_and_orient(
    mesh: &Mesh,
    tris_in: Vec<[u32; 3]>,
    diag: f64,
    options: &RepairOptions,
    report: &mut RepairReport,
) -> Result<Prepared, Error> {
    let mut welded = None;
    if options.weld_tolerance > 0.0 && diag > 0.0 {
        let (map, count) = weld_positions(&mesh.positions, options.weld_tolerance * diag);
        let mut pos = alloc::vec![DVec3::ZERO; count];
        let mut set = alloc::vec![false; count];
        for (i, &m) in map.iter().enumerate() {
            if !set[m as usize] {
                set[m as usize] = true;
                pos[m as usize] = mesh.positions[i];
            }
        }
        let mut tris = drop_collapsed_and_duplicates(tris_in.iter().map(|t| t.map(|i| map[i as usize])).collect());
        match topology::orient_consistently(&mut tris) {
            Ok(flipped) => welded = Some((pos, tris, flipped, mesh.positions.len() - count)),
            Err(e) => {
                // Non-manifold as given too: say so in the input's own vertex numbers.
                let mut own = drop_collapsed_and_duplicates(tris_in.clone());
                topology::orient_consistently(&mut own)?;
                let kind = WarningKind::NotWelded { tolerance: options.weld_tolerance, why: e };
                report.warnings.push(Warning::new(kind));
            }
        }
    }
    let (positions, mut tris) = match welded {
        Some((pos, tris, flipped, merged)) => {
            report.vertices_welded = merged;
            report.triangles_reoriented = flipped;
            report.triangles_dropped = tris_in.len() - tris.len();
            (pos, tris)
        }
        None => {
            let mut tris = drop_collapsed_and_duplicates(tris_in.clone());
            report.triangles_dropped = tris_in.len() - tris.len();
            report.triangles_reoriented = topology::orient_consistently(&mut tris)?;
            (mesh.positions.clone(), tris)
        }
    };
    if tris.is_empty() {
        return Err(Error::Repair {
            location: "mesh".into(),
            message: "no triangle is left after welding (all collapsed)".into(),
        });
    }
    let mut nbr = topology::adjacency(&tris);
    report.free_edges_in = nbr.iter().flatten().filter(|&&u| u == topology::NONE).count();
    if report.free_edges_in > 0 {
        report.warnings.push(Warning::new(WarningKind::OpenInput { free_edges: report.free_edges_in }));
    }
    let (comp, ncomp) = topology::components(&nbr);
    report.components = ncomp;
    if turn_inside_out_outward(&positions, &mut tris, (&comp, ncomp), report) {
        nbr = topology::adjacency(&tris);
    }
    report.volume_in = topology::signed_volume(&positions, tris.iter().copied());
    Ok(Prepared { positions, tris, nbr })
}

/// Turns each closed component of `tris` that encloses a negative volume
/// outward (none when the mesh is open); whether any was turned.
fn turn_inside_out_outward(
    positions: &[DVec3],
    tris: &mut [[u32; 3]],
    (comp, ncomp): (&[u32], usize),
    report: &mut RepairReport,
) -> bool {
    let mut volume = alloc::vec![0.0; ncomp];
    for (t, tri) in tris.iter().enumerate() {
        volume[comp[t] as usize] += topology::signed_volume(positions, core::iter::once(*tri));
    }
    let inside_out: Vec<bool> = volume.iter().map(|&v| v < 0.0).collect();
    if !(report.free_edges_in == 0 && inside_out.iter().any(|&b| b)) {
        return false;
    }
    let mut flipped = 0;
    for (t, tri) in tris.iter_mut().enumerate() {
        if inside_out[comp[t] as usize] {
            tri.swap(1, 2);
            flipped += 1;
        }
    }
    report.triangles_reoriented += flipped;
    let count = inside_out.iter().filter(|&&b| b).count();
    report.warnings.push(Warning::new(WarningKind::InsideOut { count, components: ncomp }));
    true
}

/// Step 1 (paper 002 §1): edges under the zero length (of `diag`) collapsed,
/// caps under the zero angle swapped at their longest edge, needles
/// collapsed, where the mesh stays a manifold.
pub(super) fn remove_degenerate(
    prepared: Prepared,
    diag: f64,
    options: &RepairOptions,
    report: &mut RepairReport,
) -> Clean {
    let Prepared { mut positions, mut tris, mut nbr } = prepared;
    let before = tris.len();
    let mut edit = degenerate::EditMesh {
        positions: &mut positions,
        tris: &mut tris,
        nbr: &mut nbr,
        alive: alloc::vec![true; before],
    };
    edit.alive.truncate(edit.tris.len());
    let stats = degenerate::remove_degenerate(&mut edit, options.zero_length * diag, options.zero_angle);
    let alive = edit.alive;
    report.degenerate_collapsed = stats.collapses;
    report.degenerate_swapped = stats.swaps;
    report.degenerate_left = stats.left;
    if stats.left > 0 {
        report.warnings.push(Warning::new(WarningKind::DegenerateLeft { count: stats.left }));
    }
    let tris: Vec<[u32; 3]> = tris.iter().zip(&alive).filter(|(_, &a)| a).map(|(t, _)| *t).collect();
    let nbr = topology::adjacency(&tris);
    let (comp, ncomp) = topology::components(&nbr);
    Clean { positions, tris, nbr, comp, ncomp }
}

/// Steps 2–5 (paper 002 §2–§5): the self-intersection segments, then the
/// valid regions grown from each component's extreme triangle, with
/// sub-triangulation and stitching. Exact coincidences (symmetric input)
/// may leave contacts or sub-triangulations unresolved: then all again on
/// vertices moved by a larger perturbation.
///
/// # Errors
/// [`Error::Limit`] past `max_segments`.
pub(super) fn intersect_and_grow(
    clean: &Clean,
    diag: f64,
    options: &RepairOptions,
    report: &mut RepairReport,
    clock: &mut dyn FnMut() -> f64,
) -> Result<(Intersections, Grown), Error> {
    let sizes = if options.perturbation > 0.0 {
        [options.perturbation, 100.0 * options.perturbation]
    } else {
        [0.0, PERTURBATION_FALLBACK]
    };
    let mut attempt = 0;
    let (x, grown) = loop {
        let size = sizes[attempt];
        let moved = if size > 0.0 { perturbed(&clean.positions, size * diag) } else { clean.positions.clone() };
        let t = clock();
        let x = intersect::find_intersections(
            &moved,
            &clean.tris,
            options.bucketing,
            options.bucket_capacity,
            options.max_segments,
        )?;
        let t_x = clock();
        let g = arrange::Geometry { positions: &moved, tris: &clean.tris, nbr: &clean.nbr, x: &x };
        let grown = region::grow(&g, &clean.comp, clean.ncomp, report.free_edges_in == 0);
        let t_g = clock();
        report.time_ms.intersect += t_x - t;
        report.time_ms.regions += t_g - t_x;
        let resolved = x.degenerate == 0 && grown.fallbacks == 0 && grown.stitch_misses == 0 && grown.closed;
        if resolved || attempt + 1 == sizes.len() {
            if attempt > 0 {
                report.warnings.push(Warning::new(WarningKind::Perturbed { size }));
            }
            report.perturbation = size;
            break (x, grown);
        }
        attempt += 1;
    };
    report.bucketing = Some(options.bucketing);
    report.kd_leaves = x.leaves;
    report.candidate_pairs = x.candidates;
    report.segments = x.segments.len();
    report.degenerate_contacts = x.degenerate;
    if x.degenerate > 0 {
        report.warnings.push(Warning::new(WarningKind::UnhandledContacts { pairs: x.degenerate }));
    }
    Ok((x, grown))
}

/// What region growing found and left, into the report.
pub(super) fn report_regions(grown: &Grown, report: &mut RepairReport) {
    report.regions = grown.regions;
    report.triangles_subdivided = grown.subdivided;
    report.subdivision_fallbacks = grown.fallbacks;
    report.stitch_misses = grown.stitch_misses;
    if grown.unseeded > 0 {
        report.warnings.push(Warning::new(WarningKind::Unseeded { components: grown.unseeded }));
    }
    if grown.fallbacks > 0 {
        report.warnings.push(Warning::new(WarningKind::SplitFallbacks { triangles: grown.fallbacks }));
    }
}

/// The kept triangles as a compact mesh (positions, indices, triangles),
/// with its edge census and volume in the report.
pub(super) fn output(grown: &Grown, report: &mut RepairReport) -> (Vec<DVec3>, Vec<u32>, Vec<[u32; 3]>) {
    let (out_pos, out_idx) = region::compact(&grown.points.pos, &grown.tris);
    let out_tris: Vec<[u32; 3]> = out_idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    report.triangles_out = out_tris.len();
    report.vertices_out = out_pos.len();
    report.census_out = check::census(&out_tris);
    report.volume_out = topology::signed_volume(&out_pos, out_tris.iter().copied());
    if out_tris.is_empty() {
        report.warnings.push(Warning::new(WarningKind::EmptyResult));
    }
    let c = report.census_out;
    if c.nonmanifold_edges > 0 || c.misoriented_edges > 0 {
        // Seen only from open input, where growth can pass round the border.
        let kind = WarningKind::NotManifold { nonmanifold: c.nonmanifold_edges, misoriented: c.misoriented_edges };
        report.warnings.push(Warning::new(kind));
    }
    (out_pos, out_idx, out_tris)
}

/// Relative size (of the diagonal) of the vertex moves tried when the
/// unmoved input (perturbation 0) leaves coincidences unresolved.
const PERTURBATION_FALLBACK: f64 = 1e-9;

/// Every vertex moved by a pseudo-random vector (fixed seed, so runs repeat)
/// with coordinates up to `size` in magnitude.
fn perturbed(positions: &[DVec3], size: f64) -> Vec<DVec3> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    positions.iter().map(|p| *p + DVec3::new(next(), next(), next()) * size).collect()
}

/// Drops triangles with a repeated vertex, and duplicates: two triangles on
/// the same three vertices cancel when they face opposite ways (a zero-volume
/// pocket), and only the first is kept when they face the same way.
fn drop_collapsed_and_duplicates(tris: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    let tris: Vec<[u32; 3]> = tris.into_iter().filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]).collect();
    let mut seen: crate::collections::HashMap<[u32; 3], (usize, bool)> =
        crate::collections::HashMap::with_capacity_and_hasher(tris.len(), Default::default());
    let mut keep = alloc::vec![true; tris.len()];
    for (i, t) in tris.iter().enumerate() {
        let mut s = *t;
        s.sort_unstable();
        // Even permutations of the sorted triple face the same way.
        let r = t.iter().position(|&v| v == s[0]).unwrap_or(0);
        let parity = t[(r + 1) % 3] == s[1];
        match seen.get(&s) {
            Some(&(j, p)) if keep[j] => {
                keep[i] = false;
                if p != parity {
                    keep[j] = false;
                }
            }
            _ => {
                seen.insert(s, (i, parity));
            }
        }
    }
    tris.into_iter().zip(keep).filter(|(_, k)| *k).map(|(t, _)| t).collect()
}
