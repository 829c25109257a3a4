//! The main job: `retarget --bvh FILE --robot NAME [-o OUT] [--config C] [--human-height H]`,
//! or `retarget --c3d FILE --config MARKER_CONFIG --robot NAME ...` (marker-driven).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::Args;
use retarget::writers::{write_motion, Format};
use retarget::{ClipDiagnostics, IkConfig, RetargetOptions, RobotMotion, SolveMode};

use crate::shipped;
use fk::markers::MarkerBody;

#[derive(Args, Debug)]
pub struct MainArgs {
    /// BVH motion capture file to retarget (this or --c3d is required).
    #[arg(long, value_name = "FILE", required_unless_present = "c3d")]
    pub bvh: Option<PathBuf>,
    /// C3D marker file to retarget (instead of --bvh); needs a marker config (--config)
    /// with `marker_bodies`, e.g. configs/c3d_plugingait_to_unitree_g1.json.
    #[arg(long, value_name = "FILE", conflicts_with = "bvh", requires = "config")]
    pub c3d: Option<PathBuf>,
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
    /// LAFAN1-named skeleton, else a config derived from the robot's and the skeleton's roles.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Subject height in metres (default: estimated from the skeleton; GMR assumes 1.75).
    #[arg(long, value_name = "METRES")]
    pub human_height: Option<f64>,
    /// Split a clip longer than this many frames into chunks solved in parallel (each warm-
    /// started from a lead-in; on the LAFAN1 walk the result equals the serial solve to
    /// 3.7e-10 rad with --gmr, 1.1e-4 rad with the default solve).
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
}

/// The output formats `--format` accepts (main command and batch).
pub const FORMATS: [&str; 4] = ["npz", "csv", "pkl", "json"];

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
    let input = args.bvh.clone().or_else(|| args.c3d.clone());
    let (Some(input), Some(robot)) = (input, args.robot.clone()) else {
        eprintln!(
            "usage: retarget --bvh FILE | --c3d FILE --config C --robot NAME [-o OUT]   (see `retarget --help`)"
        );
        return Ok(ExitCode::from(2));
    };
    let format = parse_format(args.format.as_deref())?;
    let output = output_path(&input, args.output.as_deref(), format);
    let model = shipped::robot_model(&robot)?;
    let started = Instant::now();
    let mode = if args.gmr { SolveMode::Gmr } else { SolveMode::default() };
    let chunk = args
        .chunk_frames
        .map(|frames| retarget::chunked::ChunkOptions { frames, lead_in: args.lead_in });
    let options = RetargetOptions {
        human_height: args.human_height,
        mode,
        chunk,
        ..RetargetOptions::default()
    };
    let (motion, diag) = if args.c3d.is_some() {
        let config = resolve_config(&robot, args.config.as_deref())?;
        let config_path = args.config.as_deref().context("--c3d needs --config")?;
        let markers = MarkerConfig::from_file(config_path)?;
        let (human, height, source) = c3d_human_motion(&input, &markers, args.human_height)?;
        let opts = RetargetOptions { human_height: Some(height), ..options };
        let (motion, mut diag) = retarget_human(&human, &model, &config, &opts)
            .with_context(|| format!("{}: retargeting onto {robot}", input.display()))?;
        diag.human_height_source = source;
        (motion, diag)
    } else {
        let bvh =
            crate::cmd_bvh::read_bvh(&input).with_context(|| format!("{}", input.display()))?;
        let chosen =
            choose_config(&robot, &model, args.config.as_deref(), args.gmr, &bvh, &options.fk)
                .with_context(|| format!("{}: choosing the IK config", input.display()))?;
        let (motion, mut diag) = retarget::retarget_bvh(&bvh, &model, &chosen.config, &options)
            .with_context(|| format!("{}: retargeting onto {robot}", input.display()))?;
        diag.human_inferred = with_config(&diag.human_inferred, &chosen.summary);
        (motion, diag)
    };
    match args.fps {
        Some(fps) => {
            let resampled = retarget::resample::resample(&motion, &model, fps)?;
            write_motion(&output, &resampled, &model, format)?;
            println!(
                "resampled {} frames at {} fps to {} frames at {fps} fps",
                motion.num_frames(),
                motion.fps,
                resampled.num_frames()
            );
        }
        None => write_motion(&output, &motion, &model, format)?,
    }
    let wall = started.elapsed().as_secs_f64();
    print_summary(&input, &output, &motion, &diag, wall);
    Ok(ExitCode::SUCCESS)
}

/// [`retarget::retarget_motion`], or its chunked form when `options.chunk` is set (as
/// [`retarget::retarget_bvh`] does for BVH input).
pub(crate) fn retarget_human(
    human: &fk::HumanMotion,
    model: &mjcf::Model,
    config: &IkConfig,
    options: &RetargetOptions,
) -> Result<(RobotMotion, ClipDiagnostics), retarget::Error> {
    match options.chunk {
        Some(chunk) => {
            retarget::chunked::retarget_motion_chunked(human, model, config, options, chunk)
        }
        None => retarget::retarget_motion(human, model, config, options),
    }
}

/// The marker part of a marker-driven IK config (keys the IK config itself ignores).
pub(crate) struct MarkerConfig {
    bodies: Vec<MarkerBody>,
    /// `source_axes`, checked.
    axes: String,
    metres_per_unit: f64,
    /// Landmarks for the subject height: top markers, bottom markers, and the fraction of
    /// the stature the top markers stand at.
    height: Option<(Vec<String>, Vec<String>, f64)>,
    /// `subject_height_m`, when the config fixes it.
    subject_height: Option<f64>,
}

impl MarkerConfig {
    pub(crate) fn from_file(path: &Path) -> anyhow::Result<MarkerConfig> {
        let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
        let json: serde_json::Value =
            serde_json::from_str(&text).with_context(|| format!("{}", path.display()))?;
        let at = |key: &str| format!("{}: `{key}`", path.display());
        let strings = |v: &serde_json::Value, key: &str| -> anyhow::Result<Vec<String>> {
            v.as_array()
                .with_context(|| format!("{}: expected a list of marker labels", at(key)))?
                .iter()
                .map(|m| m.as_str().map(str::to_owned).with_context(|| at(key)))
                .collect()
        };
        let table = json.get("marker_bodies").and_then(serde_json::Value::as_object).with_context(
            || format!("{}: a marker config needs `marker_bodies`", path.display()),
        )?;
        let mut bodies = Vec::new();
        for (name, def) in table {
            let markers =
                strings(def.get("markers").with_context(|| at(&format!("{name}.markers")))?, name)?;
            let frame = match def.get("frame") {
                None | Some(serde_json::Value::Null) => None,
                Some(v) => {
                    let f = strings(v, &format!("{name}.frame"))?;
                    let [a, b, c]: [String; 3] = f.try_into().map_err(|_| {
                        anyhow::anyhow!(
                            "{}: needs exactly three markers",
                            at(&format!("{name}.frame"))
                        )
                    })?;
                    Some([a, b, c])
                }
            };
            bodies.push(MarkerBody { name: name.clone(), markers, frame });
        }
        let axes_name =
            json.get("source_axes").and_then(serde_json::Value::as_str).unwrap_or("z-up");
        if fk::markers::axes_rotation(axes_name).is_none() {
            bail!("{}: `{axes_name}`: expected \"z-up\" or \"y-up\"", at("source_axes"));
        }
        let axes = axes_name.to_owned();
        let metres_per_unit =
            json.get("marker_units_m").and_then(serde_json::Value::as_f64).unwrap_or(0.001);
        let height = match json.get("marker_height") {
            None => None,
            Some(h) => Some((
                strings(
                    h.get("top").with_context(|| at("marker_height.top"))?,
                    "marker_height.top",
                )?,
                strings(
                    h.get("bottom").with_context(|| at("marker_height.bottom"))?,
                    "marker_height.bottom",
                )?,
                h.get("fraction_of_stature")
                    .and_then(serde_json::Value::as_f64)
                    .with_context(|| at("marker_height.fraction_of_stature"))?,
            )),
        };
        let subject_height = json.get("subject_height_m").and_then(serde_json::Value::as_f64);
        Ok(MarkerConfig { bodies, axes, metres_per_unit, height, subject_height })
    }
}

/// Reads a C3D file and builds the virtual marker bodies; returns them with the subject
/// height and where it came from.
pub(crate) fn c3d_human_motion(
    path: &Path,
    markers: &MarkerConfig,
    human_height: Option<f64>,
) -> anyhow::Result<(fk::HumanMotion, f64, String)> {
    let file = c3d::C3d::from_path(path).with_context(|| format!("{}", path.display()))?;
    let labels: Vec<String> = file.point_labels().iter().map(|l| l.trim().to_owned()).collect();
    let frames: Vec<Vec<Option<[f64; 3]>>> = (0..file.points.frame_count())
        .map(|f| {
            (0..labels.len())
                .map(|p| file.points.get(f, p).map(|pt| pt.position.map(f64::from)))
                .collect()
        })
        .collect();
    let fps = f64::from(file.point_rate());
    let axes = fk::markers::axes_rotation(&markers.axes).context("source_axes")?;
    let human = fk::markers::marker_motion(
        &labels,
        &frames,
        fps,
        markers.metres_per_unit,
        &axes,
        &markers.bodies,
    )
    .with_context(|| format!("{}: marker bodies", path.display()))?;
    let (height, source) = if let Some(h) = human_height {
        (h, "given".to_owned())
    } else if let Some(h) = markers.subject_height {
        (h, "config subject_height_m".to_owned())
    } else if let Some((top, bottom, fraction)) = &markers.height {
        let above = fk::markers::marker_height(
            &labels,
            &frames,
            markers.metres_per_unit,
            &axes,
            top,
            bottom,
        )
        .with_context(|| format!("{}: subject height", path.display()))?
        .with_context(|| format!("{}: height markers never seen", path.display()))?;
        (above / fraction, format!("markers {} at {fraction} of stature", top.join("+")))
    } else {
        bail!("{}: give --human-height (the config has no `marker_height`)", path.display())
    };
    if !(height.is_finite() && height > 0.0) {
        bail!("{}: subject height {height} m is not positive", path.display());
    }
    Ok((human, height, source))
}

/// The IK config for retargeting `bvh` onto `model` ([`retarget::derive::choose`]): the
/// `--config` file (bound to the skeleton when role-named), GMR's tuned config of a shipped
/// robot (always with `--gmr`; else when the skeleton has its names and joint frames), or the
/// config derived from the robot's and the skeleton's roles.
pub fn choose_config(
    robot: &str,
    model: &mjcf::Model,
    config: Option<&Path>,
    gmr: bool,
    bvh: &bvh::Bvh,
    fk: &fk::FkOptions,
) -> anyhow::Result<retarget::derive::Chosen> {
    let given = config.map(IkConfig::from_file).transpose()?;
    let tuned = shipped_config(robot).transpose()?;
    let name = robot_label(robot);
    Ok(retarget::derive::choose(model, &name, bvh, fk, given, tuned.as_ref(), gmr)?)
}

/// A robot argument as messages name it: the shipped key, or the model file's stem.
pub fn robot_label(robot: &str) -> String {
    match Path::new(robot).file_stem() {
        Some(stem) if robot.contains('.') || robot.contains(std::path::MAIN_SEPARATOR) => {
            stem.to_string_lossy().into_owned()
        }
        _ => robot.to_owned(),
    }
}

/// The one-line summary of what was inferred, with the config that was used.
pub fn with_config(inferred: &str, config: &str) -> String {
    if inferred.is_empty() {
        config.to_owned()
    } else {
        format!("{inferred}; {config}")
    }
}

/// The IK config at `path`, else the shipped default of robot `robot`.
pub fn resolve_config(robot: &str, path: Option<&Path>) -> anyhow::Result<IkConfig> {
    match (path, shipped_config(robot)) {
        (Some(path), _) => Ok(IkConfig::from_file(path)?),
        (None, Some(config)) => config,
        (None, None) if !crate::shipped::looks_like_path(robot) => {
            Err(crate::shipped::unknown_robot(robot))
        }
        (None, None) => {
            bail!("--robot {robot} is a model file, not a shipped robot: give its IK config with --config")
        }
    }
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
