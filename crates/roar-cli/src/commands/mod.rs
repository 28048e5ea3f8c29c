//! One module per `roar` subcommand: a clap `Args` struct and a `run` function returning
//! `anyhow::Result<()>`, so the binary only dispatches and prints errors.

pub mod batch;
pub mod batch_report;
pub mod decimate;
pub mod eval;
pub mod example;
pub mod extract;
pub mod info;
pub mod init;
pub mod reconstruct;
pub mod render;
pub mod scans;
