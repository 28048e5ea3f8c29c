//! Data-dependent flips: a crease cut across is flipped back onto the cube it came from; on a
//! bumpy sphere the flips lower the normal error against its normals, on a convex ellipsoid they
//! find nothing to do; and on random meshes they keep the mesh valid, move no vertex, never raise
//! the error, never make the worst face worse than the quality bound and never create an
//! intersection.

mod blocks_common;

use blocks_common::{random_mesh, worst_quality};
use proptest::prelude::*;
use roar_mesh::DVec3;
use roar_mesh::shapes::{cube, icosphere};
use roar_mesh::spatial::count_intersecting_faces;
use roar_ops::finish::data_flips::{DataFlipOptions, flip_toward_target, target_normal_error};

/// The normal of the face of the cube `[-0.5, 0.5]³` nearest to `p` (inside the cube: the axis of
/// the largest coordinate).
fn cube_normal(p: DVec3) -> Option<DVec3> {
    let a = p.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        DVec3::X
    } else if a.y >= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    Some(axis * p.dot(axis).signum())
}

#[test]
fn a_crease_cut_across_is_flipped_back_onto_the_cube() {
    let mut mesh = cube();
    // Not 0: on the cube's edges the nearest face is a tie, decided for one side.
    let original = target_normal_error(&mesh, &cube_normal);
    // Flip one cube edge (a crease) so that its two faces cut across the cube's corner region.
    let crease = mesh
        .edges()
        .find(|&e| {
            let h = e.halfedge();
            let (f, g) = (mesh.face(h), mesh.face(h.twin()));
            mesh.face_normal(f).dot(mesh.face_normal(g)) < 0.5 && mesh.can_flip(e).is_ok()
        })
        .expect("a flippable crease");
    mesh.flip(crease).unwrap();
    let cut = target_normal_error(&mesh, &cube_normal);
    assert!(
        cut > original + 0.1,
        "the cut faces leave the cube's normals: {original} -> {cut}"
    );
    let positions = mesh.to_triangles().0;

    let stats = flip_toward_target(&mut mesh, &cube_normal, &DataFlipOptions::default());
    assert!(stats.accepted >= 1, "{stats:?}");
    mesh.validate().unwrap();
    assert_eq!(mesh.to_triangles().0, positions, "no vertex moves");
    assert_eq!(target_normal_error(&mesh, &cube_normal), original);
    assert!(
        mesh.faces()
            .all(|f| mesh.face_normal(f).abs().max_element() > 1.0 - 1e-12),
        "every face lies on a face of the cube again"
    );
}

/// The bumpy sphere `|p| = 1 + 0.2 sin 3x sin 3y sin 3z` (x, y, z of the unit direction), as
/// an implicit function: it has saddles between the bumps, where either diagonal of a quad
/// can be the better one.
fn bumpy(p: DVec3) -> f64 {
    let u = p.normalize();
    p.length() - 1.0 - 0.2 * (3.0 * u.x).sin() * (3.0 * u.y).sin() * (3.0 * u.z).sin()
}

/// The bumpy sphere's unit normal at `p` (central differences of [`bumpy`]).
fn bumpy_normal(p: DVec3) -> Option<DVec3> {
    let h = 1e-6;
    let d = |axis: DVec3| bumpy(p + axis * h) - bumpy(p - axis * h);
    Some(DVec3::new(d(DVec3::X), d(DVec3::Y), d(DVec3::Z)).normalize())
}

#[test]
fn on_a_bumpy_sphere_the_flips_follow_its_normals() {
    // The icosphere's vertices moved radially onto the bumpy sphere; its triangulation is the
    // sphere's, chosen without looking at the bumps.
    let mut mesh = icosphere(3);
    let vertices: Vec<_> = mesh.vertices().collect();
    for v in vertices {
        let u = mesh.position(v).normalize();
        let r = 1.0 - bumpy(u);
        mesh.set_position(v, u * r);
    }
    let before = target_normal_error(&mesh, &bumpy_normal);
    let worst = worst_quality(&mesh);

    let stats = flip_toward_target(&mut mesh, &bumpy_normal, &DataFlipOptions::default());
    let after = target_normal_error(&mesh, &bumpy_normal);
    assert!(stats.accepted >= 100, "{stats:?}");
    assert!(after < 0.9 * before, "error {before} -> {after}");
    mesh.validate().unwrap();
    assert!(worst_quality(&mesh) <= worst.max(4.0));
    assert_eq!(count_intersecting_faces(&mesh), 0);
}

#[test]
fn on_a_convex_surface_the_triangulation_is_already_the_best() {
    // An ellipsoid's vertices span a convex polytope; flipping any edge would make it reflex
    // and tilt both new faces away from the ellipsoid.
    let axes = DVec3::new(1.0, 0.5, 0.2);
    let mut mesh = icosphere(3);
    let vertices: Vec<_> = mesh.vertices().collect();
    for v in vertices {
        let p = mesh.position(v);
        mesh.set_position(v, p * axes);
    }
    let before = mesh.to_triangles();
    let ellipsoid_normal = |p: DVec3| Some((p / (axes * axes)).normalize());
    let stats = flip_toward_target(&mut mesh, &ellipsoid_normal, &DataFlipOptions::default());
    assert_eq!(stats.accepted, 0, "{stats:?}");
    assert_eq!(mesh.to_triangles(), before);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn data_flips_keep_the_mesh_valid_and_never_raise_the_error(
        kind in 0u8..4,
        jitter in 0.0f64..0.08,
        seed in 0u64..1000,
        wave in 0.0f64..1.0,
    ) {
        let mut mesh = random_mesh(kind, jitter, seed);
        // Any smooth unit field will do as the target's normals.
        let field = |p: DVec3| {
            let bend = DVec3::new((3.0 * p.y).sin(), (3.0 * p.z).sin(), (3.0 * p.x).sin());
            Some((p + wave * bend).normalize_or_zero())
        };
        let clean = count_intersecting_faces(&mesh) == 0;
        let (faces, euler) = (mesh.n_faces(), mesh.euler_characteristic());
        let worst = worst_quality(&mesh);
        let positions = mesh.to_triangles().0;
        let before = target_normal_error(&mesh, &field);

        flip_toward_target(&mut mesh, &field, &DataFlipOptions::default());
        prop_assert!(mesh.validate().is_ok());
        prop_assert_eq!(mesh.n_faces(), faces);
        prop_assert_eq!(mesh.euler_characteristic(), euler);
        prop_assert_eq!(mesh.to_triangles().0, positions);
        prop_assert!(target_normal_error(&mesh, &field) <= before * (1.0 + 1e-12));
        prop_assert!(worst_quality(&mesh) <= worst.max(4.0));
        if clean {
            prop_assert_eq!(count_intersecting_faces(&mesh), 0);
        }
    }
}
