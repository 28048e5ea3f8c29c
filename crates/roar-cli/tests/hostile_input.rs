//! What a hostile or careless user types besides the mesh: colliding paths, unwritable outputs,
//! garbage values, impossible budgets, signals. Each is refused before any work with one line on
//! stderr and a non-zero exit, and leaves every file as it was.

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

fn roar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_roar"))
        .args(args)
        .output()
        .expect("the roar binary runs")
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// One `roar: error:` line that contains `needle`, and a failing exit.
fn assert_refused(output: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "expected a failure: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("roar: error: "), "{stderr}");
    assert!(stderr.contains(needle), "expected {needle:?} in: {stderr}");
}

/// A folder holding the README's example soup as `ex.obj`.
fn example_folder() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("ex.obj");
    assert!(roar(&["example-soup", s(&soup)]).status.success());
    (dir, soup)
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A closed torus of `n × m` quads split into triangles (genus 1, 2nm faces).
fn torus_obj(path: &Path, n: usize, m: usize) {
    let mut text = String::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                i as f64 / n as f64 * std::f64::consts::TAU,
                j as f64 / m as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.4 * v.cos();
            text += &format!("v {} {} {}\n", r * u.cos(), r * u.sin(), 0.4 * v.sin());
        }
    }
    let id = |i: usize, j: usize| (i % n) * m + (j % m) + 1;
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn colliding_input_output_report_and_config_are_refused() {
    let (dir, soup) = example_folder();
    let before = std::fs::read(&soup).unwrap();
    let out = dir.path().join("out.obj");
    let hard = dir.path().join("hard.obj");
    std::fs::hard_link(&soup, &hard).unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, "[optimize]\niterations = 0\n").unwrap();
    for args in [
        vec!["-o", s(&out), "--report", s(&out)],
        vec!["-o", s(&out), "--report", s(&soup)],
        vec!["-o", s(&soup)],
        vec!["-o", s(&hard)],
        vec!["-o", s(&config), "--config", s(&config)],
    ] {
        let mut full = vec!["reconstruct", s(&soup), "--faces", "1000"];
        full.extend(args);
        assert_refused(&roar(&full), "name the same file");
    }
    assert_eq!(std::fs::read(&soup).unwrap(), before);
    assert!(!out.exists());
    assert_refused(
        &roar(&["decimate", s(&soup), "-o", s(&hard), "--faces", "8"]),
        "same file",
    );
    assert_refused(&roar(&["init", s(&soup), "-o", s(&soup)]), "same file");
}

#[test]
fn unwritable_outputs_are_found_before_any_work() {
    let (dir, soup) = example_folder();
    let out = dir.path().join("out.obj");
    let missing = dir.path().join("no/such/folder/r.json");
    let run = |extra: &[&str]| {
        let mut full = vec!["reconstruct", s(&soup), "--faces", "1000"];
        full.extend(extra);
        roar(&full)
    };
    assert_refused(
        &run(&["-o", s(&missing.with_extension("obj"))]),
        "does not exist",
    );
    assert_refused(
        &run(&["-o", s(&out), "--report", s(&missing)]),
        "does not exist",
    );
    let folder = dir.path().join("folder.obj");
    std::fs::create_dir(&folder).unwrap();
    assert_refused(&run(&["-o", s(&folder)]), "is a folder");
    // A full disk: the device is refused as a destination (never replaced by a rename).
    let full = dir.path().join("full.obj");
    std::os::unix::fs::symlink("/dev/full", &full).unwrap();
    assert_refused(&run(&["-o", s(&full)]), "not a regular file");
    std::fs::remove_file(&full).unwrap();
    assert_refused(&roar(&["example-soup", "/dev/null"]), "not a regular file");
    assert_eq!(files_in(dir.path()), ["ex.obj", "folder.obj"]);
    assert_eq!(files_in(&folder).len(), 0);
    // The folder error names the user's path once, never a temporary file.
    let output = run(&["-o", s(&folder)]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !stderr.contains(".folder.obj.") && !stderr.contains("os error 21): Is"),
        "{stderr}"
    );
}

#[test]
fn garbage_values_are_refused_before_reading_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    // The input does not exist: a refusal naming the field proves the check came first.
    let input = dir.path().join("never-read.obj");
    for (line, field) in [
        (
            "[optimize]\nlaplacian_weight = nan",
            "optimize.laplacian_weight",
        ),
        ("[loss]\nrender_weight = inf", "loss.render_weight"),
        (
            "[target]\npoint_cloud_samples = 0",
            "target.point_cloud_samples",
        ),
        ("[loss]\nplanar_neighbours = 0", "loss.planar_neighbours"),
        (
            "[optimize]\nworking_budget_min = 30000",
            "optimize.working_budget_min",
        ),
        ("render_weight = 1", "[loss]"),
        ("[loss]\niterations = 1", "[optimize]"),
    ] {
        let config = dir.path().join("c.toml");
        std::fs::write(&config, format!("{line}\n")).unwrap();
        let output = roar(&[
            "reconstruct",
            s(&input),
            "-o",
            s(&out),
            "--config",
            s(&config),
        ]);
        assert_refused(&output, field);
    }
    // clap's own usage error (exit 2), about the value rather than "unexpected argument '-1'".
    let output = roar(&["reconstruct", s(&input), "-o", s(&out), "--faces", "-10"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("\"-10\" is not a face count"), "{stderr}");
    assert_refused(
        &roar(&[
            "reconstruct",
            s(&input),
            "-o",
            s(&out),
            "--init",
            "sphere",
            "--resolution",
            "64",
        ]),
        "no effect with --init sphere",
    );
    for (faces, advice) in [("1", "use 4"), ("3", "use 4"), ("5001", "use 5000 or 5002")] {
        let output = roar(&["reconstruct", s(&input), "-o", s(&out), "--faces", faces]);
        assert_refused(&output, advice);
    }
    assert!(!out.exists());
}

#[test]
fn budgets_that_cannot_fit_in_memory_are_refused_up_front() {
    let (dir, soup) = example_folder();
    let out = dir.path().join("out.obj");
    let output = roar(&[
        "reconstruct",
        s(&soup),
        "-o",
        s(&out),
        "--faces",
        "1000000000",
    ]);
    assert_refused(&output, "--force");
    assert!(!out.exists());
}

#[test]
fn decimate_fails_without_reaching_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let torus = dir.path().join("torus.obj");
    torus_obj(&torus, 12, 8);
    let out = dir.path().join("out.obj");
    let run = |faces: &str| roar(&["decimate", s(&torus), "-o", s(&out), "--faces", faces]);
    assert_refused(&run("400"), "above the 192 faces");
    assert_refused(&run("12"), "smallest reachable budget, 14 faces; use 14");
    assert_refused(&run("13"), "use 14");
    assert!(!out.exists());
    let reached = run("100");
    assert!(
        reached.status.success(),
        "{}",
        String::from_utf8_lossy(&reached.stderr)
    );
    let info = roar(&["info", s(&out)]);
    assert!(
        String::from_utf8_lossy(&info.stdout).contains("100"),
        "{info:?}"
    );
}

#[test]
fn eval_says_why_there_is_no_fidelity() {
    let (dir, soup) = example_folder();
    assert_refused(
        &roar(&["eval", s(&soup), "--ref", s(&soup), "--samples", "0"]),
        "--samples 0",
    );
    let flat = dir.path().join("flat.obj");
    std::fs::write(&flat, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    assert_refused(&roar(&["eval", s(&soup), "--ref", s(&flat)]), "zero area");
}

#[test]
fn outputs_honour_the_umask_and_keep_an_existing_mode() {
    let dir = tempfile::tempdir().unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    let bin = env!("CARGO_BIN_EXE_roar");
    for (umask, expected) in [("022", 0o644), ("077", 0o600), ("002", 0o664)] {
        let path = dir.path().join(format!("u{umask}.obj"));
        let status = Command::new("sh")
            .args([
                "-c",
                &format!("umask {umask} && exec \"$0\" example-soup \"$1\""),
            ])
            .args([bin, s(&path)])
            .output()
            .unwrap();
        assert!(status.status.success(), "{status:?}");
        assert_eq!(mode(&path), expected, "umask {umask}");
    }
    let kept = dir.path().join("kept.obj");
    std::fs::write(&kept, b"old").unwrap();
    std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
    assert!(roar(&["example-soup", s(&kept)]).status.success());
    assert_eq!(mode(&kept), 0o640);
    // A symbolic link is written through and stays a link.
    let link = dir.path().join("link.obj");
    std::os::unix::fs::symlink(&kept, &link).unwrap();
    let output = roar(&["example-soup", s(&link)]);
    assert!(output.status.success(), "{output:?}");
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
}

#[test]
fn sigterm_stops_a_run_and_leaves_no_temporary_file() {
    let (dir, soup) = example_folder();
    let out = dir.path().join("out.obj");
    let child = Command::new(env!("CARGO_BIN_EXE_roar"))
        .args([
            "reconstruct",
            s(&soup),
            "-o",
            s(&out),
            "--faces",
            "1000",
            "-q",
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(128 + 15), "{output:?}");
    assert!(String::from_utf8_lossy(&output.stderr).contains("stopped by signal 15"));
    assert_eq!(files_in(dir.path()), ["ex.obj"]);
}

#[test]
fn concave_polygons_are_triangulated_in_their_plane_by_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    // An arrowhead listed from a corner beside its notch (a fan would cover the notch), and a
    // polygon with all corners on one line (no plane: counted).
    let corners = "2 1 0\n0.5 0 0\n2 -1 0\n0 0 0\n3 0 0\n4 0 0\n5 0 0\n";
    let obj: String = corners
        .lines()
        .map(|l| format!("v {l}\n"))
        .collect::<String>()
        + "f 1 2 3 4\nf 4 5 6 7\n";
    let off = format!("OFF\n7 2 0\n{corners}4 0 1 2 3\n4 3 4 5 6\n");
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 7\nproperty float x\nproperty float y\n\
         property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
         {corners}4 0 1 2 3\n4 3 4 5 6\n"
    );
    for (name, text) in [("a.obj", obj), ("a.off", off), ("a.ply", ply)] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let soup = roar_io::read_mesh(&path).unwrap();
        assert_eq!(soup.triangles[..2], [[1, 2, 3], [0, 1, 3]], "{name}");
        let output = roar(&["info", "--json", s(&path)]);
        let info: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        assert_eq!(info["polygons"], 2, "{name}");
        assert_eq!(info["polygons_unclean"], 1, "{name}");
    }
}

#[test]
fn a_run_writes_its_mesh_and_report_together_and_nothing_else() {
    let (dir, soup) = example_folder();
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let output = roar(&[
        "reconstruct",
        s(&soup),
        "-o",
        s(&out),
        "--report",
        s(&report),
        "--faces",
        "500",
        "--iterations",
        "0",
        "-q",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(files_in(dir.path()), ["ex.obj", "out.obj", "report.json"]);
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(json["output"], s(&out));
    assert_eq!(roar_io::read_mesh(&out).unwrap().triangles.len(), 500);
}

#[test]
fn a_budget_too_small_for_every_piece_keeps_the_largest_and_says_so() {
    // Two cubes far apart: two pieces of genus 0 need at least 8 faces. At 6, the init keeps
    // one piece (too far apart to merge) and the report and the summary say one was dropped.
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::new();
    for (k, dx) in [0.0, 5.0].iter().enumerate() {
        for c in 0..8 {
            let (x, y, z) = ((c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64);
            text += &format!("v {} {y} {z}\n", x + dx);
        }
        let o = 8 * k + 1;
        for [a, b, c, d] in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            text += &format!("f {} {} {} {}\n", a + o, b + o, c + o, d + o);
        }
    }
    let cubes = dir.path().join("cubes.obj");
    std::fs::write(&cubes, text).unwrap();
    let out = dir.path().join("out.obj");
    let report = dir.path().join("report.json");
    let run = roar(&[
        "reconstruct",
        s(&cubes),
        "-o",
        s(&out),
        "--faces",
        "6",
        "--iterations",
        "0",
        "--report",
        s(&report),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mesh = roar_io::read_mesh(&out).unwrap();
    assert_eq!(mesh.triangles.len(), 6);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["run"]["init"]["init_pieces_dropped_for_budget"], 1);
    assert_eq!(json["output_metrics"]["topology"]["components"], 1);
    let summary = String::from_utf8_lossy(&run.stdout);
    assert!(summary.contains("1 piece(s) dropped"), "{summary}");
}
