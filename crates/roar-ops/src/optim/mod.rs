//! The Move Vertices optimizer (paper §3.1; the exact step is the authors' code's,
//! `docs/method.md#optimizer`): a VectorAdam-like step whose size follows the
//! local edge length, with a Laplacian term added in gradient space.
//!
//! The optimizer works on plain buffers: positions `&mut [DVec3]`, per-vertex gradients
//! `&[DVec3]` and the triangles `&[[u32; 3]]` of the current mesh. Vertex ids are indices into
//! these arrays. It keeps one [`VertexState`] row per vertex id; the topology operators of the
//! remeshing blocks change the vertex set, and the rows follow: the optimizer is a
//! [`roar_mesh::VertexStore`], so every operator and compaction made through a
//! [`roar_mesh::TrackedMesh`] over it calls the matching transfer method
//! ([`Optimizer::on_collapse`], [`Optimizer::on_edge_split`], [`Optimizer::on_face_split`],
//! [`Optimizer::grow`], [`Optimizer::apply_remap`]).
//!
//! One step, for every live vertex v (a vertex referenced by at least one triangle), with the
//! global step counter t = 1, 2, … that remeshing never resets:
//!
//! ```text
//! g   = ∂L/∂v (non-finite → 0) + w_lap · ν_v · δ_v        δ_v = v − mean of the 1-ring
//! if t > 1: g clamped per component to ±grad_lim·|m1|    (only where m1 ≠ 0, see below)
//! m1  = ulerp(m1, g, β1, t);   m2 = ulerp(m2, ‖g‖², β2, t)
//! u   = m1 / (√m2 + 1e-8);     ν  = ulerp(ν, ‖u‖, β3, t)
//! ℓ_v = min(shortest incident edge, edge_len_max)
//! v  ← v − η·min(1, t(1−β1)/ramp) · ℓ_v · u
//! ```
//!
//! δ_v and ℓ_v are computed from the positions *before* the step, for all vertices at once, so
//! the result does not depend on the vertex order or on the thread count.
//!
//! ```
//! use glam::DVec3;
//! use roar_ops::optim::{Optimizer, OptimizerOptions};
//!
//! // A tetrahedron pulled toward the origin by L = Σ‖v‖².
//! let mut positions = vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
//! let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
//! let mut opt = Optimizer::new(positions.len(), OptimizerOptions::default())?;
//! for _ in 0..10 {
//!     let gradient: Vec<DVec3> = positions.iter().map(|p| 2.0 * *p).collect();
//!     let stats = opt.step(&mut positions, &triangles, &gradient)?;
//!     assert!(stats.max_move <= 0.05 * 0.15);
//! }
//! assert_eq!(opt.step_count(), 10);
//! # Ok::<(), roar_ops::optim::OptimError>(())
//! ```

mod adjacency;
mod transfer;

use adjacency::VertexAdjacency;
use glam::DVec3;
use rayon::prelude::*;
use std::ops::{Add, Mul};

/// Added to √m2 before dividing, so a vertex with zero gradient history does not divide by
/// zero (the authors' `eps = 1e-8`).
pub const VELOCITY_EPSILON: f64 = 1e-8;

/// Vertices per work unit. The per-step reductions (mean move, …) sum per-chunk partials in
/// chunk order, so results are bit-identical whether the chunks run in parallel or not.
const CHUNK: usize = 4096;

/// Hyper-parameters of the optimizer. `Default` carries the paper's learning rate
/// (supplementary §1) and the authors' code's other values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimizerOptions {
    /// Learning rate η (0.05, supplementary §1). The typical move per step is about η·ℓ_v.
    pub lr: f64,
    /// (β1, β2, β3) (0.8, 0.8, 0): EMA factors of the first moment m1, of the
    /// second moment m2 and of the speed ν. Each must lie in [0, 1); β3 = 0 means ν = ‖u‖.
    pub betas: (f64, f64, f64),
    /// Weight w_lap of the uniform Laplacian added to the gradient, scaled by ν
    /// (0.02).
    pub laplacian_weight: f64,
    /// Learning-rate warm-up: η_t = η·min(1, t(1−β1)/ramp) (1: full rate after 5
    /// steps). Must be > 0.
    pub ramp: f64,
    /// From the second step on, each gradient component is clamped to ±grad_lim·|m1|
    /// (10). Must be > 0; `f64::INFINITY` disables clamping.
    pub grad_lim: f64,
    /// Cap of the reference length ℓ_v = min(shortest incident edge, edge_len_max)
    /// (0.15). Must be > 0; `f64::INFINITY` removes the cap.
    pub edge_len_max: f64,
    /// Clamp a gradient component only where its |m1| > 0
    /// (`docs/method.md#decision-gradient-clamp`). With `false` the authors' behaviour is kept,
    /// which freezes forever a component whose first gradient was exactly 0 (its bound is ±10·0).
    /// Default `true`.
    pub clamp_only_nonzero_m1: bool,
    /// Use rayon for the per-vertex passes from this many vertices on (not a parameter of the
    /// method; default 50 000). Results are bit-identical either way.
    pub parallel_min_vertices: usize,
}

impl Default for OptimizerOptions {
    fn default() -> Self {
        Self {
            lr: 0.05,
            betas: (0.8, 0.8, 0.0),
            laplacian_weight: 0.02,
            ramp: 1.0,
            grad_lim: 10.0,
            edge_len_max: 0.15,
            clamp_only_nonzero_m1: true,
            parallel_min_vertices: 50_000,
        }
    }
}

impl OptimizerOptions {
    /// Checks that every value is usable: finite non-negative `lr` and `laplacian_weight`,
    /// betas in [0, 1), `ramp` finite and > 0, `grad_lim` and `edge_len_max` > 0 (infinity
    /// allowed, NaN not).
    pub fn validate(&self) -> Result<(), OptimError> {
        let bad = |name: &'static str, value: f64, expected: &'static str| {
            Err(OptimError::InvalidOption {
                name,
                value,
                expected,
            })
        };
        if !(self.lr.is_finite() && self.lr >= 0.0) {
            return bad("lr", self.lr, "a finite value >= 0");
        }
        for (name, beta) in [
            ("betas.0", self.betas.0),
            ("betas.1", self.betas.1),
            ("betas.2", self.betas.2),
        ] {
            if !(0.0..1.0).contains(&beta) {
                return bad(name, beta, "a value in [0, 1)");
            }
        }
        if !(self.laplacian_weight.is_finite() && self.laplacian_weight >= 0.0) {
            return bad(
                "laplacian_weight",
                self.laplacian_weight,
                "a finite value >= 0",
            );
        }
        if !(self.ramp.is_finite() && self.ramp > 0.0) {
            return bad("ramp", self.ramp, "a finite value > 0");
        }
        if self.grad_lim.is_nan() || self.grad_lim <= 0.0 {
            return bad("grad_lim", self.grad_lim, "a value > 0 (infinity allowed)");
        }
        if self.edge_len_max.is_nan() || self.edge_len_max <= 0.0 {
            return bad(
                "edge_len_max",
                self.edge_len_max,
                "a value > 0 (infinity allowed)",
            );
        }
        Ok(())
    }
}

/// What can go wrong when driving the optimizer. Nothing is modified when an error is returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptimError {
    /// An option is out of its range.
    #[error("optimizer option `{name}` = {value} is invalid: expected {expected}")]
    InvalidOption {
        /// Field name in [`OptimizerOptions`].
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted range.
        expected: &'static str,
    },
    /// An input array does not have one entry per optimizer row.
    #[error(
        "{what} has {found} entries but the optimizer has {expected} vertex rows \
         (call grow/apply_remap when the mesh's vertex set changes)"
    )]
    LengthMismatch {
        /// Which input (`"positions"`, `"gradient"`, `"old_to_new"`).
        what: &'static str,
        /// Number of optimizer rows.
        expected: usize,
        /// Length of the input.
        found: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {face} names vertex {vertex}, but there are only {n_vertices} vertices")]
    VertexIndexOutOfRange {
        /// Index of the offending triangle.
        face: usize,
        /// The out-of-range vertex id.
        vertex: u32,
        /// Number of vertices.
        n_vertices: usize,
    },
    /// A transfer method names a vertex row that does not exist.
    #[error(
        "{operation}: vertex {vertex} has no optimizer row (rows: {n_rows}); \
         new vertices must be appended (id == rows) or added with grow first"
    )]
    NoSuchRow {
        /// The transfer method.
        operation: &'static str,
        /// The offending vertex id.
        vertex: u32,
        /// Number of optimizer rows.
        n_rows: usize,
    },
    /// `apply_remap` maps two old vertices onto the same new id.
    #[error("apply_remap: old vertices {first} and {second} both map to new vertex {new}")]
    RemapNotInjective {
        /// The first old id mapped to `new`.
        first: u32,
        /// The second old id mapped to `new`.
        second: u32,
        /// The shared new id.
        new: u32,
    },
}

/// The optimizer state of one vertex: m1, m2 and ν, which travel with the vertex through every
/// topology change.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VertexState {
    /// First moment: bias-corrected EMA of the gradient (3-vector).
    pub m1: DVec3,
    /// Second moment: bias-corrected EMA of ‖g‖², one scalar per vertex (rotation-equivariant).
    pub m2: f64,
    /// Speed ν = ‖u‖ of the last step (smoothed by β3); it scales the Laplacian term.
    pub nu: f64,
}

impl VertexState {
    /// `(1 − t)·a + t·b`, component-wise over the whole row.
    pub fn lerp(a: &Self, b: &Self, t: f64) -> Self {
        Self {
            m1: a.m1 * (1.0 - t) + b.m1 * t,
            m2: a.m2 * (1.0 - t) + b.m2 * t,
            nu: a.nu * (1.0 - t) + b.nu * t,
        }
    }

    /// The mean of three rows (the new vertex of a 1→3 face split).
    pub fn mean3(a: &Self, b: &Self, c: &Self) -> Self {
        let third = 1.0 / 3.0;
        Self {
            m1: (a.m1 + b.m1 + c.m1) * third,
            m2: (a.m2 + b.m2 + c.m2) * third,
            nu: (a.nu + b.nu + c.nu) * third,
        }
    }
}

/// The weights `(a_weight, b_weight)` of the bias-corrected EMA at step `t ≥ 1` (as in the authors'
/// code): with `c_t = 1 − β^t`, `a_weight = β·c_{t−1}/c_t`, `b_weight = (1−β)/c_t`. At t = 1,
/// `a_weight = 0` and `b_weight = 1`. `t = 0` is treated as t = 1.
pub fn ulerp_weights(beta: f64, t: u64) -> (f64, f64) {
    let t = t.clamp(1, i32::MAX as u64) as i32;
    let c_prev = 1.0 - beta.powi(t - 1);
    let c = 1.0 - beta.powi(t);
    (beta * c_prev / c, (1.0 - beta) / c)
}

/// One bias-corrected EMA update, `a·a_weight + b·b_weight` with [`ulerp_weights`]`(beta, t)`.
/// At t = 1 it returns `b`; fed a constant it returns that constant (up to rounding).
pub fn ulerp<T>(a: T, b: T, beta: f64, t: u64) -> T
where
    T: Mul<f64, Output = T> + Add<Output = T>,
{
    let (wa, wb) = ulerp_weights(beta, t);
    a * wa + b * wb
}

/// What one [`Optimizer::step`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepStats {
    /// The global step number t of this step (1 for the first).
    pub step: u64,
    /// The ramped learning rate η_t used.
    pub learning_rate: f64,
    /// Vertices referenced by at least one triangle (the ones updated).
    pub live_vertices: usize,
    /// Largest displacement ‖Δv‖ of a live vertex.
    pub max_move: f64,
    /// Mean displacement over live vertices (0 if none).
    pub mean_move: f64,
    /// Mean speed ν over live vertices after the step (0 if none).
    pub mean_nu: f64,
    /// Gradient components changed by the ±grad_lim·|m1| clamp.
    pub clamped_components: usize,
    /// Gradient components (loss gradient or Laplacian term) that were NaN or infinite and
    /// were replaced by 0.
    pub nonfinite_components: usize,
}

/// The per-vertex Move Vertices optimizer, with its state rows and a global step counter.
///
/// Contract with the pipeline: row `i` belongs to vertex id `i` of the arrays passed to
/// [`Optimizer::step`]. Whenever the mesh's vertex set changes, the matching transfer method
/// must run so the rows follow: editing the mesh through a [`roar_mesh::TrackedMesh`] over the
/// optimizer does that (see the `transfer` module). Positions are never touched by the
/// transfer methods: the mesh operators own them.
#[derive(Debug, Clone)]
pub struct Optimizer {
    options: OptimizerOptions,
    step: u64,
    state: Vec<VertexState>,
    /// Scratch, reused across steps.
    adjacency: VertexAdjacency,
    /// Scratch: δ_v of every vertex, from the positions before the step.
    laplacian: Vec<DVec3>,
    /// Scratch: ℓ_v of every vertex (0 for dead vertices).
    ref_len: Vec<f64>,
}

/// The step-wide constants of one step.
#[derive(Debug, Clone, Copy)]
struct StepCoefficients {
    t: u64,
    learning_rate: f64,
    laplacian_weight: f64,
    grad_lim: f64,
    clamp_only_nonzero_m1: bool,
    m1: (f64, f64),
    m2: (f64, f64),
    nu: (f64, f64),
}

/// Per-chunk partial sums of the step statistics.
#[derive(Debug, Clone, Copy, Default)]
struct Partial {
    live: usize,
    sum_move: f64,
    max_move: f64,
    sum_nu: f64,
    clamped: usize,
    nonfinite: usize,
}

impl Partial {
    fn merge(mut self, other: Partial) -> Partial {
        self.live += other.live;
        self.sum_move += other.sum_move;
        self.max_move = self.max_move.max(other.max_move);
        self.sum_nu += other.sum_nu;
        self.clamped += other.clamped;
        self.nonfinite += other.nonfinite;
        self
    }
}

impl Optimizer {
    /// An optimizer for `n_vertices` vertices, all rows zero, step counter 0.
    /// Errors if `options` fail [`OptimizerOptions::validate`].
    pub fn new(n_vertices: usize, options: OptimizerOptions) -> Result<Self, OptimError> {
        options.validate()?;
        Ok(Self {
            options,
            step: 0,
            state: vec![VertexState::default(); n_vertices],
            adjacency: VertexAdjacency::default(),
            laplacian: Vec::new(),
            ref_len: Vec::new(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &OptimizerOptions {
        &self.options
    }

    /// Replaces the options (e.g. a schedule changing `lr`); state and step counter are kept.
    pub fn set_options(&mut self, options: OptimizerOptions) -> Result<(), OptimError> {
        options.validate()?;
        self.options = options;
        Ok(())
    }

    /// Number of steps taken so far (the t of the last step; 0 before the first).
    pub fn step_count(&self) -> u64 {
        self.step
    }

    /// The state rows, one per vertex id.
    pub fn state(&self) -> &[VertexState] {
        &self.state
    }

    /// Mutable access to the state rows (for custom transfers or restoring a checkpoint).
    pub fn state_mut(&mut self) -> &mut [VertexState] {
        &mut self.state
    }

    /// Number of state rows (must equal the mesh's vertex count when stepping).
    pub fn len(&self) -> usize {
        self.state.len()
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.state.is_empty()
    }

    /// Takes one optimizer step (module docs), moving `positions` in place and updating the
    /// state rows of every live vertex. Vertices referenced by no triangle are dead: their
    /// position and row are left alone.
    ///
    /// `positions` and `gradient` (∂L/∂v) must have one entry per row, and `triangles` must
    /// only name existing vertices; otherwise an error is returned and nothing changes
    /// (including the step counter). The triangles need not form a manifold: the 1-rings are
    /// the unique vertices sharing a triangle with v.
    ///
    /// Cost O(V + F) (plus sorting each 1-ring); no allocation once the scratch buffers have
    /// grown to the mesh size. Uses rayon from `parallel_min_vertices` vertices on, with
    /// bit-identical results.
    pub fn step(
        &mut self,
        positions: &mut [DVec3],
        triangles: &[[u32; 3]],
        gradient: &[DVec3],
    ) -> Result<StepStats, OptimError> {
        let n = self.state.len();
        for (what, found) in [("positions", positions.len()), ("gradient", gradient.len())] {
            if found != n {
                return Err(OptimError::LengthMismatch {
                    what,
                    expected: n,
                    found,
                });
            }
        }
        self.adjacency.rebuild(n, triangles)?;
        let parallel = n >= self.options.parallel_min_vertices;

        // Pass 1: δ_v and ℓ_v from the positions before the step.
        self.laplacian.resize(n, DVec3::ZERO);
        self.ref_len.resize(n, 0.0);
        let old_positions: &[DVec3] = positions;
        let geometry = |(chunk, (lap, len)): (usize, (&mut [DVec3], &mut [f64]))| {
            local_geometry(
                &self.adjacency,
                old_positions,
                self.options.edge_len_max,
                chunk * CHUNK,
                lap,
                len,
            )
        };
        if parallel {
            self.laplacian
                .par_chunks_mut(CHUNK)
                .zip(self.ref_len.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(geometry);
        } else {
            self.laplacian
                .chunks_mut(CHUNK)
                .zip(self.ref_len.chunks_mut(CHUNK))
                .enumerate()
                .for_each(geometry);
        }

        // Pass 2: moments, velocity, move.
        self.step += 1;
        let k = self.coefficients(self.step);
        let (adjacency, laplacian, ref_len) = (&self.adjacency, &self.laplacian, &self.ref_len);
        let update = |(chunk, (p, s)): (usize, (&mut [DVec3], &mut [VertexState]))| {
            let start = chunk * CHUNK;
            let mut partial = Partial::default();
            for i in 0..p.len() {
                let v = start + i;
                if adjacency.neighbors(v).is_empty() {
                    continue;
                }
                update_vertex(
                    &mut p[i],
                    &mut s[i],
                    gradient[v],
                    laplacian[v],
                    ref_len[v],
                    &k,
                    &mut partial,
                );
            }
            partial
        };
        let total = if parallel {
            let partials: Vec<Partial> = positions
                .par_chunks_mut(CHUNK)
                .zip(self.state.par_chunks_mut(CHUNK))
                .enumerate()
                .map(update)
                .collect();
            partials
                .into_iter()
                .fold(Partial::default(), Partial::merge)
        } else {
            positions
                .chunks_mut(CHUNK)
                .zip(self.state.chunks_mut(CHUNK))
                .enumerate()
                .map(update)
                .fold(Partial::default(), Partial::merge)
        };

        let per_live = |sum: f64| {
            if total.live == 0 {
                0.0
            } else {
                sum / total.live as f64
            }
        };
        Ok(StepStats {
            step: k.t,
            learning_rate: k.learning_rate,
            live_vertices: total.live,
            max_move: total.max_move,
            mean_move: per_live(total.sum_move),
            mean_nu: per_live(total.sum_nu),
            clamped_components: total.clamped,
            nonfinite_components: total.nonfinite,
        })
    }

    fn coefficients(&self, t: u64) -> StepCoefficients {
        let o = &self.options;
        let (b1, b2, b3) = o.betas;
        StepCoefficients {
            t,
            learning_rate: o.lr * (t as f64 * (1.0 - b1) / o.ramp).min(1.0),
            laplacian_weight: o.laplacian_weight,
            grad_lim: o.grad_lim,
            clamp_only_nonzero_m1: o.clamp_only_nonzero_m1,
            m1: ulerp_weights(b1, t),
            m2: ulerp_weights(b2, t),
            nu: ulerp_weights(b3, t),
        }
    }
}

/// Fills δ_v (uniform Laplacian) and ℓ_v (capped shortest incident edge) for the vertices
/// `start..start + lap.len()`. Dead vertices get δ = 0 and ℓ = 0.
fn local_geometry(
    adjacency: &VertexAdjacency,
    positions: &[DVec3],
    edge_len_max: f64,
    start: usize,
    lap: &mut [DVec3],
    len: &mut [f64],
) {
    for i in 0..lap.len() {
        let v = start + i;
        let ring = adjacency.neighbors(v);
        if ring.is_empty() {
            lap[i] = DVec3::ZERO;
            len[i] = 0.0;
            continue;
        }
        let p = positions[v];
        let mut sum = DVec3::ZERO;
        let mut shortest = f64::INFINITY;
        for &u in ring {
            let q = positions[u as usize];
            sum += q;
            shortest = shortest.min(p.distance(q));
        }
        lap[i] = p - sum / ring.len() as f64;
        len[i] = shortest.min(edge_len_max);
    }
}

/// Replaces non-finite components by 0, counting them.
fn finite_or_zero(g: DVec3, count: &mut usize) -> DVec3 {
    let fix = |x: f64, count: &mut usize| {
        if x.is_finite() {
            x
        } else {
            *count += 1;
            0.0
        }
    };
    DVec3::new(fix(g.x, count), fix(g.y, count), fix(g.z, count))
}

/// The update of one live vertex (module docs).
fn update_vertex(
    position: &mut DVec3,
    s: &mut VertexState,
    gradient: DVec3,
    laplacian: DVec3,
    ref_len: f64,
    k: &StepCoefficients,
    partial: &mut Partial,
) {
    let mut g = finite_or_zero(gradient, &mut partial.nonfinite)
        + finite_or_zero(
            k.laplacian_weight * s.nu * laplacian,
            &mut partial.nonfinite,
        );

    if k.t > 1 {
        let mut clamp = |g: f64, m1: f64| {
            let limit = if m1 == 0.0 {
                if k.clamp_only_nonzero_m1 {
                    return g;
                }
                0.0
            } else {
                k.grad_lim * m1.abs()
            };
            if g.abs() > limit {
                partial.clamped += 1;
                limit.copysign(g)
            } else {
                g
            }
        };
        g = DVec3::new(clamp(g.x, s.m1.x), clamp(g.y, s.m1.y), clamp(g.z, s.m1.z));
    }

    s.m1 = s.m1 * k.m1.0 + g * k.m1.1;
    s.m2 = s.m2 * k.m2.0 + g.length_squared() * k.m2.1;
    let velocity = s.m1 / (s.m2.sqrt() + VELOCITY_EPSILON);
    s.nu = s.nu * k.nu.0 + velocity.length() * k.nu.1;

    let ref_len = if ref_len.is_finite() { ref_len } else { 0.0 };
    let delta = velocity * (-k.learning_rate * ref_len);
    *position += delta;

    let moved = delta.length();
    partial.live += 1;
    partial.sum_move += moved;
    partial.max_move = partial.max_move.max(moved);
    partial.sum_nu += s.nu;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_geometry_matches_brute_force() {
        // A square pyramid (apex 4) with a skewed apex, plus a dead vertex 5.
        let positions = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.3, 0.2, 0.05),
            DVec3::new(9.0, 9.0, 9.0),
        ];
        let triangles = [
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
            [0, 2, 1],
            [0, 3, 2],
        ];
        let adjacency = VertexAdjacency::from_triangles(6, &triangles).unwrap();
        let mut lap = vec![DVec3::NAN; 6];
        let mut len = vec![f64::NAN; 6];
        local_geometry(&adjacency, &positions, 0.5, 0, &mut lap, &mut len);

        for v in 0..5 {
            let mut ring: Vec<usize> = triangles
                .iter()
                .filter(|t| t.contains(&(v as u32)))
                .flat_map(|t| t.iter().map(|&u| u as usize))
                .filter(|&u| u != v)
                .collect();
            ring.sort();
            ring.dedup();
            let mean = ring.iter().map(|&u| positions[u]).sum::<DVec3>() / ring.len() as f64;
            let shortest = ring
                .iter()
                .map(|&u| positions[v].distance(positions[u]))
                .fold(f64::INFINITY, f64::min);
            assert!(
                (lap[v] - (positions[v] - mean)).length() < 1e-15,
                "δ of {v}"
            );
            assert_eq!(len[v], shortest.min(0.5), "ℓ of {v}");
        }
        // Apex: shortest edge is to vertex 0 (√(0.09 + 0.04 + 0.0025) < 0.5).
        assert!((len[4] - (0.1325f64).sqrt()).abs() < 1e-15);
        assert_eq!((lap[5], len[5]), (DVec3::ZERO, 0.0), "dead vertex");
    }
}
