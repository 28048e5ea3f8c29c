//! Shared helpers of the `blocks_*` integration tests: random closed meshes, planted folds,
//! tagged optimizer rows and a few target projectors.
#![allow(dead_code)]

use roar_mesh::shapes::{genus_n_solid, icosphere, perturbed, torus};
use roar_mesh::{DVec3, Mesh, VertexId};
use roar_ops::optim::{Optimizer, OptimizerOptions, VertexState};
use std::collections::HashMap;

/// One of the procedural closed meshes, chosen by `kind % 4`, with uniform vertex jitter of
/// `jitter` (relative to an edge length of roughly 0.2–0.5, so 0.1+ creates folds).
pub fn random_mesh(kind: u8, jitter: f64, seed: u64) -> Mesh {
    let base = match kind % 4 {
        0 => icosphere(2),
        1 => torus(14, 8, 1.0, 0.4),
        2 => genus_n_solid(1),
        _ => icosphere(1),
    };
    perturbed(&base, jitter, seed)
}

/// An optimizer whose rows are tagged by vertex position (m1 = position, m2 = |p|², ν = x), so
/// a row can be traced to the vertex it belongs to after compaction.
pub fn tagged_optimizer(mesh: &Mesh) -> Optimizer {
    let mut opt = Optimizer::new(mesh.vertex_capacity(), OptimizerOptions::default()).unwrap();
    for v in mesh.vertices() {
        opt.state_mut()[v.index()] = tag(mesh.position(v));
    }
    opt
}

/// The row [`tagged_optimizer`] gives a vertex at `p`.
pub fn tag(p: DVec3) -> VertexState {
    VertexState {
        m1: p,
        m2: p.length_squared(),
        nu: p.x,
    }
}

/// Exact-position lookup key.
pub fn key(p: DVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// Rows of the original vertices by exact position.
pub fn rows_by_position(mesh: &Mesh, opt: &Optimizer) -> HashMap<[u64; 3], VertexState> {
    mesh.vertices()
        .map(|v| (key(mesh.position(v)), opt.state()[v.index()]))
        .collect()
}

/// Slides vertex `v` along the surface through the far side of its 1-ring (to
/// `c + 1.6 (u − c)`, c = ring centroid, u = its first neighbour), so the faces on the side
/// it passes through turn over.
pub fn plant_fold(mesh: &mut Mesh, v: VertexId) {
    let ring: Vec<DVec3> = mesh.neighbors(v).map(|u| mesh.position(u)).collect();
    let c = ring.iter().copied().sum::<DVec3>() / ring.len() as f64;
    mesh.set_position(v, c + 1.6 * (ring[0] - c));
}

/// Mean |valence − 6| over live vertices.
pub fn valence_irregularity(mesh: &Mesh) -> f64 {
    let (sum, n) = mesh.vertices().fold((0.0, 0.0), |(s, n), v| {
        (s + (mesh.valence(v) as f64 - 6.0).abs(), n + 1.0)
    });
    sum / n
}

/// Asserts the block contract: valid mesh, no tombstones, optimizer rows in step.
pub fn assert_contract(mesh: &Mesh, opt: &Optimizer, euler: i64, what: &str) {
    if let Err(e) = mesh.validate() {
        panic!("{what}: mesh invalid: {e}");
    }
    assert_eq!(
        mesh.euler_characteristic(),
        euler,
        "{what}: Euler characteristic changed"
    );
    assert_eq!(
        mesh.vertex_capacity(),
        mesh.n_vertices(),
        "{what}: tombstones left"
    );
    assert_eq!(
        opt.len(),
        mesh.vertex_capacity(),
        "{what}: optimizer out of step"
    );
}

/// The worst aspect ratio `Q = R/(2r)` of `mesh`'s faces (1 for a mesh without faces).
pub fn worst_quality(mesh: &Mesh) -> f64 {
    mesh.faces()
        .map(|f| {
            roar_mesh::spatial::triangle_quality(mesh.face_vertices(f).map(|v| mesh.position(v)))
        })
        .fold(1.0, f64::max)
}
