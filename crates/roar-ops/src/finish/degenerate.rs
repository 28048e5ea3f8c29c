//! Degenerate-face collapses for a finished mesh: remove a face with aspect ratio above a limit
//! by collapsing one of its edges, when no flip can (see [`crate::finish::slivers`]).
//!
//! A sliver flip fixes a cap whose long edge has a good face across it. It cannot fix a needle
//! (a very short edge: flipping a long edge leaves the short one), nor a cap whose neighbour
//! across the long edge is itself a sliver (a strip of caps along a crease, where every flip
//! makes another cap). Collapsing an edge of the face removes it and its neighbour across that
//! edge; the tail vertex `a` merges into the head `b`, which keeps its position:
//!
//! ```text
//!        c                 c
//!       / \                |
//!      /   \      a → b    |
//!     a-----b     ====>    b        (faces (a, b, c) and (b, a, d) removed;
//!      \   /               |         every other face at a now ends at b)
//!       \ /                |
//!        d                 d
//! ```
//!
//! For a needle (`a` close to `b`), or a cap whose apex `a` lies on the line of a crease between
//! the other two, the faces around `a` keep their planes, so the surface barely moves. A
//! collapse of half-edge `a → b` is applied when
//! 1. it is topologically legal ([`Mesh::can_collapse`]);
//! 2. every reshaped face (around `a`, except the two removed) that was not degenerate keeps
//!    its normal within `min_normal_dot` (a degenerate face's old normal is rounding noise);
//! 3. no reshaped face that was not degenerate becomes degenerate (one that was may stay so:
//!    in a cluster of close vertices every collapse keeps some needle of the cluster a
//!    needle), so every collapse lowers the number of degenerate faces and the process ends;
//! 4. no reshaped face intersects another face ([`IntersectionGuard`], exact).
//!
//! The edges of a degenerate face are tried shortest first, each in both directions. Each
//! collapse removes two faces; the caller restores the face count (the pipeline splits edges
//! whose halves are not degenerate, longest first, which moves no geometry).

use crate::blocks::block::BlockStats;
use crate::blocks::guard::{IntersectionGuard, collapse_if_clean};
use crate::geometry::{DEGENERATE_QUALITY, is_degenerate};
use roar_mesh::spatial::{triangle_normal, triangle_quality};
use roar_mesh::{FaceId, HalfedgeId, Mesh};

/// Options of [`collapse_degenerate_faces`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegenerateOptions {
    /// Faces with `Q = R/(2r)` at or above this (or NaN, fully collapsed) are degenerate.
    /// Default [`DEGENERATE_QUALITY`] (100), as the QEM's
    /// [`crate::decimate::DecimateOptions::degenerate_quality`].
    pub min_quality: f64,
    /// Every reshaped face that was not degenerate keeps `n_new · n_old ≥` this. Default 0.95
    /// (the flat test of the sliver flips).
    pub min_normal_dot: f64,
    /// Most rounds over the degenerate faces. Default 5.
    pub max_rounds: usize,
}

impl Default for DegenerateOptions {
    fn default() -> Self {
        DegenerateOptions {
            min_quality: DEGENERATE_QUALITY,
            min_normal_dot: 0.95,
            max_rounds: 5,
        }
    }
}

/// Collapses edges of degenerate faces as the module doc says. Keeps the mesh valid and, if it
/// was free of self-intersections, keeps it so; removes two faces per collapse.
///
/// Stats: `candidates` = degenerate faces looked at; `accepted` = collapses; `rejected` (per
/// half-edge tried): `"topology"`, `"normal"`, `"quality"`, `"intersection"`.
pub fn collapse_degenerate_faces(mesh: &mut Mesh, options: &DegenerateOptions) -> BlockStats {
    let mut stats = BlockStats::new("degenerate_collapses");
    let mut guard: Option<IntersectionGuard> = None;
    for _ in 0..options.max_rounds {
        let faces: Vec<FaceId> = mesh
            .faces()
            .filter(|&f| is_degenerate(face_quality(mesh, f), options.min_quality))
            .collect();
        let mut collapsed = 0;
        for f in faces {
            if !mesh.is_face_alive(f) || !is_degenerate(face_quality(mesh, f), options.min_quality)
            {
                continue;
            }
            stats.candidates += 1;
            for h in halfedges_shortest_first(mesh, f) {
                if let Err(reason) =
                    reshaped_faces_ok(mesh, h, options.min_quality, options.min_normal_dot)
                {
                    stats.reject(reason, 1);
                    continue;
                }
                if collapse_if_clean(mesh, h, &mut guard, &mut stats) {
                    collapsed += 1;
                    break;
                }
            }
        }
        stats.accepted += collapsed;
        if collapsed == 0 {
            break;
        }
    }
    stats
}

fn face_quality(mesh: &Mesh, f: FaceId) -> f64 {
    triangle_quality(mesh.face_vertices(f).map(|v| mesh.position(v)))
}

/// The three half-edges of `f`, each followed by its twin, by increasing edge length (ties keep
/// the face's order).
fn halfedges_shortest_first(mesh: &Mesh, f: FaceId) -> Vec<HalfedgeId> {
    let first = mesh.halfedge_of_face(f);
    let mut edges = [first, mesh.next(first), mesh.next(mesh.next(first))];
    edges.sort_by(|&x, &y| {
        let length = |h: HalfedgeId| {
            mesh.position(mesh.tail(h))
                .distance(mesh.position(mesh.head(h)))
        };
        length(x).total_cmp(&length(y))
    });
    edges.iter().flat_map(|&h| [h, h.twin()]).collect()
}

/// Whether collapsing `h` (its tail onto its head's position) keeps every reshaped face that
/// was not degenerate (aspect ratio below `min_quality`) so, with its normal within
/// `min_normal_dot` of the old one (tests 2 and 3 of the module doc; the fin collapses share
/// it). A face that was degenerate may stay so: its old normal is rounding noise.
pub(crate) fn reshaped_faces_ok(
    mesh: &Mesh,
    h: HalfedgeId,
    min_quality: f64,
    min_normal_dot: f64,
) -> Result<(), &'static str> {
    let (a, b) = (mesh.tail(h), mesh.head(h));
    let removed = [mesh.face(h), mesh.face(h.twin())];
    let pb = mesh.position(b);
    for f in mesh.faces_around(a) {
        if removed.contains(&f) {
            continue;
        }
        let old = mesh.face_vertices(f).map(|v| mesh.position(v));
        let new = mesh
            .face_vertices(f)
            .map(|v| if v == a { pb } else { mesh.position(v) });
        if is_degenerate(triangle_quality(old), min_quality) {
            continue;
        }
        if is_degenerate(triangle_quality(new), min_quality) {
            return Err("quality");
        }
        let turn =
            triangle_normal(old[0], old[1], old[2]).dot(triangle_normal(new[0], new[1], new[2]));
        if turn < min_normal_dot {
            return Err("normal");
        }
    }
    Ok(())
}
