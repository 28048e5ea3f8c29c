//! Malformed input gives an error naming the file (and the line or element where it applies),
//! never a panic; invalid soups and unknown extensions are refused on write with nothing written.

mod common;

use std::path::{Path, PathBuf};

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_io::{IoError, TriangleSoup, read_mesh, write_mesh};

/// Writes `bytes` as `name` in a fresh folder and reads it back with `read_mesh`.
fn read_as(
    name: &str,
    bytes: &[u8],
) -> (PathBuf, Result<TriangleSoup, IoError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let result = read_mesh(&path);
    (path, result, dir)
}

/// Asserts that reading `bytes` as `name` fails with a one-line message that starts with the
/// path followed by `then` (e.g. `":4: face index"`), and returns the message.
fn assert_error(name: &str, bytes: &[u8], then: &str) -> String {
    let (path, result, _dir) = read_as(name, bytes);
    let message = match result {
        Ok(soup) => panic!(
            "{name}: expected an error, read {} triangles",
            soup.triangles.len()
        ),
        Err(e) => e.to_string(),
    };
    let want = format!("{}{then}", path.display());
    assert!(
        message.starts_with(&want),
        "{message:?} should start with {want:?}"
    );
    assert!(!message.contains('\n'), "{message:?} is not one line");
    message
}

fn file(name: &str) -> Vec<u8> {
    common::valid_files()
        .into_iter()
        .find(|(n, _)| *n == name)
        .unwrap()
        .1
}

const OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const OFF: &str = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
const PLY: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
const STL: &str = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";

#[test]
fn the_small_valid_files_used_below_are_valid() {
    for (name, text) in [
        ("a.obj", OBJ),
        ("a.off", OFF),
        ("a.ply", PLY),
        ("a.stl", STL),
    ] {
        let (_, result, _dir) = read_as(name, text.as_bytes());
        assert_eq!(result.unwrap().triangles, vec![[0, 1, 2]], "{name}");
    }
}

#[test]
fn truncated_files_are_errors() {
    // OBJ cut inside its only face line (an OBJ cut at a line boundary is a smaller valid OBJ).
    assert_error(
        "t.obj",
        &OBJ.as_bytes()[..OBJ.len() - 3],
        ": no faces found (3 vertices; 1 face(s) with fewer than 3 corners skipped)",
    );
    assert_error(
        "t.off",
        &OFF.as_bytes()[..OFF.len() - 9],
        ": file ends after 0 of 1 faces",
    );
    assert_error(
        "t.off",
        &OFF.as_bytes()[..OFF.len() - 3],
        ":6: face declares 3 corners",
    );
    assert_error(
        "t.ply",
        &PLY.as_bytes()[..PLY.len() - 3],
        ":13: face 0: line ends early",
    );
    assert_error(
        "t.ply",
        &PLY.as_bytes()[..100],
        ": PLY header not terminated",
    );
    assert_error(
        "t.stl",
        &STL.as_bytes()[..STL.len() - 20],
        ":7: file ends inside a solid",
    );
    let le = file("le.ply");
    assert_error("t.ply", &le[..le.len() - 1], ": face 4: file ends early");
    let be = file("be.ply");
    let header_len = be.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    assert_error(
        "t.ply",
        &be[..header_len + 30],
        ": vertex 1: file ends early",
    );
    let stl = file("binary.stl");
    let m = assert_error("t.stl", &stl[..stl.len() - 1], ": not an ASCII STL");
    assert!(m.contains("header says 5 triangles"), "{m}");
}

#[test]
fn nan_and_inf_coordinates_are_errors() {
    assert_error(
        "n.obj",
        OBJ.replace("v 1 0 0", "v 1 NaN 0").as_bytes(),
        ":2: y coordinate \"NaN\" is not finite",
    );
    assert_error(
        "n.off",
        OFF.replace("1 0 0", "1 0 -inf").as_bytes(),
        ":4: z coordinate \"-inf\" is not finite",
    );
    assert_error(
        "n.ply",
        PLY.replace("\n1 0 0", "\n1 0 inf").as_bytes(),
        ":11: vertex 1: z coordinate is inf",
    );
    assert_error(
        "n.stl",
        STL.replace("vertex 0 1 0", "vertex nan 1 0").as_bytes(),
        ":6: x coordinate",
    );

    let mut le = file("le.ply");
    let header_len = le.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let at = header_len + 2 * 24 + 8; // vertex 2, y
    le[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    assert_error("n.ply", &le, ": vertex 2: y coordinate is NaN");

    let mut stl = file("binary.stl");
    let at = 84 + 3 * 50 + 12 + 12 * 2 + 8; // triangle 3, corner 2, z
    stl[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
    assert_error(
        "n.stl",
        &stl,
        ": triangle 3: corner 2 has a NaN or infinite coordinate",
    );
}

#[test]
fn indices_out_of_range_are_errors() {
    assert_error(
        "i.obj",
        OBJ.replace("f 1 2 3", "f 1 2 9999").as_bytes(),
        ":4: face index 9999 out of range (file has 3 vertices)",
    );
    assert_error(
        "i.obj",
        OBJ.replace("f 1 2 3", "f 1 2 -7").as_bytes(),
        ":4: relative face index -7",
    );
    assert_error(
        "i.obj",
        OBJ.replace("f 1 2 3", "f 1 2 0").as_bytes(),
        ":4: face index 0 is invalid",
    );
    assert_error(
        "i.off",
        OFF.replace("3 0 1 2", "3 0 1 3").as_bytes(),
        ":6: face index 3 out of range (file has 3 vertices)",
    );
    assert_error(
        "i.off",
        OFF.replace("3 0 1 2", "3 0 -1 2").as_bytes(),
        ":6: face index -1 out of range",
    );
    assert_error(
        "i.ply",
        PLY.replace("3 0 1 2", "3 0 1 3").as_bytes(),
        ":13: face 0: face index 3 out of range (file has 3 vertices)",
    );
    let mut le = file("le.ply");
    let n = le.len();
    le[n - 4..].copy_from_slice(&77u32.to_le_bytes());
    assert_error(
        "i.ply",
        &le,
        ": face 4: face index 77 out of range (file has 4 vertices)",
    );
}

#[test]
fn files_whose_only_faces_have_fewer_than_three_corners_are_errors_that_say_so() {
    let skipped = "1 face(s) with fewer than 3 corners skipped";
    assert_error(
        "d.obj",
        OBJ.replace("f 1 2 3", "f 1 2").as_bytes(),
        &format!(": no faces found (3 vertices; {skipped})"),
    );
    assert_error(
        "d.off",
        OFF.replace("3 0 1 2", "2 0 1").as_bytes(),
        &format!(": mesh has no faces; {skipped}"),
    );
    assert_error(
        "d.ply",
        PLY.replace("3 0 1 2", "2 0 1").as_bytes(),
        &format!(": mesh has no faces; {skipped}"),
    );
    assert_error(
        "d.stl",
        STL.replace("vertex 0 1 0\n", "").as_bytes(),
        &format!(": ASCII STL without facets; {skipped}"),
    );
}

#[test]
fn skipped_faces_are_still_checked_for_bad_indices() {
    assert_error(
        "d.obj",
        OBJ.replace("f 1 2 3", "f 1 2 3\nf 1 9").as_bytes(),
        ":5: face index 9 out of range",
    );
    assert_error(
        "d.off",
        OFF.replace("3 1 0", "3 2 0")
            .replace("3 0 1 2", "3 0 1 2\n2 0 7")
            .as_bytes(),
        ":7: face index 7 out of range",
    );
    assert_error(
        "d.ply",
        PLY.replace("element face 1", "element face 2")
            .replace("3 0 1 2", "3 0 1 2\n2 0 7")
            .as_bytes(),
        ":14: face 1: face index 7 out of range",
    );
}

#[test]
fn degenerate_triangles_are_kept() {
    let (_, result, _dir) = read_as("k.obj", OBJ.replace("f 1 2 3", "f 1 1 2").as_bytes());
    assert_eq!(result.unwrap().triangles, vec![[0, 0, 1]]);
}

#[test]
fn empty_files_and_meshes_without_triangles_are_errors() {
    for name in ["e.obj", "e.off", "e.ply", "e.stl"] {
        assert_error(name, b"", ":");
    }
    assert_error(
        "e.obj",
        b"v 0 0 0\nv 1 0 0\n",
        ": no faces found (2 vertices)",
    );
    assert_error("e.off", b"OFF\n0 0 0\n", ": mesh has no faces");
    assert_error(
        "e.ply",
        PLY.replace("element face 1", "element face 0")
            .replace("3 0 1 2\n", "")
            .as_bytes(),
        ": mesh has no faces",
    );
    assert_error(
        "e.stl",
        b"solid x\nendsolid x\n",
        ": ASCII STL without facets",
    );
    let mut stl = vec![0u8; 84];
    stl[..5].copy_from_slice(b"solid");
    assert_error("e.stl", &stl, ": binary STL with 0 triangles");
}

#[test]
fn content_in_the_wrong_format_is_an_error() {
    assert_error("w.obj", PLY.as_bytes(), ": no faces found");
    assert_error("w.off", PLY.as_bytes(), ":1: not an OFF file");
    assert_error("w.ply", OFF.as_bytes(), ": not a PLY file");
    assert_error("w.stl", OBJ.as_bytes(), ": not an STL file");
    assert_error("w.stl", &file("le.ply"), ": not an ASCII STL");
    assert_error(
        "w.ply",
        PLY.replace("ascii", "binary_middle_endian").as_bytes(),
        ":2: unknown PLY format",
    );
    assert_error("w.off", b"OFF BINARY\n", ":1: binary OFF is not supported");
}

#[test]
fn unknown_or_missing_extensions_are_errors() {
    for name in ["m.xyz", "m", "m.obj.bak", "m.fbx"] {
        let (path, result, _dir) = read_as(name, OBJ.as_bytes());
        let message = result.unwrap_err().to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(message.contains("unknown mesh file extension"), "{message}");
    }
}

#[test]
fn missing_file_is_an_error_naming_it() {
    let e = read_mesh(Path::new("/no/such/dir/x.obj"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/no/such/dir/x.obj: "), "{e}");
}

#[test]
fn random_bytes_are_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for len in [1usize, 83, 84, 1000, 10_000] {
        let mut bytes = vec![0u8; len];
        rng.fill_bytes(&mut bytes);
        for name in ["r.obj", "r.off", "r.ply", "r.stl"] {
            assert_error(name, &bytes, ":");
        }
    }
}

#[test]
fn writing_an_invalid_soup_or_unknown_extension_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let good = common::awkward_soup();
    let mut nan = good.clone();
    nan.positions[2].x = f64::NAN;
    let mut out_of_range = good.clone();
    out_of_range.triangles[1][2] = 4;
    let cases = [
        ("a.obj", TriangleSoup::default(), "mesh has no triangles"),
        ("a.ply", nan, "vertex 2 has a NaN"),
        (
            "a.stl",
            out_of_range,
            "triangle 1 refers to missing vertex 4",
        ),
        ("a.dae", good, "unknown mesh file extension"),
    ];
    for (name, soup, want) in cases {
        let path = dir.path().join(name);
        let e = write_mesh(&path, &soup).unwrap_err().to_string();
        assert!(
            e.starts_with(&path.display().to_string()) && e.contains(want),
            "{e}"
        );
        assert!(!path.exists());
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
