//! The rasterizer's options.

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
