//! Why a reconstruction failed.

use roar_loss::LossError;
use roar_ops::decimate::DecimateError;
use roar_ops::finish::exact_budget::ExactBudgetError;
use roar_ops::finish::genus::ReduceGenusError;
use roar_ops::init::InitError;
use roar_ops::optim::OptimError;

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
    /// The optimizer refused a step or its options mid-run (a bug: the pipeline keeps its rows
    /// and inputs in step with the mesh).
    #[error("internal: {0}")]
    Optimizer(#[from] OptimError),
    /// The final QEM returned without error but off the budget (a bug).
    #[error("internal: the output has {faces} faces instead of {budget}")]
    MissedBudget {
        /// Faces of the output.
        faces: usize,
        /// The budget asked for.
        budget: usize,
    },
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
            ExactBudgetError::Missed { faces, budget } => {
                PipelineError::MissedBudget { faces, budget }
            }
        }
    }
}
