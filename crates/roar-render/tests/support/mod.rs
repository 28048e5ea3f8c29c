//! Test meshes and random numbers for the renderer's tests.
#![allow(dead_code)]

use glam::DVec3;

/// Deterministic pseudo-random numbers in [−1, 1) (SplitMix64), enough for test perturbations.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    pub fn vec3(&mut self) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next())
    }
}

/// `roar_mesh::shapes::icosphere(subdivisions)` scaled to radius `radius`, with every vertex pushed radially by up to `±amount`.
pub fn bumpy_sphere(
    subdivisions: u32,
    radius: f64,
    amount: f64,
    seed: u64,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (v, f) = roar_mesh::shapes::icosphere(subdivisions).to_triangles();
    let mut rng = Rng(seed);
    let v = v
        .into_iter()
        .map(|p| p * (radius + amount * rng.next()))
        .collect();
    (v, f)
}
