//! Exact triangle–triangle intersection: hand-built configurations and symmetry properties.

use glam::DVec3;
use proptest::prelude::*;
use roar_mesh::spatial::{faces_intersect, triangles_intersect};

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Positions used by the face tests: a unit right triangle 0-1-2 in z = 0 and extra points.
fn positions() -> Vec<DVec3> {
    vec![
        v(0., 0., 0.),    // 0
        v(1., 0., 0.),    // 1
        v(0., 1., 0.),    // 2
        v(1., -1., 0.),   // 3: across edge 0-1, coplanar
        v(0.5, 0.5, 1.),  // 4: above, sharing edge 0-1 -> a hinge
        v(0.6, 0.2, 0.),  // 5: coplanar, same side as 2 -> folded onto face 0-1-2
        v(-1., 0., 1.),   // 6
        v(-1., 1., 1.),   // 7
        v(0.3, 0.3, -1.), // 8: below the triangle
        v(0.3, 0.3, 1.),  // 9: above the triangle
        v(-1., -1., 0.),  // 10
    ]
}

#[test]
fn sharing_an_edge_is_not_an_intersection() {
    let p = positions();
    assert!(
        !faces_intersect(&p, [0, 1, 2], [1, 0, 3]),
        "coplanar, opposite sides"
    );
    assert!(
        !faces_intersect(&p, [0, 1, 2], [1, 0, 4]),
        "hinge at an angle"
    );
}

#[test]
fn folded_onto_each_other_intersects() {
    let p = positions();
    assert!(faces_intersect(&p, [0, 1, 2], [1, 0, 5]));
}

#[test]
fn sharing_a_vertex_is_not_an_intersection_unless_they_cross() {
    let p = positions();
    assert!(
        !faces_intersect(&p, [0, 1, 2], [0, 6, 7]),
        "fan away from the triangle"
    );
    assert!(
        !faces_intersect(&p, [0, 1, 2], [0, 10, 3]),
        "coplanar, touching only at 0"
    );
    // Shares vertex 0 and passes through the triangle's interior from below to above.
    assert!(faces_intersect(&p, [0, 1, 2], [0, 8, 9]));
    // Shares vertex 0 and overlaps it in the plane.
    assert!(faces_intersect(&p, [0, 1, 2], [0, 5, 10]));
}

#[test]
fn coplanar_overlap_intersects() {
    let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
    let b = [v(0.5, 0.5, 0.), v(3., 0.5, 0.), v(0.5, 3., 0.)];
    assert!(triangles_intersect(a, b));
    let inside = [v(0.2, 0.2, 0.), v(0.4, 0.2, 0.), v(0.2, 0.4, 0.)];
    assert!(triangles_intersect(a, inside));
    let apart = [v(2., 2., 0.), v(3., 2., 0.), v(2., 3., 0.)];
    assert!(!triangles_intersect(a, apart));
}

#[test]
fn touching_at_a_point_intersects() {
    let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
    // Corner of b on a's interior.
    let b = [v(0.5, 0.5, 0.), v(0.5, 0.5, 1.), v(1.5, 0.5, 1.)];
    assert!(triangles_intersect(a, b));
    // Corner to corner.
    let c = [v(2., 0., 0.), v(3., 0., 1.), v(3., 1., 1.)];
    assert!(triangles_intersect(a, c));
    // Same, nudged away by one ulp-scale step.
    let d = [v(2. + 1e-15, 0., 0.), v(3., 0., 1.), v(3., 1., 1.)];
    assert!(!triangles_intersect(a, d));
}

#[test]
fn crossing_through_an_edge_intersects() {
    let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
    // b's plane y = 0 contains a's edge 0-1 and b straddles z = 0.
    let b = [v(0.5, 0., -1.), v(1.5, 0., -1.), v(1., 0., 1.)];
    assert!(triangles_intersect(a, b));
    // A triangle piercing a's edge 0-1 transversally.
    let c = [v(1., -1., -1.), v(1., 1., -1.), v(1., 0., 1.)];
    assert!(triangles_intersect(a, c));
}

#[test]
fn disjoint_parallel_do_not_intersect() {
    let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
    let b = [v(0., 0., 1e-9), v(2., 0., 1e-9), v(0., 2., 1e-9)];
    assert!(!triangles_intersect(a, b));
}

#[test]
fn exact_duplicate_intersects() {
    let p = positions();
    assert!(faces_intersect(&p, [0, 1, 2], [0, 1, 2]));
    assert!(
        faces_intersect(&p, [0, 1, 2], [2, 1, 0]),
        "duplicate with flipped orientation"
    );
    let a = [p[0], p[1], p[2]];
    assert!(triangles_intersect(a, a));
}

#[test]
fn faces_with_repeated_or_bad_indices_never_intersect() {
    let p = positions();
    assert!(!faces_intersect(&p, [0, 0, 2], [0, 1, 2]));
    assert!(!faces_intersect(&p, [0, 1, 2], [0, 1, 99]));
}

fn grid_triangle() -> impl Strategy<Value = [DVec3; 3]> {
    // A coarse grid makes touching, coplanar and degenerate configurations common.
    let p = (-2i32..=2, -2i32..=2, -2i32..=2).prop_map(|(x, y, z)| v(x as f64, y as f64, z as f64));
    [p.clone(), p.clone(), p]
}

fn float_triangle() -> impl Strategy<Value = [DVec3; 3]> {
    let p = (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y, z)| v(x, y, z));
    [p.clone(), p.clone(), p]
}

fn triangle() -> impl Strategy<Value = [DVec3; 3]> {
    prop_oneof![grid_triangle(), float_triangle()]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn symmetric_and_invariant_to_corner_rotation_and_flip(a in triangle(), b in triangle()) {
        let r = triangles_intersect(a, b);
        prop_assert_eq!(r, triangles_intersect(b, a));
        prop_assert_eq!(r, triangles_intersect([a[1], a[2], a[0]], b));
        prop_assert_eq!(r, triangles_intersect(a, [b[2], b[0], b[1]]));
        prop_assert_eq!(r, triangles_intersect([a[0], a[2], a[1]], b));
        // Translating by an exactly representable offset changes nothing on the grid.
        if a.iter().chain(&b).all(|p| p.x.fract() == 0.0) {
            let t = v(4., -8., 2.);
            prop_assert_eq!(r, triangles_intersect(a.map(|p| p + t), b.map(|p| p + t)));
        }
    }

    #[test]
    fn faces_rules_are_symmetric_and_rotation_invariant(
        pts in prop::collection::vec((-2i32..=2, -2i32..=2, -2i32..=2).prop_map(|(x, y, z)| v(x as f64, y as f64, z as f64)), 6),
        ta in [0u32..6, 0u32..6, 0u32..6],
        tb in [0u32..6, 0u32..6, 0u32..6],
    ) {
        let r = faces_intersect(&pts, ta, tb);
        prop_assert_eq!(r, faces_intersect(&pts, tb, ta));
        prop_assert_eq!(r, faces_intersect(&pts, [ta[1], ta[2], ta[0]], tb));
        prop_assert_eq!(r, faces_intersect(&pts, ta, [tb[2], tb[0], tb[1]]));
        // Without shared indices the face test is the plain closed-triangle test.
        let shares = ta.iter().any(|i| tb.contains(i));
        let valid = |t: [u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
        if !shares && valid(ta) && valid(tb) {
            prop_assert_eq!(r, triangles_intersect(ta.map(|i| pts[i as usize]), tb.map(|i| pts[i as usize])));
        }
        // Shared contact alone is never reported: sharing ⇒ intersect implies overlap elsewhere,
        // so intersecting faces must at least intersect as closed triangles.
        if r {
            prop_assert!(triangles_intersect(ta.map(|i| pts[i as usize]), tb.map(|i| pts[i as usize])));
        }
    }
}

/// Floating-point Möller interval test, trusted only when nothing is near a tie: returns `None`
/// if any corner is within `eps` of the other plane or the two intervals nearly touch.
fn moller_f64(a: [DVec3; 3], b: [DVec3; 3]) -> Option<bool> {
    const EPS: f64 = 1e-7;
    let normal = |t: [DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    let (na, nb) = (normal(a), normal(b));
    let cut = |t: [DVec3; 3], n: DVec3, o: DVec3| -> Option<Vec<DVec3>> {
        let d = t.map(|p| n.dot(p - o));
        if d.iter().any(|x| x.abs() < EPS) {
            return None;
        }
        let mut pts = Vec::new();
        for i in 0..3 {
            let (p, q, dp, dq) = (t[i], t[(i + 1) % 3], d[i], d[(i + 1) % 3]);
            if dp * dq < 0.0 {
                pts.push(p + (q - p) * (dp / (dp - dq)));
            }
        }
        Some(pts)
    };
    let pa = cut(a, nb, b[0])?;
    let pb = cut(b, na, a[0])?;
    if pa.is_empty() || pb.is_empty() {
        return Some(false);
    }
    let dir = na.cross(nb);
    if dir.length() < 1e-3 {
        return None; // nearly parallel planes
    }
    let span = |pts: &[DVec3]| {
        let s: Vec<f64> = pts.iter().map(|p| dir.dot(*p)).collect();
        (
            s.iter().cloned().fold(f64::INFINITY, f64::min),
            s.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let ((a0, a1), (b0, b1)) = (span(&pa), span(&pb));
    let gap = a0.max(b0) - a1.min(b1);
    (gap.abs() > EPS).then_some(gap < 0.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn generic_triangles_agree_with_a_float_oracle_away_from_ties(a in float_triangle(), b in float_triangle()) {
        if let Some(expected) = moller_f64(a, b) {
            prop_assert_eq!(triangles_intersect(a, b), expected);
        }
    }
}
