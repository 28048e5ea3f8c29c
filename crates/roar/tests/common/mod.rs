//! Shared by the pipeline's integration tests: toy settings fast enough for the default test
//! run.
#![allow(dead_code)]

use roar::{InitConfig, LossConfig, OptimizeConfig, ReconstructConfig, TargetConfig};

/// Few views, low resolutions (the loop's views at 32², the polish's at 64²), few iterations
/// (as `reconstruct_small` uses), at `faces`.
pub fn toy_config(faces: usize, iterations: usize) -> ReconstructConfig {
    ReconstructConfig {
        faces,
        target: TargetConfig {
            views_per_axis: 2,
            render_resolution: 64,
            point_cloud_samples: 5000,
            sharp_edge_samples: 1000,
            ..Default::default()
        },
        init: InitConfig {
            init_resolution: 32,
            init_max_faces: 4000,
            ..Default::default()
        },
        loss: LossConfig {
            planar_max_samples: 5000,
            render_coarse_resolution: 32,
            ..Default::default()
        },
        optimize: OptimizeConfig {
            iterations,
            working_budget_min: 600,
            split_interval: 3,
            smoothing_interval: 2,
            ..Default::default()
        },
        ..ReconstructConfig::default()
    }
}
