//! A small uniform-grid closest-point structure over a triangle soup: the default target of the
//! projection step (brief step 4) until `roar_mesh::spatial::TriangleBvh` is plugged in.

use super::voxelize::{is_degenerate, triangle_box_overlap};
use glam::DVec3;

/// Closest-point queries on a triangle soup, accelerated by a uniform grid of cells.
///
/// Each non-degenerate triangle is listed in every cell it overlaps (exact triangle–box test), and a
/// query visits rings of cells around the query point until no unvisited cell can hold a closer
/// point. Results are exact (up to rounding) for any query point, inside the grid or not.
#[derive(Clone, Debug)]
pub struct ClosestPointGrid {
    triangles: Vec<[DVec3; 3]>,
    origin: DVec3,
    cell: f64,
    dims: [usize; 3],
    cell_start: Vec<u32>,
    cell_triangles: Vec<u32>,
}

impl ClosestPointGrid {
    /// Builds the grid over the non-degenerate triangles of the soup, with about
    /// `cells_along_longest_axis` cells along the longest axis of the soup's bounding box.
    /// Returns `None` when the soup has no non-degenerate triangle with finite coordinates.
    pub fn build(
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        cells_along_longest_axis: usize,
    ) -> Option<ClosestPointGrid> {
        let tris: Vec<[DVec3; 3]> = triangles
            .iter()
            .filter_map(|t| {
                let p = [
                    *positions.get(t[0] as usize)?,
                    *positions.get(t[1] as usize)?,
                    *positions.get(t[2] as usize)?,
                ];
                (p.iter().all(|q| q.is_finite()) && !is_degenerate(p)).then_some(p)
            })
            .collect();
        Self::from_triangles(tris, cells_along_longest_axis)
    }

    /// Builds the grid over the given (already filtered) triangles.
    pub(crate) fn from_triangles(
        tris: Vec<[DVec3; 3]>,
        cells_along_longest_axis: usize,
    ) -> Option<ClosestPointGrid> {
        let first = tris.first()?;
        let (mut min, mut max) = (first[0], first[0]);
        for t in &tris {
            for p in t {
                min = min.min(*p);
                max = max.max(*p);
            }
        }
        let extent = (max - min).max_element().max(f64::MIN_POSITIVE);
        let cell = extent / cells_along_longest_axis.max(1) as f64 * (1.0 + 1e-9);
        let mut dims = [1usize; 3];
        for a in 0..3 {
            dims[a] = (((max[a] - min[a]) / cell).floor() as usize + 1).max(1);
        }
        let n_cells = dims[0] * dims[1] * dims[2];
        // Two passes: count, then fill (CSR layout).
        let mut lists: Vec<(u32, u32)> = Vec::new();
        let half = DVec3::splat(0.5 * cell * (1.0 + 1e-6));
        for (ti, t) in tris.iter().enumerate() {
            let lo = t[0].min(t[1]).min(t[2]);
            let hi = t[0].max(t[1]).max(t[2]);
            let mut range = [(0usize, 0usize); 3];
            for a in 0..3 {
                let l = (((lo[a] - min[a]) / cell).floor().max(0.0) as usize).min(dims[a] - 1);
                let h = (((hi[a] - min[a]) / cell).floor().max(0.0) as usize).min(dims[a] - 1);
                range[a] = (l, h);
            }
            let single = range.iter().all(|r| r.0 == r.1);
            for k in range[2].0..=range[2].1 {
                for j in range[1].0..=range[1].1 {
                    for i in range[0].0..=range[0].1 {
                        let center = min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * cell;
                        if single || triangle_box_overlap(center, half, *t) {
                            let c = i + dims[0] * (j + dims[1] * k);
                            lists.push((c as u32, ti as u32));
                        }
                    }
                }
            }
        }
        lists.sort_unstable();
        let mut cell_start = vec![0u32; n_cells + 1];
        for &(c, _) in &lists {
            cell_start[c as usize + 1] += 1;
        }
        for c in 0..n_cells {
            cell_start[c + 1] += cell_start[c];
        }
        let cell_triangles = lists.into_iter().map(|(_, t)| t).collect();
        Some(ClosestPointGrid {
            triangles: tris,
            origin: min,
            cell,
            dims,
            cell_start,
            cell_triangles,
        })
    }

    /// The closest point of the soup to `p`, or `None` for a non-finite query.
    pub fn closest_point(&self, p: DVec3) -> Option<DVec3> {
        self.closest(p).map(|(q, _)| q)
    }

    /// The closest point of the soup to `p` and its squared distance.
    pub fn closest(&self, p: DVec3) -> Option<(DVec3, f64)> {
        if !p.is_finite() {
            return None;
        }
        let g = (p - self.origin) / self.cell;
        let mut c = [0i64; 3];
        for a in 0..3 {
            c[a] = (g[a].floor() as i64).clamp(0, self.dims[a] as i64 - 1);
        }
        let max_ring = self.dims.iter().copied().max().unwrap_or(1) as i64;
        let mut best: Option<(DVec3, f64)> = None;
        for ring in 0..=max_ring {
            let lo = [c[0] - ring, c[1] - ring, c[2] - ring];
            let hi = [c[0] + ring, c[1] + ring, c[2] + ring];
            for k in lo[2].max(0)..=hi[2].min(self.dims[2] as i64 - 1) {
                for j in lo[1].max(0)..=hi[1].min(self.dims[1] as i64 - 1) {
                    let inner_jk = (k - c[2]).abs() < ring && (j - c[1]).abs() < ring;
                    let mut i = lo[0].max(0);
                    let i_end = hi[0].min(self.dims[0] as i64 - 1);
                    while i <= i_end {
                        if inner_jk && (i - c[0]).abs() < ring {
                            // Interior of the ring's cube was visited earlier: jump to its end.
                            i = c[0] + ring;
                            continue;
                        }
                        let cell =
                            i as usize + self.dims[0] * (j as usize + self.dims[1] * k as usize);
                        let (s, e) = (self.cell_start[cell], self.cell_start[cell + 1]);
                        for &t in &self.cell_triangles[s as usize..e as usize] {
                            let q = closest_point_on_triangle(p, self.triangles[t as usize]);
                            let d2 = (q - p).length_squared();
                            if best.is_none_or(|b| d2 < b.1) {
                                best = Some((q, d2));
                            }
                        }
                        i += 1;
                    }
                }
            }
            // Every cell not yet visited lies at Chebyshev ring > `ring` around the (clamped)
            // query cell, hence at distance ≥ ring · cell from the clamped query point, and
            // clamping to the grid box never increases distances to points inside it.
            if let Some((_, d2)) = best {
                let bound = ring as f64 * self.cell;
                if d2 <= bound * bound {
                    break;
                }
            }
        }
        best
    }
}

/// The closest point to `p` on the triangle `t` (Ericson, Real-Time Collision Detection §5.1.5).
pub(crate) fn closest_point_on_triangle(p: DVec3, t: [DVec3; 3]) -> DVec3 {
    let [a, b, c] = t;
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p: DVec3, tris: &[[DVec3; 3]]) -> f64 {
        tris.iter()
            .map(|t| (closest_point_on_triangle(p, *t) - p).length_squared())
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn grid_matches_brute_force_on_a_random_soup() {
        // Deterministic pseudo-random soup (an LCG keeps this test free of extra dependencies).
        let mut state = 12345u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for t in 0..60 {
            let c = DVec3::new(next(), next(), next()) * 4.0;
            for _ in 0..3 {
                positions.push(c + DVec3::new(next(), next(), next()) * 0.6 - 0.3);
            }
            triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        let grid = ClosestPointGrid::build(&positions, &triangles, 8).unwrap();
        let tris: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect();
        for _ in 0..300 {
            let p = DVec3::new(next(), next(), next()) * 7.0 - 1.5;
            let (_, d2) = grid.closest(p).unwrap();
            let b = brute(p, &tris);
            assert!((d2 - b).abs() <= 1e-12 * (1.0 + b), "grid {d2} brute {b}");
        }
    }

    #[test]
    fn closest_point_on_triangle_regions() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert_eq!(
            closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), t),
            DVec3::ZERO
        );
        assert_eq!(
            closest_point_on_triangle(DVec3::new(0.25, 0.25, 3.0), t),
            DVec3::new(0.25, 0.25, 0.0)
        );
        let q = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), t);
        assert!((q - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
    }
}
