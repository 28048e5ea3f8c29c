//! Tangential smoothing ("improve quality", spec §3.9): one Jacobi sweep moving every smooth
//! vertex toward the area-weighted barycentre of its incident face centroids, within its
//! tangent plane. Sizing field s ≡ 1.
//!
//! ```text
//! q_v = Σ_f A_f c_f / Σ_f A_f
//! v'  = v − λ_v (I − n_v n_vᵀ)(v − q_v),   λ_v = 1 if μ_v ≥ 0.98 else 0
//! ```

use crate::block::{Block, BlockContext, BlockStats};
use crate::geometry::Geometry;
use crate::optim::Optimizer;
use crate::untangle::{LimiterOptions, limit_moves};
use roar_mesh::{DVec3, Mesh};

/// Options of [`tangential_smoothing`] (spec §3.9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothingOptions {
    /// Vertices with normal magnitude μ_v below this stay put (creases, spikes, folds).
    /// Default 0.98 ([SUP], §3.9).
    pub min_normal_magnitude: f64,
    /// Shorten or cancel moves that would make faces intersect ([`limit_moves`], counted in
    /// `counters["shortened"]`, `counters["cancelled"]`). Default off (the paper's block); the
    /// pipeline's `guard_intersections` key switches it on. [INF]
    pub guard_intersections: bool,
}

impl Default for SmoothingOptions {
    fn default() -> Self {
        Self {
            min_normal_magnitude: 0.98,
            guard_intersections: false,
        }
    }
}

/// One sweep of tangential smoothing (spec §3.9). All new positions are computed from the old
/// ones (Jacobi), so the result does not depend on the vertex order. No topology change.
///
/// Stats: `candidates` = live vertices, `accepted` = vertices moved, `rejected["crease"]` =
/// vertices skipped for μ_v < threshold.
pub fn tangential_smoothing(mesh: &mut Mesh, options: &SmoothingOptions) -> BlockStats {
    let mut stats = BlockStats::new("tangential_smoothing");
    let geometry = Geometry::compute(mesh);
    let mut moves: Vec<(roar_mesh::VertexId, DVec3)> = Vec::new();
    for v in mesh.vertices() {
        stats.candidates += 1;
        if geometry.normal_magnitude[v.index()] < options.min_normal_magnitude {
            stats.reject("crease", 1);
            continue;
        }
        let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
        for f in mesh.faces_around(v) {
            let a = geometry.face_areas[f.index()];
            sum += a * mesh.face_centroid(f);
            weight += a;
        }
        if weight <= 0.0 {
            continue;
        }
        let p = mesh.position(v);
        let n = geometry.vertex_normals[v.index()];
        let d = p - sum / weight;
        let tangential = d - n * n.dot(d);
        moves.push((v, p - tangential));
    }
    let before = options
        .guard_intersections
        .then(|| mesh.positions().to_vec());
    for &(v, p) in &moves {
        if p.is_finite() {
            mesh.set_position(v, p);
            stats.accepted += 1;
        }
    }
    if let Some(before) = before {
        let triangles: Vec<[u32; 3]> = mesh
            .faces()
            .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
            .collect();
        let limited = limit_moves(
            &before,
            mesh.positions_mut(),
            &triangles,
            &LimiterOptions::default(),
        );
        stats.count("shortened", limited.shortened);
        stats.count("cancelled", limited.cancelled);
    }
    stats
}

/// [`Block`] wrapper of [`tangential_smoothing`].
#[derive(Debug, Clone, Default)]
pub struct TangentialSmoothing {
    /// Options passed to [`tangential_smoothing`].
    pub options: SmoothingOptions,
}

impl Block for TangentialSmoothing {
    fn name(&self) -> &'static str {
        "tangential_smoothing"
    }

    fn apply(
        &mut self,
        mesh: &mut Mesh,
        _optimizer: &mut Optimizer,
        _ctx: &BlockContext,
    ) -> BlockStats {
        tangential_smoothing(mesh, &self.options)
    }
}
