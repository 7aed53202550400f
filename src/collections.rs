//! Hash maps and sets with a fixed hasher: the default one is seeded afresh in
//! every process, so the order of iteration (and with it the order in which
//! sewing and refinement visit nodes) changed from run to run, and so did the
//! mesh. With a fixed seed the same input gives the same mesh every time.

/// [`hashbrown::HashMap`] with a fixed seed.
pub(crate) type HashMap<K, V> = hashbrown::HashMap<K, V, foldhash::fast::FixedState>;
/// [`hashbrown::HashSet`] with a fixed seed.
pub(crate) type HashSet<K> = hashbrown::HashSet<K, foldhash::fast::FixedState>;
