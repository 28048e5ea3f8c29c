//! `compact` removes tombstones and its `Remap` carries caller data to the new ids.

use roar_mesh::{Mesh, shapes};

#[test]
fn compact_after_collapses_keeps_the_surface_and_remaps_data() {
    let mut m = shapes::icosphere(2);
    // Collapse a few edges spread over the mesh.
    let mut done = 0;
    for i in (0..m.edge_capacity()).step_by(37) {
        let h = roar_mesh::EdgeId::from_index(i).halfedge();
        if m.collapse(h).is_ok() {
            done += 1;
        }
    }
    assert!(done >= 5, "some collapses must succeed, got {done}");
    let s = m.split_face(m.faces().last().unwrap(), [0.2, 0.3, 0.5]);
    m.validate().unwrap();

    // Caller data indexed by old slots: each vertex's own old index, each face's old index.
    let vdata: Vec<usize> = (0..m.vertex_capacity()).collect();
    let fdata: Vec<usize> = (0..m.face_capacity()).collect();
    let positions_before = m.positions().to_vec();
    let buffers_before = m.to_triangles();
    let live_v: Vec<usize> = m.vertices().map(|v| v.index()).collect();
    let live_f: Vec<usize> = m.faces().map(|f| f.index()).collect();

    let remap = m.compact();
    m.validate().unwrap();
    assert!(!remap.is_identity());
    assert_eq!(m.vertex_capacity(), m.n_vertices());
    assert_eq!(m.face_capacity(), m.n_faces());
    assert_eq!(m.edge_capacity(), m.n_edges());
    assert_eq!(
        m.to_triangles(),
        buffers_before,
        "compaction keeps order and rotation"
    );
    assert_eq!(remap.apply_to_vertex_data(&vdata), live_v);
    assert_eq!(remap.apply_to_face_data(&fdata), live_f);
    assert_eq!(remap.apply_to_vertex_data(&positions_before), m.positions());
    let new_m = remap.vertices[s.new_vertex.index()].expect("split vertex survives");
    assert_eq!(m.valence(new_m), 3);
    assert_eq!(remap.vertices.len(), vdata.len());
    assert!(remap.vertices.iter().filter(|x| x.is_none()).count() >= done);

    // A second compaction is the identity.
    let again = m.compact();
    assert!(again.is_identity());
}

#[test]
fn to_triangles_round_trips_through_from_triangles() {
    let m = shapes::genus_n_solid(2);
    let (p, t) = m.to_triangles();
    let rebuilt = Mesh::from_triangles(p.clone(), &t).unwrap();
    assert_eq!(rebuilt, m);
    assert_eq!(rebuilt.to_triangles(), (p, t));
}

#[test]
fn components_and_genus_of_disjoint_union() {
    let a = shapes::torus(8, 6, 2.0, 0.5);
    let b = shapes::genus_n_solid(2);
    let (mut p, mut t) = a.to_triangles();
    let (pb, tb) = b.to_triangles();
    let off = p.len() as u32;
    p.extend(pb);
    t.extend(tb.iter().map(|x| x.map(|i| i + off)));
    let m = Mesh::from_triangles(p, &t).unwrap();
    let (count, label) = m.components();
    assert_eq!(count, 2);
    assert_eq!(label[0], Some(0));
    assert_eq!(label[off as usize], Some(1));
    assert_eq!(m.component_genera(), vec![1, 2]);
    assert_eq!(m.genus(), 3);
    assert_eq!(m.euler_characteristic(), 2 * 2 - 2 * 3);
}
