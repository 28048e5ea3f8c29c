//! [`WeightedSum`]: several losses evaluated together as one weighted [`Loss`].

use glam::DVec3;
use rayon::prelude::*;

use crate::error::LossError;
use crate::loss::Loss;

/// A weighted sum of losses, itself a [`Loss`] (the paper's objective is `3·L_render + 1·L_planar`,
/// supplementary §1).
#[derive(Default)]
pub struct WeightedSum {
    /// The terms and their weights; evaluated concurrently, summed in this order.
    pub terms: Vec<(f64, Box<dyn Loss>)>,
    /// The last evaluation's weighted value of each term (for reports), in term order.
    pub last_values: Vec<f64>,
}

impl WeightedSum {
    /// Adds a term with its weight.
    pub fn with(mut self, weight: f64, loss: Box<dyn Loss>) -> Self {
        self.terms.push((weight, loss));
        self
    }
}

impl Loss for WeightedSum {
    fn name(&self) -> &'static str {
        "weighted_sum"
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        // The terms run concurrently: each is deterministic on its own and their results are
        // added in term order, so the sum does not depend on the schedule, while one term's
        // serial stretches (sorting, tree builds, reductions) overlap the other's parallel work.
        let results: Vec<Result<(f64, Vec<DVec3>), LossError>> = self
            .terms
            .par_iter_mut()
            .map(|(_, loss)| loss.value_and_grad(positions, triangles))
            .collect();
        let mut total = 0.0;
        let mut gradient = vec![DVec3::ZERO; positions.len()];
        self.last_values.clear();
        for ((weight, _), result) in self.terms.iter().zip(results) {
            let (value, grad) = result?;
            total += *weight * value;
            self.last_values.push(*weight * value);
            for (g, d) in gradient.iter_mut().zip(&grad) {
                *g += *weight * *d;
            }
        }
        Ok((total, gradient))
    }

    fn set_iteration(&mut self, iteration: usize) {
        for (_, loss) in &mut self.terms {
            loss.set_iteration(iteration);
        }
    }

    fn last_terms(&self) -> Vec<(&'static str, f64)> {
        self.terms
            .iter()
            .zip(&self.last_values)
            .map(|((_, loss), &value)| (loss.name(), value))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `L = Σ c·|v|²` with gradient `2c·v`.
    struct Quadratic(f64);

    impl Loss for Quadratic {
        fn name(&self) -> &'static str {
            "quadratic"
        }
        fn value_and_grad(
            &mut self,
            positions: &[DVec3],
            _: &[[u32; 3]],
        ) -> Result<(f64, Vec<DVec3>), LossError> {
            let value = positions.iter().map(|p| self.0 * p.length_squared()).sum();
            Ok((value, positions.iter().map(|p| 2.0 * self.0 * *p).collect()))
        }
    }

    /// Always fails, naming itself.
    struct Failing(&'static str);

    impl Loss for Failing {
        fn name(&self) -> &'static str {
            self.0
        }
        fn value_and_grad(
            &mut self,
            _: &[DVec3],
            _: &[[u32; 3]],
        ) -> Result<(f64, Vec<DVec3>), LossError> {
            Err(LossError::InvalidTarget(self.0.to_string()))
        }
    }

    #[test]
    fn weighted_sum_reports_the_first_failing_term_in_term_order() {
        let mut sum = WeightedSum::default()
            .with(1.0, Box::new(Quadratic(1.0)))
            .with(1.0, Box::new(Failing("second")))
            .with(1.0, Box::new(Failing("third")));
        let err = sum.value_and_grad(&[DVec3::ONE], &[]).unwrap_err();
        assert_eq!(err.to_string(), "invalid target: second");
    }

    #[test]
    fn weighted_sum_adds_values_and_gradients_with_weights() {
        let mut sum = WeightedSum::default()
            .with(3.0, Box::new(Quadratic(1.0)))
            .with(0.5, Box::new(Quadratic(2.0)));
        let positions = [DVec3::new(1.0, 2.0, 0.0), DVec3::new(0.0, 0.0, -1.0)];
        let (value, grad) = sum.value_and_grad(&positions, &[]).unwrap();
        // Σ|v|² = 6; 3·6 + 0.5·2·6 = 24.
        assert_eq!(value, 24.0);
        assert_eq!(sum.last_values, vec![18.0, 6.0]);
        assert_eq!(
            sum.last_terms(),
            vec![("quadratic", 18.0), ("quadratic", 6.0)]
        );
        // 3·2v + 0.5·4v = 8v.
        assert_eq!(grad[0], 8.0 * positions[0]);
        assert_eq!(grad[1], 8.0 * positions[1]);
    }
}
