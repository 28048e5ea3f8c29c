//! The objective the loop minimizes: what a loss factory is given, and the default factory.

use std::sync::Arc;

use roar_loss::{
    CoarseViews, KnnOptions, Loss, PlanarLoss, PlanarOptions, PointCloud, RenderLoss, Sdf, SdfLoss,
    SdfLossOptions, WeightedSum,
};
use roar_render::{Camera, Image};

use crate::config::ReconstructConfig;
use crate::error::PipelineError;
use crate::rig::coarse_until;

/// What the pipeline hands to a loss factory: what the input [`Shape`] gave, in rig
/// coordinates.
pub struct Prepared<'a> {
    /// The camera rig ([`rig_cameras`]).
    pub cameras: &'a [Camera],
    /// The shape's target normal map for each camera.
    pub renders: &'a [Image],
    /// The coarse rig of the loop's first iterations ([`coarse_rig_cameras`]; empty when the
    /// config has none) and the shape's renders for it.
    pub coarse_cameras: &'a [Camera],
    /// See `coarse_cameras`.
    pub coarse_renders: &'a [Image],
    /// The oriented target point cloud P (with the sharp-edge samples).
    pub cloud: &'a PointCloud,
    /// The shape's signed distance, if it has one.
    pub signed_distance: Option<Arc<dyn Sdf>>,
    /// The effective configuration.
    pub config: &'a ReconstructConfig,
}

/// Builds the objective once the target is prepared.
pub type LossFactory = Box<dyn Fn(&Prepared) -> Result<Box<dyn Loss>, PipelineError>>;

/// The planar loss options of `config`, as [`default_loss`] uses them.
pub fn planar_options(config: &ReconstructConfig) -> PlanarOptions {
    PlanarOptions {
        knn: KnnOptions {
            k: config.loss.planar_neighbours,
            ..KnnOptions::default()
        },
        t2s: config.loss.planar_t2s,
        t2s_max_points: config.loss.planar_t2s_max_points,
        max_samples: config.loss.planar_max_samples,
        scale: config.loss.planar_scale,
        seed: config.seed,
        ..PlanarOptions::default()
    }
}

/// The default objective: `λ1·L_render + λ2·L_planar` (the paper's Eq. 2, λ1 = 3 on the render
/// term: `docs/method.md#decision-weights-of-the-objective`), plus `sdf_loss_weight·L_sdf`
/// (supplementary §3) when the shape has a signed distance.
pub fn default_loss(prepared: &Prepared) -> Result<Box<dyn Loss>, PipelineError> {
    let config = prepared.config;
    let planar = PlanarLoss::new(
        &prepared.cloud.points,
        &prepared.cloud.normals,
        &planar_options(config),
    )?;
    let mut render = RenderLoss::from_renders(prepared.cameras, prepared.renders);
    if !prepared.coarse_cameras.is_empty() {
        render = render.with_coarse(CoarseViews {
            cameras: prepared.coarse_cameras.to_vec(),
            targets: prepared.coarse_renders.to_vec(),
            until: coarse_until(config),
        });
    }
    let mut sum = WeightedSum::default()
        .with(config.loss.render_weight, Box::new(render))
        .with(config.loss.planar_weight, Box::new(planar));
    if let Some(sdf) = &prepared.signed_distance {
        let options = SdfLossOptions {
            start_iteration: config.loss.sdf_loss_start,
            epsilon: config.loss.sdf_loss_epsilon,
        };
        sum = sum.with(
            config.loss.sdf_loss_weight,
            Box::new(SdfLoss::new(sdf.clone(), options)),
        );
    }
    Ok(Box::new(sum))
}
