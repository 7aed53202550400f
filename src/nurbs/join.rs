//! Joining curve pieces that meet end to start into one curve (for surfaces
//! built on a composite curve: a ruled surface, a tabulated cylinder).

use alloc::vec::Vec;

use super::elevate::elevate;
use super::reparam::RawCurve;
use super::{NurbsCurve, NurbsError};

/// One curve through `pieces` in order: all raised to the highest degree,
/// piece `k` mapped to the parameters `[k, k + 1]`, ends joined with knots
/// of full multiplicity (the joins keep whatever corners they had). Each
/// piece's start is taken as the previous piece's end, so small gaps close.
///
/// # Errors
/// No pieces, or a degree above the maximum.
pub fn join(pieces: &[NurbsCurve]) -> Result<NurbsCurve, NurbsError> {
    let Some(first) = pieces.first() else {
        return Err(NurbsError::TooFewKnots { found: 0, needed: 1 });
    };
    if pieces.len() == 1 {
        return Ok(first.clone());
    }
    let p = pieces.iter().map(NurbsCurve::degree).max().unwrap_or(1);
    let mut knots: Vec<f64> = alloc::vec![0.0; p + 1];
    let mut points = Vec::new();
    let mut rational = false;
    for (k, c) in pieces.iter().enumerate() {
        let mut r = RawCurve::of(&elevate(c, p)?);
        r.clamp();
        r.reparametrize(k as f64, (k + 1) as f64);
        rational |= r.rational;
        // Keep the weights' scale continuous: scale the piece's homogeneous
        // points so its first weight equals the previous piece's last.
        let skip = usize::from(k > 0);
        if let (Some(prev), Some(head)) = (points.last().copied(), r.points.first().copied()) {
            let prev: glam::DVec4 = prev;
            if head.w > 0.0 {
                let f = prev.w / head.w;
                for h in &mut r.points {
                    *h *= f;
                }
            }
        }
        points.extend_from_slice(&r.points[skip..]);
        let n = r.knots.len() - p - 1;
        knots.extend_from_slice(&r.knots[p + 1..n]);
        let end = (k + 1) as f64;
        let reps = if k + 1 == pieces.len() { p + 1 } else { p };
        knots.extend(core::iter::repeat_n(end, reps));
    }
    RawCurve { degree: p, knots, points, rational }.build()
}
