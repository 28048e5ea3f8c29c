//! The reconstruction's configuration: every hyper-parameter of the spec with the paper's
//! default, each documented with the section of `spec/roar-method.md` it comes from. A TOML
//! file overrides any subset (unknown keys are errors); the CLI's flags override the file.

use roar_io::PatchOptions;
use roar_loss::planar::{DEFAULT_MAX_SAMPLES, DEFAULT_T2S_MAX_POINTS, RECONSTRUCTION_PLANAR_SCALE};
use roar_loss::{
    KnnOptions, PlanarOptions, PointCloudOptions, SdfLossOptions, SharpEdgeOptions, TargetOptions,
};
use roar_ops::blocks::collapse::FaceCollapseOptions;
use roar_ops::blocks::split::DEFAULT_SPLIT_THRESHOLD;
use roar_ops::finish::data_flips::DataFlipOptions;
use roar_ops::finish::fins::FinOptions;
use roar_ops::finish::slivers::SliverOptions;
use roar_ops::finish::zero_set::ZeroSetOptions;
use roar_ops::init::{
    ENCLOSURE_MAX_CAP_FRACTION, ENCLOSURE_WINDING_THRESHOLD, InitialMeshOptions, SdfInitOptions,
};
use roar_ops::optim::OptimizerOptions;
use roar_ops::untangle::UntangleOptions;
use roar_sdf::{SdfProjectorOptions, TraceOptions};
use serde::{Deserialize, Serialize};

/// Declares one table of the configuration, each field once: its doc, name, type, default and,
/// for a numeric field, its allowed range (`range(min, max)`: `min ..= max`; `zero_or(min, max)`:
/// 0 as well, meaning "off"; booleans and enums have none). Derives the struct (every key
/// optional, unknown keys refused, the fields in the order written, which is the TOML's), its
/// `Default` and its `field_ranges`, the ranges named `table.field` as the messages name them.
macro_rules! config_table {
    (
        $(#[$meta:meta])*
        pub struct $name:ident($table:literal) {
            $(
                $(#[$field_meta:meta])*
                $field:ident: $ty:ty = $default:expr $(, $kind:ident($min:expr, $max:expr))?;
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct $name {
            $(
                $(#[$field_meta])*
                #[doc = ""]
                #[doc = concat!(
                    "Default: `", stringify!($default), "`",
                    $("; allowed: `", stringify!($kind($min, $max)), "`",)?
                    "."
                )]
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    $($field: $default,)*
                }
            }
        }

        impl $name {
            /// Every numeric field of the table with its allowed range and its current value,
            /// in declaration order.
            pub fn field_ranges(&self) -> Vec<(FieldRange, f64)> {
                vec![
                    $($(
                        (
                            field_range!(
                                $kind,
                                concat!($table, ".", stringify!($field)),
                                $min,
                                $max
                            ),
                            RangeValue::range_value(self.$field),
                        ),
                    )?)*
                ]
            }
        }
    };
}

/// The [`FieldRange`] of a `range(min, max)` or `zero_or(min, max)` declaration.
macro_rules! field_range {
    (range, $name:expr, $min:expr, $max:expr) => {
        FieldRange::new($name, $min, $max)
    };
    (zero_or, $name:expr, $min:expr, $max:expr) => {
        FieldRange::zero_or($name, $min, $max)
    };
}

/// A numeric field's value as its range compares it.
trait RangeValue {
    fn range_value(self) -> f64;
}

impl RangeValue for f64 {
    fn range_value(self) -> f64 {
        self
    }
}

impl RangeValue for u32 {
    fn range_value(self) -> f64 {
        f64::from(self)
    }
}

impl RangeValue for usize {
    fn range_value(self) -> f64 {
        self as f64
    }
}

/// The enclosure rule's threshold for scan sets (`enclosure_winding_threshold` of
/// `ReconstructConfig::scan_defaults`), below the
/// soups' `roar_ops::init::ENCLOSURE_WINDING_THRESHOLD` (0.7) because scans leave wider
/// openings: four bunny scans around its side (bun000, bun090, bun180, bun270; top and base
/// unscanned) give an init of genus 1 at 0.7 (a tunnel from top to base) and of genus 0 at 0.6
/// and 0.5.
pub const SCAN_ENCLOSURE_WINDING_THRESHOLD: f64 = 0.6;

/// How the initial mesh M0 is made (spec §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitKind {
    /// The input shape's own initial mesh (`Shape::initial_mesh`): for a soup the watertight
    /// voxel init of the cleaned target, in the manner of Manifold (§4.1).
    Watertight,
    /// An icosphere of radius 0.5 (§4.2); its genus is 0, so holes of the input are lost.
    Sphere,
}

/// Every knob of `roar reconstruct`, grouped by the pipeline stage that reads it: the TOML file
/// has the tables `[target]`, `[init]`, `[loss]`, `[optimize]` and `[finish]` (`--print-config`
/// prints them all). Where a field's doc names its default (or `docs/method.md` does), the unit
/// test `documented_defaults` checks that the code agrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReconstructConfig {
    /// Exact face count of the output (even). §1.1 "face budget B".
    pub faces: usize,
    /// Seed of every random choice (§10: seed 43).
    pub seed: u64,
    /// The target T′ (§3.1): the rig it is rendered with, its point cloud, and how scans and
    /// signed distances are read into it.
    pub target: TargetConfig,
    /// The initial mesh M0 (§4).
    pub init: InitConfig,
    /// The loss the loop minimises (§3.2).
    pub loss: LossConfig,
    /// The loop (§1.2): Move Vertices and its blocks, at the working budget.
    pub optimize: OptimizeConfig,
    /// From the loop's mesh to exactly N faces (§1.2 step 7 and the steps after it).
    pub finish: FinishConfig,
}

impl Default for ReconstructConfig {
    fn default() -> Self {
        Self {
            faces: 5000,
            seed: 43,
            target: TargetConfig::default(),
            init: InitConfig::default(),
            loss: LossConfig::default(),
            optimize: OptimizeConfig::default(),
            finish: FinishConfig::default(),
        }
    }
}

config_table! {
    /// `[target]`
    pub struct TargetConfig("target") {
        /// Views per axis of the star rig: n² views (§3.2.1: 6 → 36). Default 5 (25 views); 6 in
        /// the SDF and scan schedules. [INF] Fewer views than the paper: each loop iteration
        /// renders 31 % fewer pixels and the loop levels off sooner, for a Chamfer distance within
        /// 0.2 % (median) of 36 views on the wild meshes (`docs/method.md`, "The rig has 25 views").
        views_per_axis: usize = 5, range(1.0, 32.0);
        /// Render resolution in pixels (§3.2.1: 512).
        render_resolution: u32 = TargetOptions::default().resolution, range(16.0, 4096.0);
        /// Keep both twins of a soup face unless one has this many times more pixels (§3.1 a: 80).
        twin_ratio: f64 = TargetOptions::default().twin_ratio, range(1.0, 1e6);
        /// Target point cloud samples (§3.1 b: 200k).
        point_cloud_samples: usize = PointCloudOptions::default().samples, range(100.0, 5e7);
        /// Keep target samples whose winding number at p + 1e-3·n is below this (§3.1 b, OQ-14).
        winding_threshold: f64 = PointCloudOptions::default().winding_threshold, range(1e-6, 1.0);
        /// Target samples on a sheet (a face of T′ whose reversed twin is kept too: an open surface
        /// or a zero-thickness part) stand off it by this much along their normal, relative to the
        /// bounding-box diagonal, so the two sides of the closed output each get their own plane
        /// instead of jamming against each other on one (0 = off). [INF] Not in the paper; the
        /// value is the offset CGAL's alpha wrap is run with in the evaluation (`roar_loss::
        /// point_cloud` explains the jam; at 5000 faces the normal cosine rose on every sheet of the
        /// evaluation, the Chamfer distance grew on closely fitted ones: `docs/method.md`, "Sheets get
        /// one plane per side").
        sheet_offset: f64 = 1e-3, range(0.0, 0.1);
        /// Sharp-edge samples from the init (§3.1 c: 30k).
        sharp_edge_samples: usize = SharpEdgeOptions::default().samples, range(0.0, 5e7);
        /// Range scans: a patch triangle with an edge longer than this many times the local grid
        /// spacing bridges a depth jump and is dropped (`roar_io::PatchOptions::max_edge_factor`,
        /// where the default is measured).
        scan_max_edge_factor: f64 = PatchOptions::default().max_edge_factor, range(1.0, 1e3);
        /// Range scans: a patch triangle whose normal is more than this many degrees from the
        /// direction to the scanner is dropped (`roar_io::PatchOptions::max_angle_degrees`).
        scan_max_angle_degrees: f64 = PatchOptions::default().max_angle_degrees, range(1.0, 90.0);
        /// Range scans: refine the `.conf` poses by ICP (`roar_ops::align`); `--no-icp` turns it off.
        scan_icp: bool = true;
        /// Cells of the grid that brackets the zero set for an SDF input's traced target renders
        /// (`roar_sdf::trace`): features thinner than about one cell can be missed.
        sdf_trace_grid: usize = TraceOptions::default().grid_resolution, range(2.0, 2048.0);
        /// Regula falsi steps per traced pixel of an SDF input.
        sdf_trace_refine_steps: usize = TraceOptions::default().refine_steps, range(0.0, 100.0);
        /// First-order steps of an SDF input's projections: the Face Split projector (§3.4 C: 5)
        /// and the point-cloud samples.
        sdf_projection_steps: usize = SdfProjectorOptions::default().steps, range(1.0, 100.0);
        /// A projected sample of an SDF input is valid when its first-order distance `|f|/|∇f|` ends
        /// at most this, in rig units (§3.4 C: 1e-6 for float64 fields; f32 networks need more).
        sdf_projection_tolerance: f64 = SdfProjectorOptions::default().tolerance, range(1e-12, 1.0);
    }
}

config_table! {
    /// `[init]`
    pub struct InitConfig("init") {
        /// Initial mesh (§4).
        kind: InitKind = InitKind::Watertight;
        /// Voxels along the longest axis of the watertight init (replaces Manifold's octree
        /// resolution, OQ-12). The init closes gaps of one voxel and the loop never changes the
        /// genus, so this decides which slots and holes of the input survive: 192 keeps gaps down to
        /// about diag/170 on a box-like shape, on a par with alpha wrapping at α = diag/300, where
        /// `roar init`'s 128 fills the slots between a chair's slats. 256 opens narrower cavities
        /// (libigl-camelhead's ears) and costs 3–5 s more on the wild meshes, but gains less than it
        /// gives roar's own init + QEM (`docs/method.md`).
        init_resolution: usize = 192, range(8.0, 1024.0);
        /// The init is decimated to at most this many faces (§4.1: 20k).
        init_max_faces: usize = InitialMeshOptions::default().max_faces, range(4.0, 1e7);
        /// Enclosure rule of the watertight init (`roar_ops::init::winding_solid`; 0 = off):
        /// exterior voxels whose generalized winding number with respect to T′ is above this value
        /// turn solid, so punctures of a closed surface close while tunnels stay. Default
        /// `roar_ops::init::ENCLOSURE_WINDING_THRESHOLD` (0.7).
        enclosure_winding_threshold: f64 = ENCLOSURE_WINDING_THRESHOLD, zero_or(0.5, 1.0);
        /// A region the enclosure rule fills stays filled only if its widest cap (a patch of its
        /// boundary no input surface covers) is at most this fraction of its boundary: punctures
        /// close, the wide opening of an open surface stays open. Default
        /// `roar_ops::init::ENCLOSURE_MAX_CAP_FRACTION` (0.02); 1 closes every opening.
        enclosure_max_cap_fraction: f64 = ENCLOSURE_MAX_CAP_FRACTION, range(0.0, 1.0);
        /// Subdivision level of the sphere init. Default 4 (§4.2 has 2; more helps a sphere reach
        /// detail).
        sphere_level: u32 = 4, range(0.0, 8.0);
        /// Cells along the longest side of an SDF input's bounds for its voxel init (§4.3: 64).
        sdf_init_resolution: usize = SdfInitOptions::default().resolution, range(2.0, 1024.0);
    }
}

config_table! {
    /// `[loss]`
    pub struct LossConfig("loss") {
        /// λ1, the render loss weight (§3.2.3: 3).
        render_weight: f64 = 3.0, range(0.0, 1e6);
        /// λ2, the planar projection loss weight (§3.2.3: 1).
        planar_weight: f64 = 1.0, range(0.0, 1e6);
        /// Scale of the planar term before its weight (Verification note 2). Measured with
        /// `crates/roar-cli/examples/loss_balance.rs` on wild meshes' inits at 5k faces: mean per-vertex gradient of
        /// 3·render ≈ 3.1e-3, raw planar ≈ 1.3e-6–3.1e-6, Laplacian ≈ 3e-4–6e-4; at 500 the planar
        /// term (6e-4–1.5e-3) is within 5× of the render term instead of 500× below it.
        planar_scale: f64 = RECONSTRUCTION_PLANAR_SCALE, range(0.0, 1e9);
        /// Source samples kept per planar loss evaluation (§3.2.2 cap; the default and why:
        /// `roar_loss::planar::DEFAULT_MAX_SAMPLES`; 50,000 in the SDF and scan schedules).
        planar_max_samples: usize = DEFAULT_MAX_SAMPLES, range(1.0, 1e8);
        /// Neighbours of the k-NN planar projection (§8: s2t_neighbours 10).
        planar_neighbours: usize = KnnOptions::default().k, range(1.0, 100.0);
        /// Include the target-to-source term (OQ-3).
        planar_t2s: bool = PlanarOptions::default().t2s;
        /// Target points the t2s term queries per evaluation, a different spatially even subset
        /// each time (0: all, the paper's; the default and why:
        /// `roar_loss::planar::DEFAULT_T2S_MAX_POINTS`; 0 in the SDF and scan schedules).
        planar_t2s_max_points: usize = DEFAULT_T2S_MAX_POINTS, range(0.0, 1e9);
        /// Side in pixels of the coarse views the render loss uses for the loop's first
        /// `render_coarse_fraction` of iterations (and the polish, see `render_coarse_polish`), when
        /// below `render_resolution`
        /// (`roar_loss::CoarseViews`; the paper renders every iteration at `render_resolution`,
        /// `docs/method.md` says why not). Default 256.
        render_coarse_resolution: u32 = 256, range(16.0, 4096.0);
        /// Fraction of the loop's iterations rendered at `render_coarse_resolution`, from the
        /// first (0: none, the paper's schedule). Default 1: the whole loop; 0 in the SDF and scan
        /// schedules.
        render_coarse_fraction: f64 = 1.0, range(0.0, 1.0);
        /// When the whole loop renders at `render_coarse_resolution`, the finish's polish does too
        /// (false: the polish renders at `render_resolution`). Default true (`docs/method.md` has
        /// the cost and the fidelity of both).
        render_coarse_polish: bool = true;
        /// Weight of the SDF projection loss (§5: 0.1), in the objective only for inputs with a
        /// signed distance (`roar_loss::SdfLoss`).
        sdf_loss_weight: f64 = 0.1, range(0.0, 1e6);
        /// Loop iteration from which the SDF loss is on (§5: 500 of the SDF schedule's 700).
        sdf_loss_start: usize = SdfLossOptions::default().start_iteration, range(0.0, 1e5);
        /// `ε` of the SDF loss's projection `v − f ∇f/(|∇f|² + ε)`.
        sdf_loss_epsilon: f64 = SdfLossOptions::default().epsilon, range(0.0, 1.0);
    }
}

config_table! {
    /// `[optimize]`
    pub struct OptimizeConfig("optimize") {
        /// Move Vertices iterations (§1.2 step 5: 200 for ShapeNet).
        iterations: usize = 200, range(0.0, 1e5);
        /// Learning rate η (§3.2.4: 0.05).
        learning_rate: f64 = OptimizerOptions::default().lr, range(1e-9, 10.0);
        /// Laplacian weight of the optimizer (§8: 0.02).
        laplacian_weight: f64 = OptimizerOptions::default().laplacian_weight, range(0.0, 1e3);
        /// Working budget W = clamp(factor·N, min, max), never below N (OQ-11, §1.2 step 6).
        /// Defaults: factor 2, min 5000, max 20 000.
        working_budget_factor: usize = 2, range(1.0, 100.0);
        /// Lower bound of the working budget.
        working_budget_min: usize = 5000, range(4.0, 1e7);
        /// Upper bound of the working budget.
        working_budget_max: usize = 20_000, range(4.0, 1e7);
        /// Face Collapse block and flips every this many iterations (§1.3: 1).
        collapse_interval: usize = 1, range(0.0, 1e5);
        /// Fold estimator slack (§3.6, note 4: 0.6).
        collapse_fold_slack: f64 = FaceCollapseOptions::default().fold_slack, range(0.0, 1.0);
        /// Spare flagged faces whose vertex-derived normal `|n_o(f)| = |Σ_k n_vk| / 3` is below this,
        /// unless they fold back onto a neighbour ([SUP] "Collapse Face normal threshold" 0.98,
        /// §3.6 step 1; note 4 makes it a switch; 0 = off). Vertex normals diverge on a crease or
        /// on a thin part, where collapsing eats the part from its rim. On by default, measured:
        /// luke-f-16 at 1000 faces, Chamfer/diag 4.3e-3 without (worse than init + QEM, 1.7e-3),
        /// 1.24e-3 with; trimesh-rabbit and manifoldplus-chair unchanged or slightly better.
        collapse_min_normal_size: f64 = 0.98, range(0.0, 1.0);
        /// Face Split block every this many iterations (§1.3: 10).
        split_interval: usize = 10, range(0.0, 1e5);
        /// Face split score threshold per sub-triangle (§3.5, note 1: 0.02).
        split_threshold: f64 = DEFAULT_SPLIT_THRESHOLD, range(0.0, 1e3);
        /// Tangential smoothing every this many iterations of the loop (§1.3, OQ-13 recommend 5;
        /// 0 = off, the default). [INF] Off, as in the reference code, whose call site is commented
        /// out (§3.9): measured at 1000 faces, each sweep raised the render loss by about a quarter
        /// and the optimizer never caught up (cgal-non_manifold_face_graph: render loss 0.011 at
        /// iteration 20, 0.064 at 200), and the output was much farther from the input
        /// (Chamfer/diag every 5 / off: cgal-non_manifold_face_graph 2.71e-3 / 1.84e-3, gc-moebius
        /// 3.05e-3 / 2.16e-3). The triangles are shaped after the final QEM instead
        /// (`final_smoothing_sweeps`).
        smoothing_interval: usize = 0, range(0.0, 1e5);
        /// Every this many iterations, keep a copy of the loop's mesh and its loss (default 5; 10
        /// in the SDF and scan schedules; 0 = only the last state). The run finishes from the kept
        /// state with the lowest loss (the last one included) that the untangle block can clear
        /// (`run.optimize.finished_from_iteration`, `run.optimize.untangle_failures` in the
        /// report). [INF] Not in the paper: the blocks make the loss rise as well as fall, and after
        /// it levels off (by iteration 30–50 on the wild meshes at 1000 faces) it can drift up
        /// (libigl-camelhead: 0.0486 at iteration 50, 0.0535 at 199); and the last state may be a
        /// tangle the untangle cannot clear. The loop's stop (`level_window`) is tested at the
        /// checkpoints, so 5 lets it stop up to 5 iterations sooner (`docs/method.md`); the SDF
        /// schedule's 700 iterations keep every checkpoint in memory, and 10 halves that.
        checkpoint_interval: usize = 5, range(0.0, 1e5);
        /// Stop the loop once its loss has levelled off: at a checkpoint, when no checkpoint of the
        /// last `level_window` iterations has a loss `level_tolerance` (relative) below the lowest
        /// one before them (0 = always run `iterations`; needs `checkpoint_interval > 0`).
        /// Defaults 20 and 0.03 (50 and 0.01 in the scan schedule); off in the SDF schedule, whose
        /// SDF loss starts at iteration 500.
        /// [INF] Not in the paper: the run finishes from the lowest-loss checkpoint, and on the wild
        /// meshes the loss levels off by iteration 50–100 (`docs/method.md`, "The loop stops when its
        /// loss has levelled off").
        level_window: usize = 20, range(0.0, 1e5);
        /// See `level_window`.
        level_tolerance: f64 = 0.03, range(0.0, 1.0);
        /// Shorten optimizer steps that would make faces intersect (`roar_ops::untangle::limit_steps`),
        /// so the loop itself keeps the mesh intersection-free where the blocks did.
        step_limiter: bool = true;
        /// Let the blocks skip (collapses, flips) or shorten (smoothing moves) operations that would
        /// make a face intersect another one (`roar_ops::blocks::guard`), so the loop's mesh stays
        /// intersection-free and every checkpoint is recent. [INF] Not in the paper. Off by default,
        /// measured: it keeps folds the Face Collapse block would have removed, and the final
        /// untangle clears what the unguarded blocks leave (gpytoolbox-airplane at 1000 faces:
        /// Chamfer/diag 3.49e-3 with it, 2.13e-3 without; luke-f-16 1.92e-3 / 1.88e-3). Worth it
        /// where the untangle fails and the run would finish from an old checkpoint (a 256-voxel
        /// init of manifoldplus-chair: the collapse, split and smoothing blocks created crossings in
        /// 88, 19 and 28 of their calls, and the run fell back to its init).
        guard_intersections: bool = false;
        /// The Face Split block of an SDF input projects its samples onto the field (§3.4 C, up to
        /// 6 gradient evaluations per sample) rather than by the k-NN planar projection over the point
        /// cloud. The spec's choice and on by default; with a neural field it is most of the run's
        /// evaluations (`docs/sdf.md`, "Measured cost").
        sdf_split_projector: bool = true;
    }
}

config_table! {
    /// `[finish]`
    pub struct FinishConfig("finish") {
        /// Separation margin of the untangle block, relative to the bounding-box diagonal.
        untangle_margin: f64 = UntangleOptions::default().margin_rel, range(0.0, 0.01);
        /// Before the final QEM, move every vertex this far (relative to the bounding-box diagonal)
        /// outward along its normal, as far as no intersection appears (default 5e-4; 0 = off; only
        /// when the polish runs, which moves the vertices back onto the target). [INF] Not in the
        /// paper: the loop pulls the two sides of a thin part or of an open surface onto one sheet,
        /// where the QEM's self-intersection veto refuses nearly every collapse and the decimation eats
        /// the part from its rim instead (libigl-camelhead, an open surface, decimated from its
        /// 5000-face loop mesh to 1000: 5.9 % of the input farther than 1 % of the diagonal from the
        /// output, 0.3 % with an offset of 5e-4).
        final_qem_offset: f64 = 5e-4, range(0.0, 0.1);
        /// Sweeps of tangential smoothing at exactly N after the final QEM, before the polish (default
        /// 3; 0 = none), each moved vertex put back on its old faces (§3.9 plus projection) and every
        /// move limited so that no intersection appears. [INF] Not in the paper: with the sweeps off in
        /// the loop, this is what keeps the output's triangles well shaped. Without it the outputs are
        /// slightly closer to the input (Chamfer/diag 0.5–1 % lower on gpytoolbox-split_mountain and
        /// libigl-camelhead at 5000 faces) but worse shaped (median aspect ratio over the 14 wild
        /// meshes 1.46 with the init at 256 voxels, against 1.26 with the sweeps at 192;
        /// `docs/method.md`).
        final_smoothing_sweeps: usize = 3, range(0.0, 1e3);
        /// Rounds of data-dependent edge flips at exactly N after the smoothing, before the polish
        /// (default 5; 0 = off): an edge flips when the quad's other diagonal follows the point cloud's
        /// normals better (`roar_ops::finish::data_flips`), no face gets worse than `Q = 4` (or the
        /// worse old face) and no intersection appears. [INF] Not in the paper: the valence flips, the
        /// smoothing and the final QEM choose the diagonals for the triangles' shapes and the working
        /// mesh's quadrics, not for the target's normals (`docs/method.md`).
        data_flip_rounds: usize = DataFlipOptions::default().max_rounds, range(0.0, 1e3);
        /// Move Vertices iterations at exactly N after the final QEM (default 20; 0 = off), with the
        /// step limiter, a learning rate falling linearly to 0 and no blocks, so the face count and
        /// topology stay; the state with the lowest loss is kept. [INF] Not in the paper: the final QEM
        /// places vertices at quadric minimisers of the working-budget surface, not on the target. If
        /// the kept mesh intersects itself, the QEM output is kept (the report says so). Runs only when
        /// `iterations > 0`, so `--iterations 0` stays the plain init + QEM.
        polish_iterations: usize = 20, range(0.0, 1e5);
        /// For an input with a signed distance (an SDF), after the polish: this many steps (default
        /// 3; 0 = off) that move every vertex along its normal by minus the mean first-order distance
        /// `f/|∇f|` over its faces (sampled at their edge midpoints), except where the move is long
        /// against its faces, would turn a face over or make faces intersect
        /// (`roar_ops::finish::zero_set`). [INF] Not in the paper: the loop's mesh is on
        /// the surface only as far as the losses pull it, and the fill splits to a large budget put
        /// their vertices on chords (`docs/sdf.md`, "Measured cost"). Soups have no field and skip
        /// it. Runs only when `iterations > 0`.
        zero_set_steps: usize = ZeroSetOptions::default().steps, range(0.0, 100.0);
        /// For an SDF input, before the fit to the zero set: a vertex whose first-order distance
        /// `|f|/|∇f|` from the zero set exceeds this times its mean edge length is collapsed into a
        /// neighbour (the nearest to the zero set first) where no face turns over and no
        /// intersection appears, and the face count is restored by edge splits
        /// (`roar_ops::finish::fins`; default 0.5; 0 = off). [INF] Not in the paper: the untangle
        /// can leave fins, flaps of faces standing off the surface that the fit would fold onto
        /// themselves and so holds (`docs/sdf.md`). Runs only when `iterations > 0`.
        fin_distance_over_edge: f64 = FinOptions::default().max_distance_over_edge, zero_or(0.01, 100.0);
        /// Last step: flip the edges of faces with aspect ratio `Q = R/(2r)` above this when both faces
        /// of the edge get better, the two are nearly coplanar (0.95; against the other face alone when
        /// one is degenerate, above 100) and no intersection appears (`roar_ops::finish::slivers`;
        /// default 10; 0 = off); then degenerate faces (above 100) that no flip fixes are removed by
        /// collapsing one of their edges, and the face count is restored by edge splits that make no
        /// degenerate face (`roar_ops::finish::degenerate`). [INF] Not in the paper: the optimization
        /// and the polish move vertices for the losses, and the final QEM bounds only the faces it
        /// creates, so a few caps (one angle near 180°) reach the output. Runs only when `iterations >
        /// 0`.
        sliver_quality: f64 = SliverOptions::default().max_quality, zero_or(1.0, 1e6);
        /// Write the closest mesh when the final QEM cannot reach the budget, instead of failing.
        best_effort: bool = false;
        /// Keep the init's genus to the end: when the budget is too small for it (or the final QEM
        /// stalls on the link condition) the run fails with the QEM's named error instead of
        /// removing handles (`roar_ops::finish::genus`; DESIGN.md §2).
        keep_topology: bool = false;
    }
}

impl ReconstructConfig {
    /// The SDF schedule of spec §5, the defaults for signed distance inputs: the full pipeline
    /// with 700 iterations and 50k faces, the SDF loss on from iteration 500, every iteration
    /// on the full rig and run (no stop when the loss levels off before the SDF loss starts).
    pub fn sdf_defaults() -> Self {
        let mut config = Self {
            faces: 50_000,
            ..Self::default()
        };
        config.optimize.iterations = 700;
        config.optimize.checkpoint_interval = 10;
        config.optimize.level_window = 0;
        config.keep_the_full_rig();
        config
    }

    /// The defaults for a set of range scans: the soup's, with the init's enclosure rule at
    /// [`SCAN_ENCLOSURE_WINDING_THRESHOLD`] closing every opening,
    /// however wide, since a scanned object is closed but the scanner never sees all of it (the
    /// bunny's base), every iteration on the full rig, and the loop's stop with the 50-iteration
    /// window and 1 % tolerance and the checkpoints every 10 iterations `docs/scans.md` was
    /// measured with (the soups' 20, 3 % and 5 are measured on soups only).
    pub fn scan_defaults() -> Self {
        let mut config = Self::default();
        config.init.enclosure_winding_threshold = SCAN_ENCLOSURE_WINDING_THRESHOLD;
        config.init.enclosure_max_cap_fraction = 1.0;
        config.keep_the_full_rig();
        config.optimize.checkpoint_interval = 10;
        config.optimize.level_window = 50;
        config.optimize.level_tolerance = 0.01;
        config
    }

    /// The paper's rig and loss schedule: 36 views, every iteration renders them at full
    /// resolution, the planar loss keeps 50,000 samples and its t2s term queries every target
    /// point. The SDF and scan schedules use it: the faster soup schedule (`docs/method.md`) is
    /// measured on soups only.
    fn keep_the_full_rig(&mut self) {
        self.target.views_per_axis = 6;
        self.loss.render_coarse_fraction = 0.0;
        self.loss.planar_max_samples = 50_000;
        self.loss.planar_t2s_max_points = 0;
    }

    /// W = clamp(factor·N, min, max), never below N (DESIGN.md §2).
    pub fn working_budget(&self) -> usize {
        let w = (self.optimize.working_budget_factor * self.faces)
            .max(self.optimize.working_budget_min)
            .min(self.optimize.working_budget_max)
            .max(self.faces);
        w + w % 2
    }

    /// Checks every numeric field against its range ([`ReconstructConfig::field_ranges`]) and
    /// the rules between fields, before any work; the one-line error names the field, its value
    /// and what is allowed. NaN and infinities are outside every range.
    pub fn validate(&self) -> Result<(), String> {
        crate::budget::check_budget("faces =", self.faces, 4).map_err(|e| e.to_string())?;
        for (range, value) in self.field_ranges() {
            if !range.allows(value) {
                return Err(format!(
                    "{} = {} is out of range: allowed {}",
                    range.name,
                    value,
                    range.describe()
                ));
            }
        }
        if self.optimize.working_budget_min > self.optimize.working_budget_max {
            return Err(format!(
                "optimize.working_budget_min = {} is above optimize.working_budget_max = {}",
                self.optimize.working_budget_min, self.optimize.working_budget_max
            ));
        }
        Ok(())
    }

    /// The config of a TOML file: `defaults` with the file's keys over them, table by table.
    /// Errors are one line: a key of another table (or a flat key of the ungrouped layout) names
    /// the table it belongs in, a bad value its line. Does not [`validate`](Self::validate).
    pub fn from_toml(text: &str, defaults: &Self) -> Result<Self, String> {
        let file: toml::Table = toml::from_str(text).map_err(one_line)?;
        check_layout(&file)?;
        // Parsed alone, so a bad value is named with its line in the file.
        toml::from_str::<Self>(text).map_err(one_line)?;
        merge_over(file, defaults)
    }

    /// Like [`from_toml`](Self::from_toml) for a table already parsed (the Python package's dict).
    pub fn from_table(file: toml::Table, defaults: &Self) -> Result<Self, String> {
        check_layout(&file)?;
        merge_over(file, defaults)
    }

    /// Every numeric field with its allowed range and its current value, named as the messages
    /// name it (`loss.render_weight`).
    /// The ranges are wide: they refuse what cannot mean anything (NaN, infinities, negative
    /// weights, zero samples, huge values that would exhaust memory or time), not what is merely
    /// unusual. `0 (off)` marks the fields where 0 switches a feature off, as their docs say.
    pub fn field_ranges(&self) -> Vec<(FieldRange, f64)> {
        let mut ranges = vec![
            (FieldRange::new("faces", 4.0, 1e9), self.faces as f64),
            (
                FieldRange::new("seed", 0.0, u64::MAX as f64),
                self.seed as f64,
            ),
        ];
        ranges.extend(self.target.field_ranges());
        ranges.extend(self.init.field_ranges());
        ranges.extend(self.loss.field_ranges());
        ranges.extend(self.optimize.field_ranges());
        ranges.extend(self.finish.field_ranges());
        ranges
    }
}

/// A TOML error on one line, for the CLI's one-line messages.
fn one_line(e: toml::de::Error) -> String {
    e.to_string().replace('\n', " ").trim().to_string()
}

/// `defaults` with the keys of `file` over them, table by table (a file's `[optimize]` replaces
/// only the keys it names).
fn merge_over(
    file: toml::Table,
    defaults: &ReconstructConfig,
) -> Result<ReconstructConfig, String> {
    let mut merged = toml::Table::try_from(defaults).map_err(|e| e.to_string())?;
    for (key, value) in file {
        match (merged.get_mut(&key), value) {
            (Some(toml::Value::Table(table)), toml::Value::Table(keys)) => table.extend(keys),
            (_, value) => {
                merged.insert(key, value);
            }
        }
    }
    merged.try_into().map_err(one_line)
}

/// Refuses a key outside the table it belongs in, naming that table: the flat keys of the
/// ungrouped layout (`render_weight = 3` at the top) and keys under the wrong table.
fn check_layout(file: &toml::Table) -> Result<(), String> {
    let layout = toml::Table::try_from(ReconstructConfig::default()).map_err(|e| e.to_string())?;
    let home = |key: &str| {
        layout.iter().find_map(|(table, value)| match value {
            toml::Value::Table(leaves) if leaves.contains_key(key) => Some(table.as_str()),
            _ => None,
        })
    };
    let misplaced = |key: &str, here: &str| -> Result<(), String> {
        if key == "init" {
            return Err(format!(
                "`init` {here}: the initial mesh's kind is `kind` in the [init] table"
            ));
        }
        match home(key) {
            Some(table) => Err(format!(
                "`{key}` {here}: it belongs in the [{table}] table (write it under [{table}])"
            )),
            None => Ok(()),
        }
    };
    for (key, value) in file {
        match (layout.get(key), value) {
            (Some(toml::Value::Table(_)), toml::Value::Table(keys)) => {
                for leaf in keys.keys() {
                    if !layout[key].as_table().is_some_and(|t| t.contains_key(leaf)) {
                        misplaced(leaf, &format!("is not a key of [{key}]"))?;
                    }
                }
            }
            (Some(toml::Value::Table(_)), _) | (None, _) => {
                misplaced(key, "is not a top-level key")?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// The values a numeric configuration field may take: `min ..= max`, and 0 as well where 0
/// switches the feature off. Named by its TOML key, so a message points at the line to fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldRange {
    /// The field's TOML key.
    pub name: &'static str,
    /// Smallest allowed value (besides 0 when `zero_is_off`).
    pub min: f64,
    /// Largest allowed value.
    pub max: f64,
    /// Whether 0 is allowed too, meaning "off".
    pub zero_is_off: bool,
}

impl FieldRange {
    /// `min ..= max`.
    pub const fn new(name: &'static str, min: f64, max: f64) -> Self {
        Self {
            name,
            min,
            max,
            zero_is_off: false,
        }
    }

    /// 0 (off) or `min ..= max`.
    pub const fn zero_or(name: &'static str, min: f64, max: f64) -> Self {
        Self {
            zero_is_off: true,
            ..Self::new(name, min, max)
        }
    }

    /// Whether `value` is allowed (never NaN or an infinity).
    pub fn allows(&self, value: f64) -> bool {
        (self.zero_is_off && value == 0.0) || (value >= self.min && value <= self.max)
    }

    /// The range in words, for messages: `0 (off) or 1 to 1000000`.
    pub fn describe(&self) -> String {
        let span = format!("{} to {}", self.min, self.max);
        if self.zero_is_off {
            format!("0 (off) or {span}")
        } else {
            span
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--print-config`'s text reads back to the same config, its tables in stage order.
    #[test]
    fn printed_layout_reads_back() {
        let defaults = ReconstructConfig::default();
        let text = toml::to_string(&defaults).unwrap();
        let tables: Vec<&str> = text.lines().filter(|l| l.starts_with('[')).collect();
        assert_eq!(
            tables,
            ["[target]", "[init]", "[loss]", "[optimize]", "[finish]"]
        );
        assert_eq!(
            ReconstructConfig::from_toml(&text, &defaults).unwrap(),
            defaults
        );
    }

    /// A file's table changes only the keys it names: the rest of that table keeps the
    /// defaults it is read over (here the SDF schedule's 700 iterations).
    #[test]
    fn file_keys_go_over_the_defaults_key_by_key() {
        let sdf = ReconstructConfig::sdf_defaults();
        let c = ReconstructConfig::from_toml("[optimize]\nlearning_rate = 0.1\n", &sdf).unwrap();
        assert_eq!(c.optimize.learning_rate, 0.1);
        assert_eq!(c.optimize.iterations, 700);
        assert_eq!(c.faces, 50_000);
        assert_eq!(c.loss, sdf.loss);
    }

    /// Keys of the ungrouped layout and keys under the wrong table name the table they belong
    /// in, in one line.
    #[test]
    fn misplaced_keys_name_their_table() {
        let d = ReconstructConfig::default();
        let refused = |text: &str| ReconstructConfig::from_toml(text, &d).unwrap_err();
        let e = refused("render_weight = 2.0\n");
        assert!(e.contains("`render_weight`") && e.contains("[loss]"), "{e}");
        let e = refused("[loss]\niterations = 3\n");
        assert!(
            e.contains("`iterations`") && e.contains("[optimize]"),
            "{e}"
        );
        let e = refused("init = \"sphere\"\n");
        assert!(e.contains("`kind`") && e.contains("[init]"), "{e}");
        let e = refused("[finish]\nno_such_key = 1\n");
        assert!(e.contains("no_such_key"), "{e}");
        let e = refused("[loss]\nrender_weight = \"three\"\n");
        assert!(e.contains("line 2"), "{e}");
        for e in [e, refused("render_weight = 2.0\n")] {
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        let sphere = ReconstructConfig::from_toml("[init]\nkind = \"sphere\"\n", &d).unwrap();
        assert_eq!(sphere.init.kind, InitKind::Sphere);
    }

    /// The defaults the field docs (and `docs/method.md`) state, so the two cannot drift apart.
    #[test]
    fn documented_defaults() {
        let c = ReconstructConfig::default();
        assert_eq!(c.seed, 43);
        assert_eq!(c.optimize.iterations, 200);
        assert_eq!(c.init.kind, InitKind::Watertight);
        assert_eq!(c.init.init_resolution, 192);
        assert_eq!(c.init.init_max_faces, 20_000);
        assert_eq!(c.init.enclosure_winding_threshold, 0.7);
        assert_eq!(c.init.enclosure_max_cap_fraction, 0.02);
        assert_eq!(roar_ops::init::ENCLOSURE_WINDING_THRESHOLD, 0.7);
        assert_eq!(c.init.sphere_level, 4);
        assert_eq!(
            (
                c.optimize.working_budget_factor,
                c.optimize.working_budget_min,
                c.optimize.working_budget_max
            ),
            (2, 5000, 20_000)
        );
        assert_eq!(
            (c.target.views_per_axis, c.target.render_resolution),
            (5, 512)
        );
        assert_eq!(c.target.twin_ratio, 80.0);
        assert_eq!((c.loss.render_weight, c.loss.planar_weight), (3.0, 1.0));
        assert_eq!(c.loss.planar_scale, 500.0);
        assert_eq!(c.loss.planar_max_samples, 12_500);
        assert_eq!(
            c.loss.planar_max_samples,
            roar_loss::planar::DEFAULT_MAX_SAMPLES
        );
        assert_eq!(c.loss.planar_neighbours, 10);
        assert_eq!(c.loss.planar_t2s_max_points, 50_000);
        assert_eq!(
            (
                c.loss.render_coarse_resolution,
                c.loss.render_coarse_fraction,
                c.loss.render_coarse_polish
            ),
            (256, 1.0, true)
        );
        for other in [
            ReconstructConfig::sdf_defaults(),
            ReconstructConfig::scan_defaults(),
        ] {
            assert_eq!(other.target.views_per_axis, 6);
            let loss = &other.loss;
            assert_eq!(
                (
                    loss.render_coarse_fraction,
                    loss.planar_max_samples,
                    loss.planar_t2s_max_points
                ),
                (0.0, 50_000, 0)
            );
        }
        assert_eq!(c.target.point_cloud_samples, 200_000);
        assert_eq!(c.target.sheet_offset, 1e-3);
        assert_eq!(c.target.sharp_edge_samples, 30_000);
        assert_eq!(
            (c.optimize.learning_rate, c.optimize.laplacian_weight),
            (0.05, 0.02)
        );
        assert_eq!(c.optimize.collapse_interval, 1);
        assert_eq!(c.optimize.collapse_fold_slack, 0.6);
        assert_eq!(
            c.optimize.collapse_min_normal_size, 0.98,
            "on in the pipeline"
        );
        assert_eq!(
            (c.optimize.split_interval, c.optimize.split_threshold),
            (10, 0.02)
        );
        assert_eq!(c.optimize.smoothing_interval, 0, "off by default");
        assert_eq!(c.finish.final_smoothing_sweeps, 3);
        assert_eq!(c.finish.data_flip_rounds, 5);
        assert_eq!(c.optimize.checkpoint_interval, 5);
        assert_eq!(
            (c.optimize.level_window, c.optimize.level_tolerance),
            (20, 0.03)
        );
        let sdf = ReconstructConfig::sdf_defaults().optimize;
        assert_eq!((sdf.checkpoint_interval, sdf.level_window), (10, 0));
        let scans = ReconstructConfig::scan_defaults().optimize;
        assert_eq!(
            (
                scans.checkpoint_interval,
                scans.level_window,
                scans.level_tolerance
            ),
            (10, 50, 0.01)
        );
        assert!(c.optimize.step_limiter);
        assert!(!c.optimize.guard_intersections, "off by default");
        assert_eq!(c.finish.final_qem_offset, 5e-4);
        assert_eq!(c.finish.polish_iterations, 20);
        assert_eq!(c.finish.sliver_quality, 10.0);
        assert_eq!(c.finish.fin_distance_over_edge, 0.5);
    }
}
