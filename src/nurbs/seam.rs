//! Moving the seam of a closed B-spline surface: a surface whose two
//! opposite edges coincide (a torus, a full revolution) can start its
//! parameter anywhere in the period. Trim loops that straddle the seam then
//! fit inside the domain without being cut.

use crate::numeric::TINY;
use alloc::vec::Vec;
use glam::{DVec3, DVec4};

use super::{KnotVector, NurbsSurface, Surface};

/// The closed surface `s` with its seam along u (`along_u`) or v moved to
/// parameter `c`: the part after `c` comes first, the part before it
/// follows, shifted by the period, so the domain becomes `[c, c + period]`.
/// `None` when `c` is not strictly inside the domain or the edges at the old
/// seam do not coincide (within `1e-7` of the surface's size).
pub fn rotate_seam(s: &NurbsSurface, along_u: bool, c: f64) -> Option<NurbsSurface> {
    let clamped = s.clamped(along_u);
    let s = &clamped;
    let (left, right) = s.split(along_u, c)?;
    let [lo, hi] = s.domain();
    let axis = usize::from(!along_u);
    let period = hi[axis] - lo[axis];
    let knots = |x: &NurbsSurface| if along_u { x.knots_u().clone() } else { x.knots_v().clone() };
    let (kl, kr) = (knots(&left), knots(&right));
    let p = kr.degree();
    let [nlu, nlv] = left.counts();
    let [nru, nrv] = right.counts();
    // Rows across the split direction: row k of a part along `axis`.
    let row = |x: &NurbsSurface, k: usize, n_other: usize| -> Vec<DVec4> {
        (0..n_other).map(|j| if along_u { x.homogeneous(k, j) } else { x.homogeneous(j, k) }).collect()
    };
    let (n_rows_l, n_other) = if along_u { (nlu, nlv) } else { (nlv, nlu) };
    let n_rows_r = if along_u { nru } else { nrv };
    // The right part's last row and the left part's first row are the old
    // seam: they must match up to one common weight factor.
    let end_r = row(&right, n_rows_r - 1, n_other);
    let start_l = row(&left, 0, n_other);
    let size = s.bbox().diagonal().max(TINY);
    let factor = end_r[0].w / start_l[0].w;
    for (a, b) in end_r.iter().zip(&start_l) {
        let (pa, pb) = (a.truncate() / a.w, b.truncate() / b.w);
        if pa.distance(pb) > 1e-7 * size || (a.w / b.w - factor).abs() > 1e-9 * factor.abs() {
            return None;
        }
    }
    let mut k: Vec<f64> = kr.knots()[..kr.knots().len() - 1].to_vec();
    k.extend(kl.knots()[p + 1..].iter().map(|&x| x + period));
    let kv = KnotVector::try_new(p, k).ok()?;
    let mut rows: Vec<Vec<DVec4>> = (0..n_rows_r).map(|r| row(&right, r, n_other)).collect();
    rows.extend((1..n_rows_l).map(|r| row(&left, r, n_other).into_iter().map(|h| h * factor).collect()));
    // Back to the grid `points[i][j]` (i along u) with weights.
    let (nu, nv) = if along_u { (rows.len(), n_other) } else { (n_other, rows.len()) };
    let mut pts = alloc::vec![alloc::vec![DVec3::ZERO; nv]; nu];
    let mut ws = alloc::vec![alloc::vec![1.0; nv]; nu];
    for (r, line) in rows.iter().enumerate() {
        for (j, h) in line.iter().enumerate() {
            let (i, jj) = if along_u { (r, j) } else { (j, r) };
            pts[i][jj] = h.truncate() / h.w;
            ws[i][jj] = h.w;
        }
    }
    let other = if along_u { s.knots_v().clone() } else { s.knots_u().clone() };
    let (ku, kv) = if along_u { (kv, other) } else { (other, kv) };
    NurbsSurface::from_parts(ku, kv, &pts, s.is_rational().then_some(ws.as_slice())).ok()
}

/// Most copies of a period [`unroll`] joins: a face wraps round a few times
/// at most (a thread), and a hostile file must not make it build more.
const MAX_TURNS: f64 = 8.0;

/// The closed surface `s` unrolled along u (`along_u`) or v over `[a, b]`,
/// which may span more than one period: copies of the surface, each shifted
/// by its period, joined where the seam was (C0 there), then cut to
/// `[a, b]`. For a face that wraps further round than one turn (a helical
/// strip, a cut that weaves round a wavy border). `None` when the edges at
/// the seam do not coincide or the range is empty or spans too many turns.
pub fn unroll(s: &NurbsSurface, along_u: bool, a: f64, b: f64) -> Option<NurbsSurface> {
    let s = s.clamped(along_u);
    let [lo, hi] = s.domain();
    let axis = usize::from(!along_u);
    let period = hi[axis] - lo[axis];
    if !(b > a && period > 0.0 && (b - a) / period <= MAX_TURNS) {
        return None;
    }
    let n0 = crate::math::floor((a - lo[axis]) / period);
    let n1 = crate::math::ceil((b - lo[axis]) / period);
    let copies = (n1 - n0) as usize;
    let kv = if along_u { s.knots_u().clone() } else { s.knots_v().clone() };
    let p = kv.degree();
    let [nu, nv] = s.counts();
    let (n_rows, n_other) = if along_u { (nu, nv) } else { (nv, nu) };
    let row = |k: usize| -> Vec<DVec4> {
        (0..n_other).map(|j| if along_u { s.homogeneous(k, j) } else { s.homogeneous(j, k) }).collect()
    };
    // The last row must be the first up to one common weight factor.
    let (first, last) = (row(0), row(n_rows - 1));
    let size = s.bbox().diagonal().max(TINY);
    let factor = last[0].w / first[0].w;
    for (x, y) in last.iter().zip(&first) {
        let (px, py) = (x.truncate() / x.w, y.truncate() / y.w);
        if px.distance(py) > 1e-7 * size || (x.w / y.w - factor).abs() > 1e-9 * factor.abs() {
            return None;
        }
    }
    let k = kv.knots();
    let mut knots: Vec<f64> = Vec::with_capacity(copies * k.len());
    let mut rows: Vec<Vec<DVec4>> = Vec::with_capacity(copies * n_rows);
    for c in 0..copies {
        let shift = (n0 + c as f64) * period;
        let from = if c == 0 { 0 } else { p + 1 };
        let to = if c + 1 == copies { k.len() } else { k.len() - 1 };
        knots.extend(k[from..to].iter().map(|&x| x + shift));
        let scale = libm::pow(factor, c as f64);
        for r in usize::from(c > 0)..n_rows {
            rows.push(row(r).into_iter().map(|h| h * scale).collect());
        }
    }
    let kn = KnotVector::try_new(p, knots).ok()?;
    let (nu2, nv2) = if along_u { (rows.len(), n_other) } else { (n_other, rows.len()) };
    let mut pts = alloc::vec![alloc::vec![DVec3::ZERO; nv2]; nu2];
    let mut ws = alloc::vec![alloc::vec![1.0; nv2]; nu2];
    for (r, line) in rows.iter().enumerate() {
        for (j, h) in line.iter().enumerate() {
            let (i, jj) = if along_u { (r, j) } else { (j, r) };
            pts[i][jj] = h.truncate() / h.w;
            ws[i][jj] = h.w;
        }
    }
    let other = if along_u { s.knots_v().clone() } else { s.knots_u().clone() };
    let (ku, kv2) = if along_u { (kn, other) } else { (other, kn) };
    let mut out = NurbsSurface::from_parts(ku, kv2, &pts, s.is_rational().then_some(ws.as_slice())).ok()?;
    let tiny = 1e-12 * period;
    let [dlo, dhi] = out.domain();
    if a > dlo[axis] + tiny {
        out = out.split(along_u, a)?.1;
    }
    if b < dhi[axis] - tiny {
        out = out.split(along_u, b)?.0;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::analytic::{line, revolve};
    use crate::nurbs::Surface;
    use glam::DVec2;

    /// A closed cylinder of radius 2 (angle along v), unrolled over one and a
    /// half turns starting at angle 1: the same points at every angle modulo
    /// the turn, over exactly the range asked for.
    #[test]
    fn unrolled_surface_repeats_its_period() {
        let profile = line(DVec3::new(2.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 3.0), 0.0, 1.0).unwrap();
        let tau = core::f64::consts::TAU;
        let s = revolve(&profile, DVec3::ZERO, DVec3::Z, 0.0, tau).unwrap();
        let (a, b) = (1.0, 1.0 + 1.5 * tau);
        let u = unroll(&s, false, a, b).unwrap();
        let [lo, hi] = u.domain();
        assert!((lo.y - a).abs() < 1e-12 && (hi.y - b).abs() < 1e-12, "{lo} {hi}");
        for i in 0..=60 {
            let t = a + (b - a) * i as f64 / 60.0;
            for h in [0.0, 0.4, 1.0] {
                let p = u.point(DVec2::new(h, t));
                let q = s.point(DVec2::new(h, t.rem_euclid(tau)));
                assert!(p.distance(q) < 1e-9, "at {t}: {p} vs {q}");
            }
        }
        assert!(unroll(&s, false, 0.0, 20.0 * tau).is_none(), "too many turns");
        assert!(unroll(&s, false, 2.0, 1.0).is_none(), "empty range");
        // One period is the seam moved.
        let r = unroll(&s, false, 1.0, 1.0 + tau).unwrap();
        let m = rotate_seam(&s, false, 1.0).unwrap();
        for i in 0..=20 {
            let uv = DVec2::new(0.5, 1.0 + tau * i as f64 / 20.0);
            assert!(r.point(uv).distance(m.point(uv)) < 1e-9);
        }
    }
}
