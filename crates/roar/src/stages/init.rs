//! The init stage: M0 (the shape's initial mesh, or a sphere), the budget check against its
//! pieces, the target point cloud P, and M0 decimated to the working budget W.

use roar_loss::{LossError, PointCloud};
use roar_mesh::Mesh;
use roar_ops::decimate::{DecimateOptions, decimate};

use crate::budget::{check_budget, smallest_budget};
use crate::config::{ConfigError, InitKind, ReconstructConfig};
use crate::error::PipelineError;
use crate::report::RunStats;
use crate::run::Run;
use crate::shape::Shape;

/// M0 at the working budget and the shape's point cloud for it.
pub(crate) fn init(shape: &dyn Shape, run: &mut Run) -> Result<(Mesh, PointCloud), PipelineError> {
    let config = run.config;
    run.report("init", 0, f64::NAN, 0)?;
    let mut mesh = initial_mesh(shape, config, &mut run.stats)?;
    check_budget(
        "faces =",
        config.faces,
        smallest_budget(&mesh.component_genera(), config.finish.keep_topology),
    )
    .map_err(ConfigError::BudgetForInit)?;
    run.clock.lap("init");

    run.report("point_cloud", 0, f64::NAN, mesh.n_faces())?;
    let cloud = shape.point_cloud(&mesh)?;
    if cloud.points.is_empty() || cloud.points.len() != cloud.normals.len() {
        return Err(PipelineError::Loss(LossError::InvalidTarget(format!(
            "{}: the point cloud is empty or has not one normal per point",
            shape.name()
        ))));
    }
    run.stats.target.point_cloud = cloud.points.len();
    run.clock.lap("point_cloud");

    let budget = config.working_budget();
    run.stats.optimize.working_budget = budget;
    if mesh.n_faces() > budget {
        let options = DecimateOptions {
            best_effort: true,
            ..DecimateOptions::default()
        };
        decimate(&mut mesh, budget, &options)?;
    }
    run.clock.lap("working_budget_qem");
    Ok((mesh, cloud))
}

/// M0: the shape's own initial mesh (for a soup the watertight init of T′, decimated to at
/// most `init_max_faces`), or an icosphere of radius 0.5 (`init = "sphere"`).
fn initial_mesh(
    shape: &dyn Shape,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<Mesh, PipelineError> {
    let mesh = match config.init.kind {
        InitKind::Watertight => {
            let initial = shape.initial_mesh()?;
            stats.init.init_voxel_faces = initial.raw_faces;
            stats.init.init_voxels_filled_by_winding = initial.enclosure.voxels_filled;
            stats.init.init_enclosures_left_open = initial.enclosure.left_open;
            stats.init.init_winding_patches = initial.enclosure.patches;
            stats.init.init_winding_patches_flipped = initial.enclosure.patches_flipped;
            stats.init.init_pieces_before_merge = initial.merged.pieces_before;
            stats.init.init_merge_radius_voxels = initial.merged.radius_voxels;
            stats.init.init_pieces_dropped_for_budget = initial.merged.pieces_dropped;
            initial.mesh
        }
        InitKind::Sphere => {
            let mut sphere = roar_mesh::shapes::icosphere(config.init.sphere_level);
            for p in sphere.positions_mut() {
                *p *= 0.5;
            }
            stats.init.init_voxel_faces = sphere.n_faces();
            sphere
        }
    };
    stats.init.init_faces = mesh.n_faces();
    stats.init.init_components = mesh.components().0;
    stats.init.init_genus = mesh.genus();
    Ok(mesh)
}
