//! One n-sided polygon of the curve net filled by n quartic triangular Bézier
//! sub-patches meeting at a centre, G¹ inside the polygon and G¹ with the
//! neighbouring polygons (paper 004 §4).
//!
//! Sub-patch `S_i` has corners `Z_i, Z_i+1, O` and, row by row from its net
//! edge (see [`super::bezier::index`]):
//!
//! ```text
//! row 0   Z_i  A_i  X_i  C_i  Z_i+1     boundary: the degree-elevated edge cubic (eq. 3)
//! row 1   E_i  B_i  D_i  E_i+1          tangent points (eqs. 8, 9)
//! row 2   M_i  L_i  M_i+1               inner points (eqs. 10, 15)
//! row 3   N_i  N_i+1                    inner points (the shrunk projected polygon)
//! row 4   O                             centre (eq. 13)
//! ```
//!
//! The spoke `Z_i … O` (points `Z_i, E_i, M_i, N_i, O`) is shared by `S_i−1`
//! and `S_i`. Farin's condition makes them meet G¹: the four pairs of
//! control-net triangles along the spoke, (`E_i C_i−1 Z_i`, `E_i A_i Z_i`),
//! (`M_i D_i−1 E_i`, `M_i B_i E_i`), (`N_i L_i−1 M_i`, `N_i L_i M_i`) and
//! (`O N_i−1 N_i`, `O N_i+1 N_i`), are each coplanar with the area ratio of
//! the projected polygon's triangles `G Z'_i−1 Z'_i`, `G Z'_i Z'_i+1`. In
//! affine form, with `c_i = α_i a_i + β_i b_i` (eqs. 5, 6) and `s_k` the
//! spoke's points, `s_k+1 = s_k + α_i (p_k − s_k) + β_i (q_k − s_k)` where
//! `p_k` is the point of `S_i−1` and `q_k` that of `S_i` beside the pair.

use alloc::vec;
use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::bezier::{elevate, index, Cubic, TriPatch, POINTS};
use super::linalg::frame;

/// Why a polygon could not be filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PatchError {
    /// Fewer than 3 corners, or inputs of different lengths.
    Shape,
    /// The polygon projected on its plane is not strictly convex.
    NotConvex,
    /// An edge curve leaves a corner along that corner's normal.
    Tangent,
    /// An even polygon whose centre conditions cannot be met (see [`fill_polygon`]).
    EvenClosure,
    /// The corners turn clockwise about their normals.
    Flipped,
    /// A non-finite control point.
    NotFinite,
}

/// The projected polygon of paper 004 §4.1 (eqs. 4–6): centre `G`, the plane
/// through it, corner coordinates `d_i = Z'_i − G` in that plane, and the
/// weights `α_i, β_i` with `c_i = α_i a_i + β_i b_i`.
pub(crate) struct Projected {
    /// `G = Σ Z_i / n` (eq. 4).
    pub centre: DVec3,
    /// Unit plane normal (Newell's normal of the corners: it passes close to
    /// every corner and points to the side from which the corners run
    /// counter-clockwise).
    pub normal: DVec3,
    /// In-plane unit axes.
    pub axes: (DVec3, DVec3),
    /// `Z'_i − G` in the plane's axes.
    pub d: Vec<DVec2>,
    /// `α_i`, the weight of `a_i = Z'_i−1 − Z'_i`.
    pub alpha: Vec<f64>,
    /// `β_i`, the weight of `b_i = Z'_i+1 − Z'_i`.
    pub beta: Vec<f64>,
}

fn cross2(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Projects the corners on their plane (paper 004 §4.1) and checks that the
/// projected polygon is strictly convex with every interior angle at most
/// `max_angle` radians (the paper's merge rule keeps them under π; the
/// weights grow without bound as an angle nears π).
pub(crate) fn project(z: &[DVec3], max_angle: f64) -> Result<Projected, PatchError> {
    let n = z.len();
    if n < 3 {
        return Err(PatchError::Shape);
    }
    let centre = z.iter().copied().sum::<DVec3>() / n as f64;
    let mut newell = DVec3::ZERO;
    for i in 0..n {
        newell += (z[i] - centre).cross(z[(i + 1) % n] - centre);
    }
    let normal = newell.normalize_or_zero();
    if normal == DVec3::ZERO {
        return Err(PatchError::NotConvex);
    }
    let axes = frame(normal);
    let d: Vec<DVec2> = z.iter().map(|p| DVec2::new((*p - centre).dot(axes.0), (*p - centre).dot(axes.1))).collect();
    let cos_max = libm::cos(max_angle);
    let (mut alpha, mut beta) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let a = d[(i + n - 1) % n] - d[i];
        let b = d[(i + 1) % n] - d[i];
        let c = -d[i];
        let ba = cross2(b, a);
        // Interior angle from b round to a, counter-clockwise: convex when sin > 0 and cos above cos(max).
        let cos = a.dot(b) / (a.length() * b.length());
        if !(ba > 0.0) || !(cos > cos_max) {
            return Err(PatchError::NotConvex);
        }
        alpha[i] = cross2(b, c) / ba;
        beta[i] = cross2(c, a) / ba;
        if !(alpha[i] > 0.0 && beta[i] > 0.0) {
            return Err(PatchError::NotConvex);
        }
    }
    Ok(Projected { centre, normal, axes, d, alpha, beta })
}

/// Fills one polygon: corners `z` (counter-clockwise seen from the side the
/// `normals` point to), unit corner normals, and `edges[i]` the cubic from
/// `z[i]` to `z[i+1]`. Returns the `n` sub-patches `S_0 … S_n−1`.
///
/// Built as paper 004 §4 builds them:
/// - boundary points by degree elevation (eq. 3);
/// - `E_i` from the projected polygon's weights (eq. 8), which puts the pair
///   (`E_i C_i−1 Z_i`, `E_i A_i Z_i`) in `Z_i`'s tangent plane with ratio `α_i/β_i`;
/// - `B_i, D_i` by Shin's tangent-ribbon condition (eq. 9): along the edge the
///   cross-boundary derivative `4 Σ a_j B³_j(t)`, `a_j = r_1j − r_0j` (rows 1
///   and 0), is `4 (p(t) T(t) + q(t) C(t))` with `T` the linear blend of
///   `t0 = c0 × n0 / |…|` and `t2 = c2 × n1 / |…|`, `C = Σ c_j B²_j` a third
///   of the edge's derivative and `p, q` linear, fitted to the end
///   differences `a_0 = E_i − Z_i` and `a_3 = E_i+1 − C_i` (both in their
///   corner's tangent plane); so `B_i = A_i + a_1`, `D_i = X_i + a_2`.
///   The polygon on the edge's other side builds the same `T` and `C` (up to
///   sign), so the two meet G¹;
/// - `M_i` by the same weights from `D_i−1, B_i` (eq. 10);
/// - `O` as the mean of the quadratic predictions `O'_i = 3Z_i + 6M_i − 8E_i`
///   (eqs. 12, 13), and `N_i = O + λ (Z'_i − G)`: the projected polygon
///   shrunk by `λ`, the mean of `|O'_i − N'_i| / |Z'_i − G|` with
///   `N'_i = Z_i + 3(M_i − E_i)` (eq. 11), which makes the pairs
///   (`O N_i−1 N_i`, `O N_i+1 N_i`) coplanar with ratio `α_i/β_i`;
/// - `L_i` from the cyclic system `α_i L_i−1 + β_i L_i = N_i − (1 − α_i − β_i) M_i`
///   (eqs. 14, 15: `Q_i` on `M_i N_i` divides `L_i−1 L_i` as the weights say).
///
/// The system for `L` has determinant `Π β_i − (−1)^n Π α_i`, and since
/// `α_i / β_i` is the area ratio `A_i+1 / A_i` of consecutive centre
/// triangles, `Π α_i = Π β_i`: for odd n it is regular; for even n it is
/// singular for every polygon (the paper's "easily obtained" does not hold),
/// and solvable only when `Σ y_i (N_i − γ_i M_i) = 0` for its left null
/// vector `y`. The project's decision: move `O` and the linear map of the
/// shrunk polygon (`N_i = O + F d_i`, which keeps the centre pairs coplanar
/// with the same ratios) by the least change, measured over `O` and the
/// `N_i`, that meets this condition, then take of the one-parameter family
/// of solutions the `L` nearest to the linear-precision guess
/// `(M_i + M_i+1) / 2`. [`PatchError::EvenClosure`] when no change of `O`
/// and `F` can meet it.
pub(crate) fn fill_polygon(
    z: &[DVec3],
    normals: &[DVec3],
    edges: &[Cubic],
    max_angle: f64,
) -> Result<Vec<TriPatch>, PatchError> {
    let n = z.len();
    if n < 3 || normals.len() != n || edges.len() != n {
        return Err(PatchError::Shape);
    }
    let proj = project(z, max_angle)?;
    // The corners must run counter-clockwise about their own normals, or the
    // sub-patches would face against the neighbours'.
    if normals.iter().any(|n| !(n.dot(proj.normal) > 0.0)) {
        return Err(PatchError::Flipped);
    }
    let (alpha, beta) = (&proj.alpha, &proj.beta);
    let prev = |i: usize| (i + n - 1) % n;
    let next = |i: usize| (i + 1) % n;

    // Boundary control points (eq. 3).
    let elev: Vec<[DVec3; 5]> = edges.iter().map(elevate).collect();
    let a_pt = |i: usize| elev[i][1];
    let c_pt = |i: usize| elev[i][3];

    // E_i (eq. 8).
    let e: Vec<DVec3> = (0..n).map(|i| z[i] + (c_pt(prev(i)) - z[i]) * alpha[i] + (a_pt(i) - z[i]) * beta[i]).collect();

    // B_i, D_i (eq. 9).
    let (mut b, mut d) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    for i in 0..n {
        let ed = &edges[i];
        let c = [ed[1] - ed[0], ed[2] - ed[1], ed[3] - ed[2]];
        let t0 = c[0].cross(normals[i]).normalize_or_zero();
        let t2 = c[2].cross(normals[next(i)]).normalize_or_zero();
        if t0 == DVec3::ZERO || t2 == DVec3::ZERO {
            return Err(PatchError::Tangent);
        }
        let t1 = (t0 + t2) * 0.5;
        let (p0, q0) = ribbon_weights(t0, c[0], e[i] - z[i]).ok_or(PatchError::Tangent)?;
        let (p1, q1) = ribbon_weights(t2, c[2], e[next(i)] - c_pt(i)).ok_or(PatchError::Tangent)?;
        b[i] = a_pt(i) + ((t1 * p0 + c[1] * q0) * 2.0 + (t0 * p1 + c[0] * q1)) / 3.0;
        d[i] = elev[i][2] + ((t2 * p0 + c[2] * q0) + (t1 * p1 + c[1] * q1) * 2.0) / 3.0;
    }

    // M_i (eq. 10).
    let m: Vec<DVec3> = (0..n).map(|i| e[i] + (d[prev(i)] - e[i]) * alpha[i] + (b[i] - e[i]) * beta[i]).collect();

    // O and the shrunk polygon (eqs. 11–13).
    let o_pred: Vec<DVec3> = (0..n).map(|i| z[i] * 3.0 + m[i] * 6.0 - e[i] * 8.0).collect();
    let n_pred: Vec<DVec3> = (0..n).map(|i| z[i] + (m[i] - e[i]) * 3.0).collect();
    let mut o = o_pred.iter().copied().sum::<DVec3>() / n as f64;
    let lambda = (0..n).map(|i| (o_pred[i] - n_pred[i]).length() / proj.d[i].length()).sum::<f64>() / n as f64;
    let mut fu = proj.axes.0 * lambda;
    let mut fv = proj.axes.1 * lambda;

    let gamma: Vec<f64> = (0..n).map(|i| 1.0 - alpha[i] - beta[i]).collect();
    let l_guess: Vec<DVec3> = (0..n).map(|i| (m[i] + m[next(i)]) * 0.5).collect();
    if n % 2 == 0 {
        close_even(&proj, &gamma, &m, &mut o, &mut fu, &mut fv)?;
    }
    let nn: Vec<DVec3> = (0..n).map(|i| o + fu * proj.d[i].x + fv * proj.d[i].y).collect();
    let rhs: Vec<DVec3> = (0..n).map(|i| nn[i] - m[i] * gamma[i]).collect();
    let l = solve_cyclic(alpha, beta, &rhs, &l_guess);

    let mut patches = Vec::with_capacity(n);
    for i in 0..n {
        let j = next(i);
        let mut points = [DVec3::ZERO; POINTS];
        for (col, p) in elev[i].iter().enumerate() {
            points[index(col, 0)] = *p;
        }
        points[index(0, 1)] = e[i];
        points[index(1, 1)] = b[i];
        points[index(2, 1)] = d[i];
        points[index(3, 1)] = e[j];
        points[index(0, 2)] = m[i];
        points[index(1, 2)] = l[i];
        points[index(2, 2)] = m[j];
        points[index(0, 3)] = nn[i];
        points[index(1, 3)] = nn[j];
        points[index(0, 4)] = o;
        if !points.iter().all(|p| p.is_finite()) {
            return Err(PatchError::NotFinite);
        }
        patches.push(TriPatch { points });
    }
    Ok(patches)
}

/// `(p, q)` with `a = p t + q c` in the least-squares sense (the paper's 2 × 2
/// normal equations under eq. 9); exact when `a` lies in the plane of `t, c`,
/// as `E_i − Z_i` lies in `Z_i`'s tangent plane.
fn ribbon_weights(t: DVec3, c: DVec3, a: DVec3) -> Option<(f64, f64)> {
    let (tt, tc, cc) = (t.dot(t), t.dot(c), c.dot(c));
    let det = tt * cc - tc * tc;
    if !(det > 1e-24 * tt * cc) {
        return None;
    }
    let (ta, ca) = (t.dot(a), c.dot(a));
    Some(((ta * cc - ca * tc) / det, (tt * ca - tc * ta) / det))
}

/// Even `n`: moves `O` and the map `F = (fu, fv)` of `N_i = O + F d_i` by
/// the least change (of `O` and the `N_i`, in the squared sum) for which the
/// singular system of `L` is consistent. See [`fill_polygon`].
fn close_even(
    proj: &Projected,
    gamma: &[f64],
    m: &[DVec3],
    o: &mut DVec3,
    fu: &mut DVec3,
    fv: &mut DVec3,
) -> Result<(), PatchError> {
    let (alpha, beta, d, g) = (&proj.alpha, &proj.beta, &proj.d, proj.centre);
    let n = d.len();
    // Left null vector: y_j β_j + y_j+1 α_j+1 = 0.
    let mut y = vec![1.0; n];
    for j in 0..n - 1 {
        y[j + 1] = -y[j] * beta[j] / alpha[j + 1];
    }
    let ymax = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    y.iter_mut().for_each(|v| *v /= ymax);
    let sigma: f64 = y.iter().sum();
    let delta: DVec2 = (0..n).map(|i| d[i] * y[i]).sum();
    // Residual of the consistency condition for the current O, F, in
    // coordinates about G (exact since Σ y_i (1 − γ_i) = 0 by linear precision).
    let mut r = DVec3::ZERO;
    for i in 0..n {
        r += ((*o - g) + *fu * d[i].x + *fv * d[i].y - (m[i] - g) * gamma[i]) * y[i];
    }
    let radius = d.iter().fold(0.0f64, |a, v| a.max(v.length()));
    if r.length() <= CLOSURE_NEGLIGIBLE * radius {
        return Ok(());
    }
    // Weights: |ΔO|² + Σ|ΔN_i|² = (n+1)|Δo|² + Σ (Δf·d_i)² (Σ d_i = 0).
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for di in d.iter() {
        sxx += di.x * di.x;
        sxy += di.x * di.y;
        syy += di.y * di.y;
    }
    let det = sxx * syy - sxy * sxy;
    if !(det > 0.0) {
        return Err(PatchError::EvenClosure);
    }
    let sinv_delta = DVec2::new((syy * delta.x - sxy * delta.y) / det, (sxx * delta.y - sxy * delta.x) / det);
    let w0 = n as f64 + 1.0;
    let denom = sigma * sigma / w0 + delta.dot(sinv_delta);
    if !(denom > 0.0) {
        return Err(PatchError::EvenClosure);
    }
    // x = −r W⁻¹ g / (gᵀ W⁻¹ g), per coordinate.
    let d_o = r * (-sigma / w0 / denom);
    let d_fu = r * (-sinv_delta.x / denom);
    let d_fv = r * (-sinv_delta.y / denom);
    let change = d_o.length() + (d_fu.length() + d_fv.length()) * radius;
    if !(change <= CLOSURE_MAX_MOVE * radius) {
        return Err(PatchError::EvenClosure);
    }
    *o += d_o;
    *fu += d_fu;
    *fv += d_fv;
    Ok(())
}

/// A closure residual below this fraction of the polygon's radius is rounding.
const CLOSURE_NEGLIGIBLE: f64 = 1e-13;
/// The largest move of the centre and the shrunk polygon (as a fraction of
/// the polygon's radius) the even closure may make; past it the polygon is
/// refused, and the polygon merge keeps its triangles apart instead.
const CLOSURE_MAX_MOVE: f64 = 0.5;

/// Solves `α_i L_i−1 + β_i L_i = rhs_i` (cyclic, `L_−1 = L_n−1`). Odd n: the
/// unique solution. Even n (singular, consistent after [`close_even`]): the
/// solution nearest to `guess`.
fn solve_cyclic(alpha: &[f64], beta: &[f64], rhs: &[DVec3], guess: &[DVec3]) -> Vec<DVec3> {
    let n = rhs.len();
    // L_i = u_i + v_i L_0 by forward substitution.
    let mut u = vec![DVec3::ZERO; n];
    let mut v = vec![0.0; n];
    v[0] = 1.0;
    for i in 1..n {
        u[i] = (rhs[i] - u[i - 1] * alpha[i]) / beta[i];
        v[i] = -alpha[i] * v[i - 1] / beta[i];
    }
    if n % 2 == 1 {
        let l0 = (rhs[0] - u[n - 1] * alpha[0]) / (alpha[0] * v[n - 1] + beta[0]);
        return (0..n).map(|i| u[i] + l0 * v[i]).collect();
    }
    // Even: every L_0 satisfies equations 1..n−1; equation 0 holds by consistency.
    // Least squares to the guess over L_0: min Σ |u_i + v_i L_0 − g_i|².
    let vv: f64 = v.iter().map(|x| x * x).sum();
    let l0 = (0..n).map(|i| (guess[i] - u[i]) * v[i]).sum::<DVec3>() / vv;
    (0..n).map(|i| u[i] + l0 * v[i]).collect()
}

#[cfg(test)]
mod tests;
