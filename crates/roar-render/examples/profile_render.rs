//! Profiling driver: `render_loss_and_grad` at 36 views × 512² on a geodesic sphere (the same
//! mesh and targets as the criterion bench `benches/benches/render.rs`).
//!
//! Usage: `cargo run --release -p roar-render --example profile_render -- [n] [iterations]
//! [single]`, where the sphere has `20·n²` faces (default `n = 22`, about 10k faces). With a third
//! argument `single`, the fused pass runs in a one-thread rayon pool on the main thread, so that
//! callgrind can restrict collection to it:
//! `valgrind --tool=callgrind --toggle-collect='*render_loss_and_grad*' target/release/examples/profile_render 22 1 single`.

use std::collections::HashMap;
use std::time::Instant;

use glam::DVec3;
use roar_render::{LossKind, RenderOptions, render, render_loss_and_grad, star_cameras};

/// Geodesic sphere: every icosahedron face split into `n²` triangles (20·n² faces), radius 0.9.
fn geodesic_sphere(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let ico: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z))
    .collect();
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut verts = Vec::new();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut tris = Vec::new();
    for [a, b, c] in faces {
        let (a, b, c) = (ico[a], ico[b], ico[c]);
        let mut id = |i: u32, j: u32| -> u32 {
            let p = (a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64))
                .normalize()
                * 0.9;
            let key = [p.x, p.y, p.z].map(|v| (v * 1e9).round() as i64);
            *index.entry(key).or_insert_with(|| {
                verts.push(p);
                (verts.len() - 1) as u32
            })
        };
        for i in 0..n {
            for j in 0..n - i {
                tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                if i + j + 1 < n {
                    tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
    }
    (verts, tris)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(22);
    let iterations: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let single = args.next().is_some_and(|s| s == "single");
    let cams = star_cameras(6, 6, 512, 512);
    let opts = RenderOptions::default();
    let (pos, tris) = geodesic_sphere(n);
    let target_pos: Vec<DVec3> = pos
        .iter()
        .map(|p| *p * DVec3::new(1.03, 0.97, 1.0))
        .collect();
    let targets: Vec<_> = render(&target_pos, &tris, &cams, &opts)
        .expect("target render")
        .views
        .into_iter()
        .map(|v| v.rgba)
        .collect();
    let pool = single.then(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .use_current_thread()
            .build()
            .expect("one-thread pool")
    });
    let run = || render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L1);
    for _ in 0..iterations {
        let start = Instant::now();
        let (loss, grad) = match &pool {
            Some(pool) => pool.install(run),
            None => run(),
        }
        .expect("render_loss_and_grad");
        let norm: f64 = grad.iter().map(|g| g.length_squared()).sum::<f64>().sqrt();
        println!(
            "{} faces: loss {loss:.9e}, |grad| {norm:.9e}, {:.1} ms",
            tris.len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
}
