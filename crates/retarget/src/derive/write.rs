//! A derived config as its file says it ([`ConfigFile`], GMR's schema): the rows in GMR's
//! order, numbers rounded as we write configs ([`rounded`]).

use fk::Role;
use nalgebra::{UnitQuaternion, Vector3};

use crate::config::{ConfigFile, FileEntry, IkConfig, Ordered};
use crate::Error;

/// Roles in the order of GMR's scale tables.
const SCALE_ORDER: [Role; 14] = [
    Role::Pelvis,
    Role::Chest,
    Role::LeftThigh,
    Role::RightThigh,
    Role::LeftShin,
    Role::RightShin,
    Role::LeftFoot,
    Role::RightFoot,
    Role::LeftUpperArm,
    Role::RightUpperArm,
    Role::LeftForearm,
    Role::RightForearm,
    Role::LeftHand,
    Role::RightHand,
];

/// One derived row before it is written: role, robot body, human joint, offsets, scale.
pub(super) struct Row {
    pub(super) role: Role,
    pub(super) body: String,
    pub(super) joint: String,
    pub(super) rot: UnitQuaternion<f64>,
    pub(super) pos: Vector3<f64>,
    pub(super) scale: f64,
    /// `[table1 pos, table1 rot, table2 pos, table2 rot]`.
    pub(super) weights: [f64; 4],
}

/// The file of a derived config: GMR's layout, the rows in their order (GMR's table order) in
/// both tables, the scales in [`SCALE_ORDER`].
pub(super) fn file_of(rows: &[Row], height: f64) -> ConfigFile {
    let pelvis = rows.iter().find(|r| r.role == Role::Pelvis);
    let scales = SCALE_ORDER
        .iter()
        .filter_map(|role| rows.iter().find(|r| r.role == *role))
        .map(|r| (r.joint.clone(), r.scale));
    let table = |k: usize| {
        let weight = |r: &Row, k: usize| r.weights.get(k).copied().unwrap_or(0.0);
        let rows = rows
            .iter()
            .map(|r| (r.body.clone(), entry(&r.joint, weight(r, 2 * k), weight(r, 2 * k + 1), r)));
        Ordered(rows.collect())
    };
    ConfigFile {
        robot_root_name: pelvis.map_or_else(String::new, |r| r.body.clone()),
        human_root_name: pelvis.map_or_else(String::new, |r| r.joint.clone()),
        ground_height: 0.0,
        human_height_assumption: height,
        use_ik_match_table1: true,
        use_ik_match_table2: true,
        human_scale_table: Ordered(scales.collect()),
        ik_match_table1: table(0),
        ik_match_table2: table(1),
        ..ConfigFile::default()
    }
}

/// A table row of `row`'s offsets tracking `joint` with these weights.
pub(super) fn entry(joint: &str, pos_weight: f64, rot_weight: f64, row: &Row) -> FileEntry {
    let (p, q) = (row.pos, row.rot);
    (joint.to_owned(), pos_weight, rot_weight, [p.x, p.y, p.z], [q.w, q.i, q.j, q.k])
}

/// The config `file` says, rounded as we write configs ([`rounded`]; rotation offsets with
/// `w ≥ 0`), with that text.
pub(super) fn written(mut file: ConfigFile, source: &str) -> Result<IkConfig, Error> {
    file.ground_height = rounded(file.ground_height);
    file.human_height_assumption = rounded(file.human_height_assumption);
    for (_, s) in &mut file.human_scale_table.0 {
        *s = rounded(*s);
    }
    let rows = file.ik_match_table1.0.iter_mut().chain(&mut file.ik_match_table2.0);
    for (_, (_, wp, wr, p, q)) in rows {
        let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
        for v in [wp, wr].into_iter().chain(p.iter_mut()) {
            *v = rounded(*v);
        }
        for v in q.iter_mut() {
            *v = rounded(sign * *v);
        }
    }
    IkConfig::from_file_form(file, source)
}

/// A number as derived configs write it: rounded to 1e-9 (offsets to a nanometre,
/// quaternions to 1e-9), `-0` as 0.
fn rounded(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_rounded_to_1e_9_without_negative_zero() {
        assert_eq!(rounded(0.5), 0.5);
        assert_eq!(rounded(0.123456789123), 0.123456789);
        assert_eq!(rounded(-0.123456789623), -0.12345679);
        assert!(rounded(-1e-12).is_sign_positive());
        assert!(rounded(-0.0).is_sign_positive());
    }
}
