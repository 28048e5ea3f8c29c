//! Step 3: the boundary between the solid and the exterior as an outward-oriented triangle mesh,
//! one vertex per grid corner (the voxel set has been repaired, so that mesh is a 2-manifold).

use super::grid::{EXTERIOR, Grid, SOLID};
use glam::DVec3;

/// One boundary square of the voxel set.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Quad {
    /// Grid corner with the smallest coordinates.
    pub min_corner: [usize; 3],
    /// Axis of the square's normal (0, 1, 2).
    pub axis: usize,
    /// Outward unit normal (±1 along `axis`).
    pub normal: DVec3,
    /// Vertex ids, counter-clockwise seen from outside.
    pub vertices: [u32; 4],
}

/// The extracted voxel surface.
#[derive(Clone, Debug, Default)]
pub(crate) struct VoxelSurface {
    /// Integer grid corner of each vertex.
    pub corners: Vec<[usize; 3]>,
    /// World position of each vertex.
    pub positions: Vec<DVec3>,
    /// Boundary squares; quad `q` owns triangles `2q` and `2q + 1`.
    pub quads: Vec<Quad>,
    /// Triangles, outward oriented.
    pub triangles: Vec<[u32; 3]>,
}

/// Extracts every square between a `SOLID` voxel and an `EXTERIOR` voxel, outward = toward the
/// exterior, and splits each into two triangles along the diagonal through its first vertex.
/// Grid border voxels are always exterior (the flood starts there), so no square is lost at the
/// border.
pub(crate) fn extract_boundary(grid: &Grid, state: &[u8]) -> VoxelSurface {
    let corner_dims = [grid.dims[0] + 1, grid.dims[1] + 1, grid.dims[2] + 1];
    let mut vertex_of_corner = vec![u32::MAX; corner_dims[0] * corner_dims[1] * corner_dims[2]];
    let mut surface = VoxelSurface::default();
    let mut vertex = |surface: &mut VoxelSurface, c: [usize; 3]| -> u32 {
        let key = c[0] + corner_dims[0] * (c[1] + corner_dims[1] * c[2]);
        if vertex_of_corner[key] == u32::MAX {
            vertex_of_corner[key] = surface.positions.len() as u32;
            surface.positions.push(grid.corner(c));
            surface.corners.push(c);
        }
        vertex_of_corner[key]
    };
    for idx in solid_voxels_in_morton_order(grid, state) {
        let c = grid.coords(idx);
        for a in 0..3 {
            for positive in [false, true] {
                let neighbour_exterior = if positive {
                    c[a] + 1 >= grid.dims[a] || {
                        let mut n = c;
                        n[a] += 1;
                        state[grid.index(n[0], n[1], n[2])] == EXTERIOR
                    }
                } else {
                    c[a] == 0 || {
                        let mut n = c;
                        n[a] -= 1;
                        state[grid.index(n[0], n[1], n[2])] == EXTERIOR
                    }
                };
                if !neighbour_exterior {
                    continue;
                }
                let (u, v) = ((a + 1) % 3, (a + 2) % 3);
                let mut base = c;
                if positive {
                    base[a] += 1;
                }
                let mut corners = [base; 4];
                corners[1][u] += 1;
                corners[2][u] += 1;
                corners[2][v] += 1;
                corners[3][v] += 1;
                // (e_u, e_v) is counter-clockwise around +e_a; reverse for the -e_a side.
                if !positive {
                    corners.swap(1, 3);
                }
                let ids = corners.map(|q| vertex(&mut surface, q));
                let mut normal = DVec3::ZERO;
                normal[a] = if positive { 1.0 } else { -1.0 };
                surface.quads.push(Quad {
                    min_corner: base,
                    axis: a,
                    normal,
                    vertices: ids,
                });
                surface.triangles.push([ids[0], ids[1], ids[2]]);
                surface.triangles.push([ids[0], ids[2], ids[3]]);
            }
        }
    }
    surface
}

/// Spreads the low 21 bits of `x` to every third bit (bit `i` goes to bit `3i`).
fn spread_bits(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The solid voxels in Morton (Z-curve) order of their coordinates.
/// Extracting in this order gives vertices and faces that are near in space nearby ids, so the
/// later stages (projection sweeps, QEM) touch few cache lines per local operation.
fn solid_voxels_in_morton_order(grid: &Grid, state: &[u8]) -> Vec<usize> {
    let mut keyed: Vec<(u64, usize)> = (0..grid.len())
        .filter(|&idx| state[idx] == SOLID)
        .map(|idx| {
            let c = grid.coords(idx);
            let key = spread_bits(c[0] as u64)
                | spread_bits(c[1] as u64) << 1
                | spread_bits(c[2] as u64) << 2;
            (key, idx)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, idx)| idx).collect()
}
