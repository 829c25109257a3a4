//! GMR's BVH loader (`general_motion_retargeting.utils.lafan1.load_bvh_file`) reproduced, for
//! code written against GMR: the skeleton's joints (no End Sites) in file order, then
//! `LeftFootMod` and `RightFootMod` (foot position, toe orientation), in metres from
//! centimetres, Y up turned to Z up as GMR turns it, and GMR's constant subject height.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use bvh::Bvh;
use fk::{AxisConvention, DerivedBody, FkOptions, HumanMotion, UnitChoice};

use crate::Error;

/// The subject height GMR's loader returns for every file (m).
pub const HUMAN_HEIGHT: f64 = 1.75;

/// The `format` argument of GMR's loader: which toe joint gives the foot's orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BvhFormat {
    /// LAFAN1: `LeftToe`.
    Lafan1,
    /// Nokov: `LeftToeBase`.
    Nokov,
}

impl BvhFormat {
    /// GMR's names, `"lafan1"` and `"nokov"`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<BvhFormat> {
        match name {
            "lafan1" => Some(BvhFormat::Lafan1),
            "nokov" => Some(BvhFormat::Nokov),
            _ => None,
        }
    }

    fn toe(self) -> &'static str {
        match self {
            BvhFormat::Lafan1 => "Toe",
            BvhFormat::Nokov => "ToeBase",
        }
    }
}

/// The FK options of GMR's loader: Y up, centimetres, the format's foot bodies.
#[must_use]
pub fn fk_options(format: BvhFormat) -> FkOptions {
    let foot = |side: &str| {
        let name = format!("{side}FootMod");
        DerivedBody::new(&name, &format!("{side}Foot"), &format!("{side}{}", format.toe()))
    };
    FkOptions {
        axes: AxisConvention::YUp,
        units: UnitChoice::Scale(0.01),
        derived: vec![foot("Left"), foot("Right")],
        ..FkOptions::default()
    }
}

/// What GMR's loader returns for `bvh`: every frame's world poses of the joints and the two
/// foot bodies (End Sites left out, as GMR's reader skips them).
pub fn load_bvh(bvh: &Bvh, format: BvhFormat) -> Result<HumanMotion, Error> {
    let (motion, _) = fk::human_motion(bvh, &fk_options(format))?;
    let keep: Vec<usize> = (0..motion.num_bodies())
        .filter(|&b| bvh.skeleton.joints.get(b).is_none_or(|j| j.kind != bvh::JointKind::End))
        .collect();
    // Frame by frame (`max(1)`: a motion without bodies has no rows to split).
    let nb = motion.num_bodies().max(1);
    let rows = motion.positions.chunks_exact(nb).zip(motion.orientations.chunks_exact(nb));
    let mut positions = Vec::with_capacity(motion.num_frames * keep.len());
    let mut orientations = Vec::with_capacity(motion.num_frames * keep.len());
    for (pos, rot) in rows {
        positions.extend(keep.iter().filter_map(|&b| pos.get(b)));
        orientations.extend(keep.iter().filter_map(|&b| rot.get(b)));
    }
    Ok(HumanMotion {
        fps: motion.fps,
        body_names: keep.iter().filter_map(|&b| motion.body_names.get(b).cloned()).collect(),
        num_frames: motion.num_frames,
        positions,
        orientations,
    })
}
