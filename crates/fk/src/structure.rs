//! What the hierarchy and the bone lengths alone say about a skeleton: where the legs meet
//! the trunk (the pelvis), where the arms branch off it (the chest), which chain leads to the
//! head, and which bones of each limb are its two long ones. No names, no poses: the OFFSETs
//! only, so the result holds for any rest pose.
//!
//! - The pelvis is a joint with two limb branches (the legs) and a third branch holding a
//!   joint with two more limb branches (the arms) and the head; or a joint whose child
//!   carries just the two legs, beside the trunk (MakeHuman's `Root` → `Hips` → legs, `Root`
//!   → `Spine1`). Of all such readings the one whose limbs reach farthest wins: fingers, eyes
//!   or props form the same shape, smaller.
//! - A limb is followed from its junction down while it has one child, or one child that
//!   reaches more than twice as far as the others (twist bones, heel markers); it ends at a
//!   joint whose children are alike (the fingers of a hand) or at an End Site. Joints named
//!   as helpers or props ([`crate::conventions::IGNORED_WORDS`]) are not followed.
//! - Along a limb, bones of zero length are skipped (several joints at one point: CMU's
//!   `LHipJoint`, `lhand`) and a segment split into named parts is one bone (Rigify's
//!   `thigh.L` → `thigh.L.001`); of the remaining bones, the proximal long bone (thigh, upper arm)
//!   and the distal one (shin, forearm) are the consecutive pair whose length ratio, with the
//!   bone before them as the girdle (clavicle), is closest to human proportions
//!   ([`LimbKind`]); bones before the girdle that the reading leaves unexplained cost extra.
//!   The joint at the end of the distal bone is the extremity (foot, hand) and, on legs, the
//!   joint at the end of the next bone the toe.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Indices here are joint ids of a skeleton `Plan::new` has checked (parents before children,
// ids < joint count) and positions in per-joint arrays sized from it.
#![allow(clippy::indexing_slicing)]

use crate::conventions;

/// Bones shorter than this fraction of the longest bone count as zero (joints at one point).
const ZERO_BONE: f64 = 1e-4;
/// A child reaching more than this many times farther than its siblings continues the limb.
const DOMINANT: f64 = 2.0;
/// Penalty per bone before the girdle that the limb reading leaves unexplained.
const UNEXPLAINED_BONE: f64 = 0.3;

/// The skeleton as a tree with bone lengths (file units).
#[derive(Debug, Clone)]
pub(crate) struct Tree {
    pub(crate) parents: Vec<Option<usize>>,
    pub(crate) children: Vec<Vec<usize>>,
    /// Bone length from the parent (`|OFFSET|`); 0 for roots, whose OFFSET is a position.
    pub(crate) length: Vec<f64>,
    pub(crate) end_site: Vec<bool>,
    /// Longest path down into the subtree (sum of bone lengths).
    reach: Vec<f64>,
    ignored: Vec<bool>,
    /// The joint continues its parent's segment ([`continues`]).
    continues: Vec<bool>,
    zero: f64,
}

impl Tree {
    pub(crate) fn new(skeleton: &bvh::Skeleton) -> Tree {
        let n = skeleton.joints.len();
        let parents: Vec<Option<usize>> =
            skeleton.joints.iter().map(|j| j.parent.map(|p| p.0)).collect();
        let mut children = vec![Vec::new(); n];
        for (i, p) in parents.iter().enumerate() {
            if let Some(p) = *p {
                children[p].push(i);
            }
        }
        let length: Vec<f64> = skeleton
            .joints
            .iter()
            .map(
                |j| if j.parent.is_some() { nalgebra::Vector3::from(j.offset).norm() } else { 0.0 },
            )
            .collect();
        let mut reach = vec![0.0_f64; n];
        for i in (0..n).rev() {
            if let Some(p) = parents[i] {
                reach[p] = reach[p].max(reach[i] + length[i]);
            }
        }
        let longest = length.iter().copied().fold(0.0, f64::max);
        Tree {
            end_site: skeleton.joints.iter().map(|j| j.kind == bvh::JointKind::End).collect(),
            ignored: skeleton.joints.iter().map(|j| conventions::is_ignored(&j.name)).collect(),
            continues: skeleton
                .joints
                .iter()
                .map(|j| j.parent.is_some_and(|p| continues(&j.name, &skeleton.joints[p.0].name)))
                .collect(),
            parents,
            children,
            length,
            reach,
            zero: longest * ZERO_BONE,
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.parents.len()
    }

    /// How far a branch starting with joint `c` reaches from `c`'s parent.
    fn branch(&self, c: usize) -> f64 {
        self.length[c] + self.reach[c]
    }

    pub(crate) fn is_zero(&self, j: usize) -> bool {
        self.length[j] <= self.zero
    }

    /// Children worth following: not helpers or props, and not empty End Sites.
    fn kids(&self, j: usize) -> Vec<usize> {
        self.children[j]
            .iter()
            .copied()
            .filter(|&c| !(self.ignored[c] || (self.end_site[c] && self.is_zero(c))))
            .collect()
    }

    /// `a` is `b` or one of its ancestors.
    pub(crate) fn is_ancestor_or_self(&self, a: usize, mut b: usize) -> bool {
        loop {
            if a == b {
                return true;
            }
            match self.parents[b] {
                Some(p) => b = p,
                None => return false,
            }
        }
    }

    /// The joints from `top` down to `bottom`, both included; `None` unless `top` is an
    /// ancestor of `bottom` (or `bottom` itself).
    pub(crate) fn path_down(&self, top: usize, bottom: usize) -> Option<Vec<usize>> {
        let mut path = vec![bottom];
        let mut at = bottom;
        while at != top {
            at = self.parents[at]?;
            path.push(at);
        }
        path.reverse();
        Some(path)
    }

    /// Length along the bones between two joints (through their lowest common ancestor).
    pub(crate) fn path_length(&self, a: usize, b: usize) -> f64 {
        let mut up = vec![a];
        while let Some(p) = self.parents[*up.last().unwrap_or(&a)] {
            up.push(p);
        }
        let mut from_b = 0.0;
        let mut at = b;
        loop {
            if let Some(k) = up.iter().position(|&j| j == at) {
                return from_b + up[..k].iter().map(|&j| self.length[j]).sum::<f64>();
            }
            match self.parents[at] {
                Some(p) => {
                    from_b += self.length[at];
                    at = p;
                }
                None => return 0.0,
            }
        }
    }

    /// Follow a chain down from `first` (see the module docs). Returns the joints and whether
    /// the chain ended at a branching joint (alike children) rather than at an end.
    pub(crate) fn walk(&self, first: usize) -> (Vec<usize>, bool) {
        let mut path = vec![first];
        let mut at = first;
        loop {
            let mut kids = self.kids(at);
            if self.end_site[at] || kids.is_empty() {
                // An empty End Site still marks the end point; keep it on the path.
                if let Some(&end) = self.children[at].iter().find(|&&c| self.end_site[c]) {
                    path.push(end);
                }
                return (path, false);
            }
            kids.sort_by(|&a, &b| self.branch(b).total_cmp(&self.branch(a)));
            let next = match kids.as_slice() {
                [only] => *only,
                [first, second, ..] if self.branch(*first) > DOMINANT * self.branch(*second) => {
                    *first
                }
                _ => return (path, true),
            };
            path.push(next);
            at = next;
        }
    }
}

/// A bone along a limb path: from `path[carrier]` to `path[end]` (several bones when a
/// segment is split into named parts, as Rigify's `thigh.L` → `thigh.L.001`).
#[derive(Debug, Clone, Copy)]
struct Bone {
    carrier: usize,
    end: usize,
    length: f64,
}

impl Tree {
    /// The non-zero bones of a limb path, split segments joined.
    fn bones(&self, path: &[usize]) -> Vec<Bone> {
        let mut bones: Vec<Bone> = Vec::new();
        for i in 0..path.len().saturating_sub(1) {
            let (carrier, length) = (path[i], self.length[path[i + 1]]);
            if self.is_zero(path[i + 1]) {
                continue;
            }
            match bones.last_mut() {
                Some(last) if self.continues[carrier] => {
                    last.end = i + 1;
                    last.length += length;
                }
                _ => bones.push(Bone { carrier: i, end: i + 1, length }),
            }
        }
        bones
    }
}

/// Whether joint `name` continues its parent's segment: the parent's name plus a separator
/// and digits (`thigh.L.001` under `thigh.L`).
fn continues(name: &str, parent: &str) -> bool {
    name.strip_prefix(parent).is_some_and(|rest| {
        let mut chars = rest.chars();
        matches!(chars.next(), Some('.' | '_' | '-'))
            && !chars.as_str().is_empty()
            && chars.all(|c| c.is_ascii_digit())
    })
}

/// Which limb, for its typical proportions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LimbKind {
    Leg,
    Arm,
}

impl LimbKind {
    /// Typical length ratios: proximal / distal long bone (thigh / shin ≈ 1.0, upper arm /
    /// forearm ≈ 1.25) and girdle / proximal (hip offset / thigh ≈ 0.3, clavicle / upper arm
    /// ≈ 0.6); segment lengths after Winter, *Biomechanics and Motor Control of Human
    /// Movement* (4th ed., fig. 4.1: 0.245 H, 0.246 H, 0.186 H, 0.146 H).
    fn ratios(self) -> (f64, f64) {
        match self {
            LimbKind::Leg => (1.0, 0.3),
            LimbKind::Arm => (1.25, 0.6),
        }
    }
}

/// Joints at one point along a limb (joined by zero-length bones), with the one a role takes
/// when names do not choose another.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Run {
    pub(crate) joints: Vec<usize>,
    pub(crate) default: usize,
}

/// A limb read from the hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Limb {
    pub(crate) path: Vec<usize>,
    /// Clavicle (arms only: on legs this bone has no role).
    pub(crate) girdle: Option<Run>,
    /// Thigh, upper arm: carries the first long bone.
    pub(crate) proximal: Run,
    /// Shin, forearm: carries the second.
    pub(crate) distal: Run,
    /// Foot, hand: at the end of the second long bone (may be an End Site).
    pub(crate) extremity: Run,
    /// Toe: at the end of the bone after the extremity, when that is a joint.
    pub(crate) tip: Option<Run>,
    /// The end point after the extremity (toe joint or End Site), for the facing.
    pub(crate) extremity_end: Option<usize>,
    /// Length of the first long bone (thigh, upper arm), file units.
    pub(crate) proximal_length: f64,
    /// How the two long bones were found.
    pub(crate) reading: &'static str,
}

impl Tree {
    /// Read a limb starting at `first` (a child of its junction).
    pub(crate) fn limb(&self, first: usize, kind: LimbKind) -> Option<Limb> {
        let (path, branching) = self.walk(first);
        let bones = self.bones(&path);
        let n = bones.len();
        if n < 2 {
            return None;
        }
        let bone = |k: usize| bones[k].length;
        let (typical, girdle_typical) = kind.ratios();
        let score = |k: usize| {
            let mut terms = vec![(bone(k) / bone(k + 1) / typical).ln().powi(2)];
            if k >= 1 {
                terms.push((bone(k - 1) / bone(k) / girdle_typical).ln().powi(2));
            }
            terms.iter().sum::<f64>() / terms.len() as f64
                + UNEXPLAINED_BONE * k.saturating_sub(1) as f64
        };
        let k = (0..n - 1).min_by(|&a, &b| score(a).total_cmp(&score(b)))?;
        let reading = if branching {
            "of the bones up to where the limb branches, the consecutive pair closest to human \
             proportions"
        } else {
            "the consecutive bone pair closest to human proportions"
        };
        let run_back = |i: usize| -> Run {
            // path[i] carries a non-zero bone; joints before it at the same point share it.
            let mut start = i;
            while start > 0 && self.is_zero(path[start]) {
                start -= 1;
            }
            Run { joints: path[start..=i].to_vec(), default: path[i] }
        };
        let run_forward = |i: usize| -> Run {
            let mut end = i;
            while end + 1 < path.len() && self.is_zero(path[end + 1]) {
                end += 1;
            }
            let joints = path[i..=end].to_vec();
            let default = if self.end_site[path[i]] {
                path[i]
            } else {
                *joints.iter().rev().find(|&&j| !self.end_site[j]).unwrap_or(&path[i])
            };
            Run { joints, default }
        };
        let extremity_at = bones[k + 1].end;
        let tip_at = (k + 2 < n).then(|| bones[k + 2].end);
        Some(Limb {
            girdle: (k >= 1 && kind == LimbKind::Arm).then(|| run_back(bones[k - 1].carrier)),
            proximal: run_back(bones[k].carrier),
            distal: run_back(bones[k + 1].carrier),
            extremity: run_forward(extremity_at),
            tip: tip_at.filter(|&i| !self.end_site[path[i]]).map(run_forward),
            extremity_end: tip_at.map(|i| path[i]),
            proximal_length: bones[k].length,
            reading,
            path,
        })
    }
}

/// The body plan found in the hierarchy: pelvis, legs, chest, arms and the head chain. Legs
/// and arms are in no particular order (left and right are decided later).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyPlan {
    /// Where the legs meet the trunk.
    pub(crate) pelvis: usize,
    /// Where the two legs branch: the pelvis, or its child that carries only them.
    pub(crate) legs_at: usize,
    pub(crate) legs: [Limb; 2],
    /// Where the arms branch off the trunk.
    pub(crate) chest: usize,
    pub(crate) arms: [Limb; 2],
    /// Pelvis to chest, both included.
    pub(crate) trunk: Vec<usize>,
    /// From the chest's child towards the head to the chain's end (End Site included).
    pub(crate) head_chain: Vec<usize>,
}

/// One reading of the hierarchy as a body, before the limbs are analysed.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    pelvis: usize,
    legs_at: usize,
    legs: [usize; 2],
    chest: usize,
    arms: [usize; 2],
    head: Option<usize>,
    score: f64,
}

impl Tree {
    /// The best reading of the hierarchy as a humanoid body, if any.
    pub(crate) fn body_plan(&self) -> Option<BodyPlan> {
        let mut candidates = self.candidates();
        candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
        candidates.iter().find_map(|c| self.plan_of(c))
    }

    fn plan_of(&self, c: &Candidate) -> Option<BodyPlan> {
        let leg = |j| self.limb(j, LimbKind::Leg);
        let arm = |j| self.limb(j, LimbKind::Arm);
        let trunk = self.path_down(c.pelvis, c.chest)?;
        let head_chain = match c.head {
            Some(h) => self.walk(h).0,
            None => Vec::new(),
        };
        Some(BodyPlan {
            pelvis: c.pelvis,
            legs_at: c.legs_at,
            legs: [leg(c.legs[0])?, leg(c.legs[1])?],
            chest: c.chest,
            arms: [arm(c.arms[0])?, arm(c.arms[1])?],
            trunk,
            head_chain,
        })
    }

    /// Every (pelvis, two legs, chest, two arms, head) reading, scored by how far the limbs
    /// reach: `2·min(legs) + 2·min(arms) + pelvis→chest + min(head, arms)`.
    fn candidates(&self) -> Vec<Candidate> {
        let mut out = Vec::new();
        for pelvis in 0..self.len() {
            let kids = self.kids(pelvis);
            if self.end_site[pelvis] || kids.len() < 2 {
                continue;
            }
            // Where the legs may branch: here, or in a child with just two branches.
            let mut junctions = vec![(pelvis, kids.clone())];
            for &k in &kids {
                let grandkids = self.kids(k);
                if grandkids.len() == 2 && !self.end_site[k] {
                    junctions.push((k, grandkids));
                }
            }
            for (legs_at, legs) in junctions {
                for (x, &a) in legs.iter().enumerate() {
                    for &b in &legs[x + 1..] {
                        let trunks = kids.iter().filter(|&&t| t != a && t != b && t != legs_at);
                        for &t in trunks {
                            let reach = 2.0 * self.branch(a).min(self.branch(b));
                            self.chests(pelvis, t, |chest, arms, head, up| {
                                out.push(Candidate {
                                    pelvis,
                                    legs_at,
                                    legs: [a, b],
                                    chest,
                                    arms,
                                    head,
                                    score: reach + up,
                                });
                            });
                        }
                    }
                }
            }
        }
        out
    }

    /// Every joint in the subtree of `trunk` with two arm branches, with its head branch:
    /// calls `found(chest, arms, head, score)`.
    fn chests(
        &self,
        pelvis: usize,
        trunk: usize,
        mut found: impl FnMut(usize, [usize; 2], Option<usize>, f64),
    ) {
        let mut stack = vec![trunk];
        while let Some(chest) = stack.pop() {
            let kids = self.kids(chest);
            stack.extend(kids.iter().copied());
            if self.end_site[chest] || kids.len() < 2 {
                continue;
            }
            let rise: f64 = self
                .path_down(pelvis, chest)
                .map_or(0.0, |p| p[1..].iter().map(|&j| self.length[j]).sum());
            for (x, &c) in kids.iter().enumerate() {
                for &d in &kids[x + 1..] {
                    let head = self.head_branch(pelvis, chest, &[c, d]);
                    let arm = self.branch(c).min(self.branch(d));
                    let arms = 2.0 * arm;
                    // A head never reaches farther than an arm: this keeps a long prop in one
                    // hand from making that arm the "head".
                    let head_reach = head.map_or(0.0, |h| self.branch(h).min(arm));
                    found(chest, [c, d], head, arms + rise + head_reach);
                }
            }
        }
    }

    /// The branch towards the head: the chest's farthest-reaching other child, or else the
    /// farthest-reaching side branch of the trunk below the chest (a neck that leaves the
    /// spine below the clavicles).
    fn head_branch(&self, pelvis: usize, chest: usize, arms: &[usize]) -> Option<usize> {
        let farthest = |kids: Vec<usize>| {
            kids.into_iter().max_by(|&a, &b| self.branch(a).total_cmp(&self.branch(b)))
        };
        let own: Vec<usize> = self.kids(chest).into_iter().filter(|c| !arms.contains(c)).collect();
        if let Some(h) = farthest(own) {
            return Some(h);
        }
        let trunk = self.path_down(pelvis, chest)?;
        trunk.windows(2).rev().find_map(|w| {
            let (joint, on_path) = (w[0], w[1]);
            if joint == pelvis {
                return None;
            }
            farthest(self.kids(joint).into_iter().filter(|&c| c != on_path).collect())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bvh::{Joint, JointId, JointKind, Skeleton};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn skeleton(joints: &[(&str, Option<usize>, [f64; 3])]) -> Skeleton {
        let joints = joints
            .iter()
            .map(|&(name, parent, offset)| Joint {
                name: name.to_owned(),
                kind: match parent {
                    None => JointKind::Root,
                    Some(_) if name.ends_with("_End") => JointKind::End,
                    Some(_) => JointKind::Joint,
                },
                parent: parent.map(JointId),
                offset,
                channels: Vec::new(),
                first_channel: 0,
            })
            .collect();
        Skeleton { joints }
    }

    #[test]
    fn split_segments_are_named_parent_dot_digits() {
        assert!(continues("DEF-thigh.L.001", "DEF-thigh.L"));
        assert!(continues("upperarm_01", "upperarm"));
        assert!(!continues("Spine1", "Spine"));
        assert!(!continues("thigh.L", "thigh.L"));
        assert!(!continues("LeftHandIndex2", "LeftHandIndex1"));
    }

    #[test]
    fn a_leg_with_a_long_clavicle_like_hip_bone_reads_thigh_and_shin() {
        // CMU's leg: a zero bone (LHipJoint on the hips), the hip offset, thigh, shin, foot.
        let s = skeleton(&[
            ("Hips", None, [0.0; 3]),
            ("LHipJoint", Some(0), [0.0; 3]),
            ("LeftHip", Some(1), [1.25, -1.64, 0.72]),
            ("LeftKnee", Some(2), [2.49, -6.85, 0.0]),
            ("LeftAnkle", Some(3), [2.37, -6.51, 0.0]),
            ("LeftToe", Some(4), [0.15, -0.41, 2.21]),
            ("LeftToe_End", Some(5), [0.0, 0.0, 1.13]),
        ]);
        let tree = Tree::new(&s);
        let leg = tree.limb(1, LimbKind::Leg).unwrap();
        assert_eq!(leg.proximal.default, 2);
        assert_eq!(leg.distal.default, 3);
        assert_eq!(leg.extremity.default, 4);
        assert_eq!(leg.tip.map(|t| t.default), Some(5));
        assert_eq!(leg.proximal.joints, [2], "LHipJoint is at the hips, not at the hip");
    }

    #[test]
    fn random_trees_never_panic() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x00b0_d1e5);
        for _ in 0..300 {
            let n = rng.gen_range(1..40);
            let mut joints = vec![("j".to_owned(), None, [0.0; 3])];
            for i in 1..n {
                let offset = if rng.gen_bool(0.2) {
                    [0.0; 3]
                } else {
                    std::array::from_fn(|_| rng.gen_range(-30.0..30.0))
                };
                joints.push((format!("j{i}"), Some(rng.gen_range(0..i)), offset));
            }
            let refs: Vec<(&str, Option<usize>, [f64; 3])> =
                joints.iter().map(|(n, p, o)| (n.as_str(), *p, *o)).collect();
            let tree = Tree::new(&skeleton(&refs));
            if let Some(plan) = tree.body_plan() {
                assert!(plan.trunk.first() == Some(&plan.pelvis));
                assert!(plan.trunk.last() == Some(&plan.chest));
            }
        }
    }
}
