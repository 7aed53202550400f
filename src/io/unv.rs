//! I-DEAS universal file (UNV) writer: the node and element datasets that
//! finite-element pre-processors read (paper 001's pipeline exports UNV).
//!
//! Layout, from the universal dataset descriptions (fixed columns, one
//! record a line; every dataset starts and ends with a line holding `-1` in
//! columns 1-6 and has its number in columns 1-6 of its second line):
//!
//! ```text
//!     -1
//!   2411                                Nodes - Double Precision
//! Record 1  FORMAT(4I10)      node label, export coordinate system,
//!                             displacement coordinate system, colour
//! Record 2  FORMAT(1P3D25.16) x, y, z
//!     -1
//!     -1
//!   2412                                Elements
//! Record 1  FORMAT(6I10)      element label, FE descriptor id (91 = thin
//!                             shell linear triangle), physical property
//!                             table, material property table, colour,
//!                             number of nodes (3)
//! Record 2  FORMAT(8I10)      node labels
//!     -1
//! ```

use alloc::string::String;
use alloc::vec::Vec;
use core::fmt::Write;

use super::msh::shared_nodes;
use crate::Mesh;

/// FE descriptor id of a thin shell linear triangle.
pub const UNV_SHELL_TRIANGLE: u32 = 91;

/// Encodes the mesh as a universal file: dataset 2411 (nodes, double
/// precision; vertices at identical positions are one node, labels from 1)
/// and dataset 2412 (one thin-shell linear triangle, descriptor 91, per
/// triangle, labels from 1). The physical property table number of an
/// element is its model face number + 1, so a pre-processor can group
/// elements by face; coordinate systems are 1 (global) and colours 11 / 7.
pub fn write_unv(mesh: &Mesh) -> Vec<u8> {
    let shared = shared_nodes(mesh);
    let mut s = String::with_capacity(110 * shared.positions.len() + 90 * mesh.triangle_count() + 64);
    // Writing into a String cannot fail; the `fmt::Result`s are ignored below.
    let _ = writeln!(s, "{:>6}\n{:>6}", -1, 2411);
    for (i, p) in shared.positions.iter().enumerate() {
        let _ = writeln!(s, "{:>10}{:>10}{:>10}{:>10}", i + 1, 1, 1, 11);
        let _ = writeln!(s, "{:>25}{:>25}{:>25}", fortran_d(p.x), fortran_d(p.y), fortran_d(p.z));
    }
    let _ = writeln!(s, "{:>6}\n{:>6}\n{:>6}", -1, -1, 2412);
    let mut label = 1u64;
    for (face, tris) in shared.faces.iter().enumerate() {
        for t in tris {
            let _ = writeln!(s, "{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}", label, UNV_SHELL_TRIANGLE, face + 1, 1, 7, 3);
            let _ = writeln!(s, "{:>10}{:>10}{:>10}", t[0] + 1, t[1] + 1, t[2] + 1);
            label += 1;
        }
    }
    let _ = writeln!(s, "{:>6}", -1);
    s.into_bytes()
}

/// `x` as Fortran's `1PD25.16` writes it, before padding: one digit, the
/// point, 16 decimals, `D` and a signed two-digit exponent
/// (`-1.2500000000000000D+01`). Exponents of three digits drop the `D`
/// (`1.0000000000000000-100`), as Fortran does; non-finite values are written as 0.
pub(super) fn fortran_d(x: f64) -> String {
    let x = if x.is_finite() { x } else { 0.0 };
    let e = alloc::format!("{x:.16e}");
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let sign = if exp < 0 { '-' } else { '+' };
    if exp.abs() < 100 {
        alloc::format!("{mantissa}D{sign}{:02}", exp.abs())
    } else {
        alloc::format!("{mantissa}{sign}{:03}", exp.abs())
    }
}
