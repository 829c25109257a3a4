//! Sampling a take: ufbx evaluates the scene at each frame time (FBX's transform semantics,
//! the file's curves), we read the skeleton's world transforms and turn them into BVH
//! channels.
//!
//! The BVH is the skeleton as a rigid chain in the file's axes and units. Each joint's BVH
//! frame is its FBX node's world rotation `R_i(t)` times the inverse of its static rotation
//! `B_i` (the pose the file stores), so the BVH's zero pose is that stored pose with every
//! joint frame along the file's axes, as BVH files are written. Then
//! `OFFSET_i = Q_parent⁻¹ (p_i − p_parent)` at the first frame, the rotation channels are
//! `Q_parent⁻¹ Q_i` (`Q = R·B⁻¹`) as `Xrotation Yrotation Zrotation` degrees, and a joint
//! whose offset changes during the take (hips and spines that translate, Biped thighs) has
//! three position channels that replace its OFFSET (Blender's and GMR's reading; `fk` reads
//! them so because the first frame repeats the OFFSET). Roots have OFFSET 0 and their world
//! position in the position channels, which "add" and "replace" readers read alike. Any
//! scale in the hierarchy (a Null scaled 100, Biped's mirrored Nubs) is folded into the
//! offsets: the world positions of every joint are kept exactly.

use bvh::{Axis, Bvh, Channel, Joint, JointId, JointKind, Motion, Skeleton};
use nalgebra::{Matrix3, Matrix4, UnitQuaternion, Vector3};

use crate::{math, scene, Error, Fbx};

/// World poses of the skeleton's nodes at some times, in the file's axes and units.
#[derive(Debug, Clone, PartialEq)]
pub struct Poses {
    pub times: Vec<f64>,
    pub num_nodes: usize,
    /// Frame-major: node `i` at time `k` is `[k * num_nodes + i]`.
    pub positions: Vec<Vector3<f64>>,
    /// The rotation of each node's world matrix `M` (scale removed; a mirrored node, whose
    /// `det M < 0`, gets the rotation of `−M`).
    pub rotations: Vec<UnitQuaternion<f64>>,
}

/// A take this long (frames × skeleton nodes) is refused rather than sampled: about 1.6 GB
/// of channels. An hour at 120 fps of a 70-joint skeleton fits.
pub const MAX_NODE_SAMPLES: usize = 1 << 25;

impl Fbx {
    /// World poses of the skeleton in take `take` at `times` (seconds on the file's
    /// timeline; any times, inside the take's range or not).
    pub fn poses_at(&self, take: usize, times: &[f64]) -> Result<Poses, Error> {
        let n = self.node_ids.len();
        let mut poses = Poses {
            times: times.to_vec(),
            num_nodes: n,
            positions: Vec::with_capacity(times.len() * n),
            rotations: Vec::with_capacity(times.len() * n),
        };
        let mut world = Vec::with_capacity(n);
        for &t in times {
            self.world_at(take, t, &mut world)?;
            poses.positions.extend(world.iter().map(math::translation));
            poses.rotations.extend(world.iter().map(math::rotation));
        }
        Ok(poses)
    }

    fn evaluate_opts(&self) -> ufbx::EvaluateOpts<'static> {
        let limits = || ufbx::AllocatorOpts {
            memory_limit: self.memory_limit,
            ..ufbx::AllocatorOpts::default()
        };
        ufbx::EvaluateOpts {
            temp_allocator: limits(),
            result_allocator: limits(),
            ..ufbx::EvaluateOpts::default()
        }
    }

    /// The skeleton's world matrices in take `take` at time `t`.
    fn world_at(&self, take: usize, t: f64, out: &mut Vec<Matrix4<f64>>) -> Result<(), Error> {
        let stack = self.scene.anim_stacks.get(take).ok_or_else(|| Error::UnknownTake {
            file: self.file.clone(),
            take: take.to_string(),
            available: self.takes_list(),
        })?;
        out.clear();
        if self.normal_inheritance {
            self.compose(&stack.anim, t, out);
        } else {
            self.evaluate(take, &stack.anim, t, out)?;
        }
        match out.iter().position(|m| !m.iter().all(|x| x.is_finite())) {
            None => Ok(()),
            Some(i) => {
                let node = self.info.skeleton.get(i).map_or("?", |n| n.name.as_str());
                Err(Error::NonFinite {
                    file: self.file.clone(),
                    take: self.take_name(take),
                    time: t,
                    node: node.to_owned(),
                })
            }
        }
    }

    /// World matrices chained from each node's evaluated local transform
    /// (`ufbx_evaluate_transform`: the curves, pre-/post-rotation, pivots and offsets), as
    /// ufbx's own scene evaluation composes them when every node inherits normally
    /// (`node_to_world = parent.node_to_world · node_to_parent`), without copying the scene
    /// for every frame: 5–10 times faster on the shared files.
    fn compose(&self, anim: &ufbx::Anim, t: f64, out: &mut Vec<Matrix4<f64>>) {
        for (i, &id) in self.node_ids.iter().enumerate() {
            let Some(node) = self.scene.nodes.get(id) else {
                out.push(Matrix4::from_element(f64::NAN));
                continue;
            };
            let local = ufbx::evaluate_transform(anim, node, t);
            let local = scene::matrix(&ufbx::transform_to_matrix(&local));
            let parent = self.info.skeleton.get(i).and_then(|n| n.parent).and_then(|p| out.get(p));
            let world = match parent {
                Some(p) => p * local,
                None => {
                    node.parent.as_ref().map_or(local, |p| scene::matrix(&p.node_to_world) * local)
                }
            };
            out.push(world);
        }
    }

    /// World matrices from ufbx's evaluation of the whole scene (any inherit type).
    fn evaluate(
        &self,
        take: usize,
        anim: &ufbx::Anim,
        t: f64,
        out: &mut Vec<Matrix4<f64>>,
    ) -> Result<(), Error> {
        let evaluated =
            ufbx::evaluate_scene(&self.scene, anim, t, self.evaluate_opts()).map_err(|e| {
                Error::Evaluate {
                    file: self.file.clone(),
                    take: self.take_name(take),
                    time: t,
                    message: scene::ufbx_message(&e),
                }
            })?;
        for &id in &self.node_ids {
            let m = evaluated.nodes.get(id).map(|node| scene::matrix(&node.node_to_world));
            out.push(m.unwrap_or_else(|| Matrix4::from_element(f64::NAN)));
        }
        Ok(())
    }

    /// [`Fbx::poses_at`] through ufbx's evaluation of the whole scene at each time, whatever
    /// the inherit types: what [`Fbx::poses_at`] does for files with other inherit types, and
    /// the reference its faster chaining is tested against.
    pub fn poses_by_scene_evaluation(&self, take: usize, times: &[f64]) -> Result<Poses, Error> {
        let stack = self.scene.anim_stacks.get(take).ok_or_else(|| Error::UnknownTake {
            file: self.file.clone(),
            take: take.to_string(),
            available: self.takes_list(),
        })?;
        let n = self.node_ids.len();
        let mut poses = Poses {
            times: times.to_vec(),
            num_nodes: n,
            positions: Vec::with_capacity(times.len() * n),
            rotations: Vec::with_capacity(times.len() * n),
        };
        let mut world = Vec::with_capacity(n);
        for &t in times {
            world.clear();
            self.evaluate(take, &stack.anim, t, &mut world)?;
            poses.positions.extend(world.iter().map(math::translation));
            poses.rotations.extend(world.iter().map(math::rotation));
        }
        Ok(poses)
    }

    /// Take `take` sampled at its frames ([`crate::TakeInfo::frames`]) as a BVH in the file's
    /// axes and units (module docs). A take without keys, or without a frame, is an error.
    pub fn bvh(&self, take: usize) -> Result<Bvh, Error> {
        self.bvh_turned(take, None)
    }

    /// [`Fbx::bvh`] in BVH's usual axes: Y up, the front (towards the viewer) +Z, right +X,
    /// whatever the file's axis system (the same numbers for a Y-up file); file units.
    pub fn bvh_y_up(&self, take: usize) -> Result<Bvh, Error> {
        let world = self.info.world_from_file().ok_or_else(|| Error::Axes {
            file: self.file.clone(),
            axes: self.info.axes.to_string(),
        })?;
        // BVH Y up → our world is (x, y, z) ↦ (x, −z, y); its inverse after the file's.
        let y_up = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0) * world;
        let identity = (y_up - Matrix3::identity()).amax() < 1e-12;
        self.bvh_turned(take, (!identity).then_some(y_up))
    }

    /// The BVH with every world transform turned by `turn` first (`None`: as in the file).
    fn bvh_turned(&self, take: usize, turn: Option<Matrix3<f64>>) -> Result<Bvh, Error> {
        let (turn4, turn_q) = match turn {
            Some(m) => {
                let r = nalgebra::Rotation3::from_matrix_unchecked(m);
                (Some(m.to_homogeneous()), UnitQuaternion::from_rotation_matrix(&r))
            }
            None => (None, UnitQuaternion::identity()),
        };
        let rest: Vec<UnitQuaternion<f64>> = self.rest.iter().map(|b| turn_q * b).collect();
        let times = self.frame_times(take)?;
        let n = self.node_ids.len();
        // Per frame and node: offset (3) and Euler angles in degrees (3).
        let mut values: Vec<f64> = Vec::with_capacity(times.len() * n * 6);
        let mut world = Vec::with_capacity(n);
        let mut q = Vec::with_capacity(n);
        let mut p = Vec::with_capacity(n);
        let mut previous: Vec<Option<[f64; 3]>> = vec![None; n];
        for &t in &times {
            self.world_at(take, t, &mut world)?;
            if let Some(turn) = &turn4 {
                world.iter_mut().for_each(|m| *m = turn * *m);
            }
            q.clear();
            p.clear();
            for (m, rest) in world.iter().zip(&rest) {
                q.push(math::rotation(m) * rest.inverse());
                p.push(math::translation(m));
            }
            for (i, node) in self.info.skeleton.iter().enumerate() {
                let (Some(qi), Some(pi)) = (q.get(i), p.get(i)) else { continue };
                let (offset, local) = match node.parent.and_then(|j| Some((q.get(j)?, p.get(j)?))) {
                    Some((qp, pp)) => (qp.inverse() * (pi - pp), qp.inverse() * qi),
                    None => (*pi, *qi),
                };
                let slot = previous.get_mut(i);
                let euler = math::euler_xyz(&local, slot.as_ref().and_then(|s| **s));
                if let Some(slot) = slot {
                    *slot = Some(euler);
                }
                values.extend(offset.iter());
                values.extend(euler.iter().map(|a| a.to_degrees()));
            }
        }
        Ok(self.assemble(&times, &values))
    }

    /// The frame times of take `take`, checked: it has keys, frames, and is not too long.
    pub(crate) fn frame_times(&self, take: usize) -> Result<Vec<f64>, Error> {
        let info = self.take_info(take)?;
        let name = info.name.clone();
        if info.keys.is_none() {
            return Err(Error::EmptyTake { file: self.file.clone(), take: name });
        }
        let bad = |message: String| Error::BadTake {
            file: self.file.clone(),
            take: name.clone(),
            message,
        };
        if info.frames == 0 {
            return Err(bad(format!(
                "its declared range {} s .. {} s holds no frame at {} fps",
                info.start, info.stop, self.info.fps
            )));
        }
        let samples = info.frames.saturating_mul(self.node_ids.len().max(1));
        if samples > MAX_NODE_SAMPLES {
            return Err(bad(format!(
                "{} frames of {} nodes is more than {MAX_NODE_SAMPLES} node samples",
                info.frames,
                self.node_ids.len()
            )));
        }
        let fps = self.info.fps;
        Ok((0..info.frames).map(|k| (info.first_frame + k as i64) as f64 / fps).collect())
    }

    /// The BVH from per-frame, per-node `[offset, euler°]` values.
    fn assemble(&self, times: &[f64], values: &[f64]) -> Bvh {
        let n = self.node_ids.len();
        let at =
            |f: usize, i: usize, c: usize| values.get((f * n + i) * 6 + c).copied().unwrap_or(0.0);
        let positions =
            [Channel::Position(Axis::X), Channel::Position(Axis::Y), Channel::Position(Axis::Z)];
        let rotations =
            [Channel::Rotation(Axis::X), Channel::Rotation(Axis::Y), Channel::Rotation(Axis::Z)];
        let mut joints = Vec::with_capacity(n);
        let mut columns: Vec<usize> = Vec::new(); // value index within a node's 6, per channel
        let mut owners: Vec<usize> = Vec::new(); // node of each channel
        for (i, node) in self.info.skeleton.iter().enumerate() {
            let first: [f64; 3] = std::array::from_fn(|c| at(0, i, c));
            let translates = node.parent.is_none() || {
                let size = 1.0 + Vector3::from(first).norm();
                (1..times.len()).any(|f| {
                    first.iter().enumerate().any(|(c, x)| (at(f, i, c) - x).abs() > 1e-9 * size)
                })
            };
            let mut channels = Vec::with_capacity(6);
            if translates {
                channels.extend(positions);
                columns.extend(0..3);
                owners.extend([i; 3]);
            }
            channels.extend(rotations);
            columns.extend(3..6);
            owners.extend([i; 3]);
            let first_channel = columns.len() - channels.len();
            joints.push(Joint {
                name: node.name.clone(),
                kind: if node.parent.is_none() { JointKind::Root } else { JointKind::Joint },
                parent: node.parent.map(JointId),
                offset: if node.parent.is_none() { [0.0; 3] } else { first },
                channels,
                first_channel,
            });
        }
        let num_channels = columns.len();
        let mut motion = Vec::with_capacity(times.len() * num_channels);
        for f in 0..times.len() {
            motion.extend(owners.iter().zip(&columns).map(|(&i, &c)| at(f, i, c)));
        }
        Bvh {
            skeleton: Skeleton { joints },
            motion: Motion {
                frame_time: 1.0 / self.info.fps,
                num_frames: times.len(),
                num_channels,
                values: motion,
            },
        }
    }
}
