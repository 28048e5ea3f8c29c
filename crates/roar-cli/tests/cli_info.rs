//! `roar info` and `roar eval` on every shared mesh, on the example, and on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn roar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_roar"))
        .args(args)
        .output()
        .expect("the roar binary runs")
}

/// The shared meshes, or `None` (with a note) outside CI when `ROAR_TEST_DATA` is unset.
fn shared_meshes() -> Option<Vec<PathBuf>> {
    let Some(root) = std::env::var_os("ROAR_TEST_DATA") else {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "ROAR_TEST_DATA must be set under CI"
        );
        eprintln!("ROAR_TEST_DATA is unset: skipping the shared meshes");
        return None;
    };
    let mut files = Vec::new();
    for folder in ["clean", "wild"] {
        let dir = Path::new(&root).join(folder);
        let entries = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("ROAR_TEST_DATA folder {} is missing: {e}", dir.display()));
        files.extend(entries.map(|e| e.unwrap().path()));
    }
    files.sort();
    assert!(files.len() >= 40, "expected the 44 shared meshes");
    Some(files)
}

fn assert_one_line_error(output: &Output, what: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{what}: expected a failure");
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{what}: {stderr}");
    assert!(stderr.starts_with("roar: error: "), "{what}: {stderr}");
    assert!(output.stdout.is_empty(), "{what}: no partial report");
}

#[test]
fn info_succeeds_on_every_shared_mesh() {
    let Some(files) = shared_meshes() else { return };
    for file in files {
        let output = roar(&["info", "--json", file.to_str().unwrap()]);
        assert!(
            output.status.success(),
            "{}: {}",
            file.display(),
            String::from_utf8_lossy(&output.stderr)
        );
        let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        assert!(json["faces"].as_u64().unwrap() > 0);
    }
}

#[test]
fn info_says_closed_manifold_with_genus_for_a_clean_torus_like_mesh() {
    let Some(files) = shared_meshes() else { return };
    let rocker = files
        .iter()
        .find(|f| f.ends_with("rocker-arm.obj"))
        .unwrap();
    let output = roar(&["info", "--json", rocker.to_str().unwrap()]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json["closed_manifold"], true);
    assert_eq!(json["genus"], 1);
    assert_eq!(json["components"], 1);
}

#[test]
fn info_names_the_first_reason_a_soup_is_not_manifold() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chair.obj");
    assert!(
        roar(&["example-soup", path.to_str().unwrap()])
            .status
            .success()
    );
    let output = roar(&["info", "--json", path.to_str().unwrap()]);
    assert!(output.status.success());
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json["closed_manifold"], false);
    assert!(json["not_manifold_because"].as_str().unwrap().len() > 10);
}

#[test]
fn info_reports_faces_with_fewer_than_three_corners_as_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lines.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\nf 2 3\n").unwrap();
    let output = roar(&["info", "--json", path.to_str().unwrap()]);
    assert!(output.status.success(), "{output:?}");
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json["faces"], 1);
    assert_eq!(json["faces_skipped"], 2);
    let output = roar(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("skipped   2 face(s) with fewer than 3 corners"),
        "{text}"
    );
}

#[test]
fn bad_input_gives_one_line_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.ply");
    std::fs::write(&garbage, [0x13u8, 0x37, 0xff, 0x00, 0x42].repeat(40)).unwrap();
    let truncated = dir.path().join("truncated.off");
    std::fs::write(&truncated, "OFF\n4 4 0\n0 0 0\n1 0 0\n").unwrap();
    let nan = dir.path().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n").unwrap();
    let unknown = dir.path().join("mesh.xyz");
    std::fs::write(&unknown, "v 0 0 0\n").unwrap();
    let missing = dir.path().join("missing.obj");
    for path in [&garbage, &truncated, &nan, &unknown, &missing] {
        for command in ["info", "eval"] {
            let output = roar(&[command, path.to_str().unwrap()]);
            assert_one_line_error(&output, &format!("{command} {}", path.display()));
        }
    }
}

#[test]
fn eval_reports_the_documented_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chair.off");
    assert!(
        roar(&["example-soup", path.to_str().unwrap()])
            .status
            .success()
    );
    let p = path.to_str().unwrap();
    let output = roar(&["eval", p, "--ref", p, "--json", "--samples", "5000"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    for section in ["topology", "topology_welded"] {
        for key in [
            "vertices",
            "faces",
            "boundary_edges",
            "nonmanifold_edges",
            "nonmanifold_vertices",
            "components",
            "watertight",
        ] {
            assert!(!json[section][key].is_null(), "{section}.{key}");
        }
    }
    assert!(json["quality"]["aspect_ratio_median"].as_f64().unwrap() >= 1.0);
    assert!(json["orientation"]["signed_volume"].is_number());
    let fidelity = &json["fidelity"];
    for key in [
        "chamfer_l2",
        "chamfer_l2_over_diag",
        "normal_cosine_abs",
        "hausdorff_over_diag",
        "chamfer_exact",
        "chamfer_exact_over_diag",
        "hausdorff_exact_over_diag",
        "normal_cosine_exact",
        "normal_cosine_exact_abs",
    ] {
        assert!(fidelity[key].is_number(), "fidelity.{key}");
    }
    // Against itself, only sampling noise remains in the sampled measure, and nothing in the
    // exact one.
    let sampled = fidelity["chamfer_l2_over_diag"].as_f64().unwrap();
    assert!(sampled > 0.0 && sampled < 0.02, "{sampled}");
    let exact = fidelity["chamfer_exact_over_diag"].as_f64().unwrap();
    assert!(exact <= 1e-12, "{exact}");
}

#[test]
fn render_writes_one_png_per_view_and_cameras_json() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("chair.stl");
    assert!(
        roar(&["example-soup", mesh.to_str().unwrap()])
            .status
            .success()
    );
    let out = dir.path().join("views");
    let output = roar(&[
        "render",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--views",
        "4",
        "--res",
        "32",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for i in 0..4 {
        assert!(out.join(format!("view_{i:02}.png")).is_file());
    }
    let cameras: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("cameras.json")).unwrap()).unwrap();
    assert_eq!(cameras["cameras"].as_array().unwrap().len(), 4);
    assert_eq!(cameras["cameras"][0]["width"], 32);
    assert!(cameras["normalization_scale"].as_f64().unwrap() > 0.0);

    let bad = roar(&[
        "render",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--views",
        "5",
    ]);
    assert_one_line_error(&bad, "render --views 5");
}

#[test]
fn init_then_decimate_gives_a_closed_mesh_with_the_exact_budget() {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("chair.obj");
    assert!(
        roar(&["example-soup", soup.to_str().unwrap()])
            .status
            .success()
    );
    let init = dir.path().join("init.ply");
    let output = roar(&[
        "init",
        soup.to_str().unwrap(),
        "-o",
        init.to_str().unwrap(),
        "--resolution",
        "32",
        "--faces",
        "1000",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let decimated = dir.path().join("small.off");
    let output = roar(&[
        "decimate",
        init.to_str().unwrap(),
        "-o",
        decimated.to_str().unwrap(),
        "--faces",
        "200",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let info = roar(&["info", "--json", decimated.to_str().unwrap()]);
    let json: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(json["faces"], 200);
    assert_eq!(json["closed_manifold"], true);

    // Odd budgets and non-manifold inputs: one line, no output file.
    let refused = dir.path().join("refused.obj");
    for args in [
        vec![
            "decimate",
            init.to_str().unwrap(),
            "-o",
            refused.to_str().unwrap(),
            "--faces",
            "201",
        ],
        vec![
            "decimate",
            soup.to_str().unwrap(),
            "-o",
            refused.to_str().unwrap(),
            "--faces",
            "200",
        ],
        vec![
            "init",
            soup.to_str().unwrap(),
            "-o",
            refused.to_str().unwrap(),
            "--faces",
            "7",
        ],
        vec![
            "reconstruct",
            soup.to_str().unwrap(),
            "-o",
            refused.to_str().unwrap(),
            "--faces",
            "999",
        ],
    ] {
        let output = roar(&args);
        assert_one_line_error(&output, &args.join(" "));
        assert!(!refused.exists(), "{}: no partial output", args.join(" "));
    }
}
