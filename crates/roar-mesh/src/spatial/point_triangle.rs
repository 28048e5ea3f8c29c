//! Closest point on a triangle and ray–triangle intersection for one triangle, in f64.
//!
//! Naming: barycentric coordinates `[w0, w1, w2]` weight the corners `[a, b, c]` in order, so a
//! point is `w0·a + w1·b + w2·c` with `w ≥ 0` and `w0 + w1 + w2 = 1`.

use glam::DVec3;

/// Closest point of the closed triangle `[a, b, c]` to `p`.
///
/// Input: query point `p`, triangle corners. Output: `(point, [w0, w1, w2])`, the closest point and
/// its barycentric coordinates. Ericson, *Real-Time Collision Detection*, section 5.1.5 (Voronoi
/// regions). Degenerate triangles (zero or near-zero area, repeated corners) are handled as the
/// union of their three edges, so the answer is always finite for finite input.
pub fn closest_point_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> (DVec3, [f64; 3]) {
    let ab = b - a;
    let ac = c - a;
    let cross = ab.cross(ac);
    // sin²(angle at a) ≤ ε: treat as a segment set (Ericson's divisions become unreliable).
    if cross.length_squared() <= f64::EPSILON * ab.length_squared() * ac.length_squared() {
        return closest_point_on_degenerate_triangle(p, [a, b, c]);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let sum = va + vb + vc;
    if sum.is_nan() || sum <= 0.0 {
        return closest_point_on_degenerate_triangle(p, [a, b, c]);
    }
    let v = vb / sum;
    let w = vc / sum;
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// Closest point to `p` on the union of the three edges (used for degenerate triangles).
fn closest_point_on_degenerate_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> (DVec3, [f64; 3]) {
    let (t_ab, q_ab) = closest_on_segment(p, a, b);
    let (t_bc, q_bc) = closest_on_segment(p, b, c);
    let (t_ca, q_ca) = closest_on_segment(p, c, a);
    let mut best = (q_ab, [1.0 - t_ab, t_ab, 0.0]);
    let mut best_d2 = p.distance_squared(q_ab);
    if p.distance_squared(q_bc) < best_d2 {
        best_d2 = p.distance_squared(q_bc);
        best = (q_bc, [0.0, 1.0 - t_bc, t_bc]);
    }
    if p.distance_squared(q_ca) < best_d2 {
        best = (q_ca, [t_ca, 0.0, 1.0 - t_ca]);
    }
    best
}

/// Closest point on segment `[a, b]`: `(t, a + t·(b − a))` with `t ∈ [0, 1]`.
fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> (f64, DVec3) {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, a + t * ab)
}

/// Möller–Trumbore ray–triangle intersection.
///
/// Input: ray `origin + t·dir`, triangle corners. Output: `Some((t, [w0, w1, w2]))` if the ray
/// meets the closed triangle (edges included, so a ray through a shared edge hits both faces)
/// at a single point with `t > 0`; `None` for misses, rays parallel to the plane and
/// degenerate triangles. The caller checks its own `t_max`.
pub fn ray_triangle(origin: DVec3, dir: DVec3, [a, b, c]: [DVec3; 3]) -> Option<(f64, [f64; 3])> {
    let e1 = b - a;
    let e2 = c - a;
    let pvec = dir.cross(e2);
    let det = e1.dot(pvec);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tvec = origin - a;
    let u = tvec.dot(pvec) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(e1);
    let v = dir.dot(qvec) * inv;
    if v < 0.0 || u + v > 1.0 || v.is_nan() {
        return None;
    }
    let t = e2.dot(qvec) * inv;
    (t > 0.0 && t.is_finite()).then_some((t, [1.0 - u - v, u, v]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [DVec3; 3] {
        [DVec3::ZERO, DVec3::X, DVec3::Y]
    }

    #[test]
    fn closest_point_regions() {
        let (q, w) = closest_point_on_triangle(DVec3::new(0.25, 0.25, 1.0), tri());
        assert_eq!(q, DVec3::new(0.25, 0.25, 0.0));
        assert!((w[0] - 0.5).abs() < 1e-15 && (w[1] - 0.25).abs() < 1e-15);
        let (q, w) = closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), tri());
        assert_eq!((q, w), (DVec3::ZERO, [1.0, 0.0, 0.0]));
        let (q, _) = closest_point_on_triangle(DVec3::new(0.5, -2.0, 3.0), tri());
        assert_eq!(q, DVec3::new(0.5, 0.0, 0.0));
        let (q, _) = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), tri());
        assert!(q.distance(DVec3::new(0.5, 0.5, 0.0)) < 1e-15);
    }

    #[test]
    fn closest_point_on_degenerate_triangles_is_finite_and_right() {
        let p = DVec3::new(0.5, 1.0, 0.0);
        let collinear = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::X];
        let (q, w) = closest_point_on_triangle(p, collinear);
        assert!(q.distance(DVec3::new(0.5, 0.0, 0.0)) < 1e-15);
        let back = w[0] * collinear[0] + w[1] * collinear[1] + w[2] * collinear[2];
        assert!(back.distance(q) < 1e-15);
        let point = [DVec3::ONE; 3];
        assert_eq!(closest_point_on_triangle(p, point).0, DVec3::ONE);
    }

    #[test]
    fn ray_hits_inside_and_edges_and_misses_outside() {
        let (t, w) = ray_triangle(DVec3::new(0.25, 0.25, 1.0), -DVec3::Z, tri()).unwrap();
        assert_eq!(t, 1.0);
        assert_eq!(w, [0.5, 0.25, 0.25]);
        assert!(ray_triangle(DVec3::new(0.5, 0.5, 1.0), -DVec3::Z, tri()).is_some());
        assert!(ray_triangle(DVec3::new(0.6, 0.6, 1.0), -DVec3::Z, tri()).is_none());
        assert!(ray_triangle(DVec3::new(0.25, 0.25, 1.0), DVec3::Z, tri()).is_none());
        assert!(ray_triangle(DVec3::new(0.25, 0.25, 1.0), DVec3::X, tri()).is_none());
        let flat = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        assert!(ray_triangle(DVec3::new(0.5, 0.0, 1.0), -DVec3::Z, flat).is_none());
    }
}
