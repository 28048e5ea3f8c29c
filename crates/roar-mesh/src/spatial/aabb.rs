//! Axis-aligned bounding boxes in f64.
//!
//! Naming: an [`Aabb`] is a closed box `[min, max]`; "empty" means no point was added yet
//! (`min > max`); `diagonal()` is the length of the box diagonal (the `D` that sampling densities
//! and tolerances are relative to).

use glam::DVec3;

/// A closed axis-aligned box `{x : min ≤ x ≤ max}` (component-wise).
///
/// The empty box has `min = +∞`, `max = −∞`, so [`Aabb::grow`] and [`Aabb::union`] need no
/// special case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (contains nothing; neutral element of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box of a single point.
    pub fn from_point(p: DVec3) -> Aabb {
        Aabb { min: p, max: p }
    }

    /// The smallest box containing every point; `None` for no points.
    ///
    /// Input: any iterator of points. Output: `Some(box)` or `None` if the iterator is empty.
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Option<Aabb> {
        let mut aabb = Aabb::EMPTY;
        for p in points {
            aabb.grow(p);
        }
        (!aabb.is_empty()).then_some(aabb)
    }

    /// The box of a triangle's three corners.
    pub fn from_triangle(corners: [DVec3; 3]) -> Aabb {
        Aabb {
            min: corners[0].min(corners[1]).min(corners[2]),
            max: corners[0].max(corners[1]).max(corners[2]),
        }
    }

    /// True if the box contains no point.
    pub fn is_empty(&self) -> bool {
        !self.min.cmple(self.max).all()
    }

    /// Enlarges the box to contain `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The smallest box containing both boxes.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Midpoint of the box.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Edge lengths `max − min` (zero vector for the empty box).
    pub fn extent(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Length of the box diagonal (0 for the empty box).
    pub fn diagonal(&self) -> f64 {
        self.extent().length()
    }

    /// Half the surface area of the box (the SAH cost measure; 0 for the empty box).
    pub fn half_area(&self) -> f64 {
        let e = self.extent();
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// True if the closed boxes share at least one point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.x <= other.max.x
            && other.min.x <= self.max.x
            && self.min.y <= other.max.y
            && other.min.y <= self.max.y
            && self.min.z <= other.max.z
            && other.min.z <= self.max.z
    }

    /// True if the closed box contains `p`.
    pub fn contains(&self, p: DVec3) -> bool {
        self.min.x <= p.x
            && p.x <= self.max.x
            && self.min.y <= p.y
            && p.y <= self.max.y
            && self.min.z <= p.z
            && p.z <= self.max.z
    }

    /// The parameters `[t_in, t_out]` (with `t_in ≥ 0`) where the ray `origin + t·dir` is inside
    /// the closed box, or `None` when it misses it.
    pub fn ray_interval(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let (mut t_in, mut t_out) = (0.0_f64, f64::INFINITY);
        for axis in 0..3 {
            let (o, d) = (origin[axis], dir[axis]);
            if d == 0.0 {
                if o < self.min[axis] || o > self.max[axis] {
                    return None;
                }
                continue;
            }
            let (a, b) = ((self.min[axis] - o) / d, (self.max[axis] - o) / d);
            t_in = t_in.max(a.min(b));
            t_out = t_out.min(a.max(b));
        }
        (t_in <= t_out).then_some((t_in, t_out))
    }

    /// Squared distance from `p` to the box (0 inside).
    pub fn distance_squared(&self, p: DVec3) -> f64 {
        let d = (self.min - p).max(p - self.max).max(DVec3::ZERO);
        d.length_squared()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_points_of_nothing_is_none() {
        assert!(Aabb::from_points(std::iter::empty()).is_none());
    }

    #[test]
    fn box_measures() {
        let b = Aabb::from_points([DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 2.0)]).unwrap();
        assert_eq!(b.center(), DVec3::new(0.5, 1.0, 1.0));
        assert_eq!(b.diagonal(), 3.0);
        assert_eq!(b.distance_squared(DVec3::new(2.0, 1.0, 1.0)), 1.0);
        assert_eq!(b.distance_squared(DVec3::new(0.5, 1.0, 1.0)), 0.0);
        let c = Aabb::from_point(DVec3::new(1.0, 2.0, 2.0));
        assert!(b.overlaps(&c), "touching boxes overlap");
        let d = Aabb::from_point(DVec3::new(1.0, 2.0, 2.5));
        assert!(!b.overlaps(&d));
        assert_eq!(b.union(&d).max, DVec3::new(1.0, 2.0, 2.5));
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert_eq!(Aabb::EMPTY.diagonal(), 0.0);
    }
}
