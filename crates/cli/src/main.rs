//! `retarget`: human motion capture in, humanoid robot joint trajectories out.
//!
//! This file only wires subcommands; each family lives in its own module and owns its
//! arguments. Exit codes: 0 success, 1 bad input or failed job, 2 usage error (clap).

mod cmd_bvh;
mod cmd_c3d;
mod cmd_retarget;
mod cmd_robot;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Retarget human motion capture (BVH, C3D) onto humanoid robots described in MJCF.
#[derive(Parser, Debug)]
#[command(name = "retarget", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(flatten)]
    main_job: cmd_retarget::MainArgs,

    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Inspect, export and rewrite BVH files.
    #[command(subcommand)]
    Bvh(cmd_bvh::BvhCommand),
    /// Inspect, dump and convert C3D files.
    #[command(subcommand)]
    C3d(cmd_c3d::C3dCommand),
    /// List the robots and configs shipped with the tool.
    Robots,
    /// Inspect one robot model (shipped name or MJCF path).
    #[command(subcommand)]
    Robot(cmd_robot::RobotCommand),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Bvh(cmd)) => cmd_bvh::run(cmd),
        Some(Command::C3d(cmd)) => cmd_c3d::run(cmd),
        Some(Command::Robots) => cmd_robot::list(),
        Some(Command::Robot(cmd)) => cmd_robot::run(cmd),
        None => cmd_retarget::run_main(cli.main_job),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(1)
        }
    }
}
