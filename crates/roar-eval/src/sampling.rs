//! Area-weighted random sampling of a triangle soup's surface.
//!
//! Temporary: this private sampler will be replaced by `roar_mesh::spatial::sample_surface`
//! (same output layout, [`SurfaceSamples`]) once that lands in the workspace.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Points drawn on a surface, one entry per sample in every vector.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceSamples {
    /// Sample positions.
    pub points: Vec<DVec3>,
    /// Unit normal of the face each sample lies on (right-hand rule on the stored winding).
    pub normals: Vec<DVec3>,
    /// Index of the face each sample lies on.
    pub faces: Vec<u32>,
    /// Barycentric coordinates of each sample in its face (they sum to 1).
    pub barycentric: Vec<[f64; 3]>,
}

/// Draws `n` points uniformly by area on the triangles (faces chosen by area through a cumulative
/// table and binary search, barycentrics `(1−√u, √u(1−v), √u v)`), deterministic for a `seed`.
///
/// Zero-area faces are never chosen. Returns no samples when `n == 0` or the total area is zero
/// (or not finite). Indices must be in range of `positions` (checked by the caller).
pub fn sample_surface(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> SurfaceSamples {
    let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = corners(t);
        let area = 0.5 * (b - a).cross(c - a).length();
        if area.is_finite() {
            total += area;
        }
        cumulative.push(total);
    }
    let mut out = SurfaceSamples::default();
    if n == 0 || total <= 0.0 || !total.is_finite() {
        return out;
    }
    out.points.reserve(n);
    out.normals.reserve(n);
    out.faces.reserve(n);
    out.barycentric.reserve(n);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..n {
        let r = rng.random::<f64>() * total;
        // First face whose cumulative area exceeds r: zero-area faces are skipped.
        let face = cumulative
            .partition_point(|&c| c <= r)
            .min(triangles.len() - 1);
        let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
        let su = u.sqrt();
        let bary = [1.0 - su, su * (1.0 - v), su * v];
        let [a, b, c] = corners(&triangles[face]);
        out.points.push(a * bary[0] + b * bary[1] + c * bary[2]);
        out.normals.push((b - a).cross(c - a).normalize_or_zero());
        out.faces.push(face as u32);
        out.barycentric.push(bary);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_on_their_faces_and_follow_area() {
        // Two coplanar triangles, the second with three times the area of the first.
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
        ];
        // Area 0.5 and 3.0; a zero-area face in between must never be chosen.
        let t = [[0, 1, 2], [0, 1, 3], [3, 4, 5]];
        let s = sample_surface(&p, &t, 7000, 7);
        assert_eq!(s.points.len(), 7000);
        assert!(s.faces.iter().all(|&f| f != 1));
        let on_big = s.faces.iter().filter(|&&f| f == 2).count() as f64 / 7000.0;
        assert!((on_big - 6.0 / 7.0).abs() < 0.02, "fraction {on_big}");
        for i in 0..s.points.len() {
            let [a, b, c] = t[s.faces[i] as usize].map(|k| p[k as usize]);
            let w = s.barycentric[i];
            assert!((w[0] + w[1] + w[2] - 1.0).abs() < 1e-12);
            assert!(w.iter().all(|&x| (0.0..=1.0).contains(&x)));
            assert!((a * w[0] + b * w[1] + c * w[2] - s.points[i]).length() < 1e-12);
            assert_eq!(s.normals[i], DVec3::Z);
        }
        assert_eq!(
            s,
            sample_surface(&p, &t, 7000, 7),
            "same seed, same samples"
        );
        assert_ne!(s.points, sample_surface(&p, &t, 7000, 8).points);
    }

    #[test]
    fn zero_area_or_empty_gives_no_samples() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(sample_surface(&p, &[[0, 1, 2]], 10, 0).points.is_empty());
        assert!(sample_surface(&p, &[], 10, 0).points.is_empty());
    }
}
