//! Unitree's LAFAN1-retargeting CSV (the layout of `unitreerobotics/LAFAN1_Retargeting_Dataset`):
//! no header, one frame per line, comma-separated: root `x, y, z` (m), root quaternion
//! `qx, qy, qz, qw`, then every other `qpos` entry in MJCF order. Numbers are the shortest
//! strings that parse back to the same `f64` (ryu).

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::io::Write;

use super::derived::{body_poses, BodyPoses};
use super::root::{root_nq, root_pose, xyzw_from_wxyz};
use crate::motion::RobotMotion;

pub(crate) fn write_csv<W: Write>(
    out: &mut W,
    motion: &RobotMotion,
    model: &mjcf::Model,
) -> std::io::Result<()> {
    let skip = root_nq(model);
    // The root comes from qpos for a free-floating model; FK is needed only without one.
    let poses = if skip == 7 {
        BodyPoses { bodies: 0, pos: Vec::new(), quat: Vec::new() }
    } else {
        body_poses(motion, model)
    };
    let mut buf = ryu::Buffer::new();
    let mut line = String::new();
    for t in 0..motion.num_frames() {
        line.clear();
        let (pos, wxyz) = root_pose(motion, model, &poses, t);
        let xyzw = xyzw_from_wxyz(wxyz);
        let values = pos.iter().chain(&xyzw).chain(motion.frame(t).get(skip..).unwrap_or_default());
        for (i, v) in values.enumerate() {
            if i > 0 {
                line.push(',');
            }
            line.push_str(buf.format(*v));
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}
