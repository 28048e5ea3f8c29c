//! The `roar` command line.

fn main() {}
