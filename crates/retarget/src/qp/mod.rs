//! The small dense convex QPs of one IK step.
//!
//! - [`BoxQp`]: bounds only, primal active set on a tree-sparse factorisation. GMR's solve
//!   (`--gmr`) uses it: joint ranges are its only constraints.
//! - [`DenseQp`]: bounds plus general linear inequalities `a·x ≥ b`, Goldfarb–Idnani's dual
//!   active-set method. The default solve uses it for the ground, self-collision, contact and
//!   joint-speed constraints.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

mod boxed;
mod dual;

pub use boxed::{BoxQp, QpStatus};
pub use dual::DenseQp;

/// Per variable of the tree `parent`, its ancestors nearest first (the rows of both solvers'
/// tree factorisations); `None` unless `parent` has `n` entries, each lower than its index.
fn ancestor_chains(parent: &[Option<usize>], n: usize) -> Option<Vec<Vec<usize>>> {
    let tree = parent.len() == n && parent.iter().enumerate().all(|(i, p)| p.is_none_or(|p| p < i));
    let up = |p: &usize| parent.get(*p).copied().flatten();
    tree.then(|| parent.iter().map(|p| std::iter::successors(*p, up).collect()).collect())
}

/// A random tree over `n` dofs (parents before children, several roots) and an `H` with its
/// sparsity: a sum of outer products of rows along root-to-leaf chains, plus `ridge` on the
/// diagonal. Test problems of both solvers' tree factorisations.
#[cfg(test)]
#[allow(clippy::indexing_slicing)]
pub(crate) fn random_tree_problem(
    rng: &mut impl rand::Rng,
    n: usize,
    ridge: f64,
) -> (Vec<Option<usize>>, Vec<f64>) {
    let parent: Vec<Option<usize>> = (0..n)
        .map(|i| if i == 0 || rng.gen_bool(0.15) { None } else { Some(rng.gen_range(0..i)) })
        .collect();
    let mut h = vec![0.0; n * n];
    for leaf in 0..n {
        let chain: Vec<usize> = std::iter::successors(Some(leaf), |&d| parent[d]).collect();
        for _ in 0..3 {
            let row: Vec<f64> = chain.iter().map(|_| rng.gen_range(-1.0..1.0)).collect();
            for (a, &i) in chain.iter().enumerate() {
                for (b, &j) in chain.iter().enumerate() {
                    h[i * n + j] += row[a] * row[b];
                }
            }
        }
    }
    for i in 0..n {
        h[i * n + i] += ridge;
    }
    (parent, h)
}
