//! GLB writer.

use alloc::vec::Vec;

use crate::Mesh;

/// Encodes the mesh as GLB.
pub fn write_glb(_mesh: &Mesh) -> Vec<u8> {
    Vec::new()
}
