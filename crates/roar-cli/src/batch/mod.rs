//! `roar batch`: a dataset of inputs reconstructed at one or more face budgets, one child
//! process of the same binary per item and budget, resumable, and split into shards that a
//! cluster's job array runs side by side (`docs/cluster.md`).
//!
//! Each module has one job: [`manifest`] reads the list of items, [`shard`] picks this task's
//! share, [`hash`] fingerprints inputs, configs and the build, [`layout`] names every file of an
//! item and decides whether it is already done, and [`child`] runs one item under a timeout and
//! a memory guard.

pub mod child;
pub mod hash;
pub mod layout;
pub mod manifest;
pub mod shard;
