//! Triangle-mesh files (STL, OBJ): format names, detection, and the builder
//! the readers share, which merges vertices with bit-identical coordinates
//! (STL stores every triangle's corners separately). Welding by a tolerance is
//! a separate step ([`crate::weld_mesh`]).

use alloc::format;
use alloc::vec::Vec;
use glam::DVec3;

use crate::{Error, Mesh};

/// Coordinates larger than this in magnitude are rejected: the exact
/// predicates of mesh repair need products of several coordinates to stay finite.
pub(crate) const MAX_COORDINATE: f64 = 1e30;

/// Mesh file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshFormat {
    /// STL, binary or ASCII (told apart by the content).
    Stl,
    /// Wavefront OBJ (vertices and faces; polygons are split into fans).
    Obj,
}

impl MeshFormat {
    /// Format from a name or file extension (`"stl"`, `".obj"`, case-insensitive).
    ///
    /// # Errors
    /// [`Error::Format`] for an unknown name.
    pub fn from_name(name: &str) -> Result<Self, Error> {
        let n = name.trim_start_matches('.');
        if n.eq_ignore_ascii_case("stl") {
            Ok(Self::Stl)
        } else if n.eq_ignore_ascii_case("obj") {
            Ok(Self::Obj)
        } else {
            Err(Error::Format(format!("unknown mesh format '{name}' (expected stl or obj)")))
        }
    }

    /// Guesses the format from the content: a binary STL's size matches the
    /// triangle count in its header; text starting with `solid` is ASCII STL;
    /// text whose lines start with `v `, `f `, `#`, `o `, `g ` is OBJ.
    pub fn detect(bytes: &[u8]) -> Option<Self> {
        if super::stl::is_binary_stl(bytes) {
            return Some(Self::Stl);
        }
        let text = bytes.get(..bytes.len().min(4096))?;
        let start = text.iter().position(|b| !b.is_ascii_whitespace())?;
        let rest = &text[start..];
        if rest.len() >= 5 && rest[..5].eq_ignore_ascii_case(b"solid") {
            return Some(Self::Stl);
        }
        let obj_line = |l: &[u8]| {
            let l = l.trim_ascii_start();
            l.is_empty()
                || l.starts_with(b"#")
                || [&b"v "[..], b"vn ", b"vt ", b"f ", b"o ", b"g ", b"s ", b"mtllib", b"usemtl"]
                    .iter()
                    .any(|p| l.starts_with(p))
        };
        let mut lines = rest.split(|&b| b == b'\n');
        let first = lines.next()?;
        (obj_line(first) && rest.windows(2).any(|w| w == b"v ")).then_some(Self::Obj)
    }
}

/// Reads a mesh file: positions (bit-identical ones merged) and triangles,
/// no normals, no face ranges.
///
/// # Errors
/// [`Error::MeshFile`] naming the line (or binary triangle) and the problem.
pub fn read_mesh(bytes: &[u8], format: MeshFormat) -> Result<Mesh, Error> {
    match format {
        MeshFormat::Stl => super::stl::read_stl(bytes),
        MeshFormat::Obj => super::obj::read_obj(bytes),
    }
}

/// Collects triangles, merging vertices with identical coordinates.
#[derive(Default)]
pub(crate) struct MeshBuilder {
    positions: Vec<DVec3>,
    indices: Vec<u32>,
    ids: crate::collections::HashMap<[u64; 3], u32>,
}

impl MeshBuilder {
    /// The id of a vertex at `p` (new or existing). `p` must be finite.
    pub(crate) fn vertex(&mut self, p: DVec3) -> Result<u32, PointError> {
        // +0.0 and -0.0 are one point.
        let k = [p.x, p.y, p.z].map(|x| (x + 0.0).to_bits());
        if let Some(&i) = self.ids.get(&k) {
            return Ok(i);
        }
        let i = u32::try_from(self.positions.len()).map_err(|_| PointError::TooManyVertices)?;
        self.positions.push(p);
        self.ids.insert(k, i);
        Ok(i)
    }

    /// Appends a triangle of vertex ids.
    pub(crate) fn triangle(&mut self, t: [u32; 3]) {
        self.indices.extend_from_slice(&t);
    }

    /// The mesh.
    pub(crate) fn finish(self) -> Mesh {
        Mesh { positions: self.positions, normals: Vec::new(), indices: self.indices, face_ranges: Vec::new() }
    }
}

/// What is wrong with a point of a mesh file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum PointError {
    /// A coordinate that is not a finite number.
    NotFinite([f64; 3]),
    /// A coordinate past [`MAX_COORDINATE`].
    TooLarge([f64; 3]),
    /// More vertices than 32-bit indices reach.
    TooManyVertices,
}

impl core::fmt::Display for PointError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotFinite(p) => write!(f, "coordinate {} {} {} is not a finite number", p[0], p[1], p[2]),
            Self::TooLarge(p) => {
                write!(f, "coordinate {} {} {} is larger than {MAX_COORDINATE:e} in magnitude", p[0], p[1], p[2])
            }
            Self::TooManyVertices => write!(f, "more than 2^32 vertices"),
        }
    }
}

/// Checks one coordinate triple: finite and within [`MAX_COORDINATE`].
pub(crate) fn check_point(p: [f64; 3]) -> Result<DVec3, PointError> {
    if p.iter().any(|x| !x.is_finite()) {
        return Err(PointError::NotFinite(p));
    }
    if p.iter().any(|x| x.abs() > MAX_COORDINATE) {
        return Err(PointError::TooLarge(p));
    }
    Ok(DVec3::from_array(p))
}
