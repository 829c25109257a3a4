//! Shoulders that cannot turn the upper arm about its bone ([`Shoulder`]: one or two hinges,
//! as servo humanoids have), and the human arm frames turned to what such an arm can do
//! ([`arm_turns`]).
//!
//! A shoulder of two hinges points the upper arm anywhere, but the turn of the arm about its
//! bone then follows from the direction: the robot has no humeral rotation. The human's arm
//! frames carry it, and the derived targets asked for it: on the LAFAN1 walk the subject
//! holds the right forearm across the body, the humerus turned inwards, and the solve found
//! the turn by swinging the upper arm elsewhere (the 0.42 m servo robot of
//! `tests/data/robots/synthetic`: its right upper arm 41° off the human's, median over the
//! take, the left 9°; ROBOTIS OP3's right 22°, which also went over into the mirrored branch
//! of its unlimited shoulder ten times; `scripts/check-any`: hands L↔L 0.63 and 0.59).
//!
//! So, for such a robot, per sampled posture: the shoulder's hinge angles that point the
//! robot's upper arm as the human's, its trunk turned as the human's (damped Gauss–Newton on
//! the direction from starts spread over the ranges; of equally good solutions the one
//! nearest the human's frame), and the turn about the bone left between the robot's upper
//! arm frame and the human's. Each arm role's human frame is turned back by the mean of
//! that turn as seen from its own frame (the forearm's and the hand's: carried by the
//! human's elbow and wrist in that posture). The targets then ask for the upper arm's
//! direction and the elbow's bend, and for the turn the robot cannot make only as far as
//! it varies over the clip (the servo robot's right arm: 52° taken out; its right upper arm
//! 10° off the human's, the left 5°; the OP3's 14° and 11°; hands L↔L 0.82 and 0.80). A
//! robot with a three-hinge (or ball) shoulder is not touched.

use std::collections::BTreeMap;
use std::f64::consts::PI;

use fk::{Part, Role, Side};
use mjcf::{Data, JointType, Model};
use nalgebra::{Matrix2, Matrix3x2, Quaternion, Unit, UnitQuaternion, Vector3, Vector4};

use super::human::HumanBody;
use crate::robot_roles::RobotRoles;

/// Starts per hinge of the search for the shoulder angles (spread over the range).
const SEEDS: usize = 8;
/// Gauss–Newton steps from each start.
const STEPS: usize = 20;
/// A posture whose upper arm the shoulder cannot point within this (rad) says nothing about
/// the turn about the bone (the direction is what is missing there).
const POINTED: f64 = 0.26;
/// Solutions within this (rad) of the best direction are as good; the one with the least
/// turn left is taken (the branch the solve is drawn to).
const TIE: f64 = 1e-3;

/// A shoulder of one or two hinges (and no other joint) from the trunk body to the upper
/// arm's, seen at `qpos0`.
#[derive(Debug, Clone)]
pub(super) struct Shoulder {
    /// The role whose body the arm hangs from: the chest, else the pelvis.
    top: Role,
    /// Root first: each hinge's world axis at `qpos0` and how far it turns from there (rad;
    /// a half turn either way when unlimited).
    hinges: Vec<(Unit<Vector3<f64>>, [f64; 2])>,
}

/// The shoulder of the `side` arm when it cannot turn the upper arm about its bone (see the
/// module docs); `data` at `qpos0`.
pub(super) fn shoulder(
    model: &Model,
    data: &Data,
    roles: &RobotRoles,
    side: Side,
) -> Option<Shoulder> {
    let top = if roles.body(Role::Chest).is_some() { Role::Chest } else { Role::Pelvis };
    let (arm, top_body) = (roles.body(Role::of(Part::UpperArm, side))?, roles.body(top)?);
    let mut hinges = Vec::new();
    let mut b = arm;
    while b != top_body {
        let body = model.bodies.get(b)?;
        for j in (body.jnt_adr..body.jnt_adr + body.jnt_num).rev() {
            let joint = model.joints.get(j)?;
            if joint.kind != JointType::Hinge {
                return None;
            }
            let q0 = *model.qpos0.get(joint.qpos_adr)?;
            let travel = joint.range.map_or([-PI, PI], |[lo, hi]| [lo - q0, hi - q0]);
            hinges.push((Unit::new_normalize(*data.xaxis.get(j)?), travel));
        }
        if b == 0 {
            return None;
        }
        b = body.parent;
    }
    hinges.reverse();
    (1..3).contains(&hinges.len()).then_some(Shoulder { top, hinges })
}

impl Shoulder {
    /// The shoulder's rotation (world, at `qpos0`) for hinge travels `t`: the product of
    /// exponentials, root first.
    fn turn(&self, t: &[f64]) -> UnitQuaternion<f64> {
        self.hinges.iter().zip(t).fold(UnitQuaternion::identity(), |d, ((a, _), x)| {
            d * UnitQuaternion::from_axis_angle(a, *x)
        })
    }

    /// The hinge travels that turn the direction `from` nearest to `to` (world, at `qpos0`),
    /// each with its angle (rad) left between the two, from [`SEEDS`] starts per hinge,
    /// clamped to the ranges.
    fn pointing(&self, from: &Vector3<f64>, to: &Vector3<f64>) -> Vec<(Vec<f64>, f64)> {
        let n = self.hinges.len();
        let seed = |k: usize, i: usize| {
            let [lo, hi] = self.hinges.get(i).map_or([0.0, 0.0], |h| h.1);
            lo + (hi - lo) * (k as f64 + 0.5) / SEEDS as f64
        };
        let starts = (0..SEEDS.pow(n as u32)).map(|s| {
            (0..n).map(|i| seed(s / SEEDS.pow(i as u32) % SEEDS, i)).collect::<Vec<f64>>()
        });
        starts
            .map(|mut t| {
                for _ in 0..STEPS {
                    if !self.step(&mut t, from, to) {
                        break;
                    }
                }
                let angle = (self.turn(&t) * from).angle(to);
                (t, angle)
            })
            .collect()
    }

    /// One damped Gauss–Newton step of `|D(t) from − to|²`; false once it stops moving.
    fn step(&self, t: &mut [f64], from: &Vector3<f64>, to: &Vector3<f64>) -> bool {
        let v = self.turn(t) * from;
        let r = v - to;
        // d(D v)/dt_k = (D_<k a_k) × D v (product of exponentials); a missing second hinge
        // is a zero column, held by the damping.
        let mut columns = [Vector3::zeros(); 2];
        let mut before = UnitQuaternion::identity();
        for (c, ((a, _), x)) in columns.iter_mut().zip(self.hinges.iter().zip(t.iter())) {
            *c = (before * a.into_inner()).cross(&v);
            before *= UnitQuaternion::from_axis_angle(a, *x);
        }
        let j = Matrix3x2::from_columns(&columns);
        let Some(s) = (j.transpose() * j + Matrix2::identity() * 1e-9)
            .try_inverse()
            .map(|m| -(m * j.transpose() * r))
        else {
            return false;
        };
        for ((x, (_, [lo, hi])), dx) in t.iter_mut().zip(&self.hinges).zip(s.iter()) {
            *x = (*x + dx).clamp(*lo, *hi);
        }
        s.norm() > 1e-10
    }
}

/// The turn about the bone (rad, about the frame's z) from the robot's upper arm frame,
/// pointed as the human's by its shoulder, to the human's: `robot` are the robot's canonical
/// frames at `qpos0`, `human` one posture's; `None` when the shoulder cannot point the arm
/// there ([`POINTED`]).
fn turn_left(
    shoulder: &Shoulder,
    robot: &BTreeMap<Role, UnitQuaternion<f64>>,
    human: &BTreeMap<Role, UnitQuaternion<f64>>,
    arm: Role,
) -> Option<f64> {
    let (human_top, human_arm) = (human.get(&shoulder.top)?, human.get(&arm)?);
    let (robot_top, robot_arm) = (robot.get(&shoulder.top)?, robot.get(&arm)?);
    // The robot's trunk as the human's: world at qpos0 → the copy.
    let copy = human_top * robot_top.inverse();
    let from = robot_arm * Vector3::z();
    let to = copy.inverse() * (human_arm * Vector3::z());
    let solutions = shoulder.pointing(&from, &to);
    let best = solutions.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
    if best > POINTED {
        return None;
    }
    solutions
        .iter()
        .filter(|s| s.1 <= best + TIE)
        .map(|(t, _)| {
            let left = (copy * shoulder.turn(t) * robot_arm).inverse() * human_arm;
            crate::feet::wrap(2.0 * left.k.atan2(left.w))
        })
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
}

/// Per arm role (upper arm, forearm, hand) of the arms with these `shoulders`, the turn to
/// right-multiply the human's frames of that role with (see the module docs): the inverse
/// of the mean over `human`'s postures of the turn left, seen from the role's frame.
/// `robot` are the robot's canonical frames at `qpos0`.
pub(super) fn arm_turns(
    human: &HumanBody,
    shoulders: &BTreeMap<Side, Shoulder>,
    robot: &BTreeMap<Role, UnitQuaternion<f64>>,
) -> BTreeMap<Role, UnitQuaternion<f64>> {
    let mut out = BTreeMap::new();
    for (side, shoulder) in shoulders {
        let arm = Role::of(Part::UpperArm, *side);
        let roles = [Part::UpperArm, Part::Forearm, Part::Hand].map(|p| Role::of(p, *side));
        let mut sums: BTreeMap<Role, Vector4<f64>> = BTreeMap::new();
        for posture in &human.postures {
            let Some(psi) = turn_left(shoulder, robot, &posture.frames, arm) else { continue };
            let Some(upper) = posture.frames.get(&arm) else { continue };
            let twist = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), psi);
            for role in roles {
                let Some(frame) = posture.frames.get(&role) else { continue };
                // The human's frame of this role seen from its upper arm's.
                let carried = upper.inverse() * frame;
                let c = (carried.inverse() * twist * carried).into_inner().coords;
                *sums.entry(role).or_insert_with(Vector4::zeros) += if c.w < 0.0 { -c } else { c };
            }
        }
        for (role, sum) in sums {
            if let Some(mean) = UnitQuaternion::try_new(Quaternion::from(sum), 1e-9) {
                out.insert(role, mean.inverse());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shoulders of a robot file and its canonical frames at `qpos0`.
    fn shoulders_of(path: &str) -> (BTreeMap<Side, Shoulder>, BTreeMap<Role, UnitQuaternion<f64>>) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path);
        let model = Model::from_path(&path).unwrap();
        let roles = RobotRoles::recognise(&model).unwrap();
        let mut data = Data::new(&model);
        model.kinematics(&model.qpos0, &mut data);
        let shoulders = [Side::Left, Side::Right]
            .into_iter()
            .filter_map(|side| Some((side, shoulder(&model, &data, &roles, side)?)))
            .collect();
        (shoulders, roles.canonical_frames())
    }

    /// The servo robot's shoulders (pitch, then roll) are found, the G1's (three hinges) not.
    /// The canonical human stands with its right arm turned about the bone by 40° in one
    /// posture and 60° in another: the servo robot's right arm frames are turned back by the
    /// mean, 50°, the hanging left arm's not at all.
    #[test]
    fn the_turn_a_two_hinge_shoulder_cannot_make_is_taken_out_of_the_arm() {
        assert!(shoulders_of("robots/unitree_g1/unitree_g1.xml").0.is_empty());
        // Its arms end at the forearm: its canonical arm frames are the ones derive uses.
        let (shoulders, frames) = shoulders_of("tests/data/robots/synthetic/kid_servo.xml");
        assert_eq!(shoulders.len(), 2);
        assert!(shoulders.values().all(|s| s.hinges.len() == 2 && s.top == Role::Pelvis));
        let mut human = HumanBody::canonical();
        let standing = human.postures[0].clone();
        human.postures = [40f64, 60.0]
            .iter()
            .map(|deg| {
                let mut posture = standing.clone();
                let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg.to_radians());
                for part in [Part::UpperArm, Part::Forearm, Part::Hand] {
                    *posture.frames.get_mut(&Role::of(part, Side::Right)).unwrap() *= turn;
                }
                posture
            })
            .collect();
        let turns = arm_turns(&human, &shoulders, &frames);
        let back = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -50f64.to_radians());
        for part in [Part::UpperArm, Part::Forearm, Part::Hand] {
            let (left, right) =
                (turns[&Role::of(part, Side::Left)], turns[&Role::of(part, Side::Right)]);
            assert!(left.angle() < 1e-6, "{part:?}: {left:?}");
            assert!(right.angle_to(&back) < 1e-6, "{part:?}: {right:?}");
        }
        for (role, turn) in turns {
            human.turn(role, turn);
        }
        let arm = Role::RightUpperArm;
        assert!(human.frame_offsets[&arm].angle_to(&back) < 1e-6);
        // Each posture is left 10° from the canonical frame, one either way.
        for p in &human.postures {
            assert!((p.frames[&arm].angle() - 10f64.to_radians()).abs() < 1e-6);
        }
    }
}
