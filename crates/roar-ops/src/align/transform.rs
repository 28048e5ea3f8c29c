//! A rigid transform ([`RigidTransform`]): the pose of a scan.

use glam::{DQuat, DVec3};

/// A rigid transform `x ↦ R x + t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTransform {
    /// The rotation R (unit quaternion).
    pub rotation: DQuat,
    /// The translation t.
    pub translation: DVec3,
}

impl RigidTransform {
    /// The identity.
    pub const IDENTITY: RigidTransform = RigidTransform {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// `R p + t`.
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// The angle of `other · self⁻¹` in degrees and the distance between the two translations
    /// measured at `at` (where the transforms place the point `at` of the scan's frame).
    pub fn difference(&self, other: &RigidTransform, at: DVec3) -> (f64, f64) {
        let relative = other.rotation * self.rotation.inverse();
        let angle = relative
            .normalize()
            .angle_between(DQuat::IDENTITY)
            .to_degrees();
        (angle, self.apply(at).distance(other.apply(at)))
    }
}
