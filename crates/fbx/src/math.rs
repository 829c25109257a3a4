//! Rotations out of FBX's affine matrices, and BVH's Euler angles.

use nalgebra::{Matrix3, Matrix4, Rotation3, UnitQuaternion, Vector3};

/// The rotation of an affine matrix's linear part `L = R·S`: the orthogonal factor of its
/// polar decomposition (exact for the uniform scales of skeletons; the nearest rotation
/// otherwise). A mirrored node (`det L < 0`, e.g. Lcl Scaling −1 on Biped's Nub leaves) has
/// no rotation of its own; that of `−L` is returned. A degenerate matrix gives the identity.
#[must_use]
pub fn rotation(m: &Matrix4<f64>) -> UnitQuaternion<f64> {
    let l: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    let det = l.determinant();
    if !(det.abs() > 1e-300 && det.is_finite()) {
        return UnitQuaternion::identity();
    }
    let l = if det < 0.0 { -l } else { l };
    let svd = l.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return UnitQuaternion::identity();
    };
    let mut r = u * v_t;
    if r.determinant() < 0.0 || !r.iter().all(|x| x.is_finite()) {
        return UnitQuaternion::identity();
    }
    // One Newton step of the polar iteration polishes the last ulps.
    if let Some(inv) = r.try_inverse() {
        r = (r + inv.transpose()) * 0.5;
    }
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r))
}

/// The translation column of an affine matrix.
#[must_use]
pub fn translation(m: &Matrix4<f64>) -> Vector3<f64> {
    Vector3::new(m.m14, m.m24, m.m34)
}

/// Euler angles (radians) with `R = Rx(a)·Ry(b)·Rz(c)`, BVH's `Xrotation Yrotation
/// Zrotation`; of the two solutions, the one nearest `previous` (each angle unwrapped to
/// within π of it), so that a clip's channels are continuous.
#[must_use]
pub fn euler_xyz(q: &UnitQuaternion<f64>, previous: Option<[f64; 3]>) -> [f64; 3] {
    let m = q.to_rotation_matrix().into_inner();
    let cos_b = m.m11.hypot(m.m12);
    let b = m.m13.atan2(cos_b);
    let (a, c) = if cos_b > 1e-12 {
        ((-m.m23).atan2(m.m33), (-m.m12).atan2(m.m11))
    } else {
        // Gimbal lock: only a ± c is defined; put it all in a.
        (m.m32.atan2(m.m22), 0.0)
    };
    let pi = std::f64::consts::PI;
    let first = [a, b, c];
    let Some(prev) = previous else { return first };
    let second = [a + pi, pi - b, c + pi];
    let unwrap = |v: [f64; 3]| -> [f64; 3] {
        let mut out = v;
        for (x, p) in out.iter_mut().zip(prev) {
            *x += ((p - *x) / (2.0 * pi)).round() * 2.0 * pi;
        }
        out
    };
    let (u1, u2) = (unwrap(first), unwrap(second));
    let dist = |u: &[f64; 3]| u.iter().zip(prev).map(|(x, p)| (x - p).abs()).sum::<f64>();
    if dist(&u2) < dist(&u1) {
        u2
    } else {
        u1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_euler(e: [f64; 3]) -> UnitQuaternion<f64> {
        let axis = |v: Vector3<f64>, a: f64| {
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(v), a)
        };
        axis(Vector3::x(), e[0]) * axis(Vector3::y(), e[1]) * axis(Vector3::z(), e[2])
    }

    #[test]
    fn euler_angles_rebuild_the_rotation_including_gimbal_lock() {
        let cases = [
            [0.3, -0.4, 1.2],
            [2.9, 1.4, -3.0],
            [0.5, std::f64::consts::FRAC_PI_2, 0.2],
            [-1.0, -std::f64::consts::FRAC_PI_2, 0.7],
            [0.0, 0.0, 0.0],
        ];
        for e in cases {
            let q = from_euler(e);
            let back = from_euler(euler_xyz(&q, None));
            assert!(q.angle_to(&back) < 1e-12, "{e:?}");
            let near = euler_xyz(&q, Some([e[0] + 6.0, e[1], e[2] - 6.5]));
            assert!(q.angle_to(&from_euler(near)) < 1e-12, "{e:?}");
        }
        // Continuity: the solution nearest the previous frame, unwrapped.
        let q = from_euler([3.1, 0.2, 0.1]);
        let e = euler_xyz(&q, Some([-3.1, 0.2, 0.1]));
        assert!((e[0] - (3.1 - 2.0 * std::f64::consts::PI)).abs() < 1e-12, "{e:?}");
    }

    #[test]
    fn rotation_ignores_scale_and_mirroring() {
        let q = from_euler([0.3, -0.4, 1.2]);
        let r = q.to_rotation_matrix().into_inner();
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&(r * 100.0));
        assert!(rotation(&m).angle_to(&q) < 1e-12);
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&(r * -1.0));
        assert!(rotation(&m).angle_to(&q) < 1e-12);
        assert_eq!(rotation(&Matrix4::zeros()), UnitQuaternion::identity());
    }
}
