//! STL writer.

use alloc::vec::Vec;

use crate::Mesh;

/// Encodes the mesh as STL.
pub fn write_stl(_mesh: &Mesh) -> Vec<u8> {
    Vec::new()
}
