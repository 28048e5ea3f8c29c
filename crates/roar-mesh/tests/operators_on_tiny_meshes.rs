//! The four operators on hand-checked tiny meshes: outcome records, counts, refusals.

use roar_mesh::{DVec3, EdgeId, HalfedgeId, Mesh, TopoError, VertexId, shapes};

/// Octahedron: 6 vertices of valence 4, 8 faces.
fn octahedron() -> Mesh {
    let p = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    // (x, y, z) octants, counter-clockwise from outside.
    let t = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    Mesh::from_triangles(p, &t).unwrap()
}

fn tetrahedron() -> Mesh {
    let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    Mesh::from_triangles(p, &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]).unwrap()
}

fn v(i: usize) -> VertexId {
    VertexId::from_index(i)
}

#[test]
fn octahedron_is_outward_and_regular() {
    let m = octahedron();
    m.validate().unwrap();
    assert!(m.signed_volume() > 0.0);
    assert!(m.vertices().all(|x| m.valence(x) == 4));
    let top = v(4);
    let mut ring: Vec<_> = m.neighbors(top).map(|x| x.index()).collect();
    ring.sort();
    assert_eq!(ring, vec![0, 1, 2, 3]);
    assert_eq!(m.faces_around(top).count(), 4);
    for h in m.outgoing(top) {
        assert_eq!(m.tail(h), top);
        assert_eq!(m.opposite_vertex(h), m.head(m.next(h)));
    }
}

#[test]
fn flip_rotates_the_edge_to_the_opposite_vertices() {
    let mut m = octahedron();
    let h = m.find_halfedge(v(4), v(0)).unwrap();
    let (c, d) = (m.opposite_vertex(h), m.opposite_vertex(h.twin()));
    let e = m.flip(h.edge()).unwrap();
    m.validate().unwrap();
    assert_eq!(e, h.edge());
    let mut ends = m.edge_vertices(e).map(|x| x.index());
    ends.sort();
    let mut cd = [c.index(), d.index()];
    cd.sort();
    assert_eq!(ends, cd);
    assert!(m.find_halfedge(v(4), v(0)).is_none());
    assert_eq!((m.valence(v(4)), m.valence(v(0))), (3, 3));
    assert_eq!((m.valence(c), m.valence(d)), (5, 5));
    assert_eq!(m.n_faces(), 8);
    assert!(m.signed_volume() > 0.0);
}

#[test]
fn flip_refuses_duplicate_edges_and_low_valence_without_changing_the_mesh() {
    let mut m = tetrahedron();
    let before = m.clone();
    for e in before.edges() {
        assert!(matches!(
            m.can_flip(e),
            Err(TopoError::FlipWouldDuplicateEdge { .. })
        ));
        assert!(m.flip(e).is_err());
        assert_eq!(m, before);
    }
    // Octahedron: after one flip the two old endpoints have valence 3; the edge between
    // one of them and a neighbour may not be flipped again.
    let mut m = octahedron();
    let h = m.find_halfedge(v(4), v(0)).unwrap();
    m.flip(h.edge()).unwrap();
    let h2 = m.find_halfedge(v(4), v(2)).unwrap();
    let before = m.clone();
    assert!(m.flip(h2.edge()).is_err());
    assert_eq!(m, before);
}

#[test]
fn dead_elements_are_refused() {
    let mut m = octahedron();
    let h = m.find_halfedge(v(4), v(0)).unwrap();
    let c = m.collapse(h).unwrap();
    let dead_edge = c.removed_edges[0];
    assert!(matches!(
        m.can_flip(dead_edge),
        Err(TopoError::DeadElement(_))
    ));
    assert!(matches!(
        m.collapse(dead_edge.halfedge()),
        Err(TopoError::DeadElement(_))
    ));
    assert!(matches!(
        m.can_flip(EdgeId::from_index(10_000)),
        Err(TopoError::DeadElement(_))
    ));
    assert!(!m.is_vertex_alive(c.removed));
    assert!(m.find_halfedge(c.removed, c.survivor).is_none());
}

#[test]
fn collapse_merges_tail_into_head_and_reports_what_died() {
    let mut m = octahedron();
    let h = m.find_halfedge(v(4), v(0)).unwrap();
    let (c, d) = (m.opposite_vertex(h), m.opposite_vertex(h.twin()));
    let p0 = m.position(v(0));
    let out = m.collapse(h).unwrap();
    m.validate().unwrap();
    assert_eq!((out.removed, out.survivor), (v(4), v(0)));
    assert_eq!(m.position(v(0)), p0, "survivor keeps its position");
    assert_eq!((m.n_vertices(), m.n_edges(), m.n_faces()), (5, 9, 6));
    assert!(out.removed_faces.iter().all(|&f| !m.is_face_alive(f)));
    assert!(out.removed_edges.iter().all(|&e| !m.is_edge_alive(e)));
    assert!(out.kept_edges.iter().all(|&e| m.is_edge_alive(e)));
    // The survivor now reaches every former neighbour of the removed vertex.
    let ring: Vec<_> = m.neighbors(v(0)).collect();
    for x in [1, 2, 3, 5] {
        assert!(ring.contains(&v(x)), "v0 must be joined to v{x}");
    }
    assert_eq!((m.valence(c), m.valence(d)), (3, 3));
    assert_eq!(m.euler_characteristic(), 2);
}

#[test]
fn collapse_refuses_link_condition_and_tetrahedra() {
    let mut m = tetrahedron();
    let before = m.clone();
    for h in before.halfedges() {
        assert!(matches!(
            m.collapse(h),
            Err(TopoError::TetrahedronCollapse { .. })
        ));
        assert_eq!(m, before);
    }
    // Triangular bipyramid (octahedron after one collapse): an equator edge's endpoints share
    // three neighbours (both apexes and the third equator vertex).
    let mut m = octahedron();
    m.collapse(m.find_halfedge(v(4), v(0)).unwrap()).unwrap();
    let equator: Vec<VertexId> = m.vertices().filter(|&x| m.valence(x) == 4).collect();
    assert_eq!(equator.len(), 3);
    let h = m.find_halfedge(equator[0], equator[1]).unwrap();
    let before = m.clone();
    assert_eq!(
        m.can_collapse(h),
        Err(TopoError::LinkCondition {
            shared_neighbors: 3
        })
    );
    assert!(m.collapse(h).is_err());
    assert_eq!(m, before);
}

#[test]
fn split_edge_inserts_a_valence_four_vertex_at_the_lerp() {
    let mut m = octahedron();
    let e = m.find_halfedge(v(4), v(0)).unwrap().edge();
    let [a, b] = m.edge_vertices(e);
    let s = m.split_edge(e, 0.25);
    m.validate().unwrap();
    assert_eq!(s.parents, [a, b]);
    let expect = m.position(a) * 0.75 + m.position(b) * 0.25;
    assert!((m.position(s.new_vertex) - expect).length() < 1e-15);
    assert_eq!(m.valence(s.new_vertex), 4);
    assert_eq!((m.n_vertices(), m.n_edges(), m.n_faces()), (7, 15, 10));
    assert!(m.find_halfedge(a, b).is_none());
    assert!(m.find_halfedge(a, s.new_vertex).is_some());
    assert!(m.find_halfedge(s.new_vertex, b).is_some());
    assert!(s.new_faces.iter().all(|&f| m.is_face_alive(f)));
    assert!(s.new_edges.iter().all(|&x| m.is_edge_alive(x)));
    // The new vertex lies on the straight edge: the solid is unchanged.
    assert!((m.signed_volume() - octahedron().signed_volume()).abs() < 1e-12);
}

#[test]
fn split_face_inserts_a_valence_three_vertex_at_the_barycentre() {
    let mut m = octahedron();
    let f = m.faces().next().unwrap();
    let corners = m.face_vertices(f);
    let area = m.face_area(f);
    let s = m.split_face(f, [1.0 / 3.0; 3]);
    m.validate().unwrap();
    assert_eq!(s.parents, corners);
    assert_eq!(m.valence(s.new_vertex), 3);
    assert!(
        (m.position(s.new_vertex) - corners.iter().map(|&c| m.position(c)).sum::<DVec3>() / 3.0)
            .length()
            < 1e-15
    );
    assert_eq!(s.new_faces[0], f);
    let sum: f64 = s.new_faces.iter().map(|&g| m.face_area(g)).sum();
    assert!(
        (sum - area).abs() < 1e-12,
        "the three faces tile the old one"
    );
    for g in s.new_faces {
        assert!(m.face_normal(g).dot(DVec3::ONE) > 0.0, "orientation kept");
    }
    assert_eq!((m.n_vertices(), m.n_edges(), m.n_faces()), (7, 15, 10));
}

#[test]
fn geometry_helpers_follow_the_spec_defaults() {
    let m = shapes::cube();
    for f in m.faces() {
        assert!((m.face_area(f) - 0.5).abs() < 1e-12);
        let n = m.face_normal(f);
        assert!((n.length() - 1.0).abs() < 1e-12);
        assert!(n.dot(m.face_centroid(f)) > 0.0, "outward");
    }
    // A degenerate (zero-area) face gets normal (1, 0, 0) and area 1e-9.
    let mut m = octahedron();
    for x in m.vertices().collect::<Vec<_>>() {
        m.set_position(x, DVec3::ZERO);
    }
    let f = m.faces().next().unwrap();
    assert_eq!(m.face_normal(f), DVec3::X);
    assert_eq!(m.face_area(f), 1e-9);
    let h = HalfedgeId::from_index(0);
    assert_eq!(m.edge_length(h.edge()), 0.0);
}

/// Bipyramid over an `n`-gon: apexes `n` (top) and `n + 1` (bottom) of valence `n`, ring
/// vertices of valence 4.
fn bipyramid(n: usize) -> Mesh {
    let mut p: Vec<DVec3> = (0..n)
        .map(|k| {
            let t = k as f64 * std::f64::consts::TAU / n as f64;
            DVec3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    p.extend([DVec3::Z, DVec3::NEG_Z]);
    let (top, bottom) = (n as u32, n as u32 + 1);
    let t: Vec<[u32; 3]> = (0..n as u32)
        .flat_map(|k| {
            let next = (k + 1) % n as u32;
            [[k, next, top], [next, k, bottom]]
        })
        .collect();
    Mesh::from_triangles(p, &t).unwrap()
}

/// `can_collapse` counts the common neighbours right whether the rings fit its stack buffer
/// (32 vertices) or not: on bipyramids with apexes of valence 6 and 40, every half-edge gets
/// the answer of a brute-force count of common neighbours.
#[test]
fn collapse_check_is_the_same_for_small_and_large_rings() {
    for n in [6, 40] {
        let m = bipyramid(n);
        for h in m.halfedges() {
            let (a, b) = (m.tail(h), m.head(h));
            let ring_b: Vec<VertexId> = m.neighbors(b).collect();
            let shared = m.neighbors(a).filter(|x| ring_b.contains(x)).count();
            let expected = if shared != 2 {
                Err(TopoError::LinkCondition {
                    shared_neighbors: shared,
                })
            } else {
                Ok(())
            };
            match m.can_collapse(h) {
                Err(TopoError::TetrahedronCollapse { .. }) => assert_eq!(expected, Ok(())),
                got => assert_eq!(got, expected, "n = {n}, {a:?} -> {b:?}"),
            }
        }
        // An equator edge (ring vertices of valence 4, apexes as wings) and an apex edge.
        let equator = m.find_halfedge(v(0), v(1)).unwrap();
        assert_eq!(m.can_collapse(equator), Ok(()));
        let apex = m.find_halfedge(v(n), v(0)).unwrap();
        assert_eq!(m.can_collapse(apex), Ok(()));
        assert_eq!(m.can_collapse(apex.twin()), Ok(()));
    }
}
