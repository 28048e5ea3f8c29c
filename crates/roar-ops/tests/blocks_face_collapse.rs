//! The Face Collapse block removes folds, transfers optimizer rows as specified and leaves
//! unfolded meshes alone.

mod blocks_common;

use blocks_common::{assert_contract, key, plant_fold, rows_by_position, tagged_optimizer};
use roar_mesh::VertexId;
use roar_mesh::shapes::icosphere;
use roar_ops::collapse_block::{FaceCollapseOptions, face_collapse, flagged_faces};
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
        let stats = face_collapse(&mut mesh, &mut opt, &FaceCollapseOptions::default());
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
    let stats = face_collapse(&mut mesh, &mut opt, &FaceCollapseOptions::default());
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
    let stats = face_collapse(&mut mesh, &mut opt, &options);
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
