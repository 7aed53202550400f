//! The JSON model reader (DESIGN.md's schema).
//!
//! Parsing happens in two steps: the text is scanned into plain nested
//! vectors (`Raw*` below, which mirror the file one to one), then [`read_json`]
//! checks sizes, shapes and numbers and builds the validated geometry, naming
//! the face, loop, curve and field of the first problem it finds.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::json_text::{Scan, Text, TextError};
use crate::nurbs::{KnotVector, NurbsCurve, NurbsError, NurbsSurface};
use crate::{Error, Face, FaceSurface, Model, TrimLoop};

/// Most faces one file may hold.
const MAX_FACES: usize = 100_000;
/// Most control points one surface may have.
const MAX_SURFACE_POINTS: usize = 1_000_000;
/// Most control points one trim curve may have.
const MAX_CURVE_POINTS: usize = 1_000_000;
/// Most trim loops one face may have.
const MAX_LOOPS: usize = 100_000;
/// Most curves one trim loop may have.
const MAX_CURVES: usize = 100_000;
/// Most control points (surfaces and curves together) one file may hold.
const MAX_TOTAL_POINTS: usize = 20_000_000;
/// Loop ends must meet within this fraction of the surface's parameter range.
const CLOSURE_TOLERANCE: f64 = 1e-9;

struct RawModel {
    units: Option<String>,
    faces: Vec<RawFace>,
}

struct RawFace {
    name: Option<String>,
    surface: Option<RawSurface>,
    loops: Vec<RawLoop>,
}

struct RawSurface {
    degree: Vec<usize>,
    knots: Vec<Vec<f64>>,
    points: Vec<Vec<Vec<f64>>>,
    weights: Option<Vec<Vec<f64>>>,
}

struct RawLoop {
    curves: Vec<RawCurve>,
}

struct RawCurve {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Vec<f64>>,
    weights: Option<Vec<f64>>,
}

/// Reads the JSON model.
///
/// # Errors
/// [`Error::Json`] with line and column for text that is not JSON or does not
/// have the model's shape; [`Error::Model`]/[`Error::Nurbs`] naming the face,
/// loop, curve and field of a bad value; [`Error::Limit`] for a file larger
/// than the reader accepts.
pub fn read_json(bytes: &[u8]) -> Result<Model, Error> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut text = Text::new(bytes);
    let raw = raw_model(&mut text).and_then(|raw| text.end().map(|()| raw)).map_err(|e| {
        let (line, column) = text.line_column(e.at);
        Error::Json { line, column, message: e.message }
    })?;
    if raw.faces.is_empty() {
        return Err(model_error("faces".into(), "the model has no faces"));
    }
    if raw.faces.len() > MAX_FACES {
        return Err(Error::Limit(format!("{} faces; at most {MAX_FACES} are accepted", raw.faces.len())));
    }
    let mut total = 0usize;
    let mut faces = Vec::with_capacity(raw.faces.len());
    for (index, face) in raw.faces.into_iter().enumerate() {
        faces.push(build_face(index, face, &mut total)?);
    }
    Ok(Model { units: raw.units.unwrap_or_else(|| "mm".into()), faces, ..Model::default() })
}

/// The error for a key the record does not have.
fn unknown(t: &Text<'_>, key: &str, expected: &str) -> TextError {
    t.error(format!("unknown field `{key}`, expected {expected}"))
}

/// The error for a required key the record lacks (at the record's end).
fn missing(t: &Text<'_>, key: &str) -> TextError {
    t.error(format!("missing field `{key}`"))
}

/// `null`, or what `read` reads.
fn nullable<'a, T>(t: &mut Text<'a>, read: impl FnOnce(&mut Text<'a>) -> Scan<T>) -> Scan<Option<T>> {
    if t.null() {
        Ok(None)
    } else {
        read(t).map(Some)
    }
}

/// An array of what `read` reads.
fn list<'a, T>(t: &mut Text<'a>, read: impl Fn(&mut Text<'a>) -> Scan<T>) -> Scan<Vec<T>> {
    let mut out = Vec::new();
    t.array(&mut |t| {
        out.push(read(t)?);
        Ok(())
    })?;
    Ok(out)
}

fn raw_model(t: &mut Text<'_>) -> Scan<RawModel> {
    let (mut units, mut faces) = (None, Vec::new());
    t.object(&mut |t, key| {
        match key {
            "units" => units = nullable(t, Text::string)?,
            "faces" => faces = list(t, raw_face)?,
            _ => return Err(unknown(t, key, "`units` or `faces`")),
        }
        Ok(())
    })?;
    Ok(RawModel { units, faces })
}

fn raw_face(t: &mut Text<'_>) -> Scan<RawFace> {
    let (mut name, mut surface, mut loops) = (None, None, Vec::new());
    t.object(&mut |t, key| {
        match key {
            "name" => name = nullable(t, Text::string)?,
            "surface" => surface = nullable(t, raw_surface)?,
            "loops" => loops = list(t, |t| raw_loop(t))?,
            _ => return Err(unknown(t, key, "one of `name`, `surface`, `loops`")),
        }
        Ok(())
    })?;
    Ok(RawFace { name, surface, loops })
}

fn raw_surface(t: &mut Text<'_>) -> Scan<RawSurface> {
    let (mut degree, mut knots, mut points, mut weights) = (None, None, None, None);
    t.object(&mut |t, key| {
        match key {
            "degree" => degree = Some(list(t, Text::count)?),
            "knots" => knots = Some(list(t, Text::numbers)?),
            "points" => points = Some(list(t, |t| list(t, Text::numbers))?),
            "weights" => weights = nullable(t, |t| list(t, Text::numbers))?,
            _ => return Err(unknown(t, key, "one of `degree`, `knots`, `points`, `weights`")),
        }
        Ok(())
    })?;
    let degree = degree.ok_or_else(|| missing(t, "degree"))?;
    let knots = knots.ok_or_else(|| missing(t, "knots"))?;
    let points = points.ok_or_else(|| missing(t, "points"))?;
    Ok(RawSurface { degree, knots, points, weights })
}

fn raw_loop(t: &mut Text<'_>) -> Scan<RawLoop> {
    let mut curves = None;
    t.object(&mut |t, key| {
        match key {
            "curves" => curves = Some(list(t, raw_curve)?),
            _ => return Err(unknown(t, key, "`curves`")),
        }
        Ok(())
    })?;
    Ok(RawLoop { curves: curves.ok_or_else(|| missing(t, "curves"))? })
}

fn raw_curve(t: &mut Text<'_>) -> Scan<RawCurve> {
    let (mut degree, mut knots, mut points, mut weights) = (None, None, None, None);
    t.object(&mut |t, key| {
        match key {
            "degree" => degree = Some(t.count()?),
            "knots" => knots = Some(t.numbers()?),
            "points" => points = Some(list(t, Text::numbers)?),
            "weights" => weights = nullable(t, Text::numbers)?,
            _ => return Err(unknown(t, key, "one of `degree`, `knots`, `points`, `weights`")),
        }
        Ok(())
    })?;
    let degree = degree.ok_or_else(|| missing(t, "degree"))?;
    let knots = knots.ok_or_else(|| missing(t, "knots"))?;
    let points = points.ok_or_else(|| missing(t, "points"))?;
    Ok(RawCurve { degree, knots, points, weights })
}

fn model_error(location: String, message: &str) -> Error {
    Error::Model { location, message: message.into() }
}

/// Adds `n` control points to the running total and checks the file-wide limit.
fn count_points(total: &mut usize, n: usize, location: &str) -> Result<(), Error> {
    *total = total.saturating_add(n);
    if *total > MAX_TOTAL_POINTS {
        return Err(Error::Limit(format!(
            "{location}: the file holds more than {MAX_TOTAL_POINTS} control points in all"
        )));
    }
    Ok(())
}

fn build_face(index: usize, raw: RawFace, total: &mut usize) -> Result<Face, Error> {
    let at = format!("face {index}");
    let Some(surface) = raw.surface else {
        return Err(model_error(at, "the face has no surface"));
    };
    let surface = build_surface(&at, surface, total)?;
    if raw.loops.len() > MAX_LOOPS {
        return Err(Error::Limit(format!("{at} loops: {} loops; at most {MAX_LOOPS} are accepted", raw.loops.len())));
    }
    let [lo, hi] = crate::nurbs::Surface::domain(&surface);
    let range = (hi - lo).max_element();
    if !range.is_finite() {
        return Err(model_error(format!("{at} surface knots"), "the parameter range is too large"));
    }
    let mut loops = Vec::with_capacity(raw.loops.len());
    for (l, raw_loop) in raw.loops.into_iter().enumerate() {
        let at = format!("{at} loop {l}");
        let trim = build_loop(&at, raw_loop, total)?;
        check_closed(&at, &trim, range)?;
        loops.push(trim);
    }
    Ok(Face { name: raw.name, surface: FaceSurface::Nurbs(surface), loops })
}

fn build_surface(face: &str, raw: RawSurface, total: &mut usize) -> Result<NurbsSurface, Error> {
    let at = format!("{face} surface");
    let [p, q] = raw.degree[..] else {
        return Err(model_error(format!("{at} degree"), "expected two degrees [degree along u, degree along v]"));
    };
    let Ok([knots_u, knots_v]) = <[Vec<f64>; 2]>::try_from(raw.knots) else {
        return Err(model_error(format!("{at} knots"), "expected two knot vectors [knots along u, knots along v]"));
    };
    let count: usize = raw.points.iter().map(Vec::len).fold(0, usize::saturating_add);
    if count > MAX_SURFACE_POINTS {
        return Err(Error::Limit(format!(
            "{at} points: {count} control points; at most {MAX_SURFACE_POINTS} are accepted per surface"
        )));
    }
    count_points(total, count, &at)?;
    let nurbs = |field: &str, source: NurbsError| Error::Nurbs { location: format!("{at} {field}"), source };
    let ku = KnotVector::try_new(p, knots_u).map_err(|e| nurbs(knot_field(&e, 0), e))?;
    let kv = KnotVector::try_new(q, knots_v).map_err(|e| nurbs(knot_field(&e, 1), e))?;
    let mut points = Vec::with_capacity(raw.points.len());
    for (i, row) in raw.points.iter().enumerate() {
        let mut out = Vec::with_capacity(row.len());
        for (j, xyz) in row.iter().enumerate() {
            let &[x, y, z] = &xyz[..] else {
                return Err(Error::Model {
                    location: format!("{at} points[{i}][{j}]"),
                    message: format!("expected 3 coordinates (x, y, z), found {}", xyz.len()),
                });
            };
            out.push(DVec3::new(x, y, z));
        }
        points.push(out);
    }
    let nv = kv.control_count();
    NurbsSurface::from_parts(ku, kv, &points, raw.weights.as_deref()).map_err(|e| {
        let field = if is_weight_error(&e) { "weights" } else { "points" };
        // The surface counts points row by row; name the row and column.
        let field = match e {
            NurbsError::NotFinite { index, .. } | NurbsError::BadWeight { index, .. } if nv > 0 => {
                format!("{field}[{}][{}]", index / nv, index % nv)
            }
            _ => field.into(),
        };
        nurbs(&field, e)
    })
}

/// Field a knot vector error belongs to: the degree or the knots, `[0]` = u, `[1]` = v.
fn knot_field(e: &NurbsError, dir: usize) -> &'static str {
    match (e, dir) {
        (NurbsError::BadDegree { .. }, 0) => "degree[0]",
        (NurbsError::BadDegree { .. }, _) => "degree[1]",
        (_, 0) => "knots[0]",
        _ => "knots[1]",
    }
}

fn is_weight_error(e: &NurbsError) -> bool {
    match e {
        NurbsError::BadWeight { .. } | NurbsError::NotFinite { what: "weight", .. } => true,
        NurbsError::CountMismatch { what, .. } => what.starts_with("weight"),
        _ => false,
    }
}

fn build_loop(at: &str, raw: RawLoop, total: &mut usize) -> Result<TrimLoop, Error> {
    if raw.curves.is_empty() {
        return Err(model_error(format!("{at} curves"), "a loop needs at least one curve"));
    }
    if raw.curves.len() > MAX_CURVES {
        return Err(Error::Limit(format!(
            "{at} curves: {} curves; at most {MAX_CURVES} are accepted per loop",
            raw.curves.len()
        )));
    }
    let mut curves = Vec::with_capacity(raw.curves.len());
    for (c, curve) in raw.curves.into_iter().enumerate() {
        curves.push(build_curve(&format!("{at} curve {c}"), curve, total)?);
    }
    Ok(TrimLoop { curves })
}

fn build_curve(at: &str, raw: RawCurve, total: &mut usize) -> Result<NurbsCurve, Error> {
    if raw.points.len() > MAX_CURVE_POINTS {
        return Err(Error::Limit(format!(
            "{at} points: {} control points; at most {MAX_CURVE_POINTS} are accepted per curve",
            raw.points.len()
        )));
    }
    count_points(total, raw.points.len(), at)?;
    let mut points = Vec::with_capacity(raw.points.len());
    for (k, uv) in raw.points.iter().enumerate() {
        let &[u, v] = &uv[..] else {
            return Err(Error::Model {
                location: format!("{at} points[{k}]"),
                message: format!("expected 2 coordinates (u, v), found {}", uv.len()),
            });
        };
        points.push(DVec3::new(u, v, 0.0));
    }
    NurbsCurve::try_new(raw.degree, raw.knots, points, raw.weights).map_err(|e| {
        let field = match &e {
            NurbsError::BadDegree { .. } => "degree",
            NurbsError::TooFewKnots { .. }
            | NurbsError::DecreasingKnots { .. }
            | NurbsError::BadMultiplicity { .. }
            | NurbsError::NotFinite { what: "knot", .. } => "knots",
            e if is_weight_error(e) => "weights",
            _ => "points",
        };
        Error::Nurbs { location: format!("{at} {field}"), source: e }
    })
}

/// Checks that each curve ends where the next starts, and the last where the
/// first starts, within [`CLOSURE_TOLERANCE`] × the surface's parameter range.
fn check_closed(at: &str, trim: &TrimLoop, range: f64) -> Result<(), Error> {
    let allowed = CLOSURE_TOLERANCE * range;
    let n = trim.curves.len();
    for (c, curve) in trim.curves.iter().enumerate() {
        let next = (c + 1) % n;
        let end = curve.point(curve.domain().1).truncate();
        let start_curve = &trim.curves[next];
        let start = start_curve.point(start_curve.domain().0).truncate();
        let gap = end.distance(start);
        if gap > allowed {
            return Err(Error::Model {
                location: format!("{at} curve {c}"),
                message: format!(
                    "the loop does not close: curve {c} ends at {} but curve {next} starts at {} \
                     (gap {gap:.3e}, allowed {allowed:.3e})",
                    show(end),
                    show(start)
                ),
            });
        }
    }
    Ok(())
}

fn show(p: DVec2) -> String {
    format!("({}, {})", p.x, p.y)
}
