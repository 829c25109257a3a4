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
    /// An option value out of its range: `name` the option, `expected` what it takes.
    #[error("invalid option {name} = {value}: expected {expected}")]
    InvalidOption { name: String, value: f64, expected: &'static str },
    /// A config bound to no body names (role-named: `retarget robot init` without a
    /// skeleton) where a motion or a streamed frame needs one naming its bodies.
    #[error(
        "config {config} is role-named: it is bound to a BVH skeleton (retarget_bvh); a motion \
         or frame needs a config naming its bodies"
    )]
    RoleNamedConfig { config: String },
    /// A motion or a stream on a robot that is not shipped, without a config given.
    #[error("robot {robot} is not a shipped robot: give its IK config (with_config)")]
    NoConfig { robot: String },
    /// A file to retarget whose extension names no motion format we read.
    #[error("{}: not a motion file we retarget (expected .bvh or .fbx)", path.display())]
    UnknownInput { path: PathBuf },
    /// The thread pool of a parallel run could not be started.
    #[error("cannot start a thread pool: {0}")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
    /// A clip with fewer frames than retargeting needs; `note` says what took them.
    #[error("too few frames to retarget: {frames}, at least {needed} needed{note}")]
    TooFewFrames { frames: usize, needed: usize, note: &'static str },
    /// A subject height that is missing or not a positive number of metres; `why` says
    /// which, and where it came from.
    #[error("no usable subject height: {why}")]
    SubjectHeight { why: String },
    /// A robot in which neither body names nor the robot recogniser find two feet.
    #[error(
        "cannot find the two foot bodies by name (ankle/foot, left/right) nor by recognising \
         the robot ({reason}): name them"
    )]
    NoFeet { reason: String },
    /// A body name (a report option's foot, a motion's tracked target) the robot model lacks.
    #[error("no body named \"{name}\" in the robot model")]
    NoSuchBody { name: String },
    /// A robot model whose masses are not known (the dynamics check needs them).
    #[error("the robot model's masses are not known: {0}")]
    NoMasses(String),
    /// A body id handed to the solver (a task's, a grip's) that is not a body of its model.
    #[error("{what}: body id {body} is not a body of the model")]
    NotABody { what: &'static str, body: usize },
    /// Values handed to the solver that do not fit its model or its tasks in number.
    #[error("{what}: {got} values, expected {expected}")]
    WrongLength { what: &'static str, got: usize, expected: usize },
    /// Values handed to the solver (a configuration, an objective term) not all finite.
    #[error("{what}: a value is not finite")]
    NotFinite { what: &'static str },
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
