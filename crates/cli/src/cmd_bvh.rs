//! `retarget bvh …`: inspect, export and rewrite BVH files.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Subcommand;

#[derive(Subcommand, Debug)]
pub enum BvhCommand {
    /// Print a summary: frames, frame time, FPS, duration, joints as a tree, channels.
    Info { file: PathBuf },
}

pub fn run(cmd: BvhCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        BvhCommand::Info { file } => {
            anyhow::bail!("{}: bvh info is not implemented yet", file.display())
        }
    }
}
