//! What refinement holds a triangle to ([`Criteria`]), what it reports
//! ([`Outcome`]), and the 12-byte cache of each triangle's measure.

use super::TriMeasure;

/// A normal turn past a right angle inside one triangle: the surface folds
/// back there or is within the tolerance of a sharp edge (see
/// [`Criteria::short_for_angle`]).
pub(crate) const FOLD_TURN: f64 = core::f64::consts::FRAC_PI_2;

/// Limits a triangle must meet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Criteria {
    pub tol: f64,
    pub angle: f64,
    pub max_edge: f64,
    pub min_edge: f64,
    pub steps: usize,
    /// Beyond the limits: needles an auto rebuild mends with its spare
    /// triangles (the CDT's faces only, so read with `std` alone).
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub lift: Lift,
}

/// The smallest angle a lift aims at and the triangles the face may reach
/// doing it (none when `goal` is 0); see `refine/lift.rs`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Lift {
    /// Radians.
    pub goal: f64,
    pub most: usize,
}

impl Lift {
    /// No lift.
    pub const NONE: Lift = Lift { goal: 0.0, most: 0 };
}

#[cfg(test)]
impl Criteria {
    /// The limits unit tests hold their faces on a plane to.
    pub const PLANE_TEST: Criteria =
        Criteria { tol: 0.1, angle: 0.5, max_edge: f64::INFINITY, min_edge: 0.0, steps: 4, lift: Lift::NONE };
}

impl Criteria {
    /// Whether a triangle that fails only the angle limit is too short to
    /// split for it: across a fold or crease of the surface the normal turns
    /// by up to 180° however small the triangle, and splitting down to
    /// `min_edge` there only breeds millions of triangles (a folded patch
    /// took 3.9M triangles and two minutes). Detail a tenth of the tolerance
    /// wide cannot be seen within the tolerance anyway. Where the normal
    /// turns past a right angle within the tolerance, the surface folds back
    /// on itself (a pleat) or bends tighter than a radius of 0.64× the
    /// tolerance: within the tolerance of a sharp edge, so splitting stops
    /// there at the tolerance's length. `len` is the longest edge, `width`
    /// how wide the triangle is across its turn (at most `len`): a long
    /// sliver turning across a curl narrower than a tenth of the tolerance
    /// sits on a crease as much as a short triangle does.
    pub fn short_for_angle(&self, m: &TriMeasure, turn: f64, len: f64, width: f64) -> bool {
        m.max <= self.tol
            && len <= self.max_edge
            && turn > self.angle
            && (len.min(width) <= 0.1 * self.tol || (turn > FOLD_TURN && len <= self.tol))
    }
}

/// Per-triangle results after refinement.
#[derive(Debug, Default)]
pub(crate) struct Outcome {
    /// Largest measured distance over the triangles.
    pub max: f64,
    /// Sum and number of the distance samples, for the mean.
    pub sum: f64,
    pub count: u64,
    /// Largest normal turn across a triangle.
    pub max_turn: f64,
    /// Triangles left failing because the budget ran out or their edges hit `min_edge`.
    pub unproven: usize,
    /// Triangles within the tolerance that turn more than the angle limit but
    /// are too short to split for it ([`Criteria::short_for_angle`]).
    pub creased: usize,
}

/// A triangle's cached measure in 12 bytes: the largest distance and the
/// normal turn rounded up to `f32` (a cached triangle never looks better than
/// it measured, and the report never understates), the distance sum to the
/// nearest. Every face's cache is held until the model is assembled.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Packed {
    pub(super) max: f32,
    sum: f32,
    turn: f32,
}

/// A measure cache slot to be filled: a measured largest distance is never
/// NaN (it starts at 0 and `f64::max` passes over NaN samples).
pub(super) const STALE: Packed = Packed { max: f32::NAN, sum: 0.0, turn: 0.0 };

/// The least `f32` not below `x`.
fn up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) >= x || y.is_nan() {
        return y;
    }
    // The next f32 towards +inf (`f32::next_up` is newer than the MSRV).
    if y == 0.0 {
        f32::from_bits(1)
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() + 1)
    } else {
        f32::from_bits(y.to_bits() - 1)
    }
}

impl Packed {
    pub(super) fn pack(m: TriMeasure, turn: f64) -> Self {
        Self { max: up(m.max), sum: m.sum as f32, turn: up(turn) }
    }

    /// The largest `f32` below the packed largest distance: the measured one
    /// lies above it (packing rounds up).
    pub(super) fn max_above(self) -> f64 {
        f64::from(if self.max > 0.0 { f32::from_bits(self.max.to_bits() - 1) } else { 0.0 })
    }

    pub(super) fn unpack(self) -> (TriMeasure, f64) {
        (TriMeasure { max: f64::from(self.max), sum: f64::from(self.sum) }, f64::from(self.turn))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn within(c: &Criteria) -> TriMeasure {
        TriMeasure { max: 0.5 * c.tol, sum: 0.0 }
    }

    /// A triangle within the tolerance that fails only the angle limit is
    /// split down to a tenth of the tolerance where the normal turns less
    /// than a right angle (a tight fillet still gets its shading), but only
    /// down to the tolerance where it turns past one (a fold or pleat, whose
    /// turn no split lowers).
    #[test]
    fn folds_stop_at_the_tolerance_bends_at_a_tenth() {
        let c = Criteria::PLANE_TEST;
        let m = within(&c);
        let (bend, fold) = (1.0, 2.5);
        let short = |m: &TriMeasure, turn: f64, len: f64| c.short_for_angle(m, turn, len, len);
        assert!(!short(&m, bend, 0.5 * c.tol));
        assert!(short(&m, bend, 0.09 * c.tol));
        assert!(short(&m, fold, 0.5 * c.tol));
        assert!(!short(&m, fold, 1.5 * c.tol));
        // Over the tolerance or within the angle limit: not a crease at all.
        assert!(!short(&TriMeasure { max: 2.0 * c.tol, sum: 0.0 }, fold, 0.5 * c.tol));
        assert!(!short(&m, 0.4, 0.05 * c.tol));
        // A long sliver turning across a narrow width is a crease too.
        assert!(c.short_for_angle(&m, bend, 5.0 * c.tol, 0.09 * c.tol));
        assert!(!c.short_for_angle(&m, bend, 5.0 * c.tol, 0.2 * c.tol));
    }
}
