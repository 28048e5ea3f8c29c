//! Small hand-built closed meshes and a deterministic pseudo-random gradient for the optimizer
//! tests.
#![allow(dead_code)]

use glam::DVec3;
use std::collections::HashMap;

/// The octahedron with vertices ±r·e_x, ±r·e_y, ±r·e_z (ids 0..6 = +x, −x, +y, −y, +z, −z),
/// faces outward-oriented. Every edge has length r·√2.
pub fn octahedron(r: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let positions = vec![
        DVec3::X * r,
        -DVec3::X * r,
        DVec3::Y * r,
        -DVec3::Y * r,
        DVec3::Z * r,
        -DVec3::Z * r,
    ];
    let triangles = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (positions, triangles)
}

/// A closed, welded grid on the surface of a cube.
pub struct CubeGrid {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Outward-oriented triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The vertex id of each lattice point `(i, j, k)` in `0..=n` on the surface.
    pub lattice: HashMap<[i32; 3], u32>,
}

/// The closed surface of the cube [0, side]³ with an n×n grid of quads (two triangles each)
/// on every face, vertices welded.
pub fn cube_grid(n: i32, side: f64) -> CubeGrid {
    let mut ids: HashMap<[i32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut id_of = |c: [i32; 3], positions: &mut Vec<DVec3>| -> u32 {
        *ids.entry(c).or_insert_with(|| {
            positions.push(DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * (side / n as f64));
            (positions.len() - 1) as u32
        })
    };
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for s in [0, n] {
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: i32, dj: i32| {
                        let mut p = [0; 3];
                        p[a] = s;
                        p[b] = i + di;
                        p[c] = j + dj;
                        p
                    };
                    let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                    let q = q.map(|p| id_of(p, &mut positions));
                    let (t0, t1) = ([q[0], q[1], q[2]], [q[0], q[2], q[3]]);
                    if s == n {
                        triangles.extend([t0, t1]);
                    } else {
                        triangles.extend([[t0[0], t0[2], t0[1]], [t1[0], t1[2], t1[1]]]);
                    }
                }
            }
        }
    }
    CubeGrid {
        positions,
        triangles,
        lattice: ids,
    }
}

/// A deterministic pseudo-random vector in [−1, 1)³ from two integers (splitmix64).
pub fn noise(a: u64, b: u64) -> DVec3 {
    let mut state = a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_add(0x632B_E59B_D9B4_E019);
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    DVec3::new(next(), next(), next())
}
