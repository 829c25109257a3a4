//! `retarget smpl …`: inspect AMASS motion files (SMPL-X stage-ii, SMPL+H) and their body
//! models; and the SMPL half of the main job (`retarget --smplx FILE --robot R`) and batch.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, Subcommand};
use retarget::{ClipDiagnostics, Retargeter, RobotMotion};
use smpl::{BodyModels, Gender, SmplMotion};

#[derive(Subcommand, Debug)]
pub enum SmplCommand {
    /// Print frames, rate, gender, betas, model type and the height GMR would use; with a
    /// body model, its file, shape components and the subject's stature.
    Info {
        /// The AMASS motion file (`*_stageii.npz`, `*_poses.npz`).
        file: PathBuf,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Forward kinematics of every frame as an `.npz` (the layout of `retarget bvh fk --npz`:
    /// `body_names`, `body_pos_w`, `body_quat_w`, `ground`, `height`, roles), for checks.
    Fk {
        /// The AMASS motion file.
        file: PathBuf,
        /// Output `.npz`.
        #[arg(long, value_name = "OUT")]
        npz: PathBuf,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// Where the body model comes from (main command, batch, `smpl` subcommands).
#[derive(Args, Debug, Clone, Default)]
pub struct ModelArgs {
    /// Body model folder for SMPL-X / SMPL+H input (the one holding `smplx/SMPLX_*.npz` and
    /// `smplh/<gender>/model.npz`), or one model `.npz`. Default: $RETARGET_BODY_MODELS.
    #[arg(long, value_name = "DIR")]
    pub body_model: Option<PathBuf>,
    /// Body model gender for SMPL-X / SMPL+H input, overriding the file's `gender`.
    #[arg(long, value_name = "GENDER", value_parser = parse_gender)]
    pub gender: Option<Gender>,
}

impl ModelArgs {
    pub fn models(&self) -> BodyModels {
        BodyModels::new(self.body_model.as_deref())
    }
}

fn parse_gender(text: &str) -> Result<Gender, String> {
    Gender::from_name(text).ok_or_else(|| format!("`{text}`: expected neutral, male or female"))
}

pub fn run(cmd: SmplCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        SmplCommand::Info { file, model } => info(&file, &model),
        SmplCommand::Fk { file, npz, model } => fk(&file, &npz, &model),
    }
}

fn read(file: &Path) -> anyhow::Result<SmplMotion> {
    Ok(SmplMotion::from_path(file)?)
}

fn info(file: &Path, args: &ModelArgs) -> anyhow::Result<ExitCode> {
    let motion = read(file)?;
    let gender = args.gender.or(motion.gender);
    println!("{}: {} motion (AMASS)", file.display(), motion.kind);
    println!("frames: {} at {} fps ({:.2} s)", motion.num_frames(), motion.fps, motion.duration());
    let said = match (args.gender, motion.gender) {
        (Some(g), _) => format!("{g} (given)"),
        (None, Some(g)) => g.to_string(),
        (None, None) => "not given in the file".to_owned(),
    };
    println!("gender: {said}");
    let betas: Vec<String> = motion.betas.iter().map(|b| format!("{b:.4}")).collect();
    println!("betas: {} [{}]", motion.betas.len(), betas.join(", "));
    println!(
        "GMR's subject height: {:.3} m (1.66 + 0.1 · betas[0])",
        smpl::conventions::gmr_height(&motion.betas)
    );
    let models = args.models();
    match gender.map(|g| models.get(motion.kind, g)) {
        Some(Ok(model)) => {
            smpl::forward::check(&model, &motion)?;
            println!(
                "body model: {} ({} joints, {} shape components)",
                model.path.display(),
                model.num_joints(),
                model.shape_components()
            );
            println!(
                "stature: {:.3} m (the body model at these betas)",
                model.stature(&motion.betas)
            );
        }
        Some(Err(e)) => println!("body model: {e}"),
        None => println!("body model: give --gender to find it"),
    }
    Ok(ExitCode::SUCCESS)
}

fn fk(file: &Path, out: &Path, args: &ModelArgs) -> anyhow::Result<ExitCode> {
    use npz::Array;
    let motion = read(file)?;
    let model = args.models().for_motion(&motion, args.gender)?;
    let clip = smpl::clip(&model, &motion).with_context(|| file.display().to_string())?;
    let human = &clip.human;
    let (t, b) = (human.num_frames, human.num_bodies());
    let mut pos = Vec::with_capacity(t * b * 3);
    let mut quat = Vec::with_capacity(t * b * 4);
    for (p, q) in human.positions.iter().zip(&human.orientations) {
        pos.extend([p.x, p.y, p.z]);
        quat.extend([q.w, q.i, q.j, q.k]);
    }
    let (mut names, mut bodies, mut offsets) = (Vec::new(), Vec::new(), Vec::new());
    for (role, joint) in clip.humanoid.roles.iter() {
        let q = clip.humanoid.frame_offsets.get(&role).copied().unwrap_or_default();
        names.push(role.name().to_owned());
        bodies.push(joint.name.clone());
        offsets.extend([q.w, q.i, q.j, q.k]);
    }
    let arrays = [
        ("fps", Array::f64(vec![1], vec![human.fps])),
        ("body_names", Array::strings(&human.body_names)),
        ("body_pos_w", Array::f64(vec![t, b, 3], pos)),
        ("body_quat_w", Array::f64(vec![t, b, 4], quat)),
        ("ground", Array::f64(vec![1], vec![clip.ground])),
        ("height", Array::f64(vec![1], vec![clip.height])),
        ("role_names", Array::strings(&names)),
        ("role_bodies", Array::strings(&bodies)),
        ("role_frame_offsets", Array::f64(vec![names.len(), 4], offsets)),
    ];
    retarget::writers::write_npz(out, &arrays)?;
    println!("{}: {t} frames, {b} bodies -> {}", file.display(), out.display());
    Ok(ExitCode::SUCCESS)
}

/// Reads an AMASS motion, finds its body model and retargets it (main command and batch).
pub fn retarget_file(
    retargeter: &Retargeter,
    file: &Path,
    models: &BodyModels,
    gender: Option<Gender>,
) -> anyhow::Result<(RobotMotion, ClipDiagnostics)> {
    let motion = read(file)?;
    let model = models.for_motion(&motion, gender)?;
    retargeter
        .retarget_smpl(&motion, &model)
        .with_context(|| format!("{}: retargeting onto {}", file.display(), retargeter.label()))
}

/// The default output of an `.npz` motion: `<stem>_<robot>.npz` beside it (its own name
/// would overwrite the input).
pub fn default_output(input: &Path, robot: &str, ext: &str) -> PathBuf {
    let stem = input.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    input.with_file_name(format!("{stem}_{robot}.{ext}"))
}
