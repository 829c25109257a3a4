//! Stage 0, the floor: a source whose feet slide back on its floor as on a treadmill (an
//! in-place loop, a walk cycle exported without its root's travel) is put on a floor that
//! stays put, so that its stance feet stand still and the robot walks the loop forward
//! ([`crate::contact_phases::treadmill`]). The default solve only: `--gmr` follows the
//! source as GMR does. Its [`StageReport`] (`treadmill`) has `belt_mps` (the belt's speed,
//! m/s) and `heading_rad` (the direction the feet slid, about world z).

use std::collections::BTreeMap;

use fk::HumanMotion;

use super::{StageReport, StageValue};
use crate::contact_phases::{off_treadmill, treadmill, ContactOptions, FootPoints};

/// `human` off its treadmill, and what was done, where it is on one (its feet `feet`, its
/// contacts with `contact`).
pub(super) fn walk_off(
    human: &HumanMotion,
    feet: [FootPoints; 2],
    contact: &ContactOptions,
) -> Option<(HumanMotion, StageReport)> {
    let belt = treadmill(human, feet, 0, contact)?;
    let report = StageReport {
        stage: "treadmill",
        summary: format!(
            "the source's feet slide back {:.2} m/s on its floor (an in-place loop): walked \
             forward at that speed",
            belt.norm()
        ),
        values: BTreeMap::from([
            ("belt_mps", StageValue::Number(belt.norm())),
            ("heading_rad", StageValue::Number(belt.y.atan2(belt.x))),
        ]),
    };
    Some((off_treadmill(human, belt), report))
}
