//! The small angle and blend helpers of the foot plan.

use nalgebra::{Quaternion, UnitQuaternion};

use crate::lie::Pose;

/// `3w² − 2w³`: from 0 to 1 over `w` in [0, 1], flat at both ends.
pub(super) fn smoothstep(w: f64) -> f64 {
    w * w * (3.0 - 2.0 * w)
}

/// `a` (rad) wrapped into [−π, π).
pub(crate) fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

pub(super) fn quat(p: &Pose) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(p.quat[0], p.quat[1], p.quat[2], p.quat[3]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothstep_ends_flat() {
        assert_eq!(smoothstep(0.0), 0.0);
        assert_eq!(smoothstep(1.0), 1.0);
        assert!((smoothstep(0.5) - 0.5).abs() < 1e-15);
        let slope = |w: f64| (smoothstep(w + 1e-6) - smoothstep(w - 1e-6)) / 2e-6;
        assert!(slope(1e-6).abs() < 1e-5 && slope(1.0 - 1e-6).abs() < 1e-5);
    }
}
