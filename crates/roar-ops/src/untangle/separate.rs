//! The last phase of [`super::untangle`]: once no face pair intersects, faces that used to cross
//! are pushed apart until every such pair is at least the margin apart, so the written (rounded)
//! file stays clean.

use glam::DVec3;
use roar_mesh::spatial::{Aabb, TriangleBvh, closest_point_on_triangle};
use std::collections::BTreeSet;

/// Squared distance between segments `p0p1` and `q0q1` (Ericson, Real-Time Collision
/// Detection, section 5.1.9).
fn segment_distance_squared(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return r.length_squared();
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    (p0 + d1 * s).distance_squared(q0 + d2 * t)
}

/// Distance between two non-intersecting triangles: the minimum over corner–triangle and
/// edge–edge distances.
fn triangle_distance(a: [DVec3; 3], b: [DVec3; 3]) -> f64 {
    let mut best = f64::INFINITY;
    for p in a {
        best = best.min(p.distance_squared(closest_point_on_triangle(p, b).0));
    }
    for p in b {
        best = best.min(p.distance_squared(closest_point_on_triangle(p, a).0));
    }
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(segment_distance_squared(
                a[i],
                a[(i + 1) % 3],
                b[j],
                b[(j + 1) % 3],
            ));
        }
    }
    best.sqrt()
}

/// Pairs `(tracked face, other face)` sharing no vertex that are closer than `margin`.
pub(super) fn near_pairs(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    tracked: &BTreeSet<u32>,
    margin: f64,
) -> Vec<(u32, u32)> {
    if tracked.is_empty() {
        return Vec::new();
    }
    let bvh = TriangleBvh::build(positions, triangles);
    let corners = |f: u32| triangles[f as usize].map(|i| positions[i as usize]);
    let mut out = Vec::new();
    for &f in tracked {
        let mut b = Aabb::from_triangle(corners(f));
        b.min -= DVec3::splat(margin);
        b.max += DVec3::splat(margin);
        let tf = triangles[f as usize];
        let mut hits = Vec::new();
        bvh.faces_in_aabb(&b, |g| {
            let tg = triangles[g as usize];
            if g != f && !tf.iter().any(|i| tg.contains(i)) {
                hits.push(g);
            }
        });
        hits.sort_unstable();
        for g in hits {
            if triangle_distance(corners(f), corners(g)) < margin {
                out.push((f, g));
            }
        }
    }
    out
}

/// Pushes each face of each near pair away from the other's plane by `margin`; returns moves.
pub(super) fn separate(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    near: &[(u32, u32)],
    margin: f64,
) -> usize {
    let before = positions.to_vec();
    let mut offset = vec![DVec3::ZERO; positions.len()];
    let corners = |f: u32| triangles[f as usize].map(|i| before[i as usize]);
    for &(f, g) in near {
        for (x, y) in [(f, g), (g, f)] {
            let [a, b, c] = corners(y);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let cx = corners(x);
            let side = ((cx[0] + cx[1] + cx[2]) / 3.0 - a).dot(n);
            let dir = if side >= 0.0 { n } else { -n };
            for i in triangles[x as usize] {
                offset[i as usize] += dir * margin;
            }
        }
    }
    let mut moves = 0;
    for (p, o) in positions.iter_mut().zip(&offset) {
        if *o != DVec3::ZERO {
            *p += o.normalize() * margin;
            moves += 1;
        }
    }
    moves
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_distance_matches_parallel_offset() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let b = a.map(|p| p + DVec3::new(0.1, 0.1, 0.25));
        assert!((triangle_distance(a, b) - 0.25).abs() < 1e-12);
        let c = [
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
        ];
        assert!((triangle_distance(a, c) - 1.0).abs() < 1e-12);
    }
}
