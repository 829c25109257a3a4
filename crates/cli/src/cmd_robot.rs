//! `retarget robots` and `retarget robot …`: the robot models we ship or a user's MJCF.

use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

use clap::Subcommand;
use mjcf::{JointType, Model};

use crate::shipped;

#[derive(Subcommand, Debug)]
pub enum RobotCommand {
    /// Print joints, ranges and bodies of a robot (shipped name, MJCF or URDF path), and
    /// which body plays each role of the canonical humanoid (and the rule that decided it).
    Info {
        /// A shipped robot (see `retarget robots`) or an MJCF (.xml) or URDF (.urdf) file.
        robot: String,
        /// Also write the roles as JSON: per role its body, role point and `frame_offset`
        /// (w x y z: the role's canonical frame is the body's world orientation ⊗ it), the
        /// sole bodies, the forward direction and the height, all at `qpos0`.
        #[arg(long, value_name = "OUT.json")]
        json: Option<std::path::PathBuf>,
    },
    /// Write the IK config derived for a robot (GMR schema): against the canonical human,
    /// with role names as human joints (bound to each skeleton when used with --config), or
    /// against the skeleton of --bvh, with its joint names.
    Init {
        /// Shipped name, MJCF (.xml) or URDF (.urdf) path.
        robot: String,
        /// Derive against this BVH's skeleton instead of the canonical human.
        #[arg(long, value_name = "FILE")]
        bvh: Option<std::path::PathBuf>,
        /// Output JSON file.
        #[arg(short, long, value_name = "FILE")]
        output: std::path::PathBuf,
    },
    /// Compare our kinematics with MuJoCo's at random configurations (needs the `mujoco`
    /// feature): model structure, body poses and body Jacobians.
    Check {
        /// A shipped robot (see `retarget robots`) or an MJCF (.xml) or URDF (.urdf) file.
        robot: String,
        /// Number of random configurations (checked in addition to qpos0).
        #[arg(long, default_value_t = 100)]
        configs: usize,
        /// Seed of the random configurations.
        #[arg(long, default_value_t = 20_251_122)]
        seed: u64,
        /// Largest deviation that passes.
        #[arg(long, default_value_t = 1e-9)]
        tolerance: f64,
    },
}

/// Degrees of freedom of the joints other than free joints (the actuated ones of a humanoid).
fn joint_dofs(model: &Model) -> usize {
    model.joints.iter().filter(|j| j.kind != JointType::Free).map(|j| j.kind.nv()).sum()
}

/// Writes `text` to stdout; a closed pipe (`retarget robot info g1 | head`) is not an error.
fn emit(text: &str) -> anyhow::Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

pub fn list() -> anyhow::Result<ExitCode> {
    let mut out = format!("{:<22} {:>4} {:>4} {:>5} {:>7}\n", "robot", "nq", "nv", "dof", "bodies");
    for key in shipped::shipped_keys() {
        let model = shipped::robot_model(key)?;
        let (nq, nv, dof, nbody) = (model.nq, model.nv, joint_dofs(&model), model.nbody());
        writeln!(out, "{key:<22} {nq:>4} {nv:>4} {dof:>5} {nbody:>7}")?;
    }
    writeln!(
        out,
        "\nGMR's robots not shipped (get the model upstream, pass --robot path/to/model.xml):"
    )?;
    for robot in retarget::shipped::NOT_SHIPPED {
        let (key, reason, upstream) = (robot.key, robot.reason, robot.upstream);
        writeln!(out, "{key:<22} YanjieZe/GMR {upstream}: {reason}")?;
    }
    emit(&out)?;
    Ok(ExitCode::SUCCESS)
}

pub fn run(cmd: RobotCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        RobotCommand::Info { robot, json } => info(&robot, json.as_deref()),
        RobotCommand::Init { robot, bvh, output } => init(&robot, bvh.as_deref(), &output),
        RobotCommand::Check { robot, configs, seed, tolerance } => {
            check(&robot, configs, seed, tolerance)
        }
    }
}

fn info(robot: &str, json: Option<&std::path::Path>) -> anyhow::Result<ExitCode> {
    let (model, notes) = retarget::shipped::load_robot_noted(robot)?;
    if let Some(path) = json {
        let roles = retarget::RobotRoles::recognise(&model)?;
        let text = serde_json::to_string_pretty(&roles_json(&model, &roles))?;
        crate::atomic_write(path, format!("{text}\n").as_bytes())?;
    }
    let mut out = String::new();
    writeln!(out, "robot: {robot}")?;
    for note in &notes {
        writeln!(out, "note: {note}")?;
    }
    writeln!(
        out,
        "nq {}  nv {}  joint dofs {}  bodies {}",
        model.nq,
        model.nv,
        joint_dofs(&model),
        model.nbody()
    )?;
    writeln!(out, "\njoints ({}):", model.joints.len())?;
    writeln!(out, "  {:>3} {:<32} {:<6} {:>5} {:>5}  range", "id", "name", "type", "qpos", "dof")?;
    for (i, j) in model.joints.iter().enumerate() {
        let range = match (j.range, j.kind) {
            (None, _) => "unlimited".to_owned(),
            (Some([lo, hi]), JointType::Slide) => format!("[{lo:.4}, {hi:.4}] m"),
            (Some([lo, hi]), _) => {
                format!(
                    "[{lo:.4}, {hi:.4}] rad  ([{:.1}, {:.1}] deg)",
                    lo.to_degrees(),
                    hi.to_degrees()
                )
            }
        };
        let unit = if j.kind == JointType::Slide { "m/s" } else { "rad/s" };
        let range = match j.velocity_limit {
            Some(v) => format!("{range}  speed {v} {unit}"),
            None => range,
        };
        let name = if j.name.is_empty() { "(unnamed)" } else { &j.name };
        writeln!(
            out,
            "  {i:>3} {name:<32} {:<6} {:>5} {:>5}  {range}",
            j.kind.as_str(),
            j.qpos_adr,
            j.dof_adr
        )?;
    }
    writeln!(out, "\nbodies ({}):", model.nbody())?;
    writeln!(out, "  {:>3} {:<32} parent", "id", "name")?;
    for (i, b) in model.bodies.iter().enumerate() {
        let parent = if i == 0 { "-" } else { &model.bodies[b.parent].name };
        writeln!(out, "  {i:>3} {:<32} {parent}", b.name)?;
    }
    self_collision_lines(&model, &mut out)?;
    writeln!(out, "\nroles (the canonical humanoid's, at qpos0):")?;
    match retarget::RobotRoles::recognise(&model) {
        Ok(roles) => out.push_str(&roles.describe(&model)),
        Err(e) => writeln!(out, "  not recognised: {e}")?,
    }
    emit(&out)?;
    Ok(ExitCode::SUCCESS)
}

/// Configurations sampled per pair by `robot info`'s chain-contact hint, and its seed.
const CHAIN_SAMPLES: usize = 400;
const CHAIN_SEED: u64 = 0x5eed_c4a1;

/// A chain pair touching in at least this share of its joints' ranges is listed as a hint.
const CHAIN_HINT_SHARE: f64 = 0.1;

/// `robot info`'s self-collision section: how many pairs the solve keeps apart, and the pairs
/// on one chain whose primitives touch over much of the ranges of the joints between them
/// ([`mjcf::Model::chain_contacts`]): a hint towards an `<exclude>` where the geometry is
/// coarser than the parts.
fn self_collision_lines(model: &Model, out: &mut String) -> anyhow::Result<()> {
    let pairs = model.self_collision_pairs();
    writeln!(
        out,
        "\nself-collision: {} pairs kept apart ({} adjacent in effect and {} touching at qpos0 \
         left out)",
        pairs.pairs.len(),
        pairs.adjacent.len(),
        pairs.touching_at_rest.len()
    )?;
    let hints: Vec<_> = model
        .chain_contacts(CHAIN_SAMPLES, CHAIN_SEED)
        .into_iter()
        .filter(|c| c.share >= CHAIN_HINT_SHARE)
        .collect();
    if hints.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "  pairs on one chain that touch in {:.0} % or more of the ranges of the joints between \
         them ({CHAIN_SAMPLES} samples each); where that is geometry coarser than the parts, \
         not a real limit, <contact><exclude body1=\"…\" body2=\"…\"/></contact> leaves the \
         pair out:",
        100.0 * CHAIN_HINT_SHARE
    )?;
    for c in hints {
        let [a, b] = c.bodies;
        writeln!(
            out,
            "    {:>5.1} %  {} / {}  (bodies {} / {}, {} joint{} between)",
            100.0 * c.share,
            model.geom_label(c.geoms[0]),
            model.geom_label(c.geoms[1]),
            model.bodies[a].name,
            model.bodies[b].name,
            c.joints,
            if c.joints == 1 { "" } else { "s" }
        )?;
    }
    Ok(())
}

/// The roles of `robot info --json` (see [`RobotCommand::Info`]).
fn roles_json(model: &Model, roles: &retarget::RobotRoles) -> serde_json::Value {
    use serde_json::{json, Map, Value};
    let mut data = mjcf::Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let frames = roles.canonical_frames();
    let mut out = Map::new();
    for (role, r) in &roles.roles {
        let mut entry = Map::new();
        entry.insert("body".into(), Value::from(r.name.clone()));
        entry.insert("point".into(), json!([r.point.x, r.point.y, r.point.z]));
        if let (Some(c), Some(q)) = (frames.get(role), data.xquat.get(r.body)) {
            let o = q.inverse() * c;
            entry.insert("frame_offset".into(), json!([o.w, o.i, o.j, o.k]));
        }
        out.insert(role.name().to_owned(), Value::Object(entry));
    }
    let body = |b: usize| model.bodies.get(b).map_or("", |b| b.name.as_str()).to_owned();
    json!({
        "base": body(roles.base),
        "forward": [roles.forward.x, roles.forward.y, roles.forward.z],
        "height": roles.height,
        "roles": out,
        "soles": { "left": body(roles.soles[0].body), "right": body(roles.soles[1].body) },
    })
}

/// `retarget robot init ROBOT [--bvh FILE] -o OUT.json`.
fn init(
    robot: &str,
    bvh: Option<&std::path::Path>,
    output: &std::path::Path,
) -> anyhow::Result<ExitCode> {
    use anyhow::Context;
    use retarget::derive::{derive, human_body, HumanBody};
    let model = shipped::robot_model(robot)?;
    let roles = retarget::RobotRoles::recognise(&model)?;
    let label = crate::cmd_retarget::robot_label(robot);
    let (human, against) = match bvh {
        Some(path) => {
            let file = crate::files::read_bvh(path).with_context(|| path.display().to_string())?;
            let human = human_body(&file, &fk::FkOptions::default(), &path.display().to_string())
                .with_context(|| format!("{}: the skeleton", path.display()))?;
            (human, path.display().to_string())
        }
        None => (HumanBody::canonical(), "the canonical human (role names)".to_owned()),
    };
    let config = derive(&model, &roles, &human, &output.display().to_string())?;
    crate::atomic_write(output, config.json().as_bytes())?;
    println!(
        "wrote {}: {} tracked bodies of {label} against {against}",
        output.display(),
        config.ik_match_table1.len()
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(feature = "mujoco")]
fn check(robot: &str, configs: usize, seed: u64, tolerance: f64) -> anyhow::Result<ExitCode> {
    use mjcf::mujoco_check::{check_file, check_xml_str, CheckOptions};
    // The file as MuJoCo reads it: no floating base added to a model without one.
    let model = match shipped::shipped_xml(robot) {
        Some(_) => shipped::robot_model(robot)?,
        None => mjcf::Model::from_path(std::path::Path::new(robot))?,
    };
    let options = CheckOptions { configs, seed };
    let report = match shipped::shipped_xml(robot) {
        Some(xml) => check_xml_str(&model, xml, robot, options)?,
        None => check_file(&model, std::path::Path::new(robot), options)?,
    };
    let verdict = report.passes(tolerance);
    let mut out = format!("robot: {robot} (ours vs MuJoCo 3.17.0)\n{report}\n");
    let result = if verdict { "PASS" } else { "FAIL" };
    writeln!(
        out,
        "max deviation {:.3e}: {result} (tolerance {tolerance:e})",
        report.max_deviation()
    )?;
    emit(&out)?;
    Ok(if verdict { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

#[cfg(not(feature = "mujoco"))]
fn check(robot: &str, _configs: usize, _seed: u64, _tolerance: f64) -> anyhow::Result<ExitCode> {
    anyhow::bail!("{robot}: `retarget robot check` needs a build with the `mujoco` feature (cargo build -p cli --features mujoco, after scripts/fetch-mujoco)")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `robot info --json`: the roles with their bodies, and frame offsets that turn the
    /// bodies' orientations at `qpos0` into the canonical frames (upright, facing +x).
    #[test]
    fn roles_json_of_the_g1() {
        let model = shipped::robot_model("unitree_g1").unwrap();
        let roles = retarget::RobotRoles::recognise(&model).unwrap();
        let json = roles_json(&model, &roles);
        assert_eq!(json["roles"]["pelvis"]["body"], "pelvis");
        assert_eq!(json["roles"]["left_foot"]["body"], "left_ankle_roll_link");
        assert_eq!(json["soles"]["right"], "right_ankle_roll_link");
        assert!((json["forward"][0].as_f64().unwrap() - 1.0).abs() < 1e-9);
        // The G1's pelvis and torso frames are the canonical ones at qpos0.
        for role in ["pelvis", "chest"] {
            let w = json["roles"][role]["frame_offset"][0].as_f64().unwrap();
            assert!((w.abs() - 1.0).abs() < 1e-6, "{role}: {json}");
        }
    }
}
