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

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: dense linear algebra on buffers sized `n` in `BoxQp::new`; every index is below `n`
// (or `n·n`) by construction, and the public methods take no indices but `is_bound`, which uses
// `get`.
#![allow(clippy::indexing_slicing)]

/// Where a variable sits in the working set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Free,
    Lower,
    Upper,
}

/// Outcome of `BoxQp::solve`.
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

/// Problem data and workspace for one size `n`. Fill `h` (row-major `n × n`, upper
/// triangle: `h[i][j]` for `i ≤ j` is all that is read), `c`, `lb`, `ub`, call
/// [`BoxQp::solve`], read `x`.
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
    y: Vec<f64>,
    /// The variables on a bound, ascending (for the right-hand sides of a face).
    fixed: Vec<usize>,
    /// Kinematic-tree sparsity of `h` (see [`BoxQp::set_tree`]): whether it is set, and per
    /// variable its ancestors nearest first (the chains of `parent`).
    tree: bool,
    chains: Vec<Vec<usize>>,
    /// Where variable `k`'s packed row starts in `packed`: `[H_kk, H_k,a₁, H_k,a₂, …]` over
    /// its chain `a₁, a₂, …` (nearest first), `chains[k].len() + 1` entries. An ancestor's
    /// row is the tail of its descendant's (its chain is the descendant's beyond it), so
    /// every update of the factorisation is one contiguous `axpy` (MuJoCo's `M` layout).
    row_adr: Vec<usize>,
    /// The tree factor `L`, `D` of `H_FF = Lᵀ D L` in the packed layout.
    packed: Vec<f64>,
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
            y: vec![0.0; n],
            fixed: Vec::with_capacity(n),
            tree: false,
            chains: Vec::new(),
            row_adr: Vec::new(),
            packed: Vec::new(),
            iterations: 0,
        }
    }

    /// Declares that `h[i][j] ≠ 0` only when `i` and `j` are equal or one is an ancestor of
    /// the other in the tree `parent` (parents have lower indices): true of a Hessian built
    /// from body Jacobians over MuJoCo's dof tree. The factorisation then follows MuJoCo's
    /// `mj_factorI` (`H = Lᵀ D L` eliminating leaves first, no fill-in) instead of a dense
    /// Cholesky. Ignored unless `parent` has `n` entries, each lower than its index.
    pub fn set_tree(&mut self, parent: Vec<Option<usize>>) {
        let chains = super::ancestor_chains(&parent, self.n);
        self.tree = chains.is_some();
        self.chains = chains.unwrap_or_default();
        self.row_adr = self
            .chains
            .iter()
            .scan(0, |adr, chain| {
                let start = *adr;
                *adr += chain.len() + 1;
                Some(start)
            })
            .collect();
        let len = self.chains.iter().map(|chain| chain.len() + 1).sum();
        self.packed = vec![0.0; len];
    }

    /// Whether variable `i` ended on one of its bounds (in the working set).
    #[cfg(test)]
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

    /// `H_ij` from the upper triangle, which is all that is read of `h`.
    #[inline]
    fn h_at(&self, i: usize, j: usize) -> f64 {
        let (a, b) = if i <= j { (i, j) } else { (j, i) };
        self.h[a * self.n + b]
    }

    /// The bound variable whose multiplier is most negative (beyond rounding), if any.
    fn worst_multiplier(&self) -> Option<usize> {
        let n = self.n;
        let (mut worst, mut which) = (0.0, None);
        for i in 0..n {
            if self.state[i] == State::Free {
                continue;
            }
            let mut g = self.c[i];
            let mut scale = self.c[i].abs();
            for (j, xj) in self.x.iter().enumerate() {
                let hij = self.h_at(i, j);
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
        self.fixed.clear();
        self.fixed.extend((0..n).filter(|&i| self.state[i] != State::Free));
        if self.tree {
            return self.solve_face_tree();
        }
        self.solve_face_dense()
    }

    /// Right-hand side `−c_F − H_FW x_W` of free variable `i` (`self.fixed`: the `W`).
    fn free_rhs(&self, i: usize) -> f64 {
        let mut r = -self.c[i];
        for &j in &self.fixed {
            r -= self.h_at(i, j) * self.x[j];
        }
        r
    }

    /// `mj_factorI` / `mj_solveM` on the free variables, fixed ones cut out of the tree.
    /// Every variable free is the common case.
    fn solve_face_tree(&mut self) -> bool {
        let n = self.n;
        // H's tree entries into the packed rows (from the upper triangle: an ancestor has
        // the lower index).
        for (k, chain) in self.chains.iter().enumerate() {
            let row = &mut self.packed[self.row_adr[k]..][..=chain.len()];
            row[0] = self.h[k * n + k];
            for (entry, &a) in row[1..].iter_mut().zip(chain) {
                *entry = self.h[a * n + k];
            }
        }
        for i in 0..n {
            self.y[i] = match (self.fixed.is_empty(), self.state[i]) {
                (true, _) => -self.c[i],
                (false, State::Free) => self.free_rhs(i),
                _ => 0.0,
            };
        }
        if !self.factor_tree() {
            return false;
        }
        self.solve_tree();
        true
    }

    /// `L` and `D` of `H_FF = Lᵀ D L`, leaves first (`mj_factorI`), in place in `packed`.
    /// Eliminating `k` subtracts `l_ki l_kj / d_k` from `(i, j)` for the free ancestors
    /// `i` of `k` and `j` of `i` (or `i` itself): row `i`'s packed entries at once, from
    /// the tail of row `k`'s. Entries in a fixed variable's column are updated too but never
    /// read for a free one.
    fn factor_tree(&mut self) -> bool {
        let all_free = self.fixed.is_empty();
        for k in (0..self.n).rev() {
            if !all_free && self.state[k] != State::Free {
                continue;
            }
            let adr = self.row_adr[k];
            let chain = &self.chains[k];
            let (above, rest) = self.packed.split_at_mut(adr);
            let row_k = &mut rest[..=chain.len()];
            let dk = row_k[0];
            if dk.is_nan() || dk <= 0.0 || !dk.is_finite() {
                return false;
            }
            for (p, &i) in chain.iter().enumerate() {
                if !all_free && self.state[i] != State::Free {
                    continue;
                }
                let tail = &row_k[p + 1..];
                let tmp = tail[0] / dk;
                let row_i = &mut above[self.row_adr[i]..][..tail.len()];
                subtract_scaled(row_i, tmp, tail);
                row_k[p + 1] = tmp;
            }
        }
        true
    }

    /// `L⁻¹`, `D⁻¹`, `L⁻ᵀ` on `y` (`mj_solveM`), the free entries into `rhs`. The fixed
    /// entries of `y` take updates that no free one reads.
    fn solve_tree(&mut self) {
        let all_free = self.fixed.is_empty();
        let (l, y) = (&self.packed, &mut self.y);
        for &k in self.free.iter().rev() {
            let yk = y[k];
            let row_k = &l[self.row_adr[k] + 1..][..self.chains[k].len()];
            for (&i, &lki) in self.chains[k].iter().zip(row_k) {
                y[i] -= yk * lki;
            }
        }
        for &k in &self.free {
            y[k] /= l[self.row_adr[k]];
        }
        for &k in &self.free {
            let row_k = &l[self.row_adr[k] + 1..][..self.chains[k].len()];
            let mut yk = y[k];
            for (&i, &lki) in self.chains[k].iter().zip(row_k) {
                if all_free || self.state[i] == State::Free {
                    yk -= lki * y[i];
                }
            }
            y[k] = yk;
            self.rhs[k] = yk;
        }
    }

    fn solve_face_dense(&mut self) -> bool {
        let m = self.free.len();
        for a in 0..m {
            let i = self.free[a];
            self.y[a] = if m == self.n { -self.c[i] } else { self.free_rhs(i) };
            for b in 0..=a {
                self.chol[a * m + b] = self.h_at(i, self.free[b]);
            }
        }
        let l = &mut self.chol[..m * m];
        if !cholesky_in_place(l, m) {
            return false;
        }
        // L y = r, then Lᵀ z = y (row access only).
        let y = &mut self.y[..m];
        for a in 0..m {
            let row = &l[a * m..a * m + a + 1];
            y[a] = (y[a] - dot(&row[..a], &y[..a])) / row[a];
        }
        for a in (0..m).rev() {
            let row = &l[a * m..a * m + a + 1];
            y[a] /= row[a];
            let ya = y[a];
            for (yb, lab) in y[..a].iter_mut().zip(&row[..a]) {
                *yb -= lab * ya;
            }
        }
        for (a, &i) in self.free.iter().enumerate() {
            self.rhs[i] = y[a];
        }
        true
    }
}
/// `x ← x − t y` elementwise.
#[inline]
fn subtract_scaled(x: &mut [f64], t: f64, y: &[f64]) {
    for (x, y) in x.iter_mut().zip(y) {
        *x -= t * y;
    }
}

/// Lower Cholesky factor `L` (row-major, lower triangle) of the `m × m` matrix in `a`.
/// Row-slice dot products keep the inner loops free of bounds checks.
fn cholesky_in_place(a: &mut [f64], m: usize) -> bool {
    for i in 0..m {
        let (done, rest) = a.split_at_mut(i * m);
        let row_i = &mut rest[..m];
        for j in 0..i {
            let row_j = &done[j * m..j * m + j + 1];
            let s = row_i[j] - dot(&row_i[..j], &row_j[..j]);
            row_i[j] = s / row_j[j];
        }
        let d = row_i[i] - dot(&row_i[..i], &row_i[..i]);
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return false;
        }
        row_i[i] = d.sqrt();
    }
    true
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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

    /// Tree-structured random problems: the tree factorisation and the dense one agree, and
    /// the result satisfies the KKT conditions.
    #[test]
    fn tree_matches_dense_and_kkt() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..200 {
            let n = rng.gen_range(1..25);
            let (parent, h) = crate::qp::random_tree_problem(&mut rng, n, 0.1);
            let mut dense = BoxQp::new(n);
            dense.h = h;
            dense.c = (0..n).map(|_| rng.gen_range(-3.0..3.0)).collect();
            dense.lb = (0..n).map(|_| rng.gen_range(-1.0..0.0)).collect();
            dense.ub = (0..n).map(|_| rng.gen_range(0.0..1.0)).collect();
            let mut tree = dense.clone();
            tree.set_tree(parent);
            assert_eq!(dense.solve(), QpStatus::Optimal, "case {case}");
            assert_eq!(tree.solve(), QpStatus::Optimal, "case {case}");
            for i in 0..n {
                assert!((dense.x[i] - tree.x[i]).abs() < 1e-9, "case {case}");
                let g: f64 =
                    dense.c[i] + (0..n).map(|j| dense.h[i * n + j] * dense.x[j]).sum::<f64>();
                let x = dense.x[i];
                assert!(x >= dense.lb[i] && x <= dense.ub[i]);
                if x > dense.lb[i] && x < dense.ub[i] {
                    assert!(g.abs() < 1e-9, "case {case}: interior gradient {g}");
                } else if x == dense.lb[i] {
                    assert!(g > -1e-9, "case {case}");
                } else {
                    assert!(g < 1e-9, "case {case}");
                }
            }
        }
    }
}
