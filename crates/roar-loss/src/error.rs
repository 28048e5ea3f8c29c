//! Why a loss could not be evaluated: the error every [`Loss`](crate::Loss) returns.

/// Why a loss could not be evaluated.
#[derive(Debug, thiserror::Error)]
pub enum LossError {
    /// The renderer refused the mesh (e.g. a vertex behind the near plane).
    #[error("render: {0}")]
    Render(#[from] roar_render::RenderError),
    /// The source mesh buffers are unusable (out-of-range index, non-finite position, …).
    #[error("invalid source mesh: {0}")]
    InvalidMesh(String),
    /// The target is unusable (no area, no points, …).
    #[error("invalid target: {0}")]
    InvalidTarget(String),
}
