//! Quirks that real datasets contain and every mainstream loader reads: each is read here too,
//! not refused, on a minimal file that reproduces it.

use std::path::Path;

use roar_io::{TriangleSoup, read_mesh};

/// Writes `bytes` as `name` in a fresh folder and reads it with `read_mesh`, panicking with the
/// error if the file is refused.
fn read(name: &str, bytes: &[u8]) -> TriangleSoup {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    read_mesh(Path::new(&path)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

const SQUARE: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

#[test]
fn obj_faces_with_fewer_than_three_corners_are_skipped_and_counted() {
    // As Sweet Home 3D writes them: `f a b` among the faces, with and without slashes; `f a` and
    // a bare `f` carry no surface either.
    let obj = format!(
        "{}f 1/1/1 2/2/1 3/3/1\nf 1 3\nf 3/3/1 4/4/1\nf 4\nf\nf 1 3 4\n",
        SQUARE
            .lines()
            .map(|l| format!("v {l}\n"))
            .collect::<String>()
    );
    let soup = read("s.obj", obj.as_bytes());
    assert_eq!(soup.triangles, [[0, 1, 2], [0, 2, 3]]);
    assert_eq!(soup.n_faces_skipped, 4);
    assert_eq!(soup.positions.len(), 4);
}

#[test]
fn off_and_ascii_ply_faces_with_fewer_than_three_corners_are_skipped_and_counted() {
    let faces = "3 0 1 2\n2 0 2\n1 3\n0\n3 0 2 3\n";
    let off = format!("OFF\n4 5 0\n{SQUARE}{faces}");
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n\
         {SQUARE}{faces}"
    );
    for (name, text) in [("s.off", off), ("s.ply", ply)] {
        let soup = read(name, text.as_bytes());
        assert_eq!(soup.triangles, [[0, 1, 2], [0, 2, 3]], "{name}");
        assert_eq!(soup.n_faces_skipped, 3, "{name}");
    }
}

#[test]
fn binary_ply_faces_with_fewer_than_three_corners_are_skipped_and_counted() {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
property float x\nproperty float y\nproperty float z\nelement face 3\n\
property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend(v.to_le_bytes());
    }
    for face in [&[0i32, 1][..], &[0, 1, 2], &[2]] {
        bytes.push(face.len() as u8);
        for i in face {
            bytes.extend(i.to_le_bytes());
        }
    }
    let soup = read("s.ply", &bytes);
    assert_eq!(soup.triangles, [[0, 1, 2]]);
    assert_eq!(soup.n_faces_skipped, 2);
}

#[test]
fn ascii_stl_loops_with_fewer_than_three_vertices_are_skipped_with_their_vertices() {
    let facet = |corners: &[&str]| {
        let vertices: String = corners.iter().map(|c| format!("vertex {c}\n")).collect();
        format!("facet normal 0 0 1\nouter loop\n{vertices}endloop\nendfacet\n")
    };
    let stl = format!(
        "solid s\n{}{}{}endsolid s\n",
        facet(&["0 0 0", "1 0 0"]),
        facet(&["0 0 0", "1 0 0", "0 1 0"]),
        facet(&[]),
    );
    let soup = read("s.stl", stl.as_bytes());
    assert_eq!(soup.triangles, [[0, 1, 2]]);
    assert_eq!(
        soup.positions.len(),
        3,
        "one vertex per corner of a kept facet"
    );
    assert_eq!(soup.n_faces_skipped, 2);
}

#[test]
fn zero_area_triangles_are_kept_not_skipped() {
    // Repeated corners and collinear corners: a geometric matter for later stages.
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 1 2\nf 1 2 3\n";
    let soup = read("z.obj", obj.as_bytes());
    assert_eq!(soup.triangles, [[0, 0, 1], [0, 1, 2]]);
    assert_eq!(soup.n_faces_skipped, 0);
}

#[test]
fn skipped_face_counts_survive_welding() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nf 1 2 3\nf 4 2\n";
    let (welded, _) = read("w.obj", obj.as_bytes()).welded();
    assert_eq!(welded.n_faces_skipped, 1);
}

#[test]
fn off_headers_with_the_vertex_count_glued_to_the_keyword_read() {
    // ModelNet40 writes `OFF700 620 0`: the vertex count glued to the keyword, the other counts
    // after it (here with extra spaces and a tab), and the same for the keyword's variants.
    let body = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    for header in [
        "OFF4 2 0",
        "OFF4   2\t0  ",
        "OFF4 2",
        "COFF4 2 0",
        "NOFF4 2 0",
        "CNOFF4 2 0",
    ] {
        let soup = read("g.off", format!("{header}\n{body}").as_bytes());
        assert_eq!(soup.positions.len(), 4, "{header:?}");
        assert_eq!(soup.triangles, [[0, 1, 2], [0, 2, 3]], "{header:?}");
    }
}
