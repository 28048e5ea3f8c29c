//! # roar-ops
//!
//! The mesh algorithms of the reconstruction, one folder per stage of the pipeline, listed here
//! in the order the pipeline runs them (`docs/design.md#one-reconstruction`):
//!
//! | stage | module | what |
//! |---|---|---|
//! | init | [`init`] | the initial closed mesh M0: watertight voxel init of a soup, icosphere |
//! | working budget, final QEM | [`decimate`] | QEM decimation to an exact face count |
//! | loop: Move Vertices | [`optim`] | the optimizer, its per-vertex state and how that state follows the mesh |
//! | loop: remeshing | [`blocks`] | the `Block` trait; Face Collapse, flips, Face Split, smoothing; candidate selection, edge costs, the intersection guard |
//! | loop and finish | [`untangle`] | the step limiter and the untangle block |
//! | finish | [`finish`] | fill to the budget, outward offset, handle removal when the budget needs it, data flips, sliver flips, degenerate collapses; for SDF inputs fin collapses and the fit to the zero set |
//!
//! Before the stages, for range scans: [`align`] (trimmed point-to-plane ICP of scan patches).
//!
//! Shared by several stages: [`geometry`] (per-mesh normals, folds, flip tests) and [`quadric`]
//! (the error quadrics of the decimation and of the QSlim edge costs); the geometric kernels
//! (triangle quality, vertex normals, the filtered exact face–face test) are
//! `roar_mesh::spatial`'s. Dependencies run down this table's stages and into the
//! shared modules; no two modules import each other.

pub mod align;

pub mod init;

pub mod decimate;

pub mod optim;

pub mod blocks;

pub mod untangle;

pub mod finish;

pub mod geometry;
pub mod quadric;
