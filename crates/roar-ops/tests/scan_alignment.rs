//! Range-scan alignment on the Stanford bunny scans (`ROAR_SCAN_DATA`, set by `.ci/run` to
//! `../shared/data/scans`): which reading of the `.conf` quaternion makes overlapping scans meet,
//! which way patches face, and that ICP converges to the same pose from a perturbed start.

use std::path::PathBuf;

use glam::{DQuat, DVec3};
use roar_io::{PatchOptions, ScanSet, TriangleSoup};
use roar_mesh::spatial::TriangleBvh;
use roar_ops::align::{IcpOptions, RigidTransform, ScanPatch, icp, others_bvh};

/// The bunny's scan set, or `None` (with a note) when `ROAR_SCAN_DATA` is unset; a set variable
/// naming a missing folder fails.
fn bunny() -> Option<ScanSet> {
    let Some(root) = std::env::var_os("ROAR_SCAN_DATA") else {
        eprintln!("ROAR_SCAN_DATA is not set: skipping (CI sets it)");
        return None;
    };
    let conf = PathBuf::from(root).join("stanford-bunny/bun.conf");
    Some(roar_io::read_scan_set(&conf).expect("the bunny's bun.conf reads"))
}

/// The patch of scan `name` of `set` and its pose as the `.conf` gives it, rotated by `rotation`.
fn scan(set: &ScanSet, name: &str, rotation: fn(DQuat) -> DQuat) -> (TriangleSoup, RigidTransform) {
    let pose = set
        .scans
        .iter()
        .find(|s| s.path.file_name().is_some_and(|f| f == name))
        .expect("scan listed in bun.conf");
    let grid = roar_io::read_range_grid_file(&pose.path).expect("scan reads");
    let (patch, _) = grid.patch(&PatchOptions::default());
    let transform = RigidTransform {
        rotation: rotation(pose.quaternion),
        translation: pose.translation,
    };
    (patch, transform)
}

fn as_written(q: DQuat) -> DQuat {
    q
}

fn w_negated(q: DQuat) -> DQuat {
    DQuat::from_xyzw(q.x, q.y, q.z, -q.w)
}

fn placed(patch: &TriangleSoup, pose: &RigidTransform) -> Vec<DVec3> {
    patch.positions.iter().map(|&p| pose.apply(p)).collect()
}

/// The `fraction`-quantile of the distances from every 10th used vertex of `moving` to the
/// surface of `fixed`: on overlapping scans a low quantile is the distance where they overlap.
fn distance_quantile(
    moving: &[DVec3],
    fixed: &TriangleBvh,
    triangles: &[[u32; 3]],
    fraction: f64,
) -> f64 {
    let mut used = vec![false; moving.len()];
    for t in triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut d: Vec<f64> = (0..moving.len())
        .filter(|&v| used[v])
        .step_by(10)
        .map(|v| {
            fixed
                .closest_point(moving[v])
                .unwrap()
                .distance_squared
                .sqrt()
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d[(d.len() as f64 * fraction) as usize]
}

#[test]
fn the_conf_quaternion_with_w_negated_makes_overlapping_scans_meet() {
    let Some(set) = bunny() else { return };
    let mut measured = Vec::new();
    for reading in [as_written, w_negated] {
        let (a, pa) = scan(&set, "bun000.ply", reading);
        let fixed = TriangleBvh::build(&placed(&a, &pa), &a.triangles);
        for other in ["bun045.ply", "bun315.ply"] {
            let (b, pb) = scan(&set, other, reading);
            let q = distance_quantile(&placed(&b, &pb), &fixed, &b.triangles, 0.3);
            eprintln!(
                "{other} vs bun000: 30 % quantile distance {:.3} mm",
                q * 1e3
            );
            measured.push(q);
        }
    }
    // As written the neighbours stay centimetres apart; with w negated they meet within the
    // scanner's noise (measured: 18.3 and 14.8 mm against 0.053 and 0.078 mm).
    assert!(measured[..2].iter().all(|&d| d > 5e-3), "{measured:?}");
    assert!(measured[2..].iter().all(|&d| d < 0.3e-3), "{measured:?}");
    // And that is the reading roar_io uses.
    let pose = &set.scans[1];
    assert_eq!(pose.rotation(), w_negated(pose.quaternion));
}

#[test]
fn patches_placed_by_the_conf_face_outward() {
    let Some(set) = bunny() else { return };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for pose in &set.scans {
        let name = pose.path.file_name().unwrap().to_str().unwrap().to_string();
        let (patch, transform) = scan(&set, &name, w_negated);
        let base = positions.len() as u32;
        positions.extend(placed(&patch, &transform));
        triangles.extend(patch.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    let centre = positions.iter().copied().sum::<DVec3>() / positions.len() as f64;
    let outward = triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0
        })
        .count();
    let fraction = outward as f64 / triangles.len() as f64;
    eprintln!(
        "{:.2} % of {} triangles face away from the centre",
        100.0 * fraction,
        triangles.len()
    );
    // Measured: 90.2 % (9.8 % with the opposite scanner direction); not 100 % because the
    // bunny is not star-shaped about its centre (ears, the neck's fold).
    assert!(fraction > 0.85, "patches face the wrong way: {fraction}");
}

/// bun045 (moving) and the union of bun000 and bun315 (fixed), placed by the `.conf`.
fn icp_setup(set: &ScanSet) -> (TriangleSoup, RigidTransform, TriangleBvh) {
    let (moving, pose) = scan(set, "bun045.ply", w_negated);
    let (a, pa) = scan(set, "bun000.ply", w_negated);
    let (b, pb) = scan(set, "bun315.ply", w_negated);
    let fixed = others_bvh(
        &[
            ScanPatch {
                positions: &a.positions,
                triangles: &a.triangles,
            },
            ScanPatch {
                positions: &b.positions,
                triangles: &b.triangles,
            },
        ],
        &[pa, pb],
        usize::MAX,
    );
    (moving, pose, fixed)
}

#[test]
fn icp_from_a_start_off_by_2_degrees_and_2_mm_ends_where_the_given_start_ends() {
    let Some(set) = bunny() else { return };
    let (moving, given, fixed) = icp_setup(&set);
    let patch = ScanPatch {
        positions: &moving.positions,
        triangles: &moving.triangles,
    };
    let options = IcpOptions::default();
    let reference = icp(&patch, &fixed, &given, &options);
    assert!(reference.overlaps);
    let centroid = moving.positions.iter().copied().sum::<DVec3>() / moving.positions.len() as f64;
    let centre = given.apply(centroid);
    let axis = DVec3::new(0.3, -0.8, 0.5).normalize();
    let turn = DQuat::from_axis_angle(axis, 2f64.to_radians());
    let shift = DVec3::new(1.0, 1.0, -1.0).normalize() * 2e-3;
    let perturbed = RigidTransform {
        rotation: turn * given.rotation,
        translation: turn * (given.translation - centre) + centre + shift,
    };
    let (angle, distance) = given.difference(&perturbed, centroid);
    assert!((angle - 2.0).abs() < 1e-9 && (distance - 2e-3).abs() < 1e-9);
    let result = icp(&patch, &fixed, &perturbed, &options);
    let (angle, distance) = reference.transform.difference(&result.transform, centroid);
    eprintln!(
        "given start: residual {:.4} → {:.4} mm in {} iterations; perturbed start: {:.4} → {:.4} mm in {}; \
         ends {angle:.4}° and {:.4} mm apart",
        reference.residual_before * 1e3,
        reference.residual_after * 1e3,
        reference.iterations,
        result.residual_before * 1e3,
        result.residual_after * 1e3,
        result.iterations,
        distance * 1e3
    );
    assert!(result.overlaps);
    assert!(angle < 0.1 && distance < 0.2e-3, "{angle}° {distance} m");
    assert!(result.residual_after < result.residual_before);
}

#[test]
fn a_scan_that_overlaps_nothing_is_reported_and_keeps_its_pose() {
    let Some(set) = bunny() else { return };
    let (moving, given, fixed) = icp_setup(&set);
    let patch = ScanPatch {
        positions: &moving.positions,
        triangles: &moving.triangles,
    };
    let far = RigidTransform {
        translation: given.translation + DVec3::new(1.0, 0.0, 0.0),
        ..given
    };
    let result = icp(&patch, &fixed, &far, &IcpOptions::default());
    assert!(!result.overlaps);
    assert_eq!(result.transform, far);
    assert_eq!(result.pairs, 0);
}
