//! Geometric kernels on plain buffers (`&[DVec3]` positions, `&[[u32; 3]]` triangles), written
//! once here and used by every crate: triangle BVH, closest point, ray cast, exact
//! triangle–triangle test, fast winding number, regular face sampling, the `Projector` trait and
//! the `Normalization` into the camera rig's sphere.

pub mod projector;
pub mod regular_sampling;
pub mod winding;

pub use projector::{Projector, SphereProjector};
pub use regular_sampling::{
    RegularSamples, RegularSamplingError, RegularSamplingOptions, face_grid, regular_samples,
};
pub use winding::{
    TriangleIndexError, WindingNumber, WindingNumberOptions, exact_winding_number,
    triangle_solid_angle,
};
