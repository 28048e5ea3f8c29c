//! The [`Optimizer`]: its state rows, its step and the step's per-vertex update.

use super::adjacency::VertexAdjacency;
use super::error::OptimError;
use super::options::OptimizerOptions;
use super::state::VertexState;
use glam::DVec3;
use rayon::prelude::*;
use std::ops::{Add, Mul};

/// Added to √m2 before dividing, so a vertex with zero gradient history does not divide by
/// zero (the authors' `eps = 1e-8`).
pub const VELOCITY_EPSILON: f64 = 1e-8;

/// Vertices per work unit. The per-step reductions (mean move, …) sum per-chunk partials in
/// chunk order, so results are bit-identical whether the chunks run in parallel or not.
const CHUNK: usize = 4096;

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
    pub(super) state: Vec<VertexState>,
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
