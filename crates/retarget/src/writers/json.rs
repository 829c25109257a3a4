//! `.json`: the whole motion, human-readable, one frame per line.
//!
//! ```text
//! {
//!   "format": "retarget-motion", "version": 1,
//!   "robot": "unitree_g1",            // MJCF model name ("" when the file has none)
//!   "conventions": {...},              // frame, units, quaternion order
//!   "fps": 30.0, "nq": 36, "num_frames": T,
//!   "joint_names": [...], "body_names": [...],
//!   "qpos": [[x, y, z, qw, qx, qy, qz, joints...], ...],
//!   "targets": null | {"body_names": [...], "pos": [[[x, y, z], ...], ...],
//!                      "quat": [[[w, x, y, z], ...], ...]}
//! }
//! ```

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::io::Write;

use serde_json::json;

use crate::motion::RobotMotion;

pub(crate) fn write_json<W: Write>(
    out: &mut W,
    motion: &RobotMotion,
    model: &mjcf::Model,
) -> std::io::Result<()> {
    let conventions = json!({
        "up": "z",
        "length": "m",
        "angle": "rad",
        "quaternion": "w x y z",
        "qpos": "MuJoCo layout: free root x y z qw qx qy qz, then joints in MJCF order",
    });
    let head = [
        ("format", json!("retarget-motion")),
        ("version", json!(1)),
        ("robot", json!(model.name)),
        ("conventions", conventions),
        ("fps", json!(motion.fps)),
        ("nq", json!(motion.nq)),
        ("num_frames", json!(motion.num_frames())),
        ("joint_names", json!(motion.joint_names)),
        ("body_names", json!(motion.body_names)),
    ];
    writeln!(out, "{{")?;
    for (key, value) in head {
        writeln!(out, "  \"{key}\": {},", serde_json::to_string(&value)?)?;
    }
    let frames = motion.num_frames();
    write_rows(out, "  ", "qpos", (0..frames).map(|t| serde_json::to_string(motion.frame(t))))?;
    match &motion.targets {
        None => writeln!(out, ",\n  \"targets\": null")?,
        Some(targets) => {
            let k = targets.body_names.len();
            writeln!(out, ",\n  \"targets\": {{")?;
            writeln!(out, "    \"body_names\": {},", serde_json::to_string(&targets.body_names)?)?;
            let pos_rows = (0..frames).map(|t| {
                let row = targets.pos.get(t * k..(t + 1) * k).unwrap_or_default();
                serde_json::to_string(&row.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>())
            });
            write_rows(out, "    ", "pos", pos_rows)?;
            writeln!(out, ",")?;
            let quat_rows = (0..frames).map(|t| {
                let row = targets.quat.get(t * k..(t + 1) * k).unwrap_or_default();
                serde_json::to_string(&row.iter().map(|q| [q.w, q.i, q.j, q.k]).collect::<Vec<_>>())
            });
            write_rows(out, "    ", "quat", quat_rows)?;
            writeln!(out, "\n  }}")?;
        }
    }
    writeln!(out, "}}")?;
    Ok(())
}

/// `<indent>"key": [\n<indent>  row,\n<indent>  row\n<indent>]` (no trailing newline).
fn write_rows<W: Write>(
    out: &mut W,
    indent: &str,
    key: &str,
    rows: impl Iterator<Item = serde_json::Result<String>>,
) -> std::io::Result<()> {
    write!(out, "{indent}\"{key}\": [")?;
    for (i, row) in rows.enumerate() {
        let sep = if i == 0 { "" } else { "," };
        write!(out, "{sep}\n{indent}  {}", row?)?;
    }
    write!(out, "\n{indent}]")?;
    Ok(())
}
