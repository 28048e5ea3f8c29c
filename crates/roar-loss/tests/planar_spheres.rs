//! The planar loss on spheres: zero on the target's own mesh, `(R − r)²` between concentric
//! spheres with a gradient pulling every vertex outward.

use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_loss::{Loss, PlanarLoss, PlanarOptions};
use roar_mesh::shapes::icosphere;
use roar_mesh::spatial::sample_surface;

/// `n` points uniformly on the sphere of radius `radius`, with exact outward normals.
fn sphere_cloud(radius: f64, n: usize, seed: u64) -> (Vec<DVec3>, Vec<DVec3>) {
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normals = Vec::with_capacity(n);
    while normals.len() < n {
        let v = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - DVec3::ONE;
        let l = v.length();
        if l > 1e-3 && l <= 1.0 {
            normals.push(v / l);
        }
    }
    (normals.iter().map(|n| *n * radius).collect(), normals)
}

fn source(radius: f64, level: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (p, t) = icosphere(level).to_triangles();
    (p.iter().map(|p| *p * radius).collect(), t)
}

fn options() -> PlanarOptions {
    PlanarOptions {
        max_samples: 30_000,
        ..PlanarOptions::raw()
    }
}

#[test]
fn concentric_spheres_give_squared_gap_and_outward_gradient() {
    let (r, big_r) = (0.5, 0.55);
    let (positions, triangles) = source(r, 4);
    let (points, normals) = sphere_cloud(big_r, 200_000, 1);
    let mut loss = PlanarLoss::new(&points, &normals, &options()).unwrap();
    let (value, grad) = loss.value_and_grad(&positions, &triangles).unwrap();
    let expected = (big_r - r) * (big_r - r);
    assert!(
        (value - expected).abs() < 0.1 * expected,
        "loss {value} vs (R − r)² = {expected}"
    );
    assert_eq!(loss.last_stats.unprojected, 0);
    for (v, g) in grad.iter().enumerate() {
        let radial = positions[v].normalize();
        assert!(
            -g.dot(radial) > 0.95 * g.length() && g.length() > 0.0,
            "vertex {v}: gradient {g} not radially inward"
        );
    }
}

#[test]
fn own_clean_mesh_gives_near_zero_loss_and_gradient() {
    let (positions, triangles) = source(0.5, 4);
    let samples = sample_surface(&positions, &triangles, 200_000, 2);
    let mut own = PlanarLoss::new(&samples.points, &samples.normals, &options()).unwrap();
    let (value, grad) = own.value_and_grad(&positions, &triangles).unwrap();

    let (points, normals) = sphere_cloud(0.55, 200_000, 1);
    let mut apart = PlanarLoss::new(&points, &normals, &options()).unwrap();
    let (apart_value, apart_grad) = apart.value_and_grad(&positions, &triangles).unwrap();

    let max = |g: &[DVec3]| g.iter().map(|g| g.length()).fold(0.0, f64::max);
    assert!(
        value < 1e-4 * apart_value,
        "own-mesh loss {value} vs concentric {apart_value}"
    );
    assert!(
        max(&grad) < 0.02 * max(&apart_grad),
        "own-mesh gradient {} vs concentric {}",
        max(&grad),
        max(&apart_grad)
    );
}
