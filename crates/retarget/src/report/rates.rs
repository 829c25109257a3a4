//! Root acceleration and the jitter over every velocity coordinate (definitions in the
//! [`crate::report`] module documentation).

// Exception to `indexing_slicing`, as in `report`: the motion was checked against the model
// (`check_motion`), so every qpos address, frame and body index comes from them.
#![allow(clippy::indexing_slicing)]

use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;

use super::stats::{mean, ratio};
use crate::motion::RobotMotion;
use crate::writers::BodyPoses;

/// Standard gravity (m/s²), the unit of [`RootAcceleration::threshold_mps2`] and of the
/// dynamics check's m·g.
pub use crate::centroidal::GRAVITY;

/// Acceleration of one trajectory of points: `|a|` over the interior frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AccelStats {
    /// Interior frames measured (frames − 2).
    pub frames: usize,
    /// Mean `|a|` (m/s²).
    pub mean_mps2: f64,
    pub max_mps2: f64,
    /// Frames with `|a|` above [`RootAcceleration::threshold_mps2`].
    pub frames_over: usize,
    /// `frames_over / frames` (0 without frames).
    pub share_over: f64,
}

/// Acceleration of the root body (the floating base) and of its IK target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RootAcceleration {
    /// The body measured: the one the root target is for ([`RootAcceleration::target_body`],
    /// the scaled human's pelvis) when the model has it, else the root body (MuJoCo body 1).
    /// (Berkeley Humanoid Lite's pelvis target is for `imu_2`, 0.68 m above its base's
    /// origin, which stands at the floor and swings as the trunk tilts.)
    pub body: String,
    /// 2 g (m/s²).
    pub threshold_mps2: f64,
    /// The robot's [`RootAcceleration::body`], from its world position.
    pub motion: AccelStats,
    /// The scaled human's pelvis: the target position of [`RootAcceleration::target_body`],
    /// when the motion has targets.
    pub target: Option<AccelStats>,
    /// The body of that target ([`super::ReportOptions::root_target`]).
    pub target_body: Option<String>,
    /// The same accelerations averaged over the dynamics check's time
    /// ([`super::DynamicsCheckOptions::span`]), so that a 120 fps clip is judged on its motion,
    /// not on the finite-difference noise of one frame's 8 ms.
    pub averaged: AveragedAcceleration,
}

/// Root accelerations averaged over about [`super::DynamicsCheckOptions::span`]: at frame t,
/// `|p[t+2h] − 2 p[t] + p[t−2h]| · fps² / (2h)²`, `h` the dynamics check's half step
/// ([`super::half_step`]), over the frames `2h` away from the ends.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AveragedAcceleration {
    /// `h` (frames) and the time read, `4h / fps` (s).
    pub half_step_frames: usize,
    pub window_s: f64,
    pub motion: AccelStats,
    pub target: Option<AccelStats>,
}

/// Mean `|q̈|` over every velocity coordinate (MuJoCo's nv), by group.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Jitter {
    /// Velocity coordinates (nv).
    pub coordinates: usize,
    /// The free root's 3 translational coordinates (m/s², world frame); `None` without a
    /// free joint.
    pub root_translation: Option<f64>,
    /// The free root's 3 rotational coordinates (rad/s², body frame); `None` without a free
    /// joint.
    pub root_rotation: Option<f64>,
    /// Every other coordinate: hinge and slide joints, ball joints' 3 (rad/s² or m/s²); 0
    /// without any.
    pub joints: f64,
    /// Over all nv coordinates (units mixed as above).
    pub all: f64,
}

/// Root acceleration of the motion and of the target of `root_target` (the first target
/// when `None`), frame by frame and averaged over the half step `h` (frames).
pub(super) fn root_acceleration(
    motion: &RobotMotion,
    model: &mjcf::Model,
    poses: &BodyPoses,
    root_target: Option<&str>,
    h: usize,
) -> RootAcceleration {
    let frames = motion.num_frames();
    let target = motion.targets.as_ref().and_then(|targets| {
        let k = targets.body_names.len();
        let j = match root_target {
            Some(name) => targets.body_names.iter().position(|n| n == name)?,
            None if k > 0 => 0,
            None => return None,
        };
        let p: Vec<Vector3<f64>> = (0..frames).map(|t| targets.pos[t * k + j]).collect();
        Some((p, targets.body_names[j].clone()))
    });
    let (target, target_body) = target.unzip();
    // The body the target is for, else the root (body 1; `poses` leaves out the world).
    let id = target_body.as_deref().and_then(|name| model.body_id(name)).filter(|&b| b > 0);
    let id = id.unwrap_or(1);
    let robot: Vec<Vector3<f64>> = (0..frames).map(|t| poses.pos(t, id - 1)).collect();
    let body = model.bodies.get(id).map(|b| b.name.clone()).unwrap_or_default();
    let fps = motion.fps;
    RootAcceleration {
        body,
        threshold_mps2: 2.0 * GRAVITY,
        motion: accel_stats(&robot, fps, 1),
        target: target.as_ref().map(|p| accel_stats(p, fps, 1)),
        target_body,
        averaged: AveragedAcceleration {
            half_step_frames: h,
            window_s: (4 * h) as f64 / fps,
            motion: accel_stats(&robot, fps, 2 * h),
            target: target.as_ref().map(|p| accel_stats(p, fps, 2 * h)),
        },
    }
}

/// `|p[t+s] − 2 p[t] + p[t−s]| · fps² / s²` over the frames `s` away from the ends (`s = 1`:
/// the interior frames).
#[must_use]
pub(super) fn accel_stats(p: &[Vector3<f64>], fps: f64, s: usize) -> AccelStats {
    let rate = fps / s as f64;
    let a: Vec<f64> = (s..p.len().saturating_sub(s))
        .map(|t| (p[t + s] - 2.0 * p[t] + p[t - s]).norm() * rate * rate)
        .collect();
    let frames_over = a.iter().filter(|a| **a > 2.0 * GRAVITY).count();
    AccelStats {
        frames: a.len(),
        mean_mps2: mean(&a),
        max_mps2: a.iter().copied().fold(0.0, f64::max),
        frames_over,
        share_over: ratio(frames_over, a.len()),
    }
}

/// Which group a velocity coordinate belongs to.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Group {
    RootTranslation,
    RootRotation,
    Joint,
}

/// Velocity between two configurations as `mj_differentiatePos` computes it, with the group
/// of each coordinate: free joints' translation in the world frame, rotations (free and ball)
/// in the body frame as `log(q_a⁻¹ q_b)` (the shorter way round), scalars `(b − a)`, all
/// times `fps`.
fn differentiate(model: &mjcf::Model, a: &[f64], b: &[f64], fps: f64, out: &mut Vec<(Group, f64)>) {
    out.clear();
    let quat = |q: &[f64], at: usize| {
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[at],
            q[at + 1],
            q[at + 2],
            q[at + 3],
        ))
    };
    let rotation = |at: usize| (quat(a, at).inverse() * quat(b, at)).scaled_axis() * fps;
    for joint in &model.joints {
        let i = joint.qpos_adr;
        match joint.kind {
            mjcf::JointType::Free => {
                out.extend((0..3).map(|k| (Group::RootTranslation, (b[i + k] - a[i + k]) * fps)));
                out.extend(rotation(i + 3).iter().map(|w| (Group::RootRotation, *w)));
            }
            mjcf::JointType::Ball => out.extend(rotation(i).iter().map(|w| (Group::Joint, *w))),
            mjcf::JointType::Hinge | mjcf::JointType::Slide => {
                out.push((Group::Joint, (b[i] - a[i]) * fps));
            }
        }
    }
}

/// Jitter over every velocity coordinate: the velocities between consecutive frames
/// ([`differentiate`]), their differences times fps at the interior frames, mean `|·|`.
pub(super) fn jitter(motion: &RobotMotion, model: &mjcf::Model) -> Jitter {
    let frames = motion.num_frames();
    let fps = motion.fps;
    let (mut prev, mut next) = (Vec::new(), Vec::new());
    // Sum of |q̈| and count per group: root translation, root rotation, joints.
    let mut sums = [(0.0, 0usize); 3];
    let slot = |g: Group| match g {
        Group::RootTranslation => 0,
        Group::RootRotation => 1,
        Group::Joint => 2,
    };
    for t in 1..frames.saturating_sub(1) {
        if t == 1 {
            differentiate(model, motion.frame(0), motion.frame(1), fps, &mut prev);
        }
        differentiate(model, motion.frame(t), motion.frame(t + 1), fps, &mut next);
        for ((g, v0), (_, v1)) in prev.iter().zip(&next) {
            let s = &mut sums[slot(*g)];
            s.0 += ((v1 - v0) * fps).abs();
            s.1 += 1;
        }
        std::mem::swap(&mut prev, &mut next);
    }
    let group = |i: usize| {
        let (s, n): (f64, usize) = sums[i];
        (n > 0).then(|| s / n as f64)
    };
    let has_free = model.joints.iter().any(|j| j.kind == mjcf::JointType::Free);
    let (total, count) = sums.iter().fold((0.0, 0), |(s, n), (a, b)| (s + a, n + b));
    Jitter {
        coordinates: model.nv,
        root_translation: group(0).or(has_free.then_some(0.0)),
        root_rotation: group(1).or(has_free.then_some(0.0)),
        joints: group(2).unwrap_or(0.0),
        all: if count > 0 { total / count as f64 } else { 0.0 },
    }
}
