//! Property tests: random sequences of the four operators on random closed meshes of genus 0..3
//! keep the mesh valid, the Euler characteristic, genus and components fixed, and change the
//! face count exactly as predicted; refused operators leave the mesh unchanged.

use proptest::prelude::*;
use roar_mesh::{EdgeId, FaceId, HalfedgeId, Mesh, shapes};

/// The random starting meshes: genus 0 to 3, smooth, perturbed and voxel-flat.
fn start_mesh(kind: u8, seed: u64) -> Mesh {
    match kind % 6 {
        0 => shapes::icosphere(1),
        1 => shapes::perturbed(&shapes::icosphere(2), 0.02, seed),
        2 => shapes::torus(8, 6, 1.0, 0.35),
        3 => shapes::perturbed(&shapes::torus(9, 5, 1.0, 0.3), 0.01, seed),
        4 => shapes::genus_n_solid(2),
        _ => shapes::perturbed(&shapes::genus_n_solid(3), 0.02, seed),
    }
}

#[derive(Debug, Clone, Copy)]
enum Op {
    Flip(u32),
    Collapse(u32),
    SplitEdge(u32, f64),
    SplitFace(u32, f64, f64),
}

fn op_strategy() -> impl Strategy<Value = Op> {
    prop_oneof![
        1 => any::<u32>().prop_map(Op::Flip),
        // Collapses are weighted up so sequences really shrink the mesh.
        2 => any::<u32>().prop_map(Op::Collapse),
        1 => (any::<u32>(), 0.0..=1.0f64).prop_map(|(i, t)| Op::SplitEdge(i, t)),
        1 => (any::<u32>(), 0.0..=1.0f64, 0.0..=1.0f64).prop_map(|(i, s, t)| Op::SplitFace(i, s, t)),
    ]
}

fn pick<T: Copy>(items: &[T], i: u32) -> T {
    items[i as usize % items.len()]
}

/// Applies `op`; returns the expected face-count change, or `None` if it was refused (after
/// asserting the mesh is unchanged and the `can_*` check agreed).
fn apply(m: &mut Mesh, op: Op) -> Result<Option<i64>, TestCaseError> {
    let before = m.clone();
    let refused = |m: &Mesh| -> Result<Option<i64>, TestCaseError> {
        prop_assert!(m == &before, "a refused operator changed the mesh");
        prop_assert_eq!(m.to_triangles(), before.to_triangles());
        Ok(None)
    };
    match op {
        Op::Flip(i) => {
            let e: EdgeId = pick(&m.edges().collect::<Vec<_>>(), i);
            let allowed = m.can_flip(e).is_ok();
            match m.flip(e) {
                Ok(e2) => {
                    prop_assert!(allowed);
                    prop_assert_eq!(e2, e);
                    Ok(Some(0))
                }
                Err(_) => {
                    prop_assert!(!allowed);
                    refused(m)
                }
            }
        }
        Op::Collapse(i) => {
            let h: HalfedgeId = pick(&m.halfedges().collect::<Vec<_>>(), i);
            let allowed = m.can_collapse(h).is_ok();
            let (a, b) = (m.tail(h), m.head(h));
            let pb = m.position(b);
            match m.collapse(h) {
                Ok(c) => {
                    prop_assert!(allowed);
                    prop_assert_eq!((c.removed, c.survivor), (a, b));
                    prop_assert!(!m.is_vertex_alive(a) && m.is_vertex_alive(b));
                    prop_assert_eq!(m.position(b), pb);
                    for f in c.removed_faces {
                        prop_assert!(!m.is_face_alive(f));
                    }
                    // Callers place the survivor afterwards, e.g. at the midpoint.
                    m.set_position(b, 0.5 * (pb + before.position(a)));
                    Ok(Some(-2))
                }
                Err(_) => {
                    prop_assert!(!allowed);
                    refused(m)
                }
            }
        }
        Op::SplitEdge(i, t) => {
            let e: EdgeId = pick(&m.edges().collect::<Vec<_>>(), i);
            let s = m.split_edge(e, t);
            prop_assert_eq!(m.valence(s.new_vertex), 4);
            Ok(Some(2))
        }
        Op::SplitFace(i, s, t) => {
            let f: FaceId = pick(&m.faces().collect::<Vec<_>>(), i);
            let (s, t) = (s.min(t), s.max(t));
            let r = m.split_face(f, [s, t - s, 1.0 - t]);
            prop_assert_eq!(m.valence(r.new_vertex), 3);
            Ok(Some(2))
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn operators_keep_the_mesh_valid_and_the_topology_fixed(
        kind in 0u8..6,
        seed in any::<u64>(),
        ops in prop::collection::vec(op_strategy(), 1..60),
    ) {
        let mut m = start_mesh(kind, seed);
        m.validate().unwrap();
        let chi = m.euler_characteristic();
        let genus = m.genus();
        let components = m.components().0;
        for op in ops {
            let faces = m.n_faces() as i64;
            if let Some(delta) = apply(&mut m, op)? {
                prop_assert_eq!(m.n_faces() as i64, faces + delta, "{:?}", op);
            }
            if let Err(e) = m.validate() {
                return Err(TestCaseError::fail(format!("after {op:?}: {e}")));
            }
            prop_assert_eq!(m.euler_characteristic(), chi);
            prop_assert_eq!(2 * m.n_edges(), 3 * m.n_faces());
        }
        prop_assert_eq!(m.genus(), genus);
        prop_assert_eq!(m.components().0, components);

        // Round trip through plain buffers, and compaction, both preserve the surface.
        let buffers = m.to_triangles();
        let rebuilt = Mesh::from_triangles(buffers.0.clone(), &buffers.1)
            .map_err(|e| TestCaseError::fail(format!("round trip rejected: {e}")))?;
        prop_assert_eq!(rebuilt.to_triangles(), buffers.clone());
        let positions = m.positions().to_vec();
        let remap = m.compact();
        m.validate().unwrap();
        prop_assert_eq!(m.to_triangles(), buffers);
        prop_assert_eq!(remap.apply_to_vertex_data(&positions), m.positions().to_vec());
        // Same surface, though edge ids may differ (the builder numbers edges by vertex pair).
        prop_assert_eq!(rebuilt.n_edges(), m.n_edges());
    }

    #[test]
    fn collapsing_greedily_never_breaks_the_mesh(kind in 0u8..6, seed in any::<u64>()) {
        // Collapse as long as any half-edge allows it: the guards must stop at a valid minimum.
        let mut m = start_mesh(kind, seed);
        let chi = m.euler_characteristic();
        let mut progress = true;
        while progress {
            progress = false;
            let hs: Vec<_> = m.halfedges().collect();
            for h in hs {
                if m.is_halfedge_alive(h) && m.collapse(h).is_ok() {
                    progress = true;
                }
            }
            m.validate().map_err(|e| TestCaseError::fail(e.to_string()))?;
        }
        prop_assert_eq!(m.euler_characteristic(), chi);
        prop_assert!(m.vertices().all(|v| m.valence(v) >= 3));
        if chi == 2 {
            // A sphere stops at a tetrahedron: every collapse of it is refused.
            prop_assert_eq!(m.n_vertices(), 4);
        }
    }
}

#[test]
fn every_operator_succeeds_often_on_every_start_mesh() {
    // Guards the property tests above against vacuity: with a fixed seed, each operator kind
    // must actually apply on every kind of start mesh.
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for kind in 0..6u8 {
        let mut m = start_mesh(kind, 3);
        let chi = m.euler_characteristic();
        let mut applied = [0usize; 4];
        for step in 0..400 {
            let i: u32 = rng.random();
            let op = match step % 4 {
                0 => Op::Flip(i),
                1 => Op::Collapse(i),
                2 => Op::SplitEdge(i, rng.random()),
                _ => Op::SplitFace(i, rng.random(), rng.random()),
            };
            if apply(&mut m, op).unwrap().is_some() {
                applied[step % 4] += 1;
            }
        }
        m.validate().unwrap();
        assert_eq!(m.euler_characteristic(), chi);
        assert!(
            applied.iter().all(|&n| n >= 10),
            "kind {kind}: applied {applied:?}"
        );
    }
}
