//! The per-clip verdict: each quality measure against its cap, and GMR's own `auto_check`
//! criteria beside ours (definitions and the reasons for each cap in docs/metrics.md).

// Indexing: as in the parent module (the motion is checked against the model first, the
// per-frame series are as long as the motion).
#![allow(clippy::indexing_slicing)]

use super::checks::{Caps, Check, GmrCaps, Verdict};
use super::quality::QualityReport;
use super::stats::{ratio, scalar_joints};
use crate::motion::RobotMotion;

/// Per-frame series the verdict reads besides the report's summaries.
pub(super) struct Series<'a> {
    /// Foot heights above the ground (m), left and right.
    pub feet: [&'a [f64]; 2],
    /// Per frame, the deepest self-collision penetration (m, 0 without any).
    pub self_depth: &'a [f64],
    /// The report's contact height (m): a foot above it is off the floor.
    pub contact_height: f64,
}

/// The longest run of `true` in `mask`.
fn longest_run(mask: impl Iterator<Item = bool>) -> usize {
    let (mut best, mut run) = (0, 0);
    for m in mask {
        run = if m { run + 1 } else { 0 };
        best = best.max(run);
    }
    best
}

fn check(name: &'static str, ok: bool, value: f64, cap: f64, unit: &'static str) -> Check {
    Check { name, ok: Some(ok), value, cap, unit, detail: String::new() }
}

impl Check {
    /// The check with what was measured, in words.
    fn because(self, detail: impl Into<String>) -> Check {
        Check { detail: detail.into(), ..self }
    }
}

fn unmeasured(name: &'static str, why: &str) -> Check {
    Check { name, ok: None, value: 0.0, cap: 0.0, unit: "", detail: why.to_owned() }
}

/// Whether joint `j` has no published speed limit (the report's `joint_speed` skips it).
fn unlimited(model: &mjcf::Model, j: usize) -> bool {
    model.joints[j].velocity_limit.is_none_or(|l| l <= 0.0)
}

/// Per frame transition, the largest `|Δq|` of the hinge and slide joints, of those without
/// a published speed limit when `only_unlimited`.
fn joint_steps(motion: &RobotMotion, model: &mjcf::Model, only_unlimited: bool) -> Vec<f64> {
    let adr: Vec<usize> = scalar_joints(model)
        .filter(|&(j, _)| !only_unlimited || unlimited(model, j))
        .map(|(_, a)| a)
        .collect();
    (1..motion.num_frames())
        .map(|t| {
            let (a, b) = (motion.frame(t - 1), motion.frame(t));
            adr.iter().map(|&i| (b[i] - a[i]).abs()).fold(0.0, f64::max)
        })
        .collect()
}

/// Per frame, the largest excess of a hinge or slide joint past its range (rad or m, 0
/// inside).
fn limit_excess(motion: &RobotMotion, model: &mjcf::Model) -> Vec<f64> {
    let ranges: Vec<(usize, [f64; 2])> =
        scalar_joints(model).filter_map(|(j, a)| model.joints[j].range.map(|r| (a, r))).collect();
    (0..motion.num_frames())
        .map(|t| {
            let q = motion.frame(t);
            ranges.iter().map(|&(a, [lo, hi])| (lo - q[a]).max(q[a] - hi)).fold(0.0, f64::max)
        })
        .collect()
}

/// The verdict of `rep` (the report of `motion` on `model`) under `caps`.
pub(super) fn verdict(
    rep: &QualityReport,
    motion: &RobotMotion,
    model: &mjcf::Model,
    series: &Series<'_>,
    caps: &Caps,
) -> Verdict {
    let fps = motion.fps;
    let frames = motion.num_frames();
    let steps = joint_steps(motion, model, false);
    let unlimited_steps = joint_steps(motion, model, true);
    let any_unlimited = scalar_joints(model).any(|(j, _)| unlimited(model, j));
    let excess = limit_excess(motion, model);
    let mut checks = vec![
        {
            let g = &rep.ground_penetration;
            check("penetration", g.frames == 0, g.frames as f64, 0.0, "frames").because(format!(
                "frames with a collision geom deeper than {:.1} cm below the floor (deepest {:.2} cm)",
                g.tolerance_cm, g.max_depth_cm
            ))
        },
        {
            let s = &rep.self_collision;
            check("self_collision", s.frames_deep == 0, s.frames_deep as f64, 0.0, "frames").because(format!(
                "frames with two of the robot's geoms deeper than {:.1} cm into each other (deepest {:.2} cm)",
                s.deep_cm, s.max_depth_cm
            ))
        },
        {
            let worst = rep.feet.iter().map(|f| f.floor_skating_share).fold(0.0, f64::max);
            check(
                "floor_skating",
                worst <= caps.floor_skating_share,
                worst,
                caps.floor_skating_share,
                "share",
            ).because("the worse foot's share of floor frames whose contact point slides")
        },
        match &rep.stance {
            Some(s) => {
                check(
                    "stance",
                    s.sole_in_band_share >= caps.sole_in_band_share,
                    s.sole_in_band_share,
                    caps.sole_in_band_share,
                    "share (at least)",
                ).because("share of source-contact samples with the sole in its band")
            }
            None => unmeasured("stance", "no source foot contacts in the motion"),
        },
        floating(rep, series, fps, caps),
        {
            let v = rep.joint_limits.violations;
            check("joint_limits", v == 0, v as f64, 0.0, "frames × joints").because(format!(
                "joint samples past their range (largest excess {:.4})",
                rep.joint_limits.max_excess
            ))
        },
        if any_unlimited {
            let fastest = unlimited_steps.iter().copied().fold(0.0, f64::max) * fps;
            check(
                "joint_jumps",
                fastest <= caps.joint_jump_speed,
                fastest,
                caps.joint_jump_speed,
                "rad/s",
            ).because("the fastest joint without a published speed limit between two consecutive frames")
        } else {
            unmeasured("joint_jumps", "every joint has a published speed limit (see joint_speed)")
        },
        match &rep.joint_speed {
            Some(s) => {
                check(
                    "joint_speed",
                    s.violations == 0,
                    s.violations as f64,
                    0.0,
                    "frames × joints",
                ).because(format!(
                    "joint samples over their published speed limit (worst {:.2}× on {})",
                    s.worst_ratio, s.worst_joint
                ))
            }
            None => unmeasured("joint_speed", "no joint has a published speed limit"),
        },
        root_acceleration(rep, caps),
        match &rep.dynamics {
            Some(d) => {
                check(
                    "dynamics",
                    d.share_over <= caps.dynamics_share,
                    d.share_over,
                    caps.dynamics_share,
                    "share",
                ).because(format!(
                    "share of frames needing more than {} m·g of wrench the feet cannot supply (accelerations over {:.3} s)",
                    d.threshold_mg, d.window_s
                ))
            }
            None => unmeasured(
                "dynamics",
                rep.dynamics_unavailable.as_deref().unwrap_or("not available"),
            ),
        },
    ];
    checks.extend(gmr_checks(series, &steps, &excess, fps, frames, &caps.gmr));
    let flags: Vec<Check> = checks.iter().filter(|c| c.ok == Some(false)).cloned().collect();
    Verdict { ok: flags.is_empty(), flags, checks }
}

fn floating(rep: &QualityReport, series: &Series<'_>, fps: f64, caps: &Caps) -> Check {
    let [l, r] = series.feet;
    let h = series.contact_height;
    let flight = longest_run(l.iter().zip(r).map(|(a, b)| a.min(*b) >= h)) as f64 / fps;
    let stance = rep.stance.as_ref().map_or(0.0, |s| s.floating_share);
    let ok = flight <= caps.flight_s && stance <= caps.stance_floating_share;
    // The value is the criterion that broke (or the flight when none did).
    let (value, cap, unit) = if stance > caps.stance_floating_share {
        (stance, caps.stance_floating_share, "share")
    } else {
        (flight, caps.flight_s, "s")
    };
    check("floating", ok, value, cap, unit).because(match &rep.stance {
        Some(_) => format!(
            "longest time with both feet above {:.0} cm: {flight:.2} s; source-contact samples floating: {:.1} %",
            h * 100.0,
            stance * 100.0
        ),
        None => format!(
            "longest time with both feet above {:.0} cm: {flight:.2} s (no source contacts: floating in stance not measured)",
            h * 100.0
        ),
    })
}

fn root_acceleration(rep: &QualityReport, caps: &Caps) -> Check {
    let a = &rep.root_acceleration.averaged;
    match &a.target {
        Some(human) => {
            let ratio = a.motion.mean_mps2 / human.mean_mps2.max(1e-12);
            let ok = ratio <= caps.root_acceleration_ratio
                || a.motion.mean_mps2 < caps.root_acceleration_floor;
            let detail = format!(
                "mean root acceleration {:.2} m/s² against the scaled human's {:.2} (over {:.3} s)",
                a.motion.mean_mps2, human.mean_mps2, a.window_s
            );
            check("root_acceleration", ok, ratio, caps.root_acceleration_ratio, "× human")
                .because(detail)
        }
        None => {
            let share = a.motion.share_over;
            check(
                "root_acceleration",
                share <= caps.root_over_2g_share,
                share,
                caps.root_over_2g_share,
                "share",
            )
            .because(format!(
                "share of frames with the root accelerating over 2 g (over {:.3} s; no targets, so not against the human)",
                a.window_s
            ))
        }
    }
}

/// GMR's `auto_check.py`, on our measures: foot heights are the soles' lowest points (GMR:
/// the foot body's origin less 3 cm), self-collision is over the report's pairs (GMR: every
/// contact MuJoCo finds between robot bodies).
fn gmr_checks(
    series: &Series<'_>,
    steps: &[f64],
    excess: &[f64],
    fps: f64,
    frames: usize,
    g: &GmrCaps,
) -> Vec<Check> {
    let [l, r] = series.feet;
    let off = longest_run(l.iter().zip(r).map(|(a, b)| a.min(*b) > g.floating_height));
    let (off_s, off_share) = (off as f64 / fps, ratio(off, frames));
    let floating = check(
        "gmr_floating",
        off_s < g.floating_s && off_share < g.floating_run_share,
        off_s,
        g.floating_s,
        "s",
    ).because(format!(
        "longest run with both feet above {:.0} cm: {off_s:.2} s, {:.1} % of the clip (GMR: ≥ {} s or ≥ {:.0} %)",
        g.floating_height * 100.0,
        off_share * 100.0,
        g.floating_s,
        g.floating_run_share * 100.0
    ));
    let past = ratio(excess.iter().filter(|e| **e > g.limit_excess).count(), frames);
    let limits = check("gmr_joint_limits", past < g.limit_share, past, g.limit_share, "share")
        .because(format!(
            "share of frames with a joint past its range by more than {} rad",
            g.limit_excess
        ));
    let jumps = ratio(steps.iter().filter(|s| **s > g.jump).count(), steps.len());
    let largest = steps.iter().copied().fold(0.0, f64::max);
    let (value, cap, unit) = if largest >= g.severe_jump {
        (largest, g.severe_jump, "rad")
    } else {
        (jumps, g.jump_share, "share")
    };
    let detail = format!(
        "{:.1} % of transitions with a joint moving more than {} rad, largest {largest:.3} rad (GMR: ≥ {:.0} % or ≥ {} rad once)",
        jumps * 100.0,
        g.jump,
        g.jump_share * 100.0,
        g.severe_jump
    );
    let ok = jumps < g.jump_share && largest < g.severe_jump;
    let jump = check("gmr_joint_jumps", ok, value, cap, unit).because(detail);
    let deep = |d: &f64| *d >= g.collision_depth;
    let share = ratio(series.self_depth.iter().filter(|d| deep(d)).count(), frames);
    let run = longest_run(series.self_depth.iter().map(deep)) as f64 / fps;
    let collision = check(
        "gmr_self_collision",
        share < g.collision_share && run < g.collision_s,
        share,
        g.collision_share,
        "share",
    ).because(format!(
        "{:.1} % of frames with two geoms {:.0} mm or more into each other, longest run {run:.2} s (GMR: ≥ {:.0} % or ≥ {} s)",
        share * 100.0,
        g.collision_depth * 1000.0,
        g.collision_share * 100.0,
        g.collision_s
    ));
    vec![floating, limits, jump, collision]
}
