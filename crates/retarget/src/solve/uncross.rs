//! Stage 7, uncrossing: crossed stances the robot could not stand in are planned again side
//! by side, and the frames whose targets that changed solved again.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// Indexing: frames and slots index the clip's own target buffer (`frames × slots`, built in
// `prepare`), body ids come from the model; the human motion's sizes are checked by
// `HumanMotion::validate` first.
#![allow(clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::ops::Range;

use super::prepare::{Prepared, Solved};
use super::{SolveMode, StageReport, StageValue};
use crate::ik::FrameDiagnostics;
use crate::Error;

/// A planted foot this far (m) from its target in a crossed stance is stuck there
/// ([`PlausibleOptions::uncross_stuck`](super::PlausibleOptions::uncross_stuck)). Where the T1 could not stand crossed, its planted
/// feet were up to 10 cm off.
pub const UNCROSS_STUCK: f64 = 0.03;

/// Time (s) solved again either side of the frames whose targets an uncrossing changed
/// (`Prepared::resolve_uncrossed`), and the lead-in before them (as a chunk's): 30 and 60
/// frames at 30 fps.
pub const RESOLVE_MARGIN_S: f64 = 1.0;
pub const RESOLVE_LEAD_IN_S: f64 = 2.0;

/// The two legs touch where geoms of theirs are closer than this (m)
/// ([`PlausibleOptions::uncross_stuck`](super::PlausibleOptions::uncross_stuck)).
pub const LEGS_TOUCH: f64 = 0.005;

/// A robot stuck in a crossed stance has its pelvis at least this far (m) below its target
/// ([`PlausibleOptions::uncross_stuck`](super::PlausibleOptions::uncross_stuck)): legs in each other's way are shorter. (The T1 on
/// the LAFAN1 walk: 6–19 cm. The H1, whose feet are off their targets in crossed stances
/// too, as elsewhere, for want of an ankle roll, stands 5–13 cm above its target there,
/// and uncrossing them widened stances its feet could not stand flat in: sliding 6.9 →
/// 7.7 %.)
pub const UNCROSS_SINK: f64 = 0.03;

impl<'a> Prepared<'a> {
    /// [`PlausibleOptions::uncross_stuck`](super::PlausibleOptions::uncross_stuck) on the whole clip's solved frames (`solved`): plans
    /// the feet again with the stuck crossed stances uncrossed ([`Prepared::uncross_stuck`])
    /// and solves again the frames whose targets that changed, with
    /// [`RESOLVE_MARGIN_S`] either side and a lead-in of [`RESOLVE_LEAD_IN_S`], as a chunk
    /// is solved ([`super::schedule`]); the rest of the clip is kept.
    pub(crate) fn resolve_uncrossed(&mut self, solved: &mut Solved) -> Result<(), Error> {
        let Some(changed) = self.uncross_stuck(&solved.qpos, &solved.frames) else {
            return Ok(());
        };
        let nq = self.model.nq;
        let n = solved.frames.len();
        let margin = self.frames_in(RESOLVE_MARGIN_S);
        let range = changed.start.saturating_sub(margin)..(changed.end + margin).min(n);
        let mut part = super::solve_range(self, range.clone(), self.frames_in(RESOLVE_LEAD_IN_S))?;
        if let Some(before) = range.start.checked_sub(1) {
            super::schedule::continue_quaternions(
                self.model,
                &solved.qpos[before * nq..range.start * nq],
                &mut part.qpos,
            );
        }
        solved.qpos.splice(range.start * nq..range.end * nq, part.qpos);
        solved.frames.splice(range.clone(), part.frames);
        if range.end < n {
            let (head, tail) = solved.qpos.split_at_mut(range.end * nq);
            super::schedule::continue_quaternions(self.model, &head[head.len() - nq..], tail);
        }
        Ok(())
    }

    /// [`PlausibleOptions::uncross_stuck`](super::PlausibleOptions::uncross_stuck): plans the feet again, with the crossed stance
    /// phases uncrossed in which the clip's solved frames (`qpos`, `frames`) have a planted
    /// foot [`UNCROSS_STUCK`] or further from its target, the legs touching and the pelvis
    /// sunk. The frames whose targets changed, if it planned again (its weights stay as they
    /// are).
    fn uncross_stuck(&mut self, qpos: &[f64], frames: &[FrameDiagnostics]) -> Option<Range<usize>> {
        let (SolveMode::Plausible(options), Some(unplanned), Some((feet, plan)), Some(contacts)) =
            (&self.options.mode, &self.unplanned, &self.plan, &self.contacts)
        else {
            return None;
        };
        let [Some(left), Some(right)] = feet else { return None };
        if plan.crossed.is_empty() {
            return None;
        }
        let model = self.model;
        // The feet's places among the solver's tracked bodies, whose errors `frames` hold.
        let tracked: Vec<usize> = [left, right]
            .iter()
            .filter_map(|foot| self.tracked.iter().position(|&(_, slot)| slot == foot.slot))
            .collect();
        // The geom pairs between the two legs: each leg is the subtree of the foot's highest
        // ancestor that the other foot does not hang from (as `feet::leg_length` walks up).
        let top = |foot: usize, other: usize| {
            if model.is_ancestor_or_self(foot, other) {
                return None;
            }
            let mut body = foot;
            while !model.is_ancestor_or_self(model.bodies[body].parent, other) {
                body = model.bodies[body].parent;
            }
            Some(body)
        };
        let (Some(top_left), Some(top_right)) =
            (top(left.body, right.body), top(right.body, left.body))
        else {
            return None;
        };
        let leg_of = |g: usize| {
            let body = model.geoms[g].body;
            if model.is_ancestor_or_self(top_left, body) {
                Some(0)
            } else if model.is_ancestor_or_self(top_right, body) {
                Some(1)
            } else {
                None
            }
        };
        let between: Vec<[usize; 2]> = model
            .self_collision_pairs()
            .pairs
            .into_iter()
            .filter(|&[a, b]| matches!((leg_of(a), leg_of(b)), (Some(x), Some(y)) if x != y))
            .collect();
        let root = self.root_body()?;
        let nq = model.nq;
        let mut data = mjcf::Data::new(model);
        // A frame is stuck where a planted foot is far from its target, the legs touch and the
        // pelvis sinks below its target.
        let mut stuck = |t: usize| {
            let far = frames.get(t).is_some_and(|f| {
                tracked.iter().any(|&k| f.pos_error.get(k).is_some_and(|e| *e >= UNCROSS_STUCK))
            });
            let Some(q) = qpos.get(t * nq..(t + 1) * nq) else { return false };
            if !far {
                return false;
            }
            model.kinematics(q, &mut data);
            let sunk = self.frame_targets(t)[self.root_target].pos.z - data.xpos[root].z;
            sunk >= UNCROSS_SINK
                && between.iter().any(|&[a, b]| {
                    mjcf::geom_distance(model, &data, a, b, LEGS_TOUCH)
                        .is_some_and(|p| p.distance < LEGS_TOUCH)
                })
        };
        let (phases, overlaps): (Vec<(usize, usize)>, Vec<Range<usize>>) = plan
            .crossed
            .iter()
            .filter(|c| c.frames.clone().any(&mut stuck))
            .map(|c| (c.phases, c.frames.clone()))
            .unzip();
        if phases.is_empty() {
            return None;
        }
        let feet = [Some(left.clone()), Some(right.clone())];
        let mut targets = unplanned.clone();
        let heading = self.heading();
        let plan = crate::feet::plan_uncrossing(
            &feet,
            contacts,
            &mut targets,
            self.slots,
            self.fps,
            &options.feet,
            &crate::feet::Uncrossing { uncross: &phases, heading: &heading },
        );
        let slots = self.slots.max(1);
        let differs = |t: &usize| {
            targets[t * slots..(t + 1) * slots] != self.targets[t * slots..(t + 1) * slots]
        };
        let frames_n = self.num_frames();
        let first = (0..frames_n).find(differs)?;
        let last = (0..frames_n).rev().find(differs)?;
        (self.targets, self.plan) = (targets, Some((feet, plan)));
        self.reports.push(report(&overlaps));
        Some(first..last + 1)
    }
}

/// What the uncrossing says of a clip whose crossed stances `overlaps` (frames, in order)
/// it planned again side by side: value `stretches`, their `(first, last)` frames.
fn report(overlaps: &[Range<usize>]) -> StageReport {
    let stretches: Vec<(usize, usize)> =
        overlaps.iter().map(|r| (r.start, r.end.saturating_sub(1))).collect();
    let list: Vec<String> = stretches.iter().map(|(a, b)| format!("{a}-{b}")).collect();
    let n = list.len();
    StageReport {
        stage: "uncross",
        summary: format!(
            "the robot could not stand in {n} crossed step{} of the human's (frames {}); \
             planned uncrossed and solved again",
            if n == 1 { "" } else { "s" },
            list.join(", ")
        ),
        values: BTreeMap::from([("stretches", StageValue::Ranges(stretches))]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's summary says what its values hold, as the main command prints it.
    #[test]
    fn the_report_says_its_stretches() {
        let one = report(&[Range { start: 392, end: 401 }]);
        assert_eq!(one.stage, "uncross");
        assert_eq!(one.values["stretches"], StageValue::Ranges(vec![(392, 400)]));
        assert_eq!(
            one.summary,
            "the robot could not stand in 1 crossed step of the human's (frames 392-400); \
             planned uncrossed and solved again"
        );
        let two = report(&[90..97, 392..401]);
        assert_eq!(two.values["stretches"], StageValue::Ranges(vec![(90, 96), (392, 400)]));
        assert!(two.summary.contains("in 2 crossed steps of the human's (frames 90-96, 392-400)"));
    }
}
