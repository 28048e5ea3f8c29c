//! Image losses of the render loss: the mean over views × pixels × 4 channels of `|I − T|` (L1, the
//! paper's) or `(I − T)²` (L2), and their gradients with respect to the rendered image.

use crate::error::RenderError;
use crate::renders::{Image, Renders};

/// Gradient of a loss with respect to the rendered images: per view, per pixel, RGBA.
pub type ImageGrad = Vec<Vec<[f64; 4]>>;

/// Which per-channel penalty the image loss uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LossKind {
    /// `|I − T|`, subgradient `sign(I − T)` with `sign(0) = 0` (as in Continuous Remeshing).
    /// The default.
    #[default]
    L1,
    /// `(I − T)²`, gradient `2 (I − T)`.
    L2,
}

/// Penalty of one channel difference `d = I − T` and its derivative with respect to `I`
/// (before the mean's `1/N`).
pub fn loss_term(kind: LossKind, d: f64) -> (f64, f64) {
    match kind {
        LossKind::L1 => {
            // sign(d) with sign(0) = +0 (and NaN), as a select of constants: no integer round
            // trip in this per-channel hot path.
            let s = if d > 0.0 {
                1.0
            } else if d < 0.0 {
                -1.0
            } else {
                0.0
            };
            (d.abs(), s)
        }
        LossKind::L2 => (d * d, 2.0 * d),
    }
}

/// Mean image loss of `renders` against `targets` (one image per view, same sizes) and its
/// gradient `dL/dI` per view and pixel (RGBA).
pub fn image_loss(
    renders: &Renders,
    targets: &[Image],
    kind: LossKind,
) -> Result<(f64, ImageGrad), RenderError> {
    if renders.views.len() != targets.len() {
        return Err(RenderError::ShapeMismatch {
            what: format!(
                "{} renders but {} targets",
                renders.views.len(),
                targets.len()
            ),
        });
    }
    let total: usize = renders.views.iter().map(|v| v.rgba.len() * 4).sum();
    let inv_n = if total > 0 { 1.0 / total as f64 } else { 0.0 };
    let mut loss = 0.0;
    let mut grads = Vec::with_capacity(targets.len());
    for (i, (view, target)) in renders.views.iter().zip(targets).enumerate() {
        if view.rgba.len() != target.len() {
            return Err(RenderError::ShapeMismatch {
                what: format!(
                    "view {i}: {} pixels vs target {}",
                    view.rgba.len(),
                    target.len()
                ),
            });
        }
        let mut g = Vec::with_capacity(target.len());
        for (px, tx) in view.rgba.iter().zip(target) {
            let mut gp = [0.0; 4];
            for c in 0..4 {
                let (v, d) = loss_term(kind, px[c] as f64 - tx[c] as f64);
                loss += v;
                gp[c] = d * inv_n;
            }
            g.push(gp);
        }
        grads.push(g);
    }
    Ok((loss * inv_n, grads))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loss_seed_finite_difference() {
        let h = 1e-6;
        for kind in [LossKind::L1, LossKind::L2] {
            for d in [-0.7, -0.01, 0.02, 0.9] {
                let (_, g) = loss_term(kind, d);
                let fd = (loss_term(kind, d + h).0 - loss_term(kind, d - h).0) / (2.0 * h);
                assert!((fd - g).abs() < 1e-6, "{kind:?} at {d}: {fd} vs {g}");
            }
        }
        assert_eq!(loss_term(LossKind::L1, 0.0), (0.0, 0.0));
        // The L1 slope is exactly ±1, and +0 at zero (either sign) and NaN.
        assert_eq!(
            loss_term(LossKind::L1, -3e-300).1.to_bits(),
            (-1.0f64).to_bits()
        );
        assert_eq!(
            loss_term(LossKind::L1, 5e-324).1.to_bits(),
            1.0f64.to_bits()
        );
        for d in [0.0, -0.0, f64::NAN] {
            assert_eq!(
                loss_term(LossKind::L1, d).1.to_bits(),
                0.0f64.to_bits(),
                "{d}"
            );
        }
    }
}
