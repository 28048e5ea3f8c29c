//! One evaluation of the loop's objective at the default rig (36 views × 512², spec §3.2.3:
//! `3·L_render + 1·L_planar`, built by `roar_cli::pipeline::default_loss`) on a real mesh, and
//! its parts on their own: the render forward pass, the render forward + backward (the render
//! loss's value and gradient) and the planar loss.
//!
//! The target is `$ROAR_TEST_DATA/clean/homer.obj` (12,000 faces, closed): its cleaned target,
//! renders and point cloud, as a run prepares them. The sources are that mesh (in the rig's
//! coordinates) decimated by QEM
//! to 10,000 and 5,000 faces and shrunk by 2 % about the rig's centre, so that both terms have
//! work to do (silhouettes off the target's, planar moves of about 1 % of the radius). Without
//! `ROAR_TEST_DATA` the bench prints why and measures nothing.
// `criterion_group!` generates a public function without documentation.
#![allow(missing_docs)]

use std::path::PathBuf;

use criterion::{Criterion, criterion_group};
use glam::DVec3;
use roar_cli::pipeline::{
    Prepared, ReconstructConfig, default_loss, planar_options, target_options,
};
use roar_loss::{Loss, PlanarLoss, PointCloudOptions, RenderLoss, build_target, point_cloud};
use roar_mesh::Mesh;
use roar_ops::decimate::{DecimateOptions, decimate};
use roar_render::{RenderOptions, render};

/// The mesh the bench reads, relative to `ROAR_TEST_DATA`.
const MESH: &str = "clean/homer.obj";

fn mesh_path() -> Option<PathBuf> {
    std::env::var_os("ROAR_TEST_DATA").map(|dir| PathBuf::from(dir).join(MESH))
}

/// `positions`/`triangles` decimated to `faces` faces, shrunk by 2 %.
fn source(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    faces: usize,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut mesh = Mesh::from_triangles(positions.to_vec(), triangles)
        .unwrap_or_else(|e| panic!("{MESH} is not a closed mesh: {e}"));
    decimate(&mut mesh, faces, &DecimateOptions::default())
        .unwrap_or_else(|e| panic!("decimating {MESH} to {faces} faces: {e}"));
    let (positions, triangles) = mesh.to_triangles();
    (positions.iter().map(|p| *p * 0.98).collect(), triangles)
}

fn bench_loss(c: &mut Criterion) {
    let Some(path) = mesh_path() else {
        return;
    };
    let soup =
        roar_io::read_mesh(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let config = ReconstructConfig::default();
    let target = build_target(&soup.positions, &soup.triangles, &target_options(&config))
        .expect("target of the bench mesh");
    let cloud = point_cloud(&target, &PointCloudOptions::default()).expect("point cloud");
    // The input itself in rig coordinates (the target may keep both sides of a face).
    let mut normalized = soup.positions.clone();
    target.normalization.apply_all(&mut normalized);
    let prepared = Prepared {
        cameras: &target.cameras,
        renders: &target.renders,
        cloud: &cloud,
        signed_distance: None,
        config: &config,
    };
    let mut group = c.benchmark_group("loss_36x512");
    group.sample_size(10);
    for faces in [5_000usize, 10_000] {
        let (positions, triangles) = source(&normalized, &soup.triangles, faces);
        let label = format!("{}k_faces", faces / 1000);
        let mut full = default_loss(&prepared).expect("default loss");
        group.bench_function(format!("full_{label}"), |b| {
            b.iter(|| full.value_and_grad(&positions, &triangles).unwrap())
        });
        group.bench_function(format!("render_forward_{label}"), |b| {
            b.iter(|| {
                render(
                    &positions,
                    &triangles,
                    &target.cameras,
                    &RenderOptions::default(),
                )
                .unwrap()
            })
        });
        let mut render_loss = RenderLoss::new(&target);
        group.bench_function(format!("render_forward_backward_{label}"), |b| {
            b.iter(|| render_loss.value_and_grad(&positions, &triangles).unwrap())
        });
        let mut planar = PlanarLoss::new(&cloud.points, &cloud.normals, &planar_options(&config))
            .expect("planar loss");
        group.bench_function(format!("planar_{label}"), |b| {
            b.iter(|| planar.value_and_grad(&positions, &triangles).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_loss);

fn main() {
    if mesh_path().is_none() {
        eprintln!("loss bench skipped: set ROAR_TEST_DATA to the shared meshes folder");
        return;
    }
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
