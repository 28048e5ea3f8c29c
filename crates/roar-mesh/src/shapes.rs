//! Procedural closed meshes for tests and initialization: [`icosphere`], [`torus`], [`cube`],
//! [`genus_n_solid`], and [`perturbed`] copies. All are outward-oriented (positive
//! [`Mesh::signed_volume`]) and valid ([`Mesh::validate`]).

use crate::mesh::Mesh;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// Builds a mesh from buffers this module generated; they are valid by construction.
fn build(positions: Vec<DVec3>, triangles: &[[u32; 3]]) -> Mesh {
    Mesh::from_triangles(positions, triangles)
        .unwrap_or_else(|e| panic!("roar-mesh shapes generated an invalid mesh (bug): {e}"))
}

/// Icosphere of radius 1 centred at the origin: the icosahedron subdivided `level` times (each
/// level splits every triangle into 4 and projects onto the sphere). `20·4^level` faces,
/// `10·4^level + 2` vertices. Level 0 is the icosahedron.
pub fn icosphere(level: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<DVec3>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(4 * triangles.len());
        for &[a, b, c] in &triangles {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    build(positions, &triangles)
}

/// Torus around the z axis with major radius `major_radius` (centre of the tube) and minor
/// radius `minor_radius` (tube), `major_segments × minor_segments` quads split into 2 triangles.
/// Segment counts below 3 are raised to 3 (the smallest that gives a simplicial torus).
/// Genus 1.
pub fn torus(
    major_segments: usize,
    minor_segments: usize,
    major_radius: f64,
    minor_radius: f64,
) -> Mesh {
    let (m, n) = (major_segments.max(3), minor_segments.max(3));
    let mut positions = Vec::with_capacity(m * n);
    for i in 0..m {
        let u = std::f64::consts::TAU * i as f64 / m as f64;
        for j in 0..n {
            let v = std::f64::consts::TAU * j as f64 / n as f64;
            let ring = major_radius + minor_radius * v.cos();
            positions.push(DVec3::new(
                ring * u.cos(),
                ring * u.sin(),
                minor_radius * v.sin(),
            ));
        }
    }
    let id = |i: usize, j: usize| ((i % m) * n + (j % n)) as u32;
    let mut triangles = Vec::with_capacity(2 * m * n);
    for i in 0..m {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    build(positions, &triangles)
}

/// The unit cube `[-0.5, 0.5]³`: 8 vertices, 12 triangles, outward.
pub fn cube() -> Mesh {
    let (positions, triangles) = voxel_surface([1, 1, 1], 1.0, |_| true);
    build(positions, &triangles)
}

/// A closed solid of genus `n`: a flat slab (about `(2n+1) × 3 × 1` units, centred at the
/// origin) with `n` square through-holes in a row, built from voxels (each unit cell split
/// into 2×2×2) and triangulated. `n = 0` gives a box (genus 0).
pub fn genus_n_solid(n: usize) -> Mesh {
    const SUB: usize = 2;
    let coarse = [2 * n + 1, 3, 1];
    let dims = coarse.map(|c| c * SUB);
    let filled = |[x, y, _]: [usize; 3]| {
        let (cx, cy) = (x / SUB, y / SUB);
        !(cy == 1 && cx % 2 == 1)
    };
    let (positions, triangles) = voxel_surface(dims, 1.0 / SUB as f64, filled);
    build(positions, &triangles)
}

/// A copy of `mesh` with every live vertex moved by an independent uniform offset in
/// `[-amplitude, amplitude]³`, seeded by `seed` (ChaCha8, deterministic). Topology unchanged.
pub fn perturbed(mesh: &Mesh, amplitude: f64, seed: u64) -> Mesh {
    let mut out = mesh.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let live: Vec<_> = out.vertices().collect();
    for v in live {
        let offset = DVec3::new(
            rng.random::<f64>() * 2.0 - 1.0,
            rng.random::<f64>() * 2.0 - 1.0,
            rng.random::<f64>() * 2.0 - 1.0,
        ) * amplitude;
        let p = out.position(v) + offset;
        out.set_position(v, p);
    }
    out
}

/// Outward boundary of the filled cells of a `dims` grid (cell size `h`, centred at the origin):
/// one quad (two triangles) per face between a filled and an empty cell. The caller's occupancy
/// must have no two cells touching only along an edge or at a corner (that would be
/// non-manifold).
fn voxel_surface(
    dims: [usize; 3],
    h: f64,
    filled: impl Fn([usize; 3]) -> bool,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let is_filled = |c: [i64; 3]| {
        (0..3).all(|k| c[k] >= 0 && (c[k] as usize) < dims[k])
            && filled([c[0] as usize, c[1] as usize, c[2] as usize])
    };
    let centre = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * (0.5 * h);
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut corner = |p: [i64; 3], positions: &mut Vec<DVec3>| -> u32 {
        *index.entry(p).or_insert_with(|| {
            positions.push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * h - centre);
            (positions.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for z in 0..dims[2] as i64 {
        for y in 0..dims[1] as i64 {
            for x in 0..dims[0] as i64 {
                let cell = [x, y, z];
                if !is_filled(cell) {
                    continue;
                }
                for d in 0..3 {
                    let (u, w) = ((d + 1) % 3, (d + 2) % 3);
                    for positive in [false, true] {
                        let mut nb = cell;
                        nb[d] += if positive { 1 } else { -1 };
                        if is_filled(nb) {
                            continue;
                        }
                        let mut base = cell;
                        if positive {
                            base[d] += 1;
                        }
                        let offset = |du: i64, dw: i64| {
                            let mut p = base;
                            p[u] += du;
                            p[w] += dw;
                            p
                        };
                        // u × w = +d, so (0,0) → u → u+w → w is counter-clockwise seen from +d.
                        let quad = if positive {
                            [offset(0, 0), offset(1, 0), offset(1, 1), offset(0, 1)]
                        } else {
                            [offset(0, 0), offset(0, 1), offset(1, 1), offset(1, 0)]
                        };
                        let q = quad.map(|p| corner(p, &mut positions));
                        triangles.push([q[0], q[1], q[2]]);
                        triangles.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
    }
    (positions, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_are_valid_outward_with_expected_counts_and_genus() {
        let ico = icosphere(2);
        assert_eq!((ico.n_vertices(), ico.n_faces()), (162, 320));
        let c = cube();
        assert_eq!((c.n_vertices(), c.n_faces()), (8, 12));
        assert!((c.signed_volume() - 1.0).abs() < 1e-12);
        let t = torus(12, 8, 1.0, 0.3);
        assert_eq!(t.n_faces(), 192);
        for (mesh, genus) in [(ico, 0), (c, 0), (t, 1)] {
            mesh.validate().unwrap();
            assert!(mesh.signed_volume() > 0.0);
            assert_eq!(mesh.genus(), genus);
        }
        for n in 0..4 {
            let m = genus_n_solid(n);
            m.validate().unwrap();
            assert!(m.signed_volume() > 0.0);
            assert_eq!(m.genus(), n, "genus_n_solid({n})");
            assert_eq!(m.components().0, 1);
        }
    }

    #[test]
    fn icosphere_is_on_the_unit_sphere() {
        let m = icosphere(3);
        for v in m.vertices() {
            assert!((m.position(v).length() - 1.0).abs() < 1e-12);
        }
        // Volume approaches 4π/3 from below.
        let vol = m.signed_volume();
        assert!(
            vol > 0.95 * 4.0 / 3.0 * std::f64::consts::PI && vol < 4.0 / 3.0 * std::f64::consts::PI
        );
    }

    #[test]
    fn perturbed_is_deterministic_and_bounded() {
        let m = icosphere(1);
        let a = perturbed(&m, 0.01, 7);
        let b = perturbed(&m, 0.01, 7);
        let c = perturbed(&m, 0.01, 8);
        assert_eq!(a, b);
        assert_ne!(a, c);
        for v in m.vertices() {
            let d = a.position(v) - m.position(v);
            assert!(d.abs().max_element() <= 0.01);
            assert!(d.length() > 0.0);
        }
        assert_eq!(a.to_triangles().1, m.to_triangles().1);
    }
}
