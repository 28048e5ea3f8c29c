//! # roar-cli
//!
//! The library half of the `roar` command: one module per subcommand (argument struct plus a
//! `run` function) over the [`roar`] pipeline crate, the batch runner and the preview picture.

pub mod batch;
pub mod checks;
pub mod commands;
pub mod mesh_files;
pub mod preview;
