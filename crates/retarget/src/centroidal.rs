//! The centroidal vocabulary the dynamics check ([`crate::report`]) and the default solve's
//! dynamics term ([`crate::solve`]) share: the bodies with mass, the candidate contact points
//! of a collision geom, the friction cone's edges, the torque unit's length and the
//! non-negative least squares that asks which part of a wrench the contacts can supply.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: body ids come from the model.
#![allow(clippy::indexing_slicing)]

use nalgebra::{Matrix3, Vector3};

mod nnls;

pub(crate) use nnls::{nnls, Column};

/// Standard gravity (m/s²).
pub const GRAVITY: f64 = 9.81;

/// The half step `h` (frames) of accelerations averaged over `span` seconds at `fps`:
/// `max(1, round(fps · span / 4))`. The dynamics check reads the centre of mass's
/// acceleration over the `4h + 1` frames around a frame and counts the contacts of the
/// `2h + 1` middle ones ([`crate::report::DynamicsCheckOptions::span`]); the solve's
/// dynamics term counts the same contacts ([`crate::DynamicsOptions::span`]).
#[must_use]
pub fn half_step(fps: f64, span: f64) -> usize {
    let h = (fps * span / 4.0).round();
    if h.is_finite() && h >= 1.0 {
        h as usize
    } else {
        1
    }
}

/// A body with mass: its pose index (MuJoCo body − 1) and inertial.
#[derive(Debug, Clone)]
pub(crate) struct MassBody {
    pub pose: usize,
    pub inertial: mjcf::Inertial,
}

/// The bodies with mass, or why the model's masses are not known: a body with geoms but no
/// `<inertial>` would get its mass from its geoms in MuJoCo, which `mjcf` does not compute.
pub(crate) fn mass_bodies(model: &mjcf::Model) -> Result<Vec<MassBody>, String> {
    let mut out = Vec::new();
    for (b, body) in model.bodies.iter().enumerate().skip(1) {
        match body.inertial {
            Some(inertial) if inertial.mass > 0.0 => out.push(MassBody { pose: b - 1, inertial }),
            Some(_) => {}
            None if model.geoms.iter().any(|g| g.body == b) => {
                return Err(format!(
                    "body \"{}\" has geoms but no inertial (MuJoCo would take its mass from \
                     the geoms, which the model reader does not)",
                    body.name
                ))
            }
            None => {}
        }
    }
    if out.is_empty() {
        return Err("no body of the model has a mass".to_owned());
    }
    Ok(out)
}

/// The candidate contact points of one collision geom in the world, in a fixed order (the
/// same count in every frame): a sphere's bottom, a capsule's bottom at each end, a box's
/// eight corners, a cylinder's lowest rim point and four rim points (along its x and y) on
/// each cap, an ellipsoid's bottom.
pub(crate) fn bottom_points(
    kind: mjcf::GeomType,
    size: &[f64; 3],
    c: &Vector3<f64>,
    r: &Matrix3<f64>,
    out: &mut Vec<Vector3<f64>>,
) {
    let [a, b, h] = *size;
    let axis = r.column(2).into_owned();
    let down = Vector3::z();
    match kind {
        mjcf::GeomType::Sphere => out.push(c - down * a),
        mjcf::GeomType::Capsule => out.extend([-1.0, 1.0].map(|e| c + axis * (e * b) - down * a)),
        mjcf::GeomType::Box => out.extend((0..8).map(|k| {
            let s = |bit: usize| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
            c + r * Vector3::new(s(0) * a, s(1) * b, s(2) * h)
        })),
        mjcf::GeomType::Cylinder => {
            // The rim's lowest point: −z projected onto the cap's plane, scaled to the radius.
            let across = (-down + axis * axis.z).try_normalize(1e-9).unwrap_or_else(Vector3::zeros);
            let (x, y) = (r.column(0).into_owned(), r.column(1).into_owned());
            for e in [-1.0, 1.0] {
                let cap = c + axis * (e * b);
                out.push(cap + across * a);
                out.extend([x, -x, y, -y].map(|d| cap + d * a));
            }
        }
        mjcf::GeomType::Ellipsoid => {
            let d = r.transpose() * -down;
            let s = Vector3::new(a * a * d.x, b * b * d.y, h * h * d.z);
            let n = (a * a * d.x * d.x + b * b * d.y * d.y + h * h * d.z * d.z).sqrt();
            out.push(if n > 0.0 { c + r * (s / n) } else { *c });
        }
        _ => {}
    }
}

/// The edges of the pyramid inscribed in the cone `|f_t| ≤ μ f_n` about +z, unit length.
pub(crate) fn cone_edges(mu: f64, n: usize) -> Vec<Vector3<f64>> {
    (0..n)
        .map(|j| {
            let a = std::f64::consts::TAU * j as f64 / n as f64;
            Vector3::new(mu * a.cos(), mu * a.sin(), 1.0).normalize()
        })
        .collect()
}

/// The length `L` of the torque unit m·g·L: the centre of mass's height above the lowest
/// collision point (the lowest body origin without collision geoms) at `qpos0`; 1 m where
/// that is not positive.
pub(crate) fn lever(model: &mjcf::Model, bodies: &[MassBody], geoms: &[usize]) -> f64 {
    let mut data = mjcf::Data::new(model);
    model.kinematics(&model.qpos0, &mut data);
    let mass: f64 = bodies.iter().map(|b| b.inertial.mass).sum();
    let com: Vector3<f64> = bodies
        .iter()
        .map(|b| {
            (data.xpos[b.pose + 1] + data.xquat[b.pose + 1] * b.inertial.pos) * b.inertial.mass
        })
        .sum::<Vector3<f64>>()
        / mass;
    let lowest = geoms
        .iter()
        .filter_map(|&g| mjcf::geom_lowest_point(model, &data, g).map(|p| p.z))
        .reduce(f64::min)
        .unwrap_or_else(|| data.xpos.iter().skip(1).map(|p| p.z).fold(f64::INFINITY, f64::min));
    let l = com.z - lowest;
    if l > 0.0 && l.is_finite() {
        l
    } else {
        1.0
    }
}
