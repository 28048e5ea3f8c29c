//! The soup clean-up that makes the target T′: welding, degenerate and duplicate faces, twin choice
//! by pixel counts, unreferenced vertices, normalization.

mod common;

use common::{append, cube, reversed};
use glam::DVec3;
use roar_loss::{LossError, Target, TargetOptions, build_target};
use roar_mesh::spatial::RIG_RADIUS;

/// Reduced resolution keeps these tests fast; the rig is the paper's 6×6.
fn options() -> TargetOptions {
    TargetOptions {
        resolution: 128,
        ..TargetOptions::default()
    }
}

/// Every face of `target` has its normal pointing away from the origin (outward on a cube).
fn all_outward(target: &Target) -> bool {
    target.triangles.iter().all(|t| {
        let [a, b, c] = t.map(|i| target.positions[i as usize]);
        (b - a).cross(c - a).dot(a + b + c) > 0.0
    })
}

#[test]
fn doubled_cube_soup_keeps_the_twelve_outward_faces() {
    for inward_first in [false, true] {
        let (p, t) = cube(DVec3::new(3.0, -1.0, 2.0), 0.5);
        let soup = if inward_first {
            reversed(&t)
                .into_iter()
                .chain(t.iter().copied())
                .collect::<Vec<_>>()
        } else {
            t.iter().copied().chain(reversed(&t)).collect()
        };
        let target = build_target(&p, &soup, &options()).unwrap();
        let s = target.stats;
        assert_eq!(s.duplicate_faces_removed, 12, "{s:?}");
        assert_eq!(s.twins_dropped, 12, "{s:?}");
        assert_eq!((s.pairs_undecided, s.pairs_tied), (0, 0), "{s:?}");
        assert_eq!(target.triangles.len(), 12);
        assert_eq!(target.positions.len(), 8);
        assert!(all_outward(&target), "inward_first {inward_first}");
    }
}

#[test]
fn an_inward_cube_is_turned_outward() {
    let (p, t) = cube(DVec3::ZERO, 1.0);
    let target = build_target(&p, &reversed(&t), &options()).unwrap();
    assert_eq!(target.stats.twins_dropped, 12);
    assert_eq!(target.triangles.len(), 12);
    assert!(all_outward(&target));
}

#[test]
fn a_zero_thickness_sheet_keeps_both_sides() {
    // A unit square in the z = 0 plane, with signed zeros that must weld.
    let p = vec![
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, -1.0, -0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0), // bit-different from vertex 1 only by the sign of zero
    ];
    let t = [[0, 1, 2], [0, 4, 2], [0, 2, 3]];
    let target = build_target(&p, &t, &options()).unwrap();
    let s = target.stats;
    assert_eq!(s.welded_vertices, 1, "{s:?}");
    assert_eq!(s.duplicate_faces_removed, 1, "{s:?}");
    assert_eq!(s.twins_dropped, 0, "{s:?}");
    assert_eq!(s.pairs_undecided + s.pairs_tied, 2, "{s:?}");
    assert_eq!(s.pairs_unseen, 0, "{s:?}");
    assert_eq!(target.triangles.len(), 4);
    let up = target
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| target.positions[i as usize]);
            (b - a).cross(c - a).z > 0.0
        })
        .count();
    assert_eq!(up, 2, "two faces per side");
}

#[test]
fn duplicates_degenerates_and_unreferenced_vertices_are_removed() {
    let mut mesh = cube(DVec3::ZERO, 1.0);
    // Exact duplicates: same orientation rotated, and reversed.
    let extra = [
        mesh.1[0],
        [mesh.1[1][1], mesh.1[1][2], mesh.1[1][0]],
        reversed(&mesh.1[2..3])[0],
    ];
    mesh.1.extend(extra);
    // Unreferenced far vertex, and vertices used only by degenerate faces.
    append(
        &mut mesh,
        (
            vec![
                DVec3::splat(100.0),
                DVec3::new(5.0, 5.0, 5.0),
                DVec3::new(6.0, 6.0, 6.0),
                DVec3::new(7.0, 7.0, 7.0),
            ],
            vec![[1, 2, 3], [1, 1, 2]], // collinear, repeated index (shifted by 8 below)
        ),
    );
    let n = mesh.1.len();
    // The appended faces index the new vertices 9..=11: [9,10,11] collinear, [9,9,10] repeated.
    assert_eq!(mesh.1[n - 2], [9, 10, 11]);
    let target = build_target(&mesh.0, &mesh.1, &options()).unwrap();
    let s = target.stats;
    assert_eq!(s.degenerate_faces_removed, 2, "{s:?}");
    assert_eq!(s.duplicate_faces_removed, 3, "{s:?}");
    assert_eq!(s.unreferenced_vertices_dropped, 4, "{s:?}");
    assert_eq!((target.positions.len(), target.triangles.len()), (8, 12));
    assert!(all_outward(&target));
    // Normalization ignores the dropped vertices: the cube reaches the rig radius.
    let r = target
        .positions
        .iter()
        .map(|p| p.length())
        .fold(0.0, f64::max);
    assert!((r - RIG_RADIUS).abs() < 1e-12, "{r}");
}

#[test]
fn normalization_round_trips_to_the_input_coordinates() {
    let (p, t) = cube(DVec3::new(10.0, -20.0, 5.0), 3.0);
    let target = build_target(&p, &t, &options()).unwrap();
    assert!(
        target
            .normalization
            .center
            .distance(DVec3::new(10.0, -20.0, 5.0))
            < 1e-12
    );
    let mut back = target.positions.clone();
    target.normalization.invert_all(&mut back);
    // Vertex order is preserved (first occurrence), so positions map back one to one.
    for (a, b) in back.iter().zip(&p) {
        assert!(a.distance(*b) < 1e-12, "{a} vs {b}");
    }
    assert_eq!(target.renders.len(), 36);
    assert_eq!(target.cameras.len(), 36);
    assert!(target.renders.iter().all(|r| r.len() == 128 * 128));
    // Every view sees the cube.
    assert!(
        target
            .renders
            .iter()
            .all(|r| r.iter().any(|px| px[3] > 0.0))
    );
}

#[test]
fn bad_soups_are_errors() {
    let (p, t) = cube(DVec3::ZERO, 1.0);
    let options = options();
    assert!(matches!(
        build_target(&p, &[], &options),
        Err(LossError::InvalidTarget(_))
    ));
    assert!(matches!(
        build_target(&p, &[[0, 0, 1], [0, 1, 1]], &options),
        Err(LossError::InvalidTarget(_))
    ));
    let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
    assert!(matches!(
        build_target(&line, &[[0, 1, 2]], &options),
        Err(LossError::InvalidTarget(_))
    ));
    assert!(matches!(
        build_target(&p, &[[0, 1, 8]], &options),
        Err(LossError::InvalidTarget(_))
    ));
    let mut nan = p.clone();
    nan[3].y = f64::NAN;
    assert!(matches!(
        build_target(&nan, &t, &options),
        Err(LossError::InvalidTarget(_))
    ));
    // A NaN on an unreferenced vertex is harmless.
    nan.push(DVec3::NAN);
    nan[3].y = p[3].y;
    assert!(build_target(&nan, &t, &options).is_ok());
    let zero_views = TargetOptions {
        views_per_axis: 0,
        ..options
    };
    assert!(build_target(&p, &t, &zero_views).is_err());
}
