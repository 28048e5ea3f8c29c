//! What rendering produces: the [`Image`] type, one [`ViewRender`] per view, the [`Renders`] of
//! all views, and the helpers that read them ([`face_pixel_counts`], [`to_rgba8`]).

use crate::antialias::AaItem;
use crate::raster::BACKGROUND;

/// An RGBA image, row-major, row 0 at the top; RGB is a raw normal in \[−1, 1\], A coverage.
pub type Image = Vec<[f32; 4]>;

/// Everything one view's forward pass produced.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewRender {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Visible triangle per pixel ([`BACKGROUND`] where empty).
    pub ids: Vec<u32>,
    /// NDC depth `z/w` per pixel (`+∞` where empty).
    pub depth: Vec<f32>,
    /// Antialiased colour: raw face normal and coverage; background 0.
    pub rgba: Image,
    /// Antialiasing blends, sorted by target pixel (empty when antialiasing is off).
    pub aa: Vec<AaItem>,
}

/// The forward pass over all cameras.
#[derive(Clone, Debug, PartialEq)]
pub struct Renders {
    /// One render per camera, in camera order.
    pub views: Vec<ViewRender>,
    /// Number of triangles rendered (length of [`face_pixel_counts`]).
    pub num_faces: usize,
}

/// Number of pixels, over all views, in which each face is the visible triangle (before
/// antialiasing). Used by the soup orientation clean-up, which keeps the twin of a face that
/// collects more pixels, with culling on.
pub fn face_pixel_counts(renders: &Renders) -> Vec<u32> {
    let mut counts = vec![0u32; renders.num_faces];
    for view in &renders.views {
        for &id in &view.ids {
            if id != BACKGROUND {
                counts[id as usize] += 1;
            }
        }
    }
    counts
}

/// Maps a rendered image to 8-bit RGBA for dumps: RGB = `(n + 1)/2`, A = coverage, both
/// clamped to \[0, 1\]. Background pixels (A = 0) map to transparent black.
pub fn to_rgba8(image: &[[f32; 4]]) -> Vec<u8> {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let mut out = Vec::with_capacity(image.len() * 4);
    for px in image {
        if px[3] == 0.0 {
            out.extend_from_slice(&[0, 0, 0, 0]);
        } else {
            for c in 0..3 {
                out.push(q((px[c] + 1.0) * 0.5));
            }
            out.push(q(px[3]));
        }
    }
    out
}
