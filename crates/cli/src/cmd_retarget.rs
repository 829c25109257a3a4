//! The main job: `retarget --bvh FILE --robot NAME [-o OUT] [--config C] [--human-height H]`,
//! `retarget --fbx FILE [--take NAME|N] --robot NAME ...` (`cmd_fbx`), or
//! `retarget --c3d FILE --config MARKER_CONFIG --robot NAME ...` (marker-driven).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::Args;
use retarget::writers::{write_motion, Format};
use retarget::{ClipDiagnostics, IkConfig, RetargetOptions, Retargeter, RobotMotion, SolveMode};

#[derive(Args, Debug)]
pub struct MainArgs {
    /// BVH motion capture file to retarget (this, --fbx, --c3d or --smplx is required).
    #[arg(long, value_name = "FILE", required_unless_present_any = ["c3d", "fbx", "smplx"])]
    pub bvh: Option<PathBuf>,
    /// FBX file to retarget (Mixamo, MotionBuilder, Maya, 3ds Max, Blender exports): one take,
    /// see --take.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["bvh", "c3d"])]
    pub fbx: Option<PathBuf>,
    /// The FBX take: its name or its index in `retarget fbx info` (default: the take with the
    /// most motion; the output says which).
    #[arg(long, value_name = "NAME|N", requires = "fbx")]
    pub take: Option<String>,
    /// C3D marker file to retarget (instead of --bvh); needs a marker config (--config)
    /// with `marker_bodies`, e.g. configs/c3d_plugingait_to_unitree_g1.json.
    #[arg(long, value_name = "FILE", conflicts_with = "bvh", requires = "config")]
    pub c3d: Option<PathBuf>,
    /// AMASS motion file to retarget: SMPL-X stage-ii (`*_stageii.npz`) or SMPL+H
    /// (`*_poses.npz`), told apart by content; needs the body model (--body-model or
    /// $RETARGET_BODY_MODELS). Default output: `<stem>_<robot>.npz` beside it.
    #[arg(long, visible_alias = "smplh", value_name = "FILE", conflicts_with_all = ["bvh", "c3d", "fbx"])]
    pub smplx: Option<PathBuf>,
    #[command(flatten)]
    pub smpl: crate::cmd_smpl::ModelArgs,
    /// Robot (required): a shipped name (see `retarget robots`) or a path to an MJCF (.xml)
    /// or URDF (.urdf) file.
    #[arg(long, required = true)]
    pub robot: Option<String>,
    /// Output file; format from the extension (.npz, .csv, .pkl, .json). Default:
    /// `<input stem>.npz` next to the input.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// IK config (GMR schema), used as given; a role-named config (`retarget robot init`) is
    /// bound to the skeleton. Default: GMR's tuned config for a shipped robot and a
    /// LAFAN1 skeleton (its names and joint frames), else a config derived from the robot's and
    /// the skeleton's roles.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Subject height in metres (default: estimated from the skeleton; GMR assumes 1.75).
    #[arg(long, value_name = "METRES")]
    pub human_height: Option<f64>,
    /// Split a clip longer than this many frames into chunks solved in parallel (each warm-
    /// started from a lead-in; on the LAFAN1 walk the result equals the serial solve to
    /// 3.7e-10 rad with --gmr; with the default solve each chunk is a trajectory problem
    /// of its own, within 0.05 rad of the serial solve, median frame 3e-4 rad).
    #[arg(long, value_name = "FRAMES")]
    pub chunk_frames: Option<usize>,
    /// Frames solved before each chunk and thrown away, so that its seam is smooth.
    #[arg(long, value_name = "FRAMES", default_value_t = 60, requires = "chunk_frames")]
    pub lead_in: usize,
    /// Output frame rate: the solved motion is resampled (linear for positions and angles,
    /// slerp for the root and ball joints). Default: the source's rate.
    #[arg(long, value_name = "HZ")]
    pub fps: Option<f64>,
    /// Output format, overriding the extension.
    #[arg(long, value_name = "FORMAT", value_parser = FORMATS)]
    pub format: Option<String>,
    /// Reproduce GMR exactly (its solver and targets: no planted feet, no ground,
    /// self-collision or joint-speed constraints). Default: the physically plausible solve.
    #[arg(long)]
    pub gmr: bool,
    /// Also solve the clip backwards and take the better direction wherever the two agree:
    /// for a limb that goes over into another branch of its joints and stays there (the
    /// PM01's right hip after the Bandai kick). The two directions run at once on two cores
    /// (about the same wall time for one clip); on one core, 1.4-1.9 times the time.
    #[arg(long, conflicts_with = "gmr")]
    pub both_ways: bool,
}

/// The output formats `--format` accepts (main command and batch).
pub const FORMATS: [&str; 4] = ["npz", "csv", "pkl", "json"];

/// The solve `--gmr` and `--both-ways` ask for (main command and batch).
pub fn solve_mode(gmr: bool, both_ways: bool) -> SolveMode {
    if gmr {
        SolveMode::Gmr
    } else {
        let mut plausible = retarget::PlausibleOptions::default();
        plausible.both_ways = both_ways;
        SolveMode::Plausible(plausible)
    }
}

/// The tuned IK config of shipped robot `key` (its `bvh_lafan1` row of `retarget::shipped::CONFIGS`).
pub fn shipped_config(key: &str) -> Option<anyhow::Result<IkConfig>> {
    retarget::shipped::tuned_config(key).map(|r| r.map_err(anyhow::Error::from))
}

pub fn run_main(args: MainArgs) -> anyhow::Result<ExitCode> {
    let input = args
        .bvh
        .clone()
        .or_else(|| args.fbx.clone())
        .or_else(|| args.c3d.clone())
        .or_else(|| args.smplx.clone());
    let (Some(input), Some(robot)) = (input, args.robot.clone()) else {
        eprintln!(
            "usage: retarget --bvh FILE | --fbx FILE | --c3d FILE --config C | --smplx FILE --robot NAME [-o OUT]   (see `retarget --help`)"
        );
        return Ok(ExitCode::from(2));
    };
    let format = parse_format(args.format.as_deref())?;
    let mut output = output_path(&input, args.output.as_deref(), format);
    if args.smplx.is_some() && args.output.is_none() {
        let ext = format.map_or("npz", Format::extension);
        output = crate::cmd_smpl::default_output(&input, &robot_label(&robot), ext);
    }
    let started = Instant::now();
    let mode = solve_mode(args.gmr, args.both_ways);
    let chunk =
        args.chunk_frames.map(|frames| retarget::ChunkOptions { frames, lead_in: args.lead_in });
    let options = {
        let mut o = RetargetOptions::default();
        o.human_height = args.human_height;
        o.mode = mode;
        o.chunk = chunk;
        o
    };
    let mut retargeter = Retargeter::new(&robot)?.with_options(options);
    for note in retargeter.robot_notes() {
        println!("robot: {note}");
    }
    let (motion, diag) = if args.smplx.is_some() {
        if let Some(path) = &args.config {
            retargeter = retargeter.with_config(IkConfig::from_file(path)?);
        }
        let models = args.smpl.models();
        crate::cmd_smpl::retarget_file(&retargeter, &input, &models, args.smpl.gender)?
    } else if args.c3d.is_some() {
        // Its errors name the file once (the C3D reader's, the marker bodies', the solve's).
        let config_path = args.config.as_deref().context("--c3d needs --config")?;
        retargeter.retarget_c3d_file(&input, config_path)?
    } else {
        if let Some(path) = &args.config {
            retargeter = retargeter.with_config(IkConfig::from_file(path)?);
        }
        if args.fbx.is_some() {
            crate::cmd_fbx::retarget(&retargeter, &input, args.take.as_deref(), &robot)?
        } else {
            let bvh =
                crate::files::read_bvh(&input).with_context(|| format!("{}", input.display()))?;
            let chosen = retargeter
                .choose_config(&bvh)
                .with_context(|| format!("{}: choosing the IK config", input.display()))?;
            retargeter
                .retarget_bvh_with(&bvh, &chosen)
                .with_context(|| format!("{}: retargeting onto {robot}", input.display()))?
        }
    };
    let model = retargeter.model();
    match args.fps {
        Some(fps) => {
            let resampled = retarget::resample(&motion, model, fps)?;
            write_motion(&output, &resampled, model, format)?;
            println!(
                "resampled {} frames at {} fps to {} frames at {fps} fps",
                motion.num_frames(),
                motion.fps,
                resampled.num_frames()
            );
        }
        None => write_motion(&output, &motion, model, format)?,
    }
    let wall = started.elapsed().as_secs_f64();
    print_summary(&input, &output, &motion, &diag, wall, args.both_ways);
    print_blocked(model, &motion);
    Ok(ExitCode::SUCCESS)
}

/// Stretches of `cannot follow` the main command prints.
const SHOWN_BLOCKED: usize = 5;

/// The stretches in which a limb cannot follow the human ([`retarget::blocked_limbs`]), one line
/// each, the longest first (nothing for a robot the recogniser does not read).
pub fn print_blocked(model: &mjcf::Model, motion: &RobotMotion) {
    let Ok(roles) = retarget::RobotRoles::recognise(model) else { return };
    let mut blocked = retarget::blocked_limbs(model, &roles, motion);
    // The longest first, five at most (`retarget report` lists them all).
    blocked.sort_by_key(|b| std::cmp::Reverse(b.last - b.first));
    for b in blocked.iter().take(SHOWN_BLOCKED) {
        println!("cannot follow: {b}");
    }
    if blocked.len() > SHOWN_BLOCKED {
        println!(
            "cannot follow: {} shorter stretches more (`retarget report` lists them)",
            blocked.len() - SHOWN_BLOCKED
        );
    }
}

/// A robot argument as messages name it: the shipped key, or the model file's stem.
pub fn robot_label(robot: &str) -> String {
    retarget::shipped::robot_label(robot)
}

/// `--format NAME` (npz, csv, pkl, json).
pub fn parse_format(text: Option<&str>) -> anyhow::Result<Option<Format>> {
    let Some(text) = text else { return Ok(None) };
    match Format::from_path(Path::new(&format!("x.{text}"))) {
        Some(f) => Ok(Some(f)),
        None => bail!("--format {text}: expected npz, csv, pkl or json"),
    }
}

/// `-o` as given (with the format's extension when it has none), else `<stem>.<ext>` beside
/// the input.
fn output_path(input: &Path, output: Option<&Path>, format: Option<Format>) -> PathBuf {
    let ext = format.map_or("npz", Format::extension);
    match output {
        Some(path) if path.extension().is_none() && format.is_some() => path.with_extension(ext),
        Some(path) => path.to_path_buf(),
        None => input.with_extension(ext),
    }
}

fn print_summary(
    input: &Path,
    output: &Path,
    motion: &RobotMotion,
    diag: &ClipDiagnostics,
    wall: f64,
    both_ways: bool,
) {
    let frames = motion.num_frames();
    println!(
        "{}: {frames} frames at {:.3} fps, subject height {:.3} m ({})",
        input.display(),
        motion.fps,
        diag.human_height,
        diag.human_height_source
    );
    if !diag.human_inferred.is_empty() {
        println!("inferred: {}", diag.human_inferred);
    }
    for stage in &diag.stages {
        println!("default solve: {}", stage.summary);
    }
    if both_ways {
        let (backward, stretches) = diag.from_backward();
        let plural = if stretches == 1 { "" } else { "es" };
        println!(
            "both ways: {backward} of {frames} frames from the backward pass, in {stretches} \
             stretch{plural}"
        );
    }
    println!(
        "solved in {wall:.3} s wall ({:.0} frames/s overall, IK {:.0} frames/s)",
        frames as f64 / wall.max(1e-9),
        frames as f64 / diag.solve_seconds.max(1e-9)
    );
    println!(
        "{:<28} {:>10} {:>10} {:>10} {:>10}",
        "body", "pos mean", "pos p95", "rot mean", "rot p95"
    );
    // Mean and 95th percentile per body, by the report's rule (numpy's linear percentile).
    let stats = |pick: fn(&retarget::FrameDiagnostics, usize) -> Option<f64>| -> Vec<(f64, f64)> {
        (0..diag.body_names.len())
            .map(|k| {
                let v: Vec<f64> = diag.frames.iter().filter_map(|f| pick(f, k)).collect();
                let mean = if v.is_empty() { 0.0 } else { v.iter().sum::<f64>() / v.len() as f64 };
                (mean, retarget::report::percentile(&v, 0.95))
            })
            .collect()
    };
    let pos = stats(|f, k| f.pos_error.get(k).copied());
    let rot = stats(|f, k| f.rot_error.get(k).copied());
    // Errors of an untracked quantity (weight 0 in every stage) are printed as "-".
    let cell =
        |on: bool, v: f64, unit: &str| if on { format!("{v:.1}{unit}") } else { "-".to_owned() };
    for (k, name) in diag.body_names.iter().enumerate() {
        let (p_on, r_on) = (diag.position_tracked[k], diag.rotation_tracked[k]);
        println!(
            "{name:<28} {:>10} {:>10} {:>10} {:>10}",
            cell(p_on, pos[k].0 * 1e3, "mm"),
            cell(p_on, pos[k].1 * 1e3, "mm"),
            cell(r_on, rot[k].0.to_degrees(), "°"),
            cell(r_on, rot[k].1.to_degrees(), "°")
        );
    }
    let (limit_frames, joint_frames) = diag.limit_hits();
    println!(
        "joint limits: {limit_frames} frames with a joint at a limit ({joint_frames} joint-frames)"
    );
    println!("wrote {}", output.display());
}
