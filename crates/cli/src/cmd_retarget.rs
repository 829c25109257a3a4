//! The main job: `retarget --bvh FILE --robot NAME [-o OUT]`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

#[derive(Args, Debug)]
pub struct MainArgs {
    /// BVH motion capture file to retarget.
    #[arg(long)]
    pub bvh: Option<PathBuf>,
    /// Robot: a shipped name (see `retarget robots`) or a path to an MJCF file.
    #[arg(long)]
    pub robot: Option<String>,
    /// Output file; format from the extension (.npz, .csv, .pkl, .json).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run_main(args: MainArgs) -> anyhow::Result<ExitCode> {
    let (Some(bvh), Some(robot)) = (args.bvh, args.robot) else {
        eprintln!("usage: retarget --bvh FILE --robot NAME [-o OUT]   (see `retarget --help`)");
        return Ok(ExitCode::from(2));
    };
    anyhow::bail!("{}: retargeting onto {robot} is not implemented yet", bvh.display())
}
