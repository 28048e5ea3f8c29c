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
//! The input is any [`Shape`] (a soup or a set of range scans is a [`SoupShape`], an SDF an [`SdfShape`]): the pipeline asks it for its
//! normalization, target renders, point cloud and initial mesh, and never which kind it is.
//! A researcher swaps a piece without forking a crate: [`Reconstruction::loss_factory`] builds
//! the objective from what the shape gave, and [`Reconstruction::blocks`] is the remeshing
//! schedule (any [`Block`]).

pub mod config;
mod finish;
mod init;
mod optimize;
mod prepare;
pub mod scans;
pub mod sdf;
pub mod soup;

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::DVec3;
use roar_loss::{
    CoarseViews, KnnOptions, Loss, LossError, PlanarLoss, PlanarOptions, PointCloud, RenderLoss,
    Sdf, SdfLoss, SdfLossOptions, Shape, ShapeError, TargetOptions, WeightedSum,
};
use roar_mesh::spatial::Projector;
use roar_ops::blocks::block::Block;
use roar_ops::blocks::collapse::{FaceCollapse, FaceCollapseOptions};
use roar_ops::blocks::flips::FlipOptions;
use roar_ops::blocks::smoothing::{SmoothingOptions, TangentialSmoothing};
use roar_ops::blocks::split::{FaceSplit, FaceSplitOptions, SplitThreshold};
use roar_ops::decimate::DecimateError;
use roar_ops::finish::genus::{ReduceGenusError, RemovedHandle};
use roar_ops::init::InitError;
use roar_render::{Camera, Image, star_cameras};
use serde::Serialize;

pub use config::{
    FinishConfig, InitConfig, InitKind, LossConfig, OptimizeConfig, ReconstructConfig, TargetConfig,
};
pub use scans::{AlignedScans, SCAN_ENCLOSURE_WINDING_THRESHOLD, ScanReport, load_scans};
pub use sdf::SdfShape;
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

/// Summary of one run, for the JSON report, grouped by stage as the config is.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RunStats {
    /// Seconds per stage, in first-run order of stage names (sorted by name in JSON).
    pub seconds: BTreeMap<String, f64>,
    /// What the target preparation made (the `[target]` stage).
    pub target: TargetStats,
    /// The initial mesh M0 (the `[init]` stage).
    pub init: InitStats,
    /// The loop at the working budget (the `[optimize]` stage).
    pub optimize: OptimizeStats,
    /// From the loop's mesh to exactly N faces (the `[finish]` stage).
    pub finish: FinishStats,
}

/// What the target preparation made (the `[target]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct TargetStats {
    /// Faces of the cleaned target T′.
    pub target_faces: usize,
    /// Twins dropped by the pixel-count rule.
    pub twins_dropped: usize,
    /// Point cloud size (with sharp-edge samples).
    pub point_cloud: usize,
}

/// The initial mesh M0 (the `[init]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct InitStats {
    /// Faces of the voxel surface before any decimation.
    pub init_voxel_faces: usize,
    /// Faces of M0 after QEM to ≤ init_max_faces.
    pub init_faces: usize,
    /// Components (pieces) of M0.
    pub init_components: usize,
    /// Genus of M0 (kept to the end unless `handles_removed` says otherwise).
    pub init_genus: usize,
    /// Voxels the init's enclosure rule turned solid (punctures closed;
    /// `roar_ops::init::InitOptions::enclosure_winding_threshold`; for scan sets also the
    /// voxels hidden from every scanner, `roar_ops::init::InitOptions::scanner_views`).
    pub init_voxels_filled_by_winding: usize,
    /// Regions the winding-number rule left open, their cap too wide for a puncture
    /// (`roar_ops::init::InitOptions::enclosure_max_cap_fraction`).
    pub init_enclosures_left_open: usize,
}

/// The loop at the working budget (the `[optimize]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct OptimizeStats {
    /// The working budget W.
    pub working_budget: usize,
    /// Loss at the first and last iteration.
    pub loss_first: f64,
    /// See `loss_first`.
    pub loss_last: f64,
    /// Loss, its terms and the face count at every iteration.
    pub history: Vec<IterationRecord>,
    /// Iterations the loop ran: `iterations`, or fewer when the loss levelled off
    /// (`level_window`).
    pub loop_iterations: usize,
    /// Faces after the optimization loop.
    pub loop_faces: usize,
    /// Accepted operations per block over the loop, by block name.
    pub block_accepted: BTreeMap<&'static str, usize>,
    /// Vertex steps the step limiter shortened or cancelled over the loop.
    pub steps_shortened: usize,
    /// Loss of the loop's last state (evaluated once more after the last iteration; NaN, null
    /// in the report, when no checkpoint was kept to compare it with).
    pub loss_of_last_state: f64,
    /// The iteration whose starting state the run finished from (`loop_iterations` for the
    /// state after the last one): the lowest-loss state of the checkpoints and the last one
    /// that the untangle block could clear (`checkpoint_interval`).
    pub finished_from_iteration: usize,
    /// States with a lower loss that the untangle block could not clear, in the order tried.
    pub untangle_failures: Vec<UntangleFailure>,
}

/// From the loop's mesh to exactly N faces (the `[finish]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct FinishStats {
    /// Untangle statistics.
    pub untangle_initial_pairs: usize,
    /// Rounds the untangle block needed.
    pub untangle_rounds: usize,
    /// Collapses of the finish's QEMs (to 2N first when the mesh has more faces, see
    /// `finish_budgets`, then to N).
    pub final_collapses: usize,
    /// Edge splits used to fill up to N.
    pub fill_splits: usize,
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
    /// Vertices far off the field's zero set collapsed before its fit (`fin_distance_over_edge`;
    /// SDF inputs only; 0 also when the step was dropped because the mesh would have
    /// intersected itself).
    pub fin_collapses: usize,
    /// Vertices the fit to the field's zero set moved the whole way (`zero_set_steps`; SDF
    /// inputs only; 0 also when the moved mesh was dropped because it would have intersected
    /// itself).
    pub zero_set_fitted: usize,
    /// Vertices that step held back, wholly or in part (a long move, a face turned over, an
    /// intersection).
    pub zero_set_held: usize,
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
    /// The remeshing schedule (default [`default_blocks`]: Face Collapse + flips every
    /// `collapse_interval` iterations (1), Face Split every `split_interval` (10), tangential
    /// smoothing every `smoothing_interval` (0 = off; spec §1.2 has 5, `docs/method.md` says why
    /// not)).
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
    /// calls), reporting progress; the output is in the input's coordinates. The stages, each
    /// in its own module of `pipeline/`: `prepare` (the shape's set-up and renders), `init` (M0,
    /// the point cloud, the working budget), `optimize` (the loop), `finish` (untangle, the
    /// final QEMs and the clean-up steps).
    pub fn run(
        &mut self,
        shape: &mut dyn Shape,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<Output, PipelineError> {
        let config = self.config.clone();
        config.validate().map_err(PipelineError::Config)?;
        let mut run = Run {
            config: &config,
            stats: RunStats::default(),
            clock: StageClock::start(),
            progress,
            cancel: self.cancel.clone(),
        };
        let target = prepare::prepare(shape, &mut run)?;
        let (mesh, cloud) = init::init(shape, &mut run)?;
        let objective = optimize::objective(shape, &target, &cloud, &self.loss_factory, &mut run)?;
        let block_projector: &dyn Projector = shape.projector().unwrap_or(&objective.projector);
        let mut loss = objective.loss;
        let states = optimize::optimize(
            mesh,
            loss.as_mut(),
            block_projector,
            &mut self.blocks,
            &mut run,
        )?;
        let mesh = finish::finish(
            states,
            loss,
            &objective.projector,
            shape.signed_distance().as_deref(),
            &target.normalization,
            &mut run,
        )?;

        let (mut positions, triangles) = mesh.to_triangles();
        target.normalization.invert_all(&mut positions);
        let mut stats = run.stats;
        stats.seconds = run.clock.seconds;
        Ok(Output {
            positions,
            triangles,
            stats,
        })
    }
}

/// The camera rig of `config` (spec §3.2.1: the star rig, `views_per_axis²` views of
/// `render_resolution²` pixels), for which every shape renders its target.
pub fn rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {
    star_cameras(
        config.target.views_per_axis,
        config.target.views_per_axis,
        config.target.render_resolution,
        config.target.render_resolution,
    )
}

/// The coarse rig of `config`: the rig's views at `render_coarse_resolution²` pixels, for the
/// loop's first `render_coarse_fraction` of iterations (and the polish, see [`coarse_until`]);
/// empty when that fraction rounds to no iteration or the resolution is not below
/// `render_resolution`.
pub fn coarse_rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {
    let resolution = config.loss.render_coarse_resolution;
    if coarse_until(config) == 0 || resolution >= config.target.render_resolution {
        return Vec::new();
    }
    let views = config.target.views_per_axis;
    star_cameras(views, views, resolution, resolution)
}

/// The first iteration rendered with the full rig; the finish's polish counts as iteration
/// `iterations`, so it renders coarse too when the whole loop does and `render_coarse_polish`.
fn coarse_until(config: &ReconstructConfig) -> usize {
    let iterations = config.optimize.iterations;
    let coarse = (config.loss.render_coarse_fraction * iterations as f64).round() as usize;
    if iterations > 0 && coarse >= iterations && config.loss.render_coarse_polish {
        usize::MAX
    } else {
        coarse
    }
}

/// The target renders' options of `config` (spec §3.1, §3.2.1), as the pipeline uses them.
pub fn target_options(config: &ReconstructConfig) -> TargetOptions {
    TargetOptions {
        views_per_axis: config.target.views_per_axis,
        resolution: config.target.render_resolution,
        twin_ratio: config.target.twin_ratio,
    }
}

/// The planar loss options of `config` (spec §3.2.2), as [`default_loss`] uses them.
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

/// The default objective: `λ1·L_render + λ2·L_planar` (spec §3.2.3), plus
/// `sdf_loss_weight·L_sdf` (spec §5) when the shape has a signed distance.
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

/// The paper's schedule (spec §1.2, §1.3).
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

/// A loop state the untangle block could not clear.
#[derive(Debug, Clone, Default, Serialize)]
pub struct UntangleFailure {
    /// The iteration whose starting state it was (`iterations` for the last state).
    pub iteration: usize,
    /// Faces still intersecting.
    pub unresolved_faces: usize,
}

/// What every stage shares: the effective config, the statistics it fills in, the stage clock
/// and the progress reports (which also check for cancellation).
struct Run<'a> {
    config: &'a ReconstructConfig,
    stats: RunStats,
    clock: StageClock,
    progress: &'a mut dyn FnMut(&Progress),
    cancel: Option<Arc<AtomicBool>>,
}

impl Run<'_> {
    /// Reports progress; fails with [`PipelineError::Cancelled`] once
    /// [`Reconstruction::cancel`] is set.
    fn report(
        &mut self,
        stage: &'static str,
        iteration: usize,
        loss: f64,
        faces: usize,
    ) -> Result<(), PipelineError> {
        (self.progress)(&Progress {
            stage,
            iteration,
            iterations: self.config.optimize.iterations,
            loss,
            faces,
        });
        match &self.cancel {
            Some(flag) if flag.load(Ordering::Relaxed) => Err(PipelineError::Cancelled),
            _ => Ok(()),
        }
    }
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

    #[test]
    fn the_coarse_rig_is_the_rig_at_the_coarse_resolution_for_the_loop_and_the_polish() {
        let mut config = ReconstructConfig::default();
        let (fine, coarse) = (rig_cameras(&config), coarse_rig_cameras(&config));
        assert_eq!(coarse.len(), fine.len());
        for (c, f) in coarse.iter().zip(&fine) {
            assert_eq!((c.width, c.height), (256, 256));
            assert_eq!((c.view, c.proj), (f.view, f.proj));
        }
        assert_eq!(coarse_until(&config), usize::MAX, "the loop and the polish");
        config.loss.render_coarse_polish = false;
        assert_eq!(coarse_until(&config), 200, "the whole loop only");
        config.loss.render_coarse_polish = true;
        config.loss.render_coarse_fraction = 0.5;
        assert_eq!(coarse_until(&config), 100);
        // None when it would not be coarser, or would render no iteration.
        config.target.render_resolution = 256;
        assert!(coarse_rig_cameras(&config).is_empty());
        config.target.render_resolution = 512;
        config.loss.render_coarse_fraction = 0.0;
        assert!(coarse_rig_cameras(&config).is_empty());
    }
}
