//! The quaternion arithmetic of the FK loop, written out in the operation order of GMR's
//! vendored LAFAN1 utilities (`lafan_vendor/utils.py`: `quat_mul`, `quat_mul_vec`,
//! `angle_axis_to_quat`, `euler_to_quat`), so that our world poses equal GMR's to the last
//! bits rather than merely to rounding. Quaternions are `[w, x, y, z]` inside this module only;
//! the public API uses `UnitQuaternion<f64>`.

use bvh::Axis;
#[cfg(test)]
use nalgebra::Vector3;
use nalgebra::{Quaternion, UnitQuaternion};

/// `[w, x, y, z]`, the hot-loop representation.
pub(crate) type Quat = [f64; 4];

pub(crate) const IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// Hamilton product `x ⊗ y`, term order as in LAFAN1's `quat_mul`.
#[must_use]
#[inline]
pub(crate) fn quat_mul(x: &Quat, y: &Quat) -> Quat {
    let [x0, x1, x2, x3] = *x;
    let [y0, y1, y2, y3] = *y;
    [
        y0 * x0 - y1 * x1 - y2 * x2 - y3 * x3,
        y0 * x1 + y1 * x0 - y2 * x3 + y3 * x2,
        y0 * x2 + y1 * x3 + y2 * x0 - y3 * x1,
        y0 * x3 - y1 * x2 + y2 * x1 + y3 * x0,
    ]
}

#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Rotate `v` by the unit quaternion `q`: `v + w·t + q_v × t` with `t = 2 q_v × v`
/// (LAFAN1's `quat_mul_vec`).
#[must_use]
#[inline]
pub(crate) fn quat_rotate(q: &Quat, v: [f64; 3]) -> [f64; 3] {
    let qv = [q[1], q[2], q[3]];
    let c = cross(qv, v);
    let t = [2.0 * c[0], 2.0 * c[1], 2.0 * c[2]];
    let u = cross(qv, t);
    [v[0] + q[0] * t[0] + u[0], v[1] + q[0] * t[1] + u[1], v[2] + q[0] * t[2] + u[2]]
}

/// Rotation by `degrees` about a coordinate axis: `(cos θ/2, sin θ/2 · axis)`, the angle
/// converted as numpy's `radians` does (`deg · (π/180)`).
#[cfg(test)]
#[must_use]
pub(crate) fn axis_quat(axis: Axis, degrees: f64) -> Quat {
    let (s, c) = half_sin_cos(degrees);
    match axis {
        Axis::X => [c, s, 0.0, 0.0],
        Axis::Y => [c, 0.0, s, 0.0],
        Axis::Z => [c, 0.0, 0.0, s],
    }
}

/// `q(axis; c, s) ⊗ y` for the elementary rotation `(c, s·axis)`: [`quat_mul`] with the
/// zero terms dropped. Adding or subtracting an exact zero does not change an IEEE result,
/// so this equals the full product bit for bit (up to the sign of zero).
#[must_use]
#[inline]
pub(crate) fn axis_mul(axis: Axis, c: f64, s: f64, y: &Quat) -> Quat {
    let [y0, y1, y2, y3] = *y;
    match axis {
        Axis::X => [y0 * c - y1 * s, y0 * s + y1 * c, y2 * c - y3 * s, y2 * s + y3 * c],
        Axis::Y => [y0 * c - y2 * s, y1 * c + y3 * s, y0 * s + y2 * c, -(y1 * s) + y3 * c],
        Axis::Z => [y0 * c - y3 * s, y1 * c - y2 * s, y1 * s + y2 * c, y0 * s + y3 * c],
    }
}

/// `(sin, cos)` of half the angle `degrees`, converted as numpy's `radians` does.
#[cfg(test)]
fn half_sin_cos(degrees: f64) -> (f64, f64) {
    crate::trig::sin_cos(degrees.to_radians() / 2.0)
}

#[cfg(test)]
/// `q(a₁) ⊗ (q(a₂) ⊗ q(a₃))` for rotation channels listed as `a₁ a₂ a₃` (intrinsic, in file
/// order: R = R₁·R₂·R₃). Folding from the right reproduces `euler_to_quat`'s association.
#[must_use]
pub(crate) fn euler_quat(rotations: impl DoubleEndedIterator<Item = (Axis, f64)>) -> Quat {
    // The innermost factor is `axis_mul(a₃, ·, IDENTITY)`, which is `q(a₃)` exactly.
    rotations.rev().fold(IDENTITY, |q, (axis, degrees)| {
        let (s, c) = half_sin_cos(degrees);
        axis_mul(axis, c, s, &q)
    })
}

#[must_use]
#[inline]
pub(crate) fn dot(a: &Quat, b: &Quat) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

#[must_use]
#[inline]
pub(crate) fn neg(q: &Quat) -> Quat {
    [-q[0], -q[1], -q[2], -q[3]]
}

#[must_use]
pub(crate) fn to_unit(q: &Quat) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]))
}

#[must_use]
pub(crate) fn from_unit(q: &UnitQuaternion<f64>) -> Quat {
    [q.w, q.i, q.j, q.k]
}

#[cfg(test)]
#[must_use]
pub(crate) fn to_vector(v: [f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Rotation3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const ORDERS: [[Axis; 3]; 6] = [
        [Axis::X, Axis::Y, Axis::Z],
        [Axis::X, Axis::Z, Axis::Y],
        [Axis::Y, Axis::X, Axis::Z],
        [Axis::Y, Axis::Z, Axis::X],
        [Axis::Z, Axis::X, Axis::Y],
        [Axis::Z, Axis::Y, Axis::X],
    ];

    /// The textbook elementary rotation matrix, written independently of the quaternion path.
    fn axis_matrix(axis: Axis, degrees: f64) -> Matrix3<f64> {
        let (s, c) = degrees.to_radians().sin_cos();
        match axis {
            Axis::X => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
            Axis::Y => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
            Axis::Z => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
        }
    }

    #[test]
    fn euler_quaternion_matches_matrix_product_for_all_orders() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0001);
        for order in ORDERS {
            for _ in 0..2000 {
                let angles: [f64; 3] = std::array::from_fn(|_| rng.gen_range(-360.0..360.0));
                let q = euler_quat(order.iter().copied().zip(angles));
                let m = order
                    .iter()
                    .zip(angles)
                    .fold(Matrix3::identity(), |m, (&a, d)| m * axis_matrix(a, d));
                let from_q = to_unit(&q).to_rotation_matrix().into_inner();
                assert!((from_q - m).amax() < 1e-14, "{order:?} {angles:?}");
                assert!((dot(&q, &q) - 1.0).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn hot_loop_products_match_nalgebra() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0002);
        for _ in 0..2000 {
            let a =
                UnitQuaternion::from_rotation_matrix(&Rotation3::new(Vector3::from_fn(|_, _| {
                    rng.gen_range(-3.0..3.0)
                })));
            let b =
                UnitQuaternion::from_scaled_axis(Vector3::from_fn(|_, _| rng.gen_range(-3.0..3.0)));
            let v = Vector3::from_fn(|_, _| rng.gen_range(-100.0..100.0));
            let ab = to_unit(&quat_mul(&from_unit(&a), &from_unit(&b)));
            assert!((ab.into_inner() - (a * b).into_inner()).norm() < 1e-15);
            let av = to_vector(quat_rotate(&from_unit(&a), [v.x, v.y, v.z]));
            assert!((av - a * v).norm() < 1e-12);
        }
    }

    #[test]
    fn axis_product_equals_full_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0003);
        for _ in 0..3000 {
            let y: Quat = std::array::from_fn(|_| rng.gen_range(-1.0..1.0));
            for axis in [Axis::X, Axis::Y, Axis::Z] {
                let degrees = rng.gen_range(-720.0..720.0);
                let (s, c) = half_sin_cos(degrees);
                assert_eq!(axis_mul(axis, c, s, &y), quat_mul(&axis_quat(axis, degrees), &y));
            }
        }
    }

    #[test]
    fn no_rotation_channels_is_identity() {
        assert_eq!(euler_quat(std::iter::empty()), IDENTITY);
    }
}
