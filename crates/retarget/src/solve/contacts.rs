//! Stage 2, the source's contacts: per human foot, its contact phases
//! ([`crate::contact_phases::detect`]), written to the output in both modes; the default
//! solve plants the robot's feet on them.

use super::prepare::Prepared;
use super::SolveMode;

impl Prepared<'_> {
    /// The source's contact phases, where its feet are found (by role, else by name).
    pub(super) fn detect_contacts(&mut self, human: &fk::HumanMotion) {
        let contact = match &self.options.mode {
            SolveMode::Plausible(p) => p.contact.clone(),
            SolveMode::Gmr => crate::contact_phases::ContactOptions::default(),
        };
        if let Some(points) =
            crate::contact_phases::human_foot_points(&human.body_names, &self.options.fk.roles)
        {
            self.contacts = Some(crate::contact_phases::detect(human, points, &contact));
        }
    }
}
