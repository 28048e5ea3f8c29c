//! Inputs with more separate parts than a small face budget can shape: the pipeline merges
//! nearby parts into fewer closed pieces instead of refusing the budget, and keeps parts that
//! are far apart.

use glam::DVec3;
use roar::{ReconstructConfig, Reconstruction};
use roar_mesh::Mesh;
use roar_mesh::spatial::self_intersecting_faces;

mod common;

/// Unit cubes (`roar_mesh::shapes::cube`) on an `n[0] × n[1] × n[2]` lattice, `spacing` apart
/// corner to corner.
fn cubes(n: [usize; 3], spacing: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (corners, faces) = roar_mesh::shapes::cube().to_triangles();
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let min = DVec3::new(i as f64, j as f64, k as f64) * spacing;
                let base = positions.len() as u32;
                positions.extend(corners.iter().map(|&p| min + p + DVec3::splat(0.5)));
                triangles.extend(faces.iter().map(|t| t.map(|v| base + v)));
            }
        }
    }
    (positions, triangles)
}

/// The toy pipeline at `faces`, with an init fine enough to keep one-cube gaps open.
fn config(faces: usize) -> ReconstructConfig {
    let mut config = common::toy_config(faces, 4);
    config.init.init_resolution = 96;
    config
}

/// Runs the pipeline; asserts a closed, oriented, intersection-free mesh of exactly `faces`
/// faces, and returns its pieces and the run's report.
fn reconstruct(soup: &(Vec<DVec3>, Vec<[u32; 3]>), faces: usize) -> (usize, roar::RunStats) {
    let out = Reconstruction::new(config(faces))
        .run_soup(&soup.0, &soup.1, &mut |_| {})
        .unwrap();
    assert_eq!(out.triangles.len(), faces);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    mesh.validate().unwrap();
    assert!(mesh.signed_volume() > 0.0);
    assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
    (mesh.components().0, out.stats)
}

#[test]
fn three_hundred_cubes_at_500_faces_merge_into_fewer_closed_pieces() {
    // Without merging, 300 pieces need at least 1200 faces so the budget would be refused.
    let (pieces, stats) = reconstruct(&cubes([10, 10, 3], 2.0), 500);
    assert_eq!(stats.init.init_pieces_before_merge, 300);
    assert!(stats.init.init_merge_radius_voxels > 0);
    assert!(
        pieces <= roar::budget::pieces_to_aim_for(500),
        "{pieces} pieces"
    );
    assert_eq!(stats.init.init_pieces_dropped_for_budget, 0);
}

#[test]
fn two_parts_far_apart_stay_two_pieces_at_a_budget_that_fits_them() {
    let mut soup = cubes([1, 1, 1], 1.0);
    let far = cubes([1, 1, 1], 1.0);
    let base = soup.0.len() as u32;
    soup.0
        .extend(far.0.iter().map(|p| *p + DVec3::new(12.0, 0.0, 0.0)));
    soup.1.extend(far.1.iter().map(|t| t.map(|v| v + base)));
    // 40 faces aim for one piece, but the two cubes are too far apart to merge.
    for faces in [40, 200] {
        let (pieces, stats) = reconstruct(&soup, faces);
        assert_eq!(pieces, 2, "{faces} faces");
        assert_eq!(stats.init.init_merge_radius_voxels, 0);
    }
}
