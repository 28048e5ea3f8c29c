//! Seeded, area-weighted random sampling of a triangle surface.
//!
//! Naming: a *sample* is a point on a face with its face index, barycentric coordinates (corner
//! order of the face) and the unit normal of its face. As in the authors' code, faces are drawn
//! with probability proportional to area, barycentrics are `(1−√u, √u(1−v), √u·v)` with
//! `u, v ~ U(0, 1)`. Same input and seed give the same samples on every machine.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Samples drawn by [`sample_surface`]; all vectors have the same length (#S).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceSamples {
    /// Sample points (#S).
    pub points: Vec<DVec3>,
    /// Unit normals of the sampled faces (#S).
    pub normals: Vec<DVec3>,
    /// Sampled face of each point (#S).
    pub faces: Vec<u32>,
    /// Barycentric coordinates of each point in its face (#S).
    pub barycentric: Vec<[f64; 3]>,
}

impl SurfaceSamples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True if there are no samples.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Draws `n` samples uniformly over the surface area.
///
/// Inputs: `positions` (#V), `triangles` (#F), sample count `n`, `seed`. Output: `n` samples;
/// faces with zero (or non-finite) area or an index out of range are never chosen, and if no
/// face has positive area the result is empty. Uses `ChaCha8Rng::seed_from_u64(seed)`, a
/// cumulative area table and a binary search per sample.
pub fn sample_surface(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> SurfaceSamples {
    let corners = |t: &[u32; 3]| -> Option<[DVec3; 3]> {
        let get = |i: u32| positions.get(i as usize).copied();
        Some([get(t[0])?, get(t[1])?, get(t[2])?])
    };
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0_f64;
    let mut last_positive = None;
    for (f, t) in triangles.iter().enumerate() {
        let area = corners(t).map_or(0.0, |[a, b, c]| 0.5 * (b - a).cross(c - a).length());
        if area.is_finite() && area > 0.0 {
            total += area;
            last_positive = Some(f);
        }
        cumulative.push(total);
    }
    let (Some(last_positive), true) = (last_positive, total.is_finite()) else {
        return SurfaceSamples::default();
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut samples = SurfaceSamples {
        points: Vec::with_capacity(n),
        normals: Vec::with_capacity(n),
        faces: Vec::with_capacity(n),
        barycentric: Vec::with_capacity(n),
    };
    for _ in 0..n {
        let r = rng.random::<f64>() * total;
        // First face whose cumulative area exceeds r: zero-area faces add nothing, so they are
        // never the first to exceed it.
        let f = cumulative.partition_point(|&c| c <= r).min(last_positive);
        let u: f64 = rng.random();
        let v: f64 = rng.random();
        let su = u.sqrt();
        let w = [1.0 - su, su * (1.0 - v), su * v];
        let [a, b, c] = corners(&triangles[f]).unwrap_or([DVec3::ZERO; 3]);
        samples.points.push(w[0] * a + w[1] * b + w[2] * c);
        samples
            .normals
            .push((b - a).cross(c - a).normalize_or_zero());
        samples.faces.push(f as u32);
        samples.barycentric.push(w);
    }
    samples
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_area_faces_are_never_chosen_and_all_zero_gives_nothing() {
        let positions = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            2.0 * DVec3::X, // collinear with 0 and 1
        ];
        let triangles = [[0, 1, 3], [0, 1, 2], [1, 1, 2], [0, 3, 1]];
        let s = sample_surface(&positions, &triangles, 500, 7);
        assert_eq!(s.len(), 500);
        assert!(s.faces.iter().all(|&f| f == 1));
        for (p, w) in s.points.iter().zip(&s.barycentric) {
            assert!(w.iter().all(|&x| x >= 0.0) && (w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(p.z == 0.0 && p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 + 1e-12);
        }
        assert!(s.normals.iter().all(|&n| n == DVec3::Z));
        assert!(sample_surface(&positions, &[[0, 1, 3]], 10, 7).is_empty());
        assert!(sample_surface(&positions, &[], 10, 7).is_empty());
    }

    #[test]
    fn same_seed_same_samples_and_area_proportional() {
        // Face 1 has three times the area of face 0.
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, 3.0)];
        let triangles = [[0, 1, 2], [0, 3, 1]];
        let a = sample_surface(&positions, &triangles, 4000, 42);
        assert_eq!(a, sample_surface(&positions, &triangles, 4000, 42));
        assert_ne!(a, sample_surface(&positions, &triangles, 4000, 43));
        let on_big = a.faces.iter().filter(|&&f| f == 1).count() as f64 / 4000.0;
        assert!(
            (on_big - 0.75).abs() < 0.03,
            "fraction on the big face {on_big}"
        );
    }
}
