//! FBX takes for the retargeter: one take of an FBX file ([`fbx::Fbx`]) as the skeleton and
//! motion our BVH path reads, with the FK options its file declares (axes, unit), so that
//! the rest of the pipeline is the BVH one.
//!
//! - Axes: the file's axis system ([`fbx::Info::world_from_file`]), unless the options give
//!   other axes.
//! - Unit: the declared `UnitScaleFactor` ([`fk::UnitChoice::Declared`]): kept for a
//!   human-sized figure, else the figure is scaled by its proportions to a human size (a
//!   0.63 m or a 4.9 m game character), unless the options force a unit.
//! - One bone per limb (no elbows or knees): straight limbs ([`fk::straighten_limbs`]).

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::path::Path;

use bvh::Bvh;
use fk::{AxisConvention, FkOptions, UnitChoice};

use crate::Error;

/// One take of an FBX file, ready for FK.
#[derive(Debug, Clone)]
pub struct FbxClip {
    /// The file as errors name it.
    pub file: String,
    pub info: fbx::Info,
    pub take: fbx::Selected,
    /// The take's skeleton and motion in the file's axes and units (straight elbows and
    /// knees added where the rig has none).
    pub bvh: Bvh,
    /// The joints added by [`fk::straighten_limbs`] (`<upper arm>.elbow`, `<thigh>.knee`).
    pub straightened: Vec<String>,
    axes: AxisConvention,
}

impl FbxClip {
    /// Reads `path` and samples take `take` (its name or index; `None`: the take with the
    /// most motion, [`fbx::Fbx::select_take`]).
    pub fn read(path: &Path, take: Option<&str>) -> Result<FbxClip, Error> {
        FbxClip::from_fbx(&fbx::Fbx::from_path(path)?, take)
    }

    /// Take `take` of a loaded file.
    pub fn from_fbx(file: &fbx::Fbx, take: Option<&str>) -> Result<FbxClip, Error> {
        let info = file.info().clone();
        let axes =
            info.world_from_file().and_then(|m| AxisConvention::from_matrix(&m)).ok_or_else(
                || fbx::Error::Axes { file: file.file().to_owned(), axes: info.axes.to_string() },
            )?;
        let take = file.select_take(take)?;
        let bvh = file.bvh(take.index)?;
        let (bvh, straightened) = match fk::straighten_limbs(&bvh) {
            Some((straight, added)) => (straight, added),
            None => (bvh, Vec::new()),
        };
        Ok(FbxClip { file: file.file().to_owned(), info, take, bvh, straightened, axes })
    }

    /// `base` with the file's axes and declared unit where `base` leaves them to inference.
    #[must_use]
    pub fn fk_options(&self, base: &FkOptions) -> FkOptions {
        let mut options = base.clone();
        if options.axes == AxisConvention::Auto {
            options.axes = self.axes;
        }
        if options.units == UnitChoice::Auto {
            options.units = UnitChoice::Declared(self.info.metres_per_unit);
        }
        options
    }

    /// One line on the take and what the file declares: "take `walk` (the only take), 41
    /// frames at 30 fps; Y up (up +Y, front +Z, right +X), 0.01 m per unit (UnitScaleFactor
    /// 1)", plus the frame-rate default and the straightened limbs when there are.
    #[must_use]
    pub fn summary(&self) -> String {
        let info = &self.info;
        let frames = info.takes.get(self.take.index).map_or(0, |t| t.frames);
        let mut out = format!(
            "take `{}` ({}), {frames} frames at {} fps; axes from the file ({}), {} m per unit \
             (UnitScaleFactor {})",
            self.take.name,
            self.take.reason,
            info.fps,
            info.axes,
            info.metres_per_unit,
            info.unit_scale_factor
        );
        if let Some(note) = &info.fps_note {
            out.push_str(&format!("; {note}"));
        }
        if !self.straightened.is_empty() {
            out.push_str(&format!(
                "; one bone per limb: straight {} added",
                self.straightened.join(", ")
            ));
        }
        out
    }
}
