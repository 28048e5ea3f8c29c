//! The [`Sdf`] trait: a signed distance function evaluated in batches, with counters of the
//! points it evaluated, and the first-order distance and projection every SDF consumer shares.
//!
//! Sign convention: negative inside the solid, positive outside, zero on the surface. A field
//! need not be a true distance (a trained network may have |∇f| in the thousands): consumers
//! that need a distance use the first-order distance `f/|∇f|` ([`first_order_step`]).

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

/// How many points an [`Sdf`] evaluated, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SdfEvaluations {
    /// Points whose value alone was asked for ([`Sdf::values`]).
    pub values: u64,
    /// Points whose value and gradient were asked for ([`Sdf::values_and_gradients`]).
    pub gradients: u64,
}

/// The points counted between two readings of the counters: `after − before`.
impl std::ops::Sub for SdfEvaluations {
    type Output = Self;
    fn sub(self, before: Self) -> Self {
        Self {
            values: self.values - before.values,
            gradients: self.gradients - before.gradients,
        }
    }
}

/// A signed distance function `f` and its gradient, evaluated for a batch of points at a time.
///
/// Implementations must be deterministic (the same point gives the same bits whatever the
/// batch), may evaluate a batch in parallel, and count the points of every call
/// ([`SdfCounter`] does it).
pub trait Sdf: Send + Sync {
    /// Writes `f(points[i])` into `values[i]`. The slices have the same length.
    fn values(&self, points: &[DVec3], values: &mut [f64]);

    /// Writes `f(points[i])` into `values[i]` and `∇f(points[i])` into `gradients[i]`. The
    /// slices have the same length.
    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]);

    /// The points evaluated so far.
    fn evaluations(&self) -> SdfEvaluations;

    /// Whether [`Sdf::values_and_gradients`] evaluates the field's own gradient. `false` when it
    /// can only difference values (several evaluations a point): a sampler then asks for values
    /// alone and differences its own samples.
    fn has_gradient(&self) -> bool {
        true
    }
}

/// Thread-safe counters of evaluated points, for [`Sdf`] implementations.
#[derive(Debug, Default)]
pub struct SdfCounter {
    values: AtomicU64,
    gradients: AtomicU64,
}

impl SdfCounter {
    /// Counts `n` points evaluated for values only.
    pub fn add_values(&self, n: usize) {
        self.values.fetch_add(n as u64, Ordering::Relaxed);
    }

    /// Counts `n` points evaluated for values and gradients.
    pub fn add_gradients(&self, n: usize) {
        self.gradients.fetch_add(n as u64, Ordering::Relaxed);
    }

    /// The counts so far.
    pub fn get(&self) -> SdfEvaluations {
        SdfEvaluations {
            values: self.values.load(Ordering::Relaxed),
            gradients: self.gradients.load(Ordering::Relaxed),
        }
    }
}

/// An [`Sdf`] of a closure `f(p)`, its gradient by central differences of step `h`: for tests
/// and small analytic fields.
pub struct FnSdf<F> {
    /// The field.
    pub f: F,
    /// Central-difference step of the gradient.
    pub h: f64,
    counter: SdfCounter,
}

impl<F: Fn(DVec3) -> f64 + Send + Sync> FnSdf<F> {
    /// The field `f` with gradient step `1e-6`.
    pub fn new(f: F) -> Self {
        Self {
            f,
            h: 1e-6,
            counter: SdfCounter::default(),
        }
    }
}

impl<F: Fn(DVec3) -> f64 + Send + Sync> Sdf for FnSdf<F> {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        for (p, v) in points.iter().zip(values) {
            *v = (self.f)(*p);
        }
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.counter.add_gradients(points.len());
        let h = self.h;
        for ((p, v), g) in points.iter().zip(values).zip(gradients) {
            *v = (self.f)(*p);
            let d = |e: DVec3| ((self.f)(*p + h * e) - (self.f)(*p - h * e)) / (2.0 * h);
            *g = DVec3::new(d(DVec3::X), d(DVec3::Y), d(DVec3::Z));
        }
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }
}

/// The first-order step onto the zero set from a point with value `f` and gradient `g`:
/// `−f g/(|g|² + ε)`, whose length is the first-order distance `|f|/|g|` whatever the scale of
/// the field (`ε` keeps it finite where the gradient vanishes).
pub fn first_order_step(f: f64, g: DVec3, epsilon: f64) -> DVec3 {
    -f * g / (g.length_squared() + epsilon)
}

/// The signed first-order distances `f/(|∇f| + ε)` of `sdf` at `points`: the distance to the
/// zero set to first order, whatever the scale of the field.
pub fn first_order_distances(sdf: &dyn Sdf, points: &[DVec3], epsilon: f64) -> Vec<f64> {
    let (values, gradients) = evaluate_with_gradients(sdf, points);
    values
        .iter()
        .zip(&gradients)
        .map(|(f, g)| f / (g.length() + epsilon))
        .collect()
}

/// Values and gradients of `sdf` at `points` in one call, as new vectors.
pub fn evaluate_with_gradients(sdf: &dyn Sdf, points: &[DVec3]) -> (Vec<f64>, Vec<DVec3>) {
    let mut values = vec![0.0; points.len()];
    let mut gradients = vec![DVec3::ZERO; points.len()];
    sdf.values_and_gradients(points, &mut values, &mut gradients);
    (values, gradients)
}

/// Projects every point onto the zero set of `sdf` by `rounds` first-order steps
/// ([`first_order_step`]), in place. Returns the last values and gradients (at the points
/// before their last step), for callers that check convergence.
pub fn project_to_zero_set(
    sdf: &dyn Sdf,
    points: &mut [DVec3],
    rounds: usize,
    epsilon: f64,
) -> (Vec<f64>, Vec<DVec3>) {
    let mut values = vec![0.0; points.len()];
    let mut gradients = vec![DVec3::ZERO; points.len()];
    for _ in 0..rounds {
        sdf.values_and_gradients(points, &mut values, &mut gradients);
        for ((p, &f), &g) in points.iter_mut().zip(&values).zip(&gradients) {
            *p += first_order_step(f, g, epsilon);
        }
    }
    (values, gradients)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f(p) = k (|p| − 1)`: a sphere whose field is scaled by `k`.
    struct ScaledSphere {
        k: f64,
        counter: SdfCounter,
    }

    impl Sdf for ScaledSphere {
        fn values(&self, points: &[DVec3], values: &mut [f64]) {
            self.counter.add_values(points.len());
            for (p, f) in points.iter().zip(values) {
                *f = self.k * (p.length() - 1.0);
            }
        }
        fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], g: &mut [DVec3]) {
            self.counter.add_gradients(points.len());
            for ((p, f), g) in points.iter().zip(values).zip(g) {
                *f = self.k * (p.length() - 1.0);
                *g = self.k * p.normalize();
            }
        }
        fn evaluations(&self) -> SdfEvaluations {
            self.counter.get()
        }
    }

    #[test]
    fn first_order_projection_ignores_the_field_scale_and_counts() {
        for k in [1.0, 4000.0] {
            let sdf = ScaledSphere {
                k,
                counter: SdfCounter::default(),
            };
            let mut points = vec![DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.1, 0.2, -0.3)];
            project_to_zero_set(&sdf, &mut points, 3, 1e-12);
            for p in &points {
                assert!((p.length() - 1.0).abs() < 1e-9, "k {k}: {p}");
            }
            assert_eq!(
                sdf.evaluations(),
                SdfEvaluations {
                    values: 0,
                    gradients: 6
                }
            );
        }
    }

    #[test]
    fn first_order_distances_ignore_the_field_scale() {
        let points = [DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.1, 0.2, -0.3)];
        for k in [1.0, 4000.0] {
            let sdf = ScaledSphere {
                k,
                counter: SdfCounter::default(),
            };
            let d = first_order_distances(&sdf, &points, 1e-12);
            assert!((d[0] - 1.0).abs() < 1e-9, "k {k}: {}", d[0]);
            assert!(
                (d[1] - (points[1].length() - 1.0)).abs() < 1e-9,
                "k {k}: {}",
                d[1]
            );
        }
    }
}
