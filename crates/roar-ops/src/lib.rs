//! # roar-ops
//!
//! Will own the optimizer (Move Vertices), the remeshing blocks (Face Collapse, edge flips,
//! Face Split, tangential smoothing, untangle), QEM decimation to an exact face count, and the
//! initial meshes (watertight init from soups, icosphere, SDF voxel init).

pub mod block;
pub mod collapse_block;
pub mod flips;
pub mod geometry;
pub mod optim;
pub mod qslim;
pub mod select;
pub mod smoothing;
pub mod split_block;
