//! The SDF readers: gradients against finite differences, one-line errors for bad files, and
//! the tracer and projectors on fields with a known zero set.

use std::io::Cursor;
use std::sync::Arc;

use glam::DVec3;
use ndarray::{Array1, Array2};
use ndarray_npy::NpzWriter;
use roar_mesh::spatial::{Aabb, Projector, Sdf, evaluate_with_gradients};
use roar_render::star_cameras;
use roar_sdf::{
    Activation, AnalyticSdf, Mlp, SdfError, SdfProjector, SdfProjectorOptions, TraceOptions,
    project_samples, trace_normal_maps,
};

/// Deterministic pseudo-random numbers in [-1, 1).
fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Largest |analytic − central difference| of the gradient over `points`, relative to
/// max(1, |∇f|).
fn worst_gradient_error(sdf: &dyn Sdf, points: &[DVec3], h: f64) -> f64 {
    let (_, gradients) = evaluate_with_gradients(sdf, points);
    let mut worst = 0.0_f64;
    for (p, g) in points.iter().zip(&gradients) {
        let mut fd = DVec3::ZERO;
        for axis in 0..3 {
            let e = DVec3::AXES[axis] * h;
            let mut v = [0.0; 2];
            sdf.values(&[*p + e, *p - e], &mut v);
            fd[axis] = (v[0] - v[1]) / (2.0 * h);
        }
        worst = worst.max((fd - *g).length() / g.length().max(1.0));
    }
    worst
}

const SHAPES: &str = r#"
[shape]
type = "union"
[[shape.children]]
type = "difference"
[[shape.children.children]]
type = "box"
half_extents = [0.5, 0.4, 0.3]
rotate = [10, 20, 30]
[[shape.children.children]]
type = "cylinder"
radius = 0.2
half_height = 0.6
[[shape.children]]
type = "torus"
major = 0.5
minor = 0.1
translate = [0.2, 0.0, 0.7]
scale = 1.5
[[shape.children]]
type = "intersection"
translate = [-0.8, 0.0, 0.0]
[[shape.children.children]]
type = "sphere"
radius = 0.3
[[shape.children.children]]
type = "capsule"
radius = 0.15
half_height = 0.3
rotate = [90, 0, 0]
"#;

#[test]
fn analytic_gradients_match_finite_differences() {
    let sdf = AnalyticSdf::from_toml(SHAPES).unwrap();
    let mut r = rng(1);
    let points: Vec<DVec3> = (0..2000).map(|_| 1.3 * DVec3::new(r(), r(), r())).collect();
    // Central differences straddle a kink of a min/max or a box edge at a few points: allow
    // those few, but the bulk must match closely.
    let (_, gradients) = evaluate_with_gradients(&sdf, &points);
    let mut bad = 0;
    for (p, g) in points.iter().zip(&gradients) {
        if worst_gradient_error(&sdf, &[*p], 1e-6) > 1e-4 {
            bad += 1;
        }
        assert!(
            (g.length() - 1.0).abs() < 1e-9,
            "not a distance gradient at {p}"
        );
    }
    assert!(bad < 20, "{bad} of 2000 gradients off");
    // Known values: inside the box's solid part, on the torus tube, in the drilled hole.
    let mut v = [0.0; 3];
    sdf.values(
        &[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.35, 0.0, 0.0),
            DVec3::new(-0.8, 0.0, 0.0),
        ],
        &mut v,
    );
    assert!(v[0] > 0.0, "the cylinder drills the box's centre: {}", v[0]);
    assert!(
        v[2] < 0.0,
        "the sphere ∩ capsule holds its centre: {}",
        v[2]
    );
    assert_eq!(sdf.evaluations().values, 2000 * 6 + 3);
    assert_eq!(sdf.evaluations().gradients, 2000 * 2);
}

#[test]
fn bad_sdf_toml_files_get_one_line_errors_naming_the_node() {
    let cases = [
        ("[shape]\ntype = \"cone\"\n", "unknown type 'cone'"),
        ("[shape]\ntype = \"sphere\"\n", "needs `radius`"),
        (
            "[shape]\ntype = \"sphere\"\nradius = -1\n",
            "radius must be finite and > 0",
        ),
        (
            "[shape]\ntype = \"sphere\"\nradius = 1\nminor = 2\n",
            "has no field `minor`",
        ),
        (
            "[shape]\ntype = \"union\"\n[[shape.children]]\ntype = \"box\"\n",
            "shape.children[0]: a box needs `half_extents`",
        ),
        (
            "[shape]\ntype = \"union\"\nchildren = []\n",
            "at least one child",
        ),
        (
            "[shape]\ntype = \"sphere\"\nradius = 1\nradiuss = 2\n",
            "unknown field",
        ),
        ("shape = 3", "invalid type"),
    ];
    for (text, expected) in cases {
        let message = AnalyticSdf::from_toml(text).unwrap_err().to_string();
        assert!(message.contains(expected), "{text:?}: {message}");
        assert!(!message.contains('\n'), "{message}");
    }
}

/// A random MLP 3 → width → … → 1 with `hidden` hidden layers.
fn random_layers(width: usize, hidden: usize, seed: u64) -> Vec<(Array2<f32>, Array1<f32>)> {
    let mut r = rng(seed);
    let mut sizes = vec![3];
    sizes.extend(std::iter::repeat_n(width, hidden));
    sizes.push(1);
    sizes
        .windows(2)
        .map(|w| {
            let scale = (2.0 / w[0] as f64).sqrt();
            (
                Array2::from_shape_fn((w[0], w[1]), |_| (scale * r()) as f32),
                Array1::from_shape_fn(w[1], |_| (0.1 * r()) as f32),
            )
        })
        .collect()
}

#[test]
fn network_gradients_match_finite_differences() {
    let mut r = rng(7);
    let points: Vec<DVec3> = (0..300).map(|_| DVec3::new(r(), r(), r())).collect();
    for activation in [
        Activation::Elu,
        Activation::Softplus { beta: 1.0 },
        Activation::Softplus { beta: 100.0 },
        Activation::Tanh,
        Activation::Sin,
        Activation::Relu,
    ] {
        let mlp = Mlp::from_layers(random_layers(32, 4, 3), activation);
        // f32 inside: a step of 1e-3 keeps rounding (≈ 1e-7 / 1e-3) well under the tolerance.
        // A difference across a ReLU kink is not a derivative: a few such points are allowed.
        let errors: Vec<f64> = points
            .iter()
            .map(|p| worst_gradient_error(&mlp, &[*p], 1e-3))
            .collect();
        let bad = errors.iter().filter(|&&e| e > 1e-2).count();
        let allowed = if activation == Activation::Relu {
            15
        } else {
            0
        };
        println!("{activation:?}: {bad} of 300 gradients off by more than 1e-2");
        assert!(bad <= allowed, "{activation:?}: {bad} gradients off");
    }
}

/// The npz bytes of `tensors` (name, array) in order.
fn npz(tensors: &[(&str, ndarray::ArrayD<f32>)]) -> Vec<u8> {
    let mut writer = NpzWriter::new(Cursor::new(Vec::new()));
    for (name, array) in tensors {
        writer.add_array(*name, array).unwrap();
    }
    writer.finish().unwrap().into_inner()
}

/// The sequential keys of a 3 → 4 → 1 network, with `edit` applied.
fn small_network(edit: impl Fn(&mut Vec<(&'static str, ndarray::ArrayD<f32>)>)) -> Vec<u8> {
    let a0 = Array2::<f32>::from_elem((3, 4), 0.5).into_dyn();
    let b0 = Array1::<f32>::zeros(4).into_dyn();
    let a1 = Array2::<f32>::from_elem((4, 1), 0.5).into_dyn();
    let b1 = Array1::<f32>::zeros(1).into_dyn();
    let empty = Array1::<f32>::zeros(0).into_dyn();
    let mut tensors = vec![
        ("0000.dense.A", a0),
        ("0000.dense.b", b0),
        ("0001.elu._", empty.clone()),
        ("0002.dense.A", a1),
        ("0002.dense.b", b1),
        ("0003.squeeze_last._", empty),
    ];
    edit(&mut tensors);
    npz(&tensors)
}

fn load_error(bytes: Vec<u8>) -> String {
    let error = Mlp::from_npz(Cursor::new(bytes)).unwrap_err();
    assert!(matches!(error, SdfError::Network(_)));
    let message = error.to_string();
    assert!(!message.contains('\n'), "{message}");
    message
}

#[test]
fn bad_network_files_get_one_line_errors_naming_the_tensor() {
    // The unedited network loads and computes x·A + b through elu.
    let good = Mlp::from_npz(Cursor::new(small_network(|_| {}))).unwrap();
    let mut v = [0.0];
    good.values(&[DVec3::new(1.0, 0.0, 0.0)], &mut v);
    assert!((v[0] - 4.0 * 0.5 * 0.5).abs() < 1e-6, "{}", v[0]);

    let wrong = load_error(small_network(|t| {
        t[3].1 = Array2::<f32>::zeros((5, 1)).into_dyn();
    }));
    assert!(
        wrong.contains("0002.dense.A is 5 × 1 but its input has 4 values"),
        "{wrong}"
    );
    let bias = load_error(small_network(|t| {
        t[1].1 = Array1::<f32>::zeros(3).into_dyn();
    }));
    assert!(
        bias.contains("0000.dense.b has 3 values but 0000.dense.A has 4 columns"),
        "{bias}"
    );
    let missing = load_error(small_network(|t| {
        t.remove(4);
    }));
    assert!(missing.contains("0002.dense.b is missing"), "{missing}");
    let nan = load_error(small_network(|t| {
        t[0].1[[1, 2]] = f32::NAN;
    }));
    assert!(nan.contains("0000.dense.A holds NaN at [1, 2]"), "{nan}");
    let dims = load_error(small_network(|t| {
        t[0].1 = ndarray::Array3::<f32>::zeros((3, 4, 1)).into_dyn();
    }));
    assert!(dims.contains("0000.dense.A has shape [3, 4, 1]"), "{dims}");
    let unknown = load_error(small_network(|t| t[2].0 = "0001.gelu._"));
    assert!(
        unknown.contains("0001.gelu._: unknown layer 'gelu'"),
        "{unknown}"
    );
    let input = load_error(small_network(|t| {
        t[0].1 = Array2::<f32>::zeros((2, 4)).into_dyn();
    }));
    assert!(input.contains("its input has 3 values"), "{input}");
    let bytes = small_network(|_| {});
    let truncated = load_error(bytes[..bytes.len() / 2].to_vec());
    assert!(truncated.contains("npz"), "{truncated}");
    let not_zip = load_error(b"hello".to_vec());
    assert!(not_zip.contains("not an npz file"), "{not_zip}");
}

#[test]
fn traced_normal_maps_of_a_sphere_hit_it_with_its_normals() {
    let sdf = AnalyticSdf::from_toml("[shape]\ntype = \"sphere\"\nradius = 0.6\n").unwrap();
    let bounds = Aabb {
        min: DVec3::splat(-0.9),
        max: DVec3::splat(0.9),
    };
    let cameras = star_cameras(2, 2, 48, 48);
    let (images, stats) = trace_normal_maps(&sdf, &bounds, &cameras, &TraceOptions::default());
    assert_eq!(images.len(), 4);
    assert_eq!(stats.rays, 4 * 48 * 48);
    // Grazing rays at the silhouette whose grid bracket the sphere does not confirm stay
    // background: a sliver of the silhouette.
    assert!(
        stats.hits > 0 && stats.unconfirmed * 30 < stats.hits,
        "{stats:?}"
    );
    // Each hit pixel's normal faces its camera; the covered fraction is the sphere's disc
    // seen from distance 10 through the rig's frustum (half-extent 1 at distance 10).
    for (image, camera) in images.iter().zip(&cameras) {
        let covered = image.iter().filter(|p| p[3] > 0.0).count() as f64;
        let expected = std::f64::consts::PI * 0.6 * 0.6 / 4.0 * (48.0 * 48.0);
        assert!(
            (covered / expected - 1.0).abs() < 0.1,
            "{covered} vs {expected}"
        );
        let to_camera = camera.position().normalize();
        for p in image.iter().filter(|p| p[3] > 0.0) {
            let n = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            assert!((n.length() - 1.0).abs() < 1e-5 && n.dot(to_camera) > 0.0);
        }
    }
    assert_eq!(stats.gradient_evaluations, stats.hits);
}

#[test]
fn projectors_land_on_the_zero_set_of_a_scaled_field() {
    // A sphere field scaled by 4000 (like the hammer network): steps must use f/|∇f|.
    let text = "[shape]\ntype = \"sphere\"\nradius = 0.5\nscale = 1.0\n";
    let base = Arc::new(AnalyticSdf::from_toml(text).unwrap());
    let scaled = roar_mesh::spatial::FnSdf::new(move |p: DVec3| {
        let mut v = [0.0];
        base.values(&[p], &mut v);
        4000.0 * v[0]
    });
    let mut r = rng(5);
    let points: Vec<DVec3> = (0..200)
        .map(|_| DVec3::new(r(), r(), r()).normalize() * (0.5 + 0.1 * r()))
        .collect();
    let (kept, normals) = project_samples(&scaled, points.clone(), 5, 1e-6);
    assert_eq!(kept.len(), 200);
    for (p, n) in kept.iter().zip(&normals) {
        assert!((p.length() - 0.5).abs() < 1e-6 && (n.dot(p.normalize()) - 1.0).abs() < 1e-6);
    }
    let projector = SdfProjector {
        sdf: Arc::new(scaled),
        options: SdfProjectorOptions::default(),
    };
    let normals: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
    let projected = projector.project(&[], &[], &points, &normals);
    for q in &projected {
        let q = q.expect("a radial sample converges");
        assert!((q.length() - 0.5).abs() < 1e-5);
    }
    // Along a tangent direction a sample cannot reach the sphere: invalid.
    let tangent = [DVec3::new(0.0, 1.0, 0.0)];
    assert_eq!(
        projector.project(&[], &[], &[DVec3::new(0.7, 0.0, 0.0)], &tangent),
        vec![None]
    );
}

#[test]
fn the_field_projector_stops_a_sample_once_it_is_within_the_tolerance() {
    let text = "[shape]\ntype = \"sphere\"\nradius = 0.5\nscale = 1.0\n";
    let sphere = Arc::new(AnalyticSdf::from_toml(text).unwrap());
    let projector = SdfProjector {
        sdf: sphere.clone(),
        options: SdfProjectorOptions::default(),
    };
    // On the sphere: kept where it is after one evaluation. Off it, radially: one step lands
    // it (the field is a true distance), a second evaluation confirms it. Tangent: every step
    // and a last check, then invalid.
    let x = DVec3::X;
    let points = [0.5 * x, 0.8 * x, 0.7 * x];
    let normals = [x, x, DVec3::Y];
    let projected = projector.project(&[], &[], &points, &normals);
    assert_eq!(projected[0], Some(0.5 * x));
    assert!((projected[1].unwrap() - 0.5 * x).length() < 1e-9);
    assert_eq!(projected[2], None);
    let steps = SdfProjectorOptions::default().steps as u64;
    assert_eq!(sphere.evaluations().gradients, 1 + 2 + (steps + 1));
}
