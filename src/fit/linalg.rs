//! Small dense linear algebra for the point fit: the eigen-decomposition of a
//! symmetric 3 × 3 matrix (normals by principal components) and Gaussian
//! elimination for the small least-squares systems of the normal refinement.

use glam::DVec3;

/// Eigenvalues (ascending) and unit eigenvectors of the symmetric matrix `m`
/// (rows), by cyclic Jacobi rotations: unconditionally stable, and exact
/// enough for the covariance of a neighbourhood.
pub(crate) fn sym_eigen3(m: [[f64; 3]; 3]) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + crate::math::sqrt(theta * theta + 1.0));
            let c = 1.0 / crate::math::sqrt(t * t + 1.0);
            let s = t * c;
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for k in 0..3 {
                let (vkp, vkq) = (v[k][p], v[k][q]);
                v[k][p] = c * vkp - s * vkq;
                v[k][q] = s * vkp + c * vkq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    crate::sort::by_f64(&mut order, |&i| a[i][i]);
    let values = [a[order[0]][order[0]], a[order[1]][order[1]], a[order[2]][order[2]]];
    let vec = |c: usize| DVec3::new(v[0][c], v[1][c], v[2][c]).normalize_or_zero();
    (values, [vec(order[0]), vec(order[1]), vec(order[2])])
}

/// Covariance (about the mean) of `points`, and the mean.
pub(crate) fn covariance(points: impl Iterator<Item = DVec3> + Clone) -> ([[f64; 3]; 3], DVec3) {
    let mut n = 0usize;
    let mut mean = DVec3::ZERO;
    for p in points.clone() {
        mean += p;
        n += 1;
    }
    if n == 0 {
        return ([[0.0; 3]; 3], DVec3::ZERO);
    }
    mean /= n as f64;
    let mut c = [[0.0; 3]; 3];
    for p in points {
        let d = (p - mean).to_array();
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] += d[i] * d[j];
            }
        }
    }
    (c, mean)
}

/// Solves the `N × N` system `a x = b` in place by Gaussian elimination with
/// partial pivoting; `None` when a pivot falls below `1e-13` × the largest entry.
pub(crate) fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    for col in 0..N {
        let mut piv = col;
        for r in col + 1..N {
            if a[r][col].abs() > a[piv][col].abs() {
                piv = r;
            }
        }
        if a[piv][col].abs() <= 1e-13 * scale {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..N {
            let f = a[r][col] / a[col][col];
            for k in col..N {
                a[r][k] -= f * a[col][k];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for r in (0..N).rev() {
        let mut s = b[r];
        for k in r + 1..N {
            s -= a[r][k] * x[k];
        }
        x[r] = s / a[r][r];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Two unit vectors completing the unit vector `n` to a right-handed frame.
pub(crate) fn frame(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.6 {
        DVec3::X
    } else if n.y.abs() < 0.6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = helper.cross(n).normalize_or_zero();
    let v = n.cross(u);
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_a_rotated_diagonal_matrix() {
        // R diag(1, 4, 9) Rᵀ for a rotation about (1, 1, 1).
        let axis = DVec3::new(1.0, 1.0, 1.0).normalize();
        let r = glam::DMat3::from_axis_angle(axis, 0.7);
        let d = glam::DMat3::from_diagonal(DVec3::new(4.0, 1.0, 9.0));
        let m = r * d * r.transpose();
        let rows = [m.row(0).to_array(), m.row(1).to_array(), m.row(2).to_array()];
        let (vals, vecs) = sym_eigen3(rows);
        assert!((vals[0] - 1.0).abs() < 1e-12 && (vals[1] - 4.0).abs() < 1e-12 && (vals[2] - 9.0).abs() < 1e-12);
        assert!((vecs[0].dot(r.col(1))).abs() > 1.0 - 1e-12);
        assert!((vecs[2].dot(r.col(2))).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn solve_needs_pivoting_and_rejects_singular() {
        let x = solve([[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [2.0, 0.0, 3.0]], [7.0, 3.0, 11.0]).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14 && (x[2] - 3.0).abs() < 1e-14);
        assert!(solve([[1.0, 2.0], [2.0, 4.0]], [1.0, 2.0]).is_none());
    }
}
