//! A bounding volume hierarchy over the triangles of plain buffers.
//!
//! Naming: a *face* is an index into the `triangles` buffer the tree was built from; a *node* is
//! an entry of the flat node array (root at 0, the two children of an inner node stored next to
//! each other after their parent); a *leaf* lists at most [`MAX_LEAF_FACES`] faces.
//!
//! Built with a binned surface-area heuristic over face centroids (median split when the
//! centroids cannot be separated). The tree owns copies of the buffers, so queries take only
//! the query geometry; [`TriangleBvh::refit`] updates it after vertices moved. Every traversal
//! visits nodes in a fixed order (the parallel pair search splits its walk in a fixed way), so
//! every answer is deterministic, whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::aabb::Aabb;
use super::point_triangle::{closest_point_on_triangle, ray_triangle};

/// Largest number of faces in a leaf.
pub const MAX_LEAF_FACES: usize = 4;

/// Number of SAH bins per axis.
const BIN_COUNT: usize = 16;

/// Node pairs [`TriangleBvh::overlapping_pairs_parallel`] unfolds before it hands them to threads.
const PARALLEL_PAIR_TASKS: usize = 64;

/// The closest surface point found by [`TriangleBvh::closest_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Face containing the point.
    pub face: u32,
    /// The closest point.
    pub point: DVec3,
    /// Squared distance from the query to `point`.
    pub distance_squared: f64,
    /// Barycentric coordinates of `point` in `face` (corner order of the face).
    pub barycentric: [f64; 3],
}

/// The answer of [`TriangleBvh::closest_point_certified`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CertifiedClosest {
    /// The closest point (as [`TriangleBvh::closest_point_within`] gives it).
    pub closest: ClosestPoint,
    /// A lower bound on the squared distance from the query to every face of the tree other than
    /// `closest.face` (`f64::INFINITY` when there is no other face). Computed with the same
    /// floating-point distances as the search, so callers should keep a small relative margin.
    pub others_squared: f64,
}

/// The nearest hit found by [`TriangleBvh::ray_cast`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Face hit.
    pub face: u32,
    /// Ray parameter of the hit: the point is `origin + t·dir`.
    pub t: f64,
    /// Barycentric coordinates of the hit in `face` (corner order of the face).
    pub barycentric: [f64; 3],
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    aabb: Aabb,
    /// Leaf: first index into `faces`. Inner node: index of the first child.
    start: u32,
    /// Leaf: number of faces (≥ 1). Inner node: 0.
    count: u32,
}

impl Node {
    /// A node not filled in yet (the serial build allocates both children before visiting them).
    const UNSET: Node = Node {
        aabb: Aabb::EMPTY,
        start: 0,
        count: 0,
    };

    fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Triangle BVH over `positions` (#V) and `triangles` (#F).
///
/// Faces with an index out of range or a non-finite corner at build time are left out of the
/// tree and never reported. Degenerate (zero-area) faces stay in and are handled by every query.
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    nodes: Vec<Node>,
    /// Faces in leaf order.
    faces: Vec<u32>,
}

impl TriangleBvh {
    /// Builds the tree.
    ///
    /// Inputs: `positions` (#V), `triangles` (#F, indices into `positions`). Output: a tree over
    /// every face whose indices are in range and whose corners are finite. O(#F log #F); the
    /// upper levels build their halves in parallel (the same tree whatever the thread count).
    pub fn build(positions: &[DVec3], triangles: &[[u32; 3]]) -> TriangleBvh {
        let n_vertices = positions.len();
        let mut faces: Vec<u32> = Vec::with_capacity(triangles.len());
        let mut boxes = vec![Aabb::EMPTY; triangles.len()];
        let mut centroids = vec![DVec3::ZERO; triangles.len()];
        for (f, tri) in triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= n_vertices) {
                continue;
            }
            let corners = tri.map(|i| positions[i as usize]);
            if !corners.iter().all(|p| p.is_finite()) {
                continue;
            }
            boxes[f] = Aabb::from_triangle(corners);
            centroids[f] = boxes[f].center();
            faces.push(f as u32);
        }
        let mut bvh = TriangleBvh {
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            nodes: Vec::new(),
            faces,
        };
        if !bvh.faces.is_empty() {
            bvh.nodes = build_subtree(&mut bvh.faces, 0, &boxes, &centroids);
        }
        bvh
    }

    /// Updates the boxes after the vertices moved; the tree shape is kept (same topology).
    ///
    /// Input: `positions` (#V), the moved vertices, same length as at build time. A face whose
    /// corners became non-finite gets a box that overlaps nothing and is no longer reported.
    ///
    /// # Panics
    /// If `positions.len()` differs from the length the tree was built with (a caller bug).
    pub fn refit(&mut self, positions: &[DVec3]) {
        assert_eq!(
            positions.len(),
            self.positions.len(),
            "TriangleBvh::refit needs the same vertex count as build"
        );
        self.positions.copy_from_slice(positions);
        for n in (0..self.nodes.len()).rev() {
            let node = self.nodes[n];
            let (start, count) = (node.start as usize, node.count as usize);
            self.nodes[n].aabb = if node.is_leaf() {
                self.faces[start..start + count]
                    .iter()
                    .fold(Aabb::EMPTY, |b, &f| b.union(&self.face_aabb(f)))
            } else {
                self.nodes[start].aabb.union(&self.nodes[start + 1].aabb)
            };
        }
    }

    /// The vertex buffer the tree currently describes (#V).
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// The triangle buffer the tree was built from (#F).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of faces in the tree (faces left out at build time are not counted).
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Box of all faces in the tree; `None` for an empty tree.
    pub fn aabb(&self) -> Option<Aabb> {
        self.nodes.first().map(|n| n.aabb)
    }

    /// Corners of face `f`.
    ///
    /// # Panics
    /// If `f` is not a face of the tree (index out of range of the build buffers).
    pub fn corners(&self, f: u32) -> [DVec3; 3] {
        self.triangles[f as usize].map(|i| self.positions[i as usize])
    }

    fn face_aabb(&self, f: u32) -> Aabb {
        Aabb::from_triangle(self.corners(f))
    }

    fn leaf_faces(&self, node: &Node) -> &[u32] {
        &self.faces[node.start as usize..(node.start + node.count) as usize]
    }

    /// Closest point on the surface to `p`.
    ///
    /// Output: `None` only for an empty tree. Ties in distance go to the smaller face index.
    pub fn closest_point(&self, p: DVec3) -> Option<ClosestPoint> {
        self.closest_point_impl(p, f64::INFINITY).map(|c| c.closest)
    }

    /// Closest point on the surface to `p` if it lies within distance `max_distance` (inclusive).
    ///
    /// Faster than [`TriangleBvh::closest_point`] for small radii, since farther nodes are
    /// never opened.
    pub fn closest_point_within(&self, p: DVec3, max_distance: f64) -> Option<ClosestPoint> {
        self.closest_point_certified(p, max_distance)
            .map(|c| c.closest)
    }

    /// [`TriangleBvh::closest_point_within`], together with a lower bound on the distance from
    /// `p` to every *other* face of the tree, gathered for free during the search: the smallest
    /// of the squared distances of the other faces it measured and of the boxes of the nodes it
    /// did not open. A caller whose query point moves by `δ` knows that no other face comes
    /// closer than `√others_squared − δ`, so while face `closest.face` stays closer than that,
    /// [`TriangleBvh::closest_point_on_face`] gives the same answer as a new search.
    pub fn closest_point_certified(&self, p: DVec3, max_distance: f64) -> Option<CertifiedClosest> {
        if max_distance.is_nan() || max_distance < 0.0 {
            return None;
        }
        self.closest_point_impl(p, max_distance * max_distance)
    }

    /// The point of face `f` closest to `p`, computed exactly as the searches compute it for that
    /// face (so it is bit-identical to their answer whenever they return `f`).
    ///
    /// # Panics
    /// If `f` is not a face of the tree (index out of range of the build buffers).
    pub fn closest_point_on_face(&self, p: DVec3, f: u32) -> ClosestPoint {
        let (point, barycentric) = closest_point_on_triangle(p, self.corners(f));
        ClosestPoint {
            face: f,
            point,
            distance_squared: p.distance_squared(point),
            barycentric,
        }
    }

    fn closest_point_impl(&self, p: DVec3, limit_d2: f64) -> Option<CertifiedClosest> {
        let mut best: Option<ClosestPoint> = None;
        let mut best_d2 = limit_d2;
        // The smallest squared distance of a face measured but not (or no longer) the best, and
        // of a node box not opened: a lower bound for every face but the best.
        let mut others_d2 = f64::INFINITY;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        let root = self.nodes.first()?;
        stack.push((0, root.aabb.distance_squared(p)));
        while let Some((n, box_d2)) = stack.pop() {
            if box_d2 > best_d2 {
                others_d2 = others_d2.min(box_d2);
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.is_leaf() {
                for &f in self.leaf_faces(node) {
                    let (point, barycentric) = closest_point_on_triangle(p, self.corners(f));
                    let d2 = p.distance_squared(point);
                    let better = match best {
                        None => d2 <= best_d2,
                        Some(b) => d2 < best_d2 || (d2 == best_d2 && f < b.face),
                    };
                    if better {
                        if best.is_some() {
                            others_d2 = others_d2.min(best_d2);
                        }
                        best_d2 = d2;
                        best = Some(ClosestPoint {
                            face: f,
                            point,
                            distance_squared: d2,
                            barycentric,
                        });
                    } else {
                        others_d2 = others_d2.min(d2);
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let dl = self.nodes[l as usize].aabb.distance_squared(p);
                let dr = self.nodes[r as usize].aabb.distance_squared(p);
                // Push the farther child first so the nearer one is opened first; children
                // beyond the best distance so far are never pushed.
                let (near, far) = if dl <= dr {
                    ((l, dl), (r, dr))
                } else {
                    ((r, dr), (l, dl))
                };
                if far.1 <= best_d2 {
                    stack.push(far);
                } else {
                    others_d2 = others_d2.min(far.1);
                }
                if near.1 <= best_d2 {
                    stack.push(near);
                } else {
                    others_d2 = others_d2.min(near.1);
                }
            }
        }
        best.map(|closest| CertifiedClosest {
            closest,
            others_squared: others_d2,
        })
    }

    /// Nearest hit of the ray `origin + t·dir` with `t ∈ (0, t_max]`.
    ///
    /// `dir` need not be unit length (`t` is in units of `dir`). Edges count as inside, so a ray
    /// through a shared edge or vertex hits; ties in `t` go to the smaller face index.
    pub fn ray_cast(&self, origin: DVec3, dir: DVec3, t_max: f64) -> Option<RayHit> {
        let root = self.nodes.first()?;
        let ray = SlabRay::new(origin, dir);
        let mut best: Option<RayHit> = None;
        let mut best_t = t_max;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        if let Some(t) = ray.enter(&root.aabb, best_t) {
            stack.push((0, t));
        }
        while let Some((n, t_enter)) = stack.pop() {
            if t_enter > best_t {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.is_leaf() {
                for &f in self.leaf_faces(node) {
                    let Some((t, barycentric)) = ray_triangle(origin, dir, self.corners(f)) else {
                        continue;
                    };
                    let better = match best {
                        None => t <= best_t,
                        Some(b) => t < best_t || (t == best_t && f < b.face),
                    };
                    if better {
                        best_t = t;
                        best = Some(RayHit {
                            face: f,
                            t,
                            barycentric,
                        });
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let tl = ray.enter(&self.nodes[l as usize].aabb, best_t);
                let tr = ray.enter(&self.nodes[r as usize].aabb, best_t);
                match (tl, tr) {
                    (Some(tl), Some(tr)) if tl <= tr => {
                        stack.push((r, tr));
                        stack.push((l, tl));
                    }
                    (Some(tl), Some(tr)) => {
                        stack.push((l, tl));
                        stack.push((r, tr));
                    }
                    (Some(tl), None) => stack.push((l, tl)),
                    (None, Some(tr)) => stack.push((r, tr)),
                    (None, None) => {}
                }
            }
        }
        best
    }

    /// Every hit of the ray `origin + t·dir` with `t ∈ (0, t_max]`, sorted by `(t, face)`.
    ///
    /// Same hit rule as [`TriangleBvh::ray_cast`]; a ray through a shared edge reports each
    /// face it touches.
    pub fn ray_cast_all(&self, origin: DVec3, dir: DVec3, t_max: f64) -> Vec<RayHit> {
        let mut hits = Vec::new();
        let Some(root) = self.nodes.first() else {
            return hits;
        };
        let ray = SlabRay::new(origin, dir);
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        if ray.enter(&root.aabb, t_max).is_some() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.is_leaf() {
                for &f in self.leaf_faces(node) {
                    if let Some((t, barycentric)) = ray_triangle(origin, dir, self.corners(f))
                        && t <= t_max
                    {
                        hits.push(RayHit {
                            face: f,
                            t,
                            barycentric,
                        });
                    }
                }
            } else {
                for child in [node.start + 1, node.start] {
                    if ray.enter(&self.nodes[child as usize].aabb, t_max).is_some() {
                        stack.push(child);
                    }
                }
            }
        }
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.face.cmp(&b.face)));
        hits
    }

    /// Calls `visit(face)` for every face whose box overlaps the closed box `aabb`, in a fixed
    /// order.
    pub fn faces_in_aabb(&self, aabb: &Aabb, mut visit: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.aabb.overlaps(aabb) {
                continue;
            }
            if node.is_leaf() {
                for &f in self.leaf_faces(node) {
                    if self.face_aabb(f).overlaps(aabb) {
                        visit(f);
                    }
                }
            } else {
                stack.push(node.start + 1);
                stack.push(node.start);
            }
        }
    }

    /// Calls `visit(i, j)` with `i < j` once for every pair of distinct faces whose boxes
    /// overlap (the broad phase of self-intersection), in a fixed order.
    pub fn overlapping_pairs(&self, mut visit: impl FnMut(u32, u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<(u32, u32)> = vec![(0, 0)];
        while let Some(task) = stack.pop() {
            self.pair_step(task, &mut stack, &mut visit);
        }
    }

    /// The pairs of [`TriangleBvh::overlapping_pairs`], as `(i, j)` with `i < j`, found in
    /// parallel: the top of the traversal is unfolded breadth first into at least
    /// [`PARALLEL_PAIR_TASKS`] node pairs, which rayon's threads then walk depth first. The
    /// order is fixed (the unfolding's own pairs, then each task's in task order), whatever
    /// the thread count; it is not the order of `overlapping_pairs`.
    pub fn overlapping_pairs_parallel(&self) -> Vec<(u32, u32)> {
        if self.nodes.is_empty() {
            return Vec::new();
        }
        let mut pairs = Vec::new();
        let mut tasks = vec![(0, 0)];
        while !tasks.is_empty() && tasks.len() < PARALLEL_PAIR_TASKS {
            let mut next = Vec::with_capacity(4 * tasks.len());
            for &task in &tasks {
                self.pair_step(task, &mut next, &mut |i, j| pairs.push((i, j)));
            }
            tasks = next;
        }
        let found: Vec<Vec<(u32, u32)>> = tasks
            .par_iter()
            .map(|&task| {
                let mut found = Vec::new();
                let mut stack = vec![task];
                while let Some(task) = stack.pop() {
                    self.pair_step(task, &mut stack, &mut |i, j| found.push((i, j)));
                }
                found
            })
            .collect();
        pairs.extend(found.into_iter().flatten());
        pairs
    }

    /// One step of the pair traversal: node pair `(a, b)` (`a == b` for the pairs within one
    /// node) either reports its leaves' overlapping face pairs or pushes the node pairs it
    /// opens into (in the order a stack pops them left first).
    fn pair_step(
        &self,
        (a, b): (u32, u32),
        tasks: &mut Vec<(u32, u32)>,
        visit: &mut impl FnMut(u32, u32),
    ) {
        let mut emit = |f: u32, g: u32| {
            if self.face_aabb(f).overlaps(&self.face_aabb(g)) {
                visit(f.min(g), f.max(g));
            }
        };
        let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
        if a == b {
            if na.is_leaf() {
                let faces = self.leaf_faces(na);
                for i in 0..faces.len() {
                    for j in i + 1..faces.len() {
                        emit(faces[i], faces[j]);
                    }
                }
            } else {
                let (l, r) = (na.start, na.start + 1);
                tasks.push((l, r));
                tasks.push((r, r));
                tasks.push((l, l));
            }
            return;
        }
        if !na.aabb.overlaps(&nb.aabb) {
            return;
        }
        match (na.is_leaf(), nb.is_leaf()) {
            (true, true) => {
                for &f in self.leaf_faces(na) {
                    for &g in self.leaf_faces(nb) {
                        emit(f, g);
                    }
                }
            }
            (false, true) => {
                tasks.push((na.start + 1, b));
                tasks.push((na.start, b));
            }
            (true, false) => {
                tasks.push((a, nb.start + 1));
                tasks.push((a, nb.start));
            }
            (false, false) => {
                // Open the larger box.
                if na.aabb.half_area() >= nb.aabb.half_area() {
                    tasks.push((na.start + 1, b));
                    tasks.push((na.start, b));
                } else {
                    tasks.push((a, nb.start + 1));
                    tasks.push((a, nb.start));
                }
            }
        }
    }
}

/// Ranges of at least this many faces build their two halves in parallel.
const PARALLEL_BUILD: usize = 4096;

/// The nodes of the subtree over `faces` (positions `first_face..` of the tree's face order), its
/// root first. Layout, as a depth-first build that allocates both children of a node together
/// makes it: `[root][left child][right child][left's descendants][right's descendants]`, inner
/// nodes pointing at their first child by absolute index within the returned vector. Large
/// ranges build their halves in parallel and splice them in, which gives the same nodes as
/// the serial build (the split depends on the faces only), so the tree does not depend on the
/// number of threads.
fn build_subtree(
    faces: &mut [u32],
    first_face: usize,
    boxes: &[Aabb],
    centroids: &[DVec3],
) -> Vec<Node> {
    if faces.len() < PARALLEL_BUILD {
        return build_serial(faces, first_face, boxes, centroids);
    }
    let (aabb, centroid_box) = bounds(faces, boxes, centroids);
    let mid = split(faces, boxes, centroids, &centroid_box);
    let (left, right) = faces.split_at_mut(mid);
    let (left, right) = rayon::join(
        || build_subtree(left, first_face, boxes, centroids),
        || build_subtree(right, first_face + mid, boxes, centroids),
    );
    // The two roots go to 1 and 2. Node `i ≥ 1` of `left` goes to `i + 2` (after the root and
    // the pair), node `i ≥ 1` of `right` to `i + left.len() + 1` (after all of left's), so
    // every inner node's child index (never a root: always `≥ 1`) shifts by the same amount.
    let shift = |node: Node, by: usize| Node {
        start: if node.is_leaf() {
            node.start
        } else {
            node.start + by as u32
        },
        ..node
    };
    let (left_by, right_by) = (2, left.len() + 1);
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node {
        aabb,
        start: 1,
        count: 0,
    });
    nodes.push(shift(left[0], left_by));
    nodes.push(shift(right[0], right_by));
    nodes.extend(left[1..].iter().map(|&n| shift(n, left_by)));
    nodes.extend(right[1..].iter().map(|&n| shift(n, right_by)));
    nodes
}

/// [`build_subtree`] on one thread: an explicit stack, left child first.
fn build_serial(
    faces: &mut [u32],
    first_face: usize,
    boxes: &[Aabb],
    centroids: &[DVec3],
) -> Vec<Node> {
    let mut nodes = Vec::with_capacity(2 * faces.len() / MAX_LEAF_FACES + 1);
    nodes.push(Node::UNSET);
    let mut stack = vec![(0usize, 0usize, faces.len())];
    while let Some((node, start, end)) = stack.pop() {
        let range = &mut faces[start..end];
        let (aabb, centroid_box) = bounds(range, boxes, centroids);
        nodes[node].aabb = aabb;
        if range.len() <= MAX_LEAF_FACES {
            nodes[node].start = (first_face + start) as u32;
            nodes[node].count = range.len() as u32;
            continue;
        }
        let mid = start + split(range, boxes, centroids, &centroid_box);
        let first_child = nodes.len();
        nodes.extend([Node::UNSET; 2]);
        nodes[node].start = first_child as u32;
        nodes[node].count = 0;
        stack.push((first_child + 1, mid, end));
        stack.push((first_child, start, mid));
    }
    nodes
}

/// The box of `faces` and the box of their centroids.
fn bounds(faces: &[u32], boxes: &[Aabb], centroids: &[DVec3]) -> (Aabb, Aabb) {
    let mut aabb = Aabb::EMPTY;
    let mut centroid_box = Aabb::EMPTY;
    for &f in faces {
        aabb = aabb.union(&boxes[f as usize]);
        centroid_box.grow(centroids[f as usize]);
    }
    (aabb, centroid_box)
}

/// Reorders `faces` so that `faces[..k]` and `faces[k..]` are the two children; returns `k`
/// with `0 < k < faces.len()`.
fn split(faces: &mut [u32], boxes: &[Aabb], centroids: &[DVec3], centroid_box: &Aabb) -> usize {
    let extent = centroid_box.extent();
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, last bin of the left side)
    for axis in 0..3 {
        if extent[axis].is_nan() || extent[axis] <= 0.0 {
            continue;
        }
        let lo = centroid_box.min[axis];
        let to_bin = BIN_COUNT as f64 / extent[axis];
        let bin_of = |f: u32| -> usize {
            (((centroids[f as usize][axis] - lo) * to_bin) as usize).min(BIN_COUNT - 1)
        };
        let mut bin_boxes = [Aabb::EMPTY; BIN_COUNT];
        let mut bin_counts = [0usize; BIN_COUNT];
        for &f in faces.iter() {
            let b = bin_of(f);
            bin_boxes[b] = bin_boxes[b].union(&boxes[f as usize]);
            bin_counts[b] += 1;
        }
        // Sweep from the right to get the cost of every right side.
        let mut right_cost = [0.0; BIN_COUNT];
        let (mut acc_box, mut acc_count) = (Aabb::EMPTY, 0usize);
        for b in (1..BIN_COUNT).rev() {
            acc_box = acc_box.union(&bin_boxes[b]);
            acc_count += bin_counts[b];
            right_cost[b] = acc_box.half_area() * acc_count as f64;
        }
        let (mut acc_box, mut acc_count) = (Aabb::EMPTY, 0usize);
        for b in 0..BIN_COUNT - 1 {
            acc_box = acc_box.union(&bin_boxes[b]);
            acc_count += bin_counts[b];
            if acc_count == 0 || acc_count == faces.len() {
                continue;
            }
            let cost = acc_box.half_area() * acc_count as f64 + right_cost[b + 1];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    if let Some((_, axis, last_left_bin)) = best {
        let lo = centroid_box.min[axis];
        let to_bin = BIN_COUNT as f64 / extent[axis];
        let goes_left = |f: u32| {
            (((centroids[f as usize][axis] - lo) * to_bin) as usize).min(BIN_COUNT - 1)
                <= last_left_bin
        };
        let k = partition_in_place(faces, goes_left);
        if k > 0 && k < faces.len() {
            return k;
        }
    }
    // Centroids cannot be separated: split the (deterministically ordered) list in half.
    faces.len() / 2
}

/// Stable-enough in-place partition: moves the faces for which `left` holds to the front and
/// returns their count. Deterministic (depends only on the input order).
fn partition_in_place(faces: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut k = 0;
    for i in 0..faces.len() {
        if left(faces[i]) {
            faces.swap(i, k);
            k += 1;
        }
    }
    k
}

/// A ray prepared for slab tests against boxes.
struct SlabRay {
    origin: DVec3,
    dir: DVec3,
    inv_dir: DVec3,
}

impl SlabRay {
    fn new(origin: DVec3, dir: DVec3) -> SlabRay {
        SlabRay {
            origin,
            dir,
            inv_dir: dir.recip(),
        }
    }

    /// Entry parameter of the ray into the closed box if the ray meets it within `(0, t_max]`.
    /// The exit parameter is padded by a few ulps (Ize 2013) so hits on box faces are not lost.
    fn enter(&self, aabb: &Aabb, t_max: f64) -> Option<f64> {
        let mut t_in = 0.0_f64;
        let mut t_out = t_max;
        for axis in 0..3 {
            let o = self.origin[axis];
            if self.dir[axis] == 0.0 {
                if o < aabb.min[axis] || o > aabb.max[axis] {
                    return None;
                }
                continue;
            }
            let inv = self.inv_dir[axis];
            let t0 = (aabb.min[axis] - o) * inv;
            let t1 = (aabb.max[axis] - o) * inv;
            let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
            t_in = t_in.max(near);
            t_out = t_out.min(far * (1.0 + 4.0 * f64::EPSILON));
        }
        (t_in <= t_out).then_some(t_in)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel build splices its halves into exactly the nodes and face order of the
    /// one-thread build (a wrong offset would point an inner node at another subtree).
    #[test]
    fn parallel_build_gives_the_serial_tree() {
        // A pseudo-random soup of small triangles, large enough for two levels of splicing.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 5 * PARALLEL_BUILD;
        let mut boxes = Vec::with_capacity(n);
        let mut centroids = Vec::with_capacity(n);
        for _ in 0..n {
            let c = DVec3::new(next(), next(), next());
            let corners = [
                c,
                c + 0.01 * DVec3::new(next(), next(), 0.0),
                c + 0.01 * DVec3::Z,
            ];
            let b = Aabb::from_triangle(corners);
            centroids.push(b.center());
            boxes.push(b);
        }
        let mut parallel_faces: Vec<u32> = (0..n as u32).collect();
        let mut serial_faces = parallel_faces.clone();
        let parallel = build_subtree(&mut parallel_faces, 0, &boxes, &centroids);
        let serial = build_serial(&mut serial_faces, 0, &boxes, &centroids);
        // A real tree: at least one leaf per MAX_LEAF_FACES faces.
        assert!(parallel.len() > n / MAX_LEAF_FACES);
        assert_eq!(parallel_faces, serial_faces);
        assert_eq!(parallel, serial);
    }
}
