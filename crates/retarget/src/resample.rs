//! Changing a robot motion's frame rate (`retarget --fps`).
//!
//! Output frame k sits at time k / fps_new; it interpolates the two source frames around
//! t · fps_old. Positions and hinge/slide angles are interpolated linearly, free-joint and
//! ball-joint quaternions (and target orientations) by slerp on the shorter arc. The last
//! output frame is the last one at or before the source's last frame, so nothing is
//! extrapolated.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use mjcf::Model;
use nalgebra::{Quaternion, UnitQuaternion};

use crate::motion::{FootContacts, RobotMotion, TrackedTargets};
use crate::Error;

/// `motion` at `fps` frames per second. Joint types come from `model` (the motion's robot).
pub fn resample(motion: &RobotMotion, model: &Model, fps: f64) -> Result<RobotMotion, Error> {
    if !(fps.is_finite() && fps > 0.0) {
        let name = "--fps".to_owned();
        return Err(Error::InvalidOption { name, value: fps, expected: "a positive rate" });
    }
    if motion.nq != model.nq {
        return Err(Error::Mismatch(format!("motion nq {} but model nq {}", motion.nq, model.nq)));
    }
    let frames = motion.num_frames();
    if frames == 0 {
        return Ok(RobotMotion { fps, ..motion.clone() });
    }
    let duration = (frames - 1) as f64 / motion.fps;
    // The small tolerance keeps a frame that lands on the last source frame up to rounding.
    let count = (duration * fps + 1e-9).floor() as usize + 1;
    let samples: Vec<(usize, f64)> = (0..count)
        .map(|k| {
            let u = (k as f64 / fps * motion.fps).min((frames - 1) as f64);
            let i = (u.floor() as usize).min(frames.saturating_sub(2));
            (i, if frames == 1 { 0.0 } else { u - i as f64 })
        })
        .collect();
    let mut qpos = Vec::with_capacity(count * motion.nq);
    for &(i, a) in &samples {
        let j = (i + 1).min(frames - 1);
        qpos.extend(blend_qpos(model, motion.frame(i), motion.frame(j), a));
    }
    let targets = motion.targets.as_ref().map(|t| resample_targets(t, &samples, frames));
    // A contact label is a state, not a quantity: take the nearer source frame's.
    let nearest = |v: &[bool]| -> Vec<bool> {
        samples
            .iter()
            .map(|&(i, a)| {
                v.get(if a < 0.5 { i } else { (i + 1).min(frames - 1) }).copied().unwrap_or(false)
            })
            .collect()
    };
    let contacts = motion.contacts.as_ref().map(|c| FootContacts {
        left: nearest(&c.left),
        right: nearest(&c.right),
        on_toes: c.on_toes.as_ref().map(|[l, r]| [nearest(l), nearest(r)]),
    });
    Ok(RobotMotion { fps, qpos, targets, contacts, ..motion.clone() })
}

/// Linear blend of two configurations with slerp for the quaternion joints.
fn blend_qpos(model: &Model, a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    let mut out: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect();
    for joint in &model.joints {
        let Some(quat_at) = joint.quat_adr() else { continue };
        let (Some(qa), Some(qb)) = (a.get(quat_at..quat_at + 4), b.get(quat_at..quat_at + 4))
        else {
            continue;
        };
        let q = slerp(quat(qa), quat(qb), t);
        if let Some(slot) = out.get_mut(quat_at..quat_at + 4) {
            slot.copy_from_slice(&[q.w, q.i, q.j, q.k]);
        }
    }
    out
}

fn quat(wxyz: &[f64]) -> UnitQuaternion<f64> {
    match wxyz {
        &[w, x, y, z] => UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
        _ => UnitQuaternion::identity(),
    }
}

/// Slerp on the shorter arc (q and −q are the same rotation).
fn slerp(a: UnitQuaternion<f64>, b: UnitQuaternion<f64>, t: f64) -> UnitQuaternion<f64> {
    let b = if a.coords.dot(&b.coords) < 0.0 {
        UnitQuaternion::new_unchecked(-b.into_inner())
    } else {
        b
    };
    a.try_slerp(&b, t, 1e-12).unwrap_or(if t < 0.5 { a } else { b })
}

fn resample_targets(t: &TrackedTargets, samples: &[(usize, f64)], frames: usize) -> TrackedTargets {
    let k = t.body_names.len();
    let mut pos = Vec::with_capacity(samples.len() * k);
    let mut quat = Vec::with_capacity(samples.len() * k);
    for &(i, a) in samples {
        let j = (i + 1).min(frames - 1);
        for b in 0..k {
            let (Some(&p0), Some(&p1), Some(&q0), Some(&q1)) = (
                t.pos.get(i * k + b),
                t.pos.get(j * k + b),
                t.quat.get(i * k + b),
                t.quat.get(j * k + b),
            ) else {
                continue;
            };
            pos.push(p0 + (p1 - p0) * a);
            quat.push(slerp(q0, q1, a));
        }
    }
    TrackedTargets { body_names: t.body_names.clone(), pos, quat }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> Model {
        let xml = r#"<mujoco><worldbody><body name="b"><freejoint/>
            <body name="c"><joint name="h" axis="0 0 1" range="-1 1"/></body></body></worldbody></mujoco>"#;
        Model::from_xml_str(xml, None).unwrap()
    }

    fn motion(frames: usize, fps: f64) -> RobotMotion {
        let mut qpos = Vec::new();
        for f in 0..frames {
            let angle = 0.1 * f as f64;
            let q = UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), angle);
            qpos.extend([f as f64, 0.0, 1.0, q.w, q.i, q.j, q.k, 0.01 * f as f64]);
        }
        RobotMotion {
            fps,
            nq: 8,
            qpos,
            joint_names: vec!["h".into()],
            body_names: vec!["b".into(), "c".into()],
            targets: None,
            contacts: None,
        }
    }

    #[test]
    fn halving_the_rate_keeps_every_other_frame_exactly() {
        let m = motion(11, 30.0);
        let r = resample(&m, &model(), 15.0).unwrap();
        assert_eq!(r.num_frames(), 6);
        for k in 0..6 {
            for (x, y) in r.frame(k).iter().zip(m.frame(2 * k)) {
                assert!((x - y).abs() < 1e-12, "frame {k}: {x} vs {y}");
            }
        }
    }

    #[test]
    fn doubling_the_rate_interpolates_midpoints_with_slerp() {
        let m = motion(3, 30.0);
        let r = resample(&m, &model(), 60.0).unwrap();
        assert_eq!(r.num_frames(), 5);
        let mid = r.frame(1);
        assert!((mid[0] - 0.5).abs() < 1e-12 && (mid[7] - 0.005).abs() < 1e-12);
        let q = quat(&mid[3..7]);
        let want = UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), 0.05);
        assert!(q.angle_to(&want) < 1e-12);
        assert!(((q.w * q.w + q.i * q.i + q.j * q.j + q.k * q.k) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_rates_and_mismatched_models_are_errors() {
        let m = motion(3, 30.0);
        let err = resample(&m, &model(), 0.0).unwrap_err();
        assert!(matches!(err, Error::InvalidOption { value: 0.0, .. }), "{err}");
        assert!(resample(&m, &model(), f64::NAN).is_err());
        let mut wrong = m.clone();
        wrong.nq = 7;
        let err = resample(&wrong, &model(), 30.0).unwrap_err();
        assert!(matches!(err, Error::Mismatch(_)), "{err}");
    }
}
