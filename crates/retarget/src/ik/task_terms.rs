//! A frame task's weighted Jacobian and its Gauss–Newton terms `J̃ᵀJ̃`, written for speed
//! but with mink's (and the solver's earlier) arithmetic: every sum keeps its terms and
//! their order, and only products with a factor that is exactly zero are left out (a zero
//! block of `Jlog`, the rows of a cost that is zero), which changes no value but the sign of
//! a zero. `--gmr` stays GMR's numbers and the default solve its own, bit for bit.

// Indexing: `dofs` index the Jacobians' columns (below `nv`, from the model) and the
// weighted rows are `dofs.len()` long (`TaskWork::new`); runs lie inside `dofs`.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, Model};
use nalgebra::{Matrix3, Matrix6, Vector3};

/// A task's weighted Jacobian, one row per task coordinate (position x y z, rotation x y
/// z), one entry per dof of `dofs` (rows apart, so that the Gram products below run along
/// contiguous memory).
pub(super) type Rows = [Vec<f64>; 6];

/// The runs of consecutive dof ids in `dofs` (ascending), as `(first, end)` indices into
/// `dofs`: over a run the Hessian row is contiguous too.
pub(super) fn runs(dofs: &[usize]) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (i, &d) in dofs.iter().enumerate() {
        match runs.last_mut() {
            Some(run) if i > 0 && dofs[i - 1] + 1 == d => run.1 = i + 1,
            _ => runs.push((i, i + 1)),
        }
    }
    runs
}

/// The 6 Jacobian entries of dof `d` of the body at `point`, as `mj_jac` writes them
/// ([`mjcf::Model::jac_column`]; zeros for a dof `data` does not hold).
#[inline]
fn column(data: &Data, point: &Vector3<f64>, d: usize) -> ([f64; 3], [f64; 3]) {
    let (jp, jr) = Model::jac_column(data, point, d).unwrap_or_default();
    (jp.into(), jr.into())
}

/// `m v` with nalgebra's order of operations (column by column: `Σₖ m[r, k] v[k]` from
/// `k = 0`).
#[inline]
fn mat3_vec(m: &Matrix3<f64>, v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[(r, 0)] * v[0] + m[(r, 1)] * v[1] + m[(r, 2)] * v[2])
}

/// mink's weighted Jacobian column by column: `w ∘ −(Jlog · [Rᵀ jp; Rᵀ jr])`. `Jlog` is
/// `[[A, B], [0, A]]` (`lie::se3_jlog_at` writes its lower left block as zeros), so the
/// products with that block are left out of the `6 × 6` product, whose other terms keep
/// nalgebra's order.
pub(super) fn mink_rows(
    jlog: &Matrix6<f64>,
    xmat: &Matrix3<f64>,
    w: &[f64; 6],
    (data, point): (&Data, &Vector3<f64>),
    dofs: &[usize],
    rows: &mut Rows,
) {
    let rt = xmat.transpose();
    let j = |r: usize, c: usize| jlog[(r, c)];
    for (i, &d) in dofs.iter().enumerate() {
        let (jp, jr) = column(data, point, d);
        let bp = mat3_vec(&rt, &jp);
        if jr == [0.0; 3] {
            // A translation: `Rᵀ jr` and every product with it are zeros.
            for r in 0..3 {
                let top = j(r, 0) * bp[0] + j(r, 1) * bp[1] + j(r, 2) * bp[2];
                rows[r][i] = w[r] * -top;
                rows[r + 3][i] = 0.0;
            }
            continue;
        }
        let br = mat3_vec(&rt, &jr);
        for r in 0..3 {
            let top = j(r, 0) * bp[0]
                + j(r, 1) * bp[1]
                + j(r, 2) * bp[2]
                + j(r, 3) * br[0]
                + j(r, 4) * br[1]
                + j(r, 5) * br[2];
            let bottom = j(r + 3, 3) * br[0] + j(r + 3, 4) * br[1] + j(r + 3, 5) * br[2];
            rows[r][i] = w[r] * -top;
            rows[r + 3][i] = w[r + 3] * -bottom;
        }
    }
}

/// The lean weighted Jacobian ([`super::Arithmetic::Lean`]): `Jlog = [[A, B], [0, A]]`
/// with the body rotation folded into its blocks once.
#[inline]
pub(super) fn lean_rows(
    jlog: &Matrix6<f64>,
    xmat: &Matrix3<f64>,
    w: &[f64; 6],
    (data, point): (&Data, &Vector3<f64>),
    dofs: &[usize],
    rows: &mut Rows,
) {
    let rt = xmat.transpose();
    let a = jlog.fixed_view::<3, 3>(0, 0) * rt;
    let b = jlog.fixed_view::<3, 3>(0, 3) * rt;
    for (i, &d) in dofs.iter().enumerate() {
        let (jp, jr) = column(data, point, d);
        let top_a = mat3_vec(&a, &jp);
        if jr == [0.0; 3] {
            // A translation: the products with `jr` are zeros.
            for r in 0..3 {
                rows[r][i] = -(w[r] * top_a[r]);
                rows[r + 3][i] = 0.0;
            }
            continue;
        }
        let (top_b, bottom) = (mat3_vec(&b, &jr), mat3_vec(&a, &jr));
        for r in 0..3 {
            rows[r][i] = -(w[r] * (top_a[r] + top_b[r]));
            rows[r + 3][i] = -(w[r + 3] * bottom[r]);
        }
    }
}

/// Adds `J̃ᵀJ̃` to the upper triangle of `h` (row-major `nv × nv`): for dofs `a ≤ b`, the
/// dot product of their columns over the rows whose cost is not zero (the others hold
/// only zeros), each summed in row order as a 6-term dot product would.
#[inline]
pub(super) fn add_gram(
    rows: &Rows,
    w: &[f64; 6],
    dofs: &[usize],
    runs: &[(usize, usize)],
    nv: usize,
    h: &mut [f64],
) {
    let zero = |r: std::ops::Range<usize>| w[r].iter().all(|v| *v == 0.0);
    if zero(0..3) {
        gram([&rows[3], &rows[4], &rows[5]], dofs, runs, nv, h);
    } else if zero(3..6) {
        gram([&rows[0], &rows[1], &rows[2]], dofs, runs, nv, h);
    } else {
        gram(std::array::from_fn::<_, 6, _>(|r| &rows[r][..]), dofs, runs, nv, h);
    }
}

/// [`add_gram`] over the `R` rows given. Along a run of consecutive dofs the Hessian row is
/// contiguous, so the inner loop runs over several `b` at once (each its own sum, in the
/// same order).
fn gram<const R: usize>(
    rows: [&[f64]; R],
    dofs: &[usize],
    runs: &[(usize, usize)],
    nv: usize,
    h: &mut [f64],
) {
    for (a, &da) in dofs.iter().enumerate() {
        let ca: [f64; R] = std::array::from_fn(|r| rows[r][a]);
        let h_row = &mut h[da * nv..(da + 1) * nv];
        for &(first, end) in runs.iter().filter(|run| run.1 > a) {
            let from = first.max(a);
            let n = end - from;
            let out = &mut h_row[dofs[from]..dofs[from] + n];
            let cols: [&[f64]; R] = std::array::from_fn(|r| &rows[r][from..end]);
            for t in 0..n {
                let mut sum = ca[0] * cols[0][t];
                for r in 1..R {
                    sum += ca[r] * cols[r][t];
                }
                out[t] += sum;
            }
        }
    }
}
