//! FBX's conventions, in one place: what the file's settings mean and how a take becomes
//! frames. The transform semantics themselves (pre-/post-rotation, rotation order, pivots
//! and offsets, inherit type, curve interpolation and extrapolation) are ufbx's, which
//! follows the FBX SDK (see the crate docs).

use nalgebra::{Matrix3, Vector3};

/// Frames per second of `GlobalSettings.TimeMode` (the FBX SDK's `FbxTime::EMode`, in its
/// order). `None` for 0 (`eDefaultMode`, see [`DEFAULT_FPS`]) and 14 (`eCustom`: the
/// `CustomFrameRate` property) and values outside the table.
#[must_use]
pub fn time_mode_fps(mode: u32) -> Option<f64> {
    Some(match mode {
        1 => 120.0,
        2 => 100.0,
        3 => 60.0,
        4 => 50.0,
        5 => 48.0,
        6 | 7 => 30.0,              // eFrames30, eFrames30Drop
        8 | 9 => 30_000.0 / 1001.0, // eNTSCDropFrame, eNTSCFullFrame (29.97)
        10 => 25.0,                 // ePAL
        11 => 24.0,                 // eFrames24
        12 => 1000.0,
        13 => 24_000.0 / 1001.0, // eFilmFullFrame (23.976)
        15 => 96.0,
        16 => 72.0,
        17 => 60_000.0 / 1001.0, // eFrames59_94
        _ => return None,
    })
}

/// The frame rate of a file whose `TimeMode` is 0 (`eDefaultMode`) or whose custom rate is
/// not positive: the FBX SDK's global default time mode, `eFrames30`. (Blender's importer
/// falls back to 25 fps instead; the XNA sample's keys lie on a 1/30 s grid.)
pub const DEFAULT_FPS: f64 = 30.0;

/// `TimeMode` 14: the rate is the `CustomFrameRate` property.
pub const TIME_MODE_CUSTOM: u32 = 14;

/// The frame times of a take declared from `start` to `stop` seconds at `fps`: the frames of
/// the file's rate grid (`k / fps`) inside the range, as animation tools play it (a take
/// starting between two frames starts at the next one). A tolerance of 10⁻⁶ frames absorbs
/// FBX's integer ticks (46 186 158 000 per second), so a range ending on a frame keeps it.
/// An empty range gives no frames.
#[must_use]
pub fn frame_range(start: f64, stop: f64, fps: f64) -> Option<(i64, i64)> {
    const EPS: f64 = 1e-6;
    if !(start.is_finite() && stop.is_finite() && fps.is_finite() && fps > 0.0) {
        return None;
    }
    let first = (start * fps - EPS).ceil();
    let last = (stop * fps + EPS).floor();
    // Beyond ±2⁵³ frames the grid is not representable; such a take is refused by the caller.
    if last < first || first.abs() > 9.0e15 || last.abs() > 9.0e15 {
        return None;
    }
    Some((first as i64, last as i64))
}

/// One axis of the file's axis system: index (0 = X, 1 = Y, 2 = Z) and sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignedAxis {
    pub index: usize,
    pub positive: bool,
}

impl std::fmt::Display for SignedAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let sign = if self.positive { '+' } else { '-' };
        let axis = ['X', 'Y', 'Z'].get(self.index).copied().unwrap_or('?');
        write!(f, "{sign}{axis}")
    }
}

/// The file's axis system (`GlobalSettings` `UpAxis`/`UpAxisSign`, `FrontAxis`/`FrontAxisSign`,
/// `CoordAxis`/`CoordAxisSign`, as ufbx reads them). `front` points out of the screen, towards
/// the viewer: a character facing the viewer faces `front`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Axes {
    pub right: SignedAxis,
    pub up: SignedAxis,
    pub front: SignedAxis,
}

impl Axes {
    /// The rotation taking file coordinates to our world (Z up): right → +X, up → +Z,
    /// front → −Y, as Blender's FBX importer does (for Y-up files `(x, y, z) ↦ (x, −z, y)`,
    /// which is also the BVH Y-up conversion of `fk`). `None` for a left-handed or degenerate
    /// system, which no rotation converts (it would mirror the motion).
    #[must_use]
    pub fn world_from_file(&self) -> Option<Matrix3<f64>> {
        // Columns: the world images of the file's X, Y and Z axes.
        let mut columns = [Vector3::<f64>::zeros(); 3];
        let images =
            [(self.right, Vector3::x()), (self.up, Vector3::z()), (self.front, -Vector3::y())];
        for (axis, world) in images {
            let sign = if axis.positive { 1.0 } else { -1.0 };
            let column = columns.get_mut(axis.index)?;
            *column += world * sign;
        }
        let m = Matrix3::from_columns(&columns);
        ((m.determinant() - 1.0).abs() < 1e-12).then_some(m)
    }
}

impl std::fmt::Display for Axes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "up {}, front {}, right {}", self.up, self.front, self.right)
    }
}

/// Metres per file unit from `GlobalSettings.UnitScaleFactor` (centimetres per file unit:
/// 1 = cm, 100 = m, 0.1 = mm); ufbx reads it as `unit_meters`. Files without it are
/// centimetres (the FBX default; FBX 6.x files).
#[must_use]
pub fn metres_per_unit(unit_meters: f64) -> f64 {
    if unit_meters.is_finite() && unit_meters > 0.0 {
        unit_meters
    } else {
        0.01
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_the_rate_grid_inside_the_declared_range() {
        assert_eq!(frame_range(0.0, 4.0 / 3.0, 30.0), Some((0, 40)));
        // The XNA take: 1/24 s .. 1.25 s at 30 fps → frames 2..=37 (36 frames).
        assert_eq!(frame_range(1.0 / 24.0, 1.25, 30.0), Some((2, 37)));
        assert_eq!(frame_range(0.0, 2.583_333_333_333_333_5, 24.0), Some((0, 62)));
        assert_eq!(frame_range(1.0, 0.5, 30.0), None);
        assert_eq!(frame_range(0.0, f64::NAN, 30.0), None);
        assert_eq!(frame_range(0.0, 1e300, 30.0), None);
    }

    #[test]
    fn y_up_is_blenders_and_bvhs_conversion() {
        let axis = |index, positive| SignedAxis { index, positive };
        let y_up = Axes { right: axis(0, true), up: axis(1, true), front: axis(2, true) };
        let m = y_up.world_from_file().unwrap();
        assert_eq!(m, Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0));
        let z_up = Axes { right: axis(0, true), up: axis(2, true), front: axis(1, false) };
        assert_eq!(z_up.world_from_file().unwrap(), Matrix3::identity());
        let left = Axes { right: axis(0, true), up: axis(1, true), front: axis(2, false) };
        assert_eq!(left.world_from_file(), None);
        assert_eq!(y_up.to_string(), "up +Y, front +Z, right +X");
    }

    #[test]
    fn time_modes_follow_the_sdk_table() {
        assert_eq!(time_mode_fps(6), Some(30.0));
        assert_eq!(time_mode_fps(11), Some(24.0));
        assert_eq!(time_mode_fps(0), None);
        assert_eq!(time_mode_fps(TIME_MODE_CUSTOM), None);
        assert!((time_mode_fps(9).unwrap() - 29.97).abs() < 1e-4);
        assert_eq!(metres_per_unit(0.01), 0.01);
        assert_eq!(metres_per_unit(0.0), 0.01);
    }
}
