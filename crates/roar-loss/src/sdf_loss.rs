//! The SDF projection loss (supplementary §3; `docs/method.md#sdf-loss`): each vertex pulled toward
//! its first-order projection onto the zero set of the target's signed distance.
//!
//! Over the mesh's vertices v: `p = v − f(v) ∇f(v)/(|∇f(v)|² + ε)`, held constant (no gradient
//! through p), and `L = mean_v ‖v − p‖` (unsquared), whose gradient per vertex is the unit
//! vector `(v − p)/‖v − p‖` divided by the vertex count. `‖v − p‖` is the first-order distance
//! `|f|/|∇f|`, so the loss treats a true distance and a field of any other scale alike. The
//! authors' code divides by `|∇f| + 1e-5`, the same for a true distance.

use std::sync::Arc;

use glam::DVec3;
use roar_mesh::spatial::{Sdf, evaluate_with_gradients, first_order_step};

use crate::error::LossError;
use crate::loss::Loss;

/// Options of [`SdfLoss`].
#[derive(Clone, Debug, PartialEq)]
pub struct SdfLossOptions {
    /// The loss is zero (and the field not evaluated) before this iteration of the loop
    /// (supplementary §3: on from iteration 500).
    pub start_iteration: usize,
    /// `ε` of the projection's denominator `|∇f|² + ε`.
    pub epsilon: f64,
}

impl Default for SdfLossOptions {
    fn default() -> Self {
        Self {
            start_iteration: 500,
            epsilon: 1e-10,
        }
    }
}

/// `L_sdf` ([module docs](self)), on a field in rig coordinates.
pub struct SdfLoss {
    sdf: Arc<dyn Sdf>,
    options: SdfLossOptions,
    iteration: usize,
}

impl SdfLoss {
    /// The loss of `sdf`, off until [`SdfLossOptions::start_iteration`].
    pub fn new(sdf: Arc<dyn Sdf>, options: SdfLossOptions) -> Self {
        Self {
            sdf,
            options,
            iteration: 0,
        }
    }
}

impl Loss for SdfLoss {
    fn name(&self) -> &'static str {
        "sdf"
    }

    fn set_iteration(&mut self, iteration: usize) {
        self.iteration = iteration;
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        _triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        let mut gradient = vec![DVec3::ZERO; positions.len()];
        if self.iteration < self.options.start_iteration || positions.is_empty() {
            return Ok((0.0, gradient));
        }
        let (values, gradients) = evaluate_with_gradients(self.sdf.as_ref(), positions);
        let inv_n = 1.0 / positions.len() as f64;
        let mut total = 0.0;
        for ((g_out, &f), &g) in gradient.iter_mut().zip(&values).zip(&gradients) {
            // v − p = −step.
            let offset = -first_order_step(f, g, self.options.epsilon);
            let distance = offset.length();
            if !distance.is_finite() {
                return Err(LossError::InvalidTarget(format!(
                    "the signed distance is not finite at a vertex (f = {f}, ∇f = {g})"
                )));
            }
            total += distance;
            if distance > 0.0 {
                *g_out = offset / distance * inv_n;
            }
        }
        Ok((total * inv_n, gradient))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::spatial::FnSdf;

    /// On a sphere field scaled by 4000 the first-order distance is the exact distance, so the
    /// loss is `mean_v ||v| − r|` and its gradient is that function's: checked by central
    /// differences of the loss itself.
    #[test]
    fn sdf_loss_gradient_matches_finite_differences_on_a_scaled_field() {
        let sdf = Arc::new(FnSdf::new(|p: DVec3| 4000.0 * (p.length() - 0.5)));
        let mut loss = SdfLoss::new(sdf.clone(), SdfLossOptions::default());
        let positions = vec![
            DVec3::new(0.7, 0.1, -0.2),
            DVec3::new(-0.1, 0.3, 0.2),
            DVec3::new(0.2, -0.5, 0.4),
        ];
        // Off before the start iteration: zero, and the field is not evaluated.
        let (value, gradient) = loss.value_and_grad(&positions, &[]).unwrap();
        assert_eq!((value, sdf.evaluations().gradients), (0.0, 0));
        assert!(gradient.iter().all(|g| *g == DVec3::ZERO));

        loss.set_iteration(500);
        let (value, gradient) = loss.value_and_grad(&positions, &[]).unwrap();
        let exact: f64 = positions
            .iter()
            .map(|p| (p.length() - 0.5).abs())
            .sum::<f64>()
            / 3.0;
        assert!((value - exact).abs() < 1e-6, "{value} vs {exact}");
        let h = 1e-6;
        for i in 0..positions.len() {
            for axis in 0..3 {
                let mut plus = positions.clone();
                let mut minus = positions.clone();
                plus[i][axis] += h;
                minus[i][axis] -= h;
                let fd = (loss.value_and_grad(&plus, &[]).unwrap().0
                    - loss.value_and_grad(&minus, &[]).unwrap().0)
                    / (2.0 * h);
                assert!(
                    (fd - gradient[i][axis]).abs() < 1e-5,
                    "{fd} vs {}",
                    gradient[i][axis]
                );
            }
        }
    }
}
