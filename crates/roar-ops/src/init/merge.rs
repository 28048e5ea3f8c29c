//! Merging nearby pieces when there are more than the face budget can shape: a morphological
//! closing of the solid (dilate by a ball of `r` voxels, then erode by the same ball), with the
//! smallest radius that brings the piece count down to the target. Parts closer than about `2r`
//! join into one closed blob, the way a wrap would close a ficus's leaves into a canopy, while
//! parts farther apart stay separate; concave details narrower than about `2r` fill too.
//!
//! Distances are Euclidean, from an exact squared distance transform (Felzenszwalb and
//! Huttenlocher 2012), computed on a copy of the grid widened by `r + 1` voxels on every side so
//! that the erosion sees the true dilation near the border.

use super::grid::{EXTERIOR, Grid, SOLID};
use rayon::prelude::*;

/// Squared distance standing for "no seed on this line" in [`squared_distances`].
const FAR: u32 = u32::MAX;

/// What [`merge_pieces`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Merge {
    /// Counted pieces before the closing.
    pub pieces_before: usize,
    /// Counted pieces after it (`pieces_before` when nothing was closed).
    pub pieces_after: usize,
    /// Radius of the closing in voxels (0: none).
    pub radius: usize,
}

/// Closes the solid of `state` (and floods the exterior again) with the smallest radius in
/// `1..=max_radius` whose result has at most `target` counted pieces and no more handles than
/// before (a radius that only bridges a lattice of parts leaves a hole in every cell of it; a
/// slightly larger one fills them). When no radius reaches `target`, the smallest radius that
/// gives the fewest pieces found without adding handles is used, and none at all when no radius
/// merges anything (so parts too far apart to merge keep their shape). The result's exterior is
/// again exactly what the border reaches.
pub(crate) fn merge_pieces(
    grid: &Grid,
    state: &mut Vec<u8>,
    target: usize,
    max_radius: usize,
    min_area_fraction: f64,
) -> Merge {
    let before = census(grid, state, min_area_fraction);
    let mut merge = Merge {
        pieces_before: before.pieces,
        pieces_after: before.pieces,
        radius: 0,
    };
    if before.pieces <= target || max_radius == 0 {
        return merge;
    }
    // Pieces at radius `r`, or `usize::MAX` when the closing adds handles.
    let pieces = |r: usize| {
        let c = census(grid, &closed(grid, state, r), min_area_fraction);
        if c.handles() > before.handles() {
            usize::MAX
        } else {
            c.pieces
        }
    };
    // Doubling radii, then bisection below the first one that gives the best count (`target`,
    // or the fewest pieces seen when `target` is out of reach) for the smallest such radius.
    let clipped = |c: usize| c.max(target);
    let mut tried: Vec<(usize, usize)> = vec![(0, before.pieces)];
    let mut r = 1;
    loop {
        let c = pieces(r);
        tried.push((r, c));
        if c <= target || r == max_radius {
            break;
        }
        r = (2 * r).min(max_radius);
    }
    let goal = tried
        .iter()
        .map(|&(_, c)| clipped(c))
        .min()
        .unwrap_or(before.pieces);
    let first = tried
        .iter()
        .position(|&(_, c)| clipped(c) == goal)
        .unwrap_or(0);
    if first == 0 {
        return merge;
    }
    let (mut lo, mut best) = (tried[first - 1].0, tried[first]);
    while best.0 - lo > 1 {
        let mid = (lo + best.0) / 2;
        let c = pieces(mid);
        if clipped(c) <= goal {
            best = (mid, c);
        } else {
            lo = mid;
        }
    }
    *state = closed(grid, state, best.0);
    merge.radius = best.0;
    merge.pieces_after = best.1;
    merge
}

/// The state after closing its solid with a ball of `radius` voxels; the exterior is flooded
/// again from the border, so voids the closing sealed become solid.
pub(crate) fn closed(grid: &Grid, state: &[u8], radius: usize) -> Vec<u8> {
    let m = radius + 1;
    let wide = [0, 1, 2].map(|a| grid.dims[a] + 2 * m);
    let wide_index = |c: [usize; 3]| (c[0] + m) + wide[0] * ((c[1] + m) + wide[1] * (c[2] + m));
    let r2 = (radius * radius) as u32;
    let mut seeds = vec![false; wide[0] * wide[1] * wide[2]];
    for (idx, &s) in state.iter().enumerate() {
        if s == SOLID {
            seeds[wide_index(grid.coords(idx))] = true;
        }
    }
    // Dilation: within `radius` of the solid. Erosion: farther than `radius` from every voxel
    // outside the dilation.
    let to_solid = squared_distances(wide, &seeds);
    let outside: Vec<bool> = to_solid.iter().map(|&d| d > r2).collect();
    let to_outside = squared_distances(wide, &outside);
    let blocked: Vec<u8> = (0..grid.len())
        .map(|idx| u8::from(state[idx] == SOLID || to_outside[wide_index(grid.coords(idx))] > r2))
        .collect();
    super::solid::flood_exterior(grid, &blocked)
}

/// Pieces and handles of a solid without cavities, counted on its voxels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Census {
    /// Pieces whose boundary holds at least the area fraction of all boundary squares: the
    /// voxel stand-in for the pieces the init keeps.
    pub pieces: usize,
    /// All pieces.
    pub components: usize,
    /// Euler characteristic of the union of the closed voxels.
    pub euler: i64,
}

impl Census {
    /// Handles (tunnels) of all pieces together: components − χ, the solid having no cavities.
    pub fn handles(&self) -> i64 {
        self.components as i64 - self.euler
    }
}

/// The [`Census`] of the solid of `state`. Voxels are joined across faces, edges and corners (26
/// neighbours), as the union of closed voxels joins them and as the manifold repair merges parts
/// that touch along an edge or at a corner.
pub(crate) fn census(grid: &Grid, state: &[u8], min_area_fraction: f64) -> Census {
    let [nx, ny, nz] = grid.dims;
    let mut label = vec![u32::MAX; grid.len()];
    let mut squares: Vec<usize> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let exterior_faces = |c: [usize; 3]| -> usize {
        let mut n = 0;
        for a in 0..3 {
            for step in [-1i64, 1] {
                let mut d = c.map(|x| x as i64);
                d[a] += step;
                let out = d[a] < 0 || d[a] >= grid.dims[a] as i64;
                if out || state[grid.index(d[0] as usize, d[1] as usize, d[2] as usize)] == EXTERIOR
                {
                    n += 1;
                }
            }
        }
        n
    };
    for start in 0..grid.len() {
        if state[start] != SOLID || label[start] != u32::MAX {
            continue;
        }
        let id = squares.len() as u32;
        let mut area = 0;
        label[start] = id;
        stack.push(start);
        while let Some(idx) = stack.pop() {
            let c = grid.coords(idx);
            area += exterior_faces(c);
            for k in c[2].saturating_sub(1)..(c[2] + 2).min(nz) {
                for j in c[1].saturating_sub(1)..(c[1] + 2).min(ny) {
                    for i in c[0].saturating_sub(1)..(c[0] + 2).min(nx) {
                        let n = grid.index(i, j, k);
                        if state[n] == SOLID && label[n] == u32::MAX {
                            label[n] = id;
                            stack.push(n);
                        }
                    }
                }
            }
        }
        squares.push(area);
    }
    let total: usize = squares.iter().sum();
    let pieces = squares
        .iter()
        .filter(|&&a| a as f64 >= min_area_fraction * total as f64)
        .count();
    Census {
        pieces,
        components: squares.len(),
        euler: euler_characteristic(grid, state),
    }
}

/// χ = V − E + F − C of the union of the closed solid voxels. Each grid corner owns itself, the
/// three edges and three squares leaving it toward +x, +y, +z, and the voxel on its +x+y+z side;
/// each of them is in the union when one of the voxels around it is solid, and all of those are
/// among the corner's eight octants, so one table over the octant mask sums χ in one pass. The
/// grid border is never solid, so corners on it own nothing.
fn euler_characteristic(grid: &Grid, state: &[u8]) -> i64 {
    let table: [i8; 256] = std::array::from_fn(|mask| {
        let any = |bits: usize| i8::from(mask & bits != 0);
        // Octant bit dx + 2 dy + 4 dz is the voxel at corner − 1 + (dx, dy, dz).
        any(0xFF) - any(0b1010_1010) - any(0b1100_1100) - any(0b1111_0000)
            + any(0b1000_1000)
            + any(0b1010_0000)
            + any(0b1100_0000)
            - any(0b1000_0000)
    });
    let [nx, ny, nz] = grid.dims;
    (1..nz)
        .into_par_iter()
        .map(|k| {
            let mut sum = 0i64;
            for j in 1..ny {
                for i in 1..nx {
                    let mut mask = 0usize;
                    for bit in 0..8 {
                        let idx = grid.index(
                            i - 1 + (bit & 1),
                            j - 1 + ((bit >> 1) & 1),
                            k - 1 + (bit >> 2),
                        );
                        if state[idx] == SOLID {
                            mask |= 1 << bit;
                        }
                    }
                    sum += i64::from(table[mask]);
                }
            }
            sum
        })
        .sum()
}

/// Squared Euclidean distance (in voxels²) from every voxel of a grid of `dims` to the nearest
/// voxel with `seeds` set; [`FAR`] when there is no seed. Separable: exact 1-D distances along
/// z, then the lower envelope of parabolas along y and along x.
fn squared_distances(dims: [usize; 3], seeds: &[bool]) -> Vec<u32> {
    let [nx, ny, nz] = dims;
    let slice = nx * ny;
    // Along z: two sweeps of slices.
    let mut d = vec![FAR; seeds.len()];
    for k in 0..nz {
        for s in 0..slice {
            let idx = s + slice * k;
            d[idx] = if seeds[idx] {
                0
            } else if k > 0 && d[idx - slice] != FAR {
                d[idx - slice] + 1
            } else {
                FAR
            };
        }
    }
    for k in (0..nz.saturating_sub(1)).rev() {
        for s in 0..slice {
            let idx = s + slice * k;
            let next = d[idx + slice];
            if next != FAR && next + 1 < d[idx] {
                d[idx] = next + 1;
            }
        }
    }
    for v in &mut d {
        if *v != FAR {
            *v *= *v;
        }
    }
    // Along y, within each z slice.
    d.par_chunks_mut(slice).for_each(|plane| {
        let mut line = vec![0u32; ny];
        let mut out = vec![0u32; ny];
        let mut envelope = Envelope::default();
        for i in 0..nx {
            for j in 0..ny {
                line[j] = plane[i + nx * j];
            }
            envelope.transform(&line, &mut out);
            for j in 0..ny {
                plane[i + nx * j] = out[j];
            }
        }
    });
    // Along x, row by row.
    d.par_chunks_mut(nx).for_each(|row| {
        let line = row.to_vec();
        Envelope::default().transform(&line, row);
    });
    d
}

/// Scratch space of the 1-D transform `out[q] = min_p (f[p] + (q − p)²)`.
#[derive(Default)]
struct Envelope {
    sites: Vec<usize>,
    bounds: Vec<f64>,
}

impl Envelope {
    /// The lower envelope of the parabolas rooted at the finite entries of `f` (Felzenszwalb and
    /// Huttenlocher's algorithm); [`FAR`] everywhere when `f` has none.
    fn transform(&mut self, f: &[u32], out: &mut [u32]) {
        self.sites.clear();
        self.bounds.clear();
        let key = |p: usize| f[p] as f64 + (p * p) as f64;
        for q in 0..f.len() {
            if f[q] == FAR {
                continue;
            }
            loop {
                let Some(&p) = self.sites.last() else {
                    self.bounds.push(f64::NEG_INFINITY);
                    self.sites.push(q);
                    break;
                };
                let s = (key(q) - key(p)) / (2.0 * (q - p) as f64);
                if s <= *self.bounds.last().unwrap_or(&f64::NEG_INFINITY) {
                    self.sites.pop();
                    self.bounds.pop();
                } else {
                    self.bounds.push(s);
                    self.sites.push(q);
                    break;
                }
            }
        }
        if self.sites.is_empty() {
            out.fill(FAR);
            return;
        }
        let mut k = 0;
        for (q, o) in out.iter_mut().enumerate() {
            while k + 1 < self.sites.len() && self.bounds[k + 1] < q as f64 {
                k += 1;
            }
            let p = self.sites[k];
            *o = f[p] + (q.abs_diff(p) * q.abs_diff(p)) as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(dims: [usize; 3], seeds: &[bool]) -> Vec<u32> {
        let at = |i: usize| {
            [
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
            ]
        };
        (0..seeds.len())
            .map(|i| {
                let a = at(i);
                (0..seeds.len())
                    .filter(|&j| seeds[j])
                    .map(|j| {
                        let b = at(j);
                        (0..3).map(|k| (a[k].abs_diff(b[k]) as u32).pow(2)).sum()
                    })
                    .min()
                    .unwrap_or(FAR)
            })
            .collect()
    }

    #[test]
    fn distance_transform_matches_brute_force() {
        let dims = [7, 5, 6];
        let n = dims[0] * dims[1] * dims[2];
        let mut seeds = vec![false; n];
        for i in [3, 40, 41, 97, 150, 209] {
            seeds[i] = true;
        }
        assert_eq!(squared_distances(dims, &seeds), brute(dims, &seeds));
        assert!(
            squared_distances(dims, &vec![false; n])
                .iter()
                .all(|&d| d == FAR)
        );
    }

    fn grid_with_boxes(boxes: &[([usize; 3], [usize; 3])]) -> (Grid, Vec<u8>) {
        let grid = Grid::unit([40, 20, 20]);
        let mut state = vec![EXTERIOR; grid.len()];
        for &(lo, hi) in boxes {
            for k in lo[2]..hi[2] {
                for j in lo[1]..hi[1] {
                    for i in lo[0]..hi[0] {
                        state[grid.index(i, j, k)] = SOLID;
                    }
                }
            }
        }
        (grid, state)
    }

    #[test]
    fn census_counts_pieces_and_handles() {
        let grid = Grid::unit([8, 8, 8]);
        let mut state = vec![EXTERIOR; grid.len()];
        // A ring of eight voxels around (3, 3, 3) in the plane z = 3: one piece, one handle.
        for (i, j) in [
            (2, 2),
            (3, 2),
            (4, 2),
            (4, 3),
            (4, 4),
            (3, 4),
            (2, 4),
            (2, 3),
        ] {
            state[grid.index(i, j, 3)] = SOLID;
        }
        let ring = census(&grid, &state, 0.0);
        assert_eq!((ring.components, ring.handles()), (1, 1));
        // Filling the hole removes the handle; a voxel touching the ring at a corner only joins
        // it.
        state[grid.index(3, 3, 3)] = SOLID;
        state[grid.index(5, 5, 4)] = SOLID;
        let filled = census(&grid, &state, 0.0);
        assert_eq!((filled.components, filled.handles()), (1, 0));
        // A far voxel is a second piece, dropped by the area fraction.
        state[grid.index(6, 1, 6)] = SOLID;
        let two = census(&grid, &state, 0.0);
        assert_eq!((two.components, two.pieces, two.handles()), (2, 2, 0));
        assert_eq!(census(&grid, &state, 0.2).pieces, 1);
    }

    #[test]
    fn closing_joins_two_slabs_across_a_narrow_gap_only() {
        // Two 6×10×10 slabs 3 voxels apart.
        let (grid, state) =
            grid_with_boxes(&[([5, 5, 5], [11, 15, 15]), ([14, 5, 5], [20, 15, 15])]);
        assert_eq!(census(&grid, &state, 0.0).pieces, 2);
        assert_eq!(census(&grid, &closed(&grid, &state, 1), 0.0).pieces, 2);
        let joined = closed(&grid, &state, 3);
        assert_eq!(census(&grid, &joined, 0.0).pieces, 1);
        // The closing only adds, and adds nothing outside the slabs' hull.
        for idx in 0..grid.len() {
            assert!(state[idx] == EXTERIOR || joined[idx] == SOLID);
            let c = grid.coords(idx);
            let in_hull =
                (5..20).contains(&c[0]) && (5..15).contains(&c[1]) && (5..15).contains(&c[2]);
            assert!(in_hull || joined[idx] == EXTERIOR);
        }
    }

    #[test]
    fn merging_takes_the_smallest_radius_that_reaches_the_target() {
        let (grid, mut state) = grid_with_boxes(&[
            ([2, 5, 5], [8, 15, 15]),
            ([10, 5, 5], [16, 15, 15]),
            ([26, 5, 5], [32, 15, 15]),
        ]);
        let merge = merge_pieces(&grid, &mut state, 2, 16, 0.0);
        assert_eq!(merge.pieces_before, 3);
        assert_eq!(merge.pieces_after, 2);
        assert_eq!(census(&grid, &state, 0.0).pieces, 2);
        // A 2-voxel gap needs a radius of 1 to 2, not the 10-voxel one.
        assert!((1..=2).contains(&merge.radius), "{merge:?}");
    }

    #[test]
    fn pieces_too_far_apart_to_merge_keep_their_shape() {
        let (grid, state) =
            grid_with_boxes(&[([2, 8, 8], [4, 10, 10]), ([34, 8, 8], [36, 10, 10])]);
        let mut merged = state.clone();
        let merge = merge_pieces(&grid, &mut merged, 1, 8, 0.0);
        assert_eq!(merge.radius, 0);
        assert_eq!(merged, state);
    }
}
