//! # roar-cli
//!
//! The library half of the `roar` command: the subcommands' logic, and later the reconstruction
//! pipeline that composes the other crates.
