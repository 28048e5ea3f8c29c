//! Fin collapses for an SDF input's finished mesh: vertices far off the field's zero set merged
//! into their neighbour nearest to it.
//!
//! The untangle clears the loop's crossings by pushing vertices apart; where two sheets crossed
//! (a concave corner) that can leave a *fin*, a thin flap of faces standing off the surface. Its
//! vertices are far from the zero set, and moving them back (the fit of [`crate::finish::zero_set`])
//! would fold the flap onto itself, so the fit holds them. Collapsing them removes the flap:
//!
//! ```text
//!        a  (far off the zero set)
//!       /|\
//!      / | \          a → b           b
//!   --c--b--d--      =======>    --c--b--d--
//! ```
//!
//! A vertex is *far* when its first-order distance `|f|/|∇f|` exceeds `max_distance_over_edge`
//! times its mean edge length: a vertex of a mesh that samples the surface is off it by about
//! the sagitta `ℓ²/8R` of its edges, well under half an edge wherever the mesh resolves the
//! surface at all. Far vertices are taken farthest first; each tries its neighbours nearest to
//! the zero set first, and the collapse `a → b` (b keeps its position) is applied when
//! 1. it is topologically legal ([`Mesh::can_collapse`]);
//! 2. no reshaped face that was not degenerate turns over or becomes degenerate (the test of
//!    [`crate::finish::degenerate`], with a turn of up to 90° allowed);
//! 3. no reshaped face intersects another face
//!    ([`IntersectionGuard`](crate::blocks::guard::IntersectionGuard), exact).
//!
//! Each collapse removes two faces; the caller restores the face count (the pipeline's fill
//! splits edges, which moves no geometry) and fits the mesh to the zero set afterwards.

use crate::blocks::block::BlockStats;
use crate::blocks::guard::collapse_if_clean;
use crate::finish::degenerate::reshaped_faces_ok;
use crate::geometry::{DEGENERATE_QUALITY, mean_edge_length};
use glam::DVec3;
use roar_mesh::spatial::{Sdf, first_order_distances};
use roar_mesh::{HalfedgeId, Mesh, VertexId};

/// Options of [`collapse_fins`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FinOptions {
    /// A vertex is far when its first-order distance exceeds this times its mean edge length.
    /// Default 0.5.
    pub max_distance_over_edge: f64,
    /// ε of the first-order distance `f/(|∇f| + ε)`.
    pub epsilon: f64,
    /// Most rounds (each evaluates the field at every vertex). Default 20.
    pub max_rounds: usize,
}

impl Default for FinOptions {
    fn default() -> Self {
        Self {
            max_distance_over_edge: 0.5,
            epsilon: 1e-10,
            max_rounds: 20,
        }
    }
}

/// Collapses far vertices as the module doc says, in rounds until one collapses nothing. Keeps
/// the mesh valid and, if it was free of self-intersections, keeps it so; removes two faces per
/// collapse.
///
/// Stats: `candidates` = far vertices looked at (over all rounds); `accepted` = collapses;
/// `rejected` (per half-edge tried): `"topology"`, `"normal"`, `"quality"`, `"intersection"`.
pub fn collapse_fins(mesh: &mut Mesh, sdf: &dyn Sdf, options: &FinOptions) -> BlockStats {
    let mut stats = BlockStats::new("fin_collapses");
    for _ in 0..options.max_rounds {
        let distances = vertex_distances(mesh, sdf, options.epsilon);
        let far = far_vertices(mesh, &distances, options.max_distance_over_edge);
        if far.is_empty() {
            break;
        }
        let mut guard = None;
        let mut collapsed = 0;
        for v in far {
            if !mesh.is_vertex_alive(v) {
                continue;
            }
            stats.candidates += 1;
            let mut outgoing: Vec<HalfedgeId> = mesh.outgoing(v).collect();
            outgoing.sort_by(|&x, &y| {
                distances[mesh.head(x).index()].total_cmp(&distances[mesh.head(y).index()])
            });
            for h in outgoing {
                if let Err(reason) = reshaped_faces_ok(mesh, h, DEGENERATE_QUALITY, 0.0) {
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

/// Per vertex slot, the first-order distance `|f|/(|∇f| + ε)` of a live vertex (0 elsewhere).
fn vertex_distances(mesh: &Mesh, sdf: &dyn Sdf, epsilon: f64) -> Vec<f64> {
    let vertices: Vec<VertexId> = mesh.vertices().collect();
    let points: Vec<DVec3> = vertices.iter().map(|&v| mesh.position(v)).collect();
    let mut distances = vec![0.0; mesh.vertex_capacity()];
    for (v, d) in vertices
        .iter()
        .zip(first_order_distances(sdf, &points, epsilon))
    {
        let d = d.abs();
        distances[v.index()] = if d.is_finite() { d } else { 0.0 };
    }
    distances
}

/// The vertices farther than `factor` times their mean edge length, farthest first.
fn far_vertices(mesh: &Mesh, distances: &[f64], factor: f64) -> Vec<VertexId> {
    let mut far: Vec<(f64, VertexId)> = mesh
        .vertices()
        .filter_map(|v| {
            let d = distances[v.index()];
            (d > factor * mean_edge_length(mesh, v)?).then_some((d, v))
        })
        .collect();
    far.sort_by(|a, b| b.0.total_cmp(&a.0));
    far.into_iter().map(|(_, v)| v).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::{FnSdf, self_intersecting_faces};

    fn unit_sphere() -> FnSdf<impl Fn(DVec3) -> f64 + Send + Sync> {
        FnSdf::new(|p: DVec3| p.length() - 1.0)
    }

    #[test]
    fn a_mesh_on_the_zero_set_loses_nothing() {
        let mut mesh = icosphere(3);
        let stats = collapse_fins(&mut mesh, &unit_sphere(), &FinOptions::default());
        assert_eq!((stats.candidates, stats.accepted), (0, 0), "{stats:?}");
    }

    #[test]
    fn a_spike_off_the_sphere_is_collapsed_away() {
        // One vertex of a level-3 icosphere pulled out to radius 1.3 (edges are about 0.16
        // long): a spike far off the zero set. Its collapse leaves a valid, intersection-free
        // mesh two faces smaller whose vertices are all on the sphere again.
        let mut mesh = icosphere(3);
        let faces = mesh.n_faces();
        let tip = mesh.vertices().next().unwrap();
        let p = mesh.position(tip);
        mesh.set_position(tip, 1.3 * p);
        let stats = collapse_fins(&mut mesh, &unit_sphere(), &FinOptions::default());
        assert_eq!(stats.accepted, 1, "{stats:?}");
        assert!(!mesh.is_vertex_alive(tip));
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces - 2);
        for v in mesh.vertices() {
            assert!((mesh.position(v).length() - 1.0).abs() < 1e-12);
        }
        let (positions, triangles) = mesh.to_triangles();
        assert!(!self_intersecting_faces(&positions, &triangles).contains(&true));
    }
}
