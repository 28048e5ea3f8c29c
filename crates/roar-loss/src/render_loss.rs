//! The render loss `L_render` (`docs/method.md#render-loss`): mean over views, pixels and RGBA
//! channels of `|I_src − I_tgt|` between flat-shaded normal maps of the source mesh and of the
//! target.
//!
//! The source is rendered **without** back-face culling, so a fold of the source (a face seen
//! from behind) shows its reversed normal and is penalized; the target renders come from
//! [`Target`] (culling on, see `target`). Gradients come from the analytic antialiasing of
//! `roar_render::render_loss_and_grad`.

use glam::DVec3;
use roar_render::{Camera, Image, LossKind, RenderOptions, render_loss_and_grad};

use crate::error::LossError;
use crate::loss::Loss;
use crate::target::Target;

/// The render loss against fixed target images, one per camera.
#[derive(Clone, Debug)]
pub struct RenderLoss {
    /// The rig (the paper's is the 6×6 star rig at 512²).
    pub cameras: Vec<Camera>,
    /// One target image per camera, same resolution.
    pub targets: Vec<Image>,
    /// How the source is rendered: culling off, so folds show their reversed
    /// normal, and antialiasing on, for silhouette gradients.
    pub options: RenderOptions,
    /// The per-channel penalty (L1, as in Continuous Remeshing).
    pub kind: LossKind,
    /// A coarser rig for the loop's first iterations (none: `cameras` throughout).
    pub coarse: Option<CoarseViews>,
    /// The iteration the next evaluations belong to ([`Loss::set_iteration`]).
    iteration: usize,
}

/// The same views at a lower resolution, with their own target renders, used while the
/// iteration is below `until`. The loss is a mean over pixels, so its value and gradient keep
/// their scale at any resolution, while a view costs less than half at half the side
/// (`docs/method.md`). Values on either side of `until` are close but not equal, which matters
/// only where they are compared (the loop's checkpoints).
#[derive(Clone, Debug)]
pub struct CoarseViews {
    /// The coarse cameras, one per fine camera.
    pub cameras: Vec<Camera>,
    /// One target image per coarse camera.
    pub targets: Vec<Image>,
    /// The first iteration rendered with the fine cameras.
    pub until: usize,
}

impl RenderLoss {
    /// The paper's render loss against a target: its cameras and renders, source culling off,
    /// antialiasing on, L1. Clones the renders (36 × 512² × 16 B ≈ 151 MB on the paper's rig);
    /// to avoid the copy, build the struct directly with `std::mem::take(&mut target.renders)`.
    pub fn new(target: &Target) -> Self {
        Self::from_renders(&target.cameras, &target.renders)
    }

    /// The paper's render loss against `renders`, one per camera of `cameras` (as a
    /// the pipeline's `Shape` gives them): source culling off, antialiasing on, L1. Clones both.
    pub fn from_renders(cameras: &[Camera], renders: &[Image]) -> Self {
        Self {
            cameras: cameras.to_vec(),
            targets: renders.to_vec(),
            options: RenderOptions::default(),
            kind: LossKind::L1,
            coarse: None,
            iteration: 0,
        }
    }

    /// The same loss rendering `coarse` instead until iteration `coarse.until`.
    pub fn with_coarse(mut self, coarse: CoarseViews) -> Self {
        self.coarse = Some(coarse);
        self
    }
}

impl Loss for RenderLoss {
    fn name(&self) -> &'static str {
        "render"
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        let (cameras, targets) = match &self.coarse {
            Some(coarse) if self.iteration < coarse.until => (&coarse.cameras, &coarse.targets),
            _ => (&self.cameras, &self.targets),
        };
        Ok(render_loss_and_grad(
            positions,
            triangles,
            cameras,
            targets,
            &self.options,
            self.kind,
        )?)
    }

    fn set_iteration(&mut self, iteration: usize) {
        self.iteration = iteration;
    }
}
