//! Step 1 and the dilation of step 2 of the watertight init (module docs): mark every voxel a
//! triangle touches, with the exact triangle–box overlap test of Akenine-Möller (separating axes).

use super::grid::Grid;
use glam::DVec3;
use rayon::prelude::*;

/// Whether the triangle `(v0, v1, v2)` overlaps the closed axis-aligned box `center ± half`.
///
/// Separating-axis test over the 13 candidate axes (3 box normals, the triangle normal and the 9
/// edge × box-axis products). Exact up to rounding; callers pass a slightly inflated `half` to make
/// it conservative. Degenerate triangles are handled (zero axes never separate).
pub(crate) fn triangle_box_overlap(center: DVec3, half: DVec3, tri: [DVec3; 3]) -> bool {
    let v = [tri[0] - center, tri[1] - center, tri[2] - center];
    // Box normals: the triangle's AABB against the box.
    for a in 0..3 {
        let lo = v[0][a].min(v[1][a]).min(v[2][a]);
        let hi = v[0][a].max(v[1][a]).max(v[2][a]);
        if lo > half[a] || hi < -half[a] {
            return false;
        }
    }
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let separated = |axis: DVec3| -> bool {
        let p0 = axis.dot(v[0]);
        let p1 = axis.dot(v[1]);
        let p2 = axis.dot(v[2]);
        let r = half.x * axis.x.abs() + half.y * axis.y.abs() + half.z * axis.z.abs();
        p0.min(p1).min(p2) > r || p0.max(p1).max(p2) < -r
    };
    if separated(edges[0].cross(edges[1])) {
        return false;
    }
    for e in edges {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            if separated(e.cross(axis)) {
                return false;
            }
        }
    }
    true
}

/// Whether the triangle has (numerically) zero area relative to its size.
pub(crate) fn is_degenerate(tri: [DVec3; 3]) -> bool {
    let e0 = tri[1] - tri[0];
    let e1 = tri[2] - tri[0];
    let area2 = e0.cross(e1).length();
    let scale = e0
        .length_squared()
        .max(e1.length_squared())
        .max((tri[2] - tri[1]).length_squared());
    !area2.is_finite() || area2 <= 1e-14 * scale
}

/// Marks (sets to 1) every voxel that one of the triangles touches. Triangles are given in world
/// coordinates; the test runs in grid coordinates with the box inflated by 1e-9 voxel so that a
/// triangle lying exactly on a voxel face marks both neighbours.
///
/// Along each row of voxels of a triangle's bounding box only the voxels near the triangle's
/// plane are tested ([`row_near_plane`]); the others fail the exact test's plane axis anyway, so
/// the marks are those of testing every voxel of the box. (A big triangle's box holds many
/// times more voxels than its plane crosses.)
pub(crate) fn mark_surface_voxels(grid: &Grid, triangles: &[[DVec3; 3]]) -> Vec<u8> {
    let mut marked = vec![0u8; grid.len()];
    let half = DVec3::splat(0.5 + 1e-9);
    for tri in triangles {
        let g = [
            grid.to_grid(tri[0]),
            grid.to_grid(tri[1]),
            grid.to_grid(tri[2]),
        ];
        let lo = g[0].min(g[1]).min(g[2]);
        let hi = g[0].max(g[1]).max(g[2]);
        let mut range = [(0usize, 0usize); 3];
        for a in 0..3 {
            let l = (lo[a] - 1e-6).floor().max(0.0) as usize;
            let h = ((hi[a] + 1e-6).floor() as usize).min(grid.dims[a] - 1);
            range[a] = (l, h);
        }
        for k in range[2].0..=range[2].1 {
            for j in range[1].0..=range[1].1 {
                let Some((i0, i1)) = row_near_plane(g, half, j, k, range[0]) else {
                    continue;
                };
                for i in i0..=i1 {
                    let center = DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5);
                    if triangle_box_overlap(center, half, g) {
                        marked[grid.index(i, j, k)] = 1;
                    }
                }
            }
        }
    }
    marked
}

/// The voxels `i0..=i1` within `range` of the row `(·, j, k)` whose boxes (`center ± half`, in
/// grid coordinates) may meet the plane of `tri`: every voxel of the row that
/// [`triangle_box_overlap`] accepts is among them. `None` when there is none.
///
/// A box meets the plane `n·x = n·tri[0]` iff `|n·tri[0] − n·center| ≤ half·|n|`, which bounds the
/// centre's `x` to an interval; it is widened by one voxel on each side, far more than the
/// rounding of either computation. Planes nearly parallel to the row (`|n.x|` tiny against `|n|`)
/// and (nearly) degenerate triangles, whose computed normals are rounding noise, keep the whole
/// range.
fn row_near_plane(
    tri: [DVec3; 3],
    half: DVec3,
    j: usize,
    k: usize,
    range: (usize, usize),
) -> Option<(usize, usize)> {
    let (e0, e1) = (tri[1] - tri[0], tri[2] - tri[0]);
    let n = e0.cross(e1);
    // The plane must be well defined (the sine of the angle at `tri[0]` above 1e-6, so the
    // exact test's own normal, computed otherwise, agrees with `n` to far better than the
    // margin) and not nearly parallel to the row.
    let len = n.length();
    let restrict = len > 1e-6 * e0.length() * e1.length() && n.x.abs() > 1e-6 * len;
    if !restrict {
        return Some(range);
    }
    let r = half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs();
    let rest = n.dot(tri[0]) - n.y * (j as f64 + 0.5) - n.z * (k as f64 + 0.5);
    let (a, b) = ((rest - r) / n.x, (rest + r) / n.x);
    // Centre x = i + 0.5 lies in [min(a, b), max(a, b)]; one voxel of margin each way.
    let lo = (a.min(b) - 1.5).floor().max(range.0 as f64);
    let hi = (a.max(b) + 0.5).ceil().min(range.1 as f64);
    (lo <= hi).then_some((lo as usize, hi as usize))
}

/// Dilates a 0/1 voxel set by one voxel in all 26 directions (a 3×3×3 box), done as three
/// separable one-voxel passes along x, y and z. A voxel keeps its own value when non-zero and
/// becomes 1 when a neighbour along the pass's axis is non-zero.
///
/// Each pass reads the previous one and writes every voxel from its own neighbours, so the
/// z-slices are filled in parallel with the same result as one loop.
pub(crate) fn dilate_box(grid: &Grid, set: &[u8]) -> Vec<u8> {
    let [nx, ny, nz] = grid.dims;
    let slice = nx * ny;
    let mut current = set.to_vec();
    let mut next = vec![0u8; set.len()];
    for a in 0..3 {
        let stride = [1, nx, slice][a];
        let cur = &current;
        next.par_chunks_mut(slice).enumerate().for_each(|(k, out)| {
            for j in 0..ny {
                for i in 0..nx {
                    let idx = i + nx * j + slice * k;
                    let c = [i, j, k][a];
                    let mut v = cur[idx];
                    if v == 0 {
                        let low = c > 0 && cur[idx - stride] != 0;
                        let high = c + 1 < grid.dims[a] && cur[idx + stride] != 0;
                        v = u8::from(low || high);
                    }
                    out[i + nx * j] = v;
                }
            }
        });
        debug_assert_eq!(nz * slice, set.len());
        std::mem::swap(&mut current, &mut next);
    }
    current
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_inside_box_overlaps_and_far_triangle_does_not() {
        let tri = [DVec3::ZERO, DVec3::X * 0.1, DVec3::Y * 0.1];
        assert!(triangle_box_overlap(DVec3::ZERO, DVec3::splat(0.5), tri));
        let far = tri.map(|p| p + DVec3::splat(3.0));
        assert!(!triangle_box_overlap(DVec3::ZERO, DVec3::splat(0.5), far));
    }

    #[test]
    fn diagonal_triangle_missing_the_corner_is_separated_by_its_plane() {
        // Plane x + y + z = 2.9 passes near the box corner (0.5, 0.5, 0.5) only at distance.
        let tri = [
            DVec3::new(2.9, 0.0, 0.0),
            DVec3::new(0.0, 2.9, 0.0),
            DVec3::new(0.0, 0.0, 2.9),
        ];
        assert!(!triangle_box_overlap(DVec3::ZERO, DVec3::splat(0.5), tri));
        let closer = tri.map(|p| p * (1.4 / 2.9));
        assert!(triangle_box_overlap(DVec3::ZERO, DVec3::splat(0.5), closer));
    }

    #[test]
    fn triangle_plane_passing_beside_a_box_edge_separates() {
        // A long thin triangle along the direction (1, -1, 0), just beyond the box edge at
        // x = y = 0.5: its plane separates it.
        let tri = [
            DVec3::new(3.0, -1.9, -5.0),
            DVec3::new(-1.9, 3.0, -5.0),
            DVec3::new(-1.9, 3.0, 5.0),
        ];
        assert!(!triangle_box_overlap(DVec3::ZERO, DVec3::splat(0.5), tri));
    }

    /// Oracle: on random triangles (big, small, thin, axis-parallel, degenerate) the marks equal
    /// those of testing every voxel of each triangle's bounding box.
    #[test]
    fn marks_equal_testing_every_voxel_of_the_box() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let grid = Grid {
            dims: [23, 19, 21],
            origin: DVec3::new(-0.3, 0.1, 0.2),
            voxel_size: 0.7,
        };
        let brute = |triangles: &[[DVec3; 3]]| {
            let mut marked = vec![0u8; grid.len()];
            let half = DVec3::splat(0.5 + 1e-9);
            for (idx, m) in marked.iter_mut().enumerate() {
                let c = grid.coords(idx);
                let center = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) + 0.5;
                let hit = triangles
                    .iter()
                    .any(|tri| triangle_box_overlap(center, half, tri.map(|p| grid.to_grid(p))));
                *m = u8::from(hit);
            }
            marked
        };
        let point = |rng: &mut rand_chacha::ChaCha8Rng| {
            DVec3::new(
                rng.random_range(0.0..15.0),
                rng.random_range(0.0..13.0),
                rng.random_range(0.0..14.0),
            )
        };
        for case in 0..300 {
            let triangles: Vec<[DVec3; 3]> = (0..4)
                .map(|t| {
                    let mut a = point(&mut rng);
                    let mut b = point(&mut rng);
                    let mut c = point(&mut rng);
                    match (case + t) % 5 {
                        0 => {
                            // Small.
                            b = a + (b - a) * 0.1;
                            c = a + (c - a) * 0.1;
                        }
                        1 => {
                            // In a plane x = const (parallel to the rows' normal axis).
                            b.x = a.x;
                            c.x = a.x;
                        }
                        2 => {
                            // In a plane y = const, on voxel faces.
                            let y = grid.origin.y + 0.7 * 6.0;
                            (a.y, b.y, c.y) = (y, y, y);
                        }
                        3 => c = a + 0.5 * (b - a), // degenerate
                        _ => {}
                    }
                    [a, b, c]
                })
                .collect();
            assert_eq!(
                mark_surface_voxels(&grid, &triangles),
                brute(&triangles),
                "case {case}"
            );
        }
    }

    #[test]
    fn dilation_equals_the_brute_force_box_on_random_sets() {
        let grid = Grid::unit([7, 5, 6]);
        let mut state = 12345u64;
        let mut bit = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            u8::from(state >> 60 == 0)
        };
        for _ in 0..20 {
            let set: Vec<u8> = (0..grid.len()).map(|_| bit()).collect();
            let d = dilate_box(&grid, &set);
            for idx in 0..grid.len() {
                let c = grid.coords(idx).map(|x| x as i64);
                let mut any = false;
                for dz in -1..=1i64 {
                    for dy in -1..=1i64 {
                        for dx in -1..=1i64 {
                            let n = [c[0] + dx, c[1] + dy, c[2] + dz];
                            if (0..3).all(|a| n[a] >= 0 && n[a] < grid.dims[a] as i64) {
                                let [x, y, z] = n.map(|v| v as usize);
                                any |= set[grid.index(x, y, z)] == 1;
                            }
                        }
                    }
                }
                assert_eq!(d[idx], u8::from(any), "voxel {c:?}");
            }
        }
    }

    #[test]
    fn dilation_grows_a_single_voxel_into_a_3x3x3_block() {
        let grid = Grid::unit([5, 5, 5]);
        let mut set = vec![0u8; grid.len()];
        set[grid.index(2, 2, 2)] = 1;
        let d = dilate_box(&grid, &set);
        assert_eq!(d.iter().filter(|&&x| x == 1).count(), 27);
        assert_eq!(d[grid.index(1, 1, 1)], 1);
        assert_eq!(d[grid.index(0, 2, 2)], 0);
    }
}
