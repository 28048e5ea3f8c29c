//! Decimation of large meshes on two threads: the two halves of the mesh on either side of a
//! cutting plane are decimated at the same time, then the whole mesh sequentially.
//!
//! ```text
//!              low side               high side
//!        ┌──────────────────────┬──────────────────────┐
//!        │ collapsed by         │ collapsed by         │
//!        │ thread 1 only        │ thread 2 only        │
//!        └──────────────────────┴──────────────────────┘
//!                               c       (along the longest axis)
//! ```
//!
//! **Why the result is what one thread would allow.** Call a vertex low if its coordinate is
//! `< c`, high if `> c`. Thread 1 works on a copy of the mesh and makes only collapses whose star
//! (every vertex around both endpoints) and placement are low, so every face it changes or
//! creates has only low corners and lies in the open half-space `x < c`; likewise thread 2 on
//! the high side. A face with a corner that is not low is never changed by thread 1 (it lies in
//! no star thread 1 touches), and one with a corner that is not high never by thread 2; in
//! particular a face with corners on both sides (or on the plane) stays frozen in phase 1, and so
//! do the positions of its corners (a vertex with a neighbour across is never an endpoint). So
//! the faces the two threads change are disjoint, and the merged mesh (faces with a low corner
//! or no high corner from copy 1, the others from copy 2) is what applying both collapse
//! sequences to one mesh gives: each collapse sees the same star and link as in its own copy, so
//! the mesh stays a closed oriented 2-manifold with the same components and genera. Every
//! collapse passed the full veto of its copy, and a face pair of the merged mesh either lies in
//! one copy's final mesh, or has one face changed by each thread, in disjoint open half-spaces:
//! no self-intersection is created. The sequential [`decimate`] then reaches the exact target
//! from the merged mesh with the usual promises.
//!
//! The same argument lets each copy's intersection grid hold only the faces with a corner on its
//! side: a face without one lies in the other closed half-space, where no face the copy's
//! collapses create can reach it. (Without that, the grid also held the other half and was never
//! rebuilt with coarser cells, since the copy's face count never halves.)
//!
//! Only the faces next to the plane are frozen. A band as wide as twice the longest edge kept out
//! of both halves would hold about 5 % of the faces of a large init, all left to the sequential
//! phase, and the argument above does not need it.
//!
//! Each side is decimated to its share of twice the target, so the last halving (and the faces
//! at the cut) is done in the global cheapest-first order. The answer does not depend on the
//! thread count.

use super::budget::check_request;
use super::decimator::{Decimator, decimate};
use super::error::DecimateError;
use super::options::DecimateOptions;
use super::slab::Slab;
use super::stats::{DecimateStats, VetoCounts};
use glam::DVec3;
use roar_mesh::Mesh;

/// Meshes with fewer faces are decimated sequentially ([`decimate`]); below it the copies and
/// the merge cost more than the second thread saves.
const MIN_FACES_TO_SPLIT: usize = 50_000;

/// Decimates `mesh` to exactly `target_faces` faces with the promises of [`decimate`], using two
/// threads for large meshes (see the module doc); small meshes and small reductions go straight
/// to [`decimate`].
///
/// The mesh is rebuilt between the phases, so face and edge ids do not follow the input and
/// `stats.remap` is `None` when the split ran; callers that keep per-element data in step use
/// [`super::decimate_with`].
pub fn decimate_in_parallel(
    mesh: &mut Mesh,
    target_faces: usize,
    options: &DecimateOptions,
) -> Result<DecimateStats, DecimateError> {
    let initial = mesh.n_faces();
    if let Some(noop) = check_request(mesh, target_faces, options)? {
        return Ok(noop);
    }
    let goal = 2 * target_faces;
    let large = initial >= MIN_FACES_TO_SPLIT && goal < initial / 2;
    let Some((low, high)) = cutting_slabs(mesh).filter(|_| large) else {
        return decimate(mesh, target_faces, options);
    };
    let (a, b) = rayon::join(
        || decimate_side(mesh, low, goal, options),
        || decimate_side(mesh, high, goal, options),
    );
    let Some(mut merged) = merge(&a.mesh, low, &b.mesh, high) else {
        // Unreachable by the module doc's argument; keep the promise with one thread anyway.
        debug_assert!(false, "merging the two decimated halves failed");
        return decimate(mesh, target_faces, options);
    };
    // On `BudgetNotReached` the caller gets the closest mesh, as from `decimate`.
    let result = decimate(&mut merged, target_faces, options);
    *mesh = merged;
    let mut stats = result?;
    stats.initial_faces = initial;
    stats.collapses += a.collapses + b.collapses;
    stats.vetoes.add(&a.vetoes);
    stats.vetoes.add(&b.vetoes);
    stats.passes += a.passes.max(b.passes);
    stats.max_cost = stats.max_cost.max(a.max_cost).max(b.max_cost);
    stats.remap = None;
    Ok(stats)
}

/// The low and high sides of the module doc: open half-spaces below and above the median vertex
/// coordinate along the longest axis of the bounding box. `None` for an empty or non-finite
/// mesh.
fn cutting_slabs(mesh: &Mesh) -> Option<(Slab, Slab)> {
    let points: Vec<DVec3> = mesh.vertices().map(|v| mesh.position(v)).collect();
    let (min, max) = points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let extent = max - min;
    if !extent.is_finite() {
        return None;
    }
    let axis = (0..3)
        .max_by(|&a, &b| extent[a].total_cmp(&extent[b]))
        .unwrap_or(0);
    let mut coords: Vec<f64> = points.iter().map(|p| p[axis]).collect();
    let mid = coords.len() / 2;
    let (_, &mut c, _) = coords.select_nth_unstable_by(mid, f64::total_cmp);
    Some((
        Slab {
            axis,
            lo: f64::NEG_INFINITY,
            hi: c,
        },
        Slab {
            axis,
            lo: c,
            hi: f64::INFINITY,
        },
    ))
}

/// A copy of the mesh with one side decimated, and what that took.
struct Side {
    mesh: Mesh,
    collapses: usize,
    vetoes: VetoCounts,
    passes: usize,
    max_cost: f64,
}

/// Decimates, in a copy of `mesh`, the faces with a corner in `slab` to their share of `goal`
/// faces (one heap pass at the first quality bound; whatever the vetoes leave is for the
/// sequential phase).
fn decimate_side(mesh: &Mesh, slab: Slab, goal: usize, options: &DecimateOptions) -> Side {
    let mut copy = mesh.clone();
    let total = copy.n_faces();
    let inside = copy
        .faces()
        .filter(|&f| {
            copy.face_vertices(f)
                .iter()
                .any(|&v| slab.contains(copy.position(v)))
        })
        .count();
    let share = (goal as f64 * inside as f64 / total as f64) as usize;
    let stop = total - inside.saturating_sub(share);
    let mut run = Decimator::new(&mut copy, options, Some(slab), |_| {});
    let vetoes = run.pass(stop, options.quality_bounds[0]);
    let (collapses, passes, max_cost) = (run.collapses, run.passes, run.max_cost);
    drop(run);
    Side {
        mesh: copy,
        collapses,
        vetoes,
        passes,
        max_cost,
    }
}

/// The merged mesh of the module doc: faces of `low_mesh` with a corner in `low` or none in
/// `high`, and faces of `high_mesh` with a corner in `high` and none in `low`, with the vertices
/// they use renumbered in id order. `None` if that is not a closed manifold (never, by the module
/// doc).
fn merge(low_mesh: &Mesh, low: Slab, high_mesh: &Mesh, high: Slab) -> Option<Mesh> {
    let capacity = low_mesh.vertex_capacity();
    let mut position = vec![None; capacity];
    let mut faces: Vec<[u32; 3]> = Vec::new();
    // The faces frozen in both copies (no corner on one side) are taken from the low one.
    for (mesh, from_low) in [(low_mesh, true), (high_mesh, false)] {
        for f in mesh.faces() {
            let corners = mesh.face_vertices(f);
            let points = corners.map(|v| mesh.position(v));
            let has_low = points.iter().any(|&p| low.contains(p));
            let has_high = points.iter().any(|&p| high.contains(p));
            let taken = if from_low {
                has_low || !has_high
            } else {
                has_high && !has_low
            };
            if taken {
                for (v, p) in corners.iter().zip(points) {
                    position[v.index()] = Some(p);
                }
                faces.push(corners.map(|v| v.raw()));
            }
        }
    }
    let mut new_id = vec![u32::MAX; capacity];
    let mut positions = Vec::new();
    for (v, p) in position.iter().enumerate() {
        if let Some(p) = p {
            new_id[v] = positions.len() as u32;
            positions.push(*p);
        }
    }
    let triangles: Vec<[u32; 3]> = faces
        .iter()
        .map(|t| t.map(|v| new_id[v as usize]))
        .collect();
    Mesh::from_triangles(positions, &triangles).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;

    /// The triangles of `mesh` (corner ids, each rotated to start at its smallest id), sorted.
    fn canonical_triangles(mesh: &Mesh) -> Vec<[u32; 3]> {
        let mut t: Vec<[u32; 3]> = mesh
            .to_triangles()
            .1
            .into_iter()
            .map(|t| {
                let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
            })
            .collect();
        t.sort_unstable();
        t
    }

    /// Merging two untouched copies gives the mesh back: every face (also those crossing the
    /// cut, and those with a corner exactly on it) is taken exactly once.
    #[test]
    fn merging_untouched_copies_takes_every_face_once() {
        let mesh = icosphere(3);
        let (low, high) = cutting_slabs(&mesh).expect("finite mesh");
        let on_cut = mesh
            .vertices()
            .filter(|&v| {
                let p = mesh.position(v);
                !low.contains(p) && !high.contains(p)
            })
            .count();
        assert!(on_cut > 0, "the median vertex lies on the cut");
        let straddling = mesh
            .faces()
            .filter(|&f| {
                let p = mesh.face_vertices(f).map(|v| mesh.position(v));
                p.iter().any(|&q| low.contains(q)) && p.iter().any(|&q| high.contains(q))
            })
            .count();
        assert!(straddling > 0, "faces cross the cut");
        let merged = merge(&mesh, low, &mesh, high).expect("a closed manifold");
        merged.validate().expect("valid merge");
        assert_eq!(canonical_triangles(&merged), canonical_triangles(&mesh));
    }
}
