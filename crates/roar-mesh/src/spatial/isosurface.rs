//! The zero level set of values sampled on a regular grid, as a closed, oriented triangle mesh,
//! by marching tetrahedra.
//!
//! Each grid cell is split into the six tetrahedra around its diagonal from the lowest to the
//! highest corner (the Kuhn split: one tetrahedron per order of the axes), so neighbouring cells
//! split their shared faces alike and the pieces match across cells. In each tetrahedron the
//! level set is linear: a triangle (one corner on the other side) or a quad split in two (two
//! corners on each side), with its vertices where the values interpolate linearly to zero on the
//! grid edges, cell diagonals included. A vertex is shared by every tetrahedron around its edge.
//!
//! Unlike marching cubes' case tables, this has no ambiguous cases: where no sample is exactly
//! zero (a zero counts as outside) the output is a 2-manifold, and it is closed when every
//! sample on the grid's boundary is outside ([`marching_tetrahedra`] treats them so).

use std::collections::HashMap;

use glam::DVec3;

/// The six tetrahedra of a cell as corner numbers (bit 0: +x, bit 1: +y, bit 2: +z), each the
/// path 0 → one axis → two axes → 7 for one order of the axes.
const KUHN: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// The zero level set of `values` (negative inside) sampled on a grid of `dims` points over the
/// box `[min, max]` ([module docs](self)): positions and triangles, each triangle
/// counter-clockwise seen from outside (the positive side).
///
/// `values` is in C order (`[i][j][k]` at `(i·ny + j)·nz + k`, i ↔ x) and sample `[i][j][k]`
/// lies at `min + (i/(nx−1), j/(ny−1), k/(nz−1)) ⊙ (max − min)`. Samples on the boundary of the
/// grid count as outside, so the output is closed; a crossing is kept at least 1e-6 of an edge
/// from either end, so no two vertices coincide. Returns empty buffers when `dims` has an axis
/// under 2 samples or `values` has not `nx·ny·nz` entries.
pub fn marching_tetrahedra(
    values: &[f32],
    dims: [usize; 3],
    min: DVec3,
    max: DVec3,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let [nx, ny, nz] = dims;
    if dims.iter().any(|&n| n < 2) || values.len() != nx * ny * nz {
        return (Vec::new(), Vec::new());
    }
    let index = |i: usize, j: usize, k: usize| (i * ny + j) * nz + k;
    let step = (max - min) / DVec3::new((nx - 1) as f64, (ny - 1) as f64, (nz - 1) as f64);
    let point =
        |i: usize, j: usize, k: usize| min + DVec3::new(i as f64, j as f64, k as f64) * step;
    let inside = |i: usize, j: usize, k: usize| {
        let boundary = i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1;
        !boundary && values[index(i, j, k)] < 0.0
    };
    let value = |i: usize, j: usize, k: usize| {
        if inside(i, j, k) {
            f64::from(values[index(i, j, k)])
        } else {
            // A boundary sample inside is mirrored outside, closing the solid there.
            f64::from(values[index(i, j, k)]).abs()
        }
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    // Vertex of the crossing on the grid edge between two samples, by their ordered indices.
    let mut vertex_of_edge: HashMap<(usize, usize), u32> = HashMap::new();
    for i in 0..nx - 1 {
        for j in 0..ny - 1 {
            for k in 0..nz - 1 {
                let corner = |c: usize| (i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                let signs: [bool; 8] = std::array::from_fn(|c| {
                    let (a, b, d) = corner(c);
                    inside(a, b, d)
                });
                if signs.iter().all(|&s| s) || signs.iter().all(|&s| !s) {
                    continue;
                }
                for tet in KUHN {
                    let ins: Vec<usize> = tet.iter().copied().filter(|&c| signs[c]).collect();
                    let outs: Vec<usize> = tet.iter().copied().filter(|&c| !signs[c]).collect();
                    if ins.is_empty() || outs.is_empty() {
                        continue;
                    }
                    let mut crossing = |a: usize, b: usize| -> u32 {
                        let (pa, pb) = (corner(a), corner(b));
                        let (ia, ib) = (index(pa.0, pa.1, pa.2), index(pb.0, pb.1, pb.2));
                        let key = (ia.min(ib), ia.max(ib));
                        *vertex_of_edge.entry(key).or_insert_with(|| {
                            let (fa, fb) = (value(pa.0, pa.1, pa.2), value(pb.0, pb.1, pb.2));
                            let t = (fa / (fa - fb)).clamp(1e-6, 1.0 - 1e-6);
                            let (xa, xb) = (point(pa.0, pa.1, pa.2), point(pb.0, pb.1, pb.2));
                            positions.push(xa + t * (xb - xa));
                            (positions.len() - 1) as u32
                        })
                    };
                    // The crossing polygon in cyclic order (a triangle or a quad).
                    let polygon: Vec<(usize, usize)> = match (ins.len(), outs.len()) {
                        (1, 3) => outs.iter().map(|&o| (ins[0], o)).collect(),
                        (3, 1) => ins.iter().map(|&n| (n, outs[0])).collect(),
                        _ => vec![
                            (ins[0], outs[0]),
                            (ins[0], outs[1]),
                            (ins[1], outs[1]),
                            (ins[1], outs[0]),
                        ],
                    };
                    // Orientation from the edge midpoints: the crossing points slide along
                    // the same edges, so the polygon's facing is that of the midpoint polygon.
                    let corner_point = |c: usize| {
                        let (a, b, d) = corner(c);
                        point(a, b, d)
                    };
                    let mid: Vec<DVec3> = polygon
                        .iter()
                        .map(|&(a, b)| 0.5 * (corner_point(a) + corner_point(b)))
                        .collect();
                    let normal = (mid[1] - mid[0]).cross(mid[2] - mid[0]);
                    let inward =
                        ins.iter().map(|&c| corner_point(c)).sum::<DVec3>() / ins.len() as f64;
                    let outward =
                        outs.iter().map(|&c| corner_point(c)).sum::<DVec3>() / outs.len() as f64;
                    let flip = normal.dot(outward - inward) < 0.0;
                    let ids: Vec<u32> = polygon.iter().map(|&(a, b)| crossing(a, b)).collect();
                    let mut emit = |a: u32, b: u32, c: u32| {
                        triangles.push(if flip { [a, c, b] } else { [a, b, c] });
                    };
                    emit(ids[0], ids[1], ids[2]);
                    if ids.len() == 4 {
                        emit(ids[0], ids[2], ids[3]);
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
    use crate::Mesh;

    fn sphere_grid(n: usize, radius: f64) -> (Vec<f32>, DVec3, DVec3) {
        let (min, max) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        let mut values = Vec::with_capacity(n * n * n);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = min
                        + DVec3::new(i as f64, j as f64, k as f64) / (n - 1) as f64 * (max - min);
                    values.push((p.length() - radius) as f32);
                }
            }
        }
        (values, min, max)
    }

    #[test]
    fn a_sampled_sphere_gives_a_closed_outward_genus_zero_mesh_on_the_sphere() {
        let (values, min, max) = sphere_grid(24, 0.7);
        let (positions, triangles) = marching_tetrahedra(&values, [24; 3], min, max);
        let mesh = Mesh::from_triangles(positions.clone(), &triangles).expect("closed manifold");
        assert_eq!(mesh.genus(), 0);
        for p in &positions {
            assert!((p.length() - 0.7).abs() < 5e-3, "{p} off the sphere");
        }
        // Outward: the signed volume is the ball's (within the polygonal shrinkage).
        let volume: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let ball = 4.0 / 3.0 * std::f64::consts::PI * 0.7f64.powi(3);
        assert!(
            (volume / ball - 1.0).abs() < 0.02,
            "volume {volume} vs {ball}"
        );
    }

    #[test]
    fn a_solid_touching_the_grid_boundary_is_closed_there_and_a_torus_has_genus_one() {
        // A ball wider than the grid: its boundary samples count as outside.
        let (values, min, max) = sphere_grid(10, 1.5);
        let (positions, triangles) = marching_tetrahedra(&values, [10; 3], min, max);
        let mesh = Mesh::from_triangles(positions, &triangles).expect("closed manifold");
        assert_eq!(mesh.genus(), 0);
        let n = 32;
        let mut values = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = DVec3::new(i as f64, j as f64, k as f64) / (n - 1) as f64 * 2.0
                        - DVec3::ONE;
                    let ring = (p.truncate().length() - 0.6).hypot(p.z);
                    values.push((ring - 0.2) as f32);
                }
            }
        }
        let (positions, triangles) =
            marching_tetrahedra(&values, [n; 3], DVec3::splat(-1.0), DVec3::ONE);
        let mesh = Mesh::from_triangles(positions, &triangles).expect("closed manifold");
        assert_eq!(mesh.genus(), 1);
        assert!(
            marching_tetrahedra(&values, [n, n, 1], DVec3::ZERO, DVec3::ONE)
                .1
                .is_empty()
        );
    }
}
