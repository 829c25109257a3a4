//! The robot's sole: the collision primitives of the foot body and its descendants, placed as
//! at `qpos0` relative to the foot body (a foot without collision geometry stands on the
//! uniform box of its mass and inertia, [`inertia_sole`]), the points it stands on
//! ([`RobotFoot::toe_point`], `bottom_points`) and the points a planted sole is held at
//! ([`SolePoint`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: geom ids come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, GeomType, Model};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use super::inertia::inertia_sole;
use super::math::{quat, smoothstep, wrap};
use crate::constraints::{collision_primitives, support_offset};
use crate::lie::Pose;

/// A robot foot: the body whose task follows the human foot, and its sole.
#[derive(Debug, Clone)]
pub struct RobotFoot {
    pub body: usize,
    /// Target slot of the foot's task.
    pub slot: usize,
    /// Sole primitives: kind, size and pose relative to the foot body (at `qpos0`).
    pub(super) sole: Vec<(GeomType, [f64; 3], Isometry3<f64>)>,
    /// The foot body's forward direction in its own frame (world +x at `qpos0`).
    pub(super) forward: Vector3<f64>,
    /// The foot body's world orientation at `qpos0`: standing flat.
    pub(super) rest: UnitQuaternion<f64>,
    /// The sole's bottom points in the foot frame (`bottom_points` of each primitive):
    /// where it stands on the floor.
    pub(super) corners: Vec<Vector3<f64>>,
    /// The shin: target slot of the nearest ancestor body with a task, and the foot's
    /// orientation relative to it at `qpos0` (`shin⁻¹ ⊗ foot`).
    pub(super) shin: Option<(usize, UnitQuaternion<f64>)>,
    /// The sole's collision geoms (none for a sole of inertia).
    pub geoms: Vec<usize>,
    /// Whether the ankle can roll the foot (a hinge between the shin and the foot turns
    /// about the foot's forward direction): a foot that can stands on the ball of its foot
    /// alone when it pivots; one that cannot (the H1's pitch-only ankle) stands on its toes.
    pub(super) rolls: bool,
}

/// Whether a hinge of the ankle, the joints from the foot `body` up to its `shin` (the
/// nearest tracked ancestor; without one, the first [`ANKLE_HINGES`] hinges above the foot),
/// turns about the foot's forward direction at `qpos0` (world +x, as [`RobotFoot`]'s
/// `forward`; within 45°).
fn ankle_rolls(model: &Model, data: &Data, body: usize, shin: Option<usize>) -> bool {
    let forward = Vector3::x();
    let mut hinges = 0;
    let mut b = body;
    while b != 0 && Some(b) != shin && hinges < ANKLE_HINGES {
        let first = model.bodies[b].jnt_adr;
        for j in first..first + model.bodies[b].jnt_num {
            if model.joints[j].kind == mjcf::JointType::Hinge {
                hinges += 1;
                if data.xaxis[j].dot(&forward).abs() > std::f64::consts::FRAC_1_SQRT_2 {
                    return true;
                }
            }
        }
        b = model.bodies[b].parent;
    }
    false
}

/// Hinges of an ankle, where no shin bounds it ([`ankle_rolls`]): pitch and roll.
const ANKLE_HINGES: usize = 2;

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
            .filter(|&g| model.is_ancestor_or_self(sole_body, model.geoms[g].body))
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
        let rolls = ankle_rolls(model, &data, body, shin.map(|s| s.0));
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
            rolls,
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
        match self.foremost_two() {
            Some((a, b)) => (a + b) / 2.0,
            None => self.sole_low_point(&self.rest),
        }
    }

    /// The ball of the foot in the foot frame, the point a pivot turns about: of the sole's
    /// two foremost bottom points, the one on the inner side (towards the other foot: the big
    /// toe's), where a foot turning on its toes stands. A foot whose ankle cannot roll
    /// ([`RobotFoot::rolls`]) stands on both, and turns about their middle
    /// ([`RobotFoot::toe_point`]), which slides them least. `side`: 0 the left foot, 1 the
    /// right.
    #[must_use]
    pub fn ball_point(&self, side: usize) -> Vector3<f64> {
        let left = self.left();
        match self.foremost_two() {
            // The left foot's inner side is its right (−left), the right foot's its left.
            Some((a, b)) if self.rolls => {
                if (left.dot(&a) < left.dot(&b)) == (side == 0) {
                    a
                } else {
                    b
                }
            }
            _ => self.toe_point(),
        }
    }

    /// The sole's two foremost bottom points (foot frame), foremost first.
    fn foremost_two(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let mut corners = self.corners.clone();
        corners.sort_by(|a, b| self.forward.dot(b).total_cmp(&self.forward.dot(a)));
        match corners.as_slice() {
            [a, b, ..] => Some((*a, *b)),
            _ => None,
        }
    }

    /// The foot's left direction in its own frame (world up × forward, standing flat).
    pub(super) fn left(&self) -> Vector3<f64> {
        (self.rest.inverse() * Vector3::z()).cross(&self.forward)
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

    /// The orientation of the foot standing flat (as at `qpos0`) with yaw `yaw`.
    pub(super) fn flat(&self, yaw: f64) -> UnitQuaternion<f64> {
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
    pub(super) fn yaw(&self, rot: &UnitQuaternion<f64>) -> f64 {
        let f = rot * self.forward;
        f.y.atan2(f.x)
    }
}

/// A cylinder whose axis is closer to the floor than 45° (this cosine of its angle to the
/// world's up) lies on its side (`bottom_points`: a bar along the foot); a steeper one stands
/// on its cap (a round sole).
const LYING: f64 = std::f64::consts::FRAC_1_SQRT_2;

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
        GeomType::Cylinder if axis.dot(&up).abs() < LYING => {
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

fn pose_of(pos: &Vector3<f64>, mat: &Matrix3<f64>) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_matrix(mat);
    Isometry3::from_parts(Translation3::from(*pos), rot)
}

/// Feet for the tests of the plan's parts.
#[cfg(test)]
pub(super) mod fixtures {
    use super::*;

    /// A flat foot with a 20 × 10 cm box sole, its origin at the sole's centre, facing +x.
    pub(crate) fn box_foot() -> RobotFoot {
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
            rolls: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
