//! The step's QP solved: the box QP alone where no constraint rows are held, else the dual
//! active-set solver with the rows, relaxing the lowest-priority ones where they cannot all
//! hold.

// Indexing: as in the parent module (buffers sized from the model in `Solver::new`).
#![allow(clippy::indexing_slicing)]

use super::*;

impl Solver<'_> {
    /// Solves the assembled step QP into `dq`: the box QP alone where no constraint rows
    /// are held, else with them ([`Solver::constrained_step`]).
    pub(super) fn solve_step(&mut self) -> QpStatus {
        if self.constraints.is_empty() || !self.constraints_on {
            let status = self.qp.solve();
            self.dq.copy_from_slice(&self.qp.x);
            status
        } else {
            self.constrained_step()
        }
    }

    /// The step under the general constraints, H, c and the bounds already in `self.qp`,
    /// solved by the dual active-set solver on the dof tree's factorisation (bounds and rows
    /// alike: a bound entering the active set is a few `O(n)` updates, where the primal box
    /// solver refactorises). If the constraints cannot hold together, the lowest-priority
    /// ones are relaxed in turn: later constraints first, then the speed limits (see
    /// [`Solver::add_constraint`]).
    fn constrained_step(&mut self) -> QpStatus {
        // Beyond this (rad or m, any coordinate) from where they were made, the rows are made
        // again. Held over any move, the linearisation took Fourier N1's walk from 8.9 to
        // 11.2 cm mean position error; with this bound it is unchanged.
        const RELINEARISE: f64 = 0.02;
        // Grips hold a point to within a millimetre or so a frame, which rows made 0.02 away
        // do not: held linearised from the frame's first step, the T1's planted feet slid up to
        // 2.2 cm in a frame of the SOMA walk's first pass. With grips, every step makes them.
        if self.rows_made
            && self.grip_boxes.is_empty()
            && self.moved.iter().all(|m| m.abs() <= RELINEARISE)
        {
            self.dense.shift_rows(&self.row_base, &self.moved);
        } else {
            self.make_rows();
            self.row_base.clear();
            self.row_base.extend_from_slice(self.dense.rhs());
            self.moved.fill(0.0);
            self.rows_made = true;
        }
        let ends = std::mem::take(&mut self.row_ends);
        let status = self.constrained_solve(&ends);
        self.row_ends = ends;
        status
    }

    /// Every constraint's rows at the current configuration into `self.dense` (cleared
    /// first), and where each constraint's rows end in `self.row_ends`.
    pub(super) fn make_rows(&mut self) {
        let ctx = StepContext {
            model: self.model,
            data: &self.data,
            qpos: &self.qpos,
            raised: &self.raised,
            grips: &self.grip_boxes,
        };
        self.dense.clear_rows();
        self.row_ends.clear();
        for c in &mut self.constraints {
            c.add_rows(&ctx, &mut self.dense);
            self.row_ends.push(self.dense.num_rows());
        }
    }

    /// [`Solver::constrained_step`] once the rows are in `self.dense`.
    fn constrained_solve(&mut self, ends: &[usize]) -> QpStatus {
        // Hand the objective and bounds over without copying: every step rebuilds all four
        // in `self.qp` (H and c from zero, the bounds from ±∞), whatever they held.
        std::mem::swap(&mut self.dense.h, &mut self.qp.h);
        std::mem::swap(&mut self.dense.c, &mut self.qp.c);
        std::mem::swap(&mut self.dense.lb, &mut self.qp.lb);
        std::mem::swap(&mut self.dense.ub, &mut self.qp.ub);
        let mut status = self.dense.solve();
        if status == QpStatus::Infeasible {
            self.relaxed_steps += 1;
            status = self.relax(ends);
        }
        self.dq.copy_from_slice(&self.dense.x);
        status
    }

    /// Solves again with fewer constraints until feasible: the constraints after the first
    /// from the last back; then all of them without the speed limits; then the first alone;
    /// then the joint ranges alone (always feasible). `ends[k]`: rows of constraints `..=k`.
    fn relax(&mut self, ends: &[usize]) -> QpStatus {
        let all = self.dense.num_rows();
        for keep in (1..ends.len()).rev() {
            self.dense.use_rows(ends[keep - 1]);
            let status = self.dense.solve();
            if status != QpStatus::Infeasible {
                return status;
            }
        }
        self.set_bounds_without_speed();
        self.dense.lb.copy_from_slice(&self.qp.lb);
        self.dense.ub.copy_from_slice(&self.qp.ub);
        for rows in [all, ends.first().copied().unwrap_or(0), 0] {
            self.dense.use_rows(rows);
            let status = self.dense.solve();
            if status != QpStatus::Infeasible {
                return status;
            }
        }
        QpStatus::Infeasible
    }
}
