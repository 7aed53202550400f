//! Global cubic B-spline interpolation with chord-length parameters and
//! averaged knots (paper 001 step 4): one banded system per direction,
//! factored once and solved for every row of points, never a dense n² matrix.

use alloc::vec;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use crate::nurbs::{KnotVector, NurbsCurve, NurbsSurface};

pub(crate) use crate::warning::InterpError;

/// A factored collocation system: degree, knots and the banded LU of
/// `N_i(t_k)` for the given parameters `t_k`.
pub(crate) struct Interp1 {
    knots: KnotVector,
    /// Rows of the band: `band[k][c]` is column `k - p + c`.
    band: Vec<Vec<f64>>,
    p: usize,
}

impl Interp1 {
    /// Factors the system for parameters `t` (strictly increasing, first 0,
    /// last 1) with degree `min(3, t.len() - 1)` and averaged knots
    /// `u_{j+p} = (t_j + … + t_{j+p-1}) / p` (de Boor's choice: the matrix is
    /// totally positive, so elimination without pivoting is stable).
    pub fn new(t: &[f64]) -> Result<Self, InterpError> {
        let n = t.len();
        if n < 2 {
            return Err(InterpError::TooFewPoints);
        }
        if t.windows(2).any(|w| !(w[1] > w[0] && w[1].is_finite())) {
            return Err(InterpError::Degenerate);
        }
        let p = (n - 1).min(3);
        let mut knots = vec![0.0; p + 1];
        for j in 1..n - p {
            let s: f64 = t[j..j + p].iter().sum();
            knots.push(s / p as f64);
        }
        knots.extend(core::iter::repeat_n(1.0, p + 1));
        let knots = KnotVector::try_new(p, knots).map_err(|_| InterpError::Degenerate)?;
        let mut band = vec![vec![0.0; 2 * p + 1]; n];
        let mut ders = [[0.0; 4]; 3];
        for (k, &tk) in t.iter().enumerate() {
            let span = knots.basis_into(tk, 0, &mut ders);
            for j in 0..=p {
                let col = span - p + j;
                // Column col sits at band index col + p - k (within 0..=2p for a banded matrix).
                let c = (col + p).checked_sub(k).filter(|&c| c <= 2 * p).ok_or(InterpError::Singular)?;
                band[k][c] = ders[0][j];
            }
        }
        // LU without pivoting, in place.
        for k in 0..n {
            let piv = band[k][p];
            if !(piv.abs() > 1e-14 && piv.is_finite()) {
                return Err(InterpError::Singular);
            }
            for i in k + 1..(k + p + 1).min(n) {
                let f = band[i][k + p - i] / piv;
                if f == 0.0 {
                    continue;
                }
                band[i][k + p - i] = f;
                for j in k + 1..(k + p + 1).min(n) {
                    let a = band[k][j + p - k];
                    band[i][j + p - i] -= f * a;
                }
            }
        }
        Ok(Self { knots, band, p })
    }

    /// The knot vector of the interpolant.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// Solves in place for control values: `rhs` holds one row of `width`
    /// values per parameter, and is overwritten with the control points.
    pub fn solve(&self, rhs: &mut [f64], width: usize) {
        let n = self.band.len();
        let p = self.p;
        if rhs.len() < n * width {
            return;
        }
        for i in 1..n {
            for k in i.saturating_sub(p)..i {
                let f = self.band[i][k + p - i];
                if f != 0.0 {
                    for w in 0..width {
                        rhs[i * width + w] -= f * rhs[k * width + w];
                    }
                }
            }
        }
        for i in (0..n).rev() {
            for j in i + 1..(i + p + 1).min(n) {
                let a = self.band[i][j + p - i];
                if a != 0.0 {
                    for w in 0..width {
                        rhs[i * width + w] -= a * rhs[j * width + w];
                    }
                }
            }
            let piv = self.band[i][p];
            for w in 0..width {
                rhs[i * width + w] /= piv;
            }
        }
    }
}

/// Normalized cumulative chord lengths of `points` (uniform when they all coincide).
pub(crate) fn chord_params(lengths: &[f64]) -> Vec<f64> {
    let total: f64 = lengths.iter().sum();
    let mut t = Vec::with_capacity(lengths.len() + 1);
    t.push(0.0);
    if !(total > 0.0 && total.is_finite()) {
        let n = lengths.len().max(1) as f64;
        t.extend((1..=lengths.len()).map(|i| i as f64 / n));
        return t;
    }
    let mut acc = 0.0;
    for l in lengths {
        acc += l;
        t.push(acc / total);
    }
    if let Some(last) = t.last_mut() {
        *last = 1.0;
    }
    t
}

/// Chord-length parameters averaged over several rows of points (rows
/// without length are left out; uniform when every row is degenerate).
pub(crate) fn averaged_params<'a>(rows: impl Iterator<Item = &'a [DVec3]>, count: usize) -> Vec<f64> {
    let mut sum = vec![0.0; count];
    let mut used = 0usize;
    for row in rows {
        let lengths: Vec<f64> = row.windows(2).map(|w| w[0].distance(w[1])).collect();
        let total: f64 = lengths.iter().sum();
        if row.len() != count || !(total > 0.0 && total.is_finite()) {
            continue;
        }
        for (s, t) in sum.iter_mut().zip(chord_params(&lengths)) {
            *s += t;
        }
        used += 1;
    }
    if used == 0 {
        let n = (count.max(2) - 1) as f64;
        return (0..count).map(|i| i as f64 / n).collect();
    }
    let mut t: Vec<f64> = sum.iter().map(|s| s / used as f64).collect();
    if let Some(first) = t.first_mut() {
        *first = 0.0;
    }
    if let Some(last) = t.last_mut() {
        *last = 1.0;
    }
    t
}

/// The bicubic (or lower degree, for few points) non-rational surface on
/// `[0,1]²` through `grid[i][j]` (i along u) at parameters `s[i]`, `t[j]`:
/// curves through each column first, then through the resulting control
/// points along the other direction (paper 001 step 4).
pub(crate) fn interpolate_surface(grid: &[Vec<DVec3>], s: &[f64], t: &[f64]) -> Result<NurbsSurface, InterpError> {
    let (nu, nv) = (s.len(), t.len());
    if grid.len() != nu || grid.iter().any(|r| r.len() != nv) {
        return Err(InterpError::TooFewPoints);
    }
    let iu = Interp1::new(s)?;
    let iv = Interp1::new(t)?;
    // Along u for every j: rhs rows indexed by i, width 3·nv.
    let width = 3 * nv;
    let mut rhs = vec![0.0; nu * width];
    for (i, row) in grid.iter().enumerate() {
        for (j, p) in row.iter().enumerate() {
            rhs[i * width + 3 * j..i * width + 3 * j + 3].copy_from_slice(&p.to_array());
        }
    }
    iu.solve(&mut rhs, width);
    // Along v for every i: transpose to rows indexed by j, width 3·nu.
    let width2 = 3 * nu;
    let mut rhs2 = vec![0.0; nv * width2];
    for i in 0..nu {
        for j in 0..nv {
            for c in 0..3 {
                rhs2[j * width2 + 3 * i + c] = rhs[i * width + 3 * j + c];
            }
        }
    }
    iv.solve(&mut rhs2, width2);
    let points: Vec<Vec<DVec3>> = (0..nu)
        .map(|i| {
            (0..nv)
                .map(|j| {
                    let k = j * width2 + 3 * i;
                    DVec3::new(rhs2[k], rhs2[k + 1], rhs2[k + 2])
                })
                .collect()
        })
        .collect();
    if points.iter().flatten().any(|p| !p.is_finite()) {
        return Err(InterpError::Singular);
    }
    NurbsSurface::from_parts(iu.knots().clone(), iv.knots().clone(), &points, None).map_err(|_| InterpError::Singular)
}

/// The cubic (or lower degree) parameter-space curve (z = 0) on `[0,1]`
/// through `points` at parameters `t`.
pub(crate) fn interpolate_curve(points: &[DVec2], t: &[f64]) -> Result<NurbsCurve, InterpError> {
    if points.len() != t.len() {
        return Err(InterpError::TooFewPoints);
    }
    let it = Interp1::new(t)?;
    let mut rhs: Vec<f64> = points.iter().flat_map(|p| [p.x, p.y]).collect();
    it.solve(&mut rhs, 2);
    let ctrl: Vec<DVec3> = rhs.chunks_exact(2).map(|c| DVec3::new(c[0], c[1], 0.0)).collect();
    if ctrl.iter().any(|p| !p.is_finite()) {
        return Err(InterpError::Singular);
    }
    NurbsCurve::try_new(it.knots().degree(), it.knots().knots().to_vec(), ctrl, None).map_err(|_| InterpError::Singular)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::Surface;

    #[test]
    fn curve_passes_through_its_points() {
        let pts: Vec<DVec2> = (0..12).map(|i| DVec2::new(i as f64, (i as f64 * 0.7).sin())).collect();
        let lengths: Vec<f64> = pts.windows(2).map(|w| w[0].distance(w[1])).collect();
        let t = chord_params(&lengths);
        let c = interpolate_curve(&pts, &t).unwrap();
        for (p, &tk) in pts.iter().zip(&t) {
            assert!(c.point(tk).truncate().distance(*p) < 1e-12, "at {tk}");
        }
        // Few points: lower degree, still through them.
        let c = interpolate_curve(&pts[..3], &[0.0, 0.4, 1.0]).unwrap();
        assert_eq!(c.degree(), 2);
        assert!(c.point(0.4).truncate().distance(pts[1]) < 1e-12);
    }

    #[test]
    fn surface_passes_through_its_grid_and_rejects_degenerate_parameters() {
        let f = |x: f64, y: f64| DVec3::new(x, y, (x * 1.3).sin() * (y * 0.8).cos());
        let xs: Vec<f64> = (0..9).map(|i| (i as f64 / 8.0).powi(2) * 4.0).collect();
        let ys: Vec<f64> = (0..7).map(|j| j as f64 * 0.5).collect();
        let grid: Vec<Vec<DVec3>> = xs.iter().map(|&x| ys.iter().map(|&y| f(x, y)).collect()).collect();
        let uniform = averaged_params(core::iter::empty(), xs.len());
        assert_eq!(uniform.len(), xs.len(), "no rows: uniform");
        assert!((uniform[4] - 0.5).abs() < 1e-15);
        let cols: Vec<Vec<DVec3>> = (0..ys.len()).map(|j| grid.iter().map(|r| r[j]).collect()).collect();
        let s = averaged_params(cols.iter().map(|c| c.as_slice()), xs.len());
        let t = averaged_params(grid.iter().map(|r| r.as_slice()), ys.len());
        let srf = interpolate_surface(&grid, &s, &t).unwrap();
        for (i, &si) in s.iter().enumerate() {
            for (j, &tj) in t.iter().enumerate() {
                let d = srf.point(DVec2::new(si, tj)).distance(grid[i][j]);
                assert!(d < 1e-12, "node {i},{j} off by {d}");
            }
        }
        assert_eq!(Interp1::new(&[0.0, 0.5, 0.5, 1.0]).err(), Some(InterpError::Degenerate));
        assert_eq!(Interp1::new(&[0.0]).err(), Some(InterpError::TooFewPoints));
    }
}
