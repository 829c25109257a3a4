//! IK configs derived from the two role sets, the robot's ([`RobotRoles`]) and a human's
//! ([`HumanBody`]: a recognised skeleton, or the canonical human), in GMR's schema so that
//! the solver and `--gmr` use them unchanged.
//!
//! Per role the robot has (pelvis, chest, and per side thigh, shin, foot, upper arm, forearm,
//! hand; the head is not tracked, as in GMR's configs):
//!
//! - **Body ↔ joint**: the role's robot body tracks the role's human joint.
//! - **Weights**: GMR's tuned G1 config (`configs/gmr/bvh_lafan1_to_g1.json`), per part,
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
//!   stand the robot on its toes). For a robot whose shoulder has one or two hinges (servo
//!   humanoids'), which cannot turn the upper arm about its bone, the human's arm frames are
//!   also turned back by the mean turn about the bone that the robot's shoulder cannot make
//!   when it points the upper arm as the human's (`shoulder`).
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
//! skeleton's frame offsets (`F_h ⊗ F_c⁻¹ ⊗ q_off`, `F_c` the canonical human's: identity
//! but for the arm turns of `shoulder`), scales are rescaled by canonical over skeleton
//! path lengths, position offsets are fitted to the skeleton's motion (keeping what the file
//! added to the canonical fit), and the height
//! assumption becomes the skeleton's height (times any factor the file applied to the
//! canonical one). Binding the role-named config of a robot gives exactly the config derived
//! for that skeleton directly.

mod fit;
mod human;
mod joint_frames;
mod robot;
mod shoulder;
mod weights;
mod write;

use std::borrow::Cow;

use fk::{Part, Role};
use mjcf::{Data, Model};

pub use self::fit::SOLE_CLEARANCE;
pub use self::human::{HumanBody, Posture, CANONICAL_HEIGHT};
pub use self::joint_frames::{JointFrames, FRAMES_AGREE, LAFAN1_FRAMES};
pub use self::weights::WEIGHTS;

use self::fit::fitted_offset;
use self::robot::{robot_side, RobotSide};
use self::shoulder::arm_turns;
use self::weights::{shoulder_hinges, weights, weights_of};
use self::write::{entry, file_of, written, Row};
use crate::config::{ConfigFile, IkConfig, MatchEntry, Ordered};
use crate::robot_roles::RobotRoles;
use crate::Error;

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

/// The config that maps `human` onto the robot (see the module docs); `source` names it in
/// messages. Roles missing on either side are left out; pelvis, thighs, shins and feet are
/// required.
pub fn derive(
    model: &Model,
    roles: &RobotRoles,
    human: &HumanBody,
    source: &str,
) -> Result<IkConfig, Error> {
    written(derived_file(model, roles, human, source)?, source)
}

/// [`derive()`]'s config as its file says it, before [`written`] rounds it.
fn derived_file(
    model: &Model,
    roles: &RobotRoles,
    human: &HumanBody,
    source: &str,
) -> Result<ConfigFile, Error> {
    let robot = robot_side(model, roles);
    let human = &*matched(human, &robot);
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
            // walk: hands L↔L 0.43 → 0.64, legs' likeness 0.81 → 0.64). With the mean turn
            // it cannot make taken out of the arm frames (`shoulder`), 100 is still no better
            // (the OP3 URDF's hands L↔L 0.80 → 0.76, legs' likeness 0.44 → 0.50).
            weights[1] = weights_of(Part::Forearm)[1];
        }
        rows.push(Row { role, body: body.clone(), joint: joint.clone(), rot, pos, scale, weights });
    }
    Ok(file_of(&rows, human.height))
}

/// `human` as `robot` is matched with: [`HumanBody::for_robot`], then the arms of a robot
/// whose shoulders cannot turn the upper arm about its bone turned to what they can do
/// ([`arm_turns`]).
fn matched<'a>(human: &'a HumanBody, robot: &RobotSide) -> Cow<'a, HumanBody> {
    let human = human.for_robot(robot.arms_sideways);
    let turns = arm_turns(&human, &robot.shoulders, &robot.frames);
    if turns.is_empty() {
        return human;
    }
    let mut out = human.into_owned();
    for (role, turn) in turns {
        out.turn(role, turn);
    }
    Cow::Owned(out)
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
    written(bound_file(config, human, model, roles)?, &config.source)
}

/// [`bind`]'s config as its file says it, before [`written`] rounds it.
fn bound_file(
    config: &IkConfig,
    human: &HumanBody,
    model: &Model,
    roles: &RobotRoles,
) -> Result<ConfigFile, Error> {
    let robot = robot_side(model, roles);
    let canonical = matched(&HumanBody::canonical(), &robot).into_owned();
    let human = &*matched(human, &robot);
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
        // The file's offset from the canonical human's frame (identity but where `matched`
        // turned it for this robot's arms), put onto this human's.
        let relative =
            canonical.frame_offsets.get(&role).map_or(e.rot_offset, |c| c.inverse() * e.rot_offset);
        let rot = frame * relative;
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
            fitted_offset(&robot, h, role, origin?, relative, root, s)
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
    let human_root = Role::from_name(&config.human_root_name)
        .and_then(|r| human.joints.get(&r))
        .cloned()
        .unwrap_or_else(|| config.human_root_name.clone());
    let scales = config
        .human_scale_table
        .iter()
        .map(|(name, _)| {
            let role = role_of(name)?;
            Ok((human.joints.get(&role).ok_or_else(|| missing(role))?.clone(), scale_of(name)?))
        })
        .collect::<Result<_, Error>>()?;
    let table = |table: &[MatchEntry]| {
        let rows = table.iter().filter_map(|e| {
            let (_, row) = rows.iter().find(|(o, _)| o.robot_body == e.robot_body)?;
            Some((row.body.clone(), entry(&row.joint, e.pos_weight, e.rot_weight, row)))
        });
        Ordered(rows.collect())
    };
    Ok(ConfigFile {
        robot_root_name: config.robot_root_name.clone(),
        human_root_name: human_root,
        ground_height: config.ground_height,
        human_height_assumption: height,
        use_ik_match_table1: config.use_ik_match_table1,
        use_ik_match_table2: config.use_ik_match_table2,
        human_scale_table: Ordered(scales),
        ik_match_table1: table(&config.ik_match_table1),
        ik_match_table2: table(&config.ik_match_table2),
        ..ConfigFile::default()
    })
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
/// - `tuned` (a config written for [`LAFAN1_FRAMES`], as the shipped ones are) when the
///   skeleton has its human body names and LAFAN1's joint frames ([`JointFrames::differs`]:
///   a property of the skeleton, whatever the motion), with or without `gmr` (`--gmr`: GMR
///   takes it on any skeleton with the names, but its rotation offsets hold only for those
///   frames; GMR stops with a `KeyError` on other names), and, in the default solve, when it
///   agrees with the robot's joint frames ([`contradiction`]);
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
    let source = format!("<derived for {robot}>");
    let derived_here = |roles: &RobotRoles| -> Result<IkConfig, Error> {
        derive(model, roles, &human_body(bvh, fk_options, "the skeleton")?, &source)
    };
    // The derived config, once made (the default solve checks the tuned one against it).
    let mut derived = None;
    let mut why_not = String::new();
    if let Some(tuned) = tuned {
        let names = fk::body_names(bvh, fk_options)?;
        let solve = if gmr { "; --gmr: GMR's solve" } else { "" };
        if tuned.validate(model, &names).is_err() {
            // GMR itself stops here (a KeyError on the first missing body); GMR's solve with
            // the derived config is the nearest thing, and what `--gmr` comparisons need.
            if gmr {
                why_not = format!(
                    " (--gmr: GMR's solve; the tuned {} names bodies the skeleton lacks)",
                    tuned.source
                );
            }
        } else {
            // GMR would take the tuned config on any skeleton with these names; its rotation
            // offsets hold only for LAFAN1's joint frames (a HumanIK or joints2bvh export
            // in a T zero pose stood on its head with them), so `--gmr` asks the same.
            let humanoid = fk::recognise(bvh, &fk_options.roles)?;
            let frames = LAFAN1_FRAMES;
            // The default solve also asks that it agree with the robot's joint frames.
            let reason = match frames.differs(&humanoid, fk_options.axes) {
                Some(reason) => Some(format!("the skeleton has its names, but {reason}")),
                None if gmr => None,
                None => {
                    let roles = RobotRoles::recognise(model)?;
                    let config = derived.insert(derived_here(&roles)?);
                    contradiction(tuned, config, &roles).map(|c| c.to_string())
                }
            };
            match reason {
                None => {
                    let summary = format!(
                        "config {} (tuned: the skeleton has its names and {}'s joint frames{solve})",
                        tuned.source, frames.name
                    );
                    return Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary });
                }
                Some(reason) => {
                    why_not = format!(" (not the tuned {}: {reason}{solve})", tuned.source);
                }
            }
        }
    }
    let config = match derived {
        Some(config) => config,
        None => derived_here(&RobotRoles::recognise(model)?)?,
    };
    let summary = format!("config derived from the roles of {robot} and of the skeleton{why_not}");
    Ok(Chosen { config, choice: Choice::Derived, summary })
}

/// Active entries of the first table (for tests and reports).
#[must_use]
pub fn active_entries(config: &IkConfig) -> Vec<&MatchEntry> {
    config.ik_match_table1.iter().filter(|e| e.is_active()).collect()
}

/// The parts of the body that carry the robot: a tuned config must agree with the robot's
/// joint frames on these ([`contradiction`]).
const CARRYING: [Part; 7] =
    [Part::Pelvis, Part::Spine, Part::Chest, Part::Thigh, Part::Shin, Part::Foot, Part::Toe];

/// A tuned config's rotation offset further than this (rad) from the derived config's for
/// the same robot and human bodies turns the body against the robot's joint frames: no
/// tuning turns a knee more than a quarter turn. (GMR's `smplx_to_bhl.json` turns the
/// Berkeley Humanoid Lite's left knee 178.6° from them, its right knee 6.5°: the default
/// solve's root accelerated 2.6–3.4 × the scaled human's on AMASS walks, 1.0 × with the
/// derived config.) Arms are left out: a servo shoulder's derived offsets turn the human's
/// arm frames (`shoulder::arm_turns`), ToddlerBot's hands by 94–150°.
pub const CONTRADICTS: f64 = std::f64::consts::FRAC_PI_2;

/// Where a tuned config contradicts the robot's joint frames ([`contradiction`]): the robot
/// body of the row and how far (rad) its rotation offset is from the derived one's.
#[derive(Debug, Clone, PartialEq)]
pub struct Contradiction {
    pub body: String,
    pub angle: f64,
}

impl std::fmt::Display for Contradiction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let degrees = self.angle.to_degrees();
        write!(f, "it turns {} {degrees:.0}° from the robot's joint frames", self.body)
    }
}

/// Where the `tuned` config contradicts the robot's joint frames (as the `derived` config
/// for the same source has them): its row for a body that carries the robot (pelvis, trunk,
/// legs) whose rotation offset is more than [`CONTRADICTS`] from the derived one's (same
/// robot and human body, both with a rotation weight), the furthest.
#[must_use]
pub fn contradiction(
    tuned: &IkConfig,
    derived: &IkConfig,
    roles: &RobotRoles,
) -> Option<Contradiction> {
    let carrying = |body: &str| {
        roles.roles.iter().any(|(role, r)| r.name == body && CARRYING.contains(&role.part()))
    };
    let rotated = |c: &IkConfig| -> Vec<MatchEntry> {
        c.ik_match_table1.iter().filter(|e| e.rot_weight > 0.0).cloned().collect()
    };
    let derived = rotated(derived);
    rotated(tuned)
        .into_iter()
        .filter(|t| carrying(&t.robot_body))
        .filter_map(|t| {
            let d = derived
                .iter()
                .find(|d| d.robot_body == t.robot_body && d.human_body == t.human_body)?;
            let angle = t.rot_offset.angle_to(&d.rot_offset);
            Some(Contradiction { body: t.robot_body, angle })
        })
        .filter(|c| c.angle > CONTRADICTS)
        .max_by(|a, b| a.angle.total_cmp(&b.angle))
}
