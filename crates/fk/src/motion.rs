//! [`HumanMotion`]: world poses of every body for every frame, in one flat array each.

use nalgebra::{UnitQuaternion, Vector3};

use crate::limits::{MAX_DISTANCE, MAX_STEP};
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
    // A caller's out-of-range index is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn position(&self, frame: usize, body: usize) -> &Vector3<f64> {
        &self.positions[self.slot(frame, body)]
    }

    /// World orientation of `body` at `frame`. Panics if either is out of range.
    #[must_use]
    // A caller's out-of-range index is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn orientation(&self, frame: usize, body: usize) -> &UnitQuaternion<f64> {
        &self.orientations[self.slot(frame, body)]
    }

    /// All bodies' positions at `frame`, indexed by body. Panics if `frame` is out of range.
    #[must_use]
    // A caller's out-of-range frame is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn frame_positions(&self, frame: usize) -> &[Vector3<f64>] {
        let n = self.num_bodies();
        &self.positions[frame * n..(frame + 1) * n]
    }

    /// All bodies' orientations at `frame`, indexed by body. Panics if `frame` is out of range.
    #[must_use]
    // A caller's out-of-range frame is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn frame_orientations(&self, frame: usize) -> &[UnitQuaternion<f64>] {
        let n = self.num_bodies();
        &self.orientations[frame * n..(frame + 1) * n]
    }

    /// Seconds from the first to the last frame.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.num_frames.saturating_sub(1) as f64 / self.fps
    }

    /// Checks that the motion is usable: it has frames, `positions` and `orientations` hold
    /// `num_frames × num_bodies` entries, every position and orientation is finite, no body
    /// is farther than [`MAX_DISTANCE`] from the origin, and none moves more than
    /// [`MAX_STEP`] between consecutive frames. Such values are not motion capture but a
    /// corrupt file or a wrong unit; the error names the first frame and body at fault.
    pub fn validate(&self) -> Result<(), Error> {
        let nb = self.num_bodies();
        if self.num_frames == 0 {
            return Err(Error::NoFrames);
        }
        let expected = self.num_frames.checked_mul(nb);
        if expected != Some(self.positions.len()) || expected != Some(self.orientations.len()) {
            return Err(Error::BodyShape {
                positions: self.positions.len(),
                orientations: self.orientations.len(),
                num_frames: self.num_frames,
                num_bodies: nb,
            });
        }
        let body = |k: usize| self.body_names.get(k).cloned().unwrap_or_default();
        let frames =
            self.positions.chunks_exact(nb.max(1)).zip(self.orientations.chunks_exact(nb.max(1)));
        // Squared norms on the common path (a finite square within the bound implies finite
        // coordinates); the exact figures are computed only for the error message.
        let (max_d2, max_s2) = (MAX_DISTANCE * MAX_DISTANCE, MAX_STEP * MAX_STEP);
        let mut previous: Option<&[Vector3<f64>]> = None;
        for (frame, (positions, orientations)) in frames.enumerate() {
            for (k, (p, q)) in positions.iter().zip(orientations).enumerate() {
                let before = previous.and_then(|before| before.get(k));
                let step2 = before.map_or(0.0, |b| (p - b).norm_squared());
                let fine = p.norm_squared() <= max_d2
                    && step2 <= max_s2
                    && q.coords.norm_squared().is_finite();
                if !fine {
                    return Err(pose_error(frame, body(k), p, q, before));
                }
            }
            previous = Some(positions);
        }
        Ok(())
    }

    fn slot(&self, frame: usize, body: usize) -> usize {
        let n = self.num_bodies();
        assert!(frame < self.num_frames && body < n, "frame {frame} body {body} out of range");
        frame * n + body
    }
}

/// Why a pose failed [`HumanMotion::validate`]'s quick test.
fn pose_error(
    frame: usize,
    body: String,
    p: &Vector3<f64>,
    q: &UnitQuaternion<f64>,
    before: Option<&Vector3<f64>>,
) -> Error {
    if !(p.iter().all(|v| v.is_finite()) && q.coords.iter().all(|v| v.is_finite())) {
        return Error::NonFinitePose { frame, body };
    }
    let distance = robust_norm(p);
    if distance > MAX_DISTANCE {
        return Error::AbsurdPosition { frame, body, distance };
    }
    let step = before.map_or(0.0, |b| robust_norm(&(p - b)));
    Error::AbsurdStep { frame, body, step }
}

/// `‖p‖` without overflow for huge finite coordinates (1e300² is infinite).
pub(crate) fn robust_norm(p: &Vector3<f64>) -> f64 {
    let m = p.amax();
    if m > 0.0 {
        m * (p / m).norm()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motion(frames: usize) -> HumanMotion {
        let positions = (0..frames)
            .flat_map(|f| [Vector3::new(0.01 * f as f64, 0.0, 1.0), Vector3::new(0.0, 0.1, 0.0)])
            .collect();
        HumanMotion {
            fps: 30.0,
            body_names: vec!["Hips".to_owned(), "LeftFoot".to_owned()],
            num_frames: frames,
            positions,
            orientations: vec![UnitQuaternion::identity(); 2 * frames],
        }
    }

    #[test]
    fn validation_names_the_frame_and_body_at_fault() {
        assert_eq!(motion(5).validate(), Ok(()));
        assert_eq!(motion(0).validate(), Err(Error::NoFrames));
        let mut m = motion(5);
        m.positions.pop();
        assert!(matches!(m.validate(), Err(Error::BodyShape { positions: 9, .. })));

        let mut m = motion(5);
        m.positions[2 * 3].x = 1e300;
        let err = m.validate().unwrap_err();
        assert!(
            matches!(&err, Error::AbsurdPosition { frame: 3, body, .. } if body == "Hips"),
            "{err:?}"
        );
        assert!(err.to_string().starts_with("frame 3: body `Hips` is 1.000e300 m"), "{err}");

        // Kilometres in one frame, still within the distance bound.
        let mut m = motion(5);
        m.positions[2 * 4 + 1].y = 2000.0;
        let err = m.validate().unwrap_err();
        assert!(
            matches!(&err, Error::AbsurdStep { frame: 4, body, step } if body == "LeftFoot" && *step > 1999.0),
            "{err:?}"
        );
        // Just inside the step bound: fine.
        let mut m = motion(2);
        m.positions[3].y = 0.1 + MAX_STEP * 0.999;
        assert_eq!(m.validate(), Ok(()));

        let mut m = motion(5);
        m.orientations[1] =
            UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0));
        assert_eq!(
            m.validate(),
            Err(Error::NonFinitePose { frame: 0, body: "LeftFoot".to_owned() })
        );
    }
}
