//! The trajectory solve's dynamics term: the wrench the motion needs, less the part its
//! contacts can supply, as small as the tracking allows.
//!
//! Per frame `t` the centroidal motion needs the external wrench
//! `b_t = (m (c̈_t + g ẑ), L̇_t)` about the centre of mass `c` (`L`: the centroidal angular
//! momentum). Contacts supply `w = Σ_k f_k (d_k, (p_k − c) × d_k)` with `f_k ≥ 0` along the
//! edges `d_k` of friction pyramids at the candidate contact points `p_k` within
//! [`DynamicsOptions::contact_height`] of the floor in the frames within a fixed time of `t`
//! ([`DynamicsOptions::span`]; as the quality report's dynamics check counts them:
//! [`crate::report`]). The residual `r_t = b_t − w*_t`, `w*_t` the best supply
//! (non-negative least squares), in units of `m g` (force) and `m g L` (torque, `L` the
//! robot's COM height at `qpos0`), costs `½ W |r_t|²` ([`DynamicsOptions::weight`]). In flight
//! no point is near the floor and the whole needed wrench is residual: the centre of mass is
//! pulled onto its ballistic arc; in support the residual is what lies outside the friction
//! cones and the support polygon (a centre of pressure beyond the soles).
//!
//! Gauss–Newton on it: `c̈_t` is the COM's second difference, linear in the steps of frames
//! `t − 1, t, t + 1` through the COM Jacobians; the supply `f*` and `L̇` are held at the
//! current trajectory (the supply's torque moves with `c` through its lever arms). So
//! `r_t(δ) ≈ r_t + Σ_s A_{t,s} δ_s` with `A_{t,t±1} = [J_c / (g dt²); 0]` and
//! `A_{t,t} = [−2 J_c / (g dt²); −[F*]× J_c / L]`.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames index the per-frame vectors built here from the same sequence; body and
// geom ids come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, Model};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

use crate::centroidal::{bottom_points, cone_edges, lever, mass_bodies, nnls, Column, MassBody};
use crate::centroidal::{half_step, GRAVITY};

/// Tunables of the dynamics term.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DynamicsOptions {
    /// Weight `W` of `½ |r|²` per frame (`r` in m·g and m·g·L); 0 turns the term off.
    /// Default 300 (decision 021).
    pub weight: f64,
    /// Candidate points within this of the floor (m) are contacts.
    pub contact_height: f64,
    /// Friction coefficient of the floor.
    pub friction: f64,
    /// Edges of each friction pyramid.
    pub cone_edges: usize,
    /// Frame `t`'s supply counts the candidate points near the floor in the frames within
    /// `h dt` of it, `h = max(1, round(span / (4 dt)))` (s), as the quality report's
    /// dynamics check counts them ([`crate::report::DynamicsCheckOptions::span`]): the same
    /// time at every frame rate. Default 1/6 s.
    pub span: f64,
}

impl Default for DynamicsOptions {
    fn default() -> Self {
        DynamicsOptions {
            weight: 300.0,
            contact_height: 0.01,
            friction: 0.8,
            cone_edges: 8,
            span: 1.0 / 6.0,
        }
    }
}

/// One frame's kinematic state for the term: the COM and its Jacobian, each mass body's
/// centre and orientation (for the angular momentum), the candidate contact points near the
/// floor.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrameState {
    pub com: Vector3<f64>,
    /// `3 × nv`, row-major.
    pub jac: Vec<f64>,
    centres: Vec<Vector3<f64>>,
    rotations: Vec<UnitQuaternion<f64>>,
    near: Vec<Vector3<f64>>,
}

/// One residual frame's linearisation: the needed wrench's lagged torque, the supply at the
/// COM it was found at, and its force's resultant.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Supply {
    /// The residual's direction in wrench space where the frame has one: the cost is
    /// `½ W d²` with `d` the residual's length, linearised along it (the squared distance to
    /// the producible wrenches has no curvature inside them).
    pub normal: Option<[f64; 6]>,
    torque: Vector3<f64>,
    force: Vector3<f64>,
    supplied_torque: Vector3<f64>,
    at: Vector3<f64>,
}

/// The term for one model: its mass bodies and units.
#[derive(Debug, Clone)]
pub(crate) struct Centroidal {
    bodies: Vec<MassBody>,
    mass: f64,
    lever: f64,
    geoms: Vec<usize>,
    edges: Vec<Vector3<f64>>,
    pub options: DynamicsOptions,
    points: Vec<Vector3<f64>>,
}

impl Centroidal {
    /// `None` when the term is off or the model's masses are not known.
    pub(crate) fn new(model: &Model, options: &DynamicsOptions) -> Option<Centroidal> {
        if options.weight <= 0.0 {
            return None;
        }
        let bodies = mass_bodies(model).ok()?;
        let mass: f64 = bodies.iter().map(|b| b.inertial.mass).sum();
        let geoms = crate::constraints::collision_primitives(model);
        let lever = lever(model, &bodies, &geoms);
        Some(Centroidal {
            bodies,
            mass,
            lever,
            geoms,
            edges: cone_edges(options.friction, options.cone_edges.max(3)),
            options: options.clone(),
            points: Vec::new(),
        })
    }

    /// The state of the configuration whose kinematics `data` holds.
    pub(crate) fn state(&mut self, model: &Model, data: &Data, out: &mut FrameState) {
        let nv = model.nv;
        out.jac.clear();
        out.jac.resize(3 * nv, 0.0);
        out.centres.clear();
        out.rotations.clear();
        let mut sum = Vector3::zeros();
        for b in &self.bodies {
            let body = b.pose + 1;
            let rot = data.xquat[body];
            let x = data.xpos[body] + rot * b.inertial.pos;
            let share = b.inertial.mass / self.mass;
            sum += x * b.inertial.mass;
            for (d, col) in model.jac_point_columns(data, body, x) {
                for r in 0..3 {
                    out.jac[r * nv + d] += share * col[r];
                }
            }
            out.centres.push(x);
            out.rotations.push(rot * b.inertial.quat);
        }
        out.com = sum / self.mass;
        out.near.clear();
        for &g in &self.geoms {
            self.points.clear();
            let geom = &model.geoms[g];
            bottom_points(
                geom.kind,
                &geom.size,
                &data.geom_xpos[g],
                &data.geom_xmat[g],
                &mut self.points,
            );
            out.near.extend(self.points.iter().filter(|p| p.z < self.options.contact_height));
        }
    }

    /// Centroidal angular momentum at the middle of three states, from central differences.
    fn momentum(&self, a: &FrameState, b: &FrameState, c: &FrameState, dt: f64) -> Vector3<f64> {
        let mut l = Vector3::zeros();
        for (i, body) in self.bodies.iter().enumerate() {
            let m = body.inertial.mass;
            let v = (c.centres[i] - a.centres[i]) / (2.0 * dt);
            let w = (c.rotations[i] * a.rotations[i].inverse()).scaled_axis() / (2.0 * dt);
            let rot = b.rotations[i];
            let spin = rot * (rot.inverse() * w).component_mul(&body.inertial.diag);
            l += (b.centres[i] - b.com).cross(&v) * m + spin;
        }
        l
    }

    /// The supplies of the residual frames `1 ..= len − 2` of `states` (none at the ends: no
    /// acceleration there), from the states as they are: the contacts of the frames within
    /// [`DynamicsOptions::span`]'s half step of each.
    pub(crate) fn supplies(&self, states: &[FrameState], dt: f64) -> Vec<Option<Supply>> {
        let len = states.len();
        let h = half_step(1.0 / dt, self.options.span);
        let momentum: Vec<Option<Vector3<f64>>> = (0..len)
            .map(|j| {
                (j >= 1 && j + 1 < len)
                    .then(|| self.momentum(&states[j - 1], &states[j], &states[j + 1], dt))
            })
            .collect();
        let mut x = Vec::new();
        let mut cols: Vec<Column> = Vec::new();
        (0..len)
            .map(|t| {
                if t == 0 || t + 1 >= len {
                    return None;
                }
                let torque = match (momentum[t - 1], momentum.get(t + 1).copied().flatten()) {
                    (Some(a), Some(b)) => (b - a) / (2.0 * dt),
                    _ => Vector3::zeros(),
                };
                let c = states[t].com;
                let b = self.needed(states, t, dt, &torque);
                cols.clear();
                for p in
                    states[t.saturating_sub(h)..=(t + h).min(len - 1)].iter().flat_map(|s| &s.near)
                {
                    let arm = (p - c) / self.lever;
                    cols.extend(self.edges.iter().map(|d| {
                        let m = arm.cross(d);
                        [d.x, d.y, d.z, m.x, m.y, m.z]
                    }));
                }
                let r = if cols.is_empty() { b } else { nnls(&cols, &b, &mut x) };
                let supplied: Column = std::array::from_fn(|i| b[i] - r[i]);
                let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
                let normal = (norm > 1e-9).then(|| r.map(|v| v / norm));
                Some(Supply {
                    normal,
                    torque,
                    force: Vector3::new(supplied[0], supplied[1], supplied[2]),
                    supplied_torque: Vector3::new(supplied[3], supplied[4], supplied[5]),
                    at: c,
                })
            })
            .collect()
    }

    /// The needed wrench of frame `t` (normalised) with the lagged torque `torque`.
    fn needed(&self, states: &[FrameState], t: usize, dt: f64, torque: &Vector3<f64>) -> Column {
        let acc = (states[t + 1].com - states[t].com * 2.0 + states[t - 1].com) / (dt * dt);
        let f = (acc + Vector3::z() * GRAVITY) / GRAVITY;
        let tau = torque / (self.mass * GRAVITY * self.lever);
        [f.x, f.y, f.z, tau.x, tau.y, tau.z]
    }

    /// The residual of frame `t` at the states as they are now, its supply held (the
    /// supplied torque carried along with the COM).
    pub(crate) fn residual(
        &self,
        states: &[FrameState],
        t: usize,
        supply: &Supply,
        dt: f64,
    ) -> [f64; 6] {
        let b = self.needed(states, t, dt, &supply.torque);
        let moved = states[t].com - supply.at;
        let torque = supply.supplied_torque + supply.force.cross(&moved) / self.lever;
        [
            b[0] - supply.force.x,
            b[1] - supply.force.y,
            b[2] - supply.force.z,
            b[3] - torque.x,
            b[4] - torque.y,
            b[5] - torque.z,
        ]
    }

    /// The length of frame `t`'s residual along its normal at the states as they are
    /// (none where the frame had no residual: it was inside the producible wrenches), and
    /// its gradient `n̂ᵀ A_{t,s}` for the step of frame `s = t + offset` into `out` (`nv`).
    pub(crate) fn distance(
        &self,
        states: &[FrameState],
        (t, offset): (usize, isize),
        supply: &Supply,
        dt: f64,
        (block, out): (&mut Vec<f64>, &mut Vec<f64>),
    ) -> Option<f64> {
        let n = supply.normal?;
        let r = self.residual(states, t, supply, dt);
        let d = (0..6).map(|i| n[i] * r[i]).sum::<f64>().max(0.0);
        let s = t.checked_add_signed(offset)?;
        self.block(&states[s], supply, offset, dt, block);
        let nv = states[s].jac.len() / 3;
        out.clear();
        out.extend((0..nv).map(|p| (0..6).map(|row| n[row] * block[row * nv + p]).sum::<f64>()));
        Some(d)
    }

    /// `A_{t,s}` of residual frame `t` for the step of frame `s = t + offset` (offset −1, 0,
    /// 1): `6 × nv` row-major into `out`.
    pub(crate) fn block(
        &self,
        state: &FrameState,
        supply: &Supply,
        offset: isize,
        dt: f64,
        out: &mut Vec<f64>,
    ) {
        let nv = state.jac.len() / 3;
        out.clear();
        out.resize(6 * nv, 0.0);
        let k = if offset == 0 { -2.0 } else { 1.0 } / (GRAVITY * dt * dt);
        for r in 0..3 {
            for d in 0..nv {
                out[r * nv + d] = k * state.jac[r * nv + d];
            }
        }
        if offset == 0 {
            // ∂r_τ/∂c = −[F*]× / L (the supply's lever arms shorten as c moves).
            let m: Matrix3<f64> = -supply.force.cross_matrix() / self.lever;
            for r in 0..3 {
                for d in 0..nv {
                    out[(3 + r) * nv + d] =
                        (0..3).map(|i| m[(r, i)] * state.jac[i * nv + d]).sum::<f64>();
                }
            }
        }
    }
}
