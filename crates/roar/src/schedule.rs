//! The remeshing schedule: which blocks run at which iterations of the loop.

use roar_ops::blocks::block::Block;
use roar_ops::blocks::collapse::{FaceCollapse, FaceCollapseOptions};
use roar_ops::blocks::flips::FlipOptions;
use roar_ops::blocks::smoothing::{SmoothingOptions, TangentialSmoothing};
use roar_ops::blocks::split::{FaceSplit, FaceSplitOptions, SplitThreshold};

use crate::config::ReconstructConfig;

/// A block and when it runs: at iterations `it` with `it % every == 0` (and `it > 0` when
/// `skip_first`).
pub struct ScheduledBlock {
    /// The block.
    pub block: Box<dyn Block>,
    /// Period in iterations (0 = never).
    pub every: usize,
    /// Skip iteration 0 (the Face Split block does, as in the authors' code).
    pub skip_first: bool,
}

/// The paper's schedule (supplementary §1: Face Collapse and flips every iteration, Face Split
/// every 10), with tangential smoothing every `smoothing_interval` iterations, off by default
/// (`docs/method.md#decision-smoothing-after-the-final-qem-not-in-the-loop`).
pub fn default_blocks(config: &ReconstructConfig) -> Vec<ScheduledBlock> {
    vec![
        ScheduledBlock {
            block: Box::new(FaceCollapse {
                options: FaceCollapseOptions {
                    fold_slack: config.optimize.collapse_fold_slack,
                    min_normal_size: (config.optimize.collapse_min_normal_size > 0.0)
                        .then_some(config.optimize.collapse_min_normal_size),
                    flips: Some(FlipOptions {
                        guard_intersections: config.optimize.guard_intersections,
                        ..FlipOptions::default()
                    }),
                    guard_intersections: config.optimize.guard_intersections,
                    ..FaceCollapseOptions::default()
                },
            }),
            every: config.optimize.collapse_interval,
            skip_first: false,
        },
        ScheduledBlock {
            block: Box::new(FaceSplit {
                options: FaceSplitOptions {
                    threshold: SplitThreshold::PerSubTriangle(config.optimize.split_threshold),
                    seed: config.seed,
                    guard_intersections: config.optimize.guard_intersections,
                    ..FaceSplitOptions::default()
                },
            }),
            every: config.optimize.split_interval,
            skip_first: true,
        },
        ScheduledBlock {
            block: Box::new(TangentialSmoothing {
                options: SmoothingOptions {
                    guard_intersections: config.optimize.guard_intersections,
                    ..SmoothingOptions::default()
                },
            }),
            every: config.optimize.smoothing_interval,
            skip_first: false,
        },
    ]
}
