//! Joint speed limits of a robot, from a `joint_speed_limits.json` beside its model (MJCF has
//! no attribute for them; URDF's `<limit velocity>` is read by `mjcf` directly):
//!
//! ```json
//! { "unit": "rad/s", "source": "where the numbers come from",
//!   "default": 20, "joints": { "left_knee_joint": 20, ... } }
//! ```
//!
//! `default` (a number or `null`) applies to every hinge and slide joint not listed in
//! `joints`. The limits end up in [`mjcf::Joint::velocity_limit`], where the solver and the
//! report read them.

#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::collections::BTreeMap;

use mjcf::{JointType, Model};
use serde::Deserialize;

use crate::Error;

/// A parsed `joint_speed_limits.json`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSpeedLimits {
    /// Only `rad/s` (m/s for slide joints) is accepted.
    pub unit: String,
    /// Where the numbers come from.
    pub source: String,
    pub default: Option<f64>,
    pub joints: BTreeMap<String, f64>,
}

impl JointSpeedLimits {
    /// Parses the JSON text; `origin` names it in errors (a path or `<string>`).
    pub fn from_json_str(text: &str, origin: &str) -> Result<JointSpeedLimits, Error> {
        let limits: JointSpeedLimits = serde_json::from_str(text).map_err(|e| Error::Config {
            at: format!("{origin}:{}:{}", e.line(), e.column()),
            message: e.to_string(),
        })?;
        let bad = |what: String| Error::Config { at: origin.to_owned(), message: what };
        if limits.unit != "rad/s" {
            return Err(bad(format!("unit must be \"rad/s\", not \"{}\"", limits.unit)));
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if let Some((name, v)) = limits.joints.iter().find(|(_, v)| !positive(**v)) {
            return Err(bad(format!("speed limit of `{name}` must be a positive number, not {v}")));
        }
        if limits.default.is_some_and(|v| !positive(v)) {
            return Err(bad("`default` must be a positive number or null".to_owned()));
        }
        Ok(limits)
    }

    /// Sets [`mjcf::Joint::velocity_limit`] of the hinge and slide joints of `model`: the
    /// listed ones, else the default (a limit already in the model, e.g. from a URDF, is
    /// replaced only by a listed one). A listed joint the model lacks is an error.
    pub fn apply(&self, model: &mut Model, origin: &str) -> Result<(), Error> {
        if let Some(name) = self.joints.keys().find(|n| model.joint_id(n).is_none()) {
            return Err(Error::Config {
                at: origin.to_owned(),
                message: format!("joint `{name}` is not a joint of robot `{}`", model.name),
            });
        }
        for joint in &mut model.joints {
            if !matches!(joint.kind, JointType::Hinge | JointType::Slide) {
                continue;
            }
            if let Some(v) = self.joints.get(&joint.name) {
                joint.velocity_limit = Some(*v);
            } else if joint.velocity_limit.is_none() {
                joint.velocity_limit = self.default;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const XML: &str = r#"<mujoco model="two"><worldbody><body><freejoint/><geom size="0.1"/>
      <body name="a"><joint name="ja" range="-1 1"/><geom size="0.1"/>
        <body name="b"><joint name="jb"/><geom size="0.1"/></body></body>
    </body></worldbody></mujoco>"#;

    #[test]
    fn listed_joints_and_the_default() {
        let mut model = Model::from_xml_str(XML, None).unwrap();
        let text = r#"{"unit": "rad/s", "source": "test", "default": 7, "joints": {"ja": 3}}"#;
        JointSpeedLimits::from_json_str(text, "t.json").unwrap().apply(&mut model, "t").unwrap();
        let limit = |n: &str| model.joints[model.joint_id(n).unwrap()].velocity_limit;
        assert_eq!((limit("ja"), limit("jb")), (Some(3.0), Some(7.0)));
        assert_eq!(model.joints[0].velocity_limit, None, "the free joint has none");
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let err = |text: &str| JointSpeedLimits::from_json_str(text, "t.json").unwrap_err();
        let e = err(r#"{"unit": "deg/s", "source": "", "default": null, "joints": {}}"#);
        assert!(e.to_string().contains("t.json: unit must be \"rad/s\""), "{e}");
        let e = err(r#"{"unit": "rad/s", "source": "", "default": null, "joints": {"a": -1}}"#);
        assert!(e.to_string().contains("`a` must be a positive number"), "{e}");
        let e = err("{\"unit\": \"rad/s\",\n \"oops\": 1}");
        assert!(e.to_string().starts_with("t.json:2:"), "{e}");
        let mut model = Model::from_xml_str(XML, None).unwrap();
        let limits = JointSpeedLimits::from_json_str(
            r#"{"unit": "rad/s", "source": "", "default": null, "joints": {"knee": 3}}"#,
            "t.json",
        )
        .unwrap();
        let e = limits.apply(&mut model, "t.json").unwrap_err();
        assert!(e.to_string().contains("joint `knee` is not a joint of robot `two`"), "{e}");
    }
}
