//! The oriented point cloud P and the sharp-edge samples.

mod common;

use common::{Lcg, append, cube, reversed, sphere};
use glam::DVec3;
use roar_loss::{
    PointCloud, PointCloudOptions, SharpEdgeOptions, TargetOptions, build_target, point_cloud,
    point_cloud_of_soup, sharp_edge_samples, sharp_edges, two_sided_faces,
};
use roar_mesh::spatial::{TriangleBvh, closest_point_on_triangle};

fn small_options(seed: u64) -> PointCloudOptions {
    PointCloudOptions {
        samples: 20_000,
        seed,
        ..PointCloudOptions::default()
    }
}

#[test]
fn buried_cube_samples_are_dropped_and_outer_normals_point_out() {
    let mut soup = cube(DVec3::ZERO, 1.0);
    append(&mut soup, cube(DVec3::ZERO, 0.3));
    let options = TargetOptions {
        resolution: 64,
        ..TargetOptions::default()
    };
    let target = build_target(&soup.0, &soup.1, &options).unwrap();
    // The inner cube is never seen: both of its twins stay (a tie at 0 pixels).
    assert_eq!(target.stats.pairs_unseen, 12, "{:?}", target.stats);
    assert_eq!(target.triangles.len(), 12 + 24);
    let cloud = point_cloud(&target, &small_options(3)).unwrap();
    let inner_half = 0.3 / 1.0 * target.normalization.scale;
    let outer_half = target.normalization.scale;
    let on_inner = |p: &DVec3| p.abs().max_element() < inner_half + 1e-9;
    // Outer area 6·2² = 24, inner 2 twins × 6·0.6² = 4.32: 24/28.32 of the draws are outside.
    assert!(
        cloud.points.iter().all(|p| !on_inner(p)),
        "buried samples kept"
    );
    let expected = 20_000.0 * 24.0 / 28.32;
    assert!(
        (cloud.len() as f64 - expected).abs() < 0.02 * expected,
        "outer samples dropped: {} kept, expected {expected}",
        cloud.len()
    );
    for (p, n) in cloud.points.iter().zip(&cloud.normals) {
        assert!((p.abs().max_element() - outer_half).abs() < 1e-9);
        assert!(n.dot(*p) > 0.0, "inward normal {n} at {p}");
        assert!((n.length() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn inward_normals_are_filtered_on_a_raw_soup() {
    // Directly on a soup holding both twins of a closed sphere's faces plus an inward-only copy:
    // an inward normal's probe lies inside (|w| ≈ 1 or more) and is dropped.
    let (p, t) = sphere(2, 0.9);
    let cloud = point_cloud_of_soup(&p, &reversed(&t), &small_options(5)).unwrap();
    // The inward-oriented sphere has w ≈ −1 inside; probes along its normals go inside: none kept.
    assert!(cloud.is_empty(), "{} kept", cloud.len());
    let cloud = point_cloud_of_soup(&p, &t, &small_options(5)).unwrap();
    assert_eq!(cloud.len(), 20_000);
    assert!(
        cloud
            .points
            .iter()
            .zip(&cloud.normals)
            .all(|(p, n)| n.dot(*p) > 0.0)
    );
}

#[test]
fn a_sheet_keeps_samples_on_both_sides_and_is_deterministic() {
    let p = vec![
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
    ];
    let target = build_target(
        &p,
        &[[0, 1, 2], [0, 2, 3]],
        &TargetOptions {
            resolution: 64,
            ..TargetOptions::default()
        },
    )
    .unwrap();
    let a = point_cloud(&target, &small_options(9)).unwrap();
    assert_eq!(a, point_cloud(&target, &small_options(9)).unwrap());
    assert_eq!(a.len(), 20_000);
    let up = a.normals.iter().filter(|n| n.z > 0.0).count() as f64 / a.len() as f64;
    assert!((up - 0.5).abs() < 0.02, "fraction facing up {up}");
}

#[test]
fn bvh_closest_point_matches_brute_force() {
    let (p, t) = sphere(1, 0.8);
    let bvh = TriangleBvh::build(&p, &t);
    let mut rng = Lcg(17);
    for _ in 0..200 {
        let q = rng.vec3() * 1.2;
        let hit = bvh.closest_point(q).unwrap();
        let brute = t
            .iter()
            .map(|f| {
                closest_point_on_triangle(q, f.map(|i| p[i as usize]))
                    .0
                    .distance_squared(q)
            })
            .fold(f64::INFINITY, f64::min);
        assert!((hit.distance_squared - brute).abs() < 1e-12, "{q}");
    }
}

#[test]
fn cube_edges_are_all_sharp_and_samples_land_on_them() {
    let (p, t) = cube(DVec3::ZERO, 0.5);
    let edges = sharp_edges(&p, &t, 0.5).unwrap();
    assert_eq!(
        edges.len(),
        12,
        "the 6 diagonals are flat, the 12 edges sharp"
    );
    let bvh = TriangleBvh::build(&p, &t);
    let options = SharpEdgeOptions {
        samples: 3000,
        seed: 1,
        ..SharpEdgeOptions::default()
    };
    let samples = sharp_edge_samples(&bvh, &[], &p, &t, &options).unwrap();
    assert_eq!(samples.len(), 3000);
    check_on_edges_with_adjacent_outward_normals(&samples);
    // Same M0, target cube inward-oriented: the flip rule restores outward normals.
    let inward = TriangleBvh::build(&p, &reversed(&t));
    let flipped = sharp_edge_samples(&inward, &[], &p, &t, &options).unwrap();
    check_on_edges_with_adjacent_outward_normals(&flipped);
    assert_eq!(flipped.points, samples.points);
    // Appending to P.
    let mut cloud = PointCloud::default();
    cloud.extend(samples.clone());
    cloud.extend(flipped);
    assert_eq!(cloud.len(), 6000);
    assert_eq!(cloud.normals.len(), 6000);
}

fn check_on_edges_with_adjacent_outward_normals(samples: &PointCloud) {
    let mut per_axis = [0usize; 3];
    for (q, n) in samples.points.iter().zip(&samples.normals) {
        let at_corner_coord: Vec<usize> = (0..3)
            .filter(|&k| (q[k].abs() - 0.5).abs() < 1e-12)
            .collect();
        assert!(at_corner_coord.len() >= 2, "{q} is not on an edge");
        // The normal is the axis normal of one of the two faces meeting there, pointing out.
        let k = n.abs().max_position();
        assert!(
            (n.abs()[k] - 1.0).abs() < 1e-12 && at_corner_coord.contains(&k),
            "{n} at {q}"
        );
        assert!(n[k] * q[k] > 0.0, "inward {n} at {q}");
        (0..3)
            .filter(|k| !at_corner_coord.contains(k))
            .for_each(|k| per_axis[k] += 1);
    }
    // Edges are all the same length, so each edge direction gets about a third of the samples.
    for c in per_axis {
        assert!(
            (c as f64 / samples.len() as f64 - 1.0 / 3.0).abs() < 0.05,
            "{per_axis:?}"
        );
    }
}

#[test]
fn smooth_meshes_have_no_sharp_edges_and_give_no_samples() {
    let (p, t) = sphere(3, 0.9);
    assert!(sharp_edges(&p, &t, 0.5).unwrap().is_empty());
    let bvh = TriangleBvh::build(&p, &t);
    let s = sharp_edge_samples(&bvh, &[], &p, &t, &SharpEdgeOptions::default()).unwrap();
    assert!(s.is_empty());
    assert!(sharp_edges(&p, &[[0, 1, 999]], 0.5).is_err());
}

#[test]
fn two_sided_faces_are_the_ones_whose_reversed_twin_is_there() {
    let triangles = [
        [0, 1, 2], // twin below, written from another corner
        [2, 1, 0],
        [1, 2, 3], // the same orientation twice is a duplicate, not a sheet
        [2, 3, 1],
        [3, 4, 5], // alone
    ];
    assert_eq!(
        two_sided_faces(&triangles),
        vec![true, true, false, false, false]
    );
    assert!(two_sided_faces(&[]).is_empty());
}

#[test]
fn sheet_samples_stand_off_on_their_own_side_and_closed_surfaces_stay() {
    // A square sheet in z = 0 with both orientations, as T′ keeps an open surface.
    let p = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    let sheet = vec![[0, 1, 2], [0, 2, 3]];
    let mut t = sheet.clone();
    t.extend(reversed(&sheet));
    let offset = 0.01;
    let options = PointCloudOptions {
        sheet_offset: offset,
        ..small_options(7)
    };
    let cloud = point_cloud_of_soup(&p, &t, &options).unwrap();
    let up = cloud.normals.iter().filter(|n| n.z > 0.0).count();
    assert!(up > 8_000 && cloud.len() - up > 8_000, "both sides kept");
    for (q, n) in cloud.points.iter().zip(&cloud.normals) {
        assert!((n.z.abs() - 1.0).abs() < 1e-12);
        assert!((q.z - offset * n.z).abs() < 1e-12, "{q} with normal {n}");
    }
    // A closed cube has no two-sided face: the same options move nothing.
    let (p, t) = cube(DVec3::ZERO, 0.5);
    let cloud = point_cloud_of_soup(&p, &t, &options).unwrap();
    assert!(!cloud.is_empty());
    assert!(
        cloud
            .points
            .iter()
            .all(|q| (q.abs().max_element() - 0.5).abs() < 1e-12)
    );
}

#[test]
fn sharp_samples_on_two_sided_faces_stand_off_along_their_normal() {
    let (p, t) = cube(DVec3::ZERO, 0.5);
    let bvh = TriangleBvh::build(&p, &t);
    let options = SharpEdgeOptions {
        samples: 500,
        seed: 2,
        sheet_offset: 0.01,
        ..SharpEdgeOptions::default()
    };
    let plain = sharp_edge_samples(&bvh, &[], &p, &t, &options).unwrap();
    let moved = sharp_edge_samples(&bvh, &vec![true; t.len()], &p, &t, &options).unwrap();
    assert_eq!(plain.len(), 500);
    assert_eq!(moved.normals, plain.normals);
    for ((a, b), n) in plain.points.iter().zip(&moved.points).zip(&plain.normals) {
        assert!((*b - (*a + 0.01 * *n)).length() < 1e-12);
    }
}
