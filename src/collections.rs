//! Hash maps and sets with a fixed hasher: the default one is seeded afresh in
//! every process, so the order of iteration (and with it the order in which
//! sewing and refinement visit nodes) changed from run to run, and so did the
//! mesh. With a fixed seed the same input gives the same mesh every time.

/// [`hashbrown::HashMap`] with a fixed seed.
pub(crate) type HashMap<K, V> = hashbrown::HashMap<K, V, foldhash::fast::FixedState>;
/// [`hashbrown::HashSet`] with a fixed seed.
pub(crate) type HashSet<K> = hashbrown::HashSet<K, foldhash::fast::FixedState>;

/// `f`, each value kept by its argument's bits: a parameter asked for again
/// (an interval's end its neighbour shares, a part of a split interval) is
/// not evaluated again, and gives the same bits as the first time. Trim
/// curves use it, so only the trimmed mesher (`std`) does.
#[cfg(feature = "std")]
pub(crate) fn memo_by_bits<T: Copy>(f: impl Fn(f64) -> T) -> impl Fn(f64) -> T {
    let seen: core::cell::RefCell<HashMap<u64, T>> = core::cell::RefCell::new(HashMap::default());
    move |t| {
        if let Some(&x) = seen.borrow().get(&t.to_bits()) {
            return x;
        }
        let x = f(t);
        seen.borrow_mut().insert(t.to_bits(), x);
        x
    }
}

/// Items hashed by position on a uniform grid of cubes, for "what lies near
/// this point" queries (welding, crack counting, sewing). Each cube holds
/// its first and last item and each item the next of its cube: a list per
/// cube, not a vector, which for the one or two points most cubes hold took
/// twice the memory (welding a whole model's vertices set the wasm peak).
pub(crate) struct CellGrid<T> {
    inv: f64,
    cells: HashMap<Key, (u32, u32)>,
    items: alloc::vec::Vec<(T, u32)>,
}

/// The end of a cube's list.
const LAST: u32 = u32::MAX;

impl<T> CellGrid<T> {
    /// A grid of cubes `1 / inv` long.
    pub fn new(inv: f64) -> Self {
        Self { inv, cells: HashMap::default(), items: alloc::vec::Vec::new() }
    }

    /// The cube holding `p`.
    pub fn key(&self, p: glam::DVec3) -> (i64, i64, i64) {
        let c = p * self.inv;
        (crate::math::floor(c.x) as i64, crate::math::floor(c.y) as i64, crate::math::floor(c.z) as i64)
    }

    /// Adds `item` in the cube holding `p`.
    pub fn insert(&mut self, p: glam::DVec3, item: T) {
        let i = self.items.len() as u32;
        self.items.push((item, LAST));
        let key = self.key(p);
        if let Some(c) = self.cells.get_mut(&key) {
            if let Some(last) = self.items.get_mut(c.1 as usize) {
                last.1 = i;
            }
            c.1 = i;
        } else {
            self.cells.insert(key, (i, i));
        }
    }

    /// The items of cube `c`, in the order added.
    fn cube(&self, c: (i64, i64, i64)) -> impl Iterator<Item = &T> + '_ {
        let first = self.cells.get(&c).map(|&(first, _)| first);
        core::iter::successors(first, |&i| self.items.get(i as usize).map(|x| x.1).filter(|&n| n != LAST))
            .filter_map(|i| self.items.get(i as usize).map(|x| &x.0))
    }

    /// The items of the 27 cubes around (and including) the one holding `p`,
    /// cube by cube (x outer, z inner), each cube's in the order added.
    pub fn near(&self, p: glam::DVec3) -> impl Iterator<Item = &T> + '_ {
        let (x, y, z) = self.key(p);
        (-1..=1)
            .flat_map(move |dx| (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| (x + dx, y + dy, z + dz))))
            .flat_map(|c| self.cube(c))
    }

    /// The items of every cube that meets the box `[lo, hi]`, in the order of [`CellGrid::near`].
    /// A box of more cubes than the grid holds takes the held cubes inside
    /// it, sorted, instead of looking up each of its cubes (a box a hundred
    /// cubes wide is a million look-ups).
    #[cfg(feature = "std")]
    pub fn in_box(&self, lo: glam::DVec3, hi: glam::DVec3) -> impl Iterator<Item = &T> + '_ {
        let (a, b) = (self.key(lo), self.key(hi));
        let walk = cubes_between(a, b) <= self.cells.len() as u128;
        let every = walk
            .then(|| (a.0..=b.0).flat_map(move |x| (a.1..=b.1).flat_map(move |y| (a.2..=b.2).map(move |z| (x, y, z)))));
        let held = (!walk).then(|| {
            let inside =
                |c: &Key| (a.0..=b.0).contains(&c.0) && (a.1..=b.1).contains(&c.1) && (a.2..=b.2).contains(&c.2);
            let mut keys: alloc::vec::Vec<Key> = self.cells.keys().copied().filter(inside).collect();
            keys.sort_unstable();
            keys
        });
        every.into_iter().flatten().chain(held.into_iter().flatten()).flat_map(|c| self.cube(c))
    }

    /// The items of the cubes that come within `r` of the segment `a`-`b`
    /// (and of a few more beside them), in the order of
    /// [`CellGrid::in_box`] over the segment's box grown by `r`: the items of
    /// that box within `r` of the segment, without visiting the rest of a
    /// long slanted segment's box.
    #[cfg(feature = "std")]
    pub fn near_segment(&self, a: glam::DVec3, b: glam::DVec3, r: f64) -> impl Iterator<Item = &T> + '_ {
        let (lo, hi) = (a.min(b) - glam::DVec3::splat(r), a.max(b) + glam::DVec3::splat(r));
        let cell = 1.0 / self.inv;
        // Samples at most a cube apart: a point within `r` of the segment
        // is within `r` + half a cube of one of them.
        let steps = a.distance(b) * self.inv;
        let short = !(steps.is_finite() && r.is_finite())
            || steps <= 4.0
            || steps > self.cells.len() as f64
            || r * self.inv > 4.0
            || cubes_between(self.key(lo), self.key(hi)) <= 64;
        let whole = short.then(|| self.in_box(lo, hi));
        let along = (!short).then(|| {
            let n = crate::math::ceil(steps) as usize;
            let reach = glam::DVec3::splat(r + 0.5 * cell);
            let mut keys: alloc::vec::Vec<Key> = alloc::vec::Vec::new();
            for k in 0..=n {
                let s = a.lerp(b, k as f64 / n as f64);
                let (p, q) = (self.key(s - reach), self.key(s + reach));
                for x in p.0..=q.0 {
                    for y in p.1..=q.1 {
                        keys.extend((p.2..=q.2).map(|z| (x, y, z)).filter(|c| self.cells.contains_key(c)));
                    }
                }
            }
            keys.sort_unstable();
            keys.dedup();
            keys.into_iter().flat_map(|c| self.cube(c))
        });
        whole.into_iter().flatten().chain(along.into_iter().flatten())
    }
}

/// A cube's key on a [`CellGrid`].
type Key = (i64, i64, i64);

/// How many cubes the keys `a` to `b` span (0 when `b` lies below `a` on an axis).
#[cfg(feature = "std")]
fn cubes_between(a: Key, b: Key) -> u128 {
    let span = |x: i64, y: i64| (i128::from(y) - i128::from(x) + 1).max(0) as u128;
    span(a.0, b.0).saturating_mul(span(a.1, b.1)).saturating_mul(span(a.2, b.2))
}

/// A map from pairs of `u32` (never both `u32::MAX`) to small values, for
/// the edges of a face's mesh while it is refined: open addressing with
/// linear probing, grown by a quarter at 80 % load. A [`HashMap`] doubles,
/// so its tables ran half empty (32 bytes an edge where the entry is 16),
/// and every face's tables are held until the model is assembled.
#[derive(Debug, Clone)]
pub(crate) struct PairMap<V> {
    slots: alloc::vec::Vec<(u64, V)>,
    len: usize,
}

/// The key of an empty slot.
const FREE: u64 = u64::MAX;

impl<V> Default for PairMap<V> {
    fn default() -> Self {
        Self { slots: alloc::vec::Vec::new(), len: 0 }
    }
}

impl<V: Copy> PairMap<V> {
    /// An empty map with room for `n` entries (`fill` stands in the empty slots).
    pub fn with_capacity(n: usize, fill: V) -> Self {
        let mut m = Self::default();
        m.rebuild((n + n / 4).max(8), fill);
        m
    }

    fn pack(k: &(u32, u32)) -> u64 {
        (u64::from(k.0) << 32) | u64::from(k.1)
    }

    /// The slot a key's probe starts at (multiplicative hash, scaled to the table).
    fn home(&self, key: u64) -> usize {
        let h = (key ^ (key >> 29)).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 32;
        ((h * self.slots.len() as u64) >> 32) as usize
    }

    /// The slot holding `key`, if any.
    fn find(&self, key: u64) -> Option<usize> {
        let n = self.slots.len();
        if n == 0 || key == FREE {
            return None;
        }
        let mut i = self.home(key);
        loop {
            match self.slots[i].0 {
                k if k == key => return Some(i),
                FREE => return None,
                _ => i = if i + 1 == n { 0 } else { i + 1 },
            }
        }
    }

    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn get(&self, k: &(u32, u32)) -> Option<&V> {
        self.find(Self::pack(k)).map(|i| &self.slots[i].1)
    }

    pub fn get_mut(&mut self, k: &(u32, u32)) -> Option<&mut V> {
        self.find(Self::pack(k)).map(|i| &mut self.slots[i].1)
    }

    pub fn contains_key(&self, k: &(u32, u32)) -> bool {
        self.find(Self::pack(k)).is_some()
    }

    /// The value of `k`, inserting `fill` first if it has none.
    pub fn get_or_insert(&mut self, k: (u32, u32), fill: V) -> &mut V {
        let key = Self::pack(&k);
        if let Some(i) = self.find(key) {
            return &mut self.slots[i].1;
        }
        if 5 * (self.len + 1) > 4 * self.slots.len() {
            self.grow(fill);
        }
        let n = self.slots.len();
        let mut i = self.home(key);
        while self.slots[i].0 != FREE {
            i = if i + 1 == n { 0 } else { i + 1 };
        }
        self.slots[i] = (key, fill);
        self.len += 1;
        &mut self.slots[i].1
    }

    /// Removes `k`, returning its value; later entries of its probe run
    /// move back, so no tombstones are left.
    pub fn remove(&mut self, k: &(u32, u32)) -> Option<V> {
        let mut i = self.find(Self::pack(k))?;
        let out = self.slots[i].1;
        let n = self.slots.len();
        let mut j = i;
        loop {
            j = if j + 1 == n { 0 } else { j + 1 };
            let key = self.slots[j].0;
            if key == FREE {
                break;
            }
            // An entry stays if its home lies cyclically in (i, j].
            let h = self.home(key);
            let stays = if i <= j { i < h && h <= j } else { i < h || h <= j };
            if !stays {
                self.slots[i] = self.slots[j];
                i = j;
            }
        }
        self.slots[i].0 = FREE;
        self.len -= 1;
        Some(out)
    }

    /// The entries, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = ((u32, u32), &V)> + '_ {
        self.slots.iter().filter(|s| s.0 != FREE).map(|(k, v)| (((k >> 32) as u32, *k as u32), v))
    }

    /// A table a quarter larger (at least 8 slots), entries moved over;
    /// `fill` stands in the empty slots' values.
    fn grow(&mut self, fill: V) {
        self.rebuild((self.slots.len() + self.slots.len() / 4).max(8), fill);
    }

    /// The entries moved into a table of `n` slots (more than hold them).
    fn rebuild(&mut self, n: usize, fill: V) {
        let old = core::mem::replace(&mut self.slots, alloc::vec![(FREE, fill); n]);
        for (key, v) in old {
            if key != FREE {
                let mut i = self.home(key);
                while self.slots[i].0 != FREE {
                    i = if i + 1 == n { 0 } else { i + 1 };
                }
                self.slots[i] = (key, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// Against a [`HashMap`] through a long run of inserts, updates,
    /// removals (which move probe runs back): the same entries
    /// every step.
    #[test]
    fn pair_map_agrees_with_a_hash_map() {
        let mut ours: PairMap<[u32; 2]> = PairMap::default();
        let mut theirs: HashMap<(u32, u32), [u32; 2]> = HashMap::default();
        let mut x: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for step in 0..60_000u32 {
            let r = next();
            // Few distinct keys, so that removals hit and runs collide.
            let k = ((r % 900) as u32, u32::MAX - 3 + ((r >> 20) % 3) as u32);
            match (r >> 40) % 4 {
                0 | 1 => {
                    let v = ours.get_or_insert(k, [step, 0]);
                    v[1] += 1;
                    theirs.entry(k).or_insert([step, 0])[1] += 1;
                }
                2 => assert_eq!(ours.remove(&k), theirs.remove(&k)),
                _ => {
                    if let Some(v) = ours.get_mut(&k) {
                        v[0] ^= 1;
                    }
                    if let Some(v) = theirs.get_mut(&k) {
                        v[0] ^= 1;
                    }
                }
            }
            assert_eq!(ours.len(), theirs.len());
            if step % 997 == 0 {
                let mut a: Vec<_> = ours.iter().map(|(k, v)| (k, *v)).collect();
                let mut b: Vec<_> = theirs.iter().map(|(k, v)| (*k, *v)).collect();
                a.sort_unstable();
                b.sort_unstable();
                assert_eq!(a, b);
                for (k, v) in &b {
                    assert_eq!(ours.get(k), Some(v));
                    assert!(ours.contains_key(k));
                }
            }
        }
        assert!(ours.get(&(5000, 5000)).is_none());
    }

    /// Cubes come x outer, z inner, and each cube's items in the order added.
    #[test]
    fn cell_grid_keeps_cube_and_insertion_order() {
        let mut g: CellGrid<u32> = CellGrid::new(1.0);
        let at = |x: f64, y: f64, z: f64| glam::DVec3::new(x, y, z);
        g.insert(at(0.5, 0.5, 1.5), 0);
        g.insert(at(0.5, 0.5, 0.5), 1);
        g.insert(at(-0.5, 0.5, 0.5), 2);
        g.insert(at(0.5, 0.5, 0.5), 3);
        g.insert(at(0.5, 0.5, 1.5), 4);
        g.insert(at(0.2, 0.7, 0.1), 5);
        g.insert(at(5.0, 5.0, 5.0), 6);
        let near: Vec<u32> = g.near(at(0.5, 0.5, 0.5)).copied().collect();
        assert_eq!(near, [2, 1, 3, 5, 0, 4]);
        assert_eq!(g.near(at(5.5, 5.5, 5.5)).copied().collect::<Vec<_>>(), [6]);
        assert!(g.near(at(50.0, 0.0, 0.0)).next().is_none());
    }

    /// Items on a slanted line and scattered round it: a box of more cubes
    /// than the grid holds, and the cubes along a long segment, give the
    /// items the cube by cube walk of the box gives (all of them, or those
    /// near the segment), in its order.
    #[test]
    fn boxes_and_segments_keep_the_walks_order() {
        let mut g: CellGrid<u32> = CellGrid::new(1.0);
        let at = |t: f64, k: u32| {
            let off = [(0.0, 0.0), (0.3, -0.2), (2.5, 0.0), (-3.0, 1.0)][k as usize % 4];
            glam::DVec3::new(t, 0.5 * t + off.0, 0.25 * t + off.1)
        };
        let mut pts = Vec::new();
        for i in 0..400u32 {
            let p = at(i as f64 * 0.17, i);
            g.insert(p, i);
            pts.push(p);
        }
        let walk = |lo: glam::DVec3, hi: glam::DVec3| -> Vec<u32> {
            let (a, b) = (g.key(lo), g.key(hi));
            let mut out = Vec::new();
            for x in a.0..=b.0 {
                for y in a.1..=b.1 {
                    for z in a.2..=b.2 {
                        out.extend(g.cube((x, y, z)).copied());
                    }
                }
            }
            out
        };
        let (lo, hi) = (glam::DVec3::new(-5.0, -8.0, -6.0), glam::DVec3::new(80.0, 45.0, 25.0));
        assert!(cubes_between(g.key(lo), g.key(hi)) > g.cells.len() as u128);
        let all: Vec<u32> = g.in_box(lo, hi).copied().collect();
        assert_eq!(all, walk(lo, hi));
        assert_eq!(all.len(), 400);
        let (a, b, r) = (at(3.0, 0), at(60.0, 0), 0.6);
        let near = |p: glam::DVec3| {
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a.lerp(b, t)) <= r
        };
        let box_walk = walk(a.min(b) - glam::DVec3::splat(r), a.max(b) + glam::DVec3::splat(r));
        let seg: Vec<u32> = g.near_segment(a, b, r).copied().collect();
        assert!(seg.len() < box_walk.len(), "{} of {}", seg.len(), box_walk.len());
        let keep = |v: &[u32]| v.iter().copied().filter(|&i| near(pts[i as usize])).collect::<Vec<_>>();
        assert_eq!(keep(&seg), keep(&box_walk));
        assert!(keep(&seg).len() > 50);
    }
}
