//! The budget is always met: when the genus needs more faces than N, the finish removes handles
//! (and says so in the stats), unless `keep_topology` asks for today's named error.

use roar_cli::pipeline::{PipelineError, ReconstructConfig, Reconstruction};
use roar_mesh::Mesh;
use roar_mesh::shapes::torus;
use roar_mesh::spatial::self_intersecting_faces;
use roar_ops::qem::DecimateError;

fn toy_config(faces: usize) -> ReconstructConfig {
    ReconstructConfig {
        faces,
        iterations: 4,
        init_resolution: 32,
        init_max_faces: 4000,
        working_budget_min: 600,
        views_per_axis: 2,
        render_resolution: 64,
        point_cloud_samples: 5000,
        sharp_edge_samples: 1000,
        planar_max_samples: 5000,
        ..ReconstructConfig::default()
    }
}

fn torus_soup() -> (Vec<glam::DVec3>, Vec<[u32; 3]>) {
    torus(32, 12, 1.0, 0.4).to_triangles()
}

#[test]
fn a_torus_asked_for_fewer_faces_than_its_genus_allows_loses_its_handle() {
    let (positions, triangles) = torus_soup();
    // A genus-1 surface needs at least 14 faces; 12 is a sphere's budget.
    let out = Reconstruction::new(toy_config(12))
        .run(&positions, &triangles, &mut |_| {})
        .unwrap();
    assert_eq!(out.stats.init_genus, 1);
    assert_eq!(out.stats.handles_removed.len(), 1);
    assert!(out.stats.handles_removed[0].loop_length > 0.0);
    assert_eq!(out.triangles.len(), 12);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    mesh.validate().unwrap();
    assert_eq!((mesh.genus(), mesh.components().0), (0, 1));
    assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
}

#[test]
fn a_budget_the_genus_allows_keeps_the_handle() {
    let (positions, triangles) = torus_soup();
    let out = Reconstruction::new(toy_config(200))
        .run(&positions, &triangles, &mut |_| {})
        .unwrap();
    assert!(out.stats.handles_removed.is_empty());
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    assert_eq!((mesh.n_faces(), mesh.genus()), (200, 1));
}

#[test]
fn keep_topology_fails_with_the_named_error_instead() {
    let (positions, triangles) = torus_soup();
    let config = ReconstructConfig {
        keep_topology: true,
        ..toy_config(12)
    };
    let err = Reconstruction::new(config)
        .run(&positions, &triangles, &mut |_| {})
        .err()
        .expect("12 faces cannot hold a torus");
    assert!(
        matches!(
            err,
            PipelineError::Budget(DecimateError::TargetBelowMinimum { minimum: 14, .. })
        ),
        "{err}"
    );
}
