//! Watertight initial meshes, in the manner of Manifold, which the paper starts from
//! (`docs/method.md#watertight-init`).
//!
//! [`watertight_init`] turns any triangle soup into a closed, outward-oriented, 2-manifold triangle
//! mesh in the manner of Manifold (Huang et al. 2018):
//!
//! 1. voxelize: mark every voxel a triangle touches (exact triangle–box test);
//! 2. close one-voxel gaps (26-neighbour dilation of the marked set), flood-fill the exterior from
//!    the grid border (6-connectivity), turn solid the exterior voxels whose generalized winding
//!    number is above [`InitOptions::enclosure_winding_threshold`] (so punctures of closed
//!    surfaces close while real tunnels and open sheets stay; module `winding_solid`) or, for
//!    range scans, that every scanner sees only through measured surface (module `sight`), then let
//!    the exterior grow back one voxel into untouched voxels (the second half of a morphological
//!    closing, so the surface hugs the touched voxels while gaps stay closed), never through a
//!    voxel that would join two exterior groups (so the regrowth cuts no tunnel through a thin
//!    wall; module `simple`); everything not exterior is solid;
//! 3. repair the voxel set so that its boundary is a 2-manifold (module `solid`: non-manifold
//!    edges and corners are resolved by adding voxels, which merges touching parts), and extract the
//!    boundary squares as outward triangles;
//! 4. pull the surface toward the target with bounded, fold-free moves (module `project`, which
//!    documents the rule that keeps opposite sides of thin parts ≥ `min_gap` voxels apart);
//! 5. split into pieces and drop pieces under 0.1 % of the total area.
//!
//! When the solid has more pieces than [`InitOptions::target_pieces`] (a small face budget cannot
//! shape thousands of leaves), nearby pieces are merged between steps 2 and 3 by closing the
//! solid with the smallest ball that brings the count down (module `merge`); pieces beyond
//! [`InitOptions::max_pieces`] are dropped at step 5, smallest first.
//!
//! [`sdf_init`] builds the same kind of mesh from the negative cells of a signed distance function
//! (supplementary §3), through the same repair and extraction code.

mod error;
mod grid;
mod initial;
mod merge;
mod options;
mod orient;
mod output;
mod pieces;
mod project;
mod sdf;
mod sight;
mod simple;
mod solid;
mod soup;
mod surface;
mod voxelize;
mod watertight;
mod winding_solid;

pub use error::InitError;
pub use initial::{InitialMeshOptions, InitialMeshStats, initial_mesh, initial_mesh_from_init};
pub use options::{
    ENCLOSURE_MAX_CAP_FRACTION, ENCLOSURE_MAX_CAP_WIDTH, ENCLOSURE_WINDING_THRESHOLD, InitOptions,
    MAX_MERGE_RADIUS, SdfInitOptions,
};
pub use output::{InitStats, WatertightInit};
pub use sdf::sdf_init;
pub use sight::ScannerView;
pub use watertight::{watertight_init, watertight_init_with};
