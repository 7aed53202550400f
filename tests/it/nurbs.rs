//! Tests: nurbs (to be written).
