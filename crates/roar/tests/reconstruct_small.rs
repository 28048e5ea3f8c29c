//! The pipeline at toy settings (few views, low resolution, few iterations), fast enough for the
//! default test run: its promises hold and it is deterministic.

use roar::{InitKind, PipelineError, ReconstructConfig, Reconstruction, RunStats, ScheduledBlock};
use roar_mesh::shapes::torus;
use roar_mesh::spatial::self_intersecting_faces;
use roar_mesh::{Mesh, TrackedMesh};
use roar_ops::blocks::block::{Block, BlockContext, BlockStats};

mod common;

fn toy_config(faces: usize) -> ReconstructConfig {
    common::toy_config(faces, 6)
}

fn run(config: ReconstructConfig) -> (Vec<glam::DVec3>, Vec<[u32; 3]>, usize) {
    let (positions, triangles, stats) = run_with(config, Vec::new());
    (positions, triangles, stats.init.init_components)
}

/// Runs the toy pipeline with `extra` blocks scheduled after the default ones.
fn run_with(
    config: ReconstructConfig,
    extra: Vec<ScheduledBlock>,
) -> (Vec<glam::DVec3>, Vec<[u32; 3]>, RunStats) {
    let soup = roar::example::chair_soup();
    let config_iterations = config.optimize.iterations;
    let (polish_iterations, faces) = (config.finish.polish_iterations, config.faces);
    let mut stages = Vec::new();
    let mut reconstruction = Reconstruction::new(config);
    reconstruction.blocks.extend(extra);
    let out = reconstruction
        .run_soup(&soup.positions, &soup.triangles, &mut |p| {
            stages.push(p.stage)
        })
        .unwrap();
    for stage in ["target", "init", "optimize", "decimate"] {
        assert!(stages.contains(&stage), "progress never reported {stage}");
    }
    // The report's history has one record per iteration run whose terms add up to the loss.
    let ran = out.stats.optimize.loop_iterations;
    assert!(ran <= config_iterations);
    assert_eq!(out.stats.optimize.history.len(), ran);
    for record in &out.stats.optimize.history {
        let names: Vec<&str> = record.terms.keys().copied().collect();
        assert_eq!(names, ["planar", "render"]);
        let sum: f64 = record.terms.values().sum();
        assert!((sum - record.loss).abs() <= 1e-12 * record.loss.abs().max(1.0));
    }
    // One polish per QEM of the finish: at 2N first when the loop's mesh had more faces than
    // that, then at exactly the budget.
    let stages: &[usize] = if out.stats.optimize.loop_faces > 2 * faces {
        &[2 * faces, faces]
    } else {
        &[faces]
    };
    let expected: Vec<usize> = stages
        .iter()
        .flat_map(|&n| std::iter::repeat_n(n, polish_iterations))
        .collect();
    let polished: Vec<usize> = out
        .stats
        .finish
        .polish_history
        .iter()
        .map(|r| r.faces)
        .collect();
    assert_eq!(polished, expected);
    (out.positions, out.triangles, out.stats)
}

/// Throws every vertex to a pseudo-random point of the unit box once, at one iteration: a
/// tangle of crossings far beyond what the untangle block can resolve.
struct Scramble {
    at_iteration: usize,
}

impl Block for Scramble {
    fn name(&self) -> &'static str {
        "scramble"
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, ctx: &BlockContext) -> BlockStats {
        let mut stats = BlockStats::new(self.name());
        if ctx.iteration == self.at_iteration {
            let mut state = 0x9E37_79B9_7F4A_7C15u64;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            mesh.with_fixed_vertices(|mesh| {
                for p in mesh.positions_mut() {
                    *p = glam::DVec3::new(next(), next(), next());
                }
            });
            stats.accepted = mesh.n_vertices();
        }
        stats
    }
}

#[test]
fn a_tangle_made_in_the_loop_is_never_the_state_the_run_finishes_from() {
    let config = {
        let mut config = toy_config(300);
        config.optimize.checkpoint_interval = 2;
        config
    };
    // Scrambled at iteration 4, after the state of iteration 4 was kept: every later state is
    // a tangle with a high loss (and one the untangle cannot clear).
    let scramble = ScheduledBlock {
        block: Box::new(Scramble { at_iteration: 4 }),
        every: 1,
        skip_first: false,
    };
    let (positions, triangles, stats) = run_with(config, vec![scramble]);
    assert!(
        stats.optimize.finished_from_iteration <= 4,
        "finished from the tangled state of iteration {}",
        stats.optimize.finished_from_iteration
    );
    assert_eq!(triangles.len(), 300);
    let mesh = Mesh::from_triangles(positions.clone(), &triangles).unwrap();
    mesh.validate().unwrap();
    assert!(mesh.signed_volume() > 0.0);
    assert!(!self_intersecting_faces(&positions, &triangles).contains(&true));
}

#[test]
fn the_loop_stops_once_its_loss_has_levelled_off() {
    let config = |level_window| {
        let mut config = toy_config(300);
        config.optimize.iterations = 20;
        config.optimize.checkpoint_interval = 2;
        config.optimize.level_window = level_window;
        config
    };
    // Scrambled at iteration 4: no later state comes near the loss before it, so the window of
    // 4 iterations after that brings nothing and the loop stops at the checkpoint of iteration
    // 8 (or earlier, had the toy's loss levelled off before the scramble).
    let scramble = || ScheduledBlock {
        block: Box::new(Scramble { at_iteration: 4 }),
        every: 1,
        skip_first: false,
    };
    let (_, triangles, stats) = run_with(config(4), vec![scramble()]);
    assert!(
        stats.optimize.loop_iterations <= 9,
        "{}",
        stats.optimize.loop_iterations
    );
    assert!(stats.optimize.finished_from_iteration <= 4);
    assert_eq!(triangles.len(), 300);
    // Without the window it runs every iteration.
    let (_, _, stats) = run_with(config(0), vec![scramble()]);
    assert_eq!(stats.optimize.loop_iterations, 20);
}

#[test]
fn toy_reconstruction_is_closed_exact_and_intersection_free() {
    for init in [InitKind::Watertight, InitKind::Sphere] {
        let (positions, triangles, init_components) = run({
            let mut config = toy_config(300);
            config.init.kind = init;
            config
        });
        assert_eq!(triangles.len(), 300, "{init:?}");
        let mesh = Mesh::from_triangles(positions.clone(), &triangles).unwrap();
        mesh.validate().unwrap();
        assert!(mesh.signed_volume() > 0.0);
        assert!(mesh.components().0 <= init_components);
        assert!(!self_intersecting_faces(&positions, &triangles).contains(&true));
    }
}

/// The bits of every coordinate.
fn bits(p: &[glam::DVec3]) -> Vec<u64> {
    p.iter()
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .collect()
}

#[test]
fn same_input_config_and_seed_give_the_same_bits() {
    let a = run(toy_config(200));
    let b = run(toy_config(200));
    assert_eq!(a.1, b.1);
    assert_eq!(bits(&a.0), bits(&b.0));
}

#[test]
fn the_output_does_not_depend_on_the_number_of_threads() {
    let in_pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(toy_config(200)))
    };
    let (one, two) = (in_pool(1), in_pool(2));
    assert_eq!(one.1, two.1);
    assert_eq!(bits(&one.0), bits(&two.0));
}

#[test]
fn the_final_mesh_is_smoothed_at_the_budget_without_intersections() {
    let (positions, triangles, stats) = run_with(toy_config(300), Vec::new());
    assert!(
        stats.finish.final_smoothing_moves > 0,
        "the final sweeps moved nothing"
    );
    assert_eq!(triangles.len(), 300);
    assert!(!self_intersecting_faces(&positions, &triangles).contains(&true));
}

// The budget is always met: when the genus needs more faces than N, the finish removes handles
// (and says so in the stats), unless `keep_topology` asks for the QEM's named error.

fn torus_soup() -> (Vec<glam::DVec3>, Vec<[u32; 3]>) {
    torus(32, 12, 1.0, 0.4).to_triangles()
}

#[test]
fn a_torus_asked_for_fewer_faces_than_its_genus_allows_loses_its_handle() {
    let (positions, triangles) = torus_soup();
    // A genus-1 surface needs at least 14 faces; 12 is a sphere's budget.
    let out = Reconstruction::new(toy_config(12))
        .run_soup(&positions, &triangles, &mut |_| {})
        .unwrap();
    assert_eq!(out.stats.init.init_genus, 1);
    assert_eq!(out.stats.finish.handles_removed.len(), 1);
    assert!(out.stats.finish.handles_removed[0].loop_length > 0.0);
    assert_eq!(out.triangles.len(), 12);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    mesh.validate().unwrap();
    assert_eq!((mesh.genus(), mesh.components().0), (0, 1));
    assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
}

#[test]
fn a_budget_the_genus_allows_keeps_the_handle() {
    let (positions, triangles) = torus_soup();
    let out = Reconstruction::new(toy_config(200))
        .run_soup(&positions, &triangles, &mut |_| {})
        .unwrap();
    assert!(out.stats.finish.handles_removed.is_empty());
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    assert_eq!((mesh.n_faces(), mesh.genus()), (200, 1));
}

#[test]
fn keep_topology_fails_with_the_named_error_instead() {
    let (positions, triangles) = torus_soup();
    let config = {
        let mut config = toy_config(12);
        config.finish.keep_topology = true;
        config
    };
    // The budget is checked against the init's pieces and genera right after the init, so
    // the run fails in seconds, naming the torus's smallest budget (14), not after the loop.
    let err = Reconstruction::new(config)
        .run_soup(&positions, &triangles, &mut |_| {})
        .err()
        .expect("12 faces cannot hold a torus");
    let message = err.to_string();
    assert!(
        matches!(err, PipelineError::Config(_))
            && message.contains("below the smallest reachable budget, 14 faces"),
        "{message}"
    );
}

#[test]
fn a_hole_in_a_soup_is_filled_by_the_fairing_and_the_output_keeps_its_promises() {
    // A torus soup with the faces around a point of its outer equator removed: the cap the loop
    // spans across that hole lies far from every input face, so the finish fairs it.
    let (positions, triangles) = torus_soup();
    let centre = glam::DVec3::new(1.4, 0.0, 0.0);
    let kept: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| {
            let c = t
                .iter()
                .map(|&v| positions[v as usize])
                .sum::<glam::DVec3>()
                / 3.0;
            c.distance(centre) > 0.3
        })
        .collect();
    assert!(kept.len() < triangles.len());
    let out = Reconstruction::new(toy_config(300))
        .run_soup(&positions, &kept, &mut |_| {})
        .unwrap();
    let finish = &out.stats.finish;
    assert!(finish.fair_free > 0, "no vertex was far from the soup");
    assert!(
        finish.fair_faired > 0,
        "{} free, none faired",
        finish.fair_free
    );
    assert_eq!(out.triangles.len(), 300);
    let mesh = Mesh::from_triangles(out.positions.clone(), &out.triangles).unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.genus(), 1);
    assert!(!self_intersecting_faces(&out.positions, &out.triangles).contains(&true));
}
