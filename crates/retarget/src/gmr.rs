//! GMR's BVH loader (`general_motion_retargeting.utils.lafan1.load_bvh_file`) reproduced, for
//! code written against GMR: the skeleton's joints (no End Sites) in file order, then
//! `LeftFootMod` and `RightFootMod` (foot position, toe orientation), in metres from
//! centimetres, Y up turned to Z up as GMR turns it, and GMR's constant subject height.

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
    let nb = motion.num_bodies();
    let mut positions = Vec::with_capacity(motion.num_frames * keep.len());
    let mut orientations = Vec::with_capacity(motion.num_frames * keep.len());
    for f in 0..motion.num_frames {
        for &b in &keep {
            positions.push(motion.positions[f * nb + b]);
            orientations.push(motion.orientations[f * nb + b]);
        }
    }
    Ok(HumanMotion {
        fps: motion.fps,
        body_names: keep.iter().map(|&b| motion.body_names[b].clone()).collect(),
        num_frames: motion.num_frames,
        positions,
        orientations,
    })
}
