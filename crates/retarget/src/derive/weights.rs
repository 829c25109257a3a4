//! The task weights of a derived config, per part ([`WEIGHTS`]; see the `derive` module
//! docs).

use fk::{Part, Role};
use mjcf::Model;

use crate::robot_roles::RobotRoles;

/// Weights per part (GMR's G1 config's; the feet's position and the upper arms' rotation in
/// table 2 GMR's other configs', see the `derive` module docs): `[table1 pos, table1 rot, table2
/// pos, table2 rot]`.
pub const WEIGHTS: [(Part, [f64; 4]); 8] = [
    (Part::Pelvis, [0.0, 10.0, 100.0, 5.0]),
    (Part::Thigh, [0.0, 10.0, 10.0, 5.0]),
    (Part::Shin, [0.0, 10.0, 10.0, 5.0]),
    (Part::Foot, [100.0, 10.0, 100.0, 10.0]),
    (Part::Chest, [0.0, 100.0, 0.0, 10.0]),
    (Part::UpperArm, [0.0, 100.0, 5.0, 10.0]),
    (Part::Forearm, [0.0, 10.0, 10.0, 5.0]),
    (Part::Hand, [0.0, 10.0, 10.0, 5.0]),
];

/// The weights of `part` ([`WEIGHTS`]). A robot without a chest role (its arms hang from the
/// pelvis body: no waist) tracks its pelvis with the larger of the pelvis's and the chest's
/// weights: that body is its chest too, and with the pelvis's rotation weight (10) against
/// the upper arms' (100) arms that cannot reach their targets tilt the whole robot.
pub(super) fn weights_of(part: Part) -> [f64; 4] {
    WEIGHTS.iter().find(|(q, _)| *q == part).map_or([0.0; 4], |w| w.1)
}

/// Hinges from the chest (else the pelvis) down to the upper arm's body (`role`), included.
pub(super) fn shoulder_hinges(model: &Model, roles: &RobotRoles, role: Role) -> usize {
    let (Some(arm), Some(top)) =
        (roles.body(role), roles.body(Role::Chest).or(roles.body(Role::Pelvis)))
    else {
        return 0;
    };
    let mut count = 0;
    let mut b = arm;
    while b != top && b != 0 {
        let Some(body) = model.bodies.get(b) else { break };
        count += model
            .joints
            .iter()
            .skip(body.jnt_adr)
            .take(body.jnt_num)
            .filter(|j| j.kind == mjcf::JointType::Hinge)
            .count();
        b = body.parent;
    }
    count
}

pub(super) fn weights(part: Part, robot_has_chest: bool) -> [f64; 4] {
    let of = weights_of;
    let own = of(part);
    if part != Part::Pelvis || robot_has_chest {
        return own;
    }
    let chest = of(Part::Chest);
    let mut out = own;
    for (o, c) in out.iter_mut().zip(chest) {
        *o = o.max(c);
    }
    out
}
