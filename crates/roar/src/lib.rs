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
//! ```no_run
//! use roar::{ReconstructConfig, Reconstruction};
//!
//! let soup = roar::example::chair_soup();
//! let config = ReconstructConfig { faces: 1000, ..ReconstructConfig::default() };
//! let output = Reconstruction::new(config)
//!     .run_soup(&soup.positions, &soup.triangles, &mut |_| {})
//!     .expect("the example soup reconstructs");
//! assert_eq!(output.triangles.len(), 1000);
//! ```
//!
//! Modules depend only on the ones listed before them: errors, configuration, the report and
//! the run state at the bottom; the input kinds and the stages above them; [`Reconstruction`]
//! on top.

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
    FinishConfig, InitConfig, InitKind, LossConfig, OptimizeConfig, ReconstructConfig, TargetConfig,
};
pub use error::PipelineError;
pub use objective::{LossFactory, Prepared, default_loss, planar_options};
pub use reconstruction::{Output, Reconstruction};
pub use report::{
    FinishStats, InitStats, IterationRecord, OptimizeStats, RunStats, TargetStats, UntangleFailure,
};
pub use rig::{coarse_rig_cameras, rig_cameras, target_options};
pub use run::Progress;
pub use schedule::{ScheduledBlock, default_blocks};
pub use shape::{InitialMesh, PieceMerge, Shape, ShapeError, ShapeSummary};
pub use shapes::scans::{AlignedScans, ScanReport, load_scans};
pub use shapes::sdf::SdfShape;
pub use shapes::soup::SoupShape;
