//! Per-frame IK targets from human body poses, with GMR's semantics
//! (`motion_retarget.py`: `scale_human_data`, `offset_human_data`, `apply_ground_offset`,
//! `update_targets`, upstream commit 62ecdff):
//!
//! 1. every scale is multiplied by `ratio = subject height / human_height_assumption`
//!    (GMR: a constant 1.75 m subject; we use the measured or given height);
//! 2. the root position is scaled about the world origin, `p_root' = s_root · p_root`; every
//!    other body of the scale table about the root, `p' = (p − p_root) · s + p_root'`;
//!    bodies not in the scale table are no targets;
//! 3. the rotation offset multiplies on the right, `q' = q ⊗ q_offset`, and the position
//!    offset is rotated by the new orientation: `p'' = p' + R(q') (offset − ground_height ẑ)`.
//!
//! The offsets are table 1's, keyed by the human body, and they are used for the targets
//! of both stages: GMR builds one set of offset human poses (`pos_offsets1`/`rot_offsets1`)
//! and sets the table-2 tasks from it too. Table 2's offsets are therefore read but unused,
//! exactly as in GMR. A scaled body with no active table-1 entry (GMR raises `KeyError`)
//! gets no offset here.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use nalgebra::{UnitQuaternion, Vector3};

use crate::config::IkConfig;
use crate::lie::Pose;
use crate::Error;

/// One scaled human body and what turns its pose into a target.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaledBody {
    pub name: String,
    /// Index in the human motion's bodies.
    pub human: usize,
    /// Table scale × height ratio.
    pub scale: f64,
    /// Table-1 position offset minus `ground_height ẑ`.
    pub pos_offset: Vector3<f64>,
    pub rot_offset: UnitQuaternion<f64>,
}

/// The map from one frame of human poses to the world targets of every scaled body.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetMap {
    pub bodies: Vec<ScaledBody>,
    /// Index in `bodies` of the human root.
    pub root: usize,
    /// `subject height / human_height_assumption`.
    pub ratio: f64,
}

impl TargetMap {
    /// `human_bodies` are the motion's body names; `subject_height` in metres.
    pub fn new(
        config: &IkConfig,
        human_bodies: &[String],
        subject_height: f64,
    ) -> Result<TargetMap, Error> {
        if !(subject_height.is_finite() && subject_height > 0.0) {
            let why = format!("{subject_height} m is not a positive number of metres");
            return Err(Error::SubjectHeight { why });
        }
        let ratio = subject_height / config.human_height_assumption;
        let ground = Vector3::new(0.0, 0.0, config.ground_height);
        let mut bodies = Vec::with_capacity(config.human_scale_table.len());
        for (name, scale) in &config.human_scale_table {
            let human =
                human_bodies.iter().position(|h| h == name).ok_or_else(|| Error::UnknownName {
                    at: config.source.clone(),
                    side: "human".to_owned(),
                    name: name.clone(),
                    nearest: Vec::new(),
                })?;
            let offset =
                config.ik_match_table1.iter().find(|e| e.is_active() && e.human_body == *name);
            bodies.push(ScaledBody {
                name: name.clone(),
                human,
                scale: scale * ratio,
                pos_offset: offset.map_or(Vector3::zeros(), |e| e.pos_offset) - ground,
                rot_offset: offset.map_or(UnitQuaternion::identity(), |e| e.rot_offset),
            });
        }
        let root =
            bodies.iter().position(|b| b.name == config.human_root_name).ok_or_else(|| {
                Error::Config {
                    at: config.source.clone(),
                    message: format!(
                        "human root `{}` is not in human_scale_table",
                        config.human_root_name
                    ),
                }
            })?;
        Ok(TargetMap { bodies, root, ratio })
    }

    /// Index in [`TargetMap::bodies`] of the human body `name`.
    #[must_use]
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Targets of one frame: `positions`/`orientations` are all human bodies of the frame
    /// (indexed like the motion), `out` gets one pose per scaled body. Panics if they hold
    /// fewer bodies than the motion the map was made for.
    // `bodies[..].human` index the motion's bodies the map was built from (`new` resolved them
    // by name) and `root` indexes `bodies`: a shorter slice is a caller's bug.
    #[allow(clippy::indexing_slicing)]
    pub fn compute(
        &self,
        positions: &[Vector3<f64>],
        orientations: &[UnitQuaternion<f64>],
        out: &mut [Pose],
    ) {
        let root_pos = positions[self.bodies[self.root].human];
        let scaled_root = root_pos * self.bodies[self.root].scale;
        for (b, slot) in self.bodies.iter().zip(out.iter_mut()) {
            let p = if b.human == self.bodies[self.root].human {
                scaled_root
            } else {
                (positions[b.human] - root_pos) * b.scale + scaled_root
            };
            let q = orientations[b.human] * b.rot_offset;
            let q = UnitQuaternion::new_normalize(q.into_inner());
            let pos = p + q.to_rotation_matrix() * b.pos_offset;
            *slot = Pose { quat: [q.w, q.i, q.j, q.k], pos };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONFIG: &str = r#"{
  "robot_root_name": "r", "human_root_name": "Hips", "ground_height": 0.1,
  "human_height_assumption": 2.0, "use_ik_match_table1": true, "use_ik_match_table2": true,
  "human_scale_table": {"Hips": 0.5, "Hand": 2.0},
  "ik_match_table1": {
    "r": ["Hips", 0, 10, [0, 0, 0], [1, 0, 0, 0]],
    "h": ["Hand", 1, 1, [1, 0, 0], [0.70710678118654757, 0, 0, 0.70710678118654757]]
  },
  "ik_match_table2": {
    "h": ["Hand", 1, 1, [5, 5, 5], [0, 1, 0, 0]]
  }
}"#;

    /// Hand-computed: height 3 m vs 2 m assumed → ratio 1.5; Hips scale 0.75, Hand 3.
    #[test]
    fn gmr_semantics_on_hand_numbers() {
        let config = IkConfig::from_json_str(CONFIG, "t").unwrap();
        let names = vec!["Hips".to_owned(), "Spine".to_owned(), "Hand".to_owned()];
        let map = TargetMap::new(&config, &names, 3.0).unwrap();
        assert_eq!(map.bodies.len(), 2);
        let pos = [Vector3::new(2.0, 0.0, 1.0), Vector3::zeros(), Vector3::new(2.0, 1.0, 1.0)];
        let rot = [UnitQuaternion::identity(); 3];
        let mut out = [Pose { quat: [1.0, 0.0, 0.0, 0.0], pos: Vector3::zeros() }; 2];
        map.compute(&pos, &rot, &mut out);
        // Root: 0.75 · (2, 0, 1) = (1.5, 0, 0.75), then the ground offset −0.1 ẑ.
        assert!((out[0].pos - Vector3::new(1.5, 0.0, 0.65)).norm() < 1e-15);
        // Hand: (0, 1, 0) · 3 + root' = (1.5, 3, 0.75); q' = 90° about z (table 1's offset,
        // table 2's is ignored); offset (1, 0, −0.1) rotated → (0, 1, −0.1).
        assert!((out[1].pos - Vector3::new(1.5, 4.0, 0.65)).norm() < 1e-12, "{}", out[1].pos);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((out[1].quat[0] - h).abs() < 1e-12 && (out[1].quat[3] - h).abs() < 1e-12);
    }
}
