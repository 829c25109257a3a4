//! The step's bounds: joint ranges (GMR's `ConfigurationLimit`, 0.95 of the way) intersected
//! with the joint speed limits around the previous frame's configuration.

// Indexing: as in the parent module (limits built from the model in `Solver::new`).
#![allow(clippy::indexing_slicing)]

use super::*;

impl Solver<'_> {
    /// Joint-range bounds on Δq, intersected with the speed limits (per joint, or the global
    /// `max_joint_speed`) around the previous frame's configuration when they overlap.
    pub(super) fn set_bounds(&mut self, dt: f64) {
        self.qp.lb.fill(f64::NEG_INFINITY);
        self.qp.ub.fill(f64::INFINITY);
        let gain = self.options.limit_gain;
        let global = self.options.max_joint_speed.filter(|v| v.is_finite() && *v > 0.0);
        // Aim 0.1 % inside the limit: the report's finite differences of the written
        // trajectory should not find a joint at 1.000001× its limit.
        let speed = |dof: usize| {
            self.dof_speed[dof].or(global).filter(|_| dt > 0.0).map(|v| v * SPEED_MARGIN)
        };
        for l in &self.limits {
            let q = self.qpos[l.qpos];
            let mut lb = -(gain * (q - l.range[0]));
            let mut ub = gain * (l.range[1] - q);
            if let Some(v) = speed(l.dof) {
                let reach = v * dt;
                let (mut vlb, mut vub) =
                    (self.previous[l.qpos] - reach - q, self.previous[l.qpos] + reach - q);
                if let Some(next) = &self.next {
                    let (nlb, nub) = (next[l.qpos] - reach - q, next[l.qpos] + reach - q);
                    if nlb.max(vlb) <= nub.min(vub) {
                        (vlb, vub) = (nlb.max(vlb), nub.min(vub));
                    }
                }
                if vlb.max(lb) <= vub.min(ub) {
                    (lb, ub) = (vlb.max(lb), vub.min(ub));
                }
            }
            self.qp.lb[l.dof] = lb;
            self.qp.ub[l.dof] = ub;
        }
        for joint in &self.model.joints {
            if !matches!(joint.kind, JointType::Hinge | JointType::Slide) || joint.range.is_some() {
                continue;
            }
            if let Some(v) = speed(joint.dof_adr) {
                let (d, a) = (joint.dof_adr, joint.qpos_adr);
                let q = self.qpos[a];
                let (mut lb, mut ub) =
                    (self.previous[a] - v * dt - q, self.previous[a] + v * dt - q);
                if let Some(next) = &self.next {
                    let (nlb, nub) = (next[a] - v * dt - q, next[a] + v * dt - q);
                    if nlb.max(lb) <= nub.min(ub) {
                        (lb, ub) = (nlb.max(lb), nub.min(ub));
                    }
                }
                self.qp.lb[d] = lb;
                self.qp.ub[d] = ub;
            }
        }
    }

    /// Joint-range bounds alone.
    pub(super) fn set_bounds_without_speed(&mut self) {
        let gain = self.options.limit_gain;
        self.qp.lb.fill(f64::NEG_INFINITY);
        self.qp.ub.fill(f64::INFINITY);
        for l in &self.limits {
            let q = self.qpos[l.qpos];
            self.qp.lb[l.dof] = -(gain * (q - l.range[0]));
            self.qp.ub[l.dof] = gain * (l.range[1] - q);
        }
    }
}
