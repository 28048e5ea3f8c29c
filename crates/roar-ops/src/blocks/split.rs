//! The Face Split block: resolution allocation under a face budget, as in the authors' code
//! (`docs/method.md#face-split`).
//!
//! 1. Regular samples of every face with smooth normals, projected onto the target by a
//!    [`Projector`].
//! 2. Face scores: on each face's projected grid, ROAR vertex normals from the valid projected
//!    sub-triangles; per sub-triangle `fold(t) = 1 − (1/3) Σ_c ñ_t·ñ_c`, zeroed when folded (> 1),
//!    invalid, flipped against the source face, or below the threshold (0.02 per sub-triangle by
//!    default, as the authors' scoring code; the per-face rule is a switch:
//!    `docs/method.md#decision-face-score-threshold`); `S_f = Σ_t fold(t)`, zeroed for folded
//!    source faces (φ_f > 1) and faces with an edge shorter than 5e-4.
//! 3. Edge costs `C_e = P_e + QS_e` (P_e = max S over faces touching either endpoint, QS_e = the
//!    QSlim cost of the best valid placement with the flip and Q ≤ 5 tests, +∞ if none),
//!    suppression of faces next to edges with `C_e < 1e-3`, independent set with priorities
//!    `exp(−C_e)`, `c_e = max(C_e, P_e)`.
//! 4. Pairing and budget (`docs/method.md#decision-budget-logic-of-the-face-split-block`), then
//!    collapses, then 1→3 centroid splits (the tracked store hears of each: the new vertex gets the
//!    mean optimizer row), then compaction.

use crate::blocks::block::{Block, BlockContext, BlockStats};
use crate::blocks::collapse::apply_collapse;
use crate::blocks::guard::IntersectionGuard;
use crate::blocks::qslim::{
    EdgeCost, QSlimOptions, ValidityOptions, edge_cost, edge_cost_lower_bound, vertex_quadrics,
};
use crate::blocks::select::{SelectOptions, Selection, select_independent_edges};
use crate::geometry::Geometry;
use crate::quadric::Quadric;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use roar_mesh::spatial::{
    Projector, RegularSamples, RegularSamplingOptions, SamplePoints, face_grid, grid_point_count,
    regular_sample_points_into,
};
use roar_mesh::{DEGENERATE_CROSS, DVec3, EdgeId, FaceId, Mesh, TrackedMesh};
use std::cell::RefCell;

/// The curvature threshold of the face score, per sub-triangle: the default of
/// [`SplitThreshold`] and of `roar reconstruct`'s `[optimize] split_threshold`.
pub const DEFAULT_SPLIT_THRESHOLD: f64 = 0.02;

/// Where the 0.02 curvature threshold of the face score applies
/// (`docs/method.md#decision-face-score-threshold`). Some threshold is needed either way: with 0,
/// rounding noise makes flat faces score.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SplitThreshold {
    /// A sub-triangle whose fold is below the value counts 0 (the authors' scoring code).
    /// Default [`DEFAULT_SPLIT_THRESHOLD`].
    PerSubTriangle(f64),
    /// Sub-triangles count whatever their fold; a face whose total is below the value scores
    /// 0 (the supplementary's threshold read per face).
    PerFace(f64),
}

impl Default for SplitThreshold {
    fn default() -> Self {
        SplitThreshold::PerSubTriangle(DEFAULT_SPLIT_THRESHOLD)
    }
}

/// Options of [`face_split`]; the defaults are the authors' code's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceSplitOptions {
    /// Regular sampling of the faces (density 0.002, cap n = 16).
    pub sampling: RegularSamplingOptions,
    /// Score threshold. Default 0.02 per sub-triangle (supplementary §1.2, applied as the authors'
    /// code applies it).
    pub threshold: SplitThreshold,
    /// Faces with an edge shorter than this score 0. Default 5e-4 = 0.1·edge_len_min (the
    /// authors' code).
    pub min_edge_length: f64,
    /// τ_e: edges with `C_e` below this suppress their faces' scores and are collapsed for
    /// free. Default 1e-3 (`edge_curvature_threshold`).
    pub edge_cost_threshold: f64,
    /// Cap on splits per call. Default 4000 (`max_faces_to_split`, a constant in the
    /// authors' code).
    pub max_faces_to_split: usize,
    /// Collapse validity: flip test and `Q ≤ 5` (`collapse_quality_threshold`; supplementary §1.2).
    pub validity: ValidityOptions,
    /// QSlim weights and vertex-plane variant.
    pub qslim: QSlimOptions,
    /// Independent selection.
    pub select: SelectOptions,
    /// Seed of the sampler's stochastic rounding (the block wrapper mixes in the iteration).
    pub seed: u64,
    /// Compute the QSlim cost (with its validity simulation) only for the edges that can
    /// change the result: those with `C_e` below τ, and, at or over budget when those do not
    /// decide the swap count, below the largest face score (exact: same collapses and splits;
    /// the `independent_edges`, `link` and, under budget, `swaps` stats then count only among
    /// those edges). `false` computes every edge, the reference for tests. Default true.
    pub prune_edge_costs: bool,
    /// Skip budget collapses that would make a face intersect another one
    /// ([`IntersectionGuard`], `rejected["intersection"]`; the swap's split is dropped with it).
    /// The centroid splits move no geometry and need no guard. Default off (the paper's block
    /// has none); the pipeline's `guard_intersections` key switches it on.
    pub guard_intersections: bool,
}

impl Default for FaceSplitOptions {
    fn default() -> Self {
        Self {
            sampling: RegularSamplingOptions::default(),
            threshold: SplitThreshold::default(),
            min_edge_length: 5e-4,
            edge_cost_threshold: 1e-3,
            max_faces_to_split: 4000,
            validity: ValidityOptions {
                max_quality: Some(5.0),
                ..ValidityOptions::default()
            },
            qslim: QSlimOptions::default(),
            select: SelectOptions::default(),
            seed: 0,
            prune_edge_costs: true,
            guard_intersections: false,
        }
    }
}

/// Face scores `S_f` of a **compact** mesh, by face id, from its regular samples and
/// their projections (`projected[i]` for `samples.points[i]`). Runs in parallel over faces
/// (deterministic: each face is independent).
pub fn face_scores(
    mesh: &Mesh,
    geometry: &Geometry,
    samples: &RegularSamples,
    projected: &[Option<DVec3>],
    options: &FaceSplitOptions,
) -> Vec<f64> {
    grid_scores(
        mesh,
        geometry,
        &samples.face_n,
        &samples.face_offsets,
        projected,
        options,
    )
}

/// [`face_scores`] from each face's grid size `face_n[f]` and first sample `face_offsets[f]`;
/// its sub-triangles are those of [`face_grid`], as in [`RegularSamples::sub_triangles`].
fn grid_scores(
    mesh: &Mesh,
    geometry: &Geometry,
    face_n: &[u32],
    face_offsets: &[u32],
    projected: &[Option<DVec3>],
    options: &FaceSplitOptions,
) -> Vec<f64> {
    let folds = geometry.face_folds(mesh);
    let (sub_threshold, face_threshold) = match options.threshold {
        SplitThreshold::PerSubTriangle(t) => (t, 0.0),
        SplitThreshold::PerFace(t) => (0.0, t),
    };
    let max_n = face_n.iter().copied().max().unwrap_or(0);
    let grids: Vec<Vec<[u32; 3]>> = (0..=max_n).map(|n| face_grid(n).1).collect();
    (0..mesh.face_capacity())
        .into_par_iter()
        .with_min_len(256)
        .map_init(
            || (Vec::new(), Vec::new()),
            |(normals, subs): &mut (Vec<DVec3>, Vec<DVec3>), f| {
                let face = FaceId::from_index(f);
                if !mesh.is_face_alive(face) || folds[f] > 1.0 {
                    return 0.0;
                }
                if mesh
                    .face_halfedges(face)
                    .iter()
                    .any(|h| mesh.edge_length(h.edge()) < options.min_edge_length)
                {
                    return 0.0;
                }
                let n = face_n[f] as usize;
                let s = grid_score(
                    projected,
                    face_offsets[f] as usize,
                    grid_point_count(n as u32),
                    &grids[n],
                    geometry.face_normals[f],
                    sub_threshold,
                    normals,
                    subs,
                );
                if s < face_threshold || s.is_nan() || s < 0.0 {
                    0.0
                } else {
                    s
                }
            },
        )
        .collect()
}

/// `Σ_t fold(t)` over one face's projected grid (module docs, step 2): its `count` samples start at
/// `start` in `projected` and `sub_triangles` index them from 0. `normals`/`subs` are scratch.
/// A projected sub-triangle with `|cross| ≤ 1e-9` counts as invalid (our rule; the paper does
/// not say).
///
/// The ROAR vertex normal weight `area · angle · n_t` is accumulated as `angle · cross_t`
/// (`cross_t = 2·area·n_t`; the common factor vanishes in the normalization), so only the face
/// normal of each sub-triangle is normalized; two corner angles come from `acos` of the edge
/// cosines and the third is `π` minus them (glibc's `acos` costs about half its `atan2`;
/// sub-triangles thin enough for `acos` to lose accuracy are rare and only change a weight).
#[allow(clippy::too_many_arguments)]
fn grid_score(
    projected: &[Option<DVec3>],
    start: usize,
    count: usize,
    sub_triangles: &[[u32; 3]],
    face_normal: DVec3,
    sub_threshold: f64,
    normals: &mut Vec<DVec3>,
    subs: &mut Vec<DVec3>,
) -> f64 {
    normals.clear();
    normals.resize(count, DVec3::ZERO);
    // Unit normal of each valid projected sub-triangle, zero for invalid ones.
    subs.clear();
    for idx in sub_triangles {
        let corner = |k: usize| projected.get(start + idx[k] as usize).copied().flatten();
        let (Some(q0), Some(q1), Some(q2)) = (corner(0), corner(1), corner(2)) else {
            subs.push(DVec3::ZERO);
            continue;
        };
        let (e01, e02, e12) = (q1 - q0, q2 - q0, q2 - q1);
        let cross = e01.cross(e02);
        let len = cross.length();
        if len.is_nan() || len <= DEGENERATE_CROSS || !len.is_finite() {
            subs.push(DVec3::ZERO);
            continue;
        }
        let (l01, l02, l12) = (e01.length(), e02.length(), e12.length());
        let a0 = (e01.dot(e02) / (l01 * l02)).clamp(-1.0, 1.0).acos();
        let a1 = (-e01.dot(e12) / (l01 * l12)).clamp(-1.0, 1.0).acos();
        let a2 = (std::f64::consts::PI - a0 - a1).max(0.0);
        normals[idx[0] as usize] += a0 * cross;
        normals[idx[1] as usize] += a1 * cross;
        normals[idx[2] as usize] += a2 * cross;
        subs.push(cross / len);
    }
    for n in normals.iter_mut() {
        *n = n.normalize_or_zero();
    }
    let mut score = 0.0;
    for (idx, &n) in sub_triangles.iter().zip(subs.iter()) {
        if n == DVec3::ZERO || n.dot(face_normal) < 0.0 {
            continue;
        }
        let sum = n.dot(normals[idx[0] as usize])
            + n.dot(normals[idx[1] as usize])
            + n.dot(normals[idx[2] as usize]);
        let fold = 1.0 - sum / 3.0;
        if fold > 1.0 || fold < sub_threshold {
            continue;
        }
        score += fold;
    }
    score
}

thread_local! {
    /// The sample points and normals of the last [`face_split`] call on this thread, kept so
    /// the next call reuses their memory (about 13 MB for a 10k-face mesh at the default
    /// density): allocated afresh, the allocator handed them back to the system between calls
    /// and every call paid some 3 000 page faults (several ms) to touch them again.
    static SAMPLE_BUFFERS: RefCell<SamplePoints> = RefCell::new(SamplePoints::default());
}

/// Runs the Face Split block with face budget `face_budget` and target projector
/// `projector`; compacts the mesh (and so the tracked store's rows) if the topology changed. Keeps its sample
/// buffers per thread between calls (see `SAMPLE_BUFFERS`).
///
/// Stats: `candidates` = faces with a positive score after suppression; `accepted` = face
/// splits; `rejected`: `"budget"` (scored faces not split), `"link"`, `"sampling"`;
/// `counters`: `faces_before`, `faces_after`, `independent_edges`, `swaps` (k),
/// `paired_collapses`, `free_collapses`, `suppressed_edges`, `edge_costs` (edges whose exact
/// QSlim cost was computed; see [`FaceSplitOptions::prune_edge_costs`] for what
/// `independent_edges`, `link` and `swaps` count when it is on).
pub fn face_split(
    mesh: &mut TrackedMesh,
    projector: &dyn Projector,
    face_budget: usize,
    options: &FaceSplitOptions,
) -> BlockStats {
    let mut stats = BlockStats::new("face_split");
    if mesh.vertex_capacity() != mesh.n_vertices()
        || mesh.face_capacity() != mesh.n_faces()
        || mesh.edge_capacity() != mesh.n_edges()
    {
        mesh.compact();
    }
    let n_faces = mesh.n_faces();
    stats.count("faces_before", n_faces);

    // 1. Samples, projection, face scores.
    let geometry = Geometry::compute(mesh);
    let triangles: Vec<[u32; 3]> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
        .collect();
    let score_faces = |samples: &mut SamplePoints| -> Option<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        regular_sample_points_into(
            samples,
            mesh.positions(),
            &triangles,
            Some(&geometry.vertex_normals),
            &options.sampling,
            &mut rng,
        )
        .ok()?;
        let projected = projector.project(
            mesh.positions(),
            &triangles,
            &samples.points,
            &samples.normals,
        );
        Some(grid_scores(
            mesh,
            &geometry,
            &samples.face_n,
            &samples.face_offsets,
            &projected,
            options,
        ))
    };
    let scores = SAMPLE_BUFFERS.with(|buffers| match buffers.try_borrow_mut() {
        Ok(mut samples) => score_faces(&mut samples),
        Err(_) => score_faces(&mut SamplePoints::default()), // re-entered from the projector
    });
    let Some(mut scores) = scores else {
        stats.reject("sampling", 1);
        return stats;
    };

    // 2. Edge costs C_e = P_e + QS_e, computed where they can matter (see `EdgeCosts`).
    let mut vertex_max = vec![0.0f64; mesh.vertex_capacity()];
    for f in mesh.faces() {
        for v in mesh.face_vertices(f) {
            vertex_max[v.index()] = vertex_max[v.index()].max(scores[f.index()]);
        }
    }
    let quadrics = vertex_quadrics(mesh, &geometry, &options.qslim);
    let mut costs = EdgeCosts::new(mesh, &quadrics, &vertex_max);
    let tau = options.edge_cost_threshold;
    // Pruning is exact only if an edge kept by the selection cannot exclude a better-ranked
    // one (the exclusion radius does not exceed the propagation radius), see `EdgeCosts`.
    let prune = options.prune_edge_costs
        && options.select.exclusion_rings.max(1) - 1 <= options.select.propagation
        && tau >= 0.0;
    let first_threshold = if prune { tau } else { f64::INFINITY };
    costs.compute_below(mesh, &quadrics, &options.validity, first_threshold);

    // 3. Suppression of flat, redundant neighbourhoods: every edge with C_e < τ has its exact
    //    cost by now.
    let mut suppressed = 0;
    for e in mesh.edges() {
        if costs.cost(e).is_some_and(|c| c < tau) {
            suppressed += 1;
            let h = e.halfedge();
            scores[mesh.face(h).index()] = 0.0;
            scores[mesh.face(h.twin()).index()] = 0.0;
        }
    }
    stats.count("suppressed_edges", suppressed);

    // Faces by S descending.
    let mut ranked: Vec<FaceId> = mesh.faces().filter(|f| scores[f.index()] > 0.0).collect();
    ranked.sort_by(|x, y| {
        scores[y.index()]
            .total_cmp(&scores[x.index()])
            .then(x.cmp(y))
    });
    stats.candidates = ranked.len();
    let delta = (face_budget as i64 - n_faces as i64).div_euclid(2);

    // 4.–6. Independent set, c_e, pairing. Under budget only the free collapses (c_e < τ)
    // act, so threshold τ suffices; at or over budget the swaps must be decided too, which
    // may need a second pass with threshold max S (every edge that can pair with a face).
    let s_max = ranked.first().map_or(0.0, |f| scores[f.index()]);
    let mut threshold = first_threshold;
    let (selection, chosen, swaps) = loop {
        let (selection, chosen, swaps, decided) =
            pair_edges(mesh, &costs, &options.select, threshold, &ranked, &scores);
        if decided || delta > 1 || threshold == f64::INFINITY {
            break (selection, chosen, swaps);
        }
        threshold = if threshold < s_max.max(tau) {
            s_max.max(tau)
        } else {
            f64::INFINITY
        };
        costs.compute_below(mesh, &quadrics, &options.validity, threshold);
    };
    stats.count("edge_costs", costs.computed);
    stats.reject("link", selection.link_rejected);
    stats.count("independent_edges", selection.edges.len());
    stats.count("swaps", swaps);

    // 7. Budget logic.
    let (n_paired, n_split) = if delta > 1 {
        (0, ranked.len().min(delta as usize))
    } else {
        (swaps, (swaps as i64 + delta.min(0)).max(0) as usize)
    };
    let n_split = n_split.min(options.max_faces_to_split);
    let mut to_collapse: Vec<EdgeId> = chosen[..n_paired].iter().map(|&(_, e)| e).collect();
    let free: Vec<EdgeId> = chosen[n_paired..]
        .iter()
        .filter(|(c, _)| *c < options.edge_cost_threshold)
        .map(|&(_, e)| e)
        .collect();
    stats.count("paired_collapses", to_collapse.len());
    stats.count("free_collapses", free.len());
    to_collapse.extend(free);

    // 8. Apply: collapses, then centroid splits.
    let mut collapsed = 0;
    let mut paired_missing = 0;
    let mut guard = (options.guard_intersections && !to_collapse.is_empty())
        .then(|| IntersectionGuard::new(mesh));
    for (i, e) in to_collapse.into_iter().enumerate() {
        let c = costs
            .placement(e)
            .expect("selected edges have finite cost, so a placement");
        if apply_collapse(mesh, &c, guard.as_mut(), &mut stats) {
            collapsed += 1;
        } else if i < n_paired {
            paired_missing += 1;
        }
    }
    // A swap whose collapse did not happen gives up its split too, so the block never ends
    // above the budget it would have kept.
    let n_split = n_split.saturating_sub(paired_missing);
    for &f in &ranked[..n_split] {
        if !mesh.is_face_alive(f) {
            stats.reject("removed_face", 1);
            continue;
        }
        mesh.split_face(f, [1.0 / 3.0; 3]);
        stats.accepted += 1;
    }
    stats.reject("budget", ranked.len() - n_split);
    if collapsed > 0 || stats.accepted > 0 {
        mesh.compact();
    }
    stats.count("faces_after", mesh.n_faces());
    stats
}

/// Relative margin between the priorities of edges that can matter and those that cannot
/// (see [`EdgeCosts`]); far larger than the rounding error of `exp`, far smaller than any
/// meaningful cost difference.
const PRIORITY_MARGIN: f64 = 1e-9;

/// Priority floor of threshold `t`: `exp(−(t + 1e-9))`. Every edge with `C_e < t` has priority
/// `exp(−C_e)` above it (by a relative margin of about 1e-9); 0 for `t = ∞`.
fn priority_floor(t: f64) -> f64 {
    (-(t + PRIORITY_MARGIN)).exp()
}

/// QSlim edge costs `C_e = P_e + QS_e` of the Face Split block, computed
/// only where they can change the block's result.
///
/// Only edges with `c_e = C_e < t` can act: `t = τ` for suppression and free collapses,
/// `t = max S` for swaps (a face f pairs with e only if `S_f > c_e`). The independent
/// selection of those edges depends only on edges ranked above them (a kept edge
/// excludes edges within `exclusion_rings − 1` hops, inside the `propagation` hops over which
/// it was a local maximum, so it never excludes a better-ranked one). Hence an edge whose
/// cheap lower bound `P_e + min(placement values)` ([`edge_cost_lower_bound`]) proves
/// `C_e ≥ t` and `exp(−C_e) < priority_floor(t)` can be left out: its validity simulation,
/// the expensive part of [`edge_cost`], is skipped, and the selection runs on the edges with
/// priority `≥ priority_floor(t)`, which rank above every left-out edge.
struct EdgeCosts {
    /// `P_e` by edge id.
    potential: Vec<f64>,
    /// `P_e + edge_cost_lower_bound(e) ≤ C_e` by edge id.
    lower: Vec<f64>,
    /// `(C_e, placement)` where computed (`C_e = ∞`, no placement, if no placement is valid).
    exact: Vec<Option<(f64, Option<EdgeCost>)>>,
    /// Number of edges whose exact cost was computed.
    computed: usize,
}

impl EdgeCosts {
    /// Potentials and lower bounds of every edge (in parallel); no exact cost yet.
    /// `vertex_max[v]` is the largest score of a face around v.
    fn new(mesh: &Mesh, quadrics: &[Quadric], vertex_max: &[f64]) -> Self {
        let ne = mesh.edge_capacity();
        let (potential, lower): (Vec<f64>, Vec<f64>) = (0..ne)
            .into_par_iter()
            .with_min_len(2048)
            .map(|i| {
                let e = EdgeId::from_index(i);
                if !mesh.is_edge_alive(e) {
                    return (0.0, f64::INFINITY);
                }
                let [a, b] = mesh.edge_vertices(e);
                let p = vertex_max[a.index()].max(vertex_max[b.index()]);
                (p, p + edge_cost_lower_bound(mesh, quadrics, e))
            })
            .unzip();
        Self {
            potential,
            lower,
            exact: vec![None; ne],
            computed: 0,
        }
    }

    /// Computes `C_e` for every edge not yet computed unless its lower bound proves
    /// `C_e ≥ t` and `exp(−C_e) < priority_floor(t)` (so `t = ∞` computes every edge). In
    /// parallel over the edges; the result does not depend on the thread count.
    fn compute_below(
        &mut self,
        mesh: &Mesh,
        quadrics: &[Quadric],
        validity: &ValidityOptions,
        t: f64,
    ) {
        let floor = priority_floor(t) * (1.0 - PRIORITY_MARGIN);
        let todo: Vec<EdgeId> = mesh
            .edges()
            .filter(|e| {
                let lower = self.lower[e.index()];
                self.exact[e.index()].is_none() && !(lower >= t && (-lower).exp() < floor)
            })
            .collect();
        let potential = &self.potential;
        let results: Vec<(f64, Option<EdgeCost>)> = todo
            .par_iter()
            .with_min_len(512)
            .map(|&e| {
                let p = potential[e.index()];
                match edge_cost(mesh, quadrics, e, validity) {
                    Ok(c) => (p + c.cost, Some(c)),
                    Err(_) => (f64::INFINITY, None),
                }
            })
            .collect();
        self.computed += todo.len();
        for (e, r) in todo.into_iter().zip(results) {
            self.exact[e.index()] = Some(r);
        }
    }

    /// `C_e` if computed.
    fn cost(&self, e: EdgeId) -> Option<f64> {
        self.exact[e.index()].map(|(c, _)| c)
    }

    /// The best valid placement of `e`, if computed and one exists.
    fn placement(&self, e: EdgeId) -> Option<EdgeCost> {
        self.exact[e.index()].and_then(|(_, p)| p)
    }
}

/// Kept edges as `(c_e, e)` sorted by `c_e`, then id.
type Chosen = Vec<(f64, EdgeId)>;

/// The block's pairing restricted to the edges that can matter below threshold `t` (see
/// [`EdgeCosts`]): the independent set over the edges with priority
/// `exp(−C_e) ≥ priority_floor(t)`, its edges with `c_e = max(C_e, P_e) < t` sorted by `(c_e, id)`,
/// and the swap count k of the pairing with `ranked` (faces by S descending). These agree with the
/// unrestricted computation (`t = ∞`) on every edge with `c_e < t`. The last value says whether k
/// is also the unrestricted swap count: yes unless all the returned edges swap and the next face
/// scores above `t` (it might pair with an edge that was left out).
fn pair_edges(
    mesh: &Mesh,
    costs: &EdgeCosts,
    select: &SelectOptions,
    t: f64,
    ranked: &[FaceId],
    scores: &[f64],
) -> (Selection, Chosen, usize, bool) {
    let floor = priority_floor(t);
    let mut priority = vec![0.0; mesh.edge_capacity()];
    for e in mesh.edges() {
        if let Some(c) = costs.cost(e) {
            let p = (-c).exp();
            if p >= floor {
                priority[e.index()] = p;
            }
        }
    }
    let selection = select_independent_edges(mesh, &priority, select);
    let mut chosen: Chosen = selection
        .edges
        .iter()
        .filter_map(|&e| {
            let c = costs.cost(e)?.max(costs.potential[e.index()]);
            (c < t).then_some((c, e))
        })
        .collect();
    chosen.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let swaps = ranked
        .iter()
        .zip(&chosen)
        .take_while(|(f, (c, _))| scores[f.index()] > *c)
        .count();
    let m = chosen.len();
    let decided =
        t == f64::INFINITY || swaps < m || ranked.len() <= m || scores[ranked[m].index()] <= t;
    (selection, chosen, swaps, decided)
}

/// [`Block`] wrapper of [`face_split`]: takes the budget and projector from the context and
/// mixes the iteration into the sampling seed. Without a projector it does nothing
/// (`rejected["no_projector"] = 1`).
#[derive(Debug, Clone, Default)]
pub struct FaceSplit {
    /// Options passed to [`face_split`].
    pub options: FaceSplitOptions,
}

impl Block for FaceSplit {
    fn name(&self) -> &'static str {
        "face_split"
    }

    fn apply(&mut self, mesh: &mut TrackedMesh, ctx: &BlockContext) -> BlockStats {
        let Some(projector) = ctx.projector else {
            let mut stats = BlockStats::new("face_split");
            stats.reject("no_projector", 1);
            return stats;
        };
        let options = FaceSplitOptions {
            seed: self
                .options
                .seed
                .wrapping_add((ctx.iteration as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)),
            ..self.options
        };
        face_split(mesh, projector, ctx.face_budget, &options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;
    use roar_mesh::shapes::icosphere;
    use roar_mesh::spatial::corner_angles;
    use roar_mesh::spatial::regular_samples;

    /// The direct reading of the face score (unit normals, `acos` corner angles), the brute-force
    /// reference of [`grid_score`].
    fn reference_grid_score(
        samples: &RegularSamples,
        projected: &[Option<DVec3>],
        f: usize,
        face_normal: DVec3,
        sub_threshold: f64,
    ) -> f64 {
        let start = samples.face_samples(f).start;
        let mut normals = vec![DVec3::ZERO; samples.face_samples(f).len()];
        let mut subs = Vec::new();
        for t in samples.face_sub_triangles(f) {
            let idx = samples.sub_triangles[t];
            let q = idx.map(|i| projected[i as usize]);
            let [Some(a), Some(b), Some(c)] = q else {
                subs.push(None);
                continue;
            };
            let q = [a, b, c];
            let cross = (q[1] - q[0]).cross(q[2] - q[0]);
            let len = cross.length();
            if len.is_nan() || len <= DEGENERATE_CROSS || !len.is_finite() {
                subs.push(None);
                continue;
            }
            let n = cross / len;
            let angles = corner_angles(q);
            for k in 0..3 {
                normals[idx[k] as usize - start] += 0.5 * len * angles[k] * n;
            }
            subs.push(Some(n));
        }
        let normals: Vec<DVec3> = normals.iter().map(|n| n.normalize_or_zero()).collect();
        let mut score = 0.0;
        for (t, n) in samples.face_sub_triangles(f).zip(&subs) {
            let Some(n) = *n else { continue };
            if n.dot(face_normal) < 0.0 {
                continue;
            }
            let idx = samples.sub_triangles[t];
            let fold = 1.0
                - idx
                    .iter()
                    .map(|&i| n.dot(normals[i as usize - start]))
                    .sum::<f64>()
                    / 3.0;
            if fold <= 1.0 && fold >= sub_threshold {
                score += fold;
            }
        }
        score
    }

    #[test]
    fn grid_score_matches_the_direct_reading_on_noisy_grids() {
        let mesh = icosphere(1);
        let g = Geometry::compute(&mesh);
        let tris: Vec<[u32; 3]> = mesh
            .faces()
            .map(|f| mesh.face_vertices(f).map(|v| v.raw()))
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let samples = regular_samples(
            mesh.positions(),
            &tris,
            Some(&g.vertex_normals),
            &RegularSamplingOptions::default(),
            &mut rng,
        )
        .unwrap();
        // Noisy projections along the normal, some missing.
        let projected: Vec<Option<DVec3>> = samples
            .points
            .iter()
            .zip(&samples.normals)
            .map(|(&p, &n)| {
                (rng.random::<f64>() > 0.03).then(|| p + rng.random_range(-0.01..0.01) * n)
            })
            .collect();
        let (mut normals, mut subs) = (Vec::new(), Vec::new());
        let mut nonzero = 0;
        for f in 0..mesh.n_faces() {
            for threshold in [0.0, 0.02] {
                let range = samples.face_samples(f);
                let (_, local) = face_grid(samples.face_n[f]);
                let fast = grid_score(
                    &projected,
                    range.start,
                    range.len(),
                    &local,
                    g.face_normals[f],
                    threshold,
                    &mut normals,
                    &mut subs,
                );
                let slow =
                    reference_grid_score(&samples, &projected, f, g.face_normals[f], threshold);
                assert!(
                    (fast - slow).abs() <= 1e-9 * (1.0 + slow.abs()),
                    "face {f}, threshold {threshold}: {fast} vs {slow}"
                );
                nonzero += usize::from(slow > 0.0);
            }
        }
        assert!(nonzero > 40, "the noise must make faces score: {nonzero}");
    }
}
