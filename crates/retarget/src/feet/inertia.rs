//! The sole of a foot without collision geometry: the equivalent inertia box of a body at or
//! below it ([`inertia_sole`]).

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: body ids come from the model.
#![allow(clippy::indexing_slicing)]

use mjcf::{Data, Model};
use nalgebra::{Isometry3, Translation3};

/// Shortest and longest plausible half length (m) of a foot's equivalent inertia box
/// ([`inertia_sole`]).
const INERTIA_SOLE_HALF_LENGTH: [f64; 2] = [0.03, 0.2];

/// A sole for a foot without collision geometry (the motion-capture models of the N1, the
/// H1, the H1-2, the Hi have bodies with masses and nothing else): the uniform box with the
/// mass and principal moments of a body at or below the foot ([`inertia_sole`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InertiaSole {
    pub body: usize,
    /// Half sizes along the principal axes (m).
    pub half: [f64; 3],
    /// The box's pose in `body`'s frame: centre of mass and principal axes.
    pub pose: Isometry3<f64>,
}

impl InertiaSole {
    /// The box's world pose with `data`'s kinematics.
    pub fn world(&self, data: &Data) -> Isometry3<f64> {
        let body = Translation3::from(data.xpos[self.body]);
        Isometry3::from_parts(body, data.xquat[self.body]) * self.pose
    }
}

/// The [`InertiaSole`] of the heaviest body at or below `sole_body` whose box has a foot's
/// length ([`INERTIA_SOLE_HALF_LENGTH`] for its longest half side). The N1's foot gives
/// 19 × 6.8 × 3.4 cm with its bottom 4.9 cm below the ankle axis; a real sole's mass sits
/// higher than its middle (motors, ankle), so the box's bottom is a little above the real
/// sole, which the floor shift of `super::plan` takes up. `None` when no body there has an
/// inertial.
pub(crate) fn inertia_sole(model: &Model, sole_body: usize) -> Option<InertiaSole> {
    (0..model.bodies.len())
        .filter(|&b| model.is_ancestor_or_self(sole_body, b))
        .filter_map(|b| {
            let inertial = model.bodies[b].inertial?;
            let half = inertial.equivalent_box()?;
            let [shortest, longest] = INERTIA_SOLE_HALF_LENGTH;
            let long = half.max();
            (long >= shortest && long <= longest).then_some((b, inertial, half))
        })
        .max_by(|a, b| a.1.mass.total_cmp(&b.1.mass))
        .map(|(body, inertial, half)| InertiaSole {
            body,
            half: [half.x, half.y, half.z],
            pose: Isometry3::from_parts(Translation3::from(inertial.pos), inertial.quat),
        })
}
