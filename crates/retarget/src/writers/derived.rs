//! Quantities derived from `qpos`: world body poses (forward kinematics) and finite-difference
//! velocities, shared by the writers and the quality report.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use nalgebra::{UnitQuaternion, Vector3};

use crate::motion::RobotMotion;

/// World poses of every body but the world, per frame: `[frame * bodies + b]`, `b = 0` being
/// MuJoCo body 1.
#[derive(Debug, Clone)]
pub(crate) struct BodyPoses {
    pub bodies: usize,
    pub pos: Vec<Vector3<f64>>,
    pub quat: Vec<UnitQuaternion<f64>>,
}

// `frame × bodies` arrays filled by `body_poses`; callers index frames and bodies of the
// same motion and model, so an out-of-range index is a bug, not input.
#[allow(clippy::indexing_slicing)]
impl BodyPoses {
    pub fn pos(&self, frame: usize, body: usize) -> Vector3<f64> {
        self.pos[frame * self.bodies + body]
    }

    pub fn quat(&self, frame: usize, body: usize) -> UnitQuaternion<f64> {
        self.quat[frame * self.bodies + body]
    }
}

/// Forward kinematics of every frame (`motion` already checked against `model`).
pub(crate) fn body_poses(motion: &RobotMotion, model: &mjcf::Model) -> BodyPoses {
    let frames = motion.num_frames();
    let bodies = model.nbody().saturating_sub(1);
    let mut data = mjcf::Data::new(model);
    let mut pos = Vec::with_capacity(frames * bodies);
    let mut quat = Vec::with_capacity(frames * bodies);
    for t in 0..frames {
        // (The bodies' poses alone: no geom is read.)
        model.body_kinematics(motion.frame(t), &mut data);
        pos.extend_from_slice(data.xpos.get(1..).unwrap_or_default());
        quat.extend_from_slice(data.xquat.get(1..).unwrap_or_default());
    }
    BodyPoses { bodies, pos, quat }
}

/// The two frames a derivative at `t` differences, numpy `gradient`'s scheme: `(t-1, t+1)`
/// inside, `(0, 1)` and `(T-2, T-1)` at the ends; `None` for fewer than two frames.
pub(crate) fn gradient_pair(t: usize, frames: usize) -> Option<(usize, usize)> {
    if frames < 2 {
        None
    } else if t == 0 {
        Some((0, 1))
    } else if t + 1 == frames {
        Some((t - 1, t))
    } else {
        Some((t - 1, t + 1))
    }
}

/// Time derivative of a row-major `frames × cols` matrix (numpy `gradient` along axis 0,
/// spacing `dt`, first-order ends); zeros for a single frame.
pub(crate) fn gradient_rows(values: &[f64], cols: usize, dt: f64) -> Vec<f64> {
    let frames = values.len().checked_div(cols).unwrap_or(0);
    let mut out = vec![0.0; values.len()];
    for t in 0..frames {
        let Some((a, b)) = gradient_pair(t, frames) else { continue };
        let h = (b - a) as f64 * dt;
        let (Some(after), Some(before)) =
            (values.get(b * cols..(b + 1) * cols), values.get(a * cols..(a + 1) * cols))
        else {
            continue;
        };
        let row = out.iter_mut().skip(t * cols).take(cols);
        for ((o, x1), x0) in row.zip(after).zip(before) {
            *o = (x1 - x0) / h;
        }
    }
    out
}

/// World-frame angular velocity of `frames × per_frame` orientations with the scheme of
/// [`gradient_rows`]: `log(q[b] q[a]⁻¹) / ((b − a) dt)` (rotation vector of the shortest
/// rotation from frame `a` to frame `b`, expressed in the world).
pub(crate) fn angular_velocity(
    quats: &[UnitQuaternion<f64>],
    per_frame: usize,
    dt: f64,
) -> Vec<Vector3<f64>> {
    let frames = quats.len().checked_div(per_frame).unwrap_or(0);
    let mut out = vec![Vector3::zeros(); quats.len()];
    for t in 0..frames {
        let Some((a, b)) = gradient_pair(t, frames) else { continue };
        let h = (b - a) as f64 * dt;
        let (Some(after), Some(before)) = (
            quats.get(b * per_frame..(b + 1) * per_frame),
            quats.get(a * per_frame..(a + 1) * per_frame),
        ) else {
            continue;
        };
        let row = out.iter_mut().skip(t * per_frame).take(per_frame);
        for ((o, q1), q0) in row.zip(after).zip(before) {
            *o = (q1 * q0.inverse()).scaled_axis() / h;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_numpy_scheme() {
        // x = t² at dt = 0.5: numpy.gradient gives [1, 2, 4, 5] for x = [0, 0.25, 1, 2.25].
        let x = [0.0, 0.25, 1.0, 2.25];
        let v = gradient_rows(&x, 1, 0.5);
        assert_eq!(v, vec![0.5, 1.0, 2.0, 2.5]);
        assert_eq!(gradient_rows(&[3.0, 4.0], 2, 0.1), vec![0.0, 0.0]);
    }

    #[test]
    fn constant_rotation_rate_is_recovered_in_the_world_frame() {
        let dt = 0.02;
        let w = Vector3::new(0.3, -1.2, 2.0);
        let base = UnitQuaternion::from_euler_angles(0.4, -0.2, 1.0);
        let quats: Vec<_> =
            (0..5).map(|t| UnitQuaternion::from_scaled_axis(w * (t as f64 * dt)) * base).collect();
        for v in angular_velocity(&quats, 1, dt) {
            assert!((v - w).norm() < 1e-12, "{v}");
        }
    }
}
