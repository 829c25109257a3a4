//! GMR's SMPL-X loader reproduced (`general_motion_retargeting/utils/smpl.py`, GMR 62ecdff):
//! `load_smplx_file` then `get_smplx_data_offline_fast`, for `--gmr` and the Python shim.
//!
//! - The pose GMR feeds smplx: `root_orient` and `pose_body` of the file, jaw, eyes and hands
//!   zero (the file's hand poses are not read), SMPL-X's `hands_mean` added
//!   (`flat_hand_mean=False`); smplx runs in float32, so the parameters are rounded to f32
//!   first (the rest is computed in f64).
//! - Resampling to `tgt_fps` when the source is faster: `frame_skip = int(src / tgt)`,
//!   `n = N // frame_skip` frames at `t = linspace(0, N − 1, n)`; joint positions linear
//!   between frames `floor(t)` and `floor(t) + 1`, every joint's *local* rotation slerped
//!   (GMR's `slerp`: the shorter way, a normalised lerp when the dot product is above 0.9995),
//!   then chained again into world orientations. The rate is `n / N · src`. A source at or
//!   below `tgt_fps` is not resampled and is labelled `tgt_fps`, as GMR labels it.
//! - The subject height `1.66 + 0.1 β₀` ([`crate::conventions::gmr_height`]).
//!
//! GMR's `smplx_to_robot.py` then retargets from frame 1 on (`i += 1` before the first use):
//! that is the retargeter's business (`retarget`'s `--gmr`), not the loader's.

use fk::HumanMotion;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::forward::{chain, check, continuous, full_pose};
use crate::model::BodyModel;
use crate::motion::SmplMotion;
use crate::Error;

/// GMR's human data of `motion` at `tgt_fps` (module docs): every joint's world pose per
/// resampled frame, named by the model's joints.
pub fn offline_fast(
    model: &BodyModel,
    motion: &SmplMotion,
    tgt_fps: f64,
) -> Result<HumanMotion, Error> {
    check(model, motion)?;
    let n_src = motion.num_frames();
    let joints = model.num_joints();
    let f32r = |v: f64| f64::from(v as f32);
    let betas: Vec<f64> = motion.betas.iter().map(|&b| f32r(b)).collect();
    let rest = model.rest_joints(&betas);
    // GMR's pose per source frame: root and body from the file, the rest zero; as float32.
    let body = 3 * 22;
    let mut raw = vec![0.0; 3 * joints];
    let mut pose = Vec::with_capacity(3 * joints);
    let mut locals: Vec<UnitQuaternion<f64>> = Vec::with_capacity(n_src * joints);
    let mut positions = Vec::with_capacity(n_src * joints);
    let mut world = Vec::with_capacity(n_src * joints);
    for f in 0..n_src {
        raw.iter_mut().for_each(|v| *v = 0.0);
        let src = motion.pose(f);
        raw.iter_mut().zip(src.iter().take(body)).for_each(|(d, s)| *d = *s);
        full_pose(model, &raw, &mut pose);
        let start = locals.len();
        locals
            .extend(pose.chunks_exact(3).map(|r| {
                UnitQuaternion::from_scaled_axis(Vector3::from_column_slice(r).map(f32r))
            }));
        let trans = motion.trans.get(f).map_or(Vector3::zeros(), |t| t.map(f32r));
        let frame = locals.get(start..).unwrap_or_default().iter().copied();
        chain(model.parents(), &rest, frame, trans, &mut positions, &mut world);
    }
    let src_fps = motion.fps;
    let (times, fps) = if tgt_fps < src_fps {
        let skip = (src_fps / tgt_fps).floor() as usize;
        let n = n_src / skip.max(1);
        if n == 0 {
            return Err(Error::Motion {
                path: motion.source.clone(),
                message: format!(
                    "{n_src} frames at {src_fps} fps: too short to resample to {tgt_fps} fps"
                ),
            });
        }
        (linspace((n_src - 1) as f64, n), n as f64 / n_src as f64 * src_fps)
    } else {
        ((0..n_src).map(|f| f as f64).collect(), tgt_fps)
    };
    let mut out_pos = Vec::with_capacity(times.len() * joints);
    let mut out_rot = Vec::with_capacity(times.len() * joints);
    for (k, &t) in times.iter().enumerate() {
        let i1 = (t.floor() as usize).min(n_src - 1);
        let i2 = (i1 + 1).min(n_src - 1);
        let alpha = t - i1 as f64;
        let at = |v: &[UnitQuaternion<f64>], f: usize, j: usize| {
            v.get(f * joints + j).copied().unwrap_or_default()
        };
        let slerped: Vec<UnitQuaternion<f64>> = (0..joints)
            .map(|j| gmr_slerp(&at(&locals, i1, j), &at(&locals, i2, j), alpha))
            .collect();
        for j in 0..joints {
            let p1 = positions.get(i1 * joints + j).copied().unwrap_or_default();
            let p2 = positions.get(i2 * joints + j).copied().unwrap_or_default();
            out_pos.push(p1 + (p2 - p1) * alpha);
        }
        // Positions come from the interpolation above; the chain gives the orientations.
        let (mut unused, mut rotations) = (Vec::new(), Vec::new());
        let slerped = slerped.into_iter();
        chain(model.parents(), &rest, slerped, Vector3::zeros(), &mut unused, &mut rotations);
        out_rot.extend(rotations);
        if k > 0 {
            continuous(&mut out_rot, k * joints, joints);
        }
    }
    let human = HumanMotion {
        fps,
        body_names: model.joint_names().iter().map(|s| (*s).to_owned()).collect(),
        num_frames: times.len(),
        positions: out_pos,
        orientations: out_rot,
    };
    human.validate()?;
    Ok(human)
}

/// numpy's `linspace(0, stop, n)`: `i · step`, the last one exactly `stop`.
fn linspace(stop: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![0.0];
    }
    let step = stop / (n - 1) as f64;
    let mut out: Vec<f64> = (0..n).map(|i| i as f64 * step).collect();
    if let Some(last) = out.last_mut() {
        *last = stop;
    }
    out
}

/// GMR's `slerp` (`utils/smpl.py`): the shorter way; a lerp, normalised, when the two are
/// within `acos(0.9995)`.
#[must_use]
pub fn gmr_slerp(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>, t: f64) -> UnitQuaternion<f64> {
    let q1 = a.into_inner();
    let mut q2 = b.into_inner();
    let mut dot = q1.coords.dot(&q2.coords);
    if dot < 0.0 {
        q2 = -q2;
        dot = -dot;
    }
    if dot > 0.9995 {
        return UnitQuaternion::new_normalize(q1 + (q2 - q1) * t);
    }
    let theta_0 = dot.acos();
    let theta = theta_0 * t;
    let (s0, s1) = (theta.cos() - dot * theta.sin() / theta_0.sin(), theta.sin() / theta_0.sin());
    UnitQuaternion::new_normalize(Quaternion::from(q1.coords * s0 + q2.coords * s1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linspace_is_numpys() {
        assert_eq!(linspace(10.0, 3), [0.0, 5.0, 10.0]);
        assert_eq!(linspace(7196.0, 1799).len(), 1799);
        assert_eq!(*linspace(7196.0, 1799).last().unwrap(), 7196.0);
        assert_eq!(linspace(5.0, 1), [0.0]);
    }

    #[test]
    fn slerp_takes_the_shorter_way_and_lerps_when_close() {
        let a = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        let b = UnitQuaternion::from_euler_angles(1.0, -0.5, 2.0);
        let nb = UnitQuaternion::new_unchecked(-b.into_inner());
        for t in [0.0, 0.25, 0.5, 1.0] {
            let ours = gmr_slerp(&a, &b, t);
            assert!(ours.angle_to(&a.slerp(&b, t)) < 1e-12, "{t}");
            assert!(gmr_slerp(&a, &nb, t).angle_to(&ours) < 1e-12);
        }
        let c = a * UnitQuaternion::from_euler_angles(1e-3, 0.0, 0.0);
        let mid = gmr_slerp(&a, &c, 0.5);
        let lerp =
            UnitQuaternion::new_normalize(a.into_inner() + (c.into_inner() - a.into_inner()) * 0.5);
        assert_eq!(mid, lerp);
    }
}
