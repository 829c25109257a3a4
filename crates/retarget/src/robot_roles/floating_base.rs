//! Rule 0: a model without a free joint gets one at its root, stood up if the file lies
//! (`STAND_UP`) and lifted onto the floor.

// Indexing: body and qpos addresses come from the model.
#![allow(clippy::indexing_slicing)]

use super::*;

/// Turns that may stand a lying model up, tried in this order (identity first): the file's
/// up axis → +z.
const STAND_UP: [(&str, [f64; 3], f64); 6] = [
    ("", [1.0, 0.0, 0.0], 0.0),
    ("+y", [1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2),
    ("-y", [1.0, 0.0, 0.0], -std::f64::consts::FRAC_PI_2),
    ("+x", [0.0, 1.0, 0.0], -std::f64::consts::FRAC_PI_2),
    ("-x", [0.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2),
    ("-z", [1.0, 0.0, 0.0], std::f64::consts::PI),
];

/// Rule 0, before the others: a model without a free joint (an MJCF whose floating base the
/// user's code adds, dm_control style) gets one on its root body ([`Model::root_body`]), the
/// way a URDF gets one on loading. When the file stands along another axis than +z (dm_control's
/// CMU humanoid is Y up), the base's rest pose turns it upright and puts its lowest point on
/// the floor: of the six axis-aligned ups, the first under which [`RobotRoles::recognise`]
/// finds a humanoid standing (+z first). Returns what was done, for the output to say once;
/// `None` when the model had a free joint (or has no jointless root body to put one on).
pub fn add_floating_base(model: &mut Model) -> Option<String> {
    if model.has_free_joint() {
        return None;
    }
    let root = model.root_body()?;
    let body = model.bodies.get(root)?;
    let (pos, quat) = (body.pos, body.quat);
    let mut first = None;
    for (up, axis, angle) in STAND_UP {
        let turn =
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis.into()), angle);
        let mut candidate = model.clone();
        let base = candidate.add_floating_base(turn * pos, turn * quat)?;
        if !up.is_empty() {
            lift_to_floor(&mut candidate, base.body);
        }
        let recognised = RobotRoles::recognise(&candidate).is_ok();
        let stood = if up.is_empty() {
            String::new()
        } else {
            format!(", turned so that the file's {up} is up (the model lies at qpos0)")
        };
        let note = format!(
            "`{}` has no free joint: a floating base `{}` was added at body `{}` for \
             retargeting{stood}",
            model.name,
            base.joint,
            body_name(model, base.body)
        );
        if recognised {
            *model = candidate;
            return Some(note);
        }
        first.get_or_insert((candidate, note));
    }
    let (candidate, note) = first?;
    *model = candidate;
    Some(note)
}

/// Moves the free body `body` up or down so that the model's lowest point (geoms, else body
/// origins) is at z = 0 at `qpos0`.
fn lift_to_floor(model: &mut Model, body: usize) {
    let mut data = Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let mut low = f64::INFINITY;
    for g in (0..model.geoms.len()).filter(|&g| model.geoms[g].body != 0) {
        if let Some(p) = mjcf::geom_lowest_point(model, &data, g) {
            low = low.min(p.z);
        }
    }
    if !low.is_finite() {
        low = data.xpos.iter().skip(1).map(|p| p.z).fold(f64::INFINITY, f64::min);
    }
    let Some(joint) = model.joints.iter().find(|j| j.body == body && j.kind == JointType::Free)
    else {
        return;
    };
    let adr = joint.qpos_adr + 2;
    if let (true, Some(z)) = (low.is_finite(), model.qpos0.get_mut(adr)) {
        *z -= low;
        model.bodies[body].pos.z -= low;
    }
}
