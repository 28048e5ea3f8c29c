//! SDF inputs: batched network evaluation (values with input gradients, in points per second)
//! for 8 × 64 and 8 × 256 MLPs with random weights, and one SDF-loss evaluation on the 25,002
//! vertices of a 50,000-face mesh (a subdivided sphere) over the 8 × 64 network.

use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_loss::{Loss, SdfLoss, SdfLossOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{Sdf, evaluate_with_gradients};
use roar_sdf::{Activation, Mlp};

/// An MLP 3 → width (× 8 hidden layers) → 1 with He-scaled random weights.
fn network(width: usize) -> Mlp {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut sizes = vec![3];
    sizes.extend(std::iter::repeat_n(width, 8));
    sizes.push(1);
    let layers = sizes
        .windows(2)
        .map(|w| {
            let scale = (2.0 / w[0] as f32).sqrt();
            (
                Array2::from_shape_fn((w[0], w[1]), |_| scale * rng.random_range(-1.0..1.0)),
                Array1::from_shape_fn(w[1], |_| 0.1 * rng.random_range(-1.0..1.0)),
            )
        })
        .collect();
    Mlp::from_layers(layers, Activation::Elu)
}

fn sdf_benches(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let points: Vec<DVec3> = (0..65_536)
        .map(|_| DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE)
        .collect();
    let mut group = c.benchmark_group("sdf");
    group.sample_size(10);
    group.throughput(Throughput::Elements(points.len() as u64));
    for width in [64, 256] {
        let mlp = network(width);
        group.bench_function(format!("mlp_8x{width}_values_and_gradients"), |b| {
            b.iter(|| evaluate_with_gradients(&mlp, &points))
        });
        let mut values = vec![0.0; points.len()];
        group.bench_function(format!("mlp_8x{width}_values"), |b| {
            b.iter(|| mlp.values(&points, &mut values))
        });
    }
    // icosphere(6): 40,962 vertices / 81,920 faces; level 5 has 20,480 faces. The loss reads
    // vertices only: 25,002 vertices is the vertex count of a closed genus-0 50k-face mesh.
    let sphere = icosphere(6);
    let vertices: Vec<DVec3> = sphere.positions()[..25_002].to_vec();
    let mut loss = SdfLoss::new(Arc::new(network(64)), SdfLossOptions::default());
    loss.set_iteration(500);
    group.throughput(Throughput::Elements(vertices.len() as u64));
    group.bench_function("sdf_loss_50k_faces_mlp_8x64", |b| {
        b.iter(|| loss.value_and_grad(&vertices, &[]).unwrap())
    });
    group.finish();
}

criterion_group!(benches, sdf_benches);
criterion_main!(benches);
