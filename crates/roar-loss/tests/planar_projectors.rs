//! The k-NN planar projector against brute force, both projectors against the analytic sphere,
//! and the t2s term reaching a target feature no s2t sample sees.

use glam::DVec3;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_loss::knn_projector::planar_move;
use roar_loss::planar::t2s_moves;
use roar_loss::{KnnOptions, KnnPlanarProjector, Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::{
    Projector, RayCastProjector, RayProjectorOptions, SphereProjector, sample_surface,
};

fn unit(v: [f64; 3]) -> DVec3 {
    let v = DVec3::from_array(v);
    if v.length() < 1e-3 {
        DVec3::Z
    } else {
        v.normalize()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn knn_matches_brute_force(
        cloud in prop::collection::vec(([-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64],
                                        [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64]), 1..80),
        query in [-1.2..1.2f64, -1.2..1.2f64, -1.2..1.2f64],
        normal in [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64],
    ) {
        let points: Vec<DVec3> = cloud.iter().map(|c| DVec3::from_array(c.0)).collect();
        let normals: Vec<DVec3> = cloud.iter().map(|c| unit(c.1)).collect();
        let options = KnnOptions::default();
        let proj = KnnPlanarProjector::new(&points, &normals, &options).unwrap();
        let q = DVec3::from_array(query);
        let mut brute: Vec<(u32, f64)> = points
            .iter()
            .enumerate()
            .map(|(j, p)| (j as u32, p.distance_squared(q)))
            .collect();
        brute.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        // The next distance after the k-th, to recognize near-ties at the cut.
        let beyond = brute.get(options.k).map(|b| b.1);
        brute.truncate(options.k);
        let found = proj.nearest(q, options.k);
        // Exact f64 distances, nearest first, within f32 search precision of the true k-NN.
        prop_assert_eq!(found.len(), brute.len());
        for (f, b) in found.iter().zip(&brute) {
            prop_assert_eq!(f.1, points[f.0 as usize].distance_squared(q));
            prop_assert!((f.1 - b.1).abs() <= 1e-6 * (1.0 + b.1), "{:?} vs {:?}", f, b);
        }
        // The set is the exact one unless the k-th and (k+1)-th distances tie in f32.
        let near_tie = match (beyond, brute.last()) {
            (Some(next), Some(last)) => next - last.1 <= 1e-6 * (1.0 + next),
            _ => false,
        };
        prop_assert!(found == brute || near_tie, "{:?} vs {:?}", found, brute);

        let n = unit(normal);
        let expected = planar_move(
            q,
            n,
            found.iter().map(|&(j, d2)| (points[j as usize], normals[j as usize], d2)),
            &options,
        );
        match (proj.displacement(q, n), expected) {
            (Some(a), Some(b)) => prop_assert!((a - b).length() <= 1e-9 * (1.0 + b.length())),
            (a, b) => prop_assert_eq!(a, b),
        }
    }
}

/// Samples of an icosphere of radius `radius` (the source surface) with normals tilted up to
/// ~0.2 rad from the face normal.
fn source_samples(
    radius: f64,
    n: usize,
    seed: u64,
) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>, Vec<DVec3>) {
    let (sp, st) = icosphere(4).to_triangles();
    let sp: Vec<DVec3> = sp.iter().map(|p| *p * radius).collect();
    let samples = sample_surface(&sp, &st, n, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normals = samples
        .normals
        .iter()
        .map(|&m| {
            let jitter =
                DVec3::new(rng.random(), rng.random(), rng.random()) * 0.4 - DVec3::splat(0.2);
            (m + jitter - m * jitter.dot(m)).normalize()
        })
        .collect();
    (sp, st, samples.points, normals)
}

#[test]
fn projectors_agree_with_the_analytic_sphere_near_its_surface() {
    let sphere = SphereProjector {
        center: DVec3::ZERO,
        radius: 0.5,
    };
    let (tp, tt) = icosphere(6).to_triangles();
    let tp: Vec<DVec3> = tp.iter().map(|p| *p * 0.5).collect();
    let cloud = sample_surface(&tp, &tt, 100_000, 3);
    // Exact normals for the cloud: the sphere's radial direction.
    let cloud_normals: Vec<DVec3> = cloud.points.iter().map(|p| p.normalize()).collect();
    let knn =
        KnnPlanarProjector::new(&cloud.points, &cloud_normals, &KnnOptions::default()).unwrap();
    let ray = RayCastProjector::new(&tp, &tt, &RayProjectorOptions::default());
    // Sources just inside and just outside the target; queries are samples of the source.
    for (radius, seed) in [(0.485, 4), (0.515, 5)] {
        let (sp, st, points, normals) = source_samples(radius, 1000, seed);
        let reference = sphere.project(&sp, &st, &points, &normals);
        for (name, result) in [
            ("knn", knn.project(&sp, &st, &points, &normals)),
            ("ray", ray.project(&sp, &st, &points, &normals)),
        ] {
            let mut errors = Vec::new();
            for (r, q) in reference.iter().zip(&result) {
                if let (Some(r), Some(q)) = (r, q) {
                    errors.push((*r - *q).length());
                }
            }
            assert!(
                errors.len() > 990,
                "{name} r={radius}: only {} valid",
                errors.len()
            );
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            let max = errors.iter().cloned().fold(0.0, f64::max);
            assert!(
                mean < 2e-4 && max < 2e-3,
                "{name} r={radius}: mean {mean}, max {max}"
            );
            eprintln!(
                "{name} r={radius}: mean {mean:.2e}, max {max:.2e}, valid {}",
                errors.len()
            );
        }
    }
}

#[test]
fn t2s_reaches_a_thin_feature_that_s2t_misses() {
    let (sp, st) = icosphere(3).to_triangles();
    let sp: Vec<DVec3> = sp.iter().map(|p| *p * 0.5).collect();
    // Target: the same sphere plus a small flat cap 0.15 above the +z pole (the tip of a spike).
    let sphere = sample_surface(&sp, &st, 50_000, 5);
    let mut points = sphere.points.clone();
    let mut normals = sphere.normals.clone();
    for i in -2..=2 {
        for j in -2..=2 {
            points.push(DVec3::new(i as f64 * 0.002, j as f64 * 0.002, 0.65));
            normals.push(DVec3::Z);
        }
    }
    let base = PlanarOptions {
        max_samples: 20_000,
        ..PlanarOptions::raw()
    };
    let mut with = PlanarLoss::new(&points, &normals, &base).unwrap();
    let mut without =
        PlanarLoss::new(&points, &normals, &PlanarOptions { t2s: false, ..base }).unwrap();
    let (lw, gw) = with.value_and_grad(&sp, &st).unwrap();
    let (lo, _) = without.value_and_grad(&sp, &st).unwrap();
    assert!(with.last_stats.from_t2s > 0);
    assert!(with.last_stats.max_move > 0.1, "{:?}", with.last_stats);
    assert!(
        without.last_stats.max_move < 0.01,
        "{:?}",
        without.last_stats
    );
    assert!(lw > 10.0 * lo, "with t2s {lw}, without {lo}");
    // The pull acts at the pole: the top vertex's negative gradient points up (+z).
    let top = sp
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.z.total_cmp(&b.1.z))
        .unwrap()
        .0;
    assert!(-gw[top].z > 0.0);

    // Direct check of the term on two samples: the one under the cap gets the cap's height.
    let samples = [DVec3::new(0.0, 0.0, 0.5), DVec3::new(0.5, 0.0, 0.0)];
    let sample_normals = [DVec3::Z, DVec3::X];
    let moves = t2s_moves(
        &samples,
        &sample_normals,
        &points[points.len() - 25..],
        &normals[normals.len() - 25..],
        0.95,
    );
    assert!((moves[0].unwrap() - DVec3::Z * 0.15).length() < 1e-12);
    assert_eq!(moves[1], None);
}
