//! IK configs derived from the two role sets, the robot's ([`RobotRoles`]) and a human's
//! ([`HumanBody`]: a recognised skeleton, or the canonical human), in GMR's schema so that
//! the solver and `--gmr` use them unchanged.
//!
//! Per role the robot has (pelvis, chest, and per side thigh, shin, foot, upper arm, forearm,
//! hand; the head is not tracked, as in GMR's configs):
//!
//! - **Body ↔ joint**: the role's robot body tracks the role's human joint.
//! - **Weights**: GMR's tuned G1 config (`configs/bvh_lafan1_to_unitree_g1.json`), per part,
//!   except the feet's position weight and the upper arm's rotation weight in table 2,
//!   which are those of GMR's configs for the T1, N1, PM01 and ToddlerBot (the G1's and the
//!   H1's have 50 on the feet and 100 on the upper arms' rotation in both tables):
//!
//!   | part | table 1 pos | table 1 rot | table 2 pos | table 2 rot |
//!   |---|---|---|---|---|
//!   | pelvis | 0 | 10 | 100 | 5 |
//!   | thigh, shin | 0 | 10 | 10 | 5 |
//!   | foot | 100 | 10 | 100 | 10 |
//!   | chest | 0 | 100 | 0 | 10 |
//!   | upper arm | 0 | 100 | 5 | 10 |
//!   | forearm, hand | 0 | 10 | 10 | 5 |
//!
//!   With 100 on the upper arms' rotation in table 2, the stage that also tracks positions
//!   (measured with `scripts/compare-configs`), arms that cannot take the human's
//!   orientation pull the whole robot on the jumps: in GMR's solve the G1's hands were
//!   86 mm from their targets against 69 mm with 10, the PM01's feet 14 mm against 3 mm,
//!   and the default solve of the PM01 turned its left hip over into a branch at its limits
//!   for the last half of the take. Table 1 (orientations only) keeps the G1's 100: with 10
//!   there too, the T1 no longer faces the way the human's pelvis does on a take that
//!   kneels and bends over (`scripts/check-any`, MocapBank).
//!
//! - **Rotation offset** `q_off = F_h ⊗ C_r⁻¹ ⊗ q_body`: `F_h = q_joint⁻¹ ⊗ C_h` is the
//!   human's frame offset ([`fk::Humanoid::frame_offsets`], identity for the canonical human),
//!   `C_r` the robot role's canonical frame and `q_body` its body's orientation at `qpos0`.
//!   The target `q_joint ⊗ q_off = C_h ⊗ (C_r⁻¹ ⊗ q_body)` puts the robot body where the
//!   human's canonical frame says, whatever either side's joint frames are. Two refinements
//!   of the frames: the robot's limbs are turned about their bones so that the knee flexes
//!   about +y and the elbow about −y of the thigh / upper arm frame (the flexion sense is the
//!   larger side of the hinge's range from straight), which is where a human's knee and
//!   elbow bend when the arm hangs: a robot whose elbow bends sideways at `qpos0`
//!   (ToddlerBot's) then bends it forward with the human's; the human's thigh and shin are
//!   turned likewise, so that the knee flexes about their +y on average over the clip
//!   (fk's frames take their twist from the reference pose, which carries the subject's hip
//!   rotation there); and the human's foot frame is turned to lie flat on average over the
//!   frames where the foot is flat on the floor (a reference pose on tiptoe would otherwise
//!   stand the robot on its toes).
//! - **Position offset**, in the body's target frame, **fitted to the motion**: the offset
//!   that puts the target where the robot's body is when the robot copies the human's
//!   posture, averaged over up to 256 sampled frames. The copy: the robot's pelvis point at
//!   the scaled human hip midpoint, its role points hanging from it along the robot's own
//!   segments, each turned by the human's canonical frame of that role (knee and elbow held
//!   in their hinge ranges), the body origin at its offset from its role point; the target:
//!   GMR's scaling of the human joint. A foot's offset is fitted over the postures where
//!   it is flat, and then so that the robot's **sole is on the floor** wherever the human's
//!   foot touches it (flat, on the heel, on the ball): least squares of the sole's lowest
//!   point over those postures, with the foot turned as the human's, put
//!   [`SOLE_CLEARANCE`] above the floor. A robot sole longer than the scaled human foot is
//!   thereby moved back, so that its toe does not dig in when the human rolls onto the
//!   ball. The sideways offset stays the copy fit's, so the scaled human's feet stand about
//!   as far apart as the robot's own. The canonical human has one posture (standing).
//! - **Scales**, robot over human: the root (pelvis) by the standing hip height (thigh +
//!   shin + ankle height); the hip by its sideways offset from the pelvis point (midway
//!   between the hips); the knee by the thigh, the foot by thigh + shin (with the root's
//!   scale this puts the foot exactly at the robot's ankle height when the human stands);
//!   the shoulder, elbow and wrist by the path from the pelvis point through the role points
//!   (shoulder; + upper arm; + forearm). `human_height_assumption` is the human's
//!   measured height, so the ratio GMR multiplies every scale with is 1 on that skeleton and
//!   `--human-height H` multiplies them by `H / measured`, as for any GMR config.
//!
//! A config against the [`HumanBody::canonical`] human names the human side by role
//! (`pelvis`, `left_thigh`, …): a **role-named config**. [`bind`] turns it into one for a
//! particular skeleton: names become the skeleton's joints, rotation offsets get the
//! skeleton's frame offsets (`F_h ⊗ q_off`), scales are rescaled by canonical over skeleton
//! path lengths, position offsets are fitted to the skeleton's motion (keeping what the file
//! added to the canonical fit), and the height
//! assumption becomes the skeleton's height (times any factor the file applied to the
//! canonical one). Binding the role-named config of a robot gives exactly the config derived
//! for that skeleton directly.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt::Write as _;

use fk::{HumanMotion, Humanoid, Part, Role, Side};
use mjcf::{Data, Model};
use nalgebra::{UnitQuaternion, Vector3};

use crate::config::{IkConfig, MatchEntry};
use crate::robot_roles::RobotRoles;

use crate::Error;

/// Weights per part (GMR's G1 config's; the feet's position and the upper arms' rotation in
/// table 2 GMR's other configs', see the module docs): `[table1 pos, table1 rot, table2
/// pos, table2 rot]`.
pub const WEIGHTS: [(Part, [f64; 4]); 8] = [
    (Part::Pelvis, [0.0, 10.0, 100.0, 5.0]),
    (Part::Thigh, [0.0, 10.0, 10.0, 5.0]),
    (Part::Shin, [0.0, 10.0, 10.0, 5.0]),
    (Part::Foot, [100.0, 10.0, 100.0, 10.0]),
    (Part::Chest, [0.0, 100.0, 0.0, 10.0]),
    (Part::UpperArm, [0.0, 100.0, 5.0, 10.0]),
    (Part::Forearm, [0.0, 10.0, 10.0, 5.0]),
    (Part::Hand, [0.0, 10.0, 10.0, 5.0]),
];

/// A foot counts as flat on the floor while its ankle is within this of its flat height (m).
const FLAT_FOOT: f64 = 0.03;

/// A knee or elbow range whose two sides from straight differ by less than this share of it
/// is symmetric (servos'): it does not tell the flexion sense.
const SYMMETRIC_RANGE: f64 = 0.1;

/// Frames of a motion sampled, evenly, for the proportions and the offset fits.
const POSTURES: usize = 256;

/// Height of the canonical human (m).
pub const CANONICAL_HEIGHT: f64 = 1.75;

/// Roles in the order of GMR's tables: pelvis, left leg, right leg, chest, left arm, right arm.
const TABLE_ORDER: [Role; 14] = [
    Role::Pelvis,
    Role::LeftThigh,
    Role::LeftShin,
    Role::LeftFoot,
    Role::RightThigh,
    Role::RightShin,
    Role::RightFoot,
    Role::Chest,
    Role::LeftUpperArm,
    Role::LeftForearm,
    Role::LeftHand,
    Role::RightUpperArm,
    Role::RightForearm,
    Role::RightHand,
];

/// Roles in the order of GMR's scale tables.
const SCALE_ORDER: [Role; 14] = [
    Role::Pelvis,
    Role::Chest,
    Role::LeftThigh,
    Role::RightThigh,
    Role::LeftShin,
    Role::RightShin,
    Role::LeftFoot,
    Role::RightFoot,
    Role::LeftUpperArm,
    Role::RightUpperArm,
    Role::LeftForearm,
    Role::RightForearm,
    Role::LeftHand,
    Role::RightHand,
];

/// One posture of a human: its role joints' positions (m, Z up) and canonical frames
/// (`q_joint ⊗ offset`, [`fk::Humanoid::frame_offsets`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Posture {
    pub points: BTreeMap<Role, Vector3<f64>>,
    pub frames: BTreeMap<Role, UnitQuaternion<f64>>,
    /// `[left, right]`: whether the foot touches the floor (its ankle or its toe joint within
    /// 3 cm of the height it has when the foot is flat): flat, on the heel or on the
    /// ball of the foot.
    pub feet_down: [bool; 2],
}

/// The human half of a derived config: one skeleton's joint per role, its frame offsets and
/// its proportions (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct HumanBody {
    /// Human body (joint) name per role.
    pub joints: BTreeMap<Role, String>,
    /// `q_joint⁻¹ ⊗ C_h` per role ([`fk::Humanoid::frame_offsets`]), limbs turned about
    /// their bones by the knees' and elbows' flexion axes (`flexion_twist`).
    pub frame_offsets: BTreeMap<Role, UnitQuaternion<f64>>,
    /// The turn about the bone that `flexion_twist` gave each arm role's frame (the last
    /// factor of its `frame_offsets` entry): undone for a robot whose arms do not flex
    /// forward at `qpos0` (`HumanBody::for_robot`).
    pub arm_twists: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Path length from the pelvis point (midway between the hip joints) to each role's joint
    /// through the role joints ([`module docs`](self)); the pelvis's entry is the standing hip
    /// height (thigh + shin + ankle height).
    pub paths: BTreeMap<Role, f64>,
    /// Sampled postures (up to 256 frames of the motion; the canonical human has one): what
    /// the position offsets are fitted to ([`module docs`](self)).
    pub postures: Vec<Posture>,
    /// Height of the floor in the motion (m, the fk ground estimate; 0 for the canonical
    /// human): the derived targets are shifted so that it lands on the robot's floor.
    pub ground: f64,
    /// Height of the ankle joints above the floor when the foot is flat (m).
    pub ankle: f64,
    /// Subject height (m).
    pub height: f64,
    /// What this human is, for messages.
    pub source: String,
}

impl HumanBody {
    /// The canonical human: 1.75 m, standing facing +x with the arms hanging, joints at
    /// Winter's segment proportions (Biomechanics and Motor Control of Human Movement, 4th ed.,
    /// fig. 4.1); joint names are the role names and every joint frame is its canonical frame.
    #[must_use]
    pub fn canonical() -> HumanBody {
        let points = canonical_points();
        let joints = points.keys().map(|r| (*r, r.name().to_owned())).collect();
        let frame_offsets = points.keys().map(|r| (*r, UnitQuaternion::identity())).collect();
        let ankle = 0.039 * CANONICAL_HEIGHT;
        HumanBody {
            joints,
            frame_offsets,
            arm_twists: BTreeMap::new(),
            paths: paths(&points, ankle),
            postures: vec![Posture {
                frames: fk::canonical_frames(&points),
                points: points.clone(),
                feet_down: [true; 2],
            }],
            ground: 0.0,
            ankle,
            height: CANONICAL_HEIGHT,
            source: "the canonical human".to_owned(),
        }
    }

    /// The human half for a recognised skeleton and its motion (metres, Z up): frame offsets
    /// from `humanoid`, proportions averaged over up to 256 frames, the ankle height from how
    /// low the ankles go above `ground`, and `height` (the measured subject height).
    pub fn from_motion(
        humanoid: &Humanoid,
        motion: &HumanMotion,
        ground: f64,
        height: f64,
        source: &str,
    ) -> Result<HumanBody, Error> {
        let joints: BTreeMap<Role, String> =
            humanoid.roles.iter().map(|(r, j)| (r, j.name.clone())).collect();
        let index = |role: Role| joints.get(&role).and_then(|n| motion.body_index(n));
        let n = motion.num_frames;
        if n == 0 {
            return Err(Error::InvalidOption(format!("{source}: the motion has no frames")));
        }
        let count = n.min(POSTURES);
        let picked: Vec<usize> =
            (0..count).map(|k| if count > 1 { k * (n - 1) / (count - 1) } else { 0 }).collect();
        let ankle = ankle_height(motion, [index(Role::LeftFoot), index(Role::RightFoot)], ground);
        let toe = flat_height(motion, [index(Role::LeftToe), index(Role::RightToe)], ground);
        let mut frame_offsets = humanoid.frame_offsets.clone();
        for side in [Side::Left, Side::Right] {
            let foot = Role::of(Part::Foot, side);
            if let (Some(b), Some(offset)) = (index(foot), frame_offsets.get_mut(&foot)) {
                *offset *= flat_foot(motion, b, *offset, ground + ankle + FLAT_FOOT);
            }
        }
        let mut arm_twists = BTreeMap::new();
        for side in [Side::Left, Side::Right] {
            for limb in [Limb::Leg, Limb::Arm] {
                let twists = flexion_twist(motion, &index, &mut frame_offsets, &picked, side, limb);
                if limb == Limb::Arm {
                    arm_twists.extend(twists);
                }
            }
        }
        let mut sums: BTreeMap<Role, f64> = BTreeMap::new();
        let mut postures = Vec::with_capacity(picked.len());
        for &f in &picked {
            let points: BTreeMap<Role, Vector3<f64>> = Role::ALL
                .iter()
                .filter_map(|&r| Some((r, *motion.position(f, index(r)?))))
                .collect();
            for (role, length) in paths(&points, 0.0) {
                *sums.entry(role).or_default() += length;
            }
            let frames = frame_offsets
                .iter()
                .filter_map(|(r, offset)| Some((*r, motion.orientation(f, index(*r)?) * offset)))
                .collect();
            let feet_down = [Side::Left, Side::Right].map(|side| {
                let low = |part, flat: Option<f64>| {
                    let z = points.get(&Role::of(part, side))?.z - ground;
                    Some(z < flat? + FLAT_FOOT)
                };
                low(Part::Foot, Some(ankle)) == Some(true) || low(Part::Toe, toe) == Some(true)
            });
            postures.push(Posture { points, frames, feet_down });
        }
        let count = picked.len() as f64;
        let folds = trunk_folds(motion, humanoid, &picked, &index);
        let mut kept = joints.clone();
        if folds {
            // A chest frame that is not along the trunk (a skeleton whose chest joint sits at
            // the neck) would fold the robot's torso over: the chest is not tracked.
            kept.remove(&Role::Chest);
        }
        let mut paths: BTreeMap<Role, f64> =
            sums.into_iter().map(|(r, s)| (r, s / count)).collect();
        if let Some(legs) = paths.get_mut(&Role::Pelvis) {
            *legs += ankle;
        }
        Ok(HumanBody {
            joints: kept,
            frame_offsets,
            arm_twists,
            paths,
            postures,
            ground,
            ankle,
            height,
            source: source.to_owned(),
        })
    }
}

/// The turn that makes a foot's canonical frame (`q_joint ⊗ offset`, taken in the reference
/// pose) flat on average over the frames where its joint is below `below` (the foot flat
/// on the floor): a reference pose on tiptoe (the tallest frame of a jump take) would
/// otherwise tell the robot to stand on its toes. Identity when no frame is that low.
fn flat_foot(
    motion: &HumanMotion,
    body: usize,
    offset: UnitQuaternion<f64>,
    below: f64,
) -> UnitQuaternion<f64> {
    let up: Vector3<f64> = (0..motion.num_frames)
        .filter(|&f| motion.position(f, body).z < below)
        .map(|f| (motion.orientation(f, body) * offset).inverse() * Vector3::z())
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .sum();
    UnitQuaternion::rotation_between(&Vector3::z(), &up).unwrap_or_default()
}

/// A limb whose frames `flexion_twist` turns about their bones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Limb {
    Leg,
    Arm,
}

impl Limb {
    /// Its three joints, the middle one the hinge (knee, elbow).
    fn chain(self) -> [Part; 3] {
        match self {
            Limb::Leg => [Part::Thigh, Part::Shin, Part::Foot],
            Limb::Arm => [Part::UpperArm, Part::Forearm, Part::Hand],
        }
    }

    /// The frame axis it flexes about: a knee about +y (the shin goes back), an elbow about
    /// −y (the forearm comes forward), as `limb_frames` turns the robot's.
    fn y_sign(self) -> f64 {
        match self {
            Limb::Leg => 1.0,
            Limb::Arm => -1.0,
        }
    }
}

/// A knee counts as bent enough to say which way it flexes when, over the sampled frames,
/// the mean of `|thigh × shin|` is this share of the mean `|thigh| |shin|` (about 3°); an
/// elbow likewise.
const FLEXION_SEEN: f64 = 0.05;

/// The most (rad) `flexion_twist` turns a leg's frames: a knee that seems to flex about an
/// axis further than this from its frame's +y is not bending forward (a subject standing
/// with straight knees, e.g. the Rigify idle take, where the little bend there is sideways
/// put the thighs 95° and 187° off), so the reference pose's twist stays. An arm's turn is
/// not bounded: a reference pose's arms may be turned any way (the Bandai kick's left
/// upper arm: 95°).
const FLEXION_TWIST_MAX: f64 = std::f64::consts::FRAC_PI_4;

/// Turns the human's frames of a limb (`offsets`, [`fk::Humanoid::frame_offsets`]) about
/// their bones so that the middle joint flexes about their ±y axis ([`Limb::y_sign`]), on
/// average over the `picked` frames weighted by how bent it is (the mean of `upper × lower`
/// seen from each frame); the hand takes the forearm's turn. fk's limb frames take their
/// twist from the body's forward direction in the reference pose, so they carry whatever
/// rotation the subject's hip or shoulder had there (8–17° at the hips on the LAFAN1 takes;
/// the arms of a reference frame taken mid-motion, as Bandai's, anything); the robot's are
/// turned by its knee and elbow axes (`limb_frames`), so both sides then agree on the
/// flexion axis, and the robot's limbs are asked for turns they can make. Measured, mean
/// rotation error on the G1 (GMR's solve): the jumps' hips and knees 15° and 13° before the
/// legs were turned, 9° and 5° after; over all bodies, after the arms were turned too, the
/// derived config on the LAFAN1 walk 7.0° → 4.4°, the CMU 131_03 take 10.3° → 4.3°, the
/// Bandai dance 20.5° → 6.1°. Returns the turn given to each role.
fn flexion_twist(
    motion: &HumanMotion,
    index: &dyn Fn(Role) -> Option<usize>,
    offsets: &mut BTreeMap<Role, UnitQuaternion<f64>>,
    picked: &[usize],
    side: Side,
    limb: Limb,
) -> BTreeMap<Role, UnitQuaternion<f64>> {
    let mut turned = BTreeMap::new();
    let roles = limb.chain().map(|p| Role::of(p, side));
    let [Some(top), Some(middle), Some(end)] = roles.map(index) else { return turned };
    let bones: Vec<(usize, Vector3<f64>, Vector3<f64>)> = picked
        .iter()
        .map(|&f| {
            let upper = motion.position(f, middle) - motion.position(f, top);
            (f, upper, motion.position(f, end) - motion.position(f, middle))
        })
        .filter(|(_, a, b)| a.iter().chain(b.iter()).all(|x| x.is_finite()))
        .collect();
    let lengths: f64 = bones.iter().map(|(_, a, b)| a.norm() * b.norm()).sum();
    let mut middle_turn = None;
    for (k, role) in roles.into_iter().enumerate() {
        let (Some(body), Some(offset)) = (index(role), offsets.get(&role).copied()) else {
            continue;
        };
        let theta = if k == 2 {
            // The foot keeps its own frame (flat on the floor); the hand turns with the
            // forearm.
            match (limb, middle_turn) {
                (Limb::Arm, Some(theta)) => theta,
                _ => continue,
            }
        } else {
            let n: Vector3<f64> = bones
                .iter()
                .map(|(f, a, b)| (motion.orientation(*f, body) * offset).inverse() * a.cross(b))
                .sum();
            if n.x.hypot(n.y) <= FLEXION_SEEN * lengths {
                continue;
            }
            // Turning the frame by θ about z brings n (at angle atan2(n.y, n.x)) to ±y.
            let theta =
                crate::feet::wrap(n.y.atan2(n.x) - limb.y_sign() * std::f64::consts::FRAC_PI_2);
            if limb == Limb::Leg && theta.abs() > FLEXION_TWIST_MAX {
                continue;
            }
            theta
        };
        if k == 1 {
            middle_turn = Some(theta);
        }
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta);
        offsets.insert(role, offset * turn);
        turned.insert(role, turn);
    }
    turned
}

impl HumanBody {
    /// This human as `robot` is matched with: itself, but for a robot whose arms do not flex
    /// forward at `qpos0` ([`RobotSide::arms_sideways`]), whose arms keep fk's frames (the
    /// `arm_twists` undone). Measured: on ToddlerBot, whose elbows bend sideways at `qpos0`,
    /// the turned arms twisted its torso 40° towards them (rotation error 20.9° → 31.6° on the
    /// LAFAN1 walk; better on the jumps, 21.6° → 17.2°). Taking the other side of its elbow's
    /// range as flexion instead gives 22.6° and 17.4°: its flexion sense, not the turn, may be
    /// what is wrong there.
    fn for_robot(&self, robot: &RobotSide) -> Cow<'_, HumanBody> {
        if !robot.arms_sideways {
            return Cow::Borrowed(self);
        }
        let mut out = self.clone();
        for (role, turn) in &self.arm_twists {
            if let Some(offset) = out.frame_offsets.get_mut(role) {
                *offset *= turn.inverse();
            }
            for posture in &mut out.postures {
                if let Some(frame) = posture.frames.get_mut(role) {
                    *frame *= turn.inverse();
                }
            }
        }
        out.arm_twists.clear();
        Cow::Owned(out)
    }
}

/// Whether the chest's canonical frame points more than 60° away from the pelvis's (z axes)
/// in most of the `picked` frames.
fn trunk_folds(
    motion: &HumanMotion,
    humanoid: &Humanoid,
    picked: &[usize],
    index: &dyn Fn(Role) -> Option<usize>,
) -> bool {
    let (Some(p), Some(c), Some(po), Some(co)) = (
        index(Role::Pelvis),
        index(Role::Chest),
        humanoid.frame_offsets.get(&Role::Pelvis),
        humanoid.frame_offsets.get(&Role::Chest),
    ) else {
        return false;
    };
    let folded = picked
        .iter()
        .filter(|&&f| {
            let zp = (motion.orientation(f, p) * po) * Vector3::z();
            let zc = (motion.orientation(f, c) * co) * Vector3::z();
            zp.angle(&zc) > 60f64.to_radians()
        })
        .count();
    2 * folded > picked.len()
}

/// Joint positions of the canonical human (m, Z up, facing +x), as fractions of its height.
fn canonical_points() -> BTreeMap<Role, Vector3<f64>> {
    let h = CANONICAL_HEIGHT;
    let mut p = BTreeMap::new();
    let mut put = |role: Role, x: f64, y: f64, z: f64| {
        p.insert(role, Vector3::new(x, y, z) * h);
    };
    put(Role::Pelvis, 0.0, 0.0, 0.530);
    put(Role::Spine, 0.0, 0.0, 0.600);
    put(Role::Chest, 0.0, 0.0, 0.720);
    put(Role::Neck, 0.0, 0.0, 0.818);
    put(Role::Head, 0.0, 0.0, 0.870);
    for (side, y) in [(Side::Left, 1.0), (Side::Right, -1.0)] {
        let r = |part| Role::of(part, side);
        put(r(Part::Clavicle), 0.0, 0.020 * y, 0.800);
        put(r(Part::UpperArm), 0.0, 0.129 * y, 0.818);
        put(r(Part::Forearm), 0.0, 0.129 * y, 0.632);
        put(r(Part::Hand), 0.0, 0.129 * y, 0.486);
        put(r(Part::Thigh), 0.0, 0.050 * y, 0.530);
        put(r(Part::Shin), 0.0, 0.050 * y, 0.285);
        put(r(Part::Foot), 0.0, 0.050 * y, 0.039);
        put(r(Part::Toe), 0.100, 0.050 * y, 0.010);
    }
    p
}

/// Path lengths from the hip midpoint to each role point (see [`HumanBody::paths`]); the
/// pelvis's entry is thigh + shin (averaged over the sides) + `ankle`.
fn paths(points: &BTreeMap<Role, Vector3<f64>>, ankle: f64) -> BTreeMap<Role, f64> {
    let mut out = BTreeMap::new();
    let at = |r: Role| points.get(&r).copied();
    let (Some(l), Some(r)) = (at(Role::LeftThigh), at(Role::RightThigh)) else { return out };
    let mid = (l + r) / 2.0;
    let mut legs = Vec::new();
    for side in [Side::Left, Side::Right] {
        let chains: [&[Part]; 2] =
            [&[Part::Thigh, Part::Shin, Part::Foot], &[Part::UpperArm, Part::Forearm, Part::Hand]];
        for chain in chains {
            let mut from = mid;
            let mut total = 0.0;
            for &part in chain {
                let role = Role::of(part, side);
                let Some(p) = at(role) else { break };
                // A leg's knee and foot are placed by the leg's length alone (the hip's
                // sideways offset would skew the height the foot is put at).
                if part == Part::Shin {
                    total = 0.0;
                }
                total += (p - from).norm();
                from = p;
                out.insert(role, total);
            }
        }
        if let (Some(t), Some(s), Some(f)) = (
            at(Role::of(Part::Thigh, side)),
            at(Role::of(Part::Shin, side)),
            at(Role::of(Part::Foot, side)),
        ) {
            legs.push((t - s).norm() + (s - f).norm());
        }
    }
    if let Some(c) = at(Role::Chest) {
        out.insert(Role::Chest, (c - mid).norm());
    }
    if !legs.is_empty() {
        out.insert(Role::Pelvis, legs.iter().sum::<f64>() / legs.len() as f64 + ankle);
    }
    out
}

/// Ankle joint height when the foot is flat: [`flat_height`] of the ankles, within 2–15 cm
/// (the canonical human's without ankles).
fn ankle_height(motion: &HumanMotion, feet: [Option<usize>; 2], ground: f64) -> f64 {
    flat_height(motion, feet, ground).map_or(0.039 * CANONICAL_HEIGHT, |z| z.clamp(0.02, 0.15))
}

/// Height of joints above `ground` when they are as low as they go: the 5th percentile of
/// `bodies`' heights over the clip (a walk's flat-foot frames). `None` without such bodies.
fn flat_height(motion: &HumanMotion, bodies: [Option<usize>; 2], ground: f64) -> Option<f64> {
    let mut z: Vec<f64> = bodies
        .iter()
        .flatten()
        .flat_map(|&b| (0..motion.num_frames).map(move |f| (b, f)))
        .map(|(b, f)| motion.position(f, b).z - ground)
        .filter(|v| v.is_finite())
        .collect();
    z.sort_by(f64::total_cmp);
    z.get(z.len().checked_sub(1)? / 20).copied()
}

/// The chains of the canonical pose: each role with the roles its segment may start from, in
/// order of preference (none: from the hip midpoint, seen from the pelvis's frame).
const POSE_CHAINS: [(Role, &[Role]); 17] = [
    (Role::Pelvis, &[]),
    (Role::LeftThigh, &[]),
    (Role::RightThigh, &[]),
    (Role::LeftShin, &[Role::LeftThigh]),
    (Role::RightShin, &[Role::RightThigh]),
    (Role::LeftFoot, &[Role::LeftShin]),
    (Role::RightFoot, &[Role::RightShin]),
    (Role::Spine, &[Role::Pelvis]),
    (Role::Chest, &[Role::Spine, Role::Pelvis]),
    (Role::LeftUpperArm, &[Role::Chest, Role::Spine, Role::Pelvis]),
    (Role::RightUpperArm, &[Role::Chest, Role::Spine, Role::Pelvis]),
    (Role::LeftForearm, &[Role::LeftUpperArm]),
    (Role::RightForearm, &[Role::RightUpperArm]),
    (Role::LeftHand, &[Role::LeftForearm]),
    (Role::RightHand, &[Role::RightForearm]),
    (Role::Neck, &[Role::Chest, Role::Spine, Role::Pelvis]),
    (Role::Head, &[Role::Neck, Role::Chest, Role::Spine, Role::Pelvis]),
];

/// One posture's segments of the canonical pose: per role the role it starts from (`None`:
/// the hip midpoint) and the segment seen from that role's canonical frame (the pelvis's for
/// the hip midpoint). `points` are joint positions, `frames` their canonical frames.
fn segments(
    points: &BTreeMap<Role, Vector3<f64>>,
    frames: &BTreeMap<Role, UnitQuaternion<f64>>,
) -> BTreeMap<Role, (Option<Role>, Vector3<f64>)> {
    let mut out = BTreeMap::new();
    let (Some(l), Some(r), Some(pelvis)) =
        (points.get(&Role::LeftThigh), points.get(&Role::RightThigh), frames.get(&Role::Pelvis))
    else {
        return out;
    };
    let mid = (l + r) / 2.0;
    for (role, parents) in POSE_CHAINS {
        let Some(p) = points.get(&role) else { continue };
        let from = parents.iter().find(|a| points.contains_key(a) && frames.contains_key(a));
        let segment = match from {
            Some(a) => (Some(*a), frames[a].inverse() * (p - points[a])),
            None if parents.is_empty() => (None, pelvis.inverse() * (p - mid)),
            None => continue,
        };
        out.insert(role, segment);
    }
    out
}

/// A knee or elbow hinge of the robot, as the position fit sees it: its axis in the canonical
/// frame of the limb's proximal role, the joint value that lays the limb straight, its range.
#[derive(Debug, Clone, Copy)]
struct MiddleHinge {
    axis: nalgebra::Unit<Vector3<f64>>,
    straight: f64,
    range: [f64; 2],
}

/// The knee or elbow hinge of the limb `[proximal, mid, distal]` (the `mid` role body's hinge
/// most across the bone), when it has a range: its world axis at `qpos0`, the joint value
/// that lays the limb straight, its range.
fn middle_hinge(
    model: &Model,
    data: &Data,
    roles: &RobotRoles,
    [proximal, mid, distal]: [Role; 3],
) -> Option<(Vector3<f64>, f64, [f64; 2])> {
    let point = |r: Role| roles.roles.get(&r).map(|x| x.point);
    let (u, f) = ((point(mid)? - point(proximal)?), (point(distal)? - point(mid)?));
    let body = roles.body(mid)?;
    let (a, joint) = model
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.body == body && j.kind == mjcf::JointType::Hinge)
        .filter_map(|(j, joint)| Some((*data.xaxis.get(j)?, joint)))
        .min_by(|a, b| a.0.dot(&f).abs().total_cmp(&b.0.dot(&f).abs()))?;
    let (u, f) = (u - a * a.dot(&u), f - a * a.dot(&f));
    // Turning the distal bone by θ about the axis lays it along the proximal one.
    let theta = a.dot(&f.cross(&u)).atan2(f.dot(&u));
    Some((a, model.qpos0.get(joint.qpos_adr)? + theta, joint.range?))
}

/// The robot's canonical frames ([`RobotRoles::canonical_frames`]) with each limb's twist
/// taken from its knee or elbow instead of from the facing: the upper arm, forearm and
/// hand turned about their bone so that the elbow flexes about −y (forward, as a human
/// elbow with the arm hanging), the thigh and shin so that the knee flexes about +y
/// (backward). A robot elbow that bends sideways at `qpos0` (ToddlerBot's) is then matched
/// with the human's flexion, not its abduction. The flexion sense is the larger side of the
/// range from straight; for a symmetric range (servos', within 10 %), backward for the knee and
/// forward for the elbow as the robot faces (ROBOTIS OP3's right knee, whose axis is the
/// left's mirrored, was read as bending forward). Also the knee and elbow hinges in the new
/// frames.
fn limb_frames(
    model: &Model,
    data: &Data,
    roles: &RobotRoles,
) -> (BTreeMap<Role, UnitQuaternion<f64>>, BTreeMap<Role, MiddleHinge>) {
    let mut frames = roles.canonical_frames();
    let mut hinges = BTreeMap::new();
    for side in [Side::Left, Side::Right] {
        let limbs: [([Part; 3], &[Part], f64); 2] = [
            ([Part::Thigh, Part::Shin, Part::Foot], &[Part::Thigh, Part::Shin], 1.0),
            (
                [Part::UpperArm, Part::Forearm, Part::Hand],
                &[Part::UpperArm, Part::Forearm, Part::Hand],
                -1.0,
            ),
        ];
        for (limb, twisted, y_sign) in limbs {
            let limb = limb.map(|p| Role::of(p, side));
            let Some((axis, straight, [lo, hi])) = middle_hinge(model, data, roles, limb) else {
                continue;
            };
            // A servo's symmetric range does not say which way the joint bends: then the
            // knee bends backward and the elbow forward (their frames' y is the robot's left).
            let larger = (hi - straight) - (straight - lo);
            let flexion = if larger.abs() > SYMMETRIC_RANGE * (hi - lo) {
                if larger > 0.0 {
                    axis
                } else {
                    -axis
                }
            } else {
                let left = Vector3::z().cross(&roles.forward);
                if (axis * y_sign).dot(&left) >= 0.0 {
                    axis
                } else {
                    -axis
                }
            };
            for &part in twisted {
                let role = Role::of(part, side);
                let Some(c) = frames.get(&role) else { continue };
                let z = c * Vector3::z();
                let y = flexion * y_sign;
                let Some(y) = (y - z * z.dot(&y)).try_normalize(0.5) else { continue };
                let m = nalgebra::Matrix3::from_columns(&[y.cross(&z), y, z]);
                let r = nalgebra::Rotation3::from_matrix_unchecked(m);
                frames.insert(role, UnitQuaternion::from_rotation_matrix(&r));
            }
            if let Some(p) = frames.get(&limb[0]) {
                let axis = nalgebra::Unit::new_normalize(p.inverse() * axis);
                hinges.insert(limb[1], MiddleHinge { axis, straight, range: [lo, hi] });
            }
        }
    }
    (frames, hinges)
}

impl MiddleHinge {
    /// The distal segment's frame relative to the proximal one, `rel` as the human has it,
    /// turned back into the hinge's range: the hinge angle is the twist of `rel` about the
    /// axis, clamped (the nearest end, angles modulo 2π).
    fn clamp(&self, rel: UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        let v = Vector3::new(rel.i, rel.j, rel.k);
        let phi = 2.0 * self.axis.dot(&v).atan2(rel.w);
        let q = self.straight + phi;
        let tau = std::f64::consts::TAU;
        let [lo, hi] = self.range;
        let Some((delta, _)) = [q - tau, q, q + tau]
            .into_iter()
            .map(|x| (x.clamp(lo, hi) - x, x))
            .min_by(|x, y| x.0.abs().total_cmp(&y.0.abs()))
        else {
            return rel;
        };
        UnitQuaternion::from_axis_angle(&self.axis, delta) * rel
    }
}

/// A collision primitive of a foot: its kind and size, its centre seen from the foot body's
/// origin and its orientation, both in the foot role's canonical frame at `qpos0`.
#[derive(Debug, Clone, Copy)]
struct SoleGeom {
    kind: mjcf::GeomType,
    size: [f64; 3],
    pos: Vector3<f64>,
    rot: UnitQuaternion<f64>,
}

/// The soles' primitives ([`RobotRoles::soles`]) per foot role, in the foot's canonical frame;
/// a foot without collision geometry gets its equivalent inertia box, as the planner does.
fn sole_geoms(
    model: &Model,
    data: &Data,
    roles: &RobotRoles,
    frames: &BTreeMap<Role, UnitQuaternion<f64>>,
) -> BTreeMap<Role, Vec<SoleGeom>> {
    let mut out = BTreeMap::new();
    for (side, sole) in [Side::Left, Side::Right].into_iter().zip(roles.soles()) {
        let role = Role::of(Part::Foot, side);
        let Some(c) = frames.get(&role) else { continue };
        let geoms = sole
            .geoms
            .iter()
            .filter_map(|&g| {
                let geom = model.geoms.get(g)?;
                let r = nalgebra::Rotation3::from_matrix_unchecked(*data.geom_xmat.get(g)?);
                Some(SoleGeom {
                    kind: geom.kind,
                    size: geom.size,
                    pos: c.inverse() * (data.geom_xpos.get(g)? - data.xpos.get(sole.body)?),
                    rot: c.inverse() * UnitQuaternion::from_rotation_matrix(&r),
                })
            })
            .collect::<Vec<_>>();
        let geoms = if geoms.is_empty() {
            // No collision geometry: the foot's equivalent inertia box, as the planner's.
            crate::feet::inertia_sole(model, sole.body)
                .and_then(|inertia| {
                    let at = inertia.world(data);
                    Some(vec![SoleGeom {
                        kind: mjcf::GeomType::Box,
                        size: inertia.half,
                        pos: c.inverse() * (at.translation.vector - data.xpos.get(sole.body)?),
                        rot: c.inverse() * at.rotation,
                    }])
                })
                .unwrap_or_default()
        } else {
            geoms
        };
        if !geoms.is_empty() {
            out.insert(role, geoms);
        }
    }
    out
}

/// Height of the sole's lowest point above the foot body's origin when the foot's canonical
/// frame is `frame` (world).
fn sole_low(geoms: &[SoleGeom], frame: &UnitQuaternion<f64>) -> f64 {
    geoms
        .iter()
        .map(|g| {
            let r = (frame * g.rot).to_rotation_matrix().into_inner();
            (frame * g.pos).z + crate::constraints::support_offset(g.kind, &g.size, &r).z
        })
        .fold(f64::INFINITY, f64::min)
}

/// The robot's half: per role, body, `C_r⁻¹ ⊗ q_body`, body offset from the role point (in the
/// body frame), and path lengths like [`HumanBody::paths`].
struct RobotSide {
    bodies: BTreeMap<Role, (String, UnitQuaternion<f64>, Vector3<f64>)>,
    paths: BTreeMap<Role, f64>,
    /// Per role: the segment to its role point from its parent role's ([`segments`]).
    segments: BTreeMap<Role, (Option<Role>, Vector3<f64>)>,
    /// Per role: the body origin from the role point, in the role's canonical frame.
    origins: BTreeMap<Role, Vector3<f64>>,
    /// Knee and elbow hinges, by the shin / forearm role.
    hinges: BTreeMap<Role, MiddleHinge>,
    /// The canonical frames used (`limb_frames`).
    frames: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Whether its arms do not flex forward at `qpos0`: `limb_frames` turned an upper arm's
    /// frame more than 45° from its canonical one (ToddlerBot's sideways elbows).
    arms_sideways: bool,
    /// Per foot role, its sole's primitives ([`sole_geoms`]).
    soles: BTreeMap<Role, Vec<SoleGeom>>,
}

fn robot_side(model: &Model, roles: &RobotRoles) -> RobotSide {
    let mut data = Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let (frames, hinges) = limb_frames(model, &data, roles);
    let mut bodies = BTreeMap::new();
    for (role, r) in &roles.roles {
        let (Some(c), Some(q), Some(x)) =
            (frames.get(role), data.xquat.get(r.body), data.xpos.get(r.body))
        else {
            continue;
        };
        let offset = q.inverse() * (x - r.point);
        bodies.insert(*role, (r.name.clone(), c.inverse() * q, offset));
    }
    let points: BTreeMap<Role, Vector3<f64>> =
        roles.roles.iter().map(|(r, role)| (*r, role.point)).collect();
    let ankle = [Side::Left, Side::Right]
        .iter()
        .zip(&roles.soles)
        .filter_map(|(&side, sole)| {
            Some(points.get(&Role::of(Part::Foot, side))?.z - sole.lowest.z)
        })
        .sum::<f64>()
        / 2.0;
    let origins = roles
        .roles
        .iter()
        .filter_map(|(role, r)| {
            Some((*role, frames.get(role)?.inverse() * (data.xpos.get(r.body)? - r.point)))
        })
        .collect();
    let canonical = roles.canonical_frames();
    let arms_sideways = [Side::Left, Side::Right].iter().any(|&side| {
        let arm = Role::of(Part::UpperArm, side);
        match (canonical.get(&arm), frames.get(&arm)) {
            (Some(c), Some(f)) => c.angle_to(f) > std::f64::consts::FRAC_PI_4,
            _ => false,
        }
    });
    RobotSide {
        bodies,
        paths: paths(&points, ankle.max(0.0)),
        segments: segments(&points, &frames),
        origins,
        hinges,
        soles: sole_geoms(model, &data, roles, &frames),
        frames,
        arms_sideways,
    }
}

/// The position offset (in the target frame) that best puts `role`'s target where the robot
/// body is when the robot copies the human's body frames (see the module docs): averaged
/// over the human's postures, `M⁻¹ C_h⁻¹ (x_robot − p_target)`, where the robot's role points
/// hang from its pelvis point (put at the scaled hip midpoint) along its own segments turned
/// by the human's canonical frames (knees and elbows held in their ranges), the body origin
/// `origin` from its role point, and `p_target` is GMR's scaling of the human joint (root
/// by `root_scale` about the origin, the joint by `scale` about the root) with the human's
/// floor moved to the robot's. `relative` is `M`, the target frame's rotation from the
/// human's canonical frame. `None` when no posture has the frames needed.
#[allow(clippy::too_many_arguments)]
fn fitted_offset(
    robot: &RobotSide,
    human: &HumanBody,
    role: Role,
    origin: Vector3<f64>,
    relative: UnitQuaternion<f64>,
    root_scale: f64,
    scale: f64,
) -> Option<Vector3<f64>> {
    // A foot's offset is fitted where it matters most and the copy is straightest: the
    // postures with that foot flat on the floor (its ankle within 3 cm of its flat height),
    // when there are any.
    let planted = |p: &Posture| {
        p.points.get(&role).is_some_and(|a| a.z - human.ground < human.ankle + FLAT_FOOT)
    };
    let foot = role.part() == Part::Foot && human.postures.iter().any(planted);
    let mut sum = Vector3::zeros();
    let mut count = 0usize;
    for posture in human.postures.iter().filter(|p| !foot || planted(p)) {
        if let Some(v) = copy_error(robot, posture, role, origin, root_scale, scale, human.ground) {
            sum += v;
            count += 1;
        }
    }
    if count == 0 {
        return None;
    }
    let mut fit = sum / count as f64;
    if let (true, Some(geoms)) = (role.part() == Part::Foot, robot.soles.get(&role)) {
        fit = sole_fit(geoms, human, role, root_scale, scale, fit).unwrap_or(fit);
    }
    Some(relative.inverse() * fit)
}

/// The offset of a foot (in its canonical frame) that puts the robot's sole on the floor wherever
/// the human's foot touches it ([`Posture::feet_down`]: flat, on the heel, on the ball), with the
/// foot turned as the human's: least squares over those postures of the sole's lowest point's
/// height above [`SOLE_CLEARANCE`], `a + (C_h o)_z + low(C_h)` with `a` the target's height (GMR's
/// scaling of the ankle: the root by `root_scale` about the origin, the ankle by `scale` about the
/// root). Flat postures fix the height; the postures on the heel or the ball fix how far forward
/// the body sits (a robot sole longer than the scaled human foot is moved back, so that its toe
/// does not dig in when the human rolls onto the ball). The forward offset stays near `prior`
/// (the copy fit) where the postures do not decide it: a shift costs as much as the same height
/// error in [`SOLE_PRIOR`] of the postures. The sideways offset is the copy fit's: a human
/// foot rolls sideways by a few degrees, mostly noise, and fitting the sole's height to those
/// rolls moved the feet up to 5 cm sideways (the scaled LAFAN1 walk's feet 134 mm apart on
/// the N1, whose feet stand 240 mm apart; the copy fit gives 222), which the default solve's
/// planted feet then pushed back apart (`keep_feet_apart`).
fn sole_fit(
    geoms: &[SoleGeom],
    human: &HumanBody,
    role: Role,
    root_scale: f64,
    scale: f64,
    prior: Vector3<f64>,
) -> Option<Vector3<f64>> {
    let k = usize::from(role.side() == Some(Side::Right));
    // Unknowns: the forward (x) and height (z) offsets; y is the prior's.
    let mut normal = nalgebra::Matrix2::zeros();
    let mut rhs = nalgebra::Vector2::zeros();
    let mut n = 0usize;
    for posture in human.postures.iter().filter(|p| p.feet_down.get(k) == Some(&true)) {
        let (Some(pelvis), Some(ankle), Some(frame)) = (
            posture.points.get(&Role::Pelvis),
            posture.points.get(&role),
            posture.frames.get(&role),
        ) else {
            continue;
        };
        let a = root_scale * pelvis.z + (ankle.z - pelvis.z) * scale;
        let low = sole_low(geoms, frame);
        let r = frame.inverse() * Vector3::z();
        if !(a + low).is_finite() {
            continue;
        }
        let rxz = nalgebra::Vector2::new(r.x, r.z);
        normal += rxz * rxz.transpose();
        rhs -= rxz * (a + low - SOLE_CLEARANCE + r.y * prior.y);
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let w = SOLE_PRIOR * n as f64;
    normal += nalgebra::Matrix2::new(w, 0.0, 0.0, 0.0);
    rhs.x += w * prior.x;
    let xz = normal.try_inverse()? * rhs;
    let fit = Vector3::new(xz.x, prior.y, xz.y);
    fit.iter().all(|v| v.is_finite()).then_some(fit)
}

/// Height (m) of the sole's lowest point above the floor that the foot offsets are fitted
/// to, the same for every robot. GMR's solve has no floor: a sole fitted to z = 0 is below it
/// in about half of the frames, more than 1 cm (the report's penetration) where a rigid sole
/// cannot follow the human's heel strike and toe-off. Measured on the five robots with GMR
/// configs and both LAFAN1 takes (`scripts/compare-configs`): 3 mm takes 2.2 to 3.7 points
/// off the frames with a geom more than 1 cm in the floor in GMR's solve (G1 walk 8.4 →
/// 6.1 %, ToddlerBot walk 7.2 → 4.4 %), while stance samples more than 2 cm above the floor
/// stay fewer than with GMR's configs (at most 1.0 %); the report's sliding share moves by
/// −1.4 to +0.6 points; 6 mm and 1 cm take penetration down further (G1 walk 4.4, 3.0 %)
/// and raise the sliding share of every walk (16.9 → 17.6 → 18.4 %). The default solve
/// moves every target onto its floor (`feet`): there the errors move by at most
/// 1 mm and the sliding share by at most 0.3 points.
pub const SOLE_CLEARANCE: f64 = 0.003;

/// Weight of the copy fit's forward foot offset in [`sole_fit`], as a share of the postures.
const SOLE_PRIOR: f64 = 0.001;

/// One posture's `C_h⁻¹ (x_robot − p_target)` for [`fitted_offset`].
fn copy_error(
    robot: &RobotSide,
    posture: &Posture,
    role: Role,
    origin: Vector3<f64>,
    root_scale: f64,
    scale: f64,
    ground: f64,
) -> Option<Vector3<f64>> {
    let (points, human) = (&posture.points, &posture.frames);
    let mid = (points.get(&Role::LeftThigh)? + points.get(&Role::RightThigh)?) / 2.0;
    let pelvis = points.get(&Role::Pelvis)?;
    let target = (pelvis - mid) * root_scale
        + (points.get(&role)? - pelvis) * scale
        + Vector3::z() * (root_scale * ground);
    // The robot's frames: the human's, knees and elbows turned back into their ranges.
    let mut frames: BTreeMap<Role, UnitQuaternion<f64>> = BTreeMap::new();
    let mut at: BTreeMap<Role, Vector3<f64>> = BTreeMap::new();
    for (r, _) in POSE_CHAINS {
        let Some((from, v)) = robot.segments.get(&r) else { continue };
        let Some(c) = human.get(&r) else { continue };
        let (start, turn) = match from {
            Some(a) => (*at.get(a)?, *frames.get(a)?),
            None => (Vector3::zeros(), *human.get(&Role::Pelvis)?),
        };
        at.insert(r, start + turn * v);
        let frame = match (robot.hinges.get(&r), from) {
            (Some(h), Some(_)) => turn * h.clamp(turn.inverse() * c),
            _ => *c,
        };
        frames.insert(r, frame);
        if r == role {
            break;
        }
    }
    let own = human.get(&role)?;
    // A foot or hand keeps the human's frame (the ankle or wrist makes up for a bent knee or
    // elbow); a shin or forearm turns with its hinge.
    let body = at.get(&role)? + frames.get(&role)? * origin;
    Some(own.inverse() * (body - target))
}

/// A written table row: robot body, human joint, position and rotation weights, offsets.
type TableRow = (String, String, f64, f64, Vector3<f64>, UnitQuaternion<f64>);

/// One derived row before it is written: role, robot body, human joint, offsets, scale.
struct Row {
    role: Role,
    body: String,
    joint: String,
    rot: UnitQuaternion<f64>,
    pos: Vector3<f64>,
    scale: f64,
    /// `[table1 pos, table1 rot, table2 pos, table2 rot]`.
    weights: [f64; 4],
}

/// The config that maps `human` onto the robot (see the module docs); `source` names it in
/// messages. Roles missing on either side are left out; pelvis, thighs, shins and feet are
/// required.
pub fn derive(
    model: &Model,
    roles: &RobotRoles,
    human: &HumanBody,
    source: &str,
) -> Result<IkConfig, Error> {
    let robot = robot_side(model, roles);
    let human = &*human.for_robot(&robot);
    let root_scale = match (robot.paths.get(&Role::Pelvis), human.paths.get(&Role::Pelvis)) {
        (Some(r), Some(h)) if *h > 0.0 => r / h,
        _ => 1.0,
    };
    let mut rows: Vec<Row> = Vec::new();
    for role in TABLE_ORDER {
        let (Some((body, relative, offset)), Some(joint), Some(frame), Some(rp), Some(hp)) = (
            robot.bodies.get(&role),
            human.joints.get(&role),
            human.frame_offsets.get(&role),
            robot.paths.get(&role),
            human.paths.get(&role),
        ) else {
            if matches!(role.part(), Part::Pelvis | Part::Thigh | Part::Shin | Part::Foot) {
                return Err(Error::Config {
                    at: source.to_owned(),
                    message: format!("cannot derive a config: no {role} on both sides"),
                });
            }
            continue;
        };
        let rot = frame * relative;
        let scale = if *hp > 0.0 { rp / hp } else { 1.0 };
        let origin = robot.origins.get(&role).copied().unwrap_or_default();
        let pos = fitted_offset(&robot, human, role, origin, *relative, root_scale, scale)
            .unwrap_or(*offset);
        let mut weights = weights(role.part(), robot.bodies.contains_key(&Role::Chest));
        if role.part() == Part::UpperArm && shoulder_hinges(model, roles, role) < 3 {
            // A shoulder of two hinges (servo humanoids') cannot take the upper arm's twist:
            // weighed as GMR weighs it, the part it cannot follow turned the shoulder into
            // another branch and pulled the trunk round (a 0.45 m servo robot on the LAFAN1
            // walk: hands L↔L 0.43 → 0.64, legs' likeness 0.81 → 0.64).
            weights[1] = weights_of(Part::Forearm)[1];
        }
        rows.push(Row { role, body: body.clone(), joint: joint.clone(), rot, pos, scale, weights });
    }
    let text = config_json(&rows, human.height);
    IkConfig::from_json_str(&text, source)
}

/// A role-named config ([`derive()`] against [`HumanBody::canonical`]) bound to `human` (see
/// the module docs) on `model` (with its `roles`). Entries whose human name is not a role, or
/// whose role the skeleton lacks, are errors naming them.
pub fn bind(
    config: &IkConfig,
    human: &HumanBody,
    model: &Model,
    roles: &RobotRoles,
) -> Result<IkConfig, Error> {
    let canonical = HumanBody::canonical();
    let robot = robot_side(model, roles);
    let human = &*human.for_robot(&robot);
    let frames = &robot.frames;
    let mut data = Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let role_of = |name: &str| {
        Role::from_name(name).ok_or_else(|| Error::Config {
            at: config.source.clone(),
            message: format!("`{name}` is not a role name: the config is not role-named"),
        })
    };
    let missing = |role: Role| Error::Config {
        at: config.source.clone(),
        message: format!("the skeleton ({}) has no {role}", human.source),
    };
    let factor = |role: Role| -> Result<f64, Error> {
        let c = canonical.paths.get(&role).copied().unwrap_or(1.0);
        let h = human.paths.get(&role).copied().ok_or_else(|| missing(role))?;
        Ok(if h > 0.0 { c / h } else { 1.0 })
    };
    let scale_of = |name: &str| -> Result<f64, Error> {
        let role = role_of(name)?;
        Ok(config.scale_of(name).unwrap_or(1.0) * factor(role)?)
    };
    let root_name = Role::Pelvis.name();
    let canonical_root = config.scale_of(root_name).unwrap_or(1.0);
    let bound_root = scale_of(root_name)?;
    let mut rows = Vec::new();
    let mut seen = Vec::new();
    for e in config.ik_match_table1.iter().chain(&config.ik_match_table2) {
        if seen.contains(&e.robot_body) {
            continue;
        }
        seen.push(e.robot_body.clone());
        let role = role_of(&e.human_body)?;
        let joint = human.joints.get(&role).ok_or_else(|| missing(role))?;
        let frame = human.frame_offsets.get(&role).ok_or_else(|| missing(role))?;
        let rot = frame * e.rot_offset;
        let scale = scale_of(&e.human_body)?;
        // The offset fitted to the canonical human is replaced by the one fitted to this
        // human; what the file adds to it (an edit) is kept.
        let origin = match (model.body_id(&e.robot_body), roles.roles.get(&role), frames.get(&role))
        {
            (Some(b), Some(r), Some(c)) => data.xpos.get(b).map(|x| c.inverse() * (x - r.point)),
            _ => None,
        };
        let written = config.scale_of(&e.human_body).unwrap_or(1.0);
        let fit = |h: &HumanBody, root: f64, s: f64| {
            fitted_offset(&robot, h, role, origin?, e.rot_offset, root, s)
        };
        let pos = match (fit(&canonical, canonical_root, written), fit(human, bound_root, scale)) {
            (Some(c), Some(h)) => e.pos_offset + h - c,
            _ => e.pos_offset,
        };
        rows.push((
            e.clone(),
            // The file's weights are kept (below): the row's are not used.
            Row {
                role,
                body: e.robot_body.clone(),
                joint: joint.clone(),
                rot,
                pos,
                scale,
                weights: [0.0; 4],
            },
        ));
    }
    let height = human.height * config.human_height_assumption / canonical.height;
    let mut text = String::new();
    write_header(&mut text, config, &human.joints, height);
    let scales: Vec<(String, f64)> = config
        .human_scale_table
        .iter()
        .map(|(name, _)| {
            let role = role_of(name)?;
            Ok((human.joints.get(&role).ok_or_else(|| missing(role))?.clone(), scale_of(name)?))
        })
        .collect::<Result<_, Error>>()?;
    write_scales(&mut text, &scales);
    for (k, table) in [&config.ik_match_table1, &config.ik_match_table2].into_iter().enumerate() {
        let entries: Vec<TableRow> = table
            .iter()
            .filter_map(|e| {
                let (_, row) = rows.iter().find(|(o, _)| o.robot_body == e.robot_body)?;
                Some((
                    row.body.clone(),
                    row.joint.clone(),
                    e.pos_weight,
                    e.rot_weight,
                    row.pos,
                    row.rot,
                ))
            })
            .collect();
        write_table(&mut text, k + 1, &entries, k == 1);
    }
    IkConfig::from_json_str(&text, &config.source)
}

/// Whether every human body of `config` is a role name (a role-named config).
#[must_use]
pub fn is_role_named(config: &IkConfig) -> bool {
    let names = config
        .human_scale_table
        .iter()
        .map(|(n, _)| n)
        .chain(config.ik_match_table1.iter().map(|e| &e.human_body))
        .chain(config.ik_match_table2.iter().map(|e| &e.human_body));
    let mut any = false;
    for n in names {
        if Role::from_name(n).is_none() {
            return false;
        }
        any = true;
    }
    any
}

/// The weights of `part` ([`WEIGHTS`]). A robot without a chest role (its arms hang from the
/// pelvis body: no waist) tracks its pelvis with the larger of the pelvis's and the chest's
/// weights: that body is its chest too, and with the pelvis's rotation weight (10) against
/// the upper arms' (100) arms that cannot reach their targets tilt the whole robot.
fn weights_of(part: Part) -> [f64; 4] {
    WEIGHTS.iter().find(|(q, _)| *q == part).map_or([0.0; 4], |w| w.1)
}

/// Hinges from the chest (else the pelvis) down to the upper arm's body (`role`), included.
fn shoulder_hinges(model: &Model, roles: &RobotRoles, role: Role) -> usize {
    let (Some(arm), Some(top)) =
        (roles.body(role), roles.body(Role::Chest).or(roles.body(Role::Pelvis)))
    else {
        return 0;
    };
    let mut count = 0;
    let mut b = arm;
    while b != top && b != 0 {
        let Some(body) = model.bodies.get(b) else { break };
        count += model
            .joints
            .iter()
            .skip(body.jnt_adr)
            .take(body.jnt_num)
            .filter(|j| j.kind == mjcf::JointType::Hinge)
            .count();
        b = body.parent;
    }
    count
}

fn weights(part: Part, robot_has_chest: bool) -> [f64; 4] {
    let of = weights_of;
    let own = of(part);
    if part != Part::Pelvis || robot_has_chest {
        return own;
    }
    let chest = of(Part::Chest);
    let mut out = own;
    for (o, c) in out.iter_mut().zip(chest) {
        *o = o.max(c);
    }
    out
}

fn config_json(rows: &[Row], height: f64) -> String {
    let joints: BTreeMap<Role, String> = rows.iter().map(|r| (r.role, r.joint.clone())).collect();
    let mut text = String::new();
    let pelvis = rows.iter().find(|r| r.role == Role::Pelvis);
    let _ = write!(
        text,
        "{{\n  \"robot_root_name\": \"{}\",\n  \"human_root_name\": \"{}\",\n  \"ground_height\": 0.0,\n  \"human_height_assumption\": {},\n  \"use_ik_match_table1\": true,\n  \"use_ik_match_table2\": true,\n",
        escape(pelvis.map_or("", |r| r.body.as_str())),
        escape(joints.get(&Role::Pelvis).map_or("", String::as_str)),
        number(height)
    );
    let scales: Vec<(String, f64)> = SCALE_ORDER
        .iter()
        .filter_map(|role| rows.iter().find(|r| r.role == *role))
        .map(|r| (r.joint.clone(), r.scale))
        .collect();
    write_scales(&mut text, &scales);
    for (k, table) in [0, 2].iter().enumerate() {
        let entries: Vec<TableRow> = rows
            .iter()
            .map(|r| {
                let weight = |k: usize| r.weights.get(k).copied().unwrap_or(0.0);
                (r.body.clone(), r.joint.clone(), weight(*table), weight(table + 1), r.pos, r.rot)
            })
            .collect();
        write_table(&mut text, k + 1, &entries, k == 1);
    }
    text
}

fn write_header(
    text: &mut String,
    config: &IkConfig,
    joints: &BTreeMap<Role, String>,
    height: f64,
) {
    let root = Role::from_name(&config.human_root_name)
        .and_then(|r| joints.get(&r))
        .cloned()
        .unwrap_or_else(|| config.human_root_name.clone());
    let _ = write!(
        text,
        "{{\n  \"robot_root_name\": \"{}\",\n  \"human_root_name\": \"{}\",\n  \"ground_height\": {},\n  \"human_height_assumption\": {},\n  \"use_ik_match_table1\": {},\n  \"use_ik_match_table2\": {},\n",
        escape(&config.robot_root_name),
        escape(&root),
        number(config.ground_height),
        number(height),
        config.use_ik_match_table1,
        config.use_ik_match_table2
    );
}

fn write_scales(text: &mut String, scales: &[(String, f64)]) {
    text.push_str("  \"human_scale_table\": {\n");
    for (i, (name, s)) in scales.iter().enumerate() {
        let comma = if i + 1 < scales.len() { "," } else { "" };
        let _ = writeln!(text, "    \"{}\": {}{comma}", escape(name), number(*s));
    }
    text.push_str("  },\n");
}

fn write_table(text: &mut String, number_: usize, entries: &[TableRow], last: bool) {
    let _ = writeln!(text, "  \"ik_match_table{number_}\": {{");
    for (i, (body, joint, wp, wr, p, q)) in entries.iter().enumerate() {
        let comma = if i + 1 < entries.len() { "," } else { "" };
        let q = if q.w < 0.0 { -q.into_inner() } else { q.into_inner() };
        let _ = writeln!(
            text,
            "    \"{}\": [\"{}\", {}, {}, [{}, {}, {}], [{}, {}, {}, {}]]{comma}",
            escape(body),
            escape(joint),
            number(*wp),
            number(*wr),
            number(p.x),
            number(p.y),
            number(p.z),
            number(q.w),
            number(q.i),
            number(q.j),
            number(q.k)
        );
    }
    text.push_str(if last { "  }\n}\n" } else { "  },\n" });
}

/// A JSON number: rounded to 1e-9 (offsets to a nanometre, quaternions to 1e-9), `-0` as 0.
fn number(v: f64) -> String {
    let r = (v * 1e9).round() / 1e9;
    let r = if r == 0.0 { 0.0 } else { r };
    if r.fract() == 0.0 && r.abs() < 1e15 {
        format!("{r:.1}")
    } else {
        format!("{r}")
    }
}

fn escape(s: &str) -> String {
    serde_json::to_string(s).map_or_else(|_| s.to_owned(), |q| q[1..q.len() - 1].to_owned())
}

/// Which config [`choose`] picked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The `--config` file as written.
    Given,
    /// A role-named `--config` file, bound to the skeleton ([`bind`]).
    Bound,
    /// The robot's tuned config (GMR's, for LAFAN1-named skeletons).
    Tuned,
    /// Derived from the robot's and the skeleton's roles ([`derive()`]).
    Derived,
}

/// The config to use and a one-line account of it.
#[derive(Debug, Clone)]
pub struct Chosen {
    pub config: IkConfig,
    pub choice: Choice,
    pub summary: String,
}

/// The joint frames a tuned config was written for, as a skeleton's zero pose shows them:
/// there every joint's frame is the file's axes, so the direction each bone points in (file
/// axes) says where the joint frames sit on the body. Two skeletons with the same names,
/// the same bone directions and the same up axis give the same joint rotations for the same
/// posture, so a config's rotation offsets written for one hold for the other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointFrames {
    /// Whose frames these are, for messages.
    pub name: &'static str,
    /// Direction of every trunk and limb bone in the zero pose (file axes): pelvis → chest
    /// → head, hip → knee → ankle → toe, shoulder → elbow → wrist.
    pub bone: [f64; 3],
    /// Direction from the right hip to the left one in the zero pose (file axes).
    pub left: [f64; 3],
    /// The file axis that points up in the motion (GMR converts it with its Y-up turn).
    pub up: fk::UpAxis,
}

/// LAFAN1's joint frames (Ubisoft La Forge's skeleton), which GMR's `bvh_lafan1_to_*`
/// configs, the tuned configs shipped, are written for: Y up; in the zero pose the skeleton
/// lies along +X (every bone along its parent joint's +X), its left hip at +Z.
pub const LAFAN1_FRAMES: JointFrames = JointFrames {
    name: "LAFAN1",
    bone: [1.0, 0.0, 0.0],
    left: [0.0, 0.0, 1.0],
    up: fk::UpAxis::PosY,
};

/// Largest angle between a zero-pose bone (or the hips) and the reference direction for
/// which the joint frames count as the reference's: LAFAN1's own bones are within 5° of
/// +X, a skeleton in another zero pose (standing in a T-pose, A-pose, arms down) has bones
/// 90° off.
pub const FRAMES_AGREE: f64 = 30.0 * std::f64::consts::PI / 180.0;

/// The bones [`JointFrames::differs`] compares, as (from, to) roles; a pair with a role the
/// skeleton lacks is skipped (the trunk then runs from the pelvis to the head).
const FRAME_BONES: [(Role, Role); 13] = [
    (Role::Pelvis, Role::Chest),
    (Role::Chest, Role::Head),
    (Role::LeftThigh, Role::LeftShin),
    (Role::LeftShin, Role::LeftFoot),
    (Role::LeftFoot, Role::LeftToe),
    (Role::RightThigh, Role::RightShin),
    (Role::RightShin, Role::RightFoot),
    (Role::RightFoot, Role::RightToe),
    (Role::LeftUpperArm, Role::LeftForearm),
    (Role::LeftForearm, Role::LeftHand),
    (Role::RightUpperArm, Role::RightForearm),
    (Role::RightForearm, Role::RightHand),
    (Role::Pelvis, Role::Head),
];

impl JointFrames {
    /// `None` when `humanoid`, read with the axis convention `axes`, has these joint frames:
    /// every bone of its zero pose ([`fk::Humanoid::rest_points`]) and its hips within
    /// [`FRAMES_AGREE`] of these directions, and the file turned to Z up as these frames'
    /// up axis is. Otherwise what differs.
    #[must_use]
    pub fn differs(&self, humanoid: &Humanoid, axes: fk::AxisConvention) -> Option<String> {
        let axes = match axes {
            fk::AxisConvention::Auto => humanoid.up.convention(),
            given => given,
        };
        if axes != self.up.convention() {
            return Some(format!("it is not turned to Z up from {}'s {} up", self.name, self.up));
        }
        let at = |r: &Role| humanoid.rest_points.get(r);
        let chest = humanoid.rest_points.contains_key(&Role::Chest);
        let mut checks: Vec<(String, Vector3<f64>, Vector3<f64>)> = FRAME_BONES
            .iter()
            .filter(|(from, to)| !(chest && *from == Role::Pelvis && *to == Role::Head))
            .filter_map(|(from, to)| {
                let bone = at(to)? - at(from)?;
                Some((format!("{from} → {to}"), bone, Vector3::from(self.bone)))
            })
            .collect();
        if let (Some(l), Some(r)) = (at(&Role::LeftThigh), at(&Role::RightThigh)) {
            checks.push(("right → left hip".to_owned(), l - r, Vector3::from(self.left)));
        }
        checks.into_iter().find_map(|(what, bone, expected)| {
            let angle = bone.angle(&expected);
            let agrees = angle <= FRAMES_AGREE;
            (bone.norm() == 0.0 || !agrees).then(|| {
                format!("its zero pose's {what} is {:.0}° from {}'s", angle.to_degrees(), self.name)
            })
        })
    }
}

/// The human half of `bvh` (FK without a height override: the measured height).
pub fn human_body(bvh: &bvh::Bvh, fk: &fk::FkOptions, source: &str) -> Result<HumanBody, Error> {
    let mut options = fk.clone();
    options.height = None;
    let (motion, report) = fk::human_motion(bvh, &options)?;
    let humanoid = report.humanoid.map_err(Error::Fk)?;
    HumanBody::from_motion(&humanoid, &motion, report.ground, report.height, source)
}

/// The config for retargeting `bvh` onto `model` when no config was written for the pair:
/// - `given` (`--config`): as written, or bound to the skeleton when it is role-named;
/// - `tuned` (a config written for [`LAFAN1_FRAMES`], as the shipped ones are) with `gmr`
///   (`--gmr`): the tuned config whenever the skeleton has the human bodies it names (GMR's
///   exact behaviour), else the derived one (GMR stops with a `KeyError` there);
/// - `tuned` when the skeleton has its human body names and LAFAN1's joint frames
///   ([`JointFrames::differs`]: a property of the skeleton, whatever the motion);
/// - otherwise the config derived from the robot's and the skeleton's roles.
///
/// `robot` names the robot in messages.
pub fn choose(
    model: &Model,
    robot: &str,
    bvh: &bvh::Bvh,
    fk_options: &fk::FkOptions,
    given: Option<IkConfig>,
    tuned: Option<&IkConfig>,
    gmr: bool,
) -> Result<Chosen, Error> {
    if let Some(config) = given {
        if !is_role_named(&config) {
            let summary = format!("config {} as given", config.source);
            return Ok(Chosen { config, choice: Choice::Given, summary });
        }
        let human = human_body(bvh, fk_options, "the skeleton")?;
        let roles = RobotRoles::recognise(model)?;
        let bound = bind(&config, &human, model, &roles)?;
        let summary = format!("config {} (role-named), bound to the skeleton", config.source);
        return Ok(Chosen { config: bound, choice: Choice::Bound, summary });
    }
    let mut why_not = String::new();
    if let Some(tuned) = tuned {
        let names = fk::body_names(bvh, fk_options)?;
        let fits = tuned.validate(model, &names);
        if gmr && fits.is_ok() {
            let summary = format!("config {} (tuned; --gmr)", tuned.source);
            return Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary });
        }
        if gmr {
            // GMR itself stops here (a KeyError on the first missing body); GMR's solve with
            // the derived config is the nearest thing, and what `--gmr` comparisons need.
            why_not = format!(
                " (--gmr: GMR's solve; the tuned {} names bodies the skeleton lacks)",
                tuned.source
            );
        } else if fits.is_ok() {
            let humanoid = fk::recognise(bvh, &fk_options.roles)?;
            let frames = LAFAN1_FRAMES;
            match frames.differs(&humanoid, fk_options.axes) {
                None => {
                    let summary = format!(
                        "config {} (tuned: the skeleton has its names and {}'s joint frames)",
                        tuned.source, frames.name
                    );
                    return Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary });
                }
                Some(reason) => {
                    why_not = format!(
                        " (not the tuned {}: the skeleton has its names, but {reason})",
                        tuned.source
                    );
                }
            }
        }
    }
    let roles = RobotRoles::recognise(model)?;
    let human = human_body(bvh, fk_options, "the skeleton")?;
    let source = format!("<derived for {robot}>");
    let derived = derive(model, &roles, &human, &source)?;
    let summary = format!("config derived from the roles of {robot} and of the skeleton{why_not}");
    Ok(Chosen { config: derived, choice: Choice::Derived, summary })
}

/// Active entries of the first table (for tests and reports).
#[must_use]
pub fn active_entries(config: &IkConfig) -> Vec<&MatchEntry> {
    config.ik_match_table1.iter().filter(|e| e.is_active()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_human_frames_are_identity_and_paths_are_winter() {
        let points = canonical_points();
        let frames = fk::canonical_frames(&points);
        for (role, q) in &frames {
            if role.part() != Part::Clavicle {
                assert!(q.angle() < 1e-12, "{role}");
            }
        }
        let human = HumanBody::canonical();
        let h = CANONICAL_HEIGHT;
        // Thigh 0.245 h, shin 0.246 h; the hip 0.05 h to the side.
        assert!((human.paths[&Role::LeftFoot] - (0.245 + 0.246) * h).abs() < 1e-12);
        assert!((human.paths[&Role::LeftThigh] - 0.05 * h).abs() < 1e-12);
        assert!((human.paths[&Role::Pelvis] - (0.245 + 0.246 + 0.039) * h).abs() < 1e-12);
    }

    /// A human foot that stands flat, then rolls onto its ball (a pivot `l` ahead of the
    /// ankle and `h` below it): the robot's sole (a box reaching past the pivot) must end
    /// up with its front bottom edge at the pivot, which is on the floor in every posture
    /// (the edge [`SOLE_CLEARANCE`] above it).
    #[test]
    fn the_sole_fit_puts_the_sole_on_the_floor_when_the_foot_rolls_onto_its_ball() {
        let (l, h) = (0.09, 0.07);
        let sole = SoleGeom {
            kind: mjcf::GeomType::Box,
            size: [0.1, 0.04, 0.01],
            pos: Vector3::new(0.03, 0.0, -0.03),
            rot: UnitQuaternion::identity(),
        };
        let mut human = HumanBody::canonical();
        human.postures = [0.0f64, 5.0, 10.0, 20.0, 30.0, 40.0]
            .iter()
            .map(|deg| {
                // Toe down: a turn about +y; the ankle rises about the pivot on the floor.
                let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
                let ankle = Vector3::new(0.0, 0.1, 0.0) - q * Vector3::new(l, 0.0, -h);
                let points = [(Role::Pelvis, Vector3::new(0.0, 0.0, 0.9)), (Role::LeftFoot, ankle)]
                    .into_iter()
                    .collect();
                let frames = [(Role::LeftFoot, q)].into_iter().collect();
                Posture { points, frames, feet_down: [true, false] }
            })
            .collect();
        let prior = Vector3::new(0.05, 0.01, 0.0);
        let fit = sole_fit(&[sole], &human, Role::LeftFoot, 1.0, 1.0, prior).unwrap();
        // Body origin + front bottom edge (0.13, ·, −0.04) = pivot (l, ·, −h) from the ankle,
        // SOLE_CLEARANCE above it (to a few mm: the prior, 9 cm off, still pulls a little).
        assert!((fit.x - (l - 0.13)).abs() < 3e-3, "{fit:?}");
        assert!((fit.z - (-h + 0.04 + SOLE_CLEARANCE)).abs() < 1e-3, "{fit:?}");
        // Tilts say nothing about the sideways offset: the prior's.
        assert!((fit.y - prior.y).abs() < 1e-9, "{fit:?}");
        // The right foot never touches: no fit.
        assert!(sole_fit(&[sole], &human, Role::RightFoot, 1.0, 1.0, prior).is_none());
    }

    /// A limb of three joints over 20 frames: the top one at `top`, the middle one `upper`
    /// below it, the end one `lower` below that, bent by `step` more each frame about
    /// `axis` (world); the middle and end joints turn with the bend.
    fn bending_limb(
        top: Vector3<f64>,
        (upper, lower): (f64, f64),
        axis: nalgebra::Unit<Vector3<f64>>,
        step: f64,
        index: &dyn Fn(Role) -> Option<usize>,
        roles: [Role; 3],
    ) -> HumanMotion {
        let frames = 20;
        let (mut positions, mut orientations) = (Vec::new(), Vec::new());
        for f in 0..frames {
            let bend = UnitQuaternion::from_axis_angle(&axis, f as f64 * step);
            let middle = top - Vector3::new(0.0, 0.0, upper);
            positions.extend([top, middle, middle + bend * Vector3::new(0.0, 0.0, -lower)]);
            orientations.extend([UnitQuaternion::identity(), bend, bend]);
        }
        assert_eq!(roles.map(index), [Some(0), Some(1), Some(2)]);
        HumanMotion {
            fps: 30.0,
            body_names: roles.map(|r| r.name().to_owned()).to_vec(),
            num_frames: frames,
            positions,
            orientations,
        }
    }

    /// A leg whose thigh and shin frames carry a 30° twist about the bone (as fk's do when
    /// the subject's hip was turned in the reference pose), walking with the knee bending
    /// about world +y: the twist is taken out, so the knee flexes about the frames' +y. A
    /// leg that never bends is left as it is.
    #[test]
    fn flexion_twist_turns_thigh_and_shin_frames_to_the_knee_axis() {
        let leg = [Role::LeftThigh, Role::LeftShin, Role::LeftFoot];
        let index = |role: Role| leg.iter().position(|&r| r == role);
        // The knee bends backward (the shin turns about +y) by 0..54°.
        let motion = bending_limb(
            Vector3::new(0.0, 0.1, 0.9),
            (0.4, 0.4),
            Vector3::y_axis(),
            0.05,
            &index,
            leg,
        );
        let twist = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 30f64.to_radians());
        let mut offsets: BTreeMap<Role, UnitQuaternion<f64>> =
            [(Role::LeftThigh, twist), (Role::LeftShin, twist)].into_iter().collect();
        let picked: Vec<usize> = (0..motion.num_frames).collect();
        flexion_twist(&motion, &index, &mut offsets, &picked, Side::Left, Limb::Leg);
        for role in [Role::LeftThigh, Role::LeftShin] {
            assert!(offsets[&role].angle() < 1e-9, "{role}: {:?}", offsets[&role]);
        }
        // Straight all along: nothing says how the knee flexes.
        let mut offsets: BTreeMap<Role, UnitQuaternion<f64>> =
            [(Role::LeftThigh, twist)].into_iter().collect();
        flexion_twist(&motion, &index, &mut offsets, &[0], Side::Left, Limb::Leg);
        assert!((offsets[&Role::LeftThigh].angle() - 30f64.to_radians()).abs() < 1e-12);
    }

    /// An arm whose frames carry a 100° twist about the bone (a reference pose taken
    /// mid-motion), the elbow flexing forward (the forearm turns about world −y): all three
    /// frames are turned back, the hand by the forearm's turn, and the turns are returned.
    #[test]
    fn flexion_twist_turns_the_arm_frames_to_the_elbow_axis() {
        let arm = [Role::LeftUpperArm, Role::LeftForearm, Role::LeftHand];
        let index = |role: Role| arm.iter().position(|&r| r == role);
        let motion = bending_limb(
            Vector3::new(0.0, 0.2, 1.4),
            (0.3, 0.25),
            -Vector3::y_axis(),
            0.06,
            &index,
            arm,
        );
        let twist = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 100f64.to_radians());
        let mut offsets: BTreeMap<Role, UnitQuaternion<f64>> =
            arm.iter().map(|&r| (r, twist)).collect();
        let picked: Vec<usize> = (0..motion.num_frames).collect();
        let turns = flexion_twist(&motion, &index, &mut offsets, &picked, Side::Left, Limb::Arm);
        for role in arm {
            assert!(offsets[&role].angle() < 1e-9, "{role}: {:?}", offsets[&role]);
            assert!((turns[&role] * twist).angle() < 1e-9, "{role}: {:?}", turns[&role]);
        }
    }

    #[test]
    fn numbers_round_trip_and_stay_readable() {
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-1e-12), "0.0");
        assert_eq!(number(100.0), "100.0");
        assert_eq!(number(0.123456789123), "0.123456789");
        assert_eq!(escape("a\"b"), "a\\\"b");
    }
}
