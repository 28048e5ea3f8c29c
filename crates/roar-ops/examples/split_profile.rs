//! Profiling driver for the Face Split block (spec §3.8): one or more `face_split` calls on the
//! ~10k-face UV sphere of the `blocks` bench against the analytic sphere projector, with a
//! coarse per-phase wall-clock breakdown. Meant for `valgrind --tool=callgrind` (repeatable
//! instruction counts on a noisy machine):
//!
//! ```text
//! cargo build --release -p roar-ops --example split_profile
//! RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/split_profile 1
//! ```
//!
//! Arguments: number of repetitions (default 5), then the mode: `all` (default: phase
//! breakdown and the block), `block` (only `face_split`) or `setup` (only the mesh set-up, to
//! subtract from the `block` count).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::perturbed;
use roar_mesh::spatial::{Projector, SphereProjector, regular_samples};
use roar_mesh::{DVec3, Mesh};
use roar_ops::geometry::Geometry;
use roar_ops::optim::{Optimizer, OptimizerOptions};
use roar_ops::split_block::{FaceSplitOptions, SplitThreshold, face_scores, face_split};
use std::time::Instant;

/// Latitude–longitude unit sphere: `2·lon·(lat − 1)` faces (50 × 100 → 9800).
fn uv_sphere(lat: usize, lon: usize) -> Mesh {
    let mut positions = vec![DVec3::Z];
    for i in 1..lat {
        let theta = std::f64::consts::PI * i as f64 / lat as f64;
        for j in 0..lon {
            let phi = std::f64::consts::TAU * j as f64 / lon as f64;
            positions.push(DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
        }
    }
    positions.push(-DVec3::Z);
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
    let mut tris = Vec::new();
    for j in 0..lon {
        tris.push([0, ring(1, j), ring(1, j + 1)]);
        tris.push([south, ring(lat - 1, j + 1), ring(lat - 1, j)]);
    }
    for i in 1..lat - 1 {
        for j in 0..lon {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i + 1, j),
                ring(i + 1, j + 1),
                ring(i, j + 1),
            );
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    Mesh::from_triangles(positions, &tris).expect("uv sphere is a closed manifold")
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let mode = std::env::args().nth(2).unwrap_or_else(|| "all".to_string());
    let mesh = perturbed(&uv_sphere(50, 100), 0.002, 2);
    let sphere = SphereProjector {
        center: DVec3::ZERO,
        radius: 1.0,
    };
    let options = FaceSplitOptions {
        threshold: SplitThreshold::PerFace(0.02),
        ..FaceSplitOptions::default()
    };
    let f = mesh.n_faces();
    for _ in 0..reps {
        if mode == "setup" {
            continue;
        }
        if mode == "block" {
            let mut m = mesh.clone();
            let mut o = Optimizer::new(m.vertex_capacity(), OptimizerOptions::default())
                .expect("optimizer");
            let t = Instant::now();
            let stats = face_split(&mut m, &mut o, &sphere, f + 2000, &options);
            println!("face_split {:.1} ms, accepted {}", ms(t), stats.accepted);
            continue;
        }
        // Phase breakdown (the block recomputes these itself).
        let t = Instant::now();
        let g = Geometry::compute(&mesh);
        let tris: Vec<[u32; 3]> = mesh
            .faces()
            .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
            .collect();
        let t_geom = ms(t);
        let t = Instant::now();
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let s = regular_samples(
            mesh.positions(),
            &tris,
            Some(&g.vertex_normals),
            &options.sampling,
            &mut rng,
        )
        .expect("valid mesh");
        let t_samples = ms(t);
        let t = Instant::now();
        let q = sphere.project(mesh.positions(), &tris, &s.points, &s.normals);
        let t_project = ms(t);
        let t = Instant::now();
        let sc = face_scores(&mesh, &g, &s, &q, &options);
        let t_scores = ms(t);

        let mut m = mesh.clone();
        let mut o =
            Optimizer::new(m.vertex_capacity(), OptimizerOptions::default()).expect("optimizer");
        let t = Instant::now();
        let stats = face_split(&mut m, &mut o, &sphere, f + 2000, &options);
        let t_block = ms(t);
        println!(
            "samples {} ({:.1} ms) geometry {t_geom:.1} ms, project {t_project:.1} ms, \
             scores {t_scores:.1} ms (sum {:.3}), face_split {t_block:.1} ms, accepted {}",
            s.points.len(),
            t_samples,
            sc.iter().sum::<f64>(),
            stats.accepted
        );
    }
}
