//! Face Split block against an analytic sphere target: scores, splits under budget, constant
//! face count at budget, decrease over budget.

mod blocks_common;

use blocks_common::{assert_contract, tagged_optimizer};
use rand::SeedableRng;
use roar_mesh::DVec3;
use roar_mesh::shapes::{genus_n_solid, icosphere};
use roar_mesh::spatial::{Projector, RegularSamples, SphereProjector, regular_samples};
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
    scores_against(mesh, &UNIT_SPHERE, options).0
}

/// Face scores of `mesh` against `projector`, with the samples and their projections.
fn scores_against(
    mesh: &roar_mesh::Mesh,
    projector: &dyn Projector,
    options: &FaceSplitOptions,
) -> (Vec<f64>, RegularSamples, Vec<Option<DVec3>>) {
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
    let q = projector.project(mesh.positions(), &tris, &s.points, &s.normals);
    (face_scores(mesh, &g, &s, &q, options), s, q)
}

/// Test-only target with sharp features: the boundary of the convex polyhedron
/// `{x : n_k·x ≤ 1}` circumscribing the unit sphere (unit outward normals `n_k`). A sample
/// inside it is projected forward along its normal to the first plane it crosses, so the
/// projected grid of a face bends exactly where the face straddles a polyhedron edge.
struct PolyhedronProjector {
    normals: Vec<DVec3>,
}

impl PolyhedronProjector {
    /// Index of the plane hit from `p` along `n`, and the hit point.
    fn hit(&self, p: DVec3, n: DVec3) -> Option<(usize, DVec3)> {
        let mut best: Option<(usize, f64)> = None;
        for (k, &nk) in self.normals.iter().enumerate() {
            let speed = nk.dot(n);
            if speed <= 1e-12 {
                continue;
            }
            let t = (1.0 - nk.dot(p)) / speed;
            if t >= 0.0 && best.is_none_or(|(_, bt)| t < bt) {
                best = Some((k, t));
            }
        }
        best.map(|(k, t)| (k, p + t * n))
    }
}

impl Projector for PolyhedronProjector {
    fn project(
        &self,
        _positions: &[DVec3],
        _triangles: &[[u32; 3]],
        points: &[DVec3],
        normals: &[DVec3],
    ) -> Vec<Option<DVec3>> {
        points
            .iter()
            .zip(normals)
            .map(|(&p, &n)| self.hit(p, n).map(|(_, q)| q))
            .collect()
    }
}

/// Per face of the icosphere source: how many of its projected samples lie off the plane of
/// `target` that holds most of them (0: the face lies over one plane; samples on a crease lie
/// on both planes).
fn samples_off_main_plane(
    target: &PolyhedronProjector,
    samples: &RegularSamples,
    n_faces: usize,
) -> Vec<usize> {
    (0..n_faces)
        .map(|f| {
            let hits: Vec<Option<DVec3>> = samples
                .face_samples(f)
                .map(|i| {
                    target
                        .hit(samples.points[i], samples.normals[i])
                        .map(|(_, q)| q)
                })
                .collect();
            (0..target.normals.len())
                .map(|k| {
                    hits.iter()
                        .filter(|q| {
                            !q.is_some_and(|q| (target.normals[k].dot(q) - 1.0).abs() < 1e-9)
                        })
                        .count()
                })
                .min()
                .unwrap_or(0)
        })
        .collect()
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

#[test]
fn default_threshold_scores_faces_over_cube_edges_and_not_flat_ones() {
    // Unit icosphere inside the cube [-1, 1]³: the projected grids are flat except where a
    // face straddles a cube edge (a 90° crease).
    let mesh = icosphere(2);
    let cube = PolyhedronProjector {
        normals: vec![
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ],
    };
    let (s, samples, _) = scores_against(&mesh, &cube, &FaceSplitOptions::default());
    let off = samples_off_main_plane(&cube, &samples, mesh.n_faces());
    let flat: Vec<bool> = off.iter().map(|&k| k == 0).collect();
    let (n_flat, n_crease) = (
        flat.iter().filter(|&&x| x).count(),
        flat.iter().filter(|&&x| !x).count(),
    );
    assert!(
        n_flat > 100 && n_crease > 50,
        "{n_flat} flat, {n_crease} crease"
    );
    for f in 0..mesh.n_faces() {
        if flat[f] {
            assert_eq!(s[f], 0.0, "face {f} lies over one cube face but scores");
        }
    }
    let scored = (0..mesh.n_faces())
        .filter(|&f| !flat[f] && s[f] > 0.0)
        .count();
    assert!(
        scored * 10 >= n_crease * 9,
        "only {scored} of {n_crease} faces over cube edges score"
    );
    // The faces that score most straddle the edges, and their scores are large.
    let max = s.iter().copied().fold(0.0, f64::max);
    assert!(max > 1.0, "max score {max}");
}

/// Fraction of faces straddling a crease of the polyhedron whose normals are the vertices of
/// `icosphere(level)` (at least 3 samples off the main plane; faces touching a crease at one
/// or two samples are left out), which score under `options` (flat faces must score 0).
fn crease_detection(level: u32, options: &FaceSplitOptions) -> f64 {
    let mesh = icosphere(2);
    let target = PolyhedronProjector {
        normals: icosphere(level)
            .positions()
            .iter()
            .map(|p| p.normalize())
            .collect(),
    };
    let (s, samples, _) = scores_against(&mesh, &target, options);
    let off = samples_off_main_plane(&target, &samples, mesh.n_faces());
    let mut crease = 0;
    let mut scored = 0;
    for f in 0..mesh.n_faces() {
        if off[f] == 0 {
            assert_eq!(s[f], 0.0, "face {f} lies over one plane but scores");
        } else if off[f] >= 3 {
            crease += 1;
            scored += usize::from(s[f] > 0.0);
        }
    }
    assert!(crease > 0);
    scored as f64 / crease as f64
}

#[test]
fn default_threshold_sees_creases_from_about_35_degrees_and_the_per_face_rule_gentler_ones() {
    // Polyhedra over icosphere(0|1|2) vertex directions bend by about 63°/36°/16° at their
    // edges. Flat faces score 0 under both rules (asserted inside). Note 1's 0.02 per
    // sub-triangle needs a sub-triangle to bend by roughly 25–30°: it scores every face
    // across a 63° or 36° crease but only part of those across 16° creases (the ones near
    // polyhedron vertices, where chords across three planes tilt more); the per-face rule sums
    // the small folds and sees all of them.
    let default = FaceSplitOptions::default();
    let rates: Vec<(f64, f64)> = (0..3)
        .map(|level| {
            (
                crease_detection(level, &default),
                crease_detection(level, &per_face()),
            )
        })
        .collect();
    eprintln!("crease faces scoring (default, per face) at 63°/36°/16°: {rates:?}");
    assert!(rates[0].0 > 0.95 && rates[1].0 > 0.95, "{rates:?}");
    assert!(rates[2].0 < 0.8, "16° creases are partly missed: {rates:?}");
    assert!(rates.iter().all(|r| r.1 >= r.0 && r.1 > 0.95), "{rates:?}");
}
