//! # roar-render
//!
//! Will own the CPU differentiable rasterizer: the camera rig, z-buffered rasterization of
//! flat-shaded normal maps with alpha, analytic antialiasing in the manner of nvdiffrast, and the
//! backward pass from image gradients to vertex positions.
