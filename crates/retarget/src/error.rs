//! The one error type of the crate: configs, robots, solving, writing and reading motions.
//! The errors of the crates below (`bvh`, `c3d`, `fk`, `mjcf`) convert into it with `?`.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::path::PathBuf;

/// Everything that can go wrong in the retargeting crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A config (or other input text) that could not be read.
    #[error("{path}: cannot read file: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A file the writers could not create or write, or a motion file that could not be read.
    #[error("{}: {source}", path.display())]
    File {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A config that does not parse or breaks a rule; `at` is `file:line:column`.
    #[error("{at}: {message}")]
    Config { at: String, message: String },
    /// A robot or human body name in a config that does not exist.
    #[error("{at}: unknown {side} body `{name}`{}", did_you_mean(nearest))]
    UnknownName { at: String, side: String, name: String, nearest: Vec<String> },
    /// A robot argument that is neither a shipped robot nor a model file; `nearest` is the
    /// shipped robot whose name is close, if one is.
    #[error(
        "unknown robot \"{name}\": not a shipped robot ({}) nor an MJCF (.xml) or URDF (.urdf) file{}",
        shipped.join(", "),
        nearest.as_ref().map_or(String::new(), |k| format!("; did you mean {k}?"))
    )]
    UnknownRobot { name: String, shipped: Vec<String>, nearest: Option<String> },
    /// One of GMR's robot keys whose model we do not ship (`shipped::NOT_SHIPPED`).
    #[error(
        "robot \"{key}\" is one of GMR's robots, but its model is not shipped ({reason}); get \
         {upstream} from https://github.com/YanjieZe/GMR and pass it: --robot path/to/{}",
        upstream.rsplit('/').next().unwrap_or(upstream)
    )]
    NotShipped { key: String, reason: String, upstream: String },
    /// An error about one input file, with its path.
    #[error("{path}: {source}")]
    InFile {
        path: String,
        #[source]
        source: Box<Error>,
    },
    /// An option, argument or call that does not fit (the robot, the model, the clip or the
    /// state of a stream); the message says which and why.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// Human forward kinematics failed (bad BVH content, NaN in the motion, ...).
    #[error(transparent)]
    Fk(#[from] fk::Error),
    /// A BVH file that does not parse.
    #[error(transparent)]
    Bvh(#[from] bvh::Error),
    /// Virtual marker bodies that cannot be built from a C3D file (`context` names the file
    /// and the step).
    #[error("{context}: {source}")]
    Markers {
        context: String,
        #[source]
        source: fk::markers::MarkerError,
    },
    /// An SMPL-X / SMPL+H body model or AMASS motion that cannot be read or posed.
    #[error(transparent)]
    Smpl(#[from] smpl::Error),
    /// An `.npz` that cannot be read: not a zip, an array missing, or one that cannot be read
    /// (the message names the file and the array).
    #[error(transparent)]
    Npz(#[from] npz::Error),
    /// A C3D file that does not parse.
    #[error(transparent)]
    C3d(#[from] c3d::Error),
    /// An FBX file that cannot be read, or a take that cannot be sampled (the message names
    /// the file and the take).
    #[error(transparent)]
    Fbx(#[from] fbx::Error),
    /// A robot model (MJCF or URDF) that does not compile.
    #[error(transparent)]
    Mjcf(#[from] mjcf::Error),
    /// A robot model in which no two-armed biped standing at `qpos0` is found
    /// ([`crate::RobotRoles`]).
    #[error("robot `{model}` is not a two-armed biped: {reason}")]
    NotHumanoid { model: String, reason: String },
    /// The solve failed numerically at `frame`: a target not finite, a solve that diverged
    /// there, a trajectory window starting there whose quadratic model is not positive
    /// definite; `message` says which.
    #[error("frame {frame}: {message}")]
    Numerical { frame: usize, message: String },
    /// A streamed frame ([`crate::HumanFrame`]) whose poses do not match its body names.
    #[error(
        "frame {frame}: {names} body names but {positions} positions and {orientations} orientations"
    )]
    FrameShape { frame: usize, names: usize, positions: usize, orientations: usize },
    /// A streamed frame without a body of the first frame (the first frame fixes which bodies
    /// the config reads).
    #[error("frame {frame}: body `{body}` of the first frame is missing")]
    FrameMissingBody { frame: usize, body: String },
    /// A motion handed to a writer with a non-finite `qpos` entry.
    #[error("qpos of frame {frame}, entry {index} is not finite ({value})")]
    NonFiniteQpos { frame: usize, index: usize, value: f64 },
    #[error("{}: unknown output format (expected .npz, .csv, .pkl or .json)", path.display())]
    UnknownFormat { path: PathBuf },
    /// A motion that does not belong to the robot model it is written or measured with.
    #[error("motion does not fit the robot model: {0}")]
    Mismatch(String),
    /// An `.npz` (or other motion file) whose content is not what we write.
    #[error("{}: {message}", path.display())]
    Read { path: PathBuf, message: String },
}

impl Error {
    /// [`Error::Numerical`] at `frame`.
    pub(crate) fn numerical(frame: usize, message: String) -> Error {
        Error::Numerical { frame, message }
    }
}

fn did_you_mean(nearest: &[String]) -> String {
    if nearest.is_empty() {
        String::new()
    } else {
        format!("; nearest: {}", nearest.join(", "))
    }
}
