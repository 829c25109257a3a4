//! The default (physically plausible) solve against GMR's on the LAFAN1 takes (G1, with the
//! published joint speed limits): the issue-11 metrics from [`retarget::report::report`].
//! Measured on whole takes by `scripts/quality-table` (README); here on a slice of each so
//! that the test stays short.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use retarget::internals::retarget_motion;
use retarget::internals::JointSpeedLimits;
use retarget::report::{report, QualityReport, ReportOptions};
use retarget::{IkConfig, RetargetOptions};

fn g1() -> mjcf::Model {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut model = mjcf::Model::from_file(&root.join("robots/unitree_g1/unitree_g1.xml")).unwrap();
    let path = root.join("robots/unitree_g1/joint_speed_limits.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let origin = path.display().to_string();
    JointSpeedLimits::from_json_str(&text, &origin).unwrap().apply(&mut model, &origin).unwrap();
    model
}

/// The worse foot's share of floor frames whose contact point slides (the corpus gate's
/// `floor_skating`).
fn worst_floor_skating(report: &QualityReport) -> f64 {
    report.feet.iter().map(|f| f.floor_skating_share).fold(0.0, f64::max)
}

/// Frames `range` of `full`.
fn slice(full: &fk::HumanMotion, range: std::ops::Range<usize>) -> fk::HumanMotion {
    let nb = full.num_bodies();
    fk::HumanMotion {
        num_frames: range.len(),
        positions: full.positions[range.start * nb..range.end * nb].to_vec(),
        orientations: full.orientations[range.start * nb..range.end * nb].to_vec(),
        ..full.clone()
    }
}

/// The first `n` frames of `bvh`.
fn first_frames(mut bvh: bvh::Bvh, n: usize) -> bvh::Bvh {
    bvh.motion.truncate(n);
    bvh
}

/// A shared BVH clip (`file` under the shared data; its first `frames` when given) retargeted
/// onto the shipped `robot` as the CLI does (default solve, its config choice; `height`, else
/// the estimated one), and its report; `None` without the shared data.
fn shared_bvh_report(
    file: &str,
    frames: Option<usize>,
    robot: &str,
    height: Option<f64>,
) -> Option<QualityReport> {
    let path = shared::shared_file(file)?;
    let bvh = bvh::from_path(&path).unwrap();
    let bvh = match frames {
        Some(n) => first_frames(bvh, n),
        None => bvh,
    };
    let r = retarget::Retargeter::new(robot).unwrap().with_human_height(height);
    let (motion, _) = r.retarget_bvh(&bvh).unwrap();
    Some(report(&motion, r.model(), &ReportOptions::default()).unwrap())
}

/// The G1, its tuned config, the shared LAFAN1 jumps take's human motion and its subject
/// height; `None` without the shared data.
fn g1_jumps() -> Option<(mjcf::Model, IkConfig, fk::HumanMotion, f64)> {
    let path = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test2.bvh")?;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let config = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let (full, report) =
        fk::human_motion(&bvh::from_path(&path).unwrap(), &fk::FkOptions::default()).unwrap();
    Some((g1(), config, full, report.height))
}

/// Frames `range` of a shared LAFAN1 take, retargeted onto the G1 with `base`, and its report.
fn solve(
    take: &str,
    range: std::ops::Range<usize>,
    base: RetargetOptions,
) -> Option<QualityReport> {
    let path = shared::shared_file(&format!("data/bvh/{take}"))?;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = g1();
    let config = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let bvh = bvh::from_path(&path).unwrap();
    let (full, human_report) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    let human = slice(&full, range);
    let options = {
        let mut o = base;
        o.human_height = Some(human_report.height);
        o
    };
    let (motion, _) = retarget_motion(&human, &model, &config, &options).unwrap();
    assert!(motion.contacts.is_some(), "both solves carry the source's contacts");
    Some(report(&motion, &model, &ReportOptions::default()).unwrap())
}

fn mean_jitter(r: &QualityReport) -> f64 {
    r.joints.iter().map(|j| j.jitter).sum::<f64>() / r.joints.len() as f64
}

fn mean_pos_error_cm(r: &QualityReport) -> f64 {
    let tracking = r.tracking.as_ref().unwrap();
    let pos: Vec<f64> = tracking.iter().filter_map(|b| b.pos_m.map(|p| p.mean)).collect();
    100.0 * pos.iter().sum::<f64>() / pos.len() as f64
}

fn mean_rot_error_deg(r: &QualityReport) -> f64 {
    let tracking = r.tracking.as_ref().unwrap();
    let rot: Vec<f64> = tracking.iter().map(|b| b.rot_rad.mean).collect();
    rot.iter().sum::<f64>().to_degrees() / rot.len() as f64
}

fn check(take: &str, range: std::ops::Range<usize>) {
    let Some(gmr) = solve(take, range.clone(), RetargetOptions::gmr()) else { return };
    let def = solve(take, range, RetargetOptions::default()).unwrap();
    let (g, d) = (&gmr, &def);
    eprintln!(
        "{take}: penetration {:.3}/{:.3}, self-collision frames {}/{}, skate {:.4}/{:.4}, \
         sole in band {:.3}/{:.3}, speed over {}/{}, jitter {:.2}/{:.2}, pos err {:.2}/{:.2} cm, \
         rot err {:.2}/{:.2}°",
        g.ground_penetration.duration,
        d.ground_penetration.duration,
        g.self_collision.frames_deep,
        d.self_collision.frames_deep,
        g.skating.as_ref().unwrap().duration,
        d.skating.as_ref().unwrap().duration,
        g.stance.as_ref().unwrap().sole_in_band_share,
        d.stance.as_ref().unwrap().sole_in_band_share,
        g.joint_speed.as_ref().unwrap().violations,
        d.joint_speed.as_ref().unwrap().violations,
        mean_jitter(g),
        mean_jitter(d),
        mean_pos_error_cm(g),
        mean_pos_error_cm(d),
        mean_rot_error_deg(g),
        mean_rot_error_deg(d),
    );
    // Nothing through the floor, nothing through itself, within the speed limits.
    assert_eq!(d.ground_penetration.frames, 0, "{:?}", d.ground_penetration);
    assert_eq!(d.self_collision.frames_deep, 0, "{:?}", d.self_collision);
    assert_eq!(d.joint_speed.as_ref().unwrap().violations, 0, "{:?}", d.joint_speed);
    assert_eq!(d.joint_limits.violations, 0);
    // Planted feet: the sole on the floor in stance, (almost) no skating.
    let stance = d.stance.as_ref().unwrap();
    assert!(stance.sole_in_band_share > 0.98, "{stance:?}");
    let skating = d.skating.as_ref().unwrap();
    assert!(skating.duration < 0.01, "{skating:?}");
    assert!(skating.duration < g.skating.as_ref().unwrap().duration / 5.0);
    // No extra jitter; tracking as good as GMR's to within 10 %.
    assert!(mean_jitter(d) <= mean_jitter(g), "{} > {}", mean_jitter(d), mean_jitter(g));
    assert!(mean_pos_error_cm(d) < 1.1 * mean_pos_error_cm(g));
    let (rot_g, rot_d) = (mean_rot_error_deg(g), mean_rot_error_deg(d));
    assert!(rot_d < 1.1 * rot_g, "rotation error {rot_d:.2}° against GMR's {rot_g:.2}°");
}

#[test]
fn walk_is_planted_collision_free_and_within_the_speed_limits() {
    check("lafan1_take_via_bvhtools_test.bvh", 0..1800);
}

#[test]
fn jumps_are_planted_collision_free_and_within_the_speed_limits() {
    // The jumps take's first minute: GMR reaches 1.1× the G1's speed limits and 6 cm into the
    // floor over the whole take.
    check("lafan1_take_via_bvhtools_test2.bvh", 0..1800);
}

/// The default solve reweighs the trunk's and legs' tasks by how far the robot's pelvis
/// stands from its target with the config's weights: GMR's tuned G1 config holds the pelvis
/// under where the G1's legs put it (reweighed), the config derived from the skeleton's own
/// proportions does not (kept).
#[test]
fn only_targets_that_disagree_with_the_legs_are_reweighed() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let bvh = first_frames(bvh::from_path(&path).unwrap(), 900);
    let model = g1();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let tuned = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let human = retarget::derive::human_body(&bvh, &fk::FkOptions::default(), "walk").unwrap();
    let roles = retarget::RobotRoles::recognise(&model).unwrap();
    let derived = retarget::derive::derive(&model, &roles, &human, "derived").unwrap();
    let diag = |config: &IkConfig| {
        retarget::internals::retarget_bvh(&bvh, &model, config, &RetargetOptions::default())
            .unwrap()
            .1
    };
    // The reweighing's report: the pelvis offset (m) and the share applied.
    let reweigh = |d: &retarget::ClipDiagnostics| {
        let report = d.stages.iter().find(|r| r.stage == "reweigh")?;
        let number = |key: &str| match report.values.get(key) {
            Some(retarget::StageValue::Number(x)) => *x,
            other => panic!("{key}: {other:?}"),
        };
        Some((number("pelvis_offset"), number("share")))
    };
    let (t, d) = (diag(&tuned), diag(&derived));
    let ((t_offset, t_share), (d_offset, d_share)) = (reweigh(&t).unwrap(), reweigh(&d).unwrap());
    eprintln!(
        "pelvis offset tuned {t_offset:.4} share {t_share:.2}, derived {d_offset:.4} share \
         {d_share:.2}"
    );
    assert!(t_offset > 0.01 && t_share > 0.5, "{:?}", t.stages);
    assert!(d_offset < 0.007 && d_share < 0.2, "{:?}", d.stages);
    // GMR's solve is never reweighed.
    let gmr =
        retarget::internals::retarget_bvh(&bvh, &model, &tuned, &RetargetOptions::gmr()).unwrap().1;
    assert_eq!(reweigh(&gmr), None);
    assert!(gmr.stages.is_empty(), "{:?}", gmr.stages);
}

/// A shipped robot's whole LAFAN1 take with the default solve (as `retarget --bvh … --robot
/// key` runs it): nothing deeper than 1 cm in the floor or in itself. The H1's jumps and walk
/// and ToddlerBot's walk had frames where the one repair step after smoothing left a geom in
/// the floor (1.6 / 1.2 cm) or two in each other (10 and 30 frames on the H1) until such
/// frames kept the first pass's pose.
fn nothing_in_the_floor_or_in_itself(key: &str, take: &str) -> Option<QualityReport> {
    let path = shared::shared_file(&format!("data/bvh/{take}"))?;
    let retargeter = retarget::Retargeter::new(key).unwrap();
    let (motion, _) = retargeter.retarget_bvh_file(&path).unwrap();
    let r = report(&motion, retargeter.model(), &ReportOptions::default()).unwrap();
    assert_eq!(r.ground_penetration.frames, 0, "{key} {take}: {:?}", r.ground_penetration);
    // (The H1's walk: one frame, its hip yaw links 1.7 cm into each other, where its first
    // pass jumps between two solutions and the trajectory solve cannot take it back.
    // ToddlerBot's walk: one frame, 3108, its left sole 1.2 cm into the right ankle, in the
    // crossover of frames 3069–3120 where both legs are held at range limits (left knee
    // straight, right hip yaw at 90°; the main command says "cannot follow") and the rows
    // cannot all hold: 0.95 cm there before pivots stood on the ball of the foot, which
    // changed the frames before it.)
    let deep = if key == "unitree_h1" || key == "stanford_toddy" { 1 } else { 0 };
    assert!(r.self_collision.frames_deep <= deep, "{key} {take}: {:?}", r.self_collision);
    Some(r)
}

#[test]
fn the_repair_pass_leaves_nothing_in_the_floor_or_in_itself() {
    nothing_in_the_floor_or_in_itself("unitree_h1", "lafan1_take_via_bvhtools_test2.bvh");
    nothing_in_the_floor_or_in_itself("unitree_h1", "lafan1_take_via_bvhtools_test.bvh");
    let toddy =
        nothing_in_the_floor_or_in_itself("stanford_toddy", "lafan1_take_via_bvhtools_test.bvh");
    // ToddlerBot's 12 cm feet cross at up to 90° in the walk's turns: kept apart by the
    // footprints they would have facing their mean heading, the swing foot stopped at the
    // planted one and the planted one was dragged (58 skating frames, 0.81 %); measured by
    // each sole's own yaw, 1 (the trajectory solve: 19, 0.26 %; the bar is 0.5 %).
    if let Some(r) = toddy {
        let skating = r.skating.as_ref().unwrap();
        assert!(skating.duration < 0.005, "ToddlerBot walk: {skating:?}");
    }
}

/// The file at `path` retargeted onto the shipped robot `key` in `mode` (as the main command
/// does it), its report and diagnostics.
fn shipped_file(
    key: &str,
    path: &std::path::Path,
    mode: retarget::SolveMode,
) -> (QualityReport, retarget::ClipDiagnostics) {
    let r = retarget::Retargeter::new(key).unwrap().with_mode(mode);
    let (motion, diag) = r.retarget_bvh_file(path).unwrap();
    (report(&motion, r.model(), &ReportOptions::default()).unwrap(), diag)
}

/// ToddlerBot's legs (0.28 m): the same centimetres of foot motion are large angles. The
/// trajectory solve's joint smoothness is set per joint by its tracking stiffness
/// ([`retarget::TrajectoryOptions::joint_cutoff_hz`]); its swing feet stay
/// clear of the floor. Its walk is the one shipped take more jittery than GMR's solve (10.0
/// against 7.6 rad/s², mostly the ankles within two frames of a contact switch; the
/// per-frame solve it replaced, with 8 smoothing passes, 7.2): bounded here, not met.
#[test]
fn a_short_legged_robot_is_smoother_than_gmr_and_its_swing_feet_stay_up() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let solve = |mode| shipped_file("stanford_toddy", &path, mode);
    let (default, _) = solve(retarget::SolveMode::default());
    let (gmr, _) = solve(retarget::SolveMode::Gmr);
    let (d, g) = (mean_jitter(&default), mean_jitter(&gmr));
    assert!(d <= 1.4 * g, "jitter {d:.2} against GMR's {g:.2}");
    let (rot_d, rot_g) = (mean_rot_error_deg(&default), mean_rot_error_deg(&gmr));
    assert!(rot_d < 1.1 * rot_g, "rotation error {rot_d:.2}° against GMR's {rot_g:.2}°");
    // A sole on the floor stands still: it is planted, or lifting its last contact point.
    let (s_d, s_g) = (floor_skating_share(&default), floor_skating_share(&gmr));
    assert!(s_d < 0.25 * s_g, "skating on the floor {s_d:.4} against GMR's {s_g:.4}");
}

/// Frames with a sole on the floor moving faster than the skating speed, over frames with a
/// sole on the floor, both feet.
fn floor_skating_share(r: &QualityReport) -> f64 {
    let (skating, floor) =
        r.feet.iter().fold((0, 0), |(s, c), f| (s + f.floor_skating_frames, c + f.floor_frames));
    skating as f64 / floor.max(1) as f64
}

/// The Bandai walker's right foot turns out 18° from its shin (mean over the take). The G1 has
/// no ankle yaw, so a planted foot turns the whole leg with it: planted at the foot's own yaw,
/// the hip and knee were 5° further from their targets than in GMR's solve and the mean
/// rotation error 4.13° against GMR's 3.35° (1.23×); sharing the toe-out between the foot and
/// the leg above it, as GMR's solve does, 3.45° with the per-frame solve, 3.79° (1.13×) with
/// the trajectory solve, whose planted feet stand flat on their soles.
#[test]
fn a_foot_turned_out_from_its_shin_is_planted_between_the_two() {
    let Some(path) = shared::shared_file("data/bvh/bandai_dataset-1_walk_normal_001.bvh") else {
        return;
    };
    let rotation = |mode| mean_rot_error_deg(&shipped_file("unitree_g1", &path, mode).0);
    let (d, g) = (rotation(retarget::SolveMode::default()), rotation(retarget::SolveMode::Gmr));
    assert!(d < 1.15 * g, "rotation error {d:.2}° against GMR's {g:.2}°");
}

/// The trajectory solve's first frame has no frame before it: no speed limit counts from
/// anything there, and it stays near the first pass's (the first pass solves it from the
/// better of two starts, which decides the branch the limbs keep). A repair once counted the
/// limits from the first pass's last frame: on the first 800 frames of the jumps take the
/// G1's first frame was pulled 0.99 rad towards the last, and the PM01 began the whole take
/// with its left hip twisted 164°.
#[test]
fn the_first_frame_is_not_pulled_towards_the_last() {
    let Some((model, config, full, height)) = g1_jumps() else { return };
    let human = slice(&full, 0..800);
    let solve = |iterations: usize| {
        let mut plausible = retarget::PlausibleOptions::default();
        plausible.trajectory.iterations = iterations;
        let mode = retarget::SolveMode::Plausible(plausible);
        let options = {
            let mut o = RetargetOptions::default();
            o.human_height = Some(height);
            o.mode = mode;
            o
        };
        retarget_motion(&human, &model, &config, &options).unwrap().0
    };
    let (solved, first_pass) = (solve(2), solve(0));
    let nq = model.nq;
    let moved = solved.qpos[..nq]
        .iter()
        .zip(&first_pass.qpos[..nq])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(moved < 0.1, "the trajectory solve moved the first frame by {moved}");
}

/// A clip that begins mid-motion: its first frame is solved without joint speed limits (its
/// start configuration, `qpos0` turned to the root's heading, is no frame of the motion), so
/// it comes out as the same frame of a clip that began two seconds earlier does. Limits
/// counted from the start configuration held the joints back: over ten such starts on the
/// jumps take the median joint difference was 0.2 rad, the largest 1.6 (0.02 and 0.33 now;
/// the rest are other solutions of the same frame).
#[test]
fn a_clip_that_begins_mid_motion_tracks_from_its_first_frame() {
    let Some((model, config, full, height)) = g1_jumps() else { return };
    let nq = model.nq;
    let solve = |from: usize, to: usize| {
        let options = {
            let mut o = RetargetOptions::causal();
            o.human_height = Some(height);
            o
        };
        retarget_motion(&slice(&full, from..to), &model, &config, &options).unwrap().0
    };
    let mut differences: Vec<f64> = (1..=10)
        .map(|k| {
            let start = 300 * k;
            let (late, early) = (solve(start, start + 1), solve(start - 60, start + 1));
            let joints = &early.qpos[60 * nq + 7..61 * nq];
            late.qpos[7..nq].iter().zip(joints).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
        })
        .collect();
    differences.sort_by(f64::total_cmp);
    let median = (differences[4] + differences[5]) / 2.0;
    assert!(median < 0.05, "first frames differ by {median} rad (median): {differences:?}");
}

/// At 120 frames/s (CMU) the smoothing spans as much time as at 30 (16 passes, not one), and
/// the default solve's jitter stays under GMR's (it was 69 against 50 rad/s² on 131_01).
#[test]
fn a_120_fps_take_is_no_more_jittery_than_gmr() {
    let Some(path) = shared::shared_file("data/bvh/cmu_bvh11_131_01.bvh") else { return };
    let bvh = first_frames(bvh::from_path(&path).unwrap(), 1200);
    let jitter = |mode: retarget::SolveMode| {
        let r = retarget::Retargeter::new("unitree_g1").unwrap().with_mode(mode);
        let (motion, _) = r.retarget_bvh(&bvh).unwrap();
        assert!((motion.fps - 120.0).abs() < 1e-6, "{}", motion.fps);
        mean_jitter(&report(&motion, r.model(), &ReportOptions::default()).unwrap())
    };
    let (default, gmr) = (jitter(retarget::SolveMode::default()), jitter(retarget::SolveMode::Gmr));
    assert!(default <= gmr, "jitter {default:.1} against GMR's {gmr:.1}");
}

/// The first frame is solved from the better of two starts (`qpos0` turned to the root's
/// heading, and not turned): the start decides which solution an arm settles in for the rest
/// of the clip. The Bandai kick begins with the subject turned 90°; from the turned start the
/// T1's right wrist stayed 130° off its target for the whole take (GMR's solve, from `qpos0`:
/// 1°).
#[test]
fn the_first_frame_starts_where_the_arms_can_follow() {
    let file = "data/bvh/bandai_dataset-1_kick_normal_001.bvh";
    let Some(r) = shared_bvh_report(file, Some(100), "booster_t1_29dof", None) else {
        return;
    };
    let tracking = r.tracking.unwrap();
    let hand = tracking.iter().find(|b| b.body == "right_hand_link").unwrap();
    assert!(hand.rot_rad.mean < 0.35, "right hand {:.2} rad off", hand.rot_rad.mean);
}

/// On the Bandai kick the PM01's right hip goes over into its other branch (pitch and roll at
/// their limits, yaw past −150°) as the leg comes up, and the warm-started solve keeps it
/// there for the rest of the take. Solved both ways ([`retarget::PlausibleOptions::both_ways`]),
/// the backward pass, which reaches the kick from the take's normal end, takes over, and the
/// hip stays in its normal branch throughout.
#[test]
fn a_limb_stuck_in_another_branch_is_taken_from_the_backward_pass() {
    let Some(path) = shared::shared_file("data/bvh/bandai_dataset-1_kick_normal_001.bvh") else {
        return;
    };
    let solve = |both_ways| {
        let mode = retarget::SolveMode::Plausible({
            let mut o = retarget::PlausibleOptions::default();
            o.both_ways = both_ways;
            o
        });
        let r = retarget::Retargeter::new("engineai_pm01").unwrap().with_mode(mode);
        let (motion, _) = r.retarget_bvh_file(&path).unwrap();
        let report = report(&motion, r.model(), &ReportOptions::default()).unwrap();
        let joint = &r.model().joints[r.model().joint_id("J08_HIP_YAW_R").unwrap()];
        let nq = motion.nq;
        let over = (0..motion.num_frames())
            .filter(|&t| motion.qpos[t * nq + joint.qpos_adr].abs() > 150f64.to_radians())
            .count();
        (over, report)
    };
    let (over_forward, forward) = solve(false);
    let (over_both, both) = solve(true);
    assert!(over_forward > 100, "the forward solve alone: {over_forward} frames over");
    assert_eq!(over_both, 0);
    let (rot_f, rot_b) = (mean_rot_error_deg(&forward), mean_rot_error_deg(&both));
    assert!(rot_b < rot_f, "rotation error {rot_b:.2}° against {rot_f:.2}° forward only");
    assert_eq!(both.ground_penetration.frames, 0);
    assert_eq!(both.joint_speed.as_ref().unwrap().violations, 0);
}

/// The LAFAN1 walk crosses over in a crouch (near frames 2990 and 3292 of the shared take, the
/// right foot landing 11 cm to the left of the left one). The T1's legs are thick for it: the
/// per-frame solve, held crossed, lifted its planted feet off their targets and sank its
/// pelvis 9–12 cm below its target. The trajectory solve stands in them. (An uncrossing stage
/// planned such steps side by side; on the corpus it changed one row of 250, by 0.14 points
/// of floor skating, and was deleted: decision 017.)
#[test]
fn a_robot_with_thick_legs_stands_in_crossed_steps() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let (full, fk_report) =
        fk::human_motion(&bvh::from_path(&path).unwrap(), &fk::FkOptions::default()).unwrap();
    let human = slice(&full, 2900..3400);
    let r = retarget::Retargeter::new("booster_t1_29dof")
        .unwrap()
        .with_human_height(Some(fk_report.height));
    let (solved, diag) = r.retarget(&human).unwrap();
    let model = r.model();
    // Over the crossovers (both feet down, the right foot 11 cm left of the left one, frames
    // 90–96 and 392–400 of the slice): how far the pelvis sinks below its target, and the
    // largest error of a planted foot.
    let worst = |motion: &retarget::RobotMotion, frames: &retarget::ClipDiagnostics| {
        let targets = motion.targets.as_ref().unwrap();
        let k = |name: &str| targets.body_names.iter().position(|b| b == name).unwrap();
        let (waist, feet) = (k("Waist"), [k("left_foot_link"), k("right_foot_link")]);
        let body = |name: &str| model.bodies.iter().position(|b| b.name == name).unwrap();
        let waist_body = body("Waist");
        let mut data = mjcf::Data::new(model);
        let (mut sink, mut foot) = (0.0_f64, 0.0_f64);
        let n = targets.body_names.len();
        for t in (90..97).chain(392..401) {
            model.kinematics(&motion.qpos[t * model.nq..(t + 1) * model.nq], &mut data);
            sink = sink.max(targets.pos[t * n + waist].z - data.xpos[waist_body].z);
            for f in feet {
                foot = foot.max(frames.frames[t].pos_error[f]);
            }
        }
        (sink, foot)
    };
    // The per-frame solve this replaced sank the pelvis 11 cm there and kept a planted foot
    // 3.3 cm off.
    let (sink, foot) = worst(&solved, &diag);
    eprintln!("stages {:?}, sink {sink:.3} m, foot {foot:.3} m", diag.stages);
    assert!(sink < 0.03, "the pelvis sinks {sink} m");
    assert!(foot < 0.06, "a planted foot {foot} m off");
}

/// `bvh` sampled `factor` times as often: Catmull–Rom through every channel, angles unwrapped
/// first (no channel of the LAFAN1 takes moves 180 units between frames but a wrapping angle).
fn upsampled(mut bvh: bvh::Bvh, factor: usize) -> bvh::Bvh {
    let (frames, channels) = (bvh.motion.num_frames, bvh.motion.num_channels);
    let mut v = bvh.motion.values.clone();
    for c in 0..channels {
        for t in 1..frames {
            let d = v[t * channels + c] - v[(t - 1) * channels + c];
            v[t * channels + c] -= 360.0 * (d / 360.0).round();
        }
    }
    let at = |t: usize, c: usize| v[t.min(frames - 1) * channels + c];
    let mut out = Vec::with_capacity(((frames - 1) * factor + 1) * channels);
    for t in 0..frames - 1 {
        for k in 0..factor {
            let u = k as f64 / factor as f64;
            for c in 0..channels {
                let (a, b, cc, d) =
                    (at(t.saturating_sub(1), c), at(t, c), at(t + 1, c), at(t + 2, c));
                out.push(
                    0.5 * (2.0 * b
                        + (cc - a) * u
                        + (2.0 * a - 5.0 * b + 4.0 * cc - d) * u * u
                        + (3.0 * b - a - 3.0 * cc + d) * u * u * u),
                );
            }
        }
    }
    out.extend_from_slice(&v[(frames - 1) * channels..]);
    bvh.motion.num_frames = out.len() / channels;
    bvh.motion.frame_time /= factor as f64;
    bvh.motion.values = out;
    bvh
}

/// Issue 40, item 1: the same motion sampled at 30, 60 and 120 fps gives the same robot
/// motion, within interpolation. 20 s of the LAFAN1 walk onto the G1; the solve at each rate,
/// every `factor`-th frame compared with the 30 fps solve's. Stated tolerances: joints within
/// 0.02 rad at the 95th percentile, the root within 1 cm everywhere, the dynamics check (over
/// 1/6 s) within 2 points of share and floor skating under 0.5 % at every rate.
#[test]
fn the_same_walk_at_30_60_and_120_fps_gives_the_same_motion() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test.bvh") else {
        return;
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let model = g1();
    let config = IkConfig::from_file(&root.join("configs/gmr/bvh_lafan1_to_g1.json")).unwrap();
    let base = first_frames(bvh::from_path(&path).unwrap(), 601);
    let solve = |factor: usize| {
        let bvh = upsampled(base.clone(), factor);
        let (human, _) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
        let mut options = RetargetOptions::default();
        options.human_height = Some(1.75);
        let (motion, _) = retarget_motion(&human, &model, &config, &options).unwrap();
        let rep = report(&motion, &model, &ReportOptions::default()).unwrap();
        (motion, rep)
    };
    let (at30, rep30) = solve(1);
    let nq = model.nq;
    for factor in [2, 4] {
        let (motion, rep) = solve(factor);
        assert_eq!(motion.num_frames(), 600 * factor + 1);
        let (mut joints, mut root) = (Vec::new(), 0.0_f64);
        for t in 0..at30.num_frames() {
            let (a, b) = (at30.frame(t), motion.frame(t * factor));
            joints.extend((7..nq).map(|i| (a[i] - b[i]).abs()));
            root = root.max(
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt(),
            );
        }
        let p95 = retarget::report::percentile(&joints, 0.95);
        let share = |r: &QualityReport| r.dynamics.as_ref().unwrap().share_over;
        let skate = worst_floor_skating;
        eprintln!(
            "{} fps: joints p95 {p95:.4} rad, root max {root:.4} m, dynamics {:.3} vs {:.3}, floor skating {:.4} vs {:.4}",
            30 * factor,
            share(&rep),
            share(&rep30),
            skate(&rep),
            skate(&rep30)
        );
        assert!(p95 < 0.02, "{} fps: joints p95 {p95} rad", 30 * factor);
        assert!(root < 0.01, "{} fps: root {root} m", 30 * factor);
        assert!((share(&rep) - share(&rep30)).abs() < 0.02);
        assert!(skate(&rep) < 0.005 && skate(&rep30) < 0.005);
    }
}

/// A planted sole's points slide no faster than the slip speed (`FootPlanOptions::slip_speed`,
/// a hard constraint of each frame's step and of the window's): on CMU 131_03, a 120 fps walk,
/// the G1's soles slid on the floor in 2.6 % of their floor frames when only the contact
/// tasks held them, the smoothness of 120 frames a second outweighing them; 0.8 % held.
#[test]
fn planted_feet_hold_at_120_fps() {
    let file = "data/bvh/cmu_bvh11_131_03.bvh";
    let Some(report) = shared_bvh_report(file, None, "unitree_g1", None) else { return };
    assert!((report.fps - 120.0).abs() < 1e-6, "{}", report.fps);
    let worst = worst_floor_skating(&report);
    assert!(worst < 0.012, "a sole slides in {:.2} % of its floor frames", 100.0 * worst);
}

/// The window's Gauss–Newton step is taken twice per iteration, linearised again where the
/// first ended (`TrajectoryOptions::banded_steps`): on the SOMA walk (120 fps) onto the T1, one
/// step turned the waist and a hip's yaw 0.3–0.45 rad, which left the planted sole's points
/// 5–12 mm out of their grip, and the right foot slid on the floor in 3.0 % of its floor
/// frames; 0.6 % with two.
#[test]
fn a_planted_foot_holds_through_the_window_step() {
    let file = "data/soma/Neutral_walk_forward_002__A057.bvh";
    let Some(report) = shared_bvh_report(file, None, "booster_t1_29dof", None) else {
        return;
    };
    let worst = worst_floor_skating(&report);
    assert!(worst < 0.012, "a sole slides in {:.2} % of its floor frames", 100.0 * worst);
}

/// A joint that the window's step would take past its range is held at its end in that step
/// (`Trajectory::ranges_crossed`), not cut back once the step is taken: cut back alone, the
/// H1's left hip roll, taken 0.1 rad past its range by the second iteration's step, slid the
/// planted left sole 5 mm a frame for 0.12 s of the SMPL-X walk (120 fps), and its soles slid
/// on the floor in 2.4 % of their floor frames (the corpus gate's cap: 2 %); 1.6 % held.
#[test]
fn a_joint_range_end_holds_in_the_window_step() {
    let Some(dir) = shared::shared_file("reference/smpl") else { return };
    let models = smpl::BodyModels::new(Some(&dir.join("body_models")));
    let path = dir.join("motions/smplx_walk_stageii.npz");
    let motion = smpl::SmplMotion::from_path(&path).unwrap();
    let body = models.for_motion(&motion, None).unwrap();
    let clip = smpl::clip(&body, &motion).unwrap();
    let r = retarget::Retargeter::new("unitree_h1").unwrap();
    let chosen = r.choose_smpl_config(&clip).unwrap();
    let (robot, _) = r.retarget_smpl_with(&motion, &body, &clip, &chosen).unwrap();
    let report = report(&robot, r.model(), &ReportOptions::default()).unwrap();
    let worst = worst_floor_skating(&report);
    assert!(worst < 0.02, "a sole slides in {:.2} % of its floor frames", 100.0 * worst);
}

/// A gripped point outside its box is held where it is on that side, not asked back
/// (`constraints::Grip`): asked back half the box, the corners of the H1's sole tipped onto
/// its toes made a QP whose exact step is huge, and the sweep threw the root 10.5 m in a
/// frame of the second LAFAN1 take (17,000 m/s²) and 17 cm in another (212 m/s²). The scaled
/// human's root peaks at about 30 m/s² there.
#[test]
fn a_sweep_step_does_not_throw_the_root() {
    let Some(path) = shared::shared_file("data/bvh/lafan1_take_via_bvhtools_test2.bvh") else {
        return;
    };
    let bvh = bvh::from_path(&path).unwrap();
    let r = retarget::Retargeter::new("unitree_h1").unwrap();
    let (motion, _) = r.retarget_bvh(&bvh).unwrap();
    let (nq, fps) = (motion.nq, motion.fps);
    let root = |t: usize| nalgebra::Vector3::from_column_slice(&motion.qpos[t * nq..t * nq + 3]);
    let (worst, at) = (1..motion.num_frames() - 1)
        .map(|t| ((root(t + 1) - 2.0 * root(t) + root(t - 1)).norm() * fps * fps, t))
        .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
    assert!(worst < 60.0, "the root accelerates at {worst:.0} m/s² in frame {at}");
}

/// A bound the window's step would cross is held in that step, constraint rows as well as
/// joint ranges (`Trajectory::crossed`): with the ranges alone, the step carried ToddlerBot's
/// left sole 4.1 cm into its right ankle in frames 3120–3121 of the LAFAN1 walk (1.75 m), a
/// frame the sweep could not take back (its constraints relaxed).
#[test]
fn a_window_step_does_not_carry_a_sole_through_the_other_ankle() {
    let file = "data/bvh/lafan1_take_via_bvhtools_test.bvh";
    let Some(report) = shared_bvh_report(file, None, "stanford_toddy", Some(1.75)) else {
        return;
    };
    let sc = &report.self_collision;
    assert_eq!(
        sc.frames_deep, 0,
        "{} frames deeper than 1 cm, {:.1} cm",
        sc.frames_deep, sc.max_depth_cm
    );
}

/// The root's acceleration is smoothed where its target is, at the root task's body's origin,
/// not at the free root's (`Trajectory::root_point_terms`): the T1's root task is on its
/// `Waist`, 11.5 cm below and 6 cm ahead of the free `Trunk`'s origin, and the trunk's turns
/// moved the `Waist` past a smooth `Trunk` origin: over the first 900 frames of the LAFAN1
/// walk it accelerated 1.40 × its target (averaged over 1/6 s; the corpus gate's cap 1.25 ×),
/// 1.16 × measured there.
#[test]
fn the_root_is_smooth_where_its_target_is() {
    let file = "data/bvh/lafan1_take_via_bvhtools_test.bvh";
    let Some(report) = shared_bvh_report(file, Some(900), "booster_t1_29dof", None) else {
        return;
    };
    let a = &report.root_acceleration;
    assert_eq!(a.body, "Waist");
    let human = a.averaged.target.as_ref().unwrap().mean_mps2;
    let ratio = a.averaged.motion.mean_mps2 / human;
    assert!(ratio < 1.25, "the Waist accelerates {ratio:.2} × its target");
}

/// A rising sole's points that stood on the floor at lift-off are held there as a planted
/// sole's are (`FootPlan::lifted_at`, grips): held by their point tasks alone, the G1's toes
/// slid 0.3–0.9 m/s within a centimetre of the floor in the frames after each toe-off of the
/// SOMA walk (120 fps), 0.7 % of the right foot's floor frames (issue 40's bar: 0.5 %).
#[test]
fn a_rising_sole_lifts_its_last_contact_without_sliding_it() {
    let file = "data/soma/Neutral_walk_forward_002__A057.bvh";
    let Some(report) = shared_bvh_report(file, None, "unitree_g1", None) else {
        return;
    };
    let worst = worst_floor_skating(&report);
    assert!(worst <= 0.005, "a sole slides in {:.2} % of its floor frames", 100.0 * worst);
}
