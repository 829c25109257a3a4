//! Rule 5 of the recogniser: a limb chain split at its knee or elbow, and the test that
//! tells a wheel from an unlimited hinge.

// Indexing: body ids come from the model and the chains found in it.
#![allow(clippy::indexing_slicing)]

use super::*;

impl Recogniser<'_> {
    /// Splits a limb chain at its knee or elbow (rule 5).
    pub(super) fn limb(
        &self,
        chain: Vec<usize>,
        what: &str,
        middle_name: &str,
    ) -> Result<Limb, Error> {
        let end = *chain.last().unwrap_or(&0);
        let all = self.hinges(&chain);
        let Some(first) = all.first().copied() else {
            return Err(self
                .not_humanoid(format!("the {what} ending in `{}` has no joint", self.name(end))));
        };
        let root = first.anchor;
        let end_point = self.end_point(&chain, root);
        let span = (end_point - root).norm();
        let middle = all.iter().enumerate().skip(1).find(|(k, h)| {
            // The bone leading to the hinge: from the last anchor before it that is elsewhere.
            let from = all[..*k]
                .iter()
                .rev()
                .map(|p| p.anchor)
                .find(|a| (h.anchor - a).norm() > 0.01 * span)
                .unwrap_or(root);
            // Joints sit beside the bone line on some robots (Talos' first shoulder joint is
            // inboard, HighTorque Hi's elbow outboard): across either line will do.
            let across = |a: Vector3<f64>| {
                let bone = (h.anchor - a).try_normalize(1e-12).unwrap_or_else(Vector3::zeros);
                h.axis.dot(&bone).abs() < PERPENDICULAR_COS
            };
            (h.anchor - root).norm() >= MIDDLE_AT * span && (across(from) || across(root))
        });
        let Some((k, middle)) = middle else {
            return Err(self.not_humanoid(format!(
                "the {what} ending in `{}` has no {middle_name}: no hinge across the limb \
                 beyond {:.0} % of its length",
                self.name(end),
                MIDDLE_AT * 100.0
            )));
        };
        let mut distal: Vec<Hinge> = Vec::new();
        for h in &all[k + 1..] {
            // A body with several jointed branches (fingers) ends the chain after it.
            if distal.last().is_some_and(|d| d.body != h.body && self.jointed_branches(d.body) > 1)
            {
                break;
            }
            distal.push(*h);
        }
        let end_body = (distal.is_empty() && end != middle.body).then_some(end);
        Ok(Limb {
            chain,
            proximal: all[..k].to_vec(),
            middle: *middle,
            distal,
            end_body,
            end_point,
        })
    }

    /// Rule 2's wheel: an unlimited hinge whose axis is horizontal and across the direction
    /// of travel (within 30° of the hips' left-right axis), carrying a round geom (a sphere,
    /// or a cylinder, capsule or ellipsoid turning about its own axis) whose lowest point is
    /// on the floor (within 2 % of the robot's height of the lowest point). An unlimited
    /// ankle roll (ROBOTIS OP3's) is a joint without limits, not a wheel.
    pub(super) fn is_wheel(&self, hinge: &Hinge, across: Vector3<f64>) -> bool {
        let floor = self.lowest.iter().copied().fold(f64::INFINITY, f64::min);
        if hinge.range.is_some() || hinge.axis.dot(&across).abs() < WHEEL_AXIS_COS {
            return false;
        }
        let bodies = self.model.subtree(hinge.body);
        self.model.geoms.iter().enumerate().any(|(g, geom)| {
            let round = match geom.kind {
                mjcf::GeomType::Sphere => true,
                mjcf::GeomType::Cylinder | mjcf::GeomType::Capsule | mjcf::GeomType::Ellipsoid => {
                    let own_axis = self.data.geom_xmat[g].column(2).into_owned();
                    own_axis.dot(&hinge.axis).abs() > WHEEL_AXIS_COS
                }
                _ => false,
            };
            round
                && bodies.contains(&geom.body)
                && mjcf::geom_lowest_point(self.model, &self.data, g)
                    .is_some_and(|p| p.z - floor <= 0.02 * self.height)
        })
    }
}
