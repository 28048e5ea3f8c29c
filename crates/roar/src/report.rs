//! What a run reports: its figures per stage, as the JSON report lists them.

use std::collections::BTreeMap;

use roar_ops::finish::best_state::UntangleFailure;
use roar_ops::finish::genus::RemovedHandle;
use serde::Serialize;

/// Summary of one run, for the JSON report, grouped by stage as the config is.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RunStats {
    /// Seconds per stage, in first-run order of stage names (sorted by name in JSON).
    pub seconds: BTreeMap<String, f64>,
    /// What the target preparation made (the `[target]` stage).
    pub target: TargetReport,
    /// The initial mesh M0 (the `[init]` stage).
    pub init: InitReport,
    /// The loop at the working budget (the `[optimize]` stage).
    pub optimize: OptimizeReport,
    /// From the loop's mesh to exactly N faces (the `[finish]` stage).
    pub finish: FinishReport,
}

/// What the target preparation made (the `[target]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct TargetReport {
    /// Faces of the cleaned target T′.
    pub target_faces: usize,
    /// Twins dropped by the pixel-count rule.
    pub twins_dropped: usize,
    /// Point cloud size (with sharp-edge samples).
    pub point_cloud: usize,
}

/// The initial mesh M0 (the `[init]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct InitReport {
    /// Faces of the voxel surface before any decimation.
    pub init_voxel_faces: usize,
    /// Faces of M0 after QEM to ≤ init_max_faces.
    pub init_faces: usize,
    /// Components (pieces) of M0.
    pub init_components: usize,
    /// Genus of M0 (kept to the end unless `handles_removed` says otherwise).
    pub init_genus: usize,
    /// Voxels the init's enclosure rule turned solid (punctures closed;
    /// `roar_ops::init::InitOptions::enclosure_winding_threshold`; for scan sets also the
    /// voxels hidden from every scanner, `roar_ops::init::InitOptions::scanner_views`).
    pub init_voxels_filled_by_winding: usize,
    /// Regions the winding-number rule left open, their cap too wide for a puncture
    /// (`roar_ops::init::InitOptions::enclosure_max_cap_fraction`).
    pub init_enclosures_left_open: usize,
    /// Patches of the soup (faces joined across two-face edges) the enclosure rule oriented,
    /// each to face the side it is seen from, before taking the winding number.
    pub init_winding_patches: usize,
    /// Of those, the patches it turned over.
    pub init_winding_patches_flipped: usize,
    /// Pieces of the init's solid, counted on its voxels before nearby ones were merged for the
    /// face budget (`roar::budget::pieces_to_aim_for`; 0 for inits that do not count them).
    pub init_pieces_before_merge: usize,
    /// Radius, in voxels, of the closing that merged them (0: none).
    pub init_merge_radius_voxels: usize,
    /// Pieces dropped, smallest first, because even merged they were too many for the budget
    /// (`roar::budget::most_pieces`).
    pub init_pieces_dropped_for_budget: usize,
}

/// The loop at the working budget (the `[optimize]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct OptimizeReport {
    /// The working budget W.
    pub working_budget: usize,
    /// Loss at the first and last iteration.
    pub loss_first: f64,
    /// See `loss_first`.
    pub loss_last: f64,
    /// Loss, its terms and the face count at every iteration.
    pub history: Vec<IterationRecord>,
    /// Iterations the loop ran: `iterations`, or fewer when the loss levelled off
    /// (`level_window`).
    pub loop_iterations: usize,
    /// Faces after the optimization loop.
    pub loop_faces: usize,
    /// Accepted operations per block over the loop, by block name.
    pub block_accepted: BTreeMap<&'static str, usize>,
    /// Vertex steps the step limiter shortened or cancelled over the loop.
    pub steps_shortened: usize,
    /// Loss of the loop's last state (evaluated once more after the last iteration; NaN, null
    /// in the report, when no checkpoint was kept to compare it with).
    pub loss_of_last_state: f64,
    /// The iteration whose starting state the run finished from (`loop_iterations` for the
    /// state after the last one): the lowest-loss state of the checkpoints and the last one
    /// that the untangle block could clear (`checkpoint_interval`).
    pub finished_from_iteration: usize,
    /// States with a lower loss that the untangle block could not clear, in the order tried.
    pub untangle_failures: Vec<UntangleFailure>,
}

/// From the loop's mesh to exactly N faces (the `[finish]` stage).
#[derive(Debug, Clone, Default, Serialize)]
pub struct FinishReport {
    /// Untangle statistics.
    pub untangle_initial_pairs: usize,
    /// Rounds the untangle block needed.
    pub untangle_rounds: usize,
    /// Collapses of the finish's QEMs (to 2N first when the mesh has more faces, see
    /// `finish_budgets`, then to N).
    pub final_collapses: usize,
    /// Edge splits used to fill up to N.
    pub fill_splits: usize,
    /// Vertices moved the whole `final_qem_offset` before the finish's QEMs, summed (the others
    /// were shortened or kept where a full move would have made faces intersect).
    pub offset_vertices: usize,
    /// Vertex moves of the tangential smoothing after the finish's QEMs, summed
    /// (`final_smoothing_sweeps`; 0 also when the smoothed mesh was dropped because it would
    /// have intersected itself).
    pub final_smoothing_moves: usize,
    /// Data-dependent flips after the finish's QEMs, summed (`data_flip_rounds`; 0 also when the
    /// flipped mesh was dropped because it would have intersected itself).
    pub data_flips: usize,
    /// Loss, terms and faces at every polish iteration (after each of the finish's QEMs).
    pub polish_history: Vec<IterationRecord>,
    /// Whether the last polished mesh was kept (false: it intersected itself, or no polish ran;
    /// true also when its best state was the unpolished one).
    pub polish_kept: bool,
    /// Vertices far off the field's zero set collapsed before its fit (`fin_distance_over_edge`;
    /// SDF inputs only; 0 also when the step was dropped because the mesh would have
    /// intersected itself).
    pub fin_collapses: usize,
    /// Vertices the fit to the field's zero set moved the whole way (`zero_set_steps`; SDF
    /// inputs only; 0 also when the moved mesh was dropped because it would have intersected
    /// itself).
    pub zero_set_fitted: usize,
    /// Vertices that step held back, wholly or in part (a long move, a face turned over, an
    /// intersection).
    pub zero_set_held: usize,
    /// Vertices the fairing found unsupported (`fair_distance_over_edge`; 0 also when the
    /// faired mesh was dropped because it would have intersected itself).
    pub fair_free: usize,
    /// Of those, the vertices moved the whole way to their faired position.
    pub fair_faired: usize,
    /// Sliver flips in the output (`sliver_quality`; 0 also when they were undone because the
    /// written mesh would have intersected itself).
    pub sliver_flips: usize,
    /// Edge collapses that removed degenerate faces no flip could, each followed by an edge
    /// split to keep the face count (0 also when undone, as `sliver_flips`).
    pub degenerate_collapses: usize,
    /// Handles the finish removed so the budget could be met (shortest loop first, in order;
    /// empty with `keep_topology`): the output's genus is `init_genus` minus their number.
    pub handles_removed: Vec<RemovedHandle>,
}

/// One iteration of the optimize stage, as the report lists it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct IterationRecord {
    /// The loss before the step.
    pub loss: f64,
    /// The weighted value of each term of the loss (empty for a one-term loss).
    pub terms: BTreeMap<&'static str, f64>,
    /// Faces when the loss was evaluated.
    pub faces: usize,
}
