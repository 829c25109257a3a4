//! FK on the real clips of `$RETARGET_SHARED/data/bvh`: units, heights, ground contact,
//! walking direction and handedness after the Y-up → Z-up conversion.

#[path = "../../../tests/support/shared.rs"]
mod shared;

use fk::{AxisConvention, FkOptions, FkReport, HumanMotion, UnitChoice};
use nalgebra::Vector3;

fn load(file: &str, options: &FkOptions) -> Option<(HumanMotion, FkReport)> {
    let path = shared::shared_file(&format!("data/bvh/{file}"))?;
    let bvh = bvh::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
    Some(fk::human_motion(&bvh, options).unwrap_or_else(|e| panic!("{file}: {e}")))
}

/// Lowest point of the named bodies (and their End Sites) per frame.
fn soles(motion: &HumanMotion, feet: &[&str]) -> Vec<f64> {
    let ids: Vec<usize> = motion
        .body_names
        .iter()
        .enumerate()
        .filter(|(_, n)| feet.iter().any(|f| n.starts_with(f) && !n.ends_with("Mod")))
        .map(|(i, _)| i)
        .collect();
    assert!(ids.len() >= feet.len(), "{feet:?} in {:?}", motion.body_names);
    (0..motion.num_frames)
        .map(|f| ids.iter().map(|&i| motion.position(f, i).z).fold(f64::INFINITY, f64::min))
        .collect()
}

/// Horizontal speed of `body` per frame (m/s, central differences).
fn speeds(motion: &HumanMotion, body: usize) -> Vec<Vector3<f64>> {
    (0..motion.num_frames)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(motion.num_frames - 1));
            (motion.position(b, body) - motion.position(a, body)) * motion.fps
                / (b - a).max(1) as f64
        })
        .collect()
}

fn fraction(values: impl Iterator<Item = bool>) -> f64 {
    let (mut yes, mut all) = (0usize, 0usize);
    for v in values {
        yes += usize::from(v);
        all += 1;
    }
    yes as f64 / all.max(1) as f64
}

const LAFAN1: [&str; 2] =
    ["lafan1_take_via_bvhtools_test.bvh", "lafan1_take_via_bvhtools_test2.bvh"];
const LAFAN1_FEET: [&str; 4] = ["LeftFoot", "LeftToe", "RightFoot", "RightToe"];

#[test]
fn lafan1_is_centimetres_of_a_plausible_adult_standing_on_z0() {
    for file in LAFAN1 {
        let Some((motion, report)) = load(file, &FkOptions::default()) else { return };
        assert_eq!(report.metres_per_unit, 0.01, "{file}: {}", report.unit_reason);
        assert!((1.6..=1.9).contains(&report.height), "{file}: {report:?}");
        assert_eq!(motion.num_bodies(), 22 + 5 + 2);
        let hips = motion.require_body("Hips").unwrap();
        let speed = speeds(&motion, hips);
        let sole = soles(&motion, &LAFAN1_FEET);
        // Standing frames: the root (nearly) still. The lowest foot point is on the floor.
        let standing: Vec<usize> =
            (0..motion.num_frames).filter(|&f| speed[f].norm() < 0.1).collect();
        assert!(standing.len() > 30, "{file}: {} standing frames", standing.len());
        let on_floor = fraction(standing.iter().map(|&f| sole[f].abs() < 0.03));
        assert!(
            on_floor > 0.95,
            "{file}: {on_floor} of standing frames have a foot within 3 cm of z = 0"
        );
        assert!(report.ground.abs() < 0.03, "{file}: {report:?}");
    }
}

#[test]
fn lafan1_walks_horizontally_with_the_left_leg_on_the_left() {
    let Some((motion, _)) = load(LAFAN1[0], &FkOptions::default()) else { return };
    let [hips, left, right] =
        ["Hips", "LeftUpLeg", "RightUpLeg"].map(|n| motion.require_body(n).unwrap());
    let velocity = speeds(&motion, hips);
    let walking: Vec<usize> =
        (0..motion.num_frames).filter(|&f| velocity[f].xy().norm() > 0.8).collect();
    assert!(walking.len() > 1000, "{} walking frames", walking.len());
    // Over one-second windows (the hips bob within a stride): a horizontal path.
    let (mut vertical, mut horizontal) = (0.0, 0.0);
    for f in walking.iter().copied().filter(|f| f + 30 < motion.num_frames) {
        let step = motion.position(f + 30, hips) - motion.position(f, hips);
        vertical += step.z.abs();
        horizontal += step.xy().norm();
    }
    assert!(
        vertical < 0.05 * horizontal,
        "hips travel: vertical {vertical} m vs horizontal {horizontal} m"
    );
    // The toes point forward (whichever way the subject walks, LAFAN1 also steps sideways
    // and back), and the subject's left is up × forward. A mirrored conversion flips this.
    let [lf, lt, rf, rt] = LAFAN1_FEET.map(|n| motion.require_body(n).unwrap());
    let left_side = fraction((0..motion.num_frames).map(|f| {
        let at = |b| motion.position(f, b);
        let forward = (at(lt) - at(lf)) + (at(rt) - at(rf));
        let leftward = Vector3::z().cross(&forward);
        (at(left) - at(right)).dot(&leftward) > 0.0
    }));
    assert!(left_side > 0.95, "LeftUpLeg on the left in {left_side} of the frames");
}

#[test]
fn lafan1_world_poses_follow_gmr_conventions() {
    let Some((motion, _)) = load(LAFAN1[0], &FkOptions::default()) else { return };
    let Some((file_axes, _)) = load(
        LAFAN1[0],
        &FkOptions {
            axes: AxisConvention::ZUp,
            units: UnitChoice::Scale(1.0),
            ..FkOptions::default()
        },
    ) else {
        return;
    };
    // GMR: p' = (x, −z, y) / 100 exactly, q' = q_x90 ⊗ q (up to sign: continuity is ours).
    let q_x90 = AxisConvention::YUp.world_from_file();
    for f in [0, 1000, motion.num_frames - 1] {
        for b in 0..motion.num_bodies() {
            let p = file_axes.position(f, b);
            assert_eq!(*motion.position(f, b), Vector3::new(p.x, -p.z, p.y) / 100.0);
            let q = q_x90 * file_axes.orientation(f, b);
            let dot = q.coords.dot(&motion.orientation(f, b).coords).abs();
            assert!(
                dot > 1.0 - 1e-14,
                "frame {f} body {b}: {dot} {q:?} {:?}",
                motion.orientation(f, b)
            );
        }
    }
    let mods = [("LeftFootMod", "LeftFoot", "LeftToe"), ("RightFootMod", "RightFoot", "RightToe")];
    for (name, foot, toe) in mods {
        let [m, foot, toe] = [name, foot, toe].map(|n| motion.require_body(n).unwrap());
        assert_eq!(motion.position(7, m), motion.position(7, foot));
        assert_eq!(motion.orientation(7, m), motion.orientation(7, toe));
    }
}

#[test]
fn cmu_mixed_orders_in_its_own_unit_match_the_metre_version() {
    let Some((cmu, report)) = load("cmu_bvh11_131_01.bvh", &FkOptions::default()) else { return };
    assert_eq!(report.metres_per_unit, 0.05644, "{}", report.unit_reason);
    assert_eq!(cmu.fps, 120.0);
    let Some((metres, scaled)) = load("cmu_bvh11_scaled_131_01.bvh", &FkOptions::default()) else {
        return;
    };
    assert_eq!(scaled.metres_per_unit, 1.0, "{}", scaled.unit_reason);
    // The CMU skeleton at the documented 0.05644 m/unit is a short subject (the 3ds Max
    // release's trunk is short); both files must agree on it to the millimetre.
    assert!((1.3..=1.9).contains(&report.height), "{report:?}");
    assert!((report.height - scaled.height).abs() < 1e-3, "{report:?} vs {scaled:?}");
    for (motion, name) in [(&cmu, "131_01"), (&metres, "scaled 131_01")] {
        let sole = soles(motion, &["LeftAnkle", "LeftToe", "RightAnkle", "RightToe"]);
        // CMU's toe End Sites float a few centimetres while the foot is flat: the floor is
        // reached at the clip's lowest points, and the foot is never far above it.
        let mut sorted = sole.clone();
        sorted.sort_by(f64::total_cmp);
        let (p5, median) = (sorted[sorted.len() / 20], sorted[sorted.len() / 2]);
        assert!(
            p5.abs() < 0.03 && (0.0..0.08).contains(&median),
            "{name}: sole p5 {p5} median {median}"
        );
    }
}

#[test]
fn bandai_six_channel_joints_give_a_plausible_subject_on_the_floor() {
    let files = [
        "bandai_dataset-1_walk_normal_001.bvh",
        "bandai_dataset-1_run_normal_001.bvh",
        "bandai_dataset-1_kick_normal_001.bvh",
        "bandai_dataset-1_dance-short_normal_001.bvh",
        "bandai_dataset-2_walk_normal_001.bvh",
    ];
    for file in files {
        let Some((motion, report)) = load(file, &FkOptions::default()) else { return };
        assert_eq!(report.metres_per_unit, 0.01, "{file}: {}", report.unit_reason);
        assert!((1.4..=1.9).contains(&report.height), "{file}: {report:?}");
        // Bandai's toe joints sit a few centimetres above the sole.
        let sole = soles(&motion, &["Foot_L", "Toes_L", "Foot_R", "Toes_R"]);
        let on_floor = fraction(sole.iter().map(|s| s.abs() < 0.06));
        assert!(on_floor > 0.8, "{file}: a foot within 6 cm of z = 0 in {on_floor} of frames");
        assert!((0.0..0.06).contains(&report.ground), "{file}: {report:?}");
    }
}

#[test]
fn every_shared_clip_converts() {
    let Some(dir) = shared::shared_file("data/bvh") else { return };
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.retain(|p| p.extension().is_some_and(|e| e == "bvh"));
    files.sort();
    assert!(files.len() >= 13);
    for path in files {
        let bvh = bvh::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let (motion, report) = fk::human_motion(&bvh, &FkOptions::default()).unwrap();
        let name = path.file_name().unwrap().to_string_lossy();
        assert!((1.2..=2.0).contains(&report.height), "{name}: {report:?}");
        assert!(motion.positions.iter().all(|p| p.iter().all(|v| v.is_finite())), "{name}");
        let expected = if name.contains("rigify") || name.contains("scaled") { 1.0 } else { 0.01 };
        let expected = if name.starts_with("cmu_bvh11_13") { 0.05644 } else { expected };
        assert_eq!(report.metres_per_unit, expected, "{name}: {}", report.unit_reason);
    }
}
