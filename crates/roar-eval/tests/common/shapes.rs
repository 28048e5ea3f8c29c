//! Procedural closed meshes for tests: cube, torus, icosphere.

use glam::DVec3;

/// Unit cube `[0,1]³`, 12 triangles wound outward.
pub fn cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3], // z = 0, normal −z
        [4, 5, 6],
        [5, 7, 6], // z = 1
        [0, 1, 4],
        [1, 5, 4], // y = 0
        [2, 6, 3],
        [3, 6, 7], // y = 1
        [0, 4, 2],
        [2, 4, 6], // x = 0
        [1, 3, 5],
        [3, 7, 5], // x = 1
    ];
    (p, t)
}

/// Torus with radii `big`, `small`, `n × m` quads split into triangles, wound outward.
pub fn torus(big: f64, small: f64, n: u32, m: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = std::f64::consts::TAU * j as f64 / m as f64;
            let r = big + small * v.cos();
            p.push(DVec3::new(r * u.cos(), r * u.sin(), small * v.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (p, t)
}

/// `roar_mesh::shapes::icosphere(levels)` scaled to `radius` (20·4^levels faces), wound outward.
pub fn icosphere(radius: f64, levels: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (p, t) = roar_mesh::shapes::icosphere(levels).to_triangles();
    (p.into_iter().map(|q| q * radius).collect(), t)
}
