//! `retarget fbx …`: inspect FBX files, convert a take to BVH, show the skeleton's roles;
//! and the main job's `--fbx` input (`retarget --fbx clip.fbx --robot R [--take NAME|N]`).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Subcommand;
use retarget::{ClipDiagnostics, FbxClip, Retargeter, RobotMotion};

#[derive(Subcommand, Debug)]
pub enum FbxCommand {
    /// Takes (frame ranges, rates, keys), skeleton, units, axes and exporter.
    Info {
        /// The FBX file.
        file: PathBuf,
    },
    /// A take as BVH (Y up, the file's unit, names with spaces written with `_`).
    Bvh {
        /// The FBX file.
        file: PathBuf,
        /// The take: its name or its index in `retarget fbx info` (default: the take with the
        /// most motion).
        #[arg(long, value_name = "NAME|N")]
        take: Option<String>,
        /// Write here (atomically) instead of to standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// The take's FK (m, Z up) and roles as an `.npz`, as `retarget bvh fk --npz` writes it.
    Fk {
        /// The FBX file.
        file: PathBuf,
        /// The take (default: the take with the most motion).
        #[arg(long, value_name = "NAME|N")]
        take: Option<String>,
        /// The `.npz` to write (`body_pos_w`, `body_quat_w`, roles; see `retarget bvh fk`).
        #[arg(long, value_name = "OUT.npz", required = true)]
        npz: PathBuf,
    },
    /// Which joint plays each role (pelvis, left_thigh, …) and why; up axis, unit, rest pose.
    Map {
        /// The FBX file.
        file: PathBuf,
        /// The take (default: the take with the most motion).
        #[arg(long, value_name = "NAME|N")]
        take: Option<String>,
        /// JSON object of roles to fix, role name → joint name (`{"left_hand": "L_Wrist"}`).
        #[arg(long)]
        map: Option<PathBuf>,
    },
}

pub fn run(cmd: FbxCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        FbxCommand::Info { file } => {
            for line in info_lines(&fbx::Fbx::from_path(&file)?)? {
                println!("{line}");
            }
        }
        FbxCommand::Bvh { file, take, output } => {
            let fbx = fbx::Fbx::from_path(&file)?;
            let selected = fbx.select_take(take.as_deref())?;
            let mut bvh = fbx.bvh_y_up(selected.index)?;
            fbx::bvh_safe_names(&mut bvh);
            let write = |w: &mut dyn Write| bvh::write(&bvh, w);
            match &output {
                Some(path) => crate::atomic_write_with(path, write)?,
                None => write(&mut std::io::stdout().lock()).or_else(closed_pipe)?,
            }
            let info = fbx.info();
            eprintln!(
                "{}: take `{}` ({}), {} frames at {} fps, {} joints, Y up, {} m per unit{}",
                file.display(),
                selected.name,
                selected.reason,
                bvh.motion.num_frames,
                info.fps,
                bvh.skeleton.joints.len(),
                info.metres_per_unit,
                output.map(|p| format!(": wrote {}", p.display())).unwrap_or_default()
            );
        }
        FbxCommand::Fk { file, take, npz } => {
            let clip = FbxClip::read(&file, take.as_deref())?;
            let options = clip.fk_options(&fk::FkOptions::default());
            crate::cmd_bvh_fk::write_npz(&clip.bvh, &options, &npz)
                .with_context(|| file.display().to_string())?;
            println!("{}: {}; wrote {}", file.display(), clip.summary(), npz.display());
        }
        FbxCommand::Map { file, take, map } => {
            let clip = FbxClip::read(&file, take.as_deref())?;
            let roles = match &map {
                Some(path) => crate::cmd_bvh_map::read_map(path)?,
                None => Default::default(),
            };
            let options = clip.fk_options(&fk::FkOptions { roles, ..fk::FkOptions::default() });
            let (_, report) = fk::human_motion(&clip.bvh, &options)
                .with_context(|| file.display().to_string())?;
            let mut lines = crate::cmd_bvh_map::lines(&file, &report)?;
            lines.insert(1, format!("take:       {}", clip.summary()));
            for line in lines {
                println!("{line}");
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `retarget fbx bvh … | head`: a reader that goes away is not an error.
fn closed_pipe(e: std::io::Error) -> std::io::Result<()> {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Ok(())
    } else {
        Err(e)
    }
}

/// `retarget fbx info`: the file, its settings, takes and skeleton tree.
fn info_lines(fbx: &fbx::Fbx) -> anyhow::Result<Vec<String>> {
    let info = fbx.info();
    let kind = if info.ascii { "ASCII" } else { "binary" };
    let application = if info.application.is_empty() { "not stated" } else { &info.application };
    let rate = match &info.fps_note {
        Some(note) => note.clone(),
        None => format!("{} fps (TimeMode {})", info.fps, info.time_mode),
    };
    let axes = match info.world_from_file().and_then(|m| fk::AxisConvention::from_matrix(&m)) {
        Some(fk::AxisConvention::YUp) => "Y up: (x, y, z) → (x, −z, y) in Z up".to_owned(),
        Some(fk::AxisConvention::ZUp) => "Z up, as ours".to_owned(),
        _ => "turned to Z up by right → +X, up → +Z".to_owned(),
    };
    let mut out = vec![
        format!("file:       {}", fbx.file()),
        format!(
            "format:     FBX {} {kind}; creator: {}; application: {application}",
            info.version, info.creator
        ),
        format!("axes:       {} ({axes})", info.axes),
        format!(
            "units:      UnitScaleFactor {} ({} m per file unit)",
            info.unit_scale_factor, info.metres_per_unit
        ),
        format!("frame rate: {rate}"),
    ];
    match fbx.select_take(None) {
        Ok(take) => out.push(format!(
            "takes:      {} (default: `{}`, {})",
            info.takes.len(),
            take.name,
            take.reason
        )),
        Err(e) => out.push(format!("takes:      {} ({e})", info.takes.len())),
    }
    for (i, take) in info.takes.iter().enumerate() {
        let keys = match take.keys {
            Some((a, b)) => format!("keys {a:.4} s .. {b:.4} s on {} curves", take.curves),
            None => "no keys".to_owned(),
        };
        out.push(format!(
            "  {i} `{}`: {:.4} s .. {:.4} s, {} frames (from frame {}); {keys}",
            take.name, take.start, take.stop, take.frames, take.first_frame
        ));
    }
    let count = |k: &fbx::NodeKind| info.skeleton.iter().filter(|n| &n.kind == k).count();
    let roots: Vec<&str> =
        info.skeleton.iter().filter(|n| n.parent.is_none()).map(|n| n.name.as_str()).collect();
    out.push(format!(
        "skeleton:   {} nodes ({} LimbNode, {} Root, {} Null); roots: {}",
        info.skeleton.len(),
        count(&fbx::NodeKind::LimbNode),
        count(&fbx::NodeKind::Root),
        count(&fbx::NodeKind::Null),
        roots.join(", ")
    ));
    let mut depth = vec![0usize; info.skeleton.len()];
    for (i, node) in info.skeleton.iter().enumerate() {
        let d = node.parent.and_then(|p| depth.get(p)).map_or(0, |d| d + 1);
        if let Some(slot) = depth.get_mut(i) {
            *slot = d;
        }
        out.push(format!("  {}{} ({})", "  ".repeat(d), node.name, node.kind));
    }
    Ok(out)
}

/// The main job's `--fbx`: take `take` retargeted with the retargeter's config choice.
pub fn retarget(
    retargeter: &Retargeter,
    input: &Path,
    take: Option<&str>,
    robot: &str,
) -> anyhow::Result<(RobotMotion, ClipDiagnostics)> {
    let clip = FbxClip::read(input, take)?;
    let chosen = retargeter
        .choose_fbx_config(&clip)
        .with_context(|| format!("{}: choosing the IK config", input.display()))?;
    retargeter
        .retarget_fbx_with(&clip, &chosen)
        .with_context(|| format!("{}: retargeting onto {robot}", input.display()))
}
