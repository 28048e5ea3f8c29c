//! A new kind of input for the pipeline, to copy: an analytic torus that gives the pipeline its
//! own target renders, oriented point cloud and initial mesh through the [`Shape`] seam, at toy
//! settings so it runs in seconds.
//!
//! `cargo run --release -p roar --example custom_shape [OUTPUT.obj]` (default
//! `target/custom_shape.obj`) writes the reconstruction in the torus's own coordinates and
//! prints how far its vertices are from the torus.

use std::borrow::Cow;
use std::f64::consts::TAU;
use std::path::PathBuf;

use glam::DVec3;
use roar::{EnclosureFigures, InitialMesh, Shape, ShapeError};
use roar::{
    FinishConfig, LossConfig, OptimizeConfig, ReconstructConfig, Reconstruction, TargetConfig,
};
use roar_io::TriangleSoup;
use roar_loss::{PointCloud, render_views};
use roar_mesh::Mesh;
use roar_mesh::shapes::torus;
use roar_mesh::spatial::{Normalization, RIG_RADIUS};
use roar_render::{Camera, Image};

/// Any error, as one line for the terminal.
type Result<T, E = Box<dyn std::error::Error>> = std::result::Result<T, E>;

/// The torus around the z axis through `center`, with tube centre `major` and tube radius
/// `minor`, in the input's (here: made-up world) coordinates.
struct AnalyticTorus {
    center: DVec3,
    major: f64,
    minor: f64,
}

impl AnalyticTorus {
    /// Rig coordinates scale the torus so its outer rim lies on the rig's sphere.
    fn scale(&self) -> f64 {
        RIG_RADIUS / (self.major + self.minor)
    }

    /// The point at angles `(u, v)` and its outward normal, in rig coordinates.
    fn point(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        let normal = DVec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin());
        let ring = DVec3::new(u.cos(), u.sin(), 0.0) * self.major;
        ((ring + self.minor * normal) * self.scale(), normal)
    }

    /// A tessellation with `m × n` quads, in rig coordinates.
    fn mesh(&self, m: usize, n: usize, tube: f64) -> Mesh {
        let s = self.scale();
        torus(m, n, self.major * s, tube * self.minor * s)
    }
}

impl Shape for AnalyticTorus {
    fn name(&self) -> &str {
        "analytic torus"
    }

    // Nothing to prepare: everything below is computed on demand.

    fn normalization(&self) -> Normalization {
        Normalization {
            center: self.center,
            scale: self.scale(),
        }
    }

    fn initial_mesh(&self) -> Result<InitialMesh, ShapeError> {
        // Coarse and with a tube 20 % too thick: the loop pulls it onto the torus. It must
        // have the torus's genus: no operator of the loop changes the topology.
        let mesh = self.mesh(24, 12, 1.2);
        let raw_faces = mesh.n_faces();
        Ok(InitialMesh {
            mesh,
            raw_faces,
            enclosure: EnclosureFigures::default(),
            merged: Default::default(),
        })
    }

    fn point_cloud(&self, _initial: &Mesh) -> Result<PointCloud, ShapeError> {
        // A regular grid in the two angles (denser along the ring, where the torus is longer).
        let (m, n) = (200, 60);
        let mut cloud = PointCloud::default();
        for i in 0..m {
            for j in 0..n {
                let (p, normal) = self.point(TAU * i as f64 / m as f64, TAU * j as f64 / n as f64);
                cloud.points.push(p);
                cloud.normals.push(normal);
            }
        }
        Ok(cloud)
    }

    fn target_renders(&self, cameras: &[Camera]) -> Result<Cow<'_, [Image]>, ShapeError> {
        // A fine tessellation stands in for ray casting the torus.
        let (positions, triangles) = self.mesh(256, 96, 1.0).to_triangles();
        Ok(Cow::Owned(render_views(
            &positions, &triangles, cameras, true,
        )?))
    }
}

fn main() -> Result<()> {
    let output = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/custom_shape.obj"), PathBuf::from);
    let mut shape = AnalyticTorus {
        center: DVec3::new(10.0, 0.0, -5.0),
        major: 3.0,
        minor: 1.0,
    };
    // Toy settings: 9 views of 96², 20 iterations; `ReconstructConfig::default()` is the paper's.
    let config = ReconstructConfig {
        faces: 800,
        target: TargetConfig {
            views_per_axis: 3,
            render_resolution: 96,
            ..Default::default()
        },
        loss: LossConfig {
            planar_max_samples: 6000,
            ..Default::default()
        },
        optimize: OptimizeConfig {
            iterations: 20,
            working_budget_min: 1600,
            split_interval: 5,
            ..Default::default()
        },
        finish: FinishConfig {
            polish_iterations: 5,
            ..Default::default()
        },
        ..ReconstructConfig::default()
    };
    let out = Reconstruction::new(config).run(&mut shape, &mut |_| {})?;

    // Distance of each output vertex from the torus, relative to the tube radius.
    let worst = out
        .positions
        .iter()
        .map(|p| {
            let q = *p - shape.center;
            let ring = (q.x * q.x + q.y * q.y).sqrt() - shape.major;
            ((ring * ring + q.z * q.z).sqrt() - shape.minor).abs() / shape.minor
        })
        .fold(0.0, f64::max);
    let faces = out.triangles.len();
    let genus = Mesh::from_triangles(out.positions.clone(), &out.triangles)?.genus();
    roar_io::write_mesh(&output, &TriangleSoup::new(out.positions, out.triangles))?;
    println!(
        "wrote {} ({faces} faces, genus {genus}); farthest vertex {:.1} % of the tube radius off the \
         torus (the init: 20 %)",
        output.display(),
        100.0 * worst
    );
    Ok(())
}
