//! [`HumanMotion`]: world poses of every body for every frame, in one flat array each.

use nalgebra::{UnitQuaternion, Vector3};

use crate::Error;

/// Forward kinematics of a whole clip: per frame, per body, world position (metres, Z up)
/// and world orientation (continuous in time: consecutive frames never differ in sign).
///
/// Bodies are every BVH joint in file order (End Sites included, named `<Parent>_End`),
/// then the derived bodies. Element `[frame * num_bodies + body]` of `positions` and
/// `orientations` belongs to `body` at `frame`.
#[derive(Debug, Clone, PartialEq)]
pub struct HumanMotion {
    /// Frames per second: `1 / Frame Time`, snapped to an integer when the file's Frame Time
    /// is that integer's reciprocal rounded (`0.033333` → 30).
    pub fps: f64,
    pub body_names: Vec<String>,
    pub num_frames: usize,
    pub positions: Vec<Vector3<f64>>,
    pub orientations: Vec<UnitQuaternion<f64>>,
}

impl HumanMotion {
    #[must_use]
    pub fn num_bodies(&self) -> usize {
        self.body_names.len()
    }

    #[must_use]
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.body_names.iter().position(|n| n == name)
    }

    /// Like [`HumanMotion::body_index`], but an unknown name is an error listing the bodies.
    pub fn require_body(&self, name: &str) -> Result<usize, Error> {
        self.body_index(name).ok_or_else(|| Error::UnknownBody {
            name: name.to_owned(),
            available: self.body_names.clone(),
        })
    }

    /// World position of `body` at `frame` (metres, Z up). Panics if either is out of range.
    #[must_use]
    pub fn position(&self, frame: usize, body: usize) -> &Vector3<f64> {
        &self.positions[self.slot(frame, body)]
    }

    /// World orientation of `body` at `frame`. Panics if either is out of range.
    #[must_use]
    pub fn orientation(&self, frame: usize, body: usize) -> &UnitQuaternion<f64> {
        &self.orientations[self.slot(frame, body)]
    }

    /// All bodies' positions at `frame`, indexed by body.
    #[must_use]
    pub fn frame_positions(&self, frame: usize) -> &[Vector3<f64>] {
        let n = self.num_bodies();
        &self.positions[frame * n..(frame + 1) * n]
    }

    /// All bodies' orientations at `frame`, indexed by body.
    #[must_use]
    pub fn frame_orientations(&self, frame: usize) -> &[UnitQuaternion<f64>] {
        let n = self.num_bodies();
        &self.orientations[frame * n..(frame + 1) * n]
    }

    /// Seconds from the first to the last frame.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.num_frames.saturating_sub(1) as f64 / self.fps
    }

    fn slot(&self, frame: usize, body: usize) -> usize {
        let n = self.num_bodies();
        assert!(frame < self.num_frames && body < n, "frame {frame} body {body} out of range");
        frame * n + body
    }
}
