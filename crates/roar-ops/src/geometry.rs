//! Per-block geometry snapshots on the half-edge mesh (`docs/method.md#conventions`): face normals
//! and areas, ROAR vertex normals (the area × corner-angle weights of `roar_mesh::spatial`), the
//! normal magnitude μ_v and face folds φ_f. Computed once per block call into `Vec`s indexed by
//! element id (slot), dead slots hold zeros.

use roar_mesh::spatial::area_angle_weights;
use roar_mesh::{DEGENERATE_CROSS, DVec3, EdgeId, Mesh, VertexId};

/// The aspect ratio (`roar_mesh::spatial::triangle_quality`) from which a face counts as degenerate,
/// the default of the QEM, the sliver flips, the degenerate collapses and the pipeline's fill:
/// above it a face's normal is rounding noise.
pub const DEGENERATE_QUALITY: f64 = 100.0;

/// Whether a triangle of aspect ratio `q` (`roar_mesh::spatial::triangle_quality`) is degenerate: at or above
/// `limit`, or NaN (fully collapsed). Such a face's normal is rounding noise, which the sliver
/// flips and the degenerate collapses must not trust.
pub fn is_degenerate(q: f64, limit: f64) -> bool {
    q.is_nan() || q >= limit
}

/// The mean length of the edges at `v` (`None` for an isolated vertex): the local scale the
/// finish's far-vertex tests (fin collapses, fairing) compare distances with.
pub fn mean_edge_length(mesh: &Mesh, v: VertexId) -> Option<f64> {
    let p = mesh.position(v);
    let (sum, count) = mesh.neighbors(v).fold((0.0, 0), |(s, n), w| {
        (s + (mesh.position(w) - p).length(), n + 1)
    });
    (count > 0).then(|| sum / count as f64)
}

/// Positions of `[a, b, c, d]` for edge (a, b) with faces (a, b, c) and (b, a, d): the quad that
/// flipping the edge re-triangulates into (a, d, c), (b, c, d).
pub fn flip_quad(mesh: &Mesh, e: EdgeId) -> [DVec3; 4] {
    let h = e.halfedge();
    [
        mesh.tail(h),
        mesh.head(h),
        mesh.opposite_vertex(h),
        mesh.opposite_vertex(h.twin()),
    ]
    .map(|v| mesh.position(v))
}

/// Whether both faces after the flip of [`flip_quad`]'s edge keep the orientation of the pair:
/// `N_old · n_new > 0` for each, with `N_old = n_L + n_R` unnormalized, so no face turns over.
pub fn flip_keeps_orientation([pa, pb, pc, pd]: [DVec3; 4]) -> bool {
    let n_old = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
    n_old.dot((pd - pa).cross(pc - pa)) > 0.0 && n_old.dot((pc - pb).cross(pd - pb)) > 0.0
}

/// Geometry of one mesh state, indexed by slot id.
#[derive(Debug, Clone, Default)]
pub struct Geometry {
    /// Unit face normals (degenerate faces: `(1, 0, 0)`), by face slot.
    pub face_normals: Vec<DVec3>,
    /// Face areas clamped below at 1e-9, by face slot.
    pub face_areas: Vec<f64>,
    /// Unnormalized ROAR vertex normal `N_v = Σ_f A_f θ_{f,v} n_f`, by vertex slot.
    pub vertex_normals_raw: Vec<DVec3>,
    /// Unit vertex normal `N_v / |N_v|` (zero if `N_v` vanishes), by vertex slot.
    pub vertex_normals: Vec<DVec3>,
    /// Normal magnitude `μ_v = |N_v| / Σ_f A_f θ_{f,v}` ∈ [0, 1], by vertex slot.
    pub normal_magnitude: Vec<f64>,
}

impl Geometry {
    /// Computes all quantities in one pass over the faces, O(F).
    pub fn compute(mesh: &Mesh) -> Self {
        let nf = mesh.face_capacity();
        let nv = mesh.vertex_capacity();
        let mut g = Geometry {
            face_normals: vec![DVec3::ZERO; nf],
            face_areas: vec![0.0; nf],
            vertex_normals_raw: vec![DVec3::ZERO; nv],
            vertex_normals: vec![DVec3::ZERO; nv],
            normal_magnitude: vec![0.0; nv],
        };
        let mut weight_sum = vec![0.0; nv];
        for f in mesh.faces() {
            let vs = mesh.face_vertices(f);
            let p = vs.map(|v| mesh.position(v));
            let (n, weights) = area_angle_weights(p);
            g.face_normals[f.index()] = n;
            g.face_areas[f.index()] =
                (0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()).max(DEGENERATE_CROSS);
            for k in 0..3 {
                g.vertex_normals_raw[vs[k].index()] += weights[k] * n;
                weight_sum[vs[k].index()] += weights[k];
            }
        }
        for v in mesh.vertices() {
            let i = v.index();
            let raw = g.vertex_normals_raw[i];
            g.vertex_normals[i] = raw.normalize_or_zero();
            g.normal_magnitude[i] = if weight_sum[i] > 0.0 {
                (raw.length() / weight_sum[i]).min(1.0)
            } else {
                0.0
            };
        }
        g
    }

    /// Unit normal of vertex `v`.
    pub fn vertex_normal(&self, v: VertexId) -> DVec3 {
        self.vertex_normals[v.index()]
    }

    /// Face folds `φ_f = 1 − (1/3) Σ_k n_f · n_{v_k}` by face slot: 0 on smooth
    /// surfaces, above 1 when a face points against its own vertex normals.
    pub fn face_folds(&self, mesh: &Mesh) -> Vec<f64> {
        let mut folds = vec![0.0; mesh.face_capacity()];
        for f in mesh.faces() {
            folds[f.index()] = 1.0
                - self
                    .vertex_normal_sum(mesh, f)
                    .dot(self.face_normals[f.index()])
                    / 3.0;
        }
        folds
    }

    /// `Σ_k n_{v_k}` over the three corners of face `f` (unit vertex normals).
    pub fn vertex_normal_sum(&self, mesh: &Mesh, f: roar_mesh::FaceId) -> DVec3 {
        mesh.face_vertices(f)
            .iter()
            .map(|&v| self.vertex_normals[v.index()])
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;

    #[test]
    fn sphere_normals_point_outward_with_unit_magnitude() {
        let mesh = icosphere(2);
        let g = Geometry::compute(&mesh);
        for v in mesh.vertices() {
            let p = mesh.position(v);
            assert!(g.vertex_normal(v).dot(p.normalize()) > 0.99);
            let mu = g.normal_magnitude[v.index()];
            assert!(mu > 0.97 && mu <= 1.0, "μ = {mu}");
        }
        let folds = g.face_folds(&mesh);
        assert!(mesh.faces().all(|f| folds[f.index()].abs() < 0.02));
    }
}
