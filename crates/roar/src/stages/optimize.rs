//! The optimize stage (`docs/method.md#the-loop`): the objective from what the shape gave, then the
//! loop of Move Vertices steps and scheduled blocks, keeping a checkpoint state every
//! `checkpoint_interval` iterations and the last state, each with its loss, for the finish.

use std::borrow::Cow;

use roar_loss::{KnnOptions, KnnPlanarProjector, Loss, LossError, PointCloud};
use roar_mesh::spatial::Projector;
use roar_mesh::{Mesh, TrackedMesh};
use roar_ops::blocks::block::{BlockContext, BlockStats};
use roar_ops::optim::{Optimizer, OptimizerOptions};
use roar_ops::untangle::{LimiterOptions, limit_steps};
use roar_render::{Camera, Image};

use crate::config::{ConfigError, ReconstructConfig};
use crate::error::PipelineError;
use crate::objective::{LossFactory, Prepared};
use crate::report::{IterationRecord, RunStats};
use crate::rig::coarse_rig_cameras;
use crate::run::{Run, StageClock};
use crate::schedule::ScheduledBlock;
use crate::shape::Shape;
use crate::stages::prepare::Rig;

/// The loss the loop minimizes and the k-NN planar projector over the point cloud (the
/// blocks' projector unless the shape has its own, and the data flips' normals).
pub(crate) struct Objective {
    pub loss: Box<dyn Loss>,
    pub projector: KnnPlanarProjector,
}

/// Builds the objective from the shape's target renders and `cloud` with `loss_factory`.
pub(crate) fn objective(
    shape: &dyn Shape,
    rig: &Rig,
    cloud: &PointCloud,
    loss_factory: &LossFactory,
    run: &mut Run,
) -> Result<Objective, PipelineError> {
    let config = run.config;
    let cameras = &rig.cameras;
    let renders = target_renders(shape, cameras)?;
    let coarse_cameras = coarse_rig_cameras(config);
    let coarse_renders = target_renders(shape, &coarse_cameras)?;
    let loss = loss_factory(&Prepared {
        cameras,
        renders: &renders,
        coarse_cameras: &coarse_cameras,
        coarse_renders: &coarse_renders,
        cloud,
        signed_distance: shape.signed_distance(),
        config,
    })?;
    drop((renders, coarse_renders));
    let projector = KnnPlanarProjector::new(
        &cloud.points,
        &cloud.normals,
        &KnnOptions {
            k: config.loss.planar_neighbours,
            ..KnnOptions::default()
        },
    )?;
    Ok(Objective { loss, projector })
}

/// The shape's target renders for `cameras`, one per camera.
fn target_renders<'s>(
    shape: &'s dyn Shape,
    cameras: &[Camera],
) -> Result<Cow<'s, [Image]>, PipelineError> {
    if cameras.is_empty() {
        return Ok(Cow::Borrowed(&[]));
    }
    let renders = shape.target_renders(cameras)?;
    if renders.len() != cameras.len() {
        return Err(PipelineError::Loss(LossError::InvalidTarget(format!(
            "{}: {} target renders for {} cameras",
            shape.name(),
            renders.len(),
            cameras.len()
        ))));
    }
    Ok(renders)
}

/// Runs `config.iterations` iterations of the loop on `mesh` (a Move Vertices step, then the
/// blocks due), fewer when the loss levels off ([`levelled_off`]), and returns the states to
/// finish from: the checkpoints, each with the loss before its iteration's step, and the last
/// state with its loss (NaN when there is no checkpoint to compare it with).
pub(crate) fn optimize(
    mut mesh: Mesh,
    loss: &mut dyn Loss,
    block_projector: &dyn Projector,
    blocks: &mut [ScheduledBlock],
    run: &mut Run,
) -> Result<Vec<LoopState>, PipelineError> {
    let config = run.config;
    let budget = config.working_budget();
    let mut optimizer = new_optimizer(&mesh, config)?;
    // The loop's state and its loss at every checkpoint iteration, to finish from.
    let mut states: Vec<LoopState> = Vec::new();
    run.clock.lap("loop_setup");

    for iteration in 0..config.optimize.iterations {
        let candidate = (config.optimize.checkpoint_interval > 0
            && iteration % config.optimize.checkpoint_interval == 0)
            .then(|| mesh.clone());
        loss.set_iteration(iteration);
        let record = move_vertices(
            &mut mesh,
            &mut optimizer,
            loss,
            config,
            &mut run.stats,
            &mut run.clock,
            "loop",
        )?;
        let value = record.loss;
        // Whether this iteration's checkpoint shows the loss levelled off: the loop then ends
        // after the iteration's blocks.
        let mut levelled = false;
        if let Some(mesh) = candidate {
            // `value` is the loss of the state before this iteration's step.
            states.push(LoopState {
                iteration,
                loss: value,
                mesh,
            });
            let level = &config.optimize;
            levelled = levelled_off(&states, level.level_window, level.level_tolerance);
            run.clock.lap("loop_checkpoint");
        }
        let stats = &mut run.stats;
        if iteration == 0 {
            stats.optimize.loss_first = value;
        }
        stats.optimize.loss_last = value;
        stats.optimize.history.push(record);
        let context = BlockContext {
            iteration,
            face_budget: budget,
            projector: Some(block_projector),
        };
        for scheduled in blocks.iter_mut() {
            let due = scheduled.every > 0
                && iteration % scheduled.every == 0
                && !(scheduled.skip_first && iteration == 0);
            if due {
                let block_stats = scheduled
                    .block
                    .apply(&mut TrackedMesh::new(&mut mesh, &mut optimizer), &context);
                *run.stats
                    .optimize
                    .block_accepted
                    .entry(block_stats.name)
                    .or_insert(0) += total_accepted(&block_stats);
                run.clock
                    .lap(&format!("loop_block_{}", scheduled.block.name()));
            }
        }
        run.report("optimize", iteration, value, mesh.n_faces())?;
        run.stats.optimize.loop_iterations = iteration + 1;
        if levelled {
            break;
        }
    }
    run.stats.optimize.loop_faces = mesh.n_faces();

    // The last state's loss decides only when there are other states to compare with.
    let last = if states.is_empty() {
        f64::NAN
    } else {
        let triangles = compact_triangles(&mut mesh, &mut optimizer);
        loss.value_and_grad(mesh.positions(), &triangles)?.0
    };
    run.stats.optimize.loss_of_last_state = last;
    states.push(LoopState {
        iteration: run.stats.optimize.loop_iterations,
        loss: last,
        mesh,
    });
    run.clock.lap("loop_loss");
    Ok(states)
}

/// Whether the loss has levelled off at the newest of the checkpoint `states` (in iteration
/// order, the newest just kept): none of those of the last `window` iterations is `tolerance`
/// (relative) below the lowest loss before them. Never with `window == 0` or before iteration
/// `window`.
fn levelled_off(states: &[LoopState], window: usize, tolerance: f64) -> bool {
    let Some(newest) = states.last() else {
        return false;
    };
    if window == 0 || newest.iteration < window {
        return false;
    }
    let start = newest.iteration - window;
    let lowest = |recent: bool| {
        states
            .iter()
            .filter(|s| (s.iteration > start) == recent)
            .map(|s| s.loss)
            .fold(f64::INFINITY, f64::min)
    };
    lowest(true) > lowest(false) * (1.0 - tolerance)
}

/// A state of the loop's mesh and its loss.
pub(crate) struct LoopState {
    pub iteration: usize,
    pub loss: f64,
    pub mesh: Mesh,
}

/// A fresh optimizer for `mesh` with the configured learning rate and Laplacian weight.
pub(crate) fn new_optimizer(
    mesh: &Mesh,
    config: &ReconstructConfig,
) -> Result<Optimizer, PipelineError> {
    Optimizer::new(
        mesh.vertex_capacity(),
        OptimizerOptions {
            lr: config.optimize.learning_rate,
            laplacian_weight: config.optimize.laplacian_weight,
            ..OptimizerOptions::default()
        },
    )
    .map_err(|e| ConfigError::Optimizer(e).into())
}

/// One Move Vertices step (paper §3.1): the loss and its gradient on the compacted mesh, the
/// optimizer step, then the step limiter if configured. Stage times go to `{stage}_loss`,
/// `{stage}_step` and `{stage}_step_limiter`. Returns the loss before the step.
pub(crate) fn move_vertices(
    mesh: &mut Mesh,
    optimizer: &mut Optimizer,
    loss: &mut dyn Loss,
    config: &ReconstructConfig,
    stats: &mut RunStats,
    clock: &mut StageClock,
    stage: &str,
) -> Result<IterationRecord, PipelineError> {
    let triangles = compact_triangles(mesh, optimizer);
    let (value, gradient) = loss.value_and_grad(mesh.positions(), &triangles)?;
    let record = IterationRecord {
        loss: value,
        terms: loss.last_terms().into_iter().collect(),
        faces: mesh.n_faces(),
    };
    clock.lap(&format!("{stage}_loss"));
    let before = config
        .optimize
        .step_limiter
        .then(|| mesh.positions().to_vec());
    optimizer.step(mesh.positions_mut(), &triangles, &gradient)?;
    clock.lap(&format!("{stage}_step"));
    if let Some(before) = before {
        let limited = limit_steps(
            &before,
            mesh.positions_mut(),
            &triangles,
            &LimiterOptions::default(),
        );
        stats.optimize.steps_shortened += limited.shortened + limited.cancelled;
        clock.lap(&format!("{stage}_step_limiter"));
    }
    Ok(record)
}

/// The triangles of a compact mesh (compacting it, and the optimizer with it, if needed).
fn compact_triangles(mesh: &mut Mesh, optimizer: &mut Optimizer) -> Vec<[u32; 3]> {
    let mut tracked = TrackedMesh::new(mesh, optimizer);
    if tracked.vertex_capacity() != tracked.n_vertices()
        || tracked.face_capacity() != tracked.n_faces()
    {
        tracked.compact();
    }
    mesh.faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect()
}

/// Accepted operations of a block, including nested blocks (the flips of Face Collapse).
fn total_accepted(stats: &BlockStats) -> usize {
    stats.accepted + stats.sub.iter().map(total_accepted).sum::<usize>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checkpoint states every 10 iterations with the given losses.
    fn states(losses: &[f64]) -> Vec<LoopState> {
        let mesh = roar_mesh::shapes::cube();
        losses
            .iter()
            .enumerate()
            .map(|(k, &loss)| LoopState {
                iteration: 10 * k,
                loss,
                mesh: mesh.clone(),
            })
            .collect()
    }

    #[test]
    fn the_loop_stops_when_a_whole_window_brings_the_lowest_loss_down_by_less_than_the_tolerance() {
        // Falling 2 % per checkpoint: never levelled off.
        let falling: Vec<f64> = (0..10).map(|k| 0.98f64.powi(k)).collect();
        for n in 1..=falling.len() {
            assert!(!levelled_off(&states(&falling[..n]), 30, 0.01));
        }
        // Flat from iteration 30 (the fourth checkpoint): the window (30, 60] brings nothing.
        let flat = [1.0, 0.5, 0.4, 0.3, 0.3, 0.31, 0.3];
        assert!(!levelled_off(&states(&flat[..6]), 30, 0.01));
        assert!(levelled_off(&states(&flat), 30, 0.01));
        // A gain of 2 % inside the window is above a 1 % tolerance, not above a 5 % one.
        let slow = [1.0, 0.5, 0.4, 0.3, 0.3, 0.3, 0.294];
        assert!(!levelled_off(&states(&slow), 30, 0.01));
        assert!(levelled_off(&states(&slow), 30, 0.05));
        // A window of 0 never stops; nor does any window before its own length.
        assert!(!levelled_off(&states(&flat), 0, 0.01));
        assert!(!levelled_off(&states(&flat), 70, 0.01));
    }
}
