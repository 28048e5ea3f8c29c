//! QSlim cost (`docs/method.md#decision-vertex-plane-of-the-collapse-cost`): free in flat regions
//! for the normalized vertex plane, Laplacian-driven for the code's raw variant, positive across a
//! crease.

use roar_mesh::shapes::genus_n_solid;
use roar_mesh::{DVec3, EdgeId, Mesh};
use roar_ops::blocks::qslim::{
    QSlimOptions, ValidityOptions, VertexPlane, edge_cost, generalized_vertex_normal,
    vertex_quadrics,
};
use roar_ops::geometry::Geometry;

/// An edge of the box whose two endpoints only touch faces with normal +z (a flat region).
fn flat_edge(mesh: &Mesh) -> EdgeId {
    let flat = |v| {
        mesh.faces_around(v)
            .all(|f| mesh.face_normal(f).dot(DVec3::Z) > 1.0 - 1e-12)
    };
    mesh.edges()
        .find(|&e| mesh.edge_vertices(e).iter().all(|&v| flat(v)))
        .expect("the box's top has interior vertices")
}

#[test]
fn flat_collapse_is_free_with_the_normalized_vertex_plane() {
    let mesh = genus_n_solid(0);
    let e = flat_edge(&mesh);
    let g = Geometry::compute(&mesh);
    let options = QSlimOptions {
        vertex_plane: VertexPlane::NormalizedMagnitude,
        ..QSlimOptions::default()
    };
    let q = vertex_quadrics(&mesh, &g, &options);
    let c = edge_cost(&mesh, &q, e, &ValidityOptions::default()).unwrap();
    assert!(c.cost < 1e-12, "cost {}", c.cost);
}

#[test]
fn flat_collapse_with_the_raw_vertex_plane_pays_for_the_laplacian_tilt() {
    // Code variant: face and edge planes are all the flat plane (cost 0), but the vertex plane of
    // the removed endpoint r has normal ñ_r = normalize(N|N|² + δ(1−|N|)²), tilted toward the
    // in-plane Laplacian δ_r, so the collapse costs 100·(ñ_r·(p_keep − p_r))² (0 only where
    // δ_r ⟂ the edge).
    let mesh = genus_n_solid(0);
    let e = flat_edge(&mesh);
    let g = Geometry::compute(&mesh);
    let q = vertex_quadrics(&mesh, &g, &QSlimOptions::default());
    let c = edge_cost(&mesh, &q, e, &ValidityOptions::default()).unwrap();
    let [a, b] = mesh.edge_vertices(e);
    let expected = |keep, remove| {
        let n = generalized_vertex_normal(&mesh, &g, remove, VertexPlane::RawMagnitude);
        100.0 * n.dot(mesh.position(keep) - mesh.position(remove)).powi(2)
    };
    let best = expected(a, b).min(expected(b, a));
    assert!((c.cost - best).abs() < 1e-9, "cost {} vs {}", c.cost, best);
    assert!(c.cost >= 0.0);
}

#[test]
fn collapse_across_a_crease_costs() {
    // Octahedron: every edge joins two vertices on sharp features; both placements deform it.
    let positions = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let tris = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mesh = Mesh::from_triangles(positions, &tris).unwrap();
    let g = Geometry::compute(&mesh);
    for variant in [VertexPlane::RawMagnitude, VertexPlane::NormalizedMagnitude] {
        let q = vertex_quadrics(
            &mesh,
            &g,
            &QSlimOptions {
                vertex_plane: variant,
                ..QSlimOptions::default()
            },
        );
        for e in mesh.edges() {
            let c = edge_cost(&mesh, &q, e, &ValidityOptions::default()).unwrap();
            assert!(c.cost > 10.0, "{variant:?} {e:?}: cost {}", c.cost);
        }
    }
}
