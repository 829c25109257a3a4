//! Stage 2, the source's contacts: per human foot, its contact phases
//! ([`crate::contact_phases::detect`]), written to the output in both modes; the default
//! solve plants the robot's feet on them.

use fk::HumanMotion;

use crate::contact_phases::{ContactOptions, FootPoints};
use crate::motion::FootContacts;

/// The source's contact phases, where its feet were found (`feet`: by role, else by name;
/// `None`: no contacts).
pub(super) fn contacts(
    human: &HumanMotion,
    feet: Option<[FootPoints; 2]>,
    options: &ContactOptions,
) -> Option<FootContacts> {
    feet.map(|points| crate::contact_phases::detect(human, points, options))
}
