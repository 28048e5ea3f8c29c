//! The supplementary's Fig. 1 (supplementary §1.4): error and time of the k-NN planar projection
//! (the paper's) with 10k, 50k and 200k target samples against the exact ray-cast projection onto
//! the target mesh (the authors' later code), for source meshes of about 1k, 10k and 100k faces;
//! plus the per-evaluation cost of the planar loss (value and gradient) at 5k faces, at the default
//! sample cap and at 100k.
//!
//! Target: a bumpy sphere (icosphere(6), 81 920 faces, radius 0.8 modulated by
//! `1 + 0.04·sin(6x)sin(6y)sin(6z)`). Sources: geodesic spheres of 980, 9 680 and 100 820 faces
//! carrying the same bumps at radius 0.79, so every sample lies within the 0.05 reach of the
//! exact projector, as during optimization. Samples: the source's regular samples,
//! capped at 50k per source by the planar loss's stratified subsampling. The error table (mean
//! `|q_knn − q_exact|` over samples valid for both, divided by the target's bounding-box
//! diagonal) is printed once before the timings.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::collections::HashMap;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_loss::planar::{stratified_subsample, vertex_normals};
use roar_loss::{KnnOptions, KnnPlanarProjector, Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{
    Projector, RayCastProjector, RayProjectorOptions, RegularSamplingOptions, regular_samples,
    sample_surface,
};

const TARGET_SAMPLES: [usize; 3] = [10_000, 50_000, 200_000];
/// Geodesic subdivision `n` (20·n² faces): 980, 9 680, 100 820 faces.
const SOURCE_SUBDIVISIONS: [u32; 3] = [7, 22, 71];
const SAMPLE_CAP: usize = 50_000;

fn bump(direction: DVec3, radius: f64) -> DVec3 {
    let d = direction.normalize();
    let f = 1.0 + 0.04 * (6.0 * d.x).sin() * (6.0 * d.y).sin() * (6.0 * d.z).sin();
    d * radius * f
}

fn target() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (p, t) = icosphere(6).to_triangles();
    (p.iter().map(|&p| bump(p, 0.8)).collect(), t)
}

/// Geodesic sphere: every icosahedron face split into `n²` triangles, bumped at radius 0.79.
fn source(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (ico, faces) = icosphere(0).to_triangles();
    let mut verts = Vec::new();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut tris = Vec::new();
    for [a, b, c] in faces {
        let (a, b, c) = (ico[a as usize], ico[b as usize], ico[c as usize]);
        let mut id = |i: u32, j: u32| -> u32 {
            let p = a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64);
            let p = bump(p, 0.79);
            let key = (p * 1e9).round().as_i64vec3().to_array();
            *index.entry(key).or_insert_with(|| {
                verts.push(p);
                verts.len() as u32 - 1
            })
        };
        for j in 0..n {
            for i in 0..(n - j) {
                let (v0, v1, v2) = (id(i, j), id(i + 1, j), id(i, j + 1));
                tris.push([v0, v1, v2]);
                if i + j + 1 < n {
                    let v3 = id(i + 1, j + 1);
                    tris.push([v1, v3, v2]);
                }
            }
        }
    }
    (verts, tris)
}

/// Regular samples of a source (normals from ROAR vertex normals), capped at [`SAMPLE_CAP`].
fn samples(positions: &[DVec3], triangles: &[[u32; 3]]) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let normals = vertex_normals(positions, triangles);
    let s = regular_samples(
        positions,
        triangles,
        Some(&normals),
        &RegularSamplingOptions::default(),
        &mut rng,
    )
    .expect("valid source");
    let kept = stratified_subsample(&s, SAMPLE_CAP, &mut rng);
    (
        kept.iter().map(|&i| s.points[i]).collect(),
        kept.iter().map(|&i| s.normals[i]).collect(),
    )
}

fn diagonal(points: &[DVec3]) -> f64 {
    let lo = points
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, b| a.min(*b));
    let hi = points
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
    (hi - lo).length()
}

fn print_table() {
    let (tp, tt) = target();
    let diag = diagonal(&tp);
    let exact = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
    println!("\nk-NN planar projection vs exact ray cast (bumpy-sphere target, 81 920 faces)");
    println!(
        "source faces | samples | exact valid | exact ms | P size | knn valid | build ms | knn ms | mean err/diag | max err/diag"
    );
    for n in SOURCE_SUBDIVISIONS {
        let (sp, st) = source(n);
        let (points, normals) = samples(&sp, &st);
        let start = Instant::now();
        let q_exact = exact.project(&sp, &st, &points, &normals);
        let exact_ms = start.elapsed().as_secs_f64() * 1e3;
        let exact_valid = q_exact.iter().flatten().count();
        for count in TARGET_SAMPLES {
            let cloud = sample_surface(&tp, &tt, count, 11);
            let start = Instant::now();
            let knn =
                KnnPlanarProjector::new(&cloud.points, &cloud.normals, &KnnOptions::default())
                    .expect("valid cloud");
            let build_ms = start.elapsed().as_secs_f64() * 1e3;
            let start = Instant::now();
            let q_knn = knn.project(&sp, &st, &points, &normals);
            let knn_ms = start.elapsed().as_secs_f64() * 1e3;
            let errors: Vec<f64> = q_exact
                .iter()
                .zip(&q_knn)
                .filter_map(|(a, b)| Some((a.as_ref()? - b.as_ref()?).length() / diag))
                .collect();
            let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
            let max = errors.iter().cloned().fold(0.0, f64::max);
            println!(
                "{:>12} | {:>7} | {:>11} | {:>8.1} | {:>6} | {:>9} | {:>8.1} | {:>6.1} | {:>13.2e} | {:>12.2e}",
                st.len(),
                points.len(),
                exact_valid,
                exact_ms,
                count,
                q_knn.iter().flatten().count(),
                build_ms,
                knn_ms,
                mean,
                max
            );
        }
    }
    println!();
}

fn bench_projection(c: &mut Criterion) {
    print_table();
    let (tp, tt) = target();
    let exact = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
    let mut group = c.benchmark_group("projection");
    group.sample_size(10);
    for n in SOURCE_SUBDIVISIONS {
        let (sp, st) = source(n);
        let (points, normals) = samples(&sp, &st);
        group.bench_function(format!("exact/F{}", st.len()), |b| {
            b.iter(|| exact.project(&sp, &st, &points, &normals))
        });
        for count in TARGET_SAMPLES {
            let cloud = sample_surface(&tp, &tt, count, 11);
            let knn =
                KnnPlanarProjector::new(&cloud.points, &cloud.normals, &KnnOptions::default())
                    .expect("valid cloud");
            group.bench_function(format!("knn/P{count}/F{}", st.len()), |b| {
                b.iter(|| knn.project(&sp, &st, &points, &normals))
            });
        }
    }
    group.finish();
}

fn bench_planar_loss(c: &mut Criterion) {
    let (tp, tt) = target();
    let cloud = sample_surface(&tp, &tt, 50_000, 11);
    let (sp, st) = icosphere(4).to_triangles();
    let sp: Vec<DVec3> = sp.iter().map(|&p| bump(p, 0.79)).collect();
    let mut group = c.benchmark_group("planar_loss");
    group.sample_size(10);
    // The default cap and twice it (100k).
    for cap in [PlanarOptions::default().max_samples, 100_000] {
        let options = PlanarOptions {
            max_samples: cap,
            ..PlanarOptions::default()
        };
        let mut loss =
            PlanarLoss::new(&cloud.points, &cloud.normals, &options).expect("valid cloud");
        group.bench_function(
            format!("value_and_grad/F{}/P50000/cap{cap}", st.len()),
            |b| b.iter(|| loss.value_and_grad(&sp, &st).expect("valid mesh")),
        );
        println!(
            "planar loss stats at {} faces, cap {cap}: {:?}",
            st.len(),
            loss.last_stats
        );
    }
    group.finish();
}

criterion_group!(benches, bench_projection, bench_planar_loss);
criterion_main!(benches);
