//! Degenerate-face collapses: a planted needle, which no sliver flip fixes, is collapsed away
//! without moving a vertex; on random meshes with planted caps and needles the collapses keep
//! the mesh valid, only lower the number of degenerate faces, and never create an intersection.

mod blocks_common;

use blocks_common::random_mesh;
use proptest::prelude::*;
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::count_intersecting_faces;
use roar_mesh::spatial::triangle_quality;
use roar_mesh::{EdgeId, Mesh, VertexId};
use roar_ops::finish::degenerate::{DegenerateOptions, collapse_degenerate_faces};
use roar_ops::finish::slivers::{SliverOptions, flip_slivers};
use roar_ops::geometry::{DEGENERATE_QUALITY, is_degenerate};

fn degenerate_faces(mesh: &Mesh) -> usize {
    mesh.faces()
        .map(|f| triangle_quality(mesh.face_vertices(f).map(|v| mesh.position(v))))
        .filter(|&q| is_degenerate(q, DEGENERATE_QUALITY))
        .count()
}

/// Bit patterns of every live vertex position.
fn positions(mesh: &Mesh) -> Vec<[u64; 3]> {
    let mut keys: Vec<[u64; 3]> = mesh
        .vertices()
        .map(|v| mesh.position(v).to_array().map(f64::to_bits))
        .collect();
    keys.sort();
    keys
}

/// Splits `e` at `t` from its first end: with `t` near 0, two needles.
fn plant_needle(mesh: &mut Mesh, e: EdgeId, t: f64) {
    mesh.split_edge(e, t);
}

#[test]
fn a_needle_that_no_flip_fixes_is_collapsed_away_without_moving_a_vertex() {
    let mut mesh = icosphere(3);
    let e = mesh.edges().next().unwrap();
    plant_needle(&mut mesh, e, 1e-3);
    assert_eq!(degenerate_faces(&mesh), 2);
    let mut flipped = mesh.clone();
    flip_slivers(&mut flipped, &SliverOptions::default());
    assert_eq!(degenerate_faces(&flipped), 2, "a flip fixed the needles");

    let before = positions(&mesh);
    let faces = mesh.n_faces();
    let stats = collapse_degenerate_faces(&mut mesh, &DegenerateOptions::default());
    assert_eq!(stats.accepted, 1, "{stats:?}");
    mesh.validate().unwrap();
    assert_eq!(mesh.n_faces(), faces - 2);
    assert_eq!(degenerate_faces(&mesh), 0);
    assert_eq!(count_intersecting_faces(&mesh), 0);
    let after = positions(&mesh);
    assert!(after.iter().all(|p| before.binary_search(p).is_ok()));
}

/// Splits the edge from `from` to `to` at `t` of its length from `from`; returns the new vertex.
fn split_near(mesh: &mut Mesh, from: VertexId, to: VertexId, t: f64) -> VertexId {
    let h = mesh.find_halfedge(from, to).unwrap();
    let e = mesh.edge(h);
    let t = if mesh.edge_vertices(e)[0] == from {
        t
    } else {
        1.0 - t
    };
    mesh.split_edge(e, t).new_vertex
}

#[test]
fn a_cluster_where_every_collapse_keeps_another_needle_is_still_collapsed_away() {
    // Three vertices u, v, w within 1e-4 of an edge length of each other, inside one face
    // (p, q, r): the needles (r, v, u), (v, q, w) and (w, r, u). Whichever short edge
    // collapses, a needle of the cluster stays a needle, so a rule that refuses any degenerate
    // reshaped face refuses them all; a needle may stay one as long as no face becomes one.
    let mut mesh = icosphere(3);
    let f = mesh.faces().next().unwrap();
    let split = mesh.split_face(f, [1.0 / 3.0; 3]);
    let (u, [p, q, _]) = (split.new_vertex, split.parents);
    split_near(&mut mesh, u, p, 1e-4);
    split_near(&mut mesh, u, q, 1e-4);
    assert_eq!(degenerate_faces(&mesh), 3);

    let before = positions(&mesh);
    let faces = mesh.n_faces();
    let stats = collapse_degenerate_faces(&mut mesh, &DegenerateOptions::default());
    mesh.validate().unwrap();
    assert_eq!(degenerate_faces(&mesh), 0, "{stats:?}");
    assert_eq!(mesh.n_faces(), faces - 2 * stats.accepted);
    assert_eq!(count_intersecting_faces(&mesh), 0);
    let after = positions(&mesh);
    assert!(after.iter().all(|p| before.binary_search(p).is_ok()));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn degenerate_collapses_keep_the_mesh_valid_and_only_remove_degenerate_faces(
        kind in 0u8..4,
        jitter in 0.0f64..0.05,
        seed in 0u64..1000,
        plants in proptest::collection::vec((0usize..1000, 1e-4f64..0.02, any::<bool>()), 1..12),
    ) {
        let mut mesh = random_mesh(kind, jitter, seed);
        for (pick, closeness, needle) in plants {
            if needle {
                let e = mesh.edges().nth(pick % mesh.n_edges()).unwrap();
                plant_needle(&mut mesh, e, closeness);
            } else {
                let f = mesh.faces().nth(pick % mesh.n_faces()).unwrap();
                let w = 0.5 * (1.0 - closeness);
                mesh.split_face(f, [w, w, closeness]);
            }
        }
        let clean = count_intersecting_faces(&mesh) == 0;
        let (faces, euler, degenerate) =
            (mesh.n_faces(), mesh.euler_characteristic(), degenerate_faces(&mesh));
        let before = positions(&mesh);
        let stats = collapse_degenerate_faces(&mut mesh, &DegenerateOptions::default());
        prop_assert!(mesh.validate().is_ok());
        prop_assert_eq!(mesh.n_faces(), faces - 2 * stats.accepted);
        prop_assert_eq!(mesh.euler_characteristic(), euler);
        prop_assert!(degenerate_faces(&mesh) + stats.accepted <= degenerate);
        let after = positions(&mesh);
        prop_assert!(after.iter().all(|p| before.binary_search(p).is_ok()));
        if clean {
            prop_assert_eq!(count_intersecting_faces(&mesh), 0);
        }
    }
}
