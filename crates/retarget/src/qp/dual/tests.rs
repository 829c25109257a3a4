//! Tests of the dual active-set solver.

use super::*;
use crate::qp::BoxQp;
use rand::{Rng, SeedableRng};

#[test]
fn shifted_rows_are_the_rows_made_at_the_new_point() {
    // The linear constraint x₀ + 2 x₁ ≥ 1 on the absolute point p = p₀ + x: made at
    // p₀ = 0 its row is (1, 2) · x ≥ 1; at p₀ = (0.5, 0.25), (1, 2) · x ≥ 0.
    let mut qp = DenseQp::new(2);
    qp.add_row(1.0).copy_from_slice(&[1.0, 2.0]);
    let base = qp.rhs().to_vec();
    qp.use_rows(0);
    qp.shift_rows(&base, &[0.5, 0.25]);
    assert_eq!(qp.row(0), Some((&[1.0, 2.0][..], 0.0)));
    assert_eq!(qp.num_rows(), 1);
    assert!(qp.rows_hold(&[0.0, 0.0]) && !qp.rows_hold(&[-0.1, 0.0]), "every row counts again");
    qp.shift_rows(&base, &[1.0]); // wrong length: unchanged
    assert_eq!(qp.rhs(), &[0.0]);
}

fn random_spd(rng: &mut impl Rng, n: usize) -> Vec<f64> {
    let m: Vec<f64> = (0..n * n).map(|_| rng.gen_range(-1.0..1.0)).collect();
    let mut h = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            h[i * n + j] = (0..n).map(|k| m[i * n + k] * m[j * n + k]).sum::<f64>();
        }
        h[i * n + i] += 0.05;
    }
    h
}

/// KKT conditions with the solver's own multipliers: primal feasibility, active
/// constraints tight, multipliers non-negative, and `Hx + c = Σ λ_i n_i`.
fn assert_kkt(qp: &DenseQp, tol: f64) {
    let n = qp.n;
    for i in 0..n {
        assert!(qp.x[i] >= qp.lb[i] - tol && qp.x[i] <= qp.ub[i] + tol, "bound {i}");
    }
    for k in 0..qp.num_rows() {
        let s = dot(&qp.a[k * n..(k + 1) * n], &qp.x) - qp.b[k];
        assert!(s > -tol, "row {k} violated by {s}");
    }
    let mut res: Vec<f64> =
        (0..n).map(|i| qp.c[i] + (0..n).map(|j| qp.h[i * n + j] * qp.x[j]).sum::<f64>()).collect();
    let mut qp2 = qp.clone();
    for (&con, &u) in qp.active.iter().zip(&qp.u) {
        assert!(u >= -tol, "negative multiplier {u}");
        assert!(qp.slack(con).abs() < tol, "active {con:?} not tight");
        qp2.load_normal(con);
        for (r, v) in res.iter_mut().zip(&qp2.normal) {
            *r -= u * v;
        }
    }
    let norm = dot(&res, &res).sqrt();
    assert!(norm < 1e-8, "stationarity residual {norm}");
}

#[test]
fn one_row_on_a_hand_problem() {
    // min ½|x|² − x₀ − x₁  s.t.  x₀ + x₁ ≤ 1  →  x = (½, ½).
    let mut qp = DenseQp::new(2);
    qp.h = vec![1.0, 0.0, 0.0, 1.0];
    qp.c = vec![-1.0, -1.0];
    qp.add_row(-1.0).copy_from_slice(&[-1.0, -1.0]);
    assert_eq!(qp.solve(), QpStatus::Optimal);
    assert!((qp.x[0] - 0.5).abs() < 1e-15 && (qp.x[1] - 0.5).abs() < 1e-15, "{:?}", qp.x);
    assert!(qp.row_is_active(0));
}

#[test]
fn infeasible_rows_are_reported() {
    let mut qp = DenseQp::new(1);
    qp.h = vec![1.0];
    qp.add_row(1.0).copy_from_slice(&[1.0]); // x ≥ 1
    qp.add_row(0.0).copy_from_slice(&[-1.0]); // x ≤ 0
    assert_eq!(qp.solve(), QpStatus::Infeasible);
    let mut qp = DenseQp::new(1);
    qp.h = vec![1.0];
    qp.ub = vec![0.0];
    qp.add_row(1.0).copy_from_slice(&[1.0]);
    assert_eq!(qp.solve(), QpStatus::Infeasible);
}

/// Bounds only: the same minimiser as the primal box solver.
#[test]
fn bounds_match_the_box_solver() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for case in 0..300 {
        let n = rng.gen_range(1..20);
        let mut boxed = BoxQp::new(n);
        boxed.h = random_spd(&mut rng, n);
        boxed.c = (0..n).map(|_| rng.gen_range(-3.0..3.0)).collect();
        boxed.lb = (0..n).map(|_| rng.gen_range(-1.0..0.0)).collect();
        boxed.ub = (0..n).map(|_| rng.gen_range(0.0..1.0)).collect();
        let mut dense = DenseQp::new(n);
        dense.h.clone_from(&boxed.h);
        dense.c.clone_from(&boxed.c);
        dense.lb.clone_from(&boxed.lb);
        dense.ub.clone_from(&boxed.ub);
        assert_eq!(boxed.solve(), QpStatus::Optimal);
        assert_eq!(dense.solve(), QpStatus::Optimal, "case {case}");
        for i in 0..n {
            assert!((boxed.x[i] - dense.x[i]).abs() < 1e-8, "case {case}: {i}");
        }
    }
}

/// The tree factorisation (and its sparse Givens updates) reaches the dense path's
/// minimiser, and KKT holds, with bounds and rows binding.
#[test]
fn tree_factorisation_matches_dense() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
    for case in 0..300 {
        let n = rng.gen_range(1..30);
        let (parent, h) = crate::qp::random_tree_problem(&mut rng, n, 0.05);
        let mut dense = DenseQp::new(n);
        dense.h = h;
        dense.c = (0..n).map(|_| rng.gen_range(-5.0..5.0)).collect();
        let feasible: Vec<f64> = (0..n).map(|_| rng.gen_range(-0.5..0.5)).collect();
        for ((lb, ub), f) in dense.lb.iter_mut().zip(dense.ub.iter_mut()).zip(&feasible) {
            if rng.gen_bool(0.7) {
                *lb = f - rng.gen_range(0.0..1.0);
                *ub = f + rng.gen_range(0.0..1.0);
            }
        }
        for _ in 0..rng.gen_range(0..n + 2) {
            // Sparse rows, like a point's Jacobian along one chain.
            let leaf = rng.gen_range(0..n);
            let mut row = vec![0.0; n];
            for d in std::iter::successors(Some(leaf), |&d| parent[d]) {
                row[d] = rng.gen_range(-1.0..1.0);
            }
            let b = dot(&row, &feasible) - rng.gen_range(0.0..0.3);
            dense.add_row(b).copy_from_slice(&row);
        }
        if dense.num_rows() > 1 {
            let (row, b) = (dense.a[..n].to_vec(), dense.b[0]);
            dense.add_row(b).copy_from_slice(&row);
        }
        let mut tree = dense.clone();
        tree.set_tree(&parent);
        assert_eq!(tree.chains.len(), n);
        assert_eq!(dense.solve(), QpStatus::Optimal, "case {case}");
        assert_eq!(tree.solve(), QpStatus::Optimal, "case {case}");
        assert_kkt(&tree, 1e-9);
        for i in 0..n {
            assert!((dense.x[i] - tree.x[i]).abs() < 1e-8, "case {case}: {i}");
        }
    }
}

/// Only the upper triangle of `h` is read, by the dense and the tree factorisation.
#[test]
fn the_lower_triangle_is_not_read() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(14);
    for tree in [false, true] {
        let n = 12;
        let (parent, h) = crate::qp::random_tree_problem(&mut rng, n, 0.05);
        let mut qp = DenseQp::new(n);
        qp.h = h;
        qp.c = (0..n).map(|_| rng.gen_range(-5.0..5.0)).collect();
        qp.ub.fill(0.3);
        qp.add_row(-0.2).copy_from_slice(&vec![-1.0; n]);
        if tree {
            qp.set_tree(&parent);
        }
        let mut poisoned = qp.clone();
        for i in 0..n {
            for j in 0..i {
                poisoned.h[i * n + j] = f64::NAN;
            }
        }
        assert_eq!(qp.solve(), QpStatus::Optimal);
        assert_eq!(poisoned.solve(), QpStatus::Optimal);
        assert_eq!(qp.x, poisoned.x, "tree {tree}");
    }
}

#[test]
fn a_parent_after_its_child_is_no_tree() {
    let mut qp = DenseQp::new(2);
    qp.set_tree(&[Some(1), None]);
    assert!(qp.chains.is_empty());
    qp.set_tree(&[None]);
    assert!(qp.chains.is_empty());
}

/// Random bounds and rows around a feasible point: optimal, and KKT holds.
#[test]
fn random_problems_satisfy_kkt() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    for case in 0..300 {
        let n = rng.gen_range(1..16);
        let mut qp = DenseQp::new(n);
        qp.h = random_spd(&mut rng, n);
        qp.c = (0..n).map(|_| rng.gen_range(-5.0..5.0)).collect();
        let feasible: Vec<f64> = (0..n).map(|_| rng.gen_range(-0.5..0.5)).collect();
        for ((lb, ub), f) in qp.lb.iter_mut().zip(qp.ub.iter_mut()).zip(&feasible) {
            if rng.gen_bool(0.7) {
                *lb = f - rng.gen_range(0.0..1.0);
                *ub = f + rng.gen_range(0.0..1.0);
            }
        }
        for _ in 0..rng.gen_range(0..2 * n + 2) {
            let row: Vec<f64> = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let b = dot(&row, &feasible) - rng.gen_range(0.0..0.3);
            qp.add_row(b).copy_from_slice(&row);
        }
        // A duplicate and a dependent row exercise the degenerate paths.
        if qp.num_rows() > 1 {
            let row = qp.a[..n].to_vec();
            let b = qp.b[0];
            qp.add_row(b).copy_from_slice(&row);
            let twice: Vec<f64> = row.iter().map(|v| 2.0 * v).collect();
            qp.add_row(2.0 * b).copy_from_slice(&twice);
        }
        assert_eq!(qp.solve(), QpStatus::Optimal, "case {case}");
        assert_kkt(&qp, 1e-9);
    }
}
