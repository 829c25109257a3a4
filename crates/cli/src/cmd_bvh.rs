//! `retarget bvh …`: inspect, export and rewrite BVH files.

use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Subcommand;

#[derive(Subcommand, Debug)]
pub enum BvhCommand {
    /// Print a summary: frames, frame time, FPS, duration, joints as a tree, channels.
    Info {
        /// The BVH file.
        file: PathBuf,
    },
    /// Export as JSON: frame count, frame time and the joint tree with each joint's motion.
    Json {
        /// The BVH file.
        file: PathBuf,
        /// Write here (atomically) instead of to standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Parse and write back (shortest round-trip numbers): a normalised, checked copy.
    Cat {
        /// The BVH file.
        file: PathBuf,
        /// Write here (atomically) instead of to standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// World poses (m, Z up) of every body at one frame, plus units, subject height and ground.
    Fk(crate::cmd_bvh_fk::FkArgs),
    /// Which joint plays each role (pelvis, left_thigh, …) and why; up axis, unit, rest pose.
    Map(crate::cmd_bvh_map::MapArgs),
}

pub fn run(cmd: BvhCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        BvhCommand::Fk(args) => return crate::cmd_bvh_fk::run(&args),
        BvhCommand::Map(args) => return crate::cmd_bvh_map::run(&args),
        BvhCommand::Info { file } => {
            let bvh = crate::files::read_bvh(&file)?;
            let summary = bvh::Summary::new(&bvh, &file.display().to_string());
            emit(None, |w| write!(w, "{summary}"))?;
            for line in crate::cmd_bvh_fk::report_lines(&bvh)? {
                println!("{line}");
            }
        }
        BvhCommand::Json { file, output } => {
            let bvh = crate::files::read_bvh(&file)?;
            emit(output.as_deref(), |w| bvh::write_json(&bvh, w))?;
        }
        BvhCommand::Cat { file, output } => {
            let bvh = crate::files::read_bvh(&file)?;
            emit(output.as_deref(), |w| bvh::write(&bvh, w))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Write to `output` atomically, or to standard output when it is `None`. A closed pipe
/// (`retarget bvh json walk.bvh | head`) is not an error.
fn emit(
    output: Option<&Path>,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> anyhow::Result<()> {
    match output {
        Some(path) => crate::atomic_write_with(path, write),
        None => {
            let mut stdout = io::stdout().lock();
            match write(&mut stdout).and_then(|()| stdout.flush()) {
                Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
                result => result.context("writing to standard output"),
            }
        }
    }
}
