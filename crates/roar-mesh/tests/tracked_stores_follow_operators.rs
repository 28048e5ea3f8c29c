//! Property tests: random operator sequences (collapses, edge and face splits, flips,
//! compactions) made through a [`TrackedMesh`] keep the half-edge invariants, and a
//! [`VertexStore`] notified by them follows the mesh: it always has one row per vertex slot,
//! and the row of every live vertex is the position the store derived from the outcome
//! records alone (a collapse's survivor keeps its own; a split's new vertex gets its parents'
//! weighted mean), which must be the vertex's position in the mesh.

use proptest::prelude::*;
use roar_mesh::{
    Collapse, DVec3, EdgeSplit, FaceSplitOutcome, Mesh, NoStore, Remap, TrackedMesh, VertexStore,
    shapes,
};

/// A store whose row per vertex slot is where it believes the vertex is, plus call counts.
#[derive(Default)]
struct Positions {
    rows: Vec<DVec3>,
    calls: [usize; 4],
}

impl VertexStore for Positions {
    fn on_grow(&mut self, vertex_slots: usize) {
        if vertex_slots > self.rows.len() {
            self.rows.resize(vertex_slots, DVec3::NAN);
        }
    }

    fn on_collapse(&mut self, _collapse: &Collapse) {
        // The survivor keeps its position, and so its row.
        self.calls[0] += 1;
    }

    fn on_edge_split(&mut self, split: &EdgeSplit) {
        let [a, b] = split.parents.map(|v| self.rows[v.index()]);
        self.rows[split.new_vertex.index()] = a + (b - a) * split.t;
        self.calls[1] += 1;
    }

    fn on_face_split(&mut self, split: &FaceSplitOutcome) {
        let [a, b, c] = split.parents.map(|v| self.rows[v.index()]);
        self.rows[split.new_vertex.index()] =
            a * split.bary[0] + b * split.bary[1] + c * split.bary[2];
        self.calls[2] += 1;
    }

    fn on_compact(&mut self, remap: &Remap) {
        self.rows = remap.apply_to_vertex_data(&self.rows);
        self.calls[3] += 1;
    }
}

fn start_mesh(kind: u8, seed: u64) -> Mesh {
    match kind % 3 {
        0 => shapes::perturbed(&shapes::icosphere(2), 0.02, seed),
        1 => shapes::perturbed(&shapes::torus(9, 5, 1.0, 0.3), 0.01, seed),
        _ => shapes::perturbed(&shapes::genus_n_solid(2), 0.02, seed),
    }
}

#[derive(Debug, Clone, Copy)]
enum Op {
    Flip(u32),
    Collapse(u32),
    SplitEdge(u32, f64),
    SplitFace(u32, f64, f64),
    Compact,
}

fn op_strategy() -> impl Strategy<Value = Op> {
    prop_oneof![
        1 => any::<u32>().prop_map(Op::Flip),
        2 => any::<u32>().prop_map(Op::Collapse),
        1 => (any::<u32>(), 0.05..=0.95f64).prop_map(|(i, t)| Op::SplitEdge(i, t)),
        1 => (any::<u32>(), 0.1..=0.45f64, 0.55..=0.9f64).prop_map(|(i, s, t)| Op::SplitFace(i, s, t)),
        1 => Just(Op::Compact),
    ]
}

fn pick<T: Copy>(items: impl Iterator<Item = T>, i: u32) -> T {
    let items: Vec<T> = items.collect();
    items[i as usize % items.len()]
}

fn apply(mesh: &mut TrackedMesh, op: Op) {
    match op {
        Op::Flip(i) => {
            let e = pick(mesh.edges(), i);
            let _ = mesh.with_fixed_vertices(|mesh| mesh.flip(e));
        }
        Op::Collapse(i) => {
            let h = pick(mesh.halfedges(), i);
            let _ = mesh.collapse(h);
        }
        Op::SplitEdge(i, t) => {
            let e = pick(mesh.edges(), i);
            mesh.split_edge(e, t);
        }
        Op::SplitFace(i, s, t) => {
            let f = pick(mesh.faces(), i);
            mesh.split_face(f, [s, t - s, 1.0 - t]);
        }
        Op::Compact => {
            mesh.compact();
        }
    }
}

/// Every live vertex's row is its position (up to the rounding of the two weighted means).
fn rows_follow(mesh: &Mesh, store: &Positions) -> Result<(), TestCaseError> {
    prop_assert_eq!(store.rows.len(), mesh.vertex_capacity());
    for v in mesh.vertices() {
        let (row, p) = (store.rows[v.index()], mesh.position(v));
        prop_assert!(
            row.distance(p) <= 1e-12 * (1.0 + p.length()),
            "{v:?}: {row} vs {p}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn a_store_follows_every_operator_and_compaction(
        kind in 0u8..3,
        seed in any::<u64>(),
        ops in prop::collection::vec(op_strategy(), 1..80),
    ) {
        let mut mesh = start_mesh(kind, seed);
        let mut store = Positions {
            rows: mesh.positions().to_vec(),
            ..Positions::default()
        };
        let chi = mesh.euler_characteristic();
        for op in ops {
            apply(&mut TrackedMesh::new(&mut mesh, &mut store), op);
            if let Err(e) = mesh.validate() {
                return Err(TestCaseError::fail(format!("after {op:?}: {e}")));
            }
            prop_assert_eq!(mesh.euler_characteristic(), chi);
            rows_follow(&mesh, &store)?;
        }
        TrackedMesh::new(&mut mesh, &mut store).compact();
        prop_assert_eq!(mesh.vertex_capacity(), mesh.n_vertices());
        rows_follow(&mesh, &store)?;
    }
}

#[test]
fn every_kind_of_notification_happens() {
    // Guards the property test against vacuity: with fixed choices, each notification fires.
    let mut mesh = start_mesh(0, 7);
    let mut store = Positions {
        rows: mesh.positions().to_vec(),
        ..Positions::default()
    };
    let ops = (0..200u32).map(|i| match i % 5 {
        0 => Op::Collapse(i.wrapping_mul(2_654_435_761)),
        1 => Op::SplitEdge(i.wrapping_mul(40_503), 0.3),
        2 => Op::SplitFace(i.wrapping_mul(97), 0.2, 0.7),
        3 => Op::Flip(i.wrapping_mul(31)),
        _ => Op::Compact,
    });
    for op in ops {
        apply(&mut TrackedMesh::new(&mut mesh, &mut store), op);
    }
    mesh.validate().unwrap();
    rows_follow(&mesh, &store).unwrap();
    assert!(store.calls.iter().all(|&n| n >= 20), "{:?}", store.calls);
}

#[test]
#[should_panic(expected = "changed the vertex set")]
fn an_untracked_collapse_is_caught() {
    let mut mesh = shapes::icosphere(1);
    let mut store = NoStore;
    let mut tracked = TrackedMesh::new(&mut mesh, &mut store);
    let h = tracked.halfedges().next().unwrap();
    tracked.with_fixed_vertices(|mesh| mesh.collapse(h).unwrap());
}
