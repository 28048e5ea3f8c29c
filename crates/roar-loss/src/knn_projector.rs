//! k-NN planar projection of source samples onto an oriented target point cloud: the paper's
//! projector of the Face Split block (supplementary §1.4) and the source→target term of the
//! planar loss (`docs/method.md#planar-loss`).
//!
//! Each sample `s` with unit normal `n` looks up its `k` nearest target points `t_j` (normals
//! `m_j`), intersects the line `s + α n` with each neighbour's tangent plane, keeps the valid
//! intersections and blends them with inverse-squared-distance weights. The kd-tree (f32, see
//! [`crate::point_tree`]) is built once over the target; neighbour distances are recomputed in
//! f64 and the plane projection runs in f64. Queries run in parallel over fixed chunks and each
//! answer depends only on its own sample, so results are bit-identical whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;
use roar_mesh::spatial::Projector;

use crate::error::LossError;
use crate::point_tree::{Neighbours, PointTree};

/// Samples per parallel work item (coarse: the machine has few cores).
const CHUNK: usize = 2048;

/// Added to squared distances before inverting them into weights (the authors' code's value).
const WEIGHT_EPSILON: f64 = 1e-5;

/// How a sample's move is built from its valid neighbours; the variants other than the default
/// are for ablations (`docs/method.md#decision-form-of-the-planar-loss`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlanarMode {
    /// Along the sample normal onto each neighbour's plane, inverse-squared-distance blend
    /// (the default).
    #[default]
    AlongNormal,
    /// Orthogonally onto each neighbour's plane, `((t_j − s)·m_j) m_j`, same validity and
    /// weights. The move is then not along `n` (breaks the [`Projector`] line contract; for
    /// ablations of the loss only).
    Orthogonal,
    /// Along the sample normal, but only the valid neighbour with the smallest |move|
    /// (an alternative mode of the authors' code).
    Nearest,
}

/// Options of the k-NN planar projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnnOptions {
    /// Number of nearest target points per sample. Default 10 (supplementary §1.2).
    pub k: usize,
    /// A neighbour is valid only if `n·m_j >` this. Default 0.01 (the value of
    /// `normal_dot_prod_threshold` in the authors' configuration; their code's default is 0.5).
    pub normal_dot_threshold: f64,
    /// Blow-up guard: the projected point must satisfy `|t_j − q| < guard·|t_j − s|`.
    /// Default 1.01 (the authors' code): a projection may not land farther from the neighbour
    /// than the sample itself, so grazing planes do not blow a move up.
    pub blowup_guard: f64,
    /// How valid neighbours are combined. Default [`PlanarMode::AlongNormal`].
    pub mode: PlanarMode,
}

impl Default for KnnOptions {
    fn default() -> Self {
        Self {
            k: 10,
            normal_dot_threshold: 0.01,
            blowup_guard: 1.01,
            mode: PlanarMode::AlongNormal,
        }
    }
}

/// Checks an oriented point cloud: same lengths, at least one point, finite coordinates.
pub(crate) fn check_cloud(points: &[DVec3], normals: &[DVec3]) -> Result<(), LossError> {
    if points.len() != normals.len() {
        return Err(LossError::InvalidTarget(format!(
            "{} points but {} normals",
            points.len(),
            normals.len()
        )));
    }
    if points.is_empty() {
        return Err(LossError::InvalidTarget("the point cloud is empty".into()));
    }
    if points.len() > u32::MAX as usize {
        return Err(LossError::InvalidTarget("more than 2^32 points".into()));
    }
    if let Some(i) = points
        .iter()
        .zip(normals)
        .position(|(p, n)| !p.is_finite() || !n.is_finite())
    {
        return Err(LossError::InvalidTarget(format!(
            "point {i} or its normal is not finite"
        )));
    }
    Ok(())
}

/// k-NN planar projector over a fixed oriented target point cloud.
#[derive(Debug, Clone)]
pub struct KnnPlanarProjector {
    tree: PointTree,
    points: Vec<DVec3>,
    /// Unit normals (zero where the input normal was zero: such points are never valid).
    normals: Vec<DVec3>,
    /// `points` and `normals` again, laid out by the tree's slots ([`PointTree::slot_ids`];
    /// zero in padding): a projection reads its neighbours' positions and normals from nearby
    /// memory rather than from wherever the cloud's order put them.
    by_slot: Vec<(DVec3, DVec3)>,
    options: KnnOptions,
}

/// A neighbour found by [`KnnPlanarProjector::nearest_into`]: (point index, exact squared
/// distance, tree slot).
type Found = (u32, f64, u32);

impl KnnPlanarProjector {
    /// Builds the kd-tree over the target points `points` with normals `normals` (one per point,
    /// normalized here). Errors: mismatched lengths, empty cloud, non-finite input.
    pub fn new(
        points: &[DVec3],
        normals: &[DVec3],
        options: &KnnOptions,
    ) -> Result<Self, LossError> {
        check_cloud(points, normals)?;
        let tree = PointTree::new(points);
        let normals: Vec<DVec3> = normals.iter().map(|n| n.normalize_or_zero()).collect();
        let by_slot = tree
            .slot_ids()
            .iter()
            .map(|&i| match points.get(i as usize) {
                Some(&p) => (p, normals[i as usize]),
                None => (DVec3::ZERO, DVec3::ZERO),
            })
            .collect();
        Ok(Self {
            tree,
            points: points.to_vec(),
            normals,
            by_slot,
            options: *options,
        })
    }

    /// The options the projector was built with.
    pub fn options(&self) -> &KnnOptions {
        &self.options
    }

    /// The target points.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// The target unit normals.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// Target point indices in a spatially coherent order (the kd-tree's leaf order).
    pub(crate) fn spatial_order(&self) -> &[u32] {
        self.tree.spatial_order()
    }

    /// The `k` nearest target points of `p` as `(index, squared distance)`, sorted by distance
    /// then index (distances recomputed in f64, so the order is exact; the set is searched in
    /// f32 and can differ from the exact one only at near-ties, within f32 precision). Fewer when
    /// the cloud is smaller than `k`; empty for `k = 0` or a non-finite `p`.
    pub fn nearest(&self, p: DVec3, k: usize) -> Vec<(u32, f64)> {
        let mut scratch = Neighbours::default();
        let mut found = Vec::new();
        self.nearest_into(p, k, &mut scratch, &mut found);
        found.into_iter().map(|(j, d2, _)| (j, d2)).collect()
    }

    /// [`KnnPlanarProjector::nearest`] into reusable buffers (no allocation once warm).
    fn nearest_into(&self, p: DVec3, k: usize, scratch: &mut Neighbours, found: &mut Vec<Found>) {
        found.clear();
        if !p.is_finite() {
            return;
        }
        self.tree.nearest_n(p, k, scratch);
        found.extend(
            scratch.items().zip(scratch.slots()).map(|((_, j), &slot)| {
                (j, self.by_slot[slot as usize].0.distance_squared(p), slot)
            }),
        );
        // Squared distances of finite points are never negative nor NaN, so their bits order
        // like the numbers (as `total_cmp` would), and one integer key compares each pair.
        found.sort_unstable_by_key(|&(j, d2, _)| (d2.to_bits(), j));
    }

    /// The move `d` of sample `s` with unit normal `n`: `None` when no neighbour is valid or the
    /// input is not finite.
    pub fn displacement(&self, s: DVec3, n: DVec3) -> Option<DVec3> {
        let mut scratch = Neighbours::default();
        let mut found = Vec::new();
        self.displacement_into(s, n, &mut scratch, &mut found)
    }

    /// [`KnnPlanarProjector::displacement`] with reusable buffers.
    fn displacement_into(
        &self,
        s: DVec3,
        n: DVec3,
        scratch: &mut Neighbours,
        found: &mut Vec<Found>,
    ) -> Option<DVec3> {
        if !s.is_finite() || !n.is_finite() {
            return None;
        }
        self.nearest_into(s, self.options.k, scratch, found);
        planar_move(
            s,
            n,
            found.iter().map(|&(_, d2, slot)| {
                let (point, normal) = self.by_slot[slot as usize];
                (point, normal, d2)
            }),
            &self.options,
        )
    }

    /// [`KnnPlanarProjector::displacement`] of every sample, in parallel over fixed chunks
    /// (deterministic). A missing normal (`normals` shorter than `points`) gives `None`.
    pub fn displacements(&self, points: &[DVec3], normals: &[DVec3]) -> Vec<Option<DVec3>> {
        let work = |start: usize, chunk: &[DVec3]| -> Vec<Option<DVec3>> {
            let mut scratch = Neighbours::default();
            let mut found = Vec::with_capacity(self.options.k);
            chunk
                .iter()
                .enumerate()
                .map(|(i, &s)| {
                    normals
                        .get(start + i)
                        .and_then(|&n| self.displacement_into(s, n, &mut scratch, &mut found))
                })
                .collect()
        };
        if points.len() <= CHUNK {
            return work(0, points);
        }
        points
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| work(c * CHUNK, chunk))
            .collect::<Vec<_>>()
            .concat()
    }
}

impl KnnPlanarProjector {
    /// [`KnnPlanarProjector::displacements`] of the samples listed in `order` (indices into
    /// `points`, each at most once), searched in that order; samples not listed get `None`.
    /// Each answer depends on its own sample only, so the result equals `displacements` at the
    /// listed samples; a spatially coherent order makes every search's bound (the previous
    /// answer of the chunk) tight, which is cheaper than the samples' face order, whose
    /// consecutive faces can lie far apart.
    pub(crate) fn displacements_in_order(
        &self,
        points: &[DVec3],
        normals: &[DVec3],
        order: &[u32],
    ) -> Vec<Option<DVec3>> {
        let work = |chunk: &[u32]| -> Vec<Option<DVec3>> {
            let mut scratch = Neighbours::default();
            let mut found = Vec::with_capacity(self.options.k);
            chunk
                .iter()
                .map(|&i| {
                    let (s, n) = (points.get(i as usize)?, normals.get(i as usize)?);
                    self.displacement_into(*s, *n, &mut scratch, &mut found)
                })
                .collect()
        };
        answers_in_order(order, points.len(), CHUNK, work)
    }
}

/// Runs `work` over `order` (indices below `len`, each at most once) in chunks of `chunk`
/// indices, in parallel when there is more than one chunk, and puts each answer at its index
/// of a vector of `len` (`None` at indices `order` does not list; indices out of range are
/// ignored). `work` answers a chunk's indices in the chunk's order; searches that carry a
/// bound from one answer to the next get a tight bound when `order` is spatially coherent.
/// The answers are scattered straight from the chunks' vectors, without a concatenated copy.
pub(crate) fn answers_in_order<T: Copy + Send>(
    order: &[u32],
    len: usize,
    chunk: usize,
    work: impl Fn(&[u32]) -> Vec<Option<T>> + Sync,
) -> Vec<Option<T>> {
    let per_chunk: Vec<Vec<Option<T>>> = if order.len() <= chunk {
        vec![work(order)]
    } else {
        order.par_chunks(chunk).map(&work).collect()
    };
    let mut result = vec![None; len];
    for (indices, answers) in order.chunks(chunk).zip(per_chunk) {
        for (&i, a) in indices.iter().zip(answers) {
            if let Some(slot) = result.get_mut(i as usize) {
                *slot = a;
            }
        }
    }
    result
}

impl Projector for KnnPlanarProjector {
    fn project(
        &self,
        _positions: &[DVec3],
        _triangles: &[[u32; 3]],
        points: &[DVec3],
        normals: &[DVec3],
    ) -> Vec<Option<DVec3>> {
        self.displacements(points, normals)
            .into_iter()
            .zip(points)
            .map(|(d, &s)| d.map(|d| s + d))
            .collect()
    }
}

/// The planar move of sample `s` (unit normal `n`) from its neighbours `(t_j, m_j, d_j²)`
/// (`mode` picks the variant). `None` when no neighbour is
/// valid. Neighbour validity: `n·m_j > threshold` and the blow-up guard on the along-normal
/// projection (also used to validate the orthogonal variant).
pub fn planar_move(
    s: DVec3,
    n: DVec3,
    neighbours: impl IntoIterator<Item = (DVec3, DVec3, f64)>,
    options: &KnnOptions,
) -> Option<DVec3> {
    let mut weight_sum = 0.0;
    let mut weighted = DVec3::ZERO;
    let mut nearest: Option<DVec3> = None;
    for (t, m, d2) in neighbours {
        let cos = n.dot(m);
        if cos.is_nan() || cos <= options.normal_dot_threshold {
            continue;
        }
        let to_t = t - s;
        let alpha = to_t.dot(m) / cos;
        let along = alpha * n;
        // |t − (s + along)| < guard·|t − s|, squared (both sides are non-negative).
        let guard2 = options.blowup_guard * options.blowup_guard;
        let guard = (to_t - along).length_squared() < guard2 * to_t.length_squared();
        if !guard || !along.is_finite() {
            continue;
        }
        let w = 1.0 / (d2 + WEIGHT_EPSILON);
        match options.mode {
            PlanarMode::AlongNormal => {
                weighted += w * along;
                weight_sum += w;
            }
            PlanarMode::Orthogonal => {
                weighted += w * to_t.dot(m) * m;
                weight_sum += w;
            }
            PlanarMode::Nearest => {
                if nearest.is_none_or(|best| along.length_squared() < best.length_squared()) {
                    nearest = Some(along);
                }
            }
        }
    }
    match options.mode {
        PlanarMode::Nearest => nearest,
        _ if weight_sum > 0.0 => Some(weighted / weight_sum),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_plane_moves_sample_onto_it_along_normal() {
        // Target: the plane z = 0 with normal +z; sample above it, tilted normal.
        let mut points = Vec::new();
        for i in -5..=5 {
            for j in -5..=5 {
                points.push(DVec3::new(i as f64 * 0.1, j as f64 * 0.1, 0.0));
            }
        }
        let normals = vec![DVec3::Z; points.len()];
        let proj = KnnPlanarProjector::new(&points, &normals, &KnnOptions::default()).unwrap();
        let s = DVec3::new(0.03, -0.02, 0.2);
        let n = DVec3::new(0.2, 0.1, 1.0).normalize();
        let d = proj.displacement(s, n).unwrap();
        assert!((s + d).z.abs() < 1e-12);
        assert!(d.cross(n).length() < 1e-12);
    }

    #[test]
    fn displacements_in_any_order_match_the_plain_ones() {
        // A wavy target and samples above it, more than one parallel chunk of each; some
        // samples non-finite, some normals missing.
        let grid = |n: usize, z: f64| -> Vec<DVec3> {
            (0..n * n)
                .map(|i| {
                    let (x, y) = ((i % n) as f64 / n as f64, (i / n) as f64 / n as f64);
                    DVec3::new(x, y, z + 0.05 * (7.0 * x).sin() * (5.0 * y).cos())
                })
                .collect()
        };
        let target = grid(60, 0.0);
        let target_normals = vec![DVec3::new(0.1, -0.2, 1.0); target.len()];
        let proj =
            KnnPlanarProjector::new(&target, &target_normals, &KnnOptions::default()).unwrap();
        let mut samples = grid(70, 0.02);
        samples[5] = DVec3::splat(f64::NAN);
        let normals = vec![DVec3::new(0.0, 0.3, 1.0).normalize(); samples.len() - 3];
        let plain = proj.displacements(&samples, &normals);
        assert!(plain.iter().filter(|d| d.is_some()).count() > samples.len() / 2);
        // Every seventh sample in a scrambled order, then all of them in reverse.
        let n = samples.len() as u32;
        // (2654435761 is prime to n = 4900, so the map is a permutation.)
        let scrambled: Vec<u32> = (0..n as u64)
            .map(|i| (i * 2654435761 % n as u64) as u32)
            .step_by(7)
            .collect();
        let reversed: Vec<u32> = (0..n).rev().collect();
        for order in [scrambled, reversed] {
            let got = proj.displacements_in_order(&samples, &normals, &order);
            for i in 0..samples.len() {
                let expected = if order.contains(&(i as u32)) {
                    plain[i]
                } else {
                    None
                };
                assert_eq!(got[i], expected, "sample {i}");
            }
        }
    }

    #[test]
    fn opposite_normals_are_invalid() {
        let points = vec![DVec3::ZERO, DVec3::X * 0.1];
        let normals = vec![-DVec3::Z, -DVec3::Z];
        let proj = KnnPlanarProjector::new(&points, &normals, &KnnOptions::default()).unwrap();
        assert_eq!(proj.displacement(DVec3::Z * 0.1, DVec3::Z), None);
        assert_eq!(proj.displacement(DVec3::splat(f64::NAN), DVec3::Z), None);
    }

    #[test]
    fn bad_clouds_are_errors() {
        let o = KnnOptions::default();
        assert!(KnnPlanarProjector::new(&[], &[], &o).is_err());
        assert!(KnnPlanarProjector::new(&[DVec3::ZERO], &[], &o).is_err());
        assert!(KnnPlanarProjector::new(&[DVec3::splat(f64::NAN)], &[DVec3::Z], &o).is_err());
    }

    #[test]
    fn nearest_mode_picks_smallest_move() {
        let o = KnnOptions {
            mode: PlanarMode::Nearest,
            ..KnnOptions::default()
        };
        let s = DVec3::ZERO;
        let neighbours = [
            (DVec3::new(0.0, 0.0, 0.3), DVec3::Z, 0.09),
            (DVec3::new(0.0, 0.0, 0.1), DVec3::Z, 0.01),
        ];
        let d = planar_move(s, DVec3::Z, neighbours, &o).unwrap();
        assert!((d - DVec3::Z * 0.1).length() < 1e-15);
    }
}
