//! The step limiter: shortens optimizer steps that would create a self-intersection.

use crate::intersect::{PreparedFace, certainly_apart, faces_intersect_filtered as faces_cross};
use glam::DVec3;
use roar_mesh::spatial::{Aabb, TriangleBvh};

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
/// after the step (overwritten with the accepted ones), `triangles` (#F), and `bvh` built (or
/// refitted) over `before` and `triangles`. Output: `proposed` holds, per vertex, either the
/// full step, the step halved `k ≤ max_halvings` times, or the old position; the result is
/// intersection-free whenever `before` was.
///
/// Method, in passes: every face with a moved corner ("changed") is tested exactly against every
/// face whose current box overlaps its own (a clone of `bvh` refitted to the current positions
/// finds them). Unchanged pairs need no test: they are as in `before`. Every corner of a face in
/// an intersecting pair that still differs from `before` has its step halved (or, after
/// `max_halvings` halvings, cancelled), and the next pass re-tests only the faces those
/// vertices touch. An intersecting pair always has a moved corner (two unchanged faces do not
/// intersect), so every pass shortens some step and the loop ends after at most
/// `max_halvings + 1` passes per vertex.
///
/// Cost: one BVH clone and refit per pass plus, for the changed faces, a box query and the
/// exact tests (adjacent pairs are mostly settled by floating-point filters, see
/// `crate::intersect::faces_intersect_filtered`). Invalid indices are ignored; non-finite proposals are cancelled.
pub fn limit_steps(
    before: &[DVec3],
    proposed: &mut [DVec3],
    triangles: &[[u32; 3]],
    bvh: &TriangleBvh,
    options: &LimiterOptions,
) -> LimiterStats {
    let mut stats = LimiterStats::default();
    let n = before.len().min(proposed.len());
    let valid = |t: &[u32; 3]| t.iter().all(|&i| (i as usize) < n);
    // Halvings applied so far per vertex; `u32::MAX` marks a cancelled (or unmoved) vertex.
    let mut halvings = vec![u32::MAX; n];
    let mut current: Vec<DVec3> = before[..n].to_vec();
    for v in 0..n {
        if proposed[v] == before[v] {
            continue;
        }
        stats.moved += 1;
        if proposed[v].is_finite() {
            current[v] = proposed[v];
            halvings[v] = 0;
        } else {
            stats.cancelled += 1;
        }
    }
    // Vertices to re-check in this pass (all moved ones first).
    let mut dirty: Vec<bool> = (0..n).map(|v| halvings[v] != u32::MAX).collect();
    let bvh_fits = bvh.positions().len() == n && bvh.triangles() == triangles;
    let mut tree = if bvh_fits {
        bvh.clone()
    } else {
        TriangleBvh::build(&current, triangles)
    };
    let mut candidates = Vec::new();
    let mut offending: Vec<u32> = Vec::new();
    loop {
        if !dirty.iter().any(|&d| d) {
            break;
        }
        stats.passes += 1;
        tree.refit(&current);
        // A face is tested when it touches a dirty vertex; a pair of two such faces once.
        let face_dirty = |t: &[u32; 3]| valid(t) && t.iter().any(|&i| dirty[i as usize]);
        offending.clear();
        for (f, tf) in triangles.iter().enumerate() {
            if !face_dirty(tf) {
                continue;
            }
            let tf = *tf;
            let pf = PreparedFace::new(tf, tf.map(|i| current[i as usize]));
            let b = Aabb::from_triangle(pf.corners);
            candidates.clear();
            tree.faces_in_aabb(&b, |g| candidates.push(g));
            for &g in &candidates {
                let tg = triangles[g as usize];
                if g as usize == f || (face_dirty(&tg) && (g as usize) < f) {
                    continue;
                }
                stats.pair_tests += 1;
                let pg = PreparedFace::new(tg, tg.map(|i| current[i as usize]));
                if !certainly_apart(&pf, &pg) && faces_cross(&current, tf, tg) {
                    offending.extend_from_slice(&tf);
                    offending.extend_from_slice(&tg);
                }
            }
        }
        dirty.iter_mut().for_each(|d| *d = false);
        offending.sort_unstable();
        offending.dedup();
        for &v in &offending {
            let v = v as usize;
            let k = halvings[v];
            if k == u32::MAX {
                continue; // at its old position already
            }
            if k >= options.max_halvings {
                halvings[v] = u32::MAX;
                current[v] = before[v];
                stats.cancelled += 1;
            } else {
                halvings[v] = k + 1;
                current[v] = before[v] + (proposed[v] - before[v]) / f64::from(1u32 << (k + 1));
            }
            dirty[v] = true;
        }
    }
    for v in 0..n {
        if halvings[v] != u32::MAX && halvings[v] > 0 {
            stats.shortened += 1;
        }
        proposed[v] = current[v];
    }
    stats
}

/// [`limit_steps`] with a BVH built over `before` and `triangles`, for callers that have none
/// to refit (the pipeline's optimizer step, guarded smoothing).
pub fn limit_moves(
    before: &[DVec3],
    proposed: &mut [DVec3],
    triangles: &[[u32; 3]],
    options: &LimiterOptions,
) -> LimiterStats {
    let bvh = TriangleBvh::build(before, triangles);
    limit_steps(before, proposed, triangles, &bvh, options)
}
