//! The evaluation report: every metric of `roar eval` for one mesh, optionally against a reference.

use glam::DVec3;
use serde::Serialize;

use crate::error::EvalError;
use crate::fidelity::{ChamferOptions, FidelityStats, fidelity};
use crate::quality::{QualityStats, triangle_quality};
use crate::self_intersections::{
    SelfIntersectionOptions, SelfIntersectionStats, self_intersections,
};
use crate::topology::{TopologyStats, signed_volume, topology, weld_bit_identical};

/// What [`evaluate`] computes and how.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalOptions {
    /// Sampling for Chamfer, Hausdorff and normal similarity.
    pub chamfer: ChamferOptions,
    /// Self-intersections with these options, or `None` to skip them (they cost a
    /// BVH pass and exact tests; on by default).
    pub self_intersections: Option<SelfIntersectionOptions>,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            chamfer: ChamferOptions::default(),
            self_intersections: Some(SelfIntersectionOptions::default()),
        }
    }
}

/// Orientation of the whole soup.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationStats {
    /// `Σ a·(b×c)/6` over all triangles: positive for an outward-wound closed mesh.
    pub signed_volume: f64,
}

/// Every metric of one mesh; serialized as the `eval` JSON report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// Topology by the stored indices.
    pub topology: TopologyStats,
    /// Topology after welding bit-identical positions (the `SOURCES.md` figures).
    pub topology_welded: TopologyStats,
    /// Triangle aspect ratios.
    pub quality: QualityStats,
    /// Signed volume.
    pub orientation: OrientationStats,
    /// Distances and normal agreement to the reference, when one is given and both have area.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fidelity: Option<FidelityStats>,
    /// Self-intersections on the welded mesh, unless skipped by the options.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_intersections: Option<SelfIntersectionStats>,
}

/// Checks that every index is in range and every coordinate finite.
pub fn validate_soup(
    mesh: &'static str,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<(), EvalError> {
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(EvalError::NonFinite { mesh, vertex });
    }
    for (face, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(EvalError::IndexOutOfRange {
                mesh,
                face,
                index,
                vertices: positions.len(),
            });
        }
    }
    Ok(())
}

/// Evaluates a mesh (any soup) and, with a reference, its fidelity to it.
///
/// Fails only on invalid input (out-of-range index, non-finite coordinate) in either soup.
/// Deterministic for given options. Self-intersections are computed on the mesh welded at
/// bit-identical positions, like `topology_welded`.
pub fn evaluate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    reference: Option<(&[DVec3], &[[u32; 3]])>,
    options: &EvalOptions,
) -> Result<Report, EvalError> {
    validate_soup("mesh", positions, triangles)?;
    if let Some((rp, rt)) = reference {
        validate_soup("reference", rp, rt)?;
    }
    let (welded_positions, welded_triangles) = weld_bit_identical(positions, triangles);
    Ok(Report {
        topology: topology(positions, triangles),
        topology_welded: topology(&welded_positions, &welded_triangles),
        quality: triangle_quality(positions, triangles),
        orientation: OrientationStats {
            signed_volume: signed_volume(positions, triangles),
        },
        fidelity: reference
            .and_then(|(rp, rt)| fidelity(positions, triangles, rp, rt, &options.chamfer)),
        self_intersections: options
            .self_intersections
            .as_ref()
            .map(|o| self_intersections(&welded_positions, &welded_triangles, o)),
    })
}
