//! Degree elevation and knot merging: bringing several curves to one degree
//! and one knot vector, as a ruled surface or a skin between them needs.
//! Both are exact (the curves keep their shape and parameterization).

use alloc::vec::Vec;
use glam::DVec4;

use super::reparam::RawCurve;
use super::{NurbsCurve, NurbsError, MAX_DEGREE};

/// `c` raised to `degree` (unchanged when its degree is already that high).
///
/// The curve is split into Bézier pieces at its knots, each piece is raised
/// by the Bernstein identity `Q_i = i/(p+1)·P_{i−1} + (1 − i/(p+1))·P_i`, and
/// the pieces are joined again with knots of multiplicity `degree`.
///
/// # Errors
/// A degree above [`MAX_DEGREE`].
pub fn elevate(c: &NurbsCurve, degree: usize) -> Result<NurbsCurve, NurbsError> {
    if degree <= c.degree() {
        return Ok(c.clone());
    }
    if degree > MAX_DEGREE {
        return Err(NurbsError::BadDegree { degree });
    }
    let mut r = RawCurve::of(c);
    r.clamp();
    let p = r.degree;
    let (a, b) = r.domain();
    let inner: Vec<f64> = {
        let mut v: Vec<f64> = r.knots.iter().copied().filter(|&k| k > a && k < b).collect();
        v.dedup();
        v
    };
    for &t in &inner {
        let m = r.knots.iter().filter(|&&k| k == t).count();
        for _ in m..p {
            r.insert(t);
        }
    }
    // Now r has Bézier pieces: piece s owns points s·p ..= s·p + p.
    let pieces = inner.len() + 1;
    let mut knots = Vec::with_capacity((pieces + 1) * (degree + 1));
    knots.extend(core::iter::repeat_n(a, degree + 1));
    for &t in &inner {
        knots.extend(core::iter::repeat_n(t, degree));
    }
    knots.extend(core::iter::repeat_n(b, degree + 1));
    let mut points: Vec<DVec4> = Vec::with_capacity(pieces * degree + 1);
    for s in 0..pieces {
        let Some(piece) = r.points.get(s * p..=s * p + p) else {
            return Err(NurbsError::CountMismatch { what: "Bézier pieces".into(), found: s, expected: pieces });
        };
        let mut cur: Vec<DVec4> = piece.to_vec();
        while cur.len() < degree + 1 {
            cur = elevate_bezier(&cur);
        }
        let skip = usize::from(s > 0);
        points.extend_from_slice(&cur[skip..]);
    }
    RawCurve { degree, knots, points, rational: r.rational }.build()
}

/// One degree up for a Bézier piece (homogeneous points).
fn elevate_bezier(p: &[DVec4]) -> Vec<DVec4> {
    let n = p.len(); // degree + 1
    let mut q = Vec::with_capacity(n + 1);
    q.push(p[0]);
    for i in 1..n {
        let a = i as f64 / n as f64;
        q.push(p[i - 1] * a + p[i] * (1.0 - a));
    }
    q.push(p[n - 1]);
    q
}

/// The curves brought to one degree (the highest), the domain `[0, 1]` and
/// one knot vector (each distinct knot at the largest multiplicity any curve has).
///
/// # Errors
/// A degree above [`MAX_DEGREE`] or an invalid input curve.
pub fn make_compatible(curves: &[NurbsCurve]) -> Result<Vec<NurbsCurve>, NurbsError> {
    let degree = curves.iter().map(NurbsCurve::degree).max().unwrap_or(1);
    let mut raws = Vec::with_capacity(curves.len());
    for c in curves {
        let mut r = RawCurve::of(&elevate(c, degree)?);
        r.clamp();
        r.reparametrize(0.0, 1.0);
        raws.push(r);
    }
    // Union of the inner knots, each at its largest multiplicity.
    let mut union: Vec<(f64, usize)> = Vec::new();
    for r in &raws {
        let mut i = degree + 1;
        let n = r.knots.len() - degree - 1;
        while i < n {
            let t = r.knots[i];
            let mut m = 1;
            while i + m < n && r.knots[i + m] == t {
                m += 1;
            }
            match union.iter_mut().find(|(v, _)| *v == t) {
                Some(e) => e.1 = e.1.max(m),
                None => union.push((t, m)),
            }
            i += m;
        }
    }
    let mut out = Vec::with_capacity(raws.len());
    for mut r in raws {
        for &(t, m) in &union {
            let have = r.knots.iter().filter(|&&k| k == t).count();
            for _ in have..m {
                r.insert(t);
            }
        }
        out.push(r.build()?);
    }
    Ok(out)
}
