//! The reconstruction's configuration: every knob of `roar reconstruct`, in the TOML tables
//! `[target]`, `[init]`, `[loss]`, `[optimize]` and `[finish]`. A TOML file (or the Python
//! package's dict) overrides any subset (unknown keys are errors); the CLI's flags override the
//! file. Each field is declared once, with its doc, type, default and allowed range
//! (`config_table!`); where a library's `Options::default()` holds the same knob, the default is
//! read from there. Why each default: `docs/method.md`, defaults table.

use roar_io::PatchOptions;
use roar_loss::planar::{DEFAULT_MAX_SAMPLES, DEFAULT_T2S_MAX_POINTS, RECONSTRUCTION_PLANAR_SCALE};
use roar_loss::{
    KnnOptions, PlanarOptions, PointCloudOptions, SdfLossOptions, SharpEdgeOptions, TargetOptions,
};
use roar_ops::blocks::collapse::FaceCollapseOptions;
use roar_ops::blocks::split::DEFAULT_SPLIT_THRESHOLD;
use roar_ops::finish::data_flips::DataFlipOptions;
use roar_ops::finish::fair::FAIR_DISTANCE_OVER_EDGE;
use roar_ops::finish::fins::FinOptions;
use roar_ops::finish::slivers::SliverOptions;
use roar_ops::finish::zero_set::ZeroSetOptions;
use roar_ops::init::{
    ENCLOSURE_MAX_CAP_FRACTION, ENCLOSURE_MAX_CAP_WIDTH, ENCLOSURE_WINDING_THRESHOLD,
    InitialMeshOptions, SdfInitOptions,
};
use roar_ops::optim::{OptimError, OptimizerOptions};
use roar_ops::untangle::UntangleOptions;
use roar_sdf::{SdfProjectorOptions, TraceOptions};
use serde::{Deserialize, Serialize};

use crate::budget::BudgetError;

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
                    $(
                        "; allowed: `", stringify!($kind), "(", stringify!($min), ", ",
                        stringify!($max), ")`",
                    )?
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

/// How the initial mesh M0 is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitKind {
    /// The input shape's own initial mesh (`Shape::initial_mesh`): for a soup the watertight
    /// voxel init of the cleaned target, in the manner of Manifold.
    Watertight,
    /// An icosphere of radius 0.5; its genus is 0, so holes of the input are lost.
    Sphere,
}

/// Every knob of `roar reconstruct`, grouped by the pipeline stage that reads it: the TOML file
/// has the tables `[target]`, `[init]`, `[loss]`, `[optimize]` and `[finish]` (`--print-config`
/// prints them all). The unit test `documented_defaults` checks the defaults that
/// `docs/method.md`'s defaults table states.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReconstructConfig {
    /// Exact face count of the output (even).
    pub faces: usize,
    /// Seed of every random choice.
    pub seed: u64,
    /// The target T′: the rig it is rendered with, its point cloud, and how scans and signed
    /// distances are read into it.
    pub target: TargetConfig,
    /// The initial mesh M0.
    pub init: InitConfig,
    /// The loss the loop minimises.
    pub loss: LossConfig,
    /// The loop: Move Vertices and its remeshing blocks, at the working budget.
    pub optimize: OptimizeConfig,
    /// From the loop's mesh to exactly `faces` faces.
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
    /// `[target]`: the target T′ the loop fits, its renders and its point cloud.
    pub struct TargetConfig("target") {
        /// Views per axis of the star rig: n² views (6 in the SDF and scan schedules).
        /// `roar_loss::TargetOptions` keeps the paper's 6 (36 views); the pipeline renders 25, so
        /// each loop iteration renders fewer pixels (why: `docs/method.md`, defaults table).
        views_per_axis: usize = 5, range(1.0, 32.0);
        /// Render resolution in pixels of the target renders (and of the loop's views when they
        /// are not coarse, see `loss.render_coarse_resolution`).
        render_resolution: u32 = TargetOptions::default().resolution, range(16.0, 4096.0);
        /// Keep both twins of a soup face unless one has this many times more pixels.
        twin_ratio: f64 = TargetOptions::default().twin_ratio, range(1.0, 1e6);
        /// Samples of the target point cloud.
        point_cloud_samples: usize = PointCloudOptions::default().samples, range(100.0, 5e7);
        /// Keep target samples whose winding number at p + 1e-3·n is below this.
        winding_threshold: f64 = PointCloudOptions::default().winding_threshold, range(1e-6, 1.0);
        /// Target samples on a sheet (a face of T′ whose reversed twin is kept too: an open
        /// surface or a zero-thickness part) stand off it by this much along their normal,
        /// relative to the bounding-box diagonal, so the two sides of the closed output each get
        /// their own plane instead of jamming against each other on one (0 = off). Not in the
        /// paper. The library's `PointCloudOptions::sheet_offset` is absolute and off; the
        /// pipeline's is relative and on (why: `docs/method.md`, defaults table).
        sheet_offset: f64 = 1e-3, range(0.0, 0.1);
        /// Samples on the sharp edges of the init, added to the target point cloud (0 = none).
        sharp_edge_samples: usize = SharpEdgeOptions::default().samples, range(0.0, 5e7);
        /// Range scans: a patch triangle with an edge longer than this many times the local grid
        /// spacing bridges a depth jump and is dropped.
        scan_max_edge_factor: f64 = PatchOptions::default().max_edge_factor, range(1.0, 1e3);
        /// Range scans: a patch triangle whose normal is more than this many degrees from the
        /// direction to the scanner is dropped.
        scan_max_angle_degrees: f64 = PatchOptions::default().max_angle_degrees, range(1.0, 90.0);
        /// Range scans: refine the `.conf` poses by ICP (`roar_ops::align`); `--no-icp` turns it
        /// off.
        scan_icp: bool = true;
        /// Cells of the grid that brackets the zero set for an SDF input's traced target renders
        /// (`roar_sdf::trace`): features thinner than about one cell can be missed.
        sdf_trace_grid: usize = TraceOptions::default().grid_resolution, range(2.0, 2048.0);
        /// Regula falsi steps per traced pixel of an SDF input.
        sdf_trace_refine_steps: usize = TraceOptions::default().refine_steps, range(0.0, 100.0);
        /// First-order steps of an SDF input's projections: the Face Split projector and the
        /// point-cloud samples.
        sdf_projection_steps: usize = SdfProjectorOptions::default().steps, range(1.0, 100.0);
        /// A projected sample of an SDF input is valid when its first-order distance `|f|/|∇f|`
        /// ends at most this, in rig units. Looser than the paper's 1e-6, which float64 fields
        /// reach but float32 networks do not.
        sdf_projection_tolerance: f64 = SdfProjectorOptions::default().tolerance,
            range(1e-12, 1.0);
        /// Sample an SDF input's field once, adaptively (`roar_sdf::sampled`), and let every
        /// stage read the samples; off, every stage evaluates the field itself.
        sdf_sample: bool = true;
        /// Finest cells of the sampling along the bounds' longest side; 0 follows the face
        /// budget: 256 up to 10,000 faces, 384 above (`roar::shapes::sdf::auto_sample_resolution`).
        sdf_sample_resolution: usize = 0, zero_or(2.0, 1048575.0);
        /// A sampling cell is split when a corner's first-order distance `|f|/|∇f|` is under
        /// this many times its diagonal (or its corners change sign). Half the library's 1.0:
        /// a plate through a cell passes within half an edge (0.29 of the diagonal) of a
        /// corner, and on nif-bunny 0.5 costs 31 % fewer evaluations than 1.0 for the same
        /// interpolation error (`docs/sdf.md`, "Sampling").
        sdf_sample_band: f64 = 0.5, range(0.0, 100.0);
    }
}

config_table! {
    /// `[init]`: the initial mesh M0.
    pub struct InitConfig("init") {
        /// Initial mesh.
        kind: InitKind = InitKind::Watertight;
        /// Voxels along the longest axis of the watertight init (in place of Manifold's octree
        /// resolution). The init closes gaps of about one voxel and the loop never changes the
        /// genus, so this decides which slots and holes of the input survive. Above `roar
        /// init`'s 128 (`roar_ops::init::InitOptions::default()`), which fills slots a
        /// reconstruction should keep, such as those between a chair's slats (why:
        /// `docs/method.md`, defaults table).
        init_resolution: usize = 192, range(8.0, 1024.0);
        /// The init is decimated to at most this many faces.
        init_max_faces: usize = InitialMeshOptions::default().max_faces, range(4.0, 1e7);
        /// Enclosure rule of the watertight init (`roar_ops::init::winding_solid`; 0 = off):
        /// exterior voxels whose generalized winding number with respect to T′ is above this
        /// value turn solid, so punctures of a closed surface close while tunnels stay.
        enclosure_winding_threshold: f64 = ENCLOSURE_WINDING_THRESHOLD, zero_or(0.5, 1.0);
        /// A region the enclosure rule fills stays filled only if its widest cap (a patch of its
        /// boundary no input surface covers) is at most this fraction of its boundary, so open
        /// containers and the concave side of an open sheet do not fill (1 accepts every
        /// region).
        enclosure_max_cap_fraction: f64 = ENCLOSURE_MAX_CAP_FRACTION, range(0.0, 1.0);
        /// ... and only if no point of its caps is farther than this fraction of the input's
        /// longest side from the input: punctures close, the wide opening of an open box or a
        /// cup stays open (1 closes every opening).
        enclosure_max_cap_width: f64 = ENCLOSURE_MAX_CAP_WIDTH, range(0.0, 1.0);
        /// Subdivision level of the sphere init. Finer than the paper's level 2, so that a sphere
        /// can reach detail.
        sphere_level: u32 = 4, range(0.0, 8.0);
        /// Cells along the longest side of an SDF input's bounds for its voxel init.
        sdf_init_resolution: usize = SdfInitOptions::default().resolution, range(2.0, 1024.0);
    }
}

config_table! {
    /// `[loss]`: the loss the loop minimises.
    pub struct LossConfig("loss") {
        /// λ1, the weight of the render loss.
        render_weight: f64 = 3.0, range(0.0, 1e6);
        /// λ2, the weight of the planar projection loss.
        planar_weight: f64 = 1.0, range(0.0, 1e6);
        /// Scale of the planar term before its weight. The library's `PlanarOptions::default()`
        /// scale (`SPHERE_BALANCED_PLANAR_SCALE`, 5) balances the terms on a sphere; on a real
        /// input's init the raw planar gradient is far smaller against the render gradient
        /// (why: `docs/method.md`, defaults table).
        planar_scale: f64 = RECONSTRUCTION_PLANAR_SCALE, range(0.0, 1e9);
        /// Source samples kept per planar loss evaluation (50,000 in the scan schedule). The
        /// paper samples at a fixed density without a cap (why:
        /// `docs/method.md`, defaults table).
        planar_max_samples: usize = DEFAULT_MAX_SAMPLES, range(1.0, 1e8);
        /// Neighbours of the k-NN planar projection.
        planar_neighbours: usize = KnnOptions::default().k, range(1.0, 100.0);
        /// Include the target-to-source (t2s) term of the planar loss.
        planar_t2s: bool = PlanarOptions::default().t2s;
        /// Target points the t2s term queries per evaluation, a different spatially even subset
        /// each time (0 = all, as the paper does; 0 in the scan schedule) (why:
        /// `docs/method.md`, defaults table).
        planar_t2s_max_points: usize = DEFAULT_T2S_MAX_POINTS, range(0.0, 1e9);
        /// Side in pixels of the coarse views the render loss uses for the loop's first
        /// `render_coarse_fraction` of iterations (and the polish, see `render_coarse_polish`),
        /// when below `target.render_resolution` (`roar_loss::CoarseViews`). The paper renders
        /// every iteration at full resolution; roar does not (why: `docs/method.md`, defaults
        /// table).
        render_coarse_resolution: u32 = 256, range(16.0, 4096.0);
        /// Fraction of the loop's iterations rendered at `render_coarse_resolution`, from the
        /// first (0 = none, the paper's schedule, and the SDF and scan schedules'; 1 = the whole
        /// loop).
        render_coarse_fraction: f64 = 1.0, range(0.0, 1.0);
        /// When the whole loop renders at `render_coarse_resolution`, the finish's polish does
        /// too (false: the polish renders at `target.render_resolution`) (why: `docs/method.md`,
        /// defaults table).
        render_coarse_polish: bool = true;
        /// Weight of the SDF projection loss, in the objective only for inputs with a signed
        /// distance (`roar_loss::SdfLoss`).
        sdf_loss_weight: f64 = 0.1, range(0.0, 1e6);
        /// Loop iteration from which the SDF loss is on.
        sdf_loss_start: usize = SdfLossOptions::default().start_iteration, range(0.0, 1e5);
        /// `ε` of the SDF loss's projection `v − f ∇f/(|∇f|² + ε)`, and of the finish's
        /// first-order distances to the zero set.
        sdf_loss_epsilon: f64 = SdfLossOptions::default().epsilon, range(0.0, 1.0);
    }
}

config_table! {
    /// `[optimize]`: the loop, Move Vertices and its remeshing blocks at the working budget.
    pub struct OptimizeConfig("optimize") {
        /// Move Vertices iterations of the loop.
        iterations: usize = 200, range(0.0, 1e5);
        /// Learning rate η of the optimizer.
        learning_rate: f64 = OptimizerOptions::default().lr, range(1e-9, 10.0);
        /// Weight of the optimizer's Laplacian term.
        laplacian_weight: f64 = OptimizerOptions::default().laplacian_weight, range(0.0, 1e3);
        /// The working budget, the face count the loop works at, is W = clamp(factor·N, min,
        /// max), never below N.
        working_budget_factor: usize = 2, range(1.0, 100.0);
        /// Lower bound of the working budget.
        working_budget_min: usize = 5000, range(4.0, 1e7);
        /// Upper bound of the working budget.
        working_budget_max: usize = 20_000, range(4.0, 1e7);
        /// Face Collapse block and its valence flips every this many iterations (0 = never).
        collapse_interval: usize = 1, range(0.0, 1e5);
        /// Slack of the Face Collapse block's fold estimator.
        collapse_fold_slack: f64 = FaceCollapseOptions::default().fold_slack, range(0.0, 1.0);
        /// Spare flagged faces whose vertex-derived normal `|n_o(f)| = |Σ_k n_vk| / 3` is below
        /// this, unless they fold back onto a neighbour (0 = off). Vertex normals diverge on a
        /// crease or on a thin part, where collapsing eats the part from its rim. Off in the
        /// library's `FaceCollapseOptions::default()`, on in the pipeline at the threshold of the
        /// paper's supplement (why: `docs/method.md`, defaults table).
        collapse_min_normal_size: f64 = 0.98, range(0.0, 1.0);
        /// Face Split block every this many iterations, never at the first (0 = never).
        split_interval: usize = 10, range(0.0, 1e5);
        /// Face Split score threshold per sub-triangle.
        split_threshold: f64 = DEFAULT_SPLIT_THRESHOLD, range(0.0, 1e3);
        /// Tangential smoothing every this many iterations of the loop (0 = off). The paper
        /// recommends 5 but its reference code never calls it; roar follows the code and shapes
        /// the triangles after the final QEM instead (`finish.final_smoothing_sweeps`) (why:
        /// `docs/method.md`, defaults table).
        smoothing_interval: usize = 0, range(0.0, 1e5);
        /// Every this many iterations, keep a copy of the loop's mesh and its loss (0 = only the
        /// last state; 10 in the SDF and scan schedules). The run finishes from the kept state
        /// with the lowest loss (the last one included) that the untangle block can clear
        /// (`run.optimize.finished_from_iteration`, `run.optimize.untangle_failures` in the
        /// report), and the loop's stop (`level_window`) is tested at the checkpoints. The paper
        /// finishes from the last state (why: `docs/method.md`, defaults table).
        checkpoint_interval: usize = 5, range(0.0, 1e5);
        /// Stop the loop once its loss has levelled off: at a checkpoint, when no checkpoint of
        /// the last `level_window` iterations has a loss `level_tolerance` (relative) below the
        /// lowest one before them (0 = always run `iterations`; needs `checkpoint_interval > 0`;
        /// 50 in the scan schedule, 0 in the SDF schedule, whose SDF loss starts late). The paper
        /// always runs every iteration (why: `docs/method.md`, defaults table).
        level_window: usize = 20, range(0.0, 1e5);
        /// See `level_window` (0.01 in the scan schedule).
        level_tolerance: f64 = 0.03, range(0.0, 1.0);
        /// Shorten optimizer steps that would make faces intersect
        /// (`roar_ops::untangle::limit_steps`), so the loop itself keeps the mesh
        /// intersection-free where the blocks did.
        step_limiter: bool = true;
        /// Let the blocks skip (collapses, flips) or shorten (smoothing moves) operations that
        /// would make a face intersect another one (`roar_ops::blocks::guard`), so the loop's
        /// mesh stays intersection-free and every checkpoint is recent. Not in the paper. Off:
        /// it keeps folds the Face Collapse block would have removed, and the final untangle
        /// clears what the unguarded blocks leave; worth turning on where the untangle fails and
        /// the run would finish from an old checkpoint (why: `docs/method.md`, defaults table).
        guard_intersections: bool = false;
        /// The Face Split block of an SDF input projects its samples onto the field, as the paper
        /// does, rather than by the k-NN planar projection over the point cloud (false). With a
        /// neural field it is most of the run's evaluations (`docs/sdf.md`).
        sdf_split_projector: bool = true;
    }
}

config_table! {
    /// `[finish]`: from the loop's mesh to exactly `faces` faces.
    pub struct FinishConfig("finish") {
        /// Separation margin of the untangle block, relative to the bounding-box diagonal.
        untangle_margin: f64 = UntangleOptions::default().margin_rel, range(0.0, 0.01);
        /// Before the final QEM, move every vertex this far (relative to the bounding-box
        /// diagonal) outward along its normal, as far as no intersection appears (0 = off; only
        /// when the polish runs, which moves the vertices back onto the target). The loop pulls
        /// the two sides of a thin part or of an open surface onto one sheet, where the QEM's
        /// self-intersection veto refuses nearly every collapse and the decimation eats the part
        /// from its rim instead. Not in the paper (why: `docs/method.md`, defaults table).
        final_qem_offset: f64 = 5e-4, range(0.0, 0.1);
        /// Sweeps of tangential smoothing at exactly N after the final QEM, before the polish
        /// (0 = none), each moved vertex put back on its old faces and every move limited so
        /// that no intersection appears. With the sweeps off in the loop, this is what keeps the
        /// output's triangles well shaped. Not in the paper (why: `docs/method.md`, defaults
        /// table).
        final_smoothing_sweeps: usize = 3, range(0.0, 1e3);
        /// Rounds of data-dependent edge flips at exactly N after the smoothing, before the
        /// polish (0 = off): an edge flips when the quad's other diagonal follows the point
        /// cloud's normals better (`roar_ops::finish::data_flips`), no face gets worse than
        /// `Q = 4` (or the worse old face) and no intersection appears. The valence flips, the
        /// smoothing and the final QEM choose the diagonals for the triangles' shapes, not for
        /// the target's normals. Not in the paper (why: `docs/method.md`, defaults table).
        data_flip_rounds: usize = DataFlipOptions::default().max_rounds, range(0.0, 1e3);
        /// Move Vertices iterations at exactly N after the final QEM (0 = off), with the step
        /// limiter, a learning rate falling linearly to 0 and no blocks, so the face count and
        /// topology stay; the state with the lowest loss is kept. If the kept mesh intersects
        /// itself, the QEM output is kept (the report says so). Runs only when `iterations > 0`,
        /// so `--iterations 0` stays the plain init + QEM. Not in the paper, whose final QEM
        /// leaves the vertices at quadric minimisers of the working-budget surface, off the
        /// target (why: `docs/method.md`, defaults table).
        polish_iterations: usize = 20, range(0.0, 1e5);
        /// For an input with a signed distance (an SDF), after the polish: this many steps
        /// (0 = off) that move every vertex along its normal by minus the mean first-order
        /// distance `f/|∇f|` over its faces (sampled at their edge midpoints), except where the
        /// move is long against its faces, would turn a face over or make faces intersect
        /// (`roar_ops::finish::zero_set`). The loop's mesh is on the surface only as far as the
        /// losses pull it. Soups have no field and skip it; runs only when `iterations > 0`. Not
        /// in the paper (why: `docs/method.md`, defaults table).
        zero_set_steps: usize = ZeroSetOptions::default().steps, range(0.0, 100.0);
        /// For an SDF input, before the fit to the zero set: a vertex whose first-order distance
        /// `|f|/|∇f|` from the zero set exceeds this times its mean edge length is collapsed
        /// into a neighbour (the nearest to the zero set first) where no face turns over and no
        /// intersection appears, and the face count is restored by edge splits
        /// (`roar_ops::finish::fins`; 0 = off). The untangle can leave fins, flaps of faces
        /// standing off the surface that the fit would fold onto themselves. Runs only when
        /// `iterations > 0`. Not in the paper.
        fin_distance_over_edge: f64 = FinOptions::default().max_distance_over_edge,
            zero_or(0.01, 100.0);
        /// For a soup, after the last polish: the vertices farther from the target surface T′
        /// than this times their mean edge length (what no data holds: the caps over the soup's
        /// holes) are moved to the thin-plate continuation of the surface around them, each
        /// move limited so that no face folds or intersects (`roar_ops::finish::fair`; 0 =
        /// off). The loop's Laplacian is a membrane, which leaves such caps flat and sunk. Runs
        /// only when `iterations > 0` and the shape has no signed distance; off for range scans.
        /// Not in the paper.
        fair_distance_over_edge: f64 = FAIR_DISTANCE_OVER_EDGE, zero_or(0.01, 100.0);
        /// Last step: flip the edges of faces with aspect ratio `Q = R/(2r)` above this when
        /// both faces of the edge get better, the two are nearly coplanar and no intersection
        /// appears (`roar_ops::finish::slivers`; 0 = off); then degenerate faces that no flip
        /// fixes are removed by collapsing one of their edges, and the face count is restored by
        /// edge splits that make no degenerate face (`roar_ops::finish::degenerate`). The
        /// optimization and the polish move vertices for the losses and the final QEM bounds
        /// only the faces it creates, so a few caps would reach the output. Runs only when
        /// `iterations > 0`. Not in the paper.
        sliver_quality: f64 = SliverOptions::default().max_quality, zero_or(1.0, 1e6);
        /// Write the closest mesh when the final QEM cannot reach the budget, instead of
        /// failing.
        best_effort: bool = false;
        /// Keep the init's genus to the end: when the budget is too small for it (or the final
        /// QEM stalls on the link condition) the run fails with the QEM's named error instead of
        /// removing handles (`roar_ops::finish::genus`).
        keep_topology: bool = false;
    }
}

impl ReconstructConfig {
    /// The SDF schedule, the defaults for signed distance inputs: the paper's full pipeline at
    /// 50k faces, but 150 iterations with the SDF loss on from iteration 100 in place of its
    /// 700 and 500 (as close or closer on the shared networks for 3.3× less CPU, measured on the
    /// sampled field: `docs/method.md`), every iteration on the full rig and run (no stop when
    /// the loss levels off before the SDF loss starts), with the soup's planar sampling (as
    /// close on the shared networks as the paper's, for a third less time: `docs/method.md`).
    pub fn sdf_defaults() -> Self {
        let mut config = Self {
            faces: 50_000,
            ..Self::default()
        };
        config.optimize.iterations = 150;
        config.loss.sdf_loss_start = 100;
        config.optimize.checkpoint_interval = 10;
        config.optimize.level_window = 0;
        config.keep_the_full_rig();
        config
    }

    /// The defaults for a set of range scans: the soup's, with the init's enclosure rule closing
    /// every opening, however wide, since a scanned object is closed but the scanner never sees
    /// all of it (the bunny's base), every iteration on the full rig with the planar loss at the
    /// paper's density (50,000 samples, every target point in its t2s term), and the loop's stop
    /// with the 50-iteration window and 1 % tolerance and the checkpoints every 10 iterations
    /// `docs/scans.md` was measured with (the soups' 20, 3 % and 5 are measured on soups only).
    pub fn scan_defaults() -> Self {
        let mut config = Self::default();
        config.init.enclosure_max_cap_fraction = 1.0;
        config.init.enclosure_max_cap_width = 1.0;
        config.finish.fair_distance_over_edge = 0.0;
        config.keep_the_full_rig();
        config.loss.planar_max_samples = 50_000;
        config.loss.planar_t2s_max_points = 0;
        config.optimize.checkpoint_interval = 10;
        config.optimize.level_window = 50;
        config.optimize.level_tolerance = 0.01;
        config
    }

    /// The paper's rig: 36 views, every iteration renders them at full resolution. The SDF and
    /// scan schedules use it: the soup's coarser rig (`docs/method.md`) is measured on soups
    /// only.
    fn keep_the_full_rig(&mut self) {
        self.target.views_per_axis = 6;
        self.loss.render_coarse_fraction = 0.0;
    }

    /// W = clamp(factor·N, min, max), never below N, rounded up to even.
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
    pub fn validate(&self) -> Result<(), ConfigError> {
        crate::budget::check_budget("faces =", self.faces, 4)?;
        for (range, value) in self.field_ranges() {
            if !range.allows(value) {
                return Err(ConfigError::OutOfRange {
                    name: range.name,
                    value,
                    allowed: range,
                });
            }
        }
        let optimize = &self.optimize;
        if optimize.working_budget_min > optimize.working_budget_max {
            return Err(ConfigError::WorkingBudgetBounds {
                min: optimize.working_budget_min,
                max: optimize.working_budget_max,
            });
        }
        Ok(())
    }

    /// The config of a TOML file: `defaults` with the file's keys over them, table by table.
    /// Errors are one line: a key of another table (or a flat key of the ungrouped layout) names
    /// the table it belongs in, a bad value its line. Does not [`validate`](Self::validate).
    pub fn from_toml(text: &str, defaults: &Self) -> Result<Self, ConfigError> {
        let file: toml::Table = toml::from_str(text)?;
        check_layout(&file)?;
        // Parsed alone, so a bad value is named with its line in the file.
        toml::from_str::<Self>(text)?;
        merge_over(file, defaults)
    }

    /// Like [`from_toml`](Self::from_toml) for a table already parsed (the Python package's dict).
    pub fn from_table(file: toml::Table, defaults: &Self) -> Result<Self, ConfigError> {
        check_layout(&file)?;
        merge_over(file, defaults)
    }

    /// Every numeric field with its allowed range and its current value, named as the messages
    /// name it (`loss.render_weight`): `faces` and `seed`, then each table's fields in order.
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

/// Why a configuration was refused. Every message is one line, naming the key to fix (the CLI
/// and the Python package print it after `config: `, or after the file's path for a TOML error).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// A numeric field is outside its range (NaN and infinities are outside every range).
    #[error("{name} = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// The field's dotted name (`loss.render_weight`).
        name: &'static str,
        /// The refused value.
        value: f64,
        /// The values the field may take.
        allowed: FieldRange,
    },
    /// `optimize.working_budget_min` is above `optimize.working_budget_max`.
    #[error("optimize.working_budget_min = {min} is above optimize.working_budget_max = {max}")]
    WorkingBudgetBounds {
        /// `optimize.working_budget_min`.
        min: usize,
        /// `optimize.working_budget_max`.
        max: usize,
    },
    /// `faces` is odd or below a tetrahedron's 4.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// `faces` is below what the init's pieces need (known only once the init is made).
    #[error("{0} (for the pieces of the init)")]
    BudgetForInit(BudgetError),
    /// A key outside the table it belongs in: a flat key of the ungrouped layout, or a key under
    /// another table.
    #[error(
        "`{key}` {}: it belongs in the [{table}] table (write it under [{table}])",
        not_a_key_of(.found_in)
    )]
    MisplacedKey {
        /// The key.
        key: String,
        /// The table it was found in (`None`: at the top level).
        found_in: Option<String>,
        /// The table it belongs in.
        table: String,
    },
    /// `init` (the ungrouped layout's initial mesh kind), which is now `kind` in `[init]`.
    #[error(
        "`init` {}: the initial mesh's kind is `kind` in the [init] table",
        not_a_key_of(.found_in)
    )]
    InitKey {
        /// The table it was found in (`None`: at the top level).
        found_in: Option<String>,
    },
    /// The text is not TOML, or a key is unknown or has a value of the wrong type; the message
    /// is the parser's, on one line, with the line of the file it refers to.
    #[error("{}", one_line(.0))]
    Toml(toml::de::Error),
    /// The defaults could not be written as a TOML table to merge a file over (a bug).
    #[error(transparent)]
    Layout(#[from] toml::ser::Error),
    /// The optimizer refused the learning rate or the Laplacian weight.
    #[error(transparent)]
    Optimizer(#[from] OptimError),
}

// Not `#[from]`: the TOML error is the message itself, not a cause to print after it.
impl From<toml::de::Error> for ConfigError {
    fn from(error: toml::de::Error) -> Self {
        ConfigError::Toml(error)
    }
}

/// Where a misplaced key was found, for [`ConfigError`]'s messages.
fn not_a_key_of(table: &Option<String>) -> String {
    match table {
        Some(table) => format!("is not a key of [{table}]"),
        None => "is not a top-level key".to_string(),
    }
}

/// A TOML error on one line, for the CLI's one-line messages.
fn one_line(e: &toml::de::Error) -> String {
    e.to_string().replace('\n', " ").trim().to_string()
}

/// `defaults` with the keys of `file` over them, table by table (a file's `[optimize]` replaces
/// only the keys it names).
fn merge_over(
    file: toml::Table,
    defaults: &ReconstructConfig,
) -> Result<ReconstructConfig, ConfigError> {
    let mut merged = toml::Table::try_from(defaults)?;
    for (key, value) in file {
        match (merged.get_mut(&key), value) {
            (Some(toml::Value::Table(table)), toml::Value::Table(keys)) => table.extend(keys),
            (_, value) => {
                merged.insert(key, value);
            }
        }
    }
    Ok(merged.try_into()?)
}

/// Refuses a key outside the table it belongs in, naming that table: the flat keys of the
/// ungrouped layout (`render_weight = 3` at the top) and keys under the wrong table.
fn check_layout(file: &toml::Table) -> Result<(), ConfigError> {
    let layout = toml::Table::try_from(ReconstructConfig::default())?;
    let home = |key: &str| {
        layout.iter().find_map(|(table, value)| match value {
            toml::Value::Table(leaves) if leaves.contains_key(key) => Some(table.clone()),
            _ => None,
        })
    };
    // A key found in `found_in` (`None`: the top level) where it is not a key: refused if it
    // belongs in another table; an unknown key is left to the parser.
    let misplaced = |key: &str, found_in: Option<&String>| -> Result<(), ConfigError> {
        let found_in = found_in.cloned();
        if key == "init" {
            return Err(ConfigError::InitKey { found_in });
        }
        match home(key) {
            Some(table) => Err(ConfigError::MisplacedKey {
                key: key.to_string(),
                found_in,
                table,
            }),
            None => Ok(()),
        }
    };
    for (key, value) in file {
        match (layout.get(key), value) {
            (Some(toml::Value::Table(_)), toml::Value::Table(keys)) => {
                for leaf in keys.keys() {
                    if !layout[key].as_table().is_some_and(|t| t.contains_key(leaf)) {
                        misplaced(leaf, Some(key))?;
                    }
                }
            }
            (Some(toml::Value::Table(_)), _) | (None, _) => {
                misplaced(key, None)?;
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

    /// The range in words, for messages: `0 (off) or 1 to 1000000` (its `Display`).
    pub fn describe(&self) -> String {
        self.to_string()
    }
}

impl std::fmt::Display for FieldRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.zero_is_off {
            write!(f, "0 (off) or ")?;
        }
        write!(f, "{} to {}", self.min, self.max)
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
    /// defaults it is read over (here the SDF schedule's 150 iterations).
    #[test]
    fn file_keys_go_over_the_defaults_key_by_key() {
        let sdf = ReconstructConfig::sdf_defaults();
        let c = ReconstructConfig::from_toml("[optimize]\nlearning_rate = 0.1\n", &sdf).unwrap();
        assert_eq!(c.optimize.learning_rate, 0.1);
        assert_eq!(c.optimize.iterations, 150);
        assert_eq!(c.faces, 50_000);
        assert_eq!(c.loss, sdf.loss);
    }

    /// Keys of the ungrouped layout and keys under the wrong table name the table they belong
    /// in, in one line.
    #[test]
    fn misplaced_keys_name_their_table() {
        let d = ReconstructConfig::default();
        let refused = |text: &str| {
            ReconstructConfig::from_toml(text, &d)
                .unwrap_err()
                .to_string()
        };
        let typed = ReconstructConfig::from_toml("render_weight = 2.0\n", &d).unwrap_err();
        assert_eq!(
            typed,
            ConfigError::MisplacedKey {
                key: "render_weight".to_string(),
                found_in: None,
                table: "loss".to_string(),
            }
        );
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

    /// The defaults `docs/method.md`'s defaults table (and the field docs) state, so they cannot
    /// drift apart, and the library defaults the field docs say the pipeline departs from.
    #[test]
    fn documented_defaults() {
        let c = ReconstructConfig::default();
        assert_eq!(c.faces, 5000);
        assert_eq!(c.seed, 43);
        assert_eq!(c.optimize.iterations, 200);
        assert_eq!(c.init.kind, InitKind::Watertight);
        assert_eq!(c.init.init_resolution, 192);
        assert_eq!(c.init.init_max_faces, 20_000);
        assert_eq!(c.init.enclosure_winding_threshold, 0.5);
        assert_eq!(c.init.enclosure_max_cap_fraction, 0.02);
        assert_eq!(c.init.enclosure_max_cap_width, 0.25);
        assert_eq!(roar_ops::init::ENCLOSURE_WINDING_THRESHOLD, 0.5);
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
        let (sdf, scans) = (
            ReconstructConfig::sdf_defaults(),
            ReconstructConfig::scan_defaults(),
        );
        for other in [&sdf, &scans] {
            assert_eq!(other.target.views_per_axis, 6);
            assert_eq!(other.loss.render_coarse_fraction, 0.0);
        }
        let planar =
            |c: &ReconstructConfig| (c.loss.planar_max_samples, c.loss.planar_t2s_max_points);
        assert_eq!(planar(&sdf), planar(&c));
        assert_eq!(planar(&scans), (50_000, 0));
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
        assert_eq!(c.finish.fair_distance_over_edge, 0.3);
        assert_eq!(
            ReconstructConfig::scan_defaults()
                .finish
                .fair_distance_over_edge,
            0.0
        );
        assert_eq!(c.finish.untangle_margin, 1e-6);
        assert_eq!(
            (c.finish.zero_set_steps, c.loss.sdf_loss_epsilon),
            (3, 1e-10)
        );
        assert_eq!((c.loss.sdf_loss_weight, c.loss.sdf_loss_start), (0.1, 500));
        assert_eq!(c.init.sdf_init_resolution, 64);
        assert_eq!(
            (c.target.winding_threshold, c.target.scan_max_edge_factor),
            (0.2, 4.0)
        );
        assert_eq!(
            (
                c.target.sdf_trace_grid,
                c.target.sdf_trace_refine_steps,
                c.target.sdf_projection_steps,
                c.target.sdf_projection_tolerance
            ),
            (128, 8, 5, 1e-5)
        );

        // The knobs whose pipeline default departs from the library's, as their docs say.
        assert_eq!(roar_loss::planar::RECONSTRUCTION_PLANAR_SCALE, 500.0);
        assert_eq!(PlanarOptions::default().scale, 5.0);
        assert_eq!(TargetOptions::default().views_per_axis, 6);
        assert_eq!(roar_ops::init::InitOptions::default().resolution, 128);
        assert_eq!(PointCloudOptions::default().sheet_offset, 0.0);
        assert_eq!(FaceCollapseOptions::default().min_normal_size, None);
    }
}
