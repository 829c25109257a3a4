//! The knobs of [`crate::human_motion`], with defaults that reproduce GMR's LAFAN1 loader.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, UnitQuaternion};

use crate::Role;

/// Which way is up (and forward) in the source file; fixes the proper rotation from file axes
/// to our world (Z up). Every variant is a rotation (determinant +1): a reflection would
/// silently mirror the motion, turning left feet into right ones.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum AxisConvention {
    /// Inferred from the motion: the file axis along which the head is above the feet
    /// ([`crate::Humanoid::up`]), converted as [`AxisConvention::YUp`] for +Y and
    /// [`AxisConvention::ZUp`] for +Z. When no humanoid is recognised, [`AxisConvention::YUp`]
    /// (the BVH norm), which is also what the matrix and quaternion of `Auto` are.
    #[default]
    Auto,
    /// Y up (the BVH norm, LAFAN1, CMU, Bandai): +90° about X, `(x, y, z) ↦ (x, −z, y)`.
    /// This is GMR's conversion; a subject facing file +Z faces world −Y.
    YUp,
    /// The file is already Z up: identity.
    ZUp,
    /// Y up, facing +Z in the file, turned to face world +X (the robots' forward):
    /// `(x, y, z) ↦ (z, x, y)`. Differs from [`AxisConvention::YUp`] by a yaw of 90°.
    YUpFaceX,
    /// Any rotation taking file coordinates to world coordinates.
    Custom(UnitQuaternion<f64>),
}

impl AxisConvention {
    /// The convention of a world-from-file rotation matrix: the named variant it equals
    /// exactly (so that positions are permuted without rounding), else [`AxisConvention::Custom`].
    /// `None` when `m` is not a rotation.
    #[must_use]
    pub fn from_matrix(m: &Matrix3<f64>) -> Option<AxisConvention> {
        let orthonormal = (m * m.transpose() - Matrix3::identity()).amax() < 1e-9;
        if !(orthonormal && (m.determinant() - 1.0).abs() < 1e-9) {
            return None;
        }
        let named = [AxisConvention::YUp, AxisConvention::ZUp, AxisConvention::YUpFaceX];
        Some(named.into_iter().find(|a| a.world_from_file_matrix() == *m).unwrap_or_else(|| {
            let r = nalgebra::Rotation3::from_matrix_unchecked(*m);
            AxisConvention::Custom(UnitQuaternion::from_rotation_matrix(&r))
        }))
    }

    /// World-from-file rotation as a matrix, exact (entries 0 and ±1) for the named variants so
    /// that positions are permuted without rounding, as GMR's `p @ R.T` does.
    #[must_use]
    pub fn world_from_file_matrix(&self) -> Matrix3<f64> {
        match self {
            AxisConvention::Auto | AxisConvention::YUp => {
                Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0)
            }
            AxisConvention::ZUp => Matrix3::identity(),
            AxisConvention::YUpFaceX => Matrix3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0),
            AxisConvention::Custom(q) => q.to_rotation_matrix().into_inner(),
        }
    }

    /// World-from-file rotation as a quaternion. For [`AxisConvention::YUp`] this is the value
    /// scipy's `Rotation.from_matrix(...).as_quat()` gives GMR, `(2, 2, 0, 0)/√8`.
    #[must_use]
    pub fn world_from_file(&self) -> UnitQuaternion<f64> {
        match self {
            AxisConvention::Custom(q) => *q,
            // scipy's from_matrix on an exact matrix: (2, 2, 0, 0) / ‖·‖, which is one ulp
            // below FRAC_1_SQRT_2; spelled out so the parity with GMR is exact.
            AxisConvention::Auto | AxisConvention::YUp => {
                let h = 2.0 / 8.0_f64.sqrt();
                UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(h, h, 0.0, 0.0))
            }
            AxisConvention::ZUp => UnitQuaternion::identity(),
            // (x, y, z) ↦ (z, x, y): 120° about (1, 1, 1)/√3, exactly (½, ½, ½, ½).
            AxisConvention::YUpFaceX => {
                UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(0.5, 0.5, 0.5, 0.5))
            }
        }
    }
}

/// How file units become metres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum UnitChoice {
    /// Chosen from the skeleton's size: the candidate (m, cm, mm, inch, CMU unit) that gives
    /// the subject a plausible human height. See [`crate::FkReport::unit_reason`].
    #[default]
    Auto,
    /// Metres per file unit (0.01 for centimetres).
    Scale(f64),
    /// The unit the file declares (FBX's `UnitScaleFactor`), in metres per file unit: used
    /// when the figure is a human size in it, else the figure is scaled by its proportions to
    /// a typical human, as [`UnitChoice::Auto`] does when no unit fits (a 0.6 m or a 4.9 m
    /// game character retargets as a human-sized one).
    Declared(f64),
}

/// A body that is not a skeleton joint but combines two: GMR's `LeftFootMod` is the position
/// of `LeftFoot` with the orientation of `LeftToe`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DerivedBody {
    pub name: String,
    pub position_from: String,
    pub orientation_from: String,
}

impl DerivedBody {
    #[must_use]
    pub fn new(name: &str, position_from: &str, orientation_from: &str) -> DerivedBody {
        DerivedBody {
            name: name.to_owned(),
            position_from: position_from.to_owned(),
            orientation_from: orientation_from.to_owned(),
        }
    }

    /// GMR's foot bodies: `LeftFootMod`/`RightFootMod` = foot position + toe orientation, the
    /// toe being `LeftToe` (LAFAN1) or `LeftToeBase` (Nokov, Mixamo-like). Used by
    /// [`FkOptions::default`]; entries whose joints are missing are skipped silently.
    #[must_use]
    pub fn gmr_defaults() -> Vec<DerivedBody> {
        vec![
            DerivedBody::new("LeftFootMod", "LeftFoot", "LeftToe"),
            DerivedBody::new("LeftFootMod", "LeftFoot", "LeftToeBase"),
            DerivedBody::new("RightFootMod", "RightFoot", "RightToe"),
            DerivedBody::new("RightFootMod", "RightFoot", "RightToeBase"),
        ]
    }
}

/// Options of [`crate::human_motion`].
#[derive(Debug, Clone, PartialEq)]
pub struct FkOptions {
    pub axes: AxisConvention,
    pub units: UnitChoice,
    /// Bodies added after the skeleton's joints, in this order. An entry equal to one of
    /// [`DerivedBody::gmr_defaults`] is skipped when its joints are missing or its name already
    /// exists (the defaults list alternatives); any other entry must resolve, or it is an error.
    pub derived: Vec<DerivedBody>,
    /// Subject height in metres; `None` estimates it from the motion (see [`crate::FkReport`]).
    pub height: Option<f64>,
    /// Roles fixed by joint name, overriding the recogniser ([`crate::recognise`]).
    pub roles: BTreeMap<Role, String>,
}

impl Default for FkOptions {
    fn default() -> FkOptions {
        FkOptions {
            axes: AxisConvention::default(),
            units: UnitChoice::default(),
            derived: DerivedBody::gmr_defaults(),
            height: None,
            roles: BTreeMap::new(),
        }
    }
}
