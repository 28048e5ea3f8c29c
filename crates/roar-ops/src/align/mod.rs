//! Rigid alignment of range-scan patches: trimmed point-to-plane ICP, scan by scan against the
//! union of the others.
//!
//! A scan set comes with approximate poses (a `.conf`); [`align_scans`] refines them. The first
//! scan is the anchor (it fixes the common frame); every other scan in turn is moved by
//! [`icp`] onto the other patches at their current poses, for [`AlignOptions::rounds`] rounds.
//! A scan with too few partners within reach (it overlaps nothing) keeps its pose and is
//! reported as such rather than pulled onto whatever is nearest.

mod icp;
mod patch;
mod transform;

pub use icp::{IcpOptions, IcpResult, icp};
pub use patch::ScanPatch;
pub use transform::RigidTransform;

use roar_mesh::spatial::TriangleBvh;

/// How [`align_scans`] runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignOptions {
    /// Passes over all scans (each pass aligns every scan but the anchor once). Default 2: a
    /// second pass lets scans aligned early profit from the later ones.
    pub rounds: usize,
    /// The per-scan ICP.
    pub icp: IcpOptions,
}

impl Default for AlignOptions {
    fn default() -> Self {
        Self {
            rounds: 2,
            icp: IcpOptions::default(),
        }
    }
}

/// What [`align_scans`] did to one scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanAlignment {
    /// RMS point-to-plane distance of the scan's trimmed pairs against the other scans at the
    /// given poses (input units; NaN when it overlaps nothing).
    pub residual_before: f64,
    /// The same after alignment.
    pub residual_after: f64,
    /// Pairs found within reach at the final pose (0 for the anchor).
    pub pairs: usize,
    /// False when the scan overlaps too little of the others to be aligned; it kept its pose.
    pub overlaps: bool,
    /// Rotation applied to the given pose, in degrees.
    pub rotated_degrees: f64,
    /// How far the scan's sample centroid moved, in input units.
    pub moved: f64,
}

/// Refines `poses` (one per patch, scan frame → common frame) by ICP of every scan but the
/// first against the union of the others; returns one [`ScanAlignment`] per scan (the anchor's
/// residuals are measured like the others', and it never moves).
pub fn align_scans(
    patches: &[ScanPatch<'_>],
    poses: &mut [RigidTransform],
    options: &AlignOptions,
) -> Vec<ScanAlignment> {
    assert_eq!(patches.len(), poses.len(), "one pose per patch");
    let given = poses.to_vec();
    let mut results: Vec<Option<IcpResult>> = vec![None; patches.len()];
    let mut first: Vec<Option<IcpResult>> = vec![None; patches.len()];
    let rounds = if patches.len() > 1 { options.rounds } else { 0 };
    for _ in 0..rounds {
        for i in 0..patches.len() {
            let others = others_bvh(patches, poses, i);
            let mut icp_options = options.icp;
            if i == 0 {
                icp_options.max_iterations = 0;
            }
            let result = icp(&patches[i], &others, &poses[i], &icp_options);
            if result.overlaps {
                poses[i] = result.transform;
            }
            first[i].get_or_insert(result);
            results[i] = Some(result);
        }
    }
    // The anchor's final residual is measured after all the others have moved.
    if rounds > 0 {
        let others = others_bvh(patches, poses, 0);
        let measure = IcpOptions {
            max_iterations: 0,
            ..options.icp
        };
        results[0] = Some(icp(&patches[0], &others, &poses[0], &measure));
    }
    (0..patches.len())
        .map(|i| {
            let centroid = icp::sample_centroid(&patches[i]);
            let (rotated_degrees, moved) = given[i].difference(&poses[i], centroid);
            match (first[i], results[i]) {
                (Some(before), Some(after)) => ScanAlignment {
                    residual_before: before.residual_before,
                    residual_after: after.residual_after,
                    pairs: after.pairs,
                    overlaps: before.overlaps && after.overlaps,
                    rotated_degrees,
                    moved,
                },
                _ => ScanAlignment {
                    residual_before: f64::NAN,
                    residual_after: f64::NAN,
                    pairs: 0,
                    overlaps: false,
                    rotated_degrees,
                    moved,
                },
            }
        })
        .collect()
}

/// The union of every patch but `skip`, placed by `poses`, as one BVH.
pub fn others_bvh(patches: &[ScanPatch<'_>], poses: &[RigidTransform], skip: usize) -> TriangleBvh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (j, (patch, pose)) in patches.iter().zip(poses).enumerate() {
        if j == skip {
            continue;
        }
        let base = positions.len() as u32;
        positions.extend(patch.positions.iter().map(|&p| pose.apply(p)));
        triangles.extend(patch.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    TriangleBvh::build(&positions, &triangles)
}
