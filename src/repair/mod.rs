//! Mesh repair (paper 002, "Extracting a regular triangular net for
//! offsetting"): a clean 2-manifold from a triangle mesh that was closed and
//! has been deformed (offset, say) into degenerate and self-intersecting
//! triangles.
//!
//! Stages: weld and orient ([`topology`]), degenerate triangles out
//! ([`degenerate`], step 1), self-intersection segments ([`intersect`], step
//! 2, with the k-d tree or BVH of [`broad`] and the exact test of
//! [`tritri`]), valid region growing from an extreme triangle with
//! sub-triangulation and stitching ([`region`], [`arrange`], [`cdt`], steps
//! 3–5). Everything is `no_std` + `alloc`: the sub-triangulation is a small
//! constrained Delaunay triangulation of its own rather than spade's, because
//! the triangles it serves carry a handful of points each (spade's set-up
//! would dominate) and because it must keep points that rounding puts on one
//! spot apart by their names, which spade would merge.

mod arrange;
mod broad;
mod cdt;
mod check;
mod degenerate;
mod intersect;
mod offset;
mod predicates;
mod region;
mod topology;
mod tritri;

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use glam::DVec3;
use serde::Serialize;

pub use check::{find_self_intersections, mesh_edge_census, mesh_volume, EdgeCensus};
pub use offset::offset_mesh;

use crate::io::MAX_COORDINATE;
use crate::nurbs::Aabb;
use crate::{weld_positions, Error, Mesh};

/// How the self-intersection search finds candidate pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Bucketing {
    /// Paper 002 §3: k-d tree buckets, pairs tested inside each leaf.
    KdTree,
    /// A bounding-volume hierarchy queried with each triangle's box.
    Bvh,
}

/// Options of [`repair_mesh`]. Lengths are fractions of the input's
/// bounding-box diagonal.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RepairOptions {
    /// Vertices closer than this are welded first. Default 1e-9 (coincident
    /// within rounding; 0 merges only identical coordinates).
    pub weld_tolerance: f64,
    /// Zero-length tolerance ε₁ of step 1: shorter edges are collapsed. Default 1e-9.
    pub zero_length: f64,
    /// Zero-angle tolerance ε₂ of step 1, radians. Default 1e-6.
    pub zero_angle: f64,
    /// Candidate-pair search. Default [`Bucketing::KdTree`], the paper's: at
    /// 250k triangles it measured faster than the BVH (`benches/repair.rs`),
    /// at 15k about the same.
    pub bucketing: Bucketing,
    /// Triangles per k-d tree leaf before it splits. Default 128: as the
    /// paper found (its Fig. 5), the best value depends on the model; on the
    /// offset tori of `benches/repair.rs` small leaves cost more in
    /// duplicated triangles than they save in pair tests (at 250k triangles
    /// the search took 0.57 s at 32, 0.43 s at 128, 0.33 s at 256; at 15k,
    /// 128 was best).
    pub bucket_capacity: usize,
    /// Every vertex is moved by a pseudo-random vector of up to this size
    /// before step 2 (fixed seed: runs repeat), so that the exact
    /// coincidences of symmetric input (intersection curves lying exactly in a
    /// mirror plane, several segments through one point) become generic;
    /// 1e-9 of the diagonal is far below what an STL file (`f32`) keeps.
    /// When the arrangement still has unresolved contacts, the run is repeated
    /// once with 100 times the size. 0 moves nothing unless needed. Default 1e-9.
    pub perturbation: f64,
    /// Also search the result for self-intersections (costs about as much as step 2). Default false.
    pub verify: bool,
    /// Largest input accepted, triangles. Default 20,000,000.
    pub max_triangles: usize,
    /// Most intersection segments accepted. Default 20,000,000.
    pub max_segments: usize,
}

impl Default for RepairOptions {
    fn default() -> Self {
        Self {
            weld_tolerance: 1e-9,
            zero_length: 1e-9,
            zero_angle: 1e-6,
            bucketing: Bucketing::KdTree,
            bucket_capacity: 128,
            perturbation: 1e-9,
            verify: false,
            max_triangles: 20_000_000,
            max_segments: 20_000_000,
        }
    }
}

impl RepairOptions {
    /// Sets [`Self::bucketing`].
    pub fn with_bucketing(mut self, b: Bucketing) -> Self {
        self.bucketing = b;
        self
    }
    /// Sets [`Self::bucket_capacity`].
    pub fn with_bucket_capacity(mut self, n: usize) -> Self {
        self.bucket_capacity = n;
        self
    }
    /// Sets [`Self::verify`].
    pub fn with_verify(mut self, v: bool) -> Self {
        self.verify = v;
        self
    }
    /// Sets [`Self::weld_tolerance`].
    pub fn with_weld_tolerance(mut self, t: f64) -> Self {
        self.weld_tolerance = t;
        self
    }
    /// Sets [`Self::zero_length`] and [`Self::zero_angle`].
    pub fn with_zero_tolerances(mut self, length: f64, angle: f64) -> Self {
        self.zero_length = length;
        self.zero_angle = angle;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::Repair`] naming the option.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |name: &str, message: String| Err(Error::Repair { location: format!("option {name}"), message });
        for (name, v) in [
            ("weld_tolerance", self.weld_tolerance),
            ("zero_length", self.zero_length),
            ("zero_angle", self.zero_angle),
            ("perturbation", self.perturbation),
        ] {
            if !(v.is_finite() && (0.0..0.1).contains(&v)) {
                return bad(name, format!("{v} is outside [0, 0.1)"));
            }
        }
        if !(2..=1_000_000).contains(&self.bucket_capacity) {
            return bad("bucket_capacity", format!("{} is outside 2..=1000000", self.bucket_capacity));
        }
        Ok(())
    }
}

/// Milliseconds per stage, measured with the clock the caller passed (the core has none).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StageTimes {
    /// Checks, welding, orientation, adjacency.
    pub prepare: f64,
    /// Step 1: degenerate triangles.
    pub degenerate: f64,
    /// Step 2: self-intersection segments.
    pub intersect: f64,
    /// Steps 3–5: region growing, sub-triangulation, stitching, output.
    pub regions: f64,
    /// Optional search of the result for self-intersections.
    pub verify: f64,
    /// All of the above.
    pub total: f64,
}

/// What [`repair_mesh`] did and measured; serialized as the CLI's report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RepairReport {
    /// Triangles given.
    pub triangles_in: usize,
    /// Vertices given.
    pub vertices_in: usize,
    /// Vertices merged into others by welding.
    pub vertices_welded: usize,
    /// Triangles dropped before step 1: collapsed by welding, or duplicates.
    pub triangles_dropped: usize,
    /// Triangles reversed to agree with their neighbours (or whole inside-out components).
    pub triangles_reoriented: usize,
    /// Connected components of the input.
    pub components: usize,
    /// Free edges of the input (an open mesh; its boundary stays open).
    pub free_edges_in: usize,
    /// Step 1: edge collapses.
    pub degenerate_collapsed: usize,
    /// Step 1: edge swaps.
    pub degenerate_swapped: usize,
    /// Degenerate triangles step 1 could not remove.
    pub degenerate_left: usize,
    /// Size of the vertex moves used (fraction of the diagonal; see [`RepairOptions::perturbation`]).
    pub perturbation: f64,
    /// Candidate-pair search used.
    pub bucketing: Option<Bucketing>,
    /// k-d tree leaves (0 with the BVH).
    pub kd_leaves: usize,
    /// Triangle pairs whose boxes overlap (narrow-phase tests).
    pub candidate_pairs: usize,
    /// Self-intersection segments (one per crossing pair of triangles).
    pub segments: usize,
    /// Contacts not handled: coplanar overlaps, touching, vertices exactly on another triangle.
    pub degenerate_contacts: usize,
    /// Valid regions grown (areas between segments).
    pub regions: usize,
    /// Triangles sub-triangulated along their segments.
    pub triangles_subdivided: usize,
    /// Sub-triangulations that could not take their segments (near-coincident points).
    pub subdivision_fallbacks: usize,
    /// Steps across an edge or segment that found nothing to join.
    pub stitch_misses: usize,
    /// Triangles in the result.
    pub triangles_out: usize,
    /// Vertices in the result.
    pub vertices_out: usize,
    /// Edge census of the result.
    pub census_out: EdgeCensus,
    /// Volume of the input after welding and orientation.
    pub volume_in: f64,
    /// Volume of the result.
    pub volume_out: f64,
    /// Pairs of result triangles that still meet (only with `verify`).
    pub self_intersections_out: Option<usize>,
    /// Time per stage.
    pub time_ms: StageTimes,
    /// What was assumed or left undone.
    pub warnings: Vec<String>,
}

/// A repaired mesh and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct RepairResult {
    /// The repaired mesh (no normals, one face).
    pub mesh: Mesh,
    /// What was done.
    pub report: RepairReport,
}

/// Repairs `mesh` with no clock (all times 0). See [`repair_mesh_timed`].
///
/// # Errors
/// As [`repair_mesh_timed`].
pub fn repair_mesh(mesh: &Mesh, options: &RepairOptions) -> Result<RepairResult, Error> {
    repair_mesh_timed(mesh, options, &mut || 0.0)
}

/// Repairs `mesh` (paper 002): welds, orients, removes degenerate triangles,
/// finds the self-intersections and keeps the valid regions grown from the
/// triangle at the vertex of largest x (one seed per connected component no
/// other one reached). `clock` returns milliseconds; it times the stages.
///
/// Best effort, reported in `warnings`: an open mesh keeps its open boundary
/// (growth stops there); vertices are not welded when welding would make the
/// mesh non-manifold; an inside-out closed component is turned outward;
/// contacts the exact test cannot resolve (coplanar overlaps, touching) are
/// counted and left as they are.
///
/// # Errors
/// [`Error::Repair`] for an empty mesh, a coordinate that is not finite or is
/// beyond 1e30, an index out of range, an edge shared by more than two
/// triangles (non-manifold input), or a component that cannot be oriented;
/// [`Error::Limit`] past `max_triangles` or `max_segments`.
pub fn repair_mesh_timed(
    mesh: &Mesh,
    options: &RepairOptions,
    clock: &mut dyn FnMut() -> f64,
) -> Result<RepairResult, Error> {
    options.validate()?;
    let t0 = clock();
    let mut report =
        RepairReport { triangles_in: mesh.triangle_count(), vertices_in: mesh.positions.len(), ..Default::default() };
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
    // Weld. Vertices an offset brought together from different sheets would
    // join them at an edge of four triangles: then the input's own indices
    // are kept instead, and the crossing is left to step 2.
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
                report.warnings.push(format!(
                    "welding within {:e} of the diagonal would make the mesh non-manifold ({e}); vertices were not welded",
                    options.weld_tolerance
                ));
            }
        }
    }
    let (mut positions, mut tris) = match welded {
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
    let before = tris.len();
    if tris.is_empty() {
        return Err(Error::Repair {
            location: "mesh".into(),
            message: "no triangle is left after welding (all collapsed)".into(),
        });
    }
    let mut nbr = topology::adjacency(&tris);
    report.free_edges_in = nbr.iter().flatten().filter(|&&u| u == topology::NONE).count();
    if report.free_edges_in > 0 {
        report.warnings.push(format!(
            "the input is open ({} free edges): its boundary stays open and growth stops there",
            report.free_edges_in
        ));
    }
    let (comp, ncomp) = topology::components(&nbr);
    report.components = ncomp;
    let mut volume = alloc::vec![0.0; ncomp];
    for (t, tri) in tris.iter().enumerate() {
        volume[comp[t] as usize] += topology::signed_volume(&positions, core::iter::once(*tri));
    }
    let inside_out: Vec<bool> = volume.iter().map(|&v| v < 0.0).collect();
    if report.free_edges_in == 0 && inside_out.iter().any(|&b| b) {
        let mut flipped = 0;
        for (t, tri) in tris.iter_mut().enumerate() {
            if inside_out[comp[t] as usize] {
                tri.swap(1, 2);
                flipped += 1;
            }
        }
        report.triangles_reoriented += flipped;
        report.warnings.push(format!(
            "{} of {ncomp} components enclosed a negative volume (inside out) and were turned outward",
            inside_out.iter().filter(|&&b| b).count()
        ));
        nbr = topology::adjacency(&tris);
    }
    report.volume_in = topology::signed_volume(&positions, tris.iter().copied());
    let t1 = clock();

    // Step 1.
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
        report
            .warnings
            .push(format!("{} degenerate triangles could not be removed without breaking the manifold", stats.left));
    }
    let tris: Vec<[u32; 3]> = tris.iter().zip(&alive).filter(|(_, &a)| a).map(|(t, _)| *t).collect();
    let nbr = topology::adjacency(&tris);
    let (comp, ncomp) = topology::components(&nbr);
    let t2 = clock();

    // Steps 2-5, again on slightly moved vertices when exact coincidences
    // (symmetric input) leave contacts or sub-triangulations unresolved.
    let sizes = if options.perturbation > 0.0 {
        [options.perturbation, 100.0 * options.perturbation]
    } else {
        [0.0, PERTURBATION_FALLBACK]
    };
    let mut attempt = 0;
    let (x, grown, positions) = loop {
        let size = sizes[attempt];
        let moved = if size > 0.0 { perturbed(&positions, size * diag) } else { positions.clone() };
        let t = clock();
        let x = intersect::find_intersections(
            &moved,
            &tris,
            options.bucketing,
            options.bucket_capacity,
            options.max_segments,
        )?;
        let t_x = clock();
        let g = arrange::Geometry { positions: &moved, tris: &tris, nbr: &nbr, x: &x };
        let grown = region::grow(&g, &comp, ncomp, report.free_edges_in == 0);
        let t_g = clock();
        report.time_ms.intersect += t_x - t;
        report.time_ms.regions += t_g - t_x;
        let clean = x.degenerate == 0 && grown.fallbacks == 0 && grown.stitch_misses == 0 && grown.closed;
        if clean || attempt + 1 == sizes.len() {
            if attempt > 0 {
                report.warnings.push(format!(
                    "the arrangement had unresolved coincidences; vertices were moved by up to {size:e} of the diagonal"
                ));
            }
            report.perturbation = size;
            break (x, grown, moved);
        }
        attempt += 1;
    };
    report.bucketing = Some(options.bucketing);
    report.kd_leaves = x.leaves;
    report.candidate_pairs = x.candidates;
    report.segments = x.segments.len();
    report.degenerate_contacts = x.degenerate;
    if x.degenerate > 0 {
        report.warnings.push(format!(
            "{} triangle pairs touch or overlap in a way not handled (coplanar, or a vertex exactly on another triangle); left as they are",
            x.degenerate
        ));
    }
    let t3 = clock();
    let _ = positions;
    report.regions = grown.regions;
    report.triangles_subdivided = grown.subdivided;
    report.subdivision_fallbacks = grown.fallbacks;
    report.stitch_misses = grown.stitch_misses;
    if grown.unseeded > 0 {
        report.warnings.push(format!(
            "{} components had no triangle on the outside of the enclosed space and were left out",
            grown.unseeded
        ));
    }
    if grown.fallbacks > 0 {
        report.warnings.push(format!(
            "{} triangles could not be split along their segments (points closer than rounding separates) and were kept or dropped whole",
            grown.fallbacks
        ));
    }
    let (out_pos, out_idx) = region::compact(&grown.points.pos, &grown.tris);
    let out_tris: Vec<[u32; 3]> = out_idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    report.triangles_out = out_tris.len();
    report.vertices_out = out_pos.len();
    report.census_out = check::census(&out_tris);
    report.volume_out = topology::signed_volume(&out_pos, out_tris.iter().copied());
    if out_tris.is_empty() {
        report.warnings.push("nothing valid was found: the result is empty".into());
    }
    let c = report.census_out;
    if c.nonmanifold_edges > 0 || c.misoriented_edges > 0 {
        // Seen only from open input, where growth can pass round the border.
        report.warnings.push(format!(
            "the result is not a clean 2-manifold: {} edges of more than two triangles, {} edges whose triangles disagree",
            c.nonmanifold_edges, c.misoriented_edges
        ));
    }
    let t4 = clock();
    if options.verify {
        report.self_intersections_out = Some(check::self_intersections(&out_pos, &out_tris).len());
    }
    let t5 = clock();
    report.time_ms.prepare = t1 - t0;
    report.time_ms.degenerate = t2 - t1;
    report.time_ms.regions += t4 - t3;
    report.time_ms.verify = t5 - t4;
    report.time_ms.total = t5 - t0;
    let mesh = Mesh { positions: out_pos, normals: Vec::new(), indices: out_idx, face_ranges: Vec::new() };
    Ok(RepairResult { mesh, report })
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
