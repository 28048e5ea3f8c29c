//! Every block, and random sequences of blocks, keep the mesh a valid closed 2-manifold with the
//! same Euler characteristic, and the optimizer rows in step with the vertices.

mod blocks_common;

use blocks_common::{assert_contract, random_mesh, tagged_optimizer};
use proptest::prelude::*;
use roar_mesh::spatial::{SphereProjector, count_intersecting_faces};
use roar_mesh::{Mesh, TrackedMesh};
use roar_ops::blocks::block::{Block, BlockContext};
use roar_ops::blocks::collapse::{FaceCollapse, FaceCollapseOptions};
use roar_ops::blocks::flips::{EdgeFlips, FlipOptions};
use roar_ops::blocks::smoothing::{SmoothingOptions, TangentialSmoothing};
use roar_ops::blocks::split::{FaceSplit, FaceSplitOptions, SplitThreshold};

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

/// The same blocks with the intersection guard on (flips inside Face Collapse too).
fn guarded_blocks() -> Vec<Box<dyn Block>> {
    let flips = FlipOptions {
        guard_intersections: true,
        ..FlipOptions::default()
    };
    vec![
        Box::new(FaceCollapse {
            options: FaceCollapseOptions {
                guard_intersections: true,
                flips: Some(flips),
                ..FaceCollapseOptions::default()
            },
        }),
        Box::new(EdgeFlips { options: flips }),
        Box::new(TangentialSmoothing {
            options: SmoothingOptions {
                guard_intersections: true,
                ..SmoothingOptions::default()
            },
        }),
        Box::new(FaceSplit {
            options: FaceSplitOptions {
                guard_intersections: true,
                ..FaceSplitOptions::default()
            },
        }),
        Box::new(FaceSplit {
            options: FaceSplitOptions {
                threshold: SplitThreshold::PerFace(0.02),
                guard_intersections: true,
                ..FaceSplitOptions::default()
            },
        }),
    ]
}

/// A jittered random mesh squashed along z to `thickness` of its height: the opposite walls
/// are a fraction of an edge apart, where collapses and smoothing moves cross them.
fn thin_mesh(kind: u8, thickness: f64, jitter: f64, seed: u64) -> Mesh {
    let mut mesh = random_mesh(kind, jitter, seed);
    for p in mesh.positions_mut() {
        p.z *= thickness;
    }
    mesh
}

/// Runs `sequence` of `blocks` on a thin mesh; returns the largest intersecting-face count seen
/// after a block, or `None` when the start mesh already intersects itself.
fn max_crossings(
    blocks: &mut [Box<dyn Block>],
    mesh: &mut Mesh,
    sequence: &[usize],
    budget_offset: i64,
) -> Option<usize> {
    if count_intersecting_faces(mesh) > 0 {
        return None;
    }
    let euler = mesh.euler_characteristic();
    let mut opt = tagged_optimizer(mesh);
    let sphere = SphereProjector {
        center: roar_mesh::DVec3::ZERO,
        radius: 1.0,
    };
    let mut worst = 0;
    for (it, &i) in sequence.iter().enumerate() {
        let budget = (mesh.n_faces() as i64 + budget_offset).max(8) as usize;
        let ctx = BlockContext {
            iteration: it,
            face_budget: budget,
            projector: Some(&sphere),
        };
        blocks[i].apply(&mut TrackedMesh::new(mesh, &mut opt), &ctx);
        assert_contract(mesh, &opt, euler, blocks[i].name());
        worst = worst.max(count_intersecting_faces(mesh));
    }
    Some(worst)
}

/// The thin meshes of the guarded test do make the unguarded blocks cross (so the guarded test
/// is not vacuous).
#[test]
fn unguarded_blocks_cross_thin_meshes() {
    let mut crossed = 0;
    for seed in 0..12 {
        let mut mesh = thin_mesh(seed as u8, 0.02, 0.1, seed);
        let sequence = [0, 2, 3, 0, 2, 4, 0, 1, 2];
        let worst = max_crossings(&mut blocks(), &mut mesh, &sequence, -40);
        assert!(
            worst.is_some(),
            "seed {seed}: the start mesh intersects itself"
        );
        crossed += worst.is_some_and(|w| w > 0) as usize;
    }
    assert!(crossed >= 4, "only {crossed} of 12 thin meshes crossed");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn guarded_blocks_never_make_a_clean_mesh_intersect_itself(
        kind in 0u8..4,
        thickness in 0.02f64..0.1,
        jitter in 0.0f64..0.15,
        seed in 0u64..1000,
        sequence in proptest::collection::vec(0usize..5, 1..8),
        budget_offset in -60i64..60,
    ) {
        let mut mesh = thin_mesh(kind, thickness, jitter, seed);
        let worst = max_crossings(&mut guarded_blocks(), &mut mesh, &sequence, budget_offset);
        prop_assume!(worst.is_some());
        prop_assert_eq!(worst, Some(0));
    }

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
            let stats = block.apply(&mut TrackedMesh::new(&mut mesh, &mut opt), &ctx);
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
    let stats = FaceSplit::default().apply(&mut TrackedMesh::new(&mut mesh, &mut opt), &ctx);
    assert_eq!(stats.rejected.get("no_projector"), Some(&1));
    assert_eq!(mesh, before);
}
