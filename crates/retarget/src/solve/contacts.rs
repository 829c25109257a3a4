//! Stage 2, the source's contacts: per human foot, its contact phases
//! ([`crate::contact_phases::detect`]), written to the output in both modes; the default
//! solve plants the robot's feet on them.

use super::prepare::Prepared;
use crate::contact_phases::FootPoints;

impl Prepared<'_> {
    /// The source's contact phases, where its feet were found (`feet`: by role, else by name).
    pub(super) fn detect_contacts(
        &mut self,
        human: &fk::HumanMotion,
        feet: Option<[FootPoints; 2]>,
    ) {
        if let Some(points) = feet {
            let contact = &self.pipeline.contacts;
            self.contacts = Some(crate::contact_phases::detect(human, points, contact));
        }
    }
}
