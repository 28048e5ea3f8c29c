//! Trimmed point-to-plane ICP of one patch against a fixed surface.
//!
//! Samples are the patch's vertices (every k-th referenced one) with their normals. Each
//! iteration pairs every placed sample with its closest point on the target surface, keeps pairs
//! within reach whose normals agree (so the front of a thin part never pairs with its back),
//! keeps the closest [`IcpOptions::keep_fraction`] of those (trimming: the part of a scan that
//! the others never saw has no true partner), and solves the linearised point-to-plane problem
//! `min Σ ((p − q)·n + ω·((p − c) × n) + δ·n)²` for a small rotation ω about the samples'
//! centroid c and a translation δ (a 6×6 normal-equation solve, nalgebra's Cholesky).

use glam::{DQuat, DVec3};
use nalgebra::{Matrix6, Vector6};
use roar_mesh::spatial::{TriangleBvh, vertex_normals};

use super::patch::ScanPatch;
use super::transform::RigidTransform;

/// How [`icp`] runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpOptions {
    /// Iterations at most. Default 100; ICP usually stops much earlier on `tolerance`.
    pub max_iterations: usize,
    /// Samples taken from the patch's vertices (evenly by index). Default 5000.
    pub samples: usize,
    /// Pairs farther apart than this many times the patch's median edge length are not pairs.
    /// Default 10 (5 mm on the Stanford scans, whose `.conf` poses are within about 1 mm).
    pub reach_factor: f64,
    /// Fraction of the pairs within reach that are kept, the closest first. Default 0.8.
    pub keep_fraction: f64,
    /// Pairs whose normals are more than this many degrees apart are rejected. Default 60.
    pub max_normal_angle_degrees: f64,
    /// A scan with fewer pairs within reach than this fraction of its samples overlaps nothing
    /// and is not moved. Default 0.05.
    pub min_overlap: f64,
    /// Stop when an iteration rotates less than this (radians) and moves less than this many
    /// median edge lengths. Default 1e-7.
    pub tolerance: f64,
}

impl Default for IcpOptions {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            samples: 5000,
            reach_factor: 10.0,
            keep_fraction: 0.8,
            max_normal_angle_degrees: 60.0,
            min_overlap: 0.05,
            tolerance: 1e-7,
        }
    }
}

/// What [`icp`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpResult {
    /// The refined pose (the start pose when the patch overlaps nothing).
    pub transform: RigidTransform,
    /// RMS point-to-plane distance of the kept pairs at the start pose (NaN without pairs).
    pub residual_before: f64,
    /// The same at the returned pose.
    pub residual_after: f64,
    /// Pairs within reach at the returned pose.
    pub pairs: usize,
    /// Whether enough samples found partners (see [`IcpOptions::min_overlap`]).
    pub overlaps: bool,
    /// Iterations run.
    pub iterations: usize,
}

/// Samples of a patch: points and unit normals in the scan's frame.
struct Samples {
    points: Vec<DVec3>,
    normals: Vec<DVec3>,
    centroid: DVec3,
    /// Median edge length of the patch, the unit of reach and tolerance.
    edge: f64,
}

/// The vertices of `patch` that some triangle uses, every k-th of them to get about `count`,
/// with their normals.
fn samples(patch: &ScanPatch<'_>, count: usize) -> Samples {
    let normals = vertex_normals(patch.positions, patch.triangles);
    let used: Vec<usize> = (0..patch.positions.len())
        .filter(|&v| normals[v] != DVec3::ZERO)
        .collect();
    let step = used.len().div_ceil(count.max(1)).max(1);
    let picked: Vec<usize> = used.iter().step_by(step).copied().collect();
    let points: Vec<DVec3> = picked.iter().map(|&v| patch.positions[v]).collect();
    let centroid = points.iter().copied().sum::<DVec3>() / points.len().max(1) as f64;
    let mut edges: Vec<f64> = patch
        .triangles
        .iter()
        .step_by(patch.triangles.len().div_ceil(20_000).max(1))
        .map(|t| patch.positions[t[0] as usize].distance(patch.positions[t[1] as usize]))
        .collect();
    let middle = edges.len() / 2;
    let edge = if edges.is_empty() {
        0.0
    } else {
        *edges.select_nth_unstable_by(middle, f64::total_cmp).1
    };
    Samples {
        points,
        normals: picked.iter().map(|&v| normals[v]).collect(),
        centroid,
        edge,
    }
}

/// The centroid of the samples [`icp`] takes from `patch` (scan frame), where alignment
/// differences are measured.
pub(super) fn sample_centroid(patch: &ScanPatch<'_>) -> DVec3 {
    samples(patch, IcpOptions::default().samples).centroid
}

/// A pair: placed sample `p`, its closest target point `q`, the target's unit normal `n`.
struct Pair {
    p: DVec3,
    q: DVec3,
    n: DVec3,
    distance: f64,
}

/// The kept pairs of `samples` placed by `pose` against `target`, and how many were within
/// reach before trimming.
fn pairs(
    samples: &Samples,
    target: &TriangleBvh,
    pose: &RigidTransform,
    options: &IcpOptions,
) -> (Vec<Pair>, usize) {
    let reach = options.reach_factor * samples.edge;
    let min_cos = options.max_normal_angle_degrees.to_radians().cos();
    let mut found: Vec<Pair> = samples
        .points
        .iter()
        .zip(&samples.normals)
        .filter_map(|(&p, &m)| {
            let p = pose.apply(p);
            let m = pose.rotation * m;
            let hit = target.closest_point_within(p, reach)?;
            let [a, b, c] = target.corners(hit.face);
            let n = (b - a).cross(c - a).normalize_or_zero();
            (n.dot(m) >= min_cos).then(|| Pair {
                p,
                q: hit.point,
                n,
                distance: hit.distance_squared.sqrt(),
            })
        })
        .collect();
    let within = found.len();
    found.sort_by(|a, b| a.distance.total_cmp(&b.distance));
    found.truncate((within as f64 * options.keep_fraction).ceil() as usize);
    (found, within)
}

/// RMS point-to-plane distance of `pairs` (NaN when empty).
fn rms(pairs: &[Pair]) -> f64 {
    let sum: f64 = pairs.iter().map(|x| (x.p - x.q).dot(x.n).powi(2)).sum();
    (sum / pairs.len() as f64).sqrt()
}

/// Moves `patch` (placed by `start`) onto the fixed surface `target` by trimmed point-to-plane
/// ICP (module docs). A patch with too few pairs within reach keeps `start`.
pub fn icp(
    patch: &ScanPatch<'_>,
    target: &TriangleBvh,
    start: &RigidTransform,
    options: &IcpOptions,
) -> IcpResult {
    let samples = samples(patch, options.samples);
    let (first, within) = pairs(&samples, target, start, options);
    let residual_before = rms(&first);
    let enough = (options.min_overlap * samples.points.len() as f64).max(6.0);
    if (within as f64) < enough {
        return IcpResult {
            transform: *start,
            residual_before,
            residual_after: residual_before,
            pairs: within,
            overlaps: false,
            iterations: 0,
        };
    }
    let mut pose = *start;
    let mut current = first;
    let mut iterations = 0;
    while iterations < options.max_iterations {
        let center = pose.apply(samples.centroid);
        let Some((omega, delta)) = solve_step(&current, center) else {
            break;
        };
        let step = DQuat::from_scaled_axis(omega);
        pose = RigidTransform {
            rotation: (step * pose.rotation).normalize(),
            translation: step * (pose.translation - center) + center + delta,
        };
        iterations += 1;
        (current, _) = pairs(&samples, target, &pose, options);
        if current.len() < 6 {
            break;
        }
        if omega.length() < options.tolerance && delta.length() < options.tolerance * samples.edge {
            break;
        }
    }
    let (last, within) = pairs(&samples, target, &pose, options);
    IcpResult {
        transform: pose,
        residual_before,
        residual_after: rms(&last),
        pairs: within,
        overlaps: true,
        iterations,
    }
}

/// The small rotation ω (about `center`) and translation δ minimising the linearised
/// point-to-plane energy of `pairs`, or `None` when the pairs do not fix all six (a plane, a
/// cylinder: the normal matrix is singular).
fn solve_step(pairs: &[Pair], center: DVec3) -> Option<(DVec3, DVec3)> {
    let mut ata = Matrix6::<f64>::zeros();
    let mut atb = Vector6::<f64>::zeros();
    for x in pairs {
        let r = (x.p - center).cross(x.n);
        let row = Vector6::new(r.x, r.y, r.z, x.n.x, x.n.y, x.n.z);
        let b = -(x.p - x.q).dot(x.n);
        ata += row * row.transpose();
        atb += row * b;
    }
    let solution = ata.cholesky()?.solve(&atb);
    let omega = DVec3::new(solution[0], solution[1], solution[2]);
    let delta = DVec3::new(solution[3], solution[4], solution[5]);
    (omega.is_finite() && delta.is_finite()).then_some((omega, delta))
}
