//! Hash maps and sets with a fixed hasher: the default one is seeded afresh in
//! every process, so the order of iteration (and with it the order in which
//! sewing and refinement visit nodes) changed from run to run, and so did the
//! mesh. With a fixed seed the same input gives the same mesh every time.

/// [`hashbrown::HashMap`] with a fixed seed.
pub(crate) type HashMap<K, V> = hashbrown::HashMap<K, V, foldhash::fast::FixedState>;
/// [`hashbrown::HashSet`] with a fixed seed.
pub(crate) type HashSet<K> = hashbrown::HashSet<K, foldhash::fast::FixedState>;

/// Items hashed by position on a uniform grid of cubes, for "what lies near
/// this point" queries (welding, crack counting, sewing).
pub(crate) struct CellGrid<T> {
    inv: f64,
    cells: HashMap<(i64, i64, i64), alloc::vec::Vec<T>>,
}

impl<T> CellGrid<T> {
    /// A grid of cubes `1 / inv` long.
    pub fn new(inv: f64) -> Self {
        Self { inv, cells: HashMap::default() }
    }

    /// The cube holding `p`.
    pub fn key(&self, p: glam::DVec3) -> (i64, i64, i64) {
        let c = p * self.inv;
        (crate::math::floor(c.x) as i64, crate::math::floor(c.y) as i64, crate::math::floor(c.z) as i64)
    }

    /// Adds `item` in the cube holding `p`.
    pub fn insert(&mut self, p: glam::DVec3, item: T) {
        self.cells.entry(self.key(p)).or_default().push(item);
    }

    /// The items of the 27 cubes around (and including) the one holding `p`,
    /// cube by cube (x outer, z inner), each cube's in the order added.
    pub fn near(&self, p: glam::DVec3) -> impl Iterator<Item = &T> + '_ {
        let (x, y, z) = self.key(p);
        (-1..=1)
            .flat_map(move |dx| (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| (x + dx, y + dy, z + dz))))
            .filter_map(|c| self.cells.get(&c))
            .flatten()
    }

    /// The items of every cube that meets the box `[lo, hi]`, in the order of [`CellGrid::near`].
    #[cfg(feature = "std")]
    pub fn in_box(&self, lo: glam::DVec3, hi: glam::DVec3) -> impl Iterator<Item = &T> + '_ {
        let (a, b) = (self.key(lo), self.key(hi));
        (a.0..=b.0)
            .flat_map(move |x| (a.1..=b.1).flat_map(move |y| (a.2..=b.2).map(move |z| (x, y, z))))
            .filter_map(|c| self.cells.get(&c))
            .flatten()
    }
}
