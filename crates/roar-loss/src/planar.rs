//! The planar projection loss `L_planar`: its form is ours where the paper is silent
//! (`docs/method.md#decision-form-of-the-planar-loss`), and so is its scale
//! (`docs/method.md#decision-balance-of-the-planar-term`).
//!
//! Every evaluation regularly samples the current source mesh (sample normals blended
//! from ROAR vertex normals), moves each sample toward the target point cloud P along its normal
//! (k-NN planar projection, the s2t term, plus the t2s term that reaches thin target parts), and
//! measures `scale · mean_i ‖s_i − sg(s_i + d_i)‖²`. The projected points are constants
//! (stop-gradient), so `∂L/∂s_i = −2·scale·d_i / N` and each sample passes its gradient to its
//! face's three vertices through its barycentric weights.

use std::borrow::Cow;

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use roar_mesh::spatial::regular_sampling::{
    continuous_grid_size, face_grid, grid_point_count, round_grid_size,
};
/// The ROAR vertex normals (area × corner-angle weights), a kernel of `roar_mesh::spatial`.
pub use roar_mesh::spatial::vertex_normals;
use roar_mesh::spatial::{RegularSamples, RegularSamplingOptions};

use crate::error::LossError;
use crate::knn_projector::{KnnOptions, KnnPlanarProjector, answers_in_order};
use crate::loss::Loss;
use crate::point_tree::{PointTree, SearchStack};

/// Target points per parallel work item of the t2s assignment.
const CHUNK: usize = 4096;

/// The library's default of [`PlanarOptions::scale`], balanced on a sphere at weight 1: not the
/// scale `roar reconstruct` uses, which is [`RECONSTRUCTION_PLANAR_SCALE`]. With the raw loss the
/// planar gradient is far below the render gradient and would do almost nothing
/// (`docs/method.md#decision-balance-of-the-planar-term`). Measured by
/// `examples/planar_balance.rs` (36 views at 256², L1 render loss, icosphere source of radius 0.5
/// against a sphere of radius R, P = 200k exact samples): mean per-vertex gradient norm of the
/// render loss over the raw planar loss is 15–20 at R − r = 0.01 and 2.8–3.8 at R − r = 0.05
/// (icospheres of 320, 1280 and 5120 faces; the ratio does not drift with resolution because both
/// scale like 1/#V). A factor 5 brings the terms to 3–4× (gap 0.01) and 0.6–0.8× (gap 0.05) at
/// weight 1, i.e. within 10× over the working range; the planar term still fades as the gap
/// closes (it is quadratic), the render term does not.
#[doc(alias = "DEFAULT_PLANAR_SCALE")]
pub const SPHERE_BALANCED_PLANAR_SCALE: f64 = 5.0;

/// The scale of the planar term in `roar reconstruct` (the default of its `[loss] planar_scale`),
/// balanced against the render term (weight 3) on the inits of real inputs, where the raw planar
/// gradient is far smaller against the render gradient than on the sphere
/// [`SPHERE_BALANCED_PLANAR_SCALE`] is balanced on. Measured with
/// `crates/roar/examples/loss_balance.rs` on wild meshes' inits at 5000 faces (mean per-vertex
/// gradient): 3·render ≈ 3.1e-3, raw planar ≈ 1.3e-6–3.1e-6, Laplacian ≈ 3e-4–6e-4; at 500 the
/// planar term (6e-4–1.5e-3) is within 5× of the render term instead of 500× below it
/// (`docs/method.md`). [`PlanarOptions::default`] does not use it.
pub const RECONSTRUCTION_PLANAR_SCALE: f64 = 500.0;

/// Default of [`PlanarOptions::max_samples`]: 12 500 source samples per evaluation (the paper's
/// density gives 150–300k on a typical shape). Measured by `examples/planar_profile.rs`
/// (`CAP_STUDY=1`; 5 120-face bumpy sphere, 263k regular samples uncapped): the relative L2 error
/// of one evaluation's gradient against uncapped evaluations is 5.2% uncapped (the floor set by the
/// stochastic grid rounding), 6.1% at 100k, 8.7% at 50k, 13.5% at 25k, 20% at 12.5k. The samples
/// are drawn afresh at every evaluation, so this error averages out over the iterations; one
/// evaluation at 12.5k costs about a third of one at 50k (the k-NN queries and the t2s tree scale
/// with the sample count, the t2s queries of the target points do not). Its effect on
/// `roar reconstruct`'s outputs: `docs/method.md#planar-loss`.
pub const DEFAULT_MAX_SAMPLES: usize = 12_500;

/// Default cap on the target points the t2s term queries per evaluation
/// ([`PlanarOptions::t2s_max_points`]); the paper queries them all. Every target point's
/// nearest-sample query (229k on a soup: the cloud plus its sharp-edge samples) is the largest
/// single kernel of a 1000-face run; a spatially even fifth of them per evaluation, a different
/// fifth each time, measured on the 14 wild meshes: `docs/method.md#planar-loss`.
pub const DEFAULT_T2S_MAX_POINTS: usize = 50_000;

/// Options of [`PlanarLoss`] (`docs/method.md#planar-loss`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarOptions {
    /// The s2t k-NN projection (k = 10, threshold 0.01, guard 1.01, mode along-normal).
    pub knn: KnnOptions,
    /// Include the target→source term, which reaches thin target parts no sample is near
    /// (default true; false for ablations).
    pub t2s: bool,
    /// t2s moves a sample only if `m_{t*}·n_i ≥` this. Default 0.95 (the authors' code).
    pub t2s_normal_dot: f64,
    /// Most target points the t2s term queries per evaluation (default
    /// [`DEFAULT_T2S_MAX_POINTS`]; 0 = all, as the paper). Above it, every `s`-th point of the
    /// cloud's spatial order, `s = ⌈points/cap⌉`, from an offset that advances by one per
    /// evaluation, so `s` consecutive evaluations query every point once ([`t2s_subset`]).
    pub t2s_max_points: usize,
    /// Regular sampling of the source (δ = 0.002, n ≤ 16, n ≥ 3).
    pub sampling: RegularSamplingOptions,
    /// Cap on source samples per evaluation (default [`DEFAULT_MAX_SAMPLES`]). Above it, every
    /// face keeps a share `cap/total` of its samples (stratified, see [`stratified_subsample`]).
    pub max_samples: usize,
    /// Multiplies the raw loss `mean_i ‖d_i‖²` and its gradient.
    /// 1 is the raw loss; the default [`SPHERE_BALANCED_PLANAR_SCALE`] makes the planar
    /// gradient comparable to the render gradient at weight 1 on a sphere (`roar reconstruct`
    /// passes [`RECONSTRUCTION_PLANAR_SCALE`]). The raw and render gradients both scale
    /// like 1/#V per vertex, so a constant factor keeps the balance across resolutions.
    pub scale: f64,
    /// Seed of the ChaCha8 stream that drives sampling; advanced on every evaluation.
    pub seed: u64,
}

impl Default for PlanarOptions {
    fn default() -> Self {
        Self {
            knn: KnnOptions::default(),
            t2s: true,
            t2s_normal_dot: 0.95,
            t2s_max_points: DEFAULT_T2S_MAX_POINTS,
            sampling: RegularSamplingOptions::default(),
            max_samples: DEFAULT_MAX_SAMPLES,
            scale: SPHERE_BALANCED_PLANAR_SCALE,
            seed: 0,
        }
    }
}

impl PlanarOptions {
    /// The raw loss (`scale = 1`, mean over samples), other options default.
    pub fn raw() -> Self {
        Self {
            scale: 1.0,
            ..Self::default()
        }
    }
}

/// What the last evaluation of [`PlanarLoss`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlanarStats {
    /// Regular samples generated on the source.
    pub samples_generated: usize,
    /// Samples kept after the cap (the N of the mean).
    pub samples_used: usize,
    /// Kept samples with no valid move from either term (d = 0).
    pub unprojected: usize,
    /// Kept samples whose move came from the t2s term (larger magnitude than s2t).
    pub from_t2s: usize,
    /// Raw loss `mean ‖d_i‖²` (before `scale`).
    pub raw_loss: f64,
    /// Largest |d_i|.
    pub max_move: f64,
}

/// The planar projection loss against a fixed oriented point cloud.
pub struct PlanarLoss {
    projector: KnnPlanarProjector,
    options: PlanarOptions,
    rng: ChaCha8Rng,
    /// Evaluations so far: which subset of the target points the t2s term queries.
    evaluations: usize,
    /// Statistics of the last evaluation.
    pub last_stats: PlanarStats,
}

impl PlanarLoss {
    /// A planar loss toward the target cloud `points`/`normals` (one unit normal per point).
    /// Errors: mismatched lengths, empty cloud, non-finite input.
    pub fn new(
        points: &[DVec3],
        normals: &[DVec3],
        options: &PlanarOptions,
    ) -> Result<Self, LossError> {
        Ok(Self {
            projector: KnnPlanarProjector::new(points, normals, &options.knn)?,
            options: *options,
            rng: ChaCha8Rng::seed_from_u64(options.seed),
            evaluations: 0,
            last_stats: PlanarStats::default(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &PlanarOptions {
        &self.options
    }

    /// The k-NN projector over the target cloud.
    pub fn projector(&self) -> &KnnPlanarProjector {
        &self.projector
    }

    /// The moves `d_i` of the given samples (s2t, combined with t2s when enabled): `None` when
    /// neither term gives a valid move. Deterministic.
    pub fn moves(&self, points: &[DVec3], normals: &[DVec3]) -> Vec<Option<DVec3>> {
        self.moves_and_t2s_count(points, normals).0
    }

    /// [`PlanarLoss::moves`], and how many of them came from the t2s term.
    fn moves_and_t2s_count(
        &self,
        points: &[DVec3],
        normals: &[DVec3],
    ) -> (Vec<Option<DVec3>>, usize) {
        if !self.options.t2s {
            return (self.projector.displacements(points, normals), 0);
        }
        // The t2s tree over the samples also gives s2t a coherent search order.
        let tree = SampleTree::new(points);
        let s2t = self
            .projector
            .displacements_in_order(points, normals, &tree.spatial_order());
        let t2s = t2s_moves_in_order(
            points,
            normals,
            &tree,
            self.projector.points(),
            self.projector.normals(),
            self.options.t2s_normal_dot,
            &t2s_subset(
                self.projector.spatial_order(),
                self.options.t2s_max_points,
                self.evaluations,
            ),
        );
        let from_t2s = s2t
            .iter()
            .zip(&t2s)
            .filter(|(a, b)| len2(**b) > len2(**a))
            .count();
        (combine_moves(&s2t, &t2s), from_t2s)
    }

    /// The regular samples of this evaluation under the cap (normals blended from
    /// the source's ROAR vertex normals); advances the RNG.
    fn draw_samples(&mut self, positions: &[DVec3], triangles: &[[u32; 3]]) -> CappedSamples {
        let normals = vertex_normals(positions, triangles);
        capped_regular_samples(
            positions,
            triangles,
            &normals,
            &self.options.sampling,
            self.options.max_samples,
            &mut self.rng,
        )
    }
}

impl Loss for PlanarLoss {
    fn name(&self) -> &'static str {
        "planar"
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        check_mesh(positions, triangles)?;
        let CappedSamples {
            points,
            normals,
            faces,
            barycentrics,
            generated,
        } = self.draw_samples(positions, triangles);

        let (moves, from_t2s) = self.moves_and_t2s_count(&points, &normals);
        self.evaluations += 1;
        let targets: Vec<Option<DVec3>> = moves
            .iter()
            .zip(&points)
            .map(|(d, &s)| d.map(|d| s + d))
            .collect();
        let (raw, mut grad) =
            planar_loss_fixed_targets(positions, triangles, &faces, &barycentrics, &targets);
        for g in &mut grad {
            *g *= self.options.scale;
        }
        self.last_stats = PlanarStats {
            samples_generated: generated,
            samples_used: points.len(),
            unprojected: moves.iter().filter(|d| d.is_none()).count(),
            from_t2s,
            raw_loss: raw,
            max_move: moves
                .iter()
                .flatten()
                .map(|d| d.length())
                .fold(0.0, f64::max),
        };
        Ok((self.options.scale * raw, grad))
    }
}

/// Squared length of an optional move (0 for `None`).
fn len2(d: Option<DVec3>) -> f64 {
    d.map_or(0.0, |d| d.length_squared())
}

/// Per sample, the move with the larger magnitude of the two terms; ties and equal magnitudes keep
/// s2t. `None` only when both are `None`.
pub fn combine_moves(s2t: &[Option<DVec3>], t2s: &[Option<DVec3>]) -> Vec<Option<DVec3>> {
    s2t.iter()
        .enumerate()
        .map(|(i, &a)| {
            let b = t2s.get(i).copied().flatten();
            match (a, b) {
                (Some(a), Some(b)) if b.length_squared() > a.length_squared() => Some(b),
                (None, Some(b)) => Some(b),
                _ => a,
            }
        })
        .collect()
}

/// The target→source term: every target point is assigned to its nearest
/// sample (f32 kd-tree over the samples, ties to the smaller sample index; the assigned
/// distance is recomputed in f64); each sample takes its farthest assigned point `t*` (ties: smaller target index) and,
/// if `m_{t*}·n_i ≥ normal_dot`, the along-normal intersection with the plane `(t*, m_{t*})`.
/// The blow-up guard of s2t is not applied (the 0.95 gate bounds the move). `None` for samples
/// with no assigned point, a failed gate, or non-finite input.
pub fn t2s_moves(
    samples: &[DVec3],
    sample_normals: &[DVec3],
    target_points: &[DVec3],
    target_normals: &[DVec3],
    normal_dot: f64,
) -> Vec<Option<DVec3>> {
    let order: Vec<u32> = (0..target_points.len() as u32).collect();
    t2s_moves_in_order(
        samples,
        sample_normals,
        &SampleTree::new(samples),
        target_points,
        target_normals,
        normal_dot,
        &order,
    )
}

/// The kd-tree over the finite samples of one evaluation (the t2s searches run in it).
struct SampleTree {
    /// Sample index of each tree point.
    finite: Vec<usize>,
    tree: PointTree,
}

impl SampleTree {
    fn new(samples: &[DVec3]) -> Self {
        let finite: Vec<usize> = (0..samples.len())
            .filter(|&i| samples[i].is_finite())
            .collect();
        let finite_points: Vec<DVec3> = finite.iter().map(|&i| samples[i]).collect();
        Self {
            tree: PointTree::new(&finite_points),
            finite,
        }
    }

    /// The finite samples' indices in the tree's leaf order (spatially coherent).
    fn spatial_order(&self) -> Vec<u32> {
        self.tree
            .spatial_order()
            .iter()
            .map(|&local| self.finite[local as usize] as u32)
            .collect()
    }
}

/// The target points (indices in the cloud's spatial `order`) the t2s term queries at
/// evaluation `evaluation` under the cap `max_points` (0 = all): every `s`-th of `order`,
/// `s = ⌈len/max_points⌉`, from offset `evaluation mod s`. Spatially even, since `order` is
/// coherent; the subsets of `s` consecutive evaluations partition `order`.
fn t2s_subset(order: &[u32], max_points: usize, evaluation: usize) -> Cow<'_, [u32]> {
    if max_points == 0 || order.len() <= max_points {
        return Cow::Borrowed(order);
    }
    let stride = order.len().div_ceil(max_points);
    Cow::Owned(
        order
            .iter()
            .skip(evaluation % stride)
            .step_by(stride)
            .copied()
            .collect(),
    )
}

/// [`t2s_moves`] with the samples' `tree` (built over `samples`), over the target points
/// listed in `order` only (indices, each at most once: all of them, or a [`t2s_subset`]),
/// visited in that order (a spatially coherent one makes the searches cheaper; the result
/// does not depend on the order, only on which points it lists).
fn t2s_moves_in_order(
    samples: &[DVec3],
    sample_normals: &[DVec3],
    tree: &SampleTree,
    target_points: &[DVec3],
    target_normals: &[DVec3],
    normal_dot: f64,
    order: &[u32],
) -> Vec<Option<DVec3>> {
    let mut result = vec![None; samples.len()];
    let SampleTree { finite, tree } = tree;
    if finite.is_empty() || target_points.is_empty() {
        return result;
    }
    // Each target point goes to its nearest sample; the previous answer of the chunk bounds the
    // next search (it never changes the answer).
    let assign_chunk = |chunk: &[u32]| -> Vec<Option<(u32, f64)>> {
        let mut hint = None;
        let mut stack = SearchStack::default();
        chunk
            .iter()
            .map(|&j| {
                let t = *target_points.get(j as usize)?;
                if !t.is_finite() {
                    return None;
                }
                let local = tree.nearest_one(t, hint, &mut stack)?;
                hint = Some(local);
                let i = finite[local as usize];
                Some((i as u32, samples[i].distance_squared(t)))
            })
            .collect()
    };
    let assigned = answers_in_order(order, target_points.len(), CHUNK, assign_chunk);
    let mut farthest: Vec<Option<(usize, f64)>> = vec![None; samples.len()];
    for (j, a) in assigned.iter().enumerate() {
        let Some((i, d2)) = *a else { continue };
        let slot = &mut farthest[i as usize];
        if slot.is_none_or(|(_, best)| d2 > best) {
            *slot = Some((j, d2));
        }
    }
    for (i, slot) in farthest.iter().enumerate() {
        let (Some((j, _)), Some(&n)) = (slot, sample_normals.get(i)) else {
            continue;
        };
        let (t, m) = (target_points[*j], target_normals[*j]);
        let cos = m.dot(n);
        if cos.is_nan() || cos < normal_dot || cos <= 0.0 {
            continue;
        }
        let d = ((t - samples[i]).dot(m) / cos) * n;
        if d.is_finite() {
            result[i] = Some(d);
        }
    }
    result
}

/// The planar loss for **fixed** projected points (the stop-gradient targets): with
/// `s_i = Σ_k w_ik v_{f_i,k}` (barycentrics `w_i` in face `f_i`), returns
/// `L = (1/N) Σ_i ‖s_i − q_i‖²` over the `N = faces.len()` samples (a `None` target contributes
/// 0 but counts in N) and `∂L/∂v` (`∂L/∂s_i = 2 (s_i − q_i)/N`, scattered with `w_i`).
/// Samples whose face is out of range are skipped. This is what [`PlanarLoss`] differentiates.
pub fn planar_loss_fixed_targets(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    faces: &[u32],
    barycentrics: &[[f64; 3]],
    targets: &[Option<DVec3>],
) -> (f64, Vec<DVec3>) {
    let mut grad = vec![DVec3::ZERO; positions.len()];
    let n = faces.len();
    if n == 0 {
        return (0.0, grad);
    }
    let inv_n = 1.0 / n as f64;
    let mut loss = 0.0;
    for ((&f, w), q) in faces.iter().zip(barycentrics).zip(targets) {
        let (Some(q), Some(tri)) = (q, triangles.get(f as usize)) else {
            continue;
        };
        let Some(corners) = corner_positions(positions, tri) else {
            continue;
        };
        let s = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2];
        let r = s - *q;
        loss += r.length_squared();
        let g = 2.0 * inv_n * r;
        for k in 0..3 {
            grad[tri[k] as usize] += w[k] * g;
        }
    }
    (loss * inv_n, grad)
}

fn corner_positions(positions: &[DVec3], tri: &[u32; 3]) -> Option<[DVec3; 3]> {
    Some([
        *positions.get(tri[0] as usize)?,
        *positions.get(tri[1] as usize)?,
        *positions.get(tri[2] as usize)?,
    ])
}

/// Indices of the samples kept under `cap` (at most `cap` samples per evaluation).
///
/// All samples when there are at most `cap`. Otherwise each face keeps a share `p = cap/total`
/// of its own samples, stratified: `k_f = ⌊p·m_f + u⌋` (u uniform, one draw per face, so the
/// expected total is `cap`), picked by systematic sampling of the face's grid (stride `m_f/k_f`,
/// random offset, one more draw), so every face keeps a spread of its samples in expectation and
/// large faces keep proportionally more. Indices are sorted ascending; deterministic for a
/// seeded `rng`.
pub fn stratified_subsample(
    samples: &RegularSamples,
    cap: usize,
    rng: &mut impl Rng,
) -> Vec<usize> {
    let counts: Vec<usize> = (0..samples.face_n.len())
        .map(|f| samples.face_samples(f).len())
        .collect();
    let mut kept = Vec::with_capacity(cap.min(samples.points.len()) + counts.len());
    stratified_pick(&counts, cap, rng, |f, local| {
        kept.push(samples.face_samples(f).start + local)
    });
    kept
}

/// The selection of [`stratified_subsample`] from per-face sample counts alone: calls
/// `keep(face, local index)` for every kept sample, in face order then ascending local index.
/// Draws from `rng` exactly as [`stratified_subsample`] does (nothing when all are kept).
fn stratified_pick(
    counts: &[usize],
    cap: usize,
    rng: &mut impl Rng,
    mut keep: impl FnMut(usize, usize),
) {
    let total: usize = counts.iter().sum();
    if total <= cap {
        for (f, &m) in counts.iter().enumerate() {
            for local in 0..m {
                keep(f, local);
            }
        }
        return;
    }
    let p = cap as f64 / total as f64;
    for (f, &m) in counts.iter().enumerate() {
        let u: f64 = rng.random();
        let k = ((p * m as f64 + u).floor() as usize).min(m);
        if k == 0 {
            continue;
        }
        let stride = m as f64 / k as f64;
        let offset: f64 = rng.random::<f64>() * stride;
        for j in 0..k {
            keep(f, ((offset + j as f64 * stride) as usize).min(m - 1));
        }
    }
}

/// The kept regular samples of one evaluation, as parallel arrays.
struct CappedSamples {
    points: Vec<DVec3>,
    normals: Vec<DVec3>,
    faces: Vec<u32>,
    barycentrics: Vec<[f64; 3]>,
    /// Regular samples the grids hold before the cap.
    generated: usize,
}

/// [`regular_samples`](roar_mesh::spatial::regular_samples) followed by
/// [`stratified_subsample`], without generating the samples the
/// cap drops: grid sizes first (same RNG draws as `regular_samples`), then the stratified pick
/// from the per-face counts (same draws as `stratified_subsample`), then only the kept points.
/// Gives the same samples, bit for bit, as the two-step route. The mesh must be checked
/// (indices in range) and `vertex_normals` must hold one normal per position.
fn capped_regular_samples(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: &[DVec3],
    sampling: &RegularSamplingOptions,
    cap: usize,
    rng: &mut impl Rng,
) -> CappedSamples {
    let diagonal = referenced_bbox_diagonal(positions, triangles);
    let sizes: Vec<u32> = triangles
        .iter()
        .map(|tri| {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            let doubled_area = (p1 - p0).cross(p2 - p0).length();
            let n_cont = continuous_grid_size(doubled_area, diagonal, sampling.density);
            round_grid_size(n_cont, sampling.min_n, sampling.max_n, rng)
        })
        .collect();
    let counts: Vec<usize> = sizes.iter().map(|&n| grid_point_count(n)).collect();
    let generated = counts.iter().sum();
    let mut picks: Vec<(u32, u32)> = Vec::with_capacity(cap.min(generated) + triangles.len());
    stratified_pick(&counts, cap, rng, |f, local| {
        picks.push((f as u32, local as u32))
    });

    // Barycentric grids per size (at most `max_n` distinct ones).
    let largest = sizes.iter().copied().max().unwrap_or(0) as usize;
    let mut grids: Vec<Vec<[f64; 3]>> = vec![Vec::new(); largest + 1];
    for &n in &sizes {
        if grids[n as usize].is_empty() {
            grids[n as usize] = face_grid(n).0;
        }
    }
    let mut out = CappedSamples {
        points: Vec::with_capacity(picks.len()),
        normals: Vec::with_capacity(picks.len()),
        faces: Vec::with_capacity(picks.len()),
        barycentrics: Vec::with_capacity(picks.len()),
        generated,
    };
    for &(f, local) in &picks {
        let tri = triangles[f as usize];
        let corners = tri.map(|v| positions[v as usize]);
        let w = grids[sizes[f as usize] as usize][local as usize];
        let vn = tri.map(|v| vertex_normals[v as usize]);
        let blended = (w[0] * vn[0] + w[1] * vn[1] + w[2] * vn[2]).normalize_or_zero();
        let normal = if blended == DVec3::ZERO {
            (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .normalize_or_zero()
        } else {
            blended
        };
        out.points
            .push(w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2]);
        out.normals.push(normal);
        out.faces.push(f);
        out.barycentrics.push(w);
    }
    out
}

/// Bounding-box diagonal of the vertices referenced by `triangles` (0 when there are none), the
/// D of the sampling density.
fn referenced_bbox_diagonal(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for tri in triangles {
        for &v in tri {
            lo = lo.min(positions[v as usize]);
            hi = hi.max(positions[v as usize]);
        }
    }
    if triangles.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    }
}

/// Checks the source buffers: in-range indices and finite positions.
fn check_mesh(positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<(), LossError> {
    if let Some(f) = triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= positions.len()))
    {
        return Err(LossError::InvalidMesh(format!(
            "triangle {f} refers to a missing vertex"
        )));
    }
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(LossError::InvalidMesh(format!(
            "vertex {v} has a non-finite position"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults the docs of [`PlanarOptions`], its constants and [`KnnOptions`] state.
    #[test]
    fn documented_defaults() {
        assert_eq!(SPHERE_BALANCED_PLANAR_SCALE, 5.0);
        assert_eq!(RECONSTRUCTION_PLANAR_SCALE, 500.0);
        assert_eq!(DEFAULT_MAX_SAMPLES, 12_500);
        let o = PlanarOptions::default();
        assert_eq!(o.scale, SPHERE_BALANCED_PLANAR_SCALE);
        assert_eq!(o.max_samples, DEFAULT_MAX_SAMPLES);
        assert!(o.t2s);
        assert_eq!(o.t2s_normal_dot, 0.95);
        assert_eq!(o.t2s_max_points, DEFAULT_T2S_MAX_POINTS);
        assert_eq!(DEFAULT_T2S_MAX_POINTS, 50_000);
        assert_eq!(PlanarOptions::raw().scale, 1.0);
        assert_eq!(
            (o.knn.k, o.knn.normal_dot_threshold, o.knn.blowup_guard),
            (10, 0.01, 1.01)
        );
        assert_eq!(o.knn.mode, crate::knn_projector::PlanarMode::AlongNormal);
    }

    #[test]
    fn t2s_subsets_of_consecutive_evaluations_partition_the_cloud() {
        let order: Vec<u32> = (0..23).rev().collect();
        // Under the cap, or without one, every evaluation queries every point in order.
        for (cap, evaluation) in [(0, 0), (0, 5), (23, 1), (100, 2)] {
            assert_eq!(&*t2s_subset(&order, cap, evaluation), &order[..]);
        }
        // 23 points under a cap of 5: stride 5, subsets of 5 or 4 points, each in order, and
        // the 5 consecutive evaluations from any start query each point exactly once.
        assert_eq!(&*t2s_subset(&order, 5, 0), &[22, 17, 12, 7, 2]);
        assert_eq!(&*t2s_subset(&order, 5, 9), &[18, 13, 8, 3]);
        for start in [0, 3, 7] {
            let mut seen: Vec<u32> = (start..start + 5)
                .flat_map(|e| t2s_subset(&order, 5, e).into_owned())
                .collect();
            assert!((start..start + 5).all(|e| t2s_subset(&order, 5, e).len() <= 5));
            seen.sort_unstable();
            assert_eq!(seen, (0..23).collect::<Vec<u32>>());
        }
    }

    /// A flat unit square against a grid of target points on it plus one point 0.3 above its
    /// middle, which only the t2s term reaches (it is never among a sample's 10 nearest): the
    /// evaluation's largest move is about 0.3 exactly when the t2s term queries that point.
    /// Under a cap of half the cloud, one of any two consecutive evaluations does; without a
    /// cap, both.
    #[test]
    fn the_loss_queries_the_capped_subset_of_its_evaluation() {
        let mut points: Vec<DVec3> = (0..21)
            .flat_map(|i| (0..21).map(move |j| DVec3::new(i as f64, j as f64, 0.0) / 20.0))
            .collect();
        points.push(DVec3::new(0.5, 0.5, 0.3));
        let normals = vec![DVec3::Z; points.len()];
        let positions = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let reaches_the_point = |cap: usize| -> Vec<bool> {
            let options = PlanarOptions {
                t2s_max_points: cap,
                ..PlanarOptions::default()
            };
            let mut loss = PlanarLoss::new(&points, &normals, &options).unwrap();
            (0..4)
                .map(|_| {
                    loss.value_and_grad(&positions, &triangles).unwrap();
                    loss.last_stats.max_move > 0.2
                })
                .collect()
        };
        assert_eq!(reaches_the_point(0), [true; 4]);
        let capped = reaches_the_point(points.len() / 2);
        assert!(
            capped == [true, false, true, false] || capped == [false, true, false, true],
            "{capped:?}"
        );
    }

    #[test]
    fn vertex_normals_of_a_tetrahedron_point_outward() {
        let p = vec![
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        let t = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        for (v, n) in vertex_normals(&p, &t).iter().enumerate() {
            assert!((n.dot(p[v].normalize()) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn capped_sampler_matches_sampling_then_subsampling() {
        use rand::SeedableRng;
        use roar_mesh::shapes::{icosphere, perturbed};
        use roar_mesh::spatial::regular_samples;
        let (p, t) = perturbed(&icosphere(2), 0.05, 9).to_triangles();
        let normals = vertex_normals(&p, &t);
        let options = RegularSamplingOptions {
            density: 0.01,
            ..RegularSamplingOptions::default()
        };
        for cap in [usize::MAX, 5000, 700, 0] {
            let mut a = ChaCha8Rng::seed_from_u64(5);
            let mut b = a.clone();
            let full = regular_samples(&p, &t, Some(&normals), &options, &mut a).unwrap();
            let kept = stratified_subsample(&full, cap, &mut a);
            let capped = capped_regular_samples(&p, &t, &normals, &options, cap, &mut b);
            assert!(kept.len() < full.points.len() || cap == usize::MAX);
            assert_eq!(capped.generated, full.points.len());
            assert_eq!(
                capped.points,
                kept.iter().map(|&i| full.points[i]).collect::<Vec<_>>()
            );
            assert_eq!(
                capped.normals,
                kept.iter().map(|&i| full.normals[i]).collect::<Vec<_>>()
            );
            assert_eq!(
                capped.faces,
                kept.iter().map(|&i| full.faces[i]).collect::<Vec<_>>()
            );
            let bary: Vec<[f64; 3]> = kept.iter().map(|&i| full.barycentrics[i]).collect();
            assert_eq!(capped.barycentrics, bary);
            // Both routes leave the generator in the same state.
            assert_eq!(a.random::<u64>(), b.random::<u64>());
        }
    }

    #[test]
    fn larger_move_wins_and_none_yields() {
        let a = [Some(DVec3::X), None, Some(DVec3::X * 3.0), None];
        let b = [Some(DVec3::Y * 2.0), Some(DVec3::Z), Some(DVec3::Y), None];
        let c = combine_moves(&a, &b);
        assert_eq!(
            c,
            vec![
                Some(DVec3::Y * 2.0),
                Some(DVec3::Z),
                Some(DVec3::X * 3.0),
                None
            ]
        );
    }
}
