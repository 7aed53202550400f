//! Transformation matrices (entity 124) and their chains through directory
//! field 7: an entity's geometry is mapped by its matrix, then by that
//! matrix's own matrix, and so on (depth-limited, so a cycle is an error).

use glam::{DAffine3, DMat3, DVec3};

use super::directory::Directory;
use super::MAX_DEPTH;
use crate::numeric::TINY;
use crate::Error;

/// The affine map of entity `de`'s own transformation chain (identity when it has none).
///
/// # Errors
/// A pointer that is not a 124 entity, a chain longer than [`MAX_DEPTH`]
/// (a cycle), or a singular or non-finite matrix.
pub(super) fn own_transform(dir: &Directory, de: usize) -> Result<DAffine3, Error> {
    let Some(e) = dir.get(de) else { return Ok(DAffine3::IDENTITY) };
    let mut at = e.xform;
    let mut total = DAffine3::IDENTITY;
    let mut depth = 0;
    while at != 0 {
        depth += 1;
        if depth > MAX_DEPTH {
            return Err(
                e.error(alloc::format!("transformation chain longer than {MAX_DEPTH} matrices (a reference cycle?)"))
            );
        }
        let m = dir
            .get(at)
            .filter(|m| m.kind == 124)
            .ok_or_else(|| e.error(alloc::format!("transformation pointer {at} does not name a 124 matrix entity")))?;
        if let Some(err) = &m.damage {
            return Err(err.clone());
        }
        let r = |i: usize| m.real(i);
        let mat = DMat3::from_cols(
            DVec3::new(r(1)?, r(5)?, r(9)?),
            DVec3::new(r(2)?, r(6)?, r(10)?),
            DVec3::new(r(3)?, r(7)?, r(11)?),
        );
        let t = DVec3::new(r(4)?, r(8)?, r(12)?);
        let det = mat.determinant();
        if !(det.is_finite() && det.abs() > TINY && t.is_finite()) {
            return Err(m.error("transformation matrix is singular or not finite"));
        }
        // The chain applies this matrix first, then the ones it points to.
        total = DAffine3::from_mat3_translation(mat, t) * total;
        at = m.xform;
    }
    Ok(total)
}

/// Whether `a` is a similarity (rotation, reflection and uniform scale):
/// returns the scale factor.
pub(super) fn similarity_scale(a: &DAffine3) -> Option<f64> {
    let m = a.matrix3;
    let (x, y, z) = (m.x_axis, m.y_axis, m.z_axis);
    let s = x.length();
    let tol = 1e-9 * s.max(TINY);
    let ok = (y.length() - s).abs() <= tol
        && (z.length() - s).abs() <= tol
        && x.dot(y).abs() <= tol * s
        && y.dot(z).abs() <= tol * s
        && z.dot(x).abs() <= tol * s;
    (ok && s > 0.0 && s.is_finite()).then_some(s)
}
