//! The planar loss gradient with the projected points held fixed (the stop-gradient targets)
//! against central finite differences, and the assembled loss against its closed form.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_loss::planar::planar_loss_fixed_targets;
use roar_loss::{Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::{icosphere, perturbed};

#[test]
fn fixed_target_gradient_matches_finite_difference() {
    let (positions, triangles) = perturbed(&icosphere(1), 0.05, 3).to_triangles();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let count = 200;
    let faces: Vec<u32> = (0..count)
        .map(|_| rng.random_range(0..triangles.len() as u32))
        .collect();
    let barycentrics: Vec<[f64; 3]> = (0..count)
        .map(|_| {
            let (a, b): (f64, f64) = (rng.random(), rng.random());
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            [1.0 - a - b, a, b]
        })
        .collect();
    let targets: Vec<Option<DVec3>> = (0..count)
        .map(|_| {
            (rng.random::<f64>() < 0.8)
                .then(|| DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE)
        })
        .collect();
    let (_, grad) =
        planar_loss_fixed_targets(&positions, &triangles, &faces, &barycentrics, &targets);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for v in 0..positions.len() {
        for axis in 0..3 {
            let mut plus = positions.clone();
            let mut minus = positions.clone();
            plus[v][axis] += h;
            minus[v][axis] -= h;
            let lp =
                planar_loss_fixed_targets(&plus, &triangles, &faces, &barycentrics, &targets).0;
            let lm =
                planar_loss_fixed_targets(&minus, &triangles, &faces, &barycentrics, &targets).0;
            let fd = (lp - lm) / (2.0 * h);
            worst = worst.max((fd - grad[v][axis]).abs());
        }
    }
    let scale = grad.iter().map(|g| g.length()).fold(0.0, f64::max);
    assert!(scale > 1e-3, "gradient should not vanish: {scale}");
    assert!(worst < 1e-7 * scale.max(1.0), "worst FD error {worst}");
}

#[test]
fn none_targets_count_in_the_mean_but_add_nothing() {
    let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    let triangles = [[0, 1, 2]];
    let faces = [0, 0];
    let bary = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let targets = [Some(DVec3::new(0.0, 0.0, 0.5)), None];
    let (loss, grad) = planar_loss_fixed_targets(&positions, &triangles, &faces, &bary, &targets);
    assert!((loss - 0.125).abs() < 1e-15);
    assert!((grad[0] - DVec3::new(0.0, 0.0, -0.5)).length() < 1e-15);
    assert_eq!(grad[1], DVec3::ZERO);
}

#[test]
fn loss_is_deterministic_for_a_seed_and_scale_multiplies_it() {
    let (positions, triangles) = icosphere(2).to_triangles();
    let positions: Vec<DVec3> = positions.iter().map(|p| *p * 0.5).collect();
    let (target, _) = icosphere(4).to_triangles();
    let points: Vec<DVec3> = target.iter().map(|p| *p * 0.55).collect();
    let normals: Vec<DVec3> = target.clone();
    let options = PlanarOptions {
        max_samples: 3000,
        ..PlanarOptions::raw()
    };
    let mut a = PlanarLoss::new(&points, &normals, &options).unwrap();
    let mut b = PlanarLoss::new(&points, &normals, &options).unwrap();
    let mut c = PlanarLoss::new(
        &points,
        &normals,
        &PlanarOptions {
            scale: 4.0,
            ..options
        },
    )
    .unwrap();
    for _ in 0..2 {
        let (la, ga) = a.value_and_grad(&positions, &triangles).unwrap();
        let (lb, gb) = b.value_and_grad(&positions, &triangles).unwrap();
        let (lc, gc) = c.value_and_grad(&positions, &triangles).unwrap();
        assert_eq!(la.to_bits(), lb.to_bits());
        assert_eq!(ga, gb);
        assert!((lc - 4.0 * la).abs() <= 1e-12 * lc);
        for (x, y) in ga.iter().zip(&gc) {
            assert!((*y - 4.0 * *x).length() <= 1e-12 * y.length().max(1e-300));
        }
    }
    assert!(a.last_stats.samples_used <= 3000 + 2 * triangles.len());
    assert!(a.last_stats.samples_generated > a.last_stats.samples_used);
}
