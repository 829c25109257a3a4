//! What the sampled poses say about a skeleton whose joints the hierarchy and the names have
//! read: left from right where the names do not say it, the up axis, the kind of rest pose,
//! the pose the body frames are taken in, and each role's frame offset there.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Indices here are joint ids of a skeleton `Plan::new` has checked (every caller, `recognise`
// and `human_motion`, builds the plan first: parents before children, ids < joint count), and
// positions of per-joint arrays sized from that skeleton.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;

use nalgebra::{UnitQuaternion, Vector3};

use crate::humanoid::{Reference, RestPose, RoleMap, UpAxis};
use crate::roles::Role;
use crate::structure::{BodyPlan, Tree};

/// One sampled frame: its index, positions and orientations of every joint.
pub(crate) type SampledFrame = (usize, Vec<Vector3<f64>>, Vec<UnitQuaternion<f64>>);

/// World poses of a few frames, in file axes and units: what the recogniser looks at.
#[derive(Debug, Clone, Default)]
pub(crate) struct Samples {
    /// The zero pose: positions (orientations are all identity).
    pub(crate) rest: Vec<Vector3<f64>>,
    /// `(frame index, positions, orientations)` of evenly spaced frames of the motion.
    pub(crate) frames: Vec<SampledFrame>,
}

/// Whether the first leg and the first arm of the plan are the left ones, from the poses:
/// the subject's left is up × forward, up runs from the pelvis to the head, forward is where
/// the toes point (else where the knees bend). Votes over the zero pose and the sampled
/// frames; `None` when no pose shows a facing.
pub(crate) fn geometric_sides(
    tree: &Tree,
    plan: &BodyPlan,
    samples: &Samples,
) -> Option<(bool, bool, String)> {
    let head =
        plan.head_chain.iter().rev().find(|&&j| !tree.end_site[j]).copied().unwrap_or(plan.chest);
    let poses = std::iter::once(&samples.rest).chain(samples.frames.iter().map(|(_, p, _)| p));
    let (mut legs, mut arms, mut by_toes, mut by_knees, mut total) = (0_i64, 0_i64, 0, 0, 0);
    for p in poses {
        total += 1;
        let up = p[head] - p[plan.pelvis];
        let flat =
            |v: Vector3<f64>| v - up * (up.dot(&v) / up.norm_squared().max(f64::MIN_POSITIVE));
        let toes: Vector3<f64> = plan
            .legs
            .iter()
            .filter_map(|l| Some(p[l.extremity_end?] - p[l.extremity.default]))
            .map(flat)
            .sum();
        let knees: Vector3<f64> = plan
            .legs
            .iter()
            .map(|l| {
                let (hip, knee, ankle) =
                    (p[l.proximal.default], p[l.distal.default], p[l.extremity.default]);
                flat(knee - (hip + ankle) / 2.0)
            })
            .sum();
        let scale = up.norm();
        let forward = if toes.norm() > 0.05 * scale {
            by_toes += 1;
            toes
        } else if knees.norm() > 0.02 * scale {
            by_knees += 1;
            knees
        } else {
            continue;
        };
        let left = up.cross(&forward);
        let vote = |x: f64| if x > 0.0 { 1 } else { -1 };
        legs +=
            vote(left.dot(&(p[plan.legs[0].proximal.default] - p[plan.legs[1].proximal.default])));
        arms +=
            vote(left.dot(&(p[plan.arms[0].proximal.default] - p[plan.arms[1].proximal.default])));
    }
    if by_toes + by_knees == 0 || legs == 0 || arms == 0 {
        return None;
    }
    let how = format!(
        "left = up × forward, forward from the toes in {by_toes} and the knees in {by_knees} \
         of {total} poses"
    );
    Some((legs > 0, arms > 0, how))
}

/// Joints the posture rules look at.
pub(crate) struct Key {
    pub(crate) pelvis: usize,
    pub(crate) head: usize,
    pub(crate) feet: [usize; 2],
    pub(crate) thighs: [usize; 2],
    pub(crate) shins: [usize; 2],
    pub(crate) upper_arms: [usize; 2],
    pub(crate) hands: [usize; 2],
}

/// Up: the signed file axis closest to feet → head, summed over the sampled frames (the
/// zero pose only when the clip has no frames).
pub(crate) fn up_axis(key: &Key, samples: &Samples) -> (UpAxis, String) {
    let poses: Vec<&Vec<Vector3<f64>>> = if samples.frames.is_empty() {
        vec![&samples.rest]
    } else {
        samples.frames.iter().map(|(_, p, _)| p).collect()
    };
    let direction = |p: &[Vector3<f64>]| {
        let v = p[key.head] - (p[key.feet[0]] + p[key.feet[1]]) / 2.0;
        v.try_normalize(0.0).unwrap_or_else(Vector3::zeros)
    };
    let sum: Vector3<f64> = poses.iter().map(|p| direction(p)).sum();
    let best = |v: &Vector3<f64>| {
        UpAxis::ALL.into_iter().max_by(|a, b| a.vector().dot(v).total_cmp(&b.vector().dot(v)))
    };
    let up = best(&sum).unwrap_or(UpAxis::PosY);
    let agree = poses.iter().filter(|p| best(&direction(p)) == Some(up)).count();
    let what =
        if samples.frames.is_empty() { "the zero pose (no frames)" } else { "sampled frames" };
    let reason =
        format!("the head is above the feet along {up} in {agree} of {} {what}", poses.len());
    (up, reason)
}

/// Degrees of arm elevation separating a T-pose, an A-pose and arms down.
const T_POSE_BELOW: f64 = 25.0;
const A_POSE_BELOW: f64 = 65.0;
/// Cosine between trunk (and legs) and the up axis for the zero pose to count as standing.
const UPRIGHT_COS: f64 = 0.8;

pub(crate) fn rest_pose(key: &Key, rest: &[Vector3<f64>], up: UpAxis) -> (RestPose, String) {
    let u = up.vector();
    let cos = |v: Vector3<f64>| v.try_normalize(0.0).map_or(0.0, |v| v.dot(&u));
    let trunk = cos(rest[key.head] - rest[key.pelvis]);
    let legs = [0, 1].map(|s| cos(rest[key.thighs[s]] - rest[key.feet[s]]));
    if trunk < UPRIGHT_COS || legs.iter().any(|&c| c < UPRIGHT_COS) {
        let axis = UpAxis::ALL
            .into_iter()
            .max_by(|a, b| {
                let v = rest[key.head] - rest[key.pelvis];
                a.vector().dot(&v).total_cmp(&b.vector().dot(&v))
            })
            .unwrap_or(up);
        let what = if trunk < UPRIGHT_COS {
            format!("pelvis → head points along {axis}, not {up}")
        } else {
            format!("the legs do not hang along {up}")
        };
        return (
            RestPose::NotUpright,
            format!("in the zero pose {what}: the zero pose is not used"),
        );
    }
    let elevation = [0, 1].map(|s| {
        cos(rest[key.hands[s]] - rest[key.upper_arms[s]]).clamp(-1.0, 1.0).asin().to_degrees()
    });
    let mean = (elevation[0] + elevation[1]) / 2.0;
    let kind = if mean > T_POSE_BELOW {
        RestPose::ArmsUp
    } else if mean >= -T_POSE_BELOW {
        RestPose::TPose
    } else if mean >= -A_POSE_BELOW {
        RestPose::APose
    } else {
        RestPose::ArmsDown
    };
    (kind, format!("standing in the zero pose, arms {mean:.0}° from horizontal"))
}

/// The pose to take body frames in: the zero pose if it stands upright, otherwise the sampled
/// frame that stands tallest and straightest (trunk along up, legs extended).
pub(crate) fn reference(
    key: &Key,
    samples: &Samples,
    up: UpAxis,
    rest: RestPose,
) -> (Reference, String) {
    if rest != RestPose::NotUpright || samples.frames.is_empty() {
        return (Reference::Rest, "the zero pose stands upright".to_owned());
    }
    let u = up.vector();
    let score = |p: &[Vector3<f64>]| {
        let trunk = (p[key.head] - p[key.pelvis]).try_normalize(0.0).map_or(-1.0, |v| v.dot(&u));
        let straight: f64 = (0..2)
            .map(|s| {
                let (h, k, a) = (p[key.thighs[s]], p[key.shins[s]], p[key.feet[s]]);
                (h - a).norm() / ((h - k).norm() + (k - a).norm()).max(f64::MIN_POSITIVE)
            })
            .sum::<f64>()
            / 2.0;
        trunk + straight
    };
    let best = samples
        .frames
        .iter()
        .max_by(|a, b| score(&a.1).total_cmp(&score(&b.1)))
        .map_or(0, |(i, _, _)| *i);
    (
        Reference::Frame(best),
        format!("the sampled frame standing tallest and straightest of {}", samples.frames.len()),
    )
}

/// `q_joint⁻¹ ⊗ R_canonical` per role in the reference pose.
pub(crate) fn frame_offsets(
    roles: &RoleMap,
    samples: &Samples,
    reference: Reference,
) -> BTreeMap<Role, UnitQuaternion<f64>> {
    let identity = vec![UnitQuaternion::identity(); samples.rest.len()];
    let (positions, orientations) = match reference {
        Reference::Rest => (&samples.rest, &identity),
        Reference::Frame(f) => match samples.frames.iter().find(|(i, _, _)| *i == f) {
            Some((_, p, q)) => (p, q),
            None => (&samples.rest, &identity),
        },
    };
    let points: BTreeMap<Role, Vector3<f64>> =
        roles.iter().map(|(r, j)| (r, positions[j.index])).collect();
    crate::frames::canonical_frames(&points)
        .into_iter()
        .filter_map(|(r, frame)| Some((r, orientations[roles.index(r)?].inverse() * frame)))
        .collect()
}
