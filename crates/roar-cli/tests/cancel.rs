//! `Reconstruction::cancel` stops a run at its next progress report with `Cancelled`.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use roar::{PipelineError, Reconstruction};

#[test]
fn a_set_cancel_flag_stops_the_run_at_the_next_report() {
    let config = common::toy_config(200, 50);
    let soup = roar::example::chair_soup();
    let flag = Arc::new(AtomicBool::new(false));
    let mut reconstruction = Reconstruction::new(config);
    reconstruction.cancel = Some(flag.clone());
    let mut seen = Vec::new();
    let result = reconstruction.run_soup(&soup.positions, &soup.triangles, &mut |p| {
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
