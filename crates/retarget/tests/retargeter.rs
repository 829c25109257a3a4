//! The owning entry point: streaming (`Retargeter::step`, one frame at a time) equals the clip
//! path with the same causal options, exactly, for GMR's solve and for the default solve's
//! causal part; the BVH path equals the pipeline the CLI used before; C3D through marker
//! configs. Reads `$RETARGET_SHARED` (see tests/support/shared.rs).

#[path = "../../../tests/support/shared.rs"]
mod shared;

use fk::HumanMotion;
use retarget::{HumanFrame, RetargetOptions, Retargeter, SolveMode};

/// The shared LAFAN1 walk's first `frames` frames (FK with the default options).
fn lafan1_walk(frames: usize) -> Option<HumanMotion> {
    let shared = shared::shared_dir()?;
    let bvh = bvh::from_path(&shared.join("data/bvh/lafan1_take_via_bvhtools_test.bvh")).unwrap();
    let (mut human, _) = fk::human_motion(&bvh, &fk::FkOptions::default()).unwrap();
    let n = human.num_bodies() * frames.min(human.num_frames);
    human.num_frames = frames.min(human.num_frames);
    human.positions.truncate(n);
    human.orientations.truncate(n);
    Some(human)
}

/// Streams every frame of `human` and returns the qpos rows, flat.
fn stream(retargeter: &mut Retargeter, human: &HumanMotion) -> Vec<f64> {
    let mut qpos = Vec::new();
    for f in 0..human.num_frames {
        let frame = HumanFrame::from_motion(human, f).unwrap();
        qpos.extend_from_slice(retargeter.step(&frame).unwrap());
    }
    assert_eq!(retargeter.streamed_frames(), human.num_frames);
    qpos
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn streaming_equals_the_clip_with_gmrs_solve() {
    let Some(human) = lafan1_walk(7184) else { return };
    let mut retargeter = Retargeter::new("unitree_g1").unwrap().with_mode(SolveMode::Gmr);
    let (clip, _) = retargeter.retarget(&human).unwrap();
    let streamed = stream(&mut retargeter, &human);
    assert_eq!(clip.num_frames(), human.num_frames);
    assert_eq!(max_difference(&clip.qpos, &streamed), 0.0, "GMR: stream and clip differ");
    // A reset starts again from the home pose: the same numbers again.
    retargeter.reset();
    assert_eq!(stream(&mut retargeter, &human), streamed);
}

#[test]
fn streaming_equals_the_clip_with_the_causal_solve() {
    let Some(human) = lafan1_walk(1200) else { return };
    let mut causal = Retargeter::new("unitree_g1").unwrap().with_options(RetargetOptions::causal());
    let (clip, diag) = causal.retarget(&human).unwrap();
    // The source's contact phases are labelled in every mode (from the whole clip), but the
    // causal solve plants nothing on them.
    let contacts = clip.contacts.clone().expect("contact labels in every mode");
    assert!(contacts.left.contains(&true) && contacts.left.contains(&false));
    let streamed = stream(&mut causal, &human);
    assert_eq!(max_difference(&clip.qpos, &streamed), 0.0, "causal: stream and clip differ");
    // The constraints are on: the joint speed limits hold between streamed frames.
    let model = causal.model();
    let dt = 1.0 / 30.0;
    for joint in model.joints.iter().filter(|j| j.kind == mjcf::JointType::Hinge) {
        let limit = joint.velocity_limit.unwrap();
        for f in 1..human.num_frames {
            let (a, b) = (f * model.nq + joint.qpos_adr, (f - 1) * model.nq + joint.qpos_adr);
            let speed = (streamed[a] - streamed[b]).abs() / dt;
            assert!(speed <= limit * (1.0 + 1e-6), "{} at frame {f}: {speed} rad/s", joint.name);
        }
    }
    assert!(diag.frames.iter().all(|f| f.qp_failures == 0));

    // The full default solve streams its causal part: the same numbers as the causal clip.
    let mut full = Retargeter::new("unitree_g1").unwrap();
    assert_eq!(stream(&mut full, &human), streamed);
    // ... while its clip plants the feet and filters, which differs.
    let (planted, _) = full.retarget(&human).unwrap();
    assert_eq!(planted.contacts.as_ref(), Some(&contacts), "the same source, the same labels");
    assert!(max_difference(&planted.qpos, &streamed) > 1e-3);
}

/// An in-place loop (the XNA dude's walk cycle, its feet sliding back on its floor): the
/// default clip walks it off its treadmill (stage 0, from the whole clip's belt), which a
/// stream cannot; the causal clip, which a stream equals, does not either.
#[test]
fn an_in_place_loop_stays_on_its_treadmill_in_the_causal_solve() {
    let Some(path) = shared::shared_file("data/fbx/xna_dude_walk_fbxsdk2017.fbx") else { return };
    let clip = retarget::FbxClip::read(&path, None).unwrap();
    let mut options = RetargetOptions::causal();
    options.fk = clip.fk_options(&fk::FkOptions::default());
    options.human_height = Some(1.75);
    let causal = Retargeter::new("unitree_g1").unwrap().with_options(options.clone());
    let (_, diag) = causal.retarget_bvh(&clip.bvh).unwrap();
    assert!(diag.stages.iter().all(|s| s.stage != "treadmill"), "{:?}", diag.stages);
    options.mode = SolveMode::default();
    let full = Retargeter::new("unitree_g1").unwrap().with_options(options);
    let (_, diag) = full.retarget_bvh(&clip.bvh).unwrap();
    assert!(diag.stages.iter().any(|s| s.stage == "treadmill"), "{:?}", diag.stages);
}

#[test]
fn frames_are_read_by_name_in_any_order() {
    let Some(human) = lafan1_walk(40) else { return };
    let mut in_order = Retargeter::new("unitree_g1").unwrap().with_mode(SolveMode::Gmr);
    let expected = stream(&mut in_order, &human);
    let mut shuffled = Retargeter::new("unitree_g1").unwrap().with_mode(SolveMode::Gmr);
    let mut got = Vec::new();
    for f in 0..human.num_frames {
        let frame = HumanFrame::from_motion(&human, f).unwrap();
        let mut order: Vec<usize> = (0..frame.body_names.len()).collect();
        // The first frame as given, later ones reversed (and one body short of the extras).
        if f > 0 {
            order.reverse();
        }
        let mut reordered = HumanFrame::with_capacity(order.len());
        for &i in &order {
            reordered.push(&frame.body_names[i], frame.positions[i], frame.orientations[i]);
        }
        got.extend_from_slice(shuffled.step(&reordered).unwrap());
    }
    assert_eq!(got, expected);
    // A frame missing a body the first one had is an error naming it.
    let mut frame = HumanFrame::from_motion(&human, 0).unwrap();
    let gone = frame.body_names.iter().position(|n| n == "LeftHand").unwrap();
    frame.body_names.remove(gone);
    frame.positions.remove(gone);
    frame.orientations.remove(gone);
    let err = shuffled.step(&frame).unwrap_err();
    assert!(
        matches!(&err, retarget::Error::FrameMissingBody { frame: 40, body } if body == "LeftHand"),
        "{err}"
    );
    // A frame whose poses do not match its names is told apart.
    let mut short = frame.clone();
    short.positions.pop();
    let err = shuffled.step(&short).unwrap_err();
    let shape = retarget::Error::FrameShape {
        frame: 40,
        names: frame.body_names.len(),
        positions: frame.body_names.len() - 1,
        orientations: frame.body_names.len(),
    };
    assert_eq!(err.to_string(), shape.to_string());
    // A fresh stream whose first frame lacks a config body is refused.
    let mut fresh = Retargeter::new("unitree_g1").unwrap();
    let err = fresh.step(&frame).unwrap_err().to_string();
    assert!(err.contains("LeftHand"), "{err}");
}

#[test]
fn the_bvh_path_is_the_clis_choice_and_pipeline() {
    let Some(shared) = shared::shared_dir() else { return };
    let path = shared.join("data/bvh/cmu_bvh11_131_01.bvh");
    let bvh = bvh::from_path(&path).unwrap();
    let retargeter = Retargeter::new("unitree_g1").unwrap();
    let chosen = retargeter.choose_config(&bvh).unwrap();
    assert_eq!(chosen.choice, retarget::derive::Choice::Derived, "CMU names: derived");
    let (motion, diag) = retargeter.retarget_bvh_file(&path).unwrap();
    let model = retarget::shipped::load_robot("unitree_g1").unwrap();
    let (expected, _) = retarget::internals::retarget_bvh(
        &bvh,
        &model,
        &chosen.config,
        &RetargetOptions::default(),
    )
    .unwrap();
    assert_eq!(motion.qpos, expected.qpos);
    assert!(diag.human_inferred.ends_with(&chosen.summary), "{}", diag.human_inferred);
}

#[test]
fn c3d_clips_go_through_the_marker_config() {
    let Some(shared) = shared::shared_dir() else { return };
    let c3d = shared.join("data/c3d/c3dorg_s00_Vicon_pyCGM2_Walking01.c3d");
    let config = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/c3d_plugingait_to_unitree_g1.json");
    let retargeter = Retargeter::new("unitree_g1").unwrap();
    let (motion, diag) = retargeter.retarget_c3d_file(&c3d, &config).unwrap();
    assert!(motion.num_frames() > 100);
    assert!(
        diag.human_height_source.starts_with("markers LASI+RASI"),
        "{}",
        diag.human_height_source
    );
    let err = retargeter.retarget_c3d_file(&shared.join("no_such.c3d"), &config).unwrap_err();
    assert!(err.to_string().contains("no_such.c3d"), "{err}");
}

#[test]
fn retargeters_are_shared_between_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Retargeter>();
    // Motions and frames need a config naming their bodies: a model file has none.
    let model = retarget::shipped::load_robot("unitree_g1").unwrap();
    let mut bare = Retargeter::from_model(model, "my_robot");
    let err = bare.step(&HumanFrame::default()).unwrap_err();
    assert!(matches!(&err, retarget::Error::NoConfig { robot } if robot == "my_robot"), "{err}");
    assert!(Retargeter::shipped("robots/unitree_g1.xml").is_err());
}

/// GMR PR #169's SOMA path (unmerged in GMR): its loader (`load_bvh_gmr`, `GmrBvhFormat::Soma`:
/// facing +X, 1.70 m) and GMR's solve with the PR's `bvh_soma` config, against our BVH path
/// under `--gmr` with the height given (facing −Y, LAFAN1's turn): a yaw of the world apart,
/// the same targets, so the same joint angles once GMR's first frame has turned the robot.
#[test]
fn gmr_soma_loader_and_our_fk_agree_but_for_the_heading() {
    let Some(config) =
        shared::shared_file("reference/gmr_ik_configs/pr169_bvh_soma/bvh_soma_to_g1.json")
    else {
        return;
    };
    let config = retarget::IkConfig::from_file(&config).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fk/tests/data/soma/soma_walk_excerpt.bvh");
    let bvh = bvh::from_path(&path).unwrap();
    let options = {
        let mut o = RetargetOptions::default();
        o.mode = SolveMode::Gmr;
        o
    };
    let retargeter = || {
        Retargeter::new("unitree_g1")
            .unwrap()
            .with_options(options.clone())
            .with_config(config.clone())
    };
    let human = retarget::load_bvh_gmr(&bvh, retarget::GmrBvhFormat::Soma).unwrap();
    let (theirs, _) = retargeter().retarget(&human).unwrap();
    let (mine, _) = retargeter().with_human_height(Some(1.70)).retarget_bvh(&bvh).unwrap();
    for f in 0..bvh.motion.num_frames {
        let (a, b) = (theirs.frame(f), mine.frame(f));
        let joints = max_difference(&a[7..], &b[7..]);
        // World (x, y) facing +X is (file z, file x); facing −Y it is (file x, −file z).
        let root = max_difference(&[a[1], -a[0], a[2]], &b[..3]);
        println!("frame {f}: joints differ by {joints:.1e} rad, the root by {root:.1e} m");
        // GMR's first frame starts from qpos0 facing +X: turned a quarter more, it ends 0.03
        // rad away; the next frames close the gap (×30 each).
        let tolerance = if f < 3 { 0.05 } else { 1e-6 };
        assert!(joints < tolerance && root < tolerance, "frame {f}: {joints:.1e}, {root:.1e}");
    }
}
