//! Behaviour of the generalized winding number: exact oracle and the fast (Barill) version.

use glam::DVec3;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{WindingNumber, WindingNumberOptions, exact_winding_number};

/// Axis-aligned cube [0,1]³, 12 outward-oriented triangles.
fn cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let positions = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3], // z = 0, normal −z
        [4, 5, 6],
        [5, 7, 6], // z = 1, normal +z
        [0, 1, 4],
        [1, 5, 4], // y = 0, normal −y
        [2, 6, 3],
        [3, 6, 7], // y = 1, normal +y
        [0, 4, 2],
        [2, 4, 6], // x = 0, normal −x
        [1, 3, 5],
        [3, 7, 5], // x = 1, normal +x
    ];
    (positions, triangles)
}

fn reversed(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
}

fn random_points(rng: &mut ChaCha8Rng, count: usize, half_extent: f64) -> Vec<DVec3> {
    (0..count)
        .map(|_| {
            DVec3::new(
                rng.random_range(-half_extent..half_extent),
                rng.random_range(-half_extent..half_extent),
                rng.random_range(-half_extent..half_extent),
            )
        })
        .collect()
}

#[test]
fn closed_sphere_is_one_inside_and_zero_outside() {
    let (p, t) = icosphere(3).to_triangles();
    let wn = WindingNumber::build(&p, &t).unwrap();
    for q in [
        DVec3::ZERO,
        DVec3::new(0.5, -0.3, 0.2),
        DVec3::new(0.0, 0.0, 0.95),
    ] {
        assert!((wn.winding_number(q) - 1.0).abs() < 1e-2, "inside {q}");
        assert!((exact_winding_number(&p, &t, q) - 1.0).abs() < 1e-9);
    }
    for q in [
        DVec3::new(1.05, 0.0, 0.0),
        DVec3::new(3.0, 2.0, -1.0),
        DVec3::splat(100.0),
    ] {
        assert!(wn.winding_number(q).abs() < 1e-2, "outside {q}");
        assert!(exact_winding_number(&p, &t, q).abs() < 1e-9);
    }
}

#[test]
fn closed_cube_is_one_inside_and_zero_outside() {
    let (p, t) = cube();
    let wn = WindingNumber::build(&p, &t).unwrap();
    assert!((wn.winding_number(DVec3::splat(0.5)) - 1.0).abs() < 1e-9);
    assert!((wn.winding_number(DVec3::new(0.01, 0.99, 0.5)) - 1.0).abs() < 1e-9);
    assert!(wn.winding_number(DVec3::new(1.01, 0.5, 0.5)).abs() < 1e-9);
    assert!(wn.winding_number(DVec3::new(-2.0, 3.0, 0.5)).abs() < 1e-9);
}

#[test]
fn reversed_orientation_gives_minus_one_inside() {
    let (p, t) = icosphere(2).to_triangles();
    let t = reversed(&t);
    let wn = WindingNumber::build(&p, &t).unwrap();
    assert!((wn.winding_number(DVec3::new(0.1, 0.2, 0.3)) + 1.0).abs() < 1e-2);
    assert!((exact_winding_number(&p, &t, DVec3::ZERO) + 1.0).abs() < 1e-9);
    assert!(wn.winding_number(DVec3::new(2.0, 0.0, 0.0)).abs() < 1e-2);
}

#[test]
fn open_hemisphere_gives_fractional_values() {
    let (p, t) = icosphere(3).to_triangles();
    // Keep the upper half: faces whose centroid has z > 0.
    let upper: Vec<[u32; 3]> = t
        .iter()
        .copied()
        .filter(|f| f.iter().map(|&v| p[v as usize].z).sum::<f64>() > 0.0)
        .collect();
    let wn = WindingNumber::build(&p, &upper).unwrap();
    // At the centre, the open hemisphere covers half of the sphere of directions.
    let centre = wn.winding_number(DVec3::ZERO);
    assert!((centre - 0.5).abs() < 0.05, "{centre}");
    let below = wn.winding_number(DVec3::new(0.0, 0.0, -0.5));
    assert!(below > 0.05 && below < 0.5, "{below}");
    assert!((below - exact_winding_number(&p, &upper, DVec3::new(0.0, 0.0, -0.5))).abs() < 1e-2);
}

#[test]
fn doubled_sheet_is_zero_everywhere() {
    // A 10×10 grid sheet in z = 0, each triangle present with both orientations.
    let mut p = Vec::new();
    for j in 0..=10 {
        for i in 0..=10 {
            p.push(DVec3::new(i as f64 / 10.0, j as f64 / 10.0, 0.0));
        }
    }
    let mut t = Vec::new();
    for j in 0..10u32 {
        for i in 0..10u32 {
            let v = j * 11 + i;
            t.push([v, v + 1, v + 12]);
            t.push([v, v + 12, v + 11]);
        }
    }
    let mut doubled = t.clone();
    doubled.extend(reversed(&t));
    let wn = WindingNumber::build(&p, &doubled).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let one_sided = WindingNumber::build(&p, &t).unwrap();
    let probe = DVec3::new(0.5, 0.5, 0.1);
    assert!(
        one_sided.winding_number(probe).abs() > 0.2,
        "one side alone is not zero"
    );
    // Twins may land in different nodes, so far-field errors need not cancel exactly.
    let mut max_abs: f64 = 0.0;
    for q in random_points(&mut rng, 200, 1.5) {
        max_abs = max_abs.max(wn.winding_number(q).abs());
        assert!(exact_winding_number(&p, &doubled, q).abs() < 1e-9, "{q}");
    }
    assert!(max_abs < 1e-2, "max |w| {max_abs}");
}

#[test]
fn batch_query_matches_single_queries_bit_for_bit() {
    let (p, t) = icosphere(3).to_triangles();
    let wn = WindingNumber::build(&p, &t).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let points = random_points(&mut rng, 5000, 1.5);
    let batch = wn.winding_numbers(&points);
    assert_eq!(batch.len(), points.len());
    for (q, w) in points.iter().zip(&batch) {
        assert_eq!(w.to_bits(), wn.winding_number(*q).to_bits());
    }
    assert_eq!(batch, wn.winding_numbers(&points));
}

#[test]
fn fast_matches_exact_on_subdivided_sphere_including_near_surface() {
    let (p, t) = icosphere(4).to_triangles();
    let wn = WindingNumber::build(&p, &t).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut points = random_points(&mut rng, 300, 2.0);
    // Points close to the surface, on both sides.
    for _ in 0..300 {
        let dir = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize_or(DVec3::X);
        points.push(dir * rng.random_range(0.97..1.03));
    }
    let mut max_error: f64 = 0.0;
    for q in points {
        max_error = max_error.max((wn.winding_number(q) - exact_winding_number(&p, &t, q)).abs());
    }
    assert!(max_error < 1e-2, "max error {max_error}");
}

#[test]
fn larger_beta_is_at_least_as_accurate_on_average() {
    let (p, t) = icosphere(3).to_triangles();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let points = random_points(&mut rng, 400, 1.5);
    let exact: Vec<f64> = points
        .iter()
        .map(|&q| exact_winding_number(&p, &t, q))
        .collect();
    let mean_error = |beta: f64| {
        let wn = WindingNumber::build_with(
            &p,
            &t,
            &WindingNumberOptions {
                beta,
                ..Default::default()
            },
        )
        .unwrap();
        let fast = wn.winding_numbers(&points);
        fast.iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .sum::<f64>()
            / points.len() as f64
    };
    let coarse = mean_error(1.2);
    let fine = mean_error(4.0);
    assert!(fine <= coarse, "beta 4: {fine}, beta 1.2: {coarse}");
    assert!(fine < 1e-4, "{fine}");
}

#[test]
fn out_of_range_triangle_is_refused() {
    let (p, _) = cube();
    assert!(WindingNumber::build(&p, &[[0, 1, 8]]).is_err());
    // The exact oracle skips it instead of panicking.
    assert_eq!(exact_winding_number(&p, &[[0, 1, 8]], DVec3::ZERO), 0.0);
}

fn soup_strategy() -> impl Strategy<Value = (Vec<DVec3>, Vec<[u32; 3]>)> {
    prop::collection::vec(
        prop::array::uniform3(prop::array::uniform3(-1.0f64..1.0)),
        1..300,
    )
    .prop_map(|tris| {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for tri in tris {
            let base = positions.len() as u32;
            positions.extend(tri.iter().map(|c| DVec3::from_array(*c)));
            triangles.push([base, base + 1, base + 2]);
        }
        (positions, triangles)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn fast_matches_exact_on_random_soups(
        (positions, triangles) in soup_strategy(),
        seed in any::<u64>(),
    ) {
        let wn = WindingNumber::build_with(
            &positions,
            &triangles,
            &WindingNumberOptions { beta: 2.0, leaf_size: 4 },
        )
        .unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for q in random_points(&mut rng, 50, 2.0) {
            let fast = wn.winding_number(q);
            let exact = exact_winding_number(&positions, &triangles, q);
            prop_assert!((fast - exact).abs() < 1e-2, "q {} fast {} exact {}", q, fast, exact);
        }
    }
}
