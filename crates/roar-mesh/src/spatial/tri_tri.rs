//! Exact triangle–triangle intersection on `robust` orientation predicates.
//!
//! Naming: triangles are *closed* point sets (interior, edges and corners), so touching at a
//! point or along an edge counts as intersecting in [`triangles_intersect`]. *Faces* are index
//! triples into a shared vertex buffer; [`faces_intersect`] discounts the contact that shared
//! indices force (a shared corner or edge) and reports only overlap beyond it.
//!
//! Method: two closed convex sets that meet have an extreme point of their intersection on the
//! boundary of one of them, so two triangles intersect iff an edge of one meets the other
//! triangle. Each segment–triangle test is decided by the signs of `orient3d`; coplanar
//! configurations drop one coordinate (chosen so the projection is one-to-one on their plane)
//! and are decided by the signs of `orient2d`. All signs are exact (Shewchuk's adaptive
//! predicates), so the answer is exact for the given f64 coordinates, degenerate triangles
//! (repeated or collinear corners) included.

use glam::DVec3;
use robust::{Coord, Coord3D};

/// Sign of the exact orientation of `d` relative to the plane through `a, b, c`.
fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let c3 = |p: DVec3| Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// A coordinate plane: the two kept axes of a projection that drops the third.
#[derive(Clone, Copy)]
struct Projection(usize, usize);

const PROJECTIONS: [Projection; 3] = [Projection(0, 1), Projection(1, 2), Projection(2, 0)];

impl Projection {
    fn apply(self, p: DVec3) -> Coord<f64> {
        Coord {
            x: p[self.0],
            y: p[self.1],
        }
    }

    fn orient2d(self, a: DVec3, b: DVec3, c: DVec3) -> i8 {
        sign(robust::orient2d(
            self.apply(a),
            self.apply(b),
            self.apply(c),
        ))
    }
}

/// True if `a, b, c` are collinear (or coincide), exactly.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    PROJECTIONS.iter().all(|pr| pr.orient2d(a, b, c) == 0)
}

/// A projection that is one-to-one on the affine hull of `points`, which must be coplanar.
/// `None` if all points coincide.
fn faithful_projection(points: &[DVec3]) -> Option<Projection> {
    // A non-collinear triple fixes the plane: drop an axis along which its normal is non-zero.
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            for k in j + 1..points.len() {
                for pr in PROJECTIONS {
                    if pr.orient2d(points[i], points[j], points[k]) != 0 {
                        return Some(pr);
                    }
                }
            }
        }
    }
    // All on one line: keep two axes in which two distinct points differ.
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            let (p, q) = (points[i], points[j]);
            for pr in PROJECTIONS {
                if p[pr.0] != q[pr.0] || p[pr.1] != q[pr.1] {
                    return Some(pr);
                }
            }
        }
    }
    None
}

/// Closed segments `[p, q]` and `[r, s]` meet, in the projection (possibly degenerate segments).
fn segments_intersect_2d(pr: Projection, p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
    let o1 = pr.orient2d(p, q, r);
    let o2 = pr.orient2d(p, q, s);
    let o3 = pr.orient2d(r, s, p);
    let o4 = pr.orient2d(r, s, q);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && within_box_2d(pr, p, q, r))
        || (o2 == 0 && within_box_2d(pr, p, q, s))
        || (o3 == 0 && within_box_2d(pr, r, s, p))
        || (o4 == 0 && within_box_2d(pr, r, s, q))
}

/// For `x` collinear with `[p, q]` (in the projection): `x` lies on the closed segment.
fn within_box_2d(pr: Projection, p: DVec3, q: DVec3, x: DVec3) -> bool {
    [pr.0, pr.1]
        .iter()
        .all(|&k| p[k].min(q[k]) <= x[k] && x[k] <= p[k].max(q[k]))
}

/// `x` lies in the closed, non-degenerate (in the projection) triangle `t`.
fn point_in_triangle_2d(pr: Projection, x: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let s = [
        pr.orient2d(a, b, x),
        pr.orient2d(b, c, x),
        pr.orient2d(c, a, x),
    ];
    !(s.contains(&1) && s.contains(&-1))
}

/// A triangle that is not `collinear` has a non-zero `orient2d` in some coordinate plane; should
/// that ever fail, fall back to the edge-by-edge test rather than panic.
macro_rules! unreachable_collinear_case {
    ($p:expr, $q:expr, $a:expr, $b:expr, $c:expr) => {
        return segments_intersect($p, $q, $a, $b)
            || segments_intersect($p, $q, $b, $c)
            || segments_intersect($p, $q, $c, $a)
    };
}

/// Closed segments `[p, q]` and `[r, s]` in 3D meet (possibly degenerate segments).
fn segments_intersect(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
    if orient3d(p, q, r, s) != 0 {
        return false;
    }
    match faithful_projection(&[p, q, r, s]) {
        Some(pr) => segments_intersect_2d(pr, p, q, r, s),
        None => true, // all four points coincide
    }
}

/// The closed segment `[p, q]` meets the closed triangle `t` (either may be degenerate).
pub fn segment_intersects_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let [a, b, c] = t;
    if collinear(a, b, c) {
        // The triangle is the union of its edges.
        return segments_intersect(p, q, a, b)
            || segments_intersect(p, q, b, c)
            || segments_intersect(p, q, c, a);
    }
    let sp = orient3d(a, b, c, p);
    let sq = orient3d(a, b, c, q);
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        // Segment in the triangle's plane: a projection keeping an axis pair where the
        // triangle is non-degenerate is one-to-one on that plane.
        let Some(pr) = PROJECTIONS.into_iter().find(|pr| pr.orient2d(a, b, c) != 0) else {
            unreachable_collinear_case!(p, q, a, b, c)
        };
        return point_in_triangle_2d(pr, p, t)
            || point_in_triangle_2d(pr, q, t)
            || segments_intersect_2d(pr, p, q, a, b)
            || segments_intersect_2d(pr, p, q, b, c)
            || segments_intersect_2d(pr, p, q, c, a);
    }
    // The segment meets the plane in exactly one point; it is in the triangle iff the line
    // passes on the same side of (or on) all three edges.
    let s = [
        orient3d(p, q, a, b),
        orient3d(p, q, b, c),
        orient3d(p, q, c, a),
    ];
    !(s.contains(&1) && s.contains(&-1))
}

/// True if the closed triangles `a` and `b` share at least one point (exact).
///
/// Touching at a corner, along an edge, or coplanar overlap all count. Degenerate triangles are
/// treated as the segments or points they are.
pub fn triangles_intersect(a: [DVec3; 3], b: [DVec3; 3]) -> bool {
    // Early out: all corners of one triangle strictly on one side of the other's plane. For a
    // degenerate triangle all signs are 0, so nothing is rejected.
    let side_of_b = a.map(|p| orient3d(b[0], b[1], b[2], p));
    if side_of_b.iter().all(|&s| s > 0) || side_of_b.iter().all(|&s| s < 0) {
        return false;
    }
    let side_of_a = b.map(|p| orient3d(a[0], a[1], a[2], p));
    if side_of_a.iter().all(|&s| s > 0) || side_of_a.iter().all(|&s| s < 0) {
        return false;
    }
    (0..3).any(|i| segment_intersects_triangle(a[i], a[(i + 1) % 3], b))
        || (0..3).any(|i| segment_intersects_triangle(b[i], b[(i + 1) % 3], a))
}

/// True if faces `ta` and `tb` of one mesh intersect beyond the contact their shared vertex
/// indices force.
///
/// Inputs: `positions` (#V); two index triples. Rules:
/// - no shared index: [`triangles_intersect`] (touching counts);
/// - one shared index: intersect iff the closed triangles meet anywhere other than that vertex;
/// - two shared indices: intersect iff they overlap beyond the shared edge (coplanar and on the
///   same side: folded onto each other);
/// - three shared indices (a duplicate face, either orientation): intersect.
///
/// A face with a repeated index or an index out of range is degenerate input counted elsewhere
/// and never intersects. Faces that are collinear (zero area with distinct indices) and pass
/// through the shared vertex are reported as intersecting (conservative).
pub fn faces_intersect(positions: &[DVec3], ta: [u32; 3], tb: [u32; 3]) -> bool {
    let valid = |t: [u32; 3]| {
        t[0] != t[1]
            && t[1] != t[2]
            && t[2] != t[0]
            && t.iter().all(|&i| (i as usize) < positions.len())
    };
    if !valid(ta) || !valid(tb) {
        return false;
    }
    let pa = ta.map(|i| positions[i as usize]);
    let pb = tb.map(|i| positions[i as usize]);
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| ta[i] == tb[j])
        .collect();
    match shared.as_slice() {
        [] => triangles_intersect(pa, pb),
        &[(i, j)] => {
            // Opposite edges of the shared corner: if either meets the other triangle, the
            // contact goes beyond the shared vertex (an extreme point of the intersection other
            // than the shared vertex lies on an opposite edge or is a corner in the other face).
            segment_intersects_triangle(pa[(i + 1) % 3], pa[(i + 2) % 3], pb)
                || segment_intersects_triangle(pb[(j + 1) % 3], pb[(j + 2) % 3], pa)
        }
        &[(i0, _), (i1, _)] => {
            let u = pa[i0];
            let v = pa[i1];
            let a = pa[3 - i0 - i1];
            let b = pb[3 - shared[0].1 - shared[1].1];
            overlap_beyond_shared_edge(u, v, a, b)
        }
        _ => true,
    }
}

/// Triangles `(u, v, a)` and `(u, v, b)` share the edge `[u, v]`; do they overlap beyond it?
fn overlap_beyond_shared_edge(u: DVec3, v: DVec3, a: DVec3, b: DVec3) -> bool {
    if orient3d(u, v, a, b) != 0 {
        // Different planes meeting in the line uv: the intersection is within the edge.
        return false;
    }
    let Some(pr) = faithful_projection(&[u, v, a, b]) else {
        return false; // every corner at one point: nothing beyond the (degenerate) edge
    };
    let sa = pr.orient2d(u, v, a);
    let sb = pr.orient2d(u, v, b);
    if sa != 0 && sb != 0 {
        return sa == sb; // same side: folded onto each other
    }
    if sa != 0 || sb != 0 {
        // One face is a segment on the line uv, the other meets that line only in [u, v].
        return false;
    }
    // Both faces are segments on the line uv: they overlap beyond [u, v] iff a and b stick
    // out past the same end.
    let beyond = |x: DVec3| {
        if within_box_2d(pr, u, v, x) {
            0
        } else if within_box_2d(pr, u, x, v) {
            1 // past v
        } else {
            -1 // past u
        }
    };
    let (ea, eb) = (beyond(a), beyond(b));
    ea != 0 && ea == eb
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn crossing_and_separated() {
        let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
        let piercing = [v(0.5, 0.5, -1.), v(0.5, 0.5, 1.), v(3., 3., 0.5)];
        assert!(triangles_intersect(a, piercing));
        let above = [v(0., 0., 1.), v(2., 0., 1.), v(0., 2., 1.)];
        assert!(!triangles_intersect(a, above));
    }

    #[test]
    fn degenerate_triangles_are_segments() {
        let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
        let needle = [v(0.5, 0.5, -1.), v(0.5, 0.5, 1.), v(0.5, 0.5, 0.)];
        assert!(triangles_intersect(a, needle));
        let beside = [v(5., 5., -1.), v(5., 5., 1.), v(5., 5., 0.)];
        assert!(!triangles_intersect(a, beside));
        let point = [v(0.5, 0.5, 0.); 3];
        assert!(triangles_intersect(a, point));
        assert!(triangles_intersect(point, point));
    }
}
