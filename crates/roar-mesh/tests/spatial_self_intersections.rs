//! Self-intersection detection agrees with an O(n²) oracle and finds the known counts on real
//! meshes.

mod spatial_common;

use glam::DVec3;
use proptest::prelude::*;
use roar_mesh::spatial::{
    TriangleBvh, face_intersects_any, faces_intersect, intersecting_pairs, self_intersecting_faces,
};

fn brute_pairs(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for i in 0..triangles.len() {
        for j in i + 1..triangles.len() {
            if faces_intersect(positions, triangles[i], triangles[j]) {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}

fn soup() -> impl Strategy<Value = (Vec<DVec3>, Vec<[u32; 3]>)> {
    let grid = (-2i32..=2, -2i32..=2, -2i32..=2)
        .prop_map(|(x, y, z)| DVec3::new(x as f64, y as f64, z as f64));
    let float =
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    prop::collection::vec(prop_oneof![grid, float], 3..20).prop_flat_map(|positions| {
        let n = positions.len() as u32;
        (
            Just(positions),
            prop::collection::vec([0..n, 0..n, 0..n], 1..30),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn pairs_match_the_quadratic_oracle((positions, triangles) in soup()) {
        let pairs = intersecting_pairs(&positions, &triangles);
        prop_assert_eq!(&pairs, &brute_pairs(&positions, &triangles));
        let flags = self_intersecting_faces(&positions, &triangles);
        for (f, &flag) in flags.iter().enumerate() {
            let f = f as u32;
            prop_assert_eq!(flag, pairs.iter().any(|&(i, j)| i == f || j == f));
        }
        // The local query agrees with the pairs when the face itself is ignored.
        let bvh = TriangleBvh::build(&positions, &triangles);
        for (f, &t) in triangles.iter().enumerate() {
            let any = face_intersects_any(&positions, &triangles, &bvh, t, |g| g as usize == f);
            let expected = (0..triangles.len()).any(|g| g != f && faces_intersect(&positions, t, triangles[g]));
            prop_assert_eq!(any, expected);
        }
    }
}

/// A closed octahedron has no self-intersections; a large triangle through its upper half cuts
/// exactly the four upper faces.
#[test]
fn octahedron_is_clean_until_a_plane_cuts_it() {
    let mut positions = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut triangles = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    assert!(intersecting_pairs(&positions, &triangles).is_empty());
    positions.extend([
        DVec3::new(-3.0, -3.0, 0.2),
        DVec3::new(3.0, -3.0, 0.2),
        DVec3::new(0.0, 3.0, 0.2),
    ]);
    triangles.push([6, 7, 8]);
    let flags = self_intersecting_faces(&positions, &triangles);
    assert_eq!(
        flags,
        [true, true, true, true, false, false, false, false, true]
    );
    assert_eq!(
        intersecting_pairs(&positions, &triangles),
        [(0, 8), (1, 8), (2, 8), (3, 8)]
    );
}

fn count_on(name: &str) -> Option<(usize, usize)> {
    let dir = spatial_common::test_data_dir()?;
    let soup = roar_io::read_mesh(&dir.join("clean").join(name)).unwrap_or_else(|e| panic!("{e}"));
    let (positions, triangles) = (soup.positions, soup.triangles);
    let flags = self_intersecting_faces(&positions, &triangles);
    Some((flags.iter().filter(|&&f| f).count(), triangles.len()))
}

#[test]
fn camel_has_the_known_self_intersecting_faces() {
    if let Some((count, faces)) = count_on("camel.off") {
        assert_eq!(faces, 19_536);
        assert_eq!(count, 20, "SOURCES.md (MeshLab) counts 20");
    }
}

/// The 100k-face meshes; slow in debug builds: `cargo test -p roar-mesh --release -- --ignored`.
///
/// Horse: SOURCES.md (MeshLab) counts 3, the exact test finds 5. Face 70686 is a sliver that
/// crosses 71145 and 71399 (no shared vertex, MeshLab's 3) and also 70670 and 71143, with which
/// it shares vertex 11778 / 11891 but overlaps along a segment beyond it (checked with exact
/// rational arithmetic); MeshLab does not count faces that share a vertex.
#[test]
#[ignore]
fn large_clean_meshes_have_the_known_self_intersecting_faces() {
    for (name, expected) in [("armadillo.obj", 0), ("dragon.obj", 28), ("horse.obj", 5)] {
        if let Some((count, _)) = count_on(name) {
            assert_eq!(count, expected, "{name}");
        }
    }
}
