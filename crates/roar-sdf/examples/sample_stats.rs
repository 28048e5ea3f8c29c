//! Samples a field file (`roar_sdf::SampledSdf`) and prints, as one JSON line, the sampling's
//! figures and its interpolation error near the zero set, in finest cells:
//! `cargo run --release -p roar-sdf --example sample_stats -- FIELD [RESOLUTION] [BAND]
//! [values]`; with `values` the sampler is given values alone and differences its samples (as
//! for a Python field without a gradient).

use glam::DVec3;
use roar_mesh::spatial::{Sdf, SdfEvaluations, evaluate_with_gradients, project_to_zero_set};
use roar_sdf::{DEFAULT_BOUNDS, SampleOptions, SampledSdf, load_sdf_input};

/// A field seen through its values alone.
struct ValuesOnly<'a>(&'a dyn Sdf);

impl Sdf for ValuesOnly<'_> {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.0.values(points, values);
    }
    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.0.values_and_gradients(points, values, gradients);
    }
    fn evaluations(&self) -> SdfEvaluations {
        self.0.evaluations()
    }
    fn has_gradient(&self) -> bool {
        false
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: sample_stats FIELD [RESOLUTION] [BAND]")?;
    let resolution: usize = args.get(2).map_or(Ok(256), |a| a.parse())?;
    let band: f64 = args.get(3).map_or(Ok(1.0), |a| a.parse())?;
    let input = load_sdf_input(std::path::Path::new(path), DEFAULT_BOUNDS)?;
    let bounds = input.bounds.unwrap_or(DEFAULT_BOUNDS);
    let options = SampleOptions::for_resolution(resolution, band);
    let values_only = args.get(4).is_some_and(|a| a == "values");
    let (sampled, stats) = if values_only {
        SampledSdf::build(&ValuesOnly(input.field.as_ref()), bounds, &options)?
    } else {
        SampledSdf::build(input.field.as_ref(), bounds, &options)?
    };
    // Points near the zero set: a regular lattice pulled onto it, then moved off it by up to a
    // finest cell along the normal.
    let fine = bounds.extent().max_element() / resolution as f64;
    let n = 40;
    let mut points: Vec<DVec3> = (0..n * n * n)
        .map(|i| {
            let t = DVec3::new((i % n) as f64, ((i / n) % n) as f64, (i / (n * n)) as f64);
            bounds.min + (t + 0.5) / n as f64 * bounds.extent()
        })
        .collect();
    project_to_zero_set(input.field.as_ref(), &mut points, 6, 1e-20);
    let (_, g) = evaluate_with_gradients(input.field.as_ref(), &points);
    let points: Vec<DVec3> = points
        .iter()
        .zip(&g)
        .enumerate()
        .map(|(i, (p, g))| *p + g.normalize_or_zero() * fine * ((i % 7) as f64 / 3.0 - 1.0))
        .filter(|p| p.is_finite())
        .collect();
    let (f, g) = evaluate_with_gradients(input.field.as_ref(), &points);
    let mut fs = vec![0.0; points.len()];
    let mut gs = vec![DVec3::ZERO; points.len()];
    sampled.values_and_gradients(&points, &mut fs, &mut gs);
    let mut errors: Vec<f64> = (0..points.len())
        .map(|i| (fs[i] - f[i]).abs() / g[i].length() / fine)
        .collect();
    let mut angles: Vec<f64> = (0..points.len())
        .map(|i| 1.0 - gs[i].normalize_or_zero().dot(g[i].normalize_or_zero()))
        .collect();
    // Query speed: a million points of the cube, values and then values with gradients.
    let many: Vec<DVec3> = (0..1_000_000)
        .map(|i| points[i % points.len()] + DVec3::splat(fine * ((i % 13) as f64 - 6.0)))
        .collect();
    let mut v = vec![0.0; many.len()];
    let mut d = vec![DVec3::ZERO; many.len()];
    let clock = std::time::Instant::now();
    sampled.values(&many, &mut v);
    let values_seconds = clock.elapsed().as_secs_f64();
    let clock = std::time::Instant::now();
    sampled.values_and_gradients(&many, &mut v, &mut d);
    let gradients_seconds = clock.elapsed().as_secs_f64();
    errors.sort_by(f64::total_cmp);
    angles.sort_by(f64::total_cmp);
    let at = |v: &[f64], q: f64| v[((v.len() - 1) as f64 * q) as usize];
    println!(
        "{{\"values_only\": {values_only}, \"resolution\": {resolution}, \"coarse\": {}, \"band\": {band}, \"field_evaluations\": {}, \"cells\": {}, \"finest_leaves\": {}, \"mb\": {:.1}, \"seconds\": {:.2}, \"median_gradient\": {:.3}, \"error_cells_median\": {:.2e}, \"error_cells_p99\": {:.2e}, \"normal_1mcos_median\": {:.2e}, \"normal_1mcos_p99\": {:.2e}, \"points\": {}, \"seconds_per_million_values\": {:.2}, \"seconds_per_million_gradients\": {:.2}}}",
        options.coarse_resolution,
        stats.field_evaluations,
        stats.cells,
        stats.finest_leaves,
        stats.bytes as f64 / 1e6,
        stats.seconds,
        stats.median_gradient,
        at(&errors, 0.5),
        at(&errors, 0.99),
        at(&angles, 0.5),
        at(&angles, 0.99),
        points.len(),
        values_seconds,
        gradients_seconds
    );
    Ok(())
}
