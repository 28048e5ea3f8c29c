//! Remeshing blocks on a ~10k-face sphere: Face Collapse + flips on a jittered (folded) copy,
//! Face Split under and at budget against the analytic sphere projector (O(1) per sample),
//! tangential smoothing. Goal: < 20 ms per block call. The Face Split goal excludes the
//! projection it is given: `sphere_projection_of_split_samples` times that projection alone
//! (same samples), to subtract from the `face_split_*` figures. `step_limiter_*`: the step
//! limiter on two concentric ~5k-face icospheres close together (an open surface pulled onto
//! one sheet has such pairs), once with small steps (one pass) and once with steps three times
//! the gap (many intersecting pairs, several passes). `untangle_crumpled_cap`: the untangle
//! block on a ~20k-face icosphere whose top cap is crumpled by steps of about an edge length
//! (hundreds of crossing pairs, most cleared by edge collapses).

use criterion::{BatchSize, Criterion, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::perturbed;
use roar_mesh::spatial::{Projector, SphereProjector, regular_sample_points};
use roar_mesh::{DVec3, Mesh, TrackedMesh};
use roar_ops::blocks::collapse::{FaceCollapseOptions, face_collapse};
use roar_ops::blocks::smoothing::{SmoothingOptions, tangential_smoothing};
use roar_ops::blocks::split::{FaceSplitOptions, SplitThreshold, face_split};
use roar_ops::geometry::Geometry;
use roar_ops::optim::{Optimizer, OptimizerOptions};
use roar_ops::untangle::{LimiterOptions, UntangleOptions, limit_steps, untangle};
use std::hint::black_box;

/// Latitude–longitude unit sphere: `2·lon·(lat − 1)` faces (50 × 100 → 9800).
fn uv_sphere(lat: usize, lon: usize) -> Mesh {
    let mut positions = vec![DVec3::Z];
    for i in 1..lat {
        let theta = std::f64::consts::PI * i as f64 / lat as f64;
        for j in 0..lon {
            let phi = std::f64::consts::TAU * j as f64 / lon as f64;
            positions.push(DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
        }
    }
    positions.push(-DVec3::Z);
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
    let mut tris = Vec::new();
    for j in 0..lon {
        tris.push([0, ring(1, j), ring(1, j + 1)]);
        tris.push([south, ring(lat - 1, j + 1), ring(lat - 1, j)]);
    }
    for i in 1..lat - 1 {
        for j in 0..lon {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i + 1, j),
                ring(i + 1, j + 1),
                ring(i, j + 1),
            );
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    Mesh::from_triangles(positions, &tris).expect("uv sphere is a closed manifold")
}

fn blocks(c: &mut Criterion) {
    let base = uv_sphere(50, 100);
    let folded = perturbed(&base, 0.02, 1);
    let smooth = perturbed(&base, 0.002, 2);
    let optimizer =
        |m: &Mesh| Optimizer::new(m.vertex_capacity(), OptimizerOptions::default()).unwrap();
    let sphere = SphereProjector {
        center: DVec3::ZERO,
        radius: 1.0,
    };
    let split_options = FaceSplitOptions {
        threshold: SplitThreshold::PerFace(0.02),
        ..FaceSplitOptions::default()
    };
    let f = base.n_faces();

    let mut group = c.benchmark_group("blocks_10k_faces");
    group.sample_size(20);
    group.bench_function("face_collapse_and_flips", |b| {
        b.iter_batched(
            || (folded.clone(), optimizer(&folded)),
            |(mut m, mut o)| {
                black_box(face_collapse(
                    &mut TrackedMesh::new(&mut m, &mut o),
                    &FaceCollapseOptions::default(),
                ))
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("face_split_under_budget", |b| {
        b.iter_batched(
            || (smooth.clone(), optimizer(&smooth)),
            |(mut m, mut o)| {
                black_box(face_split(
                    &mut TrackedMesh::new(&mut m, &mut o),
                    &sphere,
                    f + 2000,
                    &split_options,
                ))
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("face_split_at_budget", |b| {
        b.iter_batched(
            || (smooth.clone(), optimizer(&smooth)),
            |(mut m, mut o)| {
                black_box(face_split(
                    &mut TrackedMesh::new(&mut m, &mut o),
                    &sphere,
                    f,
                    &split_options,
                ))
            },
            BatchSize::LargeInput,
        )
    });
    // The samples face_split draws on `smooth` (seed 0), projected as the block does.
    let triangles: Vec<[u32; 3]> = smooth
        .faces()
        .map(|f| smooth.face_vertices(f).map(|v| v.raw()))
        .collect();
    let samples = regular_sample_points(
        smooth.positions(),
        &triangles,
        Some(&Geometry::compute(&smooth).vertex_normals),
        &split_options.sampling,
        &mut ChaCha8Rng::seed_from_u64(split_options.seed),
    )
    .expect("valid mesh");
    group.bench_function("sphere_projection_of_split_samples", |b| {
        b.iter(|| {
            black_box(sphere.project(
                smooth.positions(),
                &triangles,
                &samples.points,
                &samples.normals,
            ))
        })
    });
    group.bench_function("tangential_smoothing", |b| {
        b.iter_batched(
            || smooth.clone(),
            |mut m| black_box(tangential_smoothing(&mut m, &SmoothingOptions::default())),
            BatchSize::LargeInput,
        )
    });
    group.finish();

    let mut group = c.benchmark_group("step_limiter_10k_faces");
    group.sample_size(20);
    let (shells, shell_triangles) = two_shells(4, 0.005);
    for (label, scale) in [("small_steps", 0.001), ("steps_across_the_gap", 0.015)] {
        let proposed = jitter(&shells, scale);
        group.bench_function(label, |b| {
            b.iter_batched(
                || proposed.clone(),
                |mut p| {
                    black_box(limit_steps(
                        &shells,
                        &mut p,
                        &shell_triangles,
                        &LimiterOptions::default(),
                    ))
                },
                BatchSize::LargeInput,
            )
        });
        let mut p = proposed.clone();
        let stats = limit_steps(
            &shells,
            &mut p,
            &shell_triangles,
            &LimiterOptions::default(),
        );
        eprintln!("step limiter {label}: {stats:?}");
    }
    group.finish();

    let mut group = c.benchmark_group("untangle");
    group.sample_size(10);
    let crumpled = crumpled_cap(5);
    group.bench_function("crumpled_cap_20k_faces", |b| {
        b.iter_batched(
            || crumpled.clone(),
            |mut m| black_box(untangle(&mut m, &UntangleOptions::default())),
            BatchSize::LargeInput,
        )
    });
    group.finish();
    eprintln!(
        "untangle crumpled cap: {:?}",
        untangle(&mut crumpled.clone(), &UntangleOptions::default())
    );

    // One-off stats so the figures can be read against the work done.
    let (mut m, mut o) = (folded.clone(), optimizer(&folded));
    eprintln!(
        "face_collapse: {:?}",
        face_collapse(
            &mut TrackedMesh::new(&mut m, &mut o),
            &FaceCollapseOptions::default()
        )
    );
    let (mut m, mut o) = (smooth.clone(), optimizer(&smooth));
    eprintln!(
        "face_split under budget: {:?}",
        face_split(
            &mut TrackedMesh::new(&mut m, &mut o),
            &sphere,
            f + 2000,
            &split_options
        )
    );
}

/// Two concentric icospheres `gap` apart: positions and triangles (#F = 2 × 20·4^level).
fn two_shells(level: u32, gap: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (inner, t) = roar_mesh::shapes::icosphere(level).to_triangles();
    let offset = inner.len() as u32;
    let mut positions = inner.clone();
    positions.extend(inner.iter().map(|p| *p * (1.0 + gap)));
    let mut triangles = t.clone();
    triangles.extend(t.iter().map(|f| f.map(|i| i + offset)));
    (positions, triangles)
}

/// An icosphere (#F = 20·4^level) whose vertices above z = 0.6 are jittered by up to an edge
/// length per coordinate: a crumpled cap crossing itself.
fn crumpled_cap(level: u32) -> Mesh {
    let sphere = roar_mesh::shapes::icosphere(level);
    let (positions, triangles) = sphere.to_triangles();
    let edge = positions[triangles[0][0] as usize].distance(positions[triangles[0][1] as usize]);
    let jittered = jitter(&positions, edge);
    let crumpled = positions
        .iter()
        .zip(jittered)
        .map(|(p, q)| if p.z > 0.6 { q } else { *p })
        .collect();
    Mesh::from_triangles(crumpled, &triangles).expect("the sphere's connectivity")
}

/// `positions` each moved by a pseudo-random step of up to `scale` per coordinate (seed 0).
fn jitter(positions: &[DVec3], scale: f64) -> Vec<DVec3> {
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    positions
        .iter()
        .map(|p| {
            let r = DVec3::new(rng.random(), rng.random(), rng.random());
            *p + scale * (2.0 * r - DVec3::ONE)
        })
        .collect()
}

mod group {
    //! The criterion group (its macro generates an undocumented `pub fn`).
    #![allow(missing_docs)]
    criterion::criterion_group!(benches, super::blocks);
}
use group::benches;
criterion_main!(benches);
