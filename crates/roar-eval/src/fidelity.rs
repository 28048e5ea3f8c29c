//! Shape fidelity against a reference: Chamfer L2, Hausdorff and normal cosine similarity
//! (spec §6.1 items 1–2, OQ-16).

use glam::DVec3;
use serde::Serialize;

use crate::nearest::{Nearest, nearest_neighbours};
use roar_mesh::spatial::{SurfaceSamples, sample_surface};

/// How the two surfaces are sampled for Chamfer and normal similarity.
#[derive(Debug, Clone, PartialEq)]
pub struct ChamferOptions {
    /// Samples drawn on each surface, by area with uniform barycentrics
    /// (spec §6.1.1: 200k on each side).
    pub samples: usize,
    /// Seed of the evaluated mesh's samples; the reference uses `seed + 1`.
    pub seed: u64,
}

impl Default for ChamferOptions {
    fn default() -> Self {
        Self {
            samples: 200_000,
            seed: 0,
        }
    }
}

/// Distances and normal agreement between an evaluated mesh R and a reference T.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FidelityStats {
    /// `½(mean_{x∈R} min_y ‖x−y‖ + mean_{y∈T} min_x ‖x−y‖)` in model units (spec §6.1.1, primary).
    pub chamfer_l2: f64,
    /// `chamfer_l2` divided by the reference's bounding-box diagonal.
    pub chamfer_l2_over_diag: f64,
    /// `mean_{x∈R} min_y ‖x−y‖² + mean_{y∈T} min_x ‖x−y‖²` (PyTorch3D `chamfer_distance`, OQ-16).
    pub chamfer_l2_squared_sum: f64,
    /// Largest nearest-neighbour distance in either direction (symmetric sampled Hausdorff).
    pub hausdorff: f64,
    /// `hausdorff` divided by the reference's bounding-box diagonal.
    pub hausdorff_over_diag: f64,
    /// Mean over both directions of `n_x · n_y` for nearest pairs (face normals; spec §6.1.2).
    pub normal_cosine: f64,
    /// As `normal_cosine` with `|n_x · n_y|` (ignores orientation).
    pub normal_cosine_abs: f64,
    /// Bounding-box diagonal of the reference's referenced vertices.
    pub reference_diagonal: f64,
    /// Samples actually drawn on each side.
    pub samples: usize,
}

/// Per-direction sums of one nearest-neighbour pass, added in query order.
struct Direction {
    mean: f64,
    mean_squared: f64,
    max: f64,
    cosine: f64,
    cosine_abs: f64,
}

fn one_direction(from: &SurfaceSamples, to: &SurfaceSamples, pairs: &[Nearest]) -> Direction {
    let n = pairs.len() as f64;
    let mut d = Direction {
        mean: 0.0,
        mean_squared: 0.0,
        max: 0.0,
        cosine: 0.0,
        cosine_abs: 0.0,
    };
    for (i, nn) in pairs.iter().enumerate() {
        d.mean += nn.distance;
        d.mean_squared += nn.distance * nn.distance;
        d.max = d.max.max(nn.distance);
        let c = from.normals[i].dot(to.normals[nn.index as usize]);
        d.cosine += c;
        d.cosine_abs += c.abs();
    }
    d.mean /= n;
    d.mean_squared /= n;
    d.cosine /= n;
    d.cosine_abs /= n;
    d
}

/// Bounding-box diagonal of the vertices the triangles reference (0 when there are none).
pub fn bbox_diagonal(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &i in triangles.iter().flatten() {
        let p = positions[i as usize];
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if triangles.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    }
}

/// Compares a mesh `(positions, triangles)` with a reference by sampling both surfaces.
///
/// Returns `None` when either surface has zero total area (nothing to sample). Indices must be in
/// range and coordinates finite (see [`crate::validate_soup`]). Deterministic for given options.
pub fn fidelity(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    ref_positions: &[DVec3],
    ref_triangles: &[[u32; 3]],
    options: &ChamferOptions,
) -> Option<FidelityStats> {
    // The two sides are independent: sample them, and query them, concurrently.
    let (ours, theirs) = rayon::join(
        || sample_surface(positions, triangles, options.samples, options.seed),
        || {
            let seed = options.seed.wrapping_add(1);
            sample_surface(ref_positions, ref_triangles, options.samples, seed)
        },
    );
    if ours.points.is_empty() || theirs.points.is_empty() {
        return None;
    }
    let (forward, backward) = rayon::join(
        || nearest_neighbours(&theirs.points, &ours.points),
        || nearest_neighbours(&ours.points, &theirs.points),
    );
    let f = one_direction(&ours, &theirs, &forward);
    let b = one_direction(&theirs, &ours, &backward);
    let diag = bbox_diagonal(ref_positions, ref_triangles);
    let chamfer = 0.5 * (f.mean + b.mean);
    let hausdorff = f.max.max(b.max);
    Some(FidelityStats {
        chamfer_l2: chamfer,
        chamfer_l2_over_diag: chamfer / diag,
        chamfer_l2_squared_sum: f.mean_squared + b.mean_squared,
        hausdorff,
        hausdorff_over_diag: hausdorff / diag,
        normal_cosine: 0.5 * (f.cosine + b.cosine),
        normal_cosine_abs: 0.5 * (f.cosine_abs + b.cosine_abs),
        reference_diagonal: diag,
        samples: options.samples,
    })
}
