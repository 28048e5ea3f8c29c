//! One triangle's shape: its unit normal, its corner angles and its aspect ratio, each with one
//! rule for degenerate triangles that every crate shares.

use glam::DVec3;

/// Faces with `|cross| <= DEGENERATE_CROSS` get the default normal and clamped area, so no normal
/// or area is NaN (as in the authors' code; `docs/method.md#conventions`).
pub const DEGENERATE_CROSS: f64 = 1e-9;

/// Normal of a degenerate face.
pub const DEGENERATE_NORMAL: DVec3 = DVec3::X;

/// Unit normal of triangle `(a, b, c)`; a triangle with `|cross| ≤ 1e-9` (or non-finite corners)
/// gets `(1, 0, 0)` (`docs/method.md#conventions`).
pub fn triangle_normal(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let n = (b - a).cross(c - a);
    let len = n.length();
    if len > DEGENERATE_CROSS && len.is_finite() {
        n / len
    } else {
        DEGENERATE_NORMAL
    }
}

/// Interior angles of triangle `p` at its three corners, from the clipped cosine.
/// A corner with a zero-length side gets π/2 (its cosine is taken as 0).
pub fn corner_angles(p: [DVec3; 3]) -> [f64; 3] {
    std::array::from_fn(|k| {
        let u = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
        let v = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
        u.dot(v).clamp(-1.0, 1.0).acos()
    })
}

/// The aspect ratio `Q = R/(2r) = abc·s/(8K²)` of triangle `p` (circumradius over twice the
/// inradius, supplementary §1.1), the one triangle-quality measure of the project: 1 for an
/// equilateral triangle, growing without bound for slivers and needles. A collinear triangle with
/// three non-zero sides gives +∞; one with a zero-length side (0/0) gives NaN, which callers treat
/// as degenerate. The area comes from the cross product, exact to rounding for flat triangles where
/// Heron's `(s−a)(s−b)(s−c)` cancels.
pub fn triangle_quality([p0, p1, p2]: [DVec3; 3]) -> f64 {
    let (a, b, c) = (p1.distance(p2), p2.distance(p0), p0.distance(p1));
    let twice_area = (p1 - p0).cross(p2 - p0).length();
    let sides = a * b * c;
    if twice_area > 0.0 {
        // abc·s / (8K²) with s = (a+b+c)/2 and K = twice_area/2.
        sides * (a + b + c) / (4.0 * twice_area * twice_area)
    } else if sides > 0.0 {
        f64::INFINITY
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_is_one_for_equilateral_and_grows_for_slivers() {
        let eq = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
        ];
        assert!((triangle_quality(eq) - 1.0).abs() < 1e-12);
        // Right isosceles: R = √2/2, r = 1 − √2/2.
        let right = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let expected = (2f64.sqrt() / 2.0) / (2.0 * (1.0 - 2f64.sqrt() / 2.0));
        assert!((triangle_quality(right) - expected).abs() < 1e-12);
        let sliver = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, 0.01, 0.0)];
        assert!(triangle_quality(sliver) > 600.0);
        let line = [DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)];
        assert_eq!(triangle_quality(line), f64::INFINITY);
        assert!(triangle_quality([DVec3::ONE; 3]).is_nan());
        assert!(triangle_quality([DVec3::ZERO, DVec3::ZERO, DVec3::X]).is_nan());
    }

    #[test]
    fn angles_sum_to_pi_and_normals_follow_the_winding() {
        let p = [
            DVec3::ZERO,
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.0, 0.5),
        ];
        let a = corner_angles(p);
        assert!((a.iter().sum::<f64>() - std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(triangle_normal(DVec3::ZERO, DVec3::X, DVec3::Y), DVec3::Z);
        assert_eq!(triangle_normal(DVec3::ZERO, DVec3::Y, DVec3::X), -DVec3::Z);
        assert_eq!(
            triangle_normal(DVec3::ZERO, DVec3::X, DVec3::X * 2.0),
            DVec3::X
        );
    }
}
