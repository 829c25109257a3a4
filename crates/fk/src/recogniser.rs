//! The skeleton recogniser: which joint of a BVH skeleton plays which [`Role`], decided by
//! the hierarchy and the bone lengths (`structure`), with names ([`crate::conventions`])
//! choosing among what the hierarchy allows, and geometry of the motion deciding left from
//! right where names say nothing (`posture`); then the conventions the data follows: up
//! axis, rest-pose kind, and the reference pose the body frames are taken in.
//!
//! A hand or foot may be an End Site when the skeleton has no joint there (Rigify's forearm
//! ends at the wrist): its position is the wrist, its orientation the forearm's.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Indices here are joint ids of a skeleton `Plan::new` has checked (every caller, `recognise`
// and `human_motion`, builds the plan first: parents before children, ids < joint count), and
// positions of per-joint arrays sized from that skeleton.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;

use bvh::Bvh;
use nalgebra::{UnitQuaternion, Vector3};

use crate::conventions::{self, NameMatch, CONVENTIONS};
use crate::forward::{self, Plan, ToWorld};
use crate::humanoid::{Humanoid, RoleJoint, RoleMap, Rule};
use crate::posture::{self, Key, Samples};
use crate::roles::{Part, Role, Side};
use crate::structure::{BodyPlan, Limb, Run, Tree};
use crate::{AxisConvention, Error};

/// Recognise the humanoid in `bvh`: which joint plays each [`Role`] and by which rule, the
/// up axis, the rest-pose kind and the body frames ([`Humanoid`]). `given` fixes roles by
/// joint name. An unrecognised skeleton is an [`Error::Unrecognised`] that lists the missing
/// roles and names that would be recognised.
pub fn recognise(bvh: &Bvh, given: &BTreeMap<Role, String>) -> Result<Humanoid, Error> {
    let plan = Plan::new(bvh)?;
    forward::check_finite(bvh)?;
    from_samples(&bvh.skeleton, &samples(&plan, bvh), given)
}

/// One sampled frame for [`recognise_posed`]: its index in the clip, then every joint's
/// position and orientation (in skeleton order).
pub type PosedFrame = (usize, Vec<Vector3<f64>>, Vec<UnitQuaternion<f64>>);

/// [`recognise`] for a skeleton whose poses come from another forward kinematics (SMPL body
/// models: crate `smpl`): its hierarchy, names and OFFSETs, its joints' positions in the
/// zero pose (`rest`, every orientation the identity there) and a few frames of its motion
/// (`frames`; up to 128 evenly spaced ones are enough), all in one set of axes and units.
pub fn recognise_posed(
    skeleton: &bvh::Skeleton,
    rest: Vec<Vector3<f64>>,
    frames: Vec<PosedFrame>,
    given: &BTreeMap<Role, String>,
) -> Result<Humanoid, Error> {
    // The hierarchy's checks (a tree in parents-first order, finite OFFSETs).
    Plan::new(&Bvh { skeleton: skeleton.clone(), motion: bvh::Motion::default() })?;
    let n = skeleton.joints.len();
    let bad = std::iter::once((rest.len(), n))
        .chain(frames.iter().map(|(_, p, q)| (p.len(), q.len())))
        .find(|&(p, q)| p != n || q != n);
    if let Some((positions, orientations)) = bad {
        return Err(Error::BodyShape { positions, orientations, num_frames: 1, num_bodies: n });
    }
    from_samples(skeleton, &Samples { rest, frames }, given)
}

/// At most this many frames of a clip are looked at to recognise the humanoid.
const SAMPLED_FRAMES: usize = 128;

/// The zero pose and evenly spaced frames, in file axes and units.
pub(crate) fn samples(plan: &Plan, bvh: &Bvh) -> Samples {
    let file = ToWorld::new(&AxisConvention::ZUp, 1.0);
    let n = bvh.motion.num_frames;
    let count = n.min(SAMPLED_FRAMES);
    let picked: Vec<usize> =
        (0..count).map(|k| if count > 1 { k * (n - 1) / (count - 1) } else { 0 }).collect();
    let motion = &bvh.motion;
    let sub = Bvh {
        skeleton: bvh.skeleton.clone(),
        motion: bvh::Motion {
            frame_time: motion.frame_time,
            num_frames: picked.len(),
            num_channels: motion.num_channels,
            values: picked.iter().flat_map(|&f| motion.frame(f).iter().copied()).collect(),
        },
    };
    let (positions, orientations) = forward::run(plan, &sub, &file, &[]);
    let joints = plan.num_joints();
    let frames = picked
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let range = k * joints..(k + 1) * joints;
            let p = positions.get(range.clone()).unwrap_or_default();
            (f, p.to_vec(), orientations.get(range).unwrap_or_default().to_vec())
        })
        .collect();
    Samples { rest: forward::rest_pose(plan, &file), frames }
}

/// Recognise the humanoid in `skeleton` from its hierarchy, names and the sampled poses;
/// `given` fixes roles by joint name.
pub(crate) fn from_samples(
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
    let (up, up_reason) = posture::up_axis(&key, samples);
    let (rest_pose, rest_reason) = posture::rest_pose(&key, &samples.rest, up);
    let (reference, reference_reason) = posture::reference(&key, samples, up, rest_pose);
    let frame_offsets = posture::frame_offsets(&roles, samples, reference);
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
/// otherwise from geometry (see [`posture::geometric_sides`]).
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
    let geometry = posture::geometric_sides(tree, plan, samples);
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
                    roles.remove(role);
                } else {
                    above = Some(j);
                }
            }
        }
    }
    roles
}

/// Head → pelvis → ankle along the bones, both legs averaged (file units).
fn stature_path(tree: &Tree, key: &Key) -> f64 {
    let down = |a: usize, b: usize| tree.path_length(a, b);
    let head = down(key.pelvis, key.head);
    let legs = (down(key.pelvis, key.feet[0]) + down(key.pelvis, key.feet[1])) / 2.0;
    head + legs
}
