//! Timing and accuracy of the fast winding number: 200k queries on a subdivided icosphere (level 6,
//! 81,920 triangles, by default; `cargo run --release -p roar-mesh --example winding_timing --
//! [levels] [queries] [beta] [leaf_size]`). Prints build time, query time for uniform points in the
//! bounding box and for points near the surface (the point cloud filter's `p + 1e-3·n`), and
//! fast-vs-exact error statistics on a subset.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{WindingNumber, WindingNumberOptions, exact_winding_number};
use std::time::Instant;

/// User + system CPU seconds of this process (Linux `/proc/self/stat`, 100 ticks per second),
/// so timings stay meaningful on a shared, loaded machine.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after_name = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // Fields 14 and 15 of the full line are utime and stime; after the name they are 11 and 12.
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let levels: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(6);
    let queries: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let beta: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let leaf_size: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(8);
    let (positions, triangles) = icosphere(levels).to_triangles();
    println!(
        "mesh: {} triangles, {} queries, beta {beta}, {} rayon threads",
        triangles.len(),
        queries,
        rayon::current_num_threads()
    );
    let start = Instant::now();
    let options = WindingNumberOptions { beta, leaf_size };
    let wn = WindingNumber::build_with(&positions, &triangles, &options).unwrap();
    println!("build: {:.3} s", start.elapsed().as_secs_f64());

    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let uniform: Vec<DVec3> = (0..queries)
        .map(|_| {
            DVec3::new(
                rng.random_range(-1.2..1.2),
                rng.random_range(-1.2..1.2),
                rng.random_range(-1.2..1.2),
            )
        })
        .collect();
    // Near-surface points: on the sphere ± 1e-3 along the normal.
    let near: Vec<DVec3> = (0..queries)
        .map(|_| {
            let d = DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize_or(DVec3::X);
            d * if rng.random_bool(0.5) { 1.001 } else { 0.999 }
        })
        .collect();
    for (name, points) in [("uniform", &uniform), ("near-surface", &near)] {
        let start = Instant::now();
        let cpu_start = cpu_seconds();
        let values = wn.winding_numbers(points);
        let elapsed = start.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - cpu_start;
        let checked = 1000.min(points.len());
        let mut errors: Vec<f64> = (0..checked)
            .map(|i| (values[i] - exact_winding_number(&positions, &triangles, points[i])).abs())
            .collect();
        errors.sort_by(f64::total_cmp);
        let mean = errors.iter().sum::<f64>() / checked as f64;
        println!(
            "{name}: {elapsed:.3} s wall, {cpu:.2} s CPU for {} queries; |fast - exact| over {checked}: mean {mean:.2e}, median {:.2e}, p99 {:.2e}, max {:.2e}",
            points.len(),
            errors[checked / 2],
            errors[checked * 99 / 100],
            errors[checked - 1]
        );
    }
}
