//! Shared by the CLI's integration tests: the pipeline's toy settings (from the `roar` crate's
//! tests) and roar-io's small glTF writer.
#![allow(dead_code)]

#[path = "../../../roar-io/tests/common/gltf.rs"]
pub mod gltf;

#[path = "../../../roar/tests/common/mod.rs"]
mod toy;

pub use toy::toy_config;
