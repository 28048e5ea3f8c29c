//! # roar-render
//!
//! The CPU differentiable rasterizer of roar (spec `roar-method.md` §3.2.1,
//! `crates-and-rendering.md` §3.4): the star camera rig, z-buffered rasterization of flat-shaded
//! normal maps with alpha, analytic antialiasing in the manner of Laine et al. 2020 (nvdiffrast),
//! and the backward pass from image gradients to vertex positions.
//!
//! Pipeline per view (views run in parallel with rayon, each view single-threaded):
//! 1. [`camera`]: world → clip → pixel coordinates; a vertex behind the near plane is an error.
//! 2. [`raster`]: watertight fixed-point rasterization at pixel centres (top-left fill rule),
//!    z-buffer, per-pixel triangle id ([`BACKGROUND`] where empty) and depth.
//! 3. Flat shading: RGB = raw unit face normal in \[−1, 1\], A = 1; background all 0.
//! 4. [`antialias`]: for neighbouring pixels that see different triangles, the silhouette edge of
//!    the front triangle that crosses the segment between the pixel centres blends the two colours
//!    with the analytic coverage weight; each blend is recorded as an [`AaItem`] for backward.
//! 5. [`loss`]: L1 / L2 image losses (mean over views × pixels × 4 channels) and their seeds.
//!
//! Backward: image gradient → face normals (through `n = normalize(cross)`) for every covered
//! pixel, and → blend weights → crossing parameter → edge endpoints' pixel coordinates → clip →
//! world positions for every antialiasing item. Per-view gradients are summed in view order, so
//! results are bit-identical for any thread count.
//!
//! Entry points: [`render`], [`backward`], [`image_loss`], [`render_loss_and_grad`] (the fused,
//! memory-light path the optimizer uses), [`face_pixel_counts`], [`to_rgba8`], [`star_cameras`].

pub mod antialias;
pub mod camera;
mod draw;
pub mod loss;
pub mod normals;
pub mod raster;
pub mod topology;

pub use antialias::AaItem;
pub use camera::{Camera, star_cameras};
pub use draw::{
    Image, Renders, ViewRender, backward, face_pixel_counts, render, render_loss_and_grad, to_rgba8,
};
pub use loss::{LossKind, image_loss};

/// Triangle id stored in pixels that no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// Options of the rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Skip triangles that face away from the camera. Off by default: the render loss of
    /// spec §3.2.1 (like Continuous Remeshing) renders both sides; the soup orientation
    /// clean-up of spec §3.1(a) step 3 turns it on.
    pub cull_backfaces: bool,
    /// Analytic antialiasing (spec §3.2.1 "Antialiasing"); the only source of silhouette and
    /// occlusion gradients. On by default.
    pub antialias: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            cull_backfaces: false,
            antialias: true,
        }
    }
}

/// Everything that can go wrong when rendering user input.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RenderError {
    /// A vertex lies on or behind the near plane of a camera (the rig expects meshes normalized
    /// into the sphere of radius 0.95; no clipping is done).
    #[error("vertex {vertex} lies behind the near plane of camera {camera}")]
    BehindNearPlane {
        /// Index of the offending vertex.
        vertex: usize,
        /// Index of the camera.
        camera: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// A triangle references a vertex that does not exist.
    #[error(
        "triangle {face} references vertex {vertex}, but there are only {num_vertices} vertices"
    )]
    IndexOutOfRange {
        /// Index of the triangle.
        face: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices given.
        num_vertices: usize,
    },
    /// A camera has a zero width or height.
    #[error("camera {camera} has an empty resolution {width}x{height}")]
    EmptyResolution {
        /// Index of the camera.
        camera: usize,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Buffers passed together do not match in count or size.
    #[error("shape mismatch: {what}")]
    ShapeMismatch {
        /// Which buffers disagree, and how.
        what: String,
    },
}
