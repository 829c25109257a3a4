//! SMPL-X and SMPL+H motions (AMASS and the datasets in its format): the config choice and
//! the solve, in both modes.
//!
//! - **Config**: the one given (bound to the body when role-named); else the shipped
//!   robot's SMPL-X config (GMR's `smplx_to_*.json`, [`crate::shipped::smplx_config`]):
//!   every SMPL-X and SMPL+H body model has smplx's joint names and the same joint frames
//!   (the template's T-pose, Y up, facing +Z), which those configs are written for, so they
//!   fit any SMPL source, unless the default solve finds it contradicting the robot's joint
//!   frames ([`crate::derive::contradiction`]); else one derived from the robot's roles and
//!   the body's ([`crate::derive::derive`]).
//! - **Default solve**: the body model's FK at the file's rate ([`smpl::clip`]), its
//!   recognised roles (the contacts read the `foot` and `toe` roles: `left_ankle`,
//!   `left_foot`), the model's stature as the subject height.
//! - **`--gmr`**: GMR's SMPL-X path exactly: its loader ([`smpl::gmr::offline_fast`]:
//!   float32 parameters, jaw/eyes/hands zero, 30 fps as `get_smplx_data_offline_fast`
//!   resamples), its subject height `1.66 + 0.1 β₀`, and its `smplx_to_robot.py`, which
//!   retargets from the second resampled frame on (`i += 1` before the first use).

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use fk::HumanMotion;
use mjcf::Model;
use smpl::{BodyModel, SmplMotion};

use crate::config::IkConfig;
use crate::derive::{Choice, Chosen, HumanBody};
use crate::motion::RobotMotion;
use crate::robot_roles::RobotRoles;
use crate::solve::{ClipDiagnostics, SubjectHeight};
use crate::{Error, Retargeter};

/// The first frame `--gmr` retargets: GMR's `smplx_to_robot.py` starts at frame 1.
pub const GMR_FIRST_FRAME: usize = 1;

/// The config for an SMPL clip (module docs); `robot` names the robot in messages.
pub fn choose(
    model: &Model,
    robot: &str,
    clip: &smpl::Clip,
    given: Option<IkConfig>,
    tuned: Option<&IkConfig>,
    gmr: bool,
) -> Result<Chosen, Error> {
    let names = &clip.human.body_names;
    if let Some(config) = given {
        if !crate::derive::is_role_named(&config) {
            let summary = format!("config {} as given", config.source);
            return Ok(Chosen { config, choice: Choice::Given, summary });
        }
        let roles = RobotRoles::recognise(model)?;
        let bound = crate::derive::bind(&config, &human_body(clip)?, model, &roles)?;
        let summary = format!("config {} (role-named), bound to the body model", config.source);
        return Ok(Chosen { config: bound, choice: Choice::Bound, summary });
    }
    let tuned = tuned.filter(|t| t.validate(model, names).is_ok());
    let take = |tuned: &IkConfig| {
        let summary = format!("config {} (tuned: SMPL joint names and frames)", tuned.source);
        Ok(Chosen { config: tuned.clone(), choice: Choice::Tuned, summary })
    };
    // `--gmr` takes GMR's config as GMR does.
    if let (Some(tuned), true) = (tuned, gmr) {
        return take(tuned);
    }
    let roles = RobotRoles::recognise(model)?;
    let source = format!("<derived for {robot}>");
    let derived = crate::derive::derive(model, &roles, &human_body(clip)?, &source)?;
    let mut why_not = String::new();
    if let Some(tuned) = tuned {
        match crate::derive::contradiction(tuned, &derived, &roles) {
            None => return take(tuned),
            Some(c) => why_not = format!(" (not the tuned {}: {c})", tuned.source),
        }
    }
    let summary =
        format!("config derived from the roles of {robot} and of the body model{why_not}");
    Ok(Chosen { config: derived, choice: Choice::Derived, summary })
}

fn human_body(clip: &smpl::Clip) -> Result<HumanBody, Error> {
    HumanBody::from_motion(&clip.humanoid, &clip.human, clip.ground, clip.height, "the body model")
}

/// Frames `from..` of `human`.
#[must_use]
pub fn frames_from(human: &HumanMotion, from: usize) -> HumanMotion {
    let nb = human.num_bodies();
    let start = (from * nb).min(human.positions.len());
    HumanMotion {
        fps: human.fps,
        body_names: human.body_names.clone(),
        num_frames: human.num_frames.saturating_sub(from),
        positions: human.positions.get(start..).unwrap_or_default().to_vec(),
        orientations: human.orientations.get(start..).unwrap_or_default().to_vec(),
    }
}

impl Retargeter {
    /// The config an SMPL clip is retargeted with, and why.
    pub fn choose_smpl_config(&self, clip: &smpl::Clip) -> Result<Chosen, Error> {
        let gmr = crate::solve::Pipeline::new(self.options()).is_gmr();
        let (given, tuned) = (self.given_config().cloned(), self.smplx_config());
        choose(self.model(), self.label(), clip, given, tuned, gmr)
    }

    /// Retargets an SMPL-X or SMPL+H motion posed with `body` (module docs: what each mode
    /// does). `diag.human_inferred` ends with the config used.
    pub fn retarget_smpl(
        &self,
        motion: &SmplMotion,
        body: &BodyModel,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let in_file = |e: Error| Error::InFile {
            path: motion.source.display().to_string(),
            source: Box::new(e),
        };
        let clip = smpl::clip(body, motion).map_err(|e| in_file(e.into()))?;
        let chosen = self.choose_smpl_config(&clip).map_err(in_file)?;
        self.retarget_smpl_with(motion, body, &clip, &chosen)
    }

    /// [`Retargeter::retarget_smpl`] with the clip posed ([`smpl::clip`]) and the config
    /// chosen ([`Retargeter::choose_smpl_config`]) already.
    pub fn retarget_smpl_with(
        &self,
        motion: &SmplMotion,
        body: &BodyModel,
        clip: &smpl::Clip,
        chosen: &Chosen,
    ) -> Result<(RobotMotion, ClipDiagnostics), Error> {
        let in_file = |e: Error| Error::InFile {
            path: motion.source.display().to_string(),
            source: Box::new(e),
        };
        let gmr = crate::solve::Pipeline::new(self.options()).is_gmr();
        let options = self.options();
        let (human, height) = if gmr {
            let resampled = smpl::gmr::offline_fast(body, motion, smpl::conventions::GMR_FPS)
                .map_err(|e| in_file(e.into()))?;
            let human = frames_from(&resampled, GMR_FIRST_FRAME);
            let metres = smpl::conventions::gmr_height(&motion.betas);
            (human, SubjectHeight { metres, source: "GMR's 1.66 + 0.1 · betas[0]".to_owned() })
        } else {
            let source = clip.height_source.clone();
            (clip.human.clone(), SubjectHeight { metres: clip.height, source })
        };
        let height = options.human_height.map_or(height, SubjectHeight::given);
        // The source's feet for the contact phases (both modes write them), by role.
        let roles = crate::solve::source_roles(&options.fk.roles, clip.roles());
        if human.num_frames == 0 {
            let note = if gmr { " (GMR's path skips the first resampled frame)" } else { "" };
            return Err(in_file(Error::TooFewFrames { frames: 0, needed: 1, note }));
        }
        let (robot, mut diag) = crate::solve::solve_clip(
            &human,
            self.model(),
            &chosen.config,
            options,
            &height,
            &roles,
        )
        .map_err(in_file)?;
        diag.human_inferred = format!(
            "{} body model ({} joints), Z up, metres, {} fps; {}",
            body.kind,
            body.num_joints(),
            motion.fps,
            chosen.summary
        ) + if gmr { "; --gmr" } else { "" };
        Ok((robot, diag))
    }
}
