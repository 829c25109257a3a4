//! Forward kinematics, Jacobians and position integration: MuJoCo's `mj_kinematics`,
//! `mj_jac`/`mj_jacBody` and `mj_integratePos` (engine_core_smooth.c, engine_support.c),
//! analytic and allocation-free.

// Exception to the crate's `deny(clippy::indexing_slicing)`, justified: every index in this module is one `Model` itself holds
// (parents before children, dof and qpos addresses inside nv and nq: the compilers build
// them so), and `Data` is sized from the same model. This is the solver's per-iteration
// hot loop (the kinematics benchmark), so it indexes instead of re-checking each access.
#![allow(clippy::indexing_slicing)]

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::math::axis_angle;
use crate::model::{JointType, Model};

/// Results of [`Model::kinematics`] for one configuration (MuJoCo's `mjData` subset).
#[derive(Debug, Clone, PartialEq)]
pub struct Data {
    /// World position of each body frame.
    pub xpos: Vec<Vector3<f64>>,
    /// World orientation of each body frame.
    pub xquat: Vec<UnitQuaternion<f64>>,
    /// `xquat` as rotation matrices.
    pub xmat: Vec<Matrix3<f64>>,
    /// World position of each joint anchor.
    pub xanchor: Vec<Vector3<f64>>,
    /// World direction of each joint axis (free joint: the model axis, as in MuJoCo).
    pub xaxis: Vec<Vector3<f64>>,
    pub geom_xpos: Vec<Vector3<f64>>,
    pub geom_xmat: Vec<Matrix3<f64>>,
    pub site_xpos: Vec<Vector3<f64>>,
    pub site_xmat: Vec<Matrix3<f64>>,
    /// Per dof: world rotation axis (angular dofs) or translation direction (linear dofs).
    dof_axis: Vec<Vector3<f64>>,
    /// Per dof: whether it translates (slide, free linear) rather than rotates.
    dof_linear: Vec<bool>,
    /// Per dof: the joint anchor in the world (rotation centre of angular dofs).
    dof_anchor: Vec<Vector3<f64>>,
}

impl Data {
    /// Workspace sized for `model`, at the identity (all zeros; call [`Model::kinematics`]).
    #[must_use]
    pub fn new(model: &Model) -> Data {
        let nb = model.bodies.len();
        let nj = model.joints.len();
        Data {
            xpos: vec![Vector3::zeros(); nb],
            xquat: vec![UnitQuaternion::identity(); nb],
            xmat: vec![Matrix3::identity(); nb],
            xanchor: vec![Vector3::zeros(); nj],
            xaxis: vec![Vector3::zeros(); nj],
            geom_xpos: vec![Vector3::zeros(); model.geoms.len()],
            geom_xmat: vec![Matrix3::identity(); model.geoms.len()],
            site_xpos: vec![Vector3::zeros(); model.sites.len()],
            site_xmat: vec![Matrix3::identity(); model.sites.len()],
            dof_axis: vec![Vector3::zeros(); model.nv],
            dof_linear: (0..model.nv)
                .map(|d| model.joints[model.dof_joint[d]].kind == JointType::Slide)
                .collect(),
            dof_anchor: vec![Vector3::zeros(); model.nv],
        }
    }

    /// Takes `other`'s results (a workspace of the same model) into this one, reusing its
    /// buffers: the kinematics of the same configuration, without computing them again.
    pub fn copy_from(&mut self, other: &Data) {
        self.xpos.clone_from(&other.xpos);
        self.xquat.clone_from(&other.xquat);
        self.xmat.clone_from(&other.xmat);
        self.xanchor.clone_from(&other.xanchor);
        self.xaxis.clone_from(&other.xaxis);
        self.geom_xpos.clone_from(&other.geom_xpos);
        self.geom_xmat.clone_from(&other.geom_xmat);
        self.site_xpos.clone_from(&other.site_xpos);
        self.site_xmat.clone_from(&other.site_xmat);
        self.dof_axis.clone_from(&other.dof_axis);
        self.dof_linear.clone_from(&other.dof_linear);
        self.dof_anchor.clone_from(&other.dof_anchor);
    }
}

/// Unit quaternion from four numbers the way `mju_normalize4` does (identity when ~0).
#[inline]
fn quat_from_slice(q: &[f64]) -> UnitQuaternion<f64> {
    let q = Quaternion::new(q[0], q[1], q[2], q[3]);
    let n = q.norm();
    if n < 1e-15 {
        UnitQuaternion::identity()
    } else {
        UnitQuaternion::new_unchecked(q / n)
    }
}

/// Removes the rounding drift of a product of unit quaternions (MuJoCo's final
/// `mju_normalize4`) with one Newton step for 1/√|q|², which for |q|² = 1 + δ is exact to
/// O(δ²) (δ ~ 1e-16 here) and avoids the square root and division on the FK's critical path.
#[inline]
fn renormalize(q: UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    let q = q.into_inner();
    UnitQuaternion::new_unchecked(q * (1.5 - 0.5 * q.norm_squared()))
}

impl Model {
    /// Forward kinematics (`mj_kinematics`): world poses of all bodies, geoms and sites for
    /// `qpos` (free and ball joints as w-first quaternions). Body `b`: `xpos = xpos[parent] +
    /// R[parent] pos[b]`, `xquat = xquat[parent] quat[b]`, then each joint in turn: free sets
    /// the pose from `qpos`, hinge rotates by `q - qpos0` about its anchor, ball by its
    /// quaternion, slide translates by `q - qpos0` along its axis.
    ///
    /// A `qpos` shorter than `nq` leaves `data` unchanged (library code does not panic).
    pub fn kinematics(&self, qpos: &[f64], data: &mut Data) {
        if self.body_kinematics(qpos, data) {
            self.place_geoms_and_sites(data);
        }
    }

    /// [`Model::kinematics`] of the bodies, joint axes and anchors alone, the geoms and sites
    /// left where they were (for a caller that reads only those, and places the geoms and
    /// sites with [`Model::place_geoms_and_sites`] when it needs them). `false` when `qpos`
    /// is shorter than `nq` (then `data` is unchanged).
    pub fn body_kinematics(&self, qpos: &[f64], data: &mut Data) -> bool {
        if qpos.len() < self.nq
            || data.xpos.len() != self.bodies.len()
            || data.dof_axis.len() != self.nv
        {
            return false;
        }
        for (i, body) in self.bodies.iter().enumerate().skip(1) {
            let p = body.parent;
            let (mut xpos, mut xquat) =
                (data.xpos[p] + data.xmat[p] * body.pos, data.xquat[p] * body.quat);
            let last = body.jnt_adr + body.jnt_num;
            for j in body.jnt_adr..last {
                let joint = &self.joints[j];
                let a = joint.qpos_adr;
                match joint.kind {
                    JointType::Free => {
                        xpos = Vector3::new(qpos[a], qpos[a + 1], qpos[a + 2]);
                        xquat = quat_from_slice(&qpos[a + 3..a + 7]);
                        data.xanchor[j] = xpos;
                        data.xaxis[j] = joint.axis;
                    }
                    JointType::Slide => {
                        let xaxis = xquat * joint.axis;
                        data.xanchor[j] = xquat * joint.pos + xpos;
                        data.xaxis[j] = xaxis;
                        xpos += xaxis * (qpos[a] - self.qpos0[a]);
                    }
                    JointType::Hinge | JointType::Ball => {
                        let local = if joint.kind == JointType::Ball {
                            quat_from_slice(&qpos[a..a + 4])
                        } else {
                            axis_angle(&joint.axis, qpos[a] - self.qpos0[a])
                        };
                        // A hinge's axis is fixed by its own rotation: for the body's last
                        // joint it is taken from the final xmat below (cheaper, same value).
                        if j + 1 < last || joint.kind == JointType::Ball {
                            data.xaxis[j] = xquat * joint.axis;
                        }
                        if self.jnt_pos_zero[j] {
                            data.xanchor[j] = xpos;
                            xquat *= local;
                        } else {
                            let xanchor = xquat * joint.pos + xpos;
                            xquat *= local;
                            xpos = xanchor - xquat * joint.pos;
                            data.xanchor[j] = xanchor;
                        }
                    }
                }
            }
            let xquat = renormalize(xquat);
            let xmat = *xquat.to_rotation_matrix().matrix();
            data.xpos[i] = xpos;
            data.xquat[i] = xquat;
            data.xmat[i] = xmat;
            if body.jnt_num > 0 {
                let j = last - 1;
                if self.joints[j].kind == JointType::Hinge {
                    data.xaxis[j] = xmat * self.joints[j].axis;
                }
                self.dof_frames(body.jnt_adr..last, &xmat, data);
            }
        }
        true
    }

    /// World poses of the geoms and sites from their bodies' (the last part of
    /// [`Model::kinematics`]).
    pub fn place_geoms_and_sites(&self, data: &mut Data) {
        for (g, geom) in self.geoms.iter().enumerate() {
            let (p, r) = (data.xpos[geom.body], data.xmat[geom.body]);
            data.geom_xpos[g] = p + r * geom.pos;
            data.geom_xmat[g] = r * self.geom_mat[g];
        }
        for (s, site) in self.sites.iter().enumerate() {
            let (p, r) = (data.xpos[site.body], data.xmat[site.body]);
            data.site_xpos[s] = p + r * site.pos;
            data.site_xmat[s] = r * self.site_mat[s];
        }
    }

    /// World axis and anchor of the dofs of `joints` (one body, final orientation `r`), as
    /// MuJoCo's `cdof`: hinge and slide use the joint axis; ball and the free joint's rotation
    /// use the columns of the body's `xmat` ("assume no subsequent rotations"); the free
    /// joint's translation uses the world axes.
    fn dof_frames(&self, joints: std::ops::Range<usize>, r: &Matrix3<f64>, data: &mut Data) {
        for j in joints {
            let joint = &self.joints[j];
            let (d, anchor) = (joint.dof_adr, data.xanchor[j]);
            match joint.kind {
                JointType::Hinge | JointType::Slide => {
                    data.dof_axis[d] = data.xaxis[j];
                    data.dof_anchor[d] = anchor;
                }
                JointType::Ball => {
                    for k in 0..3 {
                        data.dof_axis[d + k] = r.column(k).into();
                        data.dof_anchor[d + k] = anchor;
                    }
                }
                JointType::Free => {
                    for k in 0..3 {
                        data.dof_axis[d + k] = Vector3::ith(k, 1.0);
                        data.dof_linear[d + k] = true;
                        data.dof_axis[d + 3 + k] = r.column(k).into();
                        data.dof_anchor[d + 3 + k] = anchor;
                    }
                }
            }
        }
    }

    /// Translational and rotational Jacobian (`mj_jacBody`) of the origin of `body`, each
    /// 3 × nv row-major in the world frame. Uses `data` from [`Model::kinematics`].
    pub fn jac_body(&self, data: &Data, body: usize, jacp: &mut [f64], jacr: &mut [f64]) {
        if let Some(point) = data.xpos.get(body).copied() {
            self.jac(data, body, &point, jacp, jacr);
        }
    }

    /// Jacobians (`mj_jac`) of the world point `point` moving with `body`: column `d` of
    /// `jacr` is the world rotation axis of dof `d` (0 for translations), column `d` of `jacp`
    /// is `axis × (point − anchor)` for rotations and the direction for translations; dofs not
    /// on the body's path to the world give zero columns. Slices shorter than `3 nv` or an
    /// unknown body leave them unchanged.
    pub fn jac(
        &self,
        data: &Data,
        body: usize,
        point: &Vector3<f64>,
        jacp: &mut [f64],
        jacr: &mut [f64],
    ) {
        let nv = self.nv;
        if body >= self.bodies.len()
            || jacp.len() < 3 * nv
            || jacr.len() < 3 * nv
            || data.dof_axis.len() != nv
        {
            return;
        }
        jacp[..3 * nv].fill(0.0);
        jacr[..3 * nv].fill(0.0);
        self.write_chain(data, body, point, jacp, jacr);
    }

    /// The columns of the dofs on `body`'s path to the world of the Jacobians at `point`
    /// ([`Model::jac_column`]) into `jacp` and `jacr` (`3 × nv` row-major; sizes checked by
    /// the callers).
    fn write_chain(
        &self,
        data: &Data,
        body: usize,
        point: &Vector3<f64>,
        jacp: &mut [f64],
        jacr: &mut [f64],
    ) {
        let nv = self.nv;
        for d in self.body_dofs(body) {
            let Some((p, r)) = Self::jac_column(data, point, d) else { continue };
            for k in 0..3 {
                jacp[k * nv + d] = p[k];
                jacr[k * nv + d] = r[k];
            }
        }
    }

    /// [`Model::jac`] at the origin of `body`, writing only the columns of the dofs on the
    /// body's path to the world (the others keep what they held): for callers that read just
    /// those columns ([`Model::body_dofs`]) and call it in a tight loop.
    pub fn jac_chain(&self, data: &Data, body: usize, jacp: &mut [f64], jacr: &mut [f64]) {
        let nv = self.nv;
        let Some(point) = data.xpos.get(body).copied() else { return };
        if jacp.len() < 3 * nv || jacr.len() < 3 * nv || data.dof_axis.len() != nv {
            return;
        }
        self.write_chain(data, body, &point, jacp, jacr);
    }

    /// Column `d` of [`Model::jac_chain`]'s `jacp` and `jacr` for a body at `point` (its
    /// `xpos`) whose path to the world has dof `d`: the same numbers, for callers that
    /// transform each column as it comes instead of gathering it from a strided `3 × nv`
    /// buffer. `None` for a dof `data` does not hold.
    #[must_use]
    #[inline]
    pub fn jac_column(
        data: &Data,
        point: &Vector3<f64>,
        d: usize,
    ) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let (axis, linear, anchor) =
            (data.dof_axis.get(d)?, data.dof_linear.get(d)?, data.dof_anchor.get(d)?);
        Some(if *linear {
            (*axis, Vector3::zeros())
        } else {
            (axis.cross(&(point - anchor)), *axis)
        })
    }

    /// The columns of [`Model::jac`]'s `jacp` at `point` moving with `body` that can be
    /// non-zero: `(dof, column)` for each dof on the body's path to the world, from the body
    /// towards the world ([`Model::body_dofs`]), the same numbers as `jac` writes. For callers
    /// that need a projection of the Jacobian (a constraint row `nᵀ J_p`), not all of it.
    /// Empty when `data` is not sized for this model.
    pub fn jac_point_columns<'a>(
        &'a self,
        data: &'a Data,
        body: usize,
        point: Vector3<f64>,
    ) -> impl Iterator<Item = (usize, Vector3<f64>)> + 'a {
        let sized = data.dof_axis.len() == self.nv && data.dof_linear.len() == self.nv;
        self.body_dofs(body)
            .take_while(move |_| sized)
            .filter_map(move |d| Some((d, Self::jac_column(data, &point, d)?.0)))
    }

    /// `mj_integratePos`: `qpos ← qpos ⊕ qvel dt`. Hinge and slide add; ball and the free
    /// joint's rotation apply the quaternion exponential of the body-frame angular velocity
    /// (`mju_quatIntegrate`); the free joint's translation adds the world-frame velocity.
    /// Slices shorter than `nq`/`nv` leave `qpos` unchanged.
    pub fn integrate_pos(&self, qpos: &mut [f64], qvel: &[f64], dt: f64) {
        if qpos.len() < self.nq || qvel.len() < self.nv {
            return;
        }
        for joint in &self.joints {
            let (mut a, mut v) = (joint.qpos_adr, joint.dof_adr);
            match joint.kind {
                JointType::Hinge | JointType::Slide => qpos[a] += dt * qvel[v],
                JointType::Ball | JointType::Free => {
                    if joint.kind == JointType::Free {
                        for k in 0..3 {
                            qpos[a + k] += dt * qvel[v + k];
                        }
                        a += 3;
                        v += 3;
                    }
                    let q = quat_integrate(
                        &qpos[a..a + 4],
                        &Vector3::new(qvel[v], qvel[v + 1], qvel[v + 2]),
                        dt,
                    );
                    qpos[a..a + 4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
                }
            }
        }
    }
}

impl Model {
    /// `mj_differentiatePos`: the velocity `qvel` (length `nv`) that [`Model::integrate_pos`]
    /// takes from `from` to `to` in time `dt`: hinge and slide coordinates and the free joint's
    /// translation by difference (world frame), ball joints and the free joint's rotation as
    /// the body-frame rotation vector of `from⁻¹ · to` (the shorter way round), over `dt`.
    /// Slices shorter than `nq`/`nv`, or `dt` not positive, leave `qvel` unchanged.
    pub fn differentiate_pos(&self, qvel: &mut [f64], dt: f64, from: &[f64], to: &[f64]) {
        if from.len() < self.nq || to.len() < self.nq || qvel.len() < self.nv || dt <= 0.0 {
            return;
        }
        for joint in &self.joints {
            let (mut a, mut v) = (joint.qpos_adr, joint.dof_adr);
            match joint.kind {
                JointType::Hinge | JointType::Slide => qvel[v] = (to[a] - from[a]) / dt,
                JointType::Ball | JointType::Free => {
                    if joint.kind == JointType::Free {
                        for k in 0..3 {
                            qvel[v + k] = (to[a + k] - from[a + k]) / dt;
                        }
                        a += 3;
                        v += 3;
                    }
                    let (q0, q1) =
                        (quat_from_slice(&from[a..a + 4]), quat_from_slice(&to[a..a + 4]));
                    let w = (q0.inverse() * q1).scaled_axis() / dt;
                    qvel[v..v + 3].copy_from_slice(w.as_slice());
                }
            }
        }
    }
}

/// `mju_quatIntegrate`: `q ← normalize(q) · exp(ω dt / 2)` with ω in the rotated frame.
fn quat_integrate(q: &[f64], omega: &Vector3<f64>, dt: f64) -> UnitQuaternion<f64> {
    let n = omega.norm();
    let rot = if n < 1e-15 { UnitQuaternion::identity() } else { axis_angle(&(omega / n), dt * n) };
    quat_from_slice(q) * rot
}

#[cfg(test)]
mod tests {
    use crate::Model;

    /// `differentiate_pos` undoes `integrate_pos`, a turn of more than half a turn of the
    /// double cover (the quaternion negated) included.
    #[test]
    fn differentiating_undoes_integrating() {
        let m = Model::from_xml_str(
            r#"<mujoco><worldbody><body><freejoint/><geom size="0.1"/>
                 <body><joint type="ball"/><geom size="0.1"/>
                 <body><joint axis="0 1 0"/><geom size="0.1"/></body></body>
               </body></worldbody></mujoco>"#,
            None,
        )
        .unwrap();
        let mut q0 = m.qpos0.clone();
        m.integrate_pos(&mut q0, &[0.3, -0.2, 0.1, 0.4, -0.7, 0.2, 0.1, 0.5, -0.3, 0.8], 1.0);
        let v = [0.5, 0.1, -0.4, 1.1, 0.3, -0.6, -0.9, 0.2, 0.4, -1.3];
        let mut q1 = q0.clone();
        m.integrate_pos(&mut q1, &v, 0.5);
        // The same rotations on the other sheet of the double cover.
        for a in [3, 7] {
            q1[a..a + 4].iter_mut().for_each(|x| *x = -*x);
        }
        let mut back = vec![0.0; m.nv];
        m.differentiate_pos(&mut back, 0.5, &q0, &q1);
        for (a, b) in back.iter().zip(&v) {
            assert!((a - b).abs() < 1e-12, "{back:?} vs {v:?}");
        }
    }
}
