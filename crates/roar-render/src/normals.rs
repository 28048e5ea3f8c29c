//! Flat shading: the unit face normal `n = normalize((p1 − p0) × (p2 − p0))` and its backward.
//! A degenerate face (zero cross product) gets the zero normal and no gradient.

use glam::DVec3;

/// Unit normal of triangle `(p0, p1, p2)`, or zero when degenerate.
pub fn face_normal(p0: DVec3, p1: DVec3, p2: DVec3) -> DVec3 {
    let c = (p1 - p0).cross(p2 - p0);
    let len = c.length();
    if len > 0.0 { c / len } else { DVec3::ZERO }
}

/// Backward of [`face_normal`]: given `dL/dn`, returns `dL/dp0, dL/dp1, dL/dp2`.
pub fn face_normal_backward(p0: DVec3, p1: DVec3, p2: DVec3, g_n: DVec3) -> [DVec3; 3] {
    let (e1, e2) = (p1 - p0, p2 - p0);
    let c = e1.cross(e2);
    let len = c.length();
    if len <= 0.0 {
        return [DVec3::ZERO; 3];
    }
    let n = c / len;
    let g_c = (g_n - n * n.dot(g_n)) / len;
    let g_e1 = e2.cross(g_c);
    let g_e2 = g_c.cross(e1);
    [-(g_e1 + g_e2), g_e1, g_e2]
}

/// Unit normals of all triangles.
pub fn face_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    triangles
        .iter()
        .map(|t| {
            face_normal(
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_cross_finite_difference() {
        let p = [
            DVec3::new(0.1, 0.2, -0.3),
            DVec3::new(1.0, 0.1, 0.2),
            DVec3::new(-0.2, 0.9, 0.4),
        ];
        let g_n = DVec3::new(0.3, -1.1, 0.7);
        let analytic = face_normal_backward(p[0], p[1], p[2], g_n);
        let h = 1e-6;
        for v in 0..3 {
            for k in 0..3 {
                let mut pp = p;
                let mut pm = p;
                pp[v][k] += h;
                pm[v][k] -= h;
                let fd = (face_normal(pp[0], pp[1], pp[2]).dot(g_n)
                    - face_normal(pm[0], pm[1], pm[2]).dot(g_n))
                    / (2.0 * h);
                assert!(
                    (fd - analytic[v][k]).abs() < 1e-6 * fd.abs() + 1e-9,
                    "vertex {v} axis {k}: {fd} vs {}",
                    analytic[v][k]
                );
            }
        }
    }

    #[test]
    fn degenerate_face_has_zero_normal_and_gradient() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(face_normal(p, p, p), DVec3::ZERO);
        assert_eq!(face_normal_backward(p, p, p, DVec3::ONE), [DVec3::ZERO; 3]);
    }
}
