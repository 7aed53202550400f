//! Gmsh MSH 4.1 ASCII: writer (one surface entity per model face, shared
//! nodes) and a reader of the same subset, so exports can be loaded back.
//!
//! Layout written (Gmsh reference manual, "MSH file format", version 4.1):
//!
//! ```text
//! $MeshFormat            4.1 0 8            (version, ASCII, sizeof(size_t))
//! $Entities              0 0 F 0            (points, curves, surfaces, volumes)
//!                        tag minX minY minZ maxX maxY maxZ 0 0   (per surface)
//! $Nodes                 blocks nodes 1 nodes
//!                        2 tag 0 count      (dim, entity, parametric, count)
//!                        node tags, one a line, then "x y z" lines
//! $Elements              blocks elements 1 elements
//!                        2 tag 2 count      (dim, entity, type 2 = 3-node triangle)
//!                        element tag and its three node tags, one element a line
//! ```

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt::Write;
use glam::DVec3;

use super::meshfile::check_point;
use super::obj::face_ranges;
use crate::{Error, FaceRange, Mesh};

/// A mesh with one node per distinct position, for the FEA formats.
pub(super) struct SharedNodes {
    /// Position of each node (tag = index + 1).
    pub positions: Vec<DVec3>,
    /// Per face: its triangles as node indices (collapsed and invalid ones left out).
    pub faces: Vec<Vec<[u32; 3]>>,
    /// Per node: the first face that uses it (the entity it is classified on).
    pub owner: Vec<u32>,
}

/// Merges vertices with bit-identical coordinates (the mesher gives every
/// face its own copies of its border vertices at the same positions) and
/// drops triangles that point past the vertex list, touch a non-finite
/// position, or repeat a node; vertices no triangle uses are not nodes.
pub(super) fn shared_nodes(mesh: &Mesh) -> SharedNodes {
    let mut ids: crate::collections::HashMap<[u64; 3], u32> = crate::collections::HashMap::default();
    let mut node_of = alloc::vec![u32::MAX; mesh.positions.len()];
    let mut out = SharedNodes { positions: Vec::new(), faces: Vec::new(), owner: Vec::new() };
    for (face, range) in face_ranges(mesh).into_iter().enumerate() {
        let mut tris = Vec::with_capacity(range.len());
        'tri: for t in range {
            let mut tri = [0u32; 3];
            for (k, &v) in mesh.indices[3 * t..3 * t + 3].iter().enumerate() {
                let Some(&p) = mesh.positions.get(v as usize) else { continue 'tri };
                if !p.is_finite() {
                    continue 'tri;
                }
                let slot = &mut node_of[v as usize];
                if *slot == u32::MAX {
                    let key = [p.x, p.y, p.z].map(|x| (x + 0.0).to_bits());
                    *slot = *ids.entry(key).or_insert_with(|| {
                        out.positions.push(p);
                        out.owner.push(face as u32);
                        (out.positions.len() - 1) as u32
                    });
                }
                tri[k] = *slot;
            }
            if tri[0] != tri[1] && tri[1] != tri[2] && tri[2] != tri[0] {
                tris.push(tri);
            }
        }
        out.faces.push(tris);
    }
    out
}

/// Encodes the mesh as Gmsh MSH 4.1 ASCII: one surface entity per face range
/// (tag = face number + 1), vertices at identical positions merged into one
/// node (classified on the first face that uses it), 3-node triangles
/// (element type 2) in the faces' order, coordinates at full `f64` precision.
pub fn write_msh(mesh: &Mesh) -> Vec<u8> {
    let shared = shared_nodes(mesh);
    let n = shared.positions.len();
    let mut s = String::with_capacity(60 * n + 40 * mesh.triangle_count() + 256);
    // Writing into a String cannot fail; the `fmt::Result`s are ignored below.
    s.push_str("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    let faces = shared.faces.len();
    let _ = writeln!(s, "$Entities\n0 0 {faces} 0");
    let mut boxes = alloc::vec![(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)); faces];
    for (f, tris) in shared.faces.iter().enumerate() {
        for &v in tris.iter().flatten() {
            let p = shared.positions[v as usize];
            boxes[f] = (boxes[f].0.min(p), boxes[f].1.max(p));
        }
    }
    for (f, (lo, hi)) in boxes.iter().enumerate() {
        let (lo, hi) = if lo.x <= hi.x { (*lo, *hi) } else { (DVec3::ZERO, DVec3::ZERO) };
        let _ = writeln!(s, "{} {:e} {:e} {:e} {:e} {:e} {:e} 0 0", f + 1, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    }
    s.push_str("$EndEntities\n");
    // Nodes in blocks by owning face; tags follow the block order.
    let mut by_face: Vec<Vec<u32>> = alloc::vec![Vec::new(); faces];
    for (v, &f) in shared.owner.iter().enumerate() {
        by_face[f as usize].push(v as u32);
    }
    let mut tag = alloc::vec![0u64; n];
    let mut next = 1u64;
    for list in &by_face {
        for &v in list {
            tag[v as usize] = next;
            next += 1;
        }
    }
    let blocks = by_face.iter().filter(|l| !l.is_empty()).count();
    let _ = writeln!(s, "$Nodes\n{blocks} {n} {} {n}", n.min(1));
    for (f, list) in by_face.iter().enumerate().filter(|(_, l)| !l.is_empty()) {
        let _ = writeln!(s, "2 {} 0 {}", f + 1, list.len());
        for &v in list {
            let _ = writeln!(s, "{}", tag[v as usize]);
        }
        for &v in list {
            let p = shared.positions[v as usize];
            let _ = writeln!(s, "{:e} {:e} {:e}", p.x, p.y, p.z);
        }
    }
    s.push_str("$EndNodes\n");
    let elements: usize = shared.faces.iter().map(Vec::len).sum();
    let blocks = shared.faces.iter().filter(|t| !t.is_empty()).count();
    let _ = writeln!(s, "$Elements\n{blocks} {elements} {} {elements}", elements.min(1));
    let mut label = 1u64;
    for (f, tris) in shared.faces.iter().enumerate().filter(|(_, t)| !t.is_empty()) {
        let _ = writeln!(s, "2 {} 2 {}", f + 1, tris.len());
        for t in tris {
            let _ = writeln!(s, "{label} {} {} {}", tag[t[0] as usize], tag[t[1] as usize], tag[t[2] as usize]);
            label += 1;
        }
    }
    s.push_str("$EndElements\n");
    s.into_bytes()
}

/// Whitespace-separated words of a text with the 1-based line each is on.
struct Words<'a> {
    lines: core::iter::Enumerate<core::str::Lines<'a>>,
    current: core::str::SplitAsciiWhitespace<'a>,
    line: usize,
}

impl<'a> Words<'a> {
    fn new(text: &'a str) -> Self {
        Self { lines: text.lines().enumerate(), current: "".split_ascii_whitespace(), line: 0 }
    }

    fn next_word(&mut self) -> Option<&'a str> {
        loop {
            if let Some(w) = self.current.next() {
                return Some(w);
            }
            let (n, l) = self.lines.next()?;
            self.line = n + 1;
            self.current = l.split_ascii_whitespace();
        }
    }

    fn error(&self, message: String) -> Error {
        Error::MeshFile { location: format!("MSH line {}", self.line), message }
    }

    fn word(&mut self, what: &str) -> Result<&'a str, Error> {
        self.next_word().ok_or_else(|| Error::MeshFile {
            location: format!("MSH line {}", self.line),
            message: format!("the file ends where {what} was expected"),
        })
    }

    fn count(&mut self, what: &str) -> Result<usize, Error> {
        let w = self.word(what)?;
        w.parse().map_err(|_| self.error(format!("{what}: '{w}' is not a count")))
    }

    fn int(&mut self, what: &str) -> Result<i64, Error> {
        let w = self.word(what)?;
        w.parse().map_err(|_| self.error(format!("{what}: '{w}' is not an integer")))
    }

    fn number(&mut self, what: &str) -> Result<f64, Error> {
        let w = self.word(what)?;
        w.parse().map_err(|_| self.error(format!("{what}: '{w}' is not a number")))
    }

    /// Skips to the word `end` (the end marker of a section not read).
    fn skip_to(&mut self, end: &str) -> Result<(), Error> {
        while let Some(w) = self.next_word() {
            if w == end {
                return Ok(());
            }
        }
        Err(self.error(format!("missing {end}")))
    }

    fn expect(&mut self, end: &str) -> Result<(), Error> {
        let w = self.word(end)?;
        if w == end {
            Ok(())
        } else {
            Err(self.error(format!("expected {end}, found '{w}'")))
        }
    }
}

/// Nodes per element of the Gmsh element types the reader takes: points and
/// lines (skipped), triangles and quadrangles; 0 for any other type.
fn nodes_per_element(kind: i64) -> usize {
    match kind {
        15 => 1, // point
        1 => 2,  // 2-node line
        8 => 3,  // 3-node line
        2 => 3,  // 3-node triangle
        3 => 4,  // 4-node quadrangle
        _ => 0,
    }
}

/// Reads a Gmsh MSH 4.1 ASCII file: nodes (any entity), triangles (type 2;
/// 4-node quadrangles, type 3, split into two) with one face range per
/// run of element blocks on the same surface; points and lines are skipped.
/// Other sections are skipped. Node positions are not merged.
///
/// # Errors
/// [`Error::MeshFile`] naming the line: another version or binary encoding,
/// a count the data does not hold, a node tag used twice or missing, volume
/// or higher-order elements.
pub fn read_msh(bytes: &[u8]) -> Result<Mesh, Error> {
    let text = core::str::from_utf8(bytes)
        .map_err(|_| Error::MeshFile { location: "MSH".into(), message: "not UTF-8 text".into() })?;
    // Every count read is checked against this: each item takes at least two bytes.
    let bound = text.len() / 2 + 1;
    let mut w = Words::new(text);
    let mut version_seen = false;
    let mut tags: crate::collections::HashMap<u64, u32> = crate::collections::HashMap::default();
    let mut mesh = Mesh::default();
    let mut last_entity: Option<i64> = None;
    while let Some(section) = w.next_word() {
        match section {
            "$MeshFormat" => {
                let version = w.word("the version")?;
                if version != "4.1" {
                    return Err(w.error(format!("version {version}: only MSH 4.1 is read")));
                }
                if w.int("the file type")? != 0 {
                    return Err(w.error("binary MSH is not read; save as ASCII".into()));
                }
                w.int("the data size")?;
                w.expect("$EndMeshFormat")?;
                version_seen = true;
            }
            "$Nodes" if version_seen => read_nodes(&mut w, bound, &mut tags, &mut mesh)?,
            "$Elements" if version_seen => read_elements(&mut w, bound, &tags, &mut mesh, &mut last_entity)?,
            s if s.starts_with("$End") => return Err(w.error(format!("{s} without its section"))),
            s if s.starts_with('$') => {
                if !version_seen {
                    return Err(w.error(format!("{s} before $MeshFormat")));
                }
                let end = format!("$End{}", &s[1..]);
                w.skip_to(&end)?;
            }
            s => return Err(w.error(format!("expected a section ($Name), found '{s}'"))),
        }
    }
    if !version_seen {
        return Err(Error::MeshFile { location: "MSH".into(), message: "no $MeshFormat section".into() });
    }
    Ok(mesh)
}

fn read_nodes(
    w: &mut Words<'_>,
    bound: usize,
    tags: &mut crate::collections::HashMap<u64, u32>,
    mesh: &mut Mesh,
) -> Result<(), Error> {
    let blocks = w.count("the number of node blocks")?;
    let total = w.count("the number of nodes")?;
    w.count("the smallest node tag")?;
    w.count("the largest node tag")?;
    if total > bound || blocks > bound {
        return Err(w.error(format!("{total} nodes in {blocks} blocks: more than the file holds")));
    }
    let mut read = 0usize;
    for _ in 0..blocks {
        let dim = w.int("the entity dimension")?;
        w.int("the entity tag")?;
        let parametric = w.int("the parametric flag")? != 0;
        let count = w.count("the block's node count")?;
        if count > total - read {
            return Err(w.error(format!("a block of {count} nodes exceeds the {total} nodes announced")));
        }
        let mut block = Vec::with_capacity(count);
        for _ in 0..count {
            let t = w.count("a node tag")? as u64;
            block.push(t);
        }
        let extra = if parametric { dim.clamp(0, 3) as usize } else { 0 };
        for t in block {
            let mut xyz = [0.0; 3];
            for x in &mut xyz {
                *x = w.number("a coordinate")?;
            }
            for _ in 0..extra {
                w.number("a parametric coordinate")?;
            }
            let p = check_point(xyz).map_err(|m| w.error(m.to_string()))?;
            let index = u32::try_from(mesh.positions.len()).map_err(|_| w.error("more than 2^32 nodes".into()))?;
            if tags.insert(t, index).is_some() {
                return Err(w.error(format!("node tag {t} is defined twice")));
            }
            mesh.positions.push(p);
        }
        read += count;
    }
    w.expect("$EndNodes")
}

fn read_elements(
    w: &mut Words<'_>,
    bound: usize,
    tags: &crate::collections::HashMap<u64, u32>,
    mesh: &mut Mesh,
    last_entity: &mut Option<i64>,
) -> Result<(), Error> {
    let blocks = w.count("the number of element blocks")?;
    let total = w.count("the number of elements")?;
    w.count("the smallest element tag")?;
    w.count("the largest element tag")?;
    if total > bound || blocks > bound {
        return Err(w.error(format!("{total} elements in {blocks} blocks: more than the file holds")));
    }
    let mut read = 0usize;
    let mut corners = [0u32; 4];
    for _ in 0..blocks {
        w.int("the entity dimension")?;
        let entity = w.int("the entity tag")?;
        let kind = w.int("the element type")?;
        let count = w.count("the block's element count")?;
        if count > total - read {
            return Err(w.error(format!("a block of {count} elements exceeds the {total} elements announced")));
        }
        let per = nodes_per_element(kind);
        if per == 0 {
            return Err(w.error(format!("element type {kind} is not read (triangles and quadrangles only)")));
        }
        let surface = matches!(kind, 2 | 3);
        if surface && *last_entity != Some(entity) {
            let first = mesh.triangle_count() as u32;
            mesh.face_ranges.push(FaceRange { first, count: 0 });
            *last_entity = Some(entity);
        }
        for _ in 0..count {
            w.count("an element tag")?;
            for c in corners.iter_mut().take(per) {
                let t = w.count("a node tag")? as u64;
                *c = *tags.get(&t).ok_or_else(|| w.error(format!("node tag {t} is not defined")))?;
            }
            if surface {
                mesh.indices.extend_from_slice(&corners[..3]);
                if kind == 3 {
                    mesh.indices.extend_from_slice(&[corners[0], corners[2], corners[3]]);
                }
            }
        }
        let tris = mesh.triangle_count() as u32;
        if let Some(r) = mesh.face_ranges.last_mut().filter(|_| surface) {
            r.count = tris - r.first;
        }
        read += count;
    }
    w.expect("$EndElements")
}
