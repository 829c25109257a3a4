//! [`Retargeter`]: the owning entry point. A robot (shipped or from a file), how the IK config
//! is chosen, and the solve options, built once; then clips ([`Retargeter::retarget`],
//! [`Retargeter::retarget_bvh`], [`Retargeter::retarget_c3d`]) or a stream of frames
//! ([`Retargeter::step`]).
//!
//! # Streaming and clips
//!
//! The default solve ([`SolveMode::Plausible`]) plans the feet from the whole clip (contact
//! phases, planted anchors) and filters the solved trajectory, which needs the frames that
//! follow. A stream has no future, so [`Retargeter::step`] runs the *causal* part of the
//! solve: GMR's tasks with the hard constraints (joint ranges, ground, self-collision, joint
//! speed), warm-started from the previous frame, without planting or filtering. With
//! [`RetargetOptions::causal`] (or a [`PlausibleOptions`] with [`Planting::Off`] and no
//! smoothing) the clip path solves exactly that problem, and the two give the same numbers;
//! with [`SolveMode::Gmr`] `step` is GMR's own per-frame solve and equals the clip path too.
//! With the full default solve, `step` runs its causal part ([`PlausibleOptions::causal`] with
//! the options' other settings).
//!
//! [`Planting::Off`]: crate::solve::Planting::Off
//! [`PlausibleOptions`]: crate::PlausibleOptions
//! [`PlausibleOptions::causal`]: crate::PlausibleOptions::causal

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use bvh::Bvh;
use fk::HumanMotion;
use mjcf::Model;
use nalgebra::{Isometry3, Quaternion, UnitQuaternion, Vector3};

use crate::config::IkConfig;
use crate::derive::Chosen;
use crate::fbx_clip::FbxClip;
use crate::ik::{FrameDiagnostics, Solver};
use crate::lie::Pose;
use crate::marker_config::MarkerConfig;
use crate::motion::RobotMotion;
use crate::report::{QualityReport, ReportOptions};
use crate::solve::{
    build_solver, finite_pose, solve_first_frame, task_specs, ClipDiagnostics, Pipeline,
    RetargetOptions, SolveMode, SubjectHeight,
};
use crate::targets::TargetMap;
use crate::writers::Format;
use crate::{shipped, Error};

/// One frame of human motion for [`Retargeter::step`]: per named body its world position
/// (metres, Z up) and orientation, as GMR's `human_data` (`{name: (pos, quat_wxyz)}`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HumanFrame {
    pub body_names: Vec<String>,
    pub positions: Vec<Vector3<f64>>,
    pub orientations: Vec<UnitQuaternion<f64>>,
}

impl HumanFrame {
    /// The position and orientation of body `name` (`None` when the frame has no such body,
    /// or no pose for it).
    #[must_use]
    pub fn pose(&self, name: &str) -> Option<(&Vector3<f64>, &UnitQuaternion<f64>)> {
        let i = self.body_names.iter().position(|n| n == name)?;
        Some((self.positions.get(i)?, self.orientations.get(i)?))
    }

    /// Frame `frame` of a clip (`None` past its end).
    #[must_use]
    pub fn from_motion(human: &HumanMotion, frame: usize) -> Option<HumanFrame> {
        if frame >= human.num_frames {
            return None;
        }
        Some(HumanFrame {
            body_names: human.body_names.clone(),
            positions: human.frame_positions(frame).to_vec(),
            orientations: human.frame_orientations(frame).to_vec(),
        })
    }

    /// An empty frame to fill with [`HumanFrame::push`].
    #[must_use]
    pub fn with_capacity(bodies: usize) -> HumanFrame {
        HumanFrame {
            body_names: Vec::with_capacity(bodies),
            positions: Vec::with_capacity(bodies),
            orientations: Vec::with_capacity(bodies),
        }
    }

    /// Adds a body.
    pub fn push(&mut self, name: &str, position: Vector3<f64>, orientation: UnitQuaternion<f64>) {
        self.body_names.push(name.to_owned());
        self.positions.push(position);
        self.orientations.push(orientation);
    }
}

/// Robot, config choice and options, owned: the way into the library.
///
/// - Clips: [`Retargeter::retarget`] (a [`HumanMotion`]), [`Retargeter::retarget_bvh`]
///   (FK and the config choice of the CLI), [`Retargeter::retarget_c3d`] (virtual marker
///   bodies); each returns the [`RobotMotion`] with per-frame [`ClipDiagnostics`].
/// - Streams: [`Retargeter::step`], one frame at a time, warm-started (module docs).
///
/// The IK config: the one given ([`Retargeter::with_config`]; a role-named config is bound
/// to each BVH skeleton), else for a BVH the CLI's choice ([`crate::derive::choose`]: a
/// shipped robot's tuned config for LAFAN1-named skeletons, else one derived from the roles),
/// else (motions and frames, which carry no skeleton) the shipped robot's tuned config.
///
/// `Retargeter` is `Send + Sync`: clips can be solved from several threads at once through a
/// shared reference (the stream state sits behind a mutex that `step` never contends for).
#[derive(Debug)]
pub struct Retargeter {
    model: Arc<Model>,
    label: String,
    given: Option<IkConfig>,
    tuned: Option<IkConfig>,
    /// The shipped robot's SMPL-X config (GMR's), for SMPL-X and SMPL+H motions.
    smplx: Option<IkConfig>,
    options: RetargetOptions,
    stream_fps: f64,
    stream: Mutex<Option<Stream>>,
    /// What was done to the robot's model file to retarget onto it.
    notes: Vec<String>,
}

impl Retargeter {
    /// A shipped robot by key (`unitree_g1`, see [`shipped::keys`]) with its tuned config, or
    /// an MJCF (`.xml`) or URDF (`.urdf`) file ([`shipped::load_robot`]); the default options.
    pub fn new(robot: &str) -> Result<Retargeter, Error> {
        let (model, notes) = shipped::load_robot_noted(robot)?;
        let tuned = shipped::tuned_config(robot).transpose()?;
        let mut retargeter = Retargeter::from_model(model, &shipped::robot_label(robot));
        retargeter.tuned = tuned;
        retargeter.notes = notes;
        retargeter.smplx = shipped::smplx_config(robot).transpose()?;
        Ok(retargeter)
    }

    /// A shipped robot by key; an error for anything else.
    pub fn shipped(key: &str) -> Result<Retargeter, Error> {
        if shipped::find(key).is_none() {
            return Err(shipped::refused(key).unwrap_or_else(|| shipped::unknown_robot(key)));
        }
        Retargeter::new(key)
    }

    /// A robot model file and an IK config file (GMR schema).
    pub fn from_files(robot: &Path, config: &Path) -> Result<Retargeter, Error> {
        let robot = robot.to_string_lossy();
        let (model, notes) = shipped::load_robot_noted(&robot)?;
        let mut retargeter = Retargeter::from_model(model, &shipped::robot_label(&robot));
        retargeter.notes = notes;
        Ok(retargeter.with_config(IkConfig::from_file(config)?))
    }

    /// Any compiled model; `label` names the robot in messages and derived configs.
    #[must_use]
    pub fn from_model(model: Model, label: &str) -> Retargeter {
        Retargeter {
            model: Arc::new(model),
            label: label.to_owned(),
            given: None,
            tuned: None,
            smplx: None,
            options: RetargetOptions::default(),
            stream_fps: 30.0,
            stream: Mutex::new(None),
            notes: Vec::new(),
        }
    }

    /// What was done to the robot's model file to retarget onto it (a floating base added
    /// to a model without one), one sentence each; empty for shipped robots.
    #[must_use]
    pub fn robot_notes(&self) -> &[String] {
        &self.notes
    }

    /// Use `config` for every clip and frame (bound to each skeleton when role-named).
    #[must_use]
    pub fn with_config(mut self, config: IkConfig) -> Retargeter {
        self.given = Some(config);
        self.reset();
        self
    }

    /// [`Retargeter::with_config`] in place.
    pub fn set_config(&mut self, config: IkConfig) {
        self.given = Some(config);
        self.reset();
    }

    /// Replace the options.
    #[must_use]
    pub fn with_options(mut self, options: RetargetOptions) -> Retargeter {
        self.options = options;
        self.reset();
        self
    }

    /// Replace the solve ([`SolveMode::Gmr`] for GMR's exact one).
    #[must_use]
    pub fn with_mode(mut self, mode: SolveMode) -> Retargeter {
        self.options.mode = mode;
        self.reset();
        self
    }

    /// The subject height in metres (`None`: estimated from a BVH skeleton, the config's
    /// `human_height_assumption` for motions and frames).
    #[must_use]
    pub fn with_human_height(mut self, height: Option<f64>) -> Retargeter {
        self.options.human_height = height;
        self.reset();
        self
    }

    /// The frame rate of streamed frames (default 30): the joint speed limits hold per frame
    /// over `1 / fps` seconds.
    #[must_use]
    pub fn with_stream_fps(mut self, fps: f64) -> Retargeter {
        self.stream_fps = fps;
        self.reset();
        self
    }

    #[must_use]
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The model, shared (for motions that outlive the retargeter, e.g. to write them).
    #[must_use]
    pub fn shared_model(&self) -> Arc<Model> {
        Arc::clone(&self.model)
    }

    /// The robot's name in messages: the shipped key or the model file's stem.
    #[must_use]
    pub fn label(&self) -> &str {
        &self.label
    }

    #[must_use]
    pub fn options(&self) -> &RetargetOptions {
        &self.options
    }

    /// The config given with [`Retargeter::with_config`].
    #[must_use]
    pub fn given_config(&self) -> Option<&IkConfig> {
        self.given.as_ref()
    }

    /// The shipped robot's tuned config.
    #[must_use]
    pub fn tuned_config(&self) -> Option<&IkConfig> {
        self.tuned.as_ref()
    }

    /// The shipped robot's SMPL-X config (GMR's `smplx_to_*.json`, `shipped::CONFIGS`), if it has one.
    #[must_use]
    pub fn smplx_config(&self) -> Option<&IkConfig> {
        self.smplx.as_ref()
    }

    /// The config a BVH clip is retargeted with, and why ([`crate::derive::choose`]).
    pub fn choose_config(&self, bvh: &Bvh) -> Result<Chosen, Error> {
        let gmr = Pipeline::new(&self.options).is_gmr();
        crate::derive::choose(
            &self.model,
            &self.label,
            bvh,
            &self.options.fk,
            self.given.clone(),
            self.tuned.as_ref(),
            gmr,
        )
    }

    /// The config of motions and frames: the given one, else the shipped robot's tuned one.
    pub fn motion_config(&self) -> Result<&IkConfig, Error> {
        motion_config(self.given.as_ref(), self.tuned.as_ref(), &self.label)
    }

    /// Retargets a clip: FK of the skeleton (up axis, units and height inferred), the config
    /// of [`Retargeter::choose_config`], then the solve. `diag.human_inferred` ends with the
    /// config used.
    pub fn retarget_bvh(&self, bvh: &Bvh) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let chosen = self.choose_config(bvh)?;
        self.retarget_bvh_with(bvh, &chosen)
    }

    /// [`Retargeter::retarget_bvh`] with a config already chosen.
    pub fn retarget_bvh_with(
        &self,
        bvh: &Bvh,
        chosen: &Chosen,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let (motion, mut diag) =
            crate::solve::retarget_bvh(bvh, &self.model, &chosen.config, &self.options)?;
        diag.human_inferred = if diag.human_inferred.is_empty() {
            chosen.summary.clone()
        } else {
            format!("{}; {}", diag.human_inferred, chosen.summary)
        };
        Ok((motion, diag))
    }

    /// [`Retargeter::retarget_bvh`] of the file at `path`.
    pub fn retarget_bvh_file(&self, path: &Path) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        self.retarget_bvh(&bvh::from_path(path)?)
    }

    /// The config an FBX take is retargeted with, and why: [`Retargeter::choose_config`] of
    /// its skeleton, with the file's axes and unit ([`FbxClip::fk_options`]).
    pub fn choose_fbx_config(&self, clip: &FbxClip) -> Result<Chosen, Error> {
        let gmr = Pipeline::new(&self.options).is_gmr();
        let fk = clip.fk_options(&self.options.fk);
        let (given, tuned) = (self.given.clone(), self.tuned.as_ref());
        crate::derive::choose(&self.model, &self.label, &clip.bvh, &fk, given, tuned, gmr)
    }

    /// Retargets an FBX take as a BVH clip ([`Retargeter::retarget_bvh`]) with the file's
    /// axes and unit; `diag.human_inferred` starts with the take and what the file declares
    /// ([`FbxClip::summary`]) and ends with the config used.
    pub fn retarget_fbx_with(
        &self,
        clip: &FbxClip,
        chosen: &Chosen,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let options =
            RetargetOptions { fk: clip.fk_options(&self.options.fk), ..self.options.clone() };
        let (motion, mut diag) =
            crate::solve::retarget_bvh(&clip.bvh, &self.model, &chosen.config, &options)?;
        diag.human_inferred = [clip.summary(), diag.human_inferred, chosen.summary.clone()]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join("; ");
        Ok((motion, diag))
    }

    /// Take `take` (name or index; `None`: the one with the most motion) of the FBX file at
    /// `path`, retargeted with [`Retargeter::choose_fbx_config`]'s config.
    pub fn retarget_fbx_file(
        &self,
        path: &Path,
        take: Option<&str>,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let clip = FbxClip::read(path, take)?;
        let in_file = |e: Error| match e {
            e @ Error::InFile { .. } => e,
            e => Error::InFile { path: clip.file.clone(), source: Box::new(e) },
        };
        let chosen = self.choose_fbx_config(&clip).map_err(in_file)?;
        self.retarget_fbx_with(&clip, &chosen).map_err(in_file)
    }

    /// Retargets a human motion with [`Retargeter::motion_config`]; the subject height is the
    /// options' or the config's `human_height_assumption` (GMR without `actual_human_height`).
    pub fn retarget(&self, human: &HumanMotion) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let config = self.motion_config()?;
        self.retarget_with(
            human,
            config,
            SubjectHeight::of_motion(self.options.human_height, config),
        )
    }

    /// Retargets a C3D clip through the virtual marker bodies of `markers` with `config` (the
    /// marker config is usually the IK config file too). `name` names the file in messages,
    /// once: the marker bodies' errors say it themselves, the solve's are wrapped in
    /// [`Error::InFile`].
    pub fn retarget_c3d(
        &self,
        file: &c3d::C3d,
        name: &str,
        markers: &MarkerConfig,
        config: &IkConfig,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let clip = markers.motion(file, name, self.options.human_height)?;
        self.retarget_with(&clip.human, config, clip.height)
            .map_err(|e| Error::InFile { path: name.to_owned(), source: Box::new(e) })
    }

    /// [`Retargeter::retarget_c3d`] of the C3D file at `path` with the marker-driven IK config
    /// file `config` (`marker_bodies` and the IK tables in one file, e.g.
    /// `configs/c3d_plugingait_to_unitree_g1.json`).
    pub fn retarget_c3d_file(
        &self,
        path: &Path,
        config: &Path,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        // c3d's errors name the file.
        let file = c3d::C3d::from_path(path)?;
        let markers = MarkerConfig::from_file(config)?;
        let ik = IkConfig::from_file(config)?;
        self.retarget_c3d(&file, &path.display().to_string(), &markers, &ik)
    }

    /// Retargets a human motion with `config` and the subject height `height` (the one the
    /// clip's source decided; [`SubjectHeight::given`] for a number), serially or in chunks
    /// ([`RetargetOptions::chunk`]).
    pub fn retarget_with(
        &self,
        human: &HumanMotion,
        config: &IkConfig,
        height: SubjectHeight,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let roles = &self.options.fk.roles;
        crate::solve::solve_clip(human, &self.model, config, &self.options, &height, roles)
    }

    /// Writes a motion of this robot (format from the extension, or `format`), atomically.
    pub fn write(
        &self,
        motion: &RobotMotion,
        path: &Path,
        format: Option<Format>,
    ) -> Result<(), Error> {
        crate::writers::write_motion(path, motion, &self.model, format)
    }

    /// The quality report of a motion of this robot.
    pub fn report(
        &self,
        motion: &RobotMotion,
        options: &ReportOptions,
    ) -> Result<QualityReport, Error> {
        crate::report::report(motion, &self.model, options)
    }

    /// Retargets one streamed frame and returns the robot's `qpos` (MuJoCo layout: root
    /// position, root quaternion w x y z, joints). Warm-started from the previous frame; the
    /// first frame starts from the robot's home pose (moved under the root target in the
    /// default mode, as clips do). The config is [`Retargeter::motion_config`], the subject
    /// height the options' or the config's assumption, the frame rate
    /// [`Retargeter::with_stream_fps`]. See the module docs for what runs.
    ///
    /// Bodies are found by name; the first frame fixes which ones the config reads, and later
    /// frames must hold them (in any order; extra bodies are ignored).
    pub fn step(&mut self, frame: &HumanFrame) -> Result<&[f64], Error> {
        let slot = self.stream.get_mut().unwrap_or_else(PoisonError::into_inner);
        let stream = match slot {
            Some(stream) => stream,
            None => {
                // motion_config's choice, without borrowing all of self.
                let config = motion_config(self.given.as_ref(), self.tuned.as_ref(), &self.label)?;
                slot.insert(Stream::new(
                    Arc::clone(&self.model),
                    config,
                    &frame.body_names,
                    &self.options,
                    self.stream_fps,
                )?)
            }
        };
        stream.step(frame)
    }

    /// The targets of the last streamed frame: per scaled human body its name and world pose
    /// (`world_from_target`) after scaling and offsets (GMR's `scaled_human_data`).
    #[must_use]
    pub fn last_step_targets(&self) -> Vec<(String, Isometry3<f64>)> {
        let guard = self.stream.lock().unwrap_or_else(PoisonError::into_inner);
        let world_from_target = |p: &Pose| {
            let [w, i, j, k] = p.quat;
            Isometry3::from_parts(
                p.pos.into(),
                UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k)),
            )
        };
        match guard.as_ref() {
            Some(s) if s.frames > 0 => {
                let names = s.map.bodies.iter().map(|b| b.name.clone());
                names.zip(s.targets.iter().map(world_from_target)).collect()
            }
            _ => Vec::new(),
        }
    }

    /// Retargets BVH and FBX files in parallel on a pool of `threads` threads (0: one per
    /// core): each `(input, output)` pair is read, retargeted ([`Retargeter::retarget_bvh`];
    /// an FBX file's take with the most motion, [`Retargeter::retarget_fbx_file`]) and written
    /// in the output's format (by extension). One result per pair, in order; a clip that fails
    /// fails alone.
    pub fn retarget_files(
        &self,
        pairs: &[(PathBuf, PathBuf)],
        threads: usize,
    ) -> Result<Vec<Result<FileResult, Error>>, Error> {
        use rayon::prelude::*;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        Ok(pool.install(|| {
            pairs.par_iter().map(|(input, output)| self.retarget_file(input, output)).collect()
        }))
    }

    fn retarget_file(&self, input: &Path, output: &Path) -> Result<FileResult, Error> {
        let started = std::time::Instant::now();
        let in_file =
            |e: Error| Error::InFile { path: input.display().to_string(), source: Box::new(e) };
        let is = |ext: &str| input.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext));
        let (motion, diag) = if is("bvh") {
            self.retarget_bvh_file(input).map_err(in_file)?
        } else if is("fbx") {
            self.retarget_fbx_file(input, None)?
        } else {
            return Err(Error::UnknownInput { path: input.to_path_buf() });
        };
        self.write(&motion, output, None)?;
        Ok(FileResult {
            frames: motion.num_frames(),
            seconds: started.elapsed().as_secs_f64(),
            inferred: diag.human_inferred,
        })
    }

    /// Diagnostics of the last streamed frame.
    #[must_use]
    pub fn last_step_diagnostics(&self) -> Option<FrameDiagnostics> {
        let guard = self.stream.lock().unwrap_or_else(PoisonError::into_inner);
        guard.as_ref().and_then(|s| s.last.clone())
    }

    /// Frames streamed since the last reset.
    #[must_use]
    pub fn streamed_frames(&self) -> usize {
        let guard = self.stream.lock().unwrap_or_else(PoisonError::into_inner);
        guard.as_ref().map_or(0, |s| s.frames)
    }

    /// Forget the stream: the next [`Retargeter::step`] starts a new one.
    pub fn reset(&mut self) {
        *self.stream.get_mut().unwrap_or_else(PoisonError::into_inner) = None;
    }
}

/// What [`Retargeter::retarget_files`] did with one file.
#[derive(Debug, Clone, PartialEq)]
pub struct FileResult {
    pub frames: usize,
    /// Wall time of this clip (read, solve, write).
    pub seconds: f64,
    /// What was inferred about the source and the config used.
    pub inferred: String,
}

self_cell::self_cell!(
    /// The stream's solver, borrowing the model it owns a handle of.
    struct StreamSolver {
        owner: Arc<Model>,
        #[covariant]
        dependent: Solver,
    }

    impl {Debug}
);

/// A stream's state: the solver (warm start), the target map and buffers.
#[derive(Debug)]
struct Stream {
    solver: StreamSolver,
    map: TargetMap,
    tracked: Vec<(usize, usize)>,
    /// The body names of the first frame, which `map` indexes.
    names: Vec<String>,
    /// A later frame's bodies in the order of `names` (when its names differ).
    positions: Vec<Vector3<f64>>,
    orientations: Vec<UnitQuaternion<f64>>,
    targets: Vec<Pose>,
    /// What runs: GMR's solve as given, else the default solve's causal part.
    pipeline: Pipeline,
    dt: f64,
    frames: usize,
    last: Option<FrameDiagnostics>,
}

/// The config of motions and frames ([`Retargeter::motion_config`]): the given one unless
/// it is role-named, else the shipped robot's tuned one.
fn motion_config<'c>(
    given: Option<&'c IkConfig>,
    tuned: Option<&'c IkConfig>,
    robot: &str,
) -> Result<&'c IkConfig, Error> {
    match (given, tuned) {
        (Some(given), _) if crate::derive::is_role_named(given) => {
            Err(Error::RoleNamedConfig { config: given.source.clone() })
        }
        (Some(given), _) => Ok(given),
        (None, Some(tuned)) => Ok(tuned),
        (None, None) => Err(Error::NoConfig { robot: robot.to_owned() }),
    }
}

impl Stream {
    fn new(
        model: Arc<Model>,
        config: &IkConfig,
        names: &[String],
        options: &RetargetOptions,
        fps: f64,
    ) -> Result<Stream, Error> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::InvalidOption {
                name: "stream fps".to_owned(),
                value: fps,
                expected: "a positive rate",
            });
        }
        let height = SubjectHeight::of_motion(options.human_height, config);
        config.validate(&model, names)?;
        let map = TargetMap::new(config, names, height.metres)?;
        let stages = task_specs(config, &model, &map);
        let pipeline = Pipeline::new(options).causal();
        let solver = StreamSolver::try_new(model, |m| build_solver(m, &stages, &pipeline))?;
        let tracked = solver.borrow_dependent().tracked().to_vec();
        let slots = map.bodies.len();
        Ok(Stream {
            solver,
            map,
            tracked,
            names: names.to_vec(),
            positions: Vec::new(),
            orientations: Vec::new(),
            targets: vec![Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::zeros() }; slots],
            pipeline,
            dt: 1.0 / fps,
            frames: 0,
            last: None,
        })
    }

    fn step(&mut self, frame: &HumanFrame) -> Result<&[f64], Error> {
        let n = frame.body_names.len();
        if frame.positions.len() != n || frame.orientations.len() != n {
            return Err(Error::FrameShape {
                frame: self.frames,
                names: n,
                positions: frame.positions.len(),
                orientations: frame.orientations.len(),
            });
        }
        let (positions, orientations) = if frame.body_names == self.names {
            (frame.positions.as_slice(), frame.orientations.as_slice())
        } else {
            self.gather(frame)?;
            (self.positions.as_slice(), self.orientations.as_slice())
        };
        self.map.compute(positions, orientations, &mut self.targets);
        if let Some(bad) = self.targets.iter().position(|p| !finite_pose(p)) {
            let name = self.map.bodies.get(bad).map_or("?", |b| b.name.as_str());
            let message = format!("target of human body `{name}` is not finite");
            return Err(Error::Numerical { frame: self.frames, message });
        }
        let first = self.frames == 0;
        let plausible = !self.pipeline.is_gmr();
        let (targets, tracked, dt, index) = (&self.targets, &self.tracked, self.dt, self.frames);
        let diag = self.solver.with_dependent_mut(|model, solver| {
            let diag = if first && plausible {
                solve_first_frame(model, solver, tracked, targets)?
            } else {
                solver.solve_frame(targets, crate::solve::first_frame_dt(first, dt))?
            };
            crate::solve::reject_divergence(solver.qpos(), index)?;
            Ok::<_, Error>(diag)
        })?;
        self.last = Some(diag);
        self.frames += 1;
        Ok(self.solver.borrow_dependent().qpos())
    }

    /// Copies `frame`'s bodies into the order of the first frame's names.
    fn gather(&mut self, frame: &HumanFrame) -> Result<(), Error> {
        self.positions.clear();
        self.orientations.clear();
        for name in &self.names {
            let Some((position, orientation)) = frame.pose(name) else {
                return Err(Error::FrameMissingBody { frame: self.frames, body: name.clone() });
            };
            self.positions.push(*position);
            self.orientations.push(*orientation);
        }
        Ok(())
    }
}
