//! IK configs in GMR's JSON schema, read unchanged.
//!
//! ```json
//! { "robot_root_name": "pelvis", "human_root_name": "Hips", "ground_height": 0.0,
//!   "human_height_assumption": 1.8, "use_ik_match_table1": true, "use_ik_match_table2": true,
//!   "human_scale_table": { "Hips": 0.9, ... },
//!   "ik_match_table1": { "pelvis": ["Hips", 0, 10, [0, 0, 0], [0.5, 0.5, 0.5, 0.5]], ... },
//!   "ik_match_table2": { ... } }
//! ```
//!
//! Table order is kept as written (it decides the order of the tasks and so the
//! floating-point sums of the solver); configs we write ([`crate::derive`]) are laid out as
//! GMR's files are, one table row a line. Syntax and type errors carry `file:line:column` from
//! serde_json; names that exist in neither the robot nor the human skeleton are reported by
//! [`IkConfig::validate`] with the position of the name in the file and the nearest names.

// No panics on input (issue 15); tests may (clippy.toml).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::fmt;
use std::path::Path;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};

use crate::Error;

/// One row of an IK match table: the robot body `robot_body` tracks `human_body`.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchEntry {
    pub robot_body: String,
    pub human_body: String,
    pub pos_weight: f64,
    pub rot_weight: f64,
    /// Position offset in the (rotated) human body frame, metres.
    pub pos_offset: Vector3<f64>,
    /// Rotation offset, applied on the right of the human body orientation. Stored as written
    /// (GMR does not normalise it beyond what scipy does; see the crate's `targets`).
    pub rot_offset: UnitQuaternion<f64>,
}

impl MatchEntry {
    /// GMR creates a task only when one of the weights is non-zero.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.pos_weight != 0.0 || self.rot_weight != 0.0
    }
}

/// A parsed IK config (GMR schema). Tables keep the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct IkConfig {
    /// Where the config came from (file path or `<string>`), for messages.
    pub source: String,
    /// Stored only, as in GMR (the floating base is always the model's free joint).
    pub robot_root_name: String,
    pub human_root_name: String,
    pub ground_height: f64,
    pub human_height_assumption: f64,
    pub use_ik_match_table1: bool,
    pub use_ik_match_table2: bool,
    /// Human body → scale, in file order.
    pub human_scale_table: Vec<(String, f64)>,
    pub ik_match_table1: Vec<MatchEntry>,
    pub ik_match_table2: Vec<MatchEntry>,
    /// The JSON text, kept to locate names in error messages.
    text: String,
}

/// A config file as GMR's schema writes it: what [`IkConfig::from_json_str`] reads and
/// [`IkConfig::from_file_form`] writes, fields in GMR's order.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ConfigFile {
    pub(crate) robot_root_name: String,
    pub(crate) human_root_name: String,
    pub(crate) ground_height: f64,
    pub(crate) human_height_assumption: f64,
    pub(crate) use_ik_match_table1: bool,
    pub(crate) use_ik_match_table2: bool,
    pub(crate) human_scale_table: Ordered<f64>,
    pub(crate) ik_match_table1: Ordered<FileEntry>,
    pub(crate) ik_match_table2: Ordered<FileEntry>,
    /// GMR reads it (initial joint values); accepted, not used yet.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) robot_initial_qpos: Option<serde_json::Value>,
    /// GMR's mink collision-avoidance limit (`xsens_mvn_to_g1.json`: `enabled`,
    /// `min_distance`, `detection_distance`, `self_collision_pairs`): accepted, not used.
    /// GMR's own file has it disabled; our default solve keeps every collision pair apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) collision_avoidance: Option<serde_json::Value>,
    /// Marker-driven configs (`retarget --c3d`): read by the CLI, ignored here.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) marker_bodies: Option<serde_json::Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) source_axes: Option<serde_json::Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) marker_units_m: Option<serde_json::Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) marker_height: Option<serde_json::Value>,
}

/// A table row as written: `"body": ["joint", pos_weight, rot_weight, [x, y, z], [w, x, y, z]]`.
pub(crate) type FileEntry = (String, f64, f64, [f64; 3], [f64; 4]);

/// A JSON object as a list of pairs in file order (duplicate keys are an error when read).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Ordered<T>(pub(crate) Vec<(String, T)>);

impl<T: Serialize> Serialize for Ordered<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (key, value) in &self.0 {
            map.serialize_entry(key, value)?;
        }
        map.end()
    }
}

impl<T> Ordered<T> {
    /// The first key that occurs twice.
    fn duplicate(&self) -> Option<&str> {
        let keys = self.0.iter().map(|(k, _)| k.as_str());
        keys.clone()
            .enumerate()
            .find_map(|(i, k)| keys.clone().take(i).any(|o| o == k).then_some(k))
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Ordered<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = Ordered<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut out: Vec<(String, T)> = Vec::new();
                while let Some((key, value)) = map.next_entry::<String, T>()? {
                    if out.iter().any(|(k, _)| *k == key) {
                        return Err(de::Error::custom(format!("duplicate key `{key}`")));
                    }
                    out.push((key, value));
                }
                Ok(Ordered(out))
            }
        }
        deserializer.deserialize_map(V(std::marker::PhantomData))
    }
}

impl IkConfig {
    /// Reads a config file. Errors name the file and `line:column`.
    pub fn from_file(path: &Path) -> Result<IkConfig, Error> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| Error::Io { path: path.display().to_string(), source })?;
        Self::from_json_str(&text, &path.display().to_string())
    }

    /// Parses config text; `source` names it in errors (a path, or e.g. `<embedded>`).
    pub fn from_json_str(text: &str, source: &str) -> Result<IkConfig, Error> {
        let raw: ConfigFile = serde_json::from_str(text).map_err(|e| Error::Config {
            at: format!("{source}:{}:{}", e.line(), e.column()),
            message: strip_position(&e.to_string()),
        })?;
        Self::from_parts(raw, text.to_owned(), source)
    }

    /// The config that `file` says, with `file` written in GMR's layout as its text
    /// ([`IkConfig::json`]): the same config as reading that text, without reading it (the
    /// numbers are written exactly, so the text reads back to `file`).
    pub(crate) fn from_file_form(file: ConfigFile, source: &str) -> Result<IkConfig, Error> {
        let tables = [&file.ik_match_table1, &file.ik_match_table2];
        let duplicate = file.human_scale_table.duplicate();
        if let Some(key) = duplicate.or_else(|| tables.iter().find_map(|t| t.duplicate())) {
            return Err(Error::Config {
                at: source.to_owned(),
                message: format!("duplicate key `{key}`"),
            });
        }
        let text = gmr_layout(&file).map_err(|e| Error::Config {
            at: source.to_owned(),
            message: format!("cannot write the config: {e}"),
        })?;
        Self::from_parts(file, text, source)
    }

    fn from_parts(raw: ConfigFile, text: String, source: &str) -> Result<IkConfig, Error> {
        let entries = |table: Ordered<FileEntry>| -> Vec<MatchEntry> {
            table.0.into_iter().map(|(robot_body, e)| entry(robot_body, e)).collect()
        };
        let config = IkConfig {
            source: source.to_owned(),
            robot_root_name: raw.robot_root_name,
            human_root_name: raw.human_root_name,
            ground_height: raw.ground_height,
            human_height_assumption: raw.human_height_assumption,
            use_ik_match_table1: raw.use_ik_match_table1,
            use_ik_match_table2: raw.use_ik_match_table2,
            human_scale_table: raw.human_scale_table.0,
            ik_match_table1: entries(raw.ik_match_table1),
            ik_match_table2: entries(raw.ik_match_table2),
            text,
        };
        config.check_numbers()?;
        Ok(config)
    }

    /// The JSON text the config was read from (for a derived config: the text it was
    /// written as, which `retarget robot init` saves).
    #[must_use]
    pub fn json(&self) -> &str {
        &self.text
    }

    /// The tables the solver runs, in order (table 1 then table 2, each if enabled).
    #[must_use]
    pub fn stages(&self) -> Vec<&[MatchEntry]> {
        let mut out: Vec<&[MatchEntry]> = Vec::new();
        if self.use_ik_match_table1 {
            out.push(&self.ik_match_table1);
        }
        if self.use_ik_match_table2 {
            out.push(&self.ik_match_table2);
        }
        out
    }

    /// Robot bodies whose position is a target: a non-zero position weight in an enabled
    /// table. The others are tracked for their orientation only.
    #[must_use]
    pub fn position_targets(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for e in self.stages().into_iter().flatten() {
            if e.is_active() && e.pos_weight != 0.0 && !out.contains(&e.robot_body) {
                out.push(e.robot_body.clone());
            }
        }
        out
    }

    /// Scale of a human body from the table (before the height ratio).
    #[must_use]
    pub fn scale_of(&self, human_body: &str) -> Option<f64> {
        self.human_scale_table.iter().find(|(k, _)| k == human_body).map(|(_, s)| *s)
    }

    /// Checks every name against the robot model and the human skeleton, and the structural
    /// rules GMR relies on (root in the scale table, every active task's human body scaled,
    /// no human body driving two active frames of one table). Unknown names are errors with
    /// their position in the file and the nearest existing names.
    pub fn validate(&self, model: &mjcf::Model, human_bodies: &[String]) -> Result<(), Error> {
        let robot = crate::RobotMotion::model_body_names(model);
        let human_known = |name: &str| human_bodies.iter().any(|h| h == name);
        if !human_known(&self.human_root_name) {
            return Err(self.unknown("human", &self.human_root_name, human_bodies));
        }
        for (name, _) in &self.human_scale_table {
            if !human_known(name) {
                return Err(self.unknown("human", name, human_bodies));
            }
        }
        for (k, table) in [&self.ik_match_table1, &self.ik_match_table2].into_iter().enumerate() {
            for e in table {
                if model.body_id(&e.robot_body).is_none() || e.robot_body.is_empty() {
                    return Err(self.unknown("robot", &e.robot_body, &robot));
                }
                if !human_known(&e.human_body) {
                    return Err(self.unknown("human", &e.human_body, human_bodies));
                }
            }
            self.check_table(k + 1, table)?;
        }
        if self.scale_of(&self.human_root_name).is_none() {
            return Err(self.invalid(
                &self.human_root_name,
                format!("human root `{}` is not in human_scale_table", self.human_root_name),
            ));
        }
        Ok(())
    }

    fn check_table(&self, number: usize, table: &[MatchEntry]) -> Result<(), Error> {
        let active: Vec<&MatchEntry> = table.iter().filter(|e| e.is_active()).collect();
        for (i, e) in active.iter().enumerate() {
            if self.scale_of(&e.human_body).is_none() {
                return Err(self.invalid(
                    &e.robot_body,
                    format!(
                        "ik_match_table{number}: `{}` tracks human body `{}`, which is not in \
                         human_scale_table",
                        e.robot_body, e.human_body
                    ),
                ));
            }
            if let Some(other) = active.iter().take(i).find(|o| o.human_body == e.human_body) {
                return Err(self.invalid(
                    &e.robot_body,
                    format!(
                        "ik_match_table{number}: human body `{}` drives both `{}` and `{}`",
                        e.human_body, other.robot_body, e.robot_body
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check_numbers(&self) -> Result<(), Error> {
        let h = self.human_height_assumption;
        if !(h.is_finite() && h > 0.0) {
            return Err(self.invalid(
                "human_height_assumption",
                format!("human_height_assumption must be a positive number, got {h}"),
            ));
        }
        if !self.ground_height.is_finite() {
            return Err(self.invalid("ground_height", "ground_height must be finite".to_owned()));
        }
        for (name, s) in &self.human_scale_table {
            if !s.is_finite() {
                return Err(
                    self.invalid(name, format!("scale of `{name}` must be finite, got {s}"))
                );
            }
        }
        for e in self.ik_match_table1.iter().chain(&self.ik_match_table2) {
            let finite = [e.pos_weight, e.rot_weight].iter().all(|w| w.is_finite() && *w >= 0.0);
            if !finite {
                return Err(self.invalid(
                    &e.robot_body,
                    format!("`{}`: weights must be finite and >= 0", e.robot_body),
                ));
            }
            if !e.pos_offset.iter().chain(e.rot_offset.coords.iter()).all(|v| v.is_finite()) {
                return Err(self.invalid(
                    &e.robot_body,
                    format!("`{}`: offsets must be finite", e.robot_body),
                ));
            }
        }
        Ok(())
    }

    fn unknown(&self, side: &str, name: &str, available: &[String]) -> Error {
        Error::UnknownName {
            at: self.locate(name),
            side: side.to_owned(),
            name: name.to_owned(),
            nearest: nearest(name, available),
        }
    }

    fn invalid(&self, name: &str, message: String) -> Error {
        Error::Config { at: self.locate(name), message }
    }

    /// `file:line:column` of the first `"name"` in the text (the file alone when absent).
    fn locate(&self, name: &str) -> String {
        let quoted = format!("\"{name}\"");
        match self.text.find(&quoted) {
            Some(offset) => {
                let before = &self.text[..offset];
                let line = before.matches('\n').count() + 1;
                let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("{}:{line}:{column}", self.source)
            }
            None => self.source.clone(),
        }
    }
}

fn entry(robot_body: String, (human_body, pos_weight, rot_weight, p, q): FileEntry) -> MatchEntry {
    MatchEntry {
        robot_body,
        human_body,
        pos_weight,
        rot_weight,
        pos_offset: Vector3::new(p[0], p[1], p[2]),
        // As written: GMR hands these to scipy, which normalises; we normalise too.
        rot_offset: UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3])),
    }
}

/// `file` as JSON in the layout of GMR's config files: an object a line per key (two spaces
/// of indent a level), a table row on one line, numbers as decimals without an exponent.
fn gmr_layout(file: &ConfigFile) -> Result<String, serde_json::Error> {
    let mut out = Vec::new();
    file.serialize(&mut serde_json::Serializer::with_formatter(&mut out, GmrLayout::default()))?;
    out.push(b'\n');
    // serde_json writes UTF-8 only.
    Ok(String::from_utf8_lossy(&out).into_owned())
}

/// serde_json's pretty layout for objects, its compact one (with a space after each comma)
/// inside arrays, so a table row stays on one line as in GMR's files; numbers in Rust's
/// shortest round-trip decimal form (`0.000000003`, `100.0`), which reads back exactly.
#[derive(Default)]
struct GmrLayout {
    /// Objects open around the value being written.
    depth: usize,
}

impl GmrLayout {
    fn indent<W: ?Sized + std::io::Write>(&self, w: &mut W) -> std::io::Result<()> {
        (0..self.depth).try_for_each(|_| w.write_all(b"  "))
    }
}

impl serde_json::ser::Formatter for GmrLayout {
    fn write_f64<W: ?Sized + std::io::Write>(&mut self, w: &mut W, v: f64) -> std::io::Result<()> {
        if v.fract() == 0.0 && v.abs() < 1e15 {
            write!(w, "{v:.1}")
        } else {
            write!(w, "{v}")
        }
    }

    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        w.write_all(if first { b"" } else { b", " })
    }

    fn begin_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.depth += 1;
        w.write_all(b"{")
    }

    fn end_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.depth -= 1;
        w.write_all(b"\n")?;
        self.indent(w)?;
        w.write_all(b"}")
    }

    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        w.write_all(if first { b"\n" } else { b",\n" })?;
        self.indent(w)
    }

    fn begin_object_value<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b": ")
    }
}

/// serde_json appends " at line L column C"; we print the position first instead.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

/// Up to three names closest to `name` by edit distance (case-insensitive).
fn nearest(name: &str, available: &[String]) -> Vec<String> {
    let lower = name.to_lowercase();
    let mut scored: Vec<(usize, &String)> = available
        .iter()
        .filter(|a| !a.is_empty())
        .map(|a| (edit_distance(&lower, &a.to_lowercase()), a))
        .collect();
    scored.sort_by(|a, b| a.0.cmp(&b.0).then_with(|| a.1.cmp(b.1)));
    scored.into_iter().take(3).map(|(_, a)| a.clone()).collect()
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        // row[j] is the distance of a[..i] to b[..j]; `left` is the new row's previous entry.
        let mut prev = i;
        let mut left = i + 1;
        for (slot, cb) in row.iter_mut().skip(1).zip(&b) {
            let cur = *slot;
            left = (prev + usize::from(ca != *cb)).min(left + 1).min(cur + 1);
            *slot = left;
            prev = cur;
        }
        if let Some(first) = row.first_mut() {
            *first = i + 1;
        }
    }
    row.last().copied().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = r#"{
  "robot_root_name": "a", "human_root_name": "Hips", "ground_height": 0.0,
  "human_height_assumption": 1.8, "use_ik_match_table1": true, "use_ik_match_table2": false,
  "human_scale_table": {"Hips": 0.9, "Spine": 0.8},
  "ik_match_table1": {
    "b": ["Spine", 1, 2, [0, 0, 0], [1, 0, 0, 0]],
    "a": ["Hips", 0, 10, [0.1, 0, 0], [0.5, 0.5, 0.5, 0.5]]
  },
  "ik_match_table2": {}
}"#;

    #[test]
    fn keeps_file_order() {
        let c = IkConfig::from_json_str(SMALL, "t.json").unwrap();
        assert_eq!(c.ik_match_table1[0].robot_body, "b");
        assert_eq!(c.ik_match_table1[1].robot_body, "a");
        assert_eq!(c.human_scale_table[1], ("Spine".to_owned(), 0.8));
        assert_eq!(c.stages().len(), 1);
    }

    #[test]
    fn type_error_has_position() {
        let bad = SMALL.replace("\"ground_height\": 0.0", "\"ground_height\": \"x\"");
        let err = IkConfig::from_json_str(&bad, "t.json").unwrap_err().to_string();
        assert!(err.starts_with("t.json:2:"), "{err}");
        assert!(err.contains("invalid type"), "{err}");
    }

    #[test]
    fn missing_field_is_named() {
        let bad = SMALL.replace("\"ground_height\": 0.0,", "");
        let err = IkConfig::from_json_str(&bad, "t.json").unwrap_err().to_string();
        assert!(err.contains("ground_height"), "{err}");
    }

    #[test]
    fn edit_distance_basics() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        let near = nearest("LeftFot", &["LeftFoot".into(), "RightFoot".into(), "Hips".into()]);
        assert_eq!(near[0], "LeftFoot");
    }

    /// Written in GMR's layout (a row a line, decimals without exponents), and read back
    /// exactly.
    #[test]
    fn the_file_form_is_written_in_gmrs_layout() {
        let file: ConfigFile = serde_json::from_str(SMALL).unwrap();
        let mut tiny = file.clone();
        tiny.ik_match_table1.0[0].1 .3 = [3e-9, -0.25, 1.0 / 3.0];
        let c = IkConfig::from_file_form(tiny, "t.json").unwrap();
        let want = r#"{
  "robot_root_name": "a",
  "human_root_name": "Hips",
  "ground_height": 0.0,
  "human_height_assumption": 1.8,
  "use_ik_match_table1": true,
  "use_ik_match_table2": false,
  "human_scale_table": {
    "Hips": 0.9,
    "Spine": 0.8
  },
  "ik_match_table1": {
    "b": ["Spine", 1.0, 2.0, [0.000000003, -0.25, 0.3333333333333333], [1.0, 0.0, 0.0, 0.0]],
    "a": ["Hips", 0.0, 10.0, [0.1, 0.0, 0.0], [0.5, 0.5, 0.5, 0.5]]
  },
  "ik_match_table2": {
  }
}
"#;
        assert_eq!(c.json(), want);
        assert_eq!(IkConfig::from_json_str(want, "t.json").unwrap(), c);
        let mut twice = file;
        twice.ik_match_table1.0[1].0 = "b".to_owned();
        let err = IkConfig::from_file_form(twice, "t.json").unwrap_err().to_string();
        assert!(err.contains("duplicate key `b`"), "{err}");
    }

    #[test]
    fn locate_finds_line_and_column() {
        let c = IkConfig::from_json_str(SMALL, "t.json").unwrap();
        assert_eq!(c.locate("Spine"), "t.json:4:38");
        assert_eq!(c.locate("b"), "t.json:6:5");
    }
}
