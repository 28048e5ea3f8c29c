//! Projection of source-mesh samples onto the target surface along their normals, which the
//! Face Split block scores faces with (`docs/method.md#projection-onto-the-target`).
//!
//! One concept, several implementations: k-NN planar projection over the target point cloud (the
//! paper's, in `roar-loss`), exact ray casting onto the target soup guarded by winding numbers of
//! the source (the authors' later code, in `spatial`), and the analytic [`SphereProjector`] here, a
//! reference for tests.

use glam::DVec3;

/// Projects sample points of the current source mesh onto the target surface along their normals.
///
/// Contract every implementation keeps:
/// - `positions`/`triangles` are the current source mesh (so an exact projector can apply
///   winding-number guards against it); implementations that do not need it ignore
///   it.
/// - `points[i]` is a sample and `normals[i]` its **unit** normal; the projection of sample `i`
///   lies on the line `points[i] + t·normals[i]`, except where an implementation documents a
///   fallback (e.g. the ray-cast projector keeps an obliquely hit sample in place).
/// - The result has exactly `points.len()` entries, in the same order: `Some(q)` is the projected
///   point, `None` means the sample has no valid projection (missed, rejected by a guard, too far,
///   non-finite input, or no normal because `normals` is shorter than `points`).
/// - Deterministic: the same inputs give bit-identical outputs whatever the thread count.
/// - Never panics on any input.
pub trait Projector: Sync {
    /// `positions`/`triangles`: the current source mesh (so an exact projector can apply
    /// winding-number guards against it). `points`/`normals`: the samples (unit normals).
    /// Returns one `Option<DVec3>` per sample: the projected point, or None when invalid.
    fn project(
        &self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        points: &[DVec3],
        normals: &[DVec3],
    ) -> Vec<Option<DVec3>>;
}

/// Reference [`Projector`] onto an analytic sphere: intersects the line `p + t·n` with the sphere
/// and returns the intersection with the smallest `|t|` (ties go to the `+n` side); `None` when
/// the line misses the sphere (tangent lines hit) or the input is not finite. Ignores the source
/// mesh. Useful to test face scoring and losses in other crates against a known target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereProjector {
    /// Centre of the target sphere.
    pub center: DVec3,
    /// Radius of the target sphere (≥ 0).
    pub radius: f64,
}

impl SphereProjector {
    /// Projects one sample `p` along unit normal `n` onto the sphere.
    pub fn project_point(&self, p: DVec3, n: DVec3) -> Option<DVec3> {
        // |p + t n − c|² = r² with |n| = 1: t² + 2 b t + (|p−c|² − r²) = 0, b = n·(p−c).
        let offset = p - self.center;
        let b = n.dot(offset);
        let c = offset.length_squared() - self.radius * self.radius;
        let discriminant = b * b - c;
        if discriminant.is_nan() || discriminant < 0.0 || !p.is_finite() || !n.is_finite() {
            return None;
        }
        let root = discriminant.sqrt();
        let t_plus = -b + root;
        let t_minus = -b - root;
        let t = if t_plus.abs() <= t_minus.abs() {
            t_plus
        } else {
            t_minus
        };
        let q = p + t * n;
        q.is_finite().then_some(q)
    }
}

impl Projector for SphereProjector {
    fn project(
        &self,
        _positions: &[DVec3],
        _triangles: &[[u32; 3]],
        points: &[DVec3],
        normals: &[DVec3],
    ) -> Vec<Option<DVec3>> {
        points
            .iter()
            .enumerate()
            .map(|(i, &p)| normals.get(i).and_then(|&n| self.project_point(p, n)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projects_to_nearest_intersection_along_normal() {
        let sphere = SphereProjector {
            center: DVec3::ZERO,
            radius: 1.0,
        };
        // From inside, moving outward along +x.
        let q = sphere
            .project_point(DVec3::new(0.5, 0.0, 0.0), DVec3::X)
            .unwrap();
        assert!((q - DVec3::X).length() < 1e-12);
        // From outside with the normal pointing away: nearest hit is behind (t < 0).
        let q = sphere
            .project_point(DVec3::new(2.0, 0.0, 0.0), DVec3::X)
            .unwrap();
        assert!((q - DVec3::X).length() < 1e-12);
        // Off-axis: the hit lies on the line and on the sphere.
        let p = DVec3::new(0.3, 0.4, -0.2);
        let n = DVec3::new(1.0, 2.0, 0.5).normalize();
        let q = sphere.project_point(p, n).unwrap();
        assert!((q.length() - 1.0).abs() < 1e-12);
        assert!((q - p).cross(n).length() < 1e-12);
    }

    #[test]
    fn missing_lines_and_missing_normals_give_none() {
        let sphere = SphereProjector {
            center: DVec3::ZERO,
            radius: 1.0,
        };
        assert_eq!(
            sphere.project_point(DVec3::new(0.0, 2.0, 0.0), DVec3::X),
            None
        );
        assert_eq!(sphere.project_point(DVec3::splat(f64::NAN), DVec3::X), None);
        let out = sphere.project(&[], &[], &[DVec3::ZERO, DVec3::ZERO], &[DVec3::Z]);
        assert_eq!(out.len(), 2);
        assert!(out[0].is_some());
        assert_eq!(out[1], None);
    }
}
