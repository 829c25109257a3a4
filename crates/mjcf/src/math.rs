//! Orientation conversions of MuJoCo's compiler (`user_util.cc`: `mjuu_frame2quat`,
//! `mjuu_z2quat`, the Euler rule of `mjs_resolveOrientation`), written so that the resulting
//! quaternions have MuJoCo's sign as well as its rotation.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::syntax::Orientation;

/// Quaternion of an orientation specifier. `angle_scale` converts the file's angle unit to
/// radians (1 or π/180), `eulerseq` is the compiler's sequence. `None` for a degenerate input
/// (zero quaternion, zero axis, parallel `xyaxes`).
#[must_use]
pub(crate) fn orientation_to_quat(
    o: &Orientation,
    angle_scale: f64,
    eulerseq: [u8; 3],
) -> Option<UnitQuaternion<f64>> {
    match *o {
        Orientation::Quat([w, x, y, z]) => normalized(Quaternion::new(w, x, y, z)),
        Orientation::AxisAngle([x, y, z, angle]) => {
            let axis = Vector3::new(x, y, z);
            let n = axis.norm();
            (n >= 1e-10).then(|| axis_angle(&(axis / n), angle * angle_scale))
        }
        Orientation::Euler(angles) => Some(euler(angles.map(|a| a * angle_scale), eulerseq)),
        Orientation::XyAxes([x0, x1, x2, y0, y1, y2]) => {
            xyaxes(Vector3::new(x0, x1, x2), Vector3::new(y0, y1, y2))
        }
        Orientation::ZAxis([x, y, z]) => {
            let v = Vector3::new(x, y, z);
            let n = v.norm();
            (n >= 1e-10).then(|| z_to_quat(&(v / n)))
        }
    }
}

/// Unit quaternion of a possibly unnormalised one; `None` when it is (nearly) zero.
#[must_use]
pub(crate) fn normalized(q: Quaternion<f64>) -> Option<UnitQuaternion<f64>> {
    let n = q.norm();
    (n >= 1e-10).then(|| UnitQuaternion::new_unchecked(q / n))
}

/// `mju_axisAngle2Quat` for a unit axis: (cos(a/2), sin(a/2) axis).
#[must_use]
#[inline]
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
    if angle == 0.0 {
        return UnitQuaternion::identity();
    }
    let (s, c) = (angle * 0.5).sin_cos();
    UnitQuaternion::new_unchecked(Quaternion::new(c, s * axis.x, s * axis.y, s * axis.z))
}

/// Euler angles (radians) in MuJoCo's `eulerseq` convention: lowercase letters rotate about
/// the moving axes (post-multiply), uppercase about the fixed axes (pre-multiply).
#[must_use]
fn euler(angles: [f64; 3], seq: [u8; 3]) -> UnitQuaternion<f64> {
    let mut q = Quaternion::new(1.0, 0.0, 0.0, 0.0);
    for (angle, axis) in angles.iter().zip(seq) {
        let (s, c) = (angle * 0.5).sin_cos();
        let rot = match axis.to_ascii_lowercase() {
            b'x' => Quaternion::new(c, s, 0.0, 0.0),
            b'y' => Quaternion::new(c, 0.0, s, 0.0),
            _ => Quaternion::new(c, 0.0, 0.0, s),
        };
        q = if axis.is_ascii_lowercase() { q * rot } else { rot * q };
    }
    UnitQuaternion::new_normalize(q)
}

/// `xyaxes`: x normalised, y made orthogonal to x and normalised, z = x × y.
#[must_use]
fn xyaxes(x: Vector3<f64>, y: Vector3<f64>) -> Option<UnitQuaternion<f64>> {
    let nx = x.norm();
    if nx < 1e-10 {
        return None;
    }
    let x = x / nx;
    let y = y - x * x.dot(&y);
    let ny = y.norm();
    if ny < 1e-10 {
        return None;
    }
    let y = y / ny;
    let z = x.cross(&y).normalize();
    Some(frame_to_quat(&x, &y, &z))
}

/// `mjuu_frame2quat`: rotation matrix with columns x, y, z to a quaternion (Shepperd's method,
/// positive largest component), then normalised.
#[must_use]
pub(crate) fn frame_to_quat(
    x: &Vector3<f64>,
    y: &Vector3<f64>,
    z: &Vector3<f64>,
) -> UnitQuaternion<f64> {
    // m[c][r]: column c, row r.
    let m = [x, y, z];
    let q = if m[0][0] + m[1][1] + m[2][2] > 0.0 {
        let w = 0.5 * (1.0 + m[0][0] + m[1][1] + m[2][2]).sqrt();
        Quaternion::new(
            w,
            0.25 * (m[1][2] - m[2][1]) / w,
            0.25 * (m[2][0] - m[0][2]) / w,
            0.25 * (m[0][1] - m[1][0]) / w,
        )
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let qx = 0.5 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
        Quaternion::new(
            0.25 * (m[1][2] - m[2][1]) / qx,
            qx,
            0.25 * (m[1][0] + m[0][1]) / qx,
            0.25 * (m[2][0] + m[0][2]) / qx,
        )
    } else if m[1][1] > m[2][2] {
        let qy = 0.5 * (1.0 - m[0][0] + m[1][1] - m[2][2]).sqrt();
        Quaternion::new(
            0.25 * (m[2][0] - m[0][2]) / qy,
            0.25 * (m[1][0] + m[0][1]) / qy,
            qy,
            0.25 * (m[2][1] + m[1][2]) / qy,
        )
    } else {
        let qz = 0.5 * (1.0 - m[0][0] - m[1][1] + m[2][2]).sqrt();
        Quaternion::new(
            0.25 * (m[0][1] - m[1][0]) / qz,
            0.25 * (m[2][0] + m[0][2]) / qz,
            0.25 * (m[2][1] + m[1][2]) / qz,
            qz,
        )
    };
    UnitQuaternion::new_normalize(q)
}

/// `mjuu_z2quat`: the shortest rotation taking (0, 0, 1) to the direction `v`.
#[must_use]
pub(crate) fn z_to_quat(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let mut axis = Vector3::z().cross(v);
    let s = axis.norm();
    if s < 1e-10 {
        axis = Vector3::x();
    } else {
        axis /= s;
    }
    let angle = s.atan2(v.z);
    axis_angle(&axis, angle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_xyz_moving_axes_is_product() {
        let q = euler([0.1, 0.2, 0.3], *b"xyz");
        let expected = axis_angle(&Vector3::x(), 0.1)
            * axis_angle(&Vector3::y(), 0.2)
            * axis_angle(&Vector3::z(), 0.3);
        assert!((q.coords - expected.coords).norm() < 1e-15);
        let q = euler([0.1, 0.2, 0.3], *b"XYZ");
        let expected = axis_angle(&Vector3::z(), 0.3)
            * axis_angle(&Vector3::y(), 0.2)
            * axis_angle(&Vector3::x(), 0.1);
        assert!((q.coords - expected.coords).norm() < 1e-15);
    }

    #[test]
    fn frame_to_quat_round_trips_rotations() {
        for (axis, angle) in [
            (Vector3::x(), 3.0),
            (Vector3::y(), -2.9),
            (Vector3::z(), 3.1),
            (Vector3::new(1.0, 2.0, 3.0), 1.0),
        ] {
            let q = axis_angle(&axis.normalize(), angle);
            let m = q.to_rotation_matrix();
            let back = frame_to_quat(
                &m.matrix().column(0).into(),
                &m.matrix().column(1).into(),
                &m.matrix().column(2).into(),
            );
            assert!(back.angle_to(&q) < 1e-12, "{axis:?} {angle}");
        }
    }

    #[test]
    fn z_to_quat_maps_z_onto_direction() {
        for v in [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(0.3, -0.4, 0.5).normalize(),
        ] {
            let q = z_to_quat(&v);
            assert!((q * Vector3::z() - v).norm() < 1e-12);
        }
    }
}
