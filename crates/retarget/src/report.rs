//! Quality metrics of a robot motion: how well it tracked its targets, whether it respects
//! joint limits, how fast and how smooth the joints move, and how the feet meet the ground.
//!
//! Definitions (T frames at `fps`, Δt = 1/fps; all positions from forward kinematics):
//!
//! - **Statistics** `mean`, `p95`, `p99`, `max` are over frames; percentiles interpolate
//!   linearly between closest ranks (numpy's default `linear` method).
//! - **Tracking error** (when the motion has targets), per target body: position error
//!   `|xpos − target_pos|` (m) and rotation error, the angle of `xquat⁻¹ · target_quat` (rad,
//!   in [0, π]).
//! - **Joint limits**: a limited hinge or slide joint violates its range in a frame when
//!   `q < lo − tol` or `q > hi + tol` ([`ReportOptions::limit_tolerance`]); the count is over
//!   frames × joints, the excess is `max(lo − q, q − hi)`.
//! - **Joint velocity** `q̇` and **jitter**: `q̇` with numpy's `gradient` scheme (central
//!   differences inside, one-sided at the ends); jitter is the mean over interior frames of
//!   `|q[t+1] − 2 q[t] + q[t−1]| / Δt²` (rad/s² or m/s²). Hinge and slide joints only.
//! - **Feet**: the foot height `h` in a frame is the lowest point of the foot's primitive
//!   collision geoms (sphere, capsule, cylinder, ellipsoid, box on the foot body or its
//!   descendants) above the ground plane `z = ground_height`; for a foot without any, the
//!   lowest point of the uniform box with its mass and inertia (the planner's sole for such a
//!   foot, `feet::inertia_sole`), or the height of the foot body's origin when it has no
//!   inertial either. The foot's horizontal velocity `v` at frame t is that of its
//!   **contact point**: the point of the foot body that is lowest at frame t (the body origin
//!   without geoms), followed as a point fixed in the body over the frames around t (`gradient`
//!   scheme). A foot rolling over its heel or toes without slipping keeps that point still;
//!   its body origin moves, which the report counted as sliding until the default solve
//!   planted rolling feet. A frame is a **contact**
//!   frame when `h < contact_height` and `|v| < contact_speed`; a contact frame **slides** when
//!   `|v| > slide_speed`. The **sliding share** is sliding frames / contact frames. A **contact
//!   phase** is a maximal run of consecutive contact frames; its **sliding distance** is the
//!   horizontal path length of the contact point between consecutive frames of the phase
//!   (reported in cm, mean and max over phases). **Penetration** in a frame is `max(0, −h)`
//!   (cm).
//! - **Floating**: a frame floats when both feet have `h ≥ contact_height`; the floating
//!   height of a frame is `max(0, min(h_left, h_right))` (cm).
//! - **Root height**: z of the first body (the floating base), m.
//!
//! Metrics of the literature, as holosoma's evaluation code defines them (amazon-far/holosoma,
//! `src/holosoma_retargeting/holosoma_retargeting/evaluation/eval_retargeting.py`,
//! `RetargetingEvaluator.evaluate_penetration` and `detect_foot_sliding`; its later strict
//! variant `evaluation/metrics.py`, `foot_skating_metrics` and `summarize_penetration_depths`,
//! read in the public copies mstoelzle/holosoma@604e9d4 and Kisechan/holosoma@5757131):
//!
//! - **Ground penetration** over every collision geom of the robot (primitive geoms of
//!   non-world bodies with `contype` or `conaffinity` set), not only the feet: a frame's depth
//!   is `max(0, ground − lowest z)` over those geoms ([`mjcf::geom_lowest_point`]; holosoma asks
//!   `mj_geomDistance` against its ground plane, which is the same number). A frame
//!   **penetrates** when its depth exceeds [`ReportOptions::penetration_tolerance`] (1 cm,
//!   holosoma's `penetration_tolerance`, strict `>`); the **duration** is penetrating frames /
//!   frames; the **max depth** is over all frames.
//! - **Skating on the floor** (the robot's own contacts): per foot, over the frames whose
//!   foot height `h` (above) is below [`ReportOptions::floor_height`] (1 cm), the share in
//!   which the contact point (above, followed as a point of the foot) moves faster than
//!   [`ReportOptions::skate_speed`] ([`FootReport::floor_skating_share`]).
//! - **Skating** (needs the source's foot contacts): a foot's speed at frame t is
//!   `|xy[t] − xy[t−1]| · fps` of its toe point (`RobotFoot::toe_point`: the
//!   middle of the sole's front bottom edge; the body origin when the foot has no collision
//!   primitive), 0 at frame 0 (holosoma: backward
//!   differences with a leading 0). A foot **skates** in a frame when the source foot is in
//!   contact and its speed exceeds [`ReportOptions::skate_speed`] (0.3 m/s: holosoma's strict
//!   threshold; its legacy one is 0.01 m per frame at its 30 fps). The **duration** is frames
//!   with a skating foot / frames with a foot in source contact (holosoma counts frames, either
//!   foot, not foot samples); the **max speed** is over skating samples. Holosoma tracks a toe
//!   body (`*_ankle_roll_sphere_5_link` on its G1, a sphere at the front of the sole); the toe
//!   point is our equivalent on any robot (a foot rolling onto its toes keeps it still).
//! - **Stance** (needs the source's foot contacts; not in holosoma): over the foot × frame
//!   samples where the source foot is in contact, the share where the foot height `h` (above)
//!   is above [`ReportOptions::stance_float_height`] (2 cm: **floating in stance**) and the
//!   share with `h` within [`ReportOptions::sole_band`] ([−0.5, +1.0] cm).
//! - **Self-collision** (not in holosoma): over [`mjcf::Model::self_collision_pairs`]
//!   (MuJoCo's pairs between robot primitives, less the pairs of bodies adjacent through
//!   bodies without geoms and the pairs already touching or penetrating at `qpos0`: the
//!   model's own design; the solver keeps the same pairs apart), frames with any pair deeper
//!   than [`ReportOptions::self_collision_depth`] (1 cm), frames with any penetration, the
//!   largest depth and its pair ([`mjcf::geom_distance`]).
//! - **Joint speed over limit**: per hinge or slide joint with a published
//!   [`mjcf::Joint::velocity_limit`], frames × joints with `|q̇| > limit` (`q̇` as above) and the
//!   largest `|q̇| / limit`; `None` when no joint has a limit.
//!
//! Motion over time, the root included (issue 30):
//!
//! - **Root acceleration** ([`RootAcceleration`]): `p` the root body's world position (MuJoCo
//!   body 1, the floating base: the free joint's `qpos` translation), at the interior frames
//!   `a_t = (p[t+1] − 2 p[t] + p[t−1]) · fps²`; mean `|a|` (m/s²), the frames with
//!   `|a| > 2 g` (g = 9.81 m/s²) and their share of the interior frames, the max. The same
//!   for the scaled human's pelvis: the target position (`target_pos`) of the config's root
//!   body ([`ReportOptions::root_target`]: GMR's `robot_root_name`, the body the human's
//!   pelvis drives, which need not be the floating base: the T1's `Waist` under its `Trunk`),
//!   when the motion has targets; in a `--gmr` motion GMR's own pelvis target.
//! - **Jitter over every velocity coordinate** ([`Jitter`]; nv as MuJoCo counts them): the
//!   velocity between consecutive frames as `mj_differentiatePos` computes it,
//!   `v[t+½] = (q[t+1] ⊖ q[t]) · fps`: a free joint's translation `(p[t+1] − p[t]) · fps` in the
//!   world frame and its rotation `log(q[t]⁻¹ q[t+1]) · fps` (the rotation vector, the shorter
//!   way round) in the body frame; a ball joint's rotation the same; a hinge or slide joint
//!   `(q[t+1] − q[t]) · fps`. The acceleration at interior frame t is
//!   `(v[t+½] − v[t−½]) · fps` (for hinge and slide joints exactly the second difference
//!   above). A group's jitter is the mean of `|q̈_i|` over interior frames and the group's
//!   coordinates: **root translation** (3, m/s²), **root rotation** (3, rad/s²), **joints**
//!   (every other coordinate), and **all** nv coordinates together (units mixed). The
//!   per-joint `jitter` above stays as it was (hinge and slide joints only).
//! - **Dynamics check** ([`Dynamics`], per frame [`FrameDynamics`], [`dynamics_frames`];
//!   tunables [`DynamicsCheckOptions`]): inverse dynamics of the floating base at the centroidal
//!   level. Mass model: every body's [`mjcf::Body::inertial`] (mass `m_i`, centre of mass
//!   `x_i`, principal inertia `I_i` in the frame `R_i`); a body without inertial and without
//!   geoms is massless, as in MuJoCo; one with geoms but no inertial (MuJoCo would take its
//!   mass from them) makes the check **not available**, with that reason
//!   ([`QualityReport::dynamics_unavailable`]), as does a model without any mass. `m = Σ m_i`,
//!   `c = Σ m_i x_i / m`.
//!   - *Velocities* by central differences at the clip's rate (numpy's `gradient`), per body:
//!     `ẋ_i[t] = (x_i[t+1] − x_i[t−1]) · fps/2`, the world angular velocity
//!     `ω_i[t] = log(R_i[t+1] R_i[t−1]⁻¹) · fps/2`. The centroidal angular momentum
//!     `L_c[t] = Σ m_i (x_i − c) × ẋ_i + R_i I_i R_iᵀ ω_i`.
//!   - *Accelerations* by central differences of those: `c̈[t] = (c[t+2] − 2 c[t] + c[t−2]) ·
//!     fps²/4` and `L̇_c[t] = (L_c[t+1] − L_c[t−1]) · fps/2`. Each reads the 5 frames
//!     t−2..t+2 and is the centred average of the three-point rates at t−1, t, t+1 with
//!     weights ¼, ½, ¼ (for `c̈`: `(a[t−1] + 2 a[t] + a[t+1]) / 4`, `a` the second
//!     differences): the 5-frame centred average. Checked frames: 2..T−3.
//!   - *Needed wrench* about `c`: `W = (m (c̈ − g), L̇_c)`, `g = (0, 0, −9.81)` m/s²
//!     (standing still it is `(0, 0, m g)` and no torque).
//!   - *Contacts*: the bottom points of every collision geom (primitives with `contype` or
//!     `conaffinity`): a sphere's bottom, a capsule's bottom at each end, a box's eight
//!     corners, a cylinder's lowest rim point and four rim points (along its x and y) on each
//!     cap, an ellipsoid's bottom. A point is a contact at frame t when it is within
//!     [`DynamicsCheckOptions::contact_height`] (1 cm) of the floor (`z − ground < 1 cm`, below
//!     included) at t−1, t or t+1, the frames whose accelerations the average reads (a foot
//!     that leaves the floor at t pushed in the averaged rate); its position is the one at t.
//!   - *Forces*: at each contact point a force in the pyramid of
//!     [`DynamicsCheckOptions::cone_edges`] (8) edges inscribed in the friction cone
//!     `|f_t| ≤ μ f_z`, μ = [`DynamicsCheckOptions::friction`] (0.8): `f = Σ_j λ_j d_j`,
//!     `λ_j ≥ 0`, `d_j ∝ (μ cos 2πj/8, μ sin 2πj/8, 1)` (tangential friction at least
//!     `μ cos(π/8) = 0.92 μ` in every direction). The `λ` minimise the residual
//!     `‖W_n − Σ λ_j A_j‖` in the normalised units below (non-negative least squares,
//!     Lawson–Hanson).
//!   - *Residual* (m·g): force part `|F_res| / (m g)`, torque part (about `c`)
//!     `|τ_res| / (m g L)` with `L` ([`Dynamics::lever_m`]) the height of the centre of mass
//!     above the lowest collision point at `qpos0` (the robot standing; 1 m where that is not
//!     positive; G1 0.71 m, T1 0.63 m); the residual is `√(force² + torque²)`. Reported: its mean, p95
//!     and max over checked frames, the frames over [`DynamicsCheckOptions::threshold`] (0.1 m·g)
//!     and their share, the same over support frames (with a contact) alone.
//!   - *Centre of pressure*: in a support frame whose needed force pushes up by the threshold
//!     or more (`F_z ≥ 0.1 m g`; as `F_z` goes to 0 the point runs off to infinity),
//!     the needed wrench's zero-moment point on the floor `p` (where
//!     `τ + (c − p) × F` has no horizontal part) and its distance outside the convex hull of
//!     the contact points seen from above (a segment or a point with fewer; 0 inside); mean,
//!     p95, max (cm) and the frames outside by more than
//!     [`DynamicsCheckOptions::cop_tolerance`] (1 cm).
//!   - *Flight*: checked frames without any contact point. The needed wrench is all residual
//!     (a ballistic centre of mass and a constant `L_c` need none): mean, p95, max (m·g), the
//!     frames over the threshold and their share.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]
// Exception to `indexing_slicing`, justified: `report` checks the motion against the model before anything
// else (`check_motion`: nq, frames, names, target and contact lengths), so frame, joint,
// body and geom indices come from that model and motion, never unchecked from a file.
#![allow(clippy::indexing_slicing)]

use std::fmt;

use nalgebra::Vector3;

mod checks;
mod dynamics;
mod foot_metrics;
mod quality;
mod rates;
mod stats;
mod text;
mod verdict;

pub use checks::{Caps, Check, GmrCaps, Verdict};
pub use dynamics::{
    half_step, CentreOfPressure, Dynamics, DynamicsCheckOptions, Flight, FrameDynamics,
};
pub use quality::{
    BodyTracking, Floating, FootReport, GroundPenetration, JointLimits, JointMotion,
    JointSpeedReport, LimitViolation, QualityReport, Range, SelfCollision, Skating, Stance,
};
pub use rates::{AccelStats, AveragedAcceleration, Jitter, RootAcceleration, GRAVITY};
pub use stats::{percentile, Stats};

use crate::constraints::support_offset;
use crate::motion::RobotMotion;
use crate::writers::{body_poses, check_motion, gradient_pair, gradient_rows, BodyPoses};
use crate::Error;
use foot_metrics::{floating, foot_heights, foot_report, skating, stance};
use stats::{mean, ratio, scalar_joints, stats};

/// Tunables of [`report`]; see the module documentation for the definitions.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ReportOptions {
    /// Foot bodies `[left, right]`; `None`: the feet the default solve plants
    /// ([`crate::feet::detect_feet`]).
    pub feet: Option<[String; 2]>,
    /// Height of the ground plane (m). Default 0.
    pub ground_height: f64,
    /// Contact needs the foot's lowest point below this height (m). Default 0.03.
    pub contact_height: f64,
    /// Contact needs a horizontal foot speed below this (m/s). Default 1.0.
    pub contact_speed: f64,
    /// A contact frame slides above this horizontal foot speed (m/s). Default 0.1.
    pub slide_speed: f64,
    /// Joint speed limit to count frames against (rad/s or m/s), if any. Default none.
    pub joint_velocity_limit: Option<f64>,
    /// Slack before a joint counts as outside its range (rad or m). Default 1e-6.
    pub limit_tolerance: f64,
    /// A frame penetrates the ground when a collision geom is deeper than this (m). Default
    /// 0.01 (holosoma).
    pub penetration_tolerance: f64,
    /// A foot in source contact skates above this horizontal speed (m/s). Default 0.3
    /// (holosoma's strict threshold, 0.01 m per frame at 30 fps).
    pub skate_speed: f64,
    /// A foot whose sole is lower than this (m) is on the floor for
    /// [`FootReport::floor_skating_frames`]. Default 0.01 (the dynamics check's contact).
    pub floor_height: f64,
    /// A foot in source contact floats above this height (m). Default 0.02.
    pub stance_float_height: f64,
    /// Foot heights (m) counted as resting on the ground in source contact. Default
    /// [−0.005, 0.01].
    pub sole_band: [f64; 2],
    /// Self-collision frames count pairs deeper than this (m). Default 0.01.
    pub self_collision_depth: f64,
    /// Robot bodies whose position is a target (a non-zero position weight in the IK config:
    /// [`crate::IkConfig::position_targets`]); the others get no position error. `None`:
    /// every target body.
    pub position_targets: Option<Vec<String>>,
    /// The robot body whose target is the scaled human's pelvis, for
    /// [`RootAcceleration::target`]: the IK config's `robot_root_name` (GMR's root target;
    /// the T1's `Waist`, tracked to the human's hips, not its floating base `Trunk`, tracked
    /// to the chest). `None`: the motion's first target (GMR's configs, the shipped and the
    /// derived ones begin their match table with the root).
    pub root_target: Option<String>,
    /// The dynamics check's contacts, friction, thresholds and averaging time.
    pub dynamics: DynamicsCheckOptions,
    /// The verdict's caps.
    pub caps: Caps,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            feet: None,
            ground_height: 0.0,
            contact_height: 0.03,
            contact_speed: 1.0,
            slide_speed: 0.1,
            joint_velocity_limit: None,
            limit_tolerance: 1e-6,
            penetration_tolerance: 0.01,
            skate_speed: 0.3,
            floor_height: 0.01,
            stance_float_height: 0.02,
            sole_band: [-0.005, 0.01],
            self_collision_depth: 0.01,
            position_targets: None,
            root_target: None,
            dynamics: DynamicsCheckOptions::default(),
            caps: Caps::default(),
        }
    }
}

/// Computes the [`QualityReport`] of `motion` on `model` (the robot it was solved for).
pub fn report(
    motion: &RobotMotion,
    model: &mjcf::Model,
    opts: &ReportOptions,
) -> Result<QualityReport, Error> {
    check_motion(motion, model)?;
    if let Some(c) = &motion.contacts {
        let frames = motion.num_frames();
        if c.left.len() != frames || c.right.len() != frames {
            return Err(Error::Mismatch(format!(
                "foot contacts hold {} and {} frames, the motion {frames}",
                c.left.len(),
                c.right.len()
            )));
        }
    }
    let feet = match &opts.feet {
        Some([l, r]) => [named_body(model, l)?, named_body(model, r)?],
        None => crate::feet::detect_feet(model)?,
    };
    let poses = body_poses(motion, model);
    let frames = motion.num_frames();
    let heights = feet.map(|f| foot_heights(motion, model, f, opts.ground_height));
    let feet_reports: Vec<FootReport> = (0..2)
        .map(|i| {
            let (h, low, from) = &heights[i];
            foot_report(model, &poses, feet[i], h, low, *from, motion.fps, opts)
        })
        .collect();
    let root: Vec<f64> = (0..frames).map(|t| poses.pos(t, 0).z).collect();
    let (ground_penetration, self_collision, self_depth) = collisions(motion, model, opts);
    // Skating is measured at the toe point of the sole (holosoma: a toe body), else at the
    // foot body's origin.
    let toe = feet.map(|f| {
        crate::feet::RobotFoot::new(model, f, f, 0, None)
            .map_or(nalgebra::Vector3::zeros(), |r| r.toe_point())
    });
    let foot_xy: [Vec<nalgebra::Vector2<f64>>; 2] = std::array::from_fn(|i| {
        let b = feet[i] - 1;
        (0..frames).map(|t| (poses.pos(t, b) + (poses.quat(t, b) * toe[i])).xy()).collect()
    });
    let contacts = motion.contacts.as_ref().map(|c| [&c.left[..], &c.right[..]]);
    let h = half_step(motion.fps, opts.dynamics.span);
    let check = |half| match dynamics::check(
        motion,
        model,
        &poses,
        opts.ground_height,
        &opts.dynamics,
        half,
    ) {
        Ok(c) if c.frames.is_empty() => Err(format!("fewer than {} frames", 4 * c.half_step + 1)),
        Ok(c) => Ok(dynamics::summarise(&c, &opts.dynamics)),
        Err(reason) => Err(reason),
    };
    let (dynamics, dynamics_unavailable) = match check(Some(h)) {
        Ok(d) => (Some(d), None),
        Err(reason) => (None, Some(reason)),
    };
    let dynamics_5_frame = if h == 1 { dynamics.clone() } else { check(Some(1)).ok() };
    let mut rep = QualityReport {
        verdict: Verdict { ok: true, flags: Vec::new(), checks: Vec::new() },
        robot: model.name.clone(),
        frames,
        fps: motion.fps,
        tracking: tracking(motion, model, &poses, opts.position_targets.as_deref())?,
        joint_limits: joint_limits(motion, model, opts.limit_tolerance),
        joints: joint_motion(motion, model, opts.joint_velocity_limit),
        feet: feet_reports,
        floating: floating(&heights[0].0, &heights[1].0, opts.contact_height),
        root_height: range(&root),
        ground_penetration,
        self_collision,
        skating: contacts.map(|c| skating(&foot_xy, c, motion.fps, opts.skate_speed)),
        stance: contacts.map(|c| stance(&[&heights[0].0, &heights[1].0], c, opts)),
        joint_speed: joint_speed(motion, model),
        root_acceleration: rates::root_acceleration(
            motion,
            model,
            &poses,
            opts.root_target.as_deref(),
            h,
        ),
        jitter: rates::jitter(motion, model),
        dynamics,
        dynamics_unavailable,
        dynamics_5_frame,
    };
    let series = verdict::Series {
        feet: [&heights[0].0, &heights[1].0],
        self_depth: &self_depth,
        contact_height: opts.contact_height,
    };
    rep.verdict = verdict::verdict(&rep, motion, model, &series, &opts.caps);
    Ok(rep)
}

/// The dynamics check of every checked frame (frames 2h..T−1−2h, accelerations averaged over
/// [`DynamicsCheckOptions::span`]; module documentation), e.g. to find the frames behind
/// [`QualityReport::dynamics`]. An [`Error::NoMasses`] when the model's masses are not known.
pub fn dynamics_frames(
    motion: &RobotMotion,
    model: &mjcf::Model,
    opts: &ReportOptions,
) -> Result<Vec<FrameDynamics>, Error> {
    check_motion(motion, model)?;
    let poses = body_poses(motion, model);
    dynamics::check(motion, model, &poses, opts.ground_height, &opts.dynamics, None)
        .map(|c| c.frames)
        .map_err(Error::NoMasses)
}

/// Ground penetration of every collision geom and self-collision, in one pass of FK; and per
/// frame the deepest self-collision (m, 0 without any).
fn collisions(
    motion: &RobotMotion,
    model: &mjcf::Model,
    opts: &ReportOptions,
) -> (GroundPenetration, SelfCollision, Vec<f64>) {
    let geoms = crate::constraints::collision_primitives(model);
    let mut data = mjcf::Data::new(model);
    let selection = model.self_collision_pairs();
    let pairs = selection.pairs;
    let mut ground = GroundPenetration {
        geoms: geoms.len(),
        tolerance_cm: opts.penetration_tolerance * 100.0,
        frames: 0,
        duration: 0.0,
        max_depth_cm: 0.0,
        worst_geom: None,
    };
    let mut own = SelfCollision {
        pairs: pairs.len(),
        ignored_pairs: selection.touching_at_rest.len(),
        adjacent_pairs: selection.adjacent.len(),
        deep_cm: opts.self_collision_depth * 100.0,
        frames_deep: 0,
        frames_penetrating: 0,
        max_depth_cm: 0.0,
        worst_pair: None,
    };
    let (mut worst_geom, mut worst_pair) = (None, None);
    let mut self_depth = Vec::with_capacity(motion.num_frames());
    for t in 0..motion.num_frames() {
        model.kinematics(motion.frame(t), &mut data);
        let mut depth = 0.0f64;
        for &g in &geoms {
            let Some(low) = mjcf::geom_lowest_point(model, &data, g) else { continue };
            let d = opts.ground_height - low.z;
            depth = depth.max(d);
            if d * 100.0 > ground.max_depth_cm {
                (ground.max_depth_cm, worst_geom) = (d * 100.0, Some(g));
            }
        }
        ground.frames += usize::from(depth > opts.penetration_tolerance);
        let mut deepest = None::<f64>;
        for &[g1, g2] in &pairs {
            let Some(p) = mjcf::geom_distance(model, &data, g1, g2, 0.0) else { continue };
            if p.distance >= 0.0 {
                continue;
            }
            deepest = Some(deepest.unwrap_or(0.0).max(-p.distance));
            if -p.distance * 100.0 > own.max_depth_cm {
                (own.max_depth_cm, worst_pair) = (-p.distance * 100.0, Some([g1, g2]));
            }
        }
        self_depth.push(deepest.unwrap_or(0.0));
        own.frames_penetrating += usize::from(deepest.is_some());
        own.frames_deep += usize::from(deepest.is_some_and(|d| d > opts.self_collision_depth));
    }
    ground.duration = ratio(ground.frames, motion.num_frames());
    ground.worst_geom = worst_geom.map(|g| model.geom_label(g));
    own.worst_pair = worst_pair.map(|[a, b]| [model.geom_label(a), model.geom_label(b)]);
    (ground, own, self_depth)
}

fn joint_speed(motion: &RobotMotion, model: &mjcf::Model) -> Option<JointSpeedReport> {
    let mut out: Option<JointSpeedReport> = None;
    for (j, a) in scalar_joints(model) {
        let Some(limit) = model.joints[j].velocity_limit.filter(|l| *l > 0.0) else { continue };
        let q: Vec<f64> = (0..motion.num_frames()).map(|t| motion.frame(t)[a]).collect();
        let speed = gradient_rows(&q, 1, 1.0 / motion.fps);
        let over = speed.iter().filter(|v| v.abs() > limit).count();
        let ratio = speed.iter().fold(0.0f64, |m, v| m.max(v.abs() / limit));
        let entry = out.get_or_insert_with(|| JointSpeedReport {
            joints: 0,
            violations: 0,
            worst_ratio: 0.0,
            worst_joint: String::new(),
        });
        entry.joints += 1;
        entry.violations += over;
        if ratio > entry.worst_ratio || entry.worst_joint.is_empty() {
            (entry.worst_ratio, entry.worst_joint) = (ratio, model.joints[j].name.clone());
        }
    }
    out
}

fn named_body(model: &mjcf::Model, name: &str) -> Result<usize, Error> {
    model
        .body_id(name)
        .filter(|&b| b > 0)
        .ok_or_else(|| Error::NoSuchBody { name: name.to_owned() })
}

fn tracking(
    motion: &RobotMotion,
    model: &mjcf::Model,
    poses: &BodyPoses,
    position_targets: Option<&[String]>,
) -> Result<Option<Vec<BodyTracking>>, Error> {
    let Some(targets) = &motion.targets else { return Ok(None) };
    let k = targets.body_names.len();
    let mut out = Vec::with_capacity(k);
    for (j, name) in targets.body_names.iter().enumerate() {
        let b = named_body(model, name)? - 1;
        let (mut pos, mut rot) = (Vec::new(), Vec::new());
        for t in 0..motion.num_frames() {
            pos.push((poses.pos(t, b) - targets.pos[t * k + j]).norm());
            rot.push(poses.quat(t, b).angle_to(&targets.quat[t * k + j]));
        }
        let tracked = position_targets.is_none_or(|names| names.contains(name));
        let pos_m = tracked.then(|| stats(&pos));
        out.push(BodyTracking { body: name.clone(), pos_m, rot_rad: stats(&rot) });
    }
    Ok(Some(out))
}

fn joint_limits(motion: &RobotMotion, model: &mjcf::Model, tol: f64) -> JointLimits {
    let mut joints = Vec::new();
    for (j, a) in scalar_joints(model) {
        let Some([lo, hi]) = model.joints[j].range else { continue };
        let excess: Vec<f64> = (0..motion.num_frames())
            .map(|t| {
                let q = motion.frame(t)[a];
                (lo - q).max(q - hi)
            })
            .filter(|e| *e > tol)
            .collect();
        if !excess.is_empty() {
            joints.push(LimitViolation {
                joint: model.joints[j].name.clone(),
                frames: excess.len(),
                max_excess: excess.iter().copied().fold(0.0, f64::max),
            });
        }
    }
    JointLimits {
        violations: joints.iter().map(|v| v.frames).sum(),
        max_excess: joints.iter().map(|v| v.max_excess).fold(0.0, f64::max),
        joints,
    }
}

fn joint_motion(motion: &RobotMotion, model: &mjcf::Model, limit: Option<f64>) -> Vec<JointMotion> {
    let frames = motion.num_frames();
    scalar_joints(model)
        .map(|(j, a)| {
            let q: Vec<f64> = (0..frames).map(|t| motion.frame(t)[a]).collect();
            let speed: Vec<f64> =
                gradient_rows(&q, 1, 1.0 / motion.fps).iter().map(|v| v.abs()).collect();
            let acc: Vec<f64> = q
                .windows(3)
                .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs() * motion.fps * motion.fps)
                .collect();
            JointMotion {
                joint: model.joints[j].name.clone(),
                vel_p99: percentile(&speed, 0.99),
                vel_max: speed.iter().copied().fold(0.0, f64::max),
                vel_over_limit: limit.map_or(0, |l| speed.iter().filter(|s| **s > l).count()),
                jitter: mean(&acc),
            }
        })
        .collect()
}

fn range(x: &[f64]) -> Range {
    Range {
        min: x.iter().copied().fold(f64::INFINITY, f64::min),
        mean: mean(x),
        max: x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    }
}
