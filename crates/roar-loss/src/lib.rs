//! # roar-loss
//!
//! Will own the reconstruction target (the cleaned soup T′, its renders, the oriented point
//! cloud P) and the losses that drive the vertices: the render loss, the planar projection loss
//! and, later, the SDF loss, behind a common `Loss` trait.
