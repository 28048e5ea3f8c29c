//! The optimizer step follows the authors' update rule exactly (`docs/method.md#optimizer`), and
//! it descends.

mod optim_common;

use glam::DVec3;
use optim_common::{cube_grid, noise, octahedron};
use roar_ops::optim::{
    OptimError, Optimizer, OptimizerOptions, VELOCITY_EPSILON, ulerp, ulerp_weights,
};

#[test]
fn ulerp_at_the_first_step_returns_the_new_value() {
    for beta in [0.0, 0.5, 0.8, 0.99] {
        assert_eq!(ulerp(123.0, 4.5, beta, 1), 4.5);
        assert_eq!(
            ulerp(DVec3::splat(7.0), DVec3::new(1.0, -2.0, 3.0), beta, 1),
            DVec3::new(1.0, -2.0, 3.0)
        );
    }
}

#[test]
fn ulerp_keeps_a_constant_input_constant() {
    for beta in [0.0, 0.3, 0.8, 0.999] {
        let mut x = 0.0;
        for t in 1..=200 {
            x = ulerp(x, 2.5, beta, t);
            assert!((x - 2.5).abs() < 1e-12, "beta {beta} t {t}: {x}");
        }
    }
}

#[test]
fn ulerp_matches_a_hand_computed_sequence() {
    // β = 0.8, inputs 1, 2, 4. Bias-corrected EMA = Σ (1−β) β^{t−k} b_k / (1 − β^t):
    // x1 = 1; x2 = (0.16·1 + 0.2·2) / 0.36 = 0.56/0.36; x3 = (0.128 + 0.32 + 0.8) / 0.488.
    let x1 = ulerp(0.0, 1.0, 0.8, 1);
    let x2 = ulerp(x1, 2.0, 0.8, 2);
    let x3 = ulerp(x2, 4.0, 0.8, 3);
    assert_eq!(x1, 1.0);
    assert!((x2 - 0.56 / 0.36).abs() < 1e-14, "{x2}");
    assert!((x3 - 1.248 / 0.488).abs() < 1e-14, "{x3}");
    // β = 0 is "no smoothing": the weights are (0, 1) at every step.
    for t in 1..5 {
        assert_eq!(ulerp_weights(0.0, t), (0.0, 1.0));
    }
}

/// A tetrahedron with distinct edge lengths (0.1, 0.2, 0.3 along the axes), plus a dead vertex
/// 4 that no triangle references.
fn tetrahedron_and_dead_vertex() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let positions = vec![
        DVec3::ZERO,
        DVec3::new(0.1, 0.0, 0.0),
        DVec3::new(0.0, 0.2, 0.0),
        DVec3::new(0.0, 0.0, 0.3),
        DVec3::new(5.0, 5.0, 5.0),
    ];
    let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    (positions, triangles)
}

#[test]
fn first_step_moves_each_vertex_by_ramped_rate_times_reference_length() {
    let (mut positions, triangles) = tetrahedron_and_dead_vertex();
    let before = positions.clone();
    let gradient: Vec<DVec3> = (0..5).map(|v| noise(v, 1) * 3.0).collect();
    let mut opt = Optimizer::new(5, OptimizerOptions::default()).unwrap();
    let stats = opt.step(&mut positions, &triangles, &gradient).unwrap();

    // η_1 = lr·min(1, 1·(1 − β1)/ramp) = 0.05·0.2; u = g/(‖g‖ + 1e-8), so ‖Δv‖ ≈ η_1·ℓ_v.
    let eta = 0.05 * 0.2;
    assert!((stats.learning_rate - eta).abs() < 1e-17);
    assert_eq!(stats.step, 1);
    assert_eq!(stats.live_vertices, 4);
    // ℓ_v: shortest incident edge, capped at 0.15.
    let reference_len = [0.1, 0.1, 0.15, 0.15];
    for v in 0..4 {
        let g = gradient[v];
        let expected = before[v] - eta * reference_len[v] * g / (g.length() + VELOCITY_EPSILON);
        assert!(
            (positions[v] - expected).length() < 1e-15,
            "vertex {v}: {:?} vs {expected:?}",
            positions[v]
        );
        let moved = (positions[v] - before[v]).length();
        assert!((moved - eta * reference_len[v]).abs() < 1e-9 * eta);
        let s = opt.state()[v];
        assert_eq!(s.m1, g, "m1 = g at t = 1");
        assert!((s.m2 - g.length_squared()).abs() < 1e-14);
        assert!((s.nu - 1.0).abs() < 1e-8, "ν = ‖u‖ ≈ 1");
    }
    assert!((stats.max_move - eta * 0.15).abs() < 1e-9 * eta);
    assert!((stats.mean_move - eta * 0.125).abs() < 1e-9 * eta);
    // The dead vertex keeps its position and zero state.
    assert_eq!(positions[4], before[4]);
    assert_eq!(opt.state()[4], Default::default());
}

#[test]
fn first_step_on_an_octahedron_uses_the_edge_length_until_the_cap() {
    for (radius, expected_len) in [(0.05, 0.05 * 2f64.sqrt()), (1.0, 0.15)] {
        let (mut positions, triangles) = octahedron(radius);
        let before = positions.clone();
        let gradient: Vec<DVec3> = (0..6).map(|v| noise(v, 7)).collect();
        let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
        let stats = opt.step(&mut positions, &triangles, &gradient).unwrap();
        for v in 0..6 {
            let moved = (positions[v] - before[v]).length();
            let g = gradient[v].length();
            let expected = 0.01 * expected_len * g / (g + VELOCITY_EPSILON);
            assert!(
                (moved - expected).abs() < 1e-15,
                "radius {radius} vertex {v}: moved {moved}"
            );
        }
        assert_eq!(stats.clamped_components, 0, "no clamping at t = 1");
    }
}

#[test]
fn learning_rate_ramps_up_over_five_steps() {
    let (mut positions, triangles) = octahedron(1.0);
    let gradient = vec![DVec3::X; 6];
    let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
    let rates: Vec<f64> = (0..7)
        .map(|_| {
            opt.step(&mut positions, &triangles, &gradient)
                .unwrap()
                .learning_rate
        })
        .collect();
    let expected = [0.01, 0.02, 0.03, 0.04, 0.05, 0.05, 0.05];
    for (got, want) in rates.iter().zip(expected) {
        assert!((got - want).abs() < 1e-15, "{rates:?}");
    }
    assert_eq!(opt.step_count(), 7);
}

/// Runs the note-6 scenario: first gradient (1, 0, 0), then (1, 1, 0); returns how far vertex
/// 0 moved in y, and the number of clamped components.
fn y_motion_after_a_late_nonzero_component(clamp_only_nonzero_m1: bool) -> (f64, usize) {
    let options = OptimizerOptions {
        laplacian_weight: 0.0,
        clamp_only_nonzero_m1,
        ..Default::default()
    };
    let (mut positions, triangles) = octahedron(1.0);
    let y0 = positions[0].y;
    let mut opt = Optimizer::new(6, options).unwrap();
    opt.step(&mut positions, &triangles, &[DVec3::X; 6])
        .unwrap();
    assert_eq!(positions[0].y, y0);
    let mut clamped = 0;
    for _ in 0..5 {
        let g = vec![DVec3::new(1.0, 1.0, 0.0); 6];
        clamped += opt
            .step(&mut positions, &triangles, &g)
            .unwrap()
            .clamped_components;
    }
    (positions[0].y - y0, clamped)
}

#[test]
fn a_component_whose_first_gradient_was_zero_still_moves_later() {
    let (dy, clamped) = y_motion_after_a_late_nonzero_component(true);
    assert!(
        dy < -0.01,
        "y must descend along the new gradient, moved {dy}"
    );
    assert_eq!(clamped, 0);
}

#[test]
fn reference_clamping_freezes_a_component_whose_first_gradient_was_zero() {
    let (dy, clamped) = y_motion_after_a_late_nonzero_component(false);
    assert_eq!(dy, 0.0, "authors' clamp: the y component stays frozen");
    assert_eq!(
        clamped,
        6 * 5,
        "the y component is clamped at every vertex and step"
    );
}

#[test]
fn gradient_clamp_limits_a_spike_to_ten_times_m1() {
    let options = OptimizerOptions {
        laplacian_weight: 0.0,
        ..Default::default()
    };
    let (mut positions, triangles) = octahedron(1.0);
    let mut opt = Optimizer::new(6, options).unwrap();
    opt.step(&mut positions, &triangles, &[DVec3::X; 6])
        .unwrap();
    let stats = opt
        .step(&mut positions, &triangles, &[DVec3::X * 1000.0; 6])
        .unwrap();
    assert_eq!(stats.clamped_components, 6);
    // g clamped to 10·|m1| = 10 → m1 = ulerp(1, 10, 0.8, 2) = (0.16 + 2) / 0.36.
    let m1 = opt.state()[0].m1.x;
    assert!((m1 - 2.16 / 0.36).abs() < 1e-12, "{m1}");
}

/// Height of the bumped vertex above the mean of its ring.
fn bump_height(positions: &[DVec3], triangles: &[[u32; 3]], bump: u32) -> f64 {
    let mut ring = std::collections::BTreeSet::new();
    for t in triangles.iter().filter(|t| t.contains(&bump)) {
        ring.extend(t.iter().copied().filter(|&u| u != bump));
    }
    let mean_z = ring.iter().map(|&u| positions[u as usize].z).sum::<f64>() / ring.len() as f64;
    positions[bump as usize].z - mean_z
}

/// Runs 60 steps on a cube grid whose top-face centre is bumped up by 0.1, with a small
/// tangential loss gradient (so ν > 0; small, because Adam-style normalization makes the
/// Laplacian's share of the move depend on its size relative to the loss gradient); returns the bump height before and after.
fn bump_after_steps(options: OptimizerOptions) -> (f64, f64) {
    let grid = cube_grid(4, 1.0);
    let (mut positions, triangles) = (grid.positions, grid.triangles);
    let bump = grid.lattice[&[2, 2, 4]];
    positions[bump as usize].z += 0.1;
    let before = bump_height(&positions, &triangles, bump);
    let gradient = vec![DVec3::new(1e-4, 0.0, 0.0); positions.len()];
    let mut opt = Optimizer::new(positions.len(), options).unwrap();
    for _ in 0..60 {
        opt.step(&mut positions, &triangles, &gradient).unwrap();
    }
    (before, bump_height(&positions, &triangles, bump))
}

#[test]
fn laplacian_term_flattens_a_bump_when_the_loss_is_tangential() {
    let (before, after) = bump_after_steps(OptimizerOptions::default());
    assert!((before - 0.1).abs() < 1e-12);
    assert!(after.abs() < 0.01, "bump height {before} → {after}");
}

#[test]
fn without_laplacian_weight_a_tangential_loss_leaves_the_bump() {
    let options = OptimizerOptions {
        laplacian_weight: 0.0,
        ..Default::default()
    };
    let (before, after) = bump_after_steps(options);
    assert_eq!(before, after);
}

#[test]
fn reference_clamping_also_blocks_the_laplacian_term() {
    // The Laplacian's z component is 0 at t = 1 (ν starts at 0), so the authors' clamp
    // freezes it: another reason to clamp only where m1 ≠ 0.
    let options = OptimizerOptions {
        clamp_only_nonzero_m1: false,
        ..Default::default()
    };
    let (before, after) = bump_after_steps(options);
    assert_eq!(before, after);
}

fn loss(positions: &[DVec3], targets: &[DVec3]) -> f64 {
    positions
        .iter()
        .zip(targets)
        .map(|(p, t)| p.distance_squared(*t))
        .sum()
}

#[test]
fn minimizing_distance_to_targets_converges_on_an_octahedron() {
    let (mut positions, triangles) = octahedron(1.0);
    let offset = DVec3::new(0.1, -0.05, 0.2);
    let targets: Vec<DVec3> = positions.iter().map(|p| *p * 1.2 + offset).collect();
    let initial = loss(&positions, &targets);
    let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
    let mut losses = vec![initial];
    for _ in 0..300 {
        let gradient: Vec<DVec3> = positions
            .iter()
            .zip(&targets)
            .map(|(p, t)| 2.0 * (*p - *t))
            .collect();
        opt.step(&mut positions, &triangles, &gradient).unwrap();
        losses.push(loss(&positions, &targets));
    }
    let last = *losses.last().unwrap();
    assert!(
        last < initial / 100.0,
        "loss {initial} → {last}; at 50/100/200: {} {} {}",
        losses[50],
        losses[100],
        losses[200]
    );
}

fn run(options: OptimizerOptions, n: i32, steps: u64) -> (Vec<DVec3>, Vec<[u64; 5]>) {
    let grid = cube_grid(n, 1.0);
    let (mut positions, triangles) = (grid.positions, grid.triangles);
    let mut opt = Optimizer::new(positions.len(), options).unwrap();
    for t in 0..steps {
        let gradient: Vec<DVec3> = (0..positions.len() as u64)
            .map(|v| noise(v, t) * 0.1)
            .collect();
        opt.step(&mut positions, &triangles, &gradient).unwrap();
    }
    let state = opt
        .state()
        .iter()
        .map(|s| {
            [
                s.m1.x.to_bits(),
                s.m1.y.to_bits(),
                s.m1.z.to_bits(),
                s.m2.to_bits(),
                s.nu.to_bits(),
            ]
        })
        .collect();
    (positions, state)
}

fn bits(positions: &[DVec3]) -> Vec<[u64; 3]> {
    positions
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

#[test]
fn same_inputs_give_bit_identical_outputs() {
    let (p1, s1) = run(OptimizerOptions::default(), 6, 40);
    let (p2, s2) = run(OptimizerOptions::default(), 6, 40);
    assert_eq!(bits(&p1), bits(&p2));
    assert_eq!(s1, s2);
}

#[test]
fn parallel_and_sequential_paths_are_bit_identical() {
    // 30×30 grid per face: 5402 vertices, more than one work chunk.
    let sequential = OptimizerOptions {
        parallel_min_vertices: usize::MAX,
        ..Default::default()
    };
    let parallel = OptimizerOptions {
        parallel_min_vertices: 0,
        ..Default::default()
    };
    let (p1, s1) = run(sequential, 30, 5);
    let (p2, s2) = run(parallel, 30, 5);
    assert!(p1.len() > 4096);
    assert_eq!(bits(&p1), bits(&p2));
    assert_eq!(s1, s2);
}

#[test]
fn nan_gradient_components_count_as_zero() {
    let (mut positions, triangles) = octahedron(1.0);
    let before = positions.clone();
    let mut gradient = vec![DVec3::X; 6];
    gradient[2] = DVec3::new(f64::NAN, 1.0, f64::INFINITY);
    let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
    let stats = opt.step(&mut positions, &triangles, &gradient).unwrap();
    assert_eq!(stats.nonfinite_components, 2);
    assert!(positions.iter().all(|p| p.is_finite()));
    assert_eq!(positions[2].x, before[2].x);
    assert!(positions[2].y < before[2].y);
}

#[test]
fn bad_inputs_are_errors_and_change_nothing() {
    let (mut positions, triangles) = octahedron(1.0);
    let before = positions.clone();
    let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
    let err = opt
        .step(&mut positions, &triangles, &[DVec3::X; 5])
        .unwrap_err();
    assert!(matches!(
        err,
        OptimError::LengthMismatch {
            what: "gradient",
            ..
        }
    ));
    let err = opt
        .step(&mut positions, &[[0, 1, 6]], &[DVec3::X; 6])
        .unwrap_err();
    assert!(matches!(
        err,
        OptimError::VertexIndexOutOfRange { vertex: 6, .. }
    ));
    let err = opt
        .step(&mut positions[..5], &triangles, &[DVec3::X; 5])
        .unwrap_err();
    assert!(matches!(
        err,
        OptimError::LengthMismatch {
            what: "positions",
            ..
        }
    ));
    assert_eq!(positions, before);
    assert_eq!(opt.step_count(), 0);
    assert!(opt.state().iter().all(|s| *s == Default::default()));
}

#[test]
fn invalid_options_are_rejected() {
    let bad = [
        OptimizerOptions {
            betas: (1.0, 0.8, 0.0),
            ..Default::default()
        },
        OptimizerOptions {
            lr: f64::NAN,
            ..Default::default()
        },
        OptimizerOptions {
            ramp: 0.0,
            ..Default::default()
        },
        OptimizerOptions {
            grad_lim: -1.0,
            ..Default::default()
        },
        OptimizerOptions {
            edge_len_max: 0.0,
            ..Default::default()
        },
    ];
    for options in bad {
        assert!(Optimizer::new(3, options).is_err(), "{options:?}");
    }
    let unlimited = OptimizerOptions {
        grad_lim: f64::INFINITY,
        edge_len_max: f64::INFINITY,
        ..Default::default()
    };
    assert!(Optimizer::new(3, unlimited).is_ok());
}
