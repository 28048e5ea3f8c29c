//! Profiling driver: `render_loss_and_grad` at 36 views × 512² on an icosphere of radius 0.9 (the same
//! mesh and targets as the criterion bench `benches/benches/render.rs`).
//!
//! Usage: `cargo run --release -p roar-render --example profile_render -- [level] [iterations]
//! [single]`, where the sphere is `roar_mesh::shapes::icosphere(level)` with `20·4^level` faces (default
//! `level = 4`, 5 120 faces). With a third
//! argument `single`, the fused pass runs in a one-thread rayon pool on the main thread, so that
//! callgrind can restrict collection to it:
//! `valgrind --tool=callgrind --toggle-collect='*render_loss_and_grad*' target/release/examples/profile_render 4 1 single`.

use std::time::Instant;

use glam::DVec3;
use roar_mesh::shapes::icosphere;
use roar_render::{LossKind, RenderOptions, render, render_loss_and_grad, star_cameras};

fn main() {
    let mut args = std::env::args().skip(1);
    let level: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(4);
    let iterations: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let single = args.next().is_some_and(|s| s == "single");
    let cams = star_cameras(6, 6, 512, 512);
    let opts = RenderOptions::default();
    let (unit, tris) = icosphere(level).to_triangles();
    let pos: Vec<DVec3> = unit.iter().map(|p| *p * 0.9).collect();
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
