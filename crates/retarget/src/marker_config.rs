//! C3D marker files → [`HumanMotion`]: the marker part of a marker-driven IK config (keys that
//! the IK config itself ignores: `marker_bodies`, `source_axes`, `marker_units_m`,
//! `marker_height`, `subject_height_m`) and the glue from a parsed [`c3d::C3d`] to
//! [`fk::markers::marker_motion`] and the subject height.
//!
//! The C3D bytes are parsed by the `c3d` crate; the virtual bodies are built by `fk`.
//! Example: `configs/c3d_plugingait_to_unitree_g1.json`.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::path::Path;

use fk::markers::MarkerBody;
use fk::HumanMotion;
use serde_json::Value;

use crate::solve::SubjectHeight;
use crate::Error;

/// The marker part of a marker-driven IK config.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerConfig {
    /// Where it came from, for messages.
    pub source: String,
    pub bodies: Vec<MarkerBody>,
    /// `source_axes` (checked: `z-up` or `y-up`; default `z-up`).
    pub axes: String,
    /// `marker_units_m` (default 0.001: millimetres).
    pub metres_per_unit: f64,
    /// `marker_height`: top markers, bottom markers, and the fraction of the stature the top
    /// markers stand at.
    pub height: Option<MarkerHeight>,
    /// `subject_height_m`, when the config fixes it.
    pub subject_height: Option<f64>,
}

/// Landmarks for the subject height: the top markers stand at `fraction_of_stature` of the
/// stature above the bottom markers.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerHeight {
    pub top: Vec<String>,
    pub bottom: Vec<String>,
    pub fraction_of_stature: f64,
}

/// A C3D clip as the retargeter sees it: the virtual bodies' motion and the subject height.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerMotion {
    pub human: HumanMotion,
    /// The subject height and where it came from (`given`, `config subject_height_m`,
    /// `markers ...`).
    pub height: SubjectHeight,
}

impl MarkerConfig {
    /// Reads the marker part of the config file at `path`.
    pub fn from_file(path: &Path) -> Result<MarkerConfig, Error> {
        let source = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Io { path: source.clone(), source: e })?;
        MarkerConfig::from_json_str(&text, &source)
    }

    /// Parses the marker part of a config; `source` names it in messages.
    pub fn from_json_str(text: &str, source: &str) -> Result<MarkerConfig, Error> {
        let json: Value = serde_json::from_str(text).map_err(|e| Error::Config {
            at: format!("{source}:{}:{}", e.line(), e.column()),
            message: e.to_string(),
        })?;
        let bad = |key: &str, message: &str| Error::Config {
            at: format!("{source}: `{key}`"),
            message: message.to_owned(),
        };
        let table = json
            .get("marker_bodies")
            .and_then(Value::as_object)
            .ok_or_else(|| bad("marker_bodies", "a marker config needs `marker_bodies`"))?;
        let mut bodies = Vec::new();
        for (name, def) in table {
            let key = format!("{name}.markers");
            let markers =
                labels(def.get("markers").ok_or_else(|| bad(&key, "missing"))?, &key, source)?;
            let frame = match def.get("frame") {
                None | Some(Value::Null) => None,
                Some(v) => {
                    let key = format!("{name}.frame");
                    let [a, b, c]: [String; 3] = labels(v, &key, source)?
                        .try_into()
                        .map_err(|_| bad(&key, "needs exactly three markers"))?;
                    Some([a, b, c])
                }
            };
            bodies.push(MarkerBody { name: name.clone(), markers, frame });
        }
        let axes = json.get("source_axes").and_then(Value::as_str).unwrap_or("z-up").to_owned();
        if fk::markers::axes_rotation(&axes).is_none() {
            return Err(bad("source_axes", &format!("`{axes}`: expected \"z-up\" or \"y-up\"")));
        }
        let metres_per_unit = json.get("marker_units_m").and_then(Value::as_f64).unwrap_or(0.001);
        let height = match json.get("marker_height") {
            None => None,
            Some(h) => {
                let list = |key: &str| -> Result<Vec<String>, Error> {
                    let full = format!("marker_height.{key}");
                    labels(h.get(key).ok_or_else(|| bad(&full, "missing"))?, &full, source)
                };
                let fraction = h
                    .get("fraction_of_stature")
                    .and_then(Value::as_f64)
                    .ok_or_else(|| bad("marker_height.fraction_of_stature", "expected a number"))?;
                Some(MarkerHeight {
                    top: list("top")?,
                    bottom: list("bottom")?,
                    fraction_of_stature: fraction,
                })
            }
        };
        let subject_height = json.get("subject_height_m").and_then(Value::as_f64);
        Ok(MarkerConfig {
            source: source.to_owned(),
            bodies,
            axes,
            metres_per_unit,
            height,
            subject_height,
        })
    }

    /// The virtual bodies' motion of a parsed C3D file and the subject height: `human_height`
    /// when given, else the config's `subject_height_m`, else measured from `marker_height`.
    /// `name` names the file in messages.
    pub fn motion(
        &self,
        file: &c3d::C3d,
        name: &str,
        human_height: Option<f64>,
    ) -> Result<MarkerMotion, Error> {
        let (labels, frames) = labelled_points(file);
        let fps = f64::from(file.point_rate());
        let axes = fk::markers::axes_rotation(&self.axes).ok_or_else(|| Error::Config {
            at: format!("{}: `source_axes`", self.source),
            message: format!("`{}`: expected \"z-up\" or \"y-up\"", self.axes),
        })?;
        let in_file = |e: Error| Error::InFile { path: name.to_owned(), source: Box::new(e) };
        let marker_error =
            |what: &str, source| Error::Markers { context: format!("{name}: {what}"), source };
        let human = fk::markers::marker_motion(
            &labels,
            &frames,
            fps,
            self.metres_per_unit,
            &axes,
            &self.bodies,
        )
        .map_err(|e| marker_error("marker bodies", e))?;
        let height = if let Some(h) = human_height {
            SubjectHeight::given(h)
        } else if let Some(h) = self.subject_height {
            SubjectHeight { metres: h, source: "config subject_height_m".to_owned() }
        } else if let Some(m) = &self.height {
            let above = fk::markers::marker_height(
                &labels,
                &frames,
                self.metres_per_unit,
                &axes,
                &m.top,
                &m.bottom,
            )
            .map_err(|e| marker_error("subject height", e))?;
            let fraction = m.fraction_of_stature;
            let source = format!("markers {} at {fraction} of stature", m.top.join("+"));
            SubjectHeight { metres: above / fraction, source }
        } else {
            let why = "none given, and the config has no `marker_height`".to_owned();
            return Err(in_file(Error::SubjectHeight { why }));
        };
        if !(height.metres.is_finite() && height.metres > 0.0) {
            let why = format!("{} m ({}) is not positive", height.metres, height.source);
            return Err(in_file(Error::SubjectHeight { why }));
        }
        Ok(MarkerMotion { human, height })
    }
}

/// A JSON list of marker labels.
fn labels(v: &Value, key: &str, source: &str) -> Result<Vec<String>, Error> {
    let bad = || Error::Config {
        at: format!("{source}: `{key}`"),
        message: "expected a list of marker labels".to_owned(),
    };
    v.as_array()
        .ok_or_else(bad)?
        .iter()
        .map(|m| m.as_str().map(str::to_owned).ok_or_else(bad))
        .collect()
}

/// Per frame and point, a point's position in file units (`None` where it is invalid).
pub type PointFrames = Vec<Vec<Option<[f64; 3]>>>;

/// A C3D file's point labels (trimmed) and their positions (`PointFrames`: per frame, per label).
#[must_use]
pub fn labelled_points(file: &c3d::C3d) -> (Vec<String>, PointFrames) {
    let labels: Vec<String> = file.point_labels().iter().map(|l| l.trim().to_owned()).collect();
    let frames = (0..file.points.frame_count())
        .map(|f| {
            (0..labels.len())
                .map(|p| file.points.get(f, p).map(|pt| pt.position.map(f64::from)))
                .collect()
        })
        .collect();
    (labels, frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_plugin_gait_config_parses() {
        let text = include_str!("../../../configs/c3d_plugingait_to_unitree_g1.json");
        let config =
            MarkerConfig::from_json_str(text, "c3d_plugingait_to_unitree_g1.json").unwrap();
        assert_eq!(config.bodies.len(), 8);
        assert_eq!(config.axes, "z-up");
        assert_eq!(config.metres_per_unit, 0.001);
        let height = config.height.unwrap();
        assert_eq!(height.top, ["LASI", "RASI"]);
        assert_eq!(height.fraction_of_stature, 0.555);
        let pelvis = &config.bodies.iter().find(|b| b.name == "Pelvis").unwrap();
        assert!(pelvis.frame.is_some());
    }

    #[test]
    fn bad_marker_configs_name_the_key() {
        let err = MarkerConfig::from_json_str("{}", "m.json").unwrap_err().to_string();
        assert_eq!(err, "m.json: `marker_bodies`: a marker config needs `marker_bodies`");
        let text = r#"{"marker_bodies": {"Pelvis": {"markers": ["A"], "frame": ["A", "B"]}}}"#;
        let err = MarkerConfig::from_json_str(text, "m.json").unwrap_err().to_string();
        assert_eq!(err, "m.json: `Pelvis.frame`: needs exactly three markers");
        let text = r#"{"marker_bodies": {}, "source_axes": "x-up"}"#;
        let err = MarkerConfig::from_json_str(text, "m.json").unwrap_err().to_string();
        assert!(err.contains("expected \"z-up\" or \"y-up\""), "{err}");
    }
}
