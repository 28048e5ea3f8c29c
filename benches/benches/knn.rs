//! The planar loss's k-nearest-neighbour queries: roar's own k-d tree
//! (`roar_loss::point_tree`, behind `KnnPlanarProjector`) against kiddo's `ImmutableKdTree`
//! (f32 coordinates like ours, buckets of 32), each doing the queries of the s2t moves of one
//! planar-loss evaluation; and the whole evaluation (value and gradient) for scale.
//!
//! Workload: the planar bench's bumpy-sphere target (50k cloud points) and a 5 120-face bumpy
//! icosphere source whose regular samples are capped at the loss's default 50k. Both variants
//! compute the same moves: neighbours found in f32, their distances recomputed in f64 and sorted
//! by (distance, index), then `planar_move`; the bench prints how many moves differ.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::num::NonZero;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_loss::knn_projector::planar_move;
use roar_loss::planar::{stratified_subsample, vertex_normals};
use roar_loss::{KnnOptions, KnnPlanarProjector, Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{RegularSamplingOptions, regular_samples, sample_surface};

fn bump(direction: DVec3, radius: f64) -> DVec3 {
    let d = direction.normalize();
    let f = 1.0 + 0.04 * (6.0 * d.x).sin() * (6.0 * d.y).sin() * (6.0 * d.z).sin();
    d * radius * f
}

/// The s2t moves of `points` with kiddo answering the k-NN queries.
fn kiddo_moves(
    tree: &ImmutableKdTree<f32, u32, 3, 32>,
    cloud: &[DVec3],
    cloud_normals: &[DVec3],
    points: &[DVec3],
    normals: &[DVec3],
    options: &KnnOptions,
) -> Vec<Option<DVec3>> {
    let k = NonZero::new(options.k).expect("k > 0");
    let mut found: Vec<(u32, f64)> = Vec::with_capacity(options.k);
    points
        .iter()
        .zip(normals)
        .map(|(&s, &n)| {
            let query = s.as_vec3().to_array();
            found.clear();
            found.extend(
                tree.nearest_n::<SquaredEuclidean>(&query, k)
                    .into_iter()
                    .map(|nb| (nb.item, cloud[nb.item as usize].distance_squared(s))),
            );
            found.sort_unstable_by_key(|&(j, d2)| (d2.to_bits(), j));
            planar_move(
                s,
                n,
                found.iter().map(|&(j, d2)| {
                    let m = cloud_normals[j as usize].normalize_or_zero();
                    (cloud[j as usize], m, d2)
                }),
                options,
            )
        })
        .collect()
}

fn bench_knn(c: &mut Criterion) {
    let (tp, tt) = icosphere(6).to_triangles();
    let tp: Vec<DVec3> = tp.iter().map(|&p| bump(p, 0.8)).collect();
    let cloud = sample_surface(&tp, &tt, 50_000, 11);
    let (sp, st) = icosphere(4).to_triangles();
    let sp: Vec<DVec3> = sp.iter().map(|&p| bump(p, 0.79)).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let vn = vertex_normals(&sp, &st);
    let s = regular_samples(
        &sp,
        &st,
        Some(&vn),
        &RegularSamplingOptions::default(),
        &mut rng,
    )
    .expect("valid source");
    let kept = stratified_subsample(&s, PlanarOptions::default().max_samples, &mut rng);
    let points: Vec<DVec3> = kept.iter().map(|&i| s.points[i]).collect();
    let normals: Vec<DVec3> = kept.iter().map(|&i| s.normals[i]).collect();

    let options = KnnOptions::default();
    let own = KnnPlanarProjector::new(&cloud.points, &cloud.normals, &options).expect("cloud");
    let coords: Vec<[f32; 3]> = cloud
        .points
        .iter()
        .map(|p| p.as_vec3().to_array())
        .collect();
    let tree: ImmutableKdTree<f32, u32, 3, 32> = ImmutableKdTree::new_from_slice(&coords);

    // Same answers? (Neighbour sets can differ only at f32 near-ties.)
    let a = own.displacements(&points, &normals);
    let b = kiddo_moves(
        &tree,
        &cloud.points,
        &cloud.normals,
        &points,
        &normals,
        &options,
    );
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    println!(
        "\nplanar k-NN: {} samples, {} cloud points, k = {}; moves differing between the trees: {differ}",
        points.len(),
        cloud.points.len(),
        options.k
    );

    let mut group = c.benchmark_group("planar_knn");
    group.sample_size(10);
    // One thread for both, so the figures compare the trees and not the scheduling.
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    group.bench_function("s2t_moves/own_tree", |bench| {
        bench.iter(|| single.install(|| own.displacements(&points, &normals)))
    });
    group.bench_function("s2t_moves/kiddo", |bench| {
        bench.iter(|| {
            kiddo_moves(
                &tree,
                &cloud.points,
                &cloud.normals,
                &points,
                &normals,
                &options,
            )
        })
    });
    group.bench_function("build/own_tree", |bench| {
        bench.iter(|| KnnPlanarProjector::new(&cloud.points, &cloud.normals, &options))
    });
    group.bench_function("build/kiddo", |bench| {
        bench.iter(|| ImmutableKdTree::<f32, u32, 3, 32>::new_from_slice(&coords))
    });
    let mut loss = PlanarLoss::new(&cloud.points, &cloud.normals, &PlanarOptions::default())
        .expect("valid cloud");
    group.bench_function("planar_loss_value_and_grad/own_tree", |bench| {
        bench.iter(|| single.install(|| loss.value_and_grad(&sp, &st).expect("valid mesh")))
    });
    group.finish();
}

criterion_group!(benches, bench_knn);
criterion_main!(benches);
