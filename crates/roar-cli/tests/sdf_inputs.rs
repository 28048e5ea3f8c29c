//! SDF inputs through the CLI and the pipeline: the SDF schedule's defaults, one-line errors
//! for bad files with no output, and (release, run by `.ci/run` with `--ignored`) reduced
//! reconstructions of analytic shapes, of a dense grid and of the two shared neural SDFs, each a closed,
//! oriented 2-manifold with exactly the budget, no self-intersecting faces and its vertices near
//! the zero set.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

use glam::DVec3;
use roar::shapes::sdf::DEFAULT_BOUNDS;
use roar::{ReconstructConfig, Reconstruction, SdfShape};
use roar_mesh::Mesh;
use roar_mesh::spatial::{
    Aabb, Sdf, TriangleBvh, evaluate_with_gradients, self_intersecting_faces,
};
use roar_sdf::{AnalyticSdf, load_sdf, load_sdf_input};

fn roar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_roar"))
        .args(args)
        .output()
        .expect("roar runs")
}

#[test]
fn print_config_of_an_sdf_input_gives_the_sdf_schedule() {
    let dir = tempfile::tempdir().unwrap();
    let shape = dir.path().join("ball.sdf.toml");
    std::fs::write(&shape, "[shape]\ntype = \"sphere\"\nradius = 0.5\n").unwrap();
    let out = roar(&["reconstruct", shape.to_str().unwrap(), "--print-config"]);
    assert!(out.status.success());
    let config: ReconstructConfig = toml::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!(config, ReconstructConfig::sdf_defaults());
    assert_eq!((config.optimize.iterations, config.faces), (150, 50_000));
    assert_eq!(
        (config.loss.sdf_loss_weight, config.loss.sdf_loss_start),
        (0.1, 100)
    );
    // A config file's keys go over the SDF defaults, not the soup's.
    let file = dir.path().join("c.toml");
    std::fs::write(&file, "faces = 1000\n").unwrap();
    let out = roar(&[
        "reconstruct",
        shape.to_str().unwrap(),
        "--print-config",
        "--config",
    ])
    .status;
    assert!(!out.success(), "--config needs a value");
    let out = roar(&[
        "reconstruct",
        shape.to_str().unwrap(),
        "--print-config",
        "--config",
        file.to_str().unwrap(),
    ]);
    let config: ReconstructConfig = toml::from_str(&String::from_utf8_lossy(&out.stdout)).unwrap();
    assert_eq!((config.optimize.iterations, config.faces), (150, 1000));
}

#[test]
fn bad_sdf_files_fail_in_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let flat = npy_f32(&[4, 4], &[0.0; 16], false);
    let mut holed = vec![1.0f32; 27];
    holed[5] = f32::NAN;
    let holed = npy_f32(&[3, 3, 3], &holed, false);
    let cases: [(&str, &[u8], &str); 6] = [
        ("flat.npy", &flat, "has 2 axes [4, 4]"),
        ("holed.npy", &holed, "NaN at [0, 1, 2]"),
        (
            "cone.sdf.toml",
            b"[shape]\ntype = \"cone\"\n",
            "unknown type 'cone'",
        ),
        ("junk.npz", b"PK\x03\x04 truncated", "npz"),
        ("empty.npz", b"", "npz"),
        (
            "alone.safetensors",
            b"\x08\0\0\0\0\0\0\0{}      ",
            "alone.json",
        ),
    ];
    for (name, bytes, expected) in cases {
        let input = dir.path().join(name);
        std::fs::write(&input, bytes).unwrap();
        let output = dir.path().join("out.obj");
        let out = roar(&[
            "reconstruct",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
            "--faces",
            "200",
            "-q",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}");
        assert!(stderr.contains(expected), "{name}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{name}: {stderr}");
        assert!(!output.exists(), "{name}: wrote an output");
    }
    let out = roar(&[
        "reconstruct",
        "x.sdf.toml",
        "-o",
        "o.obj",
        "--bounds",
        "0,0,0,1,1",
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("six numbers"));
}

/// The bytes of an `.npy` file (format 1.0, little-endian float32) of `shape`, holding `values`
/// in C order, or in Fortran order when `fortran` (written here, not by the reader's crate).
fn npy_f32(shape: &[usize], values: &[f32], fortran: bool) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
    let mut header = format!(
        "{{'descr': '<f4', 'fortran_order': {}, 'shape': ({},), }}",
        if fortran { "True" } else { "False" },
        dims.join(", ")
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    for v in values {
        bytes.extend(v.to_le_bytes());
    }
    bytes
}

/// Toy settings for an SDF input at `faces`, with the SDF loss on for the second half; the Face
/// Split block projects onto the field when `split_projector` (costly on a network: about 3
/// gradient evaluations per sample of every face, every `split_interval` iterations).
fn toy_sdf_config(faces: usize, split_projector: bool) -> ReconstructConfig {
    let iterations = 30;
    {
        let mut config = common::toy_config(faces, iterations);
        config.target.sdf_trace_grid = 64;
        config.loss.sdf_loss_start = iterations / 2;
        config.optimize.sdf_split_projector = split_projector;
        config
    }
}

/// What a reduced run gives: checked closed, exact, intersection-free; returns the mesh and
/// the mean, 99th percentile and largest first-order distance `|f|/|∇f|` of its vertices from
/// the zero set.
fn reconstruct(
    field: Arc<dyn Sdf>,
    bounds: Aabb,
    faces: usize,
    split_projector: bool,
) -> (Mesh, [f64; 3]) {
    let config = toy_sdf_config(faces, split_projector);
    let mut shape = SdfShape::new("test", field.clone(), bounds, &config);
    let out = Reconstruction::new(config)
        .run(&mut shape, &mut |_| {})
        .unwrap();
    assert_eq!(out.triangles.len(), faces);
    let intersecting = self_intersecting_faces(&out.positions, &out.triangles);
    assert!(!intersecting.contains(&true), "self-intersecting faces");
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles)
        .expect("a closed, oriented 2-manifold");
    // The run's counts, before the distances below evaluate the field.
    let report = shape.report();
    let (values, gradients) = evaluate_with_gradients(field.as_ref(), &out.positions);
    let mut distances: Vec<f64> = values
        .iter()
        .zip(&gradients)
        .map(|(f, g)| f.abs() / g.length())
        .collect();
    distances.sort_by(f64::total_cmp);
    let mean = distances.iter().sum::<f64>() / distances.len() as f64;
    let p99 = distances[distances.len() * 99 / 100];
    let max = distances[distances.len() - 1];
    println!(
        "{faces} faces: genus {}, zero-set distance mean {mean:.2e} p99 {p99:.2e} max {max:.2e}; \
         evaluations {:?} {:?}; sampled-field queries {:?} {:?}; trace {:.2} s",
        mesh.genus(),
        report.values,
        report.gradients,
        report.sampled_values,
        report.sampled_gradients,
        report.trace_seconds
    );
    // The field is evaluated by the sampling alone, within a 128³ grid's count, and every later
    // stage reads the samples.
    let sampled = report
        .sample
        .expect("the field is sampled")
        .field_evaluations as u64;
    let total: u64 = report.values.values().sum::<u64>() + report.gradients.values().sum::<u64>();
    assert_eq!(total, sampled, "field evaluations outside the sampling");
    assert!(total <= 2_100_000, "{total} field evaluations");
    (mesh, [mean, p99, max])
}

#[test]
#[ignore = "release: reduced SDF reconstructions (run by .ci/run)"]
fn analytic_box_minus_cylinder_has_genus_one_and_a_sphere_is_within_one_percent() {
    // The shipped example, as a user runs it.
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/drilled_box.sdf.toml");
    let drilled = AnalyticSdf::from_toml(&std::fs::read_to_string(example).unwrap()).unwrap();
    let (mesh, _) = reconstruct(Arc::new(drilled), DEFAULT_BOUNDS, 2000, true);
    assert_eq!(mesh.genus(), 1);

    let radius = 0.7;
    let sphere = AnalyticSdf::from_toml(&format!(
        "[shape]\ntype = \"sphere\"\nradius = {radius}\ntranslate = [0.3, -0.2, 0.1]\n"
    ))
    .unwrap();
    let bounds = Aabb {
        min: DVec3::new(-0.6, -1.0, -0.7),
        max: DVec3::new(1.1, 0.6, 0.9),
    };
    let (mesh, [_, _, max]) = reconstruct(Arc::new(sphere), bounds, 1000, true);
    assert_eq!(mesh.genus(), 0);
    let diagonal = 2.0 * radius * 3f64.sqrt();
    assert!(
        max < 0.01 * diagonal,
        "farthest vertex {max} off the sphere"
    );
}

#[test]
#[ignore = "release: reduced SDF reconstructions (run by .ci/run)"]
fn the_finish_fits_the_mesh_to_the_zero_set() {
    let torus: Arc<dyn Sdf> = Arc::new(
        AnalyticSdf::from_toml("[shape]\ntype = \"torus\"\nmajor = 0.6\nminor = 0.25\n").unwrap(),
    );
    // The first-order distance of the output's surface from the zero set, sampled at every
    // face's corners, edge midpoints and centroid: its mean (the bias) and its mean magnitude;
    // and how many vertices the fit moved the whole way, of how many.
    let distances = |zero_set_steps: usize| {
        let mut config = toy_sdf_config(4000, false);
        config.finish.zero_set_steps = zero_set_steps;
        let mut shape = SdfShape::new("torus", torus.clone(), DEFAULT_BOUNDS, &config);
        let out = Reconstruction::new(config)
            .run(&mut shape, &mut |_| {})
            .unwrap();
        assert_eq!(out.triangles.len(), 4000);
        assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
        let samples: Vec<DVec3> = out
            .triangles
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.map(|i| out.positions[i as usize]);
                [
                    a,
                    b,
                    c,
                    (a + b) / 2.0,
                    (b + c) / 2.0,
                    (c + a) / 2.0,
                    (a + b + c) / 3.0,
                ]
            })
            .collect();
        let (values, gradients) = evaluate_with_gradients(torus.as_ref(), &samples);
        let signed: Vec<f64> = values
            .iter()
            .zip(&gradients)
            .map(|(f, g)| f / g.length())
            .collect();
        let n = signed.len() as f64;
        let bias = signed.iter().sum::<f64>() / n;
        let magnitude = signed.iter().map(|d| d.abs()).sum::<f64>() / n;
        let fitted = out.stats.finish.zero_set_fitted;
        (bias, magnitude, fitted, out.positions.len())
    };
    let (bias_off, off, fitted_off, _) = distances(0);
    let (bias_on, on, fitted, vertices) = distances(3);
    // Measured: bias 2.4e-3 → 5.8e-4, magnitude 3.1e-3 → 1.6e-3; 1810 of 2000 vertices fitted.
    println!(
        "bias {bias_off:.2e} → {bias_on:.2e}, magnitude {off:.2e} → {on:.2e}; {fitted} of \
         {vertices} fitted"
    );
    assert_eq!(fitted_off, 0);
    assert!(fitted > vertices / 2, "{fitted} of {vertices}");
    assert!(
        bias_on.abs() < 0.35 * bias_off.abs(),
        "{bias_on} against {bias_off}"
    );
    assert!(on < 0.6 * off, "{on} against {off}");
}

#[test]
#[ignore = "release: a reduced reconstruction of a dense grid (run by .ci/run)"]
fn a_dense_grid_of_a_sphere_reconstructs_within_one_percent() {
    // |p − c| − r sampled on a 40 × 36 × 38 grid (Fortran order) over the sidecar's bounds.
    let (centre, radius) = (DVec3::new(0.2, -0.1, 0.15), 0.65);
    let bounds = Aabb {
        min: DVec3::new(-0.7, -1.0, -0.8),
        max: DVec3::new(1.1, 0.9, 1.0),
    };
    let n = [40, 36, 38];
    let mut values = Vec::with_capacity(n[0] * n[1] * n[2]);
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let t = DVec3::new(i as f64, j as f64, k as f64)
                    / DVec3::new((n[0] - 1) as f64, (n[1] - 1) as f64, (n[2] - 1) as f64);
                let p = bounds.min + t * (bounds.max - bounds.min);
                values.push(((p - centre).length() - radius) as f32);
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ball.npy");
    std::fs::write(&path, npy_f32(&n, &values, true)).unwrap();
    std::fs::write(
        dir.path().join("ball.json"),
        r#"{"min": [-0.7, -1.0, -0.8], "max": [1.1, 0.9, 1.0]}"#,
    )
    .unwrap();
    let input = load_sdf_input(&path, DEFAULT_BOUNDS).unwrap();
    assert_eq!(input.bounds, Some(bounds));
    let (mesh, _) = reconstruct(input.field, bounds, 1000, true);
    assert_eq!(mesh.genus(), 0);
    let diagonal = 2.0 * radius * 3f64.sqrt();
    let farthest = mesh
        .vertices()
        .map(|v| ((mesh.position(v) - centre).length() - radius).abs())
        .fold(0.0, f64::max);
    println!(
        "grid sphere: farthest vertex {:.2e} of the diagonal",
        farthest / diagonal
    );
    assert!(
        farthest < 0.01 * diagonal,
        "farthest vertex {farthest} off the sphere"
    );
}

#[test]
#[ignore = "release: a reduced reconstruction of an IDR network from Python (run by .ci/run)"]
fn an_implicit_network_written_by_python_reconstructs_within_one_percent_of_its_zero_set() {
    // IDR's geometric init (|x| − 0.5 at infinite width) with weight norm, from
    // scripts/make_implicit_fixture.py; its zero set, found by numpy along 400 rays, is a blob
    // of radius 0.35–0.74, so the reconstruction is held to that, not to the ideal sphere.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../roar-sdf/tests/data/implicit-sphere.safetensors");
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(path.with_extension("reference.json")).unwrap(),
    )
    .unwrap();
    let surface: Vec<DVec3> = reference["zero_set"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            DVec3::new(
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            )
        })
        .collect();
    let input = load_sdf_input(&path, DEFAULT_BOUNDS).unwrap();
    let (mesh, [mean, _, _]) = reconstruct(input.field, DEFAULT_BOUNDS, 1000, true);
    assert_eq!(mesh.genus(), 0);
    let (positions, triangles) = mesh.to_triangles();
    let bvh = TriangleBvh::build(&positions, &triangles);
    let extent = Aabb::from_points(surface.iter().copied()).unwrap();
    let diagonal = (extent.max - extent.min).length();
    let farthest = surface
        .iter()
        .map(|p| bvh.closest_point(*p).unwrap().distance_squared.sqrt())
        .fold(0.0, f64::max);
    println!(
        "python network: numpy's zero set at most {:.2e} of the diagonal from the mesh, \
         vertices {:.2e} from the zero set on average",
        farthest / diagonal,
        mean / diagonal
    );
    assert!(
        farthest < 0.01 * diagonal,
        "numpy's zero set {farthest} from the mesh"
    );
    assert!(mean < 0.01 * diagonal);
}

/// The shared neural SDFs, or `None` (with a note) outside CI when `ROAR_SDF_DATA` is unset.
fn sdf_data() -> Option<PathBuf> {
    let Some(root) = std::env::var_os("ROAR_SDF_DATA") else {
        assert!(
            std::env::var_os("CI").is_none(),
            "ROAR_SDF_DATA must be set under CI"
        );
        eprintln!("ROAR_SDF_DATA is unset: skipping the shared neural SDFs");
        return None;
    };
    Some(PathBuf::from(root))
}

#[test]
#[ignore = "release: reduced reconstructions of the shared neural SDFs (run by .ci/run)"]
fn shared_neural_sdfs_reconstruct_closed_exact_and_near_their_zero_sets() {
    let Some(root) = sdf_data() else { return };
    for name in ["nif-bunny.npz", "nif-hammer.npz"] {
        let field = load_sdf(&Path::new(&root).join(name)).unwrap();
        let (mesh, [mean, p99, max]) = reconstruct(field, DEFAULT_BOUNDS, 2000, false);
        assert_eq!(mesh.genus(), 0, "{name}: its zero set has genus 0");
        // Against the bounds' diagonal (3.8). Measured with these toy settings: mean 1.0e-3
        // (bunny) and 7.2e-4 (hammer) of it, 99th percentile 4.2e-3 and 3.9e-3; the largest,
        // 2.5e-2 on the hammer, is a vertex of a thin part that the toy run's coarse renders
        // and few iterations leave off the surface.
        let diagonal = DEFAULT_BOUNDS.diagonal();
        println!(
            "{name}: mean {:.2e} p99 {:.2e} max {:.2e} of the diagonal",
            mean / diagonal,
            p99 / diagonal,
            max / diagonal
        );
        assert!(mean < 2e-3 * diagonal, "{name}: mean {mean}");
        assert!(p99 < 1e-2 * diagonal, "{name}: 99th percentile {p99}");
    }
}

#[test]
fn extract_writes_the_closed_zero_set_and_reports_its_evaluations() {
    let dir = tempfile::tempdir().unwrap();
    let shape = dir.path().join("ring.sdf.toml");
    std::fs::write(
        &shape,
        "[shape]\ntype = \"torus\"\nmajor = 0.6\nminor = 0.25\n",
    )
    .unwrap();
    let output = dir.path().join("ring.obj");
    let out = roar(&[
        "extract",
        shape.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--resolution",
        "24",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(line["dims"], serde_json::json!([24, 24, 24]));
    assert_eq!(
        (line["values"].as_u64(), line["gradients"].as_u64()),
        (Some(24 * 24 * 24), Some(0))
    );
    let soup = roar_io::read_mesh(&output).unwrap();
    assert_eq!(soup.triangles.len() as u64, line["faces"].as_u64().unwrap());
    let mesh = Mesh::from_triangles(soup.positions, &soup.triangles).expect("closed manifold");
    assert_eq!(mesh.genus(), 1);
    // A field with no zero set in the bounds, and an unreadable field: one line, no output.
    std::fs::write(
        &shape,
        "[shape]\ntype = \"sphere\"\nradius = 0.5\ntranslate = [5, 0, 0]\n",
    )
    .unwrap();
    let cone = dir.path().join("cone.sdf.toml");
    std::fs::write(&cone, "[shape]\ntype = \"cone\"\n").unwrap();
    for (input, expected) in [(&shape, "no zero set"), (&cone, "unknown type 'cone'")] {
        let output = dir.path().join("none.obj");
        let out = roar(&[
            "extract",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
            "--resolution",
            "8",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(stderr.contains(expected), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!output.exists());
    }
}
