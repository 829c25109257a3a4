//! Which bodies are the robot's feet ([`detect_feet`]): what the foot plan plants and the
//! quality report measures.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: body and geom ids come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::Model;

use crate::error::Error;
use crate::robot_roles::RobotRoles;

/// The two foot bodies `[left, right]` of `model`: `left_ankle_roll_link` /
/// `right_ankle_roll_link` if the model has them; else the bodies of the geoms named
/// `left_sole` / `right_sole`; else on each side the lowest body (at `qpos0`) whose name has
/// `ankle` or `foot` and a side marker (`left`, `l_`, `_l`; `right`, `r_`, `_r`), or the robot
/// recogniser's ([`RobotRoles`]) sole where that is below the named body; else the
/// recogniser's feet.
pub fn detect_feet(model: &Model) -> Result<[usize; 2], Error> {
    if let (Some(l), Some(r)) =
        (model.body_id("left_ankle_roll_link"), model.body_id("right_ankle_roll_link"))
    {
        return Ok([l, r]);
    }
    // The robots in `robots/` mark their soles with geoms named `left_sole` / `right_sole`.
    if let (Some(l), Some(r)) = (model.geom_id("left_sole"), model.geom_id("right_sole")) {
        return Ok([model.geoms[l].body, model.geoms[r].body]);
    }
    let mut data = mjcf::Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let side = |markers: [&str; 3], prefix: &str| {
        let candidates = model.bodies.iter().enumerate().skip(1).filter(|(_, b)| {
            let n = b.name.to_ascii_lowercase();
            (n.contains("ankle") || n.contains("foot"))
                && (n.contains(markers[0])
                    || n.starts_with(prefix)
                    || n.contains(markers[1])
                    || n.ends_with(markers[2]))
        });
        // Lowest at qpos0; the later (deeper) body on ties.
        candidates
            .map(|(i, _)| i)
            .min_by(|&a, &b| data.xpos[a].z.total_cmp(&data.xpos[b].z).then(b.cmp(&a)))
    };
    let recognised = RobotRoles::recognise(model).map(|roles| roles.soles.map(|s| s.body));
    match (side(["left", "_l_", "_l"], "l_"), side(["right", "_r_", "_r"], "r_"), recognised) {
        // A named body above the recognised foot is an ankle link between the shin and the
        // foot (Adam Lite's `anklePitchLeft`, over its `toeLeft`): the foot is the recognised
        // one. (Planting that ankle link planted the shin, its tracked ancestor.)
        (Some(l), Some(r), Ok([rl, rr])) if l != r => {
            let foot = |named: usize, found: usize| {
                if model.is_ancestor_or_self(named, found) {
                    found
                } else {
                    named
                }
            };
            Ok([foot(l, rl), foot(r, rr)])
        }
        (Some(l), Some(r), Err(_)) if l != r => Ok([l, r]),
        // Names say nothing: the robot recogniser's feet (tree and geometry).
        (_, _, Ok(found)) => Ok(found),
        (_, _, Err(e)) => Err(Error::NoFeet { reason: e.to_string() }),
    }
}
