//! `retarget`: human motion capture in, humanoid robot joint trajectories out.
//!
//! This file only wires subcommands; each family lives in its own module and owns its
//! arguments. Exit codes: 0 success, 1 bad input or failed job, 2 usage error (clap).

mod batch;
mod cmd_batch;
mod cmd_bvh;
mod cmd_bvh_fk;
mod cmd_bvh_map;
mod cmd_c3d;
mod cmd_fbx;
mod cmd_report;
mod cmd_retarget;
mod cmd_robot;
mod cmd_smpl;
mod cmd_view;
mod errors;
mod files;
mod shipped;
mod view;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

// The subcommands write through these (`crate::atomic_write`); they live in `files`.
pub(crate) use files::{atomic_write, atomic_write_with};

/// Retarget human motion capture (BVH, FBX, C3D, AMASS SMPL-X / SMPL+H) onto humanoid robots described in MJCF.
#[derive(Parser, Debug)]
#[command(
    name = "retarget",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    override_usage = "retarget --bvh <FILE> --robot <ROBOT> [OPTIONS]\n       \
                      retarget --fbx <FILE> [--take <NAME|N>] --robot <ROBOT> [OPTIONS]\n       \
                      retarget --c3d <FILE> --config <FILE> --robot <ROBOT> [OPTIONS]\n       \
                      retarget --smplx <FILE> --robot <ROBOT> [--body-model DIR] [OPTIONS]\n       \
                      retarget <COMMAND>"
)]
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
    /// Inspect FBX files, convert a take to BVH, show the skeleton's roles.
    #[command(subcommand)]
    Fbx(cmd_fbx::FbxCommand),
    /// Inspect AMASS motion files (SMPL-X, SMPL+H) and their body models.
    #[command(subcommand)]
    Smpl(cmd_smpl::SmplCommand),
    /// List the robots and configs shipped with the tool.
    Robots,
    /// Inspect one robot model (shipped name, MJCF or URDF path).
    #[command(subcommand)]
    Robot(cmd_robot::RobotCommand),
    /// Convert a whole directory tree of clips, in parallel and resumable.
    Batch(cmd_batch::BatchArgs),
    /// Quality metrics of a robot motion (ours or .npz / .pkl / .csv of GMR, BeyondMimic,
    /// Unitree): tracking, limits, jitter, foot contact.
    Report(cmd_report::ReportArgs),
    /// Write a self-contained HTML player (WebGL) with plots for a robot motion or a BVH.
    View(cmd_view::ViewArgs),
}

fn main() -> ExitCode {
    restore_sigpipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Bvh(cmd)) => cmd_bvh::run(cmd),
        Some(Command::C3d(cmd)) => cmd_c3d::run(cmd),
        Some(Command::Fbx(cmd)) => cmd_fbx::run(cmd),
        Some(Command::Smpl(cmd)) => cmd_smpl::run(cmd),
        Some(Command::Robots) => cmd_robot::list(),
        Some(Command::Robot(cmd)) => cmd_robot::run(cmd),
        Some(Command::View(args)) => cmd_view::run(args),
        Some(Command::Batch(args)) => cmd_batch::run(args),
        Some(Command::Report(args)) => cmd_report::run(args),
        None => cmd_retarget::run_main(cli.main_job),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {}", errors::error_chain(&err));
            ExitCode::from(1)
        }
    }
}

/// Rust ignores SIGPIPE, which turns `retarget … | head` into a panic in `println!`. A
/// command-line tool should instead end quietly when its reader goes away, as C tools do.
#[allow(unsafe_code)]
fn restore_sigpipe() {
    // SAFETY: called first thing in `main`, before any other thread exists; setting a signal
    // disposition to the default has no other effect on Rust's runtime.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
