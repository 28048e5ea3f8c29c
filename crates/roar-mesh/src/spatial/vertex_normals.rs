//! Vertex normals: the sum of the normals of the faces around a vertex, each weighting a named
//! function. Faces with an out-of-range index are skipped; a vertex whose sum vanishes (or that
//! no face references) gets a zero normal.

use super::triangle::{DEGENERATE_CROSS, corner_angles, triangle_normal};
use glam::DVec3;

/// The ROAR weighting (`docs/method.md#conventions`) of face `p`: its unit normal and, at each
/// corner, its area **times** the corner angle. A degenerate face (`|cross| ≤ 1e-9`) has normal
/// `(1, 0, 0)` and area 1e-9, as the authors' code does.
pub fn area_angle_weights(p: [DVec3; 3]) -> (DVec3, [f64; 3]) {
    let len = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let area = if len > DEGENERATE_CROSS && len.is_finite() {
        0.5 * len
    } else {
        DEGENERATE_CROSS
    };
    let normal = triangle_normal(p[0], p[1], p[2]);
    (normal, corner_angles(p).map(|angle| area * angle))
}

/// ROAR vertex normals: `N_v = Σ_{f∋v} A_f θ_{f,v} n_f`, normalized (weights of
/// [`area_angle_weights`]); what the losses and the finish use.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for (tri, p) in corners(positions, triangles) {
        let (normal, weights) = area_angle_weights(p);
        for k in 0..3 {
            sums[tri[k] as usize] += weights[k] * normal;
        }
    }
    sums.into_iter().map(|n| n.normalize_or_zero()).collect()
}

/// Area-weighted vertex normals: `Σ_{f∋v} (p1 − p0) × (p2 − p0)`, normalized (each face weighs
/// with twice its area); the untangle block's probe directions.
pub fn area_weighted_vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for (tri, [a, b, c]) in corners(positions, triangles) {
        let cross = (b - a).cross(c - a);
        for i in tri {
            sums[i as usize] += cross;
        }
    }
    sums.into_iter().map(|n| n.normalize_or_zero()).collect()
}

/// The triangles whose three indices are in range, with their corners.
fn corners<'a>(
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
) -> impl Iterator<Item = ([u32; 3], [DVec3; 3])> + 'a {
    triangles.iter().filter_map(|&tri| {
        let p = tri.map(|i| positions.get(i as usize).copied());
        Some((tri, [p[0]?, p[1]?, p[2]?]))
    })
}
