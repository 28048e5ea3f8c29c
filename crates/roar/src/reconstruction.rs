//! [`Reconstruction`]: the stages in order, with a replaceable objective and schedule.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::DVec3;
use roar_mesh::spatial::Projector;

use crate::config::ReconstructConfig;
use crate::error::PipelineError;
use crate::objective::{LossFactory, default_loss};
use crate::report::RunStats;
use crate::run::{Progress, Run, StageClock};
use crate::schedule::{ScheduledBlock, default_blocks};
use crate::shape::Shape;
use crate::shapes::soup::SoupShape;
use crate::stages::{finish, init, optimize, prepare};

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
    /// Builds the objective (default [`default_loss`]: λ1·render + λ2·planar).
    pub loss_factory: LossFactory,
    /// The remeshing schedule (default [`default_blocks`]: Face Collapse + flips every
    /// `collapse_interval` iterations (1), Face Split every `split_interval` (10), tangential
    /// smoothing every `smoothing_interval` (0 = off; why:
    /// `docs/method.md#decision-smoothing-after-the-final-qem-not-in-the-loop`)).
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
    /// in its own module of `stages/`: `prepare` (the shape's set-up and renders), `init` (M0,
    /// the point cloud, the working budget), `optimize` (the loop), `finish` (untangle, the
    /// final QEMs and the clean-up steps).
    pub fn run(
        &mut self,
        shape: &mut dyn Shape,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<Output, PipelineError> {
        let config = self.config.clone();
        config.validate()?;
        let mut run = Run {
            config: &config,
            stats: RunStats::default(),
            clock: StageClock::start(),
            progress,
            cancel: self.cancel.clone(),
        };
        let rig = prepare::prepare(shape, &mut run)?;
        let (mesh, cloud) = init::init(shape, &mut run)?;
        let objective = optimize::objective(shape, &rig, &cloud, &self.loss_factory, &mut run)?;
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
            shape.target_surface(),
            &rig.normalization,
            &mut run,
        )?;

        let (mut positions, triangles) = mesh.to_triangles();
        rig.normalization.invert_all(&mut positions);
        let mut stats = run.stats;
        stats.seconds = run.clock.seconds;
        Ok(Output {
            positions,
            triangles,
            stats,
        })
    }
}
