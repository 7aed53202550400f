//! Welding coincident vertices.

use alloc::vec::Vec;
use glam::DVec3;

/// Cubes of the weld's grid (each `tol` long) to a side of one cell of its
/// table: a position's 27 cubes lie in one to eight cells (one in about
/// half the cases) where 27 lookups missed the cache on large meshes.
const CELL: i64 = 8;

/// Maps each position to a representative index so that positions closer than
/// `tol` share one: the first earlier representative found in the 27 cubes of
/// size `tol` about it (x outer, z inner). Returns `(map, count)`. The
/// positions grouped by a hash of their cell (`CELL` cubes a side; each
/// group in index order) and a table from hash to where its group starts
/// stand in for a hash grid of cells, which took about 60 bytes a vertex
/// and set the peak of a model's edge census.
pub fn weld_positions(positions: &[DVec3], tol: f64) -> (Vec<u32>, usize) {
    let tol = if tol > 0.0 && tol.is_finite() { tol } else { 1e-12 };
    let inv = 1.0 / tol;
    let cube = |p: DVec3| {
        let c = p * inv;
        (crate::math::floor(c.x) as i64, crate::math::floor(c.y) as i64, crate::math::floor(c.z) as i64)
    };
    let cell = |c: (i64, i64, i64)| (c.0.div_euclid(CELL), c.1.div_euclid(CELL), c.2.div_euclid(CELL));
    let hash = |c: (i64, i64, i64)| {
        let h = (c.0 as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (c.1 as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f).rotate_left(21)
            ^ (c.2 as u64).wrapping_mul(0x1656_67b1_9e37_79f9).rotate_left(42);
        h ^ (h >> 31)
    };
    // (hash of the cell, index), sorted: each cell's positions together, in
    // index order (the order the grid adds them); cells of one hash share a group.
    let mut order: Vec<(u64, u32)> =
        positions.iter().enumerate().map(|(i, &p)| (hash(cell(cube(p))), i as u32)).collect();
    crate::sort::sort_u64_keys(&mut order);
    let groups = (0..order.len()).filter(|&k| k == 0 || order[k].0 != order[k - 1].0).count();
    let slots = groups + groups / 3 + 1;
    let home = |h: u64| ((u128::from(h) * slots as u128) >> 64) as usize;
    let mut table = alloc::vec![u32::MAX; slots];
    for k in (0..order.len()).filter(|&k| k == 0 || order[k].0 != order[k - 1].0) {
        let mut s = home(order[k].0);
        while table[s] != u32::MAX {
            s = if s + 1 == slots { 0 } else { s + 1 };
        }
        table[s] = k as u32;
    }
    // The positions from the group of hash `h` on, read while the hash is
    // `h` (a search for the group's end visited the whole rest of `order`).
    let group = |h: u64| -> &[(u64, u32)] {
        let mut s = home(h);
        while let Some(&k) = table.get(s).filter(|&&k| k != u32::MAX) {
            if order[k as usize].0 == h {
                return &order[k as usize..];
            }
            s = if s + 1 == slots { 0 } else { s + 1 };
        }
        &[]
    };
    let mut map: Vec<u32> = Vec::with_capacity(positions.len());
    let mut first: Vec<u32> = Vec::new();
    for (i, &p) in positions.iter().enumerate() {
        let (x, y, z) = cube(p);
        // The cells of the 27 cubes; of the representatives made before this
        // position within `tol`, the first in the cubes' order (x outer, z
        // inner), then in index order.
        let (lo, hi) = (
            cell((x.saturating_sub(1), y.saturating_sub(1), z.saturating_sub(1))),
            cell((x.saturating_add(1), y.saturating_add(1), z.saturating_add(1))),
        );
        let mut found: Option<(u32, u32, u32)> = None;
        for cx in lo.0..=hi.0 {
            for cy in lo.1..=hi.1 {
                for cz in lo.2..=hi.2 {
                    let h = hash((cx, cy, cz));
                    for &(_, j) in group(h).iter().take_while(|x| x.0 == h && x.1 < i as u32) {
                        let r = map[j as usize];
                        let q = positions[j as usize];
                        if first[r as usize] != j || q.distance_squared(p) > tol * tol {
                            continue;
                        }
                        let (qx, qy, qz) = cube(q);
                        if qx.abs_diff(x) > 1 || qy.abs_diff(y) > 1 || qz.abs_diff(z) > 1 {
                            continue;
                        }
                        // The cube's place in the 27 (x outer, z inner).
                        let rank = ((qx - x + 1) * 9 + (qy - y + 1) * 3 + (qz - z + 1)) as u32;
                        if found.is_none_or(|(fr, fj, _)| (rank, j) < (fr, fj)) {
                            found = Some((rank, j, r));
                        }
                    }
                }
            }
        }
        let id = found.map_or_else(
            || {
                first.push(i as u32);
                (first.len() - 1) as u32
            },
            |f| f.2,
        );
        map.push(id);
    }
    (map, first.len())
}

/// A copy of `mesh` with vertices closer than `tol` merged (first one's
/// position kept, unused ones dropped) and normals dropped; triangles keep
/// their order, including any that welding collapsed (two equal indices).
pub fn weld_mesh(mesh: &super::Mesh, tol: f64) -> super::Mesh {
    let (map, count) = weld_positions(&mesh.positions, tol);
    let mut positions = alloc::vec![DVec3::ZERO; count];
    let mut seen = alloc::vec![false; count];
    for (i, &m) in map.iter().enumerate() {
        if !seen[m as usize] {
            seen[m as usize] = true;
            positions[m as usize] = mesh.positions[i];
        }
    }
    let indices = mesh.indices.iter().map(|&i| map.get(i as usize).copied().unwrap_or(u32::MAX)).collect();
    super::Mesh { positions, normals: Vec::new(), indices, face_ranges: mesh.face_ranges.clone() }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weld by a hash grid of cells (what [`weld_positions`] replaced),
    /// as the oracle: the same map, representatives and all.
    fn grid_weld(positions: &[DVec3], tol: f64) -> (Vec<u32>, usize) {
        let tol = if tol > 0.0 && tol.is_finite() { tol } else { 1e-12 };
        let mut cells = crate::collections::CellGrid::new(1.0 / tol);
        let mut map = Vec::with_capacity(positions.len());
        let mut reps: Vec<DVec3> = Vec::new();
        for &p in positions {
            let found = cells.near(p).copied().find(|&r| reps[r as usize].distance_squared(p) <= tol * tol);
            let id = match found {
                Some(r) => r,
                None => {
                    let r = reps.len() as u32;
                    reps.push(p);
                    cells.insert(p, r);
                    r
                }
            };
            map.push(id);
        }
        (map, reps.len())
    }

    /// The weld gives the hash grid's map, representatives and all,
    /// on clusters that chain (a, b within the tolerance, b, c within it, a,
    /// c not), on both sides of zero, points on cube corners, and repeats.
    #[test]
    fn weld_matches_the_hash_grid() {
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts: Vec<DVec3> = Vec::new();
        for _ in 0..3000 {
            // Negative coordinates too: cells below zero round down.
            let base = DVec3::new(next(), next(), next()) * 4.0 - DVec3::splat(2.0);
            pts.push(base);
            for _ in 0..(next() * 4.0) as usize {
                pts.push(base + DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.02);
            }
        }
        pts.push(DVec3::new(1.0, 1.0, 1.0));
        pts.push(DVec3::new(1.0, 1.0, 1.0));
        pts.push(DVec3::new(1.0 - 1e-9, 1.0, 1.0));
        for tol in [0.01, 0.005, 1e-12] {
            let (a, n) = grid_weld(&pts, tol);
            assert!(n < pts.len() || tol < 1e-9);
            assert_eq!(weld_positions(&pts, tol), (a, n), "tol {tol}");
        }
    }
}
