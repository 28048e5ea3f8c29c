//! A new kind of input, implemented through the public API alone: an analytic sphere with its
//! own target renders, point cloud, initial mesh, signed distance and projector, reconstructed
//! by the unchanged pipeline at toy settings.

use std::borrow::Cow;
use std::cell::Cell;
use std::rc::Rc;
use std::sync::Arc;

use glam::DVec3;
use roar::{
    EnclosureFigures, FinishConfig, InitialMesh, LossConfig, OptimizeConfig, Prepared,
    ReconstructConfig, Reconstruction, Shape, ShapeError, ShapeSummary, TargetConfig, default_loss,
};
use roar_loss::{PointCloud, Sdf, SdfEvaluations, render_views};
use roar_mesh::Mesh;
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{
    Normalization, Projector, RIG_RADIUS, SphereProjector, self_intersecting_faces,
};
use roar_render::{Camera, Image};

/// The sphere of `radius` around `center` in the input's coordinates; in rig coordinates it is
/// the sphere of radius `RIG_RADIUS` around the origin.
struct AnalyticSphere {
    center: DVec3,
    radius: f64,
    prepared_with: usize,
    projector: SphereProjector,
    distance: Arc<RigSphereDistance>,
}

/// `f(p) = |p| − RIG_RADIUS`, in rig coordinates.
struct RigSphereDistance;

impl Sdf for RigSphereDistance {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        for (p, f) in points.iter().zip(values) {
            *f = p.length() - RIG_RADIUS;
        }
    }
    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        for ((p, f), g) in points.iter().zip(values).zip(gradients) {
            *f = p.length() - RIG_RADIUS;
            *g = p.normalize_or_zero();
        }
    }
    fn evaluations(&self) -> SdfEvaluations {
        SdfEvaluations::default()
    }
}

impl AnalyticSphere {
    fn new(center: DVec3, radius: f64) -> Self {
        Self {
            center,
            radius,
            prepared_with: 0,
            projector: SphereProjector {
                center: DVec3::ZERO,
                radius: RIG_RADIUS,
            },
            distance: Arc::new(RigSphereDistance),
        }
    }
}

/// `n` points spread evenly over the unit sphere (a Fibonacci lattice).
fn fibonacci_sphere(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

impl Shape for AnalyticSphere {
    fn name(&self) -> &str {
        "analytic sphere"
    }

    fn prepare(&mut self, cameras: &[Camera]) -> Result<(), ShapeError> {
        self.prepared_with = cameras.len();
        Ok(())
    }

    fn normalization(&self) -> Normalization {
        Normalization {
            center: self.center,
            scale: RIG_RADIUS / self.radius,
        }
    }

    fn initial_mesh(&self) -> Result<InitialMesh, ShapeError> {
        // A coarse sphere a little inside the target: the loop has to push it out.
        let mut mesh = icosphere(3);
        for p in mesh.positions_mut() {
            *p *= 0.9 * RIG_RADIUS;
        }
        let raw_faces = mesh.n_faces();
        Ok(InitialMesh {
            mesh,
            raw_faces,
            enclosure: EnclosureFigures::default(),
            merged: Default::default(),
        })
    }

    fn point_cloud(&self, _initial: &Mesh) -> Result<PointCloud, ShapeError> {
        let normals = fibonacci_sphere(4000);
        let points = normals.iter().map(|n| RIG_RADIUS * *n).collect();
        Ok(PointCloud { points, normals })
    }

    fn target_renders(&self, cameras: &[Camera]) -> Result<Cow<'_, [Image]>, ShapeError> {
        // A fine tessellation stands in for ray casting the sphere.
        let mut fine = icosphere(5);
        for p in fine.positions_mut() {
            *p *= RIG_RADIUS;
        }
        let (positions, triangles) = fine.to_triangles();
        Ok(Cow::Owned(render_views(
            &positions, &triangles, cameras, true,
        )?))
    }

    fn signed_distance(&self) -> Option<Arc<dyn Sdf>> {
        Some(self.distance.clone())
    }

    fn projector(&self) -> Option<&dyn Projector> {
        Some(&self.projector)
    }

    fn summary(&self) -> ShapeSummary {
        ShapeSummary::default()
    }
}

fn toy_config() -> ReconstructConfig {
    ReconstructConfig {
        faces: 400,
        target: TargetConfig {
            views_per_axis: 3,
            render_resolution: 96,
            ..Default::default()
        },
        loss: LossConfig {
            planar_max_samples: 4000,
            ..Default::default()
        },
        optimize: OptimizeConfig {
            iterations: 20,
            working_budget_min: 800,
            split_interval: 5,
            ..Default::default()
        },
        finish: FinishConfig {
            polish_iterations: 5,
            ..Default::default()
        },
        ..ReconstructConfig::default()
    }
}

/// Largest relative deviation of the vertices from the sphere.
fn worst_radius_error(positions: &[DVec3], center: DVec3, radius: f64) -> f64 {
    positions
        .iter()
        .map(|p| ((*p - center).length() - radius).abs() / radius)
        .fold(0.0, f64::max)
}

#[test]
fn an_analytic_sphere_is_reconstructed_through_the_shape_seam() {
    let center = DVec3::new(3.0, -1.0, 2.0);
    let radius = 2.5;
    let mut shape = AnalyticSphere::new(center, radius);
    let config = toy_config();
    let cameras = config.target.views_per_axis * config.target.views_per_axis;

    // The loss factory sees what the shape offers.
    let saw_distance = Rc::new(Cell::new(false));
    let seen = Rc::clone(&saw_distance);
    let mut reconstruction = Reconstruction::new(config.clone());
    reconstruction.loss_factory = Box::new(move |prepared: &Prepared| {
        seen.set(prepared.signed_distance.is_some() && prepared.renders.len() == cameras);
        default_loss(prepared)
    });
    let out = reconstruction.run(&mut shape, &mut |_| {}).unwrap();

    assert_eq!(shape.prepared_with, cameras, "prepare saw another rig");
    assert!(
        saw_distance.get(),
        "the loss factory missed the shape's offer"
    );
    assert_eq!(out.triangles.len(), config.faces);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    assert_eq!(mesh.genus(), 0);
    assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
    assert_eq!(out.stats.init.init_faces, 1280);
    assert_eq!(out.stats.target.point_cloud, 4000);

    // In the input's coordinates, on the sphere: the init sat 10 % inside it.
    let error = worst_radius_error(&out.positions, center, radius);
    println!("worst relative radius error {error:.4}");
    assert!(error < 0.05, "worst relative radius error {error}");
}
