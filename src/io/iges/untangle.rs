//! Removing the small self-crossings of a trim loop. Two edges of a face
//! that meet tangentially (a plane cutting a tube at a grazing angle) leave a
//! horn whose width is below the file's accuracy; once projected and fitted
//! the two sides of the horn may cross. Every crossing splits the loop into
//! two: the smaller part (by area in the parameter plane) is dropped and the
//! two curves are cut at the crossing point.

use alloc::vec::Vec;
use glam::DVec2;

use crate::numeric::TINY;
use crate::nurbs::reparam::{segment, with_end_points};
use crate::nurbs::NurbsCurve;

/// Rounds of crossing removal at most.
const MAX_ROUNDS: usize = 32;

/// One chord of the sampled loop.
#[derive(Debug, Clone, Copy)]
struct Chord {
    a: DVec2,
    b: DVec2,
    curve: usize,
    ta: f64,
    tb: f64,
}

/// The loop (closed chain of curves) without self-crossings; returns how
/// many crossings were removed.
pub(super) fn untangle(curves: &mut Vec<NurbsCurve>) -> usize {
    let mut removed = 0;
    for _ in 0..MAX_ROUNDS {
        let chords = sample(curves);
        let Some((i, j, x, si, sj)) = first_crossing(&chords) else { break };
        let (ci, ti) = (chords[i].curve, chords[i].ta + (chords[i].tb - chords[i].ta) * si);
        let (cj, tj) = (chords[j].curve, chords[j].ta + (chords[j].tb - chords[j].ta) * sj);
        // Area of the part between the crossings (chords i+1 ..= j) against the rest.
        let mut inner: Vec<DVec2> = alloc::vec![x];
        inner.extend(chords[i + 1..=j].iter().map(|c| c.a));
        let mut outer: Vec<DVec2> = alloc::vec![x];
        outer.extend(chords[j + 1..].iter().chain(&chords[..=i]).map(|c| c.a));
        let keep_outer = area(&outer).abs() >= area(&inner).abs();
        let Some(next) = (if keep_outer { cut(curves, cj, tj, ci, ti, x) } else { cut(curves, ci, ti, cj, tj, x) })
        else {
            break;
        };
        *curves = next;
        removed += 1;
    }
    removed
}

/// The loop that leaves curve `from` at `t_from` (through point `x`) and
/// continues forward to curve `to` at `t_to`, both cut there.
fn cut(curves: &[NurbsCurve], from: usize, t_from: f64, to: usize, t_to: f64, x: DVec2) -> Option<Vec<NurbsCurve>> {
    let n = curves.len();
    let x3 = x.extend(0.0);
    let mut out = Vec::new();
    // Start: the tail of `from` after t_from.
    let (_, fb) = curves[from].domain();
    if from == to && t_to > t_from {
        // The kept part lies inside one curve.
        let c = segment(&curves[from], t_from, t_to).ok()?;
        out.push(with_end_points(&c, x3, x3).ok()?);
        return Some(out);
    }
    if t_from < fb {
        let c = segment(&curves[from], t_from, fb).ok()?;
        let end = c.point(c.domain().1);
        out.push(with_end_points(&c, x3, end).ok()?);
    }
    let mut k = (from + 1) % n;
    let mut guard = 0;
    while k != to {
        out.push(curves[k].clone());
        k = (k + 1) % n;
        guard += 1;
        if guard > n {
            return None;
        }
    }
    let (ta, _) = curves[to].domain();
    if t_to > ta {
        let c = segment(&curves[to], ta, t_to).ok()?;
        let start = c.point(c.domain().0);
        out.push(with_end_points(&c, start, x3).ok()?);
    }
    // Degenerate results (a point) are no loop.
    (out.len() >= 2 || out.iter().any(|c| c.bbox().diagonal() > 0.0)).then_some(out)
}

/// Chords along every curve: 8 per knot span, at least 16, at most 1024.
fn sample(curves: &[NurbsCurve]) -> Vec<Chord> {
    let mut out = Vec::new();
    for (ci, c) in curves.iter().enumerate() {
        let (a, b) = c.domain();
        let spans = c.knots().breakpoints().len().saturating_sub(1);
        let n = (8 * spans).clamp(16, 1024);
        let mut prev = (a, c.point(a).truncate());
        for k in 1..=n {
            let t = a + (b - a) * k as f64 / n as f64;
            let p = c.point(t).truncate();
            out.push(Chord { a: prev.1, b: p, curve: ci, ta: prev.0, tb: t });
            prev = (t, p);
        }
    }
    out
}

/// The first pair of non-adjacent chords `i < j` that cross properly, with
/// the crossing point and its fractions along each chord.
fn first_crossing(chords: &[Chord]) -> Option<(usize, usize, DVec2, f64, f64)> {
    let n = chords.len();
    if n < 4 {
        return None;
    }
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for c in chords {
        lo = lo.min(c.a.min(c.b));
        hi = hi.max(c.a.max(c.b));
    }
    let cells = (libm::sqrt(n as f64) as usize).clamp(1, 256);
    let size = ((hi - lo) / cells as f64).max(DVec2::splat(TINY));
    let cell = |p: DVec2| {
        let c = ((p - lo) / size).floor();
        (c.x.clamp(0.0, (cells - 1) as f64) as usize, c.y.clamp(0.0, (cells - 1) as f64) as usize)
    };
    let mut grid: Vec<Vec<u32>> = alloc::vec![Vec::new(); cells * cells];
    for (k, c) in chords.iter().enumerate() {
        let (x0, y0) = cell(c.a.min(c.b));
        let (x1, y1) = cell(c.a.max(c.b));
        for x in x0..=x1 {
            for y in y0..=y1 {
                grid[y * cells + x].push(k as u32);
            }
        }
    }
    let mut best: Option<(usize, usize, DVec2, f64, f64)> = None;
    for bucket in &grid {
        for (u, &i) in bucket.iter().enumerate() {
            for &j in &bucket[u + 1..] {
                let (i, j) = (i.min(j) as usize, i.max(j) as usize);
                if j == i + 1 || (i == 0 && j == n - 1) {
                    continue;
                }
                if let Some((x, s, t)) = crossing(&chords[i], &chords[j]) {
                    if best.is_none_or(|b| (i, j) < (b.0, b.1)) {
                        best = Some((i, j, x, s, t));
                    }
                }
            }
        }
    }
    best
}

/// Proper crossing of two chords (strictly inside both).
fn crossing(p: &Chord, q: &Chord) -> Option<(DVec2, f64, f64)> {
    let r = p.b - p.a;
    let s = q.b - q.a;
    let den = r.perp_dot(s);
    if den == 0.0 {
        return None;
    }
    let d = q.a - p.a;
    let t = d.perp_dot(s) / den;
    let u = d.perp_dot(r) / den;
    (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0).then(|| (p.a + r * t, t, u))
}

fn area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() * 0.5
}
