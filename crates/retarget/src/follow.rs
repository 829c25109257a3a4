//! Why a limb cannot follow the human: stretches of a clip in which a robot limb stays far
//! from its targets while joints of that limb sit at their range limits. The robot's joint
//! ranges keep the limb in a branch that does not reach the human's pose (the G1's hip pitch
//! stops at −90°: it cannot sit as deep as a person on a chair), which no weight or offset
//! changes. The main command prints each stretch, `retarget report` too.
//!
//! A frame of a limb (hip to foot, shoulder to hand) is **blocked** when
//! - one of the limb's range-limited joints is within 1 % of its range (at least 0.5°) of a
//!   bound, and
//! - a tracked body of the limb (its knee / elbow and foot / hand bodies with a target) is
//!   farther from its target than the limb usually is (the median over the frames with no
//!   joint at a bound) by more than 6 % of the robot's height;
//!
//! blocked frames at most 0.2 s apart form a stretch, and stretches of at least 1 s are
//! reported (shorter ones are kicks and turns the solve catches up with), with the joints at a bound in at least half of their frames.
//!
//! An arm hangs from the chest: when the chest body itself is more than 45° off its own
//! target on average over the stretch, that is said instead of blaming the arm's ranges (the
//! MocapBank take under `--gmr` onto the G1: GMR's first frame, from `qpos0` turned 96° from
//! the subject, left the waist yawed, the torso 85° off, the left arm's joints at their limits).

// Indexing: body and joint ids come from the model the motion was solved on (the motion's
// names are checked against it first), frames below `num_frames`.
#![allow(clippy::indexing_slicing)]

use std::fmt;

use fk::{Part, Role, Side};
use mjcf::{Data, JointType, Model};

use crate::robot_roles::RobotRoles;
use crate::RobotMotion;

/// A joint bound counts as reached within this share of the range ...
const AT_BOUND_SHARE: f64 = 0.01;
/// ... and at least this much (rad).
const AT_BOUND_MIN: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// A limb body is off its target by this share of the robot's height more than usual.
const OFF_TARGET: f64 = 0.06;
/// Blocked frames at most this far apart (s) belong to one stretch ...
const GAP: f64 = 0.2;
/// ... and a stretch is reported from this long on (s).
const MIN_STRETCH: f64 = 1.0;
/// A joint is named when it is at a bound in at least this share of the stretch's frames.
const NAMED_SHARE: f64 = 0.5;
/// An arm's chest this far off its own orientation target (rad, mean over the stretch) holds
/// the arm away from the human's pose whatever the arm's ranges.
const TRUNK_OFF: f64 = 45.0 * std::f64::consts::PI / 180.0;

/// One joint held at a bound through a stretch.
#[derive(Debug, Clone, PartialEq)]
pub struct PinnedJoint {
    pub name: String,
    /// The bound (rad, or m for a slide).
    pub bound: f64,
    /// Whether it is the lower bound.
    pub lower: bool,
    /// Share of the stretch's frames at that bound.
    pub share: f64,
}

/// A stretch of frames in which a limb cannot follow (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Blocked {
    /// `left leg`, `right arm`, ...
    pub limb: String,
    /// First and last frame (inclusive).
    pub first: usize,
    pub last: usize,
    pub fps: f64,
    pub joints: Vec<PinnedJoint>,
    /// Mean over the stretch of the limb's largest distance to a target (m).
    pub error: f64,
    /// The body an arm hangs from (the chest) and its mean rotation error over the stretch
    /// (rad), when that is more than 45°: the trunk, not the arm's ranges, is off.
    pub trunk_off: Option<(String, f64)>,
}

impl fmt::Display for Blocked {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let joints: Vec<String> = self
            .joints
            .iter()
            .map(|j| {
                format!(
                    "{} at its {} limit ({:.0}°, {:.0} % of the frames)",
                    j.name,
                    if j.lower { "lower" } else { "upper" },
                    j.bound.to_degrees(),
                    100.0 * j.share
                )
            })
            .collect();
        let why = match &self.trunk_off {
            Some((body, angle)) => format!(
                "{body}, which it hangs from, is {:.0}° off its own target: the trunk keeps the \
                 limb from the human's pose",
                angle.to_degrees()
            ),
            None => "the joint ranges keep the limb from the human's pose".to_owned(),
        };
        write!(
            f,
            "the {} cannot follow the human in frames {}-{} ({:.1} s): {}; its targets stay \
             {:.0} cm away on average ({why})",
            self.limb,
            self.first,
            self.last,
            (self.last + 1 - self.first) as f64 / self.fps.max(1e-9),
            joints.join(", "),
            100.0 * self.error
        )
    }
}

/// One frame of a limb: its joints at a bound (joint id, whether the lower one), its largest
/// distance to a target, and the rotation error of the chest an arm hangs from (rad).
type FrameState = (Vec<(usize, bool)>, f64, Option<f64>);

/// A limb: its name, the bodies of its chain, the bodies whose targets say where it is, and
/// for an arm the chest body it hangs from.
struct LimbSpec {
    name: String,
    joints: Vec<usize>,
    tracked: Vec<usize>,
    trunk: Option<usize>,
}

fn limbs(model: &Model, roles: &RobotRoles) -> Vec<LimbSpec> {
    let chain = |top: usize, end: usize| -> Vec<usize> {
        let mut out = Vec::new();
        let mut b = end;
        while b != top && b != 0 {
            out.push(b);
            b = model.bodies[b].parent;
        }
        out
    };
    let mut out = Vec::new();
    for side in [Side::Left, Side::Right] {
        let word = if side == Side::Left { "left" } else { "right" };
        for (limb, top, parts) in [
            ("leg", Role::Pelvis, [Part::Thigh, Part::Shin, Part::Foot]),
            ("arm", Role::Chest, [Part::UpperArm, Part::Forearm, Part::Hand]),
        ] {
            let chest = roles.body(top).filter(|_| top == Role::Chest);
            let chest = chest.filter(|&c| Some(c) != roles.body(Role::Pelvis));
            let top = roles.body(top).or_else(|| roles.body(Role::Pelvis)).unwrap_or(0);
            let ends: Vec<usize> =
                parts.iter().filter_map(|&p| roles.body(Role::of(p, side))).collect();
            let Some(&end) = ends.last() else { continue };
            let bodies = chain(top, end);
            let joints = bodies
                .iter()
                .flat_map(|&b| {
                    let body = &model.bodies[b];
                    body.jnt_adr..body.jnt_adr + body.jnt_num
                })
                .filter(|&j| {
                    model.joints[j].range.is_some() && model.joints[j].kind != JointType::Ball
                })
                .collect();
            out.push(LimbSpec {
                name: format!("{word} {limb}"),
                joints,
                tracked: ends[1..].to_vec(),
                trunk: chest,
            });
        }
    }
    out
}

/// A body and its slot among the motion's targets (none: it has no target).
type BodySlot = (usize, Option<usize>);

/// The stretches of `motion` (solved on `model`, recognised as `roles`) in which a limb
/// cannot follow; empty without tracked targets or when the motion's joints are not the
/// model's.
#[must_use]
pub fn blocked_limbs(model: &Model, roles: &RobotRoles, motion: &RobotMotion) -> Vec<Blocked> {
    let Some(targets) = &motion.targets else { return Vec::new() };
    if motion.nq != model.nq || motion.joint_names != RobotMotion::model_joint_names(model) {
        return Vec::new();
    }
    let frames = motion.num_frames();
    let k_of = |b: usize| targets.body_names.iter().position(|n| *n == model.bodies[b].name);
    let specs = limbs(model, roles);
    // Each limb's tracked bodies and trunk as slots of the targets, looked up once.
    let slots: Vec<(Vec<BodySlot>, Option<BodySlot>)> = specs
        .iter()
        .map(|s| (s.tracked.iter().map(|&b| (b, k_of(b))).collect(), s.trunk.map(|b| (b, k_of(b)))))
        .collect();
    let mut data = Data::new(model);
    // Per limb, per frame: the joints at a bound (and which bound) and the limb's error.
    let mut per_limb: Vec<Vec<FrameState>> = vec![Vec::new(); specs.len()];
    for t in 0..frames {
        let q = motion.frame(t);
        // (The bodies' poses alone: no geom is read.)
        model.body_kinematics(q, &mut data);
        for ((spec, (tracked, trunk)), out) in specs.iter().zip(&slots).zip(&mut per_limb) {
            let pinned: Vec<(usize, bool)> = spec
                .joints
                .iter()
                .filter_map(|&j| {
                    let joint = &model.joints[j];
                    let [lo, hi] = joint.range?;
                    let tol = (AT_BOUND_SHARE * (hi - lo)).max(AT_BOUND_MIN);
                    let v = q[joint.qpos_adr];
                    if v - lo <= tol {
                        Some((j, true))
                    } else if hi - v <= tol {
                        Some((j, false))
                    } else {
                        None
                    }
                })
                .collect();
            let error = tracked
                .iter()
                .filter_map(|&(b, k)| {
                    let target = targets.pos.get(t * targets.body_names.len() + k?)?;
                    Some((data.xpos[b] - target).norm())
                })
                .fold(0.0, f64::max);
            let trunk = trunk.and_then(|(b, k)| {
                let target = targets.quat.get(t * targets.body_names.len() + k?)?;
                Some(data.xquat[b].angle_to(target))
            });
            out.push((pinned, error, trunk));
        }
    }
    let mut blocked = Vec::new();
    for (spec, series) in specs.iter().zip(&per_limb) {
        // The limb's usual distance to its targets (scaled human targets are rarely met
        // exactly): the median over the frames with no joint at a bound.
        let mut free: Vec<f64> =
            series.iter().filter(|(p, _, _)| p.is_empty()).map(|(_, e, _)| *e).collect();
        if free.is_empty() {
            free = series.iter().map(|(_, e, _)| *e).collect();
        }
        free.sort_by(f64::total_cmp);
        let usual = free.get(free.len() / 2).copied().unwrap_or(0.0);
        let is_blocked: Vec<bool> = series
            .iter()
            .map(|(pinned, error, _)| {
                !pinned.is_empty() && *error > usual + OFF_TARGET * roles.height
            })
            .collect();
        for (first, last) in stretches(&is_blocked, motion.fps) {
            blocked.push(describe(model, spec, &series[first..=last], first, last, motion.fps));
        }
    }
    blocked.sort_by_key(|b| b.first);
    blocked
}

/// Runs of `true`, joined across gaps up to [`GAP`], at least [`MIN_STRETCH`] long.
fn stretches(flags: &[bool], fps: f64) -> Vec<(usize, usize)> {
    let gap = (GAP * fps).round() as usize;
    let min = (MIN_STRETCH * fps).round().max(1.0) as usize;
    let mut out: Vec<(usize, usize)> = Vec::new();
    for (t, _) in flags.iter().enumerate().filter(|(_, &f)| f) {
        match out.last_mut() {
            Some((_, last)) if t - *last <= gap + 1 => *last = t,
            _ => out.push((t, t)),
        }
    }
    out.retain(|(a, b)| b + 1 - a >= min);
    out
}

fn describe(
    model: &Model,
    spec: &LimbSpec,
    series: &[FrameState],
    first: usize,
    last: usize,
    fps: f64,
) -> Blocked {
    let n = series.len().max(1) as f64;
    let mut joints: Vec<PinnedJoint> = Vec::new();
    for &j in &spec.joints {
        for lower in [true, false] {
            let count = series.iter().filter(|(p, _, _)| p.contains(&(j, lower))).count();
            let share = count as f64 / n;
            if share >= NAMED_SHARE {
                let joint = &model.joints[j];
                let [lo, hi] = joint.range.unwrap_or([0.0, 0.0]);
                joints.push(PinnedJoint {
                    name: joint.name.clone(),
                    bound: if lower { lo } else { hi },
                    lower,
                    share,
                });
            }
        }
    }
    if joints.is_empty() {
        // No single joint holds the whole stretch: name the one at a bound most often.
        let best = spec
            .joints
            .iter()
            .flat_map(|&j| [(j, true), (j, false)])
            .max_by_key(|key| series.iter().filter(|(p, _, _)| p.contains(key)).count());
        if let Some((j, lower)) = best {
            let joint = &model.joints[j];
            let [lo, hi] = joint.range.unwrap_or([0.0, 0.0]);
            let share =
                series.iter().filter(|(p, _, _)| p.contains(&(j, lower))).count() as f64 / n;
            joints.push(PinnedJoint {
                name: joint.name.clone(),
                bound: if lower { lo } else { hi },
                lower,
                share,
            });
        }
    }
    let error = series.iter().map(|(_, e, _)| e).sum::<f64>() / n;
    let trunk: Vec<f64> = series.iter().filter_map(|(_, _, a)| *a).collect();
    let trunk_mean = trunk.iter().sum::<f64>() / trunk.len().max(1) as f64;
    let trunk_off = spec
        .trunk
        .filter(|_| trunk_mean > TRUNK_OFF)
        .map(|b| (model.bodies[b].name.clone(), trunk_mean));
    Blocked { limb: spec.name.clone(), first, last, fps, joints, error, trunk_off }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretches_join_short_gaps_and_drop_short_runs() {
        let mut flags = vec![false; 100];
        flags[10..30].iter_mut().for_each(|f| *f = true);
        flags[33..50].iter_mut().for_each(|f| *f = true); // 3 frames apart at 30 fps: joined
        flags[70..75].iter_mut().for_each(|f| *f = true); // 5 frames: too short
        assert_eq!(stretches(&flags, 30.0), [(10, 49)]);
    }
}
