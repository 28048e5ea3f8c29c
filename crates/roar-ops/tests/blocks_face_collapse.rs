//! The Face Collapse block removes folds, transfers optimizer rows as specified and leaves
//! unfolded meshes alone.

mod blocks_common;

use blocks_common::{assert_contract, key, plant_fold, rows_by_position, tagged_optimizer};
use roar_mesh::shapes::icosphere;
use roar_mesh::{TrackedMesh, VertexId};
use roar_ops::blocks::collapse::{FaceCollapseOptions, face_collapse, flagged_faces};
use roar_ops::geometry::Geometry;

fn flagged_count(mesh: &roar_mesh::Mesh) -> usize {
    let g = Geometry::compute(mesh);
    flagged_faces(mesh, &g, &FaceCollapseOptions::default())
        .iter()
        .filter(|&&f| f)
        .count()
}

#[test]
fn removes_a_planted_fold() {
    let mut mesh = icosphere(2);
    let euler = mesh.euler_characteristic();
    plant_fold(&mut mesh, VertexId::from_index(17));
    // The two faces next to the first neighbour turn over.
    assert!(
        flagged_count(&mesh) >= 2,
        "the planted fold must be flagged"
    );
    let mut opt = tagged_optimizer(&mesh);
    let mut rounds = 0;
    while flagged_count(&mesh) > 0 && rounds < 5 {
        let stats = face_collapse(
            &mut TrackedMesh::new(&mut mesh, &mut opt),
            &FaceCollapseOptions::default(),
        );
        assert!(
            stats.accepted > 0,
            "a flagged mesh must collapse something: {stats:?}"
        );
        assert_contract(&mesh, &opt, euler, "face_collapse");
        rounds += 1;
    }
    assert_eq!(flagged_count(&mesh), 0, "fold left after {rounds} calls");
    assert_eq!(rounds, 1, "one call removes a single planted fold");
}

#[test]
fn clean_sphere_is_left_alone() {
    let mut mesh = icosphere(3);
    let before = mesh.clone();
    let mut opt = tagged_optimizer(&mesh);
    let stats = face_collapse(
        &mut TrackedMesh::new(&mut mesh, &mut opt),
        &FaceCollapseOptions::default(),
    );
    assert_eq!(stats.candidates, 0);
    assert_eq!(stats.accepted, 0);
    assert_eq!(stats.sub[0].accepted, 0, "an icosphere has nothing to flip");
    assert_eq!(mesh, before);
}

#[test]
fn survivors_keep_the_chosen_endpoints_position_and_row() {
    let mut mesh = roar_mesh::shapes::perturbed(&icosphere(3), 0.1, 7);
    let euler = mesh.euler_characteristic();
    let mut opt = tagged_optimizer(&mesh);
    let rows = rows_by_position(&mesh, &opt);
    let n_before = mesh.n_vertices();
    let options = FaceCollapseOptions {
        flips: None,
        ..FaceCollapseOptions::default()
    };
    let stats = face_collapse(&mut TrackedMesh::new(&mut mesh, &mut opt), &options);
    assert!(stats.accepted > 0, "jitter 0.1 folds some faces: {stats:?}");
    assert_eq!(mesh.n_vertices(), n_before - stats.accepted);
    assert_contract(&mesh, &opt, euler, "face_collapse");
    for v in mesh.vertices() {
        // Every vertex sits at an original vertex position and carries that vertex's row.
        let row = rows
            .get(&key(mesh.position(v)))
            .expect("survivor at an original position");
        assert_eq!(opt.state()[v.index()], *row);
    }
}

/// A thin convex part whose every vertex lies on its rim: the tetrahedron spanned by a top edge
/// and a crossing bottom edge, `2h` apart. Each vertex's normal sums faces that look up and
/// faces that look down and points sideways, so the fold estimator alone flags faces that are
/// not folded; collapsing such faces eats a thin part from its rim (what the pipeline did to
/// thin wings before the gate was on).
fn thin_tetrahedron(h: f64) -> roar_mesh::Mesh {
    let positions = vec![
        roar_mesh::DVec3::new(1.0, 0.0, h),
        roar_mesh::DVec3::new(-1.0, 0.0, h),
        roar_mesh::DVec3::new(0.0, 1.0, -h),
        roar_mesh::DVec3::new(0.0, -1.0, -h),
    ];
    let triangles = [[0, 2, 1], [1, 3, 0], [0, 3, 2], [1, 2, 3]];
    roar_mesh::Mesh::from_triangles(positions, &triangles).expect("a tetrahedron")
}

fn flagged_with(mesh: &roar_mesh::Mesh, options: &FaceCollapseOptions) -> usize {
    let g = Geometry::compute(mesh);
    flagged_faces(mesh, &g, options)
        .iter()
        .filter(|&&f| f)
        .count()
}

#[test]
fn normal_size_gate_spares_thin_parts_but_still_removes_folds() {
    let gated = FaceCollapseOptions {
        min_normal_size: Some(0.98),
        ..FaceCollapseOptions::default()
    };
    let thin = thin_tetrahedron(0.05);
    assert!(thin.signed_volume() > 0.0, "outward");
    let ungated_flags = flagged_with(&thin, &FaceCollapseOptions::default());
    assert!(
        ungated_flags > 0,
        "without the gate the estimator flags faces of the thin part"
    );
    assert_eq!(
        flagged_with(&thin, &gated),
        0,
        "the gate spares the thin part"
    );

    // A fold in a smooth region is still flagged and removed with the gate on.
    let mut mesh = icosphere(2);
    let euler = mesh.euler_characteristic();
    plant_fold(&mut mesh, VertexId::from_index(17));
    assert!(
        flagged_with(&mesh, &gated) >= 2,
        "the planted fold is flagged"
    );
    let mut opt = tagged_optimizer(&mesh);
    let stats = face_collapse(&mut TrackedMesh::new(&mut mesh, &mut opt), &gated);
    assert!(stats.accepted > 0, "{stats:?}");
    assert_contract(&mesh, &opt, euler, "gated face_collapse");
    assert_eq!(flagged_with(&mesh, &gated), 0, "fold left");
}
