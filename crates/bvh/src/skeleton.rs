//! The typed tree a BVH file describes, independent of how it was parsed.

/// Index of a joint in [`Skeleton::joints`] (file order, parents before children).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct JointId(pub usize);

/// A coordinate axis named by a channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    X,
    Y,
    Z,
}

/// One motion channel of a joint, in the order the file lists them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    Position(Axis),
    /// Rotation in degrees about the joint's local axis.
    Rotation(Axis),
    /// Scale along the joint's local axis (`Xscale`, written by some Maya and MotionBuilder
    /// exporters, usually 1). Kept so that files round-trip; `fk` does not apply it and the
    /// parser warns about it ([`crate::Warning::ScaleChannels`]).
    Scale(Axis),
}

impl Channel {
    /// The name used in BVH files, e.g. `Xposition`, `Zrotation`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Channel::Position(Axis::X) => "Xposition",
            Channel::Position(Axis::Y) => "Yposition",
            Channel::Position(Axis::Z) => "Zposition",
            Channel::Rotation(Axis::X) => "Xrotation",
            Channel::Rotation(Axis::Y) => "Yrotation",
            Channel::Rotation(Axis::Z) => "Zrotation",
            Channel::Scale(Axis::X) => "Xscale",
            Channel::Scale(Axis::Y) => "Yscale",
            Channel::Scale(Axis::Z) => "Zscale",
        }
    }

    /// Inverse of [`Channel::name`] (exact, case-sensitive match).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Channel> {
        Some(match name {
            "Xposition" => Channel::Position(Axis::X),
            "Yposition" => Channel::Position(Axis::Y),
            "Zposition" => Channel::Position(Axis::Z),
            "Xrotation" => Channel::Rotation(Axis::X),
            "Yrotation" => Channel::Rotation(Axis::Y),
            "Zrotation" => Channel::Rotation(Axis::Z),
            "Xscale" => Channel::Scale(Axis::X),
            "Yscale" => Channel::Scale(Axis::Y),
            "Zscale" => Channel::Scale(Axis::Z),
            _ => return None,
        })
    }
}

/// What kind of node a joint is in the HIERARCHY block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointKind {
    Root,
    Joint,
    /// An `End Site`: an end point with an offset and no channels, named `<Parent>_End`.
    End,
}

/// One node of the skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// `None` only for roots.
    pub parent: Option<JointId>,
    /// OFFSET from the parent joint, in file units.
    pub offset: [f64; 3],
    /// Channels in file order (empty for End Sites).
    pub channels: Vec<Channel>,
    /// Column of this joint's first channel in a motion row.
    pub first_channel: usize,
}

/// The HIERARCHY block: every ROOT, JOINT and End Site in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Skeleton {
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Total number of channels (columns of a motion row).
    #[must_use]
    pub fn num_channels(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// Look a joint up by exact name.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<JointId> {
        self.joints.iter().position(|j| j.name == name).map(JointId)
    }

    /// # Panics
    /// If `id` is not a joint of this skeleton (ids from [`Skeleton::find`] and
    /// [`Joint::parent`] always are).
    #[must_use]
    // A caller's out-of-range id is a bug, like slice indexing; file input never reaches it.
    #[allow(clippy::indexing_slicing)]
    pub fn joint(&self, id: JointId) -> &Joint {
        &self.joints[id.0]
    }
}

/// The MOTION block: `num_frames` rows of `num_channels` values, row-major.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Motion {
    /// Seconds per frame, as written after `Frame Time:`.
    pub frame_time: f64,
    pub num_frames: usize,
    pub num_channels: usize,
    pub values: Vec<f64>,
}

impl Motion {
    /// One frame's channel values.
    ///
    /// # Panics
    /// If `index >= num_frames` (a parsed motion holds `num_frames × num_channels` values).
    #[must_use]
    // A caller's out-of-range frame is a bug, like slice indexing; file input never reaches it.
    #[allow(clippy::indexing_slicing)]
    pub fn frame(&self, index: usize) -> &[f64] {
        &self.values[index * self.num_channels..(index + 1) * self.num_channels]
    }

    /// Keeps the first `frames` frames (all of them when there are fewer), values and count
    /// together.
    pub fn truncate(&mut self, frames: usize) {
        self.num_frames = self.num_frames.min(frames);
        self.values.truncate(self.num_frames * self.num_channels);
    }

    /// Frames per second (`1 / frame_time`).
    #[must_use]
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }
}

/// A whole BVH file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Bvh {
    pub skeleton: Skeleton,
    pub motion: Motion,
}

#[cfg(test)]
mod tests {
    use super::Motion;

    #[test]
    fn truncating_keeps_the_count_and_the_values_together() {
        let mut m = Motion {
            frame_time: 0.1,
            num_frames: 3,
            num_channels: 2,
            values: vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
        };
        m.truncate(5);
        assert_eq!((m.num_frames, m.values.len()), (3, 6), "fewer frames than asked: all kept");
        m.truncate(2);
        assert_eq!((m.num_frames, m.values.as_slice()), (2, &[1.0, 2.0, 3.0, 4.0][..]));
        m.truncate(0);
        assert_eq!((m.num_frames, m.values.len()), (0, 0));
    }
}
