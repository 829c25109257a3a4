//! Planted feet: the source's contact phases turned into foot targets that stand still on
//! the floor.
//!
//! Given the per-frame targets (GMR's, from the config) and the source's contact labels:
//!
//! 1. **Floor**: all targets move by one vertical shift per clip, the median over the
//!    stance samples of "how far the foot target must move for its sole to rest on z = 0"
//!    (the source's floor becomes the robot's floor; jumps keep their height). Then, in
//!    every frame, two feet alongside each other are moved apart sideways until their soles
//!    are [`FootPlanOptions::sole_gap`] apart (the scaled human's feet can pass closer than
//!    the robot's fit).
//! 2. **Planting**: during a stance phase the foot target's horizontal position and yaw are
//!    the phase's anchor ([`Anchor`]), its z puts the sole's lowest point at
//!    [`FootPlanOptions::clearance`], and the foot task's weights are multiplied by
//!    [`FootPlanOptions::stance_weight`]; the sole's bottom points are point tasks that hold it
//!    there ([`SolePoint`]). The foot stands on its whole sole: the human foot's tilt is
//!    scaled down until the sole's bottom points are within [`FootPlanOptions::sole_band`] of
//!    each other, except while the other foot stands too, when it rolls with the human's
//!    (heel strike, toe off), faded in and out over [`FootPlanOptions::roll_s`].
//!    A phase over which the source foot turns through more than
//!    [`FootPlanOptions::pivot_turn`] (45°) is a **pivot**: the planted foot turns with the
//!    source's yaw about its toe point (which stays on the anchor), as a foot turning on its
//!    ball does, instead of holding the mean yaw and twisting the leg by half the turn.
//!    Overlapping stance phases of the two feet are kept apart; where the left foot stands
//!    to the right of the right one, they are a [`Crossing`], which the solve can ask to be
//!    planned again side by side ([`plan_uncrossing`]) when the robot cannot stand in it.
//! 3. **Swing**: out of stance the sole stays at least [`FootPlanOptions::swing_clearance`]
//!    above the floor ([`FootPlan::swing_floor`], which the solve holds as that sole's
//!    floor), risen to it over [`FootPlanOptions::lift_s`] after lift-off and left over as
//!    long before touch-down; in those frames the sole points that stood on the floor at
//!    lift-off (stand on it at touch-down) are held where they were (will be), seen from
//!    above: a foot leaves the floor by lifting its last contact, not by sliding it.
//!
//! The solve ([`crate::solve`]) sees every frame at once: there is no blending of targets
//! into and out of stance; the accelerations cost it makes the transitions.
//!
//! The sole is every collision primitive on the foot body and its descendants, placed as at
//! `qpos0` relative to the foot body; a foot without collision geometry stands on the
//! uniform box of its mass and inertia (`inertia_sole`).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frame and slot indices are bounded by `plan`'s `targets.len() / slots` and the contact
// labels' lengths, which `plan` clips to it; body and geom ids come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, GeomType, Model};
use std::ops::Range;

use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::constraints::{collision_primitives, support_offset};
use crate::contact::phases;
use crate::lie::Pose;
use crate::motion::FootContacts;

/// Where a planted foot stays during its stance phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// Where the phase began (needs no look-ahead).
    PhaseStart,
    /// The mean over the phase of the free target (position) and its yaw (circular mean).
    PhaseMean,
}

/// Tunables of the foot plan (`plan`).
#[derive(Debug, Clone, PartialEq)]
pub struct FootPlanOptions {
    pub anchor: Anchor,
    /// Planting starts this long before the source's touch-down (s), so that the foot has
    /// arrived when the source's contact begins.
    pub lead_s: f64,
    /// Factor on the foot task's weights while planted.
    pub stance_weight: f64,
    /// Height of the sole's lowest point above the floor while planted (m).
    pub clearance: f64,
    /// Weight of the contact-point task that holds the sole's contact point on its anchor
    /// in stance (the foot tasks' position weights are 50 in GMR's configs).
    pub contact_weight: f64,
    /// Least horizontal gap (m) between the two soles when both are planted at once: anchors
    /// closer than this are moved apart, half the shortfall each, along the footprints'
    /// separating axis, so that the planted feet do not ask for the soles inside each other,
    /// which the self-collision constraint then fights. In every frame, soles alongside each
    /// other are also kept this far apart sideways (`keep_feet_apart`), before planting.
    pub sole_gap: f64,
    /// Least height (m) of the sole's lowest point above the floor out of stance, once the
    /// foot has risen ([`FootPlanOptions::lift_s`]); the solve holds it as the sole's floor
    /// (`FootPlan::swing_floor`). A foot is either planted or clear of the floor: the
    /// dynamics check and the report's skating on the floor count a sole within 1 cm as on
    /// it. (3.2 cm, held from the first frame off the floor, hiked ToddlerBot's short legs:
    /// its walk's jitter 12.5 rad/s² against 10.0 at 1.5 cm, `--gmr` 7.6.)
    pub swing_clearance: f64,
    /// Time (s) over which the swing clearance fades in after lift-off and out before
    /// touch-down (smoothstep).
    pub lift_s: f64,
    /// A stance phase over which the source foot's yaw turns through more than this (rad,
    /// largest minus smallest) is a **pivot**: the planted foot turns with the source's, about
    /// its toe point (`RobotFoot::toe_point`), which stays where the anchor puts it. Holding the mean yaw there
    /// (a dancer or a jumper turning on one foot) twisted the leg by half the turn: 45° on
    /// the LAFAN1 jumps, where the PM01's hip then went past its yaw range's middle and
    /// stayed there for the 2,000 frames that followed. A turning sole sweeps the floor, so
    /// the threshold trades rotation error for the report's sliding share: on the G1 jumps
    /// 30° gives 6.78° / 15.4 %, 45° 6.84° / 13.3 %, 60° 6.99° / 12.1 %, none 7.42° / 9.7 %.
    pub pivot_turn: f64,
    /// A planted foot stands on its whole sole: its tilt from standing flat is scaled down
    /// until its bottom points are within this height (m) of each other (the dynamics check
    /// counts the points within 1 cm of the floor as support; a sole on its edge supports no
    /// torque about that edge). Copied whole, the tilt GMR's G1 config gives the feet (4°
    /// nose-up) stood them on their heel edges: 30 % of the LAFAN1 walk's frames on two
    /// points, and the motion needed more than 0.1 m·g of wrench the feet could not give in
    /// a third of its frames.
    pub sole_band: f64,
    /// While the other foot is planted too, a planted foot rolls with the human's (heel
    /// strike, toe off: the other foot carries the centre of pressure); the roll fades in and
    /// out over this time (s) at the double support's ends.
    pub roll_s: f64,
}

impl Default for FootPlanOptions {
    fn default() -> Self {
        FootPlanOptions {
            anchor: Anchor::PhaseMean,
            lead_s: 1.0 / 30.0,
            stance_weight: 2.0,
            clearance: 0.002,
            contact_weight: 400.0,
            sole_gap: 0.03,
            swing_clearance: 0.015,
            lift_s: 1.0 / 30.0,
            pivot_turn: 45f64.to_radians(),
            sole_band: 0.006,
            roll_s: 0.1,
        }
    }
}

/// A robot foot: the body whose task follows the human foot, and its sole.
#[derive(Debug, Clone)]
pub struct RobotFoot {
    pub body: usize,
    /// Target slot of the foot's task.
    pub slot: usize,
    /// Sole primitives: kind, size and pose relative to the foot body (at `qpos0`).
    sole: Vec<(GeomType, [f64; 3], Isometry3<f64>)>,
    /// The foot body's forward direction in its own frame (world +x at `qpos0`).
    forward: Vector3<f64>,
    /// The foot body's world orientation at `qpos0`: standing flat.
    rest: UnitQuaternion<f64>,
    /// The sole's bottom points in the foot frame (`bottom_points` of each primitive):
    /// where it stands on the floor.
    corners: Vec<Vector3<f64>>,
    /// The shin: target slot of the nearest ancestor body with a task, and the foot's
    /// orientation relative to it at `qpos0` (`shin⁻¹ ⊗ foot`).
    shin: Option<(usize, UnitQuaternion<f64>)>,
    /// The sole's collision geoms (none for a sole of inertia).
    pub geoms: Vec<usize>,
}

/// Sole bottom points higher than the lowest by this much (m) are not held vertically;
/// lower ones are held the more, the lower they are.
pub const CONTACT_PATCH: f64 = 0.01;

/// A point of a planted sole: where it is in the foot (`point`, foot frame), where it stays
/// (`at`, world), and the share of the contact weight that holds it horizontally and
/// vertically. Every bottom point of the sole (`bottom_points`: a box's corners, a bar's
/// ends, a ball) is held horizontally (so the foot neither slides nor turns, whatever tilt
/// the robot's ankle can reach); vertically, the points that touch the floor in the planted
/// pose (four standing flat, two on the toes or the heel), fading out over
/// [`CONTACT_PATCH`] above the lowest. A sole without bottom points is held at its lowest
/// point. The shares of one foot have a root sum of squares of 1 (per axis,
/// standing flat), so a foot's hold does not depend on how many points it has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolePoint {
    pub point: Vector3<f64>,
    pub at: Vector3<f64>,
    pub horizontal: f64,
    pub vertical: f64,
}

impl RobotFoot {
    /// `body` tracks target `slot`; its sole: the collision primitives of `sole_body` and its
    /// descendants, or where there are none its equivalent inertia box (`inertia_sole`;
    /// `None` when there is neither).
    #[must_use]
    pub fn new(
        model: &Model,
        body: usize,
        sole_body: usize,
        slot: usize,
        shin: Option<(usize, usize)>,
    ) -> Option<RobotFoot> {
        let mut data = Data::new(model);
        model.kinematics(&model.qpos0, &mut data);
        let body_pose = pose_of(&data.xpos[body], &data.xmat[body]);
        let inverse = body_pose.inverse();
        let geoms: Vec<usize> = collision_primitives(model)
            .into_iter()
            .filter(|&g| is_descendant(model, model.geoms[g].body, sole_body))
            .collect();
        let mut sole: Vec<_> = geoms
            .iter()
            .map(|&g| {
                let geom = pose_of(&data.geom_xpos[g], &data.geom_xmat[g]);
                (model.geoms[g].kind, model.geoms[g].size, inverse * geom)
            })
            .collect();
        if sole.is_empty() {
            // (From `xmat`, as the geoms' poses here, not `world`'s `xquat`: the two differ
            // by rounding, which the solve can carry to 1e-4 rad on the N1 mocap's walk.)
            let inertia = inertia_sole(model, sole_body)?;
            let at = pose_of(&data.xpos[inertia.body], &data.xmat[inertia.body]) * inertia.pose;
            sole.push((GeomType::Box, inertia.half, inverse * at));
        }
        let forward = data.xmat[body].transpose() * Vector3::x();
        let corners = sole
            .iter()
            .flat_map(|(kind, size, rel)| bottom_points(*kind, size, rel, &body_pose.rotation))
            .collect();
        let shin = shin.map(|(shin_body, shin_slot)| {
            let shin_rest = UnitQuaternion::from_matrix(&data.xmat[shin_body]);
            (shin_slot, shin_rest.inverse() * body_pose.rotation)
        });
        Some(RobotFoot {
            body,
            slot,
            sole,
            forward,
            rest: body_pose.rotation,
            corners,
            shin,
            geoms,
        })
    }

    /// Height of the sole's lowest point above the foot body's origin, for a body
    /// orientation `rot`.
    #[must_use]
    pub fn sole_offset(&self, rot: &UnitQuaternion<f64>) -> f64 {
        self.sole
            .iter()
            .map(|(kind, size, rel)| {
                let r = (rot * rel.rotation).to_rotation_matrix().into_inner();
                (rot * rel.translation.vector).z + support_offset(*kind, size, &r).z
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The toe point in the foot frame: the middle of the sole's two foremost bottom points
    /// (`bottom_points`; holosoma measures skating at a toe body), else the sole's lowest
    /// point at rest.
    #[must_use]
    pub fn toe_point(&self) -> Vector3<f64> {
        let mut corners = self.corners.clone();
        corners.sort_by(|a, b| self.forward.dot(b).total_cmp(&self.forward.dot(a)));
        match corners.as_slice() {
            [a, b, ..] => (a + b) / 2.0,
            _ => self.sole_low_point(&self.rest),
        }
    }

    /// The sole's lowest point for a body orientation `rot`, in the foot body's frame.
    #[must_use]
    pub fn sole_low_point(&self, rot: &UnitQuaternion<f64>) -> Vector3<f64> {
        let world = self
            .sole
            .iter()
            .map(|(kind, size, rel)| {
                let r = (rot * rel.rotation).to_rotation_matrix().into_inner();
                rot * rel.translation.vector + support_offset(*kind, size, &r)
            })
            .min_by(|a, b| a.z.total_cmp(&b.z))
            .unwrap_or_else(Vector3::zeros);
        rot.inverse() * world
    }

    /// `rot` with its tilt (from standing flat at its yaw) scaled down until the sole's
    /// bottom points are within `band` (m) of each other in height: a planted foot stands
    /// on its whole sole (the dynamics check counts the points within 1 cm of the floor as
    /// its support).
    #[must_use]
    pub fn within_band(&self, rot: &UnitQuaternion<f64>, band: f64) -> UnitQuaternion<f64> {
        let flat = self.flat(self.yaw(rot));
        let tilt = flat.inverse() * rot;
        let spread = |q: &UnitQuaternion<f64>| {
            let z = self.corners.iter().map(|c| (q * c).z);
            let (lo, hi) =
                z.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            hi - lo
        };
        let rest = spread(&flat);
        if self.corners.len() < 2 || spread(rot) - rest <= band {
            return *rot;
        }
        // The spread grows about linearly with the tilt's angle: a few rescalings settle it.
        let mut share = 1.0;
        for _ in 0..4 {
            let at = flat * UnitQuaternion::identity().slerp(&tilt, share);
            let over = spread(&at) - rest;
            if over <= band {
                break;
            }
            share *= band / over;
        }
        flat * UnitQuaternion::identity().slerp(&tilt, share)
    }

    /// The orientation of the foot standing flat (as at `qpos0`) with yaw `yaw`.
    fn flat(&self, yaw: f64) -> UnitQuaternion<f64> {
        let turn = wrap(yaw - self.yaw(&self.rest));
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turn) * self.rest
    }

    /// The sole points held at the planted `pose` ([`SolePoint`]), their weights scaled
    /// by `scale` (fading in and out around a stance phase).
    #[must_use]
    pub fn contact_points(&self, pose: &Pose, scale: f64) -> Vec<SolePoint> {
        let q = quat(pose);
        let world = |p: &Vector3<f64>| pose.pos + q * p;
        let low = self.sole_low_point(&q);
        let floor = world(&low).z;
        if self.corners.is_empty() {
            let share = scale;
            return vec![SolePoint {
                point: low,
                at: world(&low),
                horizontal: share,
                vertical: share,
            }];
        }
        let share = scale / (self.corners.len() as f64).sqrt();
        self.corners
            .iter()
            .map(|c| {
                let at = world(c);
                let lifted = ((at.z - floor) / CONTACT_PATCH).clamp(0.0, 1.0);
                SolePoint {
                    point: *c,
                    at,
                    horizontal: share,
                    vertical: share * (1.0 - smoothstep(lifted)),
                }
            })
            .collect()
    }

    /// Yaw (rad, about world z) of the foot's forward direction at orientation `rot`.
    fn yaw(&self, rot: &UnitQuaternion<f64>) -> f64 {
        let f = rot * self.forward;
        f.y.atan2(f.x)
    }
}

/// Where a sole primitive (`kind`, MuJoCo `size`, pose `rel` in the foot frame) stands on the
/// floor when the foot stands as at `qpos0` (world orientation `rest`), in the foot frame: a
/// box's four lowest corners; a capsule's, or a lying cylinder's, lowest point at each end
/// (soles of two bars along the foot, as the T1's, Adam Lite's or the G1's URDF); a standing
/// cylinder's lowest cap, four points on its rim (forward, back and to either side); a
/// sphere's or an ellipsoid's lowest point (the G1 MJCFs' four corner balls). Other kinds
/// stand nowhere.
fn bottom_points(
    kind: GeomType,
    size: &[f64; 3],
    rel: &Isometry3<f64>,
    rest: &UnitQuaternion<f64>,
) -> Vec<Vector3<f64>> {
    // The world's up in the foot frame, and a point `p` of the geom's frame in the foot's.
    let up = rest.inverse() * Vector3::z();
    let at = |p: Vector3<f64>| (rel * nalgebra::Point3::from(p)).coords;
    let axis = rel.rotation * Vector3::z();
    match kind {
        GeomType::Box => {
            let mut all: Vec<Vector3<f64>> = (0..8)
                .map(|k| {
                    let sign = |bit: usize| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
                    at(Vector3::new(sign(0) * size[0], sign(1) * size[1], sign(2) * size[2]))
                })
                .collect();
            all.sort_by(|a, b| up.dot(a).total_cmp(&up.dot(b)));
            all.truncate(4);
            all
        }
        GeomType::Capsule => {
            [-1.0, 1.0].map(|end| at(Vector3::new(0.0, 0.0, end * size[1])) - up * size[0]).to_vec()
        }
        GeomType::Cylinder if axis.dot(&up).abs() < std::f64::consts::FRAC_1_SQRT_2 => {
            // The unit vector across the axis that points down the most.
            let Some(across) = (-up + axis * axis.dot(&up)).try_normalize(1e-9) else {
                return Vec::new();
            };
            [-1.0, 1.0]
                .map(|end| at(Vector3::new(0.0, 0.0, end * size[1])) + across * size[0])
                .to_vec()
        }
        GeomType::Cylinder => {
            let cap = at(Vector3::new(0.0, 0.0, -size[1] * axis.dot(&up).signum()));
            let forward = rest.inverse() * Vector3::x();
            let Some(forward) = (forward - axis * axis.dot(&forward)).try_normalize(1e-9) else {
                return vec![cap];
            };
            let side = axis.cross(&forward);
            [forward, -forward, side, -side].map(|d| cap + d * size[0]).to_vec()
        }
        GeomType::Sphere | GeomType::Ellipsoid => {
            let r = (rest * rel.rotation).to_rotation_matrix().into_inner();
            vec![rel.translation.vector + rest.inverse() * support_offset(kind, size, &r)]
        }
        _ => Vec::new(),
    }
}

/// Longest and shortest plausible half length (m) of a foot's equivalent inertia box
/// ([`inertia_sole`]).
const INERTIA_SOLE_HALF_LENGTH: [f64; 2] = [0.03, 0.2];

/// A sole for a foot without collision geometry (the motion-capture models of the N1, the
/// H1, the H1-2, the Hi have bodies with masses and nothing else): the uniform box with the
/// mass and principal moments of a body at or below the foot ([`inertia_sole`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InertiaSole {
    pub body: usize,
    /// Half sizes along the principal axes (m).
    pub half: [f64; 3],
    /// The box's pose in `body`'s frame: centre of mass and principal axes.
    pub pose: Isometry3<f64>,
}

impl InertiaSole {
    /// The box's world pose with `data`'s kinematics.
    pub fn world(&self, data: &Data) -> Isometry3<f64> {
        let body = Translation3::from(data.xpos[self.body]);
        Isometry3::from_parts(body, data.xquat[self.body]) * self.pose
    }
}

/// The [`InertiaSole`] of the heaviest body at or below `sole_body` whose box has a foot's
/// length ([`INERTIA_SOLE_HALF_LENGTH`] for its longest half side). The N1's foot gives
/// 19 × 6.8 × 3.4 cm with its bottom 4.9 cm below the ankle axis; a real sole's mass sits
/// higher than its middle (motors, ankle), so the box's bottom is a little above the real
/// sole, which the floor shift of [`plan`] takes up. `None` when no body there has an
/// inertial.
pub(crate) fn inertia_sole(model: &Model, sole_body: usize) -> Option<InertiaSole> {
    (0..model.bodies.len())
        .filter(|&b| is_descendant(model, b, sole_body))
        .filter_map(|b| {
            let inertial = model.bodies[b].inertial?;
            let half = inertial.equivalent_box()?;
            let [shortest, longest] = INERTIA_SOLE_HALF_LENGTH;
            let long = half.max();
            (long >= shortest && long <= longest).then_some((b, inertial, half))
        })
        .max_by(|a, b| a.1.mass.total_cmp(&b.1.mass))
        .map(|(body, inertial, half)| InertiaSole {
            body,
            half: [half.x, half.y, half.z],
            pose: Isometry3::from_parts(Translation3::from(inertial.pos), inertial.quat),
        })
}

/// Whether `body` is `ancestor` or one of the bodies below it.
pub(crate) fn is_descendant(model: &Model, mut body: usize, ancestor: usize) -> bool {
    loop {
        if body == ancestor {
            return true;
        }
        if body == 0 {
            return false;
        }
        body = model.bodies[body].parent;
    }
}

fn pose_of(pos: &Vector3<f64>, mat: &Matrix3<f64>) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_matrix(mat);
    Isometry3::from_parts(Translation3::from(*pos), rot)
}

/// What [`plan`] did: the vertical shift and per frame the weight factor of each foot.
#[derive(Debug, Clone, PartialEq)]
pub struct FootPlan {
    /// Added to every target's z (m).
    pub shift: f64,
    /// Per frame, `[left, right]` factors on the foot tasks' weights.
    pub weight: Vec<[f64; 2]>,
    /// Per frame and foot in stance: points of the sole (foot frame), where they stay
    /// (world), and which world axes hold them ([`SolePoint`]).
    pub contact: Vec<[Vec<SolePoint>; 2]>,
    /// Per frame and foot out of stance: the least height (m) above the floor the swing
    /// clearance asks of the sole's lowest point, where it asks any.
    pub swing_floor: Vec<[Option<f64>; 2]>,
    /// Stance phases of the two feet that overlap in time with the left foot planted to the
    /// right of the right one ([`Crossing`]), as planned (uncrossed ones included).
    pub crossed: Vec<Crossing>,
}

/// Two stance phases, one per foot, that overlap in time with the feet crossed: the left
/// foot's footprint centre is to the right of the right one's (across the robot's heading,
/// [`plan_uncrossing`]).
/// The human steps over like this in a crossover or a turn; a robot whose legs are too thick
/// for it cannot stand there with both feet down (the T1 in the LAFAN1 walk's crouched
/// crossover steps) and is uncrossed ([`plan_uncrossing`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Crossing {
    /// First frames of the left and the right foot's stance phase (with the lead).
    pub phases: (usize, usize),
    /// The frames both are planted.
    pub frames: Range<usize>,
}

/// Rewrites `targets` (`frames × slots` poses, frame-major) in place; see the module docs.
#[cfg(test)]
pub fn plan(
    feet: &[Option<RobotFoot>; 2],
    contacts: &FootContacts,
    targets: &mut [Pose],
    slots: usize,
    fps: f64,
    options: &FootPlanOptions,
) -> FootPlan {
    plan_uncrossing(feet, contacts, targets, slots, fps, options, &Uncrossing::default())
}

/// Which crossed stances [`plan_uncrossing`] uncrosses, and across what.
#[derive(Debug, Clone, Copy, Default)]
pub struct Uncrossing<'a> {
    /// The [`Crossing::phases`] to move apart.
    pub uncross: &'a [(usize, usize)],
    /// Per frame, the yaw (rad) the robot's pelvis is to face; empty: the two feet's mean
    /// yaw.
    pub heading: &'a [f64],
}

/// [`plan`], with the crossed stance phases `crossings.uncross` moved apart sideways until
/// they are no longer crossed and their soles are [`FootPlanOptions::sole_gap`] apart, half
/// the way each. Crossed and apart are across the robot's heading
/// ([`Uncrossing::heading`]).
pub fn plan_uncrossing(
    feet: &[Option<RobotFoot>; 2],
    contacts: &FootContacts,
    targets: &mut [Pose],
    slots: usize,
    fps: f64,
    options: &FootPlanOptions,
    crossings: &Uncrossing<'_>,
) -> FootPlan {
    let Uncrossing { uncross, heading } = *crossings;
    let frames = targets.len().checked_div(slots).unwrap_or(0);
    let labels = [&contacts.left, &contacts.right];
    let shift = floor_shift(feet, &labels, targets, slots, options.clearance);
    for p in targets.iter_mut() {
        p.pos.z += shift;
    }
    if let [Some(left), Some(right)] = feet {
        keep_feet_apart(left, right, targets, slots, options.sole_gap);
    }
    let lead = (options.lead_s * fps).round().max(0.0) as usize;
    let mut weight = vec![[1.0; 2]; frames];
    let mut contact = vec![[Vec::new(), Vec::new()]; frames];
    let mut swing_floor = vec![[None; 2]; frames];
    // Each foot's stance phases and their anchors, (range, xy, yaw), then kept apart.
    let mut anchors: [Vec<Planted>; 2] = [Vec::new(), Vec::new()];
    let mut free_targets: [Vec<Pose>; 2] = [Vec::new(), Vec::new()];
    // Per foot and frame, the free target's yaw (what a pivot follows).
    let mut free_yaw: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        let label = &labels[side][..frames.min(labels[side].len())];
        let phase_list: Vec<Range<usize>> =
            phases(label).into_iter().map(|r| r.start.saturating_sub(lead)..r.end).collect();
        let free: Vec<Pose> = (0..frames).map(|t| targets[t * slots + foot.slot]).collect();
        // The foot orientation each frame's shin target implies (the ankle straight).
        let mut shin: Vec<Option<UnitQuaternion<f64>>> = (0..frames)
            .map(|t| foot.shin.map(|(slot, rel)| quat(&targets[t * slots + slot]) * rel))
            .collect();
        // The config's shin and foot offsets need not agree about yaw (Toddy's left calf and
        // toe targets disagree by 177°, with GMR's config and with ours): turn the shin's by
        // the half turn of their mean difference over the clip, if any
        // (`convention_turn`), so that a frame convention never outvotes the foot, while the
        // human's toe-out stays and the planted yaw shares it between the foot and the leg
        // above, as GMR's solve does. (Turned by the whole difference, the planted yaw was
        // the foot's, and a robot without an ankle yaw turned the whole leg to it.)
        let (mut s, mut c) = (0.0, 0.0);
        for (t, q) in shin.iter().enumerate() {
            if let Some(q) = q {
                let d = wrap(foot.yaw(q) - foot.yaw(&quat(&free[t])));
                (s, c) = (s + d.sin(), c + d.cos());
            }
        }
        let turn =
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -convention_turn(s.atan2(c)));
        for q in shin.iter_mut().flatten() {
            *q = turn * *q;
        }
        anchors[side] = phase_list
            .into_iter()
            .map(|r| {
                let (xy, yaw) = anchor(foot, &free, &shin, r.clone(), options.anchor);
                (r, xy, yaw)
            })
            .collect();
        free_yaw[side] = free.iter().map(|p| foot.yaw(&quat(p))).collect();
        free_targets[side] = free;
    }
    let mut crossed = Vec::new();
    if let [Some(left), Some(right)] = feet {
        separate(left, right, &mut anchors, options.sole_gap);
        crossed = uncrossed(left, right, &mut anchors, options.sole_gap, uncross, heading);
    }
    // Per foot and frame, whether it is planted (any stance phase of it covers the frame).
    let planted_mask: [Vec<bool>; 2] = std::array::from_fn(|side| {
        let mut m = vec![false; frames];
        for (r, _, _) in &anchors[side] {
            for t in r.clone() {
                if t < frames {
                    m[t] = true;
                }
            }
        }
        m
    });
    let roll_frames = (options.roll_s * fps).round().max(1.0);
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        let free = &free_targets[side];
        let other = &planted_mask[1 - side];
        // How far a planted foot may roll as the human's does (1) or stands on its whole sole
        // (0): only while the other foot stands too, fading in and out at the double
        // support's ends.
        let roll: Vec<f64> = (0..frames)
            .map(|t| {
                if !other[t] {
                    return 0.0;
                }
                let since = (0..=t).rev().take_while(|&u| other[u]).count() as f64;
                let until = (t..frames).take_while(|&u| other[u]).count() as f64;
                smoothstep((since.min(until) / roll_frames).min(1.0))
            })
            .collect();
        // Per planted frame, where the flat foot stands: its horizontal position and yaw (a
        // pivot's turned with the source's).
        let mut held: Vec<Option<(Vector3<f64>, f64)>> = vec![None; frames];
        for (r, xy, yaw) in &anchors[side] {
            let (xy, yaw) = (*xy, *yaw);
            let pivots = turn_of(&free_yaw[side][r.clone()], yaw) > options.pivot_turn;
            for t in r.clone() {
                let (xy, yaw) = if pivots {
                    (pivot(foot, xy, yaw, free_yaw[side][t]), free_yaw[side][t])
                } else {
                    (xy, yaw)
                };
                let tilt = quat(&free[t]);
                let q = foot.within_band(&tilt, options.sole_band).slerp(&tilt, roll[t]);
                let rolled = Pose { quat: [q.w, q.i, q.j, q.k], pos: free[t].pos };
                let pose = planted_pose(foot, &rolled, xy, yaw, options.clearance);
                contact[t][side] = foot.contact_points(&pose, 1.0);
                targets[t * slots + foot.slot] = pose;
                weight[t][side] = options.stance_weight;
                held[t] = Some((xy, yaw));
            }
        }
        // Out of stance the sole keeps clear of the floor: the swing clearance, reached over
        // `lift_s` after lift-off and left over as long before touch-down.
        let edges = swing_edges(&held.iter().map(Option::is_some).collect::<Vec<_>>());
        // (The tolerance: 1/30 s at 30 fps is one frame.)
        let lift_frames = (options.lift_s * fps - 1e-9).ceil();
        for t in 0..frames {
            let Some((edge, frames_off)) = edges[t].filter(|_| held[t].is_none()) else { continue };
            if frames_off as f64 <= lift_frames {
                // Rising (coming down): the sole points that stood on the floor at lift-off
                // (stand on it at touch-down) stay where they were (will be), seen from
                // above: a foot leaves the floor by lifting, not sliding, its last contact.
                let edge_pose = targets[edge * slots + foot.slot];
                contact[t][side] = foot
                    .contact_points(&edge_pose, 1.0)
                    .into_iter()
                    .filter(|p| p.vertical > 0.0)
                    .map(|p| SolePoint { vertical: 0.0, ..p })
                    .collect();
            }
            // (The tolerance: at 30 fps and 1/30 s, one frame is all the way up.)
            let rise = smoothstep((frames_off as f64 / (options.lift_s * fps) + 1e-9).min(1.0));
            let height = options.swing_clearance * rise;
            if height <= 0.0 {
                continue;
            }
            swing_floor[t][side] = Some(height);
            let mut pose = free[t];
            let low = height - pose.pos.z - foot.sole_offset(&quat(&pose));
            if low > 0.0 {
                pose.pos.z += low;
                targets[t * slots + foot.slot] = pose;
            }
        }
    }
    FootPlan { shift, weight, contact, swing_floor, crossed }
}

/// The part of a mean yaw difference (rad) between a foot's target and the foot its shin's
/// target implies that comes from the config's frames, not from the human: a half turn
/// where the two face apart (ToddlerBot's left calf and toe, 177° with GMR's config and with
/// ours), none otherwise. A human foot turns out from its shin by a few degrees (the LAFAN1
/// walk 3–4°, CMU 131_01 6–9°, the Bandai walk's right foot 18°, its kick 20–28°; the first
/// 15 s of the Bandai dance 46°, where its left foot turns on the floor), and that is
/// kept: removing it planted the foot at its own yaw, which a leg without an ankle yaw can
/// only follow by turning the hip, knee and foot together (the G1 on the Bandai walk:
/// rotation error 4.13° against `--gmr`'s 3.35°; 3.45° with the toe-out kept). (Rounding to
/// the nearest quarter turn instead turned that dance's left shin by 90°: the leg's rotation
/// error went from 0.75 to 1.07 rad.)
fn convention_turn(mean: f64) -> f64 {
    if mean.abs() > std::f64::consts::FRAC_PI_2 {
        std::f64::consts::PI.copysign(mean)
    } else {
        0.0
    }
}

/// How far (rad) `yaws` turn: the largest minus the smallest of their differences from
/// `reference` (wrapped), 0 for none.
fn turn_of(yaws: &[f64], reference: f64) -> f64 {
    let d = yaws.iter().map(|y| wrap(y - reference));
    let (lo, hi) = d.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo <= hi {
        hi - lo
    } else {
        0.0
    }
}

/// The flat foot's horizontal position (`xy` at `yaw0`) turned to `yaw` about its toe point
/// ([`RobotFoot::toe_point`], where the report measures skating).
fn pivot(foot: &RobotFoot, xy: Vector3<f64>, yaw0: f64, yaw: f64) -> Vector3<f64> {
    let c = foot.toe_point();
    let d = foot.flat(yaw0) * c - foot.flat(yaw) * c;
    Vector3::new(xy.x + d.x, xy.y + d.y, xy.z)
}

/// Sideways push between the two feet ([`keep_feet_apart`]) fades in over this much (m) of
/// forward distance as the soles come alongside each other.
const ALONGSIDE_FADE: f64 = 0.05;

/// At most this much (m) of sideways push between the two feet: a step that crosses over
/// (a dance) is narrowed, not uncrossed.
const MAX_WIDENING: f64 = 0.1;

/// Moves the two foot targets of every frame apart sideways (perpendicular to their mean
/// heading, half each) until the inner edges of their flat soles, each turned to its own yaw,
/// are `gap` apart, while the soles are alongside each other: the push fades out over
/// [`ALONGSIDE_FADE`] once one is `gap` ahead of the other, and is at most [`MAX_WIDENING`].
/// The scaled human's feet can pass closer than the robot's feet fit (ToddlerBot: 4.9 cm
/// apart, median, against soles 4.2 cm wide); the self-collision rows then stop a foot short
/// of its anchor, and it catches up later at a skate.
fn keep_feet_apart(
    left: &RobotFoot,
    right: &RobotFoot,
    targets: &mut [Pose],
    slots: usize,
    gap: f64,
) {
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() || gap < 0.0 {
        return;
    }
    let frames = targets.len().checked_div(slots).unwrap_or(0);
    for t in 0..frames {
        let (l, r) = (targets[t * slots + left.slot], targets[t * slots + right.slot]);
        let (yl, yr) = (left.yaw(&quat(&l)), right.yaw(&quat(&r)));
        let yaw = (yl.sin() + yr.sin()).atan2(yl.cos() + yr.cos());
        let lateral = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
        let forward = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
        // How far a flat sole turned to its own yaw reaches from its body origin along `axis`
        // (a foot turned across the other reaches further sideways than along the mean
        // heading: ToddlerBot's 12 cm feet, on the LAFAN1 walk's turns).
        let reach = |foot: &RobotFoot, foot_yaw: f64, axis: Vector3<f64>| {
            let flat = foot.flat(foot_yaw);
            foot.corners.iter().map(|c| (flat * c).dot(&axis)).fold(0.0, f64::max)
        };
        let apart = (l.pos - r.pos).dot(&lateral);
        let short = reach(left, yl, -lateral) + reach(right, yr, lateral) + gap - apart;
        if short <= 0.0 {
            continue;
        }
        let ahead = (l.pos - r.pos).dot(&forward);
        let clear = if ahead >= 0.0 {
            ahead - reach(left, yl, -forward) - reach(right, yr, forward)
        } else {
            -ahead - reach(left, yl, forward) - reach(right, yr, -forward)
        };
        let alongside =
            smoothstep(((gap + ALONGSIDE_FADE - clear) / ALONGSIDE_FADE).clamp(0.0, 1.0));
        let push = (short * alongside).min(MAX_WIDENING) / 2.0;
        targets[t * slots + left.slot].pos += lateral * push;
        targets[t * slots + right.slot].pos -= lateral * push;
    }
}

/// Per frame out of stance, the nearer of the planted frames around it (the last before, the
/// first after; the earlier on a tie) and how many frames away it is; `None` in stance and
/// where the foot is never planted.
fn swing_edges(planted: &[bool]) -> Vec<Option<(usize, usize)>> {
    let mut out = vec![None; planted.len()];
    let mut last = None;
    for (t, &p) in planted.iter().enumerate() {
        if p {
            last = Some(t);
        } else if let Some(a) = last {
            out[t] = Some((a, t - a));
        }
    }
    let mut next = None;
    for (t, &p) in planted.iter().enumerate().rev() {
        if p {
            next = Some(t);
        } else if let Some(b) = next {
            if out[t].is_none_or(|(_, d)| b - t < d) {
                out[t] = Some((b, b - t));
            }
        }
    }
    out
}

/// A stance phase (frames) with its anchor: the flat foot's horizontal position and yaw.
type Planted = (Range<usize>, Vector3<f64>, f64);

/// Moves the anchors of stance phases that overlap in time apart until the flat soles'
/// footprints (their bottom points at the anchors) are at least `gap` apart along one of the
/// footprints' edge directions (the separating axis along which they are furthest apart, so
/// the shortest way apart: sideways for feet side by side, forwards for one behind the
/// other): each moves half the shortfall, along that axis. Separation along an axis bounds
/// the true gap from below, so the result is conservative. A phase that
/// overlaps several of the other foot's is moved for each (three sweeps settle chains).
/// Soles without bottom points have no footprint and are left alone.
fn separate(left: &RobotFoot, right: &RobotFoot, anchors: &mut [Vec<Planted>; 2], gap: f64) {
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() {
        return;
    }
    let footprint = |foot: &RobotFoot, xy: &Vector3<f64>, yaw: f64| -> Vec<Vector3<f64>> {
        let flat = foot.flat(yaw);
        foot.corners.iter().map(|c| Vector3::new(xy.x, xy.y, 0.0) + flat * c).collect()
    };
    let [lefts, rights] = anchors;
    for _ in 0..3 {
        for (lr, lxy, lyaw) in lefts.iter_mut() {
            for (rr, rxy, ryaw) in rights.iter_mut() {
                if lr.end <= rr.start || rr.end <= lr.start {
                    continue;
                }
                let (a, b) = (footprint(left, lxy, *lyaw), footprint(right, rxy, *ryaw));
                // Separating-axis test over both footprints' edge directions: the axis with
                // the largest separation is the shortest way apart.
                let axes = [*lyaw, *ryaw].map(|yaw| {
                    let (s, c) = yaw.sin_cos();
                    [Vector3::new(c, s, 0.0), Vector3::new(-s, c, 0.0)]
                });
                let centre = |p: &[Vector3<f64>]| p.iter().sum::<Vector3<f64>>() / p.len() as f64;
                let apart = centre(&b) - centre(&a);
                let (d, separation) = axes
                    .iter()
                    .flatten()
                    .map(|u| {
                        let d = if apart.dot(u) < 0.0 { -u } else { *u };
                        let reach = a.iter().map(|p| p.dot(&d)).fold(f64::NEG_INFINITY, f64::max);
                        let start = b.iter().map(|p| p.dot(&d)).fold(f64::INFINITY, f64::min);
                        (d, start - reach)
                    })
                    .fold((Vector3::zeros(), f64::NEG_INFINITY), |best, x| {
                        if x.1 > best.1 {
                            x
                        } else {
                            best
                        }
                    });
                let short = gap - separation;
                if short > 0.0 {
                    *lxy -= d * (short / 2.0);
                    *rxy += d * (short / 2.0);
                }
            }
        }
    }
}

/// The crossed pairs of overlapping stance phases ([`Crossing`]), found after [`separate`];
/// those listed in `uncross` are moved apart across the heading, half the way each,
/// until the left footprint is `gap` to the left of the right one.
fn uncrossed(
    left: &RobotFoot,
    right: &RobotFoot,
    anchors: &mut [Vec<Planted>; 2],
    gap: f64,
    uncross: &[(usize, usize)],
    heading: &[f64],
) -> Vec<Crossing> {
    let mut out = Vec::new();
    if left.corners.is_empty() || right.corners.is_empty() || gap.is_nan() {
        return out;
    }
    let [lefts, rights] = anchors;
    for (lr, lxy, lyaw) in lefts.iter_mut() {
        for (rr, rxy, ryaw) in rights.iter_mut() {
            let frames = lr.start.max(rr.start)..lr.end.min(rr.end);
            if frames.is_empty() {
                continue;
            }
            // Across the pelvis's heading over the overlap (the legs hang from it; a foot
            // pivoting in its stance turns the feet's mean heading away from it), else the
            // feet's mean heading. (On the T1's LAFAN1 walk with the derived config, 4 stuck
            // crossings against 5 by the feet's heading, foot error 26.6 → 26.0 mm.)
            let yaw = match heading.get(frames.clone()) {
                Some(h) if !h.is_empty() => {
                    let (s, c) = h.iter().fold((0.0, 0.0), |(s, c), y| (s + y.sin(), c + y.cos()));
                    s.atan2(c)
                }
                _ => (lyaw.sin() + ryaw.sin()).atan2(lyaw.cos() + ryaw.cos()),
            };
            let across = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
            // The footprints' extents across the heading: the left one's least, the right
            // one's greatest.
            let extent = |foot: &RobotFoot, xy: &Vector3<f64>, foot_yaw: f64| {
                let flat = foot.flat(foot_yaw);
                let at = |c: &Vector3<f64>| (Vector3::new(xy.x, xy.y, 0.0) + flat * c).dot(&across);
                let (lo, hi) = foot
                    .corners
                    .iter()
                    .map(at)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
                (lo, hi, (lo + hi) / 2.0)
            };
            let (l_lo, _, l_mid) = extent(left, lxy, *lyaw);
            let (_, r_hi, r_mid) = extent(right, rxy, *ryaw);
            if l_mid >= r_mid {
                continue;
            }
            let phases = (lr.start, rr.start);
            if uncross.contains(&phases) {
                // Half the way each. (Moving only the foot that stepped into the crossed stance
                // set the T1's feet wide apart in its crouch: its pelvis then dropped more than
                // 5 cm below its target in 35 frames of the LAFAN1 walk, against 2.)
                let short = gap + r_hi - l_lo;
                *lxy += across * (short / 2.0);
                *rxy -= across * (short / 2.0);
            }
            out.push(Crossing { phases, frames });
        }
    }
    out
}

/// `3w² − 2w³`: from 0 to 1 over `w` in [0, 1], flat at both ends.
fn smoothstep(w: f64) -> f64 {
    w * w * (3.0 - 2.0 * w)
}

/// Median over stance samples of the vertical move that rests the sole on the floor.
fn floor_shift(
    feet: &[Option<RobotFoot>; 2],
    labels: &[&Vec<bool>; 2],
    targets: &[Pose],
    slots: usize,
    clearance: f64,
) -> f64 {
    let mut moves = Vec::new();
    for (side, foot) in feet.iter().enumerate() {
        let Some(foot) = foot else { continue };
        for (t, _) in labels[side].iter().enumerate().filter(|(_, c)| **c) {
            let Some(p) = targets.get(t * slots + foot.slot) else { break };
            moves.push(clearance - foot.sole_offset(&quat(p)) - p.pos.z);
        }
    }
    if moves.is_empty() {
        return 0.0;
    }
    moves.sort_by(f64::total_cmp);
    moves[moves.len() / 2]
}

/// Anchor of one phase: the yaw (circular mean or first frame of the free targets' yaws),
/// then the horizontal position of the flat foot that, rolled over its sole's lowest point
/// to each free target's tilt, puts the foot origin where the free target is (its mean over
/// the phase, or its first frame): a foot rolling from heel to toe without slipping has one
/// such position.
fn anchor(
    foot: &RobotFoot,
    free: &[Pose],
    shin: &[Option<UnitQuaternion<f64>>],
    range: Range<usize>,
    kind: Anchor,
) -> (Vector3<f64>, f64) {
    let frames: Vec<usize> = match kind {
        Anchor::PhaseStart => vec![range.start],
        Anchor::PhaseMean => range.collect(),
    };
    let (mut s, mut c) = (0.0, 0.0);
    for &t in &frames {
        let yaws = std::iter::once(foot.yaw(&quat(&free[t]))).chain(shin[t].map(|q| foot.yaw(&q)));
        for yaw in yaws {
            (s, c) = (s + yaw.sin(), c + yaw.cos());
        }
    }
    let yaw = s.atan2(c);
    let flat = foot.flat(yaw);
    let mut sum = Vector3::zeros();
    for &t in &frames {
        let q = anchored(foot, &free[t], yaw);
        let low = foot.sole_low_point(&q);
        sum += free[t].pos + q * low - flat * low;
    }
    (sum / frames.len().max(1) as f64, yaw)
}

/// The free target's orientation turned about world z to yaw `yaw`.
fn anchored(foot: &RobotFoot, free: &Pose, yaw: f64) -> UnitQuaternion<f64> {
    let q = quat(free);
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), wrap(yaw - foot.yaw(&q))) * q
}

/// The planted pose: the free target's tilt with the anchor's yaw, rolled over the sole's
/// lowest point, which stays where it is on the flat foot at the anchor and rests at
/// `clearance` above the floor.
fn planted_pose(
    foot: &RobotFoot,
    free: &Pose,
    anchor: Vector3<f64>,
    yaw: f64,
    clearance: f64,
) -> Pose {
    let q = anchored(foot, free, yaw);
    let flat = foot.flat(yaw);
    let low = foot.sole_low_point(&q);
    let contact = Vector3::new(anchor.x, anchor.y, 0.0) + flat * low;
    let rolled = q * low;
    let pos = Vector3::new(contact.x - rolled.x, contact.y - rolled.y, clearance - rolled.z);
    Pose { quat: [q.w, q.i, q.j, q.k], pos }
}

/// `a` (rad) wrapped into [−π, π).
pub(crate) fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

fn quat(p: &Pose) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(p.quat[0], p.quat[1], p.quat[2], p.quat[3]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat foot with a 20 × 10 cm box sole, its origin at the sole's centre, facing +x.
    fn box_foot() -> RobotFoot {
        let corners = [(-0.1, -0.05), (-0.1, 0.05), (0.1, -0.05), (0.1, 0.05)]
            .map(|(x, y)| Vector3::new(x, y, -0.02))
            .to_vec();
        RobotFoot {
            body: 1,
            slot: 0,
            sole: Vec::new(),
            forward: Vector3::x(),
            rest: UnitQuaternion::identity(),
            corners,
            shin: None,
            geoms: Vec::new(),
        }
    }

    /// A foot on a free body at 5 cm, facing +x, with `geoms` (MJCF) as its sole.
    fn foot_with(geoms: &str) -> RobotFoot {
        let xml = format!(
            r#"<mujoco><worldbody><body name="foot" pos="0 0 0.05"><freejoint/>{geoms}</body>
               </worldbody></mujoco>"#
        );
        let model = Model::from_xml_str(&xml, None).unwrap();
        RobotFoot::new(&model, 1, 1, 0, None).unwrap()
    }

    fn sorted(mut points: Vec<Vector3<f64>>) -> Vec<[f64; 3]> {
        let r = |v: f64| (v * 1e9).round() / 1e9;
        let mut out: Vec<[f64; 3]> = points.drain(..).map(|p| [r(p.x), r(p.y), r(p.z)]).collect();
        out.sort_by(|a, b| a.partial_cmp(b).unwrap());
        out
    }

    #[test]
    fn soles_of_bars_and_balls_stand_on_their_ends_and_balls() {
        // Two capsule bars along the foot (the T1's), two lying cylinders (Adam Lite's, the
        // G1 URDF's), four balls (the G1 MJCFs'): each stands on the four bottom points of
        // its ends and balls, and its toe point is between the front two.
        let bars = [
            r#"<geom type="capsule" size="0.02 0.09" pos="0.03 0.03 -0.03" euler="0 90 0"/>
               <geom type="capsule" size="0.02 0.09" pos="0.03 -0.03 -0.03" euler="0 90 0"/>"#,
            r#"<geom type="cylinder" size="0.02 0.09" pos="0.03 0.03 -0.03" euler="0 90 0"/>
               <geom type="cylinder" size="0.02 0.09" pos="0.03 -0.03 -0.03" euler="0 90 0"/>"#,
            r#"<geom size="0.02" pos="-0.06 0.03 -0.03"/><geom size="0.02" pos="0.12 0.03 -0.03"/>
               <geom size="0.02" pos="-0.06 -0.03 -0.03"/><geom size="0.02" pos="0.12 -0.03 -0.03"/>"#,
        ];
        let expected = sorted(
            [(-0.06, -0.03), (-0.06, 0.03), (0.12, -0.03), (0.12, 0.03)]
                .map(|(x, y)| Vector3::new(x, y, -0.05))
                .to_vec(),
        );
        for sole in bars {
            let foot = foot_with(sole);
            assert_eq!(sorted(foot.corners.clone()), expected, "{sole}");
            assert!((foot.toe_point() - Vector3::new(0.12, 0.0, -0.05)).norm() < 1e-9, "{sole}");
        }
        // A standing cylinder (a round sole) stands on its rim: front, back and both sides.
        let foot = foot_with(r#"<geom type="cylinder" size="0.05 0.01" pos="0 0 -0.04"/>"#);
        let rim = [(0.05, 0.0), (-0.05, 0.0), (0.0, 0.05), (0.0, -0.05)]
            .map(|(x, y)| Vector3::new(x, y, -0.05))
            .to_vec();
        assert_eq!(sorted(foot.corners.clone()), sorted(rim));
    }

    #[test]
    fn a_foot_without_geoms_stands_on_its_inertia_box() {
        // The N1 motion-capture model's foot: no geoms, 0.528 kg, centre of mass 3.1 cm ahead
        // of and 3.2 cm below the ankle, principal moments giving a 19.2 × 6.8 × 3.4 cm box
        // (long axis along the principal z, turned onto the body's x).
        let xml = r#"<mujoco><worldbody><body name="foot" pos="0 0 0.05"><freejoint/>
            <body name="toe"/></body></worldbody></mujoco>"#;
        let mut model = Model::from_xml_str(xml, None).unwrap();
        let inertial = mjcf::Inertial {
            mass: 0.528,
            pos: Vector3::new(0.031, 0.0, -0.032),
            quat: UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2),
            diag: Vector3::new(0.00183246, 0.00168042, 0.000253637),
        };
        model.bodies[1].inertial = Some(inertial);
        let foot = RobotFoot::new(&model, 1, 1, 0, None).unwrap();
        let half = inertial.equivalent_box().unwrap();
        assert!((half.z - 0.096).abs() < 1e-3 && (half.x - 0.017).abs() < 1e-3, "{half:?}");
        // Four bottom corners, 1.7 cm under the centre of mass, 9.6 cm ahead and behind it.
        assert_eq!(foot.corners.len(), 4);
        for c in &foot.corners {
            assert!((c.z - (-0.032 - half.x)).abs() < 1e-9, "{c:?}");
            assert!(((c.x - 0.031).abs() - half.z).abs() < 1e-9, "{c:?}");
        }
        assert!((foot.sole_offset(&UnitQuaternion::identity()) + 0.032 + half.x).abs() < 1e-9);
        // A body with no mass, or a box no foot is (a point mass, a 1 m beam), is no sole.
        model.bodies[1].inertial = Some(mjcf::Inertial { mass: 0.0, ..inertial });
        assert!(RobotFoot::new(&model, 1, 1, 0, None).is_none());
        model.bodies[1].inertial =
            Some(mjcf::Inertial { diag: Vector3::new(0.0440, 0.0440, 1e-5), ..inertial });
        assert!(RobotFoot::new(&model, 1, 1, 0, None).is_none());
        // The heaviest plausible body below the foot is taken.
        model.bodies[1].inertial = None;
        model.bodies[2].inertial = Some(inertial);
        let toe = RobotFoot::new(&model, 1, 1, 0, None).unwrap();
        assert_eq!(toe.corners.len(), 4);
    }

    #[test]
    fn planted_soles_are_kept_apart() {
        let foot = box_foot();
        // Both planted over frames 5..15, side by side 6 cm apart: the soles overlap by 4 cm.
        // A third, later left phase does not overlap any right one and stays.
        let mut anchors = [
            vec![
                (0..10, Vector3::new(0.0, 0.03, 0.0), 0.0),
                (20..30, Vector3::new(1.0, 0.0, 0.0), 0.0),
            ],
            vec![(5..15, Vector3::new(0.0, -0.03, 0.0), 0.0)],
        ];
        separate(&foot, &foot, &mut anchors, 0.02);
        let (left, right) = (anchors[0][0].1, anchors[1][0].1);
        // Centres 6 cm apart, footprints 10 cm wide: 6 cm short of a 2 cm gap, 3 cm each.
        assert!((left.y - 0.06).abs() < 1e-12, "{left}");
        assert!((right.y + 0.06).abs() < 1e-12, "{right}");
        assert_eq!(anchors[0][1].1, Vector3::new(1.0, 0.0, 0.0));
        // Already apart: nothing moves.
        let before = anchors.clone();
        separate(&foot, &foot, &mut anchors, 0.02);
        assert_eq!(anchors, before);
    }

    #[test]
    fn crossed_stances_are_found_and_uncrossed_on_request() {
        let foot = box_foot();
        // Facing +x, the left foot planted 4 cm to the right of the right one (10 cm wide
        // soles), 25 cm behind it, over frames 0..10 and 5..15; a later pair is not crossed.
        let mut anchors = [
            vec![
                (0..10, Vector3::new(0.0, -0.02, 0.0), 0.0),
                (20..30, Vector3::new(1.0, 0.1, 0.0), 0.0),
            ],
            vec![
                (5..15, Vector3::new(0.25, 0.02, 0.0), 0.0),
                (25..35, Vector3::new(1.2, -0.1, 0.0), 0.0),
            ],
        ];
        let found = uncrossed(&foot, &foot, &mut anchors.clone(), 0.03, &[], &[]);
        assert_eq!(found, vec![Crossing { phases: (0, 5), frames: 5..10 }]);
        let again = uncrossed(&foot, &foot, &mut anchors, 0.03, &[(0, 5)], &[]);
        assert_eq!(again, found);
        // Each moves half of 4 + 10 + 3 cm sideways: the left sole's right edge is 3 cm to
        // the left of the right sole's left edge.
        let (left, right) = (anchors[0][0].1, anchors[1][0].1);
        assert!((left.y - 0.065).abs() < 1e-12, "{left}");
        assert!((right.y + 0.065).abs() < 1e-12, "{right}");
        assert!((left.x, right.x) == (0.0, 0.25));
        assert_eq!(anchors[0][1].1, Vector3::new(1.0, 0.1, 0.0));
    }

    /// One step of a flat box foot (sole 2 cm below its origin) at `fps`: planted for the
    /// first and last third of a 1 s clip, in between it moves 0.5 m forward barely off the
    /// floor (1 cm at most). Returns the planned foot targets and the contact labels.
    fn low_step(fps: f64) -> (Vec<Pose>, Vec<bool>, FootPlan) {
        low_step_with(fps, &FootPlanOptions::default())
    }

    fn low_step_with(fps: f64, options: &FootPlanOptions) -> (Vec<Pose>, Vec<bool>, FootPlan) {
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        let frames = fps as usize;
        let (lift, touch) = (frames / 3, 2 * frames / 3);
        let labels: Vec<bool> = (0..frames).map(|t| t < lift || t >= touch).collect();
        let mut targets: Vec<Pose> = (0..frames)
            .map(|t| {
                let u = ((t as f64 - lift as f64) / (touch - lift) as f64).clamp(0.0, 1.0);
                let pos =
                    Vector3::new(0.5 * u, 0.0, 0.02 + 0.01 * (std::f64::consts::PI * u).sin());
                Pose { quat: [1.0, 0.0, 0.0, 0.0], pos }
            })
            .collect();
        let contacts = FootContacts { left: labels.clone(), right: vec![false; frames] };
        let plan = plan(&[Some(foot), None], &contacts, &mut targets, 1, fps, options);
        (targets, labels, plan)
    }

    #[test]
    fn swing_feet_clear_the_floor_and_lift_before_they_move() {
        let options = FootPlanOptions::default();
        for fps in [30.0, 120.0] {
            let (targets, labels, plan) = low_step(fps);
            let sole = |p: &Pose| p.pos.z - 0.02;
            let lift = labels.iter().position(|c| !c).unwrap_or(0);
            let touch = lift + labels[lift..].iter().position(|c| *c).unwrap_or(0);
            let lead = (options.lead_s * fps).round() as usize;
            let rise = (options.lift_s * fps).round() as usize;
            // Planted frames rest on the floor.
            assert!((sole(&targets[lift - 1]) - options.clearance).abs() < 1e-9, "fps {fps}");
            for t in lift..touch - lead {
                let off = (t + 1 - lift).min(touch - lead - t);
                let floor = plan.swing_floor[t][0].unwrap_or(0.0);
                assert!(sole(&targets[t]) >= floor - 1e-9, "fps {fps} frame {t}");
                if off >= rise {
                    // Clear of the floor (the free target is 1 cm up at most).
                    assert!((floor - options.swing_clearance).abs() < 1e-9, "fps {fps} {t}");
                }
                if off > rise {
                    assert!(plan.contact[t][0].is_empty(), "fps {fps} frame {t}");
                } else {
                    // Rising or coming down: the sole points on the floor at the edge are
                    // held where they stand, horizontally only.
                    let anchor = if t - lift < touch - lead - t { lift - 1 } else { touch - lead };
                    let held = &plan.contact[t][0];
                    assert!(!held.is_empty(), "fps {fps} frame {t}");
                    for p in held {
                        let at_edge = targets[anchor].pos + quat(&targets[anchor]) * p.point;
                        assert!(p.vertical == 0.0 && p.horizontal > 0.0);
                        assert!((p.at - at_edge).xy().norm() < 1e-9, "fps {fps} frame {t}");
                    }
                }
            }
            assert_eq!(plan.weight.len(), labels.len());
        }
    }

    /// A planted foot whose human foot stands 10° toes-down: alone on the floor it stands
    /// on its whole sole (corners within the band); while the other foot stands too, it
    /// rolls with the human's.
    #[test]
    fn a_foot_alone_on_the_floor_stands_on_its_whole_sole() {
        let options = FootPlanOptions::default();
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        let fps = 30.0;
        let frames = 60;
        let toes_down = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.17);
        let q = toes_down.quaternion();
        let tilted = Pose { quat: [q.w, q.i, q.j, q.k], pos: Vector3::new(0.0, 0.0, 0.05) };
        let beside = Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(0.0, 0.3, 0.02) };
        let mut targets: Vec<Pose> = (0..frames).flat_map(|_| [tilted, beside]).collect();
        // The right foot stands in the second half only.
        let contacts = FootContacts {
            left: vec![true; frames],
            right: (0..frames).map(|t| t >= 30).collect(),
        };
        let feet = [Some(foot.clone()), Some(RobotFoot { slot: 1, ..foot.clone() })];
        plan(&feet, &contacts, &mut targets, 2, fps, &options);
        let spread = |p: &Pose| {
            let z: Vec<f64> = foot.corners.iter().map(|c| (quat(p) * c).z).collect();
            z.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - z.iter().copied().fold(f64::INFINITY, f64::min)
        };
        assert!(spread(&targets[10 * 2]) <= options.sole_band + 1e-9, "{}", spread(&targets[20]));
        // Deep in the double support: the human's 10°, its corners 3.5 cm apart in height.
        assert!(spread(&targets[45 * 2]) > 0.03, "{}", spread(&targets[90]));
    }

    /// One stance phase of 30 frames whose source foot turns through `turn` (rad) about its
    /// toe, standing flat: the planned foot targets and the foot.
    fn turning_stance(turn: f64) -> (Vec<Pose>, RobotFoot) {
        let mut foot = box_foot();
        foot.sole = vec![(GeomType::Box, [0.1, 0.05, 0.02], Isometry3::identity())];
        let frames = 30;
        let toe = foot.toe_point();
        let mut targets: Vec<Pose> = (0..frames)
            .map(|t| {
                let yaw = turn * t as f64 / (frames - 1) as f64;
                let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
                // The toe stays at (0.1, 0, ·): the origin turns about it.
                let pos = Vector3::new(toe.x, toe.y, 0.02) - q * Vector3::new(toe.x, toe.y, 0.0);
                Pose { quat: [q.w, q.i, q.j, q.k], pos }
            })
            .collect();
        let contacts = FootContacts { left: vec![true; frames], right: vec![false; frames] };
        let options = FootPlanOptions::default();
        plan(&[Some(foot.clone()), None], &contacts, &mut targets, 1, 30.0, &options);
        (targets, foot)
    }

    #[test]
    fn a_foot_that_turns_far_in_stance_pivots_about_its_toe() {
        let yaw = |p: &Pose| quat(p).euler_angles().2;
        // 90°: the planted foot turns with the source's, its toe still.
        let (targets, foot) = turning_stance(std::f64::consts::FRAC_PI_2);
        let toe = |p: &Pose| p.pos + quat(p) * foot.toe_point();
        let first = toe(&targets[0]);
        for (t, p) in targets.iter().enumerate() {
            let expected = std::f64::consts::FRAC_PI_2 * t as f64 / 29.0;
            assert!((yaw(p) - expected).abs() < 1e-9, "frame {t}: yaw {}", yaw(p));
            let moved = (toe(p) - first).xy().norm();
            assert!(moved < 1e-9, "frame {t}: the toe moved {moved} m");
        }
        // 20°, under `pivot_turn`: one yaw for the whole phase (the mean), the foot still.
        let (targets, _) = turning_stance(20f64.to_radians());
        for p in &targets {
            assert!((yaw(p) - 10f64.to_radians()).abs() < 1e-6, "yaw {}", yaw(p));
            assert!((p.pos - targets[0].pos).norm() < 1e-9);
        }
    }

    #[test]
    fn feet_alongside_each_other_are_kept_apart_sideways() {
        let (left, mut right) = (box_foot(), box_foot());
        right.slot = 1;
        let at = |x: f64, y: f64| Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::new(x, y, 0.0) };
        let apart = |left_x: f64, left_y: f64, right_y: f64| {
            let mut targets = vec![at(left_x, left_y), at(0.0, right_y)];
            keep_feet_apart(&left, &right, &mut targets, 2, 0.03);
            (targets[0].pos - targets[1].pos, targets[0].pos.x - left_x)
        };
        // Side by side, 6 cm apart: soles 10 cm wide need 13 cm (half the push each).
        let (d, dx) = apart(0.0, 0.03, -0.03);
        assert!((d.y - 0.13).abs() < 1e-12 && d.x.abs() < 1e-12 && dx.abs() < 1e-12, "{d}");
        // Already far enough apart, or one well ahead of the other: left alone.
        assert!((apart(0.0, 0.1, -0.1).0.y - 0.2).abs() < 1e-12);
        assert!((apart(0.5, 0.03, -0.03).0.y - 0.06).abs() < 1e-12);
        // Crossed over by 20 cm: narrowed by at most MAX_WIDENING, not uncrossed.
        let (d, _) = apart(0.0, -0.1, 0.1);
        assert!((d.y - (-0.2 + MAX_WIDENING)).abs() < 1e-12, "{d}");
    }

    /// A foot turned across the other (a turn on the spot) reaches sideways by its own
    /// footprint, not by the footprint it would have facing the mean heading: the left foot
    /// turned 90° to the left (yaw ±45° about the mean, 20 × 10 cm soles) is moved until the
    /// two turned footprints are `gap` apart across the mean heading.
    #[test]
    fn a_foot_turned_across_the_other_is_kept_apart_by_its_own_footprint() {
        let (left, mut right) = (box_foot(), box_foot());
        right.slot = 1;
        let turned = |yaw: f64, y: f64| {
            let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
            let q = [q.w, q.i, q.j, q.k];
            Pose { quat: q, pos: Vector3::new(0.0, y, 0.0) }
        };
        let quarter = std::f64::consts::FRAC_PI_4;
        let mut targets = vec![turned(quarter, 0.08), turned(-quarter, -0.08)];
        keep_feet_apart(&left, &right, &mut targets, 2, 0.03);
        // Each turned sole reaches (0.1 + 0.05) cos 45° = 10.6 cm across the mean heading
        // (+x): 21.2 cm + the 3 cm gap between the origins.
        let need = 2.0 * 0.15 * quarter.cos() + 0.03;
        let d = targets[0].pos - targets[1].pos;
        assert!((d.y - need).abs() < 1e-12, "{d} against {need}");
        assert!(d.x.abs() < 1e-12, "{d}");
    }

    #[test]
    fn only_a_frame_convention_is_turned_away() {
        let deg = f64::to_radians;
        assert!((convention_turn(deg(177.0)) - deg(180.0)).abs() < 1e-12, "Toddy's left calf");
        assert!((convention_turn(deg(-170.0)) + deg(180.0)).abs() < 1e-12);
        for toe_out in [3.7, -3.0, 18.3, -46.3, 60.0] {
            assert_eq!(convention_turn(deg(toe_out)), 0.0, "{toe_out}° is the human's");
        }
    }

    #[test]
    fn smoothstep_ends_flat() {
        assert_eq!(smoothstep(0.0), 0.0);
        assert_eq!(smoothstep(1.0), 1.0);
        assert!((smoothstep(0.5) - 0.5).abs() < 1e-15);
        let slope = |w: f64| (smoothstep(w + 1e-6) - smoothstep(w - 1e-6)) / 2e-6;
        assert!(slope(1e-6).abs() < 1e-5 && slope(1.0 - 1e-6).abs() < 1e-5);
    }
}
