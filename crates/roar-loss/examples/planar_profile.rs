//! Cost of one planar loss evaluation at about 5k faces, for profiling.
//!
//! Target: a bumpy sphere (icosphere(6), radius 0.8, modulated by
//! `1 + 0.04·sin(6x)sin(6y)sin(6z)`) sampled with `P` points; source: icosphere(4) (5 120 faces)
//! with the same bumps at radius 0.79 — the scenario of `benches/benches/projection.rs`.
//!
//! Run: `cargo run --release -p roar-loss --example planar_profile [P] [iterations]`, or under
//! `valgrind --tool=callgrind` with one iteration (instruction counts are repeatable on a
//! shared machine, wall times are not; one evaluation costs the difference between runs with
//! 2 and 1 iterations). Env `PHASES=1` adds a per-phase wall-time breakdown, `CAP_STUDY=1` the
//! gradient error of smaller sample caps against the uncapped loss.

use std::time::Instant;

use glam::DVec3;
use roar_loss::{Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::sample_surface;

fn bump(direction: DVec3, radius: f64) -> DVec3 {
    let d = direction.normalize();
    let f = 1.0 + 0.04 * (6.0 * d.x).sin() * (6.0 * d.y).sin() * (6.0 * d.z).sin();
    d * radius * f
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(50_000);
    let iterations: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);

    let (tp, tt) = icosphere(6).to_triangles();
    let tp: Vec<DVec3> = tp.iter().map(|&p| bump(p, 0.8)).collect();
    let cloud = sample_surface(&tp, &tt, count, 11);
    let (sp, st) = icosphere(4).to_triangles();
    let sp: Vec<DVec3> = sp.iter().map(|&p| bump(p, 0.79)).collect();

    let start = Instant::now();
    let mut loss = PlanarLoss::new(&cloud.points, &cloud.normals, &PlanarOptions::default())
        .expect("valid cloud");
    println!(
        "P = {count}: build {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    let mut times = Vec::new();
    let mut checksum = 0.0;
    for _ in 0..iterations {
        let start = Instant::now();
        let (value, grad) = loss.value_and_grad(&sp, &st).expect("valid mesh");
        times.push(start.elapsed().as_secs_f64() * 1e3);
        checksum += value + grad.iter().map(|g| g.x + g.y + g.z).sum::<f64>();
    }
    times.sort_by(f64::total_cmp);
    println!(
        "F = {}: value_and_grad min {:.1} ms, median {:.1} ms over {iterations}",
        st.len(),
        times[0],
        times[times.len() / 2]
    );
    println!("stats: {:?}", loss.last_stats);
    println!("checksum {checksum:.12e}");
    if std::env::var_os("CAP_STUDY").is_some() {
        cap_study(&cloud.points, &cloud.normals, &sp, &st);
    }
    if std::env::var_os("PHASES").is_some() {
        phases(&loss, &sp, &st);
    }
}

/// Wall time of each phase of one evaluation, through the public building blocks.
fn phases(loss: &PlanarLoss, sp: &[DVec3], st: &[[u32; 3]]) {
    use rand::SeedableRng;
    use roar_loss::planar::{stratified_subsample, t2s_moves, vertex_normals};
    use roar_mesh::spatial::regular_samples;
    let options = loss.options();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let mut lap = Instant::now();
    let mut report = |name: &str| {
        println!("  {name}: {:.1} ms", lap.elapsed().as_secs_f64() * 1e3);
        lap = Instant::now();
    };
    let normals = vertex_normals(sp, st);
    let samples =
        regular_samples(sp, st, Some(&normals), &options.sampling, &mut rng).expect("valid");
    report("sampling");
    let kept = stratified_subsample(&samples, options.max_samples, &mut rng);
    let points: Vec<DVec3> = kept.iter().map(|&i| samples.points[i]).collect();
    let normals: Vec<DVec3> = kept.iter().map(|&i| samples.normals[i]).collect();
    report("subsample");
    let s2t = loss.projector().displacements(&points, &normals);
    report("s2t");
    let t2s = t2s_moves(
        &points,
        &normals,
        loss.projector().points(),
        loss.projector().normals(),
        options.t2s_normal_dot,
    );
    report("t2s");
    println!("  ({} s2t, {} t2s moves)", s2t.len(), t2s.len());
}

/// Relative L2 gradient error and loss error of capped evaluations against uncapped ones (other
/// seeds), next to the uncapped seed-to-seed spread (the floor set by the grid rounding).
fn cap_study(points: &[DVec3], normals: &[DVec3], sp: &[DVec3], st: &[[u32; 3]]) {
    let evaluate = |cap: usize, seed: u64| {
        let options = PlanarOptions {
            max_samples: cap,
            seed,
            ..PlanarOptions::default()
        };
        let mut loss = PlanarLoss::new(points, normals, &options).expect("valid cloud");
        let start = Instant::now();
        let (value, grad) = loss.value_and_grad(sp, st).expect("valid mesh");
        (value, grad, start.elapsed().as_secs_f64() * 1e3)
    };
    let references: Vec<_> = (100..103).map(|seed| evaluate(usize::MAX, seed)).collect();
    let norm = |g: &[DVec3]| g.iter().map(|g| g.length_squared()).sum::<f64>().sqrt();
    let error = |a: &(f64, Vec<DVec3>, f64), b: &(f64, Vec<DVec3>, f64)| {
        let diff: Vec<DVec3> = a.1.iter().zip(&b.1).map(|(x, y)| *x - *y).collect();
        (norm(&diff) / norm(&b.1), (a.0 - b.0).abs() / b.0)
    };
    println!("cap | grad rel. err (mean over 3 refs) | loss rel. err | ms");
    for cap in [usize::MAX, 200_000, 100_000, 50_000, 25_000, 12_500] {
        let (mut ge, mut le, mut ms) = (0.0, 0.0, 0.0);
        for (r, seed) in references.iter().zip([7u64, 8, 9]) {
            let run = evaluate(cap, seed);
            let (g, l) = error(&run, r);
            ge += g / 3.0;
            le += l / 3.0;
            ms += run.2 / 3.0;
        }
        println!("{cap:>8} | {ge:.4} | {le:.2e} | {ms:.0}");
    }
}
