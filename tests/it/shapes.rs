//! Test shapes shared by every integration test: exact NURBS builders, the
//! analytic distance to each exact shape, and the JSON files in `tests/data/`.
//!
//! Each shape is first described as plain data (a [`ModelSpec`]); the same
//! data gives the in-memory [`Model`] and the JSON text, so the files in
//! `tests/data/` and the builders cannot drift apart unnoticed: the test
//! `shapes_committed_data_matches_builders` compares them, and running the tests with
//! `SURFMESH_REGEN=1` rewrites the files.
// Every test module uses a different subset of these helpers.
#![allow(dead_code)]

use core::f64::consts::{FRAC_1_SQRT_2, PI};
use std::path::PathBuf;

use glam::{DVec2, DVec3};
use serde_json::{json, Value};
use surfmesh::{Face, FaceSurface, Model, NurbsCurve, NurbsSurface, Surface, TrimLoop};

/// Radius of the standard [`sphere`] used by the tests and `tests/data/sphere.json`.
pub const SPHERE_RADIUS: f64 = 10.0;
/// Major radius (centre of the tube to the z axis) of the standard torus.
pub const TORUS_MAJOR: f64 = 20.0;
/// Minor radius (of the tube) of the standard torus.
pub const TORUS_MINOR: f64 = 5.0;
/// Radius of [`cylinder`].
pub const CYLINDER_RADIUS: f64 = 10.0;
/// Height of [`cylinder`] (its axis is z from 0 to this).
pub const CYLINDER_HEIGHT: f64 = 30.0;

/// Centres and radii of the two holes of [`trimmed_holes`], in (u,v).
pub const HOLES: [(DVec2, f64); 2] = [(DVec2::new(0.38, 0.42), 0.12), (DVec2::new(0.62, 0.42), 0.10)];
/// Tip of the sharp spike of the outer loop of [`trimmed_holes`], in (u,v).
pub const SPIKE_TIP: DVec2 = DVec2::new(0.78, 0.97);
/// Opening angle of the spike, degrees.
pub const SPIKE_ANGLE_DEG: f64 = 20.0;
/// Length of the two straight sides of the spike, parameter units.
pub const SPIKE_SIDE: f64 = 0.3;

// ---------------------------------------------------------------------------
// Plain-data descriptions
// ---------------------------------------------------------------------------

/// A surface as the JSON schema spells it: `points[i][j]`, i along u.
#[derive(Debug, Clone)]
pub struct SurfaceSpec {
    /// Degrees `[p, q]`.
    pub degree: [usize; 2],
    /// Knot vectors `[u, v]`.
    pub knots: [Vec<f64>; 2],
    /// Control points, `points[i][j]`.
    pub points: Vec<Vec<DVec3>>,
    /// Weights of the same shape, `None` for a polynomial surface.
    pub weights: Option<Vec<Vec<f64>>>,
}

/// A trim curve in (u,v) as the JSON schema spells it.
#[derive(Debug, Clone)]
pub struct CurveSpec {
    /// Degree.
    pub degree: usize,
    /// Knot vector.
    pub knots: Vec<f64>,
    /// Control points in (u,v).
    pub points: Vec<DVec2>,
    /// Weights, `None` for a polynomial curve.
    pub weights: Option<Vec<f64>>,
}

/// One face: a surface and its trim loops (each a closed chain of curves).
#[derive(Debug, Clone)]
pub struct FaceSpec {
    /// Face name written to the file.
    pub name: String,
    /// The base surface.
    pub surface: SurfaceSpec,
    /// Trim loops; empty = the whole domain.
    pub loops: Vec<Vec<CurveSpec>>,
}

/// A whole model (units are always `"mm"`).
#[derive(Debug, Clone)]
pub struct ModelSpec {
    /// The faces in order.
    pub faces: Vec<FaceSpec>,
}

impl SurfaceSpec {
    /// The surface as the library's type.
    pub fn build(&self) -> NurbsSurface {
        NurbsSurface::try_new(
            self.degree,
            self.knots[0].clone(),
            self.knots[1].clone(),
            &self.points,
            self.weights.as_deref(),
        )
        .expect("test shape surface is valid")
    }

    fn json(&self) -> Value {
        let points: Vec<Vec<[f64; 3]>> =
            self.points.iter().map(|row| row.iter().map(|p| p.to_array()).collect()).collect();
        let mut v = json!({
            "degree": self.degree,
            "knots": self.knots,
            "points": points,
        });
        if let Some(w) = &self.weights {
            v["weights"] = json!(w);
        }
        v
    }
}

impl CurveSpec {
    /// The curve as the library's type (z = 0).
    pub fn build(&self) -> NurbsCurve {
        NurbsCurve::try_new(
            self.degree,
            self.knots.clone(),
            self.points.iter().map(|p| p.extend(0.0)).collect(),
            self.weights.clone(),
        )
        .expect("test shape curve is valid")
    }

    /// The same curve traversed backwards (knots mirrored, points and weights reversed).
    pub fn reversed(&self) -> Self {
        let (a, b) = (self.knots[0], self.knots[self.knots.len() - 1]);
        Self {
            degree: self.degree,
            knots: self.knots.iter().rev().map(|&k| a + b - k).collect(),
            points: self.points.iter().rev().copied().collect(),
            weights: self.weights.as_ref().map(|w| w.iter().rev().copied().collect()),
        }
    }

    /// Exact point at parameter `t`, evaluated here for single-span (Bézier)
    /// curves by de Casteljau in homogeneous coordinates, independently of the
    /// library.
    pub fn bezier_point(&self, t: f64) -> DVec2 {
        let p = self.degree;
        assert_eq!(self.knots.len(), 2 * (p + 1), "bezier_point needs a single-span curve");
        let (a, b) = (self.knots[0], self.knots[self.knots.len() - 1]);
        let s = (t - a) / (b - a);
        let mut h: Vec<(DVec2, f64)> = self
            .points
            .iter()
            .enumerate()
            .map(|(i, &q)| {
                let w = self.weights.as_ref().map_or(1.0, |w| w[i]);
                (q * w, w)
            })
            .collect();
        for r in 1..=p {
            for i in 0..=p - r {
                h[i] = (h[i].0 * (1.0 - s) + h[i + 1].0 * s, h[i].1 * (1.0 - s) + h[i + 1].1 * s);
            }
        }
        h[0].0 / h[0].1
    }

    /// First control point (where a clamped curve starts).
    pub fn start(&self) -> DVec2 {
        self.points[0]
    }

    /// Last control point (where a clamped curve ends).
    pub fn end(&self) -> DVec2 {
        self.points[self.points.len() - 1]
    }

    fn json(&self) -> Value {
        let points: Vec<[f64; 2]> = self.points.iter().map(|p| p.to_array()).collect();
        let mut v = json!({
            "degree": self.degree,
            "knots": self.knots,
            "points": points,
        });
        if let Some(w) = &self.weights {
            v["weights"] = json!(w);
        }
        v
    }
}

impl ModelSpec {
    /// The model as the library's type.
    pub fn model(&self) -> Model {
        Model {
            units: "mm".into(),
            faces: self
                .faces
                .iter()
                .map(|f| Face {
                    name: Some(f.name.clone()),
                    surface: FaceSurface::Nurbs(f.surface.build()),
                    loops: f
                        .loops
                        .iter()
                        .map(|l| TrimLoop { curves: l.iter().map(CurveSpec::build).collect() })
                        .collect(),
                })
                .collect(),
            warnings: Vec::new(),
            tolerance: None,
            bodies: Vec::new(),
            ..Default::default()
        }
    }

    /// The model in DESIGN.md's JSON schema.
    pub fn json(&self) -> Value {
        let faces: Vec<Value> = self
            .faces
            .iter()
            .map(|f| {
                let mut v = json!({ "name": f.name, "surface": f.surface.json() });
                if !f.loops.is_empty() {
                    let loops: Vec<Value> = f
                        .loops
                        .iter()
                        .map(|l| json!({ "curves": l.iter().map(CurveSpec::json).collect::<Vec<_>>() }))
                        .collect();
                    v["loops"] = Value::Array(loops);
                }
                v
            })
            .collect();
        json!({ "units": "mm", "faces": faces })
    }

    /// The JSON text written to `tests/data/`: objects indented, short arrays on one line.
    pub fn json_text(&self) -> String {
        let mut out = String::new();
        write_value(&self.json(), 0, &mut out);
        out.push('\n');
        out
    }
}

/// Order of keys in the written files.
const KEY_ORDER: [&str; 9] = ["units", "name", "surface", "loops", "curves", "degree", "knots", "points", "weights"];

/// Writes `v` with two-space indentation, keeping any array or object whose
/// compact form is short on one line (rows of control points stay readable).
fn write_value(v: &Value, indent: usize, out: &mut String) {
    let compact = v.to_string();
    if compact.len() + 2 * indent <= 110 {
        out.push_str(&compact);
        return;
    }
    let pad = "  ".repeat(indent + 1);
    match v {
        Value::Array(items) => {
            out.push_str("[\n");
            for (k, item) in items.iter().enumerate() {
                out.push_str(&pad);
                write_value(item, indent + 1, out);
                out.push_str(if k + 1 < items.len() { ",\n" } else { "\n" });
            }
            out.push_str(&"  ".repeat(indent));
            out.push(']');
        }
        Value::Object(map) => {
            out.push_str("{\n");
            // The schema's order (units first, weights after points), not alphabetical.
            let rank = |k: &str| KEY_ORDER.iter().position(|&o| o == k).unwrap_or(KEY_ORDER.len());
            let mut entries: Vec<(&String, &Value)> = map.iter().collect();
            entries.sort_by_key(|(k, _)| rank(k));
            for (k, (key, item)) in entries.into_iter().enumerate() {
                out.push_str(&pad);
                out.push_str(&Value::String(key.clone()).to_string());
                out.push_str(": ");
                write_value(item, indent + 1, out);
                out.push_str(if k + 1 < map.len() { ",\n" } else { "\n" });
            }
            out.push_str(&"  ".repeat(indent));
            out.push('}');
        }
        _ => out.push_str(&compact),
    }
}

// ---------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------

/// Knots of the exact 9-point rational quadratic full circle.
pub const CIRCLE_KNOTS: [f64; 12] = [0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0];

/// Control points and weights of the unit circle (counter-clockwise from (1,0)):
/// the corners of the circumscribed square carry weight √2/2.
pub fn unit_circle() -> (Vec<DVec2>, Vec<f64>) {
    let pts = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    let points = pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
    let weights = (0..9).map(|i| if i % 2 == 0 { 1.0 } else { FRAC_1_SQRT_2 }).collect();
    (points, weights)
}

/// Surface of revolution about z of a rational profile `(ρ, z)` with weights:
/// `P_ij = (ρ_j·cx_i, ρ_j·cy_i, z_j)`, `w_ij = wc_i·wp_j` (exact, The NURBS Book §8.5).
fn revolve(profile_degree: usize, profile_knots: &[f64], profile: &[(f64, f64)], profile_w: &[f64]) -> SurfaceSpec {
    let (circle, cw) = unit_circle();
    // `+ 0.0` turns the -0.0 of 0·(−1) into 0.0, which keeps the JSON tidy.
    let points = circle
        .iter()
        .map(|c| profile.iter().map(|&(rho, z)| DVec3::new(rho * c.x + 0.0, rho * c.y + 0.0, z)).collect())
        .collect();
    let weights = cw.iter().map(|&wu| profile_w.iter().map(|&wv| wu * wv).collect()).collect();
    SurfaceSpec {
        degree: [2, profile_degree],
        knots: [CIRCLE_KNOTS.to_vec(), profile_knots.to_vec()],
        points,
        weights: Some(weights),
    }
}

/// A full circle in (u,v), counter-clockwise from `centre + (radius, 0)`.
pub fn uv_circle(centre: DVec2, radius: f64) -> CurveSpec {
    let (circle, weights) = unit_circle();
    CurveSpec {
        degree: 2,
        knots: CIRCLE_KNOTS.to_vec(),
        points: circle.iter().map(|&c| centre + c * radius).collect(),
        weights: Some(weights),
    }
}

fn line(a: DVec2, b: DVec2) -> CurveSpec {
    CurveSpec { degree: 1, knots: vec![0.0, 0.0, 1.0, 1.0], points: vec![a, b], weights: None }
}

fn single_face(name: &str, surface: SurfaceSpec, loops: Vec<Vec<CurveSpec>>) -> ModelSpec {
    ModelSpec { faces: vec![FaceSpec { name: name.into(), surface, loops }] }
}

/// The base surface of the first face of `model`.
pub fn first_surface(model: &Model) -> &NurbsSurface {
    match &model.faces[0].surface {
        FaceSurface::Nurbs(s) => s,
        other => panic!("unexpected surface kind {other:?}"),
    }
}

// ---------------------------------------------------------------------------
// The shapes
// ---------------------------------------------------------------------------

/// Bicubic free-form height field, about 100 × 100 units, 8 × 8 control
/// points, non-uniform knots in both directions, polynomial (no weights).
pub fn freeform_spec() -> ModelSpec {
    let xs = [0.0, 12.0, 27.0, 41.0, 58.0, 72.0, 87.0, 100.0];
    let ys = [0.0, 15.0, 26.0, 44.0, 57.0, 70.0, 86.0, 100.0];
    let points = (0..8)
        .map(|i| {
            (0..8)
                .map(|j| {
                    let (fi, fj) = (i as f64, j as f64);
                    let z = 12.0 * (1.3 * fi + 0.4).sin() * (0.9 * fj).cos() + 4.0 * (0.7 * (fi + fj)).sin();
                    // Round to 1e-6 so the file holds short, platform-independent numbers.
                    DVec3::new(xs[i], ys[j], (z * 1e6).round() / 1e6)
                })
                .collect()
        })
        .collect();
    let surface = SurfaceSpec {
        degree: [3, 3],
        knots: [
            vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.35, 0.5, 0.9, 1.0, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.0, 0.2, 0.3, 0.65, 0.8, 1.0, 1.0, 1.0, 1.0],
        ],
        points,
        weights: None,
    };
    single_face("freeform", surface, Vec::new())
}

/// See [`freeform_spec`].
pub fn freeform() -> Model {
    freeform_spec().model()
}

/// Exact rational sphere of radius `r` centred at the origin, degree (2,2):
/// u is the full circle around z (9 points), v the meridian half circle from
/// the south pole (v = 0) to the north pole (v = 1) (5 points). Both v edges
/// collapse to a pole. The normal `Su × Sv` points outward.
pub fn sphere_spec(r: f64) -> ModelSpec {
    let s = FRAC_1_SQRT_2;
    let surface = revolve(
        2,
        &[0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0],
        &[(0.0, -r), (r, -r), (r, 0.0), (r, r), (0.0, r)],
        &[1.0, s, 1.0, s, 1.0],
    );
    single_face("sphere", surface, Vec::new())
}

/// See [`sphere_spec`].
pub fn sphere(r: f64) -> Model {
    sphere_spec(r).model()
}

/// The base surface of [`sphere`].
pub fn sphere_surface(r: f64) -> NurbsSurface {
    sphere_spec(r).faces[0].surface.build()
}

/// Exact distance from `p` to the sphere of radius `r` about the origin.
pub fn sphere_distance_r(p: DVec3, r: f64) -> f64 {
    (p.length() - r).abs()
}

/// Exact distance from `p` to the standard sphere (`r =` [`SPHERE_RADIUS`]).
pub fn sphere_distance(p: DVec3) -> f64 {
    sphere_distance_r(p, SPHERE_RADIUS)
}

/// Exact rational full torus about the z axis, degree (2,2), 9 × 9 points:
/// u runs around z, v around the tube starting at the outer equator and
/// going up. Major radius `big`, tube radius `small`; normal points outward.
pub fn torus_spec(big: f64, small: f64) -> ModelSpec {
    let (circle, cw) = unit_circle();
    let profile: Vec<(f64, f64)> = circle.iter().map(|c| (big + small * c.x, small * c.y)).collect();
    let surface = revolve(2, &CIRCLE_KNOTS, &profile, &cw);
    single_face("torus", surface, Vec::new())
}

/// See [`torus_spec`].
pub fn torus(big: f64, small: f64) -> Model {
    torus_spec(big, small).model()
}

/// The base surface of [`torus`].
pub fn torus_surface(big: f64, small: f64) -> NurbsSurface {
    torus_spec(big, small).faces[0].surface.build()
}

/// Exact distance from `p` to the torus with radii `big`, `small` about z.
pub fn torus_distance_r(p: DVec3, big: f64, small: f64) -> f64 {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    ((rho - big).hypot(p.z) - small).abs()
}

/// Exact distance from `p` to the standard torus ([`TORUS_MAJOR`], [`TORUS_MINOR`]).
pub fn torus_distance(p: DVec3) -> f64 {
    torus_distance_r(p, TORUS_MAJOR, TORUS_MINOR)
}

/// Exact rational cylinder: full circle of radius [`CYLINDER_RADIUS`] around z
/// (u, degree 2) × straight line z = 0 … [`CYLINDER_HEIGHT`] (v, degree 1).
/// Open at both ends; the u = 0 and u = 1 edges meet in a seam at x > 0, y = 0.
pub fn cylinder_spec() -> ModelSpec {
    let surface =
        revolve(1, &[0.0, 0.0, 1.0, 1.0], &[(CYLINDER_RADIUS, 0.0), (CYLINDER_RADIUS, CYLINDER_HEIGHT)], &[1.0, 1.0]);
    single_face("cylinder", surface, Vec::new())
}

/// See [`cylinder_spec`].
pub fn cylinder() -> Model {
    cylinder_spec().model()
}

/// Exact distance from `p` to the (finite, open) cylinder of [`cylinder`].
pub fn cylinder_distance(p: DVec3) -> f64 {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    let dz = p.z - p.z.clamp(0.0, CYLINDER_HEIGHT);
    (rho - CYLINDER_RADIUS).hypot(dz)
}

/// Apex of [`pole`]: the point its whole v = 0 edge collapses to.
pub const POLE_APEX: DVec3 = DVec3::new(0.0, 0.0, 20.0);

/// Polynomial bicubic dome cap whose v = 0 edge collapses to the apex
/// [`POLE_APEX`] (all control points of the first v-row are equal). u sweeps
/// 270° around z (6 points, non-uniform knots); the second row lies in the
/// apex's plane, so the tangent plane at the apex is horizontal (normal ±z).
pub fn pole_spec() -> ModelSpec {
    let rho = [0.0, 8.0, 18.0, 30.0];
    let z = [POLE_APEX.z, POLE_APEX.z, 12.0, 0.0];
    let points = (0..6)
        .map(|i| {
            let a = 1.5 * PI * i as f64 / 5.0;
            (0..4)
                .map(|j| {
                    // Round to 1e-9 so the file holds short numbers; the apex
                    // row stays exactly the apex.
                    let x = (rho[j] * a.cos() * 1e9).round() / 1e9 + 0.0;
                    let y = (rho[j] * a.sin() * 1e9).round() / 1e9 + 0.0;
                    DVec3::new(x, y, z[j])
                })
                .collect()
        })
        .collect();
    let surface = SurfaceSpec {
        degree: [3, 3],
        knots: [vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.6, 1.0, 1.0, 1.0, 1.0], vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]],
        points,
        weights: None,
    };
    single_face("pole", surface, Vec::new())
}

/// See [`pole_spec`].
pub fn pole() -> Model {
    pole_spec().model()
}

/// Corners of the spike of the outer loop, `(a, b)`: `a` right of the tip,
/// `b` left, both [`SPIKE_SIDE`] from [`SPIKE_TIP`], [`SPIKE_ANGLE_DEG`] apart.
pub fn spike_corners() -> (DVec2, DVec2) {
    let half = (SPIKE_ANGLE_DEG / 2.0).to_radians();
    let a = SPIKE_TIP + SPIKE_SIDE * DVec2::new(half.sin(), -half.cos());
    let b = SPIKE_TIP + SPIKE_SIDE * DVec2::new(-half.sin(), -half.cos());
    (a, b)
}

/// The outer loop of [`trimmed_holes`] in counter-clockwise order (the file
/// stores it reversed, clockwise). Eight single-span curves: four lines, the
/// two sides of the 20° spike, a cubic, a rational quadratic arc and a
/// quadratic whose parameter runs over [2, 3].
pub fn trimmed_holes_outer_ccw() -> Vec<CurveSpec> {
    let (a, b) = spike_corners();
    let p = |x: f64, y: f64| DVec2::new(x, y);
    vec![
        line(p(0.05, 0.05), p(0.95, 0.05)),
        CurveSpec {
            degree: 3,
            knots: vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            points: vec![p(0.95, 0.05), p(0.99, 0.22), p(0.90, 0.42), p(0.95, 0.60)],
            weights: None,
        },
        line(p(0.95, 0.60), a),
        line(a, SPIKE_TIP),
        line(SPIKE_TIP, b),
        CurveSpec {
            degree: 2,
            knots: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            points: vec![b, p(0.52, 0.90), p(0.30, 0.80)],
            weights: Some(vec![1.0, 0.8, 1.0]),
        },
        CurveSpec {
            degree: 2,
            knots: vec![2.0, 2.0, 2.0, 3.0, 3.0, 3.0],
            points: vec![p(0.30, 0.80), p(0.10, 0.80), p(0.05, 0.60)],
            weights: None,
        },
        line(p(0.05, 0.60), p(0.05, 0.05)),
    ]
}

/// A gently curved bicubic patch over [0,1]² trimmed by an outer loop with
/// sharp corners (a 20° spike among them), given clockwise on purpose, and two
/// circular holes ([`HOLES`], the first counter-clockwise, the second
/// clockwise) 0.02 apart in (u,v).
pub fn trimmed_holes_spec() -> ModelSpec {
    let heights = [[0.0, 2.0, 2.0, 0.0], [3.0, 6.0, 5.0, 2.0], [2.0, 5.0, 6.0, 3.0], [0.0, 2.0, 3.0, 1.0]];
    let points = (0..4)
        .map(|i| (0..4).map(|j| DVec3::new(100.0 * i as f64 / 3.0, 100.0 * j as f64 / 3.0, heights[i][j])).collect())
        .collect();
    let surface = SurfaceSpec {
        degree: [3, 3],
        knots: [vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0], vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]],
        points,
        weights: None,
    };
    let outer_cw: Vec<CurveSpec> = trimmed_holes_outer_ccw().iter().rev().map(CurveSpec::reversed).collect();
    let hole0 = vec![uv_circle(HOLES[0].0, HOLES[0].1)];
    let hole1 = vec![uv_circle(HOLES[1].0, HOLES[1].1).reversed()];
    single_face("trimmed_holes", surface, vec![outer_cw, hole0, hole1])
}

/// See [`trimmed_holes_spec`].
pub fn trimmed_holes() -> Model {
    trimmed_holes_spec().model()
}

/// The kept region of [`trimmed_holes`] in (u,v): inside the outer loop
/// (a fine polyline of its exact curves) and outside both (analytic) circles.
#[derive(Debug, Clone)]
pub struct TrimRegion {
    /// Outer boundary, counter-clockwise, closed implicitly.
    pub outer: Vec<DVec2>,
    /// Holes as `(centre, radius)`.
    pub holes: Vec<(DVec2, f64)>,
}

impl TrimRegion {
    /// How far `uv` lies outside the kept region: 0 inside or on the boundary,
    /// else the distance to the region (parameter units).
    pub fn outside_by(&self, uv: DVec2) -> f64 {
        let mut out = 0.0f64;
        if !point_in_polygon(&self.outer, uv) {
            out = out.max(distance_to_polyline(&self.outer, uv));
        }
        for &(c, r) in &self.holes {
            out = out.max(r - uv.distance(c));
        }
        out
    }

    /// Whether `uv` is in the kept region, allowing `tol` outside it.
    pub fn contains(&self, uv: DVec2, tol: f64) -> bool {
        self.outside_by(uv) <= tol
    }
}

/// The kept region of [`trimmed_holes`]; the outer polyline has chords of
/// at most 1/4000 of each curved piece (sagitta below 1e-7).
pub fn trimmed_holes_regions() -> TrimRegion {
    let mut outer = Vec::new();
    for c in trimmed_holes_outer_ccw() {
        let n = if c.degree == 1 { 1 } else { 4000 };
        let (a, b) = (c.knots[0], c.knots[c.knots.len() - 1]);
        for k in 0..n {
            outer.push(c.bezier_point(a + (b - a) * k as f64 / n as f64));
        }
    }
    TrimRegion { outer, holes: HOLES.to_vec() }
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n).map(|i| poly[i].perp_dot(poly[(i + 1) % n])).sum::<f64>() * 0.5
}

fn point_in_polygon(poly: &[DVec2], p: DVec2) -> bool {
    let n = poly.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn distance_to_polyline(poly: &[DVec2], p: DVec2) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
            p.distance(a + ab * t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every shape written to `tests/data/`, by file stem.
pub fn all_specs() -> Vec<(&'static str, ModelSpec)> {
    vec![
        ("freeform", freeform_spec()),
        ("sphere", sphere_spec(SPHERE_RADIUS)),
        ("torus", torus_spec(TORUS_MAJOR, TORUS_MINOR)),
        ("cylinder", cylinder_spec()),
        ("pole", pole_spec()),
        ("trimmed_holes", trimmed_holes_spec()),
    ]
}

/// Path of `tests/data/<stem>.json`.
pub fn data_path(stem: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests").join("data").join(format!("{stem}.json"))
}

// ---------------------------------------------------------------------------
// Tests of the shapes themselves
// ---------------------------------------------------------------------------

/// Grid of `n × n` parameters covering the closed domain of `s`.
fn grid(s: &dyn Surface, n: usize) -> Vec<DVec2> {
    let [lo, hi] = s.domain();
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            out.push(lo + (hi - lo) * DVec2::new(i as f64 / n as f64, j as f64 / n as f64));
        }
    }
    out
}

/// Numbers equal within a relative 1e-12 (guards against last-bit differences
/// of `sin`/`cos` between platforms), everything else exactly.
fn json_close(a: &Value, b: &Value, at: &str) -> Result<(), String> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap_or(f64::NAN), y.as_f64().unwrap_or(f64::NAN));
            if (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1.0) {
                Ok(())
            } else {
                Err(format!("{at}: {x} != {y}"))
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            x.iter().zip(y).enumerate().try_for_each(|(i, (x, y))| json_close(x, y, &format!("{at}[{i}]")))
        }
        (Value::Object(x), Value::Object(y)) if x.len() == y.len() => x.iter().try_for_each(|(k, xv)| match y.get(k) {
            Some(yv) => json_close(xv, yv, &format!("{at}.{k}")),
            None => Err(format!("{at}: key {k} missing")),
        }),
        _ if a == b => Ok(()),
        _ => Err(format!("{at}: {a} != {b}")),
    }
}

/// With `SURFMESH_REGEN=1` rewrites `tests/data/*.json` from the builders;
/// always checks that the committed files hold exactly the builders' data.
#[test]
fn shapes_committed_data_matches_builders() {
    let regen = std::env::var("SURFMESH_REGEN").is_ok_and(|v| v == "1");
    for (stem, spec) in all_specs() {
        let path = data_path(stem);
        if regen {
            std::fs::create_dir_all(path.parent().expect("data dir")).expect("create tests/data");
            std::fs::write(&path, spec.json_text()).expect("write test data");
        }
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run with SURFMESH_REGEN=1 to create it)", path.display()));
        let committed: Value = serde_json::from_str(&text).expect("committed data is JSON");
        if let Err(e) = json_close(&committed, &spec.json(), stem) {
            panic!("{stem}.json differs from its builder at {e}; run with SURFMESH_REGEN=1");
        }
    }
}

/// The JSON text parses back to the same value (numbers round-trip exactly).
#[test]
fn shapes_json_text_round_trips() {
    for (stem, spec) in all_specs() {
        let parsed: Value = serde_json::from_str(&spec.json_text()).expect("valid JSON");
        assert_eq!(parsed, spec.json(), "{stem}");
    }
}

/// Every sampled point of the rational sphere, torus and cylinder lies on the
/// exact analytic shape (the constructions are exact, not approximations).
#[test]
fn shapes_analytic_surfaces_are_exact() {
    type Case = (&'static str, NurbsSurface, fn(DVec3) -> f64, f64);
    let cases: [Case; 3] = [
        ("sphere", sphere_surface(SPHERE_RADIUS), sphere_distance, SPHERE_RADIUS),
        ("torus", torus_surface(TORUS_MAJOR, TORUS_MINOR), torus_distance, TORUS_MAJOR),
        ("cylinder", cylinder_spec().faces[0].surface.build(), cylinder_distance, CYLINDER_HEIGHT),
    ];
    for (name, s, dist, size) in cases {
        for uv in grid(&s, 37) {
            let p = s.point(uv);
            assert!(dist(p) <= 1e-13 * size, "{name} at {uv}: off by {}", dist(p));
        }
    }
    // The sphere covers both poles and the whole equator.
    let s = sphere_surface(SPHERE_RADIUS);
    assert!(s.point(DVec2::new(0.3, 0.0)).distance(DVec3::new(0.0, 0.0, -SPHERE_RADIUS)) < 1e-12);
    assert!(s.point(DVec2::new(0.7, 1.0)).distance(DVec3::new(0.0, 0.0, SPHERE_RADIUS)) < 1e-12);
    let mut min_angle_gap = 0.0f64;
    let mut angles: Vec<f64> =
        (0..=400).map(|k| s.point(DVec2::new(k as f64 / 400.0, 0.5))).map(|p| p.y.atan2(p.x)).collect();
    angles.sort_by(f64::total_cmp);
    for w in angles.windows(2) {
        min_angle_gap = min_angle_gap.max(w[1] - w[0]);
    }
    assert!(angles[0] < -3.1 && angles[angles.len() - 1] > 3.1 && min_angle_gap < 0.05, "equator not covered");
}

/// The cylinder distance is the distance to the finite patch, not the infinite cylinder.
#[test]
fn shapes_cylinder_distance_respects_ends() {
    assert!((cylinder_distance(DVec3::new(0.0, 13.0, 15.0)) - 3.0).abs() < 1e-12);
    assert!((cylinder_distance(DVec3::new(10.0, 0.0, -4.0)) - 4.0).abs() < 1e-12);
    assert!((cylinder_distance(DVec3::new(0.0, 0.0, 15.0)) - 10.0).abs() < 1e-12);
    assert!((cylinder_distance(DVec3::new(13.0, 0.0, 34.0)) - 5.0).abs() < 1e-12);
    assert!((torus_distance(DVec3::new(0.0, 27.0, 0.0)) - 2.0).abs() < 1e-12);
    assert!((torus_distance(DVec3::new(0.0, 0.0, 0.0)) - 15.0).abs() < 1e-12);
    assert!((sphere_distance(DVec3::new(3.0, 4.0, 0.0)) - 5.0).abs() < 1e-12);
}

/// The pole shape's whole v = 0 edge is the apex, and nothing else collapses.
#[test]
fn shapes_pole_edge_collapses_to_apex() {
    let m = pole();
    let s = first_surface(&m);
    for k in 0..=50 {
        let u = k as f64 / 50.0;
        assert!(s.point(DVec2::new(u, 0.0)).distance(POLE_APEX) < 1e-12);
        let far = s.point(DVec2::new(u, 1.0));
        // The polynomial rim lies inside its control polygon of radius 30.
        let rim = far.truncate().length();
        assert!(rim > 20.0 && rim <= 30.0 && far.z.abs() < 1e-12, "rim at {far}");
        let d = s.derivs(DVec2::new(u, 0.5));
        assert!(d.su.cross(d.sv).length() > 1e-3, "unexpected degeneracy at u = {u}");
    }
}

/// The trimmed face: loops closed, outer loop clockwise in the file, spike
/// angle and hole gap as documented, and the region test sensible.
#[test]
fn shapes_trimmed_holes_layout() {
    let spec = trimmed_holes_spec();
    let face = &spec.faces[0];
    for (l, lp) in face.loops.iter().enumerate() {
        for (k, c) in lp.iter().enumerate() {
            let next = &lp[(k + 1) % lp.len()];
            assert!(c.end().distance(next.start()) < 1e-15, "loop {l} curve {k} not joined");
            assert!(c.points.iter().all(|p| p.cmpge(DVec2::ZERO).all() && p.cmple(DVec2::ONE).all()));
        }
    }
    // Orientation from the exact curves (fine polyline), as stored in the file.
    let poly = |lp: &[CurveSpec]| -> Vec<DVec2> {
        lp.iter()
            .flat_map(|c| {
                let built = c.build();
                let (a, b) = built.domain();
                (0..200).map(move |k| built.point(a + (b - a) * k as f64 / 200.0).truncate())
            })
            .collect()
    };
    assert!(signed_area(&poly(&face.loops[0])) < 0.0, "outer loop must be clockwise in the file");
    assert!(signed_area(&poly(&face.loops[1])) > 0.0);
    assert!(signed_area(&poly(&face.loops[2])) < 0.0);
    // The library's curves agree with the independent Bézier evaluation.
    for c in trimmed_holes_outer_ccw() {
        let built = c.build();
        let (a, b) = built.domain();
        for k in 0..=20 {
            let t = a + (b - a) * k as f64 / 20.0;
            assert!(built.point(t).truncate().distance(c.bezier_point(t)) < 1e-14);
        }
    }
    // Circles are exact.
    for (l, &(c, r)) in HOLES.iter().enumerate() {
        let curve = face.loops[l + 1][0].build();
        for k in 0..=100 {
            let p = curve.point(k as f64 / 100.0).truncate();
            assert!((p.distance(c) - r).abs() < 1e-15, "hole {l}");
        }
    }
    let gap = HOLES[1].0.distance(HOLES[0].0) - HOLES[0].1 - HOLES[1].1;
    assert!((gap - 0.02).abs() < 1e-12);
    let (a, b) = spike_corners();
    let angle = (a - SPIKE_TIP).angle_to(b - SPIKE_TIP).abs().to_degrees();
    assert!((angle - SPIKE_ANGLE_DEG).abs() < 1e-9, "spike angle {angle}");

    let region = trimmed_holes_regions();
    assert!(signed_area(&region.outer) > 0.3);
    assert!(region.contains(DVec2::new(0.2, 0.2), 0.0));
    assert!(region.contains(SPIKE_TIP - DVec2::new(0.0, 0.05), 0.0), "inside the spike");
    assert!(!region.contains(SPIKE_TIP - DVec2::new(0.04, 0.05), 1e-3), "beside the spike");
    assert!(!region.contains(HOLES[0].0, 1e-3) && !region.contains(HOLES[1].0, 1e-3), "hole centres");
    assert!(region.contains(DVec2::new(0.51, 0.42), 0.0), "in the gap between the holes");
    assert!(!region.contains(DVec2::new(0.02, 0.5), 1e-3) && !region.contains(DVec2::new(0.5, 0.99), 1e-3));
    assert!((region.outside_by(DVec2::new(0.5, 0.0)) - 0.05).abs() < 1e-12);
    // Points on the exact boundary are inside within the polyline's sagitta.
    for lp in &face.loops {
        for p in poly(lp) {
            assert!(region.outside_by(p) < 1e-7, "boundary point {p} outside by {}", region.outside_by(p));
        }
    }
}

/// Each builder's model holds what its spec says, and `first_surface` finds it.
#[test]
fn shapes_models_match_specs() {
    for (stem, spec) in all_specs() {
        let m = spec.model();
        assert_eq!(m.faces.len(), 1, "{stem}");
        assert_eq!(m.faces[0].name.as_deref(), Some(stem));
        assert_eq!(m.faces[0].loops.len(), spec.faces[0].loops.len());
        let s = first_surface(&m);
        assert_eq!(s.degree(), spec.faces[0].surface.degree);
        assert_eq!(s.is_rational(), spec.faces[0].surface.weights.is_some(), "{stem}");
    }
}

/// The committed files read with the library's JSON reader give the builders'
/// geometry: same faces and loops, sampled points within 1e-12.
#[test]
fn shapes_committed_data_reads_back() {
    for (stem, spec) in all_specs() {
        let bytes = std::fs::read(data_path(stem)).expect("committed test data");
        let read = surfmesh::read_json(&bytes).unwrap_or_else(|e| panic!("{stem}.json: {e}"));
        let built = spec.model();
        assert_eq!(read.units, "mm", "{stem}");
        assert_eq!(read.faces.len(), built.faces.len(), "{stem}");
        for (f, (rf, bf)) in read.faces.iter().zip(&built.faces).enumerate() {
            assert_eq!(rf.name, bf.name, "{stem} face {f}");
            let size = bf.surface.bounding_box().diagonal().max(1.0);
            for uv in grid(&bf.surface, 23) {
                let (p, q) = (rf.surface.point(uv), bf.surface.point(uv));
                assert!(p.distance(q) <= 1e-12 * size, "{stem} face {f} at {uv}: {p} vs {q}");
            }
            assert_eq!(rf.loops.len(), bf.loops.len(), "{stem} face {f}");
            for (l, (rl, bl)) in rf.loops.iter().zip(&bf.loops).enumerate() {
                assert_eq!(rl.curves.len(), bl.curves.len(), "{stem} face {f} loop {l}");
                for (c, (rc, bc)) in rl.curves.iter().zip(&bl.curves).enumerate() {
                    assert_eq!(rc.domain(), bc.domain(), "{stem} face {f} loop {l} curve {c}");
                    let (a, b) = bc.domain();
                    for k in 0..=40 {
                        let t = a + (b - a) * k as f64 / 40.0;
                        let (p, q) = (rc.point(t), bc.point(t));
                        assert!(p.distance(q) <= 1e-12, "{stem} face {f} loop {l} curve {c} at {t}");
                    }
                }
            }
        }
    }
}
