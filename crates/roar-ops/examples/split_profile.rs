//! Profiling driver for the Face Split block: one or more `face_split` calls on the
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
//! breakdown and the block), `block` (only `face_split`), `setup` (only the mesh set-up, to
//! subtract from the `block` count) or `digest` (one line per scenario: a hash of the output
//! mesh, its positions' bits and the optimizer rows, plus the stats; compare two builds' lines
//! to check that a change keeps the block's results bit-identical).

mod common;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::{genus_n_solid, icosphere, perturbed};
use roar_mesh::spatial::{Projector, SphereProjector, regular_samples};
use roar_mesh::{DVec3, Mesh, TrackedMesh};
use roar_ops::blocks::qslim::{QSlimOptions, VertexPlane};
use roar_ops::blocks::split::{FaceSplitOptions, SplitThreshold, face_scores, face_split};
use roar_ops::geometry::Geometry;
use roar_ops::optim::{Optimizer, OptimizerOptions};
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

/// FNV-1a over the mesh's triangles, its positions' bits and the optimizer rows' `m1`.
fn digest(mesh: &Mesh, optimizer: &Optimizer) -> u64 {
    let mut h = common::Fnv::new();
    let mut eat = |x: u64| h.eat(x);
    for f in mesh.faces() {
        for v in mesh.face_vertices(f) {
            eat(u64::from(v.raw()));
        }
    }
    for p in mesh.positions() {
        for c in p.to_array() {
            eat(c.to_bits());
        }
    }
    for row in optimizer.state() {
        for c in row.m1.to_array() {
            eat(c.to_bits());
        }
    }
    h.finish()
}

/// Runs `calls` Face Split calls per scenario (seed = call index) and prints a digest line each.
fn digests(calls: u64) {
    let sphere = SphereProjector {
        center: DVec3::ZERO,
        radius: 1.0,
    };
    let offset = SphereProjector {
        center: DVec3::new(0.05, -0.02, 0.03),
        radius: 1.02,
    };
    let per_face = FaceSplitOptions {
        threshold: SplitThreshold::PerFace(0.02),
        ..FaceSplitOptions::default()
    };
    let normalized = FaceSplitOptions {
        qslim: QSlimOptions {
            vertex_plane: VertexPlane::NormalizedMagnitude,
            ..QSlimOptions::default()
        },
        ..per_face
    };
    let bench = perturbed(&uv_sphere(50, 100), 0.002, 2);
    let rough = perturbed(&uv_sphere(50, 100), 0.02, 1);
    let coarse = icosphere(1);
    let slab = genus_n_solid(2);
    let f = |m: &Mesh| m.n_faces() as i64;
    let scenarios: Vec<(&str, &Mesh, &SphereProjector, i64, FaceSplitOptions)> = vec![
        ("bench_under", &bench, &sphere, 2000, per_face),
        ("bench_at", &bench, &sphere, 0, per_face),
        ("bench_over", &bench, &sphere, -400, per_face),
        (
            "bench_default_at",
            &bench,
            &sphere,
            0,
            FaceSplitOptions::default(),
        ),
        ("rough_under", &rough, &offset, 2000, per_face),
        ("rough_at", &rough, &offset, 0, per_face),
        (
            "rough_default_at",
            &rough,
            &offset,
            0,
            FaceSplitOptions::default(),
        ),
        ("coarse_under", &coarse, &offset, 60, per_face),
        ("coarse_at", &coarse, &offset, 0, per_face),
        ("coarse_over", &coarse, &sphere, -20, per_face),
        ("coarse_normalized_at", &coarse, &sphere, 0, normalized),
        ("slab_over", &slab, &sphere, -40, normalized),
        ("slab_at", &slab, &offset, 0, per_face),
    ];
    for (name, mesh, projector, slack, options) in scenarios {
        let mut m = mesh.clone();
        let mut o =
            Optimizer::new(m.vertex_capacity(), OptimizerOptions::default()).expect("optimizer");
        // Tag each row with its vertex position, so the digest sees which rows survive.
        for v in m.vertices() {
            o.state_mut()[v.index()].m1 = m.position(v);
        }
        let budget = (f(mesh) + slack) as usize;
        let mut line = String::new();
        for seed in 0..calls {
            let options = FaceSplitOptions { seed, ..options };
            let stats = face_split(
                &mut TrackedMesh::new(&mut m, &mut o),
                projector,
                budget,
                &options,
            );
            line += &format!(
                " [{} faces, {} splits, {} paired, {} free]",
                m.n_faces(),
                stats.accepted,
                stats.counters.get("paired_collapses").copied().unwrap_or(0),
                stats.counters.get("free_collapses").copied().unwrap_or(0),
            );
        }
        println!("{name}: {:016x}{line}", digest(&m, &o));
    }
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
    if mode == "digest" {
        digests(reps as u64);
        return;
    }
    for _ in 0..reps {
        if mode == "setup" {
            continue;
        }
        if mode == "block" {
            let mut m = mesh.clone();
            let mut o = Optimizer::new(m.vertex_capacity(), OptimizerOptions::default())
                .expect("optimizer");
            let t = Instant::now();
            let stats = face_split(
                &mut TrackedMesh::new(&mut m, &mut o),
                &sphere,
                f + 2000,
                &options,
            );
            println!(
                "face_split {:.1} ms, accepted {}, exact edge costs {}",
                ms(t),
                stats.accepted,
                stats.counters.get("edge_costs").copied().unwrap_or(0)
            );
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
        let stats = face_split(
            &mut TrackedMesh::new(&mut m, &mut o),
            &sphere,
            f + 2000,
            &options,
        );
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
