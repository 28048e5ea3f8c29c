//! Render forward + backward at the ROAR setting: 36 views × 512², on icospheres of radius 0.9
//! with 5 120 and 81 920 faces (`render_loss_and_grad`, L1 against renders of a slightly larger sphere).
// `criterion_group!` generates a public function without documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use roar_mesh::shapes::icosphere;
use roar_render::{LossKind, RenderOptions, render, render_loss_and_grad, star_cameras};

fn bench_render(c: &mut Criterion) {
    let cams = star_cameras(6, 6, 512, 512);
    let opts = RenderOptions::default();
    let mut group = c.benchmark_group("render_36x512");
    group.sample_size(10);
    for (label, level) in [("5k_faces", 4u32), ("82k_faces", 6)] {
        let (unit, tris) = icosphere(level).to_triangles();
        let pos: Vec<DVec3> = unit.iter().map(|p| *p * 0.9).collect();
        let target_pos: Vec<DVec3> = pos
            .iter()
            .map(|p| *p * DVec3::new(1.03, 0.97, 1.0))
            .collect();
        let targets: Vec<_> = render(&target_pos, &tris, &cams, &opts)
            .unwrap()
            .views
            .into_iter()
            .map(|v| v.rgba)
            .collect();
        group.bench_function(format!("forward_backward_{label}"), |b| {
            b.iter(|| {
                render_loss_and_grad(&pos, &tris, &cams, &targets, &opts, LossKind::L1).unwrap()
            })
        });
        group.bench_function(format!("forward_only_{label}"), |b| {
            b.iter(|| render(&pos, &tris, &cams, &opts).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_render);
criterion_main!(benches);
