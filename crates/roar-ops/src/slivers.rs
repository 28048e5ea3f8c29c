//! Sliver flips for a finished mesh: flip the edge of a badly shaped triangle when that makes both
//! triangles of the edge better, without changing the surface or creating an intersection.
//!
//! The optimization moves vertices for the losses, not for the triangle shapes, and the final QEM
//! only bounds the quality of the faces it creates, so a few caps (a vertex almost on the opposite
//! edge, one angle near 180°) survive to the output. Flipping the long edge of a cap replaces it
//! and its neighbour across that edge:
//!
//! ```text
//!        c                         c
//!       /|\                       / \
//!      / | \        flip         /   \
//!     a--+--b      (a,b)→(c,d)  a-----b      (cap (a, b, c) with c near edge (a, b))
//!      \ | /                     \   /
//!       \|/                       \ /
//!        d                         d
//! ```
//!
//! An edge (a, b) with faces (a, b, c) and (b, a, d) is flipped when the worse of its two faces
//! has `Q = R/(2r)` above `max_quality`, and
//! 1. the worse of the two new faces (a, d, c), (b, c, d) is strictly better than that (so the
//!    sorted list of face qualities decreases at each flip and the process ends);
//! 2. the two old faces are nearly coplanar (`|n_L · n_R| ≥ min_abs_flatness`), so the flip
//!    keeps the surface where it is, and each new face keeps the orientation of the pair
//!    (`N_old · n_new > 0` with `N_old = n_L + n_R` unnormalized);
//! 3. the flip is topologically legal ([`Mesh::can_flip`]: no duplicate edge, no valence 2);
//! 4. neither new face intersects another face ([`IntersectionGuard`], exact).
//!
//! Edges are visited in id order, rounds repeat until a round flips nothing (or `max_rounds`).

use crate::block::BlockStats;
use crate::geometry::{triangle_normal, triangle_quality};
use crate::guard::IntersectionGuard;
use roar_mesh::Mesh;

/// Options of [`flip_slivers`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliverOptions {
    /// Faces with `Q` above this are slivers. Default 10 (the QEM's second quality bound).
    pub max_quality: f64,
    /// Only edges whose two faces have `|n_L · n_R| ≥` this are flipped. Default 0.95 (the gate
    /// of the valence flips, spec §3.7).
    pub min_abs_flatness: f64,
    /// Most rounds over all edges. Default 5.
    pub max_rounds: usize,
}

impl Default for SliverOptions {
    fn default() -> Self {
        SliverOptions {
            max_quality: 10.0,
            min_abs_flatness: 0.95,
            max_rounds: 5,
        }
    }
}

/// Flips sliver edges as the module doc says. Moves no vertex and keeps the face count; the mesh
/// stays valid and, if it was free of self-intersections, stays so.
///
/// Stats: `candidates` = edges with a face above `max_quality` looked at; `accepted` = flips;
/// `rejected`: `"no_better"`, `"dihedral"`, `"normal"`, `"topology"`, `"intersection"`.
pub fn flip_slivers(mesh: &mut Mesh, options: &SliverOptions) -> BlockStats {
    let mut stats = BlockStats::new("sliver_flips");
    // Built at the first flip that passes the other tests, so meshes without slivers pay nothing.
    let mut guard: Option<IntersectionGuard> = None;
    for _ in 0..options.max_rounds {
        let mut flipped = 0;
        let edges: Vec<_> = mesh.edges().collect();
        for e in edges {
            let h = e.halfedge();
            let (a, b) = (mesh.tail(h), mesh.head(h));
            let (c, d) = (mesh.opposite_vertex(h), mesh.opposite_vertex(h.twin()));
            let [pa, pb, pc, pd] = [a, b, c, d].map(|v| mesh.position(v));
            let q_old = triangle_quality([pa, pb, pc]).max(triangle_quality([pb, pa, pd]));
            // Written so that NaN (a degenerate face) means "no".
            let sliver = q_old > options.max_quality;
            if !sliver {
                continue;
            }
            stats.candidates += 1;
            let q_new = triangle_quality([pa, pd, pc]).max(triangle_quality([pb, pc, pd]));
            let better = q_new < q_old;
            if !better {
                stats.reject("no_better", 1);
                continue;
            }
            let (n_l, n_r) = (triangle_normal(pa, pb, pc), triangle_normal(pb, pa, pd));
            let flat = n_l.dot(n_r).abs() >= options.min_abs_flatness;
            if !flat {
                stats.reject("dihedral", 1);
                continue;
            }
            let n_old = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
            if !(n_old.dot((pd - pa).cross(pc - pa)) > 0.0
                && n_old.dot((pc - pb).cross(pd - pb)) > 0.0)
            {
                stats.reject("normal", 1);
                continue;
            }
            if mesh.can_flip(e).is_err() {
                stats.reject("topology", 1);
                continue;
            }
            let guard = guard.get_or_insert_with(|| IntersectionGuard::new(mesh));
            if guard.flip_intersects(mesh, e) {
                stats.reject("intersection", 1);
                continue;
            }
            guard.mark(mesh.face(h));
            guard.mark(mesh.face(h.twin()));
            mesh.flip(e)
                .expect("sliver flip passed can_flip (invariant)");
            flipped += 1;
        }
        stats.accepted += flipped;
        if flipped == 0 {
            break;
        }
    }
    stats
}
