//! The SE(3) pieces of mink 1.3.0 the solver needs, ported operation by operation from its
//! C implementation (`mink/lie/_lie_ops_c.c`, itself following Solà, Deray, Atchuthan, "A
//! micro Lie theory for state estimation in robotics", 2018, eqs. 133, 145, 174, 179–180),
//! including the small-angle branches, so that the solver reproduces GMR to rounding.
//!
//! Poses are `(w, x, y, z)` quaternion + translation, `Pose`. Tangent vectors are
//! `[v; ω]`: translation part first.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]
// Exception to `indexing_slicing`, justified: constant indices into fixed-size nalgebra vectors and matrices
// (`Vector3`, `Vector6`, `Matrix3`, `Matrix6`): in range by their types.
#![allow(clippy::indexing_slicing)]

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// mink's epsilon for `f64` (`get_epsilon`).
const EPS: f64 = 1e-10;

/// A rigid transform as mink stores it: quaternion `[w, x, y, z]` and translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    pub quat: [f64; 4],
    pub pos: Vector3<f64>,
}

#[inline]
fn quat_neg(q: &[f64; 4]) -> [f64; 4] {
    [q[0], -q[1], -q[2], -q[3]]
}

/// Hamilton product `a ⊗ b`.
#[inline]
#[must_use]
pub fn quat_mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Rotate `v` by the unit quaternion `q` (mink's `quat_rotate`).
#[inline]
#[must_use]
pub fn quat_rotate(q: &[f64; 4], v: &Vector3<f64>) -> Vector3<f64> {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let tx = 2.0 * (y * v[2] - z * v[1]);
    let ty = 2.0 * (z * v[0] - x * v[2]);
    let tz = 2.0 * (x * v[1] - y * v[0]);
    Vector3::new(
        v[0] + w * tx + (y * tz - z * ty),
        v[1] + w * ty + (z * tx - x * tz),
        v[2] + w * tz + (x * ty - y * tx),
    )
}

/// Rotation matrix → unit quaternion (Shepperd's method as in `mju_mat2Quat`, then
/// normalised), as mink reads a MuJoCo `xmat`.
#[must_use]
pub fn mat_to_quat(m: &Matrix3<f64>) -> [f64; 4] {
    let r = |i: usize, j: usize| m[(i, j)];
    let tr = r(0, 0) + r(1, 1) + r(2, 2);
    let mut q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [0.25 * s, (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s]
    } else if r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2) {
        let s = (1.0 + r(0, 0) - r(1, 1) - r(2, 2)).sqrt() * 2.0;
        [(r(2, 1) - r(1, 2)) / s, 0.25 * s, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s]
    } else if r(1, 1) > r(2, 2) {
        let s = (1.0 + r(1, 1) - r(0, 0) - r(2, 2)).sqrt() * 2.0;
        [(r(0, 2) - r(2, 0)) / s, (r(0, 1) + r(1, 0)) / s, 0.25 * s, (r(1, 2) + r(2, 1)) / s]
    } else {
        let s = (1.0 + r(2, 2) - r(0, 0) - r(1, 1)).sqrt() * 2.0;
        [(r(1, 0) - r(0, 1)) / s, (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, 0.25 * s]
    };
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if n > 0.0 {
        let inv = 1.0 / n;
        for v in &mut q {
            *v *= inv;
        }
    }
    q
}

/// `a⁻¹ · b`.
#[must_use]
pub fn inverse_multiply(a: &Pose, b: &Pose) -> Pose {
    let inv_q = quat_neg(&a.quat);
    let inv_t = quat_rotate(&inv_q, &(-a.pos));
    Pose { quat: quat_mul(&inv_q, &b.quat), pos: quat_rotate(&inv_q, &b.pos) + inv_t }
}

/// SO(3) logarithm of a quaternion (eq. 133), sign chosen so that `w ≥ 0`.
#[must_use]
pub fn so3_log(q: &[f64; 4]) -> Vector3<f64> {
    let s = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let (w, mut v) = (s * q[0], Vector3::new(s * q[1], s * q[2], s * q[3]));
    let norm = v.norm();
    if norm > 0.0 {
        v *= 1.0 / norm;
    }
    if norm < EPS {
        return Vector3::zeros();
    }
    v * (2.0 * norm.atan2(w))
}

#[inline]
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0)
}

/// SE(3) logarithm: `[V⁻¹(ω) t; ω]`, `V⁻¹ = I − ½ [ω]× + k [ω]×²`. mink forms `[ω]×²` as
/// a matrix product; its terms with a zero factor (the skew matrix's diagonal) are left out
/// here, which changes no value but the sign of a zero.
#[must_use]
pub fn se3_log(p: &Pose) -> Vector6<f64> {
    let omega = so3_log(&p.quat);
    let theta = omega.norm();
    let t2 = theta * theta;
    let skw = skew(&omega);
    let skw2 = mul3_sparse(&skw, &skw, |i, j, k| k == i || k == j);
    let coeff = if t2 < EPS {
        1.0 / 12.0
    } else {
        let half = 0.5 * theta;
        (1.0 - 0.5 * theta * half.cos() / half.sin()) / t2
    };
    let vinv = |i: usize, j: usize| {
        if i == j {
            skw2[(i, j)] * coeff + 1.0
        } else {
            skw[(i, j)] * -0.5 + skw2[(i, j)] * coeff
        }
    };
    let t = &p.pos;
    let v: [f64; 3] =
        std::array::from_fn(|i| vinv(i, 0) * t[0] + vinv(i, 1) * t[1] + vinv(i, 2) * t[2]);
    Vector6::new(v[0], v[1], v[2], omega[0], omega[1], omega[2])
}

/// `a b` summed as nalgebra sums it (`Σₖ a[i, k] b[k, j]` from `k = 0`), without the terms
/// where `zero(i, j, k)` says a factor is exactly zero (a skew matrix's diagonal): the same
/// value up to the sign of a zero.
#[inline(always)]
fn mul3_sparse(
    a: &Matrix3<f64>,
    b: &Matrix3<f64>,
    zero: impl Fn(usize, usize, usize) -> bool,
) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| {
        let mut sum: Option<f64> = None;
        for k in (0..3).filter(|&k| !zero(i, j, k)) {
            let term = a[(i, k)] * b[(k, j)];
            sum = Some(sum.map_or(term, |s| s + term));
        }
        sum.unwrap_or(0.0)
    })
}

/// `a ⊖ b = log(b⁻¹ · a)` (right minus).
#[must_use]
pub fn rminus(a: &Pose, b: &Pose) -> Vector6<f64> {
    se3_log(&inverse_multiply(b, a))
}

/// Left Jacobian inverse of SO(3) (eq. 146), mink's expansion order, given `θ = |ω|` and
/// `(sin θ, cos θ)`.
fn so3_ljacinv_with(omega: &Vector3<f64>, theta: f64, (st, ct): (f64, f64)) -> Matrix3<f64> {
    let t2 = theta * theta;
    let beta = if theta < EPS {
        (1.0 / 12.0) * (1.0 + t2 / 60.0 * (1.0 + t2 / 42.0 * (1.0 + t2 / 40.0)))
    } else {
        (1.0 / t2) * (1.0 - (theta * st / (2.0 * (1.0 - ct))))
    };
    let inner = omega.dot(omega);
    let mut out = Matrix3::zeros();
    for i in 0..3 {
        for j in 0..3 {
            out[(i, j)] = beta * (omega[i] * omega[j] - if i == j { inner } else { 0.0 });
        }
    }
    let a = omega * -0.5;
    out[(0, 1)] += -a[2];
    out[(0, 2)] += a[1];
    out[(1, 0)] += a[2];
    out[(1, 2)] += -a[0];
    out[(2, 0)] += -a[1];
    out[(2, 1)] += a[0];
    out[(0, 0)] += 1.0;
    out[(1, 1)] += 1.0;
    out[(2, 2)] += 1.0;
    out
}

/// The Q block's four coefficients (eq. 180) at `θ` with `(sin θ, cos θ)`: its Taylor
/// series near 0.
fn q_coefficients(theta: f64, (st, ct): (f64, f64)) -> (f64, f64, f64, f64) {
    let t2 = theta * theta;
    let (b, cc, d) = if t2 < EPS {
        (1.0 / 6.0 + (1.0 / 120.0) * t2, -(1.0 / 24.0) + (1.0 / 720.0) * t2, -(1.0 / 60.0))
    } else {
        let t4 = t2 * t2;
        (
            (theta - st) / (t2 * theta),
            (1.0 - 0.5 * t2 - ct) / t4,
            (2.0 * theta - 3.0 * st + theta * ct) / (2.0 * t4 * theta),
        )
    };
    (0.5, b, cc, d)
}

/// The Q block of the SE(3) left Jacobian (eq. 180), `c = [v; ω]`, given `θ = |ω|` and
/// `(sin θ, cos θ)`.
fn q_block(c: &Vector6<f64>, theta: f64, (st, ct): (f64, f64)) -> Matrix3<f64> {
    let v = Vector3::new(c[0], c[1], c[2]);
    let w = Vector3::new(c[3], c[4], c[5]);
    let (a, b, cc, d) = q_coefficients(theta, (st, ct));
    let vs = skew(&v);
    let ws = skew(&w);
    // Products with a skew matrix, its zero diagonal's terms left out (`mul3_sparse`).
    let right = |_: usize, j: usize, k: usize| k == j;
    let vw = mul3_sparse(&vs, &ws, |i, j, k| k == i || k == j);
    let wv = vw.transpose();
    let wvw = mul3_sparse(&wv, &ws, right);
    let vww = mul3_sparse(&vw, &ws, right);
    let vww_t = vww.transpose();
    let wvww = mul3_sparse(&wvw, &ws, right);
    let wwvw = mul3_sparse(&ws, &wvw, |i, _, k| k == i);
    let mut q = Matrix3::zeros();
    for i in 0..9 {
        q[i] = a * vs[i] + b * (wv[i] + vw[i] + wvw[i]) - cc * (vww[i] - vww_t[i] - 3.0 * wvw[i])
            + d * (wvww[i] + wwvw[i]);
    }
    q
}

/// mink's `SE3.jlog`: the right Jacobian inverse of SE(3) at `log(p)`,
/// `rjacinv(τ) = ljacinv(−τ)` (eq. 179b).
#[must_use]
pub fn se3_jlog(p: &Pose) -> Matrix6<f64> {
    se3_jlog_at(&-se3_log(p))
}

/// [`se3_jlog`] from `neg = −log(p)` (`= log(p⁻¹)`), for a caller that has that logarithm
/// already: `ljacinv(neg)`.
#[must_use]
pub fn se3_jlog_at(neg: &Vector6<f64>) -> Matrix6<f64> {
    let neg = *neg;
    let w = Vector3::new(neg[3], neg[4], neg[5]);
    if w.dot(&w) < EPS {
        return Matrix6::identity();
    }
    // One sine and cosine for both blocks (each computed them from the same θ).
    let theta = w.norm();
    let sc = theta.sin_cos();
    let q = q_block(&neg, theta, sc);
    let lji = so3_ljacinv_with(&w, theta, sc);
    let jqj = lji * (q * lji);
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&lji);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&lji);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-jqj));
    out
}

/// SE(3) exponential (for tests): `exp([v; ω])`.
#[cfg(test)]
#[must_use]
pub fn se3_exp(t: &Vector6<f64>) -> Pose {
    let w = Vector3::new(t[3], t[4], t[5]);
    let v = Vector3::new(t[0], t[1], t[2]);
    let theta = w.norm();
    let rot = nalgebra::UnitQuaternion::from_scaled_axis(w);
    let t2 = theta * theta;
    let vmat = if t2 < EPS {
        *rot.to_rotation_matrix().matrix()
    } else {
        let s = skew(&w);
        Matrix3::identity()
            + s * ((1.0 - theta.cos()) / t2)
            + s * s * ((theta - theta.sin()) / (t2 * theta))
    };
    Pose { quat: [rot.w, rot.i, rot.j, rot.k], pos: vmat * v }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_tangent(rng: &mut ChaCha8Rng, scale: f64) -> Vector6<f64> {
        Vector6::from_fn(|_, _| rng.gen_range(-1.0..1.0) * scale)
    }

    /// The mink-order implementations the sparse products replaced, for bitwise comparison.
    /// SE(3) logarithm: `[V⁻¹(ω) t; ω]`.
    fn se3_log_reference(p: &Pose) -> Vector6<f64> {
        let omega = so3_log(&p.quat);
        let theta = omega.norm();
        let t2 = theta * theta;
        let skw = skew(&omega);
        let skw2 = skw * skw;
        let coeff = if t2 < EPS {
            1.0 / 12.0
        } else {
            let half = 0.5 * theta;
            (1.0 - 0.5 * theta * half.cos() / half.sin()) / t2
        };
        let mut vinv = skw * -0.5 + skw2 * coeff;
        vinv[(0, 0)] += 1.0;
        vinv[(1, 1)] += 1.0;
        vinv[(2, 2)] += 1.0;
        let v = vinv * p.pos;
        Vector6::new(v[0], v[1], v[2], omega[0], omega[1], omega[2])
    }

    fn q_block_reference(c: &Vector6<f64>, theta: f64, (st, ct): (f64, f64)) -> Matrix3<f64> {
        let v = Vector3::new(c[0], c[1], c[2]);
        let w = Vector3::new(c[3], c[4], c[5]);
        let (a, b, cc, d) = q_coefficients(theta, (st, ct));
        let vs = skew(&v);
        let ws = skew(&w);
        let vw = vs * ws;
        let wv = vw.transpose();
        let wvw = wv * ws;
        let vww = vw * ws;
        let vww_t = vww.transpose();
        let wvww = wvw * ws;
        let wwvw = ws * wvw;
        let mut q = Matrix3::zeros();
        for i in 0..9 {
            q[i] = a * vs[i] + b * (wv[i] + vw[i] + wvw[i])
                - cc * (vww[i] - vww_t[i] - 3.0 * wvw[i])
                + d * (wvww[i] + wwvw[i]);
        }
        q
    }

    /// Bit for bit (zeros compared by value): `se3_log` and `q_block` as mink orders them.
    #[test]
    fn sparse_products_match_mink_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        for scale in [0.0, 1e-9, 1e-4, 0.3, 1.5, 3.0] {
            for _ in 0..2000 {
                let t = random_tangent(&mut rng, scale);
                let p = se3_exp(&t);
                let p =
                    Pose { pos: p.pos + Vector3::from_fn(|_, _| rng.gen_range(-2.0..2.0)), ..p };
                assert_eq!(se3_log(&p), se3_log_reference(&p));
                let theta = Vector3::new(t[3], t[4], t[5]).norm();
                let sc = theta.sin_cos();
                assert_eq!(q_block(&t, theta, sc), q_block_reference(&t, theta, sc));
            }
        }
    }

    #[test]
    fn log_inverts_exp() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for scale in [1e-9, 1e-3, 0.5, 1.5] {
            for _ in 0..50 {
                let t = random_tangent(&mut rng, scale);
                let back = se3_log(&se3_exp(&t));
                assert!((back - t).norm() < 1e-12 * (1.0 + t.norm()), "{t} vs {back}");
            }
        }
    }

    #[test]
    fn mat_to_quat_round_trip() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100 {
            let t = random_tangent(&mut rng, 3.0);
            let q = nalgebra::UnitQuaternion::from_scaled_axis(Vector3::new(t[3], t[4], t[5]));
            let back = mat_to_quat(q.to_rotation_matrix().matrix());
            let dot = back[0] * q.w + back[1] * q.i + back[2] * q.j + back[3] * q.k;
            assert!((dot.abs() - 1.0).abs() < 1e-14);
        }
    }

    /// jlog is d log(T) / dτ for right perturbations: log(T·exp(δ)) ≈ log(T) + jlog·δ.
    #[test]
    fn jlog_matches_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for scale in [1e-7, 0.3, 1.2] {
            for _ in 0..20 {
                let t = se3_exp(&random_tangent(&mut rng, scale));
                let j = se3_jlog(&t);
                let h = 1e-6;
                for k in 0..6 {
                    let mut d = Vector6::zeros();
                    d[k] = h;
                    let plus = compose(&t, &se3_exp(&d));
                    d[k] = -h;
                    let minus = compose(&t, &se3_exp(&d));
                    let col = (se3_log(&plus) - se3_log(&minus)) / (2.0 * h);
                    assert!((col - j.column(k)).norm() < 1e-6, "{col} vs {}", j.column(k));
                }
            }
        }
    }

    fn compose(a: &Pose, b: &Pose) -> Pose {
        Pose { quat: quat_mul(&a.quat, &b.quat), pos: quat_rotate(&a.quat, &b.pos) + a.pos }
    }
}
