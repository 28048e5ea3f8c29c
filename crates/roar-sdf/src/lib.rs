//! # roar-sdf
//!
//! Signed distance functions as inputs of roar (supplementary §3; `docs/sdf.md`): readers for the
//! kinds of field (an analytic `.sdf.toml` [`AnalyticSdf`], a neural MLP [`Mlp`] from a sequential
//! `.npz` or an IDR/VolSDF/NeuS `.safetensors` state dict ([`implicit_network`]), a dense `.npy`
//! grid [`GridSdf`]), all behind `roar_mesh::spatial::Sdf`, and what the pipeline needs from a
//! field: its normal maps by grid-bracketed tracing ([`trace`]), the Face Split projector and the
//! projection of samples onto the zero set ([`project`]), one adaptive sampling of the field
//! that every stage reads ([`sampled`]), the field in rig coordinates
//! ([`RigSdf`]), and the marching baseline that samples a field on a grid and extracts its zero set
//! ([`extract`]).

pub mod analytic;
mod error;
pub mod extract;
pub mod grid;
pub mod implicit_network;
pub mod network;
pub mod project;
pub mod sampled;
pub mod trace;

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use roar_mesh::spatial::{Aabb, Normalization, Sdf, SdfEvaluations};

pub use analytic::AnalyticSdf;
pub use error::SdfError;
pub use extract::{ExtractOptions, ExtractStats, extract_zero_set};
pub use grid::GridSdf;
pub use network::{Activation, Mlp};
pub use project::{SdfProjector, SdfProjectorOptions, project_samples};
pub use sampled::{SampleOptions, SampleStats, SampledSdf};
pub use trace::{TraceOptions, TraceStats, trace_normal_maps};

/// The bounds an SDF input is reconstructed in, and a grid without a sidecar is placed over,
/// when none are given: `[-1.1, 1.1]³`.
pub const DEFAULT_BOUNDS: Aabb = Aabb {
    min: DVec3::splat(-1.1),
    max: DVec3::splat(1.1),
};

/// An SDF input as read: its field and, when the file places it (a grid's sidecar), its bounds.
pub struct SdfInput {
    /// The field in the input's coordinates.
    pub field: Arc<dyn Sdf>,
    /// The bounds the file gives, if any.
    pub bounds: Option<Aabb>,
}

/// True when `path` names an SDF input by its extension: `.npz`, `.safetensors`, `.sdf.toml` or
/// `.npy`.
pub fn is_sdf_path(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    [".npz", ".safetensors", ".sdf.toml", ".npy"]
        .iter()
        .any(|extension| name.ends_with(extension))
}

/// Reads the SDF at `path`, of the kind its extension names ([`is_sdf_path`]); a grid without
/// a sidecar is placed over [`DEFAULT_BOUNDS`].
pub fn load_sdf(path: &Path) -> Result<Arc<dyn Sdf>, SdfError> {
    Ok(load_sdf_input(path, DEFAULT_BOUNDS)?.field)
}

/// Reads the SDF at `path` ([`load_sdf`]) with the bounds its file gives (a grid's or a
/// network's sidecar); a grid without a sidecar is placed over `grid_bounds`.
pub fn load_sdf_input(path: &Path, grid_bounds: Aabb) -> Result<SdfInput, SdfError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if name.ends_with(".npz") {
        Ok(SdfInput {
            field: Arc::new(Mlp::from_npz_file(path)?),
            bounds: None,
        })
    } else if name.ends_with(".safetensors") {
        let (network, bounds) = implicit_network::read_implicit_network(path)?;
        Ok(SdfInput {
            field: Arc::new(network),
            bounds,
        })
    } else if name.ends_with(".sdf.toml") {
        Ok(SdfInput {
            field: Arc::new(AnalyticSdf::from_file(path)?),
            bounds: None,
        })
    } else if name.ends_with(".npy") {
        let bounds = grid::read_sidecar(path)?;
        let grid = GridSdf::from_npy_file(path, bounds.unwrap_or(grid_bounds))?;
        Ok(SdfInput {
            field: Arc::new(grid),
            bounds,
        })
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

    fn has_gradient(&self) -> bool {
        self.inner.has_gradient()
    }
}
