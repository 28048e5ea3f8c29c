//! `Reconstruction::cancel` stops a run at its next progress report with `Cancelled`.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use roar_cli::pipeline::{PipelineError, ReconstructConfig, Reconstruction, SoupShape};

#[test]
fn a_set_cancel_flag_stops_the_run_at_the_next_report() {
    let config = ReconstructConfig {
        faces: 200,
        iterations: 50,
        init_resolution: 32,
        init_max_faces: 4000,
        working_budget_min: 600,
        views_per_axis: 2,
        render_resolution: 64,
        point_cloud_samples: 5000,
        sharp_edge_samples: 1000,
        planar_max_samples: 5000,
        ..ReconstructConfig::default()
    };
    let soup = roar_cli::example::chair_soup();
    let flag = Arc::new(AtomicBool::new(false));
    let mut shape = SoupShape::new("chair_soup", &soup.positions, &soup.triangles, &config);
    let mut reconstruction = Reconstruction::new(config);
    reconstruction.cancel = Some(flag.clone());
    let mut seen = Vec::new();
    let result = reconstruction.run(&mut shape, &mut |p| {
        seen.push((p.stage, p.iteration));
        if p.stage == "optimize" && p.iteration == 2 {
            flag.store(true, Ordering::Relaxed);
        }
    });
    assert!(
        matches!(result, Err(PipelineError::Cancelled)),
        "{:?}",
        result.err()
    );
    assert_eq!(seen.last(), Some(&("optimize", 2)));
}
