//! Non-negative least squares with six rows: `min ‖A x − b‖` subject to `x ≥ 0`, Lawson and
//! Hanson's active-set algorithm (C. L. Lawson, R. J. Hanson, *Solving Least Squares
//! Problems*, 1974, ch. 23, algorithm NNLS).
//!
//! Written here rather than taken from a crate: the dynamics check solves one such problem
//! per frame with six rows (a wrench) and a few dozen columns (friction-cone edges), and the
//! passive set never holds more than six independent columns, so the whole solve runs on
//! fixed 6 × 6 arrays without allocating; the crates for NNLS work on general dense matrices
//! and allocate per call.

// Exception to `indexing_slicing`: every index runs over the caller's columns (`0..n`) or
// the passive set (at most 6 entries, each an index into those columns, the arrays sized 6).
#![allow(clippy::indexing_slicing)]

/// Rows of every problem: a wrench (force, torque).
pub(crate) const ROWS: usize = 6;

pub(crate) type Column = [f64; ROWS];

fn dot(a: &Column, b: &Column) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves `min ‖Σ_j x_j cols[j] − b‖`, `x ≥ 0`; writes `x` (resized to the columns) and
/// returns the residual `b − A x`.
pub(crate) fn nnls(cols: &[Column], b: &Column, x: &mut Vec<f64>) -> Column {
    let n = cols.len();
    x.clear();
    x.resize(n, 0.0);
    let scale = cols.iter().map(|c| dot(c, c)).fold(dot(b, b), f64::max).sqrt().max(1e-300);
    let tol = 1e-12 * scale * scale;
    let mut passive: Vec<usize> = Vec::with_capacity(ROWS);
    let mut blocked = vec![false; n];
    let mut r = *b;
    // The columns by rows, for the gradient (`by_rows[i n + j]`: row i of column j).
    let mut by_rows = Vec::with_capacity(ROWS * n);
    for i in 0..ROWS {
        by_rows.extend(cols.iter().map(|c| c[i]));
    }
    let mut w = vec![0.0; n];
    // Lawson and Hanson bound the outer loop by 3n in their implementation.
    for _ in 0..3 * n.max(1) {
        // The most promising column outside the passive set (gradient w = Aᵀ r; the last
        // of equal ones, as `max_by`).
        gradient(&by_rows, &r, &mut w);
        let mut entering: Option<(usize, f64)> = None;
        for (j, &wj) in w.iter().enumerate() {
            if wj > tol
                && !blocked[j]
                && entering.is_none_or(|(_, best)| wj.total_cmp(&best).is_ge())
                && !passive.contains(&j)
            {
                entering = Some((j, wj));
            }
        }
        let Some((j, _)) = entering else { break };
        passive.push(j);
        let mut z = [0.0; ROWS];
        if passive.len() > ROWS || !least_squares(cols, &passive, b, &mut z) {
            // Dependent on the passive columns to rounding: it cannot reduce the residual.
            passive.pop();
            blocked[j] = true;
            continue;
        }
        // Inner loop: step from x towards z until z is positive on the passive set.
        let mut solved = true;
        while let Some(alpha) = passive
            .iter()
            .enumerate()
            .filter(|&(k, _)| z[k] <= 0.0)
            .map(|(k, &i)| x[i] / (x[i] - z[k]))
            .min_by(f64::total_cmp)
        {
            for (k, &i) in passive.iter().enumerate() {
                x[i] += alpha * (z[k] - x[i]);
            }
            passive.retain(|&i| {
                let keep = x[i] > 1e-15 * scale;
                if !keep {
                    x[i] = 0.0;
                }
                keep
            });
            if passive.is_empty() || !least_squares(cols, &passive, b, &mut z) {
                solved = false;
                break;
            }
        }
        if solved {
            for (k, &i) in passive.iter().enumerate() {
                x[i] = z[k].max(0.0);
            }
        }
        r = *b;
        for (j, c) in cols.iter().enumerate().filter(|(j, _)| x[*j] > 0.0) {
            for (ri, ci) in r.iter_mut().zip(c) {
                *ri -= x[j] * ci;
            }
        }
        blocked.iter_mut().for_each(|b| *b = false);
    }
    r
}

/// `w = Aᵀ r` from `A`'s rows (`by_rows`, `ROWS × n`): each entry [`dot`]'s sum, in its
/// order (`p₀ + p₁ + … + p₅`), the columns side by side (vectorised across them).
fn gradient(by_rows: &[f64], r: &Column, w: &mut [f64]) {
    let n = w.len();
    let mut rows = by_rows.chunks_exact(n.max(1));
    let mut row = || rows.next().unwrap_or_default();
    let (a, b, c, d, e, f) = (row(), row(), row(), row(), row(), row());
    let columns = a.iter().zip(b).zip(c).zip(d).zip(e).zip(f);
    for (wj, (((((a, b), c), d), e), f)) in w.iter_mut().zip(columns) {
        *wj = a * r[0] + b * r[1] + c * r[2] + d * r[3] + e * r[4] + f * r[5];
    }
}

/// The unconstrained least squares on the passive columns, through the normal equations
/// (Cholesky of their Gram matrix). False when the columns are dependent to rounding.
fn least_squares(cols: &[Column], passive: &[usize], b: &Column, z: &mut Column) -> bool {
    let k = passive.len();
    let mut g = [[0.0; ROWS]; ROWS];
    let mut rhs = [0.0; ROWS];
    for (p, &i) in passive.iter().enumerate() {
        for (q, &j) in passive.iter().enumerate().take(p + 1) {
            g[p][q] = dot(&cols[i], &cols[j]);
        }
        rhs[p] = dot(&cols[i], b);
    }
    // In-place Cholesky (lower triangle): G = L Lᵀ.
    for p in 0..k {
        let diag = g[p][p];
        let d = diag - g[p][..p].iter().map(|v| v * v).sum::<f64>();
        if d <= 1e-12 * diag.max(1e-300) {
            return false;
        }
        let d = d.sqrt();
        g[p][p] = d;
        for i in p + 1..k {
            let s = g[i][p] - g[i][..p].iter().zip(&g[p][..p]).map(|(a, b)| a * b).sum::<f64>();
            g[i][p] = s / d;
        }
    }
    // L y = rhs, then Lᵀ z = y.
    for p in 0..k {
        let mut s = rhs[p];
        for q in 0..p {
            s -= g[p][q] * z[q];
        }
        z[p] = s / g[p][p];
    }
    for p in (0..k).rev() {
        let mut s = z[p];
        for q in p + 1..k {
            s -= g[q][p] * z[q];
        }
        z[p] = s / g[p][p];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(i: usize) -> Column {
        let mut c = [0.0; ROWS];
        c[i] = 1.0;
        c
    }

    #[test]
    fn reaches_a_target_inside_the_cone_exactly() {
        let cols = [unit(0), unit(1), [1.0, 1.0, 0.0, 0.0, 0.0, 1.0]];
        let b = [2.0, 3.0, 0.0, 0.0, 0.0, 1.0];
        let mut x = Vec::new();
        let r = nnls(&cols, &b, &mut x);
        assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
        assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12, "{x:?}");
        assert!((x[2] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_target_outside_the_cone_leaves_its_distance() {
        // The cone of e0 and e1 cannot push along −e0 nor along e2.
        let cols = [unit(0), unit(1), unit(1)];
        let b = [-1.0, 2.0, 0.5, 0.0, 0.0, 0.0];
        let mut x = Vec::new();
        let r = nnls(&cols, &b, &mut x);
        assert_eq!(x[0], 0.0);
        assert!((x[1] + x[2] - 2.0).abs() < 1e-12, "{x:?}");
        assert!((r[0] + 1.0).abs() < 1e-12 && (r[2] - 0.5).abs() < 1e-12 && r[1].abs() < 1e-12);
    }

    #[test]
    fn matches_projected_gradient_on_random_problems() {
        // The KKT conditions: x ≥ 0, w = Aᵀ r ≤ 0, and w_j = 0 where x_j > 0.
        let mut seed = 7u64;
        let mut rand = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..200 {
            let cols: Vec<Column> = (0..20).map(|_| std::array::from_fn(|_| rand())).collect();
            let b: Column = std::array::from_fn(|_| 3.0 * rand());
            let mut x = Vec::new();
            let r = nnls(&cols, &b, &mut x);
            for (j, c) in cols.iter().enumerate() {
                let w = dot(c, &r);
                assert!(x[j] >= 0.0);
                assert!(w < 1e-9, "w {w}");
                if x[j] > 0.0 {
                    assert!(w.abs() < 1e-9, "w {w} at x {}", x[j]);
                }
            }
        }
    }
}
