//! Every block, and random sequences of blocks, keep the mesh a valid closed 2-manifold with the
//! same Euler characteristic, and the optimizer rows in step with the vertices.

mod blocks_common;

use blocks_common::{assert_contract, random_mesh, tagged_optimizer};
use proptest::prelude::*;
use roar_mesh::spatial::SphereProjector;
use roar_ops::block::{Block, BlockContext};
use roar_ops::collapse_block::FaceCollapse;
use roar_ops::flips::EdgeFlips;
use roar_ops::smoothing::TangentialSmoothing;
use roar_ops::split_block::{FaceSplit, FaceSplitOptions, SplitThreshold};

fn blocks() -> Vec<Box<dyn Block>> {
    vec![
        Box::new(FaceCollapse::default()),
        Box::new(EdgeFlips::default()),
        Box::new(TangentialSmoothing::default()),
        Box::new(FaceSplit::default()),
        Box::new(FaceSplit {
            options: FaceSplitOptions {
                threshold: SplitThreshold::PerFace(0.02),
                ..FaceSplitOptions::default()
            },
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_block_sequences_keep_the_mesh_valid(
        kind in 0u8..4,
        jitter in 0.0f64..0.25,
        seed in 0u64..1000,
        sequence in proptest::collection::vec(0usize..5, 1..6),
        budget_offset in -60i64..60,
    ) {
        let mut mesh = random_mesh(kind, jitter, seed);
        let euler = mesh.euler_characteristic();
        let mut opt = tagged_optimizer(&mesh);
        let sphere = SphereProjector { center: roar_mesh::DVec3::ZERO, radius: 1.0 };
        let mut all = blocks();
        for (it, &i) in sequence.iter().enumerate() {
            let budget = (mesh.n_faces() as i64 + budget_offset).max(8) as usize;
            let ctx = BlockContext { iteration: it, face_budget: budget, projector: Some(&sphere) };
            let block = &mut all[i];
            let stats = block.apply(&mut mesh, &mut opt, &ctx);
            prop_assert_eq!(stats.name, block.name());
            assert_contract(&mesh, &opt, euler, block.name());
        }
    }
}

#[test]
fn face_split_without_projector_does_nothing() {
    let mut mesh = random_mesh(0, 0.0, 1);
    let before = mesh.clone();
    let mut opt = tagged_optimizer(&mesh);
    let ctx = BlockContext {
        iteration: 0,
        face_budget: 10_000,
        projector: None,
    };
    let stats = FaceSplit::default().apply(&mut mesh, &mut opt, &ctx);
    assert_eq!(stats.rejected.get("no_projector"), Some(&1));
    assert_eq!(mesh, before);
}
