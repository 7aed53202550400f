//! The curve net: every edge of the polygon net becomes a cubic Bézier curve
//! that leaves each end point in that point's tangent plane (paper 004 §3).

use glam::DVec3;

use super::bezier::Cubic;

/// The cubic of edge `PQ` by the paper's tangent-plane construction
/// (paper 004 §3, eqs. 1–2): with `R` the projection of `Q` on `P`'s tangent
/// plane, `R = Q + ((P − Q)·n)n`, and `h = |R − Q|`,
/// `V1 = V0 + (1/3 + (h/9)/|R − P|)(R − P)`; `V2` likewise from `Q`'s plane.
/// `None` when `Q` lies on `P`'s normal line (or `P` on `Q`'s): the edge has
/// no direction in the tangent plane.
pub(crate) fn edge_curve(p: DVec3, np: DVec3, q: DVec3, nq: DVec3) -> Option<Cubic> {
    let v1 = inner_point(p, np, q)?;
    let v2 = inner_point(q, nq, p)?;
    Some([p, v1, v2, q])
}

/// `V1` of the edge from `p` (unit normal `n`) towards `q`.
fn inner_point(p: DVec3, n: DVec3, q: DVec3) -> Option<DVec3> {
    let r = q + n * (p - q).dot(n);
    let h = (r - q).length();
    let rp = r - p;
    let len = rp.length();
    // A direction shorter than 1e-9 of the chord is no direction.
    if !(len > 1e-9 * (q - p).length()) {
        return None;
    }
    let v = p + rp * (1.0 / 3.0 + (h / 9.0) / len);
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edge_on_a_circle_follows_the_arc() {
        // Two points of the unit circle 60 degrees apart, normals radial.
        let a = 1.0f64.atan2(1.0) * 4.0 / 3.0;
        let p = DVec3::new(1.0, 0.0, 0.0);
        let q = DVec3::new(a.cos(), a.sin(), 0.0);
        let c = edge_curve(p, p, q, q).unwrap();
        // Leaves p along the tangent (0, 1, 0) and q along q's tangent.
        assert!((c[1] - p).normalize().dot(DVec3::Y) > 1.0 - 1e-12);
        assert!((c[2] - q).dot(q).abs() < 1e-12);
        // The midpoint lies near the circle: within 1 % of the radius (the
        // construction's handles are 4 % short of a circle's at 60 degrees).
        let mid = super::super::bezier::cubic_point(&c, 0.5);
        assert!((mid.length() - 1.0).abs() < 1e-2, "{}", mid.length());
        // Q straight above P on P's normal: no tangent direction.
        assert!(edge_curve(p, p, p * 2.0, DVec3::Y).is_none());
    }
}
