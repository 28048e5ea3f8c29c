//! A set of range scans as an input: the kind `roar reconstruct` reads from a `.conf`
//! (or the folder holding one).
//!
//! [`load_scans`] turns every scan into its patch (`roar_io::RangeGrid::patch` for range images,
//! `roar_io::point_scan_patch` for points alone), places
//! the patches by the `.conf` poses and refines the poses by ICP (`roar_ops::align`). The union
//! of the aligned patches, holes and overlaps included, is the target: a [`crate::SoupShape`]
//! of it, with the scan defaults' enclosure rule (`ReconstructConfig::scan_defaults`), since a
//! scanned object is closed but the scanner never sees all of it (the bunny's base), and the
//! scanners' lines of sight ([`AlignedScans::scanner_views`]), which close what the scanners
//! saw only from outside.

use std::path::Path;

use glam::DVec3;
use roar_io::{IoError, PatchOptions, TriangleSoup};
use roar_ops::align::{AlignOptions, RigidTransform, ScanPatch, align_scans};
use roar_ops::init::ScannerView;
use serde::Serialize;

use crate::config::ReconstructConfig;

/// What happened to one scan, for reports.
#[derive(Debug, Clone, Serialize)]
pub struct ScanReport {
    /// The scan's file.
    pub file: String,
    /// Triangles of its patch.
    pub triangles: usize,
    /// Grid triangles dropped for bridging a depth jump.
    pub dropped_long_edge: usize,
    /// Grid triangles dropped for facing the scanner at a grazing angle.
    pub dropped_grazing: usize,
    /// RMS point-to-plane distance to the other scans at the `.conf` pose (input units; null
    /// when ICP was off or the scan overlaps nothing).
    pub residual_before: Option<f64>,
    /// The same after ICP.
    pub residual_after: Option<f64>,
    /// False when the scan overlaps too little of the others for ICP; it kept its `.conf` pose.
    pub overlaps: bool,
    /// Rotation ICP applied to the `.conf` pose, in degrees.
    pub rotated_degrees: f64,
    /// How far ICP moved the scan, in input units.
    pub moved: f64,
}

/// A scan set read, patched and aligned.
#[derive(Debug, Clone)]
pub struct AlignedScans {
    /// One patch per scan, placed in the common frame (every grid vertex kept).
    pub patches: Vec<TriangleSoup>,
    /// One report per scan, in `.conf` order.
    pub reports: Vec<ScanReport>,
    /// Per scan, the unit direction toward its scanner in the common frame: its frame's +z
    /// placed by the final pose (the scanner looks along −z).
    pub toward_scanner: Vec<DVec3>,
}

impl AlignedScans {
    /// The union of the patches, without unreferenced vertices: the reconstruction's target.
    pub fn union(&self) -> TriangleSoup {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for patch in &self.patches {
            let base = positions.len() as u32;
            positions.extend_from_slice(&patch.positions);
            triangles.extend(patch.triangles.iter().map(|t| t.map(|v| v + base)));
        }
        let (positions, triangles) = crate::input::drop_unreferenced(&positions, &triangles);
        TriangleSoup::new(positions, triangles)
    }

    /// Each scan's patch with the direction toward its scanner, for the init's lines of sight
    /// (`roar_ops::init::ScannerView`).
    pub fn scanner_views(&self) -> Vec<ScannerView> {
        self.patches
            .iter()
            .zip(&self.toward_scanner)
            .map(|(patch, &toward_scanner)| ScannerView {
                toward_scanner,
                positions: patch.positions.clone(),
                triangles: patch.triangles.clone(),
            })
            .collect()
    }
}

/// Reads the scan set at `path` (a `.conf` or its folder), makes each scan's patch with the
/// config's filters, places it by its `.conf` pose and, when `icp`, refines the poses.
///
/// Errors: those of `roar_io::read_scan_set` and `roar_io::read_range_grid`, and a scan whose
/// patch has no triangle (named).
pub fn load_scans(
    path: &Path,
    config: &ReconstructConfig,
    icp: bool,
) -> Result<AlignedScans, IoError> {
    let set = roar_io::read_scan_set(path)?;
    let options = PatchOptions {
        max_edge_factor: config.target.scan_max_edge_factor,
        max_angle_degrees: config.target.scan_max_angle_degrees,
    };
    let mut patches = Vec::with_capacity(set.scans.len());
    let mut reports = Vec::with_capacity(set.scans.len());
    let mut poses = Vec::with_capacity(set.scans.len());
    for scan in &set.scans {
        let (patch, stats) = roar_io::read_scan_patch_file(&scan.path, &options)?;
        let file = scan.path.display().to_string();
        if patch.triangles.is_empty() {
            return Err(IoError::in_file(
                &file,
                "the scan's patch has no triangle (every grid triangle was filtered out)",
            ));
        }
        reports.push(ScanReport {
            file,
            triangles: patch.triangles.len(),
            dropped_long_edge: stats.dropped_long_edge,
            dropped_grazing: stats.dropped_grazing,
            residual_before: None,
            residual_after: None,
            overlaps: true,
            rotated_degrees: 0.0,
            moved: 0.0,
        });
        poses.push(RigidTransform {
            rotation: scan.rotation(),
            translation: scan.translation,
        });
        patches.push(patch);
    }
    if icp && patches.len() > 1 {
        let views: Vec<ScanPatch<'_>> = patches
            .iter()
            .map(|p| ScanPatch {
                positions: &p.positions,
                triangles: &p.triangles,
            })
            .collect();
        let alignments = align_scans(&views, &mut poses, &AlignOptions::default());
        for (report, alignment) in reports.iter_mut().zip(alignments) {
            let finite = |x: f64| x.is_finite().then_some(x);
            report.residual_before = finite(alignment.residual_before);
            report.residual_after = finite(alignment.residual_after);
            report.overlaps = alignment.overlaps;
            report.rotated_degrees = alignment.rotated_degrees;
            report.moved = alignment.moved;
        }
    }
    for (patch, pose) in patches.iter_mut().zip(&poses) {
        for p in &mut patch.positions {
            *p = pose.apply(*p);
        }
    }
    let toward_scanner = poses.iter().map(|pose| pose.rotation * DVec3::Z).collect();
    Ok(AlignedScans {
        patches,
        reports,
        toward_scanner,
    })
}
