//! The similarity transform that puts a mesh into the camera rig's sphere, and back.
//!
//! Naming: *apply* maps world (file) coordinates into rig coordinates, *invert* maps rig
//! coordinates back to world coordinates. The rig sphere has radius [`RIG_RADIUS`] around the
//! origin: the bounding-box midpoint goes to the origin and the farthest vertex to 0.95, not to
//! 1 as in the authors' code, so that no silhouette touches the border of a camera's frame
//! (`docs/method.md#conventions`).

use glam::DVec3;

use super::aabb::Aabb;

/// Radius of the sphere that normalized meshes fit in: the farthest referenced vertex lies at
/// this distance from the origin.
pub const RIG_RADIUS: f64 = 0.95;

/// Translation + uniform scale: `apply(p) = (p − center) · scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalization {
    /// World-space point that maps to the origin (bounding-box midpoint of the referenced vertices).
    pub center: DVec3,
    /// Uniform scale factor, finite and > 0.
    pub scale: f64,
}

impl Normalization {
    /// The transform that changes nothing.
    pub const IDENTITY: Normalization = Normalization {
        center: DVec3::ZERO,
        scale: 1.0,
    };

    /// Fits the transform to the vertices referenced by `triangles`.
    ///
    /// Inputs: `positions` (#V), `triangles` (#F) of indices into `positions`; indices out of
    /// range are ignored, unreferenced vertices are ignored.
    /// Output: the centre is the bounding-box midpoint of the referenced vertices and the scale
    /// puts the farthest referenced vertex at distance [`RIG_RADIUS`]. `None` if no vertex is
    /// referenced, or the referenced vertices are all at one point, or a coordinate is not
    /// finite.
    pub fn fit(positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<Normalization> {
        let referenced = || {
            triangles
                .iter()
                .flatten()
                .filter_map(|&i| positions.get(i as usize).copied())
        };
        let center = Aabb::from_points(referenced())?.center();
        let radius = referenced()
            .map(|p| p.distance_squared(center))
            .fold(0.0_f64, f64::max)
            .sqrt();
        let scale = RIG_RADIUS / radius;
        (center.is_finite() && radius > 0.0 && scale.is_finite() && scale > 0.0)
            .then_some(Normalization { center, scale })
    }

    /// World → rig coordinates: `(p − center) · scale`.
    pub fn apply(&self, p: DVec3) -> DVec3 {
        (p - self.center) * self.scale
    }

    /// Rig → world coordinates: `p / scale + center` (the inverse of [`Normalization::apply`]).
    pub fn invert(&self, p: DVec3) -> DVec3 {
        p / self.scale + self.center
    }

    /// Applies [`Normalization::apply`] to every point in place.
    pub fn apply_all(&self, points: &mut [DVec3]) {
        for p in points {
            *p = self.apply(*p);
        }
    }

    /// Applies [`Normalization::invert`] to every point in place.
    pub fn invert_all(&self, points: &mut [DVec3]) {
        for p in points {
            *p = self.invert(*p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_uses_referenced_vertices_only_and_reaches_the_rig_radius() {
        let positions = vec![
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(3.0, 1.0, 1.0),
            DVec3::new(1.0, 5.0, 1.0),
            DVec3::new(100.0, 100.0, 100.0), // unreferenced
        ];
        let n = Normalization::fit(&positions, &[[0, 1, 2]]).unwrap();
        assert_eq!(n.center, DVec3::new(2.0, 3.0, 1.0));
        let mut moved = positions[..3].to_vec();
        n.apply_all(&mut moved);
        let farthest = moved.iter().map(|p| p.length()).fold(0.0, f64::max);
        assert!((farthest - RIG_RADIUS).abs() < 1e-12);
        n.invert_all(&mut moved);
        for (a, b) in moved.iter().zip(&positions) {
            assert!(a.distance(*b) < 1e-12);
        }
    }

    #[test]
    fn fit_rejects_empty_and_zero_extent() {
        let positions = vec![DVec3::ONE; 3];
        assert!(Normalization::fit(&positions, &[]).is_none());
        assert!(Normalization::fit(&positions, &[[0, 1, 2]]).is_none());
        assert!(Normalization::fit(&positions, &[[7, 8, 9]]).is_none());
    }
}
