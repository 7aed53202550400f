//! Test shapes (to be written).
