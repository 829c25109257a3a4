//! The main job: `retarget --bvh FILE --robot NAME [-o OUT] [--config C] [--human-height H]`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::Args;
use retarget::writers::{write_motion, Format};
use retarget::{ClipDiagnostics, IkConfig, RetargetOptions, RobotMotion};

use crate::shipped;

#[derive(Args, Debug)]
pub struct MainArgs {
    /// BVH motion capture file to retarget.
    #[arg(long)]
    pub bvh: Option<PathBuf>,
    /// Robot: a shipped name (see `retarget robots`) or a path to an MJCF file.
    #[arg(long)]
    pub robot: Option<String>,
    /// Output file; format from the extension (.npz, .csv, .pkl, .json). Default:
    /// `<input stem>.npz` next to the input.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// IK config (GMR schema). Default: the shipped LAFAN1 config of a shipped robot;
    /// required with an MJCF path as --robot.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Subject height in metres (default: estimated from the skeleton; GMR assumes 1.75).
    #[arg(long, value_name = "METRES")]
    pub human_height: Option<f64>,
    /// Output frame rate (resampling; not supported yet).
    #[arg(long, value_name = "HZ")]
    pub fps: Option<f64>,
    /// Output format, overriding the extension: npz, csv, pkl or json.
    #[arg(long, value_name = "FORMAT")]
    pub format: Option<String>,
}

/// The default IK config of each shipped robot (`configs/bvh_lafan1_to_<key>.json`).
pub const SHIPPED_CONFIGS: &[(&str, &str)] = &[
    ("booster_t1_29dof", include_str!("../../../configs/bvh_lafan1_to_booster_t1_29dof.json")),
    ("engineai_pm01", include_str!("../../../configs/bvh_lafan1_to_engineai_pm01.json")),
    ("fourier_n1", include_str!("../../../configs/bvh_lafan1_to_fourier_n1.json")),
    ("stanford_toddy", include_str!("../../../configs/bvh_lafan1_to_stanford_toddy.json")),
    ("unitree_g1", include_str!("../../../configs/bvh_lafan1_to_unitree_g1.json")),
    ("unitree_h1", include_str!("../../../configs/bvh_lafan1_to_unitree_h1.json")),
];

/// The shipped default config of robot `key`.
pub fn shipped_config(key: &str) -> Option<anyhow::Result<IkConfig>> {
    let (_, text) = SHIPPED_CONFIGS.iter().find(|(k, _)| *k == key)?;
    let name = format!("configs/bvh_lafan1_to_{key}.json");
    Some(IkConfig::from_json_str(text, &name).map_err(anyhow::Error::from))
}

pub fn run_main(args: MainArgs) -> anyhow::Result<ExitCode> {
    let (Some(bvh_path), Some(robot)) = (args.bvh.clone(), args.robot.clone()) else {
        eprintln!("usage: retarget --bvh FILE --robot NAME [-o OUT]   (see `retarget --help`)");
        return Ok(ExitCode::from(2));
    };
    if args.fps.is_some() {
        bail!("--fps: resampling is not supported yet; the output keeps the source frame rate");
    }
    let format = parse_format(args.format.as_deref())?;
    let output = output_path(&bvh_path, args.output.as_deref(), format);
    let config = match (&args.config, shipped_config(&robot)) {
        (Some(path), _) => IkConfig::from_file(path)?,
        (None, Some(config)) => config?,
        (None, None) => {
            bail!("--robot {robot} is not a shipped robot: give its IK config with --config")
        }
    };
    let model = shipped::robot_model(&robot)?;
    let started = Instant::now();
    let bvh = bvh::from_path(&bvh_path).with_context(|| format!("{}", bvh_path.display()))?;
    let options = RetargetOptions { human_height: args.human_height, ..RetargetOptions::default() };
    let (motion, diag) = retarget::retarget_bvh(&bvh, &model, &config, &options)
        .with_context(|| format!("{}: retargeting onto {robot}", bvh_path.display()))?;
    write_motion(&output, &motion, &model, format)?;
    let wall = started.elapsed().as_secs_f64();
    print_summary(&bvh_path, &output, &motion, &diag, wall);
    Ok(ExitCode::SUCCESS)
}

fn parse_format(text: Option<&str>) -> anyhow::Result<Option<Format>> {
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
) {
    let frames = motion.num_frames();
    println!(
        "{}: {frames} frames at {:.3} fps, subject height {:.3} m ({})",
        input.display(),
        motion.fps,
        diag.human_height,
        diag.human_height_source
    );
    println!(
        "solved in {wall:.3} s wall ({:.0} frames/s overall, IK {:.0} frames/s)",
        frames as f64 / wall.max(1e-9),
        frames as f64 / diag.solve_seconds.max(1e-9)
    );
    println!(
        "{:<28} {:>10} {:>10} {:>10} {:>10}",
        "body", "pos mean", "pos p95", "rot mean", "rot p95"
    );
    let pos = diag.position_error_stats();
    let rot = diag.rotation_error_stats();
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
