//! Moving the seam of a closed B-spline surface: a surface whose two
//! opposite edges coincide (a torus, a full revolution) can start its
//! parameter anywhere in the period. Trim loops that straddle the seam then
//! fit inside the domain without being cut.

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
    let size = s.bbox().diagonal().max(1e-300);
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
