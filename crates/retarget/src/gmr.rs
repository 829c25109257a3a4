//! GMR's BVH loader (`general_motion_retargeting.utils.lafan1.load_bvh_file`) reproduced, for
//! code written against GMR: the skeleton's joints (no End Sites) in file order, then
//! `LeftFootMod` and `RightFootMod` (foot position, toe orientation), in metres from
//! centimetres, Y up turned to Z up as GMR turns it, and GMR's constant subject height.
//!
//! `format="soma"` is the loader of GMR's PR #169 (`utils/soma.py` at 67f3f248, not merged
//! into GMR): no foot bodies, Y up turned to Z up *and* +Z forward to +X
//! ([`AxisConvention::YUpFaceX`], its matrix `[[0,0,1],[1,0,0],[0,1,0]]`), a constant 1.70 m.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use bvh::Bvh;
use fk::{AxisConvention, DerivedBody, FkOptions, HumanMotion, UnitChoice};

use crate::Error;

/// The subject height GMR's loader returns for every LAFAN1 or Nokov file (m); see
/// [`BvhFormat::human_height`].
pub const HUMAN_HEIGHT: f64 = 1.75;

/// The `format` argument of GMR's loader: which toe joint gives the foot's orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BvhFormat {
    /// LAFAN1: `LeftToe`.
    Lafan1,
    /// Nokov: `LeftToeBase`.
    Nokov,
    /// SOMA (BONES-SEED, GMR PR #169, unmerged): no foot bodies, facing +X, 1.70 m.
    Soma,
}

impl BvhFormat {
    /// GMR master's names, `"lafan1"` and `"nokov"`, and GMR PR #169's `"soma"` (unmerged in
    /// GMR).
    #[must_use]
    pub fn from_name(name: &str) -> Option<BvhFormat> {
        match name {
            "lafan1" => Some(BvhFormat::Lafan1),
            "nokov" => Some(BvhFormat::Nokov),
            "soma" => Some(BvhFormat::Soma),
            _ => None,
        }
    }

    /// The subject height the loader returns for every file of this format (m).
    #[must_use]
    pub fn human_height(self) -> f64 {
        match self {
            BvhFormat::Lafan1 | BvhFormat::Nokov => HUMAN_HEIGHT,
            BvhFormat::Soma => 1.70,
        }
    }

    /// The joint whose orientation `LeftFootMod` takes, if the format has foot bodies.
    fn toe(self) -> Option<&'static str> {
        match self {
            BvhFormat::Lafan1 => Some("Toe"),
            BvhFormat::Nokov => Some("ToeBase"),
            BvhFormat::Soma => None,
        }
    }

    /// World from file: LAFAN1's Y-up turn, and for SOMA a quarter turn more to face +X.
    fn axes(self) -> AxisConvention {
        match self {
            BvhFormat::Lafan1 | BvhFormat::Nokov => AxisConvention::YUp,
            BvhFormat::Soma => AxisConvention::YUpFaceX,
        }
    }
}

/// The FK options of GMR's loader: the format's axes, centimetres, its foot bodies.
#[must_use]
pub fn fk_options(format: BvhFormat) -> FkOptions {
    let derived = match format.toe() {
        Some(toe) => ["Left", "Right"]
            .map(|side| {
                let name = format!("{side}FootMod");
                DerivedBody::new(&name, &format!("{side}Foot"), &format!("{side}{toe}"))
            })
            .into(),
        None => Vec::new(),
    };
    FkOptions {
        axes: format.axes(),
        units: UnitChoice::Scale(0.01),
        derived,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// PR #169's SOMA loader on the SOMA excerpt (`crates/fk/tests/data/soma`, eight frames of
    /// a walk along file +Z): no foot bodies, file (x, y, z) cm → world (z, x, y) m, 1.70 m.
    #[test]
    fn soma_faces_x_in_metres_without_foot_bodies() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../fk/tests/data/soma/soma_walk_excerpt.bvh");
        let bvh = bvh::from_path(&path).unwrap();
        let human = load_bvh(&bvh, BvhFormat::Soma).unwrap();
        assert_eq!(BvhFormat::Soma.human_height(), 1.70);
        assert_eq!(BvhFormat::Lafan1.human_height(), HUMAN_HEIGHT);
        assert!(!human.body_names.iter().any(|n| n.ends_with("FootMod")));
        assert_eq!(human.body_names.len(), bvh.skeleton.joints.len());
        let hips = human.body_index("Hips").unwrap();
        let (first, last) = (*human.position(0, hips), *human.position(7, hips));
        // Hips' position channels of frame 0, in the file: x, y (up), z (forward).
        let file = bvh.motion.frame(0);
        let channel = |i: usize| file[6 + i] * 0.01;
        assert!(
            (first - nalgebra::Vector3::new(channel(2), channel(0), channel(1))).norm() < 1e-12
        );
        // Walking forward is walking along world +X, upright.
        assert!(last.x - first.x > 1.0, "{first} → {last}");
        assert!((0.9..1.1).contains(&first.z), "{first}");
    }
}
