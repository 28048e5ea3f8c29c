//! The triangle BVH agrees with brute force on random soups (degenerate faces included), also
//! after its vertices moved and it was refitted.

use glam::DVec3;
use proptest::prelude::*;
use roar_mesh::spatial::{Aabb, TriangleBvh, closest_point_on_triangle, ray_triangle};

/// A random soup: coordinates on a coarse grid (many coplanar, collinear, repeated points and
/// zero-area faces) or arbitrary floats; indices may repeat within a face.
fn soup() -> impl Strategy<Value = (Vec<DVec3>, Vec<[u32; 3]>)> {
    let grid = (-3i32..=3, -3i32..=3, -3i32..=3)
        .prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64));
    let float =
        (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    let point = prop_oneof![grid, float];
    prop::collection::vec(point, 3..24).prop_flat_map(|positions| {
        let n = positions.len() as u32;
        let faces = prop::collection::vec([0..n, 0..n, 0..n], 1..40);
        (Just(positions), faces)
    })
}

fn query_point() -> impl Strategy<Value = DVec3> {
    (-4.0..4.0f64, -4.0..4.0f64, -4.0..4.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn corners(positions: &[DVec3], t: [u32; 3]) -> [DVec3; 3] {
    t.map(|i| positions[i as usize])
}

fn brute_closest_d2(positions: &[DVec3], triangles: &[[u32; 3]], p: DVec3) -> f64 {
    triangles
        .iter()
        .map(|&t| p.distance_squared(closest_point_on_triangle(p, corners(positions, t)).0))
        .fold(f64::INFINITY, f64::min)
}

fn brute_ray_t(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    o: DVec3,
    d: DVec3,
    t_max: f64,
) -> Option<f64> {
    triangles
        .iter()
        .filter_map(|&t| ray_triangle(o, d, corners(positions, t)).map(|h| h.0))
        .filter(|&t| t <= t_max)
        .min_by(f64::total_cmp)
}

/// The certified search gives the bounded search's answer, a lower bound on the distance to every
/// other face (checked by brute force), and lets a moved query be answered by its face alone
/// exactly when the bound proves it.
fn check_certificate(
    bvh: &TriangleBvh,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    p: DVec3,
    radius: f64,
    toward: DVec3,
) {
    let within = bvh.closest_point_within(p, radius);
    let certified = bvh.closest_point_certified(p, radius);
    assert_eq!(within, certified.map(|c| c.closest));
    let Some(c) = certified else {
        return;
    };
    assert_eq!(bvh.closest_point_on_face(p, c.closest.face), c.closest);
    for (f, &t) in triangles.iter().enumerate() {
        if f as u32 == c.closest.face {
            continue;
        }
        let d2 = p.distance_squared(closest_point_on_triangle(p, corners(positions, t)).0);
        assert!(
            c.others_squared <= d2 * (1.0 + 1e-12),
            "face {f} at {d2} is nearer than the bound {}",
            c.others_squared
        );
    }
    // Moves of several lengths towards another point: wherever the bound proves the face is
    // still the nearest, the face's point is the fresh search's answer.
    for s in [1e-3, 1e-2, 0.1, 0.5] {
        let q = p + s * (toward - p);
        let moved = q.distance(p);
        let clear = c.others_squared.sqrt() - moved;
        let on_face = bvh.closest_point_on_face(q, c.closest.face);
        if on_face.distance_squared.sqrt() * (1.0 + 1e-9) < clear * (1.0 - 1e-9) {
            assert_eq!(bvh.closest_point(q), Some(on_face), "moved by {moved}");
        }
    }
}

fn check_against_brute_force(
    bvh: &TriangleBvh,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    queries: &[DVec3],
) {
    for (k, &p) in queries.iter().enumerate() {
        let hit = bvh.closest_point(p).expect("non-empty soup");
        let brute = brute_closest_d2(positions, triangles, p);
        assert!(
            (hit.distance_squared - brute).abs() <= 1e-12 * (1.0 + brute),
            "closest {hit:?} vs {brute}"
        );
        let face = corners(positions, triangles[hit.face as usize]);
        let w = hit.barycentric;
        let back = w[0] * face[0] + w[1] * face[1] + w[2] * face[2];
        assert!(back.distance(hit.point) < 1e-9);
        assert!((hit.point.distance_squared(p) - hit.distance_squared).abs() < 1e-12);

        let radius = 0.5 * brute.sqrt() + 0.3 * k as f64;
        let within = bvh.closest_point_within(p, radius);
        assert_eq!(
            within.is_some(),
            brute <= radius * radius,
            "within {radius}"
        );
        if let Some(w) = within {
            assert!((w.distance_squared - brute).abs() <= 1e-12 * (1.0 + brute));
        }
        check_certificate(
            bvh,
            positions,
            triangles,
            p,
            radius,
            queries[(k + 1) % queries.len()],
        );

        // A ray from the query towards the next query point (and a ray along an axis).
        let target = queries[(k + 1) % queries.len()];
        for (dir, t_max) in [
            (target - p, 1.0),
            (DVec3::Z, 10.0),
            (DVec3::new(1.0, 0.0, 0.0), 2.0),
        ] {
            let hit = bvh.ray_cast(p, dir, t_max);
            let brute = brute_ray_t(positions, triangles, p, dir, t_max);
            assert_eq!(hit.map(|h| h.t), brute, "ray from {p} along {dir}");
            let all = bvh.ray_cast_all(p, dir, t_max);
            let mut expected: Vec<(f64, u32)> = triangles
                .iter()
                .enumerate()
                .filter_map(|(f, &t)| {
                    ray_triangle(p, dir, corners(positions, t)).map(|h| (h.0, f as u32))
                })
                .filter(|&(t, _)| t <= t_max)
                .collect();
            expected.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(
                all.iter().map(|h| (h.t, h.face)).collect::<Vec<_>>(),
                expected
            );
            if let Some(h) = hit {
                let face = corners(positions, triangles[h.face as usize]);
                let w = h.barycentric;
                let on_face = w[0] * face[0] + w[1] * face[1] + w[2] * face[2];
                assert!(on_face.distance(p + h.t * dir) < 1e-9);
            }
        }
    }

    // Box queries and overlapping pairs against brute force.
    let face_box = |f: usize| Aabb::from_triangle(corners(positions, triangles[f]));
    let probe = Aabb::from_points(queries[..2].iter().copied()).unwrap();
    let mut found = Vec::new();
    bvh.faces_in_aabb(&probe, |f| found.push(f));
    found.sort();
    let expected: Vec<u32> = (0..triangles.len())
        .filter(|&f| face_box(f).overlaps(&probe))
        .map(|f| f as u32)
        .collect();
    assert_eq!(found, expected);

    let mut pairs = Vec::new();
    bvh.overlapping_pairs(|i, j| pairs.push((i, j)));
    pairs.sort();
    let mut expected = Vec::new();
    for i in 0..triangles.len() {
        for j in i + 1..triangles.len() {
            if face_box(i).overlaps(&face_box(j)) {
                expected.push((i as u32, j as u32));
            }
        }
    }
    assert_eq!(pairs, expected);
    let mut parallel = bvh.overlapping_pairs_parallel();
    parallel.sort();
    assert_eq!(parallel, expected);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn queries_match_brute_force((positions, triangles) in soup(), queries in prop::collection::vec(query_point(), 2..8)) {
        let bvh = TriangleBvh::build(&positions, &triangles);
        prop_assert_eq!(bvh.face_count(), triangles.len());
        check_against_brute_force(&bvh, &positions, &triangles, &queries);
    }

    #[test]
    fn refit_after_moving_vertices_matches_a_fresh_build(
        (positions, triangles) in soup(),
        shift in prop::collection::vec(query_point(), 24),
        queries in prop::collection::vec(query_point(), 2..6),
    ) {
        let mut bvh = TriangleBvh::build(&positions, &triangles);
        let moved: Vec<DVec3> = positions.iter().zip(&shift).map(|(p, s)| *p + 0.7 * *s).collect();
        bvh.refit(&moved);
        check_against_brute_force(&bvh, &moved, &triangles, &queries);
    }
}

#[test]
fn large_grid_of_quads_closest_points_and_rays() {
    // 200 × 200 quads in the plane z = 0: more than a few levels of tree.
    let n = 200u32;
    let positions: Vec<DVec3> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| DVec3::new(i as f64, j as f64, 0.0)))
        .collect();
    let idx = |i: u32, j: u32| j * (n + 1) + i;
    let triangles: Vec<[u32; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                [
                    [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)],
                    [idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)],
                ]
            })
        })
        .collect();
    let bvh = TriangleBvh::build(&positions, &triangles);
    let p = DVec3::new(17.3, 101.6, 2.5);
    let hit = bvh.closest_point(p).unwrap();
    assert!(hit.point.distance(DVec3::new(17.3, 101.6, 0.0)) < 1e-12);
    assert_eq!(hit.distance_squared, 6.25);
    let ray = bvh.ray_cast(p, -DVec3::Z, 100.0).unwrap();
    assert_eq!(ray.t, 2.5);
    assert!(bvh.ray_cast(p, -DVec3::Z, 2.0).is_none());
    assert!(bvh.closest_point_within(p, 2.4).is_none());
    assert!(bvh.closest_point_within(p, 2.5).is_some());
    // A ray exactly through a grid vertex still hits (closed triangles, padded boxes).
    assert!(
        bvh.ray_cast(DVec3::new(50.0, 50.0, 1.0), -DVec3::Z, 10.0)
            .is_some()
    );
}

#[test]
fn out_of_range_and_empty_inputs_do_not_crash() {
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    let bvh = TriangleBvh::build(&positions, &[[0, 1, 7], [0, 1, 2]]);
    assert_eq!(bvh.face_count(), 1);
    assert_eq!(bvh.closest_point(DVec3::Z).unwrap().face, 1);
    let empty = TriangleBvh::build(&positions, &[]);
    assert!(empty.closest_point(DVec3::Z).is_none());
    assert!(empty.ray_cast(DVec3::Z, -DVec3::Z, 1.0).is_none());
    empty.overlapping_pairs(|_, _| panic!("no pairs in an empty tree"));
}

/// On a tree deep enough to be split over many tasks, the parallel pair search finds the serial
/// one's pairs, each once, in an order that does not depend on the thread count.
#[test]
fn parallel_pairs_match_the_serial_ones_for_any_thread_count() {
    // Two icospheres 1 % apart (10,240 faces): each face overlaps its neighbours and the faces
    // across the gap.
    let (inner, shell) = roar_mesh::shapes::icosphere(4).to_triangles();
    let mut positions = inner.clone();
    positions.extend(inner.iter().map(|p| *p * 1.01));
    let offset = inner.len() as u32;
    let mut triangles = shell.clone();
    triangles.extend(shell.iter().map(|f| f.map(|i| i + offset)));
    let bvh = TriangleBvh::build(&positions, &triangles);
    let mut serial = Vec::new();
    bvh.overlapping_pairs(|i, j| serial.push((i, j)));
    serial.sort();
    assert!(serial.len() > 6 * triangles.len(), "{} pairs", serial.len());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| bvh.overlapping_pairs_parallel())
    };
    let one = run(1);
    assert_eq!(one, run(3));
    let mut sorted = one;
    sorted.sort();
    assert_eq!(sorted, serial);
}
