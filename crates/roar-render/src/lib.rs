//! # roar-render
//!
//! The CPU differentiable rasterizer of roar, for the render loss
//! (`docs/method.md#render-loss`): the star camera rig, z-buffered rasterization of flat-shaded
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
mod error;
pub mod loss;
pub mod normals;
mod options;
pub mod raster;
mod renders;
pub mod topology;

pub use antialias::AaItem;
pub use camera::{Camera, star_cameras};
pub use draw::{backward, render, render_loss_and_grad};
pub use error::RenderError;
pub use loss::{LossKind, image_loss};
pub use options::RenderOptions;
pub use raster::BACKGROUND;
pub use renders::{Image, Renders, ViewRender, face_pixel_counts, to_rgba8};
