//! A symmetric positive definite system that is block-pentadiagonal in time: frame `t`'s
//! unknowns (`n` of them, the robot's velocity coordinates) couple with those of frames
//! `t ± 1` and `t ± 2` only (a second difference couples three frames), solved exactly by the
//! block Cholesky factorisation `A = L Lᵀ`, `L` block lower-banded with the same bandwidth.
//!
//! ```text
//! L_{t,t−2} = A_{t,t−2} L_{t−2,t−2}⁻ᵀ
//! L_{t,t−1} = (A_{t,t−1} − L_{t,t−2} L_{t−1,t−2}ᵀ) L_{t−1,t−1}⁻ᵀ
//! L_{t,t}   = chol(A_{t,t} − L_{t,t−1} L_{t,t−1}ᵀ − L_{t,t−2} L_{t,t−2}ᵀ)
//! ```
//!
//! The cost is `O(T n³)` (about 6 n³ flops a frame) and the storage three `n × n` blocks a
//! frame; eliminating in time order creates no fill outside the band, where any other order
//! fills the off-diagonal blocks of the whole clip (the tree's own sparsity inside a block is
//! lost either way: the Schur complements couple every dof of a frame with every other).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: blocks are `n × n` and vectors `T n`, sized in `Banded::new`; frame indices stay
// below `T`.
#![allow(clippy::indexing_slicing)]

use nalgebra::{DMatrix, DMatrixView, DVector};

/// The system: per frame its diagonal block and its blocks towards the frame before and the
/// one before that (`A_{t,t−1}`, `A_{t,t−2}`; zero for the first frames), and the right-hand
/// side. Fill with [`Banded::add`], [`Banded::block_mut`] and `rhs`, then
/// [`Banded::factor`] and [`Banded::solve`].
#[derive(Debug, Clone)]
pub struct Banded {
    n: usize,
    frames: usize,
    /// `A_{t,t}` (symmetric; overwritten by `L_{t,t}` in [`Banded::factor`]).
    diag: Vec<DMatrix<f64>>,
    /// `A_{t,t−1}`, then `L_{t,t−1}`.
    sub1: Vec<DMatrix<f64>>,
    /// `A_{t,t−2}`, then `L_{t,t−2}`.
    sub2: Vec<DMatrix<f64>>,
    pub rhs: DVector<f64>,
    /// `L_{t,t}⁻¹` per frame ([`Banded::factor`]).
    inverse: Vec<DMatrix<f64>>,
    /// A product's output, swapped with the block it replaces (its old contents are never
    /// read: the products into it do not read their output).
    scratch: DMatrix<f64>,
    /// Work buffers: the non-zero entries of a penalty's two rows ([`Banded::add_penalty`]),
    /// a diagonal block's reciprocal pivots ([`lower_inverse`]).
    nonzero: (Vec<usize>, Vec<usize>),
    reciprocal: Vec<f64>,
    /// The system as [`Banded::save`] found it.
    saved: Option<Saved>,
}

/// A copy of the system's blocks and right-hand side ([`Banded::save`]).
#[derive(Debug, Clone)]
struct Saved {
    diag: Vec<DMatrix<f64>>,
    sub1: Vec<DMatrix<f64>>,
    sub2: Vec<DMatrix<f64>>,
    rhs: DVector<f64>,
}

/// `to = from`, block by block (`to` of the same shapes).
fn copy_blocks(to: &mut [DMatrix<f64>], from: &[DMatrix<f64>]) {
    for (t, f) in to.iter_mut().zip(from) {
        t.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// The factorisation met a block that is not positive definite (at this frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotPositiveDefinite {
    pub frame: usize,
}

impl Banded {
    #[must_use]
    pub fn new(n: usize, frames: usize) -> Banded {
        let zeros = || vec![DMatrix::zeros(n, n); frames];
        Banded {
            n,
            frames,
            diag: zeros(),
            sub1: zeros(),
            sub2: zeros(),
            rhs: DVector::zeros(n * frames),
            inverse: zeros(),
            scratch: DMatrix::zeros(n, n),
            nonzero: (Vec::with_capacity(n), Vec::with_capacity(n)),
            reciprocal: vec![0.0; n],
            saved: None,
        }
    }

    #[must_use]
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Sets the off-diagonal blocks to zero for the next system of the same size. The
    /// diagonal blocks and the right-hand side are left as they are: the caller writes each
    /// frame's whole (the trajectory's `frame_terms`) before it adds to them.
    pub fn clear_couplings(&mut self) {
        // (Through the slices: nalgebra's `fill` walks a generic strided iterator.)
        for m in self.sub1.iter_mut().chain(&mut self.sub2) {
            m.as_mut_slice().fill(0.0);
        }
    }

    /// `A_{t,t}`, to add a frame's own terms to (symmetric: both triangles are read).
    pub fn diag_mut(&mut self, t: usize) -> &mut DMatrix<f64> {
        &mut self.diag[t]
    }

    /// Adds `w` to entry `(i, j)` of the block coupling frame `t` with frame `t − lag`
    /// (`lag` 0, 1 or 2; for lag 0 the caller keeps the block symmetric).
    pub fn add(&mut self, t: usize, lag: usize, i: usize, j: usize, w: f64) {
        let block = match lag {
            0 => &mut self.diag[t],
            1 => &mut self.sub1[t],
            _ => &mut self.sub2[t],
        };
        block[(i, j)] += w;
    }

    /// The block coupling frame `t` with frame `t − lag` (`lag` 0, 1 or 2).
    pub fn block_mut(&mut self, t: usize, lag: usize) -> &mut DMatrix<f64> {
        match lag {
            0 => &mut self.diag[t],
            1 => &mut self.sub1[t],
            _ => &mut self.sub2[t],
        }
    }

    /// Adds the penalty `½ ρ (a · x_t − c · x_{t−1} − b)²` (`rho` = ρ): a row of frame `t`
    /// alone (`c`: none), or one that couples it with the frame before.
    pub fn add_penalty(&mut self, t: usize, a: &[f64], c: Option<&[f64]>, b: f64, rho: f64) {
        let nz = |v: &[f64], out: &mut Vec<usize>| {
            out.clear();
            out.extend((0..v.len()).filter(|&d| v[d] != 0.0));
        };
        let n = self.n;
        let (ia, ic) = &mut self.nonzero;
        nz(a, ia);
        add_outer(&mut self.diag[t], rho, (a, ia), (a, ia));
        let rhs = &mut self.rhs.as_mut_slice()[t * n..(t + 1) * n];
        for &i in ia.iter() {
            rhs[i] += rho * a[i] * b;
        }
        let Some(c) = c else { return };
        nz(c, ic);
        add_outer(&mut self.diag[t - 1], rho, (c, ic), (c, ic));
        add_outer(&mut self.sub1[t], -rho, (a, ia), (c, ic));
        let rhs = &mut self.rhs.as_mut_slice()[(t - 1) * n..t * n];
        for &i in ic.iter() {
            rhs[i] -= rho * c[i] * b;
        }
    }

    /// Frame `t`'s part of the right-hand side.
    pub fn rhs_mut(&mut self, t: usize) -> nalgebra::DVectorViewMut<'_, f64> {
        let n = self.n;
        self.rhs.rows_mut(t * n, n)
    }

    /// Keeps a copy of the system as it stands (before [`Banded::factor`] overwrites it), for
    /// [`Banded::restore_from`].
    pub fn save(&mut self) {
        match &mut self.saved {
            Some(saved) if saved.diag.len() == self.frames => {
                copy_blocks(&mut saved.diag, &self.diag);
                copy_blocks(&mut saved.sub1, &self.sub1);
                copy_blocks(&mut saved.sub2, &self.sub2);
                saved.rhs.copy_from(&self.rhs);
            }
            _ => {
                self.saved = Some(Saved {
                    diag: self.diag.clone(),
                    sub1: self.sub1.clone(),
                    sub2: self.sub2.clone(),
                    rhs: self.rhs.clone(),
                });
            }
        }
    }

    /// The system back as [`Banded::save`] kept it from frame `from` on, and its whole
    /// right-hand side (nothing where nothing was kept): to be added to from that frame on and
    /// factored again from there ([`Banded::factor_from`]), without assembling it again. The
    /// factor of the frames before stands: theirs depends on no block after them.
    pub fn restore_from(&mut self, from: usize) {
        let Some(saved) = &self.saved else { return };
        copy_blocks(&mut self.diag[from..], &saved.diag[from..]);
        copy_blocks(&mut self.sub1[from..], &saved.sub1[from..]);
        copy_blocks(&mut self.sub2[from..], &saved.sub2[from..]);
        self.rhs.copy_from(&saved.rhs);
    }

    /// Factorises in place. The blocks are overwritten; [`Banded::clear_couplings`] and new
    /// diagonal blocks start again.
    /// (The off-diagonal blocks are formed with the diagonal factors' inverses, products
    /// that run at matrix-multiply speed, where triangular solves by columns do not.)
    pub fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        self.factor_from(0)
    }

    /// [`Banded::factor`] of the frames from `from` on, those before already factored (by a
    /// factorisation of the same blocks there: [`Banded::restore_from`]).
    pub fn factor_from(&mut self, from: usize) -> Result<(), NotPositiveDefinite> {
        for t in from..self.frames {
            if t >= 2 {
                // L_{t,t−2} = A_{t,t−2} L_{t−2,t−2}⁻ᵀ
                gemm_abt(&mut self.scratch, 1.0, &self.sub2[t], &self.inverse[t - 2], 0.0);
                std::mem::swap(&mut self.sub2[t], &mut self.scratch);
                // A_{t,t−1} −= L_{t,t−2} L_{t−1,t−2}ᵀ
                let (head, tail) = self.sub1.split_at_mut(t);
                gemm_abt(&mut tail[0], -1.0, &self.sub2[t], &head[t - 1], 1.0);
            }
            if t >= 1 {
                gemm_abt(&mut self.scratch, 1.0, &self.sub1[t], &self.inverse[t - 1], 0.0);
                std::mem::swap(&mut self.sub1[t], &mut self.scratch);
            }
            let (s1, s2) = (&self.sub1[t], &self.sub2[t]);
            let d = &mut self.diag[t];
            if t >= 1 {
                gemm_abt(d, -1.0, s1, s1, 1.0);
            }
            if t >= 2 {
                gemm_abt(d, -1.0, s2, s2, 1.0);
            }
            cholesky_in_place(d).map_err(|()| NotPositiveDefinite { frame: t })?;
            lower_inverse(d, &mut self.inverse[t], &mut self.reciprocal);
        }
        Ok(())
    }

    /// Solves `A x = rhs` with the factorisation; `rhs` becomes `x`.
    pub fn solve(&mut self) {
        let n = self.n;
        let frames = self.frames;
        let mut b = DVector::zeros(n);
        let mut y = DVector::zeros(n);
        // Forward: L y = b.
        for t in 0..frames {
            b.copy_from(&self.rhs.rows(t * n, n));
            if t >= 1 {
                b.gemv(-1.0, &self.sub1[t], &self.rhs.rows((t - 1) * n, n), 1.0);
            }
            if t >= 2 {
                b.gemv(-1.0, &self.sub2[t], &self.rhs.rows((t - 2) * n, n), 1.0);
            }
            y.gemv(1.0, &self.inverse[t], &b, 0.0);
            self.rhs.rows_mut(t * n, n).copy_from(&y);
        }
        // Backward: Lᵀ x = y.
        for t in (0..frames).rev() {
            b.copy_from(&self.rhs.rows(t * n, n));
            if t + 1 < frames {
                b.gemv_tr(-1.0, &self.sub1[t + 1], &self.rhs.rows((t + 1) * n, n), 1.0);
            }
            if t + 2 < frames {
                b.gemv_tr(-1.0, &self.sub2[t + 2], &self.rhs.rows((t + 2) * n, n), 1.0);
            }
            y.gemv_tr(1.0, &self.inverse[t], &b, 0.0);
            self.rhs.rows_mut(t * n, n).copy_from(&y);
        }
    }
}

/// `block += s u vᵀ` over the non-zero entries of `u` and `v` (each with their indices).
fn add_outer(
    block: &mut DMatrix<f64>,
    s: f64,
    (u, iu): (&[f64], &[usize]),
    (v, iv): (&[f64], &[usize]),
) {
    for &i in iu {
        for &j in iv {
            block[(i, j)] += s * u[i] * v[j];
        }
    }
}

/// `c = β c + α a bᵀ` through nalgebra's `gemm` with `bᵀ` a view of `b`, its strides
/// swapped: the product `b.transpose()` would give (matrixmultiply packs the same numbers),
/// without allocating and copying the transpose.
fn gemm_abt(c: &mut DMatrix<f64>, alpha: f64, a: &DMatrix<f64>, b: &DMatrix<f64>, beta: f64) {
    let bt = DMatrixView::from_slice_with_strides(b.as_slice(), b.ncols(), b.nrows(), b.nrows(), 1);
    c.gemm(alpha, a, &bt, beta);
}

/// The Cholesky factor of the symmetric `a` (its lower triangle read) in place: `a = L Lᵀ`,
/// the strict upper triangle set to zero. `Err` where a pivot is not positive. Left-looking
/// by columns on the column-major storage: every update is an axpy down a contiguous column.
fn cholesky_in_place(a: &mut DMatrix<f64>) -> Result<(), ()> {
    let n = a.nrows();
    let m = a.as_mut_slice();
    for j in 0..n {
        // Column j below the diagonal, less the contributions of the columns before it.
        let (done, rest) = m.split_at_mut(j * n);
        let col = &mut rest[j..n];
        for k in 0..j {
            let ck = &done[k * n + j..k * n + n];
            let ljk = ck[0];
            if ljk != 0.0 {
                col.iter_mut().zip(ck).for_each(|(c, l)| *c -= ljk * l);
            }
        }
        let d = col[0];
        if d.is_nan() || d <= 0.0 || d.is_infinite() {
            return Err(());
        }
        let d = d.sqrt();
        col[0] = d;
        let inv = 1.0 / d;
        col[1..].iter_mut().for_each(|c| *c *= inv);
        rest[..j].fill(0.0);
    }
    Ok(())
}

/// `out = l⁻¹` for the lower-triangular `l` (non-zero diagonal), by columns: column `j` is the
/// forward substitution of `e_j`, each step an axpy down a contiguous column of `l`.
/// (`reciprocal`: a buffer for the diagonal's reciprocals.)
fn lower_inverse(l: &DMatrix<f64>, out: &mut DMatrix<f64>, reciprocal: &mut Vec<f64>) {
    let n = l.nrows();
    let l = l.as_slice();
    reciprocal.clear();
    reciprocal.extend((0..n).map(|k| 1.0 / l[k * n + k]));
    let o = out.as_mut_slice();
    o.fill(0.0);
    for j in 0..n {
        let x = &mut o[j * n..(j + 1) * n];
        x[j] = 1.0;
        for k in j..n {
            let xk = x[k] * reciprocal[k];
            x[k] = xk;
            if xk != 0.0 {
                x[k + 1..].iter_mut().zip(&l[k * n + k + 1..(k + 1) * n]).for_each(|(v, lv)| {
                    *v -= xk * lv;
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random banded SPD system against a dense Cholesky solve of the same matrix.
    #[test]
    fn the_banded_solve_equals_the_dense_one() {
        let (n, frames) = (5, 9);
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 33) as f64) / f64::from(1u32 << 31) - 0.5
        };
        let size = n * frames;
        let mut dense = DMatrix::<f64>::zeros(size, size);
        let mut banded = Banded::new(n, frames);
        for t in 0..frames {
            for lag in 0..=2.min(t) {
                for i in 0..n {
                    for j in 0..n {
                        if lag == 0 && j > i {
                            continue;
                        }
                        let v = rnd();
                        let (r, c) = (t * n + i, (t - lag) * n + j);
                        dense[(r, c)] += v;
                        dense[(c, r)] += if r == c { 0.0 } else { v };
                        banded.add(t, lag, i, j, v);
                        if lag == 0 && i != j {
                            banded.add(t, 0, j, i, v);
                        }
                    }
                }
            }
        }
        // Diagonally dominant: positive definite.
        for t in 0..frames {
            for i in 0..n {
                dense[(t * n + i, t * n + i)] += 10.0;
                banded.add(t, 0, i, i, 10.0);
            }
        }
        let b = DVector::from_fn(size, |_, _| rnd());
        banded.rhs.copy_from(&b);
        banded.save();
        banded.factor().unwrap();
        banded.solve();
        let x = dense.clone().cholesky().unwrap().solve(&b);
        assert!((&banded.rhs - &x).amax() < 1e-12, "{}", (&banded.rhs - &x).amax());
        assert!((&dense * &banded.rhs - &b).amax() < 1e-12);
        // Restored from frame 4, with a penalty added there: the system saved plus that term.
        banded.restore_from(4);
        let a: Vec<f64> = (0..n).map(|_| rnd()).collect();
        banded.add_penalty(4, &a, None, 0.3, 50.0);
        for i in 0..n {
            for j in 0..n {
                dense[(4 * n + i, 4 * n + j)] += 50.0 * a[i] * a[j];
            }
        }
        let mut b = b;
        for i in 0..n {
            b[4 * n + i] += 50.0 * a[i] * 0.3;
        }
        banded.factor_from(4).unwrap();
        banded.solve();
        let x = dense.cholesky().unwrap().solve(&b);
        assert!((&banded.rhs - &x).amax() < 1e-12, "{}", (&banded.rhs - &x).amax());
    }

    #[test]
    fn an_indefinite_block_is_reported_with_its_frame() {
        let mut banded = Banded::new(2, 3);
        for t in 0..3 {
            banded.add(t, 0, 0, 0, 1.0);
            banded.add(t, 0, 1, 1, if t == 1 { -1.0 } else { 1.0 });
        }
        assert_eq!(banded.factor(), Err(NotPositiveDefinite { frame: 1 }));
    }
}
