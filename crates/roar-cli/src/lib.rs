//! # roar-cli
//!
//! The library half of the `roar` command: one module per subcommand (argument struct plus a
//! `run` function), and the reconstruction pipeline that composes the other crates
//! ([`pipeline::Reconstruction`], with replaceable losses and blocks).

pub mod batch;
pub mod budget;
pub mod checks;
pub mod commands;
pub mod example;
pub mod input;
pub mod pipeline;
pub mod preview;
