//! An indexed 4-ary min-heap of edge costs: at most one entry per edge, updated in place.
//!
//! Compared with a lazy heap (push a new entry on every cost change, skip stale ones on pop)
//! it stays as small as the live edge set (16-byte entries plus a 4-byte position per edge),
//! which keeps the sift paths in cache. Order: cost ascending (`f64::total_cmp`), ties by the
//! lower edge id, so the pop sequence depends only on the set of (cost, edge) keys.

/// Children per node. A 4-ary heap is half as deep as a binary one and a node's children
/// share one or two cache lines, so sifting through a large heap (most of it out of cache)
/// touches about half as many lines. The pop order is the same for any arity: it is fixed
/// by the keys' total order.
const ARITY: usize = 4;

/// Marks an edge that has no entry.
const ABSENT: u32 = u32::MAX;

#[derive(Debug, Clone, Copy)]
struct Key {
    cost: f64,
    edge: u32,
}

impl Key {
    #[inline]
    fn less(&self, o: &Key) -> bool {
        match self.cost.total_cmp(&o.cost) {
            std::cmp::Ordering::Less => true,
            std::cmp::Ordering::Greater => false,
            std::cmp::Ordering::Equal => self.edge < o.edge,
        }
    }
}

/// Min-heap of `(cost, edge)` with one entry per edge id `< capacity`.
#[derive(Debug, Default)]
pub(crate) struct EdgeHeap {
    keys: Vec<Key>,
    /// `pos[e]`: index of edge `e`'s entry in `keys`, or [`ABSENT`].
    pos: Vec<u32>,
}

impl EdgeHeap {
    /// An empty heap for edge ids `< capacity`.
    pub(crate) fn new(capacity: usize) -> EdgeHeap {
        EdgeHeap {
            keys: Vec::new(),
            pos: vec![ABSENT; capacity],
        }
    }

    /// Number of entries.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }

    /// Replaces the content by `entries` (one per edge, edges distinct), in O(n).
    pub(crate) fn rebuild(&mut self, entries: impl IntoIterator<Item = (f64, u32)>) {
        for k in &self.keys {
            self.pos[k.edge as usize] = ABSENT;
        }
        self.keys.clear();
        self.keys
            .extend(entries.into_iter().map(|(cost, edge)| Key { cost, edge }));
        for (i, k) in self.keys.iter().enumerate() {
            debug_assert_eq!(self.pos[k.edge as usize], ABSENT, "duplicate edge");
            self.pos[k.edge as usize] = i as u32;
        }
        for i in (0..self.keys.len().div_ceil(ARITY)).rev() {
            self.sift_down(i);
        }
    }

    /// Sets the cost of `edge`, inserting it if absent.
    pub(crate) fn set(&mut self, edge: u32, cost: f64) {
        let key = Key { cost, edge };
        match self.pos[edge as usize] {
            ABSENT => {
                self.keys.push(key);
                let i = self.keys.len() - 1;
                self.pos[edge as usize] = i as u32;
                self.sift_up(i);
            }
            i => {
                let i = i as usize;
                let old = self.keys[i];
                self.keys[i] = key;
                if key.less(&old) {
                    self.sift_up(i);
                } else {
                    self.sift_down(i);
                }
            }
        }
    }

    /// Removes `edge`'s entry if present.
    pub(crate) fn remove(&mut self, edge: u32) {
        let i = self.pos[edge as usize];
        if i == ABSENT {
            return;
        }
        self.take(i as usize);
    }

    /// Removes and returns the cheapest entry.
    pub(crate) fn pop(&mut self) -> Option<(f64, u32)> {
        if self.keys.is_empty() {
            return None;
        }
        let k = self.take(0);
        Some((k.cost, k.edge))
    }

    fn take(&mut self, i: usize) -> Key {
        let last = self.keys.len() - 1;
        self.keys.swap(i, last);
        let k = self.keys.pop().expect("non-empty");
        self.pos[k.edge as usize] = ABSENT;
        if i < self.keys.len() {
            self.pos[self.keys[i].edge as usize] = i as u32;
            // The moved entry may belong above or below `i`.
            self.sift_up(i);
            self.sift_down(i);
        }
        k
    }

    fn sift_up(&mut self, mut i: usize) {
        let key = self.keys[i];
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if !key.less(&self.keys[parent]) {
                break;
            }
            self.keys[i] = self.keys[parent];
            self.pos[self.keys[i].edge as usize] = i as u32;
            i = parent;
        }
        self.keys[i] = key;
        self.pos[key.edge as usize] = i as u32;
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.keys.len();
        let key = self.keys[i];
        loop {
            let first = ARITY * i + 1;
            if first >= n {
                break;
            }
            let mut child = first;
            for c in first + 1..(first + ARITY).min(n) {
                if self.keys[c].less(&self.keys[child]) {
                    child = c;
                }
            }
            if !self.keys[child].less(&key) {
                break;
            }
            self.keys[i] = self.keys[child];
            self.pos[self.keys[i].edge as usize] = i as u32;
            i = child;
        }
        self.keys[i] = key;
        self.pos[key.edge as usize] = i as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::BTreeMap;

    /// Random sets, updates, removals and pops agree with a sorted map (the brute force).
    #[test]
    fn matches_a_sorted_map_under_random_operations() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 200u32;
        let mut heap = EdgeHeap::new(n as usize);
        let mut costs: BTreeMap<u32, f64> = BTreeMap::new();
        let initial: Vec<(f64, u32)> = (0..n)
            .step_by(2)
            .map(|e| ((rng.random_range(0..50) as f64), e))
            .collect();
        heap.rebuild(initial.iter().copied());
        costs.extend(initial.iter().map(|&(c, e)| (e, c)));
        for _ in 0..5000 {
            let e = rng.random_range(0..n);
            match rng.random_range(0..4) {
                0 | 1 => {
                    let c = rng.random_range(0..50) as f64;
                    heap.set(e, c);
                    costs.insert(e, c);
                }
                2 => {
                    heap.remove(e);
                    costs.remove(&e);
                }
                _ => {
                    let expected = costs
                        .iter()
                        .map(|(&e, &c)| (c, e))
                        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    assert_eq!(heap.pop(), expected);
                    if let Some((_, e)) = expected {
                        costs.remove(&e);
                    }
                }
            }
            assert_eq!(heap.len(), costs.len());
        }
    }
}
