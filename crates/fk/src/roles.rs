//! The canonical humanoid and the skeleton recogniser: which joint of a BVH skeleton plays
//! which [`Role`], decided by the hierarchy and the bone lengths (`structure`), with names
//! ([`crate::conventions`]) choosing among what the hierarchy allows, and geometry of the
//! motion deciding left from right where names say nothing; then the conventions the data
//! follows: up axis, rest-pose kind, and the reference pose the body frames are taken in.
//!
//! Required roles: pelvis, head, and per side upper arm, forearm, hand, thigh, shin, foot
//! (a retargeter needs the ends of every limb and the trunk between them). Optional: spine,
//! chest, neck, clavicles, toes (many skeletons lack some; a robot rarely has them all).
//! A hand or foot may be an End Site when the skeleton has no joint there (Rigify's forearm
//! ends at the wrist): its position is the wrist, its orientation the forearm's.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Indices here are joint ids of a skeleton `Plan::new` has checked (every caller, `recognise`
// and `human_motion`, builds the plan first: parents before children, ids < joint count), and
// positions of per-joint arrays sized from that skeleton.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::fmt;

use nalgebra::{UnitQuaternion, Vector3};

use crate::conventions::{self, NameMatch, CONVENTIONS};
use crate::structure::{BodyPlan, Limb, Run, Tree};
use crate::{AxisConvention, Error};

/// Left or right, as the subject sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    #[must_use]
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// A body part of the canonical humanoid, without its side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Part {
    Pelvis,
    Spine,
    Chest,
    Neck,
    Head,
    Clavicle,
    UpperArm,
    Forearm,
    Hand,
    Thigh,
    Shin,
    Foot,
    Toe,
}

impl Part {
    /// Whether the part comes in a left and a right one.
    #[must_use]
    pub fn is_sided(self) -> bool {
        !matches!(self, Part::Pelvis | Part::Spine | Part::Chest | Part::Neck | Part::Head)
    }

    /// `[Left, Right]` for sided parts, `[None]` otherwise.
    pub(crate) fn sides(self) -> &'static [Option<Side>] {
        if self.is_sided() {
            &[Some(Side::Left), Some(Side::Right)]
        } else {
            &[None]
        }
    }
}

macro_rules! roles {
    ($($role:ident = $name:literal: $part:ident $(, $side:ident)?;)*) => {
        /// A role of the canonical humanoid. Each role is played by one joint: the one at the
        /// proximal end of the body segment it names (the thigh is the hip joint, whose
        /// rotation carries the thigh bone), except the hand, foot and head, which are the
        /// joints at the wrist, ankle and skull base.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Role { $($role,)* }

        impl Role {
            /// Every role, trunk first, then the arms and the legs, left before right.
            pub const ALL: [Role; 21] = [$(Role::$role,)*];

            /// Stable snake_case name (JSON keys, `--map`, reports): `left_thigh`.
            #[must_use]
            pub fn name(self) -> &'static str {
                match self { $(Role::$role => $name,)* }
            }

            #[must_use]
            pub fn part(self) -> Part {
                match self { $(Role::$role => Part::$part,)* }
            }

            #[must_use]
            pub fn side(self) -> Option<Side> {
                match self { $(Role::$role => roles!(@side $($side)?),)* }
            }
        }
    };
    (@side) => { None };
    (@side $side:ident) => { Some(Side::$side) };
}

roles! {
    Pelvis = "pelvis": Pelvis;
    Spine = "spine": Spine;
    Chest = "chest": Chest;
    Neck = "neck": Neck;
    Head = "head": Head;
    LeftClavicle = "left_clavicle": Clavicle, Left;
    LeftUpperArm = "left_upper_arm": UpperArm, Left;
    LeftForearm = "left_forearm": Forearm, Left;
    LeftHand = "left_hand": Hand, Left;
    RightClavicle = "right_clavicle": Clavicle, Right;
    RightUpperArm = "right_upper_arm": UpperArm, Right;
    RightForearm = "right_forearm": Forearm, Right;
    RightHand = "right_hand": Hand, Right;
    LeftThigh = "left_thigh": Thigh, Left;
    LeftShin = "left_shin": Shin, Left;
    LeftFoot = "left_foot": Foot, Left;
    LeftToe = "left_toe": Toe, Left;
    RightThigh = "right_thigh": Thigh, Right;
    RightShin = "right_shin": Shin, Right;
    RightFoot = "right_foot": Foot, Right;
    RightToe = "right_toe": Toe, Right;
}

impl Role {
    /// The role of `part` on `side` (`None` when the side does not fit the part).
    #[must_use]
    pub fn new(part: Part, side: Option<Side>) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.part() == part && r.side() == side)
    }

    /// The role of a sided `part` on `side`; for a central part, that part (no side).
    #[must_use]
    pub fn of(part: Part, side: Side) -> Role {
        Role::new(part, part.is_sided().then_some(side))
            .unwrap_or(Role::Pelvis /* unreachable: every part has a role */)
    }

    /// Inverse of [`Role::name`].
    #[must_use]
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }

    /// Roles without which a skeleton is not recognised (see the module docs).
    #[must_use]
    pub fn is_required(self) -> bool {
        !matches!(self.part(), Part::Spine | Part::Chest | Part::Neck | Part::Clavicle | Part::Toe)
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How a role's joint was decided.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Rule {
    /// Its name in a naming convention, among the joints the hierarchy allows for the role.
    Name { convention: &'static str, hierarchy: String },
    /// The hierarchy and bone lengths alone (no name fitted, or the names were refused).
    Hierarchy(String),
    /// Given by the caller (`FkOptions::roles`, `--map`).
    Given,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rule::Name { convention, hierarchy } => write!(f, "name ({convention}); {hierarchy}"),
            Rule::Hierarchy(why) => write!(f, "hierarchy: {why}"),
            Rule::Given => f.write_str("given"),
        }
    }
}

/// The joint playing a role.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RoleJoint {
    /// Joint name as in the file (`<Parent>_End` for an End Site, as body names).
    pub name: String,
    /// Index in the skeleton's joints (= body index in [`crate::HumanMotion`]).
    pub index: usize,
    pub end_site: bool,
    pub rule: Rule,
}

/// Role → joint, with the rule that decided each.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RoleMap {
    entries: BTreeMap<Role, RoleJoint>,
}

impl RoleMap {
    #[must_use]
    pub fn get(&self, role: Role) -> Option<&RoleJoint> {
        self.entries.get(&role)
    }

    /// The joint name playing `role`.
    #[must_use]
    pub fn joint(&self, role: Role) -> Option<&str> {
        self.entries.get(&role).map(|j| j.name.as_str())
    }

    /// Assigned roles in [`Role::ALL`] order.
    pub fn iter(&self) -> impl Iterator<Item = (Role, &RoleJoint)> {
        self.entries.iter().map(|(r, j)| (*r, j))
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Required roles that no joint plays.
    #[must_use]
    pub fn missing_required(&self) -> Vec<Role> {
        Role::ALL.into_iter().filter(|r| r.is_required() && !self.entries.contains_key(r)).collect()
    }

    fn insert(&mut self, role: Role, joint: RoleJoint) {
        self.entries.insert(role, joint);
    }

    fn index(&self, role: Role) -> Option<usize> {
        self.entries.get(&role).map(|j| j.index)
    }
}

/// Which file axis points up (towards the head).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    PosX,
    NegX,
    PosY,
    NegY,
    PosZ,
    NegZ,
}

impl UpAxis {
    const ALL: [UpAxis; 6] =
        [UpAxis::PosX, UpAxis::NegX, UpAxis::PosY, UpAxis::NegY, UpAxis::PosZ, UpAxis::NegZ];

    /// The axis as a unit vector in file coordinates.
    #[must_use]
    pub fn vector(self) -> Vector3<f64> {
        match self {
            UpAxis::PosX => Vector3::x(),
            UpAxis::NegX => -Vector3::x(),
            UpAxis::PosY => Vector3::y(),
            UpAxis::NegY => -Vector3::y(),
            UpAxis::PosZ => Vector3::z(),
            UpAxis::NegZ => -Vector3::z(),
        }
    }

    /// The file-to-world rotation that puts this axis up: [`AxisConvention::YUp`] (GMR's)
    /// for +Y, [`AxisConvention::ZUp`] for +Z, a quarter or half turn otherwise.
    #[must_use]
    pub fn convention(self) -> AxisConvention {
        use std::f64::consts::{FRAC_PI_2, PI};
        let turn = |axis: Vector3<f64>, angle: f64| {
            AxisConvention::Custom(UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                angle,
            ))
        };
        match self {
            UpAxis::PosY => AxisConvention::YUp,
            UpAxis::PosZ => AxisConvention::ZUp,
            UpAxis::NegY => turn(Vector3::x(), -FRAC_PI_2),
            UpAxis::PosX => turn(Vector3::y(), -FRAC_PI_2),
            UpAxis::NegX => turn(Vector3::y(), FRAC_PI_2),
            UpAxis::NegZ => turn(Vector3::x(), PI),
        }
    }
}

impl fmt::Display for UpAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            UpAxis::PosX => "+X",
            UpAxis::NegX => "-X",
            UpAxis::PosY => "+Y",
            UpAxis::NegY => "-Y",
            UpAxis::PosZ => "+Z",
            UpAxis::NegZ => "-Z",
        })
    }
}

/// What the all-zeros pose (OFFSETs only) is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestPose {
    /// Standing, arms within 25° of horizontal.
    TPose,
    /// Standing, arms 25°–65° below horizontal.
    APose,
    /// Standing, arms more than 65° below horizontal.
    ArmsDown,
    /// Standing, arms more than 25° above horizontal.
    ArmsUp,
    /// Not standing upright along the up axis: the zero pose means nothing (LAFAN1, Bandai).
    NotUpright,
}

impl fmt::Display for RestPose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            RestPose::TPose => "T-pose",
            RestPose::APose => "A-pose",
            RestPose::ArmsDown => "arms down",
            RestPose::ArmsUp => "arms up",
            RestPose::NotUpright => "not upright",
        })
    }
}

/// The pose the body frames were taken in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// The zero pose (it stands upright).
    Rest,
    /// A frame of the motion (the zero pose does not stand).
    Frame(usize),
}

impl fmt::Display for Reference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reference::Rest => f.write_str("the zero pose"),
            Reference::Frame(i) => write!(f, "frame {i}"),
        }
    }
}

/// A recognised skeleton: its roles and the conventions its data follows.
#[derive(Debug, Clone, PartialEq)]
pub struct Humanoid {
    pub roles: RoleMap,
    /// The naming convention that names most of the skeleton, if any.
    pub convention: Option<&'static str>,
    /// How left and right were told apart.
    pub sides: String,
    pub up: UpAxis,
    pub up_reason: String,
    pub rest_pose: RestPose,
    pub rest_reason: String,
    pub reference: Reference,
    pub reference_reason: String,
    /// Per role, the rotation from the joint's frame to its canonical body frame
    /// ([`crate::frames`]), computed in the reference pose: the canonical frame at any frame
    /// is `q_joint ⊗ offset`. Roles whose frame the geometry does not fix are absent.
    pub frame_offsets: BTreeMap<Role, UnitQuaternion<f64>>,
    /// Head joint → pelvis → ankle along the bones (file units; both legs averaged): the
    /// body proportion the unit is chosen from, fingers and props not included.
    pub stature_path: f64,
    /// Per role, its joint's position in the zero pose (all channels zero, OFFSETs only),
    /// in file axes and units. Every joint's frame is the file's axes there, so these say
    /// where the skeleton's joint frames sit on the body: two skeletons whose zero poses
    /// point each bone the same way have the same joint frames.
    pub rest_points: BTreeMap<Role, Vector3<f64>>,
}

/// One sampled frame: its index, positions and orientations of every joint.
pub(crate) type SampledFrame = (usize, Vec<Vector3<f64>>, Vec<UnitQuaternion<f64>>);

/// World poses of a few frames, in file axes and units: what the recogniser looks at.
#[derive(Debug, Clone, Default)]
pub(crate) struct Samples {
    /// The zero pose: positions (orientations are all identity).
    pub(crate) rest: Vec<Vector3<f64>>,
    /// `(frame index, positions, orientations)` of evenly spaced frames of the motion.
    pub(crate) frames: Vec<SampledFrame>,
}

/// Recognise the humanoid in `skeleton` from its hierarchy, names and the sampled poses;
/// `given` fixes roles by joint name.
pub(crate) fn recognise(
    skeleton: &bvh::Skeleton,
    samples: &Samples,
    given: &BTreeMap<Role, String>,
) -> Result<Humanoid, Error> {
    let tree = Tree::new(skeleton);
    let names = Names::new(skeleton);
    let plan = tree.body_plan();
    let (mut roles, sides) = match &plan {
        Some(plan) => from_plan(&tree, &names, plan, samples),
        None => (from_names(&tree, &names), "names (no body plan found in the hierarchy)".into()),
    };
    for (role, name) in given {
        let index = skeleton
            .joints
            .iter()
            .position(|j| &j.name == name)
            .ok_or_else(|| Error::UnknownRoleJoint { role: *role, name: name.clone() })?;
        roles.insert(*role, names.joint(index, Rule::Given));
    }
    let missing = roles.missing_required();
    if !missing.is_empty() {
        return Err(Error::Unrecognised { missing, found: roles.len() });
    }
    let at = |role| roles.index(role);
    let need = |role| at(role).ok_or(Error::Unrecognised { missing: vec![role], found: 0 });
    let key = Key {
        pelvis: need(Role::Pelvis)?,
        head: need(Role::Head)?,
        feet: [need(Role::LeftFoot)?, need(Role::RightFoot)?],
        thighs: [need(Role::LeftThigh)?, need(Role::RightThigh)?],
        shins: [need(Role::LeftShin)?, need(Role::RightShin)?],
        upper_arms: [need(Role::LeftUpperArm)?, need(Role::RightUpperArm)?],
        hands: [need(Role::LeftHand)?, need(Role::RightHand)?],
    };
    let (up, up_reason) = up_axis(&key, samples);
    let (rest_pose, rest_reason) = rest_pose(&key, &samples.rest, up);
    let (reference, reference_reason) = reference(&key, samples, up, rest_pose);
    let frame_offsets = frame_offsets(&roles, samples, reference);
    let stature_path = stature_path(&tree, &key);
    let rest_points =
        roles.iter().filter_map(|(r, j)| Some((r, *samples.rest.get(j.index)?))).collect();
    Ok(Humanoid {
        convention: names.best.map(|c| CONVENTIONS[c].name),
        roles,
        sides,
        up,
        up_reason,
        rest_pose,
        rest_reason,
        reference,
        reference_reason,
        frame_offsets,
        stature_path,
        rest_points,
    })
}

/// What the names of a skeleton say.
struct Names<'a> {
    skeleton: &'a bvh::Skeleton,
    /// Per joint, every role some convention gives its name.
    matches: Vec<Vec<NameMatch>>,
    /// Rank of each convention: 0 names the most roles in this skeleton.
    rank: Vec<usize>,
    /// The convention of rank 0, if it names anything.
    best: Option<usize>,
}

impl<'a> Names<'a> {
    fn new(skeleton: &'a bvh::Skeleton) -> Names<'a> {
        let matches: Vec<Vec<NameMatch>> = skeleton
            .joints
            .iter()
            .map(|j| match j.kind {
                bvh::JointKind::End => Vec::new(),
                _ => conventions::matches(&conventions::normalise(&j.name)),
            })
            .collect();
        let count = |c: usize| {
            let mut roles: Vec<Role> =
                matches.iter().flatten().filter(|m| m.convention == c).map(|m| m.role).collect();
            roles.sort();
            roles.dedup();
            roles.len()
        };
        let counts: Vec<usize> = (0..CONVENTIONS.len()).map(count).collect();
        let mut order: Vec<usize> = (0..CONVENTIONS.len()).collect();
        order.sort_by_key(|&c| std::cmp::Reverse(counts[c]));
        let mut rank = vec![0; CONVENTIONS.len()];
        for (r, &c) in order.iter().enumerate() {
            rank[c] = r;
        }
        let best = order.first().copied().filter(|&c| counts[c] > 0);
        Names { skeleton, matches, rank, best }
    }

    /// The best-named joint among `allowed` for `role`: convention rank, then the
    /// convention's preference among its names, then file order.
    fn choose(&self, role: Role, allowed: &[usize]) -> Option<(usize, &'static str)> {
        allowed
            .iter()
            .flat_map(|&j| self.matches[j].iter().filter(|m| m.role == role).map(move |m| (j, m)))
            .min_by_key(|(j, m)| (self.rank[m.convention], m.preference, *j))
            .map(|(j, m)| (j, CONVENTIONS[m.convention].name))
    }

    /// Whether some convention names joint `j` as `part`.
    fn says(&self, j: usize, part: Part) -> bool {
        self.matches[j].iter().any(|m| m.role.part() == part)
    }

    /// Net side the names of `joints` state: positive left, negative right.
    fn side_vote(&self, joints: &[usize]) -> i32 {
        joints
            .iter()
            .map(|&j| match conventions::side_of(&self.skeleton.joints[j].name, &self.matches[j]) {
                Some(Side::Left) => 1,
                Some(Side::Right) => -1,
                None => 0,
            })
            .sum()
    }

    fn joint(&self, index: usize, rule: Rule) -> RoleJoint {
        let joint = &self.skeleton.joints[index];
        RoleJoint {
            name: joint.name.clone(),
            index,
            end_site: joint.kind == bvh::JointKind::End,
            rule,
        }
    }

    /// The joint for `role` among `allowed`: the best-named one, else `default`.
    fn pick(&self, role: Role, allowed: &[usize], default: usize, why: &str) -> RoleJoint {
        match self.choose(role, allowed) {
            Some((j, convention)) => {
                self.joint(j, Rule::Name { convention, hierarchy: why.to_owned() })
            }
            None => self.joint(default, Rule::Hierarchy(why.to_owned())),
        }
    }
}

/// Roles from the body plan: limbs by their long bones, trunk by where limbs branch.
fn from_plan(tree: &Tree, names: &Names, plan: &BodyPlan, samples: &Samples) -> (RoleMap, String) {
    let mut roles = RoleMap::default();
    let (legs, arms, sides) = sides(tree, names, plan, samples);
    for (side, leg) in [(Side::Left, legs[0]), (Side::Right, legs[1])] {
        let mut put = |part, run: &Run, why: String| {
            let role = Role::of(part, side);
            roles.insert(role, names.pick(role, &run.joints, run.default, &why));
        };
        put(
            Part::Thigh,
            &leg.proximal,
            format!("carries the leg's first long bone ({})", leg.reading),
        );
        put(Part::Shin, &leg.distal, "carries the leg's second long bone".to_owned());
        put(Part::Foot, &leg.extremity, "at the end of the shin bone (the ankle)".to_owned());
        if let Some(tip) = &leg.tip {
            put(Part::Toe, tip, "at the end of the foot bone".to_owned());
        }
    }
    for (side, arm) in [(Side::Left, arms[0]), (Side::Right, arms[1])] {
        let mut put = |part, run: &Run, why: String| {
            let role = Role::of(part, side);
            roles.insert(role, names.pick(role, &run.joints, run.default, &why));
        };
        if let Some(girdle) = &arm.girdle {
            put(Part::Clavicle, girdle, "carries the bone before the upper arm".to_owned());
        }
        put(
            Part::UpperArm,
            &arm.proximal,
            format!("carries the arm's first long bone ({})", arm.reading),
        );
        put(Part::Forearm, &arm.distal, "carries the arm's second long bone".to_owned());
        put(Part::Hand, &arm.extremity, "at the end of the forearm bone (the wrist)".to_owned());
    }
    trunk_roles(tree, names, plan, &mut roles);
    (roles, sides)
}

/// How far above the leg junction (in thigh lengths) a joint named as the pelvis may be.
const PELVIS_REACH: f64 = 0.5;

/// Pelvis, spine, chest, neck and head along the trunk and the head chain.
fn trunk_roles(tree: &Tree, names: &Names, plan: &BodyPlan, roles: &mut RoleMap) {
    // Ancestors of the leg junction may be the pelvis by name (3ds Max Biped's legs hang on
    // `Bip01 Spine`, below `Bip01 Pelvis`), if close to it: not a root on the floor.
    let near = PELVIS_REACH * plan.legs[0].proximal_length;
    let mut above_pelvis: Vec<usize> = vec![plan.pelvis];
    // Legs branching below the pelvis (MakeHuman's `Hips` under `Root`): the joints down to
    // where they branch may be the pelvis by name too.
    if let Some(path) = tree.path_down(plan.pelvis, plan.legs_at) {
        above_pelvis.extend(path.into_iter().skip(1));
    }
    let mut distance = 0.0;
    let mut at = plan.pelvis;
    while let Some(p) = tree.parents[at] {
        distance += tree.length[at];
        if distance > near {
            break;
        }
        above_pelvis.push(p);
        at = p;
    }
    let pelvis = names.pick(
        Role::Pelvis,
        &above_pelvis,
        plan.pelvis,
        "where the legs meet the trunk (or just above it, by name)",
    );
    // 3ds Max Biped hangs the clavicles on the neck: the chest is then the joint below it.
    let arms_at = plan.chest;
    let arms_at_neck = names.says(arms_at, Part::Neck) && !names.says(arms_at, Part::Chest);
    let below_arms = plan.trunk.len().checked_sub(2).map(|i| plan.trunk[i]);
    let (chest, why) = match below_arms {
        Some(below) if arms_at_neck && below != plan.pelvis => {
            (below, "below the neck, from which the arms branch")
        }
        _ => (arms_at, "where the arms branch off the trunk"),
    };
    roles.insert(Role::Chest, names.pick(Role::Chest, &[chest], chest, why));
    let neck_at_arms = (chest != arms_at).then_some(arms_at);
    for (role, joint) in head_and_neck(tree, names, plan, neck_at_arms) {
        roles.insert(role, joint);
    }
    // The trunk runs from where the legs meet it, whichever joint the pelvis is.
    let trunk_from =
        if tree.is_ancestor_or_self(pelvis.index, chest) { pelvis.index } else { plan.pelvis };
    if let Some(spine) = spine(tree, names, plan, trunk_from, chest) {
        roles.insert(Role::Spine, spine);
    }
    roles.insert(Role::Pelvis, pelvis);
}

/// Head: the end of the head chain (before face, eyes or the head-top End Site), or the
/// joint so named along it. Neck: between the chest and the head, by default the first
/// joint above the chest's point (CMU's `lowerneck` sits on `Chest2`), or `neck_at_arms`.
fn head_and_neck(
    tree: &Tree,
    names: &Names,
    plan: &BodyPlan,
    neck_at_arms: Option<usize>,
) -> Vec<(Role, RoleJoint)> {
    let chain: Vec<usize> =
        plan.head_chain.iter().copied().filter(|&j| !tree.end_site[j]).collect();
    let Some(&last) = chain.last() else { return Vec::new() };
    let head =
        names.pick(Role::Head, &chain, last, "the last joint of the chain from the chest up");
    let head_at = chain.iter().position(|&j| j == head.index).unwrap_or(chain.len() - 1);
    let mut allowed: Vec<usize> = neck_at_arms.into_iter().collect();
    allowed.extend_from_slice(&chain[..head_at]);
    let mut first = 0;
    while neck_at_arms.is_none() && first + 1 < allowed.len() && tree.is_zero(allowed[first + 1]) {
        first += 1;
    }
    let mut out = Vec::new();
    if let Some(&default) = allowed.get(first) {
        let neck = names.pick(Role::Neck, &allowed, default, "between the chest and the head");
        out.push((Role::Neck, neck));
    }
    out.push((Role::Head, head));
    out
}

/// Spine: between the pelvis and the chest; by default the first joint above the leg
/// junction that carries a bone of its own.
fn spine(
    tree: &Tree,
    names: &Names,
    plan: &BodyPlan,
    pelvis: usize,
    chest: usize,
) -> Option<RoleJoint> {
    let trunk = tree.path_down(pelvis, chest)?;
    let between: Vec<usize> = trunk.get(1..trunk.len().saturating_sub(1))?.to_vec();
    let start = trunk.iter().position(|&j| j == plan.pelvis).unwrap_or(0);
    let mut default = trunk.get(start + 1).copied().filter(|j| between.contains(j))?;
    while let Some(&next) =
        tree.children[default].iter().find(|c| between.contains(c) && tree.is_zero(**c))
    {
        default = next;
    }
    Some(names.pick(Role::Spine, &between, default, "first joint of the trunk above the pelvis"))
}

/// Left and right legs and arms: from names when the two chains' names state opposite sides,
/// otherwise from geometry (see [`geometric_sides`]).
fn sides<'p>(
    tree: &Tree,
    names: &Names,
    plan: &'p BodyPlan,
    samples: &Samples,
) -> ([&'p Limb; 2], [&'p Limb; 2], String) {
    let [a, b] = &plan.legs;
    let [c, d] = &plan.arms;
    let by_names = |x: &Limb, y: &Limb| {
        let (vx, vy) = (names.side_vote(&x.path), names.side_vote(&y.path));
        match (vx.signum(), vy.signum()) {
            (1, -1) => Some(true),
            (-1, 1) => Some(false),
            _ => None,
        }
    };
    let geometry = geometric_sides(tree, plan, samples);
    let (legs_left, arms_left, how) = match (by_names(a, b), by_names(c, d), geometry) {
        (Some(l), Some(r), Some((gl, gr, _))) => {
            let agree = if (l, r) == (gl, gr) { "geometry agrees" } else { "geometry disagrees" };
            (l, r, format!("names ({agree})"))
        }
        (Some(l), Some(r), None) => (l, r, "names".to_owned()),
        (_, _, Some((gl, gr, how))) => (gl, gr, format!("geometry: {how}")),
        (l, r, None) => (
            l.unwrap_or(true),
            r.unwrap_or(true),
            "undecided (no names, no facing): file order".to_owned(),
        ),
    };
    let legs = if legs_left { [a, b] } else { [b, a] };
    let arms = if arms_left { [c, d] } else { [d, c] };
    (legs, arms, how)
}

/// Whether the first leg and the first arm of the plan are the left ones, from the poses:
/// the subject's left is up × forward, up runs from the pelvis to the head, forward is where
/// the toes point (else where the knees bend). Votes over the zero pose and the sampled
/// frames; `None` when no pose shows a facing.
fn geometric_sides(
    tree: &Tree,
    plan: &BodyPlan,
    samples: &Samples,
) -> Option<(bool, bool, String)> {
    let head =
        plan.head_chain.iter().rev().find(|&&j| !tree.end_site[j]).copied().unwrap_or(plan.chest);
    let poses = std::iter::once(&samples.rest).chain(samples.frames.iter().map(|(_, p, _)| p));
    let (mut legs, mut arms, mut by_toes, mut by_knees, mut total) = (0_i64, 0_i64, 0, 0, 0);
    for p in poses {
        total += 1;
        let up = p[head] - p[plan.pelvis];
        let flat =
            |v: Vector3<f64>| v - up * (up.dot(&v) / up.norm_squared().max(f64::MIN_POSITIVE));
        let toes: Vector3<f64> = plan
            .legs
            .iter()
            .filter_map(|l| Some(p[l.extremity_end?] - p[l.extremity.default]))
            .map(flat)
            .sum();
        let knees: Vector3<f64> = plan
            .legs
            .iter()
            .map(|l| {
                let (hip, knee, ankle) =
                    (p[l.proximal.default], p[l.distal.default], p[l.extremity.default]);
                flat(knee - (hip + ankle) / 2.0)
            })
            .sum();
        let scale = up.norm();
        let forward = if toes.norm() > 0.05 * scale {
            by_toes += 1;
            toes
        } else if knees.norm() > 0.02 * scale {
            by_knees += 1;
            knees
        } else {
            continue;
        };
        let left = up.cross(&forward);
        let vote = |x: f64| if x > 0.0 { 1 } else { -1 };
        legs +=
            vote(left.dot(&(p[plan.legs[0].proximal.default] - p[plan.legs[1].proximal.default])));
        arms +=
            vote(left.dot(&(p[plan.arms[0].proximal.default] - p[plan.arms[1].proximal.default])));
    }
    if by_toes + by_knees == 0 || legs == 0 || arms == 0 {
        return None;
    }
    let how = format!(
        "left = up × forward, forward from the toes in {by_toes} and the knees in {by_knees} \
         of {total} poses"
    );
    Some((legs > 0, arms > 0, how))
}

/// Roles from names alone, when the hierarchy shows no body plan: each role takes its
/// best-named joint, and a limb role is dropped unless it lies below the previous one.
fn from_names(tree: &Tree, names: &Names) -> RoleMap {
    let mut roles = RoleMap::default();
    let all: Vec<usize> = (0..tree.len()).collect();
    for role in Role::ALL {
        if let Some((j, convention)) = names.choose(role, &all) {
            let rule = Rule::Name { convention, hierarchy: "names only".to_owned() };
            roles.insert(role, names.joint(j, rule));
        }
    }
    let chains: [&[Part]; 3] = [
        &[Part::Pelvis, Part::Spine, Part::Chest, Part::Neck, Part::Head],
        &[Part::Pelvis, Part::Thigh, Part::Shin, Part::Foot, Part::Toe],
        &[Part::Chest, Part::Clavicle, Part::UpperArm, Part::Forearm, Part::Hand],
    ];
    for side in [Side::Left, Side::Right] {
        for chain in chains {
            let mut above: Option<usize> = None;
            for &part in chain {
                let role = Role::of(part, side);
                let Some(j) = roles.index(role) else { continue };
                if above.is_some_and(|a| !tree.is_ancestor_or_self(a, j) || a == j) {
                    roles.entries.remove(&role);
                } else {
                    above = Some(j);
                }
            }
        }
    }
    roles
}

/// Joints the posture rules look at.
struct Key {
    pelvis: usize,
    head: usize,
    feet: [usize; 2],
    thighs: [usize; 2],
    shins: [usize; 2],
    upper_arms: [usize; 2],
    hands: [usize; 2],
}

/// Up: the signed file axis closest to feet → head, summed over the sampled frames (the
/// zero pose only when the clip has no frames).
fn up_axis(key: &Key, samples: &Samples) -> (UpAxis, String) {
    let poses: Vec<&Vec<Vector3<f64>>> = if samples.frames.is_empty() {
        vec![&samples.rest]
    } else {
        samples.frames.iter().map(|(_, p, _)| p).collect()
    };
    let direction = |p: &[Vector3<f64>]| {
        let v = p[key.head] - (p[key.feet[0]] + p[key.feet[1]]) / 2.0;
        v.try_normalize(0.0).unwrap_or_else(Vector3::zeros)
    };
    let sum: Vector3<f64> = poses.iter().map(|p| direction(p)).sum();
    let best = |v: &Vector3<f64>| {
        UpAxis::ALL.into_iter().max_by(|a, b| a.vector().dot(v).total_cmp(&b.vector().dot(v)))
    };
    let up = best(&sum).unwrap_or(UpAxis::PosY);
    let agree = poses.iter().filter(|p| best(&direction(p)) == Some(up)).count();
    let what =
        if samples.frames.is_empty() { "the zero pose (no frames)" } else { "sampled frames" };
    let reason =
        format!("the head is above the feet along {up} in {agree} of {} {what}", poses.len());
    (up, reason)
}

/// Degrees of arm elevation separating a T-pose, an A-pose and arms down.
const T_POSE_BELOW: f64 = 25.0;
const A_POSE_BELOW: f64 = 65.0;
/// Cosine between trunk (and legs) and the up axis for the zero pose to count as standing.
const UPRIGHT_COS: f64 = 0.8;

fn rest_pose(key: &Key, rest: &[Vector3<f64>], up: UpAxis) -> (RestPose, String) {
    let u = up.vector();
    let cos = |v: Vector3<f64>| v.try_normalize(0.0).map_or(0.0, |v| v.dot(&u));
    let trunk = cos(rest[key.head] - rest[key.pelvis]);
    let legs = [0, 1].map(|s| cos(rest[key.thighs[s]] - rest[key.feet[s]]));
    if trunk < UPRIGHT_COS || legs.iter().any(|&c| c < UPRIGHT_COS) {
        let axis = UpAxis::ALL
            .into_iter()
            .max_by(|a, b| {
                let v = rest[key.head] - rest[key.pelvis];
                a.vector().dot(&v).total_cmp(&b.vector().dot(&v))
            })
            .unwrap_or(up);
        let what = if trunk < UPRIGHT_COS {
            format!("pelvis → head points along {axis}, not {up}")
        } else {
            format!("the legs do not hang along {up}")
        };
        return (
            RestPose::NotUpright,
            format!("in the zero pose {what}: the zero pose is not used"),
        );
    }
    let elevation = [0, 1].map(|s| {
        cos(rest[key.hands[s]] - rest[key.upper_arms[s]]).clamp(-1.0, 1.0).asin().to_degrees()
    });
    let mean = (elevation[0] + elevation[1]) / 2.0;
    let kind = if mean > T_POSE_BELOW {
        RestPose::ArmsUp
    } else if mean >= -T_POSE_BELOW {
        RestPose::TPose
    } else if mean >= -A_POSE_BELOW {
        RestPose::APose
    } else {
        RestPose::ArmsDown
    };
    (kind, format!("standing in the zero pose, arms {mean:.0}° from horizontal"))
}

/// The pose to take body frames in: the zero pose if it stands upright, otherwise the sampled
/// frame that stands tallest and straightest (trunk along up, legs extended).
fn reference(key: &Key, samples: &Samples, up: UpAxis, rest: RestPose) -> (Reference, String) {
    if rest != RestPose::NotUpright || samples.frames.is_empty() {
        return (Reference::Rest, "the zero pose stands upright".to_owned());
    }
    let u = up.vector();
    let score = |p: &[Vector3<f64>]| {
        let trunk = (p[key.head] - p[key.pelvis]).try_normalize(0.0).map_or(-1.0, |v| v.dot(&u));
        let straight: f64 = (0..2)
            .map(|s| {
                let (h, k, a) = (p[key.thighs[s]], p[key.shins[s]], p[key.feet[s]]);
                (h - a).norm() / ((h - k).norm() + (k - a).norm()).max(f64::MIN_POSITIVE)
            })
            .sum::<f64>()
            / 2.0;
        trunk + straight
    };
    let best = samples
        .frames
        .iter()
        .max_by(|a, b| score(&a.1).total_cmp(&score(&b.1)))
        .map_or(0, |(i, _, _)| *i);
    (
        Reference::Frame(best),
        format!("the sampled frame standing tallest and straightest of {}", samples.frames.len()),
    )
}

/// `q_joint⁻¹ ⊗ R_canonical` per role in the reference pose.
fn frame_offsets(
    roles: &RoleMap,
    samples: &Samples,
    reference: Reference,
) -> BTreeMap<Role, UnitQuaternion<f64>> {
    let identity = vec![UnitQuaternion::identity(); samples.rest.len()];
    let (positions, orientations) = match reference {
        Reference::Rest => (&samples.rest, &identity),
        Reference::Frame(f) => match samples.frames.iter().find(|(i, _, _)| *i == f) {
            Some((_, p, q)) => (p, q),
            None => (&samples.rest, &identity),
        },
    };
    let points: BTreeMap<Role, Vector3<f64>> =
        roles.iter().map(|(r, j)| (r, positions[j.index])).collect();
    crate::frames::canonical_frames(&points)
        .into_iter()
        .filter_map(|(r, frame)| Some((r, orientations[roles.index(r)?].inverse() * frame)))
        .collect()
}

/// Head → pelvis → ankle along the bones, both legs averaged (file units).
fn stature_path(tree: &Tree, key: &Key) -> f64 {
    let down = |a: usize, b: usize| tree.path_length(a, b);
    let head = down(key.pelvis, key.head);
    let legs = (down(key.pelvis, key.feet[0]) + down(key.pelvis, key.feet[1])) / 2.0;
    head + legs
}
