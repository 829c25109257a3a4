//! The FK loop: channels → local poses → global poses → world (axes, units), one forward pass
//! per frame over the parents-first joint array (MuJoCo's `body_parentid` loop).
//!
//! Per joint, as GMR's LAFAN1 loader (`read_bvh` + `quat_fk`) does it:
//! `q_local = q(c₁) ⊗ q(c₂) ⊗ q(c₃)` in the joint's channel order, `p_local` = its position
//! channels (replacing OFFSET) or OFFSET; `q = q_parent ⊗ q_local`,
//! `p = q_parent · p_local + p_parent`. World: `p' = R_axes · p · metres_per_unit`,
//! `q' = q_axes ⊗ q`.

use bvh::{Axis, Bvh, Channel, JointKind};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::math::{self, Quat};
use crate::{AxisConvention, Error};

/// One joint, compiled for the loop.
#[derive(Debug, Clone)]
struct JointPlan {
    parent: Option<usize>,
    offset: [f64; 3],
    /// Column of each position channel, per axis; `None` keeps the OFFSET component.
    position_columns: [Option<usize>; 3],
    /// Rotation channels in file order: (axis, column).
    rotations: Vec<(Axis, usize)>,
}

/// The skeleton compiled for FK; built once per clip, after validation.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    joints: Vec<JointPlan>,
}

impl Plan {
    /// Validate the skeleton and motion shape and compile the channel layout.
    pub(crate) fn new(bvh: &Bvh) -> Result<Plan, Error> {
        let skeleton = &bvh.skeleton;
        if skeleton.joints.is_empty() {
            return Err(Error::EmptySkeleton);
        }
        let motion = &bvh.motion;
        if motion.values.len() != motion.num_frames.saturating_mul(motion.num_channels) {
            return Err(Error::MotionShape {
                len: motion.values.len(),
                num_frames: motion.num_frames,
                num_channels: motion.num_channels,
            });
        }
        if motion.num_channels == 0 && motion.num_frames > 0 {
            return Err(Error::NoChannels(motion.num_frames));
        }
        let joints = skeleton
            .joints
            .iter()
            .enumerate()
            .map(|(index, joint)| compile_joint(index, joint, motion.num_channels))
            .collect::<Result<_, _>>()?;
        Ok(Plan { joints })
    }

    pub(crate) fn num_joints(&self) -> usize {
        self.joints.len()
    }

    /// Parent of each joint (`None` for roots).
    pub(crate) fn parents(&self) -> impl Iterator<Item = Option<usize>> + '_ {
        self.joints.iter().map(|j| j.parent)
    }

    /// Offsets (file units), indexed by joint.
    pub(crate) fn offsets(&self) -> impl Iterator<Item = [f64; 3]> + '_ {
        self.joints.iter().map(|j| j.offset)
    }

    /// Global poses (file axes and units) of one frame into `q`, `p`: `row` is the frame's
    /// channel values, `sin`/`cos` those of the half angles of every column.
    #[inline]
    pub(crate) fn global(&self, row: &Row, q: &mut [Quat], p: &mut [[f64; 3]]) {
        for (i, joint) in self.joints.iter().enumerate() {
            let mut local_p = joint.offset;
            for (c, column) in joint.position_columns.iter().enumerate() {
                if let Some(column) = column {
                    local_p[c] = row.values[*column];
                }
            }
            // q(a₁) ⊗ (q(a₂) ⊗ q(a₃)): fold from the right (`math::euler_quat`).
            let local_q = joint.rotations.iter().rev().fold(math::IDENTITY, |q, &(axis, col)| {
                math::axis_mul(axis, row.cos[col], row.sin[col], &q)
            });
            match joint.parent {
                None => {
                    q[i] = local_q;
                    p[i] = local_p;
                }
                Some(parent) => {
                    let (pq, pp) = (q[parent], p[parent]);
                    let r = math::quat_rotate(&pq, local_p);
                    q[i] = math::quat_mul(&pq, &local_q);
                    p[i] = [r[0] + pp[0], r[1] + pp[1], r[2] + pp[2]];
                }
            }
        }
    }

    /// Global poses of the rest pose: every channel zero (positions: OFFSET for all joints).
    pub(crate) fn rest(&self, q: &mut [Quat], p: &mut [[f64; 3]]) {
        let rest = Plan {
            joints: self
                .joints
                .iter()
                .map(|j| JointPlan {
                    position_columns: [None; 3],
                    rotations: Vec::new(),
                    ..j.clone()
                })
                .collect(),
        };
        rest.global(&Row::default(), q, p);
    }
}

fn compile_joint(
    index: usize,
    joint: &bvh::Joint,
    num_channels: usize,
) -> Result<JointPlan, Error> {
    let parent = joint.parent.map(|p| p.0);
    if let Some(parent) = parent.filter(|&p| p >= index) {
        return Err(Error::BadParent { joint: joint.name.clone(), index, parent });
    }
    if !joint.offset.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFiniteOffset(joint.name.clone()));
    }
    let end = joint.first_channel.saturating_add(joint.channels.len());
    if end > num_channels {
        return Err(Error::ChannelOutOfRange {
            joint: joint.name.clone(),
            first: joint.first_channel,
            end,
            num_channels,
        });
    }
    let mut plan = JointPlan {
        parent,
        offset: joint.offset,
        position_columns: [None; 3],
        rotations: Vec::new(),
    };
    if joint.kind == JointKind::End {
        return Ok(plan);
    }
    for (k, channel) in joint.channels.iter().enumerate() {
        let column = joint.first_channel + k;
        match *channel {
            Channel::Position(axis) => plan.position_columns[axis_index(axis)] = Some(column),
            Channel::Rotation(axis) => plan.rotations.push((axis, column)),
        }
    }
    Ok(plan)
}

pub(crate) fn axis_index(axis: Axis) -> usize {
    match axis {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
    }
}

/// One frame's channel values and the sine and cosine of their half angles (degrees).
#[derive(Debug, Clone, Default)]
pub(crate) struct Row {
    values: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
}

impl Row {
    fn load(&mut self, values: &[f64]) {
        self.values.clear();
        self.values.extend_from_slice(values);
        self.sin.resize(values.len(), 0.0);
        self.cos.resize(values.len(), 0.0);
        crate::trig::half_angles_sin_cos(values, &mut self.sin, &mut self.cos);
    }
}

/// File-to-world conversion applied to global poses.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ToWorld {
    matrix: Matrix3<f64>,
    quat: Quat,
    scale: Scale,
    /// GMR's +90° about X, done with its zero terms dropped (same bits, fewer operations).
    x_quarter_turn: bool,
}

/// Metres per file unit, applied as GMR does: a division by 100 for centimetres (`p / 100`
/// and `p · 0.01` differ in the last bit for some `p`), a multiplication otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Scale {
    Divide(f64),
    Multiply(f64),
}

impl Scale {
    pub(crate) fn from_metres_per_unit(m: f64) -> Scale {
        let inverse = 1.0 / m;
        if m < 1.0 && inverse == inverse.round() && 1.0 / inverse == m {
            Scale::Divide(inverse)
        } else {
            Scale::Multiply(m)
        }
    }

    #[inline]
    pub(crate) fn apply(self, v: f64) -> f64 {
        match self {
            Scale::Divide(d) => v / d,
            Scale::Multiply(m) => v * m,
        }
    }
}

impl ToWorld {
    pub(crate) fn new(axes: &AxisConvention, metres_per_unit: f64) -> ToWorld {
        ToWorld {
            matrix: axes.world_from_file_matrix(),
            quat: math::from_unit(&axes.world_from_file()),
            scale: Scale::from_metres_per_unit(metres_per_unit),
            x_quarter_turn: *axes == AxisConvention::YUp,
        }
    }

    #[inline]
    pub(crate) fn position(&self, p: [f64; 3]) -> Vector3<f64> {
        // `(x, −z, y)` is what the exact matrix product gives, without the nine products.
        let r = if self.x_quarter_turn {
            Vector3::new(p[0], -p[2], p[1])
        } else {
            self.matrix * Vector3::new(p[0], p[1], p[2])
        };
        Vector3::new(self.scale.apply(r.x), self.scale.apply(r.y), self.scale.apply(r.z))
    }

    #[inline]
    pub(crate) fn orientation(&self, q: &Quat) -> Quat {
        if self.x_quarter_turn {
            math::axis_mul(Axis::X, self.quat[0], self.quat[1], q)
        } else {
            math::quat_mul(&self.quat, q)
        }
    }
}

/// World poses of every frame, `[frame * stride + body]` with `stride = num_joints +
/// derived.len()`: the joints, then per derived body `(position_from, orientation_from)`
/// copies. Orientations are made continuous in time per body (sign flip when the dot product
/// with the previous frame's is negative). Written once, in order: no zero-fill pass.
pub(crate) fn run(
    plan: &Plan,
    bvh: &Bvh,
    world: &ToWorld,
    derived: &[(usize, usize)],
) -> (Vec<Vector3<f64>>, Vec<UnitQuaternion<f64>>) {
    let n = plan.num_joints();
    let stride = n + derived.len();
    let total = bvh.motion.num_frames * stride;
    let mut positions = Vec::with_capacity(total);
    let mut orientations: Vec<UnitQuaternion<f64>> = Vec::with_capacity(total);
    let mut q = vec![math::IDENTITY; n];
    let mut p = vec![[0.0; 3]; n];
    let mut row = Row::default();
    for frame in 0..bvh.motion.num_frames {
        row.load(bvh.motion.frame(frame));
        plan.global(&row, &mut q, &mut p);
        let base = frame * stride;
        for i in 0..n {
            let mut wq = world.orientation(&q[i]);
            if frame > 0 && math::dot(&wq, &math::from_unit(&orientations[base - stride + i])) < 0.0
            {
                wq = math::neg(&wq);
            }
            orientations.push(math::to_unit(&wq));
            positions.push(world.position(p[i]));
        }
        for &(position_from, orientation_from) in derived {
            positions.push(positions[base + position_from]);
            orientations.push(orientations[base + orientation_from]);
        }
    }
    (positions, orientations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_quarter_turn_shortcut_is_the_full_product_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0005);
        let fast = ToWorld::new(&AxisConvention::YUp, 0.01);
        let full = ToWorld { x_quarter_turn: false, ..fast };
        for _ in 0..10_000 {
            let p: [f64; 3] = std::array::from_fn(|_| rng.gen_range(-500.0..500.0));
            let q: Quat = std::array::from_fn(|_| rng.gen_range(-1.0..1.0));
            assert_eq!(fast.position(p), full.position(p));
            assert_eq!(fast.orientation(&q), full.orientation(&q));
        }
    }
}
