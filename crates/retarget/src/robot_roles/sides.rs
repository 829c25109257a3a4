//! Rules 6 and 7 of the recogniser: which way the robot faces at `qpos0`, which limbs are
//! its left ones (geometry first, names to break a tie), and the sole under each foot.

// Indexing: body ids come from the model and the limbs found in it.
#![allow(clippy::indexing_slicing)]

use super::*;

impl Recogniser<'_> {
    /// Forward at `qpos0` (rule 6): ⟂ the hips' axis, sign from the knees and the feet.
    pub(super) fn facing(
        &self,
        legs: &[Limb],
        across: Vector3<f64>,
    ) -> Option<(Vector3<f64>, String)> {
        let ahead = across.cross(&Vector3::z());
        let (mut knees, mut toes) = (0.0, 0.0);
        for leg in legs {
            let knee = leg.middle;
            if let Some([lo, hi]) = knee.range {
                let flex = if hi.abs() >= lo.abs() { 1.0 } else { -1.0 };
                let ankle = leg.distal.first().map_or(leg.end_point, |h| h.anchor);
                let moves = knee.axis.cross(&(ankle - knee.anchor)) * flex;
                knees -= moves.dot(&ahead).signum() * f64::from(u8::from(moves.norm() > 1e-9));
            }
            let ankle = joint_centre(&leg.distal);
            let foot_root = leg.distal.first().map_or(leg.middle.body, |h| h.body);
            let mut reach = Vector3::zeros();
            for b in self.model.subtree(foot_root) {
                reach += self.data.xpos[b] - ankle;
            }
            for (g, geom) in self.model.geoms.iter().enumerate() {
                if self.model.is_ancestor_or_self(foot_root, geom.body) && geom.kind.is_primitive()
                {
                    reach += self.data.geom_xpos[g] - ankle;
                }
            }
            let r = reach.dot(&ahead);
            if r.abs() > 1e-6 {
                toes += r.signum();
            }
        }
        // A knee's flexion is unambiguous; the feet's shape only breaks its ties.
        let vote = 2.0 * knees + toes;
        if vote == 0.0 {
            return None;
        }
        let forward = ahead * vote.signum();
        let how = format!(
            "({:+.2}, {:+.2}, 0): knees bending backward {:+}, feet reaching forward {:+} (votes \
             of the two legs)",
            forward.x,
            forward.y,
            knees * vote.signum(),
            toes * vote.signum()
        );
        Some((forward, how))
    }

    /// Whether the first leg and arm of the lists are the left ones, and why (rule 6).
    pub(super) fn sides(
        &self,
        legs: &[Limb],
        arms: &[Limb],
        forward: Vector3<f64>,
    ) -> (bool, String) {
        let left = Vector3::z().cross(&forward);
        let geometry_legs = (legs[0].root() - legs[1].root()).dot(&left) > 0.0;
        let geometry_arms = (arms[0].root() - arms[1].root()).dot(&left) > 0.0;
        match self.named_left_first(legs, arms) {
            Some(l) => {
                let agree = if l == geometry_legs && l == geometry_arms {
                    "geometry agrees"
                } else {
                    "geometry disagrees: names win"
                };
                (l, format!("names ({agree})"))
            }
            _ if geometry_legs == geometry_arms => {
                (geometry_legs, "geometry: left = up × forward".to_owned())
            }
            _ => (geometry_legs, "geometry of the legs (the arms cross over)".to_owned()),
        }
    }

    /// Whether the first leg and arm are the left ones by their names: `Some` when both legs'
    /// and both arms' names state opposite sides, consistently.
    pub(super) fn named_left_first(&self, legs: &[Limb], arms: &[Limb]) -> Option<bool> {
        let named = |limb: &Limb| -> i32 {
            limb.chain.iter().map(|&b| robot_names::side_of(&self.name(b))).sum::<i32>().signum()
        };
        let by_names = |a: &Limb, b: &Limb| match (named(a), named(b)) {
            (1, -1) => Some(true),
            (-1, 1) => Some(false),
            _ => None,
        };
        match (by_names(&legs[0], &legs[1]), by_names(&arms[0], &arms[1])) {
            (Some(l), Some(a)) if l == a => Some(l),
            _ => None,
        }
    }

    /// The sole under a foot (rule 7).
    pub(super) fn sole(&self, roles: &BTreeMap<Role, RobotRole>, leg: &Limb, side: Side) -> Sole {
        let body = roles.get(&Role::of(Part::Foot, side)).map_or(leg.middle.body, |r| r.body);
        let bodies = self.model.subtree(body);
        let mut geoms: Vec<(usize, Vector3<f64>)> = self
            .model
            .geoms
            .iter()
            .enumerate()
            .filter(|(_, g)| {
                bodies.contains(&g.body)
                    && g.kind.is_primitive()
                    && (g.contype != 0 || g.conaffinity != 0)
            })
            .filter_map(|(i, _)| Some((i, mjcf::geom_lowest_point(self.model, &self.data, i)?)))
            .collect();
        let named = if side == Side::Left { "left_sole" } else { "right_sole" };
        geoms.sort_by(|a, b| {
            let n = |g: usize| self.model.geoms[g].name != named;
            n(a.0).cmp(&n(b.0)).then(a.1.z.total_cmp(&b.1.z))
        });
        let lowest = geoms
            .iter()
            .map(|(_, p)| *p)
            .min_by(|a, b| a.z.total_cmp(&b.z))
            .or_else(|| {
                bodies.iter().map(|&b| self.data.xpos[b]).min_by(|a, b| a.z.total_cmp(&b.z))
            })
            .unwrap_or_else(Vector3::zeros);
        Sole { body, geoms: geoms.into_iter().map(|(g, _)| g).collect(), lowest }
    }
}
