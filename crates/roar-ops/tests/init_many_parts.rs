//! The watertight init of soups with more separate parts than the piece target: nearby parts are
//! merged into fewer closed pieces, parts too far apart to merge are kept, and the piece limit
//! drops the smallest pieces, every output a closed, outward 2-manifold without
//! self-intersections.

mod common;

use common::{Soup, append, box_soup, check_closed_manifold, count_self_intersections};
use glam::DVec3;
use roar_ops::init::{InitOptions, WatertightInit, watertight_init};

/// `nx × ny × nz` unit cubes, `spacing` apart corner to corner.
fn cube_lattice(n: [usize; 3], spacing: f64) -> Soup {
    let mut soup = Soup {
        positions: Vec::new(),
        triangles: Vec::new(),
    };
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let min = DVec3::new(i as f64, j as f64, k as f64) * spacing;
                append(&mut soup, &box_soup(min, min + DVec3::ONE));
            }
        }
    }
    soup
}

fn init(soup: &Soup, options: &InitOptions) -> WatertightInit {
    let out = watertight_init(&soup.positions, &soup.triangles, options).unwrap();
    let report = check_closed_manifold(&out.positions, &out.triangles).unwrap();
    assert_eq!(report.components, out.stats.pieces);
    assert_eq!(
        count_self_intersections(&out.positions, &out.triangles),
        0,
        "self-intersections"
    );
    out
}

fn options(target_pieces: usize, max_pieces: usize) -> InitOptions {
    InitOptions {
        resolution: 96,
        target_pieces,
        max_pieces,
        ..InitOptions::default()
    }
}

#[test]
fn three_hundred_cubes_merge_into_at_most_the_target_pieces() {
    // 10 × 10 × 3 cubes, gaps as wide as a cube (about 4.6 voxels).
    let soup = cube_lattice([10, 10, 3], 2.0);
    let out = init(&soup, &options(12, 125));
    assert_eq!(out.stats.pieces_before_merge, 300);
    assert!(out.stats.merge_radius > 0);
    assert!(out.stats.pieces <= 12, "{} pieces", out.stats.pieces);
    assert_eq!(out.stats.pieces_over_limit, 0);
    // The merged blob spans the lattice: its volume is more than the cubes'.
    let volume = check_closed_manifold(&out.positions, &out.triangles)
        .unwrap()
        .volume;
    assert!(volume > 300.0, "volume {volume}");
}

#[test]
fn three_hundred_cubes_stay_three_hundred_pieces_when_the_target_allows() {
    let soup = cube_lattice([10, 10, 3], 2.0);
    let out = init(&soup, &options(300, 300));
    assert_eq!(out.stats.pieces, 300);
    assert_eq!(out.stats.merge_radius, 0);
    // The same mesh as without a target.
    let free = init(&soup, &options(usize::MAX, usize::MAX));
    assert_eq!(free.triangles, out.triangles);
    assert_eq!(free.positions, out.positions);
}

#[test]
fn the_merge_takes_the_smallest_radius_so_nearby_groups_stay_apart() {
    // Two clusters of 4 × 4 × 1 cubes with one-cube gaps, five cubes apart: merging down to two
    // pieces joins each cluster but not the two.
    let mut soup = cube_lattice([4, 4, 1], 2.0);
    let cluster = cube_lattice([4, 4, 1], 2.0);
    let far = Soup {
        positions: cluster
            .positions
            .iter()
            .map(|p| *p + DVec3::new(12.0, 0.0, 0.0))
            .collect(),
        triangles: cluster.triangles,
    };
    append(&mut soup, &far);
    let out = init(&soup, &options(2, 32));
    assert_eq!(out.stats.pieces_before_merge, 32);
    assert_eq!(out.stats.pieces, 2);
}

#[test]
fn two_parts_too_far_apart_to_merge_keep_their_shape() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    append(
        &mut soup,
        &box_soup(DVec3::new(20.0, 0.0, 0.0), DVec3::new(21.0, 1.0, 1.0)),
    );
    let free = init(&soup, &options(usize::MAX, usize::MAX));
    let out = init(&soup, &options(1, 2));
    assert_eq!(out.stats.pieces, 2);
    assert_eq!(out.stats.merge_radius, 0);
    assert_eq!(free.triangles, out.triangles);
}

#[test]
fn pieces_beyond_the_limit_are_dropped_smallest_first() {
    // A big cube and two small ones far apart, limited to two pieces: the smaller small cube
    // goes.
    let mut soup = box_soup(DVec3::ZERO, DVec3::splat(4.0));
    append(
        &mut soup,
        &box_soup(DVec3::new(20.0, 0.0, 0.0), DVec3::new(21.5, 1.5, 1.5)),
    );
    append(
        &mut soup,
        &box_soup(DVec3::new(0.0, 20.0, 0.0), DVec3::new(1.0, 21.0, 1.0)),
    );
    let out = init(&soup, &options(1, 2));
    assert_eq!(out.stats.pieces, 2);
    assert_eq!(out.stats.pieces_over_limit, 1);
    let highest = out.positions.iter().map(|p| p.y).fold(f64::MIN, f64::max);
    assert!(highest < 10.0, "the small cube at y = 20 was kept");
    let farthest = out.positions.iter().map(|p| p.x).fold(f64::MIN, f64::max);
    assert!(farthest > 20.0, "the larger small cube was dropped");
}
