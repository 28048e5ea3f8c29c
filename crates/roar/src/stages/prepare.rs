//! The prepare stage: the shape's own set-up (for a soup: weld, normalize, twin clean-up and
//! the target renders) for the camera rig, and the normalization the output is undone with.

use roar_mesh::spatial::Normalization;
use roar_render::Camera;

use crate::error::PipelineError;
use crate::rig::rig_cameras;
use crate::run::Run;
use crate::shape::Shape;

/// What the prepare stage hands on: the rig and the input's normalization.
pub(crate) struct Rig {
    /// The camera rig ([`rig_cameras`]), for which the shape renders its target.
    pub cameras: Vec<Camera>,
    /// Input → rig coordinates; inverted on the output.
    pub normalization: Normalization,
}

/// Prepares `shape` for the rig of `run.config` and records the target's figures.
pub(crate) fn prepare(shape: &mut dyn Shape, run: &mut Run) -> Result<Rig, PipelineError> {
    run.report("target", 0, f64::NAN, 0)?;
    let cameras = rig_cameras(run.config);
    shape.prepare(&cameras)?;
    let normalization = shape.normalization();
    let summary = shape.summary();
    run.stats.target.target_faces = summary.target_faces;
    run.stats.target.twins_dropped = summary.twins_dropped;
    run.clock.lap("target");
    Ok(Rig {
        cameras,
        normalization,
    })
}
