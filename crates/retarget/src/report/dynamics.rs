//! The dynamics check: per frame, can non-negative contact forces inside friction cones at
//! the robot's points on the floor supply the wrench its motion needs? (Definitions in the
//! [`crate::report`] module documentation.)

// Exception to `indexing_slicing`, as in `report`: the motion was checked against the model
// (`check_motion`), so frame, body and geom indices come from them; per-frame arrays are
// sized from the same frame and point counts.
#![allow(clippy::indexing_slicing)]

use nalgebra::{UnitQuaternion, Vector2, Vector3};
use serde::Serialize;

use super::rates::GRAVITY;
use super::stats::{ratio, stats, Stats};
pub use crate::centroidal::half_step;
use crate::centroidal::{bottom_points, cone_edges, lever, mass_bodies, nnls, Column, MassBody};
use crate::motion::RobotMotion;
use crate::writers::BodyPoses;

/// Tunables of the dynamics check ([`super::ReportOptions::dynamics`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DynamicsCheckOptions {
    /// A collision geom's bottom point within this height of the ground is a contact (m).
    /// Default 0.01.
    pub contact_height: f64,
    /// Friction coefficient of every contact. Default 0.8.
    pub friction: f64,
    /// Edges of the pyramid inscribed in each friction cone (at least 3). Default 8.
    pub cone_edges: usize,
    /// A frame needs too much extra wrench above this (m·g). Default 0.1.
    pub threshold: f64,
    /// The centre of pressure counts as outside the support polygon beyond this (m).
    /// Default 0.01.
    pub cop_tolerance: f64,
    /// The time the averaged accelerations read (s): velocities and their rates are central
    /// differences over `h` frames, `h = max(1, round(fps · span / 4))` ([`half_step`]), so
    /// the centre of mass's acceleration reads the `4h + 1` frames of about `span` around a
    /// frame whatever the clip's rate (5 frames at 30 fps, 21 at 120). Default 1/6 s.
    pub span: f64,
}

impl Default for DynamicsCheckOptions {
    fn default() -> Self {
        DynamicsCheckOptions {
            contact_height: 0.01,
            friction: 0.8,
            cone_edges: 8,
            threshold: 0.1,
            cop_tolerance: 0.01,
            span: 1.0 / 6.0,
        }
    }
}

/// The dynamics check of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameDynamics {
    pub frame: usize,
    /// Contact points (bottom points within the contact height in this frame or the next or
    /// previous one).
    pub contacts: usize,
    /// The wrench the motion needs: force `m (c̈ − g)` (N) and torque `L̇_c` about the centre
    /// of mass (N m).
    pub force: [f64; 3],
    pub torque: [f64; 3],
    /// The residual wrench no contact force supplies: `√(|f|² + (|τ|/L)²)` in m·g, and its
    /// force (m·g) and torque (m·g·L) parts.
    pub residual: f64,
    pub residual_force: f64,
    pub residual_torque: f64,
    /// Distance of the centre of pressure outside the support polygon (m, 0 inside); `None`
    /// without contacts or when the needed force pushes up by less than the threshold.
    pub cop_outside: Option<f64>,
}

/// The centre of pressure against the support polygon, over support frames.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CentreOfPressure {
    /// Support frames whose needed force pushes up by the threshold or more (below it the
    /// CoP is ill-defined: it runs off to infinity as the vertical force goes to 0).
    pub frames: usize,
    /// Distance outside the support polygon (cm; 0 inside).
    pub outside_cm: Stats,
    /// [`DynamicsCheckOptions::cop_tolerance`] (cm).
    pub tolerance_cm: f64,
    /// Frames with the CoP outside by more than the tolerance, and their share of `frames`.
    pub frames_outside: usize,
    pub share_outside: f64,
}

/// Frames without any contact: the motion should need no wrench at all (a ballistic COM).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flight {
    pub frames: usize,
    /// The needed wrench, which is all residual (m·g).
    pub residual_mg: Stats,
    /// Flight frames over [`DynamicsCheckOptions::threshold`], and their share of `frames`.
    pub frames_over: usize,
    pub share_over: f64,
}

/// The dynamics check over the clip.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Dynamics {
    /// Total mass (kg).
    pub mass_kg: f64,
    /// The torque unit's length `L` (m): the centre of mass's height above the lowest
    /// collision point at `qpos0`.
    pub lever_m: f64,
    pub friction: f64,
    pub cone_edges: usize,
    /// [`DynamicsCheckOptions::contact_height`] (cm).
    pub contact_height_cm: f64,
    /// [`DynamicsCheckOptions::threshold`] (m·g).
    pub threshold_mg: f64,
    /// The half step `h` of the averaged accelerations (frames; [`half_step`]) and the time
    /// they read, `4h / fps` (s): 1 and 0.133 s at 30 fps, 5 and 0.167 s at 120 fps.
    pub half_step_frames: usize,
    pub window_s: f64,
    /// Frames checked: every frame `2h` away from the ends.
    pub frames: usize,
    /// Residual wrench (m·g) over the checked frames; its force (m·g) and torque (m·g·L)
    /// parts.
    pub residual_mg: Stats,
    pub residual_force_mg: Stats,
    pub residual_torque_mgl: Stats,
    /// Checked frames over the threshold, and their share.
    pub frames_over: usize,
    pub share_over: f64,
    /// Checked frames with a contact, and those over the threshold.
    pub support_frames: usize,
    pub support_frames_over: usize,
    pub support_share_over: f64,
    pub cop: CentreOfPressure,
    pub flight: Flight,
}

/// Every collision geom's candidate points in frame `t`.
fn frame_points(
    model: &mjcf::Model,
    poses: &BodyPoses,
    geoms: &[usize],
    t: usize,
    out: &mut Vec<Vector3<f64>>,
) {
    out.clear();
    for &g in geoms {
        let geom = &model.geoms[g];
        let (p, q) = (poses.pos(t, geom.body - 1), poses.quat(t, geom.body - 1));
        let c = p + q * geom.pos;
        let r = (q * geom.quat).to_rotation_matrix().into_inner();
        bottom_points(geom.kind, &geom.size, &c, &r, out);
    }
}

/// World centre of mass of every mass body in every frame, `[t * n + i]`, and the total.
fn centres(
    bodies: &[MassBody],
    poses: &BodyPoses,
    frames: usize,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let mass: f64 = bodies.iter().map(|b| b.inertial.mass).sum();
    let mut each = Vec::with_capacity(frames * bodies.len());
    let mut com = Vec::with_capacity(frames);
    for t in 0..frames {
        let mut sum = Vector3::zeros();
        for b in bodies {
            let x = poses.pos(t, b.pose) + poses.quat(t, b.pose) * b.inertial.pos;
            sum += x * b.inertial.mass;
            each.push(x);
        }
        com.push(sum / mass);
    }
    (each, com)
}

/// Centroidal angular momentum at frame t (h ≤ t ≤ T − 1 − h) from central differences over
/// `h` frames: `Σ m_i (x_i − c) × ẋ_i + R_i I_i R_iᵀ ω_i`.
fn angular_momentum(
    bodies: &[MassBody],
    poses: &BodyPoses,
    each: &[Vector3<f64>],
    com: &Vector3<f64>,
    (t, h): (usize, usize),
    fps: f64,
) -> Vector3<f64> {
    let n = bodies.len();
    let rate = fps / (2 * h) as f64;
    let mut l = Vector3::zeros();
    for (i, b) in bodies.iter().enumerate() {
        let m = b.inertial.mass;
        let v = (each[(t + h) * n + i] - each[(t - h) * n + i]) * rate;
        let (q0, q1) = (poses.quat(t - h, b.pose), poses.quat(t + h, b.pose));
        // World angular velocity: q(t+h) = exp(ω 2hΔt) q(t−h).
        let w = (q1 * q0.inverse()).scaled_axis() * rate;
        let rot: UnitQuaternion<f64> = poses.quat(t, b.pose) * b.inertial.quat;
        let local = rot.inverse() * w;
        let spin = rot * local.component_mul(&b.inertial.diag);
        l += (each[t * n + i] - com).cross(&v) * m + spin;
    }
    l
}

/// The per-frame checks with the total mass (kg), the torque unit's length `L` (m) and the
/// half step `h` (frames).
pub(super) struct Checked {
    pub frames: Vec<FrameDynamics>,
    pub mass: f64,
    pub lever: f64,
    pub half_step: usize,
    pub fps: f64,
}

/// Per checked frame (2h ≤ t ≤ T − 1 − 2h), the dynamics check with accelerations averaged
/// over the half step `h` (frames; `None`: [`half_step`] of the clip's rate and
/// [`DynamicsCheckOptions::span`]; `Some(1)`: the 5-frame figure); or why the model's masses are
/// not known. `ground` is the floor's height.
pub(super) fn check(
    motion: &RobotMotion,
    model: &mjcf::Model,
    poses: &BodyPoses,
    ground: f64,
    opts: &DynamicsCheckOptions,
    half: Option<usize>,
) -> Result<Checked, String> {
    let bodies = mass_bodies(model)?;
    let mass: f64 = bodies.iter().map(|b| b.inertial.mass).sum();
    let geoms = crate::constraints::collision_primitives(model);
    let lever = lever(model, &bodies, &geoms);
    let (frames, fps) = (motion.num_frames(), motion.fps);
    let h = half.unwrap_or_else(|| half_step(fps, opts.span)).max(1);
    if frames < 4 * h + 1 {
        return Ok(Checked { frames: Vec::new(), mass, lever, half_step: h, fps });
    }
    let (each, com) = centres(&bodies, poses, frames);
    let momentum: Vec<Vector3<f64>> = (0..frames)
        .map(|t| {
            if t < h || t + h >= frames {
                Vector3::zeros()
            } else {
                angular_momentum(&bodies, poses, &each, &com[t], (t, h), fps)
            }
        })
        .collect();
    // Which candidate points are near the floor in each frame.
    let mut points = Vec::new();
    let mut near: Vec<bool> = Vec::new();
    for t in 0..frames {
        frame_points(model, poses, &geoms, t, &mut points);
        near.extend(points.iter().map(|p| p.z - ground < opts.contact_height));
    }
    let count = points.len();
    let weight = mass * GRAVITY;
    let edges = cone_edges(opts.friction, opts.cone_edges.max(3));
    let (mut cols, mut x, mut contact) = (Vec::<Column>::new(), Vec::new(), Vec::new());
    let mut out = Vec::with_capacity(frames - 4 * h);
    let span = (2 * h) as f64;
    for t in 2 * h..frames - 2 * h {
        let c = com[t];
        let acc = (com[t + 2 * h] - com[t] * 2.0 + com[t - 2 * h]) * (fps * fps / (span * span));
        let force = (acc + Vector3::z() * GRAVITY) * mass;
        let torque = (momentum[t + h] - momentum[t - h]) * (fps / span);
        frame_points(model, poses, &geoms, t, &mut points);
        contact.clear();
        contact.extend(
            (0..count).filter(|&k| (t - h..=t + h).any(|s| near[s * count + k])).map(|k| points[k]),
        );
        let f = force / weight;
        let b: Column = [
            f.x,
            f.y,
            f.z,
            torque.x / (weight * lever),
            torque.y / (weight * lever),
            torque.z / (weight * lever),
        ];
        cols.clear();
        for p in &contact {
            let arm = (p - c) / lever;
            cols.extend(edges.iter().map(|d| {
                let m = arm.cross(d);
                [d.x, d.y, d.z, m.x, m.y, m.z]
            }));
        }
        let r = if cols.is_empty() { b } else { nnls(&cols, &b, &mut x) };
        let rf = Vector3::new(r[0], r[1], r[2]).norm();
        let rt = Vector3::new(r[3], r[4], r[5]).norm();
        let cop_outside = (!contact.is_empty() && force.z > opts.threshold * weight)
            .then(|| cop_distance(&c, &force, &torque, ground, &contact));
        out.push(FrameDynamics {
            frame: t,
            contacts: contact.len(),
            force: force.into(),
            torque: torque.into(),
            residual: rf.hypot(rt),
            residual_force: rf,
            residual_torque: rt,
            cop_outside,
        });
    }
    Ok(Checked { frames: out, mass, lever, half_step: h, fps })
}

/// The needed wrench's zero-moment point on the floor (the point about which its moment has
/// no horizontal part) and its distance outside the convex hull of the contact points, seen
/// from above.
fn cop_distance(
    c: &Vector3<f64>,
    force: &Vector3<f64>,
    torque: &Vector3<f64>,
    ground: f64,
    contact: &[Vector3<f64>],
) -> f64 {
    let dz = c.z - ground;
    let zmp = Vector2::new(
        c.x - (torque.y + dz * force.x) / force.z,
        c.y - (dz * force.y - torque.x) / force.z,
    );
    let hull = convex_hull(contact.iter().map(|p| p.xy()).collect());
    outside(&hull, &zmp)
}

/// Andrew's monotone chain: the hull counter-clockwise, without collinear points.
fn convex_hull(mut p: Vec<Vector2<f64>>) -> Vec<Vector2<f64>> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
    if p.len() < 3 {
        return p;
    }
    let cross = |o: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Vector2<f64>> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &Vector2<f64>>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for q in ordered {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(*q);
        }
        hull.pop();
    }
    hull
}

/// Distance of `p` outside a convex polygon (counter-clockwise; a point or segment when
/// shorter), 0 inside.
fn outside(hull: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
    let segment = |a: &Vector2<f64>, b: &Vector2<f64>| {
        let d = b - a;
        let s = if d.norm_squared() > 0.0 {
            ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + d * s - p).norm()
    };
    match hull {
        [] => 0.0,
        [a] => (a - p).norm(),
        [a, b] => segment(a, b),
        _ => {
            let n = hull.len();
            let inside = (0..n).all(|i| {
                let (a, b) = (&hull[i], &hull[(i + 1) % n]);
                (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) >= 0.0
            });
            if inside {
                0.0
            } else {
                (0..n).map(|i| segment(&hull[i], &hull[(i + 1) % n])).fold(f64::INFINITY, f64::min)
            }
        }
    }
}

/// The dynamics section of the report from the per-frame checks.
pub(super) fn summarise(checked: &Checked, opts: &DynamicsCheckOptions) -> Dynamics {
    let Checked { frames, mass, lever, half_step, fps } = checked;
    let (mass, lever) = (*mass, *lever);
    let pick = |f: fn(&FrameDynamics) -> f64, keep: fn(&FrameDynamics) -> bool| -> Vec<f64> {
        frames.iter().filter(|d| keep(d)).map(f).collect()
    };
    let residual = pick(|d| d.residual, |_| true);
    let over = |x: &[f64]| x.iter().filter(|r| **r > opts.threshold).count();
    let support = pick(|d| d.residual, |d| d.contacts > 0);
    let flight = pick(|d| d.residual, |d| d.contacts == 0);
    let cop: Vec<f64> = frames.iter().filter_map(|d| d.cop_outside).map(|m| m * 100.0).collect();
    let cop_out = cop.iter().filter(|d| **d > opts.cop_tolerance * 100.0).count();
    Dynamics {
        mass_kg: mass,
        lever_m: lever,
        friction: opts.friction,
        cone_edges: opts.cone_edges.max(3),
        contact_height_cm: opts.contact_height * 100.0,
        threshold_mg: opts.threshold,
        half_step_frames: *half_step,
        window_s: (4 * half_step) as f64 / fps,
        frames: frames.len(),
        residual_mg: stats(&residual),
        residual_force_mg: stats(&pick(|d| d.residual_force, |_| true)),
        residual_torque_mgl: stats(&pick(|d| d.residual_torque, |_| true)),
        frames_over: over(&residual),
        share_over: ratio(over(&residual), residual.len()),
        support_frames: support.len(),
        support_frames_over: over(&support),
        support_share_over: ratio(over(&support), support.len()),
        cop: CentreOfPressure {
            frames: cop.len(),
            outside_cm: stats(&cop),
            tolerance_cm: opts.cop_tolerance * 100.0,
            frames_outside: cop_out,
            share_outside: ratio(cop_out, cop.len()),
        },
        flight: Flight {
            frames: flight.len(),
            residual_mg: stats(&flight),
            frames_over: over(&flight),
            share_over: ratio(over(&flight), flight.len()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_and_distance_outside() {
        let square = convex_hull(vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.5, 0.5),
            Vector2::new(1.0, 1.0),
            Vector2::new(0.0, 1.0),
        ]);
        assert_eq!(square.len(), 4, "{square:?}");
        assert_eq!(outside(&square, &Vector2::new(0.3, 0.7)), 0.0);
        assert!((outside(&square, &Vector2::new(1.5, 0.5)) - 0.5).abs() < 1e-12);
        assert!((outside(&square, &Vector2::new(2.0, 2.0)) - 2f64.sqrt()).abs() < 1e-12);
        let bar = convex_hull(vec![Vector2::new(0.0, 0.0), Vector2::new(2.0, 0.0)]);
        assert!((outside(&bar, &Vector2::new(1.0, 0.25)) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn cone_edges_lie_on_the_cone() {
        for d in cone_edges(0.8, 8) {
            assert!((d.xy().norm() / d.z - 0.8).abs() < 1e-12);
        }
    }
}
