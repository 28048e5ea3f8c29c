//! The loss benches' fixture, shared by `benches/loss.rs` and `examples/loss_once.rs`:
//! `$ROAR_TEST_DATA/clean/homer.obj` (12,000 faces, closed) prepared as a run prepares a soup
//! (cleaned target, renders of the paper's full rig and of the soup schedule's coarse rig,
//! point cloud), and sources made from it: decimated by QEM and shrunk by 2 % about the rig's
//! centre, so that both terms have work to do (silhouettes off the target's, planar moves of
//! about 1 % of the radius).

use std::path::PathBuf;

use glam::DVec3;
use roar::{Prepared, ReconstructConfig, coarse_rig_cameras, target_options};
use roar_loss::{PointCloud, PointCloudOptions, Target, build_target, point_cloud, render_views};
use roar_mesh::Mesh;
use roar_ops::decimate::{DecimateOptions, decimate};
use roar_render::{Camera, Image};

/// The mesh, relative to `ROAR_TEST_DATA`.
pub const MESH: &str = "clean/homer.obj";

/// The prepared target of [`MESH`]: the full rig is the paper's (36 × 512², as the SDF and
/// scan schedules render it), the coarse rig and the rest the default (soup) config's.
pub struct Homer {
    pub config: ReconstructConfig,
    pub target: Target,
    pub coarse_cameras: Vec<Camera>,
    pub coarse_renders: Vec<Image>,
    pub cloud: PointCloud,
    /// The input itself in rig coordinates (the target may keep both sides of a face).
    normalized: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl Homer {
    /// The fixture, or `None` when `ROAR_TEST_DATA` is not set.
    pub fn load() -> Option<Self> {
        let path = PathBuf::from(std::env::var_os("ROAR_TEST_DATA")?).join(MESH);
        let soup = roar_io::read_mesh(&path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let config = ReconstructConfig::default();
        let full_rig = target_options(&ReconstructConfig::sdf_defaults());
        let target = build_target(&soup.positions, &soup.triangles, &full_rig)
            .expect("target of the bench mesh");
        let coarse_cameras = coarse_rig_cameras(&config);
        let coarse_renders =
            render_views(&target.positions, &target.triangles, &coarse_cameras, true)
                .expect("coarse renders");
        let cloud = point_cloud(&target, &PointCloudOptions::default()).expect("point cloud");
        let mut normalized = soup.positions.clone();
        target.normalization.apply_all(&mut normalized);
        Some(Self {
            config,
            target,
            coarse_cameras,
            coarse_renders,
            cloud,
            normalized,
            triangles: soup.triangles,
        })
    }

    /// What the pipeline hands the loss factory; with `coarse`, the loop's coarse rig too.
    pub fn prepared(&self, coarse: bool) -> Prepared<'_> {
        let (coarse_cameras, coarse_renders): (&[Camera], &[Image]) = if coarse {
            (&self.coarse_cameras, &self.coarse_renders)
        } else {
            (&[], &[])
        };
        Prepared {
            cameras: &self.target.cameras,
            renders: &self.target.renders,
            coarse_cameras,
            coarse_renders,
            cloud: &self.cloud,
            signed_distance: None,
            config: &self.config,
        }
    }

    /// The mesh decimated to `faces` faces and shrunk by 2 %.
    pub fn source(&self, faces: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut mesh = Mesh::from_triangles(self.normalized.clone(), &self.triangles)
            .unwrap_or_else(|e| panic!("{MESH} is not a closed mesh: {e}"));
        decimate(&mut mesh, faces, &DecimateOptions::default())
            .unwrap_or_else(|e| panic!("decimating {MESH} to {faces} faces: {e}"));
        let (positions, triangles) = mesh.to_triangles();
        (positions.iter().map(|p| *p * 0.98).collect(), triangles)
    }
}
