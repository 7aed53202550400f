//! OBJ writer.

use alloc::vec::Vec;

use crate::Mesh;

/// Encodes the mesh as OBJ.
pub fn write_obj(_mesh: &Mesh) -> Vec<u8> {
    Vec::new()
}
