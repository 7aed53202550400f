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

/// Every edge use `3 * triangle + local edge`, sorted by its undirected edge
/// (sorting a flat list is much faster than a map of lists at this size).
fn sorted_uses(tris: &[[u32; 3]]) -> Vec<(u64, u32)> {
    let mut uses: Vec<(u64, u32)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = key(tri[k], tri[(k + 1) % 3]);
            uses.push(((u64::from(a) << 32) | u64::from(b), 3 * t as u32 + k as u32));
        }
    }
    uses.sort_unstable();
    uses
}

/// The other use of each edge use when exactly two triangles share the edge
/// ([`NONE`] for a free edge), or the first edge (lowest vertex ids) that more
/// than two share, with its uses, and how many such edges there are.
fn mates(tris: &[[u32; 3]]) -> Result<Vec<u32>, (u64, Vec<u32>, usize)> {
    let uses = sorted_uses(tris);
    let mut mate = alloc::vec![NONE; 3 * tris.len()];
    let mut bad: Option<(u64, Vec<u32>)> = None;
    let mut bad_count = 0;
    let mut i = 0;
    while i < uses.len() {
        let mut j = i + 1;
        while j < uses.len() && uses[j].0 == uses[i].0 {
            j += 1;
        }
        match j - i {
            1 => {}
            2 => {
                mate[uses[i].1 as usize] = uses[i + 1].1;
                mate[uses[i + 1].1 as usize] = uses[i].1;
            }
            _ => {
                bad_count += 1;
                if bad.is_none() {
                    bad = Some((uses[i].0, uses[i..j].iter().map(|u| u.1).collect()));
                }
            }
        }
        i = j;
    }
    match bad {
        Some((k, list)) => Err((k, list, bad_count)),
        None => Ok(mate),
    }
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
    let mate = match mates(tris) {
        Ok(m) => m,
        Err((k, list, count)) => {
            let owners: Vec<u32> = list.iter().map(|u| u / 3).collect();
            return Err(Error::Repair {
                location: format!("edge between vertices {} and {}", k >> 32, k & 0xFFFF_FFFF),
                message: format!(
                    "shared by {} triangles {owners:?}: the input is not a 2-manifold ({count} such edges)",
                    list.len()
                ),
            });
        }
    };
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
                let u = mate[3 * t + k];
                if u == NONE {
                    continue;
                }
                let n = (u / 3) as usize;
                let (a, _) = edge(&tris[t], k);
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
    let mate = mates(tris).unwrap_or_else(|_| alloc::vec![NONE; 3 * tris.len()]);
    let mut nbr = alloc::vec![[NONE; 3]; tris.len()];
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let u = mate[3 * t + k];
            if u == NONE {
                continue;
            }
            let (a, b) = edge(tri, k);
            let (c, d) = edge(&tris[(u / 3) as usize], (u % 3) as usize);
            // Only a twin running the other way is a neighbour.
            if (c, d) == (b, a) {
                nbr[t][k] = u;
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
