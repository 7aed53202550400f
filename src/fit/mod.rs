//! Surfaces through scattered 3-D points (paper 004): a triangle net over the
//! points, merged into convex polygons, its edges made cubic Bézier curves,
//! each n-gon filled with n quartic triangular Bézier sub-patches meeting G¹;
//! then the patches tessellated within a chordal tolerance.
//!
//! [`fit_points`] runs it all; [`read_points`] reads xyz, csv and ply files.
//!
//! Numbers ([`crate::numeric`]): the tangent-plane Delaunay triangulations
//! decide exactly ([`crate::predicates`]); duplicate points and colinear
//! input are found within tolerances relative to the points' spread, and
//! the tessellation holds the chordal tolerance.

// Comparisons are written `!(x > 0.0)` on purpose: they reject NaN too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bezier;
mod curvenet;
mod delaunay;
mod export;
mod kdtree;
mod linalg;
mod normals;
mod patch;
mod points;
mod polynet;
mod tessellate;
mod trinet;

use crate::collections::HashMap;
use crate::warning::{Warning, WarningKind};
use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;
use core::f64::consts::PI;
use glam::DVec3;
use serde::Serialize;

pub use bezier::{Cubic, PatchPoint, TriPatch};
pub use points::{read_points, PointFormat, MAX_FILE_POINTS};

use crate::mesh::{edge_counts, Mesh};
use crate::numeric::TINY;
use crate::options::{OptionsError, Tolerance};
use crate::Error;
use kdtree::KdTree;
use normals::Neighbours;

/// Options of [`fit_points`]; every angle in radians.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitOptions {
    /// Largest distance between the output mesh and the fitted surface.
    /// Default: relative 1e-3 (of the points' bounding-box diagonal).
    pub tolerance: Tolerance,
    /// Points closer than this fraction of the diagonal are one point (merged
    /// with a warning). Default 1e-9, so every input point is interpolated
    /// within 1e-9 of the diagonal.
    pub merge_distance: f64,
    /// Neighbours a normal is estimated from. Default 12.
    pub normal_neighbours: usize,
    /// Neighbours each point triangulates in its tangent plane. Default 16.
    pub net_neighbours: usize,
    /// Largest angle between a net triangle's normal and its corners' normals
    /// (also between neighbours' normals that may share a triangle). Default π/3.
    pub max_normal_angle: f64,
    /// Largest corner angle of a merged polygon in its projection. Default
    /// 165° (the paper's bound is 180°; the patch weights grow without bound near it).
    pub max_polygon_angle: f64,
    /// Most sides of a merged polygon. Default 8.
    pub max_polygon_sides: usize,
    /// Largest angle between a polygon corner's normal and the polygon's
    /// plane. Default π/4.
    pub max_polygon_tilt: f64,
    /// Longest boundary loop of the triangle net that is closed as a gap.
    /// Default 24.
    pub max_hole_edges: usize,
    /// Most points accepted. Default 200,000.
    pub max_points: usize,
    /// Most segments per sub-patch edge in the tessellation. Default 64.
    pub max_level: usize,
    /// Most output triangles. Default 4,000,000.
    pub max_triangles: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            tolerance: Tolerance::Relative(1e-3),
            merge_distance: 1e-9,
            normal_neighbours: 12,
            net_neighbours: 16,
            max_normal_angle: PI / 3.0,
            max_polygon_angle: 165.0 * PI / 180.0,
            max_polygon_sides: 8,
            max_polygon_tilt: PI / 4.0,
            max_hole_edges: 24,
            max_points: 200_000,
            max_level: 64,
            max_triangles: 4_000_000,
        }
    }
}

impl FitOptions {
    /// Sets an absolute chordal tolerance.
    pub fn with_tolerance(mut self, tol: f64) -> Self {
        self.tolerance = Tolerance::Absolute(tol);
        self
    }

    /// Sets the tolerance as a fraction of the points' bounding-box diagonal.
    pub fn with_relative_tolerance(mut self, r: f64) -> Self {
        self.tolerance = Tolerance::Relative(r);
        self
    }

    /// Sets the largest polygon size of the merge (3 keeps the triangle net).
    pub fn with_max_polygon_sides(mut self, n: usize) -> Self {
        self.max_polygon_sides = n;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// The first field out of range.
    pub fn validate(&self) -> Result<(), OptionsError> {
        let bad = |option, message| Err(OptionsError { option, message });
        match self.tolerance {
            Tolerance::Absolute(t) if !(t > 0.0 && t.is_finite()) => return bad("tol", "must be a positive number"),
            Tolerance::Relative(r) if !(r > 0.0 && r < 1.0) => return bad("tol-rel", "must be in (0, 1)"),
            _ => {}
        }
        if !(self.merge_distance >= 0.0 && self.merge_distance < 1e-2) {
            return bad("merge-distance", "must be in [0, 0.01)");
        }
        if !(3..=64).contains(&self.normal_neighbours) {
            return bad("normal-neighbours", "must be 3 to 64");
        }
        if !(6..=64).contains(&self.net_neighbours) {
            return bad("net-neighbours", "must be 6 to 64");
        }
        if !(self.max_normal_angle > 0.0 && self.max_normal_angle < PI / 2.0) {
            return bad("max-normal-angle", "must be in (0, π/2)");
        }
        if !(self.max_polygon_angle > PI / 2.0 && self.max_polygon_angle < PI) {
            return bad("max-polygon-angle", "must be in (π/2, π)");
        }
        if !(3..=32).contains(&self.max_polygon_sides) {
            return bad("max-polygon-sides", "must be 3 to 32");
        }
        if !(self.max_polygon_tilt > 0.0 && self.max_polygon_tilt < PI / 2.0) {
            return bad("max-polygon-tilt", "must be in (0, π/2)");
        }
        if self.max_hole_edges < 3 {
            return bad("max-hole-edges", "must be at least 3");
        }
        if !(4..=MAX_FILE_POINTS).contains(&self.max_points) {
            return bad("max-points", "must be 4 to 10,000,000");
        }
        if !(1..=1024).contains(&self.max_level) {
            return bad("max-level", "must be 1 to 1024");
        }
        if self.max_triangles == 0 {
            return bad("max-triangles", "must be positive");
        }
        Ok(())
    }
}

/// One polygon of the net and the sub-patches that fill it.
#[derive(Debug, Clone, PartialEq)]
pub struct FitPolygon {
    /// Net vertices (indices into [`FitSurface::points`]), counter-clockwise
    /// seen from the side the normals point to.
    pub corners: Vec<u32>,
    /// Sub-patch `i` has corners `corners[i]`, `corners[i+1]` and the centre.
    pub patches: Vec<TriPatch>,
}

/// The fitted surface: the polygon net and its G¹ quartic sub-patches.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FitSurface {
    /// The net's vertices: the input points after merging duplicates.
    pub points: Vec<DVec3>,
    /// Unit normal of each vertex's tangent plane (the surface's normal there).
    pub normals: Vec<DVec3>,
    /// The polygons.
    pub polygons: Vec<FitPolygon>,
}

impl FitSurface {
    /// The curve net: every polygon edge once, as `(a, b, cubic from a to b)` with `a < b`.
    pub fn edges(&self) -> Vec<(u32, u32, Cubic)> {
        let mut seen: HashMap<(u32, u32), ()> = HashMap::default();
        let mut out = Vec::new();
        for poly in &self.polygons {
            let n = poly.corners.len();
            for i in 0..n {
                let (a, b) = (poly.corners[i], poly.corners[(i + 1) % n]);
                if seen.insert((a.min(b), a.max(b)), ()).is_some() {
                    continue;
                }
                let row = poly.patches.get(i).map(|p| {
                    let e = [p.at(0, 0), p.at(1, 0), p.at(2, 0), p.at(3, 0), p.at(4, 0)];
                    // Back from the degree-elevated quartic (paper 004 eq. 3) to the cubic.
                    let v1 = (e[1] * 4.0 - e[0]) / 3.0;
                    let v2 = (e[3] * 4.0 - e[4]) / 3.0;
                    [e[0], v1, v2, e[4]]
                });
                if let Some(c) = row {
                    out.push(if a < b { (a, b, c) } else { (b, a, [c[3], c[2], c[1], c[0]]) });
                }
            }
        }
        out
    }

    /// Largest angle between the normals of neighbouring sub-patches along
    /// their shared borders (spokes inside polygons, net edges between them),
    /// sampled at `samples` + 1 points per border; the G¹ check.
    pub fn max_g1_angle(&self, samples: usize) -> f64 {
        let samples = samples.max(1);
        let mut worst: f64 = 0.0;
        let mut by_edge: HashMap<(u32, u32), (usize, usize)> = HashMap::default();
        for (pi, poly) in self.polygons.iter().enumerate() {
            let n = poly.patches.len();
            for i in 0..n {
                let (left, right) = (&poly.patches[(i + n - 1) % n], &poly.patches[i]);
                for s in 0..=samples {
                    let t = s as f64 / samples as f64;
                    let a = left.eval(1.0 - t, t).normal();
                    let b = right.eval(0.0, t).normal();
                    worst = worst.max(crate::math::angle_between(a, b));
                }
                by_edge.insert((poly.corners[i], poly.corners[(i + 1) % n]), (pi, i));
            }
        }
        for (&(a, b), &(pi, i)) in &by_edge {
            let Some(&(pj, j)) = by_edge.get(&(b, a)) else { continue };
            if a > b {
                continue;
            }
            let (p, q) = (&self.polygons[pi].patches[i], &self.polygons[pj].patches[j]);
            for s in 0..=samples {
                let t = s as f64 / samples as f64;
                let na = p.eval(t, 0.0).normal();
                let nb = q.eval(1.0 - t, 0.0).normal();
                worst = worst.max(crate::math::angle_between(na, nb));
            }
        }
        worst
    }

    /// The patches as JSON (see `export.rs` for the layout).
    pub fn to_json(&self) -> String {
        export::to_json(self)
    }
}

/// What [`fit_points`] measured; serialized as the CLI's JSON report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FitReport {
    /// Points given.
    pub points_in: usize,
    /// Net vertices after merging duplicates.
    pub points: usize,
    /// Points merged into an earlier one.
    pub duplicates_merged: usize,
    /// Triangles of the triangle net.
    pub net_triangles: usize,
    /// Gaps of the triangle net closed by ear clipping.
    pub holes_filled: usize,
    /// Gap-like boundary loops left open.
    pub holes_open: usize,
    /// Open boundary loops (the border of a sheet).
    pub borders: usize,
    /// Edges swapped by the smoothness criterion.
    pub swaps: usize,
    /// Polygons of the polygon net.
    pub polygons: usize,
    /// `polygon_sides[n]` polygons have n sides.
    pub polygon_sides: Vec<usize>,
    /// Sub-patches: the sum of the polygons' sides (paper 004: n per n-gon).
    pub sub_patches: usize,
    /// Sub-patches the classic split of the same polygons would need: Σ 3(n − 2).
    pub sub_patches_triangular: usize,
    /// Largest normal angle across shared sub-patch borders (8 samples per border), radians.
    pub max_g1_angle: f64,
    /// Absolute chordal tolerance of the tessellation.
    pub tolerance: f64,
    /// Output triangles.
    pub triangles: usize,
    /// Output vertices.
    pub vertices: usize,
    /// Mesh edges with one triangle (the sheet's border; 0 on a closed surface).
    pub boundary_edges: usize,
    /// Mesh edges with more than two triangles.
    pub nonmanifold_edges: usize,
    /// Core time in milliseconds (filled by the caller: the core has no clock).
    pub time_ms: f64,
    /// Merged duplicates, polygons that could not be filled, open gaps.
    pub warnings: Vec<Warning>,
}

/// Everything [`fit_points`] made.
#[derive(Debug, Clone, Default)]
pub struct FitResult {
    /// The fitted surface.
    pub surface: FitSurface,
    /// Its tessellation: one face range per polygon, vertices shared.
    pub mesh: Mesh,
    /// The triangle net the polygons were merged from.
    pub net: Vec<[u32; 3]>,
    /// For each input point, its net vertex.
    pub point_index: Vec<u32>,
    /// Measurements and warnings.
    pub report: FitReport,
}

/// Fits a G¹ surface through `points` and tessellates it (paper 004).
///
/// Degenerate inputs: a non-finite coordinate, fewer than 4 distinct points
/// or points on one line are errors. Points on one plane are fitted by the
/// flat surface of their polygon net (every normal is the plane's): the
/// region of the plane they span, with a warning.
///
/// # Errors
/// [`Error::Options`] for a bad option, [`Error::Fit`] for the degenerate
/// inputs above or when no triangle net forms, [`Error::Limit`] past
/// `max_points` or `max_triangles`.
pub fn fit_points(points: &[DVec3], options: &FitOptions) -> Result<FitResult, Error> {
    options.validate()?;
    let mut warnings = Vec::new();
    let distinct = distinct_points(points, options, &mut warnings)?;
    let Distinct { verts, point_index, merged, diag } = distinct;
    let (normals, net) = triangle_net(&verts, options, &mut warnings)?;
    let surface = polygons(verts, normals, &net.tris, options, &mut warnings);
    let (tol, mesh) = tessellated(&surface, options, diag, &mut warnings)?;
    let counts = edge_counts(&mesh, 1e-12 * diag.max(TINY), 0.0);
    let mut sides = Vec::new();
    for poly in &surface.polygons {
        let n = poly.corners.len();
        if sides.len() <= n {
            sides.resize(n + 1, 0);
        }
        sides[n] += 1;
    }
    let report = FitReport {
        points_in: points.len(),
        points: surface.points.len(),
        duplicates_merged: merged,
        net_triangles: net.tris.len(),
        holes_filled: net.holes_filled,
        holes_open: net.holes_open,
        borders: net.borders,
        swaps: net.swaps,
        polygons: surface.polygons.len(),
        polygon_sides: sides,
        sub_patches: surface.polygons.iter().map(|p| p.patches.len()).sum(),
        sub_patches_triangular: surface.polygons.iter().map(|p| 3 * (p.corners.len() - 2)).sum(),
        max_g1_angle: surface.max_g1_angle(8),
        tolerance: tol,
        triangles: mesh.triangle_count(),
        vertices: mesh.positions.len(),
        boundary_edges: counts.boundary_edges,
        nonmanifold_edges: counts.nonmanifold_edges,
        time_ms: 0.0,
        warnings,
    };
    Ok(FitResult { surface, mesh, net: net.tris, point_index, report })
}

/// The input points with duplicates merged, and what merging took.
struct Distinct {
    verts: Vec<DVec3>,
    /// For each input point, its kept index.
    point_index: Vec<u32>,
    /// Points merged away.
    merged: usize,
    /// Diagonal of the points' bounding box.
    diag: f64,
}

/// The distinct points of `points` (closer than the merge distance are
/// one), checked: finite, at least 4, not on one line; points on one plane
/// leave a warning.
///
/// # Errors
/// As [`fit_points`] for the points themselves.
fn distinct_points(points: &[DVec3], options: &FitOptions, warnings: &mut Vec<Warning>) -> Result<Distinct, Error> {
    if points.len() > options.max_points {
        return Err(Error::Limit(format!("{} points; at most {} are accepted", points.len(), options.max_points)));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::Fit(format!("point {i} has a coordinate that is not finite")));
    }
    if points.len() < 4 {
        return Err(Error::Fit(format!("at least 4 points are needed, found {}", points.len())));
    }
    let (lo, hi) = points
        .iter()
        .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), p| (l.min(*p), h.max(*p)));
    let diag = (hi - lo).length();
    let (verts, point_index) = merge_duplicates(points, options.merge_distance * diag);
    let merged = points.len() - verts.len();
    if merged > 0 {
        let distance = options.merge_distance * diag;
        warnings.push(Warning::new(WarningKind::DuplicatesMerged { count: merged, distance }));
    }
    if verts.len() < 4 {
        return Err(Error::Fit(format!("at least 4 distinct points are needed, found {}", verts.len())));
    }
    let (cov, _) = linalg::covariance(verts.iter().copied());
    let (ev, axes) = linalg::sym_eigen3(cov);
    if !(ev[1] > 1e-14 * ev[2]) {
        return Err(Error::Fit(format!(
            "the {} points lie on one line (along {:.3?}): no surface passes through them",
            verts.len(),
            axes[2].to_array()
        )));
    }
    if !(ev[0] > 1e-14 * ev[2]) {
        warnings.push(Warning::new(WarningKind::Planar));
    }
    Ok(Distinct { verts, point_index, merged, diag })
}

/// Paper 004 §1: each point's neighbours and normal, and the triangle net
/// over the points, a closed net oriented outwards.
///
/// # Errors
/// [`Error::Fit`] when no triangle net forms.
fn triangle_net(
    verts: &[DVec3],
    options: &FitOptions,
    warnings: &mut Vec<Warning>,
) -> Result<(Vec<DVec3>, trinet::TriNet), Error> {
    let k = options.normal_neighbours.max(options.net_neighbours).min(verts.len() - 1);
    let tree = KdTree::new(verts);
    let mut idx = Vec::with_capacity(verts.len() * k);
    let mut out = Vec::new();
    for (i, p) in verts.iter().enumerate() {
        tree.nearest(*p, k, Some(i as u32), &mut out);
        idx.extend(out.iter().map(|x| x.0));
        // Fewer than k found only if points are missing; pad with the nearest.
        for _ in out.len()..k {
            idx.push(out.first().map_or(i as u32, |x| x.0));
        }
    }
    let nb = Neighbours { k, idx };
    let normals = normals::estimate(verts, &nb, options.normal_neighbours.min(k), options.max_normal_angle / 2.0);
    let net_opt = trinet::NetOptions {
        neighbours: options.net_neighbours.min(k),
        max_normal_angle: options.max_normal_angle,
        max_hole_edges: options.max_hole_edges,
    };
    let mut net = trinet::build(verts, &normals, &nb, &net_opt);
    if net.tris.is_empty() {
        return Err(Error::Fit("no triangle net forms over the points (too sparse or too noisy?)".into()));
    }
    let mut normals = normals;
    if net.borders == 0 && net.holes_open == 0 {
        // A closed net: orient it outwards (positive enclosed volume).
        let volume: f64 =
            net.tris.iter().map(|t| verts[t[0] as usize].dot(verts[t[1] as usize].cross(verts[t[2] as usize]))).sum();
        if volume < 0.0 {
            normals.iter_mut().for_each(|n| *n = -*n);
            net.tris.iter_mut().for_each(|t| t.swap(1, 2));
        }
    }
    if net.holes_open > 0 {
        warnings.push(Warning::new(WarningKind::NetGaps { count: net.holes_open }));
    }
    let used: usize = {
        let mut u = vec![false; verts.len()];
        net.tris.iter().flatten().for_each(|&v| u[v as usize] = true);
        u.iter().filter(|x| !**x).count()
    };
    if used > 0 {
        warnings.push(Warning::new(WarningKind::PointsUnused { count: used }));
    }
    Ok((normals, net))
}

/// Paper 004 §2–§4: the net's triangles merged into convex polygons, each
/// filled with its G¹ sub-patches; a polygon that cannot be filled leaves
/// a hole, with a warning.
fn polygons(
    verts: Vec<DVec3>,
    normals: Vec<DVec3>,
    tris: &[[u32; 3]],
    options: &FitOptions,
    warnings: &mut Vec<Warning>,
) -> FitSurface {
    let poly_opt = polynet::PolyOptions {
        max_angle: options.max_polygon_angle,
        max_sides: options.max_polygon_sides,
        max_tilt: options.max_polygon_tilt,
    };
    let corners_list = polynet::merge(&verts, &normals, tris, &poly_opt);
    let mut polygons = Vec::with_capacity(corners_list.len());
    let mut failed = 0usize;
    for corners in corners_list {
        match polynet::fill(&verts, &normals, &corners, &poly_opt) {
            Ok(patches) => polygons.push(FitPolygon { corners, patches }),
            Err(_) => failed += 1,
        }
    }
    if failed > 0 {
        warnings.push(Warning::new(WarningKind::PolygonsUnfilled { count: failed }));
    }
    FitSurface { points: verts, normals, polygons }
}

/// The surface's tessellation within the tolerance (relative: of `diag`):
/// the tolerance and the mesh.
///
/// # Errors
/// [`Error::Limit`] when the tolerance needs more than `max_triangles`.
fn tessellated(
    surface: &FitSurface,
    options: &FitOptions,
    diag: f64,
    warnings: &mut Vec<Warning>,
) -> Result<(f64, Mesh), Error> {
    let tol = match options.tolerance {
        Tolerance::Absolute(t) => t,
        Tolerance::Relative(r) => r * diag,
    };
    let mut estimate = 0usize;
    for poly in &surface.polygons {
        let m = poly.patches.iter().map(|p| p.level_for(tol, options.max_level)).max().unwrap_or(1);
        estimate = estimate.saturating_add(poly.patches.len().saturating_mul(m * m));
    }
    if estimate > options.max_triangles {
        return Err(Error::Limit(format!(
            "about {estimate} triangles needed for tolerance {tol:.3e}; at most {} (give a larger tolerance)",
            options.max_triangles
        )));
    }
    let polys: Vec<tessellate::PolyPatches> =
        surface.polygons.iter().map(|p| tessellate::PolyPatches { corners: &p.corners, patches: &p.patches }).collect();
    let tess = tessellate::tessellate(&surface.points, &surface.normals, &polys, tol, options.max_level);
    if tess.levels.iter().any(|&l| l >= options.max_level) {
        warnings.push(Warning::new(WarningKind::SplitLimit { level: options.max_level }));
    }
    Ok((tol, tess.mesh))
}

/// Merges points closer than `dist` (grid hashing); returns the kept points
/// and, per input point, its kept index.
fn merge_duplicates(points: &[DVec3], dist: f64) -> (Vec<DVec3>, Vec<u32>) {
    let mut kept: Vec<DVec3> = Vec::with_capacity(points.len());
    let mut index = Vec::with_capacity(points.len());
    if !(dist > 0.0) {
        // Exact duplicates only.
        let mut seen: HashMap<[u64; 3], u32> = HashMap::default();
        for p in points {
            let key = p.to_array().map(|c| (c + 0.0).to_bits());
            let k = *seen.entry(key).or_insert_with(|| {
                kept.push(*p);
                (kept.len() - 1) as u32
            });
            index.push(k);
        }
        return (kept, index);
    }
    let mut grid = crate::collections::CellGrid::new(1.0 / dist);
    let d2 = dist * dist;
    for p in points {
        let found = grid.near(*p).copied().find(|&k| kept[k as usize].distance_squared(*p) <= d2);
        let k = found.unwrap_or_else(|| {
            kept.push(*p);
            let k = (kept.len() - 1) as u32;
            grid.insert(*p, k);
            k
        });
        index.push(k);
    }
    (kept, index)
}
