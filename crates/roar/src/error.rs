//! Why a reconstruction failed.

use roar_loss::LossError;
use roar_ops::decimate::DecimateError;
use roar_ops::finish::exact_budget::ExactBudgetError;
use roar_ops::finish::genus::ReduceGenusError;
use roar_ops::init::InitError;

use crate::config::ConfigError;
use crate::shape::ShapeError;

/// Why a reconstruction failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The configuration is unusable, or its face budget too small for the init's pieces.
    #[error("config: {0}")]
    Config(#[from] ConfigError),
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

impl From<ExactBudgetError> for PipelineError {
    fn from(error: ExactBudgetError) -> Self {
        match error {
            ExactBudgetError::Decimate(error) => PipelineError::Budget(error),
            ExactBudgetError::Genus(error) => PipelineError::Genus(error),
            ExactBudgetError::Intersections(faces) => PipelineError::Intersections(faces),
            ExactBudgetError::Missed { .. } => PipelineError::Internal(error.to_string()),
        }
    }
}
