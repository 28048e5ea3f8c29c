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
//! 2. the flip keeps the surface where it is: the two old faces are nearly coplanar
//!    (`|n_L · n_R| ≥ min_abs_flatness`) and each new face keeps the orientation of the pair
//!    (`N_old · n_new > 0` with `N_old = n_L + n_R` unnormalized). When one old face is
//!    degenerate (`Q ≥ degenerate_quality`) its normal is rounding noise and says nothing about
//!    the surface, so the test is made against the other face `g` alone: both new faces must
//!    satisfy `n_new · n_g ≥ min_abs_flatness`. A cap lying along a crease then flips into two
//!    faces that tile its neighbour (its apex is on their common edge), and the crease stays;
//! 3. the flip is topologically legal ([`Mesh::can_flip`]: no duplicate edge, no valence 2);
//! 4. neither new face intersects another face ([`IntersectionGuard`], exact).
//!
//! Edges are visited in id order, rounds repeat until a round flips nothing (or `max_rounds`).

use crate::blocks::block::BlockStats;
use crate::blocks::guard::{IntersectionGuard, flip_if_clean};
use crate::geometry::{flip_keeps_orientation, flip_quad, is_degenerate};
use glam::DVec3;
use roar_mesh::Mesh;
use roar_mesh::spatial::{triangle_normal, triangle_quality};

/// Options of [`flip_slivers`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliverOptions {
    /// Faces with `Q` above this are slivers. Default 10 (the QEM's second quality bound).
    pub max_quality: f64,
    /// Only edges whose two faces have `|n_L · n_R| ≥` this are flipped. Default 0.95 (the gate
    /// of the valence flips).
    pub min_abs_flatness: f64,
    /// A face with `Q` at or above this is degenerate: its normal is not trusted, and the flat
    /// test looks at the other face only (module doc, test 2). Default 100, the QEM's
    /// [`crate::decimate::DecimateOptions::degenerate_quality`]. Without it, the caps the
    /// optimization leaves along creases were nearly all refused by the flat test (on roar's
    /// 5000-face output of luke-f-16: 61 of 95 candidates refused as not flat, 12 for the
    /// orientation, none flipped).
    pub degenerate_quality: f64,
    /// Most rounds over all edges. Default 5.
    pub max_rounds: usize,
}

impl Default for SliverOptions {
    fn default() -> Self {
        SliverOptions {
            max_quality: 10.0,
            min_abs_flatness: 0.95,
            degenerate_quality: crate::geometry::DEGENERATE_QUALITY,
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
            let [pa, pb, pc, pd] = flip_quad(mesh, e);
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
            if let Err(reason) = keeps_surface([pa, pb, pc, pd], options) {
                stats.reject(reason, 1);
                continue;
            }
            if flip_if_clean(mesh, e, &mut guard, &mut stats) {
                flipped += 1;
            }
        }
        stats.accepted += flipped;
        if flipped == 0 {
            break;
        }
    }
    stats
}

/// Test 2 of the module doc for the flip of edge (a, b) with faces (a, b, c) and (b, a, d):
/// `Err("dihedral")` when the old faces are not flat enough, `Err("normal")` when a new face
/// turns against the pair.
fn keeps_surface(
    [pa, pb, pc, pd]: [DVec3; 4],
    options: &SliverOptions,
) -> Result<(), &'static str> {
    let new = [(pd - pa).cross(pc - pa), (pc - pb).cross(pd - pb)];
    let degenerate = |q: f64| is_degenerate(q, options.degenerate_quality);
    let (q_l, q_r) = (
        triangle_quality([pa, pb, pc]),
        triangle_quality([pb, pa, pd]),
    );
    // Only one face may be untrusted: with both degenerate there is no surface to compare with.
    let good = match (degenerate(q_l), degenerate(q_r)) {
        (true, false) => Some(triangle_normal(pb, pa, pd)),
        (false, true) => Some(triangle_normal(pa, pb, pc)),
        _ => None,
    };
    if let Some(n_g) = good {
        let within = |n: DVec3| n.normalize_or_zero().dot(n_g) >= options.min_abs_flatness;
        return if new.iter().all(|&n| within(n)) {
            Ok(())
        } else {
            Err("dihedral")
        };
    }
    let (n_l, n_r) = (triangle_normal(pa, pb, pc), triangle_normal(pb, pa, pd));
    if n_l.dot(n_r).abs() < options.min_abs_flatness {
        return Err("dihedral");
    }
    if !flip_keeps_orientation([pa, pb, pc, pd]) {
        return Err("normal");
    }
    Ok(())
}
