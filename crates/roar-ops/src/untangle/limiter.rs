//! The step limiter: shortens optimizer steps that would create a self-intersection.

use glam::DVec3;
use rayon::prelude::*;
use roar_mesh::spatial::{Aabb, TriangleBvh};
use roar_mesh::spatial::{PreparedFace, certainly_apart, faces_intersect_filtered as faces_cross};

/// Options of [`limit_steps`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimiterOptions {
    /// Halve a rejected move at most this many times before cancelling it (default 3).
    pub max_halvings: u32,
}

impl Default for LimiterOptions {
    fn default() -> Self {
        Self { max_halvings: 3 }
    }
}

/// Outcome of [`limit_steps`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimiterStats {
    /// Vertices whose proposed position differed from the old one.
    pub moved: usize,
    /// Moves accepted only after halving.
    pub shortened: usize,
    /// Moves cancelled (vertex kept at its old position).
    pub cancelled: usize,
    /// Exact triangle–triangle tests run (after the box and adjacency filters).
    pub pair_tests: usize,
    /// Check passes run (1 when no move had to be shortened).
    pub passes: usize,
}

/// Shortens optimizer steps that would create a self-intersection.
///
/// Inputs: `before` (#V) positions of an intersection-free mesh, `proposed` (#V) the positions
/// after the step (overwritten with the accepted ones), `triangles` (#F). Output: `proposed`
/// holds, per vertex, either the full step, the step halved `k ≤ max_halvings` times, or the
/// old position; the result is intersection-free whenever `before` was. The result does not
/// depend on the number of threads.
///
/// Method, in passes: every face with a moved corner ("changed") is tested exactly against every
/// face whose current box overlaps its own. Unchanged pairs need no test: they are as in
/// `before`. Every corner of a face in an intersecting pair that still differs from `before`
/// has its step halved (or, after `max_halvings` halvings, cancelled), and the next pass
/// re-tests only the faces those vertices touch. An intersecting pair always has a moved corner
/// (two unchanged faces do not intersect), so every pass shortens some step and the loop ends
/// after at most `max_halvings + 1` passes per vertex.
///
/// Broad phase, once per call: a corner only ever sits on the segment from its old position to
/// its proposed one, so a face's box in every pass lies inside its swept box (the box of its
/// old and proposed corners). The pairs of overlapping swept boxes ([`swept_candidates`]) are
/// therefore all the pairs a pass may need; a pass keeps those whose current boxes overlap.
///
/// Cost: one BVH build and pair search over the swept boxes, then per pass, for the changed
/// faces, a walk over their candidates and the exact tests (most pairs are settled by
/// `certainly_apart`, the rest by `roar_mesh::spatial::faces_intersect_filtered`). The pair
/// search and the tests run on rayon's threads; the bookkeeping between them (candidate rows,
/// dirty faces, shortening) runs on one. Invalid indices are ignored, and so are faces with a
/// non-finite old corner; non-finite proposals are cancelled.
pub fn limit_steps(
    before: &[DVec3],
    proposed: &mut [DVec3],
    triangles: &[[u32; 3]],
    options: &LimiterOptions,
) -> LimiterStats {
    let mut stats = LimiterStats::default();
    let n = before.len().min(proposed.len());
    // Halvings applied so far per vertex; `u32::MAX` marks a cancelled (or unmoved) vertex.
    let mut halvings = vec![u32::MAX; n];
    let mut current: Vec<DVec3> = before[..n].to_vec();
    for v in 0..n {
        if proposed[v] == before[v] {
            continue;
        }
        stats.moved += 1;
        if proposed[v].is_finite() && before[v].is_finite() {
            current[v] = proposed[v];
            halvings[v] = 0;
        } else {
            stats.cancelled += 1;
        }
    }
    // Faces that take part: indices in range and finite old corners.
    let active: Vec<bool> = triangles
        .iter()
        .map(|t| {
            t.iter()
                .all(|&i| (i as usize) < n && before[i as usize].is_finite())
        })
        .collect();
    let candidates = swept_candidates(before, &current, triangles, &active, &halvings);
    // Per face: its current box and its prepared plane, refreshed when a corner changes.
    let corners = |t: &[u32; 3], current: &[DVec3]| t.map(|i| current[i as usize]);
    let mut boxes = vec![Aabb::EMPTY; triangles.len()];
    let mut prepared: Vec<Option<PreparedFace>> = vec![None; triangles.len()];
    // Faces to re-check in this pass (all changed ones first).
    let mut dirty: Vec<bool> = (0..n).map(|v| halvings[v] != u32::MAX).collect();
    for (f, t) in triangles.iter().enumerate() {
        if active[f] {
            let c = corners(t, &current);
            boxes[f] = Aabb::from_triangle(c);
            prepared[f] = Some(PreparedFace::new(*t, c));
        }
    }
    let mut face_dirty = vec![false; triangles.len()];
    let mut dirty_faces: Vec<u32> = Vec::new();
    loop {
        dirty_faces.clear();
        for (f, t) in triangles.iter().enumerate() {
            face_dirty[f] = active[f] && t.iter().any(|&i| dirty[i as usize]);
            if face_dirty[f] {
                dirty_faces.push(f as u32);
            }
        }
        if dirty_faces.is_empty() {
            break;
        }
        stats.passes += 1;
        for &f in &dirty_faces {
            let t = &triangles[f as usize];
            let c = corners(t, &current);
            boxes[f as usize] = Aabb::from_triangle(c);
            prepared[f as usize] = Some(PreparedFace::new(*t, c));
        }
        let pass = PassInput {
            current: &current,
            candidates: &candidates,
            boxes: &boxes,
            prepared: &prepared,
            face_dirty: &face_dirty,
        };
        // Chunks of faces in parallel; their outputs are joined in chunk order.
        let found: Vec<(usize, Vec<u32>)> = dirty_faces
            .par_chunks(PASS_CHUNK)
            .map(|chunk| pass.test_faces(chunk))
            .collect();
        let mut offending: Vec<u32> = Vec::new();
        for (tests, vertices) in found {
            stats.pair_tests += tests;
            offending.extend_from_slice(&vertices);
        }
        let shortening = Shortening {
            before,
            proposed,
            max_halvings: options.max_halvings,
        };
        stats.cancelled += shortening.apply(offending, &mut halvings, &mut current, &mut dirty);
    }
    for v in 0..n {
        if halvings[v] != u32::MAX && halvings[v] > 0 {
            stats.shortened += 1;
        }
        proposed[v] = current[v];
    }
    stats
}

/// The step-shortening rule of [`limit_steps`], shared with its test reference.
struct Shortening<'a> {
    before: &'a [DVec3],
    proposed: &'a [DVec3],
    max_halvings: u32,
}

impl Shortening<'_> {
    /// Halves the step of every vertex of `offending` (repeats allowed) that still differs from
    /// `before`, or cancels it after `max_halvings` halvings; marks exactly those vertices
    /// `dirty` (all others clean). Returns the number cancelled.
    fn apply(
        &self,
        mut offending: Vec<u32>,
        halvings: &mut [u32],
        current: &mut [DVec3],
        dirty: &mut [bool],
    ) -> usize {
        dirty.iter_mut().for_each(|d| *d = false);
        offending.sort_unstable();
        offending.dedup();
        let mut cancelled = 0;
        for &v in &offending {
            let v = v as usize;
            let k = halvings[v];
            if k == u32::MAX {
                continue; // at its old position already
            }
            if k >= self.max_halvings {
                halvings[v] = u32::MAX;
                current[v] = self.before[v];
                cancelled += 1;
            } else {
                halvings[v] = k + 1;
                let step = self.proposed[v] - self.before[v];
                current[v] = self.before[v] + step / f64::from(1u32 << (k + 1));
            }
            dirty[v] = true;
        }
        cancelled
    }
}

/// Dirty faces per rayon task in a pass of [`limit_steps`].
const PASS_CHUNK: usize = 64;

/// What one pass of [`limit_steps`] reads (nothing is written during the tests).
struct PassInput<'a> {
    current: &'a [DVec3],
    candidates: &'a Candidates,
    boxes: &'a [Aabb],
    prepared: &'a [Option<PreparedFace>],
    face_dirty: &'a [bool],
}

impl PassInput<'_> {
    /// Tests each face of `faces` (dirty ones) against its candidates whose current box overlaps
    /// its own; a pair of two dirty faces is tested once, from the larger index. Returns the
    /// number of exact tests and the corners of every intersecting pair (with repeats).
    fn test_faces(&self, faces: &[u32]) -> (usize, Vec<u32>) {
        let mut tests = 0;
        let mut offending = Vec::new();
        for &f in faces {
            let f = f as usize;
            let Some(pf) = &self.prepared[f] else {
                continue;
            };
            for &g in self.candidates.of(f) {
                let g = g as usize;
                if (self.face_dirty[g] && g < f) || !self.boxes[f].overlaps(&self.boxes[g]) {
                    continue;
                }
                let Some(pg) = &self.prepared[g] else {
                    continue;
                };
                tests += 1;
                if !certainly_apart(pf, pg) && faces_cross(self.current, pf.ids, pg.ids) {
                    offending.extend_from_slice(&pf.ids);
                    offending.extend_from_slice(&pg.ids);
                }
            }
        }
        (tests, offending)
    }
}

/// For every face, the other faces whose swept boxes overlap its own (compressed rows).
struct Candidates {
    /// Row `f` is `faces[offsets[f]..offsets[f + 1]]`.
    offsets: Vec<usize>,
    faces: Vec<u32>,
}

impl Candidates {
    fn of(&self, f: usize) -> &[u32] {
        &self.faces[self.offsets[f]..self.offsets[f + 1]]
    }
}

/// The candidate pairs of [`limit_steps`]: per active face, every other active face whose
/// swept box (the box of its `before` and `proposed` corners) overlaps its own, keeping only
/// pairs with a changed face (a corner with `halvings != u32::MAX`). The boxes go into a
/// [`TriangleBvh`] as degenerate triangles `(min, max, max)`, whose boxes are exactly them,
/// and [`TriangleBvh::overlapping_pairs_parallel`] lists the overlapping ones (their order
/// does not matter: a pass's result depends only on which pairs intersect).
fn swept_candidates(
    before: &[DVec3],
    proposed: &[DVec3],
    triangles: &[[u32; 3]],
    active: &[bool],
    halvings: &[u32],
) -> Candidates {
    let mut box_corners = vec![DVec3::NAN; 2 * triangles.len()];
    let mut box_triangles = Vec::with_capacity(triangles.len());
    for (f, t) in triangles.iter().enumerate() {
        if active[f] {
            let swept = Aabb::from_triangle(t.map(|i| before[i as usize]))
                .union(&Aabb::from_triangle(t.map(|i| proposed[i as usize])));
            box_corners[2 * f] = swept.min;
            box_corners[2 * f + 1] = swept.max;
        }
        // Inactive faces keep NaN corners, which the tree leaves out.
        let (lo, hi) = (2 * f as u32, 2 * f as u32 + 1);
        box_triangles.push([lo, hi, hi]);
    }
    let tree = TriangleBvh::build(&box_corners, &box_triangles);
    let changed = |f: u32| {
        triangles[f as usize]
            .iter()
            .any(|&i| halvings[i as usize] != u32::MAX)
    };
    let mut pairs = tree.overlapping_pairs_parallel();
    pairs.retain(|&(f, g)| changed(f) || changed(g));
    let mut offsets = vec![0usize; triangles.len() + 1];
    for &(f, g) in &pairs {
        offsets[f as usize + 1] += 1;
        offsets[g as usize + 1] += 1;
    }
    for f in 0..triangles.len() {
        offsets[f + 1] += offsets[f];
    }
    let mut fill = offsets.clone();
    let mut faces = vec![0u32; offsets[triangles.len()]];
    for &(f, g) in &pairs {
        faces[fill[f as usize]] = g;
        fill[f as usize] += 1;
        faces[fill[g as usize]] = f;
        fill[g as usize] += 1;
    }
    Candidates { offsets, faces }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::intersecting_pairs;

    /// The method of [`limit_steps`] without its broad phase: every pass tests each dirty face
    /// against every other face whose current box overlaps its own (all pairs, no tree).
    fn reference(
        before: &[DVec3],
        proposed: &mut [DVec3],
        triangles: &[[u32; 3]],
        max_halvings: u32,
    ) -> LimiterStats {
        let mut stats = LimiterStats::default();
        let n = before.len();
        let mut halvings = vec![u32::MAX; n];
        let mut current = before.to_vec();
        for v in 0..n {
            if proposed[v] != before[v] {
                stats.moved += 1;
                current[v] = proposed[v];
                halvings[v] = 0;
            }
        }
        let mut dirty: Vec<bool> = halvings.iter().map(|&k| k != u32::MAX).collect();
        loop {
            let face_dirty: Vec<bool> = triangles
                .iter()
                .map(|t| t.iter().any(|&i| dirty[i as usize]))
                .collect();
            if !face_dirty.contains(&true) {
                break;
            }
            stats.passes += 1;
            let bx = |t: &[u32; 3]| Aabb::from_triangle(t.map(|i| current[i as usize]));
            let mut offending = Vec::new();
            for (f, tf) in triangles.iter().enumerate() {
                for (g, tg) in triangles.iter().enumerate() {
                    let wanted = face_dirty[f] && g != f && !(face_dirty[g] && g < f);
                    if wanted && bx(tf).overlaps(&bx(tg)) {
                        stats.pair_tests += 1;
                        if faces_cross(&current, *tf, *tg) {
                            offending.extend_from_slice(tf);
                            offending.extend_from_slice(tg);
                        }
                    }
                }
            }
            let shortening = Shortening {
                before,
                proposed,
                max_halvings,
            };
            stats.cancelled += shortening.apply(offending, &mut halvings, &mut current, &mut dirty);
        }
        stats.shortened = halvings.iter().filter(|&&k| k != u32::MAX && k > 0).count();
        proposed.copy_from_slice(&current);
        stats
    }

    /// Two concentric icospheres `gap` apart (an inner and an outer shell, #F = 2 × 20·4^level).
    fn two_shells(level: u32, gap: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (inner, t) = icosphere(level).to_triangles();
        let offset = inner.len() as u32;
        let mut positions = inner.clone();
        positions.extend(inner.iter().map(|p| *p * (1.0 + gap)));
        let mut triangles = t.clone();
        triangles.extend(t.iter().map(|f| f.map(|i| i + offset)));
        (positions, triangles)
    }

    /// Pseudo-random steps of length up to `scale` (a fixed hash of the vertex index and `seed`).
    fn jitter(positions: &[DVec3], scale: f64, seed: u64) -> Vec<DVec3> {
        positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let h = |k: u64| {
                    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (seed + k);
                    let x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
                };
                *p + scale * DVec3::new(h(1), h(2), h(3))
            })
            .collect()
    }

    #[test]
    fn shells_pushed_into_each_other_need_several_passes_and_end_intersection_free() {
        let (before, t) = two_shells(3, 0.01);
        assert!(intersecting_pairs(&before, &t).is_empty());
        let mut proposed = jitter(&before, 0.03, 7);
        assert!(!intersecting_pairs(&proposed, &t).is_empty());
        let stats = limit_steps(&before, &mut proposed, &t, &LimiterOptions::default());
        assert!(stats.passes >= 3, "{stats:?}");
        assert!(stats.shortened > 0 && stats.cancelled > 0, "{stats:?}");
        assert!(intersecting_pairs(&proposed, &t).is_empty());
    }

    #[test]
    fn matches_the_all_pairs_reference() {
        let (before, t) = two_shells(2, 0.02);
        for seed in 0..4 {
            let mut fast = jitter(&before, 0.05, seed);
            let mut slow = fast.clone();
            let a = limit_steps(&before, &mut fast, &t, &LimiterOptions::default());
            let b = reference(&before, &mut slow, &t, 3);
            assert_eq!(a, b);
            assert_eq!(fast, slow);
        }
    }

    #[test]
    fn result_does_not_depend_on_the_thread_count() {
        let (before, t) = two_shells(3, 0.01);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut proposed = jitter(&before, 0.03, 3);
            let stats = pool
                .install(|| limit_steps(&before, &mut proposed, &t, &LimiterOptions::default()));
            (stats, proposed)
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(3));
    }

    #[test]
    fn invalid_indices_and_non_finite_proposals_are_ignored() {
        let (before, mut t) = two_shells(1, 0.05);
        t.push([0, 1, before.len() as u32 + 5]);
        let mut proposed = jitter(&before, 0.01, 1);
        proposed[0] = DVec3::NAN;
        let stats = limit_steps(&before, &mut proposed, &t, &LimiterOptions::default());
        assert_eq!(proposed[0], before[0]);
        assert!(stats.cancelled >= 1);
        assert!(intersecting_pairs(&proposed, &t[..t.len() - 1]).is_empty());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Same accepted positions and stats as the all-pairs reference for random steps,
        /// including unmoved vertices and halvings limits, and an intersection-free result.
        #[test]
        fn same_as_reference(seed in 0u64..1000, scale in 0.001f64..0.1, keep in 0usize..4,
                             max_halvings in 0u32..5) {
            let (before, t) = two_shells(1, 0.03);
            let mut fast = jitter(&before, scale, seed);
            for (i, p) in fast.iter_mut().enumerate() {
                if i % 4 < keep {
                    *p = before[i];
                }
            }
            let mut slow = fast.clone();
            let options = LimiterOptions { max_halvings };
            let a = limit_steps(&before, &mut fast, &t, &options);
            let b = reference(&before, &mut slow, &t, max_halvings);
            prop_assert_eq!(a, b);
            prop_assert_eq!(&fast, &slow);
            prop_assert!(intersecting_pairs(&fast, &t).is_empty());
        }
    }
}
