//! # roar
//!
//! Robust adaptive reconstruction: from a messy shape (a triangle soup, a signed distance
//! function, a set of range scans) to a **closed, oriented 2-manifold triangle mesh with exactly
//! the face count asked for and no self-intersections**.
//!
//! ```text
//! Shape ──prepare──▶ normalization, target renders        (stages::prepare)
//!       ──init─────▶ M0 (watertight init), point cloud P,
//!                    M0 decimated to the working budget W  (stages::init)
//!       ──optimize─▶ loop: loss (λ1·render + λ2·planar) → optimizer step → scheduled blocks
//!                    (Face Collapse + flips, Face Split), checkpoints kept  (stages::optimize)
//!       ──finish───▶ best state filled to N and untangled → [QEM to 2N → polish]
//!                    → QEM to exactly N → smoothing → data flips → polish
//!                    → sliver flips → denormalize          (stages::finish)
//! ```
//!
//! The input is any [`Shape`]: a soup or a set of range scans is a [`SoupShape`], a signed
//! distance function an [`SdfShape`]. The pipeline asks it for its normalization, target renders,
//! point cloud and initial mesh, and never which kind it is. A researcher swaps a piece without
//! forking a crate: [`Reconstruction::loss_factory`] builds the objective from what the shape
//! gave, and [`Reconstruction::blocks`] is the remeshing schedule (any
//! [`roar_ops::blocks::block::Block`]).
//!
//! ```
//! use roar::{ReconstructConfig, Reconstruction};
//!
//! let soup = roar::example::chair_soup();
//! // `ReconstructConfig::default()` is the full schedule; this is a quick, coarse one.
//! let mut config = ReconstructConfig { faces: 600, ..ReconstructConfig::default() };
//! config.target.views_per_axis = 2;
//! config.target.render_resolution = 64;
//! config.target.point_cloud_samples = 5000;
//! config.init.init_resolution = 32;
//! config.loss.render_coarse_resolution = 32;
//! config.optimize.iterations = 4;
//! config.optimize.working_budget_min = 600;
//! let output = Reconstruction::new(config)
//!     .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
//!     .expect("the example soup reconstructs");
//! assert_eq!(output.triangles.len(), 600);
//! ```
//!
//! Imports point down (`scripts/module-cycles.py` checks it):
//! - bottom: [`error`], [`shape`] (the seam), [`budget`], [`config`], [`report`], [`run`] (the
//!   state a run shares), [`rig`], [`objective`] (the loss factory), [`schedule`] (the blocks),
//!   [`input`] and [`example`];
//! - above them: [`shapes`] (soups, signed distances, scan sets) and the stages
//!   (`prepare`, `init`, `optimize`, `finish`);
//! - on top: [`reconstruction`], the stages in order.

pub mod budget;
pub mod config;
pub mod error;
pub mod example;
pub mod input;
pub mod objective;
pub mod reconstruction;
pub mod report;
pub mod rig;
pub mod run;
pub mod schedule;
pub mod shape;
pub mod shapes;
mod stages;

pub use config::{
    ConfigError, FinishConfig, InitConfig, InitKind, LossConfig, OptimizeConfig, ReconstructConfig,
    TargetConfig,
};
pub use error::PipelineError;
pub use objective::{LossFactory, Prepared, default_loss, planar_options};
pub use reconstruction::{Output, Reconstruction};
pub use report::{
    FinishReport, InitReport, IterationRecord, OptimizeReport, RunStats, TargetReport,
};
pub use rig::{coarse_rig_cameras, rig_cameras, target_options};
pub use run::Progress;
pub use schedule::{ScheduledBlock, default_blocks};
pub use shape::{EnclosureFigures, InitialMesh, PieceMerge, Shape, ShapeError, ShapeSummary};
pub use shapes::scans::{AlignedScans, ScanReport, load_scans};
pub use shapes::sdf::SdfShape;
pub use shapes::soup::SoupShape;
