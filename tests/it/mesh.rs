//! Tests: mesh (to be written).
