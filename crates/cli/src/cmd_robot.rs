//! `retarget robots` and `retarget robot …`: the robot models we ship or a user's MJCF.

use std::process::ExitCode;

use clap::Subcommand;

#[derive(Subcommand, Debug)]
pub enum RobotCommand {
    /// Print joints, ranges and bodies of a robot (shipped name or MJCF path).
    Info { robot: String },
}

pub fn list() -> anyhow::Result<ExitCode> {
    anyhow::bail!("robots: not implemented yet")
}

pub fn run(cmd: RobotCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        RobotCommand::Info { robot } => anyhow::bail!("{robot}: robot info is not implemented yet"),
    }
}
