//! The `.safetensors` reader of IDR/VolSDF/NeuS implicit networks: values against numpy's
//! (`tests/data/implicit-sphere.*`, written by `scripts/make_implicit_fixture.py` with the
//! Python `safetensors` package), the three ways PyTorch stores a weight, gradients against
//! finite differences, and one-line errors for bad files.

use std::path::{Path, PathBuf};

use glam::DVec3;
use roar_mesh::spatial::{Sdf, evaluate_with_gradients};
use roar_sdf::{SdfError, load_sdf_input};
use safetensors::SafeTensors;
use serde_json::{Value, json};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/implicit-sphere.safetensors")
}

fn reference() -> Value {
    let text = std::fs::read_to_string(fixture().with_extension("reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn points(value: &Value) -> Vec<DVec3> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p: Vec<f64> = serde_json::from_value(p.clone()).unwrap();
            DVec3::new(p[0], p[1], p[2])
        })
        .collect()
}

fn values_at(sdf: &dyn Sdf, points: &[DVec3]) -> Vec<f64> {
    let mut values = vec![0.0; points.len()];
    sdf.values(points, &mut values);
    values
}

/// A tensor as the tests write it: name, shape, f32 values.
type Tensor = (String, Vec<usize>, Vec<f32>);

/// The tensors of the fixture, as f32.
fn fixture_tensors() -> Vec<Tensor> {
    let bytes = std::fs::read(fixture()).unwrap();
    let file = SafeTensors::deserialize(&bytes).unwrap();
    let mut tensors: Vec<Tensor> = file
        .tensors()
        .into_iter()
        .map(|(name, view)| {
            let values = view
                .data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            (name, view.shape().to_vec(), values)
        })
        .collect();
    tensors.sort_by(|a, b| a.0.cmp(&b.0));
    tensors
}

/// The bytes of a `.safetensors` file holding `tensors` as F32 (the format written by hand:
/// an 8-byte header length, the JSON header, the data).
fn safetensors_bytes(tensors: &[Tensor]) -> Vec<u8> {
    let mut header = serde_json::Map::new();
    let mut data = Vec::new();
    for (name, shape, values) in tensors {
        let start = data.len();
        for v in values {
            data.extend_from_slice(&v.to_le_bytes());
        }
        header.insert(
            name.clone(),
            json!({"dtype": "F32", "shape": shape, "data_offsets": [start, data.len()]}),
        );
    }
    let mut header = serde_json::to_vec(&header).unwrap();
    while !header.len().is_multiple_of(8) {
        header.push(b' ');
    }
    let mut bytes = (header.len() as u64).to_le_bytes().to_vec();
    bytes.extend(header);
    bytes.extend(data);
    bytes
}

/// Writes `tensors` and `sidecar` as `dir/NAME.safetensors` and `dir/NAME.json`.
fn write_network(dir: &Path, name: &str, tensors: &[Tensor], sidecar: &str) -> PathBuf {
    let path = dir.join(format!("{name}.safetensors"));
    std::fs::write(&path, safetensors_bytes(tensors)).unwrap();
    std::fs::write(path.with_extension("json"), sidecar).unwrap();
    path
}

fn sidecar() -> String {
    std::fs::read_to_string(fixture().with_extension("json")).unwrap()
}

#[test]
fn a_network_written_by_python_gives_numpys_values() {
    let input = load_sdf_input(&fixture(), roar_sdf::DEFAULT_BOUNDS).unwrap();
    assert_eq!(input.bounds, None);
    let reference = reference();
    let points = points(&reference["points"]);
    let expected: Vec<f64> = serde_json::from_value(reference["values"].clone()).unwrap();
    let values = values_at(input.field.as_ref(), &points);
    let worst = values
        .iter()
        .zip(&expected)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "worst |roar − numpy| over {} points: {worst:.2e}",
        points.len()
    );
    // f32 inside against numpy's float64: values of order 1 agree to a few ulps times depth.
    assert!(worst < 1e-5, "worst difference {worst}");
    // numpy's zero set (bisection along rays) is the reader's zero set.
    let surface = points_on_zero_set(&reference);
    let on_surface = values_at(input.field.as_ref(), &surface);
    let worst = on_surface.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(worst < 1e-5, "|f| {worst} on numpy's zero set");
}

fn points_on_zero_set(reference: &Value) -> Vec<DVec3> {
    points(&reference["zero_set"])
}

#[test]
fn plain_weight_norm_and_parametrized_weights_give_one_network() {
    let dir = tempfile::tempdir().unwrap();
    let normed = fixture_tensors();
    // W = g·v/|v| row by row, written as a plain `weight`.
    let mut plain = Vec::new();
    let mut parametrized = Vec::new();
    for (name, shape, values) in &normed {
        if let Some(layer) = name.strip_suffix(".weight_v") {
            let g = &normed
                .iter()
                .find(|t| t.0 == format!("{layer}.weight_g"))
                .unwrap()
                .2;
            let cols = shape[1];
            let mut w = values.clone();
            for (row, g) in w.chunks_mut(cols).zip(g) {
                let norm = row.iter().map(|x| x * x).sum::<f32>().sqrt();
                row.iter_mut().for_each(|x| *x *= g / norm);
            }
            plain.push((format!("{layer}.weight"), shape.clone(), w));
            parametrized.push((
                format!("{layer}.parametrizations.weight.original1"),
                shape.clone(),
                values.clone(),
            ));
        } else if let Some(layer) = name.strip_suffix(".weight_g") {
            parametrized.push((
                format!("{layer}.parametrizations.weight.original0"),
                shape.clone(),
                values.clone(),
            ));
        } else {
            plain.push((name.clone(), shape.clone(), values.clone()));
            parametrized.push((name.clone(), shape.clone(), values.clone()));
        }
    }
    let points = points(&reference()["points"]);
    let base = values_at(
        load_sdf_input(&fixture(), roar_sdf::DEFAULT_BOUNDS)
            .unwrap()
            .field
            .as_ref(),
        &points,
    );
    for (name, tensors) in [("plain", &plain), ("parametrized", &parametrized)] {
        let path = write_network(dir.path(), name, tensors, &sidecar());
        let field = load_sdf_input(&path, roar_sdf::DEFAULT_BOUNDS)
            .unwrap()
            .field;
        let values = values_at(field.as_ref(), &points);
        let worst = values
            .iter()
            .zip(&base)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-5, "{name}: differs by {worst}");
    }
}

#[test]
fn scale_bounds_and_gradients_of_an_implicit_network() {
    let dir = tempfile::tempdir().unwrap();
    // The same weights read with scale 2: f(x) = net(2x)/2.
    let scaled = sidecar().replacen(
        "\"scale\": 1.0",
        "\"scale\": 2.0, \"bounds\": {\"min\": [-1, -1, -1], \"max\": [1, 1, 1]}",
        1,
    );
    let path = write_network(dir.path(), "scaled", &fixture_tensors(), &scaled);
    let input = load_sdf_input(&path, roar_sdf::DEFAULT_BOUNDS).unwrap();
    assert_eq!(input.bounds.unwrap().max, DVec3::ONE);
    let base = load_sdf_input(&fixture(), roar_sdf::DEFAULT_BOUNDS)
        .unwrap()
        .field;
    let points = points(&reference()["points"]);
    let doubled: Vec<DVec3> = points.iter().map(|p| 2.0 * *p).collect();
    let expected = values_at(base.as_ref(), &doubled);
    for (a, b) in values_at(input.field.as_ref(), &points)
        .iter()
        .zip(&expected)
    {
        assert!((a - b / 2.0).abs() < 1e-6, "{a} vs {b}/2");
    }
    // Gradients by backpropagation (encoding, skips, weight norm, scale) against central
    // differences; softplus with β = 100 bends sharply, so the step is small and f32 rounding
    // (≈ 1e-7 / 1e-4) bounds the agreement.
    for field in [&base, &input.field] {
        let (_, gradients) = evaluate_with_gradients(field.as_ref(), &points);
        let h = 1e-4;
        let mut worst = 0.0_f64;
        for (p, g) in points.iter().zip(&gradients) {
            let mut fd = DVec3::ZERO;
            for axis in 0..3 {
                let e = DVec3::AXES[axis] * h;
                let v = values_at(field.as_ref(), &[*p + e, *p - e]);
                fd[axis] = (v[0] - v[1]) / (2.0 * h);
            }
            worst = worst.max((fd - *g).length() / g.length().max(1.0));
        }
        println!("worst relative gradient error {worst:.2e}");
        assert!(worst < 1e-2, "gradient off by {worst}");
    }
}

#[test]
fn bad_implicit_networks_fail_in_one_line_naming_the_tensor() {
    let dir = tempfile::tempdir().unwrap();
    let tensors = fixture_tensors();
    let edit = |name: &str, change: &dyn Fn(&mut Tensor)| -> Vec<Tensor> {
        let mut edited = tensors.clone();
        change(edited.iter_mut().find(|t| t.0 == name).unwrap());
        edited
    };
    let without =
        |name: &str| -> Vec<Tensor> { tensors.iter().filter(|t| t.0 != name).cloned().collect() };
    let v1 = "implicit_network.lin1.weight_v";
    let narrow = edit(v1, &|t| {
        t.1 = vec![t.1[0], t.1[1] - 1];
        t.2.truncate(t.1[0] * t.1[1]);
    });
    let nan = edit("implicit_network.lin2.bias", &|t| t.2[3] = f32::NAN);
    let missing = without("implicit_network.lin3.bias");
    let cases: Vec<(&str, Vec<u8>, String, &str)> = vec![
        (
            "narrow",
            safetensors_bytes(&narrow),
            sidecar(),
            "implicit_network.lin1.weight_v is 37 × 63 but the layer takes 64 inputs",
        ),
        (
            "nan",
            safetensors_bytes(&nan),
            sidecar(),
            "implicit_network.lin2.bias holds NaN at flat index 3",
        ),
        (
            "missing",
            safetensors_bytes(&missing),
            sidecar(),
            "implicit_network.lin3.bias is missing",
        ),
        (
            "deeper",
            safetensors_bytes(&tensors),
            sidecar().replace("\"n_layers\": 4", "\"n_layers\": 5"),
            "implicit_network.lin4.weight_v is 9 × 64 but the layer gives 64 outputs",
        ),
        (
            "truncated",
            safetensors_bytes(&tensors)[..2000].to_vec(),
            sidecar(),
            "not a safetensors file",
        ),
        (
            "typo",
            safetensors_bytes(&tensors),
            sidecar().replace("multires", "multires_"),
            "unknown field `multires_`",
        ),
        (
            "wrong-prefix",
            safetensors_bytes(&tensors),
            sidecar().replace("\"d_in\": 3,", "\"d_in\": 3, \"prefix\": \"sdf_network.\","),
            "sdf_network.lin0.weight is missing",
        ),
    ];
    for (name, bytes, side, expected) in cases {
        let path = dir.path().join(format!("{name}.safetensors"));
        std::fs::write(&path, bytes).unwrap();
        std::fs::write(path.with_extension("json"), side).unwrap();
        let error = match load_sdf_input(&path, roar_sdf::DEFAULT_BOUNDS) {
            Ok(_) => panic!("{name}: read"),
            Err(e) => e,
        };
        assert!(matches!(error, SdfError::Network(_)), "{name}: {error:?}");
        let message = error.to_string();
        assert!(message.contains(expected), "{name}: {message}");
        assert!(!message.contains('\n'), "{name}: {message}");
    }
    // No sidecar: the error says what it must hold.
    let path = dir.path().join("alone.safetensors");
    std::fs::write(&path, safetensors_bytes(&tensors)).unwrap();
    let message = load_sdf_input(&path, roar_sdf::DEFAULT_BOUNDS)
        .err()
        .unwrap()
        .to_string();
    assert!(
        message.contains("alone.json") && message.contains("d_hidden"),
        "{message}"
    );
}
