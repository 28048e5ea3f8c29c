//! # roar-ops
//!
//! Will own the optimizer (Move Vertices), the remeshing blocks (Face Collapse, edge flips,
//! Face Split, tangential smoothing, untangle), QEM decimation to an exact face count, and the
//! initial meshes (watertight init from soups, icosphere, SDF voxel init).

pub mod optim;
pub mod qem;
pub mod untangle;
