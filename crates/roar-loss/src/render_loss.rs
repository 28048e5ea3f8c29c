//! The render loss `L_render` (spec §3.2.1): mean over views, pixels and RGBA channels of
//! `|I_src − I_tgt|` between flat-shaded normal maps of the source mesh and of the target.
//!
//! The source is rendered **without** back-face culling, so a fold of the source (a face seen
//! from behind) shows its reversed normal and is penalized; the target renders come from
//! [`Target`] (culling on, see `target`). Gradients come from the analytic antialiasing of
//! `roar_render::render_loss_and_grad`.

use glam::DVec3;
use roar_render::{Camera, Image, LossKind, RenderOptions, render_loss_and_grad};

use crate::target::Target;
use crate::{Loss, LossError};

/// The render loss against fixed target images, one per camera.
#[derive(Clone, Debug)]
pub struct RenderLoss {
    /// The rig (spec §3.2.1: the 6×6 star rig at 512²).
    pub cameras: Vec<Camera>,
    /// One target image per camera, same resolution.
    pub targets: Vec<Image>,
    /// How the source is rendered: culling off, antialiasing on (spec §3.2.1).
    pub options: RenderOptions,
    /// The per-channel penalty (spec §3.2.1: L1).
    pub kind: LossKind,
}

impl RenderLoss {
    /// The paper's render loss against a target: its cameras and renders, source culling off,
    /// antialiasing on, L1. Clones the renders (36 × 512² × 16 B ≈ 151 MB at the defaults);
    /// to avoid the copy, build the struct directly with `std::mem::take(&mut target.renders)`.
    pub fn new(target: &Target) -> Self {
        Self::from_renders(&target.cameras, &target.renders)
    }

    /// The paper's render loss against `renders`, one per camera of `cameras` (as a
    /// [`crate::Shape`] gives them): source culling off, antialiasing on, L1. Clones both.
    pub fn from_renders(cameras: &[Camera], renders: &[Image]) -> Self {
        Self {
            cameras: cameras.to_vec(),
            targets: renders.to_vec(),
            options: RenderOptions::default(),
            kind: LossKind::L1,
        }
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
        Ok(render_loss_and_grad(
            positions,
            triangles,
            &self.cameras,
            &self.targets,
            &self.options,
            self.kind,
        )?)
    }
}
