//! The ROAR pipeline (DESIGN.md §2): from a soup to a closed, oriented 2-manifold with exactly N
//! faces and no self-intersections.
//!
//! ```text
//! soup ─weld, normalize, twin clean-up─▶ target T′ + renders
//! T′ ─watertight init, QEM ≤ 20k─▶ M0 ;  T′ + sharp edges of M0 ─▶ point cloud P
//! M0 ─QEM─▶ working budget W
//! loop: loss (λ1·render + λ2·planar) → optimizer step → scheduled blocks
//! fill to N (edge splits) → untangle → [QEM to 2N → polish, when W > 2N] → QEM to exactly N
//!   → smoothing → data flips → polish → denormalize
//! ```
//!
//! The input is any [`Shape`] (the soup is [`SoupShape`]): the pipeline asks it for its
//! normalization, target renders, point cloud and initial mesh, and never which kind it is.
//! A researcher swaps a piece without forking a crate: [`Reconstruction::loss_factory`] builds
//! the objective from what the shape gave, and [`Reconstruction::blocks`] is the remeshing
//! schedule (any [`Block`]).

pub mod config;
pub mod soup;

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::DVec3;
use roar_loss::{
    KnnOptions, KnnPlanarProjector, Loss, LossError, PlanarLoss, PlanarOptions, PointCloud,
    RenderLoss, Shape, ShapeError, SignedDistance, TargetOptions, WeightedSum,
};
use roar_mesh::Mesh;
use roar_mesh::spatial::{Normalization, Projector, self_intersecting_faces};
use roar_ops::blocks::block::{Block, BlockContext, BlockStats};
use roar_ops::blocks::collapse::{FaceCollapse, FaceCollapseOptions};
use roar_ops::blocks::flips::FlipOptions;
use roar_ops::blocks::smoothing::{SmoothingOptions, TangentialSmoothing};
use roar_ops::blocks::split::{FaceSplit, FaceSplitOptions, SplitThreshold};
use roar_ops::decimate::{DecimateError, DecimateOptions, DecimateStats, decimate};
use roar_ops::finish::data_flips::{DataFlipOptions, flip_toward_target};
use roar_ops::finish::degenerate::{DegenerateOptions, collapse_degenerate_faces};
use roar_ops::finish::fill::fill_to_budget;
use roar_ops::finish::genus::{
    HandleRemovalOptions, ReduceGenusError, RemovedHandle, decimate_removing_handles,
};
use roar_ops::finish::offset::offset_outward;
use roar_ops::finish::slivers::{SliverOptions, flip_slivers};
use roar_ops::init::InitError;
use roar_ops::optim::{Optimizer, OptimizerOptions};
use roar_ops::untangle::{LimiterOptions, UntangleOptions, UntangleStats, limit_steps, untangle};
use roar_render::{Camera, Image, star_cameras};
use serde::Serialize;

pub use config::{InitKind, ReconstructConfig};
pub use soup::SoupShape;

/// Why a reconstruction failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The configuration is unusable.
    #[error("config: {0}")]
    Config(String),
    /// Target preparation or a loss failed.
    #[error("{0}")]
    Loss(#[from] LossError),
    /// The watertight init failed.
    #[error("init: {0}")]
    Init(#[from] InitError),
    /// The input shape could not give what the pipeline asked for.
    #[error("{0}")]
    Shape(#[from] ShapeError),
    /// A mesh that must be a closed manifold is not (a bug in an operator).
    #[error("internal: {0}")]
    Internal(String),
    /// The final QEM could not reach the budget.
    #[error("{0}")]
    Budget(#[from] DecimateError),
    /// Self-intersections survived the untangle block.
    #[error("{0} faces still intersect after the untangle block")]
    Intersections(usize),
    /// [`Reconstruction::cancel`] was set; the run stopped at its next progress report.
    #[error("cancelled")]
    Cancelled,
    /// The budget is below a tetrahedron per piece, or a handle could not be cut.
    #[error("{0}")]
    Genus(#[from] ReduceGenusError),
}

/// What the pipeline hands to a loss factory: what the input [`Shape`] gave, in rig
/// coordinates.
pub struct Prepared<'a> {
    /// The camera rig ([`rig_cameras`]).
    pub cameras: &'a [Camera],
    /// The shape's target normal map for each camera.
    pub renders: &'a [Image],
    /// The oriented target point cloud P (with the sharp-edge samples).
    pub cloud: &'a PointCloud,
    /// The shape's signed distance, if it has one.
    pub signed_distance: Option<&'a dyn SignedDistance>,
    /// The effective configuration.
    pub config: &'a ReconstructConfig,
}

/// Builds the objective once the target is prepared.
pub type LossFactory = Box<dyn Fn(&Prepared) -> Result<Box<dyn Loss>, PipelineError>>;

/// A block and when it runs: at iterations `it` with `it % every == 0` (and `it > 0` when
/// `skip_first`).
pub struct ScheduledBlock {
    /// The block.
    pub block: Box<dyn Block>,
    /// Period in iterations (0 = never).
    pub every: usize,
    /// Skip iteration 0 (the Face Split block does, spec §1.2).
    pub skip_first: bool,
}

/// One progress report.
#[derive(Debug, Clone)]
pub struct Progress {
    /// What is running ("target", "init", "optimize", "untangle", "decimate", …).
    pub stage: &'static str,
    /// Iteration within the optimize stage (0-based), or 0.
    pub iteration: usize,
    /// Total iterations of the optimize stage.
    pub iterations: usize,
    /// Last loss value (NaN before the first).
    pub loss: f64,
    /// Current face count (0 before the init).
    pub faces: usize,
}

/// Summary of one run, for the JSON report.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RunStats {
    /// Seconds per stage, in first-run order of stage names (sorted by name in JSON).
    pub seconds: BTreeMap<String, f64>,
    /// Target clean-up figures.
    pub target_faces: usize,
    /// Twins dropped by the pixel-count rule.
    pub twins_dropped: usize,
    /// Point cloud size (with sharp-edge samples).
    pub point_cloud: usize,
    /// Faces of the voxel surface before any decimation.
    pub init_voxel_faces: usize,
    /// Faces of M0 after QEM to ≤ init_max_faces.
    pub init_faces: usize,
    /// Components (pieces) of M0.
    pub init_components: usize,
    /// Genus of M0 (kept to the end unless `handles_removed` says otherwise).
    pub init_genus: usize,
    /// Voxels the init's winding-number rule turned solid (punctures closed;
    /// `roar_ops::init::InitOptions::enclosure_winding_threshold`).
    pub init_voxels_filled_by_winding: usize,
    /// The working budget W.
    pub working_budget: usize,
    /// Loss at the first and last iteration.
    pub loss_first: f64,
    /// See `loss_first`.
    pub loss_last: f64,
    /// Loss, its terms and the face count at every iteration.
    pub history: Vec<IterationRecord>,
    /// Faces after the optimization loop.
    pub loop_faces: usize,
    /// Accepted operations per block over the loop, by block name.
    pub block_accepted: BTreeMap<&'static str, usize>,
    /// Vertex steps the step limiter shortened or cancelled over the loop.
    pub steps_shortened: usize,
    /// Edge splits used to fill up to N.
    pub fill_splits: usize,
    /// Loss of the loop's last state (evaluated once more after the last iteration; NaN, null
    /// in the report, when no checkpoint was kept to compare it with).
    pub loss_of_last_state: f64,
    /// The iteration whose starting state the run finished from (`iterations` for the state
    /// after the last one): the lowest-loss state of the checkpoints and the last one that the
    /// untangle block could clear (`checkpoint_interval`).
    pub finished_from_iteration: usize,
    /// States with a lower loss that the untangle block could not clear, in the order tried.
    pub untangle_failures: Vec<UntangleFailure>,
    /// Untangle statistics.
    pub untangle_initial_pairs: usize,
    /// Rounds the untangle block needed.
    pub untangle_rounds: usize,
    /// Collapses of the finish's QEMs (to 2N first when the mesh has more faces, see
    /// `finish_budgets`, then to N).
    pub final_collapses: usize,
    /// Vertices moved the whole `final_qem_offset` before the finish's QEMs, summed (the others
    /// were shortened or kept where a full move would have made faces intersect).
    pub offset_vertices: usize,
    /// Vertex moves of the tangential smoothing after the finish's QEMs, summed
    /// (`final_smoothing_sweeps`; 0 also when the smoothed mesh was dropped because it would
    /// have intersected itself).
    pub final_smoothing_moves: usize,
    /// Data-dependent flips after the finish's QEMs, summed (`data_flip_rounds`; 0 also when the
    /// flipped mesh was dropped because it would have intersected itself).
    pub data_flips: usize,
    /// Loss, terms and faces at every polish iteration (after each of the finish's QEMs).
    pub polish_history: Vec<IterationRecord>,
    /// Whether the last polished mesh was kept (false: it intersected itself, or no polish ran;
    /// true also when its best state was the unpolished one).
    pub polish_kept: bool,
    /// Sliver flips in the output (`sliver_quality`; 0 also when they were undone because the
    /// written mesh would have intersected itself).
    pub sliver_flips: usize,
    /// Edge collapses that removed degenerate faces no flip could, each followed by an edge
    /// split to keep the face count (0 also when undone, as `sliver_flips`).
    pub degenerate_collapses: usize,
    /// Handles the finish removed so the budget could be met (shortest loop first, in order;
    /// empty with `keep_topology`): the output's genus is `init_genus` minus their number.
    pub handles_removed: Vec<RemovedHandle>,
}

/// One iteration of the optimize stage, as the report lists it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct IterationRecord {
    /// The loss before the step.
    pub loss: f64,
    /// The weighted value of each term of the loss (empty for a one-term loss).
    pub terms: BTreeMap<&'static str, f64>,
    /// Faces when the loss was evaluated.
    pub faces: usize,
}

/// The output of a run: the mesh in the input's coordinates.
pub struct Output {
    /// Vertex positions (denormalized).
    pub positions: Vec<DVec3>,
    /// Triangles (closed, oriented, 2-manifold; exactly `config.faces` of them).
    pub triangles: Vec<[u32; 3]>,
    /// What happened.
    pub stats: RunStats,
}

/// A configured reconstruction whose losses and blocks can be replaced.
pub struct Reconstruction {
    /// Every hyper-parameter.
    pub config: ReconstructConfig,
    /// Builds the objective (default: λ1·render + λ2·planar, spec §3.2.3).
    pub loss_factory: LossFactory,
    /// The remeshing schedule (default: Face Collapse + flips every iteration, Face Split every
    /// 10, tangential smoothing every 5; spec §1.2).
    pub blocks: Vec<ScheduledBlock>,
    /// When set (by another thread, a signal handler, a binding), the run stops with
    /// [`PipelineError::Cancelled`] at its next progress report (once per iteration of the
    /// loop, and between stages). `None` (the default) never cancels.
    pub cancel: Option<Arc<AtomicBool>>,
}

impl Reconstruction {
    /// The paper's pipeline for `config`.
    pub fn new(config: ReconstructConfig) -> Self {
        let blocks = default_blocks(&config);
        Self {
            config,
            loss_factory: Box::new(default_loss),
            blocks,
            cancel: None,
        }
    }

    /// Runs the whole pipeline on a soup (any coordinates): [`Reconstruction::run`] on a
    /// [`SoupShape`] with this reconstruction's config.
    pub fn run_soup(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<Output, PipelineError> {
        let mut shape = SoupShape::new("soup", positions, triangles, &self.config);
        self.run(&mut shape, progress)
    }

    /// Runs the whole pipeline on `shape` (the [`Shape`] module docs give the order of the
    /// calls), reporting progress; the output is in the input's coordinates.
    pub fn run(
        &mut self,
        shape: &mut dyn Shape,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<Output, PipelineError> {
        let config = self.config.clone();
        config.validate().map_err(PipelineError::Config)?;
        let mut stats = RunStats::default();
        let mut clock = StageClock::start();
        let cancel = self.cancel.clone();
        let mut report = |stage, iteration, loss, faces| {
            progress(&Progress {
                stage,
                iteration,
                iterations: config.iterations,
                loss,
                faces,
            });
            match &cancel {
                Some(flag) if flag.load(Ordering::Relaxed) => Err(PipelineError::Cancelled),
                _ => Ok(()),
            }
        };

        report("target", 0, f64::NAN, 0)?;
        let cameras = rig_cameras(&config);
        shape.prepare(&cameras)?;
        let normalization = shape.normalization();
        let summary = shape.summary();
        stats.target_faces = summary.target_faces;
        stats.twins_dropped = summary.twins_dropped;
        clock.lap("target");

        report("init", 0, f64::NAN, 0)?;
        let mut mesh = initial_mesh(&*shape, &config, &mut stats)?;
        crate::budget::check_budget(
            "faces =",
            config.faces,
            crate::budget::min_reachable_budget(&mesh.component_genera(), config.keep_topology),
        )
        .map_err(|e| PipelineError::Config(format!("{e} (for the pieces of the init)")))?;
        clock.lap("init");

        report("point_cloud", 0, f64::NAN, mesh.n_faces())?;
        let cloud = shape.point_cloud(&mesh)?;
        if cloud.points.is_empty() || cloud.points.len() != cloud.normals.len() {
            return Err(PipelineError::Loss(LossError::InvalidTarget(format!(
                "{}: the point cloud is empty or has not one normal per point",
                shape.name()
            ))));
        }
        stats.point_cloud = cloud.points.len();
        clock.lap("point_cloud");

        let budget = config.working_budget();
        stats.working_budget = budget;
        if mesh.n_faces() > budget {
            let options = DecimateOptions {
                best_effort: true,
                ..DecimateOptions::default()
            };
            decimate(&mut mesh, budget, &options)?;
        }
        clock.lap("working_budget_qem");

        let renders = shape.target_renders(&cameras)?;
        if renders.len() != cameras.len() {
            return Err(PipelineError::Loss(LossError::InvalidTarget(format!(
                "{}: {} target renders for {} cameras",
                shape.name(),
                renders.len(),
                cameras.len()
            ))));
        }
        let mut loss = (self.loss_factory)(&Prepared {
            cameras: &cameras,
            renders: &renders,
            cloud: &cloud,
            signed_distance: shape.signed_distance(),
            config: &config,
        })?;
        drop(renders);
        let projector = KnnPlanarProjector::new(
            &cloud.points,
            &cloud.normals,
            &KnnOptions {
                k: config.planar_neighbours,
                ..KnnOptions::default()
            },
        )?;
        // The Face Split block's scores use the shape's own projector if it has one.
        let block_projector: &dyn Projector = shape.projector().unwrap_or(&projector);
        let mut optimizer = new_optimizer(&mesh, &config)?;
        // The loop's state and its loss at every checkpoint iteration, to finish from.
        let mut states: Vec<LoopState> = Vec::new();
        clock.lap("loop_setup");

        for iteration in 0..config.iterations {
            let candidate = (config.checkpoint_interval > 0
                && iteration % config.checkpoint_interval == 0)
                .then(|| mesh.clone());
            let record = move_vertices(
                &mut mesh,
                &mut optimizer,
                loss.as_mut(),
                &config,
                &mut stats,
                &mut clock,
                "loop",
            )?;
            let value = record.loss;
            if let Some(mesh) = candidate {
                // `value` is the loss of the state before this iteration's step.
                states.push(LoopState {
                    iteration,
                    loss: value,
                    mesh,
                });
                clock.lap("loop_checkpoint");
            }
            if iteration == 0 {
                stats.loss_first = value;
            }
            stats.loss_last = value;
            stats.history.push(record);
            let context = BlockContext {
                iteration,
                face_budget: budget,
                projector: Some(block_projector),
            };
            for scheduled in &mut self.blocks {
                let due = scheduled.every > 0
                    && iteration % scheduled.every == 0
                    && !(scheduled.skip_first && iteration == 0);
                if due {
                    let block_stats = scheduled.block.apply(&mut mesh, &mut optimizer, &context);
                    *stats.block_accepted.entry(block_stats.name).or_insert(0) +=
                        total_accepted(&block_stats);
                    clock.lap(&format!("loop_block_{}", scheduled.block.name()));
                }
            }
            report("optimize", iteration, value, mesh.n_faces())?;
        }
        stats.loop_faces = mesh.n_faces();

        report("finish", config.iterations, stats.loss_last, mesh.n_faces())?;
        // The last state's loss decides only when there are other states to compare with.
        let last = if states.is_empty() {
            f64::NAN
        } else {
            let triangles = compact_triangles(&mut mesh, &mut optimizer);
            loss.value_and_grad(mesh.positions(), &triangles)?.0
        };
        stats.loss_of_last_state = last;
        states.push(LoopState {
            iteration: config.iterations,
            loss: last,
            mesh,
        });
        clock.lap("loop_loss");
        let mut mesh = finish_from_best_state(states, &config, &mut stats)?;
        clock.lap("untangle");

        report(
            "decimate",
            config.iterations,
            stats.loss_last,
            mesh.n_faces(),
        )?;
        let polishing = config.iterations > 0 && config.polish_iterations > 0;
        for faces in finish_budgets(mesh.n_faces(), config.faces, polishing) {
            if polishing && config.final_qem_offset > 0.0 {
                stats.offset_vertices += offset_outward(&mut mesh, config.final_qem_offset);
                clock.lap("offset");
            }
            let decimated = final_decimation(&mut mesh, faces, &config, &mut stats)?;
            stats.final_collapses += decimated.collapses;
            clock.lap("final_qem");

            if config.iterations > 0 && config.final_smoothing_sweeps > 0 {
                mesh = smooth_if_clean(mesh, &normalization, &config, &mut stats);
                clock.lap("final_smoothing");
            }

            if config.iterations > 0 && config.data_flip_rounds > 0 {
                mesh = flip_toward_cloud_if_clean(
                    mesh,
                    &projector,
                    &normalization,
                    &config,
                    &mut stats,
                );
                clock.lap("data_flips");
            }

            // No Move Vertices step at all with `iterations = 0`: that run is the plain init + QEM.
            if polishing {
                report("polish", config.iterations, stats.loss_last, mesh.n_faces())?;
                mesh = polish(
                    mesh,
                    loss.as_mut(),
                    &normalization,
                    &config,
                    &mut stats,
                    &mut clock,
                )?;
            }
        }
        drop(loss);
        if config.iterations > 0 && config.sliver_quality > 0.0 {
            mesh = remove_slivers_if_clean(mesh, &normalization, &config, &mut stats);
            clock.lap("sliver_flips");
        }

        let (mut out_positions, out_triangles) = mesh.to_triangles();
        normalization.invert_all(&mut out_positions);
        stats.seconds = clock.seconds;
        Ok(Output {
            positions: out_positions,
            triangles: out_triangles,
            stats,
        })
    }
}

/// The camera rig of `config` (spec §3.2.1: the star rig, `views_per_axis²` views of
/// `render_resolution²` pixels), for which every shape renders its target.
pub fn rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {
    star_cameras(
        config.views_per_axis,
        config.views_per_axis,
        config.render_resolution,
        config.render_resolution,
    )
}

/// The target renders' options of `config` (spec §3.1, §3.2.1), as the pipeline uses them.
pub fn target_options(config: &ReconstructConfig) -> TargetOptions {
    TargetOptions {
        views_per_axis: config.views_per_axis,
        resolution: config.render_resolution,
        twin_ratio: config.twin_ratio,
    }
}

/// The planar loss options of `config` (spec §3.2.2), as [`default_loss`] uses them.
pub fn planar_options(config: &ReconstructConfig) -> PlanarOptions {
    PlanarOptions {
        knn: KnnOptions {
            k: config.planar_neighbours,
            ..KnnOptions::default()
        },
        t2s: config.planar_t2s,
        max_samples: config.planar_max_samples,
        scale: config.planar_scale,
        seed: config.seed,
        ..PlanarOptions::default()
    }
}

/// The default objective: `λ1·L_render + λ2·L_planar` (spec §3.2.3).
pub fn default_loss(prepared: &Prepared) -> Result<Box<dyn Loss>, PipelineError> {
    let config = prepared.config;
    let planar = PlanarLoss::new(
        &prepared.cloud.points,
        &prepared.cloud.normals,
        &planar_options(config),
    )?;
    Ok(Box::new(
        WeightedSum::default()
            .with(
                config.render_weight,
                Box::new(RenderLoss::from_renders(prepared.cameras, prepared.renders)),
            )
            .with(config.planar_weight, Box::new(planar)),
    ))
}

/// The paper's schedule (spec §1.2, §1.3).
pub fn default_blocks(config: &ReconstructConfig) -> Vec<ScheduledBlock> {
    vec![
        ScheduledBlock {
            block: Box::new(FaceCollapse {
                options: FaceCollapseOptions {
                    fold_slack: config.collapse_fold_slack,
                    min_normal_size: (config.collapse_min_normal_size > 0.0)
                        .then_some(config.collapse_min_normal_size),
                    flips: Some(FlipOptions {
                        guard_intersections: config.guard_intersections,
                        ..FlipOptions::default()
                    }),
                    guard_intersections: config.guard_intersections,
                    ..FaceCollapseOptions::default()
                },
            }),
            every: config.collapse_interval,
            skip_first: false,
        },
        ScheduledBlock {
            block: Box::new(FaceSplit {
                options: FaceSplitOptions {
                    threshold: SplitThreshold::PerSubTriangle(config.split_threshold),
                    seed: config.seed,
                    guard_intersections: config.guard_intersections,
                    ..FaceSplitOptions::default()
                },
            }),
            every: config.split_interval,
            skip_first: true,
        },
        ScheduledBlock {
            block: Box::new(TangentialSmoothing {
                options: SmoothingOptions {
                    guard_intersections: config.guard_intersections,
                    ..SmoothingOptions::default()
                },
            }),
            every: config.smoothing_interval,
            skip_first: false,
        },
    ]
}

/// M0: the shape's own initial mesh (for a soup the watertight init of T′, decimated to at
/// most `init_max_faces`), or an icosphere of radius 0.5 (`init = "sphere"`).
fn initial_mesh(
    shape: &dyn Shape,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<Mesh, PipelineError> {
    let mesh = match config.init {
        InitKind::Watertight => {
            let initial = shape.initial_mesh()?;
            stats.init_voxel_faces = initial.raw_faces;
            stats.init_voxels_filled_by_winding = initial.voxels_filled_by_winding;
            initial.mesh
        }
        InitKind::Sphere => {
            let mut sphere = roar_mesh::shapes::icosphere(config.sphere_level);
            for p in sphere.positions_mut() {
                *p *= 0.5;
            }
            stats.init_voxel_faces = sphere.n_faces();
            sphere
        }
    };
    stats.init_faces = mesh.n_faces();
    stats.init_components = mesh.components().0;
    stats.init_genus = mesh.genus();
    Ok(mesh)
}

/// A fresh optimizer for `mesh` with the configured learning rate and Laplacian weight.
fn new_optimizer(mesh: &Mesh, config: &ReconstructConfig) -> Result<Optimizer, PipelineError> {
    Optimizer::new(
        mesh.vertex_capacity(),
        OptimizerOptions {
            lr: config.learning_rate,
            laplacian_weight: config.laplacian_weight,
            ..OptimizerOptions::default()
        },
    )
    .map_err(|e| PipelineError::Config(e.to_string()))
}

/// One Move Vertices step (spec §3.2.4): the loss and its gradient on the compacted mesh, the
/// optimizer step, then the step limiter if configured. Stage times go to `{stage}_loss`,
/// `{stage}_step` and `{stage}_step_limiter`. Returns the loss before the step.
fn move_vertices(
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
    let before = config.step_limiter.then(|| mesh.positions().to_vec());
    optimizer
        .step(mesh.positions_mut(), &triangles, &gradient)
        .map_err(|e| PipelineError::Internal(e.to_string()))?;
    clock.lap(&format!("{stage}_step"));
    if let Some(before) = before {
        let limited = limit_steps(
            &before,
            mesh.positions_mut(),
            &triangles,
            &LimiterOptions::default(),
        );
        stats.steps_shortened += limited.shortened + limited.cancelled;
        clock.lap(&format!("{stage}_step_limiter"));
    }
    Ok(record)
}

/// `config.polish_iterations` Move Vertices steps on the final mesh, with a fresh optimizer, a
/// learning rate falling linearly to 0 (a constant rate leaves the vertices jittering by about
/// η·ℓ_v, which on a converged mesh is all a step does) and no blocks, so the face count and
/// topology stay. Keeps the evaluated state with the lowest loss (the given mesh is state 0, so
/// the polish never raises the loss), and only if it is free of self-intersections in the
/// input's coordinates, where it will be written (the step limiter makes that the rule, but
/// may leave faces closer than the untangle margin, and undoing the normalization rounds);
/// otherwise returns the mesh it was given.
fn polish(
    mesh: Mesh,
    loss: &mut dyn Loss,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
    clock: &mut StageClock,
) -> Result<Mesh, PipelineError> {
    let mut current = mesh.clone();
    let mut optimizer = new_optimizer(&current, config)?;
    let mut best: Option<(f64, Mesh)> = None;
    let steps = config.polish_iterations;
    for k in 0..steps {
        let mut options = *optimizer.options();
        options.lr = config.learning_rate * (steps - k) as f64 / steps as f64;
        optimizer
            .set_options(options)
            .map_err(|e| PipelineError::Internal(e.to_string()))?;
        let before = current.clone();
        let record = move_vertices(
            &mut current,
            &mut optimizer,
            loss,
            config,
            stats,
            clock,
            "polish",
        )?;
        if best.as_ref().is_none_or(|(l, _)| record.loss < *l) {
            best = Some((record.loss, before));
        }
        stats.polish_history.push(record);
    }
    let Some((_, best)) = best else {
        return Ok(mesh);
    };
    let clean = clean_in_output_coordinates(&best, normalization);
    clock.lap("polish_check");
    stats.polish_kept = clean;
    Ok(if clean { best } else { mesh })
}

/// The sliver flips of `roar_ops::finish::slivers` on the final mesh; then, for the degenerate faces
/// they leave, the collapses of `roar_ops::finish::degenerate`, the face count restored by edge splits
/// ([`fill_to_budget`], which moves no geometry), and the flips once more. Kept only if the result is
/// free of self-intersections in the input's coordinates, where it will be written (everything
/// is checked exactly in the normalized ones; undoing the normalization rounds).
fn remove_slivers_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let options = SliverOptions {
        max_quality: config.sliver_quality,
        ..SliverOptions::default()
    };
    let (mut flips, mut collapses) = (0, 0);
    let (mesh, changes) = keep_if_clean(mesh, normalization, |cleaned| {
        flips = flip_slivers(cleaned, &options).accepted;
        let faces = cleaned.n_faces();
        collapses = collapse_degenerate_faces(cleaned, &DegenerateOptions::default()).accepted;
        if collapses > 0 {
            fill_to_budget(cleaned, faces);
            flips += flip_slivers(cleaned, &options).accepted;
        }
        flips + collapses
    });
    if changes > 0 {
        stats.sliver_flips = flips;
        stats.degenerate_collapses = collapses;
    }
    mesh
}

/// The finish's one pattern for a step that must not make the output intersect itself: runs
/// `step` on a copy of `mesh` (`step` returns how many changes it made) and returns the copy
/// and that count if it is positive and the copy is free of self-intersections in the input's
/// coordinates ([`clean_in_output_coordinates`]); otherwise `mesh` as it was and 0.
fn keep_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    step: impl FnOnce(&mut Mesh) -> usize,
) -> (Mesh, usize) {
    let mut changed = mesh.clone();
    let changes = step(&mut changed);
    if changes == 0 || !clean_in_output_coordinates(&changed, normalization) {
        return (mesh, 0);
    }
    (changed, changes)
}

/// Whether `mesh`, with the normalization undone (as it will be written), is free of
/// self-intersections: the exact checks ran in normalized coordinates, and undoing the
/// normalization rounds.
fn clean_in_output_coordinates(mesh: &Mesh, normalization: &Normalization) -> bool {
    let (mut positions, triangles) = mesh.to_triangles();
    normalization.invert_all(&mut positions);
    !self_intersecting_faces(&positions, &triangles).contains(&true)
}

/// The triangles of a compact mesh (compacting it, and the optimizer with it, if needed).
fn compact_triangles(mesh: &mut Mesh, optimizer: &mut Optimizer) -> Vec<[u32; 3]> {
    if mesh.vertex_capacity() != mesh.n_vertices() || mesh.face_capacity() != mesh.n_faces() {
        roar_ops::optim::compact_with_optimizer(mesh, optimizer);
    }
    roar_ops::optim::sync_optimizer_len(mesh, optimizer);
    mesh.faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect()
}

/// Fills the mesh up to `config.faces`, runs the untangle block and fills again (its collapses
/// may take the mesh below the budget, and the final QEM never adds faces; splits do not move
/// any geometry, so no intersection comes back). Returns how many faces it could not clear.
fn fill_and_untangle(mesh: &mut Mesh, config: &ReconstructConfig, stats: &mut RunStats) -> usize {
    stats.fill_splits = fill_to_budget(mesh, config.faces);
    let untangled = untangle(
        mesh,
        &UntangleOptions {
            margin_rel: config.untangle_margin,
            ..UntangleOptions::default()
        },
    );
    record_untangle(stats, &untangled);
    stats.fill_splits += fill_to_budget(mesh, config.faces);
    untangled.unresolved_faces.len()
}

/// `config.final_smoothing_sweeps` sweeps of tangential smoothing with every move limited so
/// that no face pair starts to intersect, kept only if the result is free of self-intersections
/// in the input's coordinates, where it will be written (as for the polish and the sliver
/// flips).
fn smooth_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let options = SmoothingOptions {
        guard_intersections: true,
        ..SmoothingOptions::default()
    };
    let (mesh, moves) = keep_if_clean(mesh, normalization, |smoothed| {
        (0..config.final_smoothing_sweeps)
            .map(|_| roar_ops::blocks::smoothing::tangential_smoothing(smoothed, &options).accepted)
            .sum()
    });
    stats.final_smoothing_moves += moves;
    mesh
}

/// `config.data_flip_rounds` rounds of data-dependent flips toward the normals of the point cloud
/// (the normal of the cloud point nearest to each sample), kept only if the result is free of
/// self-intersections in the input's coordinates, as for the smoothing.
fn flip_toward_cloud_if_clean(
    mesh: Mesh,
    cloud: &KnnPlanarProjector,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let target_normal = |p: DVec3| {
        cloud
            .nearest(p, 1)
            .first()
            .map(|&(i, _)| cloud.normals()[i as usize])
    };
    let options = DataFlipOptions {
        max_rounds: config.data_flip_rounds,
        ..DataFlipOptions::default()
    };
    let (mesh, flips) = keep_if_clean(mesh, normalization, |flipped| {
        flip_toward_target(flipped, &target_normal, &options).accepted
    });
    stats.data_flips += flips;
    mesh
}

/// The face counts the finish decimates to, each followed by a polish: `[2N, N]` when the
/// polished mesh has more than 2N faces, otherwise `[N]`.
///
/// Why: below N = 2500 the working budget stays at its floor (5000), so the final QEM would
/// remove most of the faces in one go, placing vertices from the working mesh's quadrics alone.
/// Decimating to 2N first (where the working budget would be without the floor) and polishing
/// there puts the mesh back on the target before the last halving. Measured at N = 1000
/// (Chamfer/diag, one step → two): gpytoolbox-airplane 2.18e-3 → 2.05e-3, manifoldplus-chair
/// 3.51e-3 → 3.12e-3, manifoldplus-table 3.29e-3 → 3.18e-3, luke-f-16 1.82e-3 → 1.78e-3,
/// libigl-camelhead 2.95e-3 → 3.00e-3; normal cosine better on all seven meshes tried.
fn finish_budgets(faces: usize, budget: usize, polishing: bool) -> Vec<usize> {
    if polishing && faces > 2 * budget {
        vec![2 * budget, budget]
    } else {
        vec![budget]
    }
}

/// The guaranteed QEM to exactly `faces` (best effort only if configured). Unless
/// `keep_topology`, handles are removed (shortest loop first, `roar_ops::finish::genus`) when the genus
/// needs more faces than `faces` or the QEM stalls above it; each removal is noted on stderr and
/// recorded in `stats.handles_removed`.
fn final_decimation(
    mesh: &mut Mesh,
    faces: usize,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<DecimateStats, PipelineError> {
    let options = DecimateOptions {
        best_effort: config.best_effort,
        ..DecimateOptions::default()
    };
    let decimated = if config.keep_topology {
        decimate(mesh, faces, &options)?
    } else {
        let (decimated, removed) = decimate_removing_handles(
            mesh,
            faces,
            &options,
            &HandleRemovalOptions::default(),
            decimate,
        )?;
        for handle in &removed {
            eprintln!(
                "note: removed a handle to reach {faces} faces (cut along a loop of {} edges, \
                 length {:.4} in the unit sphere; --keep-topology fails instead)",
                handle.loop_vertices, handle.loop_length
            );
        }
        stats.handles_removed.extend(removed);
        decimated
    };
    if mesh.n_faces() != faces && !config.best_effort {
        return Err(PipelineError::Internal(format!(
            "the output has {} faces instead of {}",
            mesh.n_faces(),
            faces
        )));
    }
    Ok(decimated)
}

fn record_untangle(stats: &mut RunStats, untangled: &UntangleStats) {
    stats.untangle_initial_pairs = untangled.initial_pairs;
    stats.untangle_rounds = untangled.rounds;
}

/// A loop state the untangle block could not clear.
#[derive(Debug, Clone, Default, Serialize)]
pub struct UntangleFailure {
    /// The iteration whose starting state it was (`iterations` for the last state).
    pub iteration: usize,
    /// Faces still intersecting.
    pub unresolved_faces: usize,
}

/// A state of the loop's mesh and its loss.
struct LoopState {
    iteration: usize,
    loss: f64,
    mesh: Mesh,
}

/// Fills and untangles the loop's states in order of increasing loss (the later one first
/// among equals) and returns the first one the untangle block clears, recording the others in
/// `stats.untangle_failures`. Fails with the last state's unresolved face count when none
/// clears.
fn finish_from_best_state(
    mut states: Vec<LoopState>,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<Mesh, PipelineError> {
    states.sort_by(|a, b| {
        a.loss
            .total_cmp(&b.loss)
            .then(b.iteration.cmp(&a.iteration))
    });
    let mut unresolved = 0;
    for state in states {
        let mut mesh = state.mesh;
        unresolved = fill_and_untangle(&mut mesh, config, stats);
        if unresolved == 0 {
            stats.finished_from_iteration = state.iteration;
            return Ok(mesh);
        }
        stats.untangle_failures.push(UntangleFailure {
            iteration: state.iteration,
            unresolved_faces: unresolved,
        });
    }
    Err(PipelineError::Intersections(unresolved))
}

/// Accepted operations of a block, including nested blocks (the flips of Face Collapse).
fn total_accepted(stats: &BlockStats) -> usize {
    stats.accepted + stats.sub.iter().map(total_accepted).sum::<usize>()
}

/// Accumulates wall time per stage name.
struct StageClock {
    seconds: BTreeMap<String, f64>,
    last: Option<Instant>,
}

impl StageClock {
    fn start() -> Self {
        Self {
            seconds: BTreeMap::new(),
            last: Some(Instant::now()),
        }
    }

    /// Charges the time since the previous lap (or since creation) to `stage`.
    fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        let since = self.last.unwrap_or(now);
        *self.seconds.entry(stage.to_string()).or_insert(0.0) += (now - since).as_secs_f64();
        self.last = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::EdgeId;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::Aabb;
    use roar_mesh::spatial::count_intersecting_faces;
    use roar_ops::finish::fill::bisects_well;
    use roar_ops::geometry::{DEGENERATE_QUALITY, is_degenerate, triangle_quality};

    /// Faces at or above [`DEGENERATE_QUALITY`].
    fn degenerate_faces(mesh: &Mesh) -> usize {
        mesh.faces()
            .filter(|&f| {
                let corners = mesh.face_vertices(f).map(|v| mesh.position(v));
                is_degenerate(triangle_quality(corners), DEGENERATE_QUALITY)
            })
            .count()
    }

    #[test]
    fn the_finish_halves_through_2n_only_from_above_2n_and_when_polishing() {
        assert_eq!(finish_budgets(5000, 1000, true), vec![2000, 1000]);
        assert_eq!(finish_budgets(2000, 1000, true), vec![1000]);
        assert_eq!(finish_budgets(10000, 5000, true), vec![5000]);
        assert_eq!(finish_budgets(5000, 1000, false), vec![1000]);
    }

    #[test]
    fn the_last_stage_removes_a_needle_and_keeps_the_face_count() {
        let mut mesh = icosphere(3);
        let e = mesh.edges().next().unwrap();
        // Splitting an edge next to its end makes two needles (aspect ratio far above 100).
        mesh.split_edge(e, 1e-3);
        mesh.compact();
        let faces = mesh.n_faces();
        assert_eq!(degenerate_faces(&mesh), 2);
        let mut stats = RunStats::default();
        let config = ReconstructConfig::default();
        let mesh = remove_slivers_if_clean(mesh, &Normalization::IDENTITY, &config, &mut stats);
        assert_eq!(stats.degenerate_collapses, 1, "{stats:?}");
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert_eq!(degenerate_faces(&mesh), 0);
        assert_eq!(count_intersecting_faces(&mesh), 0);
    }

    #[test]
    fn the_fill_splits_no_edge_of_a_needle_even_when_it_is_the_longest() {
        // A spike makes the edges at one vertex the longest of the mesh; a needle planted on
        // one of them (split next to the spike's tip) borders the longest edges.
        let mut mesh = icosphere(1);
        let tip = mesh.vertices().next().unwrap();
        mesh.set_position(tip, 1.6 * mesh.position(tip));
        let spoke = mesh
            .edges()
            .find(|&e| mesh.edge_vertices(e)[0] == tip)
            .unwrap();
        mesh.split_edge(spoke, 1e-4);
        assert_eq!(degenerate_faces(&mesh), 2);
        let longest = mesh
            .edges()
            .max_by(|&a, &b| mesh.edge_length(a).total_cmp(&mesh.edge_length(b)))
            .unwrap();
        assert!(!bisects_well(&mesh, longest), "the setup lost its point");

        let faces = mesh.n_faces() + 20;
        let splits = fill_to_budget(&mut mesh, faces);
        assert_eq!(splits, 10);
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert_eq!(degenerate_faces(&mesh), 2, "a split made a degenerate face");
    }

    /// Two unit icospheres whose centres are `distance` apart, as one mesh of two pieces.
    fn two_spheres(distance: f64) -> Mesh {
        let (mut positions, mut triangles) = icosphere(2).to_triangles();
        let n = positions.len() as u32;
        let moved: Vec<DVec3> = positions.iter().map(|p| *p + DVec3::X * distance).collect();
        let shifted: Vec<[u32; 3]> = triangles.iter().map(|t| t.map(|v| v + n)).collect();
        positions.extend(moved);
        triangles.extend(shifted);
        Mesh::from_triangles(positions, &triangles).unwrap()
    }

    #[test]
    fn untangling_that_collapses_edges_is_filled_back_to_the_budget() {
        // Slivers on the first sphere where it crosses the second: the untangle block collapses
        // crossing slivers at once instead of moving them.
        let mut mesh = two_spheres(1.9);
        let centre = DVec3::X * 1.9;
        let inside = |p: DVec3| (p - centre).length() < 1.0;
        let crossing: Vec<EdgeId> = mesh
            .edges()
            .filter(|&e| {
                let [a, b] = mesh.edge_vertices(e).map(|v| mesh.position(v));
                a.x < 1.0 && inside(a) != inside(b)
            })
            .collect();
        assert!(!crossing.is_empty());
        for e in crossing {
            mesh.split_edge(e, 0.02);
        }
        let faces = mesh.n_faces();
        let config = ReconstructConfig {
            faces,
            ..ReconstructConfig::default()
        };
        let mut stats = RunStats::default();
        let unresolved = fill_and_untangle(&mut mesh, &config, &mut stats);
        assert_eq!(unresolved, 0);
        // The mesh started at the budget, so every split refilled a face the untangle removed.
        assert!(stats.untangle_initial_pairs > 0);
        assert!(stats.fill_splits > 0, "the untangle collapsed nothing");
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert!(count_intersecting_faces(&mesh) == 0);
    }

    #[test]
    fn the_offset_before_the_final_qem_moves_outward_without_crossing() {
        // Two spheres 1e-3 apart: the offset (2e-3 of the 4.9 diagonal here, 1e-2 each) would
        // push them into each other where they nearly touch, so those moves are shortened or
        // cancelled; everywhere else every vertex moves the whole way along its normal.
        let mut mesh = two_spheres(2.001);
        let before = mesh.clone();
        let moved = offset_outward(&mut mesh, 2e-3);
        mesh.validate().unwrap();
        assert_eq!(count_intersecting_faces(&mesh), 0);
        assert!(moved < mesh.n_vertices() && moved > mesh.n_vertices() * 9 / 10);
        let diagonal = Aabb::from_points(before.positions().iter().copied())
            .unwrap()
            .diagonal();
        let mut full = 0;
        for v in mesh.vertices() {
            let centre = if before.position(v).x < 1.0005 {
                DVec3::ZERO
            } else {
                DVec3::X * 2.001
            };
            let grown =
                (mesh.position(v) - centre).length() - (before.position(v) - centre).length();
            assert!(
                grown >= -1e-12 && grown <= 2e-3 * diagonal * (1.0 + 1e-9),
                "{grown}"
            );
            if grown > 2e-3 * diagonal * 0.999 {
                full += 1;
            }
        }
        assert_eq!(full, moved);
    }

    #[test]
    fn the_run_finishes_from_the_lowest_loss_state_the_untangle_clears() {
        // A sphere scrambled into a tangle the untangle cannot clear, with the lowest loss.
        let mut tangle = icosphere(2);
        for (k, p) in tangle.positions_mut().iter_mut().enumerate() {
            let t = k as f64;
            *p = DVec3::new((1.7 * t).sin(), (2.3 * t).cos(), (3.1 * t).sin());
        }
        let state = |iteration, loss, mesh: &Mesh| LoopState {
            iteration,
            loss,
            mesh: mesh.clone(),
        };
        let apart = two_spheres(3.0);
        let states = vec![
            state(0, 3.0, &apart),
            state(10, 1.0, &tangle),
            state(20, 2.0, &apart),
            state(30, 2.0, &apart),
        ];
        let config = ReconstructConfig {
            faces: apart.n_faces(),
            ..ReconstructConfig::default()
        };
        let mut stats = RunStats::default();
        let mesh = finish_from_best_state(states, &config, &mut stats).unwrap();
        assert_eq!(stats.untangle_failures.len(), 1);
        assert_eq!(stats.untangle_failures[0].iteration, 10);
        assert!(stats.untangle_failures[0].unresolved_faces > 0);
        // Of the two clean states with the next lowest loss, the later one.
        assert_eq!(stats.finished_from_iteration, 30);
        assert_eq!(mesh.n_faces(), apart.n_faces());
        assert_eq!(count_intersecting_faces(&mesh), 0);
    }
}
