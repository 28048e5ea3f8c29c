//! The optimizer's hyper-parameters ([`OptimizerOptions`]) and their validation.

use super::error::OptimError;

/// Hyper-parameters of the optimizer. `Default` carries the paper's learning rate
/// (supplementary §1) and the authors' code's other values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimizerOptions {
    /// Learning rate η (0.05, supplementary §1). The typical move per step is about η·ℓ_v.
    pub lr: f64,
    /// (β1, β2, β3) (0.8, 0.8, 0): EMA factors of the first moment m1, of the
    /// second moment m2 and of the speed ν. Each must lie in [0, 1); β3 = 0 means ν = ‖u‖.
    pub betas: (f64, f64, f64),
    /// Weight w_lap of the uniform Laplacian added to the gradient, scaled by ν
    /// (0.02).
    pub laplacian_weight: f64,
    /// Learning-rate warm-up: η_t = η·min(1, t(1−β1)/ramp) (1: full rate after 5
    /// steps). Must be > 0.
    pub ramp: f64,
    /// From the second step on, each gradient component is clamped to ±grad_lim·|m1|
    /// (10). Must be > 0; `f64::INFINITY` disables clamping.
    pub grad_lim: f64,
    /// Cap of the reference length ℓ_v = min(shortest incident edge, edge_len_max)
    /// (0.15). Must be > 0; `f64::INFINITY` removes the cap.
    pub edge_len_max: f64,
    /// Clamp a gradient component only where its |m1| > 0
    /// (`docs/method.md#decision-gradient-clamp`). With `false` the authors' behaviour is kept,
    /// which freezes forever a component whose first gradient was exactly 0 (its bound is ±10·0).
    /// Default `true`.
    pub clamp_only_nonzero_m1: bool,
    /// Use rayon for the per-vertex passes from this many vertices on (not a spec parameter;
    /// default 50 000). Results are bit-identical either way.
    pub parallel_min_vertices: usize,
}

impl Default for OptimizerOptions {
    fn default() -> Self {
        Self {
            lr: 0.05,
            betas: (0.8, 0.8, 0.0),
            laplacian_weight: 0.02,
            ramp: 1.0,
            grad_lim: 10.0,
            edge_len_max: 0.15,
            clamp_only_nonzero_m1: true,
            parallel_min_vertices: 50_000,
        }
    }
}

impl OptimizerOptions {
    /// Checks that every value is usable: finite non-negative `lr` and `laplacian_weight`,
    /// betas in [0, 1), `ramp` finite and > 0, `grad_lim` and `edge_len_max` > 0 (infinity
    /// allowed, NaN not).
    pub fn validate(&self) -> Result<(), OptimError> {
        let bad = |name: &'static str, value: f64, expected: &'static str| {
            Err(OptimError::InvalidOption {
                name,
                value,
                expected,
            })
        };
        if !(self.lr.is_finite() && self.lr >= 0.0) {
            return bad("lr", self.lr, "a finite value >= 0");
        }
        for (name, beta) in [
            ("betas.0", self.betas.0),
            ("betas.1", self.betas.1),
            ("betas.2", self.betas.2),
        ] {
            if !(0.0..1.0).contains(&beta) {
                return bad(name, beta, "a value in [0, 1)");
            }
        }
        if !(self.laplacian_weight.is_finite() && self.laplacian_weight >= 0.0) {
            return bad(
                "laplacian_weight",
                self.laplacian_weight,
                "a finite value >= 0",
            );
        }
        if !(self.ramp.is_finite() && self.ramp > 0.0) {
            return bad("ramp", self.ramp, "a finite value > 0");
        }
        if self.grad_lim.is_nan() || self.grad_lim <= 0.0 {
            return bad("grad_lim", self.grad_lim, "a value > 0 (infinity allowed)");
        }
        if self.edge_len_max.is_nan() || self.edge_len_max <= 0.0 {
            return bad(
                "edge_len_max",
                self.edge_len_max,
                "a value > 0 (infinity allowed)",
            );
        }
        Ok(())
    }
}
