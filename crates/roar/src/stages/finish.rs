//! The finish stage: the lowest-loss loop state the untangle block clears, filled to N; the
//! final QEMs (to 2N and polish first when the mesh is larger), each followed by smoothing,
//! data flips and the polish; for a soup the fairing of what lies far from T′; for an SDF input
//! the fin collapses and the fit to the field's zero set; then sliver flips. Every step after
//! the QEMs goes through [`keep_if_clean`]: it is kept only if the mesh stays free of
//! self-intersections in the input's coordinates, where it will be written.

use std::convert::Infallible;

use glam::DVec3;
use roar_loss::{KnnPlanarProjector, Loss};
use roar_mesh::Mesh;
use roar_mesh::spatial::{Normalization, Sdf, TriangleBvh, self_intersecting_faces};
use roar_ops::blocks::smoothing::SmoothingOptions;
use roar_ops::decimate::{DecimateOptions, DecimateStats, decimate};
use roar_ops::finish::best_state::{
    BestStateOptions, Candidate, finish_from_best_state as finish_from_best_state_of,
};
use roar_ops::finish::data_flips::{DataFlipOptions, flip_toward_target};
use roar_ops::finish::degenerate::{DegenerateOptions, collapse_degenerate_faces};
use roar_ops::finish::exact_budget::{ExactBudgetOptions, decimate_to_exact_budget};
use roar_ops::finish::fair::{FairOptions, FairStats, fair_free_vertices, vertices_far_from};
use roar_ops::finish::fill::fill_to_budget;
use roar_ops::finish::fins::{FinOptions, collapse_fins};
use roar_ops::finish::offset::offset_outward;
use roar_ops::finish::slivers::{SliverOptions, flip_slivers};
use roar_ops::finish::zero_set::{ZeroSetOptions, ZeroSetStats, fit_to_zero_set};
use roar_ops::untangle::UntangleOptions;

use crate::config::ReconstructConfig;
use crate::error::PipelineError;
use crate::report::RunStats;
use crate::run::{Run, StageClock};
use crate::stages::optimize::{LoopState, move_vertices, new_optimizer};

/// Finishes from the loop's `states` with `loss` (dropped before the sliver flips), the
/// cloud's `projector` (for the data flips) and the shape's `field`, if it has one; returns the
/// final mesh in rig coordinates.
pub(crate) fn finish(
    states: Vec<LoopState>,
    mut loss: Box<dyn Loss>,
    projector: &KnnPlanarProjector,
    field: Option<&dyn Sdf>,
    surface: Option<(&[DVec3], &[[u32; 3]])>,
    normalization: &Normalization,
    run: &mut Run,
) -> Result<Mesh, PipelineError> {
    let config = run.config;
    loss.set_iteration(config.optimize.iterations);
    let faces = states.last().map_or(0, |state| state.mesh.n_faces());
    run.report(
        "finish",
        config.optimize.iterations,
        run.stats.optimize.loss_last,
        faces,
    )?;
    let mut mesh = finish_from_best_state(states, field, config, &mut run.stats)?;
    run.clock.lap("untangle");

    run.report(
        "decimate",
        config.optimize.iterations,
        run.stats.optimize.loss_last,
        mesh.n_faces(),
    )?;
    let polishing = config.optimize.iterations > 0 && config.finish.polish_iterations > 0;
    for faces in finish_budgets(mesh.n_faces(), config.faces, polishing) {
        let stats = &mut run.stats;
        if polishing && config.finish.final_qem_offset > 0.0 {
            stats.finish.offset_vertices +=
                offset_outward(&mut mesh, config.finish.final_qem_offset);
            run.clock.lap("offset");
        }
        let decimated = final_decimation(&mut mesh, faces, config, stats)?;
        stats.finish.final_collapses += decimated.collapses;
        run.clock.lap("final_qem");

        if config.optimize.iterations > 0 && config.finish.final_smoothing_sweeps > 0 {
            mesh = smooth_if_clean(mesh, normalization, config, stats);
            run.clock.lap("final_smoothing");
        }

        if config.optimize.iterations > 0 && config.finish.data_flip_rounds > 0 {
            mesh = flip_toward_cloud_if_clean(mesh, projector, normalization, config, stats);
            run.clock.lap("data_flips");
        }

        // No Move Vertices step at all with `iterations = 0`: that run is the plain init + QEM.
        if polishing {
            run.report(
                "polish",
                config.optimize.iterations,
                run.stats.optimize.loss_last,
                mesh.n_faces(),
            )?;
            mesh = polish(
                mesh,
                loss.as_mut(),
                normalization,
                config,
                &mut run.stats,
                &mut run.clock,
            )?;
        }
    }
    drop(loss);
    if let Some(surface) = surface
        && config.optimize.iterations > 0
        && config.finish.fair_distance_over_edge > 0.0
        && field.is_none()
    {
        mesh = fair_unsupported_if_clean(mesh, surface, normalization, config, &mut run.stats);
        run.clock.lap("fair");
    }
    if let Some(field) = field
        && config.optimize.iterations > 0
        && (config.finish.zero_set_steps > 0 || config.finish.fin_distance_over_edge > 0.0)
    {
        mesh = fit_to_zero_set_if_clean(mesh, field, normalization, config, &mut run.stats);
        run.clock.lap("zero_set");
    }
    if config.optimize.iterations > 0 && config.finish.sliver_quality > 0.0 {
        mesh = remove_slivers_if_clean(mesh, normalization, config, &mut run.stats);
        run.clock.lap("sliver_flips");
    }
    Ok(mesh)
}

/// The lowest-loss loop state that fills to N and untangles
/// ([`roar_ops::finish::best_state`]), with its figures recorded in `stats`.
fn finish_from_best_state(
    states: Vec<LoopState>,
    field: Option<&dyn Sdf>,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<Mesh, PipelineError> {
    let candidates = states
        .into_iter()
        .map(|state| Candidate {
            mesh: state.mesh,
            loss: state.loss,
            iteration: state.iteration,
        })
        .collect();
    let options = BestStateOptions {
        faces: config.faces,
        untangle: untangle_options(config),
        field_epsilon: config.loss.sdf_loss_epsilon,
    };
    let (result, best) = match finish_from_best_state_of(candidates, field, &options) {
        Ok((mesh, best)) => (Ok(mesh), best),
        Err(best) => (
            Err(PipelineError::Intersections(best.fill.unresolved_faces)),
            best,
        ),
    };
    stats.finish.fill_splits = best.fill.fill_splits;
    stats.finish.untangle_initial_pairs = best.fill.untangle_initial_pairs;
    stats.finish.untangle_rounds = best.fill.untangle_rounds;
    stats.optimize.untangle_failures = best.failures;
    if result.is_ok() {
        stats.optimize.finished_from_iteration = best.iteration;
    }
    result
}

/// The untangle block's options under `config` (its separation margin).
fn untangle_options(config: &ReconstructConfig) -> UntangleOptions {
    UntangleOptions {
        margin_rel: config.finish.untangle_margin,
        ..UntangleOptions::default()
    }
}

/// The face counts the finish decimates to, each followed by a polish: `[2N, N]` when the
/// polished mesh has more than 2N faces, otherwise `[N]`.
///
/// Why: below N = 2500 the working budget stays at its floor (5000), so the final QEM would
/// remove most of the faces in one go, placing vertices from the working mesh's quadrics alone.
/// Decimating to 2N first (where the working budget would be without the floor) and polishing
/// there puts the mesh back on the target before the last halving. Measured at N = 1000
/// (Chamfer/diag, one step → two): gpytoolbox-airplane 2.18e-3 → 2.05e-3, manifoldplus-chair
/// 3.51e-3 → 3.12e-3, manifoldplus-table 3.29e-3 → 3.18e-3, luke-f-16 1.82e-3 → 1.78e-3,
/// libigl-camelhead 2.95e-3 → 3.00e-3; normal cosine better on all seven meshes tried.
fn finish_budgets(faces: usize, budget: usize, polishing: bool) -> Vec<usize> {
    if polishing && faces > 2 * budget {
        vec![2 * budget, budget]
    } else {
        vec![budget]
    }
}

/// The guaranteed QEM to exactly `faces` (best effort only if configured), removing handles
/// unless `keep_topology` ([`roar_ops::finish::exact_budget`]); the handles removed are recorded
/// in `stats.handles_removed`.
fn final_decimation(
    mesh: &mut Mesh,
    faces: usize,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Result<DecimateStats, PipelineError> {
    let options = ExactBudgetOptions {
        decimate: DecimateOptions {
            best_effort: config.finish.best_effort,
            ..DecimateOptions::default()
        },
        keep_topology: config.finish.keep_topology,
        untangle: untangle_options(config),
    };
    let reached = decimate_to_exact_budget(mesh, faces, &options, decimate)?;
    stats.finish.handles_removed.extend(reached.handles_removed);
    Ok(reached.decimate)
}

/// `config.final_smoothing_sweeps` sweeps of tangential smoothing with every move limited so
/// that no face pair starts to intersect, kept only if the result is free of self-intersections
/// in the input's coordinates, where it will be written (as for the polish and the sliver
/// flips).
fn smooth_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let options = SmoothingOptions {
        guard_intersections: true,
        ..SmoothingOptions::default()
    };
    let (mesh, moves) = keep_if_clean(mesh, normalization, |smoothed| {
        (0..config.finish.final_smoothing_sweeps)
            .map(|_| roar_ops::blocks::smoothing::tangential_smoothing(smoothed, &options).accepted)
            .sum()
    });
    stats.finish.final_smoothing_moves += moves;
    mesh
}

/// `config.data_flip_rounds` rounds of data-dependent flips toward the normals of the point cloud
/// (the normal of the cloud point nearest to each sample), kept only if the result is free of
/// self-intersections in the input's coordinates, as for the smoothing.
fn flip_toward_cloud_if_clean(
    mesh: Mesh,
    cloud: &KnnPlanarProjector,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let target_normal = |p: DVec3| {
        cloud
            .nearest(p, 1)
            .first()
            .map(|&(i, _)| cloud.normals()[i as usize])
    };
    let options = DataFlipOptions {
        max_rounds: config.finish.data_flip_rounds,
        ..DataFlipOptions::default()
    };
    let (mesh, flips) = keep_if_clean(mesh, normalization, |flipped| {
        flip_toward_target(flipped, &target_normal, &options).accepted
    });
    stats.finish.data_flips += flips;
    mesh
}

/// The mesh with the vertices farther from the target `surface` than `fair_distance_over_edge`
/// times their mean edge length faired (`roar_ops::finish::fair`), kept only if the result is
/// free of self-intersections in the input's coordinates, as for the smoothing.
fn fair_unsupported_if_clean(
    mut mesh: Mesh,
    surface: (&[DVec3], &[[u32; 3]]),
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let bvh = TriangleBvh::build(surface.0, surface.1);
    let near = |p, reach| bvh.closest_point_within(p, reach).is_some();
    let free = vertices_far_from(&mut mesh, near, config.finish.fair_distance_over_edge);
    let mut faired = FairStats::default();
    let (mesh, changed) = keep_if_clean(mesh, normalization, |moved| {
        faired = fair_free_vertices(moved, &free, &FairOptions::default());
        faired.free
    });
    if changed > 0 {
        stats.finish.fair_free = faired.free;
        stats.finish.fair_faired = faired.faired;
    }
    mesh
}

/// The mesh with its fins collapsed (`roar_ops::finish::fins`, the face count restored by edge
/// splits) and fitted to `field`'s zero set (`roar_ops::finish::zero_set`), kept only if the
/// result is free of self-intersections in the input's coordinates, as for the smoothing.
fn fit_to_zero_set_if_clean(
    mesh: Mesh,
    field: &dyn Sdf,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let fin_options = FinOptions {
        max_distance_over_edge: config.finish.fin_distance_over_edge,
        epsilon: config.loss.sdf_loss_epsilon,
        ..FinOptions::default()
    };
    let fit_options = ZeroSetOptions {
        steps: config.finish.zero_set_steps,
        epsilon: config.loss.sdf_loss_epsilon,
        ..ZeroSetOptions::default()
    };
    let mut collapsed = 0;
    let mut fit = ZeroSetStats::default();
    let (mesh, changed) = keep_if_clean(mesh, normalization, |moved| {
        if fin_options.max_distance_over_edge > 0.0 {
            let faces = moved.n_faces();
            collapsed = collapse_fins(moved, field, &fin_options).accepted;
            fill_to_budget(moved, faces);
        }
        if fit_options.steps > 0 {
            fit = fit_to_zero_set(moved, field, &fit_options);
        }
        collapsed + fit.fitted + fit.shortened
    });
    if changed > 0 {
        stats.finish.fin_collapses = collapsed;
        stats.finish.zero_set_fitted = fit.fitted;
        stats.finish.zero_set_held = fit.shortened + fit.unmoved;
    }
    mesh
}

/// `config.polish_iterations` Move Vertices steps on the final mesh, with a fresh optimizer, a
/// learning rate falling linearly to 0 (a constant rate leaves the vertices jittering by about
/// η·ℓ_v, which on a converged mesh is all a step does) and no blocks, so the face count and
/// topology stay. Keeps the evaluated state with the lowest loss (the given mesh is state 0, so
/// the polish never raises the loss), through [`try_keep_if_clean`] (the step limiter makes
/// a clean result the rule, but may leave faces closer than the untangle margin, and undoing
/// the normalization rounds); otherwise returns the mesh it was given.
fn polish(
    mesh: Mesh,
    loss: &mut dyn Loss,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
    clock: &mut StageClock,
) -> Result<Mesh, PipelineError> {
    let steps = config.finish.polish_iterations;
    let (mesh, kept) = try_keep_if_clean(mesh, normalization, |polished| {
        let mut current = polished.clone();
        let mut optimizer = new_optimizer(&current, config)?;
        let mut best: Option<(f64, Mesh)> = None;
        for k in 0..steps {
            let mut options = *optimizer.options();
            options.lr = config.optimize.learning_rate * (steps - k) as f64 / steps as f64;
            optimizer.set_options(options)?;
            let before = current.clone();
            let record = move_vertices(
                &mut current,
                &mut optimizer,
                loss,
                config,
                stats,
                clock,
                "polish",
            )?;
            if best.as_ref().is_none_or(|(l, _)| record.loss < *l) {
                best = Some((record.loss, before));
            }
            stats.finish.polish_history.push(record);
        }
        // One change: the mesh became its best state (possibly the state it started from).
        Ok::<_, PipelineError>(best.map_or(0, |(_, best)| {
            *polished = best;
            1
        }))
    })?;
    clock.lap("polish_check");
    stats.finish.polish_kept = kept > 0;
    Ok(mesh)
}

/// The sliver flips of `roar_ops::finish::slivers` on the final mesh; then, for the degenerate faces
/// they leave, the collapses of `roar_ops::finish::degenerate`, the face count restored by edge splits
/// ([`fill_to_budget`], which moves no geometry), and the flips once more. Kept only if the result is
/// free of self-intersections in the input's coordinates, where it will be written (everything
/// is checked exactly in the normalized ones; undoing the normalization rounds).
fn remove_slivers_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    config: &ReconstructConfig,
    stats: &mut RunStats,
) -> Mesh {
    let options = SliverOptions {
        max_quality: config.finish.sliver_quality,
        ..SliverOptions::default()
    };
    let (mut flips, mut collapses) = (0, 0);
    let (mesh, changes) = keep_if_clean(mesh, normalization, |cleaned| {
        flips = flip_slivers(cleaned, &options).accepted;
        let faces = cleaned.n_faces();
        collapses = collapse_degenerate_faces(cleaned, &DegenerateOptions::default()).accepted;
        if collapses > 0 {
            fill_to_budget(cleaned, faces);
            flips += flip_slivers(cleaned, &options).accepted;
        }
        flips + collapses
    });
    if changes > 0 {
        stats.finish.sliver_flips = flips;
        stats.finish.degenerate_collapses = collapses;
    }
    mesh
}

/// The finish's one pattern for a step that must not make the output intersect itself: runs
/// `step` on a copy of `mesh` (`step` returns how many changes it made) and returns the copy
/// and that count if it is positive and the copy is free of self-intersections in the input's
/// coordinates ([`clean_in_output_coordinates`]); otherwise `mesh` as it was and 0. A step
/// that fails leaves `mesh` dropped and returns its error.
fn try_keep_if_clean<E>(
    mesh: Mesh,
    normalization: &Normalization,
    step: impl FnOnce(&mut Mesh) -> Result<usize, E>,
) -> Result<(Mesh, usize), E> {
    let mut changed = mesh.clone();
    let changes = step(&mut changed)?;
    if changes == 0 || !clean_in_output_coordinates(&changed, normalization) {
        return Ok((mesh, 0));
    }
    Ok((changed, changes))
}

/// [`try_keep_if_clean`] for a step that cannot fail.
fn keep_if_clean(
    mesh: Mesh,
    normalization: &Normalization,
    step: impl FnOnce(&mut Mesh) -> usize,
) -> (Mesh, usize) {
    let kept = try_keep_if_clean(mesh, normalization, |mesh| Ok::<_, Infallible>(step(mesh)));
    match kept {
        Ok(kept) => kept,
        Err(never) => match never {},
    }
}

/// Whether `mesh`, with the normalization undone (as it will be written), is free of
/// self-intersections: the exact checks ran in normalized coordinates, and undoing the
/// normalization rounds.
fn clean_in_output_coordinates(mesh: &Mesh, normalization: &Normalization) -> bool {
    let (mut positions, triangles) = mesh.to_triangles();
    normalization.invert_all(&mut positions);
    !self_intersecting_faces(&positions, &triangles).contains(&true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use roar_mesh::EdgeId;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::Aabb;
    use roar_mesh::spatial::count_intersecting_faces;
    use roar_mesh::spatial::triangle_quality;
    use roar_ops::finish::best_state::fill_and_untangle;
    use roar_ops::finish::fill::bisects_well;
    use roar_ops::geometry::{DEGENERATE_QUALITY, is_degenerate};

    /// Faces at or above [`DEGENERATE_QUALITY`].
    fn degenerate_faces(mesh: &Mesh) -> usize {
        mesh.faces()
            .filter(|&f| {
                let corners = mesh.face_vertices(f).map(|v| mesh.position(v));
                is_degenerate(triangle_quality(corners), DEGENERATE_QUALITY)
            })
            .count()
    }

    #[test]
    fn the_finish_halves_through_2n_only_from_above_2n_and_when_polishing() {
        assert_eq!(finish_budgets(5000, 1000, true), vec![2000, 1000]);
        assert_eq!(finish_budgets(2000, 1000, true), vec![1000]);
        assert_eq!(finish_budgets(10000, 5000, true), vec![5000]);
        assert_eq!(finish_budgets(5000, 1000, false), vec![1000]);
    }

    #[test]
    fn the_last_stage_removes_a_needle_and_keeps_the_face_count() {
        let mut mesh = icosphere(3);
        let e = mesh.edges().next().unwrap();
        // Splitting an edge next to its end makes two needles (aspect ratio far above 100).
        mesh.split_edge(e, 1e-3);
        mesh.compact();
        let faces = mesh.n_faces();
        assert_eq!(degenerate_faces(&mesh), 2);
        let mut stats = RunStats::default();
        let config = ReconstructConfig::default();
        let mesh = remove_slivers_if_clean(mesh, &Normalization::IDENTITY, &config, &mut stats);
        assert_eq!(stats.finish.degenerate_collapses, 1, "{stats:?}");
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert_eq!(degenerate_faces(&mesh), 0);
        assert_eq!(count_intersecting_faces(&mesh), 0);
    }

    #[test]
    fn the_fill_splits_no_edge_of_a_needle_even_when_it_is_the_longest() {
        // A spike makes the edges at one vertex the longest of the mesh; a needle planted on
        // one of them (split next to the spike's tip) borders the longest edges.
        let mut mesh = icosphere(1);
        let tip = mesh.vertices().next().unwrap();
        mesh.set_position(tip, 1.6 * mesh.position(tip));
        let spoke = mesh
            .edges()
            .find(|&e| mesh.edge_vertices(e)[0] == tip)
            .unwrap();
        mesh.split_edge(spoke, 1e-4);
        assert_eq!(degenerate_faces(&mesh), 2);
        let longest = mesh
            .edges()
            .max_by(|&a, &b| mesh.edge_length(a).total_cmp(&mesh.edge_length(b)))
            .unwrap();
        assert!(!bisects_well(&mesh, longest), "the setup lost its point");

        let faces = mesh.n_faces() + 20;
        let splits = fill_to_budget(&mut mesh, faces);
        assert_eq!(splits, 10);
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert_eq!(degenerate_faces(&mesh), 2, "a split made a degenerate face");
    }

    /// Two unit icospheres whose centres are `distance` apart, as one mesh of two pieces.
    fn two_spheres(distance: f64) -> Mesh {
        let (mut positions, mut triangles) = icosphere(2).to_triangles();
        let n = positions.len() as u32;
        let moved: Vec<DVec3> = positions.iter().map(|p| *p + DVec3::X * distance).collect();
        let shifted: Vec<[u32; 3]> = triangles.iter().map(|t| t.map(|v| v + n)).collect();
        positions.extend(moved);
        triangles.extend(shifted);
        Mesh::from_triangles(positions, &triangles).unwrap()
    }

    #[test]
    fn untangling_that_collapses_edges_is_filled_back_to_the_budget() {
        // Slivers on the first sphere where it crosses the second: the untangle block collapses
        // crossing slivers at once instead of moving them.
        let mut mesh = two_spheres(1.9);
        let centre = DVec3::X * 1.9;
        let inside = |p: DVec3| (p - centre).length() < 1.0;
        let crossing: Vec<EdgeId> = mesh
            .edges()
            .filter(|&e| {
                let [a, b] = mesh.edge_vertices(e).map(|v| mesh.position(v));
                a.x < 1.0 && inside(a) != inside(b)
            })
            .collect();
        assert!(!crossing.is_empty());
        for e in crossing {
            mesh.split_edge(e, 0.02);
        }
        let faces = mesh.n_faces();
        let config = ReconstructConfig {
            faces,
            ..ReconstructConfig::default()
        };
        let options = BestStateOptions {
            faces,
            untangle: untangle_options(&config),
            field_epsilon: config.loss.sdf_loss_epsilon,
        };
        let stats = fill_and_untangle(&mut mesh, None, &options);
        assert_eq!(stats.unresolved_faces, 0);
        // The mesh started at the budget, so every split refilled a face the untangle removed.
        assert!(stats.untangle_initial_pairs > 0);
        assert!(stats.fill_splits > 0, "the untangle collapsed nothing");
        mesh.validate().unwrap();
        assert_eq!(mesh.n_faces(), faces);
        assert!(count_intersecting_faces(&mesh) == 0);
    }

    #[test]
    fn the_offset_before_the_final_qem_moves_outward_without_crossing() {
        // Two spheres 1e-3 apart: the offset (2e-3 of the 4.9 diagonal here, 1e-2 each) would
        // push them into each other where they nearly touch, so those moves are shortened or
        // cancelled; everywhere else every vertex moves the whole way along its normal.
        let mut mesh = two_spheres(2.001);
        let before = mesh.clone();
        let moved = offset_outward(&mut mesh, 2e-3);
        mesh.validate().unwrap();
        assert_eq!(count_intersecting_faces(&mesh), 0);
        assert!(moved < mesh.n_vertices() && moved > mesh.n_vertices() * 9 / 10);
        let diagonal = Aabb::from_points(before.positions().iter().copied())
            .unwrap()
            .diagonal();
        let mut full = 0;
        for v in mesh.vertices() {
            let centre = if before.position(v).x < 1.0005 {
                DVec3::ZERO
            } else {
                DVec3::X * 2.001
            };
            let grown =
                (mesh.position(v) - centre).length() - (before.position(v) - centre).length();
            assert!(
                grown >= -1e-12 && grown <= 2e-3 * diagonal * (1.0 + 1e-9),
                "{grown}"
            );
            if grown > 2e-3 * diagonal * 0.999 {
                full += 1;
            }
        }
        assert_eq!(full, moved);
    }

    #[test]
    fn the_run_finishes_from_the_lowest_loss_state_the_untangle_clears() {
        // Two copies of one tetrahedron on top of each other, every face overlapping its copy
        // and no edge collapsible: a tangle the untangle cannot clear, with the lowest loss.
        let corners = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let faces = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let copy = faces.map(|f: [u32; 3]| f.map(|v| v + 4));
        let tangle = Mesh::from_triangles(corners.repeat(2), &[faces, copy].concat()).unwrap();
        let state = |iteration, loss, mesh: &Mesh| LoopState {
            iteration,
            loss,
            mesh: mesh.clone(),
        };
        let apart = two_spheres(3.0);
        let states = vec![
            state(0, 3.0, &apart),
            state(10, 1.0, &tangle),
            state(20, 2.0, &apart),
            state(30, 2.0, &apart),
        ];
        let config = ReconstructConfig {
            faces: apart.n_faces(),
            ..ReconstructConfig::default()
        };
        let mut stats = RunStats::default();
        let mesh = finish_from_best_state(states, None, &config, &mut stats).unwrap();
        assert_eq!(stats.optimize.untangle_failures.len(), 1);
        assert_eq!(stats.optimize.untangle_failures[0].iteration, 10);
        assert!(stats.optimize.untangle_failures[0].unresolved_faces > 0);
        // Of the two clean states with the next lowest loss, the later one.
        assert_eq!(stats.optimize.finished_from_iteration, 30);
        assert_eq!(mesh.n_faces(), apart.n_faces());
        assert_eq!(count_intersecting_faces(&mesh), 0);
    }
}
