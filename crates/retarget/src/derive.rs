//! IK configs derived from the two role sets, the robot's ([`RobotRoles`]) and a human's
//! ([`HumanBody`]: a recognised skeleton, or the canonical human), in GMR's schema so that
//! the solver and `--gmr` use them unchanged.
//!
//! Per role the robot has (pelvis, chest, and per side thigh, shin, foot, upper arm, forearm,
//! hand; the head is not tracked, as in GMR's configs):
//!
//! - **Body ↔ joint**: the role's robot body tracks the role's human joint.
//! - **Weights**: GMR's tuned G1 config (`configs/bvh_lafan1_to_unitree_g1.json`), per part:
//!
//!   | part | table 1 pos | table 1 rot | table 2 pos | table 2 rot |
//!   |---|---|---|---|---|
//!   | pelvis | 0 | 10 | 100 | 5 |
//!   | thigh, shin | 0 | 10 | 10 | 5 |
//!   | foot | 50 | 10 | 50 | 10 |
//!   | chest | 0 | 100 | 0 | 10 |
//!   | upper arm | 0 | 100 | 5 | 100 |
//!   | forearm, hand | 0 | 10 | 10 | 5 |
//!
//! - **Rotation offset** `q_off = F_h ⊗ C_r⁻¹ ⊗ q_body`: `F_h = q_joint⁻¹ ⊗ C_h` is the
//!   human's frame offset ([`fk::Humanoid::frame_offsets`], identity for the canonical human),
//!   `C_r` the robot role's canonical frame and `q_body` its body's orientation at `qpos0`.
//!   The target `q_joint ⊗ q_off = C_h ⊗ (C_r⁻¹ ⊗ q_body)` puts the robot body where the
//!   human's canonical frame says, whatever either side's joint frames are.
//! - **Position offset**, in the body's target frame: `q_body⁻¹ (x_body − p_r)`, the body's
//!   origin seen from its role point `p_r` (a hip's joint centre, not the hip-yaw body's
//!   origin 12 cm below it on the G1), so that the role point lands on the human joint; for
//!   the pelvis also the human's hip midpoint seen from its pelvis joint, `s · q_off⁻¹ d_h`.
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
//! path lengths, the pelvis offset gets the skeleton's hip midpoint, and the height
//! assumption becomes the skeleton's height (times any factor the file applied to the
//! canonical one). Binding the role-named config of a robot gives exactly the config derived
//! for that skeleton directly.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use fk::{HumanMotion, Humanoid, Part, Role, Side};
use mjcf::{Data, Model};
use nalgebra::{UnitQuaternion, Vector3};

use crate::config::{IkConfig, MatchEntry};
use crate::robot_roles::RobotRoles;

use crate::Error;

/// GMR's G1 weights per part: `[table1 pos, table1 rot, table2 pos, table2 rot]`.
pub const WEIGHTS: [(Part, [f64; 4]); 8] = [
    (Part::Pelvis, [0.0, 10.0, 100.0, 5.0]),
    (Part::Thigh, [0.0, 10.0, 10.0, 5.0]),
    (Part::Shin, [0.0, 10.0, 10.0, 5.0]),
    (Part::Foot, [50.0, 10.0, 50.0, 10.0]),
    (Part::Chest, [0.0, 100.0, 0.0, 10.0]),
    (Part::UpperArm, [0.0, 100.0, 5.0, 100.0]),
    (Part::Forearm, [0.0, 10.0, 10.0, 5.0]),
    (Part::Hand, [0.0, 10.0, 10.0, 5.0]),
];

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

/// The human half of a derived config: one skeleton's joint per role, its frame offsets and
/// its proportions (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct HumanBody {
    /// Human body (joint) name per role.
    pub joints: BTreeMap<Role, String>,
    /// `q_joint⁻¹ ⊗ C_h` per role ([`fk::Humanoid::frame_offsets`]).
    pub frame_offsets: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Path length from the pelvis point (midway between the hip joints) to each role's joint
    /// through the role joints ([`module docs`](self)); the pelvis's entry is the standing hip
    /// height (thigh + shin + ankle height).
    pub paths: BTreeMap<Role, f64>,
    /// The hip midpoint in the pelvis joint's frame (m).
    pub hip_midpoint: Vector3<f64>,
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
            paths: paths(&points, ankle),
            hip_midpoint: Vector3::zeros(),
            height: CANONICAL_HEIGHT,
            source: "the canonical human".to_owned(),
        }
    }

    /// The human half for a recognised skeleton and its motion (metres, Z up): frame offsets
    /// from `humanoid`, proportions averaged over up to 64 frames, the ankle height from how
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
        let count = n.min(64);
        let picked: Vec<usize> =
            (0..count).map(|k| if count > 1 { k * (n - 1) / (count - 1) } else { 0 }).collect();
        let mut sums: BTreeMap<Role, f64> = BTreeMap::new();
        let mut hip_midpoint = Vector3::zeros();
        for &f in &picked {
            let points: BTreeMap<Role, Vector3<f64>> = Role::ALL
                .iter()
                .filter_map(|&r| Some((r, *motion.position(f, index(r)?))))
                .collect();
            for (role, length) in paths(&points, 0.0) {
                *sums.entry(role).or_default() += length;
            }
            if let (Some(p), Some(l), Some(r)) =
                (index(Role::Pelvis), index(Role::LeftThigh), index(Role::RightThigh))
            {
                let mid = (motion.position(f, l) + motion.position(f, r)) / 2.0;
                hip_midpoint += motion.orientation(f, p).inverse() * (mid - motion.position(f, p));
            }
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
        let ankle = ankle_height(motion, [index(Role::LeftFoot), index(Role::RightFoot)], ground);
        if let Some(legs) = paths.get_mut(&Role::Pelvis) {
            *legs += ankle;
        }
        Ok(HumanBody {
            joints: kept,
            frame_offsets: humanoid.frame_offsets.clone(),
            paths,
            hip_midpoint: hip_midpoint / count,
            height,
            source: source.to_owned(),
        })
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

/// Ankle joint height when the foot is flat: the 5th percentile of the ankles' height above
/// `ground` over the clip (a walk's flat-foot frames), within 2–15 cm.
fn ankle_height(motion: &HumanMotion, feet: [Option<usize>; 2], ground: f64) -> f64 {
    let mut z: Vec<f64> = feet
        .iter()
        .flatten()
        .flat_map(|&b| (0..motion.num_frames).map(move |f| (b, f)))
        .map(|(b, f)| motion.position(f, b).z - ground)
        .filter(|v| v.is_finite())
        .collect();
    if z.is_empty() {
        return 0.039 * CANONICAL_HEIGHT;
    }
    z.sort_by(f64::total_cmp);
    z[(z.len() - 1) / 20].clamp(0.02, 0.15)
}

/// The robot's half: per role, body, `C_r⁻¹ ⊗ q_body`, body offset from the role point (in the
/// body frame), and path lengths like [`HumanBody::paths`].
struct RobotSide {
    bodies: BTreeMap<Role, (String, UnitQuaternion<f64>, Vector3<f64>)>,
    paths: BTreeMap<Role, f64>,
}

fn robot_side(model: &Model, roles: &RobotRoles) -> RobotSide {
    let mut data = Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let frames = roles.canonical_frames();
    let mut bodies = BTreeMap::new();
    for (role, r) in &roles.roles {
        let Some(c) = frames.get(role) else { continue };
        let q = data.xquat[r.body];
        let offset = q.inverse() * (data.xpos[r.body] - r.point);
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
    RobotSide { bodies, paths: paths(&points, ankle.max(0.0)) }
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
        let mut pos = *offset;
        if role == Role::Pelvis {
            pos += rot.inverse() * human.hip_midpoint * scale;
        }
        rows.push(Row { role, body: body.clone(), joint: joint.clone(), rot, pos, scale });
    }
    let text = config_json(&rows, human.height);
    IkConfig::from_json_str(&text, source)
}

/// A role-named config ([`derive()`] against [`HumanBody::canonical`]) bound to `human` (see
/// the module docs). Entries whose human name is not a role, or whose role the skeleton
/// lacks, are errors naming them.
pub fn bind(config: &IkConfig, human: &HumanBody) -> Result<IkConfig, Error> {
    let canonical = HumanBody::canonical();
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
        let mut pos = e.pos_offset;
        if role == Role::Pelvis {
            pos += rot.inverse() * human.hip_midpoint * scale;
        }
        rows.push((
            e.clone(),
            Row { role, body: e.robot_body.clone(), joint: joint.clone(), rot, pos, scale },
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

/// The largest angle (rad) between the rotation offsets `a` and `b` give the same robot body,
/// over the bodies both track: how far apart two configs' ideas of the joint frames are.
#[must_use]
pub fn largest_offset_difference(a: &IkConfig, b: &IkConfig) -> Option<f64> {
    let mut worst: Option<f64> = None;
    for e in a.ik_match_table1.iter().filter(|e| e.is_active()) {
        let Some(o) = b.ik_match_table1.iter().find(|o| o.robot_body == e.robot_body) else {
            continue;
        };
        let angle = e.rot_offset.angle_to(&o.rot_offset);
        worst = Some(worst.map_or(angle, |w: f64| w.max(angle)));
    }
    worst
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
                let w = WEIGHTS.iter().find(|(p, _)| *p == r.role.part()).map_or([0.0; 4], |w| w.1);
                (r.body.clone(), r.joint.clone(), w[*table], w[table + 1], r.pos, r.rot)
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

/// Largest rotation-offset difference (rad) between a tuned config and the derived one for
/// which the skeleton counts as the one the tuned config was written for.
pub const TUNED_AGREES: f64 = 45.0 * std::f64::consts::PI / 180.0;

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
/// - `tuned` with `gmr` (`--gmr`): always the tuned config (GMR's exact behaviour);
/// - `tuned` when the skeleton has its human body names and the same joint frames (every
///   rotation offset within [`TUNED_AGREES`] of the derived config's): the tuned config;
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
        let bound = bind(&config, &human)?;
        let summary = format!("config {} (role-named), bound to the skeleton", config.source);
        return Ok(Chosen { config: bound, choice: Choice::Bound, summary });
    }
    if let (Some(tuned), true) = (tuned, gmr) {
        let summary = format!("config {} (tuned; --gmr)", tuned.source);
        return Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary });
    }
    let roles = RobotRoles::recognise(model)?;
    let human = human_body(bvh, fk_options, "the skeleton")?;
    let source = format!("<derived for {robot}>");
    let derived = derive(model, &roles, &human, &source)?;
    if let Some(tuned) = tuned {
        let names = fk::body_names(bvh, fk_options)?;
        let names_fit = tuned.validate(model, &names).is_ok();
        let angle = largest_offset_difference(tuned, &bind_names(&derived, tuned, &human));
        if names_fit && angle.is_some_and(|a| a <= TUNED_AGREES) {
            let summary = format!(
                "config {} (tuned: the skeleton has its names and joint frames, within {:.0}°)",
                tuned.source,
                angle.unwrap_or(0.0).to_degrees()
            );
            return Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary });
        }
    }
    let summary = format!("config derived from the roles of {robot} and of the skeleton");
    Ok(Chosen { config: derived, choice: Choice::Derived, summary })
}

/// `derived` with its robot bodies renamed to the ones `tuned` uses for the same human joint
/// (GMR's configs pick other bodies for some roles, e.g. the N1's thigh roll link): offsets
/// of different bodies are not comparable, so only shared (robot body, human joint) pairs
/// count in [`largest_offset_difference`].
/// Hands are left out: their canonical frame is the forearm's in the reference pose, so it
/// carries whatever bend the subject's wrist had there.
fn bind_names(derived: &IkConfig, tuned: &IkConfig, human: &HumanBody) -> IkConfig {
    let hands: Vec<&String> =
        [Role::LeftHand, Role::RightHand].iter().filter_map(|r| human.joints.get(r)).collect();
    let mut out = derived.clone();
    out.ik_match_table1.retain(|e| !hands.contains(&&e.human_body));
    out.ik_match_table1.retain(|e| {
        tuned
            .ik_match_table1
            .iter()
            .any(|t| t.robot_body == e.robot_body && t.human_body == e.human_body)
    });
    out
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

    #[test]
    fn numbers_round_trip_and_stay_readable() {
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(-1e-12), "0.0");
        assert_eq!(number(100.0), "100.0");
        assert_eq!(number(0.123456789123), "0.123456789");
        assert_eq!(escape("a\"b"), "a\\\"b");
    }
}
