//! The rasterizer's options.

/// Options of the rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Skip triangles that face away from the camera. Off by default: the render loss
    /// (like Continuous Remeshing) renders both sides, so a fold shows its reversed normal; the
    /// soup orientation clean-up, which counts each twin's visible pixels, turns it on.
    pub cull_backfaces: bool,
    /// Analytic antialiasing; the only source of silhouette and
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
