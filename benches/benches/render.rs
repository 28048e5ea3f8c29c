//! Render forward + backward at the ROAR setting: 36 views × 512², on geodesic spheres of about
//! 10k and 100k faces (`render_loss_and_grad`, L1 against renders of a slightly larger sphere).
// `criterion_group!` generates a public function without documentation.
#![allow(missing_docs)]

use std::collections::HashMap;

use criterion::{Criterion, criterion_group, criterion_main};
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

fn bench_render(c: &mut Criterion) {
    let cams = star_cameras(6, 6, 512, 512);
    let opts = RenderOptions::default();
    let mut group = c.benchmark_group("render_36x512");
    group.sample_size(10);
    for (label, n) in [("10k_faces", 22u32), ("100k_faces", 71)] {
        let (pos, tris) = geodesic_sphere(n);
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
