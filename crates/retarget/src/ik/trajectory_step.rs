//! The solver as the trajectory solve sees it (`crate::solve`): a frame's objective with
//! its neighbours' terms added (`set_extra`, `set_next`, `set_previous`), raised floors for
//! swing soles, the objective's model and stiffness, its constraint rows, one step of the
//! window's iteration and the frame's diagnostics.

// Indexing: as in the parent module (buffers sized from the model in `Solver::new`).
#![allow(clippy::indexing_slicing)]

use super::*;

impl<'m> Solver<'m> {
    /// The trajectory solve's term of the next steps: `½ Δqᵀ H Δq + cᵀ Δq` added to the
    /// objective (`h`: row-major `nv × nv`, its upper triangle read; `c`: `nv`), the terms of
    /// the trajectory's cost that involve this frame with its neighbours held
    /// (`crate::solve`). Empty slices remove it.
    pub fn set_extra(&mut self, h: &[f64], c: &[f64]) -> Result<(), Error> {
        let nv = self.model.nv;
        if h.is_empty() && c.is_empty() {
            self.extra_h.clear();
            self.extra_c.clear();
            return Ok(());
        }
        same_len("extra objective H", h.len(), nv * nv)?;
        same_len("extra objective c", c.len(), nv)?;
        if h.iter().chain(c).any(|v| !v.is_finite()) {
            return Err(Error::NotFinite { what: "extra objective" });
        }
        self.extra_h.clear();
        self.extra_h.extend_from_slice(h);
        self.extra_c.clear();
        self.extra_c.extend_from_slice(c);
        Ok(())
    }

    /// The configuration of the frame after this one (length `nq`), or none: the speed
    /// limits of the next steps hold towards it as well as from the frame before.
    pub fn set_next(&mut self, next: Option<&[f64]>) -> Result<(), Error> {
        if let Some(q) = next {
            self.check_qpos(q)?;
        }
        self.next = next.map(<[f64]>::to_vec);
        Ok(())
    }

    /// The configuration the speed limits count from (the frame before this one).
    pub fn set_previous(&mut self, previous: &[f64]) -> Result<(), Error> {
        self.check_qpos(previous)?;
        self.previous.copy_from_slice(previous);
        self.grip_boxes_made = false;
        Ok(())
    }

    /// Geoms that keep a height above the floor in the next steps, `(geom, height)` (a swing
    /// foot's sole: [`crate::constraints::Ground`] holds them that much higher).
    pub fn set_raised_geoms(&mut self, raised: &[(usize, f64)]) {
        self.raised.clear();
        self.raised.extend_from_slice(raised);
        self.raised.sort_by_key(|r| r.0);
        self.rows_made = false;
    }

    /// The Gauss–Newton model of the tracking objective of `stages` (their tasks summed) and
    /// the point tasks at the current configuration, with the damping: `H` (row-major
    /// `nv × nv`, upper triangle only) and `c` of `½ Δqᵀ H Δq + cᵀ Δq`. The same terms as a
    /// step of [`Solver::trajectory_step`] before its prior.
    pub fn objective_model(
        &mut self,
        stages: &[(usize, f64)],
        targets: &[Pose],
    ) -> (&[f64], &[f64]) {
        self.fill_objective(stages, targets);
        (&self.qp.h, &self.qp.c)
    }

    /// The diagonal of the tracking objective's Gauss–Newton Hessian of `stages` at the
    /// current configuration (the tasks alone: no point tasks, no damping): how stiffly the
    /// targets hold each dof.
    pub fn tracking_stiffness(&mut self, stages: &[(usize, f64)], targets: &[Pose]) -> Vec<f64> {
        let points = std::mem::take(&mut self.point_tasks);
        self.fill_tasks(stages, targets);
        self.point_tasks = points;
        let nv = self.model.nv;
        (0..nv).map(|d| self.qp.h[d * nv + d]).collect()
    }

    /// `stages`: `(stage, factor)`, the factor multiplying that stage's cost.
    fn fill_objective(&mut self, stages: &[(usize, f64)], targets: &[Pose]) {
        let mu_total = self.fill_tasks(stages, targets);
        self.add_point_tasks();
        self.add_diagonal(self.options.damping + mu_total);
    }

    /// The tasks of `stages` into H and c (from zero); returns their μ.
    fn fill_tasks(&mut self, stages: &[(usize, f64)], targets: &[Pose]) -> f64 {
        self.clear_objective();
        let mut mu_total = 0.0;
        let count = self.stages.len();
        for &(s, factor) in stages.iter().filter(|&&(s, f)| s < count && f > 0.0) {
            self.stage_error(s, targets);
            let root = factor.sqrt();
            for k in 0..self.stages[s].len() {
                let scale = self.stages[s][k].scale;
                if factor != 1.0 {
                    self.stages[s][k].scale = scale.map(|v| v * root);
                }
                mu_total += self.task_objective(s, k, targets);
                self.stages[s][k].scale = scale;
            }
        }
        mu_total
    }

    /// The constraints' rows `a · Δq ≥ b` at the current configuration (every constraint
    /// added with [`Solver::add_constraint`]), as `(a, b)` pairs; without the grips
    /// ([`Solver::set_grips`]): they count from the frame before, which the window's step
    /// moves too, so the window holds them coupled with that frame (`grip_terms` in
    /// `crate::solve::trajectory`).
    pub fn constraint_rows(&mut self) -> Vec<(&[f64], f64)> {
        self.grip_boxes.clear();
        self.grip_boxes_made = false;
        self.make_rows();
        self.rows_made = false;
        (0..self.dense.num_rows()).filter_map(|k| self.dense.row(k)).collect()
    }

    /// One step of the trajectory solve's frame subproblem from the current configuration
    /// (two where the first ends more than 5 mm past a constraint):
    /// the tracking objective of `stages`, the point tasks, the extra terms ([`Solver::set_extra`]),
    /// the joint ranges, the speed limits from the frame before ([`Solver::set_previous`]) and
    /// towards the one after ([`Solver::set_next`]), and every constraint. Returns the steps
    /// that had to relax constraints (0 to 2) and whether the last QP reached its optimum.
    pub fn trajectory_step(
        &mut self,
        stages: &[(usize, f64)],
        targets: &[Pose],
        dt: f64,
    ) -> Result<(usize, bool), Error> {
        self.check_targets(targets)?;
        self.relaxed_steps = 0;
        let mut status = self.objective_step(stages, targets, dt);
        // A step's rows are the constraints linearised where it starts, and a pair of geoms
        // further apart there than their activation has none: one step can carry them through
        // each other (with decision 021's heavier dynamics term, the Fourier N1 put a hand
        // 5.3 cm into its waist in one frame of the LAFAN1 jumps at 16.7 rad/s; on the corpus
        // the G1 with hands a wrist 4.2 cm into its hip in 5 frames of a LAFAN1 take, and the
        // Adam Lite a foot 1.4 cm through the floor in 3 frames of CMU 131_01). Where the step
        // ends past a constraint by more than this (m), one more step from there, which has
        // its row.
        const PAST: f64 = 0.005;
        if self.constraints_on && self.past_constraints() > PAST {
            status = self.objective_step(stages, targets, dt);
        }
        let optimal = status == QpStatus::Optimal;
        Ok((self.relaxed_steps, optimal))
    }

    /// One step of [`Solver::trajectory_step`] from the current configuration.
    fn objective_step(&mut self, stages: &[(usize, f64)], targets: &[Pose], dt: f64) -> QpStatus {
        self.rows_made = false;
        self.fill_objective(stages, targets);
        let nv = self.model.nv;
        if self.extra_c.len() == nv {
            for i in 0..nv {
                self.qp.c[i] += self.extra_c[i];
                for j in i..nv {
                    self.qp.h[i * nv + j] += self.extra_h[i * nv + j];
                }
            }
        }
        self.set_bounds(dt);
        self.make_grip_boxes(dt);
        let status = self.solve_step();
        if matches!(status, QpStatus::Optimal | QpStatus::IterationLimit) {
            self.take_step();
        }
        self.place_geoms();
        status
    }

    /// How far (m) the current configuration is past its constraints (their rows made here:
    /// the floor, the robot's geoms apart), 0 where within them all. A grip's rows never are:
    /// past its box, a point is held where it is ([`crate::constraints::Grip`]).
    fn past_constraints(&mut self) -> f64 {
        if self.constraints.is_empty() {
            return 0.0;
        }
        self.make_rows();
        self.rows_made = false;
        // A row `a · Δq ≥ b` at Δq = 0: past it by b.
        (0..self.dense.num_rows()).filter_map(|k| self.dense.row(k)).fold(0.0, |p, (_, b)| p.max(b))
    }

    /// Diagnostics of the current configuration against `targets`: tracking errors and the
    /// joints at a limit (as [`Solver::solve_frame`] reports them), with `relaxed_steps`.
    pub fn diagnostics(
        &self,
        targets: &[Pose],
        relaxed_steps: usize,
    ) -> Result<FrameDiagnostics, Error> {
        self.check_targets(targets)?;
        let (pos_error, rot_error) = self.tracking_errors(targets);
        Ok(FrameDiagnostics {
            steps: vec![1],
            error: 0.0,
            pos_error,
            rot_error,
            at_limit: self.at_limit(),
            qp_failures: self.qp_failures,
            relaxed_steps,
            backward: false,
        })
    }
}
