//! Bodies: sets of faces that share no border (solids, sheets, assembly
//! parts), and how they are dealt out to workers that mesh side by side.

use alloc::vec::Vec;

use super::{body_of, Model};

/// Which faces share `index` of `count` meshes: bodies go, the largest (most
/// faces) first, to the share with the fewest faces so far; ties by body id
/// and by share index, so every worker computes the same split.
pub fn share_of_faces(bodies: &[u32], faces: usize, index: u32, count: u32) -> Vec<bool> {
    let body = |f: usize| body_of(bodies, f);
    let mut sizes: crate::collections::HashMap<u32, usize> = crate::collections::HashMap::default();
    for f in 0..faces {
        *sizes.entry(body(f)).or_insert(0) += 1;
    }
    let mut order: Vec<(u32, usize)> = sizes.into_iter().collect();
    crate::sort::by_u64(&mut order, |o| crate::sort::pair(u32::MAX - o.1.min(u32::MAX as usize) as u32, o.0));
    let count = count.max(1) as usize;
    let mut load = alloc::vec![0usize; count];
    let mut owner: crate::collections::HashMap<u32, usize> = crate::collections::HashMap::default();
    for (b, n) in order {
        let to = (0..count).min_by_key(|&i| (load[i], i)).unwrap_or(0);
        load[to] += n;
        owner.insert(b, to);
    }
    (0..faces).map(|f| owner.get(&body(f)).copied() == Some(index as usize)).collect()
}

/// How many bodies the faces of `model` fall in.
pub(crate) fn body_count(model: &Model) -> usize {
    let mut ids: Vec<u32> = (0..model.face_count()).map(|f| body_of(&model.bodies, f)).collect();
    ids.sort_unstable();
    ids.dedup();
    ids.len()
}
