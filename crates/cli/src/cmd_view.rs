//! `retarget view`: one self-contained HTML file (WebGL player and plots) for a robot motion
//! (`.npz`, drawn on its MJCF model) or a BVH or FBX file (the skeleton alone).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};

use crate::view::{sources, PointFigure, Scene};

#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// A robot motion (`.npz`), or a BVH or FBX file (skeleton only; an FBX file's take with
    /// the most motion).
    pub input: PathBuf,
    /// Robot of an `.npz` motion: a shipped robot name or an MJCF path (default: the robot
    /// named in the file).
    #[arg(long)]
    pub robot: Option<String>,
    /// The BVH or FBX file the motion was retargeted from, drawn beside the robot.
    #[arg(long)]
    pub source: Option<PathBuf>,
    /// Output HTML file (default: the input with the extension `.html`).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(args: ViewArgs) -> anyhow::Result<ExitCode> {
    let output = args.output.clone().unwrap_or_else(|| args.input.with_extension("html"));
    let ext = args.input.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let scene = match ext.as_str() {
        "bvh" | "fbx" => {
            if args.robot.is_some() || args.source.is_some() {
                bail!("--robot and --source apply to a robot motion (.npz), not to a {ext} file");
            }
            bvh_scene(&args.input)?
        }
        "npz" => robot_scene(&args)?,
        _ => bail!(
            "{}: cannot view this file: expected a .npz robot motion, a .bvh or an .fbx file",
            args.input.display()
        ),
    };
    let html = scene.to_html()?;
    crate::atomic_write(&output, html.as_bytes())?;
    #[allow(clippy::cast_precision_loss)] // a file size in MB
    let mb = html.len() as f64 / 1e6;
    println!("{}: {} frames, {mb:.1} MB", output.display(), scene.num_frames);
    Ok(ExitCode::SUCCESS)
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// A BVH (or an FBX file's take) read and converted to our world (metres, Z up) by `fk`.
struct Human {
    bvh: bvh::Bvh,
    motion: fk::HumanMotion,
    report: fk::FkReport,
    /// An FBX file's take and what the file declares ([`retarget::FbxClip::summary`]).
    take: Option<String>,
}

fn read_human(path: &Path) -> anyhow::Result<Human> {
    let is_fbx = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("fbx"));
    let (bvh, options, take) = if is_fbx {
        let clip = retarget::FbxClip::read(path, None)?;
        let options = clip.fk_options(&fk::FkOptions::default());
        let take = clip.summary();
        (clip.bvh, options, Some(take))
    } else {
        (bvh::from_path(path)?, fk::FkOptions::default(), None)
    };
    let (motion, report) = fk::human_motion(&bvh, &options)
        .with_context(|| format!("{}: forward kinematics", path.display()))?;
    Ok(Human { bvh, motion, report, take })
}

/// The BVH joints (End Sites included) as a skeleton figure; derived bodies are left out.
fn human_figure(human: &Human, label: &str, frames: usize) -> PointFigure {
    let joints = &human.bvh.skeleton.joints;
    let n = joints.len();
    let parents: Vec<Option<usize>> = joints.iter().map(|j| j.parent.map(|p| p.0)).collect();
    let names = &human.motion.body_names[..n];
    let positions = (0..frames)
        .flat_map(|f| human.motion.frame_positions(f)[..n].iter().map(|p| [p.x, p.y, p.z]));
    sources::skeleton_figure(label, names, &parents, positions)
}

/// The joint names as an indented tree (End Sites left out).
fn joint_tree(skeleton: &bvh::Skeleton) -> String {
    let mut depth = vec![0usize; skeleton.joints.len()];
    let mut out = String::new();
    for (i, joint) in skeleton.joints.iter().enumerate() {
        depth[i] = joint.parent.map_or(0, |p| depth[p.0] + 1);
        if joint.kind != bvh::JointKind::End {
            out.push_str(&"  ".repeat(depth[i]));
            out.push_str(&joint.name);
            out.push('\n');
        }
    }
    out
}

fn human_info(human: &Human) -> Vec<(String, String)> {
    let joints = &human.bvh.skeleton.joints;
    let ends = joints.iter().filter(|j| j.kind == bvh::JointKind::End).count();
    let r = &human.report;
    let mut info = vec![
        ("joints".into(), format!("{} (+{ends} end sites)", joints.len() - ends)),
        ("channels".into(), human.bvh.skeleton.num_channels().to_string()),
        ("height".into(), format!("{:.2} m", r.height)),
        ("units".into(), format!("{} m per file unit", r.metres_per_unit)),
    ];
    if let Some(take) = &human.take {
        info.push(("take".into(), take.clone()));
    }
    info
}

fn bvh_scene(path: &Path) -> anyhow::Result<Scene> {
    let human = read_human(path)?;
    let frames = human.motion.num_frames;
    Ok(Scene {
        title: file_name(path),
        fps: human.motion.fps,
        num_frames: frames,
        info: human_info(&human),
        tree: Some(joint_tree(&human.bvh.skeleton)),
        skeletons: vec![human_figure(&human, "skeleton", frames)],
        robot: None,
        plots: vec![],
    })
}

fn robot_scene(args: &ViewArgs) -> anyhow::Result<Scene> {
    let path = &args.input;
    let motion = retarget::writers::read_motion_npz(path)?;
    // Our own .npz files name their robot; others (GMR's) need --robot.
    let stored = retarget::writers::read_npz_robot(path)?;
    let Some(robot) = args.robot.as_deref().or(stored.as_deref()) else {
        bail!(
            "{}: the file names no robot: pass --robot NAME (shipped) or --robot FILE.xml",
            path.display()
        );
    };
    let model = crate::shipped::robot_model(robot).with_context(|| match &args.robot {
        Some(_) => format!("{}: robot", path.display()),
        None => format!(
            "{}: the robot named in the file (pass --robot to choose another)",
            path.display()
        ),
    })?;
    sources::check_motion_fits(&model, &motion)
        .with_context(|| format!("{}: robot {robot}", path.display()))?;
    let mut frames = motion.num_frames();
    let mut info = vec![
        ("robot".to_owned(), file_name(Path::new(robot))),
        ("joints".to_owned(), motion.joint_names.len().to_string()),
    ];
    let mut skeletons = Vec::new();
    if let Some(targets) = &motion.targets {
        skeletons.push(sources::targets_figure(targets, frames)?);
        info.push(("IK targets".into(), targets.body_names.len().to_string()));
    }
    if let Some(source) = &args.source {
        let human = read_human(source)?;
        if human.motion.num_frames != frames {
            info.push(("note".into(), format!("source has {} frames", human.motion.num_frames)));
            frames = frames.min(human.motion.num_frames);
            for s in &mut skeletons {
                s.positions.truncate(frames * s.names.len() * 3);
                s.orientations.truncate(frames * s.names.len() * 4);
            }
        }
        skeletons.push(human_figure(&human, &format!("source {}", file_name(source)), frames));
    }
    let label = file_name(Path::new(robot));
    let figure = sources::robot_figure(&model, &motion.qpos[..frames * motion.nq], &label)?;
    let plots =
        motion.contacts.as_ref().map_or_else(Vec::new, |c| sources::contact_plots(c, frames));
    Ok(Scene {
        title: file_name(path),
        fps: motion.fps,
        num_frames: frames,
        info,
        tree: None,
        skeletons,
        robot: Some(figure),
        plots,
    })
}
