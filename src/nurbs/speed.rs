//! How fast a B-spline moves with its parameter, bounded from its control
//! points: what lets sewing rule out a curve piece without searching it.

use glam::{DVec3, DVec4};

use super::knots::KnotVector;

/// Per coordinate, a bound of the first derivative along `knots` of the
/// rational B-spline whose homogeneous control points are `points[i *
/// stride + j]`, `i` along `knots`; `j` runs across (the other direction
/// of a surface, whose basis spans `width` points at a time; a curve has
/// `stride` = `width` = 1). `None` for a non-positive or non-finite weight.
///
/// On a knot span `s` the derivative is a weighted mean, over the
/// derivative's basis, of `p / (k[i+p+1] - k[i+1]) · (w_{i+1}(P_{i+1} - C) -
/// w_i(P_i - C))` divided by the weight `w(t)`; each such difference is at
/// most `w_{i+1}·|P_{i+1} - P_i| + |w_{i+1} - w_i|·D`, with `D` the extent of
/// the block of points the span's basis reaches (C lies in their hull),
/// and `w(t)` at least the block's least weight. The bound is the largest
/// over all spans and all windows across; exact for a non-rational piece.
pub(crate) fn speed_bound(knots: &KnotVector, points: &[DVec4], stride: usize, width: usize) -> Option<DVec3> {
    let p = knots.degree();
    let k = knots.knots();
    let n = knots.control_count();
    if width == 0 || width > stride || points.len() != n * stride {
        return None;
    }
    if points.iter().any(|h| h.w <= 0.0 || !h.is_finite()) {
        return None;
    }
    let euclid = |h: DVec4| h.truncate() / h.w;
    let mut bound = DVec3::ZERO;
    for s in p..n {
        if k[s + 1] <= k[s] {
            continue;
        }
        for j0 in 0..=stride - width {
            let (mut lo, mut hi, mut w_min) = (DVec3::INFINITY, DVec3::NEG_INFINITY, f64::INFINITY);
            for i in s - p..=s {
                for j in j0..j0 + width {
                    let h = points[i * stride + j];
                    let e = euclid(h);
                    (lo, hi, w_min) = (lo.min(e), hi.max(e), w_min.min(h.w));
                }
            }
            let extent = hi - lo;
            let mut most = DVec3::ZERO;
            for i in s - p..s {
                // k[i+p+1] - k[i+1] spans k[s]..k[s+1]: never zero here.
                let c = p as f64 / (k[i + p + 1] - k[i + 1]);
                for j in j0..j0 + width {
                    let (a, b) = (points[i * stride + j], points[(i + 1) * stride + j]);
                    let step = (euclid(b) - euclid(a)).abs() * b.w + extent * (b.w - a.w).abs();
                    most = most.max(step * c);
                }
            }
            bound = bound.max(most / w_min);
        }
    }
    bound.is_finite().then_some(bound)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::{NurbsCurve, NurbsSurface, Surface};
    use alloc::vec;
    use alloc::vec::Vec;
    use glam::DVec2;

    /// The largest derivative seen on a dense sample, by central differences.
    fn sampled_speed(f: &dyn Fn(f64) -> DVec3, t0: f64, t1: f64) -> DVec3 {
        let n = 2000;
        let h = (t1 - t0) * 1e-6;
        (1..n).fold(DVec3::ZERO, |m, i| {
            let t = t0 + (t1 - t0) * i as f64 / n as f64;
            m.max(((f(t + h) - f(t - h)) / (2.0 * h)).abs())
        })
    }

    #[test]
    fn a_rational_circle_moves_no_faster_than_its_bound() {
        let w = core::f64::consts::FRAC_1_SQRT_2;
        let pts = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)];
        let weights = [1.0, w, 1.0, w, 1.0];
        let points: Vec<DVec3> = pts.iter().map(|&(x, y)| DVec3::new(3.0 * x, 3.0 * y, 0.0)).collect();
        let c = NurbsCurve::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0], points, Some(weights.to_vec()))
            .expect("circle");
        let bound = c.derivative_bound().expect("positive weights");
        let seen = sampled_speed(&|t| c.point(t), 0.0, 1.0);
        assert!(seen.cmple(bound).all(), "seen {seen} bound {bound}");
        // Not uselessly loose: within a few times the true speed.
        assert!(bound.max_element() < 4.0 * seen.max_element(), "seen {seen} bound {bound}");
    }

    #[test]
    fn a_plane_has_its_exact_speed() {
        let s = NurbsSurface::try_new(
            [1, 1],
            vec![0.0, 0.0, 2.0, 2.0],
            vec![0.0, 0.0, 1.0, 1.0],
            &[vec![DVec3::ZERO, DVec3::new(0.0, 5.0, 0.0)], vec![DVec3::new(8.0, 0.0, 0.0), DVec3::new(8.0, 5.0, 0.0)]],
            None,
        )
        .expect("plane");
        let [bu, bv] = s.derivative_bounds().expect("non-rational");
        assert!((bu - 4.0).abs() < 1e-12 && (bv - 5.0).abs() < 1e-12, "{bu} {bv}");
    }

    #[test]
    fn a_cylinder_moves_no_faster_than_its_bounds() {
        let w = core::f64::consts::FRAC_1_SQRT_2;
        let ring = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)];
        let weights = [1.0, w, 1.0, w, 1.0];
        let net: Vec<Vec<DVec3>> = ring
            .iter()
            .map(|&(x, y)| vec![DVec3::new(2.0 * x, 2.0 * y, 0.0), DVec3::new(2.0 * x, 2.0 * y, 7.0)])
            .collect();
        let wn: Vec<Vec<f64>> = weights.iter().map(|&w| vec![w, w]).collect();
        let s = NurbsSurface::try_new(
            [2, 1],
            vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            &net,
            Some(&wn),
        )
        .expect("cylinder");
        let [bu, bv] = s.derivative_bounds().expect("positive weights");
        for v in [0.0, 0.3, 1.0] {
            let su = sampled_speed(&|u| s.point(DVec2::new(u, v)), 0.0, 1.0);
            assert!(su.length() <= bu, "{su} {bu}");
        }
        for u in [0.0, 0.2, 0.5, 0.9] {
            let sv = sampled_speed(&|v| s.point(DVec2::new(u, v)), 0.0, 1.0);
            assert!(sv.length() <= bv, "{sv} {bv}");
        }
    }
}
