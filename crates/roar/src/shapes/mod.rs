//! The input kinds roar reads, each a [`crate::Shape`]: triangle soups, signed distance
//! functions, and sets of range scans (whose aligned patches are a soup).

pub mod scans;
pub mod sdf;
pub mod soup;
