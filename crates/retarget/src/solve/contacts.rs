//! Stage 2, the source's contacts: per human foot, its contact phases
//! ([`crate::contact_phases::detect`]), written to the output in both modes; the default
//! solve plants the robot's feet on them.

use super::prepare::Prepared;

impl Prepared<'_> {
    /// The source's contact phases, where its feet are found (by role, else by name).
    pub(super) fn detect_contacts(&mut self, human: &fk::HumanMotion) {
        if let Some(points) =
            crate::contact_phases::human_foot_points(&human.body_names, &self.options.fk.roles)
        {
            let contact = &self.pipeline.contacts;
            self.contacts = Some(crate::contact_phases::detect(human, points, contact));
        }
    }
}
