//! IGES writer (5.3, fixed 80-column ASCII form): the surfaces of a
//! [`Model`] back out as geometry, as paper 001 does with its rebuilt
//! surfaces, so they can be meshed or repaired by other programs.
//!
//! Each untrimmed face is a rational B-spline surface (entity 128). A trimmed
//! face is a trimmed surface (144) over its 128: every loop becomes a curve on
//! the surface (142) whose parameter-space curve is a composite curve (102)
//! of the loop's B-spline curves (126, z = 0). The loop of largest (u,v) area
//! is written as the outer boundary and the others as holes, as the mesher
//! decides. Numbers are written with 17 significant digits, so a file read
//! back gives the same geometry to the last bit.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use crate::model::{Face, FaceSurface};
use crate::nurbs::{NurbsCurve, NurbsSurface, Surface};
use crate::Model;

/// One entity: type, form, status and its parameters (numbers and pointers,
/// written as given; a pointer is the 0-based index of an earlier entity,
/// resolved to its directory line when the file is assembled).
struct Entity {
    kind: u32,
    form: u32,
    status: &'static str,
    params: Vec<Param>,
}

enum Param {
    Int(i64),
    Real(f64),
    Ptr(usize),
}

/// Status numbers (blank, subordinate, use, hierarchy): independent
/// geometry, physically dependent geometry, physically dependent parameter-space geometry.
const INDEPENDENT: &str = "00000000";
const DEPENDENT: &str = "00010000";
const DEPENDENT_2D: &str = "00010500";

/// Writes the faces of `model` as IGES 5.3: one 128 per untrimmed face, one
/// 144 over 128 / 142 / 102 / 126 per trimmed face. Offset surfaces (which
/// have no 128 form) are written as their base surface with a warning line
/// in the Start section.
pub fn write_iges(model: &Model) -> Vec<u8> {
    let mut entities: Vec<Entity> = Vec::new();
    let mut notes: Vec<String> = Vec::new();
    for (index, face) in model.faces.iter().enumerate() {
        let surface = match &face.surface {
            FaceSurface::Nurbs(s) | FaceSurface::Rebuilt(s) => s,
            FaceSurface::Offset { .. } => {
                notes.push(format!("face {index}: an offset surface, written as its base surface"));
                base_nurbs(&face.surface)
            }
        };
        write_face(face, surface, &mut entities);
    }
    assemble(model, &entities, &notes)
}

/// The B-spline surface under any offsets.
fn base_nurbs(s: &FaceSurface) -> &NurbsSurface {
    let mut s = s;
    loop {
        match s {
            FaceSurface::Nurbs(n) | FaceSurface::Rebuilt(n) => return n,
            FaceSurface::Offset { base, .. } => s = base,
        }
    }
}

fn write_face(face: &Face, surface: &NurbsSurface, out: &mut Vec<Entity>) {
    let trimmed = !face.loops.is_empty();
    let srf = out.len();
    out.push(surface_entity(surface, if trimmed { DEPENDENT } else { INDEPENDENT }));
    if !trimmed {
        return;
    }
    // Outer loop first: the largest (u,v) area.
    let mut order: Vec<(f64, usize)> =
        face.loops.iter().enumerate().map(|(i, lp)| (loop_area(&lp.curves).abs(), i)).collect();
    crate::sort::by_f64_desc(&mut order, |o| o.0);
    let mut boundaries = Vec::with_capacity(order.len());
    for &(_, li) in &order {
        let Some(lp) = face.loops.get(li) else { continue };
        let mut parts = Vec::with_capacity(lp.curves.len());
        for c in &lp.curves {
            parts.push(out.len());
            out.push(curve_entity(c, DEPENDENT_2D));
        }
        let composite = out.len();
        let mut params = alloc::vec![Param::Int(parts.len() as i64)];
        params.extend(parts.into_iter().map(Param::Ptr));
        out.push(Entity { kind: 102, form: 0, status: DEPENDENT_2D, params });
        let on_surface = out.len();
        // 142: created unspecified, the surface, the (u,v) curve, no model-space curve, prefer (u,v).
        let params = alloc::vec![Param::Int(0), Param::Ptr(srf), Param::Ptr(composite), Param::Int(0), Param::Int(1)];
        out.push(Entity { kind: 142, form: 0, status: DEPENDENT, params });
        boundaries.push(on_surface);
    }
    let Some((&outer, inner)) = boundaries.split_first() else { return };
    let mut params = alloc::vec![Param::Ptr(srf), Param::Int(1), Param::Int(inner.len() as i64), Param::Ptr(outer)];
    params.extend(inner.iter().map(|&b| Param::Ptr(b)));
    out.push(Entity { kind: 144, form: 0, status: INDEPENDENT, params });
}

/// Signed area of a loop's (u,v) polyline, 16 points per curve.
fn loop_area(curves: &[NurbsCurve]) -> f64 {
    let mut pts = Vec::new();
    for c in curves {
        let (a, b) = c.domain();
        pts.extend((0..16).map(|k| c.point(a + (b - a) * k as f64 / 16.0).truncate()));
    }
    let n = pts.len();
    (0..n).map(|i| pts[i].perp_dot(pts[(i + 1) % n])).sum::<f64>() * 0.5
}

/// Entity 128: indices, degrees, flags (not closed, rational or not, not
/// periodic), knots, weights and points with u running fastest, parameter range.
fn surface_entity(s: &NurbsSurface, status: &'static str) -> Entity {
    let [nu, nv] = s.counts();
    let [pu, pv] = s.degree();
    let [lo, hi] = s.domain();
    let rational = s.is_rational();
    let mut p = Vec::with_capacity(16 + 4 * nu * nv);
    for v in [nu as i64 - 1, nv as i64 - 1, pu as i64, pv as i64, 0, 0, i64::from(!rational), 0, 0] {
        p.push(Param::Int(v));
    }
    p.extend(s.knots_u().knots().iter().map(|&k| Param::Real(k)));
    p.extend(s.knots_v().knots().iter().map(|&k| Param::Real(k)));
    let hom = |i: usize, j: usize| s.homogeneous(i, j);
    for j in 0..nv {
        for i in 0..nu {
            p.push(Param::Real(hom(i, j).w));
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let h = hom(i, j);
            let q = h.truncate() / h.w;
            p.extend([Param::Real(q.x), Param::Real(q.y), Param::Real(q.z)]);
        }
    }
    p.extend([Param::Real(lo.x), Param::Real(hi.x), Param::Real(lo.y), Param::Real(hi.y)]);
    Entity { kind: 128, form: 0, status, params: p }
}

/// Entity 126 of a parameter-space curve: planar in z = 0, not closed,
/// rational or not, not periodic; knots, weights, points, range, normal +z.
fn curve_entity(c: &NurbsCurve, status: &'static str) -> Entity {
    let hom = c.homogeneous_points();
    let (a, b) = c.domain();
    let mut p = Vec::with_capacity(16 + 4 * hom.len());
    for v in [hom.len() as i64 - 1, c.degree() as i64, 1, 0, i64::from(!c.is_rational()), 0] {
        p.push(Param::Int(v));
    }
    p.extend(c.knots().knots().iter().map(|&k| Param::Real(k)));
    p.extend(hom.iter().map(|h| Param::Real(h.w)));
    for h in hom {
        let q = h.truncate() / h.w;
        p.extend([Param::Real(q.x), Param::Real(q.y), Param::Real(0.0)]);
    }
    p.extend([Param::Real(a), Param::Real(b), Param::Real(0.0), Param::Real(0.0), Param::Real(1.0)]);
    Entity { kind: 126, form: 0, status, params: p }
}

/// An IGES real: 17 significant digits, exponent form with a decimal point.
fn real(x: f64) -> String {
    let x = if x.is_finite() { x } else { 0.0 };
    let s = format!("{x:.16E}");
    // "1.0000000000000000E0": trim trailing zeros of the mantissa, keep one digit after the point.
    match s.split_once('E') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0');
            let m = if m.ends_with('.') { format!("{m}0") } else { String::from(m) };
            format!("{m}E{e}")
        }
        None => s,
    }
}

/// `nH...`
fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// IGES unit flag and name for the model's unit name (3 = named, for others).
fn units(name: &str) -> (i64, String) {
    let flag = match name.to_ascii_lowercase().as_str() {
        "in" | "inch" | "inches" => 1,
        "mm" | "millimeter" | "millimetre" => 2,
        "ft" | "foot" | "feet" => 4,
        "mi" | "mile" => 5,
        "m" | "meter" | "metre" => 6,
        "km" | "kilometer" => 7,
        "mil" => 8,
        "um" | "micron" => 9,
        "cm" | "centimeter" => 10,
        "uin" | "microinch" => 11,
        _ => 3,
    };
    let canonical = match flag {
        1 => "INCH",
        2 => "MM",
        4 => "FT",
        5 => "MI",
        6 => "M",
        7 => "KM",
        8 => "MIL",
        9 => "UM",
        10 => "CM",
        11 => "UIN",
        _ => name,
    };
    (flag, String::from(canonical))
}

/// Fills `lines` with `tokens` joined by `,` and ended by `;`, at most
/// `width` columns each, a token never split.
fn pack(tokens: &[String], width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for (i, t) in tokens.iter().enumerate() {
        let piece = format!("{t}{}", if i + 1 == tokens.len() { ';' } else { ',' });
        if !line.is_empty() && line.len() + piece.len() > width {
            lines.push(core::mem::take(&mut line));
        }
        line.push_str(&piece);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// One 80-column record: `body` padded to 72 columns, the section letter, the sequence number.
fn record(out: &mut String, body: &str, letter: char, seq: usize) {
    out.push_str(&format!("{body:<72}{letter}{seq:>7}\n"));
}

fn assemble(model: &Model, entities: &[Entity], notes: &[String]) -> Vec<u8> {
    let mut out = String::new();
    let mut start = alloc::vec![String::from("surfmesh: surfaces of the model as IGES 5.3")];
    start.extend(notes.iter().cloned());
    for (i, s) in start.iter().enumerate() {
        let s: String = s.chars().filter(char::is_ascii).take(72).collect();
        record(&mut out, &s, 'S', i + 1);
    }
    // Global section.
    let (flag, unit) = units(&model.units);
    let resolution = model.tolerance.filter(|t| *t > 0.0 && t.is_finite()).unwrap_or(1e-6);
    let max_coord = model.control_bbox();
    let max_coord =
        if max_coord.is_empty() { 1.0 } else { max_coord.min.abs().max(max_coord.max.abs()).max_element().max(1.0) };
    let global: Vec<String> = alloc::vec![
        hollerith(","),
        hollerith(";"),
        hollerith("surfmesh"),
        hollerith("surfmesh.igs"),
        hollerith("surfmesh"),
        hollerith(env!("CARGO_PKG_VERSION")),
        String::from("32"),
        String::from("38"),
        String::from("6"),
        String::from("308"),
        String::from("15"),
        hollerith("surfmesh"),
        real(1.0),
        format!("{flag}"),
        hollerith(&unit),
        String::from("1"),
        real(1.0),
        hollerith("20000101.000000"),
        real(resolution),
        real(max_coord),
        hollerith(""),
        hollerith(""),
        String::from("11"),
        String::from("0"),
        hollerith("20000101.000000"),
    ];
    // An empty Hollerith string is written as no value.
    let global: Vec<String> = global.into_iter().map(|g| if g == "0H" { String::new() } else { g }).collect();
    let global_lines = pack(&global, 72);
    for (i, l) in global_lines.iter().enumerate() {
        record(&mut out, l, 'G', i + 1);
    }
    // Parameter lines first (the directory needs their positions), pointers
    // resolved to directory lines: entity k sits at line 2k + 1.
    let mut param_lines: Vec<(String, usize)> = Vec::new();
    let mut first_line = Vec::with_capacity(entities.len());
    for (k, e) in entities.iter().enumerate() {
        let mut tokens = alloc::vec![format!("{}", e.kind)];
        tokens.extend(e.params.iter().map(|p| match p {
            Param::Int(i) => format!("{i}"),
            Param::Real(x) => real(*x),
            Param::Ptr(j) => format!("{}", 2 * j + 1),
        }));
        first_line.push(param_lines.len() + 1);
        for l in pack(&tokens, 64) {
            param_lines.push((l, 2 * k + 1));
        }
    }
    for (k, e) in entities.iter().enumerate() {
        let count = first_line.get(k + 1).copied().unwrap_or(param_lines.len() + 1) - first_line[k];
        let line1 =
            format!("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}", e.kind, first_line[k], 0, 0, 0, 0, 0, 0, e.status);
        let line2 =
            format!("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}", e.kind, 0, 0, count, e.form, "", "", "", 0);
        record(&mut out, &line1, 'D', 2 * k + 1);
        record(&mut out, &line2, 'D', 2 * k + 2);
    }
    for (i, (l, de)) in param_lines.iter().enumerate() {
        let body = format!("{l:<64} {de:>7}");
        record(&mut out, &body, 'P', i + 1);
    }
    let t = format!("S{:>7}G{:>7}D{:>7}P{:>7}", start.len(), global_lines.len(), 2 * entities.len(), param_lines.len());
    record(&mut out, &t, 'T', 1);
    out.into_bytes()
}
