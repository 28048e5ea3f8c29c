//! The voxel grid shared by the voxelizer, the solid builder and the surface extractor.

use glam::DVec3;

/// Voxel state: part of the exterior (reached by the flood fill from the border).
pub(crate) const EXTERIOR: u8 = 0;
/// Voxel state: part of the solid (everything the exterior flood did not reach).
pub(crate) const SOLID: u8 = 1;

/// A dense axis-aligned grid of cubic voxels. Voxel `(i, j, k)` covers
/// `origin + voxel_size * [i, i+1] × [j, j+1] × [k, k+1]`.
#[derive(Clone, Debug)]
pub(crate) struct Grid {
    /// Voxel counts along x, y, z.
    pub dims: [usize; 3],
    /// World position of the corner of voxel (0, 0, 0).
    pub origin: DVec3,
    /// Edge length of one voxel.
    pub voxel_size: f64,
}

impl Grid {
    /// A grid of unit voxels with its corner at the origin (test set-ups).
    #[cfg(test)]
    pub fn unit(dims: [usize; 3]) -> Grid {
        Grid {
            dims,
            origin: DVec3::ZERO,
            voxel_size: 1.0,
        }
    }

    /// A grid whose longest axis holds `resolution` voxels over `[min, max]`, padded by `padding`
    /// voxels on every side.
    pub fn around(min: DVec3, max: DVec3, resolution: usize, padding: usize) -> Grid {
        let extent = max - min;
        let voxel_size = extent.max_element() / resolution as f64;
        let mut dims = [0usize; 3];
        let mut origin = DVec3::ZERO;
        for a in 0..3 {
            let inner = ((extent[a] / voxel_size).ceil() as usize).max(1);
            dims[a] = inner + 2 * padding;
            // Centre the inner voxels on the box along this axis.
            let slack = inner as f64 * voxel_size - extent[a];
            origin[a] = min[a] - 0.5 * slack - padding as f64 * voxel_size;
        }
        Grid {
            dims,
            origin,
            voxel_size,
        }
    }

    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Linear index of voxel `(i, j, k)` (x fastest).
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Voxel coordinates of a linear index.
    #[inline]
    pub fn coords(&self, index: usize) -> [usize; 3] {
        let i = index % self.dims[0];
        let rest = index / self.dims[0];
        [i, rest % self.dims[1], rest / self.dims[1]]
    }

    /// World position of grid corner `(i, j, k)`.
    #[inline]
    pub fn corner(&self, c: [usize; 3]) -> DVec3 {
        self.origin + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.voxel_size
    }

    /// World position of the centre of voxel `(i, j, k)` (any coordinates, also beyond the grid).
    #[inline]
    pub fn centre(&self, c: [usize; 3]) -> DVec3 {
        self.corner(c) + DVec3::splat(0.5 * self.voxel_size)
    }

    /// Continuous voxel coordinates of a world point.
    #[inline]
    pub fn to_grid(&self, p: DVec3) -> DVec3 {
        (p - self.origin) / self.voxel_size
    }

    /// Whether voxel `(i, j, k)` lies on the outermost layer of the grid.
    #[inline]
    pub fn on_border(&self, c: [usize; 3]) -> bool {
        (0..3).any(|a| c[a] == 0 || c[a] + 1 == self.dims[a])
    }
}
