//! The fill to a face budget by edge splits: the finish's way up to N from a loop state below
//! it and back up after the untangle block's and the degenerate collapses' removals. Longest
//! first, splits move no geometry, so no self-intersection can appear; on a field, where the
//! chords stray from the zero set first, with the new vertices moved onto it.

use glam::DVec3;
use roar_mesh::spatial::{Sdf, first_order_distances, project_to_zero_set, triangle_quality};
use roar_mesh::{EdgeId, EdgeSplit, Mesh, VertexId};

use crate::geometry::{DEGENERATE_QUALITY, is_degenerate};

/// Splits edges at their midpoints until the mesh has `faces` faces (each split adds two),
/// longest first, skipping edges whose halving would leave a degenerate face
/// ([`bisects_well`]): halving a needle's long edge leaves two needles and halving a flat
/// cap's edge can make a flatter one, which would undo the degenerate collapses this fill
/// follows. When no edge qualifies the longest is split anyway, so the fill always ends. The
/// geometry does not change, so no intersection can appear. Returns the split count.
pub fn fill_to_budget(mesh: &mut Mesh, faces: usize) -> usize {
    fill_in_rounds(
        mesh,
        faces,
        1.0,
        |mesh, edges| edges.iter().map(|&e| mesh.edge_length(e)).collect(),
        |_, _| {},
    )
}

/// [`fill_to_budget`] on a field: the edges along which the surface curves farthest away from
/// the chord are split first, in rounds that each split at most a quarter of the edges and
/// then judge the new ones, and each new vertex is moved onto the zero set. An edge's gap is
/// `|s(m) − (s(a) + s(b))/2|`, `s` the signed first-order distance `f/(|∇f| + epsilon)` of
/// `sdf` and `m` the midpoint of `(a, b)`: the chord's sagitta. Longest first would subdivide
/// flat and curved parts alike; this puts the faces where the surface bends, as a QEM of a fine
/// extraction does. A new vertex left on its chord would stand off the surface by that sagitta,
/// a large part of its short new edges where the surface bends sharply, so it takes up to three
/// first-order steps onto the zero set, kept when they move it at most half the split edge's
/// length in all.
///
/// Unlike [`fill_to_budget`] this moves geometry, so faces may come to intersect: call it where
/// the untangle block follows.
pub fn fill_to_budget_on_field(
    mesh: &mut Mesh,
    faces: usize,
    sdf: &dyn Sdf,
    epsilon: f64,
) -> usize {
    let priority = |mesh: &Mesh, edges: &[EdgeId]| -> Vec<f64> {
        let vertices: Vec<VertexId> = mesh.vertices().collect();
        let ends: Vec<[VertexId; 2]> = edges.iter().map(|&e| mesh.edge_vertices(e)).collect();
        let points: Vec<DVec3> = vertices
            .iter()
            .map(|&v| mesh.position(v))
            .chain(
                ends.iter()
                    .map(|&[a, b]| 0.5 * (mesh.position(a) + mesh.position(b))),
            )
            .collect();
        let s = first_order_distances(sdf, &points, epsilon);
        let mut at_vertex = vec![0.0; mesh.vertex_capacity()];
        for (v, &d) in vertices.iter().zip(&s) {
            at_vertex[v.index()] = d;
        }
        ends.iter()
            .zip(&s[vertices.len()..])
            .map(|(&[a, b], &m)| {
                let gap = (m - 0.5 * (at_vertex[a.index()] + at_vertex[b.index()])).abs();
                if gap.is_finite() { gap } else { 0.0 }
            })
            .collect()
    };
    let onto_zero_set = |mesh: &mut Mesh, splits: &[EdgeSplit]| {
        let start: Vec<DVec3> = splits.iter().map(|s| mesh.position(s.new_vertex)).collect();
        let mut moved = start.clone();
        project_to_zero_set(sdf, &mut moved, 3, epsilon);
        for ((split, from), to) in splits.iter().zip(start).zip(moved) {
            let [a, b] = split.parents.map(|v| mesh.position(v));
            if to.is_finite() && from.distance(to) <= 0.5 * a.distance(b) {
                mesh.set_position(split.new_vertex, to);
            }
        }
    };
    fill_in_rounds(mesh, faces, 0.25, priority, onto_zero_set)
}

/// The fill's rounds: each ranks the edges that [`bisects_well`] (all edges when none does) by
/// `priority`, highest first, ties by id, splits as many as the budget still wants, at most
/// `fraction` of them (at least one), and hands the round's splits to `settle`.
fn fill_in_rounds(
    mesh: &mut Mesh,
    faces: usize,
    fraction: f64,
    mut priority: impl FnMut(&Mesh, &[EdgeId]) -> Vec<f64>,
    mut settle: impl FnMut(&mut Mesh, &[EdgeSplit]),
) -> usize {
    let mut splits = 0;
    while mesh.n_faces() < faces {
        let mut candidates: Vec<EdgeId> = mesh.edges().filter(|&e| bisects_well(mesh, e)).collect();
        if candidates.is_empty() {
            candidates = mesh.edges().collect();
        }
        let mut edges: Vec<(f64, EdgeId)> = priority(mesh, &candidates)
            .into_iter()
            .zip(candidates)
            .collect();
        edges.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let wanted = ((faces - mesh.n_faces()) / 2)
            .min((fraction * edges.len() as f64).ceil() as usize)
            .max(1);
        let mut round = Vec::with_capacity(wanted);
        for &(_, e) in edges.iter().take(wanted) {
            if mesh.n_faces() >= faces {
                break;
            }
            round.push(mesh.split_edge(e, 0.5));
        }
        splits += round.len();
        settle(mesh, &round);
    }
    mesh.compact();
    splits
}

/// Whether halving `e` leaves no degenerate face ([`DEGENERATE_QUALITY`]): neither face of `e`
/// is degenerate, nor is any of the four faces the split would make (see [`fill_to_budget`]).
pub fn bisects_well(mesh: &Mesh, e: EdgeId) -> bool {
    let h = mesh.edge_halfedge(e);
    [h, h.twin()].into_iter().all(|h| {
        let (a, b) = (mesh.position(mesh.tail(h)), mesh.position(mesh.head(h)));
        let c = mesh.position(mesh.head(mesh.next(h)));
        let m = 0.5 * (a + b);
        [[a, b, c], [a, m, c], [m, b, c]]
            .into_iter()
            .all(|t| !is_degenerate(triangle_quality(t), DEGENERATE_QUALITY))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::FnSdf;

    /// An icosphere stretched threefold along x: its vertices lie on the ellipsoid
    /// `(x/3)² + y² + z² = 1`, whose ends curve nine times more than its waist.
    fn ellipsoid() -> (Mesh, FnSdf<impl Fn(DVec3) -> f64 + Send + Sync>) {
        let mut mesh = icosphere(2);
        let vertices: Vec<_> = mesh.vertices().collect();
        for v in vertices {
            let p = mesh.position(v);
            mesh.set_position(v, DVec3::new(3.0 * p.x, p.y, p.z));
        }
        let field = FnSdf::new(|p: DVec3| DVec3::new(p.x / 3.0, p.y, p.z).length() - 1.0);
        (mesh, field)
    }

    /// The largest first-order distance of `points` from the zero set of `field`; panics on a
    /// non-finite distance, which `f64::max` would skip.
    fn farthest_from_zero_set(field: &dyn Sdf, points: &[DVec3]) -> f64 {
        let distances = first_order_distances(field, points, 0.0);
        assert!(
            distances.iter().all(|d| d.is_finite()),
            "a non-finite distance"
        );
        distances.into_iter().fold(0.0, |far, d| far.max(d.abs()))
    }

    /// The largest first-order distance of an edge midpoint from the zero set of `field`.
    fn largest_chord_gap(mesh: &Mesh, field: &dyn Sdf) -> f64 {
        let midpoints: Vec<DVec3> = mesh
            .edges()
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                0.5 * (mesh.position(a) + mesh.position(b))
            })
            .collect();
        farthest_from_zero_set(field, &midpoints)
    }

    #[test]
    fn both_fills_reach_the_budget_with_a_valid_mesh() {
        let (mesh, field) = ellipsoid();
        let budget = 4 * mesh.n_faces() + 2;
        let mut by_length = mesh.clone();
        let mut on_field = mesh.clone();
        let splits = fill_to_budget(&mut by_length, budget);
        let field_splits = fill_to_budget_on_field(&mut on_field, budget, &field, 1e-10);
        for (filled, splits) in [(&by_length, splits), (&on_field, field_splits)] {
            assert_eq!(filled.n_faces(), budget);
            assert_eq!(splits, (budget - mesh.n_faces()) / 2);
            filled.validate().unwrap();
            assert_eq!(filled.genus(), 0);
        }
    }

    #[test]
    fn the_field_fill_splits_where_the_chords_stray_from_the_zero_set() {
        let (mesh, field) = ellipsoid();
        let budget = 4 * mesh.n_faces();
        let mut by_length = mesh.clone();
        let mut on_field = mesh.clone();
        fill_to_budget(&mut by_length, budget);
        fill_to_budget_on_field(&mut on_field, budget, &field, 1e-10);
        // The finish fits the mesh to the zero set after the fill: here every vertex is put on
        // it, so what is left of a gap is the chord's own.
        for filled in [&mut by_length, &mut on_field] {
            let vertices: Vec<_> = filled.vertices().collect();
            let mut points: Vec<DVec3> = vertices.iter().map(|&v| filled.position(v)).collect();
            project_to_zero_set(&field, &mut points, 20, 1e-12);
            for (v, p) in vertices.into_iter().zip(points) {
                filled.set_position(v, p);
            }
        }
        let (length_gap, field_gap) = (
            largest_chord_gap(&by_length, &field),
            largest_chord_gap(&on_field, &field),
        );
        assert!(
            field_gap < 0.7 * length_gap,
            "largest chord gap: {field_gap:.3e} on the field, {length_gap:.3e} longest first"
        );
    }

    #[test]
    fn the_field_fill_puts_its_new_vertices_on_the_zero_set() {
        let (mut mesh, field) = ellipsoid();
        let budget = 4 * mesh.n_faces();
        fill_to_budget_on_field(&mut mesh, budget, &field, 1e-10);
        let points: Vec<DVec3> = mesh.vertices().map(|v| mesh.position(v)).collect();
        let farthest = farthest_from_zero_set(&field, &points);
        assert!(farthest < 1e-6, "a vertex {farthest:.3e} off the zero set");
    }
}
