//! Behaviour of the watertight init on procedural soups: every output is a closed,
//! outward-oriented 2-manifold without self-intersections, with the expected pieces and genus.

mod common;

use common::{Soup, append, box_soup, check_closed_manifold, count_self_intersections};
use glam::DVec3;
use roar_mesh::spatial::{FnSdf, Sdf, TriangleBvh};
use roar_ops::init::{
    InitError, InitOptions, SdfInitOptions, WatertightInit, sdf_init, watertight_init,
};

fn options(resolution: usize) -> InitOptions {
    InitOptions {
        resolution,
        ..InitOptions::default()
    }
}

fn init(soup: &Soup, resolution: usize) -> WatertightInit {
    watertight_init(&soup.positions, &soup.triangles, &options(resolution)).unwrap()
}

/// Closed 2-manifold, outward, no self-intersection; returns (components, Euler characteristic).
fn assert_valid(out: &WatertightInit) -> (usize, i64) {
    let report = check_closed_manifold(&out.positions, &out.triangles).unwrap();
    assert_eq!(
        count_self_intersections(&out.positions, &out.triangles),
        0,
        "self-intersections"
    );
    assert_eq!(report.components, out.stats.pieces);
    (report.components, report.euler)
}

fn mean_distance_to(soup: &Soup, points: &[DVec3]) -> f64 {
    let grid = TriangleBvh::build(&soup.positions, &soup.triangles);
    points
        .iter()
        .map(|p| grid.closest_point(*p).unwrap().distance_squared.sqrt())
        .sum::<f64>()
        / points.len() as f64
}

#[test]
fn cube_soup_becomes_a_closed_outward_genus_zero_mesh_near_the_cube() {
    let soup = box_soup(DVec3::ZERO, DVec3::ONE);
    let out = init(&soup, 16);
    assert_eq!(assert_valid(&out), (1, 2));
    let mean = mean_distance_to(&soup, &out.positions);
    assert!(mean < 0.5 * out.stats.voxel_size, "mean distance {mean}");
    // The output encloses about the cube's volume.
    let volume = check_closed_manifold(&out.positions, &out.triangles)
        .unwrap()
        .volume;
    assert!((volume - 1.0).abs() < 0.25, "volume {volume}");
}

#[test]
fn doubled_cube_with_inward_duplicates_gives_the_same_mesh() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    let inward: Vec<[u32; 3]> = soup.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    soup.triangles.extend(inward);
    let out = init(&soup, 16);
    assert_eq!(assert_valid(&out), (1, 2));
    let single = init(&box_soup(DVec3::ZERO, DVec3::ONE), 16);
    assert_eq!(out.triangles, single.triangles);
}

#[test]
fn cubes_touching_along_an_edge_merge_into_one_closed_manifold() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    append(
        &mut soup,
        &box_soup(DVec3::new(1.0, 1.0, 0.0), DVec3::new(2.0, 2.0, 1.0)),
    );
    let out = init(&soup, 12);
    let (pieces, euler) = assert_valid(&out);
    assert_eq!((pieces, euler), (1, 2));
}

#[test]
fn cubes_touching_at_a_corner_merge_into_one_closed_manifold() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    append(&mut soup, &box_soup(DVec3::ONE, DVec3::splat(2.0)));
    let out = init(&soup, 12);
    assert_eq!(assert_valid(&out), (1, 2));
}

#[test]
fn voxel_level_edge_and_corner_contacts_are_repaired_without_dilation() {
    // Without gap closing the voxel sets of the two cubes touch only along an edge / a corner, so
    // the repair itself has to resolve the non-manifold configurations.
    // Voxels are 0.2 wide: the first cube fills voxels 0..=4, the second 5..=9 along x and y
    // (and along z for the corner case).
    for offset in [DVec3::new(1.1, 1.1, 0.0), DVec3::splat(1.1)] {
        let mut soup = box_soup(DVec3::ZERO, DVec3::splat(0.9));
        append(&mut soup, &box_soup(offset, offset + DVec3::splat(0.9)));
        let opts = InitOptions {
            close_gaps: false,
            ..options(10)
        };
        let out = watertight_init(&soup.positions, &soup.triangles, &opts).unwrap();
        assert_valid(&out);
        assert!(
            out.stats.nonmanifold_edges_resolved + out.stats.nonmanifold_vertices_resolved > 0,
            "{:?}",
            out.stats
        );
    }
}

#[test]
fn two_separate_cubes_stay_two_pieces() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    append(
        &mut soup,
        &box_soup(DVec3::new(2.0, 0.0, 0.0), DVec3::new(3.0, 1.0, 1.0)),
    );
    let out = init(&soup, 24);
    let (pieces, euler) = assert_valid(&out);
    assert_eq!((pieces, euler), (2, 4));
    assert_eq!(out.stats.pieces, 2);
    assert_eq!(out.stats.dropped_pieces, 0);
}

#[test]
fn tiny_far_away_triangle_is_dropped_and_counted() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    let base = soup.positions.len() as u32;
    soup.positions.extend([
        DVec3::new(1.5, 1.5, 1.5),
        DVec3::new(1.501, 1.5, 1.5),
        DVec3::new(1.5, 1.501, 1.5),
    ]);
    soup.triangles.push([base, base + 1, base + 2]);
    let out = init(&soup, 64);
    check_closed_manifold(&out.positions, &out.triangles).unwrap();
    assert_eq!(out.stats.pieces, 1);
    assert_eq!(out.stats.dropped_pieces, 1);
    assert!(out.stats.dropped_area > 0.0);
    assert!(out.positions.iter().all(|p| p.max_element() < 1.3));
}

#[test]
fn zero_thickness_sheet_becomes_a_thin_closed_slab_whose_sides_stay_apart() {
    let soup = Soup {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::new(1.0, 0.0, 0.5),
            DVec3::new(1.0, 1.0, 0.5),
            DVec3::new(0.0, 1.0, 0.5),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let out = init(&soup, 16);
    assert_eq!(assert_valid(&out), (1, 2));
    let h = out.stats.voxel_size;
    let (lo, hi) = out
        .positions
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.z), hi.max(p.z))
        });
    assert!(hi - lo < 4.0 * h, "slab thickness {}", hi - lo);
    // The two sides keep the half-voxel gap of the non-crossing rule: no vertex reaches the sheet.
    let min_offset = out
        .positions
        .iter()
        .map(|p| (p.z - 0.5).abs())
        .fold(f64::INFINITY, f64::min);
    assert!(
        min_offset >= 0.25 * h - 1e-9,
        "a vertex is {min_offset} from the sheet"
    );
}

#[test]
fn open_box_with_a_large_hole_is_still_closed() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::ONE);
    soup.triangles.truncate(10); // drop the +x face: a hole the size of a face
    let out = init(&soup, 16);
    assert_eq!(assert_valid(&out), (1, 2));
}

#[test]
fn projection_moves_the_voxel_surface_onto_a_slanted_box() {
    // A box rotated about two axes: the staircase has to be pulled onto slanted faces.
    let mut soup = box_soup(DVec3::splat(-0.5), DVec3::splat(0.5));
    let rot = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, 0.7, 0.1);
    for p in &mut soup.positions {
        *p = rot * *p;
    }
    let out = init(&soup, 20);
    assert_eq!(assert_valid(&out), (1, 2));
    let mean = mean_distance_to(&soup, &out.positions);
    assert!(
        mean < 0.35 * out.stats.voxel_size,
        "mean {mean} voxel {}",
        out.stats.voxel_size
    );
    let unprojected = watertight_init(
        &soup.positions,
        &soup.triangles,
        &InitOptions {
            projection_rounds: 0,
            ..options(20)
        },
    )
    .unwrap();
    assert!(mean < 0.5 * mean_distance_to(&soup, &unprojected.positions));
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let o = InitOptions::default();
    assert_eq!(
        watertight_init(&[], &[], &o).unwrap_err(),
        InitError::EmptyInput
    );
    let p = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    assert!(matches!(
        watertight_init(&p, &[[0, 1, 2]], &o).unwrap_err(),
        InitError::AllDegenerate { .. }
    ));
    assert!(matches!(
        watertight_init(&p, &[[0, 1, 7]], &o).unwrap_err(),
        InitError::IndexOutOfRange { index: 7, .. }
    ));
    let nan = vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)];
    assert!(matches!(
        watertight_init(&nan, &[[0, 1, 2]], &o).unwrap_err(),
        InitError::NonFiniteCoordinate { vertex: 2 }
    ));
    let same = vec![DVec3::ONE; 3];
    assert!(watertight_init(&same, &[[0, 1, 2]], &o).is_err());
}

#[test]
fn sdf_init_of_a_sphere_and_two_touching_balls_is_a_closed_manifold() {
    let sphere = FnSdf::new(|p: DVec3| p.length() - 0.7);
    let out = sdf_init(
        &sphere,
        DVec3::splat(-1.0),
        DVec3::ONE,
        &SdfInitOptions {
            resolution: 16,
            ..SdfInitOptions::default()
        },
    )
    .unwrap();
    assert_eq!(assert_valid(&out), (1, 2));
    assert_eq!(
        sphere.evaluations().values,
        16 * 16 * 16,
        "one batch of cell centres"
    );
    assert_eq!(sphere.evaluations().gradients, 0);
    // Two balls touching at one point: non-manifold contacts on the grid get repaired.
    let balls = FnSdf::new(|p: DVec3| {
        let a = (p - DVec3::splat(-0.3)).length() - 0.52;
        let b = (p - DVec3::splat(0.3)).length() - 0.52;
        a.min(b)
    });
    let out = sdf_init(
        &balls,
        DVec3::splat(-1.0),
        DVec3::ONE,
        &SdfInitOptions::default(),
    )
    .unwrap();
    check_closed_manifold(&out.positions, &out.triangles).unwrap();
    assert!(
        sdf_init(
            &FnSdf::new(|_| 1.0),
            DVec3::ZERO,
            DVec3::ONE,
            &SdfInitOptions::default()
        )
        .is_err()
    );
}

#[test]
fn torus_soup_keeps_genus_one() {
    // A coarse torus (major radius 1, minor 0.35) as a triangle soup.
    let (n, m) = (24u32, 12u32);
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                i as f64 / n as f64 * std::f64::consts::TAU,
                j as f64 / m as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.35 * v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), 0.35 * v.sin()));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let a = i * m + j;
            let b = ((i + 1) % n) * m + j;
            let c = ((i + 1) % n) * m + (j + 1) % m;
            let d = i * m + (j + 1) % m;
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let out = init(
        &Soup {
            positions,
            triangles,
        },
        24,
    );
    assert_eq!(assert_valid(&out), (1, 0));
}

/// The projection sweeps two halves of the surface at once (and the decimation of large inits
/// runs two halves at once): the result must not depend on the thread count.
#[test]
fn init_is_the_same_on_one_thread_and_on_two() {
    let mut soup = box_soup(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
    append(
        &mut soup,
        &box_soup(DVec3::new(0.5, 0.3, 0.2), DVec3::new(1.7, 1.4, 0.8)),
    );
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| init(&soup, 48))
    };
    let (one, two) = (run(1), run(2));
    assert_valid(&two);
    assert!(two.stats.rejected_moves < two.positions.len());
    assert_eq!(one, two);
}
