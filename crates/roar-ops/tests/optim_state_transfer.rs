//! Optimizer rows follow the vertices through topology changes.

mod optim_common;

use glam::DVec3;
use optim_common::{noise, octahedron};
use roar_ops::optim::{OptimError, Optimizer, OptimizerOptions, VertexState};

fn row(x: f64) -> VertexState {
    VertexState {
        m1: DVec3::new(x, -x, 2.0 * x),
        m2: x * x + 1.0,
        nu: x,
    }
}

fn optimizer_with_rows(rows: &[VertexState]) -> Optimizer {
    let mut opt = Optimizer::new(rows.len(), OptimizerOptions::default()).unwrap();
    opt.state_mut().copy_from_slice(rows);
    opt
}

#[test]
fn face_split_gives_the_new_vertex_the_mean_of_the_corner_rows() {
    let mut opt = optimizer_with_rows(&[row(1.0), row(2.0), row(6.0), row(100.0)]);
    opt.on_face_split(4, [0, 1, 2]).unwrap();
    assert_eq!(opt.len(), 5);
    let r = opt.state()[4];
    assert!((r.m1 - DVec3::new(3.0, -3.0, 6.0)).length() < 1e-14);
    assert!((r.m2 - (2.0 + 5.0 + 37.0) / 3.0).abs() < 1e-14);
    assert!((r.nu - 3.0).abs() < 1e-14);
    // The corners are untouched.
    assert_eq!(opt.state()[..4], [row(1.0), row(2.0), row(6.0), row(100.0)]);
}

#[test]
fn apply_remap_permutes_and_drops_rows() {
    let mut opt = optimizer_with_rows(&[row(0.0), row(1.0), row(2.0), row(3.0), row(4.0)]);
    // Old 1 and 3 removed; the rest reversed.
    opt.apply_remap(&[2, u32::MAX, 1, u32::MAX, 0]).unwrap();
    assert_eq!(opt.state(), &[row(4.0), row(2.0), row(0.0)]);
}

#[test]
fn apply_remap_rejects_bad_maps_without_changing_anything() {
    let rows = [row(0.0), row(1.0), row(2.0)];
    let mut opt = optimizer_with_rows(&rows);
    assert!(matches!(
        opt.apply_remap(&[0, 0, 1]),
        Err(OptimError::RemapNotInjective {
            first: 0,
            second: 1,
            new: 0
        })
    ));
    assert!(matches!(
        opt.apply_remap(&[0, 1]),
        Err(OptimError::LengthMismatch { .. })
    ));
    assert_eq!(opt.state(), &rows);
    // Removing everything leaves no rows.
    opt.apply_remap(&[u32::MAX; 3]).unwrap();
    assert!(opt.is_empty());
}

#[test]
fn grow_adds_zeroed_rows_and_never_shrinks() {
    let mut opt = optimizer_with_rows(&[row(1.0), row(2.0)]);
    opt.grow(5);
    assert_eq!(opt.len(), 5);
    assert_eq!(opt.state()[..2], [row(1.0), row(2.0)]);
    assert!(
        opt.state()[2..]
            .iter()
            .all(|s| *s == VertexState::default())
    );
    opt.grow(1);
    assert_eq!(opt.len(), 5);
}

#[test]
fn transfers_do_not_reset_the_step_counter_and_stepping_continues() {
    let (mut positions, mut triangles) = octahedron(1.0);
    let mut opt = Optimizer::new(6, OptimizerOptions::default()).unwrap();
    for t in 0..3 {
        let g: Vec<DVec3> = (0..6).map(|v| noise(v, t)).collect();
        opt.step(&mut positions, &triangles, &g).unwrap();
    }
    // Split face 0 = (0, 2, 4) at its centroid, as the mesh would.
    let [a, b, c] = triangles[0];
    let m = positions.len() as u32;
    positions.push((positions[a as usize] + positions[b as usize] + positions[c as usize]) / 3.0);
    triangles[0] = [a, b, m];
    triangles.extend([[b, c, m], [c, a, m]]);
    opt.on_face_split(m, [a, b, c]).unwrap();
    let expected = VertexState::mean3(
        &opt.state()[a as usize],
        &opt.state()[b as usize],
        &opt.state()[c as usize],
    );
    assert_eq!(opt.state()[m as usize], expected);

    let g: Vec<DVec3> = (0..7).map(|v| noise(v, 9)).collect();
    let stats = opt.step(&mut positions, &triangles, &g).unwrap();
    assert_eq!(stats.step, 4);
    assert_eq!(stats.live_vertices, 7);
    assert!(positions.iter().all(|p| p.is_finite()));
}

#[test]
fn collapse_then_compaction_keeps_the_chosen_row() {
    let mut opt = optimizer_with_rows(&[row(0.0), row(1.0), row(2.0), row(3.0)]);
    // Collapse 1 into 2, keeping the removed vertex 1's placement.
    opt.on_collapse(2, 1).unwrap();
    opt.apply_remap(&[0, u32::MAX, 1, 2]).unwrap();
    assert_eq!(opt.state(), &[row(0.0), row(1.0), row(3.0)]);
}
