//! `retarget bvh map FILE [--map map.json]`: which joint plays each role of the canonical
//! humanoid and the rule that decided it, with the conventions inferred from the data (up
//! axis, unit, rest pose, left/right, the pose the body frames are taken in). `--map` fixes
//! roles by joint name: a JSON object `{"left_thigh": "LeftUpLeg", …}`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use fk::{FkOptions, FkReport, Role};

/// Arguments of `retarget bvh map`.
#[derive(Args, Debug, Clone)]
pub struct MapArgs {
    /// The BVH file.
    pub file: PathBuf,
    /// JSON object of roles to fix, role name → joint name (`{"left_hand": "L_Wrist"}`).
    #[arg(long)]
    pub map: Option<PathBuf>,
}

/// `retarget bvh map`, from parsed arguments.
pub fn run(args: &MapArgs) -> anyhow::Result<ExitCode> {
    let bvh = bvh::from_path(&args.file)?;
    let roles = match &args.map {
        Some(path) => read_map(path)?,
        None => BTreeMap::new(),
    };
    let options = FkOptions { roles, ..FkOptions::default() };
    let (_, report) =
        fk::human_motion(&bvh, &options).with_context(|| args.file.display().to_string())?;
    for line in lines(&args.file, &report)? {
        println!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}

/// Read a role map: a JSON object of role names (`left_thigh`) to joint names.
pub fn read_map(path: &Path) -> anyhow::Result<BTreeMap<Role, String>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let object: BTreeMap<String, String> = serde_json::from_str(&text).with_context(|| {
        format!("{}: expected a JSON object of role name → joint name", path.display())
    })?;
    object
        .into_iter()
        .map(|(role, joint)| {
            let parsed = Role::from_name(&role).with_context(|| {
                let known: Vec<&str> = Role::ALL.iter().map(|r| r.name()).collect();
                format!("{}: unknown role `{role}`; roles: {}", path.display(), known.join(", "))
            })?;
            Ok((parsed, joint))
        })
        .collect()
}

/// The report: conventions first, then the role table.
pub fn lines(file: &Path, report: &FkReport) -> anyhow::Result<Vec<String>> {
    let humanoid =
        report.humanoid.as_ref().map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let mut out = vec![
        format!("file:       {}", file.display()),
        format!(
            "skeleton:   {} roles; names: {}",
            humanoid.roles.len(),
            humanoid.convention.unwrap_or("none recognised (hierarchy alone)")
        ),
        format!("up axis:    {} ({})", humanoid.up, report.axes_reason),
        format!("unit:       {} m per file unit ({})", report.metres_per_unit, report.unit_reason),
        format!("rest pose:  {} ({})", humanoid.rest_pose, humanoid.rest_reason),
        format!("sides:      {}", humanoid.sides),
        format!("frames:     in {} ({})", humanoid.reference, humanoid.reference_reason),
    ];
    let width = humanoid.roles.iter().map(|(_, j)| j.name.len()).max().unwrap_or(5).max(5);
    out.push(format!("{:<16} {:<width$} rule", "role", "joint"));
    for role in Role::ALL {
        match humanoid.roles.get(role) {
            Some(joint) => {
                out.push(format!("{:<16} {:<width$} {}", role.name(), joint.name, joint.rule));
            }
            None => out.push(format!("{:<16} {:<width$} -", role.name(), "-")),
        }
    }
    Ok(out)
}
