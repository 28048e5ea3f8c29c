//! Times the spatial kernels on real meshes and prints self-intersection counts.
//!
//! Usage: `ROAR_TEST_DATA=/path/to/meshes cargo run -p roar-mesh --release --example
//! spatial_timings [mesh paths relative to ROAR_TEST_DATA...]`.

#[path = "../tests/spatial_common/mod.rs"]
mod spatial_common;

use std::time::Instant;

use glam::DVec3;
use roar_mesh::spatial::{
    TriangleBvh, intersecting_pairs, sample_surface, self_intersecting_faces,
};

/// CPU time used by this process so far (user + system), from `/proc/self/stat`; 0 elsewhere.
/// Wall times on a loaded machine mislead, so both are printed.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let after_name = &stat[stat.rfind(')').map_or(0, |i| i + 2)..];
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let ticks = |k: usize| {
        fields
            .get(k)
            .and_then(|t| t.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// Wall milliseconds and CPU milliseconds of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, String) {
    let (wall, cpu) = (Instant::now(), cpu_seconds());
    let out = f();
    let text = format!(
        "{:.0} ms wall / {:.0} ms cpu",
        wall.elapsed().as_secs_f64() * 1e3,
        (cpu_seconds() - cpu) * 1e3
    );
    (out, text)
}

fn main() {
    let Some(dir) = spatial_common::test_data_dir() else {
        return;
    };
    let mut names: Vec<String> = std::env::args().skip(1).collect();
    if names.is_empty() {
        names = [
            "clean/armadillo.obj",
            "clean/dragon.obj",
            "clean/horse.obj",
            "clean/camel.off",
        ]
        .map(String::from)
        .to_vec();
    }
    println!("rayon threads: {}", rayon::current_num_threads());
    for name in names {
        let soup = roar_io::read_mesh(&dir.join(&name)).unwrap_or_else(|e| panic!("{e}"));
        let (positions, triangles) = (soup.positions, soup.triangles);
        let (bvh, build) = timed(|| TriangleBvh::build(&positions, &triangles));

        // Queries off the surface along the normal by 0.1 % and 1 % of the box diagonal.
        let samples = sample_surface(&positions, &triangles, 200_000, 1);
        let diag = bvh.aabb().map_or(1.0, |b| b.diagonal());
        let offset_queries = |fraction: f64| -> Vec<DVec3> {
            let lift = fraction * diag;
            samples
                .points
                .iter()
                .zip(&samples.normals)
                .map(|(p, n)| *p + lift * *n)
                .collect()
        };
        let closest_point_time = |queries: &[DVec3]| {
            timed(|| {
                queries
                    .iter()
                    .map(|&q| bvh.closest_point(q).map_or(0.0, |c| c.distance_squared))
                    .sum::<f64>()
            })
            .1
        };
        let near = closest_point_time(&offset_queries(0.001));
        let queries = offset_queries(0.01);
        let closest = format!(
            "{near} (0.1 % off), {} (1 % off)",
            closest_point_time(&queries)
        );
        let (hits, rays) = timed(|| {
            (0..queries.len())
                .filter(|&k| {
                    let dir = queries[(k * 7919 + 1) % queries.len()] - queries[k];
                    bvh.ray_cast(queries[k], dir, 1.0).is_some()
                })
                .count()
        });
        let (flags, selfx) = timed(|| self_intersecting_faces(&positions, &triangles));
        let count = flags.iter().filter(|&&f| f).count();
        println!(
            "{name}: {} faces\n  BVH build: {build}\n  200k closest points: {closest}\n  \
             200k ray casts ({hits} hits): {rays}\n  self-intersections: {selfx}, {count} faces",
            triangles.len(),
        );
        if count <= 40 {
            for (i, j) in intersecting_pairs(&positions, &triangles) {
                let (ti, tj) = (triangles[i as usize], triangles[j as usize]);
                let shared = ti.iter().filter(|k| tj.contains(k)).count();
                println!("    pair {i} {ti:?} – {j} {tj:?}: {shared} shared vertices");
            }
        }
    }
}
