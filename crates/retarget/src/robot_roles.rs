//! The robot recogniser: which body of a robot model plays which [`Role`] of the canonical
//! humanoid (the vocabulary the skeleton recogniser [`fk::recognise`] uses on the human side),
//! decided by the kinematic tree and its geometry at `qpos0`, with names
//! ([`crate::robot_names`]) telling left from right.
//!
//! The rules, in the order they run (each role's [`RobotRole::rule`] says which decided it):
//!
//! 0. A model without a free joint gets one first ([`add_floating_base`], called by
//!    [`crate::shipped::load_robot`]), stood up when it lies at `qpos0`.
//! 1. **Floating base**: the body of the first free joint (a URDF gets one on loading).
//! 2. **Legs**: the lowest body at `qpos0` (origin or primitive geom) is one foot; walking up
//!    its ancestors, the first one with another branch that reaches as low (within 15 % of the
//!    robot's height) while hanging at least 25 % of that height below it is the **pelvis**;
//!    the lowest body of that branch is the other foot. A leg rolling on a wheel (an unlimited
//!    hinge across the direction of travel carrying a round geom on the floor) is an error;
//!    an unlimited hinge alone is only a joint without limits (ROBOTIS OP3's ankles).
//! 3. **Arms**: among the bodies outside the legs, the ones farthest to either side of the
//!    hips' left-right axis belong to the two arms; their lowest common ancestor is the
//!    **chest**, and each arm runs from it to the body of its branch farthest from the chest
//!    (through the hand to a fingertip, if any).
//! 4. **Head**: the highest body outside the arms and legs that is not a sensor by its name
//!    (camera, IMU: [`robot_names::EXTRAS`]), if it is above the shoulders: the
//!    last body with a joint on the way to it, else that body.
//! 5. **Limb joints** (the same rule for arms and legs): the hinges along the chain are split
//!    at the **knee / elbow**, the first hinge at least 35 % of the limb's span away from the
//!    limb's first hinge and whose axis is within 60° of perpendicular to the bone leading to
//!    it from the previous hinge or from the limb's first one (a twist joint along the upper
//!    arm, like the G1's shoulder yaw, is skipped). The
//!    hinges before it form the hip / shoulder; the **thigh / upper arm** is the body of the
//!    last of them (it carries all the joint's rotations, as the human thigh does: GMR's
//!    choice on the G1, the T1's legs and ToddlerBot; its N1 and PM01 configs take the
//!    middle, roll body, which leaves the yaw out). The **shin / forearm** is the knee /
//!    elbow hinge's body. The **foot / hand** is the body of the last hinge after it, the
//!    chain stopping where it branches into fingers; with no hinge after the elbow, the
//!    arm's end body when it is another body (ToddlerBot's `hand`), else no hand.
//! 6. **Facing and sides**: forward is ⟂ the hips' axis, its sign from where the knees bend
//!    (the ankle moves back when a knee flexes in its larger range) and where the feet reach
//!    (sole geometry and toe bodies ahead of the ankle); left = up × forward. When both legs'
//!    and both arms' names state opposite sides, names decide (and the facing follows them).
//!    Up is world +z; the robot must stand at `qpos0` (shoulders above the hips above the
//!    feet).
//! 7. **Soles**: the collision primitives of each foot's subtree (the foot body and what hangs
//!    from it), lowest first; a geom named `left_sole` / `right_sole` in it comes first.
//!
//! Every role also has a **role point** (world, `qpos0`): the point the human joint of that
//! role corresponds to. For a group of hinges it is the point nearest to all their axes
//! (least squares: their intersection when they meet, as a spherical hip's do); for the
//! pelvis the midpoint of the two hip points, for the chest its body's origin, for an end
//! body without a joint its origin.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: body, joint and geom ids come from the `mjcf::Model` being recognised, whose loader
// guarantees parents, addresses and geom bodies in range.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::fmt::Write as _;

use fk::{Part, Role, Side};
use mjcf::{Data, JointType, Model};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::robot_names;
use crate::Error;

mod floating_base;
mod limbs;
mod sides;

pub use floating_base::add_floating_base;

/// A limb's knee or elbow is at least this share of the limb's span from its first hinge.
const MIDDLE_AT: f64 = 0.35;
/// ... and its axis within 60° of perpendicular to the bone (|cos| below this).
const PERPENDICULAR_COS: f64 = 0.5;
/// Legs hang at least this share of the robot's height below the pelvis ...
const LEG_LENGTH: f64 = 0.25;
/// ... and the second foot is within this share of the height of the lowest point.
const FEET_LEVEL: f64 = 0.15;
/// A wheel's axis is within 30° of the hips' left-right axis (|cos| above this), and so is a
/// round geom's own axis to the wheel's.
const WHEEL_AXIS_COS: f64 = 0.866;

/// The body playing a role, the point the human joint maps to, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRole {
    pub body: usize,
    /// Body name (`body <id>` when the model gives none).
    pub name: String,
    /// The role point in the world at `qpos0` (see the module docs).
    pub point: Vector3<f64>,
    /// The rule that decided it, for `retarget robot info`.
    pub rule: String,
}

/// The ground-contact geometry under one foot.
#[derive(Debug, Clone, PartialEq)]
pub struct Sole {
    /// The foot role's body.
    pub body: usize,
    /// Collision primitives of the foot's subtree, lowest first (empty when it has none).
    pub geoms: Vec<usize>,
    /// The lowest point of the foot at `qpos0` (of those geoms, else of the bodies' origins).
    pub lowest: Vector3<f64>,
}

/// A recognised robot: its roles at `qpos0`.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRoles {
    /// The body of the floating base's free joint.
    pub base: usize,
    pub roles: BTreeMap<Role, RobotRole>,
    /// `[left, right]`.
    pub soles: [Sole; 2],
    /// The robot's forward direction at `qpos0` (horizontal unit vector) and how it was found.
    pub forward: Vector3<f64>,
    pub facing: String,
    /// How left and right were told apart.
    pub sides: String,
    /// Lowest to highest point at `qpos0` (m).
    pub height: f64,
    /// `[left, right]`: where each arm ends (its farthest point from the shoulder, geometry
    /// included), for the forearm's direction when the arm has no hand body.
    pub arm_ends: [Vector3<f64>; 2],
}

impl RobotRoles {
    /// Recognise the humanoid in `model` (see the module docs). A model that is not a
    /// two-armed biped standing at `qpos0` is an [`Error::NotHumanoid`] saying why.
    pub fn recognise(model: &Model) -> Result<RobotRoles, Error> {
        Recogniser::new(model)?.run()
    }

    /// The body playing `role`.
    #[must_use]
    pub fn body(&self, role: Role) -> Option<usize> {
        self.roles.get(&role).map(|r| r.body)
    }

    /// `[left, right]` soles: the foot bodies and their ground-contact geoms.
    #[must_use]
    pub fn soles(&self) -> [&Sole; 2] {
        [&self.soles[0], &self.soles[1]]
    }

    /// Role points as [`fk::canonical_frames`] takes them: the robot's trunk line is world up
    /// from the pelvis point (the robot stands at `qpos0`), given as a neck point at the
    /// shoulders' height straight above it and the chest midway; the head is left out (its
    /// frame is not used).
    #[must_use]
    pub fn frame_points(&self) -> BTreeMap<Role, Vector3<f64>> {
        let mut points: BTreeMap<Role, Vector3<f64>> = self
            .roles
            .iter()
            .filter(|(r, _)| **r != Role::Head)
            .map(|(r, role)| (*r, role.point))
            .collect();
        if let (Some(&p), Some(&l), Some(&r)) = (
            points.get(&Role::Pelvis),
            points.get(&Role::LeftUpperArm),
            points.get(&Role::RightUpperArm),
        ) {
            let neck = Vector3::new(p.x, p.y, (l.z + r.z) / 2.0);
            points.insert(Role::Neck, neck);
            // The chest body's origin may sit anywhere along the trunk (N1's at the shoulders):
            // its frame takes the trunk line, from a point midway up it.
            if points.contains_key(&Role::Chest) {
                points.insert(Role::Chest, (p + neck) / 2.0);
            }
        }
        // A forearm without a hand body points to where the arm ends, or (no geometry beyond
        // the elbow) continues the upper arm.
        for (side, end) in [Side::Left, Side::Right].into_iter().zip(self.arm_ends) {
            let at = |part| points.get(&Role::of(part, side)).copied();
            if let (None, Some(elbow), Some(shoulder)) =
                (at(Part::Hand), at(Part::Forearm), at(Part::UpperArm))
            {
                let hand = if (end - elbow).norm() > 0.02 * self.height {
                    end
                } else {
                    elbow + (elbow - shoulder) * 0.8
                };
                points.insert(Role::of(Part::Hand, side), hand);
            }
        }
        points
    }

    /// Canonical body frames ([`fk::canonical_frames`]) of the robot's roles at `qpos0`.
    #[must_use]
    pub fn canonical_frames(&self) -> BTreeMap<Role, UnitQuaternion<f64>> {
        let mut frames = fk::canonical_frames(&self.frame_points());
        frames.retain(|r, _| self.roles.contains_key(r));
        frames
    }

    /// The role table as `retarget robot info` prints it.
    #[must_use]
    pub fn describe(&self, model: &Model) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "floating base: {}", body_name(model, self.base));
        let _ = writeln!(out, "facing:        {}", self.facing);
        let _ = writeln!(out, "sides:         {}", self.sides);
        let _ = writeln!(out, "height:        {:.3} m at qpos0", self.height);
        let _ = writeln!(out, "{:<16} {:<28} {:>24}  rule", "role", "body", "point at qpos0 (m)");
        for (role, r) in &self.roles {
            let p = r.point;
            let point = format!("{:.3} {:.3} {:.3}", p.x, p.y, p.z);
            let _ = writeln!(out, "{:<16} {:<28} {point:>24}  {}", role.name(), r.name, r.rule);
        }
        for (side, sole) in ["left", "right"].iter().zip(&self.soles) {
            let geoms: Vec<String> = sole.geoms.iter().map(|&g| model.geom_label(g)).collect();
            let what = if geoms.is_empty() {
                "no collision geoms: the lowest body origin".to_owned()
            } else {
                geoms.join(", ")
            };
            let _ = writeln!(
                out,
                "{side:<5} sole       {:<28} lowest z {:.3}  {what}",
                body_name(model, sole.body),
                sole.lowest.z
            );
        }
        out
    }
}

fn body_name(model: &Model, b: usize) -> String {
    match model.bodies.get(b).map(|b| b.name.as_str()) {
        Some("") | None => format!("body {b}"),
        Some(name) => name.to_owned(),
    }
}

/// One hinge on a limb chain.
#[derive(Debug, Clone, Copy)]
struct Hinge {
    body: usize,
    anchor: Vector3<f64>,
    axis: Vector3<f64>,
    range: Option<[f64; 2]>,
}

/// A limb split at its knee or elbow.
#[derive(Debug, Clone)]
struct Limb {
    /// Bodies from the first below the pelvis / chest to the end.
    chain: Vec<usize>,
    proximal: Vec<Hinge>,
    middle: Hinge,
    distal: Vec<Hinge>,
    /// The end body when it has no hinge of its own after the middle one.
    end_body: Option<usize>,
    /// Farthest point of the limb from its first hinge.
    end_point: Vector3<f64>,
}

impl Limb {
    fn root(&self) -> Vector3<f64> {
        joint_centre(&self.proximal)
    }
}

/// The point nearest to the hinges' axis lines (least squares, slightly pulled towards the
/// anchors' mean so that parallel or single axes have an answer: the anchor for one hinge).
fn joint_centre(hinges: &[Hinge]) -> Vector3<f64> {
    if hinges.is_empty() {
        return Vector3::zeros();
    }
    let mean = hinges.iter().map(|h| h.anchor).sum::<Vector3<f64>>() / hinges.len() as f64;
    let lambda = 1e-3;
    let mut a = Matrix3::identity() * lambda;
    let mut b = mean * lambda;
    for h in hinges {
        let p = Matrix3::identity() - h.axis * h.axis.transpose();
        a += p;
        b += p * h.anchor;
    }
    a.lu().solve(&b).unwrap_or(mean)
}

struct Recogniser<'m> {
    model: &'m Model,
    data: Data,
    children: Vec<Vec<usize>>,
    /// Lowest point of each body (origin and primitive geoms), world z.
    lowest: Vec<f64>,
    base: usize,
    height: f64,
}

impl<'m> Recogniser<'m> {
    fn new(model: &'m Model) -> Result<Recogniser<'m>, Error> {
        let not = |reason: &str| Error::NotHumanoid {
            model: model.name.clone(),
            reason: reason.to_owned(),
        };
        let base = model
            .joints
            .iter()
            .find(|j| j.kind == JointType::Free)
            .map(|j| j.body)
            .ok_or_else(|| not("no floating base (no free joint)"))?;
        let mut data = Data::new(model);
        model.kinematics(&model.qpos0, &mut data);
        let mut children = vec![Vec::new(); model.nbody()];
        for (b, body) in model.bodies.iter().enumerate().skip(1) {
            children[body.parent].push(b);
        }
        // A body's geoms say where it reaches; an origin (which may sit anywhere, Berkeley
        // Humanoid Lite's base is on the floor) counts only for bodies without geoms.
        let mut lowest = vec![f64::INFINITY; model.nbody()];
        for (g, geom) in model.geoms.iter().enumerate() {
            if let Some(p) = mjcf::geom_lowest_point(model, &data, g) {
                lowest[geom.body] = lowest[geom.body].min(p.z);
            }
        }
        for (b, low) in lowest.iter_mut().enumerate() {
            if low.is_infinite() {
                *low = data.xpos[b].z;
            }
        }
        let mut r = Recogniser { model, data, children, lowest, base, height: 0.0 };
        let bodies = r.model.subtree(base);
        let low = bodies.iter().map(|&b| r.lowest[b]).fold(f64::INFINITY, f64::min);
        let high = bodies.iter().map(|&b| r.data.xpos[b].z).fold(f64::NEG_INFINITY, f64::max);
        r.height = high - low;
        if !(r.height.is_finite() && r.height > 0.0) {
            return Err(not("the model has no extent at qpos0"));
        }
        Ok(r)
    }

    fn not_humanoid(&self, reason: String) -> Error {
        Error::NotHumanoid { model: self.model.name.clone(), reason }
    }

    fn name(&self, b: usize) -> String {
        body_name(self.model, b)
    }

    fn lca(&self, a: usize, b: usize) -> usize {
        std::iter::once(a)
            .chain(self.model.ancestors(a))
            .find(|&x| self.model.is_ancestor_or_self(x, b))
            .unwrap_or(0)
    }

    /// Bodies strictly below `top` down to `bottom` (inclusive), top first.
    fn path(&self, top: usize, bottom: usize) -> Vec<usize> {
        let mut out = vec![bottom];
        let mut b = bottom;
        while b != top && b != 0 {
            b = self.model.bodies[b].parent;
            if b != top {
                out.push(b);
            }
        }
        out.reverse();
        out
    }

    fn hinges(&self, chain: &[usize]) -> Vec<Hinge> {
        let mut out = Vec::new();
        for &b in chain {
            let body = &self.model.bodies[b];
            for j in body.jnt_adr..body.jnt_adr + body.jnt_num {
                let joint = &self.model.joints[j];
                if matches!(joint.kind, JointType::Hinge | JointType::Ball) {
                    out.push(Hinge {
                        body: b,
                        anchor: self.data.xanchor[j],
                        axis: self.data.xaxis[j],
                        range: joint.range.filter(|_| joint.kind == JointType::Hinge),
                    });
                }
            }
        }
        out
    }

    fn run(self) -> Result<RobotRoles, Error> {
        let (pelvis, feet) = self.legs()?;
        let legs = feet
            .iter()
            .map(|&f| self.limb(self.path(pelvis, f), "leg", "knee"))
            .collect::<Result<Vec<Limb>, Error>>()?;
        let hips = [legs[0].root(), legs[1].root()];
        let mut across = hips[0] - hips[1];
        across.z = 0.0;
        let across = across
            .try_normalize(1e-9)
            .ok_or_else(|| self.not_humanoid("the two legs start at the same point".to_owned()))?;
        for (leg, &foot) in legs.iter().zip(&feet) {
            if let Some(wheel) = leg.distal.iter().rev().find(|h| self.is_wheel(h, across)) {
                return Err(self.not_humanoid(format!(
                    "wheeled: the leg ending in `{}` rolls on a wheel: an unlimited (continuous) \
                     hinge on `{}` across the direction of travel, carrying a round geom on the \
                     floor",
                    self.name(foot),
                    self.name(wheel.body)
                )));
            }
        }
        let (chest, hands) = self.arms(pelvis, &feet, across, (hips[0] + hips[1]) / 2.0)?;
        let arms = hands
            .iter()
            .map(|&h| self.limb(self.path(chest, h), "arm", "elbow"))
            .collect::<Result<Vec<Limb>, Error>>()?;
        let shoulders_z = (arms[0].root().z + arms[1].root().z) / 2.0;
        let hips_z = (hips[0].z + hips[1].z) / 2.0;
        let feet_z = (self.lowest[feet[0]] + self.lowest[feet[1]]) / 2.0;
        if !(shoulders_z > hips_z && hips_z > feet_z) {
            return Err(self.not_humanoid(
                "not standing upright at qpos0 (shoulders above hips above feet along +z)"
                    .to_owned(),
            ));
        }
        let (forward, facing) = match self.facing(&legs, across) {
            Some(found) => found,
            None => match self.named_left_first(&legs, &arms) {
                Some(first) => {
                    let left = if first { across } else { -across };
                    (
                        left.cross(&Vector3::z()),
                        "from the sides' names (no knee range or foot shape)".to_owned(),
                    )
                }
                None => {
                    let ahead = across.cross(&Vector3::z());
                    let forward = if ahead.x < 0.0 { -ahead } else { ahead };
                    (
                        forward,
                        "assumed towards +x (no knee range, foot shape or side names)".to_owned(),
                    )
                }
            },
        };
        let (left_first, _) = self.sides(&legs, &arms, forward);
        // Names that put both limbs on the other side than the geometry's facing says turn the
        // facing round (the names decide the sides, and the facing follows them): feet whose
        // body origins sit behind the ankle (ROBOTIS OP3's) vote the wrong way.
        let left = Vector3::z().cross(&forward);
        let by_geometry = (legs[0].root() - legs[1].root()).dot(&left) > 0.0;
        let arms_by_geometry = (arms[0].root() - arms[1].root()).dot(&left) > 0.0;
        let (forward, facing) = if self.named_left_first(&legs, &arms).is_some()
            && by_geometry != left_first
            && arms_by_geometry != left_first
        {
            let f = -forward;
            (f, format!("({:+.2}, {:+.2}, 0): from the sides' names (the knees and feet voted {facing})", f.x, f.y))
        } else {
            (forward, facing)
        };
        let (left_first, sides) = self.sides(&legs, &arms, forward);
        let order = |pair: [Limb; 2]| {
            let [a, b] = pair;
            if left_first {
                [a, b]
            } else {
                [b, a]
            }
        };
        let legs = order([legs[0].clone(), legs[1].clone()]);
        let arms = order([arms[0].clone(), arms[1].clone()]);
        let mut roles = BTreeMap::new();
        let pelvis_point = (legs[0].root() + legs[1].root()) / 2.0;
        let rule = format!(
            "where the two legs meet (lowest common ancestor of `{}` and `{}`); point: midway \
             between the hip centres",
            self.name(*legs[0].chain.last().unwrap_or(&0)),
            self.name(*legs[1].chain.last().unwrap_or(&0))
        );
        roles.insert(Role::Pelvis, self.role(pelvis, pelvis_point, rule, Part::Pelvis));
        if chest != pelvis {
            let rule = "where the two arms meet (their lowest common ancestor)".to_owned();
            let point = self.data.xpos[chest];
            roles.insert(Role::Chest, self.role(chest, point, rule, Part::Chest));
        }
        if let Some((head, rule)) = self.head(chest, &arms, &legs, shoulders_z) {
            let point = self.data.xpos[head];
            roles.insert(Role::Head, self.role(head, point, rule, Part::Head));
        }
        for (side, leg, arm) in
            [(Side::Left, &legs[0], &arms[0]), (Side::Right, &legs[1], &arms[1])]
        {
            self.limb_roles(&mut roles, side, leg, [Part::Thigh, Part::Shin, Part::Foot], "hip");
            self.limb_roles(
                &mut roles,
                side,
                arm,
                [Part::UpperArm, Part::Forearm, Part::Hand],
                "shoulder",
            );
        }
        for side in [Side::Left, Side::Right] {
            if !roles.contains_key(&Role::of(Part::Foot, side)) {
                return Err(self.not_humanoid(format!("the {side:?} leg has no foot")));
            }
        }
        let soles =
            [self.sole(&roles, &legs[0], Side::Left), self.sole(&roles, &legs[1], Side::Right)];
        let arm_ends = [arms[0].end_point, arms[1].end_point];
        Ok(RobotRoles {
            base: self.base,
            roles,
            soles,
            forward,
            facing,
            sides,
            height: self.height,
            arm_ends,
        })
    }

    fn role(&self, body: usize, point: Vector3<f64>, rule: String, part: Part) -> RobotRole {
        let name = self.name(body);
        let rule = if robot_names::names_part(&name, part) {
            format!("{rule} (the name agrees)")
        } else {
            rule
        };
        RobotRole { body, name, point, rule }
    }

    /// The pelvis and the two feet (see rule 2).
    fn legs(&self) -> Result<(usize, [usize; 2]), Error> {
        let bodies = self.model.subtree(self.base);
        let lowest_in = |root: usize| {
            self.model
                .subtree(root)
                .into_iter()
                .min_by(|&a, &b| self.lowest[a].total_cmp(&self.lowest[b]).then(b.cmp(&a)))
                .unwrap_or(root)
        };
        let Some(a) = self.children[self.base]
            .iter()
            .map(|&c| lowest_in(c))
            .min_by(|&a, &b| self.lowest[a].total_cmp(&self.lowest[b]).then(b.cmp(&a)))
        else {
            return Err(self.not_humanoid("the floating base carries no bodies".to_owned()));
        };
        let za = self.lowest[a];
        for anc in self.model.ancestors(a) {
            if !bodies.contains(&anc) {
                break;
            }
            let branch_a = self.path(anc, a)[0];
            let hang = self.data.xpos[branch_a].z - za;
            for &c in &self.children[anc] {
                if self.model.is_ancestor_or_self(c, a) {
                    continue;
                }
                let b = lowest_in(c);
                let level = self.lowest[b] - za <= FEET_LEVEL * self.height;
                let long = self.data.xpos[c].z - self.lowest[b] >= LEG_LENGTH * self.height;
                if level && long && hang >= LEG_LENGTH * self.height {
                    return Ok((anc, [a, b]));
                }
            }
        }
        Err(self.not_humanoid(
            "no two legs: no body has two branches reaching the ground (upper body only, or a \
             wheeled base)"
                .to_owned(),
        ))
    }

    /// The chest and the two arm ends (see rule 3).
    fn arms(
        &self,
        pelvis: usize,
        feet: &[usize; 2],
        across: Vector3<f64>,
        hips: Vector3<f64>,
    ) -> Result<(usize, [usize; 2]), Error> {
        let leg_roots: Vec<usize> = feet.iter().map(|&f| self.path(pelvis, f)[0]).collect();
        let upper: Vec<usize> = self
            .model
            .subtree(self.base)
            .into_iter()
            .filter(|&b| !leg_roots.iter().any(|&r| self.model.is_ancestor_or_self(r, b)))
            .collect();
        let side = |b: &usize| (self.data.xpos[*b] - hips).dot(&across);
        let by = |a: &&usize, b: &&usize| side(a).total_cmp(&side(b));
        let (Some(&plus), Some(&minus)) = (upper.iter().max_by(by), upper.iter().min_by(by)) else {
            return Err(self.not_humanoid("no body above the legs".to_owned()));
        };
        let reach = 0.08 * self.height;
        if side(&plus) < reach || side(&minus) > -reach {
            return Err(self.not_humanoid(
                "no arms: nothing above the legs reaches out to both sides".to_owned(),
            ));
        }
        let chest = self.lca(plus, minus);
        let mut ends = [plus, minus];
        for end in &mut ends {
            let root = self.path(chest, *end)[0];
            *end = self.farthest_along(chest, root);
        }
        if ends.iter().any(|&e| self.path_length(chest, e) < 0.15 * self.height) {
            return Err(self.not_humanoid("no arms: the side branches are too short".to_owned()));
        }
        Ok((chest, ends))
    }

    /// Length of the tree path from `top` down to `bottom` (sum of body-to-body distances).
    fn path_length(&self, top: usize, bottom: usize) -> f64 {
        let mut previous = self.data.xpos[top];
        let mut total = 0.0;
        for b in self.path(top, bottom) {
            total += (self.data.xpos[b] - previous).norm();
            previous = self.data.xpos[b];
        }
        total
    }

    /// The body of `root`'s subtree farthest from `top` along the tree (a fingertip when
    /// the arm has fingers): the end of the limb that starts at `root`.
    fn farthest_along(&self, top: usize, root: usize) -> usize {
        self.model
            .subtree(root)
            .into_iter()
            .max_by(|&a, &b| self.path_length(top, a).total_cmp(&self.path_length(top, b)))
            .unwrap_or(root)
    }

    /// Number of children of `b` whose subtree holds a joint.
    fn jointed_branches(&self, b: usize) -> usize {
        self.children[b]
            .iter()
            .filter(|&&c| self.model.subtree(c).iter().any(|&x| self.model.bodies[x].jnt_num > 0))
            .count()
    }

    /// The chain's farthest point from `root`: body origins and primitive geoms' extents.
    fn end_point(&self, chain: &[usize], root: Vector3<f64>) -> Vector3<f64> {
        let mut best = self.data.xpos[*chain.last().unwrap_or(&0)];
        let mut consider = |p: Vector3<f64>| {
            if (p - root).norm() > (best - root).norm() {
                best = p;
            }
        };
        for &b in chain {
            consider(self.data.xpos[b]);
        }
        for (g, geom) in self.model.geoms.iter().enumerate() {
            if chain.contains(&geom.body) {
                if let Some(r) = geom.bounding_radius() {
                    let c = self.data.geom_xpos[g];
                    let away = (c - root).try_normalize(1e-12).unwrap_or_else(Vector3::zeros);
                    consider(c + away * r);
                }
            }
        }
        best
    }

    /// The roles of one limb: thigh/upper arm, shin/forearm, foot/hand.
    fn limb_roles(
        &self,
        roles: &mut BTreeMap<Role, RobotRole>,
        side: Side,
        limb: &Limb,
        parts: [Part; 3],
        proximal_name: &str,
    ) {
        let [upper, middle, end] = parts;
        let last = limb.proximal.last().copied().unwrap_or(limb.middle);
        let rule = format!(
            "last of the {} hinges of the {proximal_name} (before the {}): carries all its rotations",
            limb.proximal.len(),
            if upper == Part::Thigh { "knee" } else { "elbow" }
        );
        roles.insert(Role::of(upper, side), self.role(last.body, limb.root(), rule, upper));
        let rule = format!(
            "{}: first hinge across the limb at least {:.0} % of its length from the {proximal_name}",
            if upper == Part::Thigh { "knee" } else { "elbow" },
            MIDDLE_AT * 100.0
        );
        let point = limb.middle.anchor;
        roles.insert(Role::of(middle, side), self.role(limb.middle.body, point, rule, middle));
        if let Some(last) = limb.distal.last() {
            let rule = format!(
                "last of the {} hinges after the {} (up to where fingers branch)",
                limb.distal.len(),
                if upper == Part::Thigh { "knee" } else { "elbow" }
            );
            let point = joint_centre(&limb.distal);
            roles.insert(Role::of(end, side), self.role(last.body, point, rule, end));
        } else if let Some(body) = limb.end_body {
            let rule = "the limb's end body (no joint after the elbow)".to_owned();
            roles.insert(Role::of(end, side), self.role(body, self.data.xpos[body], rule, end));
        }
    }

    /// The head (rule 4).
    fn head(
        &self,
        chest: usize,
        arms: &[Limb],
        legs: &[Limb],
        shoulders_z: f64,
    ) -> Option<(usize, String)> {
        let limbs: Vec<usize> = arms.iter().chain(legs).map(|l| l.chain[0]).collect();
        let top = self
            .model
            .subtree(self.base)
            .into_iter()
            .filter(|&b| !limbs.iter().any(|&r| self.model.is_ancestor_or_self(r, b)))
            .filter(|&b| !robot_names::is_extra(&self.name(b)))
            .max_by(|&a, &b| self.data.xpos[a].z.total_cmp(&self.data.xpos[b].z))?;
        if self.data.xpos[top].z < shoulders_z + 0.03 * self.height {
            return None;
        }
        let from = self.lca(chest, top);
        let path = self.path(from, top);
        match path.iter().rev().find(|&&b| self.model.bodies[b].jnt_num > 0) {
            Some(&b) => {
                Some((b, "last jointed body on the way to the top of the robot".to_owned()))
            }
            None => Some((top, "the highest body above the shoulders".to_owned())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_centre_is_where_axes_meet() {
        let h = |anchor: [f64; 3], axis: [f64; 3]| Hinge {
            body: 0,
            anchor: Vector3::from(anchor),
            axis: Vector3::from(axis).normalize(),
            range: None,
        };
        // Three axes through (1, 2, 3), anchored elsewhere along them.
        let c = joint_centre(&[
            h([5.0, 2.0, 3.0], [1.0, 0.0, 0.0]),
            h([1.0, -4.0, 3.0], [0.0, 1.0, 0.0]),
            h([1.0, 2.0, 9.0], [0.0, 0.0, 1.0]),
        ]);
        assert!((c - Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-2, "{c}");
        // One hinge: its anchor.
        let c = joint_centre(&[h([0.5, 0.0, 1.0], [0.0, 1.0, 0.0])]);
        assert!((c - Vector3::new(0.5, 0.0, 1.0)).norm() < 1e-12);
    }
}
