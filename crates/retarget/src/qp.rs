//! A small dense box-constrained QP, solved exactly:
//!
//! ```text
//! minimise ½ xᵀ H x + cᵀ x   subject to   lb ≤ x ≤ ub       (H symmetric positive definite)
//! ```
//!
//! Primal active-set method (Nocedal & Wright, *Numerical Optimization*, 2nd ed., Alg. 16.3)
//! specialised to bounds: the working set fixes variables at a bound; each iteration solves
//! the equality-constrained problem on the free variables with a Cholesky factorisation,
//! steps towards it until a bound blocks, and frees the bound with the most negative
//! multiplier once the face is optimal. It terminates at the exact KKT point (no clamping
//! of an unconstrained solution). The unconstrained solution is tried first, which is the
//! whole job when no limit is active. All buffers are allocated once in [`BoxQp::new`].

/// Where a variable sits in the working set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Free,
    Lower,
    Upper,
}

/// Outcome of [`BoxQp::solve`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QpStatus {
    /// KKT conditions hold.
    Optimal,
    /// `H` restricted to the free variables is not positive definite.
    NotPositiveDefinite,
    /// `lb > ub` somewhere, or a non-finite input.
    Infeasible,
    /// The iteration cap (`10 n + 10`) was hit; `x` is feasible and the best found.
    IterationLimit,
}

/// Problem data and workspace for one size `n`. Fill `h` (row-major `n × n`), `c`, `lb`,
/// `ub`, call [`BoxQp::solve`], read `x`.
#[derive(Debug, Clone)]
pub struct BoxQp {
    n: usize,
    pub h: Vec<f64>,
    pub c: Vec<f64>,
    pub lb: Vec<f64>,
    pub ub: Vec<f64>,
    pub x: Vec<f64>,
    state: Vec<State>,
    free: Vec<usize>,
    chol: Vec<f64>,
    rhs: Vec<f64>,
    /// Number of active-set iterations of the last solve.
    pub iterations: usize,
}

impl BoxQp {
    #[must_use]
    pub fn new(n: usize) -> BoxQp {
        BoxQp {
            n,
            h: vec![0.0; n * n],
            c: vec![0.0; n],
            lb: vec![f64::NEG_INFINITY; n],
            ub: vec![f64::INFINITY; n],
            x: vec![0.0; n],
            state: vec![State::Free; n],
            free: Vec::with_capacity(n),
            chol: vec![0.0; n * n],
            rhs: vec![0.0; n],
            iterations: 0,
        }
    }

    #[must_use]
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Whether variable `i` ended on one of its bounds (in the working set).
    #[must_use]
    pub fn is_bound(&self, i: usize) -> bool {
        self.state[i] != State::Free
    }

    /// Solves the problem currently stored; the minimiser is left in `x`.
    pub fn solve(&mut self) -> QpStatus {
        let n = self.n;
        self.iterations = 0;
        if (0..n).any(|i| {
            self.lb[i].partial_cmp(&self.ub[i]).is_none_or(|o| o.is_gt()) || self.c[i].is_nan()
        }) {
            return QpStatus::Infeasible;
        }
        self.state.fill(State::Free);
        if !self.solve_face() {
            return QpStatus::NotPositiveDefinite;
        }
        // Unconstrained minimiser: done if feasible, else start from its projection.
        let mut feasible = true;
        for i in 0..n {
            if self.rhs[i] < self.lb[i] {
                (self.x[i], self.state[i], feasible) = (self.lb[i], State::Lower, false);
            } else if self.rhs[i] > self.ub[i] {
                (self.x[i], self.state[i], feasible) = (self.ub[i], State::Upper, false);
            } else {
                self.x[i] = self.rhs[i];
            }
        }
        if feasible {
            return QpStatus::Optimal;
        }
        self.active_set()
    }

    fn active_set(&mut self) -> QpStatus {
        let n = self.n;
        let cap = 10 * n + 10;
        while self.iterations < cap {
            self.iterations += 1;
            if !self.solve_face() {
                return QpStatus::NotPositiveDefinite;
            }
            // Step from x towards the face minimiser (in rhs), stopping at the first bound.
            let (mut alpha, mut blocking) = (1.0, None);
            for &i in &self.free {
                let p = self.rhs[i] - self.x[i];
                let (bound, state) = if p < 0.0 {
                    (self.lb[i], State::Lower)
                } else if p > 0.0 {
                    (self.ub[i], State::Upper)
                } else {
                    continue;
                };
                if (self.x[i] + p - bound) * p > 0.0 {
                    let a = ((bound - self.x[i]) / p).max(0.0);
                    if a < alpha {
                        (alpha, blocking) = (a, Some((i, state, bound)));
                    }
                }
            }
            for k in 0..self.free.len() {
                let i = self.free[k];
                self.x[i] = if alpha == 1.0 {
                    self.rhs[i]
                } else {
                    self.x[i] + alpha * (self.rhs[i] - self.x[i])
                };
            }
            if let Some((i, state, bound)) = blocking {
                self.x[i] = bound;
                self.state[i] = state;
                continue;
            }
            // x minimises the face: check the multipliers of the bound variables.
            match self.worst_multiplier() {
                Some(i) => self.state[i] = State::Free,
                None => return QpStatus::Optimal,
            }
        }
        QpStatus::IterationLimit
    }

    /// The bound variable whose multiplier is most negative (beyond rounding), if any.
    fn worst_multiplier(&self) -> Option<usize> {
        let n = self.n;
        let (mut worst, mut which) = (0.0, None);
        for i in 0..n {
            if self.state[i] == State::Free {
                continue;
            }
            let row = &self.h[i * n..(i + 1) * n];
            let mut g = self.c[i];
            let mut scale = self.c[i].abs();
            for (hij, xj) in row.iter().zip(&self.x) {
                g += hij * xj;
                scale += (hij * xj).abs();
            }
            let lambda = if self.state[i] == State::Lower { g } else { -g };
            let tol = 1e-13 * scale.max(f64::MIN_POSITIVE);
            if lambda < -tol && lambda < worst {
                (worst, which) = (lambda, Some(i));
            }
        }
        which
    }

    /// Minimiser over the free variables with the others fixed at `x`, written to `rhs`
    /// (free entries only). `false` if the reduced Hessian is not positive definite.
    fn solve_face(&mut self) -> bool {
        let n = self.n;
        self.free.clear();
        self.free.extend((0..n).filter(|&i| self.state[i] == State::Free));
        let m = self.free.len();
        for (a, &i) in self.free.iter().enumerate() {
            let mut r = -self.c[i];
            for j in 0..n {
                if self.state[j] != State::Free {
                    r -= self.h[i * n + j] * self.x[j];
                }
            }
            self.rhs[i] = r;
            for (b, &j) in self.free.iter().enumerate() {
                self.chol[a * m + b] = self.h[i * n + j];
            }
        }
        if !cholesky_in_place(&mut self.chol[..m * m], m) {
            return false;
        }
        // Forward and back substitution on the free entries of rhs.
        for a in 0..m {
            let mut s = self.rhs[self.free[a]];
            for b in 0..a {
                s -= self.chol[a * m + b] * self.rhs[self.free[b]];
            }
            self.rhs[self.free[a]] = s / self.chol[a * m + a];
        }
        for a in (0..m).rev() {
            let mut s = self.rhs[self.free[a]];
            for b in a + 1..m {
                s -= self.chol[b * m + a] * self.rhs[self.free[b]];
            }
            self.rhs[self.free[a]] = s / self.chol[a * m + a];
        }
        true
    }
}

/// Lower Cholesky factor `L` (row-major, lower triangle) of the `m × m` matrix in `a`.
fn cholesky_in_place(a: &mut [f64], m: usize) -> bool {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unconstrained_and_one_bound() {
        let mut qp = BoxQp::new(2);
        qp.h = vec![2.0, 0.0, 0.0, 2.0];
        qp.c = vec![-2.0, -4.0];
        assert_eq!(qp.solve(), QpStatus::Optimal);
        assert!((qp.x[0] - 1.0).abs() < 1e-15 && (qp.x[1] - 2.0).abs() < 1e-15);
        qp.ub[1] = 0.5;
        assert_eq!(qp.solve(), QpStatus::Optimal);
        assert!((qp.x[0] - 1.0).abs() < 1e-15 && qp.x[1] == 0.5, "{:?}", qp.x);
        assert!(qp.is_bound(1) && !qp.is_bound(0));
    }

    #[test]
    fn coupled_bound_released() {
        // Projection of the unconstrained minimiser is not optimal here: the active set must
        // move variable 0 off its initial clamp.
        let mut qp = BoxQp::new(2);
        qp.h = vec![1.0, 0.9, 0.9, 1.0];
        qp.c = vec![0.0, -1.0];
        qp.lb = vec![-0.5, -10.0];
        qp.ub = vec![10.0, 0.2];
        assert_eq!(qp.solve(), QpStatus::Optimal);
        // With x1 = 0.2 fixed: x0 = -0.9 * 0.2 = -0.18 (inside), multiplier of x1 = -(0.9 x0 + x1 - 1) > 0.
        assert!((qp.x[0] + 0.18).abs() < 1e-15, "{:?}", qp.x);
        assert_eq!(qp.x[1], 0.2);
    }

    #[test]
    fn infeasible_box() {
        let mut qp = BoxQp::new(1);
        qp.h = vec![1.0];
        qp.lb = vec![1.0];
        qp.ub = vec![0.0];
        assert_eq!(qp.solve(), QpStatus::Infeasible);
    }
}
