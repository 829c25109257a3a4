//! Body mass and inertia the way MuJoCo's compiler makes them from explicit inertials
//! (`user_objects.cc`: `mjCBody::Compile`, `mjCBody::AccumulateInertia`; `user_util.cc`:
//! `mjuu_fullInertia`; `engine_support.c`: `mj_setTotalmass`), shared by MJCF and URDF.
//!
//! MuJoCo keeps a body's inertia as principal moments on principal axes (`body_inertia`,
//! `body_iquat`). A full tensor (`fullinertia`, a URDF `<inertia>`) is diagonalised, moments in
//! decreasing order as `mjuu_eig3` sorts them; a static link fused into its parent adds its
//! mass, moves the centre of mass to the mass-weighted mean and its tensor by the
//! parallel-axis theorem, and the sum is diagonalised again.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::model::{Body, Inertial};

/// MuJoCo's `mjMINVAL`: a fused link lighter than this adds nothing to its parent.
pub(crate) const MJ_MINVAL: f64 = 1e-15;

/// MuJoCo's `mjEPS`: the smallest principal moment `mjuu_fullInertia` accepts.
const MJ_EPS: f64 = 1e-14;

/// `<compiler>` attributes that change explicit inertials (MuJoCo's defaults when absent).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct InertiaOptions {
    /// `inertiafromgeom="true"`: MuJoCo ignores `<inertial>` and takes every body's mass from
    /// its geoms, which is not done here.
    pub from_geom: bool,
    pub boundmass: f64,
    pub boundinertia: f64,
    pub balance: bool,
    /// `settotalmass` when positive.
    pub total_mass: Option<f64>,
}

/// A massless point at the body origin: what a body without an `<inertial>` and without geoms
/// has when a static link is fused into it.
pub(crate) const NO_MASS: Inertial = Inertial {
    mass: 0.0,
    pos: Vector3::new(0.0, 0.0, 0.0),
    quat: UnitQuaternion::new_unchecked(Quaternion::new(1.0, 0.0, 0.0, 0.0)),
    diag: Vector3::new(0.0, 0.0, 0.0),
};

/// The symmetric matrix of MuJoCo's `fullinertia` order `ixx iyy izz ixy ixz iyz`.
#[must_use]
pub(crate) fn full_matrix([xx, yy, zz, xy, xz, yz]: [f64; 6]) -> Matrix3<f64> {
    Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}

/// `mjuu_fullInertia`: principal axes (a right-handed frame) and moments of a symmetric
/// inertia, moments in decreasing order, by MuJoCo's Jacobi iteration ([`eig3`]). MuJoCo
/// rejects a smallest moment below `mjEPS`, and so do we.
pub(crate) fn principal_axes(
    full: &Matrix3<f64>,
) -> Result<(UnitQuaternion<f64>, Vector3<f64>), &'static str> {
    let (quat, [a, b, c]) = eig3(full);
    if c.is_nan() || c < MJ_EPS {
        return Err("inertia must have positive eigenvalues");
    }
    Ok((quat, Vector3::new(a, b, c)))
}

/// `mjuu_eig3` (`user_util.cc`) orders equal eigenvalues within this as they come.
const EIG_TIE: f64 = 1e-12;

/// `mjuu_eig3`: Jacobi rotations, each zeroing the largest off-diagonal element of `Rᵀ M R`,
/// accumulated in the quaternion of `R`; then the eigenvalues sorted in decreasing order by
/// quarter turns of the frame (MuJoCo's order and axes).
///
/// The stopping rule is ours: until the off-diagonal is rounding (largest element below
/// `ε max|M|`, or its norm no longer shrinking), with the half angle computed from `t` so
/// that small rotations stay exact. MuJoCo 3.17.0's `mjuu_eig3` takes a tolerance whose rule
/// is not published; it also converges to rounding (`R diag Rᵀ` within ~1e-14 of the input,
/// measured), whereas the published older one, stopping once the cosine is within 1e-12 of 1,
/// is off by up to 1e-8. nalgebra's `SymmetricEigen` is not used: it loses the axes of nearly
/// equal moments (3.9e-12 kg m² off on G1's `right_knee_link`, up to 5e-4 relative on random
/// near-degenerate tensors).
fn eig3(m: &Matrix3<f64>) -> (UnitQuaternion<f64>, [f64; 3]) {
    let floor = f64::EPSILON * m.amax();
    let mut q = Quaternion::identity();
    let mut d = *m;
    let mut last = f64::INFINITY;
    for _ in 0..64 {
        let r = UnitQuaternion::new_unchecked(q).to_rotation_matrix().into_inner();
        d = r.transpose() * m * r;
        // In exact arithmetic every rotation shrinks the off-diagonal norm: once it does not,
        // rounding is all that is left.
        let norm = d.m12.hypot(d.m13).hypot(d.m23);
        if norm >= last {
            break;
        }
        last = norm;
        // (off-diagonal element, its row's and column's diagonal ones, rotation axis); a
        // rotation about y turns the other way in the (x, z) plane.
        let (off, row, col, axis) = if d.m12.abs() > d.m13.abs() && d.m12.abs() > d.m23.abs() {
            (d.m12, d.m11, d.m22, Vector3::z())
        } else if d.m13.abs() > d.m23.abs() {
            (d.m13, d.m11, d.m33, -Vector3::y())
        } else {
            (d.m23, d.m22, d.m33, Vector3::x())
        };
        if off.abs() <= floor {
            break;
        }
        // The 2×2 symmetric Schur decomposition (Golub & Van Loan, Algorithm 8.4.1): the
        // rotation by atan(t) zeroes `off`; its half angle from t, stable for small angles.
        let tau = (col - row) / (2.0 * off);
        let t = if tau >= 0.0 { 1.0 } else { -1.0 } / (tau.abs() + (1.0 + tau * tau).sqrt());
        let c = 1.0 / (1.0 + t * t).sqrt();
        let half_sin = t * c / (2.0 * (1.0 + c)).sqrt();
        let step = Quaternion::from_parts(((1.0 + c) / 2.0).sqrt(), axis * -half_sin);
        q = (q * step).normalize();
    }
    let [mut a, mut b, mut c] = [d.m11, d.m22, d.m33];
    // A quarter turn about z swaps the first two axes, about x the last two.
    let turn = |q: Quaternion<f64>, axis: Vector3<f64>| {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        (q * Quaternion::from_parts(h, axis * h)).normalize()
    };
    if a + EIG_TIE < b {
        std::mem::swap(&mut a, &mut b);
        q = turn(q, Vector3::z());
    }
    if b + EIG_TIE < c {
        std::mem::swap(&mut b, &mut c);
        q = turn(q, Vector3::x());
    }
    if a + EIG_TIE < b {
        std::mem::swap(&mut a, &mut b);
        q = turn(q, Vector3::z());
    }
    (UnitQuaternion::new_unchecked(q), [a, b, c])
}

/// `mjCBody::Compile` on a body's mass and principal moments: `boundmass` and `boundinertia`
/// raise them, then the moments must satisfy the triangle inequality `A + B ≥ C` (a rigid
/// body's do), else `balanceinertia` replaces all three by their mean or it is an error.
pub(crate) fn bound_and_check(
    mass: f64,
    diag: Vector3<f64>,
    options: &InertiaOptions,
) -> Result<(f64, Vector3<f64>), &'static str> {
    let mass = mass.max(options.boundmass);
    let d = diag.map(|m| m.max(options.boundinertia));
    if d.x + d.y >= d.z && d.x + d.z >= d.y && d.y + d.z >= d.x {
        return Ok((mass, d));
    }
    if options.balance {
        Ok((mass, Vector3::repeat((d.x + d.y + d.z) / 3.0)))
    } else {
        Err("inertia must satisfy A + B >= C; use 'balanceinertia' to fix")
    }
}

/// The inertia tensor about the centre of mass, in the body frame: `R diag Rᵀ`.
#[must_use]
pub(crate) fn tensor(i: &Inertial) -> Matrix3<f64> {
    let r = i.quat.to_rotation_matrix();
    r.matrix() * Matrix3::from_diagonal(&i.diag) * r.matrix().transpose()
}

/// `i`, given in a frame placed at `pos`, `quat` in the body frame, in the body frame.
#[must_use]
pub(crate) fn placed(i: &Inertial, pos: &Vector3<f64>, quat: &UnitQuaternion<f64>) -> Inertial {
    Inertial { pos: pos + quat * i.pos, quat: quat * i.quat, ..*i }
}

/// `mjCBody::AccumulateInertia`: `b` (at least `mjMINVAL` heavy, lighter links are skipped)
/// fused into `a`, both in `a`'s body frame. Masses add,
/// the centre of mass is their weighted mean, each tensor moves to it by the parallel-axis
/// theorem (`m (|d|² 1 − d dᵀ)`, MuJoCo's `mjuu_offcenter`) and the sum is diagonalised again.
pub(crate) fn combine(a: &Inertial, b: &Inertial) -> Result<Inertial, &'static str> {
    let mass = a.mass + b.mass;
    let pos = (a.pos * a.mass + b.pos * b.mass) / mass;
    let about_com = |i: &Inertial| {
        let d = i.pos - pos;
        tensor(i) + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * i.mass
    };
    let (quat, diag) = principal_axes(&(about_com(a) + about_com(b)))?;
    Ok(Inertial { mass, pos, quat, diag })
}

/// `settotalmass` (`mj_setTotalmass` on the compiled model): every mass and moment scaled by
/// one factor so that the masses sum to `total`. The sum needs every body's mass, so this is
/// done only when every body but the world has an inertial; otherwise every one becomes
/// `None` (the others' masses would come from their geoms).
pub(crate) fn set_total_mass(bodies: &mut [Body], total: f64) {
    let rest = bodies.get_mut(1..).unwrap_or_default();
    if rest.iter().any(|b| b.inertial.is_none()) {
        rest.iter_mut().for_each(|b| b.inertial = None);
        return;
    }
    let sum: f64 = rest.iter().filter_map(|b| b.inertial).map(|i| i.mass).sum();
    let scale = (total / sum.max(MJ_MINVAL)).max(MJ_MINVAL);
    for i in rest.iter_mut().filter_map(|b| b.inertial.as_mut()) {
        i.mass *= scale;
        i.diag *= scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inertial(mass: f64, pos: [f64; 3], full: [f64; 6]) -> Inertial {
        let (quat, diag) = principal_axes(&full_matrix(full)).unwrap();
        Inertial { mass, pos: Vector3::from(pos), quat, diag }
    }

    #[test]
    fn principal_axes_are_mujocos() {
        // MuJoCo 3.17.0's body_inertia and body_iquat for fullinertia="3 3.5 4 0.1 0.2 0.3".
        let full = full_matrix([3.0, 3.5, 4.0, 0.1, 0.2, 0.3]);
        let (quat, diag) = principal_axes(&full).unwrap();
        let moments = Vector3::new(4.18276016566592, 3.3595649771583007, 2.957674857175793);
        let axes = Quaternion::new(
            0.17295090213860134,
            0.7502957525703104,
            0.13475501351867408,
            0.6236869049899816,
        );
        assert!((diag - moments).amax() < 1e-14, "{diag}");
        assert!((quat.coords - axes.coords).amax() < 1e-14, "{quat}");
        let i = Inertial { mass: 1.0, pos: Vector3::zeros(), quat, diag };
        assert!((tensor(&i) - full).amax() < 4.0 * f64::EPSILON * 4.0, "{}", tensor(&i) - full);
        // Already diagonal: sorted (3 2 1), the axes turned with them as MuJoCo turns them
        // (its quaternion is 1e-15 off unit length).
        let (quat, diag) = principal_axes(&full_matrix([1.0, 2.0, 3.0, 0.0, 0.0, 0.0])).unwrap();
        let h = 0.7071067811865489;
        assert_eq!(diag, Vector3::new(3.0, 2.0, 1.0));
        assert!((quat.coords - Quaternion::new(0.0, h, 0.0, h).coords).amax() < 1e-14, "{quat}");
        assert!(principal_axes(&full_matrix([1.0, 1.0, 1.0, 2.0, 0.0, 0.0])).is_err());
    }

    /// Two nearly equal moments, where nalgebra's `SymmetricEigen` gets the axes wrong by
    /// 4e-5 kg m² of `R diag Rᵀ`.
    #[test]
    fn principal_axes_of_nearly_equal_moments() {
        let full = full_matrix([
            7.730508440427661e-2,
            7.73052356153337e-2,
            1.3479821119828879e-2,
            5.277666689318701e-8,
            8.497981369983603e-4,
            -7.451099351157997e-4,
        ]);
        let (quat, diag) = principal_axes(&full).unwrap();
        let i = Inertial { mass: 1.0, pos: Vector3::zeros(), quat, diag };
        assert!((tensor(&i) - full).amax() < 1e-15, "{}", tensor(&i) - full);
    }

    /// Random rotations of moments that are well apart, nearly equal in pairs and triples,
    /// equal, or zero, at scales from 1e-9 to 1e3 (fixed seed): `R diag Rᵀ` is the tensor to
    /// rounding, the moments come sorted, the frame is a rotation.
    #[test]
    fn principal_axes_reconstruct_random_tensors() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let mut worst = 0.0f64;
        for n in 0..20_000 {
            let a: f64 = rng.gen_range(0.1..10.0);
            let near = |rng: &mut rand_chacha::ChaCha8Rng| 10f64.powf(-rng.gen_range(3.0..16.0));
            let moments = match n % 5 {
                0 => [a, rng.gen_range(0.1..10.0), rng.gen_range(0.1..10.0)],
                1 => [a, a * (1.0 + near(&mut rng)), rng.gen_range(0.1..10.0)],
                2 => [a, a * (1.0 + near(&mut rng)), a * (1.0 - near(&mut rng))],
                3 => [a, a, rng.gen_range(0.1..10.0)],
                _ => [a, rng.gen_range(0.1..10.0), 0.0],
            };
            let scale = 10f64.powf(rng.gen_range(-9.0..3.0));
            let axis = Vector3::new(rng.gen(), rng.gen(), rng.gen()) - Vector3::repeat(0.5);
            let turn = UnitQuaternion::from_scaled_axis(axis * 7.0);
            let given = Inertial {
                mass: 1.0,
                pos: Vector3::zeros(),
                quat: turn,
                diag: Vector3::from(moments) * scale,
            };
            let full = tensor(&given);
            let (quat, [x, y, z]) = eig3(&full);
            let ours = Inertial { quat, diag: Vector3::new(x, y, z), ..given };
            worst = worst.max((tensor(&ours) - full).amax() / full.amax());
            assert!(x + EIG_TIE >= y && y + EIG_TIE >= z, "{n}: {x} {y} {z}");
            assert!((quat.norm() - 1.0).abs() < 1e-15);
        }
        assert!(worst < 1e-14, "{worst:e}");
    }

    #[test]
    fn bounds_and_balance_follow_mujoco() {
        let options = InertiaOptions::default();
        let lopsided = Vector3::new(1.0, 1.0, 3.0);
        assert!(bound_and_check(1.0, lopsided, &options).is_err());
        let balance = InertiaOptions { balance: true, ..options };
        let (_, d) = bound_and_check(1.0, lopsided, &balance).unwrap();
        assert_eq!(d, Vector3::repeat(5.0 / 3.0));
        let bound = InertiaOptions { boundmass: 0.01, boundinertia: 1.5, ..options };
        let (m, d) = bound_and_check(0.001, Vector3::new(1.0, 2.0, 3.0), &bound).unwrap();
        assert_eq!((m, d), (0.01, Vector3::new(1.5, 2.0, 3.0)));
    }

    /// Two unit point-ish masses 2 m apart: the parallel-axis terms by hand.
    #[test]
    fn combine_adds_mass_and_moves_tensors_to_the_centre_of_mass() {
        let a = inertial(1.0, [-1.0, 0.0, 0.0], [0.1, 0.1, 0.1, 0.0, 0.0, 0.0]);
        let b = inertial(3.0, [1.0, 0.0, 0.0], [0.2, 0.3, 0.4, 0.0, 0.0, 0.0]);
        let c = combine(&a, &b).unwrap();
        assert_eq!(c.mass, 4.0);
        assert!((c.pos - Vector3::new(0.5, 0.0, 0.0)).norm() < 1e-15);
        // About the centre of mass: a is 1.5 m away, b 0.5 m, both along x.
        let offset = 1.0 * 1.5 * 1.5 + 3.0 * 0.5 * 0.5;
        let expected = full_matrix([0.3, 0.4 + offset, 0.5 + offset, 0.0, 0.0, 0.0]);
        assert!((tensor(&c) - expected).norm() < 1e-14, "{}", tensor(&c));
        // Fusing into a massless body diagonalises again: a point mass alone has no axes.
        let point = Inertial { mass: 1.0, ..NO_MASS };
        assert!(combine(&NO_MASS, &point).is_err());
        assert!((tensor(&combine(&NO_MASS, &b).unwrap()) - tensor(&b)).norm() < 1e-15);
    }
}
