//! The B-rep edges of a mesh as polylines, for outline rendering: chains of
//! the faces' border edges, so that every point is a vertex of the mesh and
//! the lines run exactly where the triangles end.
//!
//! A face's border edges are its triangle edges used once within the face,
//! vertices of equal position taken as one (so a seam, where a face meets
//! itself, is no border). Where two faces meet, their borders share their
//! vertices (sewing puts them on the same point) and give one line. A line
//! ends where the set of faces along it changes (a B-rep vertex, a corner
//! where three faces meet) or where more or fewer than two border edges
//! meet; a closed border with no such point (a circular hole) is one closed
//! line whose last point is its first.

use alloc::vec::Vec;
use glam::DVec3;

use crate::collections::HashMap;
use crate::Mesh;

/// Polylines along a mesh's face borders.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct EdgeLines {
    /// The points of every line, one line after another.
    pub points: Vec<DVec3>,
    /// `(first point, point count)` per line; every line has at least two points.
    pub ranges: Vec<(u32, u32)>,
}

/// One border edge of the welded mesh: its two vertices and the faces whose border it is.
struct Border {
    ends: [u32; 2],
    faces: Vec<u32>,
}

/// The border polylines of `mesh` (see the module documentation).
pub fn edge_lines(mesh: &Mesh) -> EdgeLines {
    // One id per distinct position.
    let mut ids: HashMap<[u64; 3], u32> = HashMap::default();
    let mut points: Vec<DVec3> = Vec::new();
    let weld: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            *ids.entry(key).or_insert_with(|| {
                points.push(*p);
                (points.len() - 1) as u32
            })
        })
        .collect();
    drop(ids);
    // Each face's edges used once, then the faces of each such edge.
    let mut borders: Vec<Border> = Vec::new();
    let mut border_of: HashMap<(u32, u32), u32> = HashMap::default();
    let mut uses: HashMap<(u32, u32), u32> = HashMap::default();
    for (f, r) in mesh.face_ranges.iter().enumerate() {
        uses.clear();
        let tris = mesh.indices.get(3 * r.first as usize..3 * (r.first + r.count) as usize).unwrap_or_default();
        for t in tris.chunks_exact(3) {
            for k in 0..3 {
                let (Some(&a), Some(&b)) = (weld.get(t[k] as usize), weld.get(t[(k + 1) % 3] as usize)) else {
                    continue;
                };
                if a != b {
                    *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
        }
        let mut once: Vec<(u32, u32)> = uses.iter().filter(|(_, &n)| n == 1).map(|(e, _)| *e).collect();
        crate::sort::pairs(&mut once);
        for e in once {
            let b = *border_of.entry(e).or_insert_with(|| {
                borders.push(Border { ends: [e.0, e.1], faces: Vec::new() });
                (borders.len() - 1) as u32
            });
            borders[b as usize].faces.push(f as u32);
        }
    }
    drop(border_of);
    // Border edges at each vertex.
    let mut at: Vec<Vec<u32>> = alloc::vec![Vec::new(); points.len()];
    for (i, b) in borders.iter().enumerate() {
        at[b.ends[0] as usize].push(i as u32);
        at[b.ends[1] as usize].push(i as u32);
    }
    // A line goes on through a vertex with two border edges along the same faces.
    let through = |v: u32| match at[v as usize].as_slice() {
        [a, b] => borders[*a as usize].faces == borders[*b as usize].faces,
        _ => false,
    };
    let mut out = EdgeLines::default();
    let mut used = alloc::vec![false; borders.len()];
    let walk = |start_edge: usize, start: u32, out: &mut EdgeLines, used: &mut Vec<bool>| {
        let first = out.points.len() as u32;
        out.points.push(points[start as usize]);
        let (mut e, mut v) = (start_edge, start);
        loop {
            used[e] = true;
            let [a, b] = borders[e].ends;
            let next = if a == v { b } else { a };
            out.points.push(points[next as usize]);
            v = next;
            if !through(v) {
                break;
            }
            match at[v as usize].iter().map(|&x| x as usize).find(|&x| !used[x]) {
                Some(x) => e = x,
                None => break, // back at the start of a closed line
            }
        }
        out.ranges.push((first, out.points.len() as u32 - first));
    };
    // Lines from their ends first, then closed ones.
    for v in 0..points.len() as u32 {
        if through(v) {
            continue;
        }
        for k in 0..at[v as usize].len() {
            let e = at[v as usize][k] as usize;
            if !used[e] {
                walk(e, v, &mut out, &mut used);
            }
        }
    }
    for e in 0..borders.len() {
        if !used[e] {
            walk(e, borders[e].ends[0], &mut out, &mut used);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FaceRange;

    /// Two unit squares side by side (faces 0 and 1), each of two triangles,
    /// each face with its own vertices.
    fn two_squares() -> Mesh {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let positions = alloc::vec![
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(1.0, 1.0),
            p(0.0, 1.0),
            p(1.0, 0.0),
            p(2.0, 0.0),
            p(2.0, 1.0),
            p(1.0, 1.0),
        ];
        Mesh {
            normals: alloc::vec![DVec3::Z; positions.len()],
            positions,
            indices: alloc::vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7],
            face_ranges: alloc::vec![FaceRange { first: 0, count: 2 }, FaceRange { first: 2, count: 2 }],
        }
    }

    #[test]
    fn two_faces_give_their_shared_edge_once_and_their_outer_borders() {
        let lines = edge_lines(&two_squares());
        // The shared edge (1,0)-(1,1) is one line of two points; the rest of
        // each square's border is one line of four points (three edges
        // along one face, ending at the corners where the shared edge starts).
        let mut counts: Vec<u32> = lines.ranges.iter().map(|r| r.1).collect();
        counts.sort_unstable();
        assert_eq!(counts, [2, 4, 4]);
        let shared = lines.ranges.iter().find(|r| r.1 == 2).unwrap();
        let mut xs: Vec<(f64, f64)> =
            (0..2).map(|i| lines.points[(shared.0 + i) as usize]).map(|p| (p.x, p.y)).collect();
        xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(xs, [(1.0, 0.0), (1.0, 1.0)]);
    }

    #[test]
    fn a_closed_border_of_one_face_is_one_closed_line() {
        let mut m = two_squares();
        m.face_ranges = alloc::vec![FaceRange { first: 0, count: 2 }];
        m.indices.truncate(6);
        m.positions.truncate(4);
        m.normals.truncate(4);
        let lines = edge_lines(&m);
        assert_eq!(lines.ranges, [(0, 5)]);
        assert_eq!(lines.points[0], lines.points[4]);
    }
}
