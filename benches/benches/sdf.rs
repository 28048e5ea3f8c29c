//! SDF inputs: batched network evaluation (values with input gradients, in points per second)
//! for 8 × 64 and 8 × 256 sequential MLPs with random weights and for an IDR-sized implicit
//! network (8 × 256, positional encoding with 6 frequencies, a skip into layer 4, softplus β
//! 100), read from a `.safetensors` file the bench writes; and one SDF-loss evaluation on the
//! 25,002 vertices of a 50,000-face mesh (a subdivided sphere) over the 8 × 64 network; and
//! the tracer's normal maps of the drilled box example, sampled as the pipeline samples it, from
//! 6 views at 256².

use std::sync::Arc;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_loss::{Loss, SdfLoss, SdfLossOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{Aabb, Sdf, evaluate_with_gradients};
use roar_render::star_cameras;
use roar_sdf::{
    Activation, AnalyticSdf, Mlp, SampleOptions, SampledSdf, TraceOptions, trace_normal_maps,
};

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

/// IDR's geometry network at its paper size (`d_hidden` 256, `n_layers` 8, `skip_in` [4],
/// `multires` 6) with random weights, written as a PyTorch state dict in `.safetensors` with
/// its sidecar, and read back as `roar reconstruct` reads it.
fn idr_network() -> Mlp {
    let (width, layers, skip, multires) = (256usize, 8usize, 4usize, 6usize);
    let encoded = 3 * (1 + 2 * multires);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut tensors: Vec<(String, Vec<usize>, Vec<u8>)> = Vec::new();
    for l in 0..=layers {
        let inputs = if l == 0 { encoded } else { width };
        let outputs = match l {
            l if l == layers => 1,
            l if l + 1 == skip => width - encoded,
            _ => width,
        };
        let scale = (2.0 / inputs as f32).sqrt();
        let mut random = |n: usize, scale: f32| -> Vec<u8> {
            (0..n)
                .flat_map(|_| (scale * rng.random_range(-1.0f32..1.0)).to_le_bytes())
                .collect()
        };
        tensors.push((
            format!("lin{l}.weight"),
            vec![outputs, inputs],
            random(outputs * inputs, scale),
        ));
        tensors.push((format!("lin{l}.bias"), vec![outputs], random(outputs, 0.1)));
    }
    let views = tensors.iter().map(|(name, shape, bytes)| {
        let view =
            safetensors::tensor::TensorView::new(safetensors::Dtype::F32, shape.clone(), bytes)
                .expect("a tensor view");
        (name.clone(), view)
    });
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("idr.safetensors");
    safetensors::tensor::serialize_to_file(views, None, &path).expect("writing the network");
    let sidecar = format!(
        "{{\"d_hidden\": {width}, \"n_layers\": {layers}, \"skip_in\": [{skip}], \"multires\": {multires}}}"
    );
    std::fs::write(dir.path().join("idr.json"), sidecar).expect("writing the sidecar");
    roar_sdf::implicit_network::read_implicit_network(&path)
        .expect("reading the network back")
        .0
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
    let idr = idr_network();
    group.bench_function("idr_8x256_multires6_values_and_gradients", |b| {
        b.iter(|| evaluate_with_gradients(&idr, &points))
    });
    let mut values = vec![0.0; points.len()];
    group.bench_function("idr_8x256_multires6_values", |b| {
        b.iter(|| idr.values(&points, &mut values))
    });
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

    let drilled = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/drilled_box.sdf.toml"),
    )
    .expect("the drilled box example");
    let field = AnalyticSdf::from_toml(&drilled).expect("the drilled box parses");
    let bounds = Aabb {
        min: DVec3::splat(-0.9),
        max: DVec3::splat(0.9),
    };
    let (sampled, _) = SampledSdf::build(&field, bounds, &SampleOptions::for_resolution(256, 0.5))
        .expect("the drilled box samples");
    let cameras = star_cameras(3, 2, 256, 256);
    let mut group = c.benchmark_group("trace");
    group.sample_size(10);
    group.bench_function("drilled_box_sampled_6_views_256", |b| {
        b.iter(|| trace_normal_maps(&sampled, &bounds, &cameras, &TraceOptions::default()))
    });
    group.finish();
}

criterion_group!(benches, sdf_benches);
criterion_main!(benches);
