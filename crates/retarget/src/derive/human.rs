//! The human half of a derived config ([`HumanBody`]): a skeleton's joint per role, its frame
//! offsets (limbs turned by their knee and elbow flexion, feet laid flat), its proportions
//! (path lengths from the hip midpoint) and sampled postures; the canonical human; the
//! chains of the canonical pose both sides' segments follow.

use std::borrow::Cow;
use std::collections::BTreeMap;

use fk::{HumanMotion, Humanoid, Part, Role, Side};
use nalgebra::{UnitQuaternion, Vector3};

use crate::Error;

/// A foot counts as flat on the floor while its ankle is within this of its flat height (m).
pub(super) const FLAT_FOOT: f64 = 0.03;

/// Frames of a motion sampled, evenly, for the proportions and the offset fits.
const POSTURES: usize = 256;

/// Height of the canonical human (m).
pub const CANONICAL_HEIGHT: f64 = 1.75;

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
    /// through the role joints ([`module docs`](super)); the pelvis's entry is the standing hip
    /// height (thigh + shin + ankle height).
    pub paths: BTreeMap<Role, f64>,
    /// Sampled postures (up to 256 frames of the motion; the canonical human has one): what
    /// the position offsets are fitted to ([`module docs`](super)).
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
            return Err(fk::Error::NoFrames.into());
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
    /// This human as a robot is matched with: itself, but for a robot whose arms do not flex
    /// forward at `qpos0` (`arms_sideways`, the robot side's), whose arms keep fk's frames
    /// (the `arm_twists` undone). Measured: on ToddlerBot, whose elbows bend sideways at `qpos0`,
    /// the turned arms twisted its torso 40° towards them (rotation error 20.9° → 31.6° on the
    /// LAFAN1 walk; better on the jumps, 21.6° → 17.2°). Taking the other side of its elbow's
    /// range as flexion instead gives 22.6° and 17.4°: its flexion sense, not the turn, may be
    /// what is wrong there.
    pub(super) fn for_robot(&self, arms_sideways: bool) -> Cow<'_, HumanBody> {
        if !arms_sideways {
            return Cow::Borrowed(self);
        }
        let mut out = self.clone();
        for (role, turn) in &self.arm_twists {
            out.turn(*role, turn.inverse());
        }
        out.arm_twists.clear();
        Cow::Owned(out)
    }

    /// Turns the canonical frames of `role` by `turn` (on the right: about the frame's own
    /// axes), its frame offset and every posture's frame.
    pub(super) fn turn(&mut self, role: Role, turn: UnitQuaternion<f64>) {
        if let Some(offset) = self.frame_offsets.get_mut(&role) {
            *offset *= turn;
        }
        for posture in &mut self.postures {
            if let Some(frame) = posture.frames.get_mut(&role) {
                *frame *= turn;
            }
        }
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
pub(super) fn paths(points: &BTreeMap<Role, Vector3<f64>>, ankle: f64) -> BTreeMap<Role, f64> {
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
pub(super) const POSE_CHAINS: [(Role, &[Role]); 17] = [
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
pub(super) fn segments(
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
}
