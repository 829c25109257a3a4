//! Position offsets fitted to the motion: the robot copying the human's posture
//! ([`copy_error`]), averaged ([`fitted_offset`]), and the feet's sole fit ([`sole_fit`]).

use fk::{Part, Role, Side};
use nalgebra::{UnitQuaternion, Vector3};

use super::human::{HumanBody, Posture, FLAT_FOOT, POSE_CHAINS};
use super::robot::{sole_low, RobotSide, SoleGeom};

/// The position offset (in the target frame) that best puts `role`'s target where the robot
/// body is when the robot copies the human's body frames (see the `derive` module docs): averaged
/// over the human's postures, `M⁻¹ C_h⁻¹ (x_robot − p_target)`, where the robot's role points
/// hang from its pelvis point (put at the scaled hip midpoint) along its own segments turned
/// by the human's canonical frames (knees and elbows held in their ranges), the body origin
/// `origin` from its role point, and `p_target` is GMR's scaling of the human joint (root
/// by `root_scale` about the origin, the joint by `scale` about the root) with the human's
/// floor moved to the robot's. `relative` is `M`, the target frame's rotation from the
/// human's canonical frame. `None` when no posture has the frames needed.
#[allow(clippy::too_many_arguments)]
pub(super) fn fitted_offset(
    robot: &RobotSide,
    human: &HumanBody,
    role: Role,
    origin: Vector3<f64>,
    relative: UnitQuaternion<f64>,
    root_scale: f64,
    scale: f64,
) -> Option<Vector3<f64>> {
    // A foot's offset is fitted where it matters most and the copy is straightest: the
    // postures with that foot flat on the floor (its ankle within 3 cm of its flat height),
    // when there are any.
    let planted = |p: &Posture| {
        p.points.get(&role).is_some_and(|a| a.z - human.ground < human.ankle + FLAT_FOOT)
    };
    let foot = role.part() == Part::Foot && human.postures.iter().any(planted);
    let mut sum = Vector3::zeros();
    let mut count = 0usize;
    for posture in human.postures.iter().filter(|p| !foot || planted(p)) {
        if let Some(v) = copy_error(robot, posture, role, origin, root_scale, scale, human.ground) {
            sum += v;
            count += 1;
        }
    }
    if count == 0 {
        return None;
    }
    let mut fit = sum / count as f64;
    if let (true, Some(geoms)) = (role.part() == Part::Foot, robot.soles.get(&role)) {
        fit = sole_fit(geoms, human, role, root_scale, scale, fit).unwrap_or(fit);
    }
    Some(relative.inverse() * fit)
}

/// The offset of a foot (in its canonical frame) that puts the robot's sole on the floor wherever
/// the human's foot touches it ([`Posture::feet_down`]: flat, on the heel, on the ball), with the
/// foot turned as the human's: least squares over those postures of the sole's lowest point's
/// height above [`SOLE_CLEARANCE`], `a + (C_h o)_z + low(C_h)` with `a` the target's height (GMR's
/// scaling of the ankle: the root by `root_scale` about the origin, the ankle by `scale` about the
/// root). Flat postures fix the height; the postures on the heel or the ball fix how far forward
/// the body sits (a robot sole longer than the scaled human foot is moved back, so that its toe
/// does not dig in when the human rolls onto the ball). The forward offset stays near `prior`
/// (the copy fit) where the postures do not decide it: a shift costs as much as the same height
/// error in [`SOLE_PRIOR`] of the postures. The sideways offset is the copy fit's: a human
/// foot rolls sideways by a few degrees, mostly noise, and fitting the sole's height to those
/// rolls moved the feet up to 5 cm sideways (the scaled LAFAN1 walk's feet 134 mm apart on
/// the N1, whose feet stand 240 mm apart; the copy fit gives 222), which the default solve's
/// planted feet then pushed back apart (`keep_feet_apart`).
fn sole_fit(
    geoms: &[SoleGeom],
    human: &HumanBody,
    role: Role,
    root_scale: f64,
    scale: f64,
    prior: Vector3<f64>,
) -> Option<Vector3<f64>> {
    let k = usize::from(role.side() == Some(Side::Right));
    // Unknowns: the forward (x) and height (z) offsets; y is the prior's.
    let mut normal = nalgebra::Matrix2::zeros();
    let mut rhs = nalgebra::Vector2::zeros();
    let mut n = 0usize;
    for posture in human.postures.iter().filter(|p| p.feet_down.get(k) == Some(&true)) {
        let (Some(pelvis), Some(ankle), Some(frame)) = (
            posture.points.get(&Role::Pelvis),
            posture.points.get(&role),
            posture.frames.get(&role),
        ) else {
            continue;
        };
        let a = root_scale * pelvis.z + (ankle.z - pelvis.z) * scale;
        let low = sole_low(geoms, frame);
        let r = frame.inverse() * Vector3::z();
        if !(a + low).is_finite() {
            continue;
        }
        let rxz = nalgebra::Vector2::new(r.x, r.z);
        normal += rxz * rxz.transpose();
        rhs -= rxz * (a + low - SOLE_CLEARANCE + r.y * prior.y);
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let w = SOLE_PRIOR * n as f64;
    normal += nalgebra::Matrix2::new(w, 0.0, 0.0, 0.0);
    rhs.x += w * prior.x;
    let xz = normal.try_inverse()? * rhs;
    let fit = Vector3::new(xz.x, prior.y, xz.y);
    fit.iter().all(|v| v.is_finite()).then_some(fit)
}

/// Height (m) of the sole's lowest point above the floor that the foot offsets are fitted
/// to, the same for every robot. GMR's solve has no floor: a sole fitted to z = 0 is below it
/// in about half of the frames, more than 1 cm (the report's penetration) where a rigid sole
/// cannot follow the human's heel strike and toe-off. Measured on the five robots with GMR
/// configs and both LAFAN1 takes (`scripts/compare-configs`): 3 mm takes 2.2 to 3.7 points
/// off the frames with a geom more than 1 cm in the floor in GMR's solve (G1 walk 8.4 →
/// 6.1 %, ToddlerBot walk 7.2 → 4.4 %), while stance samples more than 2 cm above the floor
/// stay fewer than with GMR's configs (at most 1.0 %); the report's sliding share moves by
/// −1.4 to +0.6 points; 6 mm and 1 cm take penetration down further (G1 walk 4.4, 3.0 %)
/// and raise the sliding share of every walk (16.9 → 17.6 → 18.4 %). The default solve
/// moves every target onto its floor (`feet`): there the errors move by at most
/// 1 mm and the sliding share by at most 0.3 points.
pub const SOLE_CLEARANCE: f64 = 0.003;

/// Weight of the copy fit's forward foot offset in [`sole_fit`], as a share of the postures.
const SOLE_PRIOR: f64 = 0.001;

/// One posture's `C_h⁻¹ (x_robot − p_target)` for [`fitted_offset`].
fn copy_error(
    robot: &RobotSide,
    posture: &Posture,
    role: Role,
    origin: Vector3<f64>,
    root_scale: f64,
    scale: f64,
    ground: f64,
) -> Option<Vector3<f64>> {
    let (points, human) = (&posture.points, &posture.frames);
    let mid = (points.get(&Role::LeftThigh)? + points.get(&Role::RightThigh)?) / 2.0;
    let pelvis = points.get(&Role::Pelvis)?;
    let target = (pelvis - mid) * root_scale
        + (points.get(&role)? - pelvis) * scale
        + Vector3::z() * (root_scale * ground);
    // The robot's frames: the human's, knees and elbows turned back into their ranges; per
    // role of the chains so far, where its segment ends and its frame (at most 17 roles).
    let mut posed: Vec<(Role, Vector3<f64>, UnitQuaternion<f64>)> =
        Vec::with_capacity(POSE_CHAINS.len());
    let find = |posed: &[(Role, Vector3<f64>, UnitQuaternion<f64>)], r: Role| {
        posed.iter().find(|p| p.0 == r).map(|&(_, end, frame)| (end, frame))
    };
    for (r, _) in POSE_CHAINS {
        let Some((from, v)) = robot.segments.get(&r) else { continue };
        let Some(c) = human.get(&r) else { continue };
        let (start, turn) = match from {
            Some(a) => find(&posed, *a)?,
            None => (Vector3::zeros(), *human.get(&Role::Pelvis)?),
        };
        let end = start + turn * v;
        let frame = match (robot.hinges.get(&r), from) {
            (Some(h), Some(_)) => turn * h.clamp(turn.inverse() * c),
            _ => *c,
        };
        posed.push((r, end, frame));
        if r == role {
            break;
        }
    }
    let own = human.get(&role)?;
    // A foot or hand keeps the human's frame (the ankle or wrist makes up for a bent knee or
    // elbow); a shin or forearm turns with its hinge.
    let (end, frame) = find(&posed, role)?;
    let body = end + frame * origin;
    Some(own.inverse() * (body - target))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A human foot that stands flat, then rolls onto its ball (a pivot `l` ahead of the
    /// ankle and `h` below it): the robot's sole (a box reaching past the pivot) must end
    /// up with its front bottom edge at the pivot, which is on the floor in every posture
    /// (the edge [`SOLE_CLEARANCE`] above it).
    #[test]
    fn the_sole_fit_puts_the_sole_on_the_floor_when_the_foot_rolls_onto_its_ball() {
        let (l, h) = (0.09, 0.07);
        let sole = SoleGeom {
            kind: mjcf::GeomType::Box,
            size: [0.1, 0.04, 0.01],
            pos: Vector3::new(0.03, 0.0, -0.03),
            rot: UnitQuaternion::identity(),
        };
        let mut human = HumanBody::canonical();
        human.postures = [0.0f64, 5.0, 10.0, 20.0, 30.0, 40.0]
            .iter()
            .map(|deg| {
                // Toe down: a turn about +y; the ankle rises about the pivot on the floor.
                let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
                let ankle = Vector3::new(0.0, 0.1, 0.0) - q * Vector3::new(l, 0.0, -h);
                let points = [(Role::Pelvis, Vector3::new(0.0, 0.0, 0.9)), (Role::LeftFoot, ankle)]
                    .into_iter()
                    .collect();
                let frames = [(Role::LeftFoot, q)].into_iter().collect();
                Posture { points, frames, feet_down: [true, false] }
            })
            .collect();
        let prior = Vector3::new(0.05, 0.01, 0.0);
        let fit = sole_fit(&[sole], &human, Role::LeftFoot, 1.0, 1.0, prior).unwrap();
        // Body origin + front bottom edge (0.13, ·, −0.04) = pivot (l, ·, −h) from the ankle,
        // SOLE_CLEARANCE above it (to a few mm: the prior, 9 cm off, still pulls a little).
        assert!((fit.x - (l - 0.13)).abs() < 3e-3, "{fit:?}");
        assert!((fit.z - (-h + 0.04 + SOLE_CLEARANCE)).abs() < 1e-3, "{fit:?}");
        // Tilts say nothing about the sideways offset: the prior's.
        assert!((fit.y - prior.y).abs() < 1e-9, "{fit:?}");
        // The right foot never touches: no fit.
        assert!(sole_fit(&[sole], &human, Role::RightFoot, 1.0, 1.0, prior).is_none());
    }
}
