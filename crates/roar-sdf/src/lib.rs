//! # roar-sdf
//!
//! Signed distance functions as inputs of roar (spec §5): readers for the kinds of field
//! (an analytic `.sdf.toml` [`AnalyticSdf`], a neural MLP `.npz` [`Mlp`]), all behind
//! `roar_mesh::spatial::Sdf`, and what the pipeline needs from a field: its normal maps by
//! grid-bracketed tracing ([`trace`]), the Face Split projector and the projection of samples
//! onto the zero set ([`project`]), and the field in rig coordinates ([`RigSdf`]).

pub mod analytic;
pub mod network;
pub mod project;
pub mod trace;

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use roar_mesh::spatial::{Normalization, Sdf, SdfEvaluations};

pub use analytic::AnalyticSdf;
pub use network::{Activation, Mlp};
pub use project::{SdfProjector, SdfProjectorOptions, project_samples};
pub use trace::{TraceOptions, TraceStats, trace_normal_maps};

/// Why an SDF file could not be read. Every message is one line.
#[derive(Debug, thiserror::Error)]
pub enum SdfError {
    /// The file could not be read.
    #[error("{0}")]
    Io(String),
    /// A malformed network file (names the tensor).
    #[error("{0}")]
    Network(String),
    /// A malformed `.sdf.toml` file (names the node).
    #[error("{0}")]
    Analytic(String),
    /// The file's extension names no SDF kind.
    #[error("not an SDF input (.npz or .sdf.toml)")]
    UnknownKind,
}

/// True when `path` names an SDF input by its extension: `.npz` or `.sdf.toml`.
pub fn is_sdf_path(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(".npz") || name.ends_with(".sdf.toml")
}

/// Reads the SDF at `path`, of the kind its extension names ([`is_sdf_path`]).
pub fn load_sdf(path: &Path) -> Result<Arc<dyn Sdf>, SdfError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if name.ends_with(".npz") {
        Ok(Arc::new(Mlp::from_npz_file(path)?))
    } else if name.ends_with(".sdf.toml") {
        Ok(Arc::new(AnalyticSdf::from_file(path)?))
    } else {
        Err(SdfError::UnknownKind)
    }
}

/// A field given in the input's coordinates, seen in rig coordinates: `f_rig(p) = s·f(q)` with
/// `q` the input point of `p` and `s` the normalization's scale, so distances scale with the
/// rig and the gradient is unchanged. Evaluations are counted by the inner field.
pub struct RigSdf {
    /// The field in the input's coordinates.
    pub inner: Arc<dyn Sdf>,
    /// Input → rig coordinates.
    pub normalization: Normalization,
}

impl RigSdf {
    fn to_input(&self, points: &[DVec3]) -> Vec<DVec3> {
        points
            .iter()
            .map(|p| self.normalization.invert(*p))
            .collect()
    }
}

impl Sdf for RigSdf {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.inner.values(&self.to_input(points), values);
        for v in values {
            *v *= self.normalization.scale;
        }
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.inner
            .values_and_gradients(&self.to_input(points), values, gradients);
        for v in values {
            *v *= self.normalization.scale;
        }
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.inner.evaluations()
    }
}
