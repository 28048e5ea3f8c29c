//! # roar-ops
//!
//! The optimizer (Move Vertices), the remeshing blocks (Face Collapse, edge flips, Face Split,
//! tangential smoothing, untangle), QEM decimation to an exact face count, and the initial meshes
//! (watertight init from soups, SDF voxel init).

pub mod block;
pub mod collapse_block;
pub mod data_flips;
pub mod degenerate;
pub mod flips;
pub mod genus;
pub mod geometry;
pub mod guard;
pub mod init;
mod intersect;
pub mod optim;
pub mod qem;
pub mod qslim;
pub mod select;
pub mod slivers;
pub mod smoothing;
pub mod split_block;
pub mod untangle;
