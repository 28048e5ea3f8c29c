//! The optimizer state of one vertex ([`VertexState`]), which travels with the vertex.

use glam::DVec3;

/// The optimizer state of one vertex: m1, m2 and ν, which travel with the vertex through every
/// topology change.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VertexState {
    /// First moment: bias-corrected EMA of the gradient (3-vector).
    pub m1: DVec3,
    /// Second moment: bias-corrected EMA of ‖g‖², one scalar per vertex (rotation-equivariant).
    pub m2: f64,
    /// Speed ν = ‖u‖ of the last step (smoothed by β3); it scales the Laplacian term.
    pub nu: f64,
}

impl VertexState {
    /// `(1 − t)·a + t·b`, component-wise over the whole row.
    pub fn lerp(a: &Self, b: &Self, t: f64) -> Self {
        Self {
            m1: a.m1 * (1.0 - t) + b.m1 * t,
            m2: a.m2 * (1.0 - t) + b.m2 * t,
            nu: a.nu * (1.0 - t) + b.nu * t,
        }
    }

    /// The mean of three rows (the new vertex of a 1→3 face split).
    pub fn mean3(a: &Self, b: &Self, c: &Self) -> Self {
        let third = 1.0 / 3.0;
        Self {
            m1: (a.m1 + b.m1 + c.m1) * third,
            m2: (a.m2 + b.m2 + c.m2) * third,
            nu: (a.nu + b.nu + c.nu) * third,
        }
    }
}
