//! A static kd-tree over 3-D points for k-nearest and nearest-one queries, with f32 coordinates
//! and allocation-free queries (the hot loop of the planar loss).
//!
//! Geometry is normalized into a sphere of radius about 1, where f32 (relative precision 6e-8)
//! finds the same neighbours as f64 except for near-ties; callers that need exact distances
//! recompute them in f64 from their own points. Results are ordered by (f32 squared distance,
//! index), a total order that does not depend on the traversal, so a query's answer is a pure
//! function of the tree's input and the query point.
//!
//! Kept over kiddo (the project's specified k-d tree crate) by `cargo bench -p benches --bench
//! knn`: the s2t moves of one planar-loss evaluation (49,905 samples of a 5,120-face source,
//! 50,000 cloud points, k = 10, one thread) take 126 ms with this tree and 219 ms with kiddo's
//! `ImmutableKdTree` (f32, buckets of 32): this tree 1.73× faster (a first run: 163 and 227 ms,
//! 1.39×; criterion medians on a loaded 2-core machine). Building takes 7.2 and 6.5 ms. Both
//! give the same moves (0 of 49,905 differ).

use glam::DVec3;

/// Points per leaf: small enough to prune well, large enough to amortize the descent. Measured
/// on the planar loss (one evaluation, callgrind, rabbit and moebius at 5000 faces): 24 takes
/// about 1% fewer instructions than 16 or 32, 8 and 20 1.5-5% more. The answers do not
/// depend on it.
const LEAF_SIZE: usize = 24;

/// Subtrees with at least this many points build their two halves in parallel.
const PARALLEL_BUILD: usize = 16_384;

/// `Node::axis` value of a leaf.
const LEAF: u8 = 3;

/// Relative slack on the pruning bound, so f32 rounding of the incremental cell distance never
/// skips a cell that holds a point tying with the current worst neighbour.
const PRUNE_SLACK: f32 = 1.0 + 1e-5;

/// One node, in preorder (the left child of an inner node is the next node).
#[derive(Debug, Clone, Copy)]
struct Node {
    /// First point of the node in tree order; for a leaf once the tree is built, its first slot
    /// in the padded leaf arrays (a multiple of [`LEAF_SIZE`]).
    start: u32,
    /// One past the last point (slot).
    end: u32,
    /// Split axis (0, 1, 2), or [`LEAF`].
    axis: u8,
    /// Left points have `coord[axis] ≤ split`, right points `≥ split`.
    split: f32,
    /// Index of the right child (inner nodes only).
    right: u32,
}

/// A kd-tree over a fixed set of points (median split on the widest axis, leaves of at most
/// [`LEAF_SIZE`] points). The point indices it returns are positions in the input slice.
#[derive(Debug, Clone, Default)]
pub(crate) struct PointTree {
    nodes: Vec<Node>,
    /// Point coordinates of the leaves, one array per axis, each leaf in a block of
    /// [`LEAF_SIZE`] slots padded with NaN (whose distances compare false with any bound), so a
    /// leaf's distances compute in fixed-width SIMD lanes.
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    /// Input index of each slot of the leaf blocks (`u32::MAX` for padding).
    leaf_ids: Vec<u32>,
    /// Input index of each point in tree order (no padding).
    ids: Vec<u32>,
    /// Point coordinates in input order (to turn a previous answer into a search bound).
    coords_by_id: Vec<[f32; 3]>,
}

/// The best neighbours of one query, sorted by (squared distance, index); a reusable buffer so
/// queries do not allocate. The previous answer also seeds the next query's search bound
/// (consecutive queries are usually close), which changes the work, never the answer.
#[derive(Debug, Clone, Default)]
pub(crate) struct Neighbours {
    best: Best,
    stack: SearchStack,
}

/// The `k` best neighbours found so far by a [`PointTree::nearest_n`] search.
///
/// Each neighbour is kept as one `u64` key, the f32 squared distance's bits above the index:
/// distances are never negative, so their bits order like the numbers and the keys order like
/// the pairs (ties broken by the smaller index) with a single comparison.
#[derive(Debug, Clone, Default)]
struct Best {
    keys: Vec<u64>,
    /// The tree slot of each key's point (see [`PointTree::slot_ids`]), in the keys' order.
    slots: Vec<u32>,
    k: usize,
    /// A key enters iff it is below this: the limit's (any index) until `k` are found, then the
    /// current `k`-th key.
    enter_below: u64,
    /// The squared distance of `enter_below`, for pruning (never below a distance that can
    /// still enter).
    bound: f32,
}

/// The sort key of `(d2, id)` (see [`Neighbours`]).
#[inline]
fn key(d2: f32, id: u32) -> u64 {
    ((d2.to_bits() as u64) << 32) | id as u64
}

impl Neighbours {
    /// The neighbours found by the last query: `(f32 squared distance, index)` pairs, nearest
    /// first.
    pub(crate) fn items(&self) -> impl ExactSizeIterator<Item = (f32, u32)> + '_ {
        self.best
            .keys
            .iter()
            .map(|&key| (f32::from_bits((key >> 32) as u32), key as u32))
    }

    /// The tree slot of each neighbour of [`Neighbours::items`], in the same order.
    pub(crate) fn slots(&self) -> &[u32] {
        &self.best.slots
    }
}

impl Best {
    /// Clears the buffer for a query of `k` neighbours known to lie within squared distance
    /// `limit` (not NaN).
    fn reset(&mut self, k: usize, limit: f32) {
        self.keys.clear();
        self.slots.clear();
        self.k = k;
        self.enter_below = key(limit, u32::MAX).saturating_add(1);
        self.bound = limit;
    }

    /// Inserts `(d2, id)`, held by tree slot `slot`, if it is among the `k` best so far (ties
    /// broken by smaller index).
    #[inline]
    fn offer(&mut self, d2: f32, id: u32, slot: u32) {
        let new = key(d2, id);
        if new >= self.enter_below {
            return;
        }
        if self.keys.len() < self.k {
            self.keys.push(new);
            self.slots.push(slot);
        }
        // Shift the worse keys up by one (dropping the last when full) and insert.
        let (keys, slots) = (&mut self.keys[..], &mut self.slots[..]);
        let mut pos = keys.len() - 1;
        while pos > 0 && keys[pos - 1] > new {
            keys[pos] = keys[pos - 1];
            slots[pos] = slots[pos - 1];
            pos -= 1;
        }
        keys[pos] = new;
        slots[pos] = slot;
        if keys.len() == self.k {
            self.enter_below = keys[self.k - 1];
            self.bound = f32::from_bits((self.enter_below >> 32) as u32);
        }
    }
}

/// Appends to `nodes` the subtree over `entries` (tree positions from `start`), in preorder
/// with absolute child indices. Large halves are built in parallel into their own vectors and
/// spliced in, which gives the same nodes as the serial recursion.
fn build(entries: &mut [([f32; 3], u32)], start: usize, nodes: &mut Vec<Node>) {
    let index = nodes.len();
    let count = entries.len();
    let mut node = Node {
        start: start as u32,
        end: (start + count) as u32,
        axis: LEAF,
        split: 0.0,
        right: 0,
    };
    if count <= LEAF_SIZE {
        nodes.push(node);
        return;
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    // Plain comparisons instead of `f32::min`/`max`, whose NaN handling the finite coordinates
    // do not need (a `−0`/`+0` tie may keep either zero: the extents, hence the axis, are the
    // same).
    for (c, _) in entries.iter() {
        for a in 0..3 {
            if c[a] < lo[a] {
                lo[a] = c[a];
            }
            if c[a] > hi[a] {
                hi[a] = c[a];
            }
        }
    }
    let extent = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    };
    let mid = count / 2;
    // Ties on the split coordinate may fall on either side: answers are a function of the
    // point set alone, and the selection is deterministic, so the tree is too. One comparator
    // per axis keeps the coordinate index a constant in the selection's inner loop.
    match axis {
        0 => entries.select_nth_unstable_by(mid, |a, b| coordinate_order(a.0[0], b.0[0])),
        1 => entries.select_nth_unstable_by(mid, |a, b| coordinate_order(a.0[1], b.0[1])),
        _ => entries.select_nth_unstable_by(mid, |a, b| coordinate_order(a.0[2], b.0[2])),
    };
    node.axis = axis as u8;
    node.split = entries[mid].0[axis];
    nodes.push(node);
    let (left, right) = entries.split_at_mut(mid);
    if count < PARALLEL_BUILD {
        build(left, start, nodes);
        nodes[index].right = nodes.len() as u32;
        build(right, start + mid, nodes);
        return;
    }
    let subtree = |entries: &mut [([f32; 3], u32)], start: usize| {
        let mut sub = Vec::with_capacity(2 * entries.len() / LEAF_SIZE + 1);
        build(entries, start, &mut sub);
        sub
    };
    let (left_nodes, right_nodes) =
        rayon::join(|| subtree(left, start), || subtree(right, start + mid));
    let right_index = index + 1 + left_nodes.len();
    nodes[index].right = right_index as u32;
    for (offset, sub) in [(index + 1, left_nodes), (right_index, right_nodes)] {
        nodes.extend(sub.into_iter().map(|mut n| {
            if n.axis != LEAF {
                n.right += offset as u32;
            }
            n
        }));
    }
}

/// The order of two coordinates of tree points (never NaN: the points are finite), with `−0`
/// and `+0` tied, which the median selection allows. Two float comparisons, cheaper than
/// `total_cmp`'s bit transform in the build's inner loop.
#[inline]
fn coordinate_order(a: f32, b: f32) -> std::cmp::Ordering {
    if a < b {
        std::cmp::Ordering::Less
    } else if a > b {
        std::cmp::Ordering::Greater
    } else {
        std::cmp::Ordering::Equal
    }
}

/// Bit `i` set iff `d2[i] ≤ bound` (never for NaN).
#[inline]
fn within(d2: &[f32; LEAF_SIZE], bound: f32) -> u32 {
    const _: () = assert!(LEAF_SIZE <= 32);
    let mut mask = 0;
    for (i, &d) in d2.iter().enumerate() {
        mask |= ((d <= bound) as u32) << i;
    }
    mask
}

#[inline]
fn to_f32(p: DVec3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

#[inline]
fn distance2(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

impl PointTree {
    /// Builds the tree over `points` (finite, fewer than 2³² — the callers check both).
    /// Deterministic: the same input gives the same tree.
    pub(crate) fn new(points: &[DVec3]) -> Self {
        let mut entries: Vec<([f32; 3], u32)> = points
            .iter()
            .enumerate()
            .map(|(i, &p)| (to_f32(p), i as u32))
            .collect();
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * points.len() / LEAF_SIZE + 1),
            ..Self::default()
        };
        if !entries.is_empty() {
            build(&mut entries, 0, &mut tree.nodes);
        }
        // Leaves into padded blocks, in tree order.
        let leaves = tree.nodes.iter().filter(|n| n.axis == LEAF).count();
        tree.xs = vec![f32::NAN; leaves * LEAF_SIZE];
        tree.ys = vec![f32::NAN; leaves * LEAF_SIZE];
        tree.zs = vec![f32::NAN; leaves * LEAF_SIZE];
        tree.leaf_ids = vec![u32::MAX; leaves * LEAF_SIZE];
        let mut slot = 0;
        for node in tree.nodes.iter_mut().filter(|n| n.axis == LEAF) {
            let (start, end) = (node.start as usize, node.end as usize);
            for (i, (c, id)) in entries[start..end].iter().enumerate() {
                tree.xs[slot + i] = c[0];
                tree.ys[slot + i] = c[1];
                tree.zs[slot + i] = c[2];
                tree.leaf_ids[slot + i] = *id;
            }
            node.start = slot as u32;
            node.end = (slot + end - start) as u32;
            slot += LEAF_SIZE;
        }
        tree.coords_by_id = points.iter().map(|&p| to_f32(p)).collect();
        tree.ids = entries.iter().map(|e| e.1).collect();
        tree
    }

    /// Input indices in tree order: a spatially coherent visiting order (points of a leaf are
    /// adjacent), which makes the hints of consecutive queries tight.
    pub(crate) fn spatial_order(&self) -> &[u32] {
        &self.ids
    }

    /// The input index held by each slot of the leaves (`u32::MAX` for padding), which
    /// [`Neighbours::slots`] refer to: a caller that lays out its per-point data in this order
    /// reads a query's neighbours from nearby memory.
    pub(crate) fn slot_ids(&self) -> &[u32] {
        &self.leaf_ids
    }

    /// Fills `neighbours` with the `k` nearest points of `query` (fewer if the tree is
    /// smaller), sorted by (f32 squared distance, index). `k = 0` or an empty tree gives
    /// nothing. The buffer's previous answer (any `k` distinct points of this tree) bounds the
    /// search.
    pub(crate) fn nearest_n(&self, query: DVec3, k: usize, neighbours: &mut Neighbours) {
        let Neighbours { best: found, stack } = neighbours;
        let q = to_f32(query);
        let mut limit = f32::INFINITY;
        if k > 0 && found.keys.len() == k {
            // The previous k neighbours all lie within `limit` of the new query. A plain
            // comparison instead of `f32::max`, which likewise leaves the limit as it is for a
            // NaN distance (a query beyond f32), without the extra NaN test.
            limit = 0.0;
            for &key in &found.keys {
                match self.coords_by_id.get(key as u32 as usize) {
                    Some(c) => {
                        let d2 = distance2(c, &q);
                        if d2 > limit {
                            limit = d2;
                        }
                    }
                    None => limit = f32::INFINITY,
                }
            }
        }
        found.reset(k, limit);
        if k == 0 || self.nodes.is_empty() {
            return;
        }
        let start = self.start_node(&q, limit);
        self.search(start, &q, found, stack);
    }

    /// The nearest point of `query` (ties: smaller index); `None` for an empty tree. `hint`, a
    /// point of this tree (e.g. the previous answer), bounds the search; `stack` is scratch
    /// space reused across queries.
    pub(crate) fn nearest_one(
        &self,
        query: DVec3,
        hint: Option<u32>,
        stack: &mut SearchStack,
    ) -> Option<u32> {
        if self.nodes.is_empty() {
            return None;
        }
        let q = to_f32(query);
        let limit = hint
            .and_then(|id| self.coords_by_id.get(id as usize))
            .map_or(f32::INFINITY, |c| distance2(c, &q));
        // Starts at (limit, u32::MAX): the hint itself always qualifies, so `best` is filled.
        let mut best = Nearest(limit, u32::MAX);
        let start = self.start_node(&q, limit);
        self.search(start, &q, &mut best, stack);
        Some(best.1)
    }

    /// The deepest node whose subtree holds every point within squared distance `limit` of `q`
    /// (`q` lies in its cell): the descent follows `q` while the split plane is farther than
    /// the limit. A point beyond the plane has an f32 squared distance of at least the plane's
    /// (rounding is monotone), so skipping the other side is exact, ties included; the search
    /// then starts there with zero cell offsets.
    fn start_node(&self, q: &[f32; 3], limit: f32) -> u32 {
        let mut node = 0;
        loop {
            let nd = self.nodes[node as usize];
            if nd.axis == LEAF {
                return node;
            }
            let diff = q[nd.axis as usize] - nd.split;
            // A NaN (non-finite query or limit) stops the descent too.
            let beyond = diff * diff > limit;
            if !beyond {
                return node;
            }
            node = if diff < 0.0 { node + 1 } else { nd.right };
        }
    }

    /// Squared distances from `q` to the slots of leaf `leaf` (NaN for padding).
    #[inline]
    fn leaf_distances(&self, leaf: Node, q: &[f32; 3]) -> [f32; LEAF_SIZE] {
        let block = leaf.start as usize..leaf.start as usize + LEAF_SIZE;
        let (xs, ys, zs) = (
            &self.xs[block.clone()],
            &self.ys[block.clone()],
            &self.zs[block],
        );
        let mut out = [0.0; LEAF_SIZE];
        for i in 0..LEAF_SIZE {
            let (dx, dy, dz) = (xs[i] - q[0], ys[i] - q[1], zs[i] - q[2]);
            out[i] = dx * dx + dy * dy + dz * dz;
        }
        out
    }

    /// Depth-first search of the subtree at `start` (whose cell holds `q`, so at distance 0):
    /// each inner node visits its child on `q`'s side first, then the other child if that
    /// cell's squared distance is within `found`'s bound (with [`PRUNE_SLACK`]) at that time;
    /// every visited leaf goes to `found`.
    ///
    /// The far children wait on a fixed stack instead of in recursive calls, whose entry,
    /// argument passing and exit cost more than the node test itself; the visiting order and
    /// every pruning decision are those of the recursion. A pending far child is pushed per
    /// inner level of the descent, and median splits halve the points per level, so a tree
    /// over fewer than 2³² points never holds more than [`MAX_PENDING`] of them. The stack is
    /// the caller's ([`SearchStack`]): the search reads only the slots it wrote.
    fn search<C: Collector>(
        &self,
        start: u32,
        q: &[f32; 3],
        found: &mut C,
        stack: &mut SearchStack,
    ) {
        let pending = &mut stack.0;
        let mut len = 0;
        let (mut node, mut off, mut rd) = (start, [0.0f32; 3], 0.0f32);
        loop {
            let nd = self.nodes[node as usize];
            if nd.axis != LEAF {
                let axis = nd.axis as usize;
                let diff = q[axis] - nd.split;
                let (near, far) = if diff < 0.0 {
                    (node + 1, nd.right)
                } else {
                    (nd.right, node + 1)
                };
                let far_rd = rd - off[axis] * off[axis] + diff * diff;
                // The bound never grows, so a far cell beyond it now is beyond it when its
                // turn comes: skipping it here makes the same decision sooner.
                if far_rd <= found.bound() * PRUNE_SLACK {
                    let mut far_off = off;
                    far_off[axis] = diff;
                    pending[len] = (far, far_off, far_rd);
                    len += 1;
                }
                node = near;
                continue;
            }
            let d2 = self.leaf_distances(nd, q);
            let ids = &self.leaf_ids[nd.start as usize..nd.start as usize + LEAF_SIZE];
            found.visit_leaf(&d2, ids, nd.start);
            // Resume at the latest pending far child that is still within the bound.
            loop {
                if len == 0 {
                    return;
                }
                len -= 1;
                let (far, far_off, far_rd) = pending[len];
                if far_rd <= found.bound() * PRUNE_SLACK {
                    (node, off, rd) = (far, far_off, far_rd);
                    break;
                }
            }
        }
    }
}

/// Most far children a [`PointTree::search`] keeps pending (see there).
const MAX_PENDING: usize = 32;

/// A far child waiting in a [`PointTree::search`]: (node, per-axis cell offsets, squared cell
/// distance).
type Pending = (u32, [f32; 3], f32);

/// The pending far children of a [`PointTree::search`], kept by the caller across queries.
/// Only the slots a search writes are read back by that search, so the array is filled once
/// when created instead of once per query (which cost more than a short search's pushes).
#[derive(Debug, Clone, Default)]
pub(crate) struct SearchStack([Pending; MAX_PENDING]);

/// What a [`PointTree::search`] collects from the leaves it visits.
trait Collector {
    /// Squared distance beyond which no point can be collected any more (prunes cells); never
    /// grows during a search.
    fn bound(&self) -> f32;

    /// Offers the points of one leaf: squared distances `d2` (NaN for padding) and input
    /// indices `ids` of its slots, the first of which is `first_slot`.
    fn visit_leaf(&mut self, d2: &[f32; LEAF_SIZE], ids: &[u32], first_slot: u32);
}

/// The single nearest point found so far, `(d2, id)` (ties: smaller index).
struct Nearest(f32, u32);

impl Collector for Nearest {
    #[inline]
    fn bound(&self) -> f32 {
        self.0
    }

    #[inline]
    fn visit_leaf(&mut self, d2: &[f32; LEAF_SIZE], ids: &[u32], _first_slot: u32) {
        let mut mask = within(d2, self.0);
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let id = ids[i];
            if d2[i] < self.0 || (d2[i] == self.0 && id < self.1) {
                (self.0, self.1) = (d2[i], id);
            }
        }
    }
}

impl Collector for Best {
    /// The squared distance a point must not exceed to enter: the limit until `k` are found,
    /// then the current `k`-th distance (never above the limit).
    #[inline]
    fn bound(&self) -> f32 {
        self.bound
    }

    #[inline]
    fn visit_leaf(&mut self, d2: &[f32; LEAF_SIZE], ids: &[u32], first_slot: u32) {
        let mut mask = within(d2, self.bound);
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            self.offer(d2[i], ids[i], first_slot + i as u32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn brute(points: &[DVec3], q: DVec3, k: usize) -> Vec<(f32, u32)> {
        let qf = to_f32(q);
        let mut all: Vec<(f32, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, &p)| (distance2(&to_f32(p), &qf), i as u32))
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        all.truncate(k);
        all
    }

    /// `n` random points in [-1, 1]³ with exact duplicates (a quarter) and a flat patch (a
    /// third at z = 0.25), which stress the tie order and degenerate cells.
    fn stress_points(rng: &mut ChaCha8Rng, n: usize) -> Vec<DVec3> {
        let mut points: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE)
            .collect();
        for i in 0..n / 4 {
            points[i] = points[n - 1 - i];
        }
        for p in points.iter_mut().take(n / 3) {
            p.z = 0.25;
        }
        points
    }

    #[test]
    fn matches_brute_force_in_f32_including_duplicates() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // One buffer and one stack across queries, k and trees: the previous answer seeds each
        // search bound (also when it comes from another tree, whose indices may be out of this
        // one's range), and stack slots left by earlier searches must not leak into later ones.
        let mut found = Neighbours::default();
        let mut stack = SearchStack::default();
        // 40 000 points exercise the parallel build; sizes up and down.
        for n in [2000usize, 1, 40_000, 13, 100, 5] {
            let points = stress_points(&mut rng, n);
            let tree = PointTree::new(&points);
            let mut previous = None;
            for _ in 0..50 {
                let q = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.4 - DVec3::ONE;
                for k in [1, 10, 40] {
                    tree.nearest_n(q, k, &mut found);
                    assert_eq!(
                        found.items().collect::<Vec<_>>(),
                        brute(&points, q, k),
                        "n {n} k {k}"
                    );
                    // Each neighbour's slot holds that neighbour.
                    assert_eq!(found.slots().len(), found.items().len());
                    for ((_, id), &slot) in found.items().zip(found.slots()) {
                        assert_eq!(tree.slot_ids()[slot as usize], id);
                    }
                }
                for hint in [None, previous, Some(0)] {
                    assert_eq!(
                        tree.nearest_one(q, hint, &mut stack),
                        Some(brute(&points, q, 1)[0].1),
                        "nearest one, n {n}"
                    );
                }
                previous = tree.nearest_one(q, None, &mut stack);
            }
        }
    }

    #[test]
    fn coherent_queries_match_brute_force() {
        // Queries on and next to the points, in the tree's spatial order: the previous answer
        // gives tight bounds, so the searches start deep in the tree (`start_node`).
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let n = 3000;
        let points = stress_points(&mut rng, n);
        let tree = PointTree::new(&points);
        let mut found = Neighbours::default();
        let mut stack = SearchStack::default();
        let mut hint = None;
        for (step, &id) in tree.spatial_order().iter().enumerate().step_by(3) {
            let jitter = if step % 2 == 0 { 0.0 } else { 1e-3 };
            let q =
                points[id as usize] + DVec3::new(rng.random(), rng.random(), rng.random()) * jitter;
            for k in [1, 10] {
                tree.nearest_n(q, k, &mut found);
                assert_eq!(found.items().collect::<Vec<_>>(), brute(&points, q, k));
            }
            let nearest = tree.nearest_one(q, hint, &mut stack);
            assert_eq!(nearest, Some(brute(&points, q, 1)[0].1));
            hint = nearest;
        }
    }

    #[test]
    fn within_sets_one_bit_per_slot_at_or_below_the_bound() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..200 {
            let d2: [f32; LEAF_SIZE] = std::array::from_fn(|_| match rng.random_range(0..4) {
                0 => f32::NAN,
                1 => 0.5,
                _ => rng.random(),
            });
            let plain = (0..LEAF_SIZE)
                .filter(|&i| d2[i] <= 0.5)
                .fold(0u32, |m, i| m | 1 << i);
            assert_eq!(within(&d2, 0.5), plain);
        }
    }

    /// Inner levels on the deepest root-to-leaf path of `tree`'s subtree at `node`.
    fn inner_depth(tree: &PointTree, node: u32) -> usize {
        let nd = tree.nodes[node as usize];
        if nd.axis == LEAF {
            return 0;
        }
        1 + inner_depth(tree, node + 1).max(inner_depth(tree, nd.right))
    }

    #[test]
    fn searches_keep_fewer_far_children_pending_than_the_stack_holds() {
        // One pending far child per inner level at most; median splits keep the depth near
        // log2(n / LEAF_SIZE), far below the stack for the sizes the losses use.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let points = stress_points(&mut rng, 200_000);
        let tree = PointTree::new(&points);
        let depth = inner_depth(&tree, 0);
        assert!(depth <= 15, "depth {depth}");
        assert!(depth < MAX_PENDING);
    }

    #[test]
    fn empty_tree_and_zero_k_give_nothing() {
        let tree = PointTree::new(&[]);
        assert_eq!(
            tree.nearest_one(DVec3::ZERO, Some(3), &mut SearchStack::default()),
            None
        );
        let tree = PointTree::new(&[DVec3::X]);
        let mut found = Neighbours::default();
        tree.nearest_n(DVec3::ZERO, 0, &mut found);
        assert_eq!(found.items().len(), 0);
        tree.nearest_n(DVec3::ZERO, 3, &mut found);
        assert_eq!(found.items().collect::<Vec<_>>(), [(1.0, 0)]);
    }
}
