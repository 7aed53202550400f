//! A small sorted edge map for the work mesh.

use alloc::vec::Vec;

use super::room;

/// Edges with a value each, sorted by their key: a binary search finds one,
/// and the list holds exactly its entries (a hash table ran a quarter empty
/// with at least 8 slots a face, and every face is held until assembly).
#[derive(Debug, Clone)]
pub(crate) struct EdgeList<V>(pub(super) Vec<((u32, u32), V)>);

impl<V> Default for EdgeList<V> {
    fn default() -> Self {
        Self(Vec::new())
    }
}

impl<V: Copy> EdgeList<V> {
    pub(super) fn find(&self, k: &(u32, u32)) -> Result<usize, usize> {
        self.0.binary_search_by(|e| e.0.cmp(k))
    }

    pub fn get(&self, k: &(u32, u32)) -> Option<&V> {
        self.find(k).ok().map(|i| &self.0[i].1)
    }

    pub(super) fn get_mut(&mut self, k: &(u32, u32)) -> Option<&mut V> {
        self.find(k).ok().map(|i| &mut self.0[i].1)
    }

    pub fn contains_key(&self, k: &(u32, u32)) -> bool {
        self.find(k).is_ok()
    }

    /// Sets the value of `k`.
    pub fn insert(&mut self, k: (u32, u32), v: V) {
        match self.find(&k) {
            Ok(i) => self.0[i].1 = v,
            Err(i) => {
                room(&mut self.0, 1);
                self.0.insert(i, (k, v));
            }
        }
    }

    /// Removes `k`, returning its value.
    pub fn remove(&mut self, k: &(u32, u32)) -> Option<V> {
        self.find(k).ok().map(|i| self.0.remove(i).1)
    }

    /// The keys, in order.
    pub fn keys(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.0.iter().map(|e| e.0)
    }

    /// The list of `items`, sorted (the last of a repeated key wins).
    pub fn from_unsorted(mut items: Vec<((u32, u32), V)>) -> Self {
        crate::sort::by_u64(&mut items, |e| crate::sort::pair(e.0 .0, e.0 .1));
        items.dedup_by(|later, earlier| {
            let same = later.0 == earlier.0;
            if same {
                earlier.1 = later.1;
            }
            same
        });
        items.shrink_to_fit();
        Self(items)
    }

    pub(super) fn shrink(&mut self) {
        self.0.shrink_to_fit();
    }
}
