//! `retarget report MOTION`: quality metrics of a robot motion (see `retarget::report` for
//! the definitions), as a table and optionally as JSON. The motion is ours (.npz) or another
//! tool's (`retarget::writers::read_motion`: an .npz of qpos, BeyondMimic's .npz, GMR's .pkl,
//! Unitree's .csv).

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use retarget::report::{report, ReportOptions};
use retarget::writers::{read_motion, read_motion_npz, read_npz_robot, FpsFrom};

use crate::shipped;

#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    /// A robot motion: retarget's .npz; an .npz of `qpos` (T×nq, MuJoCo's layout, e.g.
    /// GMR's) with or without `fps`; BeyondMimic's / mjlab's .npz (`joint_pos`,
    /// `body_pos_w`, `body_quat_w`, `fps`; the root is body 0); GMR's .pkl (read without
    /// executing it); Unitree's .csv (`x,y,z,qx,qy,qz,qw,joints…` per line, needs --fps).
    /// Only retarget's .npz stores targets and source foot contacts: without them tracking,
    /// skating and stance are not measured.
    pub motion: PathBuf,
    /// Robot (shipped name or MJCF path); default: the `robot` name stored in the .npz
    /// (required for files that store none: .pkl, .csv and most other tools' .npz).
    #[arg(long)]
    pub robot: Option<String>,
    /// Frame rate of a motion that stores none (a .csv, an .npz without `fps`). A value that
    /// disagrees with the file's stored fps is an error (the file's timing is measured).
    #[arg(long)]
    pub fps: Option<f64>,
    /// The IK config the motion was solved with: bodies without a position weight get no
    /// position error, and its `robot_root_name`'s target is the scaled human's pelvis.
    /// Default: the shipped config of a shipped robot (else every target body's position is
    /// measured, and the first target is the pelvis).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Also write the report as JSON to this file.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Foot bodies, left then right (default: the ankle/foot bodies found by name, else the
    /// robot recogniser's feet).
    #[arg(long, num_args = 2, value_names = ["LEFT", "RIGHT"])]
    pub feet: Option<Vec<String>>,
    /// Height of the ground plane (m).
    #[arg(long, default_value_t = ReportOptions::default().ground_height)]
    pub ground: f64,
    /// Contact: foot lowest point below this height (m).
    #[arg(long, default_value_t = ReportOptions::default().contact_height)]
    pub contact_height: f64,
    /// Contact: horizontal foot speed below this (m/s).
    #[arg(long, default_value_t = ReportOptions::default().contact_speed)]
    pub contact_speed: f64,
    /// A contact frame slides above this horizontal foot speed (m/s).
    #[arg(long, default_value_t = ReportOptions::default().slide_speed)]
    pub slide_speed: f64,
    /// Count frames with a joint speed above this (rad/s).
    #[arg(long)]
    pub velocity_limit: Option<f64>,
    /// Also write the dynamics check of every checked frame as CSV (frame, contact points,
    /// residual in m·g with its force and torque parts, centre of pressure outside the
    /// support in m, the needed force in N and torque in N m).
    #[arg(long, value_name = "OUT.csv")]
    pub dynamics_frames: Option<PathBuf>,
    /// Measure tracking against the targets stored in another motion of the same clip
    /// (same frame count and target bodies), e.g. a `--gmr` run's: the default solve's motion
    /// against GMR's own targets rather than the planted ones it tracked.
    #[arg(long, value_name = "OTHER.npz")]
    pub targets_from: Option<PathBuf>,
}

pub fn run(args: ReportArgs) -> anyhow::Result<ExitCode> {
    let (model, robot_arg) = match &args.robot {
        Some(robot) => (shipped::robot_model(robot)?, robot.clone()),
        None => {
            let stored = stored_robot(&args.motion)?.with_context(|| {
                format!("{}: no robot name stored in the file; pass --robot", args.motion.display())
            })?;
            let model = shipped::robot_model(&stored).with_context(|| {
                format!("{}: stored robot \"{stored}\"; pass --robot", args.motion.display())
            })?;
            (model, stored)
        }
    };
    let (mut motion, source) = read_motion(&args.motion, &model, args.fps)?;
    if let Some(other) = &args.targets_from {
        motion.targets = Some(targets_of(other, &motion)?);
    }
    let config = match &args.config {
        Some(path) => Some(retarget::IkConfig::from_file(path)?),
        None => crate::cmd_retarget::shipped_config(&robot_arg).transpose()?,
    };
    let position_targets = config.as_ref().map(retarget::IkConfig::position_targets);
    let robot = if model.name.is_empty() { "(unnamed)" } else { model.name.as_str() };
    let mut opts = ReportOptions::default();
    opts.feet = args.feet.map(|f| [f[0].clone(), f[1].clone()]);
    opts.ground_height = args.ground;
    opts.contact_height = args.contact_height;
    opts.contact_speed = args.contact_speed;
    opts.slide_speed = args.slide_speed;
    opts.joint_velocity_limit = args.velocity_limit;
    opts.position_targets = position_targets;
    opts.root_target = config.map(|c| c.robot_root_name);
    let rep = report(&motion, &model, &opts)
        .with_context(|| format!("{}: robot {robot}", args.motion.display()))?;
    if let Some(path) = &args.json {
        let mut text = serde_json::to_string_pretty(&rep)?;
        text.push('\n');
        crate::atomic_write(path, text.as_bytes())?;
    }
    if let Some(path) = &args.dynamics_frames {
        let frames = retarget::report::dynamics_frames(&motion, &model, &opts)?;
        let mut text = String::from(
            "frame,contacts,residual_mg,residual_force_mg,residual_torque_mgl,cop_outside_m,force_x,force_y,force_z,torque_x,torque_y,torque_z\n",
        );
        for d in &frames {
            let cop = d.cop_outside.map_or_else(String::new, |c| format!("{c:.4}"));
            let [fx, fy, fz] = d.force;
            let [tx, ty, tz] = d.torque;
            text.push_str(&format!(
                "{},{},{:.6},{:.6},{:.6},{cop},{fx:.3},{fy:.3},{fz:.3},{tx:.3},{ty:.3},{tz:.3}\n",
                d.frame, d.contacts, d.residual, d.residual_force, d.residual_torque
            ));
        }
        crate::atomic_write(path, text.as_bytes())?;
    }
    let mut text = rep.to_string();
    text.push_str(&input_note(&source, &motion, args.targets_from.is_some()));
    if let Ok(roles) = retarget::RobotRoles::recognise(&model) {
        for blocked in retarget::blocked_limbs(&model, &roles, &motion) {
            text.push_str(&format!("cannot follow: {blocked}\n"));
        }
    }
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(ExitCode::SUCCESS),
    }
}

/// The robot name an .npz stores (`robot`); none for other files.
fn stored_robot(path: &std::path::Path) -> anyhow::Result<Option<String>> {
    let mut head = [0u8; 2];
    // A file that cannot be opened is said so (not "no robot name stored").
    let mut file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let is_zip = std::io::Read::read_exact(&mut file, &mut head).is_ok_and(|()| head == *b"PK");
    Ok(if is_zip { read_npz_robot(path)? } else { None })
}

/// What the report read, and what it could not measure for want of targets or contacts.
fn input_note(
    source: &retarget::writers::MotionSource,
    motion: &retarget::RobotMotion,
    targets_from: bool,
) -> String {
    let fps = match source.fps_from {
        FpsFrom::File => "fps from the file",
        FpsFrom::Caller => "fps from --fps",
    };
    let mut note = format!("\ninput: {} ({fps})\n", source.format.describe());
    let mut missing = Vec::new();
    if motion.targets.is_none() && !targets_from {
        missing.push(
            "tracking error: the file has no targets (--targets-from takes them from a motion \
             of the same clip)",
        );
    }
    if motion.contacts.is_none() {
        missing.push("skating and stance: the file has no source foot contacts");
    }
    for m in missing {
        note.push_str(&format!("not measured: {m}\n"));
    }
    note
}

/// The targets stored in `other`, checked to be of the same clip as `motion`: same frame
/// count, and targets there.
fn targets_of(
    other: &std::path::Path,
    motion: &retarget::RobotMotion,
) -> anyhow::Result<retarget::TrackedTargets> {
    let theirs = read_motion_npz(other)?;
    let frames = motion.num_frames();
    anyhow::ensure!(
        theirs.num_frames() == frames,
        "{}: {} frames, the motion has {frames}: --targets-from needs a motion of the same clip",
        other.display(),
        theirs.num_frames()
    );
    theirs.targets.with_context(|| {
        format!("{}: no targets stored (target_pos / target_quat)", other.display())
    })
}
