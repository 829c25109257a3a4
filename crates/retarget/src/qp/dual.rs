//! A dense convex QP with bounds and general linear inequalities, solved exactly by
//! Goldfarb and Idnani's dual active-set method:
//!
//! ```text
//! minimise ½ xᵀ H x + cᵀ x   subject to   lb ≤ x ≤ ub,   a_i · x ≥ b_i   (H positive definite)
//! ```
//!
//! D. Goldfarb, A. Idnani, "A numerically stable dual method for solving strictly convex
//! quadratic programs", *Mathematical Programming* 27 (1983) 1–33; the same algorithm as
//! Turlach's `quadprog`. It starts at the unconstrained minimiser `−H⁻¹c` (dual feasible) and
//! adds the most violated constraint at a time, dropping active ones whose multiplier would
//! turn negative, so every iterate is dual feasible and the primal infeasibility falls
//! monotonically; it ends at the exact KKT point or proves the problem infeasible. With
//! `H = L Lᵀ` it keeps `J = L⁻ᵀ Q` and an upper-triangular `R` with `Jᵀ N = [R; 0]` (`N`: the
//! active normals), updated by Givens rotations when a constraint enters or leaves. On a
//! kinematic tree's Hessian ([`DenseQp::set_tree`]) the factor is the tree's sparse
//! `H = Lᵀ D L` instead and `J` starts as sparse `L⁻¹ D^-½`, so that the factorisation and
//! the first rotations cost a fraction of the dense ones.
//!
//! Why this and not an interior-point crate: our problems are tiny (`n` = 35 for the G1,
//! a few general rows active) and a step changes little between calls. The dual method costs
//! one factorisation and a few `O(n²)` updates per active constraint, and is exact;
//! `benches/qp.rs` measures it against `clarabel` on QPs recorded from a G1 solve.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: dense linear algebra on buffers sized `n` in `DenseQp::new` and rows of length `n`
// from `add_row`; indices stay below `n`, `num_rows` by construction.
#![allow(clippy::indexing_slicing)]

use super::QpStatus;

/// A constraint of the problem: a bound of one variable or a general row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Con {
    /// `x_i ≥ lb_i`.
    Lower(usize),
    /// `x_i ≤ ub_i`, i.e. `−x_i ≥ −ub_i`.
    Upper(usize),
    /// `a_k · x ≥ b_k`.
    Row(usize),
}

/// Problem data and workspace. Fill `h` (row-major `n × n`, symmetric; the upper triangle is
/// read), `c`, `lb`, `ub` (±∞ where unbounded), add general rows with [`DenseQp::add_row`],
/// call [`DenseQp::solve`], read `x`. [`DenseQp::clear_rows`] starts the next problem's rows.
#[derive(Debug, Clone)]
pub struct DenseQp {
    n: usize,
    pub h: Vec<f64>,
    pub c: Vec<f64>,
    pub lb: Vec<f64>,
    pub ub: Vec<f64>,
    /// General rows, `rows × n` row-major, and their right-hand sides.
    a: Vec<f64>,
    b: Vec<f64>,
    /// Rows taken into account: the first `in_use` ([`DenseQp::use_rows`]).
    in_use: usize,
    /// Per row, its normal's length and whether every entry is finite, for the first
    /// `checked` rows (rows are only appended or all cleared, and [`DenseQp::add_row`]'s
    /// caller fills a row before the next solve, which checks the new ones).
    row_norm: Vec<f64>,
    row_finite: Vec<bool>,
    /// Per row, the range of its non-zero entries (a point's Jacobian row is zero beyond
    /// its body's dof chain).
    row_span: Vec<(usize, usize)>,
    checked: usize,
    pub x: Vec<f64>,
    /// `J` by columns (`Q` in tree mode): `jt[k n .. (k+1) n]` is column `k`.
    jt: Vec<f64>,
    /// `R` by columns: `r[k n + i] = R[i][k]`, upper triangular in the first `active.len()`.
    r: Vec<f64>,
    active: Vec<Con>,
    /// Per variable: lower / upper bound active; per row: active (mirrors `active`).
    bound_active: Vec<[bool; 2]>,
    row_active: Vec<bool>,
    /// Multipliers of the active constraints (same order), and of the one being added.
    u: Vec<f64>,
    d: Vec<f64>,
    z: Vec<f64>,
    dual_dir: Vec<f64>,
    normal: Vec<f64>,
    /// Per variable, its ancestors nearest first in the tree declared by
    /// [`DenseQp::set_tree`] (empty: no tree, dense factorisation).
    chains: Vec<Vec<usize>>,
    /// The tree factorisation `H = Lᵀ D L` (`L` unit lower triangular, non-zero only at
    /// `L[k][i]` for ancestors `i` of `k`), row `k` packed along its chain: `L[k][chains[k][a]]`
    /// at `tree_start[k] + a`. Packed so, the ancestors of `chains[k][a]` are the rest of
    /// `k`'s chain and the elimination updates contiguous slices. `D` apart.
    tree_l: Vec<f64>,
    tree_start: Vec<usize>,
    tree_d: Vec<f64>,
    /// `1 / D` from the factorisation, and `D^-½` once a constraint needs it (`inv_sqrt_d`
    /// is current when `sqrt_ready`).
    inv_d: Vec<f64>,
    sqrt_ready: bool,
    /// Tree mode: `J = L⁻¹ D^-½ Q` with `L⁻¹ D^-½` applied through the factor and only the
    /// orthogonal `Q` (the Givens rotations so far) stored, by columns in `jt`: column `k`
    /// is `e_k` until a rotation first touches it (`touched[k]`).
    touched: Vec<bool>,
    inv_sqrt_d: Vec<f64>,
    /// Scratch for the tree solves.
    w: Vec<f64>,
    /// Constraints added or dropped in the last solve.
    pub iterations: usize,
}

impl DenseQp {
    #[must_use]
    pub fn new(n: usize) -> DenseQp {
        DenseQp {
            n,
            h: vec![0.0; n * n],
            c: vec![0.0; n],
            lb: vec![f64::NEG_INFINITY; n],
            ub: vec![f64::INFINITY; n],
            a: Vec::new(),
            b: Vec::new(),
            in_use: 0,
            row_norm: Vec::new(),
            row_finite: Vec::new(),
            row_span: Vec::new(),
            checked: 0,
            x: vec![0.0; n],
            jt: vec![0.0; n * n],
            r: vec![0.0; n * n],
            active: Vec::with_capacity(n),
            bound_active: vec![[false; 2]; n],
            row_active: Vec::new(),
            u: Vec::with_capacity(n + 1),
            d: vec![0.0; n],
            z: vec![0.0; n],
            dual_dir: vec![0.0; n],
            normal: vec![0.0; n],
            chains: Vec::new(),
            tree_l: Vec::new(),
            tree_start: Vec::new(),
            tree_d: vec![0.0; n],
            inv_d: vec![0.0; n],
            sqrt_ready: false,
            touched: vec![true; n],
            inv_sqrt_d: vec![0.0; n],
            w: vec![0.0; n],
            iterations: 0,
        }
    }

    /// Declares that `h[i][j] ≠ 0` only when `i` and `j` are equal or one is an ancestor of
    /// the other in the tree `parent` (parents have lower indices), as for `BoxQp::set_tree`:
    /// true of a Hessian built from body Jacobians over MuJoCo's dof tree. The factorisation
    /// is then MuJoCo's `mj_factorI` (`H = Lᵀ D L` eliminating leaves first, no fill-in) and
    /// `J = L⁻¹ D^-½ Q` (`J Jᵀ = H⁻¹` for any orthogonal `Q`) is never formed: products with
    /// `L⁻¹ D^-½` are tree solves, and only `Q`, the identity until the Givens rotations of
    /// the active set touch its columns, is stored. Ignored unless `parent` has `n` entries,
    /// each lower than its index.
    pub fn set_tree(&mut self, parent: &[Option<usize>]) {
        if let Some(chains) = super::ancestor_chains(parent, self.n) {
            self.chains = chains;
            self.tree_start = self
                .chains
                .iter()
                .scan(0, |start, chain| {
                    let at = *start;
                    *start += chain.len();
                    Some(at)
                })
                .collect();
            self.tree_l = vec![0.0; self.chains.iter().map(Vec::len).sum()];
        } else {
            self.chains.clear();
        }
    }

    #[must_use]
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Removes every general row.
    pub fn clear_rows(&mut self) {
        self.a.clear();
        self.b.clear();
        self.in_use = 0;
        self.checked = 0;
    }

    /// Takes only the first `k` rows into account from now on (all rows stay stored; a
    /// larger `k` brings them back). [`DenseQp::add_row`] makes every row count again.
    pub fn use_rows(&mut self, k: usize) {
        self.in_use = k.min(self.b.len());
    }

    /// Whether `x` satisfies every row in use (to a rounding tolerance).
    #[must_use]
    pub fn rows_hold(&self, x: &[f64]) -> bool {
        let n = self.n;
        (0..self.in_use).all(|k| {
            let row = &self.a[k * n..(k + 1) * n];
            dot(row, x) - self.b[k] >= -1e-12 * (1.0 + self.b[k].abs())
        })
    }

    /// Adds the row `a · x ≥ b` and returns `a` (zeros) to fill in.
    pub fn add_row(&mut self, b: f64) -> &mut [f64] {
        let start = self.a.len();
        self.a.resize(start + self.n, 0.0);
        self.b.push(b);
        self.in_use = self.b.len();
        &mut self.a[start..]
    }

    /// Right-hand sides of the stored rows.
    #[must_use]
    pub fn rhs(&self) -> &[f64] {
        &self.b
    }

    /// Re-centres every stored row on a point `shift` away from where it was made: with
    /// `base` the right-hand sides as made (from [`DenseQp::rhs`]), `a · x ≥ base − a · shift`.
    /// Every row counts again. Rows or `shift` of the wrong length leave the rows unchanged.
    pub fn shift_rows(&mut self, base: &[f64], shift: &[f64]) {
        let n = self.n;
        if base.len() != self.b.len() || shift.len() != n {
            return;
        }
        for ((b, base), row) in self.b.iter_mut().zip(base).zip(self.a.chunks_exact(n)) {
            *b = base - dot(row, shift);
        }
        self.in_use = self.b.len();
    }

    /// Row `k`: `(a, b)` of `a · x ≥ b`.
    #[must_use]
    pub fn row(&self, k: usize) -> Option<(&[f64], f64)> {
        Some((self.a.get(k * self.n..(k + 1) * self.n)?, *self.b.get(k)?))
    }

    /// Rows stored (in use or not).
    #[must_use]
    pub fn num_rows(&self) -> usize {
        self.b.len()
    }

    /// Whether general row `k` is in the final active set.
    #[must_use]
    pub fn row_is_active(&self, k: usize) -> bool {
        self.row_active.get(k).copied().unwrap_or(false)
    }

    /// Solves the problem currently stored; the minimiser is left in `x`. On
    /// [`QpStatus::Infeasible`] `x` is the last dual-feasible iterate (it satisfies the
    /// constraints that were active, not all of them).
    pub fn solve(&mut self) -> QpStatus {
        self.iterations = 0;
        self.active.clear();
        self.u.clear();
        self.bound_active.fill([false; 2]);
        self.row_active.clear();
        self.row_active.resize(self.b.len(), false);
        let m = self.in_use;
        self.check_rows();
        let finite_data = self.c.iter().chain(&self.b[..m]).all(|v| v.is_finite())
            && self.row_finite[..m].iter().all(|f| *f);
        let ordered_bounds =
            self.lb.iter().zip(&self.ub).all(|(l, u)| l <= u && *l < f64::INFINITY);
        if !finite_data || !ordered_bounds {
            return QpStatus::Infeasible;
        }
        let tree = self.chains.len() == self.n;
        if !(if tree { self.factor_tree() } else { self.factor() }) {
            return QpStatus::NotPositiveDefinite;
        }
        if tree {
            self.unconstrained_tree();
        } else {
            self.unconstrained();
        }
        let cap = 4 * (2 * self.n + m) + 20;
        while let Some((p, slack)) = self.most_violated() {
            match self.add_constraint(p, slack, cap) {
                Ok(()) => {}
                Err(status) => return status,
            }
        }
        QpStatus::Optimal
    }

    /// Norms and finiteness of the rows added since the last check.
    fn check_rows(&mut self) {
        let n = self.n;
        let rows = self.b.len();
        self.row_norm.truncate(self.checked);
        self.row_finite.truncate(self.checked);
        self.row_span.truncate(self.checked);
        for row in self.a[self.checked * n..rows * n].chunks_exact(n) {
            // Zeros outside the span change neither the norm nor finiteness.
            let first = row.iter().position(|v| *v != 0.0).unwrap_or(0);
            let last = row.iter().rposition(|v| *v != 0.0).map_or(first, |i| i + 1);
            let span = &row[first..last];
            self.row_norm.push(dot(span, span).sqrt());
            self.row_finite.push(span.iter().all(|v| v.is_finite()));
            self.row_span.push((first, last));
        }
        self.checked = rows;
    }

    /// `H = L Lᵀ`, then `J = L⁻ᵀ` (its column `k` is row `k` of `L⁻¹`). Row slices and
    /// skipped zeros keep it fast on the kinematic tree's sparsity (no fill-in: most of `L`'s
    /// lower triangle is zero).
    fn factor(&mut self) -> bool {
        let n = self.n;
        // Cholesky into `r` as scratch (row-major lower triangle), row by row.
        let l = &mut self.r;
        for i in 0..n {
            for j in 0..=i {
                l[i * n + j] = self.h[j * n + i];
            }
        }
        let inv = &mut self.z; // 1 / L[j][j], scratch until the first iteration
        for i in 0..n {
            let (done, rest) = l.split_at_mut(i * n);
            let row_i = &mut rest[..n];
            for j in 0..i {
                let row_j = &done[j * n..j * n + j];
                row_i[j] = (row_i[j] - dot(&row_i[..j], row_j)) * inv[j];
            }
            let d = row_i[i] - dot(&row_i[..i], &row_i[..i]);
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            row_i[i] = d.sqrt();
            inv[i] = 1.0 / row_i[i];
            row_i[i + 1..].fill(0.0);
        }
        // Rows of L⁻¹: row i = (e_i − Σ_{k<i} L[i][k] row_k) / L[i][i], row k non-zero in ..=k.
        let jt = &mut self.jt;
        jt.fill(0.0);
        for i in 0..n {
            let inv_lii = self.z[i];
            let (done, rest) = jt.split_at_mut(i * n);
            let row_i = &mut rest[..n];
            row_i[i] = inv_lii;
            for k in 0..i {
                let f = l[i * n + k] * inv_lii;
                if f != 0.0 {
                    for (x, y) in row_i[..=k].iter_mut().zip(&done[k * n..k * n + k + 1]) {
                        *x -= f * y;
                    }
                }
            }
        }
        self.r.fill(0.0);
        self.touched.fill(true);
        true
    }

    /// `H = Lᵀ D L` on the tree (`mj_factorI`: rows from the leaves up, each row's
    /// elimination touching only its ancestors); `Q` starts as the identity.
    fn factor_tree(&mut self) -> bool {
        let n = self.n;
        let (l, d) = (&mut self.tree_l, &mut self.tree_d);
        for (k, (chain, &start)) in self.chains.iter().zip(&self.tree_start).enumerate() {
            d[k] = self.h[k * n + k];
            for (v, &i) in l[start..start + chain.len()].iter_mut().zip(chain) {
                *v = self.h[i * n + k];
            }
        }
        for k in (0..n).rev() {
            let dk = d[k];
            if !(dk > 0.0 && dk.is_finite()) {
                return false;
            }
            let inv = 1.0 / dk;
            let (chain, start) = (&self.chains[k], self.tree_start[k]);
            // Row k lies after the rows of its ancestors (lower indices come first).
            let (above, row_k) = l.split_at_mut(start);
            let row_k = &mut row_k[..chain.len()];
            // Ancestors nearest first: row k's entries above `i` are not scaled yet. The
            // ancestors of `i = chain[a]` are `chain[a + 1..]`, in the same order.
            for (a, &i) in chain.iter().enumerate() {
                let tmp = row_k[a] * inv;
                d[i] -= tmp * row_k[a];
                let row_i =
                    &mut above[self.tree_start[i]..self.tree_start[i] + chain.len() - a - 1];
                for (x, y) in row_i.iter_mut().zip(&row_k[a + 1..]) {
                    *x -= tmp * y;
                }
                row_k[a] = tmp;
            }
            self.inv_d[k] = inv;
        }
        self.sqrt_ready = false;
        self.touched.fill(false);
        // `R` needs no clearing: only entries written since (a column's rows up to its
        // diagonal when it enters, kept so when columns move) are ever read.
        true
    }

    /// Row `k` of the packed `L` with its columns (`chains[k]`).
    fn tree_row(&self, k: usize) -> impl Iterator<Item = (f64, usize)> + '_ {
        let start = self.tree_start[k];
        let chain = &self.chains[k];
        self.tree_l[start..start + chain.len()].iter().copied().zip(chain.iter().copied())
    }

    /// Column `k` of `Q` holds `e_k` from now on if no rotation has touched it yet.
    fn ready(&mut self, k: usize) {
        let n = self.n;
        if !self.touched[k] {
            let col = &mut self.jt[k * n..(k + 1) * n];
            col.fill(0.0);
            col[k] = 1.0;
            self.touched[k] = true;
        }
    }

    /// Tree mode: `d = Jᵀ n_p = Qᵀ D^-½ L⁻ᵀ n_p` (`Lᵀ w = n_p` from the leaves up).
    fn tree_dual(&mut self) {
        let n = self.n;
        if !self.sqrt_ready {
            // Half the solves add no constraint and never need it.
            for (s, inv) in self.inv_sqrt_d.iter_mut().zip(&self.inv_d) {
                *s = inv.sqrt();
            }
            self.sqrt_ready = true;
        }
        let mut w = std::mem::take(&mut self.w);
        w.copy_from_slice(&self.normal);
        for k in (0..n).rev() {
            let wk = w[k];
            if wk != 0.0 {
                for (lki, i) in self.tree_row(k) {
                    w[i] -= lki * wk;
                }
            }
        }
        for (wk, s) in w.iter_mut().zip(&self.inv_sqrt_d) {
            *wk *= s;
        }
        for k in 0..n {
            self.d[k] = if self.touched[k] { dot(&self.jt[k * n..(k + 1) * n], &w) } else { w[k] };
        }
        self.w = w;
    }

    /// Tree mode: `z = J₂ d₂ = L⁻¹ D^-½ (Q₂ d₂)` (`L z = y` from the root down).
    fn tree_primal(&mut self, q: usize) {
        let n = self.n;
        let mut y = std::mem::take(&mut self.w);
        y.fill(0.0);
        for k in q..n {
            let dk = self.d[k];
            if dk == 0.0 {
                continue;
            }
            if self.touched[k] {
                for (yi, qi) in y.iter_mut().zip(&self.jt[k * n..(k + 1) * n]) {
                    *yi += dk * qi;
                }
            } else {
                y[k] += dk;
            }
        }
        let mut z = std::mem::take(&mut self.z);
        for k in 0..n {
            let mut zk = y[k] * self.inv_sqrt_d[k];
            for (lki, i) in self.tree_row(k) {
                zk -= lki * z[i];
            }
            z[k] = zk;
        }
        self.z = z;
        self.w = y;
    }

    /// `x = −H⁻¹ c` through the tree factorisation (`mj_solveM`).
    fn unconstrained_tree(&mut self) {
        let n = self.n;
        let mut x = std::mem::take(&mut self.x);
        for (xi, ci) in x.iter_mut().zip(&self.c) {
            *xi = -ci;
        }
        for k in (0..n).rev() {
            let xk = x[k];
            for (lki, i) in self.tree_row(k) {
                x[i] -= lki * xk;
            }
        }
        for (xk, inv) in x.iter_mut().zip(&self.inv_d) {
            *xk *= inv;
        }
        for k in 0..n {
            let mut xk = x[k];
            for (lki, i) in self.tree_row(k) {
                xk -= lki * x[i];
            }
            x[k] = xk;
        }
        self.x = x;
    }

    /// Dense mode: `x = −J Jᵀ c`.
    fn unconstrained(&mut self) {
        let n = self.n;
        self.x.fill(0.0);
        for k in 0..n {
            let col = &self.jt[k * n..(k + 1) * n];
            let w = dot(col, &self.c);
            for (xi, ji) in self.x.iter_mut().zip(col) {
                *xi -= w * ji;
            }
        }
    }

    /// Slack `s = n·x − b` of a constraint (negative when violated).
    fn slack(&self, con: Con) -> f64 {
        match con {
            Con::Lower(i) => self.x[i] - self.lb[i],
            Con::Upper(i) => self.ub[i] - self.x[i],
            Con::Row(k) => dot(&self.a[k * self.n..(k + 1) * self.n], &self.x) - self.b[k],
        }
    }

    /// The most violated inactive constraint (slack scaled by the normal's length) beyond a
    /// rounding tolerance, with its slack.
    fn most_violated(&self) -> Option<(Con, f64)> {
        let n = self.n;
        let mut worst: Option<(Con, f64)> = None;
        let mut worst_scaled = 0.0;
        let tol = |scale: f64| -1e-12 * (1.0 + scale);
        let mut consider = |con: Con, slack: f64, norm: f64, scale: f64| {
            if slack < tol(scale) && slack / norm < worst_scaled {
                worst_scaled = slack / norm;
                worst = Some((con, slack));
            }
        };
        for i in 0..n {
            let [lower, upper] = self.bound_active[i];
            if self.lb[i] > f64::NEG_INFINITY && !lower {
                consider(Con::Lower(i), self.x[i] - self.lb[i], 1.0, self.lb[i].abs());
            }
            if self.ub[i] < f64::INFINITY && !upper {
                consider(Con::Upper(i), self.ub[i] - self.x[i], 1.0, self.ub[i].abs());
            }
        }
        for k in 0..self.in_use {
            if self.row_active[k] {
                continue;
            }
            let norm = self.row_norm[k];
            if norm == 0.0 {
                continue; // 0 ≥ b: cannot be helped; a violated one stays violated
            }
            let (first, last) = self.row_span[k];
            let row = &self.a[k * n + first..k * n + last];
            let slack = dot(row, &self.x[first..last]) - self.b[k];
            consider(Con::Row(k), slack, norm, self.b[k].abs());
        }
        worst
    }

    /// Writes the normal of `con` into `self.normal`.
    fn load_normal(&mut self, con: Con) {
        let n = self.n;
        match con {
            Con::Lower(i) => {
                self.normal.fill(0.0);
                self.normal[i] = 1.0;
            }
            Con::Upper(i) => {
                self.normal.fill(0.0);
                self.normal[i] = -1.0;
            }
            Con::Row(k) => self.normal.copy_from_slice(&self.a[k * n..(k + 1) * n]),
        }
    }

    /// Goldfarb–Idnani steps 2–3 for the violated constraint `p`: partial and full steps
    /// until `p` is satisfied and active.
    fn add_constraint(&mut self, p: Con, mut slack: f64, cap: usize) -> Result<(), QpStatus> {
        let (n, tree) = (self.n, self.chains.len() == self.n);
        self.load_normal(p);
        let mut u_p = 0.0;
        loop {
            self.iterations += 1;
            if self.iterations > cap {
                return Err(QpStatus::IterationLimit);
            }
            let q = self.active.len();
            // d = Jᵀ n_p; z = J₂ d₂ (primal direction); r = R⁻¹ d₁ (dual direction).
            if tree {
                self.tree_dual();
                self.tree_primal(q);
            } else {
                self.dense_directions(p, q);
            }
            for i in (0..q).rev() {
                let mut s = self.d[i];
                for k in i + 1..q {
                    s -= self.r[k * n + i] * self.dual_dir[k];
                }
                self.dual_dir[i] = s / self.r[i * n + i];
            }
            // Partial step: the first active multiplier to reach zero.
            let (mut t1, mut drop) = (f64::INFINITY, None);
            for i in 0..q {
                if self.dual_dir[i] > 0.0 {
                    let t = self.u[i] / self.dual_dir[i];
                    if t < t1 {
                        (t1, drop) = (t, Some(i));
                    }
                }
            }
            // Full step: the length that satisfies p (z·n_p = |d₂|² > 0 unless p depends
            // linearly on the active normals).
            let zn: f64 = self.d[q..].iter().map(|v| v * v).sum();
            let nn = dot(&self.normal, &self.normal);
            // A normal (nearly) in the span of the active ones has a tiny z: treat it as
            // dependent (a dual step), as a full step along it would be huge and wrong.
            let t2 = if zn > 1e-12 * nn { -slack / zn } else { f64::INFINITY };
            let t = t1.min(t2);
            if t == f64::INFINITY {
                return Err(QpStatus::Infeasible);
            }
            if t2.is_finite() {
                for (xi, zi) in self.x.iter_mut().zip(&self.z) {
                    *xi += t * zi;
                }
            }
            for i in 0..q {
                self.u[i] -= t * self.dual_dir[i];
            }
            u_p += t;
            if t == t2 {
                self.push_active(p, u_p);
                return Ok(());
            }
            if let Some(i) = drop {
                self.drop_active(i);
            }
            slack = self.slack(p);
            if slack >= 0.0 {
                // Rounding satisfied p on a partial step: nothing to add.
                return Ok(());
            }
        }
    }

    /// Dense mode: `d = Jᵀ n_p` and `z = J₂ d₂` with `J` stored.
    fn dense_directions(&mut self, p: Con, q: usize) {
        let n = self.n;
        match p {
            Con::Lower(i) | Con::Upper(i) => {
                let sign = if matches!(p, Con::Lower(_)) { 1.0 } else { -1.0 };
                for k in 0..n {
                    self.d[k] = sign * self.jt[k * n + i];
                }
            }
            Con::Row(_) => {
                for k in 0..n {
                    self.d[k] = dot(&self.jt[k * n..(k + 1) * n], &self.normal);
                }
            }
        }
        self.z.fill(0.0);
        for k in q..n {
            let dk = self.d[k];
            if dk != 0.0 {
                for (zi, ji) in self.z.iter_mut().zip(&self.jt[k * n..(k + 1) * n]) {
                    *zi += dk * ji;
                }
            }
        }
    }

    /// Adds `con` (its `d = Jᵀ n` is in `self.d`): rotate the non-zeros of `d[q..]` into one
    /// entry, pairwise from the last up, carrying each rotation over to the columns of `J`,
    /// and swap that column to position `q` (any orthogonal map of `J`'s columns `q..` keeps
    /// `Jᵀ N = [R; 0]`); `R` gains the column `d[..=q]`. With the tree's sparse `J` this is a
    /// few rotations instead of `n − q`.
    fn push_active(&mut self, con: Con, multiplier: f64) {
        let n = self.n;
        let q = self.active.len();
        let mut kept: Option<usize> = None;
        for i in (q..n).rev() {
            if self.d[i] == 0.0 {
                continue;
            }
            if let Some(upper) = kept {
                self.ready(i);
                self.ready(upper);
                let (a, b) = (self.d[i], self.d[upper]);
                let h = (a * a + b * b).sqrt(); // no overflow at these magnitudes; faster than hypot
                let (cs, sn) = (a / h, b / h);
                self.d[i] = h;
                self.d[upper] = 0.0;
                rotate_columns(&mut self.jt, n, i, upper, cs, sn);
            }
            kept = Some(i);
        }
        if let Some(p) = kept.filter(|&p| p != q) {
            self.ready(q);
            self.ready(p);
            let (lo, hi) = self.jt.split_at_mut(p * n);
            lo[q * n..(q + 1) * n].swap_with_slice(&mut hi[..n]);
            self.d.swap(q, p);
        }
        self.r[q * n..q * n + q + 1].copy_from_slice(&self.d[..=q]);
        self.active.push(con);
        self.u.push(multiplier);
        self.set_flag(con, true);
    }

    /// Removes active constraint `i`: its column leaves `R`, the Hessenberg remainder is
    /// made triangular again by rotating rows of `R` (and the matching columns of `J`).
    fn drop_active(&mut self, i: usize) {
        let n = self.n;
        let q = self.active.len();
        let con = self.active.remove(i);
        self.set_flag(con, false);
        self.u.remove(i);
        for k in i..q - 1 {
            let (src, dst) = ((k + 1) * n, k * n);
            self.r.copy_within(src..src + n, dst);
        }
        self.r[(q - 1) * n..q * n].fill(0.0);
        for k in i..q - 1 {
            // Zero R[k+1][k] against R[k][k].
            let (a, b) = (self.r[k * n + k], self.r[k * n + k + 1]);
            if b == 0.0 {
                continue;
            }
            let h = (a * a + b * b).sqrt(); // no overflow at these magnitudes; faster than hypot
            let (cs, sn) = (a / h, b / h);
            for col in k..q - 1 {
                let (x, y) = (self.r[col * n + k], self.r[col * n + k + 1]);
                self.r[col * n + k] = cs * x + sn * y;
                self.r[col * n + k + 1] = -sn * x + cs * y;
            }
            self.r[k * n + k + 1] = 0.0;
            self.ready(k);
            self.ready(k + 1);
            rotate_columns(&mut self.jt, n, k, k + 1, cs, sn);
        }
    }
}

impl DenseQp {
    fn set_flag(&mut self, con: Con, on: bool) {
        match con {
            Con::Lower(i) => self.bound_active[i][0] = on,
            Con::Upper(i) => self.bound_active[i][1] = on,
            Con::Row(k) => self.row_active[k] = on,
        }
    }
}

/// Columns `a < b` of `J` become `c·Ja + s·Jb` and `−s·Ja + c·Jb`.
fn rotate_columns(jt: &mut [f64], n: usize, a: usize, b: usize, cs: f64, sn: f64) {
    let (lo, hi) = jt.split_at_mut(b * n);
    let col_a = &mut lo[a * n..(a + 1) * n];
    let col_b = &mut hi[..n];
    for (x, y) in col_a.iter_mut().zip(col_b.iter_mut()) {
        let (p, q) = (*x, *y);
        *x = cs * p + sn * q;
        *y = -sn * p + cs * q;
    }
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests;
