//! The joint frames a tuned config was written for ([`JointFrames`], [`LAFAN1_FRAMES`]):
//! whether a skeleton's hold them, so that the tuned config's rotation offsets hold for it.

use fk::{Humanoid, Role};
use nalgebra::Vector3;

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
