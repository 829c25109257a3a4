//! `retarget`: human motion capture in, humanoid robot joint trajectories out.
//!
//! This file only wires subcommands; each family lives in its own module and owns its
//! arguments. Exit codes: 0 success, 1 bad input or failed job, 2 usage error (clap).

#[allow(dead_code)] // wired to `retarget batch` once the pipeline lands
mod batch;
mod cmd_bvh;
mod cmd_c3d;
mod cmd_retarget;
mod cmd_robot;
mod shipped;

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

/// Write `bytes` to `path` through a temporary file in the same directory and a rename, so
/// that an interrupted run never leaves a half-written file under the final name.
pub(crate) fn atomic_write(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    use anyhow::Context;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("{}: cannot write", path.display()))
}
