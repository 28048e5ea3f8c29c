//! Sliver flips: planted caps in flat regions are flipped away; on creases, a badly shaped cap is
//! left alone and a degenerate one is flipped into its neighbour, keeping the crease;
//! and on random meshes the flips keep the mesh valid, never worsen the worst face and never
//! create an intersection.

mod blocks_common;

use blocks_common::{random_mesh, worst_quality};
use proptest::prelude::*;
use roar_mesh::shapes::{cube, icosphere};
use roar_mesh::spatial::count_intersecting_faces;
use roar_mesh::spatial::triangle_quality;
use roar_mesh::{FaceId, Mesh};
use roar_ops::finish::slivers::{SliverOptions, flip_slivers};

/// Splits `f` at a point close to the middle of its first edge: a cap (one angle near 180°).
fn plant_cap(mesh: &mut Mesh, f: FaceId, closeness: f64) {
    let w = 0.5 * (1.0 - closeness);
    mesh.split_face(f, [w, w, closeness]);
}

#[test]
fn a_cap_in_a_flat_region_is_flipped_away() {
    let mut mesh = icosphere(3);
    let f = mesh.faces().next().unwrap();
    plant_cap(&mut mesh, f, 0.01);
    let before = worst_quality(&mesh);
    assert!(before > 20.0, "the planted cap has Q = {before}");
    let faces = mesh.n_faces();
    let stats = flip_slivers(&mut mesh, &SliverOptions::default());
    assert!(stats.accepted >= 1, "{stats:?}");
    mesh.validate().unwrap();
    assert_eq!(mesh.n_faces(), faces);
    let after = worst_quality(&mesh);
    assert!(after < 10.0, "worst Q {before} -> {after}");
    assert_eq!(count_intersecting_faces(&mesh), 0);
}

/// A cube with a cap planted on one of its edges (a crease) at `closeness`; returns the mesh and
/// the cap's quality.
fn cube_with_cap_on_a_crease(closeness: f64) -> (Mesh, f64) {
    let mut mesh = cube();
    let f = mesh.faces().next().unwrap();
    // The first edge of a cube face may be a diagonal (flat) or a cube edge (a crease); plant
    // the cap on one that lies on a crease.
    let h = mesh.halfedge_of_face(f);
    let across = mesh.face(mesh.twin(h));
    let crease = mesh.face_normal(f).dot(mesh.face_normal(across)) < 0.5;
    let f = if crease {
        f
    } else {
        mesh.face(mesh.twin(mesh.next(h)))
    };
    plant_cap(&mut mesh, f, closeness);
    let h = mesh.halfedge_of_face(f);
    assert!(
        mesh.face_normal(f)
            .dot(mesh.face_normal(mesh.face(mesh.twin(h))))
            < 0.5
    );
    let quality = triangle_quality(mesh.face_vertices(f).map(|v| mesh.position(v)));
    (mesh, quality)
}

/// Whether every face's normal is one of the cube's six axis directions, within `tolerance`.
fn faces_lie_on_the_cube(mesh: &Mesh, tolerance: f64) -> bool {
    mesh.faces().all(|f| {
        let n = mesh.face_normal(f);
        n.abs().max_element() >= 1.0 - tolerance
    })
}

#[test]
fn a_badly_shaped_but_not_degenerate_cap_across_a_crease_is_left_alone() {
    let (mut mesh, quality) = cube_with_cap_on_a_crease(0.05);
    // A sliver (above 10) whose normal is still meaningful (below the degenerate limit 100).
    assert!(
        (10.0..100.0).contains(&quality),
        "the cap has Q = {quality}"
    );
    let before = mesh.to_triangles();
    let stats = flip_slivers(&mut mesh, &SliverOptions::default());
    assert_eq!(stats.accepted, 0, "{stats:?}");
    assert!(stats.rejected.get("dihedral").copied().unwrap_or(0) >= 1);
    assert_eq!(mesh.to_triangles(), before);
}

#[test]
fn a_degenerate_cap_along_a_crease_is_flipped_into_its_neighbour_and_the_crease_stays() {
    let (mut mesh, quality) = cube_with_cap_on_a_crease(0.001);
    assert!(quality > 100.0, "the cap has Q = {quality}");
    let positions = mesh.to_triangles().0;
    let stats = flip_slivers(&mut mesh, &SliverOptions::default());
    assert!(stats.accepted >= 1, "{stats:?}");
    mesh.validate().unwrap();
    assert!(
        worst_quality(&mesh) < 10.0,
        "worst Q {}",
        worst_quality(&mesh)
    );
    // No vertex moved, and every face now lies on a face of the cube: the crease is intact.
    assert_eq!(mesh.to_triangles().0, positions);
    assert!(faces_lie_on_the_cube(&mesh, 1e-3));
    assert_eq!(count_intersecting_faces(&mesh), 0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn sliver_flips_keep_the_mesh_valid_and_never_make_it_worse(
        kind in 0u8..4,
        jitter in 0.0f64..0.05,
        seed in 0u64..1000,
        caps in proptest::collection::vec((0usize..1000, 0.001f64..0.05), 1..12),
    ) {
        let mut mesh = random_mesh(kind, jitter, seed);
        for (pick, closeness) in caps {
            let f = mesh.faces().nth(pick % mesh.n_faces()).unwrap();
            plant_cap(&mut mesh, f, closeness);
        }
        let clean = count_intersecting_faces(&mesh) == 0;
        let (faces, euler, worst) = (mesh.n_faces(), mesh.euler_characteristic(), worst_quality(&mesh));
        flip_slivers(&mut mesh, &SliverOptions::default());
        prop_assert!(mesh.validate().is_ok());
        prop_assert_eq!(mesh.n_faces(), faces);
        prop_assert_eq!(mesh.euler_characteristic(), euler);
        prop_assert!(worst_quality(&mesh) <= worst);
        if clean {
            prop_assert_eq!(count_intersecting_faces(&mesh), 0);
        }
    }
}
