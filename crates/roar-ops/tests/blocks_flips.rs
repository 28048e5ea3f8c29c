//! Edge flips never duplicate edges, improve valences, and respect the feature gate.

mod blocks_common;

use blocks_common::{random_mesh, valence_irregularity};
use proptest::prelude::*;
use roar_mesh::FaceId;
use roar_mesh::shapes::{genus_n_solid, icosphere};
use roar_ops::blocks::flips::{FlipOptions, flip_edges};
use std::collections::HashSet;

fn assert_no_duplicate_edges(mesh: &roar_mesh::Mesh) {
    let mut seen = HashSet::new();
    for e in mesh.edges() {
        let [a, b] = mesh.edge_vertices(e);
        assert!(
            seen.insert((a.min(b), a.max(b))),
            "duplicate edge {a:?}-{b:?}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn flips_never_create_duplicate_edges(kind in 0u8..4, jitter in 0.0f64..0.3, seed in 0u64..500, gate in any::<bool>()) {
        let mut mesh = random_mesh(kind, jitter, seed);
        let euler = mesh.euler_characteristic();
        let options = FlipOptions { min_abs_flatness: gate.then_some(0.95), ..FlipOptions::default() };
        flip_edges(&mut mesh, &options);
        mesh.validate().unwrap();
        assert_no_duplicate_edges(&mesh);
        prop_assert_eq!(mesh.euler_characteristic(), euler);
    }
}

#[test]
fn flips_after_face_splits_restore_valences() {
    let mut mesh = icosphere(3);
    let faces: Vec<FaceId> = mesh.faces().step_by(3).collect();
    for f in faces {
        mesh.split_face(f, [1.0 / 3.0; 3]);
    }
    let split = valence_irregularity(&mesh);
    let stats = flip_edges(&mut mesh, &FlipOptions::default());
    let flipped = valence_irregularity(&mesh);
    mesh.validate().unwrap();
    assert_no_duplicate_edges(&mesh);
    assert!(stats.accepted > 100, "{stats:?}");
    assert!(
        flipped < 0.6 * split,
        "mean |val − 6|: {split} after splits, {flipped} after flips"
    );
}

#[test]
fn feature_gate_protects_sharp_edges() {
    // On the box, edges on the 90° creases have |n_L·n_R| = 0 < 0.95: never flipped with the gate.
    let mut mesh = genus_n_solid(0);
    let crease = |m: &roar_mesh::Mesh| -> HashSet<(usize, usize)> {
        m.edges()
            .filter(|&e| {
                let h = e.halfedge();
                m.face_normal(m.face(h))
                    .dot(m.face_normal(m.face(h.twin())))
                    .abs()
                    < 0.5
            })
            .map(|e| {
                let [a, b] = m.edge_vertices(e);
                (a.index().min(b.index()), a.index().max(b.index()))
            })
            .collect()
    };
    let before = crease(&mesh);
    flip_edges(&mut mesh, &FlipOptions::default());
    assert_eq!(crease(&mesh), before);
}
