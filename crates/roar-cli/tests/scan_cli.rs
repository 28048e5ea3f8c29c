//! The range-scan commands from the outside: a scan set with a missing scan or a malformed
//! grid fails with one line naming the file and line and writes nothing; a range image is read
//! as its patch by `roar info`; `roar scans` writes the patches.

use std::path::Path;
use std::process::Command;

fn roar(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_roar"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A 3 × 2 range grid, fully seen, flat at z = `z`, with CRLF line endings.
fn grid(z: f64) -> String {
    let mut s = String::from(
        "ply\r\nformat ascii 1.0\r\nobj_info num_cols 3\r\nobj_info num_rows 2\r\n\
         element vertex 6\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n\
         element range_grid 6\r\nproperty list uchar int vertex_indices\r\nend_header\r\n",
    );
    for (x, y) in [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)] {
        s += &format!("{x} {y} {z}\r\n");
    }
    for i in 0..6 {
        s += &format!("1 {i}\r\n");
    }
    s
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn a_set_naming_a_missing_scan_fails_in_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.ply", &grid(0.0));
    let conf = write(
        dir.path(),
        "set.conf",
        "bmesh a.ply 0 0 0 0 0 0 1\nbmesh missing.ply 0 0 0 0 0 0 1\n",
    );
    let out = dir.path().join("out.obj").display().to_string();
    for args in [
        vec!["reconstruct", &conf, "-o", &out, "--faces", "100"],
        vec!["scans", &conf, "-o", &out],
    ] {
        let (ok, _, stderr) = roar(&args);
        assert!(!ok);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains(&format!("{conf}:2: scan file \"missing.ply\" not found")),
            "{stderr}"
        );
        assert!(!Path::new(&out).exists());
    }
}

#[test]
fn a_malformed_grid_in_a_set_names_its_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = write(
        dir.path(),
        "b.ply",
        &grid(0.0).replace("1 5\r\n", "1 9\r\n"),
    );
    let conf = write(dir.path(), "set.conf", "bmesh b.ply 0 0 0 0 0 0 1\n");
    let out = dir.path().join("out.ply").display().to_string();
    let (ok, _, stderr) = roar(&["scans", &conf, "-o", &out]);
    assert!(!ok);
    assert!(
        stderr.contains(&format!(
            "{bad}:23: range_grid 5: vertex index 9 out of range (file has 6 vertices)"
        )),
        "{stderr}"
    );
    assert!(!Path::new(&out).exists());
}

#[test]
fn a_range_image_is_a_mesh_to_info_and_a_set_folder_writes_its_patches() {
    let dir = tempfile::tempdir().unwrap();
    let scan = write(dir.path(), "a.ply", &grid(0.0));
    let (ok, stdout, stderr) = roar(&["info", &scan]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains('4'), "{stdout}");
    write(dir.path(), "b.ply", &grid(100.0));
    write(
        dir.path(),
        "set.conf",
        "bmesh a.ply 0 0 0 0 0 0 1\nbmesh b.ply 0 0 0 0 0 0 1\n",
    );
    let out = dir.path().join("patches.ply");
    let folder = dir.path().display().to_string();
    let (ok, stdout, stderr) =
        roar(&["scans", &folder, "-o", &out.display().to_string(), "--json"]);
    assert!(ok, "{stderr}");
    let soup = roar_io::read_mesh(&out).unwrap();
    assert_eq!(soup.triangles.len(), 8);
    // Two patches 100 grid steps apart overlap nothing within ICP's reach: reported, not moved.
    let reports: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(reports[1]["overlaps"], false);
    assert_eq!(reports[1]["moved"], 0.0);
    assert!(stderr.contains("b.ply overlaps too little"), "{stderr}");
}
