//! Regular supersampling of faces, after the MESH sampler of Aspert et al. 2002 that the
//! authors' code follows (`docs/method.md#regular-samples-of-the-source`).
//!
//! Each face gets its own triangular grid of `n(n+1)/2` points (`n` points per side) and
//! `(n−1)²` sub-triangles oriented like the face, with `n` chosen so that the sample count is
//! proportional to the face's area over `(δ·D)²` (δ = density, D = bounding-box diagonal of the
//! sampled mesh). Grids of neighbouring faces are independent: points on shared edges are
//! duplicated. Each sample keeps its barycentric weights in its parent face, so gradients of
//! anything computed at the samples flow back to the face's three vertices.
//!
//! # Grid layout
//! For a face `(v0, v1, v2)` and integers `a, b ≥ 0`, `a + b ≤ n − 1`, the point
//! `p_{a,b} = v0 + a/(n−1)·(v1−v0) + b/(n−1)·(v2−v0)` has barycentrics
//! `(1 − a/(n−1) − b/(n−1), a/(n−1), b/(n−1))` and local ordinal `(a+b)(a+b+1)/2 + a`.
//! Sub-triangles: "up" `(a,b), (a+1,b), (a,b+1)` for `a + b ≤ n−2`, then "down"
//! `(a,b), (a−1,b), (a,b−1)` for `a, b ≥ 1`.

use glam::DVec3;
use rand::Rng;
use rayon::prelude::*;
use std::ops::Range;

use super::winding::{TriangleIndexError, check_triangle_indices};

/// Barycentrics and local sub-triangles of one grid, as returned by [`face_grid`].
type FaceGrid = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Options of [`regular_samples`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegularSamplingOptions {
    /// Sampling density δ as a fraction of the bounding-box diagonal D of the sampled mesh: a face
    /// gets about `A_f / (δD)²` samples. Default 0.002 (supplementary §1.2).
    pub density: f64,
    /// Per-face cap on the grid size `n` (points per side). Default 16, i.e. 136 samples, the
    /// authors' code's effective cap (its `max_samples = 20`); the supplementary's "420 samples"
    /// would be 28 (`docs/method.md#decision-sample-cap-per-face`).
    pub max_n: u32,
    /// Minimum grid size, used when the area calls for fewer points. Default 3 (6 samples, the
    /// fewest that measure curvature). Values below 2 are treated as 2.
    pub min_n: u32,
}

impl Default for RegularSamplingOptions {
    fn default() -> Self {
        Self {
            density: 0.002,
            max_n: 16,
            min_n: 3,
        }
    }
}

/// Error of [`regular_samples`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RegularSamplingError {
    /// A triangle refers to a missing vertex.
    #[error(transparent)]
    TriangleIndex(#[from] TriangleIndexError),
    /// The per-vertex normal buffer does not have one normal per position.
    #[error("got {normals} vertex normals for {positions} positions")]
    NormalCount {
        /// Number of positions.
        positions: usize,
        /// Number of vertex normals supplied.
        normals: usize,
    },
}

/// Regular samples of every face of a mesh, in face order (face 0's grid first).
///
/// Per sample `i`: `points[i]`, `faces[i]`, `barycentrics[i]`, `normals[i]`.
/// Per face `f`: grid size `face_n[f]`, samples `face_offsets[f]..face_offsets[f+1]` and
/// sub-triangles `face_sub_triangle_offsets[f]..face_sub_triangle_offsets[f+1]` (both vectors have
/// `F + 1` entries). Per sub-triangle `s`: its three global sample indices `sub_triangles[s]`
/// (oriented like the parent face) and `sub_triangle_faces[s]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RegularSamples {
    /// Sample positions.
    pub points: Vec<DVec3>,
    /// Parent face of each sample.
    pub faces: Vec<u32>,
    /// Barycentric weights of each sample w.r.t. its parent face's vertices (sum to 1).
    pub barycentrics: Vec<[f64; 3]>,
    /// Unit normal of each sample: the normalized barycentric blend of the parent's vertex normals
    /// when supplied (the "smooth" normals), else the face's unit normal. Zero when both
    /// are degenerate (zero blend and zero-area face).
    pub normals: Vec<DVec3>,
    /// Grid size `n` (points per side) of each face.
    pub face_n: Vec<u32>,
    /// Offset of each face's first sample; `F + 1` entries, the last is the sample count.
    pub face_offsets: Vec<u32>,
    /// Offset of each face's first sub-triangle; `F + 1` entries.
    pub face_sub_triangle_offsets: Vec<u32>,
    /// Sub-triangles as global sample indices, oriented like their parent face.
    pub sub_triangles: Vec<[u32; 3]>,
    /// Parent face of each sub-triangle.
    pub sub_triangle_faces: Vec<u32>,
}

impl RegularSamples {
    /// Sample index range of face `f`.
    pub fn face_samples(&self, f: usize) -> Range<usize> {
        self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize
    }

    /// Sub-triangle index range of face `f`.
    pub fn face_sub_triangles(&self, f: usize) -> Range<usize> {
        self.face_sub_triangle_offsets[f] as usize..self.face_sub_triangle_offsets[f + 1] as usize
    }
}

/// Number of grid points of a grid of size `n`: `n(n+1)/2`.
pub fn grid_point_count(n: u32) -> usize {
    let n = n as usize;
    n * (n + 1) / 2
}

/// Local ordinal of grid point `(a, b)`: `(a+b)(a+b+1)/2 + a` (row by row of `a + b`).
#[inline]
pub fn grid_ordinal(a: u32, b: u32) -> u32 {
    let s = a + b;
    s * (s + 1) / 2 + a
}

/// The regular grid of size `n` on the reference triangle: barycentrics of its `n(n+1)/2` points
/// (indexed by [`grid_ordinal`]) and its `(n−1)²` sub-triangles as local point indices, "up" ones
/// first, all oriented like the face. `n = 1` gives the single point `(1, 0, 0)` and no
/// sub-triangles; `n = 0` gives nothing.
pub fn face_grid(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let mut barycentrics = vec![[0.0; 3]; grid_point_count(n)];
    let step = if n > 1 { 1.0 / (n - 1) as f64 } else { 0.0 };
    for s in 0..n {
        for a in 0..=s {
            let b = s - a;
            let wa = a as f64 * step;
            let wb = b as f64 * step;
            barycentrics[grid_ordinal(a, b) as usize] = [1.0 - wa - wb, wa, wb];
        }
    }
    let mut sub = Vec::with_capacity(((n - 1) * (n - 1)) as usize);
    for b in 0..n.saturating_sub(1) {
        for a in 0..(n - 1 - b) {
            sub.push([
                grid_ordinal(a, b),
                grid_ordinal(a + 1, b),
                grid_ordinal(a, b + 1),
            ]);
        }
    }
    for b in 1..n {
        for a in 1..(n - b) {
            sub.push([
                grid_ordinal(a, b),
                grid_ordinal(a - 1, b),
                grid_ordinal(a, b - 1),
            ]);
        }
    }
    (barycentrics, sub)
}

/// The continuous grid size `n'_f = sqrt(1/4 + T_f/(D²δ²)) − 1/2` of a face with doubled area
/// `doubled_area`, so that `n'(n'+1)/2 = A_f/(Dδ)²`. Returns 0 for
/// non-finite or degenerate input (which then falls back to the minimum grid).
pub fn continuous_grid_size(doubled_area: f64, diagonal: f64, density: f64) -> f64 {
    let scale = diagonal * diagonal * density * density;
    let value = (0.25 + doubled_area / scale).sqrt() - 0.5;
    if value.is_finite() && value > 0.0 {
        value
    } else {
        0.0
    }
}

/// Picks the integer grid size of a face from its continuous size `n_cont`:
///
/// 1. clip: `n_cont ≥ max_n − 1` counts as clipped and always gets `n = max_n`. This reproduces
///    the authors' code, which clips `n'` to `max_samples − 5` *before* the stochastic rounding
///    and then rounds a clipped face up, so its effective cap is `max_n = 16`
///    (`docs/method.md#decision-sample-cap-per-face`).
/// 2. `n_cont < min_n` gives `n = min_n`.
/// 3. otherwise unbiased stochastic rounding: with `k = ⌊n'⌋`, `N* = n'(n'+1)/2`, keep `k` with
///    probability `p = ((k+1)(k+2)/2 − N*)/(k+1)`, else `k + 1`, so `E[n(n+1)/2] = N*` exactly.
///
/// Draws one uniform number from `rng` only in case 3. `min_n` is raised to 2 and `max_n` to
/// `min_n`.
pub fn round_grid_size(n_cont: f64, min_n: u32, max_n: u32, rng: &mut impl Rng) -> u32 {
    let min_n = min_n.max(2);
    let max_n = max_n.max(min_n);
    if n_cont >= (max_n - 1) as f64 {
        return max_n;
    }
    if n_cont.is_nan() || n_cont < min_n as f64 {
        return min_n;
    }
    let k = n_cont.floor();
    let target = n_cont * (n_cont + 1.0) / 2.0;
    let keep_probability = ((k + 1.0) * (k + 2.0) / 2.0 - target) / (k + 1.0);
    let u: f64 = rng.random();
    let n = if u < keep_probability { k } else { k + 1.0 };
    (n as u32).clamp(min_n, max_n)
}

/// Regular supersampling of every face of `(positions, triangles)`.
///
/// `vertex_normals`, when given, must hold one normal per position; sample normals are then the
/// normalized barycentric blend of the parent's vertex normals (falling back to the face normal
/// when the blend vanishes), else the face's unit normal. D is the bounding-box diagonal of the
/// vertices referenced by `triangles`. The RNG is used once per face whose grid size needs
/// stochastic rounding, in face order, so a seeded RNG gives identical samples every run.
pub fn regular_samples(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: Option<&[DVec3]>,
    options: &RegularSamplingOptions,
    rng: &mut impl Rng,
) -> Result<RegularSamples, RegularSamplingError> {
    let buffers = (Vec::new(), Vec::new());
    sample_faces(
        positions,
        triangles,
        vertex_normals,
        options,
        rng,
        buffers,
        true,
    )
}

/// The sample points and normals of every face and each face's grid: the parts of
/// [`RegularSamples`] that face scoring needs, from [`regular_sample_points`].
///
/// Face `f` has the samples `face_offsets[f]..face_offsets[f+1]` and the sub-triangles of
/// [`face_grid`]`(face_n[f])` shifted by `face_offsets[f]` (exactly the entries of
/// [`RegularSamples::sub_triangles`] for that face).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SamplePoints {
    /// Sample positions.
    pub points: Vec<DVec3>,
    /// Unit normal of each sample (as in [`RegularSamples::normals`]).
    pub normals: Vec<DVec3>,
    /// Grid size `n` (points per side) of each face.
    pub face_n: Vec<u32>,
    /// Offset of each face's first sample; `F + 1` entries, the last is the sample count.
    pub face_offsets: Vec<u32>,
}

/// [`regular_samples`] without the per-sample faces and barycentrics and the sub-triangle
/// lists: the same points, normals and grid sizes for the same RNG state (and the same RNG
/// draws), with about half the memory written.
pub fn regular_sample_points(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: Option<&[DVec3]>,
    options: &RegularSamplingOptions,
    rng: &mut impl Rng,
) -> Result<SamplePoints, RegularSamplingError> {
    let mut out = SamplePoints::default();
    regular_sample_points_into(&mut out, positions, triangles, vertex_normals, options, rng)?;
    Ok(out)
}

/// [`regular_sample_points`] into `out`, reusing the memory of its point and normal buffers
/// (repeated calls then touch no fresh pages for them). On error `out` is left empty.
pub fn regular_sample_points_into(
    out: &mut SamplePoints,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: Option<&[DVec3]>,
    options: &RegularSamplingOptions,
    rng: &mut impl Rng,
) -> Result<(), RegularSamplingError> {
    let buffers = (
        std::mem::take(&mut out.points),
        std::mem::take(&mut out.normals),
    );
    *out = SamplePoints::default();
    let s = sample_faces(
        positions,
        triangles,
        vertex_normals,
        options,
        rng,
        buffers,
        false,
    )?;
    *out = SamplePoints {
        points: s.points,
        normals: s.normals,
        face_n: s.face_n,
        face_offsets: s.face_offsets,
    };
    Ok(())
}

/// [`regular_samples`], writing points and normals into the recycled `buffers`; with
/// `full == false` the `faces`, `barycentrics`, `sub_triangles` and `sub_triangle_faces` of
/// the result are left empty.
fn sample_faces(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: Option<&[DVec3]>,
    options: &RegularSamplingOptions,
    rng: &mut impl Rng,
    buffers: (Vec<DVec3>, Vec<DVec3>),
    full: bool,
) -> Result<RegularSamples, RegularSamplingError> {
    check_triangle_indices(positions.len(), triangles)?;
    if let Some(normals) = vertex_normals
        && normals.len() != positions.len()
    {
        return Err(RegularSamplingError::NormalCount {
            positions: positions.len(),
            normals: normals.len(),
        });
    }
    let diagonal = referenced_bbox_diagonal(positions, triangles);

    // Continuous grid sizes in parallel (each depends only on its face), then grid sizes and
    // offsets sequentially: one RNG draw per rounded face, in face order, so the samples do
    // not depend on the thread count.
    let continuous: Vec<f64> = triangles
        .par_iter()
        .with_min_len(4096)
        .map(|tri| {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            let doubled_area = (p1 - p0).cross(p2 - p0).length();
            continuous_grid_size(doubled_area, diagonal, options.density)
        })
        .collect();
    let mut face_n = Vec::with_capacity(triangles.len());
    let mut face_offsets = Vec::with_capacity(triangles.len() + 1);
    let mut face_sub_triangle_offsets = Vec::with_capacity(triangles.len() + 1);
    let mut sample_count = 0usize;
    let mut sub_count = 0usize;
    for &n_cont in &continuous {
        let n = round_grid_size(n_cont, options.min_n, options.max_n, rng);
        face_n.push(n);
        face_offsets.push(sample_count as u32);
        face_sub_triangle_offsets.push(sub_count as u32);
        sample_count += grid_point_count(n);
        sub_count += ((n - 1) * (n - 1)) as usize;
    }
    face_offsets.push(sample_count as u32);
    face_sub_triangle_offsets.push(sub_count as u32);

    // One reference grid per distinct size (at most `max_n` of them), shared by all faces.
    let max_n = face_n.iter().copied().max().unwrap_or(0) as usize;
    let mut grids: Vec<Option<FaceGrid>> = vec![None; max_n + 1];
    for &n in &face_n {
        grids[n as usize].get_or_insert_with(|| face_grid(n));
    }

    // Recycled entries are not cleared: `fill_faces` overwrites every sample (the faces'
    // sample ranges tile 0..sample_count), so only new entries are zeroed (no 13 MB memset
    // per call on a 10k-face mesh).
    let (mut points, mut normals) = buffers;
    points.truncate(sample_count);
    points.resize(sample_count, DVec3::ZERO);
    normals.truncate(sample_count);
    normals.resize(sample_count, DVec3::ZERO);
    let (extra_samples, extra_subs) = if full {
        (sample_count, sub_count)
    } else {
        (0, 0)
    };
    let mut faces = vec![0; extra_samples];
    let mut barycentrics = vec![[0.0; 3]; extra_samples];
    let mut sub_triangles = vec![[0; 3]; extra_subs];
    let mut sub_triangle_faces = vec![0; extra_subs];

    // Then fill the flat arrays in parallel over contiguous face ranges; every entry depends
    // only on its face, so the result is bit-identical whatever the thread count.
    let mut chunks = Vec::new();
    let mut rest = SampleSlices {
        first_face: 0,
        points: &mut points,
        faces: &mut faces,
        barycentrics: &mut barycentrics,
        normals: &mut normals,
        sub_triangles: &mut sub_triangles,
        sub_triangle_faces: &mut sub_triangle_faces,
    };
    let mut first = 0;
    while first < triangles.len() {
        let end = (first + FILL_CHUNK_FACES).min(triangles.len());
        let samples = (face_offsets[end] - face_offsets[first]) as usize;
        let subs = (face_sub_triangle_offsets[end] - face_sub_triangle_offsets[first]) as usize;
        let (head, tail) = rest.split(samples, subs, end, full);
        chunks.push((first..end, head));
        rest = tail;
        first = end;
    }
    chunks.into_par_iter().for_each(|(range, chunk)| {
        fill_faces(
            range,
            chunk,
            positions,
            triangles,
            vertex_normals,
            &face_n,
            &face_offsets,
            &grids,
            full,
        )
    });
    Ok(RegularSamples {
        points,
        faces,
        barycentrics,
        normals,
        face_n,
        face_offsets,
        face_sub_triangle_offsets,
        sub_triangles,
        sub_triangle_faces,
    })
}

/// Faces per parallel fill task of [`regular_samples`] (about 2–3k samples at the default
/// density on a 10k-face mesh; small meshes stay in one task).
const FILL_CHUNK_FACES: usize = 512;

/// The output slices of a contiguous face range, starting at face `first_face`.
struct SampleSlices<'a> {
    first_face: usize,
    points: &'a mut [DVec3],
    faces: &'a mut [u32],
    barycentrics: &'a mut [[f64; 3]],
    normals: &'a mut [DVec3],
    sub_triangles: &'a mut [[u32; 3]],
    sub_triangle_faces: &'a mut [u32],
}

impl<'a> SampleSlices<'a> {
    /// Splits off the first `samples` samples and `subs` sub-triangles (of the per-sample
    /// faces and barycentrics and the sub-triangle slices only if `full`; they are empty
    /// otherwise); the rest starts at face `next_face`.
    fn split(self, samples: usize, subs: usize, next_face: usize, full: bool) -> (Self, Self) {
        let (extra_samples, extra_subs) = if full { (samples, subs) } else { (0, 0) };
        let (p0, p1) = self.points.split_at_mut(samples);
        let (f0, f1) = self.faces.split_at_mut(extra_samples);
        let (b0, b1) = self.barycentrics.split_at_mut(extra_samples);
        let (n0, n1) = self.normals.split_at_mut(samples);
        let (s0, s1) = self.sub_triangles.split_at_mut(extra_subs);
        let (t0, t1) = self.sub_triangle_faces.split_at_mut(extra_subs);
        (
            Self {
                first_face: self.first_face,
                points: p0,
                faces: f0,
                barycentrics: b0,
                normals: n0,
                sub_triangles: s0,
                sub_triangle_faces: t0,
            },
            Self {
                first_face: next_face,
                points: p1,
                faces: f1,
                barycentrics: b1,
                normals: n1,
                sub_triangles: s1,
                sub_triangle_faces: t1,
            },
        )
    }
}

/// Writes the samples and (if `full`) the per-sample faces and barycentrics and the
/// sub-triangles of the faces `range` into `chunk` (whose slices start at the first of them).
#[allow(clippy::too_many_arguments)]
fn fill_faces(
    range: Range<usize>,
    chunk: SampleSlices<'_>,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_normals: Option<&[DVec3]>,
    face_n: &[u32],
    face_offsets: &[u32],
    grids: &[Option<FaceGrid>],
    full: bool,
) {
    let sample_base = face_offsets[chunk.first_face] as usize;
    let mut sub_start = 0usize;
    for f in range {
        let tri = triangles[f];
        let Some((bary, sub)) = &grids[face_n[f] as usize] else {
            continue; // every used size has a grid
        };
        let local = face_offsets[f] as usize - sample_base;
        let count = bary.len();
        let corners = tri.map(|v| positions[v as usize]);
        let face_normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        let vn = vertex_normals.map(|normals| tri.map(|v| normals[v as usize]));
        let points = &mut chunk.points[local..local + count];
        let normals = &mut chunk.normals[local..local + count];
        for ((w, p), n) in bary.iter().zip(points.iter_mut()).zip(normals.iter_mut()) {
            *p = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2];
            *n = match vn {
                Some(vn) => {
                    let blended = (w[0] * vn[0] + w[1] * vn[1] + w[2] * vn[2]).normalize_or_zero();
                    if blended == DVec3::ZERO {
                        face_normal
                    } else {
                        blended
                    }
                }
                None => face_normal,
            };
        }
        if !full {
            continue;
        }
        chunk.faces[local..local + count].fill(f as u32);
        chunk.barycentrics[local..local + count].copy_from_slice(bary);
        let offset = face_offsets[f];
        let subs = &mut chunk.sub_triangles[sub_start..sub_start + sub.len()];
        for (dst, s) in subs.iter_mut().zip(sub) {
            *dst = s.map(|i| i + offset);
        }
        chunk.sub_triangle_faces[sub_start..sub_start + sub.len()].fill(f as u32);
        sub_start += sub.len();
    }
}

/// Bounding-box diagonal of the vertices referenced by `triangles` (0 when there are none).
fn referenced_bbox_diagonal(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for tri in triangles {
        for &v in tri {
            let p = positions[v as usize];
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if triangles.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn grid_of_size_three_has_six_points_and_four_sub_triangles() {
        let (bary, sub) = face_grid(3);
        assert_eq!(bary.len(), 6);
        assert_eq!(sub.len(), 4);
        assert_eq!(bary[grid_ordinal(0, 0) as usize], [1.0, 0.0, 0.0]);
        assert_eq!(bary[grid_ordinal(2, 0) as usize], [0.0, 1.0, 0.0]);
        assert_eq!(bary[grid_ordinal(0, 2) as usize], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn tiny_grids_do_not_panic() {
        assert_eq!(face_grid(0), (vec![], vec![]));
        let (bary, sub) = face_grid(1);
        assert_eq!(bary, vec![[1.0, 0.0, 0.0]]);
        assert!(sub.is_empty());
    }

    #[test]
    fn clipped_face_rounds_up_to_cap() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert_eq!(round_grid_size(15.0, 3, 16, &mut rng), 16);
        assert_eq!(round_grid_size(1e9, 3, 16, &mut rng), 16);
        assert_eq!(round_grid_size(0.5, 3, 16, &mut rng), 3);
        assert_eq!(round_grid_size(f64::NAN, 3, 16, &mut rng), 3);
        let n = round_grid_size(14.5, 3, 16, &mut rng);
        assert!(n == 14 || n == 15);
    }

    #[test]
    fn sample_points_are_those_of_the_full_samples() {
        // Faces of different sizes (some need stochastic rounding draws), one tiny.
        let p = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.3, 0.2, 0.1),
            DVec3::new(0.02, 0.01, 0.0),
        ];
        let t = [[0, 1, 2], [1, 3, 2], [2, 4, 0], [0, 3, 4]];
        let n: Vec<DVec3> = p.iter().map(|q| (*q + DVec3::Z).normalize()).collect();
        let options = RegularSamplingOptions {
            density: 0.03,
            ..RegularSamplingOptions::default()
        };
        for normals in [None, Some(&n[..])] {
            let mut a = ChaCha8Rng::seed_from_u64(9);
            let mut b = ChaCha8Rng::seed_from_u64(9);
            let full = regular_samples(&p, &t, normals, &options, &mut a).unwrap();
            let light = regular_sample_points(&p, &t, normals, &options, &mut b).unwrap();
            assert_eq!(light.points, full.points);
            assert_eq!(light.normals, full.normals);
            assert_eq!(light.face_n, full.face_n);
            assert_eq!(light.face_offsets, full.face_offsets);
            assert_eq!(a.random::<u64>(), b.random::<u64>(), "same RNG draws");
            // Reusing a buffer filled for another mesh gives the same samples.
            let mut reused = regular_sample_points(&p, &t[..2], None, &options, &mut a).unwrap();
            let mut c = ChaCha8Rng::seed_from_u64(9);
            regular_sample_points_into(&mut reused, &p, &t, normals, &options, &mut c).unwrap();
            assert_eq!(reused, light);
            // And a larger buffer (stale entries) for a smaller mesh.
            let mut d = ChaCha8Rng::seed_from_u64(4);
            let mut e = ChaCha8Rng::seed_from_u64(4);
            regular_sample_points_into(&mut reused, &p, &t[1..3], normals, &options, &mut d)
                .unwrap();
            let fresh = regular_sample_points(&p, &t[1..3], normals, &options, &mut e).unwrap();
            assert_eq!(reused, fresh);
            for f in 0..t.len() {
                let (_, sub) = face_grid(light.face_n[f]);
                let shifted: Vec<[u32; 3]> = sub
                    .iter()
                    .map(|s| s.map(|i| i + light.face_offsets[f]))
                    .collect();
                assert_eq!(shifted, full.sub_triangles[full.face_sub_triangles(f)]);
            }
        }
    }

    #[test]
    fn mismatched_normals_are_an_error() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let err = regular_samples(
            &p,
            &[[0, 1, 2]],
            Some(&[DVec3::Z]),
            &RegularSamplingOptions::default(),
            &mut rng,
        )
        .unwrap_err();
        assert_eq!(
            err,
            RegularSamplingError::NormalCount {
                positions: 3,
                normals: 1
            }
        );
    }
}
