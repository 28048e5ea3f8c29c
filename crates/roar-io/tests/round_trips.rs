//! Write-then-read round trips through real files for every format and encoding, and reading of
//! the same polygonal mesh written by hand in every format.

mod common;

use common::{awkward_soup, bits, f32_soup, unshared};
use roar_io::{
    MeshFormat, PlyEncoding, StlEncoding, TriangleSoup, WriteOptions, read_mesh, write_mesh,
    write_mesh_with,
};

fn round_trip(name: &str, soup: &TriangleSoup, options: WriteOptions) -> TriangleSoup {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    write_mesh_with(&path, soup, &options).unwrap();
    read_mesh(&path).unwrap()
}

#[test]
fn obj_off_and_every_ply_encoding_round_trip_bit_identical() {
    let soup = awkward_soup();
    let ply = |ply| WriteOptions {
        ply,
        ..Default::default()
    };
    let cases = [
        ("m.obj", WriteOptions::default()),
        ("m.off", WriteOptions::default()),
        ("m.ply", ply(PlyEncoding::BinaryLittleEndian)),
        ("m.ply", ply(PlyEncoding::BinaryBigEndian)),
        ("m.ply", ply(PlyEncoding::Ascii)),
    ];
    for (name, options) in cases {
        let back = round_trip(name, &soup, options);
        assert_eq!(
            bits(&back.positions),
            bits(&soup.positions),
            "{name} {options:?}"
        );
        assert_eq!(back.triangles, soup.triangles, "{name} {options:?}");
        assert_eq!(back.n_polygons, 0);
    }
}

#[test]
fn ascii_stl_round_trips_f64_with_one_vertex_per_corner() {
    let soup = awkward_soup();
    let options = WriteOptions {
        stl: StlEncoding::Ascii,
        ..Default::default()
    };
    let back = round_trip("m.stl", &soup, options);
    let want = unshared(&soup);
    assert_eq!(bits(&back.positions), bits(&want.positions));
    assert_eq!(back.triangles, want.triangles);
}

#[test]
fn binary_stl_round_trips_f32_representable_coordinates() {
    let soup = f32_soup();
    let back = round_trip("m.stl", &soup, WriteOptions::default());
    let want = unshared(&soup);
    assert_eq!(bits(&back.positions), bits(&want.positions));
    assert_eq!(back.triangles, want.triangles);
    // Welding recovers the shared vertices.
    let (welded, _) = back.welded();
    assert_eq!(welded.positions.len(), soup.positions.len());
}

#[test]
fn binary_stl_rounds_f64_to_f32() {
    let soup = awkward_soup();
    let back = round_trip("m.stl", &soup, WriteOptions::default());
    assert_eq!(back.positions[0].x, 0.1f32 as f64);
    assert_ne!(back.positions[0].x, 0.1);
}

#[test]
fn extensions_are_case_insensitive() {
    for name in ["M.OBJ", "m.Ply", "m.STL", "m.oFf"] {
        let back = round_trip(name, &f32_soup(), WriteOptions::default());
        assert_eq!(back.triangles.len(), 5, "{name}");
    }
    assert_eq!(
        MeshFormat::from_path(std::path::Path::new("x/Y.STL")).unwrap(),
        MeshFormat::Stl
    );
}

/// A unit square as one quad plus a triangle, written by hand in each format and encoding.
fn quad_files() -> Vec<(&'static str, Vec<u8>)> {
    let mut files: Vec<(&'static str, Vec<u8>)> = vec![
        (
            "q.obj",
            b"o first\nv 0 0 0\nv 1 0 0\ng second\nv 1 1 0\nv 0 1 0\nv 2 0 0\n\
f 1/1 2/2 3/3 4/4\nf -4 -1 -3\n"
                .to_vec(),
        ),
        (
            "q.off",
            b"OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3\n3 1 4 2\n".to_vec(),
        ),
        (
            "q.stl",
            b"solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n\
vertex 0 1 0\nendloop\nendfacet\nendsolid q\nsolid r\nfacet normal 0 0 1\nouter loop\n\
vertex 1 0 0\nvertex 2 0 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n"
                .to_vec(),
        ),
    ];
    // PLY with awkward types and extra elements/properties that must be skipped correctly:
    // float xyz plus a colour and a list, a `face` list of ushort indices with int counts after
    // another list, and an `edge` element with a list between vertex and face.
    let header = |format: &str| {
        format!(
            "ply\r\nformat {format} 1.0\r\ncomment hand made\r\nobj_info x\r\nelement vertex 5\r\n\
property uchar red\r\nproperty float x\r\nproperty float y\r\nproperty list uchar double junk\r\n\
property float z\r\nelement edge 2\r\nproperty list int int pair\r\nproperty short w\r\n\
element face 2\r\nproperty list uchar uint tags\r\nproperty list int ushort vertex_index\r\n\
end_header\r\n"
        )
    };
    let xyz = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let faces: [&[u16]; 2] = [&[0, 1, 2, 3], &[1, 4, 2]];
    let mut ascii = header("ascii").into_bytes();
    for (i, p) in xyz.iter().enumerate() {
        let junk = if i % 2 == 0 { "2 0.5 7" } else { "0" };
        ascii.extend(format!("{i} {} {} {junk} {}\n", p[0], p[1], p[2]).bytes());
    }
    ascii.extend(b"2 0 1 -3\n\n2 1 2 4\n");
    for f in faces {
        let idx: Vec<String> = f.iter().map(u16::to_string).collect();
        ascii.extend(format!("1 99 {} {}\n", f.len(), idx.join(" ")).bytes());
    }
    files.push(("q-ascii.ply", ascii));
    for big in [false, true] {
        let mut b = header(if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        })
        .into_bytes();
        macro_rules! put {
            ($v:expr) => {
                if big {
                    b.extend($v.to_be_bytes())
                } else {
                    b.extend($v.to_le_bytes())
                }
            };
        }
        for (i, p) in xyz.iter().enumerate() {
            put!(i as u8);
            put!(p[0]);
            put!(p[1]);
            let n_junk = if i % 2 == 0 { 2u8 } else { 0 };
            put!(n_junk);
            for _ in 0..n_junk {
                put!(0.5f64);
            }
            put!(p[2]);
        }
        for _ in 0..2 {
            put!(2i32);
            put!(0i32);
            put!(1i32);
            put!(-3i16);
        }
        for f in faces {
            put!(1u8);
            put!(99u32);
            put!(f.len() as i32);
            for &i in f {
                put!(i);
            }
        }
        files.push((if big { "q-be.ply" } else { "q-le.ply" }, b));
    }
    files
}

#[test]
fn polygons_are_fan_triangulated_and_counted_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in quad_files() {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let soup = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(soup.n_polygons, 1, "{name}");
        let (welded, _) = soup.welded();
        assert_eq!(welded.positions.len(), 5, "{name}");
        let expected_positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
        ];
        let got: Vec<[f64; 3]> = welded.positions.iter().map(|p| p.to_array()).collect();
        assert_eq!(got, expected_positions, "{name}");
        assert_eq!(
            welded.triangles,
            vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]],
            "{name}"
        );
    }
}

#[test]
fn obj_groups_keep_global_indices_and_negative_indices_are_relative() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\no a\nf -3 -2 -1\nv 0 0 1\ng b\nf 1 2 4\nf -4/1/1 -1//2 -2\n",
    )
    .unwrap();
    let soup = read_mesh(&path).unwrap();
    assert_eq!(soup.triangles, vec![[0, 1, 2], [0, 1, 3], [0, 3, 2]]);
}

#[test]
fn written_file_replaces_an_old_one_completely() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.obj");
    std::fs::write(&path, "x".repeat(100_000)).unwrap();
    write_mesh(&path, &awkward_soup()).unwrap();
    assert_eq!(read_mesh(&path).unwrap().triangles.len(), 5);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
