//! Forward kinematics of a body model posed by a motion, and the clip the retargeter takes:
//! world poses of every joint, the recognised humanoid, the subject's height and the floor.
//!
//! smplx's kinematics (`lbs.batch_rigid_transform`): `G_0 = R(root)`, `G_j = G_parent R(θ_j)`;
//! `p_0 = J_0 + trans` (the root turns about its own rest position), `p_j = p_parent +
//! G_parent (J_j − J_parent)`; SMPL-X's hand poses get `hands_mean` added first (smplx's
//! `flat_hand_mean=False`). Orientations are GMR's (`get_smplx_data`: the same chain of
//! world rotations), made continuous in sign over time as `fk`'s are.

use std::collections::BTreeMap;

use fk::{HumanMotion, Humanoid, Role};
use nalgebra::{UnitQuaternion, Vector3};

use crate::conventions::{hand_joints, ModelKind};
use crate::model::BodyModel;
use crate::motion::SmplMotion;
use crate::Error;

/// The full pose a frame is posed with: `raw` (3 per joint) with the model's hand mean added.
pub(crate) fn full_pose(model: &BodyModel, raw: &[f64], out: &mut Vec<f64>) {
    out.clear();
    out.extend_from_slice(raw);
    if let Some(mean) = model.hands_mean() {
        let [left, _] = hand_joints(model.kind);
        if let Some(hands) = out.get_mut(3 * left.start..) {
            hands.iter_mut().zip(mean).for_each(|(v, m)| *v += m);
        }
    }
}

/// Checks that `motion` can be posed with `model`: the same kind, betas it has.
pub fn check(model: &BodyModel, motion: &SmplMotion) -> Result<(), Error> {
    if model.kind != motion.kind {
        return Err(Error::Mismatch {
            motion: motion.source.clone(),
            model: model.path.clone(),
            message: format!(
                "a {} motion ({} pose values per frame) needs a {} body model, not {}",
                motion.kind,
                motion.kind.pose_width(),
                motion.kind,
                model.kind
            ),
        });
    }
    if motion.betas.len() > model.shape_components() {
        return Err(Error::TooManyBetas {
            motion: motion.source.clone(),
            betas: motion.betas.len(),
            model: model.path.clone(),
            components: model.shape_components(),
        });
    }
    Ok(())
}

/// World poses of every joint of every frame (metres, Z up as AMASS's world; body names are
/// the model's joint names).
pub fn forward(model: &BodyModel, motion: &SmplMotion) -> Result<HumanMotion, Error> {
    check(model, motion)?;
    let rest = model.rest_joints(&motion.betas);
    let parents = model.parents();
    let n = model.num_joints();
    let frames = motion.num_frames();
    let mut positions = Vec::with_capacity(frames * n);
    let mut orientations: Vec<UnitQuaternion<f64>> = Vec::with_capacity(frames * n);
    let mut pose = Vec::with_capacity(3 * n);
    for f in 0..frames {
        full_pose(model, motion.pose(f), &mut pose);
        let locals = pose
            .chunks_exact(3)
            .map(|r| UnitQuaternion::from_scaled_axis(Vector3::from_column_slice(r)));
        let root = motion.trans.get(f).copied().unwrap_or_default();
        let start = positions.len();
        chain(parents, &rest, locals, root, &mut positions, &mut orientations);
        if f > 0 {
            continuous(&mut orientations, start, n);
        }
    }
    let human = HumanMotion {
        fps: motion.fps,
        body_names: model.joint_names().iter().map(|s| (*s).to_owned()).collect(),
        num_frames: frames,
        positions,
        orientations,
    };
    human.validate()?;
    Ok(human)
}

/// One frame's chain (smplx's kinematics, module docs), appended to `positions` and
/// `orientations`.
pub(crate) fn chain(
    parents: &[Option<usize>],
    rest: &[Vector3<f64>],
    locals: impl Iterator<Item = UnitQuaternion<f64>>,
    root: Vector3<f64>,
    positions: &mut Vec<Vector3<f64>>,
    orientations: &mut Vec<UnitQuaternion<f64>>,
) {
    let start = positions.len();
    for ((j, local), rest_j) in locals.enumerate().zip(rest) {
        let parent = parents.get(j).copied().flatten();
        let at =
            |k: usize| (positions.get(start + k).copied(), orientations.get(start + k).copied());
        match parent.map(|p| (at(p), rest.get(p))) {
            Some(((Some(pp), Some(pq)), Some(rest_p))) => {
                positions.push(pp + pq * (rest_j - rest_p));
                orientations.push(pq * local);
            }
            _ => {
                positions.push(rest_j + root);
                orientations.push(local);
            }
        }
    }
}

/// Flips the quaternions of the frame starting at `start` to the sign of the frame before.
pub(crate) fn continuous(orientations: &mut [UnitQuaternion<f64>], start: usize, n: usize) {
    let Some((before, now)) = orientations.get_mut(start - n..start + n).map(|s| s.split_at_mut(n))
    else {
        return;
    };
    for (q, p) in now.iter_mut().zip(before.iter()) {
        if q.coords.dot(&p.coords) < 0.0 {
            *q = UnitQuaternion::new_unchecked(-q.into_inner());
        }
    }
}

/// A posed motion ready to retarget: world poses, the recognised humanoid (roles of the
/// canonical humanoid, body frames), the subject height and the floor.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    pub human: HumanMotion,
    pub humanoid: Humanoid,
    /// The body model's stature at the motion's betas (m).
    pub height: f64,
    pub height_source: String,
    /// GMR's subject height for the motion (`1.66 + 0.1 β₀`).
    pub gmr_height: f64,
    /// The floor (world z, m): the lowest the soles go over the clip (foot and toe joints
    /// less their rest height above the sole).
    pub ground: f64,
}

impl Clip {
    /// Roles by joint name, as the retargeter's options take them (`FkOptions::roles`).
    #[must_use]
    pub fn roles(&self) -> BTreeMap<Role, String> {
        self.humanoid.roles.iter().map(|(r, j)| (r, j.name.clone())).collect()
    }

    /// One line on what was read and inferred.
    #[must_use]
    pub fn inferred(&self, kind: ModelKind) -> String {
        format!(
            "{kind} body model, Z up, metres, {} roles by {}",
            self.humanoid.roles.len(),
            self.humanoid.convention.unwrap_or("hierarchy alone")
        )
    }
}

/// At most this many frames are shown to the recogniser (as `fk` samples a BVH).
const SAMPLED_FRAMES: usize = 128;

/// [`forward`], then the humanoid recognised on the model's skeleton, the stature and the
/// floor ([`Clip`]).
pub fn clip(model: &BodyModel, motion: &SmplMotion) -> Result<Clip, Error> {
    let human = forward(model, motion)?;
    let rest = model.rest_joints(&motion.betas);
    let humanoid = recognise(model, &rest, &human)?;
    let sole = model.sole(&motion.betas);
    let feet = [Role::LeftFoot, Role::RightFoot, Role::LeftToe, Role::RightToe];
    let feet: Vec<(usize, f64)> = feet
        .iter()
        .filter_map(|r| humanoid.roles.get(*r))
        .filter_map(|j| Some((j.index, rest.get(j.index)?.y - sole)))
        .collect();
    let ground = (0..human.num_frames)
        .flat_map(|f| feet.iter().map(move |&(b, h)| (f, b, h)))
        .map(|(f, b, h)| human.position(f, b).z - h)
        .fold(f64::INFINITY, f64::min);
    let height = model.stature(&motion.betas);
    Ok(Clip {
        humanoid,
        height,
        height_source: format!(
            "the {} body model's stature at the file's {} betas",
            model.kind,
            motion.betas.len()
        ),
        gmr_height: crate::conventions::gmr_height(&motion.betas),
        ground: if ground.is_finite() { ground } else { 0.0 },
        human,
    })
}

/// The model's skeleton (joint names, parents, rest offsets) as the recogniser takes it,
/// with the rest pose and evenly spaced frames of `human`.
fn recognise(
    model: &BodyModel,
    rest: &[Vector3<f64>],
    human: &HumanMotion,
) -> Result<Humanoid, Error> {
    let joints = model
        .joint_names()
        .iter()
        .zip(model.parents())
        .zip(rest)
        .map(|((name, parent), p)| {
            let offset = match parent.and_then(|q| rest.get(q)) {
                Some(pp) => p - pp,
                None => *p,
            };
            bvh::Joint {
                name: (*name).to_owned(),
                kind: if parent.is_some() { bvh::JointKind::Joint } else { bvh::JointKind::Root },
                parent: parent.map(bvh::JointId),
                offset: [offset.x, offset.y, offset.z],
                channels: Vec::new(),
                first_channel: 0,
            }
        })
        .collect();
    let skeleton = bvh::Skeleton { joints };
    let n = human.num_frames;
    let count = n.min(SAMPLED_FRAMES);
    let frames = (0..count)
        .map(|k| if count > 1 { k * (n - 1) / (count - 1) } else { 0 })
        .map(|f| (f, human.frame_positions(f).to_vec(), human.frame_orientations(f).to_vec()))
        .collect();
    Ok(fk::recognise_posed(&skeleton, rest.to_vec(), frames, &BTreeMap::new())?)
}
