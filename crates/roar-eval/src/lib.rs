//! # roar-eval
//!
//! Metrics on arbitrary triangle soups (those of supplementary §1.1 and more;
//! `docs/method.md#evaluation-metrics`), on plain buffers (`&[DVec3]`, `&[[u32; 3]]`):
//!
//! - [`topology`]: boundary edges and loops, non-manifold edges and vertices, inconsistent winding,
//!   duplicates, degenerate faces, components, watertightness, Euler characteristic, genus, with the
//!   counting rules of the shared test data's `SOURCES.md`; [`weld_bit_identical`] merges exact
//!   duplicate positions first.
//! - [`triangle_quality`]: aspect ratio `Q = R/(2r)` statistics.
//! - [`fidelity`]: Chamfer L2 (mean and PyTorch3D squared-sum forms), Hausdorff and normal cosine
//!   similarity against a reference, from area-weighted samples (`roar_mesh::spatial::sample_surface`),
//!   each both to the other side's nearest sample (k-d tree) and to the other mesh's exact closest
//!   point (BVH).
//! - [`self_intersections`]: faces intersecting a non-adjacent face (exact, on the welded mesh),
//!   and the paper's ε-offset variant (supplementary §1.1).
//! - [`evaluate`] gathers everything in a serde [`Report`].

mod error;
mod fidelity;
mod nearest;
mod quality;
mod report;
mod self_intersections;
mod topology;

pub use error::EvalError;
pub use fidelity::{ChamferOptions, FidelityStats, bbox_diagonal, fidelity};
pub use nearest::{Nearest, nearest_neighbours};
pub use quality::{QualityStats, aspect_ratio, triangle_quality};
pub use report::{EvalOptions, OrientationStats, Report, evaluate, validate_soup};
pub use self_intersections::{
    SelfIntersectionOptions, SelfIntersectionStats, area_weighted_vertex_normals,
    self_intersections,
};
pub use topology::{TopologyStats, signed_volume, topology, weld_bit_identical};
