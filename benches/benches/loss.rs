//! One evaluation of the loop's objective (`3·L_render + 1·L_planar`, built by
//! `roar::default_loss`) on a real mesh, and its parts on their own. A soup's loop
//! and polish render the default rig coarse (25 views × 256², `render_coarse_resolution`), the
//! paper the full rig (36 × 512², the SDF and scan schedules): `loop_*` and `render_coarse_*`
//! are the former, `full_*`, `render_forward_*` and `render_forward_backward_*` the latter;
//! `planar_*` is the same in both. The fixture and sources (5,000 and 10,000 faces):
//! `common/homer.rs`. Without `ROAR_TEST_DATA` the bench prints why and measures nothing.
// `criterion_group!` generates a public function without documentation.
#![allow(missing_docs)]

#[path = "common/homer.rs"]
mod homer;

use criterion::{Criterion, criterion_group};
use homer::Homer;
use roar::{default_loss, planar_options};
use roar_loss::{Loss, PlanarLoss, RenderLoss};
use roar_render::{RenderOptions, render};

fn bench_loss(c: &mut Criterion) {
    let Some(homer) = Homer::load() else {
        return;
    };
    let mut group = c.benchmark_group("loss");
    group.sample_size(10);
    for faces in [5_000usize, 10_000] {
        let (positions, triangles) = homer.source(faces);
        let label = format!("{}k_faces", faces / 1000);
        let mut loop_loss = default_loss(&homer.prepared(true)).expect("default loss");
        group.bench_function(format!("loop_{label}"), |b| {
            b.iter(|| loop_loss.value_and_grad(&positions, &triangles).unwrap())
        });
        let mut full = default_loss(&homer.prepared(false)).expect("default loss");
        group.bench_function(format!("full_{label}"), |b| {
            b.iter(|| full.value_and_grad(&positions, &triangles).unwrap())
        });
        let mut coarse = RenderLoss::from_renders(&homer.coarse_cameras, &homer.coarse_renders);
        group.bench_function(format!("render_coarse_forward_backward_{label}"), |b| {
            b.iter(|| coarse.value_and_grad(&positions, &triangles).unwrap())
        });
        group.bench_function(format!("render_forward_{label}"), |b| {
            b.iter(|| {
                render(
                    &positions,
                    &triangles,
                    &homer.target.cameras,
                    &RenderOptions::default(),
                )
                .unwrap()
            })
        });
        let mut render_loss = RenderLoss::new(&homer.target);
        group.bench_function(format!("render_forward_backward_{label}"), |b| {
            b.iter(|| render_loss.value_and_grad(&positions, &triangles).unwrap())
        });
        let mut planar = PlanarLoss::new(
            &homer.cloud.points,
            &homer.cloud.normals,
            &planar_options(&homer.config),
        )
        .expect("planar loss");
        group.bench_function(format!("planar_{label}"), |b| {
            b.iter(|| planar.value_and_grad(&positions, &triangles).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_loss);

fn main() {
    if std::env::var_os("ROAR_TEST_DATA").is_none() {
        eprintln!(
            "loss bench skipped: set ROAR_TEST_DATA to the shared meshes folder ({})",
            homer::MESH
        );
        return;
    }
    benches();
    criterion::Criterion::default()
        .configure_from_args()
        .final_summary();
}
