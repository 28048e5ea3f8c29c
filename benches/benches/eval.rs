//! Evaluation metrics on the Stanford armadillo (100k faces, `$ROAR_TEST_DATA/clean/armadillo.obj`):
//! self-intersections (BVH + exact tests + the ε re-test) and Chamfer with 200k samples per side
//! against a copy scaled by 1.01 about its centroid. Goal: each under 1 s on 2 cores.
//! Without `ROAR_TEST_DATA` the benches are skipped with a note.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use roar_eval::{ChamferOptions, SelfIntersectionOptions, fidelity, self_intersections};

fn armadillo() -> Option<(Vec<DVec3>, Vec<[u32; 3]>)> {
    let Some(root) = std::env::var_os("ROAR_TEST_DATA") else {
        eprintln!("note: ROAR_TEST_DATA unset; skipping the eval benches");
        return None;
    };
    let path = std::path::Path::new(&root).join("clean/armadillo.obj");
    let soup = roar_io::read_mesh(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Some((soup.positions, soup.triangles))
}

fn eval_benches(c: &mut Criterion) {
    let Some((p, t)) = armadillo() else {
        return;
    };
    let mut group = c.benchmark_group("eval");
    group.sample_size(10);
    group.bench_function("self_intersections/armadillo_100k", |b| {
        b.iter(|| self_intersections(&p, &t, &SelfIntersectionOptions::default()))
    });
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let scaled: Vec<DVec3> = p.iter().map(|&x| centre + 1.01 * (x - centre)).collect();
    let options = ChamferOptions {
        samples: 200_000,
        seed: 0,
    };
    group.bench_function("chamfer_200k/armadillo_vs_scaled", |b| {
        b.iter(|| fidelity(&scaled, &t, &p, &t, &options))
    });
    group.finish();
}

criterion_group!(benches, eval_benches);
criterion_main!(benches);
