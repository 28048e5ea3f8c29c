//! Small hand-made soups and valid files in every format, shared by the integration tests.
#![allow(dead_code)]

pub mod gltf;

use glam::DVec3;
use roar_io::{PlyEncoding, StlEncoding, TriangleSoup, write_obj, write_off, write_ply, write_stl};

/// A tetrahedron plus a degenerate triangle, with coordinates that need all 17 significant
/// digits (and -0.0, tiny and huge values) to round-trip.
pub fn awkward_soup() -> TriangleSoup {
    TriangleSoup::new(
        vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0 / 3.0, -0.0, 1e-300),
            DVec3::new(-2.5e17, std::f64::consts::E, 7.0),
            DVec3::new(f64::MIN_POSITIVE, 123_456.789_012_345_67, -1.0 / 7.0),
        ],
        vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0], [0, 0, 1]],
    )
}

/// A soup whose coordinates are exactly representable in f32 (for binary STL).
pub fn f32_soup() -> TriangleSoup {
    let mut soup = awkward_soup();
    for p in &mut soup.positions {
        *p = p.as_vec3().as_dvec3();
    }
    soup
}

/// One valid file per format and encoding, as (file name, bytes).
pub fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let soup = awkward_soup();
    let mut out = Vec::new();
    let mut put = |name: &'static str, f: &dyn Fn(&mut Vec<u8>) -> std::io::Result<()>| {
        let mut bytes = Vec::new();
        f(&mut bytes).unwrap();
        out.push((name, bytes));
    };
    put("a.obj", &|w| write_obj(w, &soup));
    put("a.off", &|w| write_off(w, &soup));
    put("ascii.ply", &|w| write_ply(w, &soup, PlyEncoding::Ascii));
    put("le.ply", &|w| {
        write_ply(w, &soup, PlyEncoding::BinaryLittleEndian)
    });
    put("be.ply", &|w| {
        write_ply(w, &soup, PlyEncoding::BinaryBigEndian)
    });
    put("ascii.stl", &|w| write_stl(w, &soup, StlEncoding::Ascii));
    put("binary.stl", &|w| write_stl(w, &soup, StlEncoding::Binary));
    out
}

/// Bit patterns of positions (so -0.0 vs 0.0 and every last bit count).
pub fn bits(positions: &[DVec3]) -> Vec<[u64; 3]> {
    positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect()
}

/// The soup with every triangle given its own three corners, as STL stores it.
pub fn unshared(soup: &TriangleSoup) -> TriangleSoup {
    let positions = soup
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| soup.positions[i as usize]))
        .collect();
    let triangles = (0..soup.triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    TriangleSoup::new(positions, triangles)
}
