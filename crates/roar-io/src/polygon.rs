//! Triangulating a polygon face in its own plane, by ear clipping: the one place every reader's
//! polygons (OBJ, OFF, PLY faces, ASCII STL loops) become triangles.
//!
//! The polygon is projected onto the coordinate plane most nearly parallel to it (its Newell
//! normal decides which, and the winding), then ears are clipped. On a convex polygon the first
//! ear is always at corner 1, so the result is the fan around corner 0, as before: only
//! concave polygons change, which a fan would have covered with overlapping triangles.

use glam::{DVec2, DVec3};

/// Polygons with more corners than this are fan-triangulated (ear clipping is quadratic in the
/// corner count) and counted as not triangulated cleanly.
pub const MAX_EAR_CLIPPING_CORNERS: usize = 4096;

/// Appends the triangles of the polygon `corners` (indices into `positions`, at least 3) to
/// `out`, `corners.len() − 2` of them, each wound like the polygon. Returns `false` when the
/// polygon could not be triangulated cleanly: a corner index out of range, no plane (all
/// corners on a line or a point, or corners off the plane: [`PLANARITY_TOLERANCE`]), more than
/// [`MAX_EAR_CLIPPING_CORNERS`] corners, or a self-intersecting outline where no ear is left;
/// the polygon (or what remains of it) is then fan-triangulated.
pub fn triangulate_polygon(positions: &[DVec3], corners: &[u32], out: &mut Vec<[u32; 3]>) -> bool {
    let n = corners.len();
    if n == 3 {
        out.push([corners[0], corners[1], corners[2]]);
        return true;
    }
    let points: Option<Vec<DVec3>> = corners
        .iter()
        .map(|&c| positions.get(c as usize).copied())
        .collect();
    let Some(points) = points else {
        push_fan(corners, out);
        return false;
    };
    let normal = newell_normal(&points);
    if n > MAX_EAR_CLIPPING_CORNERS || !normal.is_finite() || normal.length() == 0.0 {
        push_fan(corners, out);
        return false;
    }
    if !is_planar(&points, normal) {
        push_fan(corners, out);
        return false;
    }
    let flat = project(&points, normal);
    let mut remaining: Vec<usize> = (0..n).collect();
    while remaining.len() > 3 {
        let m = remaining.len();
        let ear = (1..=m).map(|k| k % m).find(|&k| {
            let (a, b, c) = (
                remaining[(k + m - 1) % m],
                remaining[k],
                remaining[(k + 1) % m],
            );
            is_ear(&flat, &remaining, a, b, c)
        });
        let Some(k) = ear else {
            let rest: Vec<u32> = remaining.iter().map(|&i| corners[i]).collect();
            push_fan(&rest, out);
            return false;
        };
        let (a, b, c) = (
            remaining[(k + m - 1) % m],
            remaining[k],
            remaining[(k + 1) % m],
        );
        out.push([corners[a], corners[b], corners[c]]);
        remaining.remove(k);
    }
    out.push([
        corners[remaining[0]],
        corners[remaining[1]],
        corners[remaining[2]],
    ]);
    true
}

/// Relative distance from the polygon's plane above which a polygon counts as non-planar: it has
/// no plane to be triangulated in, so it keeps the fan (what every tool does with it).
pub const PLANARITY_TOLERANCE: f64 = 1e-6;

/// Whether every corner lies within [`PLANARITY_TOLERANCE`] × the polygon's extent of the plane
/// through the centroid with the Newell normal.
fn is_planar(points: &[DVec3], normal: DVec3) -> bool {
    let unit = normal.normalize();
    let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let extent = points
        .iter()
        .map(|p| (*p - centroid).length())
        .fold(0.0, f64::max);
    points
        .iter()
        .all(|p| (*p - centroid).dot(unit).abs() <= PLANARITY_TOLERANCE * extent)
}

/// The fan `(c0, c1, c2), (c0, c2, c3), …`.
fn push_fan(corners: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..corners.len().saturating_sub(1) {
        out.push([corners[0], corners[k], corners[k + 1]]);
    }
}

/// Newell's normal: twice the vector area of the outline, robust for non-planar and concave
/// polygons.
fn newell_normal(points: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        n += DVec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    n
}

/// The points in the coordinate plane most nearly perpendicular to `normal`, oriented so the
/// outline runs counter-clockwise.
fn project(points: &[DVec3], normal: DVec3) -> Vec<DVec2> {
    let a = normal.abs();
    let (u, v, sign) = if a.z >= a.x && a.z >= a.y {
        (0, 1, normal.z)
    } else if a.x >= a.y {
        (1, 2, normal.x)
    } else {
        (2, 0, normal.y)
    };
    points
        .iter()
        .map(|p| {
            let p = p.to_array();
            DVec2::new(p[u], if sign >= 0.0 { p[v] } else { -p[v] })
        })
        .collect()
}

fn cross(o: DVec2, a: DVec2, b: DVec2) -> f64 {
    (a - o).perp_dot(b - o)
}

/// Whether `(a, b, c)` is an ear: a convex corner at `b` whose triangle holds no other remaining
/// corner (inside or on its boundary, except at a position equal to one of its own corners).
fn is_ear(flat: &[DVec2], remaining: &[usize], a: usize, b: usize, c: usize) -> bool {
    let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
    if cross(pa, pb, pc) <= 0.0 {
        return false;
    }
    remaining.iter().all(|&i| {
        if i == a || i == b || i == c {
            return true;
        }
        let p = flat[i];
        if p == pa || p == pb || p == pc {
            return true;
        }
        let inside = cross(pa, pb, p) >= 0.0 && cross(pb, pc, p) >= 0.0 && cross(pc, pa, p) >= 0.0;
        !inside
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(positions: &[DVec3], triangles: &[[u32; 3]]) -> DVec3 {
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                (b - a).cross(c - a) * 0.5
            })
            .sum()
    }

    #[test]
    fn convex_polygons_stay_fans() {
        let positions: Vec<DVec3> = (0..6)
            .map(|k| {
                let t = k as f64 / 6.0 * std::f64::consts::TAU;
                DVec3::new(t.cos(), t.sin(), 0.3)
            })
            .collect();
        let mut out = Vec::new();
        assert!(triangulate_polygon(
            &positions,
            &[0, 1, 2, 3, 4, 5],
            &mut out
        ));
        assert_eq!(out, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]);
    }

    #[test]
    fn concave_polygons_get_no_overlapping_triangles_in_any_plane() {
        // An L-shape (concave at corner 0), tilted out of every coordinate plane and wound both
        // ways: the triangles' vector areas add up to the polygon's, so none overlap or flip.
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let rotate = |x: f64, y: f64| DVec3::new(x, 0.6 * y, 0.8 * y + 0.1 * x);
        for start in 0..6 {
            for reverse in [false, true] {
                let mut order: Vec<u32> = (0..6).map(|k| ((k + start) % 6) as u32).collect();
                if reverse {
                    order.reverse();
                }
                let positions: Vec<DVec3> = l.iter().map(|&(x, y)| rotate(x, y)).collect();
                let mut out = Vec::new();
                assert!(triangulate_polygon(&positions, &order, &mut out));
                assert_eq!(out.len(), 4);
                let ordered: Vec<DVec3> = order.iter().map(|&i| positions[i as usize]).collect();
                let want = newell_normal(&ordered) * 0.5;
                let got = area(&positions, &out);
                assert!(
                    (got - want).length() < 1e-12,
                    "{start} {reverse}: {got} vs {want}"
                );
                for t in &out {
                    let [a, b, c] = t.map(|i| positions[i as usize]);
                    assert!(
                        (b - a).cross(c - a).dot(want) > 0.0,
                        "{t:?} flipped or flat"
                    );
                }
            }
        }
    }

    #[test]
    fn degenerate_and_broken_polygons_are_reported_and_still_triangulated() {
        let line: Vec<DVec3> = (0..4).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        let mut out = Vec::new();
        assert!(!triangulate_polygon(&line, &[0, 1, 2, 3], &mut out));
        assert_eq!(out.len(), 2);
        out.clear();
        assert!(!triangulate_polygon(&line, &[0, 1, 2, 9], &mut out));
        assert_eq!(out.len(), 2);
        // A quad bent out of its plane keeps its fan.
        let bent = [
            (0.0, 0.0, 0.0),
            (1.0, 0.0, 0.0),
            (1.0, 1.0, 0.2),
            (0.0, 1.0, 0.0),
        ]
        .map(|(x, y, z)| DVec3::new(x, y, z));
        out.clear();
        assert!(!triangulate_polygon(&bent, &[0, 1, 2, 3], &mut out));
        assert_eq!(out, [[0, 1, 2], [0, 2, 3]]);
        // A bow tie: its outline crosses itself.
        let bow = [(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0), (-1.0, 1.0)]
            .map(|(x, y)| DVec3::new(x, y, 0.0));
        out.clear();
        triangulate_polygon(&bow, &[0, 1, 2, 3, 4], &mut out);
        assert_eq!(out.len(), 3);
    }
}
