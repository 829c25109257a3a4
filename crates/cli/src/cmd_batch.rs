//! `retarget batch IN_DIR --robot R -o OUT_DIR`: a whole tree of clips, in parallel, resumable.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::Args;

use retarget::writers::{write_motion, Format};
use retarget::{IkConfig, MarkerConfig, RetargetOptions, Retargeter};

use crate::batch::{self, ClipResult, Plan, Shard, Summary};

#[derive(Args, Debug)]
pub struct BatchArgs {
    /// Directory tree of BVH, FBX (each file's take with the most motion), C3D and AMASS
    /// (`*_stageii.npz`, `*_poses.npz`; `shape.npz` and other `.npz` files are skipped)
    /// files; relative paths are mirrored into the output directory. Required unless
    /// --merge-summaries.
    #[arg(value_name = "IN_DIR", required_unless_present = "merge_summaries")]
    pub input: Option<PathBuf>,
    /// Robot (required unless --merge-summaries): a shipped name (see `retarget robots`) or a
    /// path to an MJCF (.xml) or URDF (.urdf) file (with --config).
    #[arg(long, required_unless_present = "merge_summaries")]
    pub robot: Option<String>,
    /// Output directory (required; created if missing); with --merge-summaries, the merged
    /// JSON file.
    #[arg(short, long, required = true)]
    pub output: Option<PathBuf>,
    /// IK config (GMR schema) for every clip (bound to each skeleton when role-named);
    /// default: per clip, GMR's tuned config or one derived from the roles (as without
    /// --config in the main command). C3D clips need a marker config (with `marker_bodies`,
    /// e.g. configs/c3d_plugingait_to_unitree_g1.json).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Output format of every clip.
    #[arg(long, value_name = "FORMAT", default_value = "npz", value_parser = crate::cmd_retarget::FORMATS)]
    pub format: String,
    /// Clips converted at once (default: the number of cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Convert clips whose output already exists (default: skip them, which makes a killed
    /// run resumable).
    #[arg(long)]
    pub overwrite: bool,
    /// Process only shard K of N (0 <= K < N): the files whose index in the sorted file list
    /// is K modulo N. For Slurm arrays: `--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Subject height in metres for every clip (default: estimated per clip from its skeleton).
    #[arg(long, value_name = "METRES")]
    pub human_height: Option<f64>,
    /// Output frame rate: each solved motion is resampled (linear for positions and angles,
    /// slerp for the root and ball joints). Default: the source's rate.
    #[arg(long, value_name = "HZ")]
    pub fps: Option<f64>,
    /// Reproduce GMR exactly (its solver and targets: no planted feet, no ground,
    /// self-collision or joint-speed constraints). Default: the physically plausible solve.
    #[arg(long)]
    pub gmr: bool,
    /// Also solve each clip backwards and take the better direction wherever the two agree
    /// (as the main command's --both-ways).
    #[arg(long, conflicts_with = "gmr")]
    pub both_ways: bool,
    /// Split clips longer than this many frames into chunks solved in parallel (each warm-
    /// started from a lead-in; on the LAFAN1 walk the result equals the serial solve to
    /// 3.7e-10 rad with --gmr; with the default solve each chunk is a trajectory problem
    /// of its own, within 0.05 rad of the serial solve, median frame 3e-4 rad).
    #[arg(long, value_name = "FRAMES")]
    pub chunk_frames: Option<usize>,
    /// Frames solved before each chunk and thrown away, so that its seam is smooth.
    #[arg(long, value_name = "FRAMES", default_value_t = 60, requires = "chunk_frames")]
    pub lead_in: usize,
    #[command(flatten)]
    pub smpl: crate::cmd_smpl::ModelArgs,
    /// Exit with code 3 when a converted clip's verdict is flagged (a measure past its cap:
    /// `retarget report`'s verdict, docs/metrics.md); failures still exit with 1.
    #[arg(long)]
    pub fail_on_flag: bool,
    /// Merge shard summaries (summary-shard-K-of-N.json files) into one JSON file (-o).
    #[arg(long, num_args = 1.., value_name = "SUMMARY", conflicts_with_all = ["input", "robot", "config", "shard"])]
    pub merge_summaries: Vec<PathBuf>,
}

pub fn run(args: BatchArgs) -> anyhow::Result<ExitCode> {
    let output = args.output.clone().context("--output is required")?;
    if !args.merge_summaries.is_empty() {
        return merge(&args.merge_summaries, &output);
    }
    let (Some(input), Some(robot)) = (args.input.clone(), args.robot.clone()) else {
        bail!("batch needs IN_DIR and --robot");
    };
    if !input.is_dir() {
        bail!("{}: not a directory", input.display());
    }
    if let Some(fps) = args.fps.filter(|f| !(f.is_finite() && *f > 0.0)) {
        bail!("--fps {fps}: expected a positive rate");
    }
    let mut options = RetargetOptions::default();
    options.human_height = args.human_height;
    options.chunk =
        args.chunk_frames.map(|frames| retarget::ChunkOptions { frames, lead_in: args.lead_in });
    options.mode = crate::cmd_retarget::solve_mode(args.gmr, args.both_ways);
    let mut job = Job::load(&robot, args.config.as_deref(), options, &args.format)?;
    job.fps = args.fps;
    job.body_models = args.smpl.models();
    job.gender = args.smpl.gender;
    let files: Vec<PathBuf> = batch::walk(&input, &["bvh", "fbx", "c3d", "npz"])?
        .into_iter()
        .filter(|f| !is_npz(f) || smpl::conventions::is_motion_file_name(f))
        .collect();
    let files = batch::select_shard(files, args.shard);
    let jobs =
        args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    eprintln!(
        "batch: {} clips{} from {} onto {robot}, {jobs} at a time",
        files.len(),
        args.shard.map(|s| format!(" (shard {s})")).unwrap_or_default(),
        input.display()
    );
    let plan = Plan {
        input_dir: &input,
        output_dir: &output,
        files,
        extension: &args.format,
        overwrite: args.overwrite,
        jobs,
        robot: &robot,
        shard: args.shard,
    };
    let summary = batch::run(&plan, |src: &Path, dst: &Path| job.convert_file(src, dst))?;
    print_table(&summary);
    eprintln!("batch: summary in {}", output.join(Summary::file_name(args.shard)).display());
    Ok(exit_code(&summary, args.fail_on_flag))
}

fn merge(parts: &[PathBuf], output: &Path) -> anyhow::Result<ExitCode> {
    let summaries = parts
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("{}: cannot read", p.display()))?;
            serde_json::from_str::<Summary>(&text)
                .with_context(|| format!("{}: not a batch summary", p.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let merged = Summary::merge(&summaries)?;
    crate::atomic_write(output, (serde_json::to_string_pretty(&merged)? + "\n").as_bytes())?;
    print_table(&merged);
    Ok(exit_code(&merged, false))
}

/// 1 when a clip failed, else 3 when `fail_on_flag` and a clip was flagged, else 0.
fn exit_code(summary: &Summary, fail_on_flag: bool) -> ExitCode {
    if summary.totals.failed > 0 {
        ExitCode::from(1)
    } else if fail_on_flag && summary.totals.flagged > 0 {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    }
}

fn print_table(summary: &Summary) {
    let t = &summary.totals;
    let rate = t.frames as f64 / t.seconds.max(1e-9);
    println!(
        "clips {}  converted {}  skipped {}  failed {}  frames {}  wall {:.1} s  {rate:.0} frames/s",
        t.clips, t.converted, t.skipped, t.failed, t.frames, t.seconds
    );
    for clip in summary.clips.iter().filter(|c| c.status == "failed") {
        println!("  failed  {}: {}", clip.input, clip.error.as_deref().unwrap_or("?"));
    }
    let measured = summary.clips.iter().filter(|c| c.verdict.is_some()).count();
    if measured > 0 {
        let by: Vec<String> = t.flags.iter().map(|(name, n)| format!("{name} {n}")).collect();
        let by = if by.is_empty() { String::new() } else { format!(" ({})", by.join(", ")) };
        println!("verdicts: {} of {measured} clips flagged{by}", t.flagged);
    }
    for clip in summary.flagged() {
        let flags = clip.verdict.as_ref().map(|v| v.flags.join(", ")).unwrap_or_default();
        println!("  flagged {}: {flags}", clip.input);
    }
}

/// What every clip of a batch shares: the retargeter (robot, config choice, options) and
/// the output settings.
struct Job {
    retargeter: Retargeter,
    /// `--config`, read once.
    given: Option<IkConfig>,
    /// The marker part of `--config`, when it has one (needed by C3D clips).
    markers: Option<MarkerConfig>,
    config_path: Option<PathBuf>,
    format: Format,
    /// `--fps`: resample every output.
    fps: Option<f64>,
    /// The body models of AMASS clips (`--body-model`), each read once, and `--gender`.
    body_models: smpl::BodyModels,
    gender: Option<smpl::Gender>,
}

impl Job {
    fn load(
        robot: &str,
        config: Option<&Path>,
        options: RetargetOptions,
        format: &str,
    ) -> anyhow::Result<Job> {
        let given = config.map(IkConfig::from_file).transpose()?;
        let format = crate::cmd_retarget::parse_format(Some(format))?
            .context("an output format is required")?;
        let markers =
            config.filter(|p| has_marker_bodies(p)).map(MarkerConfig::from_file).transpose()?;
        let mut retargeter = Retargeter::new(robot)?.with_options(options);
        if let Some(given) = &given {
            retargeter = retargeter.with_config(given.clone());
        }
        Ok(Job {
            retargeter,
            given,
            markers,
            config_path: config.map(Path::to_path_buf),
            format,
            fps: None,
            body_models: smpl::BodyModels::default(),
            gender: None,
        })
    }

    /// Retarget one file and write it; returns the frame count, the quality metrics and
    /// what was inferred about the source.
    fn convert_file(&self, src: &Path, dst: &Path) -> anyhow::Result<ClipResult> {
        remove_stale_temporaries(dst);
        let is = |ext: &str| src.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext));
        let (motion, diag, config) = if is("c3d") {
            self.convert_c3d(src)?
        } else if is("fbx") {
            // An FBX file: its take with the most motion (the summary's `inferred` says which).
            let clip = retarget::FbxClip::read(src, None)?;
            let chosen = self
                .retargeter
                .choose_fbx_config(&clip)
                .with_context(|| format!("{}: choosing the IK config", src.display()))?;
            let (motion, diag) = self
                .retargeter
                .retarget_fbx_with(&clip, &chosen)
                .with_context(|| format!("{}: retargeting", src.display()))?;
            (motion, diag, chosen.config)
        } else if is_npz(src) {
            self.convert_smpl(src)?
        } else {
            let bvh = bvh::from_path(src)?;
            let chosen = self
                .retargeter
                .choose_config(&bvh)
                .with_context(|| format!("{}: choosing the IK config", src.display()))?;
            let (motion, diag) = self
                .retargeter
                .retarget_bvh_with(&bvh, &chosen)
                .with_context(|| format!("{}: retargeting", src.display()))?;
            (motion, diag, chosen.config)
        };
        let report_options = {
            let mut o = retarget::report::ReportOptions::default();
            o.position_targets = Some(config.position_targets());
            o.root_target = Some(config.robot_root_name.clone());
            o
        };
        let quality = self.retargeter.report(&motion, &report_options)?;
        let model = self.retargeter.model();
        match self.fps {
            Some(fps) => {
                let resampled = retarget::resample(&motion, model, fps)?;
                write_motion(dst, &resampled, model, Some(self.format))?;
            }
            None => write_motion(dst, &motion, model, Some(self.format))?,
        }
        Ok(ClipResult {
            frames: motion.num_frames(),
            metrics: serde_json::to_value(&quality)?,
            inferred: Some(diag.human_inferred),
            verdict: Some(clip_verdict(&quality.verdict)),
        })
    }
}

impl Job {
    /// An AMASS clip posed with its body model (as the main command's `--smplx`).
    fn convert_smpl(
        &self,
        src: &Path,
    ) -> anyhow::Result<(retarget::RobotMotion, retarget::ClipDiagnostics, IkConfig)> {
        let motion = smpl::SmplMotion::from_path(src)?;
        let model = self.body_models.for_motion(&motion, self.gender)?;
        let clip = smpl::clip(&model, &motion).with_context(|| format!("{}", src.display()))?;
        let chosen = self
            .retargeter
            .choose_smpl_config(&clip)
            .with_context(|| format!("{}: choosing the IK config", src.display()))?;
        let (robot, diag) = self
            .retargeter
            .retarget_smpl_with(&motion, &model, &clip, &chosen)
            .with_context(|| format!("{}: retargeting", src.display()))?;
        Ok((robot, diag, chosen.config))
    }

    /// A C3D clip through the marker config's virtual bodies (as the main command's `--c3d`).
    fn convert_c3d(
        &self,
        src: &Path,
    ) -> anyhow::Result<(retarget::RobotMotion, retarget::ClipDiagnostics, IkConfig)> {
        let Some(markers) = &self.markers else {
            bail!(
                "{}: a C3D clip needs a marker config: --config with `marker_bodies` (e.g. configs/c3d_plugingait_to_unitree_g1.json){}",
                src.display(),
                self.config_path
                    .as_ref()
                    .map_or(String::new(), |p| format!("; {} has none", p.display()))
            );
        };
        let Some(config) = self.given.clone() else {
            bail!("{}: a C3D clip needs --config (a marker config)", src.display());
        };
        // Its errors name the file once (the C3D reader's, the marker bodies', the solve's).
        let file = c3d::C3d::from_path(src)?;
        let (motion, diag) =
            self.retargeter.retarget_c3d(&file, &src.display().to_string(), markers, &config)?;
        Ok((motion, diag, config))
    }
}

fn is_npz(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("npz"))
}

/// Whether the JSON config at `path` has a `marker_bodies` table (a marker config).
fn has_marker_bodies(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|json| json.get("marker_bodies").is_some())
}

/// A run killed while writing `dst` leaves `.<name>.tmp-*` beside it (the writers rename a
/// temporary file into place); the clip is about to be rewritten, so they can go.
fn remove_stale_temporaries(dst: &Path) {
    let (Some(dir), Some(name)) = (dst.parent(), dst.file_name()) else { return };
    let prefix = format!(".{}.tmp-", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        if entry.file_name().to_string_lossy().starts_with(&prefix) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// A report's verdict as a summary row carries it: ok and the names of the broken checks.
fn clip_verdict(verdict: &retarget::report::Verdict) -> batch::ClipVerdict {
    batch::ClipVerdict { ok: verdict.ok, flags: verdict.flag_names().map(str::to_owned).collect() }
}
