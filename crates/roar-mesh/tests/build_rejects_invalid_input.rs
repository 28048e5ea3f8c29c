//! `Mesh::from_triangles` reports each violation with its precise variant.

use roar_mesh::{BuildError, DVec3, Mesh};

fn tetra_positions() -> Vec<DVec3> {
    vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
    ]
}

const TETRA: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

/// The tetrahedron with every index shifted by `k`, positions shifted by `offset`.
fn shifted_tetra(k: u32, offset: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    (
        tetra_positions().into_iter().map(|p| p + offset).collect(),
        TETRA.iter().map(|t| t.map(|i| i + k)).collect(),
    )
}

fn build_err(positions: Vec<DVec3>, triangles: &[[u32; 3]]) -> BuildError {
    let err = Mesh::from_triangles(positions, triangles).expect_err("input must be rejected");
    let line = err.to_string();
    assert!(
        !line.contains('\n') && !line.is_empty(),
        "one clear line: {line:?}"
    );
    err
}

#[test]
fn valid_tetrahedron_is_accepted() {
    let m = Mesh::from_triangles(tetra_positions(), &TETRA).unwrap();
    m.validate().unwrap();
    assert_eq!(m.euler_characteristic(), 2);
}

#[test]
fn empty_input_is_rejected() {
    assert!(matches!(build_err(vec![], &[]), BuildError::Empty { .. }));
    assert!(matches!(
        build_err(tetra_positions(), &[]),
        BuildError::Empty {
            n_positions: 4,
            n_triangles: 0
        }
    ));
}

#[test]
fn non_finite_position_is_rejected() {
    let mut p = tetra_positions();
    p[2].y = f64::NAN;
    assert!(matches!(
        build_err(p.clone(), &TETRA),
        BuildError::NonFinitePosition { vertex: 2, .. }
    ));
    p[2].y = 0.0;
    p[3].z = f64::INFINITY;
    assert!(matches!(
        build_err(p, &TETRA),
        BuildError::NonFinitePosition { vertex: 3, .. }
    ));
}

#[test]
fn index_out_of_range_is_rejected() {
    let mut t = TETRA.to_vec();
    t[2][1] = 9;
    assert_eq!(
        build_err(tetra_positions(), &t),
        BuildError::IndexOutOfRange {
            face: 2,
            corner: 1,
            index: 9,
            n_positions: 4
        }
    );
}

#[test]
fn degenerate_face_is_rejected() {
    let mut t = TETRA.to_vec();
    t[1] = [0, 3, 0];
    assert_eq!(
        build_err(tetra_positions(), &t),
        BuildError::DegenerateFace {
            face: 1,
            vertices: [0, 3, 0]
        }
    );
}

#[test]
fn duplicate_face_is_rejected_in_either_orientation() {
    let mut t = TETRA.to_vec();
    t.push([1, 2, 0]); // face 0 reversed
    assert!(matches!(
        build_err(tetra_positions(), &t),
        BuildError::DuplicateFace {
            first: 0,
            second: 4,
            ..
        }
    ));
    let mut t = TETRA.to_vec();
    t.push([2, 1, 0]); // face 0 again, rotated
    assert!(matches!(
        build_err(tetra_positions(), &t),
        BuildError::DuplicateFace {
            first: 0,
            second: 4,
            ..
        }
    ));
}

#[test]
fn unreferenced_vertex_is_rejected() {
    let mut p = tetra_positions();
    p.push(DVec3::ONE);
    assert_eq!(
        build_err(p, &TETRA),
        BuildError::UnreferencedVertex { vertex: 4 }
    );
}

#[test]
fn boundary_edge_is_rejected() {
    // Remove face 3 = (0, 3, 2): its three edges become boundary edges, face 0 is the lowest.
    let t = &TETRA[..3];
    match build_err(tetra_positions(), t) {
        BuildError::BoundaryEdge { a, b, face } => {
            assert_eq!(face, 0);
            assert_eq!(
                (a, b),
                (0, 2),
                "the edge 0 -> 2 of face 0 = (0, 2, 1), as directed there"
            );
        }
        other => panic!("wrong variant {other:?}"),
    }
}

#[test]
fn edge_with_more_than_two_faces_is_rejected() {
    // Two tetrahedra sharing the edge (0, 1): four faces on it.
    let (mut p, mut t) = shifted_tetra(0, DVec3::ZERO);
    p.push(DVec3::new(0.5, -1.0, 0.0));
    p.push(DVec3::new(0.5, -0.5, -1.0));
    t.extend([[0, 4, 1], [0, 1, 5], [1, 4, 5], [0, 5, 4]]);
    match build_err(p, &t) {
        BuildError::NonManifoldEdge {
            a,
            b,
            n_faces,
            faces,
        } => {
            assert_eq!((a, b, n_faces), (0, 1, 4));
            assert_eq!(faces, [0, 1]);
        }
        other => panic!("wrong variant {other:?}"),
    }
}

#[test]
fn inconsistent_orientation_is_rejected() {
    let mut t = TETRA.to_vec();
    t[0] = [0, 1, 2]; // flipped
    match build_err(tetra_positions(), &t) {
        BuildError::InconsistentOrientation { faces, .. } => assert_eq!(faces[0], 0),
        other => panic!("wrong variant {other:?}"),
    }
}

#[test]
fn pinched_vertex_is_rejected() {
    // Two tetrahedra sharing only vertex 0.
    let (mut p, mut t) = shifted_tetra(0, DVec3::ZERO);
    let (p2, t2) = shifted_tetra(3, DVec3::new(-1.0, -1.0, -1.0));
    p.extend_from_slice(&p2[1..]);
    // Second tetra uses 0 in place of its own corner 0 (which would be index 3).
    t.extend(t2.iter().map(|tri| tri.map(|i| if i == 3 { 0 } else { i })));
    match build_err(p, &t) {
        BuildError::NonManifoldVertex {
            vertex,
            n_faces,
            fan_size,
        } => {
            assert_eq!(vertex, 0);
            assert_eq!((n_faces, fan_size), (6, 3));
        }
        other => panic!("wrong variant {other:?}"),
    }
}

#[test]
fn earliest_check_wins_when_several_fail() {
    // Out-of-range index (face check) beats a NaN? No: non-finite positions are checked first.
    let mut p = tetra_positions();
    p[1].x = f64::NAN;
    let mut t = TETRA.to_vec();
    t[0][0] = 99;
    assert!(matches!(
        build_err(p, &t),
        BuildError::NonFinitePosition { vertex: 1, .. }
    ));
    // A degenerate face 1 and an out-of-range face 3: face order decides.
    let mut t = TETRA.to_vec();
    t[1] = [1, 1, 3];
    t[3] = [0, 3, 42];
    assert!(matches!(
        build_err(tetra_positions(), &t),
        BuildError::DegenerateFace { face: 1, .. }
    ));
}

#[test]
fn large_build_is_fast_enough_to_not_be_quadratic() {
    // 131k-face torus: an O(n²) edge matcher would take minutes here.
    let m = roar_mesh::shapes::torus(512, 128, 1.0, 0.3);
    let (p, t) = m.to_triangles();
    let start = std::time::Instant::now();
    let rebuilt = Mesh::from_triangles(p, &t).unwrap();
    let elapsed = start.elapsed();
    assert_eq!(rebuilt.n_faces(), 131_072);
    eprintln!("from_triangles, 131072 faces: {elapsed:?}");
}
