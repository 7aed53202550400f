//! Triangle adjacency of an indexed mesh: each triangle's neighbour across
//! each of its edges, with non-manifold and inconsistently oriented edges
//! found and named, and per-component orientation made consistent.

use alloc::collections::VecDeque;
use alloc::format;
use alloc::vec::Vec;
use glam::DVec3;

use crate::Error;

/// No neighbour (a free edge).
pub(crate) const NONE: u32 = u32::MAX;

/// Edge `k` of a triangle runs from its vertex `k` to vertex `k + 1 (mod 3)`.
#[inline]
pub(crate) fn edge(t: &[u32; 3], k: usize) -> (u32, u32) {
    (t[k], t[(k + 1) % 3])
}

/// An undirected edge key.
#[inline]
pub(crate) fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

/// The triangles on each undirected edge, as `3 * triangle + local edge`.
fn edge_uses(tris: &[[u32; 3]]) -> hashbrown::HashMap<(u32, u32), Vec<u32>> {
    let mut uses: hashbrown::HashMap<(u32, u32), Vec<u32>> = hashbrown::HashMap::with_capacity(tris.len() * 3 / 2);
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = edge(tri, k);
            uses.entry(key(a, b)).or_default().push(3 * t as u32 + k as u32);
        }
    }
    uses
}

/// Reverses triangles so that each connected component is consistently
/// oriented (every interior edge traversed once each way), keeping the
/// orientation of the component's first triangle. Returns how many were
/// reversed.
///
/// # Errors
/// [`Error::Repair`] naming the edge when more than two triangles share it,
/// or naming a triangle of a component that cannot be oriented (a Möbius band).
pub(crate) fn orient_consistently(tris: &mut [[u32; 3]]) -> Result<usize, Error> {
    let uses = edge_uses(tris);
    if let Some(((a, b), list)) = uses.iter().filter(|(_, l)| l.len() > 2).min_by_key(|(k, _)| **k) {
        let owners: Vec<u32> = list.iter().map(|u| u / 3).collect();
        return Err(Error::Repair {
            location: format!("edge between vertices {a} and {b}"),
            message: format!(
                "shared by {} triangles {owners:?}: the input is not a 2-manifold ({} such edges)",
                list.len(),
                uses.values().filter(|l| l.len() > 2).count()
            ),
        });
    }
    // flip[t]: 0 unknown, 1 keep, 2 reverse.
    let mut flip = alloc::vec![0u8; tris.len()];
    let mut queue = VecDeque::new();
    for start in 0..tris.len() {
        if flip[start] != 0 {
            continue;
        }
        flip[start] = 1;
        queue.push_back(start);
        while let Some(t) = queue.pop_front() {
            for k in 0..3 {
                let (a, b) = edge(&tris[t], k);
                let Some(list) = uses.get(&key(a, b)) else { continue };
                for &u in list {
                    let n = (u / 3) as usize;
                    if n == t {
                        continue;
                    }
                    let (c, _) = edge(&tris[n], (u % 3) as usize);
                    // Same direction means one of the two must be reversed.
                    let same = c == a;
                    let want = if same == (flip[t] == 1) { 2 } else { 1 };
                    if flip[n] == 0 {
                        flip[n] = want;
                        queue.push_back(n);
                    } else if flip[n] != want {
                        return Err(Error::Repair {
                            location: format!("triangle {n}"),
                            message: "its component cannot be oriented consistently (a Möbius band or similar)".into(),
                        });
                    }
                }
            }
        }
    }
    let mut reversed = 0;
    for (t, f) in tris.iter_mut().zip(&flip) {
        if *f == 2 {
            t.swap(1, 2);
            reversed += 1;
        }
    }
    Ok(reversed)
}

/// Neighbour of each triangle across each edge, `3 * triangle + its local
/// edge`, or [`NONE`] on a free edge. Edges must have been checked by
/// [`orient_consistently`] (at most two triangles, opposite directions);
/// anything else is left free.
pub(crate) fn adjacency(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut nbr = alloc::vec![[NONE; 3]; tris.len()];
    let mut open: hashbrown::HashMap<(u32, u32), u32> = hashbrown::HashMap::with_capacity(tris.len() * 3 / 2);
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = edge(tri, k);
            let me = 3 * t as u32 + k as u32;
            // The twin runs b -> a.
            if let Some(other) = open.remove(&(b, a)) {
                nbr[t][k] = other;
                nbr[(other / 3) as usize][(other % 3) as usize] = me;
            } else {
                open.insert((a, b), me);
            }
        }
    }
    nbr
}

/// Connected components over the adjacency: a component id per triangle and the count.
pub(crate) fn components(nbr: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut comp = alloc::vec![NONE; nbr.len()];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for s in 0..nbr.len() {
        if comp[s] != NONE {
            continue;
        }
        comp[s] = count;
        stack.push(s);
        while let Some(t) = stack.pop() {
            for &u in &nbr[t] {
                if u != NONE && comp[(u / 3) as usize] == NONE {
                    comp[(u / 3) as usize] = count;
                    stack.push((u / 3) as usize);
                }
            }
        }
        count += 1;
    }
    (comp, count as usize)
}

/// Signed volume enclosed by the triangles (divergence theorem); positive for
/// a closed mesh whose normals point outward.
pub(crate) fn signed_volume(positions: &[DVec3], tris: impl Iterator<Item = [u32; 3]>) -> f64 {
    let mut v = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        v += a.dot(b.cross(c));
    }
    v / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    /// A tetrahedron, outward.
    fn tet() -> Vec<[u32; 3]> {
        alloc::vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    }

    #[test]
    fn tetrahedron_is_closed_and_consistent() {
        let mut t = tet();
        assert_eq!(orient_consistently(&mut t).unwrap(), 0);
        let nbr = adjacency(&t);
        for (i, n) in nbr.iter().enumerate() {
            for (k, &u) in n.iter().enumerate() {
                assert_ne!(u, NONE);
                // The neighbour's neighbour is back here.
                assert_eq!(nbr[(u / 3) as usize][(u % 3) as usize], 3 * i as u32 + k as u32);
            }
        }
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        assert!((signed_volume(&p, t.iter().copied()) - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn a_reversed_triangle_is_turned_back() {
        let mut t = tet();
        t[2].swap(0, 1);
        assert_eq!(orient_consistently(&mut t).unwrap(), 1);
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        assert!(signed_volume(&p, t.iter().copied()) > 0.0);
        assert!(adjacency(&t).iter().all(|n| n.iter().all(|&u| u != NONE)));
    }

    #[test]
    fn three_triangles_on_one_edge_are_named() {
        let mut t = alloc::vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let e = orient_consistently(&mut t).unwrap_err().to_string();
        assert!(e.contains("edge between vertices 0 and 1"), "{e}");
        assert!(e.contains("3 triangles"), "{e}");
    }
}
