//! # roar-ops
//!
//! The optimizer (Move Vertices), the remeshing blocks (Face Collapse, edge flips, Face Split,
//! tangential smoothing, untangle), QEM decimation to an exact face count, and the initial meshes
//! (watertight init from soups, SDF voxel init).

pub mod init;
pub mod optim;
pub mod qem;
pub mod untangle;
