//! Face Split block against an analytic sphere target: scores, splits under budget, constant
//! face count at budget, decrease over budget.

mod blocks_common;

use blocks_common::{assert_contract, tagged_optimizer};
use rand::SeedableRng;
use roar_mesh::DVec3;
use roar_mesh::shapes::{genus_n_solid, icosphere};
use roar_mesh::spatial::{SphereProjector, regular_samples};
use roar_ops::geometry::Geometry;
use roar_ops::qslim::{QSlimOptions, VertexPlane};
use roar_ops::split_block::{FaceSplitOptions, SplitThreshold, face_scores, face_split};

const UNIT_SPHERE: SphereProjector = SphereProjector {
    center: DVec3::ZERO,
    radius: 1.0,
};

fn per_face() -> FaceSplitOptions {
    FaceSplitOptions {
        threshold: SplitThreshold::PerFace(0.02),
        ..FaceSplitOptions::default()
    }
}

fn scores(mesh: &roar_mesh::Mesh, options: &FaceSplitOptions) -> Vec<f64> {
    let g = Geometry::compute(mesh);
    let tris: Vec<[u32; 3]> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let s = regular_samples(
        mesh.positions(),
        &tris,
        Some(&g.vertex_normals),
        &options.sampling,
        &mut rng,
    )
    .unwrap();
    let q = roar_mesh::spatial::Projector::project(
        &UNIT_SPHERE,
        mesh.positions(),
        &tris,
        &s.points,
        &s.normals,
    );
    face_scores(mesh, &g, &s, &q, options)
}

#[test]
fn coarse_icosphere_faces_score_on_a_sphere() {
    let mesh = icosphere(1);
    let s = scores(&mesh, &per_face());
    assert!(
        s.iter().all(|&x| x > 0.02),
        "every face lies over curved target: {s:?}"
    );
    // Default (0.02 per sub-triangle, note 1): a smooth unit sphere bends far less than 0.02
    // per sub-triangle at the sampling density, so nothing scores.
    let s = scores(&mesh, &FaceSplitOptions::default());
    assert!(s.iter().all(|&x| x == 0.0));
}

#[test]
fn a_flat_source_over_a_flat_target_scores_nothing() {
    // Identity projection: each face grid stays planar, so no face scores.
    let mesh = icosphere(1);
    let g = Geometry::compute(&mesh);
    let tris: Vec<[u32; 3]> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let opts = per_face();
    let s = regular_samples(
        mesh.positions(),
        &tris,
        Some(&g.vertex_normals),
        &opts.sampling,
        &mut rng,
    )
    .unwrap();
    // "Project" every sample onto itself: each face's grid is planar.
    let q: Vec<_> = s.points.iter().map(|&p| Some(p)).collect();
    let sc = face_scores(&mesh, &g, &s, &q, &opts);
    assert!(sc.iter().all(|&x| x == 0.0), "{sc:?}");
}

#[test]
fn splits_under_budget() {
    let mut mesh = icosphere(1);
    let euler = mesh.euler_characteristic();
    let mut opt = tagged_optimizer(&mesh);
    let f0 = mesh.n_faces();
    let stats = face_split(&mut mesh, &mut opt, &UNIT_SPHERE, f0 + 100, &per_face());
    assert_contract(&mesh, &opt, euler, "face_split");
    assert_eq!(stats.accepted, 50, "Δ = 50 splits: {stats:?}");
    assert_eq!(mesh.n_faces(), f0 + 100);
    // The new vertices (ids ≥ old count after compaction keeps order) carry the mean row of
    // their three parents, which the tags make equal to the tag of their (centroid) position.
    for v in mesh.vertices().skip(42) {
        let row = opt.state()[v.index()];
        assert!(
            (row.m1 - mesh.position(v)).length() < 1e-12,
            "row of {v:?} is not the mean"
        );
    }
}

#[test]
fn face_count_is_constant_at_budget() {
    let mut mesh = icosphere(2);
    let euler = mesh.euler_characteristic();
    let mut opt = tagged_optimizer(&mesh);
    let f0 = mesh.n_faces();
    for it in 0..3 {
        let options = FaceSplitOptions {
            seed: it,
            ..per_face()
        };
        face_split(&mut mesh, &mut opt, &UNIT_SPHERE, f0, &options);
        assert_contract(&mesh, &opt, euler, "face_split");
        assert!(
            mesh.n_faces().abs_diff(f0) <= 2,
            "{} faces vs budget {f0}",
            mesh.n_faces()
        );
    }
}

#[test]
fn face_count_decreases_over_budget() {
    // A slab with through-holes: its flat ends (|x| > 1) miss the unit sphere target and are
    // redundant, its middle lies over curved target.
    let mut mesh = genus_n_solid(2);
    let euler = mesh.euler_characteristic();
    let mut opt = tagged_optimizer(&mesh);
    let f0 = mesh.n_faces();
    let options = FaceSplitOptions {
        qslim: QSlimOptions {
            vertex_plane: VertexPlane::NormalizedMagnitude,
            ..QSlimOptions::default()
        },
        ..per_face()
    };
    let stats = face_split(&mut mesh, &mut opt, &UNIT_SPHERE, f0 - 40, &options);
    assert_contract(&mesh, &opt, euler, "face_split");
    assert!(mesh.n_faces() < f0, "{stats:?}");
}
