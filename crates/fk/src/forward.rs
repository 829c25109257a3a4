//! The FK loop: channels → local poses → global poses → world (axes, units), one forward pass
//! per frame over the parents-first joint array (MuJoCo's `body_parentid` loop).
//!
//! Per joint, as GMR's LAFAN1 loader (`read_bvh` + `quat_fk`) does it:
//! `q_local = q(c₁) ⊗ q(c₂) ⊗ q(c₃)` in the joint's channel order, `p_local` = its position
//! channels read as [`PositionReading`] says (GMR: they replace OFFSET) or OFFSET;
//! `q = q_parent ⊗ q_local`, `p = q_parent · p_local + p_parent` (a [`PositionReading::World`]
//! joint: `p = p_local`). World: `p' = R_axes · p · metres_per_unit`, `q' = q_axes ⊗ q`.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: Every index in this module is established by `Plan::new`, which checks the skeleton (parents before
// children, channel columns inside the motion row) before anything is computed: `q`/`p` hold one
// entry per joint, rows one value per column. This is the per-frame hot loop (the fk benchmark),
// so it indexes instead of re-checking each access.
#![allow(clippy::indexing_slicing)]

use bvh::{Axis, Bvh, Channel, JointKind};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::math::{self, Quat};
use crate::{AxisConvention, Error};

/// How a joint's position channels are read. The BVH format does not say and exporters
/// differ, so `fk` decides per joint and per clip from the numbers, parents first, and reports
/// the choice in [`crate::FkReport::position_channels`]. With `c` a joint's position channels
/// and `o` its OFFSET (axes without a channel are left out of both):
///
/// 1. Frame 0 repeats the OFFSET (`|c − o|` within 1e-3 of `|o|` or of the mean bone length,
///    whichever is larger) → [`PositionReading::Local`]. LAFAN1 writes its root's first
///    position as the root OFFSET; Bandai Namco and Blender write every non-root joint's OFFSET
///    again in its channels.
/// 2. A non-root joint with all three position channels whose values, in more than half of
///    the frames (at most 256, spread over the clip), lie at least 4 times nearer the world
///    position its parent's pose and OFFSET predict (`p_parent + q_parent · o`) than they lie
///    to either `o` or zero → [`PositionReading::World`].
/// 3. Otherwise the one axis that tells the two local readings apart best decides: the
///    channel whose median absolute deviation over those frames is smallest for the size of
///    its OFFSET component (for a root: the height, not the floor plan it walks). When the
///    zero pose stands along that axis (its lowest point below the joint by at least half
///    the joint's reach), the reading that stands the joint that far above 0, the floor,
///    is chosen: HumanML3D's converters write SMPL's pelvis in the body model (0.22 m *below*
///    its origin) as the root OFFSET and the world position in the channels, a Rigify
///    export its standing height as the OFFSET and sway in the channels. Otherwise its median
///    nearer that component than zero → [`PositionReading::Local`], else
///    [`PositionReading::Added`].
///
/// A zero OFFSET makes `Local` and `Added` the same numbers (CMU, Mixamo): `Local` is chosen.
/// Channels read as `Local` give exactly GMR's numbers, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PositionReading {
    /// The channels are the joint's position in its parent's frame: they replace OFFSET (GMR's
    /// and Blender's reading, and what Blender, LAFAN1 and Bandai Namco write: Bandai's Hips
    /// under a still floor root carry the whole translation, height included). Adding OFFSET
    /// to these would put the hips at twice their height.
    Local,
    /// The channels are a displacement added to OFFSET: the root as Biovision's format is
    /// usually described ("the sum of the offset data and the translation data"). A Rigify
    /// export whose pelvis OFFSET is its standing height and whose channels are centimetres of
    /// sway is one; read as `Local` its feet would sink a pelvis height below the floor.
    Added,
    /// The channels are the joint's position in the file's world frame (exporters that write
    /// every joint's global position): the joint is put there; its orientation still chains
    /// from its parent.
    World,
}

/// The reading chosen for one joint with position channels, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionChannels {
    pub joint: String,
    pub reading: PositionReading,
    /// What decided it, e.g. "frame 0 repeats the OFFSET".
    pub reason: String,
}

/// At most this many frames, spread over the clip, decide a joint's [`PositionReading`].
const MAX_VOTERS: usize = 256;
/// How much nearer its predicted world position than either local reading a frame's position
/// channels must be to count for [`PositionReading::World`].
const WORLD_MARGIN: f64 = 4.0;
/// Frame 0 "repeats the OFFSET" within this fraction of `max(|OFFSET|, mean bone length)`.
const REPEAT_TOLERANCE: f64 = 1e-3;

/// One joint, compiled for the loop.
#[derive(Debug, Clone)]
struct JointPlan {
    parent: Option<usize>,
    offset: [f64; 3],
    /// Column of each position channel, per axis; `None` keeps the OFFSET component.
    position_columns: [Option<usize>; 3],
    reading: PositionReading,
    /// Rotation channels in file order: (axis, column).
    rotations: Vec<(Axis, usize)>,
}

impl JointPlan {
    fn has_positions(&self) -> bool {
        self.position_columns.iter().any(Option::is_some)
    }

    /// The channel values of the axes that have position channels (0 elsewhere).
    fn channels(&self, values: &[f64]) -> [f64; 3] {
        self.position_columns.map(|c| c.map_or(0.0, |c| values[c]))
    }

    /// Global pose from this frame's `row` and the parent's global pose.
    #[inline]
    fn pose(&self, row: &Row, parent: Option<(Quat, [f64; 3])>) -> (Quat, [f64; 3]) {
        let mut local_p = self.offset;
        for (c, column) in self.position_columns.iter().enumerate() {
            if let Some(column) = column {
                local_p[c] = match self.reading {
                    PositionReading::Added => self.offset[c] + row.values[*column],
                    PositionReading::Local | PositionReading::World => row.values[*column],
                };
            }
        }
        // q(a₁) ⊗ (q(a₂) ⊗ q(a₃)): fold from the right (`math::euler_quat`).
        let local_q = self.rotations.iter().rev().fold(math::IDENTITY, |q, &(axis, col)| {
            math::axis_mul(axis, row.cos[col], row.sin[col], &q)
        });
        match parent {
            None => (local_q, local_p),
            Some((pq, _)) if self.reading == PositionReading::World => {
                (math::quat_mul(&pq, &local_q), local_p)
            }
            Some((pq, pp)) => {
                let r = math::quat_rotate(&pq, local_p);
                (math::quat_mul(&pq, &local_q), [r[0] + pp[0], r[1] + pp[1], r[2] + pp[2]])
            }
        }
    }
}

/// The skeleton compiled for FK; built once per clip, after validation.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    joints: Vec<JointPlan>,
    /// The reading of every joint with position channels, in joint order.
    position_channels: Vec<PositionChannels>,
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
        let mut plan = Plan { joints, position_channels: Vec::new() };
        plan.decide_readings(bvh);
        Ok(plan)
    }

    /// How each joint's position channels were read ([`PositionReading`]).
    pub(crate) fn position_channels(&self) -> &[PositionChannels] {
        &self.position_channels
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
            (q[i], p[i]) = joint.pose(row, joint.parent.map(|j| (q[j], p[j])));
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
                    reading: PositionReading::Local,
                    rotations: Vec::new(),
                    ..j.clone()
                })
                .collect(),
            position_channels: Vec::new(),
        };
        rest.global(&Row::default(), q, p);
    }
}

impl Plan {
    /// Decide every joint's [`PositionReading`], parents first, from frame 0 and up to
    /// [`MAX_VOTERS`] frames; a sample's parent poses come from the readings already decided.
    fn decide_readings(&mut self, bvh: &Bvh) {
        let motion = &bvh.motion;
        if motion.num_frames == 0 || !self.joints.iter().any(JointPlan::has_positions) {
            return;
        }
        let scale = mean_bone_length(&self.joints);
        let with_positions = self.joints.iter().filter(|j| j.has_positions());
        // Frame 0 settles every joint of most files (LAFAN1, Bandai): then it is the only sample.
        let settled = with_positions.clone().all(|j| j.repeats_offset(motion.frame(0), scale));
        let samples = if settled { vec![0] } else { sample_frames(motion.num_frames) };
        let rows: Vec<Row> = samples
            .iter()
            .map(|&f| {
                let mut row = Row::default();
                row.load(motion.frame(f));
                row
            })
            .collect();
        let n = self.joints.len();
        let stands = self.zero_pose_stands();
        // Global pose of joint i in sample s at [s * n + i].
        let mut poses = vec![(math::IDENTITY, [0.0; 3]); rows.len() * n];
        for i in 0..n {
            if self.joints[i].has_positions() {
                let parents: Option<Vec<(Quat, [f64; 3])>> = self.joints[i]
                    .parent
                    .map(|j| (0..rows.len()).map(|s| poses[s * n + j]).collect());
                let (reading, reason) =
                    self.joints[i].read(&rows, parents.as_deref(), scale, stands[i]);
                self.joints[i].reading = reading;
                let joint = bvh.skeleton.joints[i].name.clone();
                self.position_channels.push(PositionChannels { joint, reading, reason });
            }
            let joint = &self.joints[i];
            for (s, row) in rows.iter().enumerate() {
                poses[s * n + i] = joint.pose(row, joint.parent.map(|j| poses[s * n + j]));
            }
        }
    }
}

impl Plan {
    /// Per joint and axis, how far the zero pose's lowest point under the joint lies below
    /// it when the zero pose stands along that axis (at least half the joint's reach, its
    /// farthest descendant in any direction, lies below it), else `None`.
    fn zero_pose_stands(&self) -> Vec<[Option<f64>; 3]> {
        let n = self.joints.len();
        let mut at = vec![[0.0; 3]; n];
        for i in 0..n {
            let base = self.joints[i].parent.map_or([0.0; 3], |p| at[p]);
            at[i] = std::array::from_fn(|k| base[k] + self.joints[i].offset[k]);
        }
        (0..n)
            .map(|i| {
                if !self.joints[i].has_positions() {
                    return [None; 3];
                }
                let mut under = vec![false; n];
                let (mut below, mut reach) = ([0.0_f64; 3], 0.0_f64);
                for j in i + 1..n {
                    under[j] = self.joints[j].parent.is_some_and(|p| p == i || under[p]);
                    if under[j] {
                        reach = reach.max(distance(at[j], at[i]));
                        below = std::array::from_fn(|k| below[k].max(at[i][k] - at[j][k]));
                    }
                }
                below.map(|d| (d > 0.0 && 2.0 * d >= reach).then_some(d))
            })
            .collect()
    }
}

/// Frame 0 and up to [`MAX_VOTERS`] − 1 more, evenly spread to the last frame.
fn sample_frames(num_frames: usize) -> Vec<usize> {
    if num_frames <= MAX_VOTERS {
        return (0..num_frames).collect();
    }
    (0..MAX_VOTERS).map(|k| k * (num_frames - 1) / (MAX_VOTERS - 1)).collect()
}

/// Mean length of the non-zero non-root OFFSETs (1 when there are none).
fn mean_bone_length(joints: &[JointPlan]) -> f64 {
    let lengths: Vec<f64> = joints
        .iter()
        .filter(|j| j.parent.is_some())
        .map(|j| norm(j.offset))
        .filter(|&l| l > 0.0)
        .collect();
    if lengths.is_empty() {
        1.0
    } else {
        lengths.iter().sum::<f64>() / lengths.len() as f64
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

impl JointPlan {
    /// This joint's reading from the sampled `rows` (frame 0 first) and, for a non-root
    /// joint, its parent's global pose in each of them; `stands`: how far below it the zero
    /// pose reaches along each axis it stands on (see [`PositionReading`]).
    fn read(
        &self,
        rows: &[Row],
        parents: Option<&[(Quat, [f64; 3])]>,
        scale: f64,
        stands: [Option<f64>; 3],
    ) -> (PositionReading, String) {
        if self.repeats_offset(&rows[0].values, scale) {
            return (PositionReading::Local, "frame 0 repeats the OFFSET".to_owned());
        }
        let o = self.channel_offset();
        let all_axes = self.position_columns.iter().all(Option::is_some);
        if let Some(parents) = parents.filter(|_| all_axes) {
            let world = self.world_votes(rows, parents, o);
            if 2 * world > rows.len() {
                let why = format!(
                    "at the world position parent + OFFSET predicts in {world} of {} frames",
                    rows.len()
                );
                return (PositionReading::World, why);
            }
        }
        self.local_or_added(rows, o, REPEAT_TOLERANCE * norm(self.offset).max(scale), stands)
    }

    /// The OFFSET on the axes with a position channel (0 elsewhere, like [`Self::channels`]).
    fn channel_offset(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.position_columns[k].map_or(0.0, |_| self.offset[k]))
    }

    /// Whether the channel values of a frame repeat the OFFSET ([`REPEAT_TOLERANCE`]).
    fn repeats_offset(&self, values: &[f64], scale: f64) -> bool {
        let tolerance = REPEAT_TOLERANCE * norm(self.offset).max(scale);
        distance(self.channels(values), self.channel_offset()) <= tolerance
    }

    /// How many of the frames have the channels [`WORLD_MARGIN`] times nearer the world
    /// position the parent's pose and OFFSET predict than either local reading.
    fn world_votes(&self, rows: &[Row], parents: &[(Quat, [f64; 3])], o: [f64; 3]) -> usize {
        let votes = rows.iter().zip(parents).filter(|(row, (pq, pp))| {
            let c = self.channels(&row.values);
            let r = math::quat_rotate(pq, self.offset);
            let predicted = [r[0] + pp[0], r[1] + pp[1], r[2] + pp[2]];
            WORLD_MARGIN * distance(c, predicted) < distance(c, o).min(norm(c))
        });
        votes.count()
    }

    /// Local or Added, decided on the one axis that tells them apart best: the channel whose
    /// spread over the clip (median absolute deviation) is smallest for the size of its
    /// OFFSET component (a root's height, not the floor plan it walks). Where the zero pose
    /// stands along that axis (`stands`), the reading that puts the joint its zero pose's
    /// depth above 0 is chosen; else its median value nearer that component than zero is
    /// `Local`.
    fn local_or_added(
        &self,
        rows: &[Row],
        o: [f64; 3],
        tolerance: f64,
        stands: [Option<f64>; 3],
    ) -> (PositionReading, String) {
        let mut best: Option<(f64, usize, f64)> = None; // (score, axis, median)
        for (k, column) in self.position_columns.iter().enumerate() {
            let Some(column) = *column else { continue };
            if o[k] == 0.0 {
                continue;
            }
            let values: Vec<f64> = rows.iter().map(|row| row.values[column]).collect();
            let middle = median(values.clone());
            let spread = median(values.iter().map(|v| (v - middle).abs()).collect());
            let score = o[k].abs() / spread.max(tolerance * 1e-6);
            if best.is_none_or(|(s, _, _)| score > s) {
                best = Some((score, k, middle));
            }
        }
        let Some((_, k, m)) = best else {
            let why = "the OFFSET is zero along the channels: both readings agree".to_owned();
            return (PositionReading::Local, why);
        };
        let axis = ["X", "Y", "Z"][k];
        let (o, m) = (o[k], m);
        if let Some(depth) = stands[k] {
            return if (m - depth).abs() <= (m + o - depth).abs() {
                let why = format!(
                    "{axis} median {m:.4} stands it {m:.4} above 0, nearer its zero pose's depth \
                     {depth:.4} than with the OFFSET's {o:.4} added"
                );
                (PositionReading::Local, why)
            } else {
                let why = format!(
                    "{axis} median {m:.4} plus the OFFSET's {o:.4} stands it {:.4} above 0, nearer \
                     its zero pose's depth {depth:.4} than the median alone",
                    m + o
                );
                (PositionReading::Added, why)
            };
        }
        if (m - o).abs() <= m.abs() {
            let why = format!("{axis} median {m:.4} is nearer the OFFSET's {o:.4} than 0");
            (PositionReading::Local, why)
        } else {
            let why = format!("{axis} median {m:.4} is nearer 0 than the OFFSET's {o:.4}");
            (PositionReading::Added, why)
        }
    }
}

/// The median (upper middle value for an even count) of finite values.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
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
        reading: PositionReading::Local,
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
            // Kept by the parser (it warns); not applied: a scaled frame is no rigid pose.
            Channel::Scale(_) => {}
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

/// NaN or infinity anywhere in the motion is an error naming the first one.
pub(crate) fn check_finite(bvh: &Bvh) -> Result<(), Error> {
    let motion = &bvh.motion;
    let Some(at) = motion.values.iter().position(|v| !v.is_finite()) else {
        return Ok(());
    };
    let (frame, column) = (at / motion.num_channels, at % motion.num_channels);
    let joint = bvh
        .skeleton
        .joints
        .iter()
        .find(|j| (j.first_channel..j.first_channel + j.channels.len()).contains(&column));
    Err(Error::NonFinite {
        frame,
        joint: joint.map(|j| j.name.clone()).unwrap_or_default(),
        channel: joint
            .and_then(|j| j.channels.get(column - j.first_channel))
            .map(|c| c.name().to_owned())
            .unwrap_or_default(),
        value: motion.values.get(at).copied().unwrap_or(f64::NAN),
    })
}

/// World positions of the rest pose (all channels zero, OFFSETs only), metres.
pub(crate) fn rest_pose(plan: &Plan, world: &ToWorld) -> Vec<Vector3<f64>> {
    let n = plan.num_joints();
    let mut q = vec![math::IDENTITY; n];
    let mut p = vec![[0.0; 3]; n];
    plan.rest(&mut q, &mut p);
    p.iter().map(|&x| world.position(x)).collect()
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
