//! Untangle on randomly planted crossings: a patch of a (perturbed) icosphere or torus pushed
//! through the opposite wall, two overlapping spheres, and a thin sheet whose top is pushed
//! through its bottom. Afterwards no face may intersect another (checked independently with
//! `self_intersecting_faces`), the mesh must validate and keep its genus and piece count, and
//! every face still crossing must be listed in `unresolved_faces`.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_mesh::shapes::{icosphere, perturbed, torus};
use roar_mesh::spatial::self_intersecting_faces;
use roar_mesh::{DVec3, FaceId, Mesh, VertexId};
use roar_ops::untangle::{UntangleOptions, UntangleStats, untangle};
use std::collections::{BTreeSet, HashMap};

/// Faces of `mesh` (ids) that intersect another face, by the independent brute-force-backed
/// `self_intersecting_faces` on the uncompacted slot buffer.
fn crossing_faces(mesh: &Mesh) -> BTreeSet<FaceId> {
    let faces: Vec<FaceId> = mesh.faces().collect();
    let triangles: Vec<[u32; 3]> = faces
        .iter()
        .map(|&f| mesh.face_vertices(f).map(VertexId::raw))
        .collect();
    let flags = self_intersecting_faces(mesh.positions(), &triangles);
    faces
        .into_iter()
        .zip(flags)
        .filter_map(|(f, x)| x.then_some(f))
        .collect()
}

/// Smooth bump weight: 1 at the centre, 0 at `radius` and beyond.
fn falloff(distance: f64, radius: f64) -> f64 {
    let s = (1.0 - (distance / radius).powi(2)).max(0.0);
    s * s
}

/// Icosphere (level 2 or 3, perturbed) with a patch around a random vertex pushed through the
/// opposite side, either as a smooth spike or as a flat-bottomed dent.
fn pushed_sphere(rng: &mut ChaCha8Rng) -> Mesh {
    let level = rng.random_range(2..=3);
    let mut m = perturbed(&icosphere(level), 0.01, rng.random());
    let verts: Vec<VertexId> = m.vertices().collect();
    let c = m
        .position(verts[rng.random_range(0..verts.len())])
        .normalize();
    let radius = rng.random_range(0.25..0.6);
    let depth = rng.random_range(2.05..2.4);
    let flat = rng.random_bool(0.5);
    for v in verts {
        let p = m.position(v);
        let w = if flat {
            f64::from(u8::from(p.distance(c) < radius))
        } else {
            falloff(p.distance(c), radius)
        };
        m.set_position(v, p - depth * w * c);
    }
    m
}

/// Torus (tube 0.3) with a patch of its outer equator pushed through the inner wall of its tube.
fn pushed_torus(rng: &mut ChaCha8Rng) -> Mesh {
    let mut m = perturbed(&torus(48, 16, 1.0, 0.3), 0.005, rng.random());
    // On a vertex of the outer equator, so the bump's full depth lands on the mesh.
    let angle = std::f64::consts::TAU * f64::from(rng.random_range(0..48u32)) / 48.0;
    let dir = DVec3::new(angle.cos(), angle.sin(), 0.0);
    let c = 1.3 * dir;
    let radius = rng.random_range(0.15..0.3);
    let depth = rng.random_range(0.7..1.1);
    for v in m.vertices().collect::<Vec<_>>() {
        let p = m.position(v);
        let w = falloff(p.distance(c), radius);
        m.set_position(v, p - depth * w * dir);
    }
    m
}

/// Two overlapping perturbed icospheres of random radii in one mesh. Unless `nested` is allowed,
/// the smaller sticks out of the larger by at least a quarter of its radius (a nearly nested
/// sphere is the known weak case, see `resolution_rate_on_a_fixed_sweep`).
fn two_spheres(rng: &mut ChaCha8Rng, nested: bool) -> Mesh {
    let r1: f64 = rng.random_range(0.6..1.2);
    let r2: f64 = rng.random_range(0.6..1.2);
    let lo = (r1 - r2).abs() + if nested { 0.1 } else { 0.25 * r1.min(r2) };
    let hi = r1 + r2 - 0.1;
    let d = rng.random_range(lo..hi);
    let axis = DVec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    )
    .normalize_or(DVec3::X);
    let a = perturbed(&icosphere(rng.random_range(2..=3)), 0.01, rng.random());
    let b = perturbed(&icosphere(rng.random_range(2..=3)), 0.01, rng.random());
    let (pa, ta) = a.to_triangles();
    let (pb, tb) = b.to_triangles();
    let n = pa.len() as u32;
    let mut positions: Vec<DVec3> = pa.iter().map(|&p| p * r1).collect();
    positions.extend(pb.iter().map(|&p| p * r2 + d * axis));
    let mut triangles = ta;
    triangles.extend(tb.iter().map(|t| t.map(|i| i + n)));
    Mesh::from_triangles(positions, &triangles).unwrap()
}

/// Closed box surface on the integer lattice `[0,nx]×[0,ny]×[0,nz]`, scaled to `size`, each
/// unit square split into two triangles, outward.
fn lattice_box([nx, ny, nz]: [i64; 3], size: DVec3) -> Mesh {
    let dims = [nx, ny, nz];
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut id = |p: [i64; 3], positions: &mut Vec<DVec3>| {
        *index.entry(p).or_insert_with(|| {
            positions.push(DVec3::new(
                p[0] as f64 / nx as f64 * size.x,
                p[1] as f64 / ny as f64 * size.y,
                p[2] as f64 / nz as f64 * size.z,
            ));
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    for axis in 0..3 {
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, dims[axis]] {
            let outward = if side == 0 { -1.0 } else { 1.0 };
            for i in 0..dims[u] {
                for j in 0..dims[w] {
                    let corner = |di: i64, dj: i64| {
                        let mut p = [0; 3];
                        p[axis] = side;
                        p[u] = i + di;
                        p[w] = j + dj;
                        p
                    };
                    let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                        .map(|p| id(p, &mut positions));
                    // (u, w, axis) is right-handed, so (0,0)→(1,0)→(1,1) faces +axis.
                    let (t1, t2) = if outward > 0.0 {
                        ([q[0], q[1], q[2]], [q[0], q[2], q[3]])
                    } else {
                        ([q[0], q[2], q[1]], [q[0], q[3], q[2]])
                    };
                    triangles.push(t1);
                    triangles.push(t2);
                }
            }
        }
    }
    Mesh::from_triangles(positions, &triangles).unwrap()
}

/// Runs untangle and checks every promise; returns the stats.
fn untangle_and_check(m: Mesh, label: &str) -> UntangleStats {
    untangle_with_and_check(m, &UntangleOptions::default(), label)
}

/// [`untangle_and_check`] with `options`; also checks that no more faces cross than before.
fn untangle_with_and_check(mut m: Mesh, options: &UntangleOptions, label: &str) -> UntangleStats {
    let (pieces, genus) = (m.components().0, m.genus());
    let before = crossing_faces(&m).len();
    assert!(before > 0, "{label}: the planted case must cross");
    let stats = untangle(&mut m, options);
    m.validate().unwrap();
    assert_eq!(m.components().0, pieces, "{label}");
    assert_eq!(m.genus(), genus, "{label}");
    let left = crossing_faces(&m);
    let reported: BTreeSet<FaceId> = stats.unresolved_faces.iter().copied().collect();
    assert!(
        left.is_subset(&reported),
        "{label}: crossing faces {left:?} not all reported in {stats:?}"
    );
    assert!(
        left.len() <= before,
        "{label}: {} faces cross after the untangle, {before} before",
        left.len()
    );
    stats
}

fn planted(kind: u8, seed: u64, nested: bool) -> (Mesh, String) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    match kind {
        0 => (pushed_sphere(&mut rng), format!("pushed sphere {seed}")),
        1 => (pushed_torus(&mut rng), format!("pushed torus {seed}")),
        _ => (two_spheres(&mut rng, nested), format!("two spheres {seed}")),
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: RngSeed::Fixed(0x0a7a_4e1e),
        ..ProptestConfig::with_cases(32)
    })]

    /// A patch pushed through the opposite wall is always resolved: zero intersecting faces,
    /// valid mesh, same genus and piece count.
    #[test]
    fn random_pushed_patches_are_removed(kind in 0u8..2, seed in any::<u64>()) {
        let (m, label) = planted(kind, seed, false);
        let stats = untangle_and_check(m, &label);
        prop_assert!(stats.unresolved_faces.is_empty(), "{}: {:?}", label, stats);
    }

    /// Two overlapping spheres: the mesh stays valid with the same genus and pieces, and every
    /// face still crossing is reported (resolution rate: see the fixed sweep).
    #[test]
    fn random_overlapping_spheres_are_untangled_or_reported(seed in any::<u64>()) {
        let (m, label) = planted(2, seed, false);
        untangle_and_check(m, &label);
    }

    /// Cut short after a few rounds, the untangle fails on most cases: it then returns the
    /// state with the fewest crossings it reached, never more crossing faces than it was
    /// given, and reports every face still crossing.
    #[test]
    fn a_failed_untangle_leaves_no_more_crossings_than_it_was_given(
        kind in 0u8..3,
        seed in any::<u64>(),
        rounds in 1usize..6,
    ) {
        let (m, label) = planted(kind, seed, true);
        let options = UntangleOptions { max_rounds: rounds, ..UntangleOptions::default() };
        untangle_with_and_check(m, &options, &label);
    }
}

/// A fixed sweep of 60 seeded cases (20 per kind, nearly nested spheres allowed), to state the
/// resolution rate. Measured: 59/60; the miss is a sphere of radius 0.64 sitting 0.3 off the
/// centre of one of radius 0.82 (a cap 0.12 deep sticking out): both sides retreat from the
/// overlap and the small sphere folds into itself before the 200 rounds end. The failure is
/// reported honestly (checked by `untangle_and_check`).
#[test]
fn resolution_rate_on_a_fixed_sweep() {
    let mut resolved = 0;
    let mut total = 0;
    let mut collapses = 0;
    for kind in 0..3u8 {
        for seed in 0..20u64 {
            let (m, label) = planted(kind, 1000 + seed, true);
            let stats = untangle_and_check(m, &label);
            total += 1;
            collapses += stats.collapses;
            if stats.unresolved_faces.is_empty() {
                resolved += 1;
            } else {
                println!("unresolved: {label}: {stats:?}");
            }
        }
    }
    println!("resolved {resolved}/{total}, {collapses} collapses");
    assert!(resolved * 100 >= 95 * total, "resolved {resolved}/{total}");
}

/// A flat box 1 × 1 × 0.001 whose top is pushed 0.0005 below its bottom over a disc.
#[test]
fn thin_sheet_pushed_through_its_bottom_is_untangled() {
    let thickness = 1e-3;
    let mut m = lattice_box([16, 16, 1], DVec3::new(1.0, 1.0, thickness));
    for v in m.vertices().collect::<Vec<_>>() {
        let p = m.position(v);
        let r = DVec3::new(p.x - 0.5, p.y - 0.5, 0.0).length();
        if p.z > 0.5 * thickness && r < 0.3 {
            m.set_position(v, DVec3::new(p.x, p.y, -0.5 * thickness));
        }
    }
    let stats = untangle_and_check(m, "thin sheet");
    println!("thin sheet: {stats:?}");
    assert!(stats.unresolved_faces.is_empty(), "{stats:?}");
}
