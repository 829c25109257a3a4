//! The robot half of a derived config ([`RobotSide`]): per role its body and frame, the limb
//! frames turned by the knee and elbow hinges ([`MiddleHinge`]), the soles' primitives
//! ([`SoleGeom`]) and the robot's proportions.

use std::collections::BTreeMap;

use fk::{Part, Role, Side};
use mjcf::{Data, Model};
use nalgebra::{UnitQuaternion, Vector3};

use super::human::{paths, segments};
use super::shoulder::{shoulder, Shoulder};
use crate::robot_roles::RobotRoles;

/// A knee or elbow range whose two sides from straight differ by less than this share of it
/// is symmetric (servos'): it does not tell the flexion sense.
const SYMMETRIC_RANGE: f64 = 0.1;

/// A knee or elbow hinge of the robot, as the position fit sees it: its axis in the canonical
/// frame of the limb's proximal role, the joint value that lays the limb straight, its range.
#[derive(Debug, Clone, Copy)]
pub(super) struct MiddleHinge {
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
    pub(super) fn clamp(&self, rel: UnitQuaternion<f64>) -> UnitQuaternion<f64> {
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
pub(super) struct SoleGeom {
    pub(super) kind: mjcf::GeomType,
    pub(super) size: [f64; 3],
    pub(super) pos: Vector3<f64>,
    pub(super) rot: UnitQuaternion<f64>,
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
pub(super) fn sole_low(geoms: &[SoleGeom], frame: &UnitQuaternion<f64>) -> f64 {
    geoms
        .iter()
        .map(|g| {
            let r = (frame * g.rot).to_rotation_matrix().into_inner();
            (frame * g.pos).z + crate::constraints::support_offset(g.kind, &g.size, &r).z
        })
        .fold(f64::INFINITY, f64::min)
}

/// The robot's half: per role, body, `C_r⁻¹ ⊗ q_body`, body offset from the role point (in the
/// body frame), and path lengths like [`HumanBody::paths`](super::human::HumanBody::paths).
pub(super) struct RobotSide {
    pub(super) bodies: BTreeMap<Role, (String, UnitQuaternion<f64>, Vector3<f64>)>,
    pub(super) paths: BTreeMap<Role, f64>,
    /// Per role: the segment to its role point from its parent role's ([`segments`]).
    pub(super) segments: BTreeMap<Role, (Option<Role>, Vector3<f64>)>,
    /// Per role: the body origin from the role point, in the role's canonical frame.
    pub(super) origins: BTreeMap<Role, Vector3<f64>>,
    /// Knee and elbow hinges, by the shin / forearm role.
    pub(super) hinges: BTreeMap<Role, MiddleHinge>,
    /// The canonical frames used (`limb_frames`).
    pub(super) frames: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Whether its arms do not flex forward at `qpos0`: `limb_frames` turned an upper arm's
    /// frame more than 45° from its canonical one (ToddlerBot's sideways elbows).
    pub(super) arms_sideways: bool,
    /// Per foot role, its sole's primitives ([`sole_geoms`]).
    pub(super) soles: BTreeMap<Role, Vec<SoleGeom>>,
    /// The arms whose shoulders cannot turn the upper arm about its bone ([`Shoulder`]).
    pub(super) shoulders: BTreeMap<Side, Shoulder>,
}

pub(super) fn robot_side(model: &Model, roles: &RobotRoles) -> RobotSide {
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
        shoulders: [Side::Left, Side::Right]
            .into_iter()
            .filter_map(|side| Some((side, shoulder(model, &data, roles, side)?)))
            .collect(),
        frames,
        arms_sideways,
    }
}
