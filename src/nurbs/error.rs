//! Errors raised while building NURBS geometry from user data.

use alloc::string::String;
use core::fmt;

/// Why a knot vector, curve or surface was rejected.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum NurbsError {
    /// Degree 0 or above the supported maximum.
    BadDegree {
        /// The degree given.
        degree: usize,
    },
    /// Fewer knots than `2 * (degree + 1)`.
    TooFewKnots {
        /// Knots given.
        found: usize,
        /// Knots needed at least.
        needed: usize,
    },
    /// A knot smaller than the one before it.
    DecreasingKnots {
        /// Index of the offending knot.
        index: usize,
    },
    /// A knot multiplicity above `degree + 1`, or an empty parameter range.
    BadMultiplicity {
        /// Index of the knot where the run ends.
        index: usize,
    },
    /// A knot, coordinate or weight that is NaN or infinite.
    NotFinite {
        /// Which value (`"knot"`, `"point"`, `"weight"`).
        what: &'static str,
        /// Index of the value.
        index: usize,
    },
    /// A weight that is zero or negative.
    BadWeight {
        /// Index of the weight.
        index: usize,
        /// The weight given.
        found: f64,
    },
    /// Number of control points (or weights) does not match the knot vector.
    CountMismatch {
        /// What was counted.
        what: String,
        /// How many were given.
        found: usize,
        /// How many the knot vector and degree need.
        expected: usize,
    },
}

impl fmt::Display for NurbsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadDegree { degree } => write!(f, "degree {degree} is not in 1..={}", super::MAX_DEGREE),
            Self::TooFewKnots { found, needed } => {
                write!(f, "knot vector too short: {found} knots, need at least {needed}")
            }
            Self::DecreasingKnots { index } => write!(f, "knots decrease at index {index}"),
            Self::BadMultiplicity { index } => {
                write!(f, "knot multiplicity above degree + 1 or empty parameter range at index {index}")
            }
            Self::NotFinite { what, index } => write!(f, "{what} {index} is not a finite number"),
            Self::BadWeight { index, found } => write!(f, "weight {index} is {found}; weights must be > 0"),
            Self::CountMismatch { what, found, expected } => {
                write!(f, "{what}: found {found}, expected {expected}")
            }
        }
    }
}

impl core::error::Error for NurbsError {}
