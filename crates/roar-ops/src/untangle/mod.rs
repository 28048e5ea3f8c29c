//! Untangle: remove every self-intersection of a closed mesh, and a step limiter that keeps the
//! optimizer from creating new ones.
//!
//! The Face Collapse block only sees local folds; two distant sheets crossing each
//! other slip through it, yet the output promises zero self-intersections. [`untangle`] finds
//! every intersecting face pair ([`intersecting_pairs`], BVH + exact test) and resolves them in
//! rounds. The idea: a closed oriented mesh without intersections has winding number 1 just
//! inside and 0 just outside every face; a crossing creates a region of winding number 2
//! (overlap) or −1 (inverted pocket). Each vertex of an involved face probes the winding number
//! a little behind and in front of itself along its normal (fast winding numbers, one hierarchy
//! per round); if the back is inside twice, it retreats along −n, if the front is inverted it
//! advances along +n. Both shrink the bad region, from both sides at once. Bad vertices grow
//! the moving region through the mesh (so the whole cap of a sphere stuck inside another
//! retreats, not only its rim). Pairs without a bad vertex get their vertices smoothed
//! (Laplacian). A crossing that involves a sliver, or that has survived `stuck_rounds` rounds,
//! is offered an edge collapse (kept only if it lowers the local crossing count; module
//! `collapse`). When no pair is left, the faces that were involved are pushed apart until every
//! non-adjacent pair of them is at least `margin_rel × bounding-box diagonal` apart, so the
//! written file stays clean after rounding. When the rounds run out, the state with the fewest
//! crossing pairs is returned (the input at worst): on a coarse mesh the moving regions can
//! spread a crossing they do not clear.
//!
//! [`limit_steps`] guards an optimizer step: it accepts the proposed vertex moves, halving a
//! move up to `max_halvings` times and cancelling it if its faces would intersect the mesh.

mod collapse;
mod limiter;
mod options;
mod pairs;
mod resolve;
mod separate;

pub use limiter::{LimiterOptions, LimiterStats, limit_steps};
pub use options::UntangleOptions;

use crate::geometry::is_degenerate;
use collapse::{Buffers, try_collapse_face};
use roar_mesh::spatial::triangle_quality;
use roar_mesh::spatial::{Aabb, TriangleBvh};
use roar_mesh::{FaceId, Mesh};
use std::collections::BTreeSet;

/// Outcome of [`untangle`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UntangleStats {
    /// Intersecting face pairs found at the start.
    pub initial_pairs: usize,
    /// Rounds run (0 when the mesh had no intersection).
    pub rounds: usize,
    /// Vertex moves applied (a vertex moved in two rounds counts twice).
    pub moves: usize,
    /// Edge collapses applied.
    pub collapses: usize,
    /// Faces still intersecting another face, or closer than the margin to a formerly crossing
    /// face, when the rounds ran out (empty on success). Ids of the (uncompacted) mesh after the
    /// collapses.
    pub unresolved_faces: Vec<FaceId>,
}

/// Removes the self-intersections of `mesh` by moving vertices and, where a sliver or a stuck
/// crossing calls for it, collapsing edges (see the module docs).
///
/// Promises: the mesh stays valid; only edge collapses that pass [`Mesh::can_collapse`] change
/// the topology (genus and piece count are kept); a mesh without intersections is left
/// bit-for-bit unchanged; at most `max_rounds` rounds run; on failure the mesh is the state
/// with the fewest crossing pairs the rounds reached (never more than the input's), and every
/// face still intersecting (or within the margin of a formerly crossing face) is listed in
/// `unresolved_faces`. Cost: one full BVH self-intersection query at the start (and after each
/// round with collapses); then per round a BVH refit, exact tests for the faces that moved, one
/// fast-winding-number build and two O(log F) probes per examined vertex.
pub fn untangle(mesh: &mut Mesh, options: &UntangleOptions) -> UntangleStats {
    let mut stats = UntangleStats::default();
    let mut buffers = Buffers::from_mesh(mesh);
    let diag =
        Aabb::from_points(mesh.vertices().map(|v| mesh.position(v))).map_or(0.0, |b| b.diagonal());
    let margin = options.margin_rel * diag;
    let mut tracked: BTreeSet<FaceId> = BTreeSet::new();
    // Consecutive rounds each face (by id slot) has been crossing.
    let mut crossing_rounds = vec![0usize; mesh.face_capacity()];
    let mut remaining: Vec<(u32, u32)> = Vec::new();
    let mut moved = false;
    let mut finder = pairs::PairFinder::default();
    let mut best: Option<Snapshot> = None;
    let mut last_score = (0, 0);
    for round in 0..=options.max_rounds {
        let pairs = finder.find(&buffers.positions, &buffers.triangles);
        if round == 0 {
            stats.initial_pairs = pairs.len();
        }
        let mut crossing: BTreeSet<FaceId> = BTreeSet::new();
        for &(i, j) in &pairs {
            crossing.insert(buffers.face_ids[i as usize]);
            crossing.insert(buffers.face_ids[j as usize]);
        }
        for (slot, count) in crossing_rounds.iter_mut().enumerate() {
            let f = FaceId::from_index(slot);
            *count = if crossing.contains(&f) { *count + 1 } else { 0 };
        }
        tracked.extend(crossing.iter().copied());
        let tracked_slots: BTreeSet<u32> = tracked
            .iter()
            .map(|f| buffers.index_of[f.index()])
            .filter(|&s| s != u32::MAX)
            .collect();
        remaining = if pairs.is_empty() {
            separate::near_pairs(
                &buffers.positions,
                &buffers.triangles,
                &tracked_slots,
                margin,
            )
        } else {
            pairs.clone()
        };
        let score = (pairs.len(), remaining.len());
        last_score = score;
        if best.as_ref().is_none_or(|b: &Snapshot| score < b.score) && !remaining.is_empty() {
            best = Some(Snapshot::take(mesh, &buffers, &remaining, score));
        }
        if remaining.is_empty() || round == options.max_rounds {
            break;
        }
        stats.rounds += 1;
        moved = true;
        if pairs.is_empty() {
            stats.moves += separate::separate(
                &mut buffers.positions,
                &buffers.triangles,
                &remaining,
                margin,
            );
            continue;
        }
        if options.allow_collapses {
            let candidates = collapse_candidates(&buffers, &crossing, &crossing_rounds, options);
            if !candidates.is_empty() {
                let applied = collapse_some(mesh, &mut buffers, &candidates, options);
                if applied > 0 {
                    stats.collapses += applied;
                    finder.invalidate();
                    crossing_rounds.iter_mut().for_each(|c| *c = 0);
                    continue; // re-detect the pairs on the new topology
                }
            }
        }
        stats.moves += resolve::resolve_round(
            &mut buffers.positions,
            &buffers.triangles,
            &buffers.adjacency,
            &pairs,
            options,
        );
    }
    if moved {
        write_positions(mesh, &buffers);
    }
    stats.unresolved_faces = unresolved_faces(&buffers, &remaining);
    // On failure, the state with the fewest crossings (the input at worst): the rounds can
    // spread a crossing that they do not clear.
    if let Some(best) = best
        && !remaining.is_empty()
        && best.score < last_score
    {
        *mesh = best.mesh;
        stats.unresolved_faces = best.unresolved_faces;
    }
    stats
}

/// A state of the rounds: the mesh, its crossing and margin-violating pair counts, and the
/// faces of those pairs.
struct Snapshot {
    mesh: Mesh,
    score: (usize, usize),
    unresolved_faces: Vec<FaceId>,
}

impl Snapshot {
    fn take(
        mesh: &Mesh,
        buffers: &Buffers,
        remaining: &[(u32, u32)],
        score: (usize, usize),
    ) -> Self {
        let mut copy = mesh.clone();
        write_positions(&mut copy, buffers);
        Snapshot {
            mesh: copy,
            score,
            unresolved_faces: unresolved_faces(buffers, remaining),
        }
    }
}

/// The faces of the `remaining` pairs (buffer slots), as mesh ids in order.
fn unresolved_faces(buffers: &Buffers, remaining: &[(u32, u32)]) -> Vec<FaceId> {
    let faces: BTreeSet<FaceId> = remaining
        .iter()
        .flat_map(|&(i, j)| [i, j])
        .map(|f| buffers.face_ids[f as usize])
        .collect();
    faces.into_iter().collect()
}

/// Copies the buffer positions of live vertices into `mesh` (only those that changed).
fn write_positions(mesh: &mut Mesh, buffers: &Buffers) {
    for v in mesh.vertices().collect::<Vec<_>>() {
        let p = buffers.positions[v.index()];
        if mesh.position(v) != p {
            mesh.set_position(v, p);
        }
    }
}

/// Crossing faces worth a collapse: slivers, and faces stuck for `stuck_rounds` rounds; worst
/// aspect ratio first (ties by id), so the order is deterministic.
fn collapse_candidates(
    buffers: &Buffers,
    crossing: &BTreeSet<FaceId>,
    crossing_rounds: &[usize],
    options: &UntangleOptions,
) -> Vec<FaceId> {
    let mut out: Vec<(f64, FaceId)> = crossing
        .iter()
        .filter_map(|&f| {
            let t = buffers.triangles[buffers.index_of[f.index()] as usize];
            let q = triangle_quality(t.map(|i| buffers.positions[i as usize]));
            let stuck = crossing_rounds[f.index()] >= options.stuck_rounds.max(1);
            (is_degenerate(q, options.sliver_quality) || stuck).then_some((q, f))
        })
        .collect();
    out.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    out.into_iter().map(|(_, f)| f).collect()
}

/// Tries the candidates in order, applying at most `max_collapses_per_round` collapses; the
/// buffers (positions written to the mesh first) are rebuilt after each. Returns the count.
fn collapse_some(
    mesh: &mut Mesh,
    buffers: &mut Buffers,
    candidates: &[FaceId],
    options: &UntangleOptions,
) -> usize {
    write_positions(mesh, buffers);
    let mut bvh = TriangleBvh::build(&buffers.positions, &buffers.triangles);
    let mut applied = 0;
    for &f in candidates {
        if applied >= options.max_collapses_per_round {
            break;
        }
        if try_collapse_face(mesh, buffers, &bvh, f) {
            applied += 1;
            *buffers = Buffers::from_mesh(mesh);
            bvh = TriangleBvh::build(&buffers.positions, &buffers.triangles);
        }
    }
    applied
}
