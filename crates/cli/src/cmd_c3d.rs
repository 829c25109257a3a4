//! `retarget c3d …`: inspect, dump and convert C3D files.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Subcommand;

#[derive(Subcommand, Debug)]
pub enum C3dCommand {
    /// Print header facts, points, analog channels, rate, events and parameter groups.
    Info { file: PathBuf },
}

pub fn run(cmd: C3dCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        C3dCommand::Info { file } => {
            anyhow::bail!("{}: c3d info is not implemented yet", file.display())
        }
    }
}
