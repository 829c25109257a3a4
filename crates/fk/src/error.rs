//! The one error type of this crate.

use thiserror::Error;

/// Everything that can go wrong turning a BVH into a [`crate::HumanMotion`].
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A body name (derived-body source, `require_body`) that the motion does not have.
    #[error("unknown body `{name}`; available bodies: {}", available.join(", "))]
    UnknownBody { name: String, available: Vec<String> },
    /// Two bodies (skeleton joints or derived bodies) with the same name.
    #[error("duplicate body name `{0}`")]
    DuplicateBody(String),
    #[error("the skeleton has no joints")]
    EmptySkeleton,
    /// The skeleton is not a tree in parents-first order.
    #[error("joint `{joint}` (#{index}) has parent #{parent}, which does not come before it")]
    BadParent { joint: String, index: usize, parent: usize },
    /// A joint's channels point outside the motion rows.
    #[error(
        "joint `{joint}` uses channel columns {first}..{end} but a motion row has {num_channels}"
    )]
    ChannelOutOfRange { joint: String, first: usize, end: usize, num_channels: usize },
    /// The motion matrix does not hold `num_frames × num_channels` values.
    #[error("motion has {len} values, expected {num_frames} frames × {num_channels} channels")]
    MotionShape { len: usize, num_frames: usize, num_channels: usize },
    /// Frames without channels: nothing moves, and the frame count bounds nothing.
    #[error("the motion has {0} frames but no channels")]
    NoChannels(usize),
    #[error("frame time must be a positive finite number of seconds, got {0}")]
    BadFrameTime(f64),
    /// NaN or infinity in the motion data.
    #[error("frame {frame}: channel {channel} of joint `{joint}` is {value}")]
    NonFinite { frame: usize, joint: String, channel: String, value: f64 },
    /// A motion with no frames: nothing to retarget.
    #[error("the motion has no frames")]
    NoFrames,
    /// A [`crate::HumanMotion`] whose pose arrays do not match its frames and bodies.
    #[error("human motion holds {positions} positions and {orientations} orientations, expected {num_frames} frames × {num_bodies} bodies")]
    BodyShape { positions: usize, orientations: usize, num_frames: usize, num_bodies: usize },
    /// NaN or infinity in a computed world pose.
    #[error("frame {frame}: the pose of body `{body}` is not finite")]
    NonFinitePose { frame: usize, body: String },
    /// A body absurdly far from the origin ([`crate::MAX_DISTANCE`]).
    #[error("frame {frame}: body `{body}` is {distance:.3e} m from the origin (more than {} km): a corrupt value or a wrong unit", crate::MAX_DISTANCE / 1e3)]
    AbsurdPosition { frame: usize, body: String, distance: f64 },
    /// A body moving absurdly far in one frame ([`crate::MAX_STEP`]).
    #[error("frame {frame}: body `{body}` moves {step:.3e} m since the previous frame (more than {} m): a corrupt value or a wrong unit", crate::MAX_STEP)]
    AbsurdStep { frame: usize, body: String, step: f64 },
    #[error("the OFFSET of joint `{0}` is not finite")]
    NonFiniteOffset(String),
    /// A scale or height option that is zero, negative or not finite.
    #[error("invalid option {name} = {value}: must be a positive finite number")]
    InvalidOption { name: &'static str, value: f64 },
    /// The skeleton is not recognised as a humanoid: required roles no joint plays.
    #[error("{}", unrecognised(missing, *found))]
    Unrecognised { missing: Vec<crate::Role>, found: usize },
    /// A role given by joint name (`FkOptions::roles`, `--map`) names no joint.
    #[error("role {role} is given as joint `{name}`, which the skeleton does not have")]
    UnknownRoleJoint { role: crate::Role, name: String },
}

/// The message of [`Error::Unrecognised`]: each missing role with names we accept for it.
fn unrecognised(missing: &[crate::Role], found: usize) -> String {
    let roles: Vec<String> = missing
        .iter()
        .map(|role| {
            let names = crate::conventions::examples(*role);
            let shown = names.iter().take(8).map(String::as_str).collect::<Vec<_>>().join(", ");
            format!("  {role}: a joint named e.g. {shown}")
        })
        .collect();
    format!(
        "not recognised as a humanoid skeleton ({found} roles found); missing:\n{}\n\
         name the joints as one of the conventions does, or map the roles to joints \
         explicitly (role -> joint name)",
        roles.join("\n")
    )
}
