//! Triangle shape quality: the aspect ratio `Q = R_circ / (2 r_in)` (supplementary §1.1).

use glam::DVec3;
use serde::Serialize;

/// Aspect-ratio statistics over the non-degenerate faces; the median is the
/// paper's metric (supplementary §1.1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualityStats {
    /// Median Q (mean of the two middle values for an even count); `None` without any valid face.
    pub aspect_ratio_median: Option<f64>,
    /// Mean Q.
    pub aspect_ratio_mean: Option<f64>,
    /// 95th percentile of Q (linear interpolation between order statistics, as numpy's default).
    pub aspect_ratio_p95: Option<f64>,
    /// Largest Q.
    pub aspect_ratio_max: Option<f64>,
    /// Faces left out: a repeated vertex index or zero area (Q infinite or undefined).
    pub degenerate: usize,
}

/// `Q = R/(2r)` of one triangle (`roar_mesh::spatial::triangle_quality`): 1 for an equilateral
/// triangle, larger for worse shapes. `None` when the triangle has zero area (Q infinite or
/// undefined) or non-finite corners.
pub fn aspect_ratio(a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let q = roar_mesh::spatial::triangle_quality([a, b, c]);
    q.is_finite().then_some(q)
}

/// Linear-interpolation percentile of sorted values, `p` in [0, 1].
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let pos = p * (sorted.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

/// Aspect-ratio statistics of every triangle. Indices must be in range.
pub fn triangle_quality(positions: &[DVec3], triangles: &[[u32; 3]]) -> QualityStats {
    let mut q: Vec<f64> = Vec::with_capacity(triangles.len());
    let mut degenerate = 0;
    for t in triangles {
        let repeated = t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
        let [a, b, c] = t.map(|i| positions[i as usize]);
        match aspect_ratio(a, b, c) {
            Some(v) if !repeated => q.push(v),
            _ => degenerate += 1,
        }
    }
    q.sort_by(f64::total_cmp);
    let stat = |f: &dyn Fn(&[f64]) -> f64| (!q.is_empty()).then(|| f(&q));
    QualityStats {
        aspect_ratio_median: stat(&|s| percentile(s, 0.5)),
        aspect_ratio_mean: stat(&|s| s.iter().sum::<f64>() / s.len() as f64),
        aspect_ratio_p95: stat(&|s| percentile(s, 0.95)),
        aspect_ratio_max: stat(&|s| s[s.len() - 1]),
        degenerate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equilateral_is_one_and_right_isosceles_is_known() {
        let h = 3f64.sqrt() / 2.0;
        let q = aspect_ratio(DVec3::ZERO, DVec3::X, DVec3::new(0.5, h, 0.0)).unwrap();
        assert!((q - 1.0).abs() < 1e-12);
        // Legs 1, hypotenuse √2: R = √2/2, r = (2 − √2)/2, Q = √2 / (2(2 − √2)) = (1 + √2)/2.
        let q = aspect_ratio(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
        assert!((q - (1.0 + 2f64.sqrt()) / 2.0).abs() < 1e-12, "{q}");
        // Invariant under scaling and rotation.
        let s = aspect_ratio(DVec3::ZERO, DVec3::Z * 7.0, DVec3::Y * 7.0).unwrap();
        assert!((s - q).abs() < 1e-12);
    }

    #[test]
    fn degenerate_faces_are_counted_and_excluded() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X * 2.0];
        let t = [[0, 1, 2], [0, 0, 1], [0, 1, 3], [0, 2, 1]];
        let s = triangle_quality(&p, &t);
        assert_eq!(s.degenerate, 2);
        let right = (1.0 + 2f64.sqrt()) / 2.0;
        assert!((s.aspect_ratio_median.unwrap() - right).abs() < 1e-12);
        assert_eq!(s.aspect_ratio_max, s.aspect_ratio_median);
        assert!(triangle_quality(&p, &[]).aspect_ratio_median.is_none());
    }

    #[test]
    fn percentile_interpolates() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.95), 95.0);
        assert_eq!(percentile(&[1.0, 2.0], 0.5), 1.5);
    }
}
