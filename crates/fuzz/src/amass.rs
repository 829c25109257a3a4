//! The AMASS motion-file target (issue 31): SMPL-X stage-ii and SMPL+H `.npz` files, their
//! keys, shapes and dtypes generated (and mutated), read by `smpl::SmplMotion`, then posed
//! with a small SMPL-X or SMPL+H body model made here (one vertex per joint: the reader's
//! layout, not a real body), recognised and resampled as GMR does.

use std::io::{Cursor, Write};
use std::sync::OnceLock;

use arbitrary::{Result, Unstructured};

use crate::Target;

pub struct AmassTarget;

/// An `.npy` member: `descr`, shape text and raw data.
fn npy(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    let header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}\n");
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&u16::try_from(header.len()).unwrap_or(0).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

fn f8(values: impl IntoIterator<Item = f64>) -> Vec<u8> {
    values.into_iter().flat_map(f64::to_le_bytes).collect()
}

fn unicode(text: &str) -> Vec<u8> {
    text.chars().flat_map(|c| u32::from(c).to_le_bytes()).collect()
}

fn zip(members: &[(String, Vec<u8>)], deflate: bool) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let method =
        if deflate { zip::CompressionMethod::Deflated } else { zip::CompressionMethod::Stored };
    let options = zip::write::SimpleFileOptions::default().compression_method(method);
    for (name, bytes) in members {
        if zip.start_file(format!("{name}.npy"), options).is_err() || zip.write_all(bytes).is_err()
        {
            break;
        }
    }
    zip.finish().map(Cursor::into_inner).unwrap_or_default()
}

/// The 22 body joints of a standing T-pose (template frame: Y up, facing +Z, left +X) and
/// their SMPL parents.
const BODY: [([f64; 3], i64); 22] = [
    ([0.0, 0.93, 0.0], -1),
    ([0.09, 0.85, 0.0], 0),
    ([-0.09, 0.85, 0.0], 0),
    ([0.0, 1.03, 0.0], 0),
    ([0.09, 0.48, 0.0], 1),
    ([-0.09, 0.48, 0.0], 2),
    ([0.0, 1.15, 0.0], 3),
    ([0.09, 0.08, 0.0], 4),
    ([-0.09, 0.08, 0.0], 5),
    ([0.0, 1.28, 0.0], 6),
    ([0.09, 0.02, 0.12], 7),
    ([-0.09, 0.02, 0.12], 8),
    ([0.0, 1.50, 0.0], 9),
    ([0.07, 1.42, 0.0], 9),
    ([-0.07, 1.42, 0.0], 9),
    ([0.0, 1.62, 0.0], 12),
    ([0.18, 1.42, 0.0], 13),
    ([-0.18, 1.42, 0.0], 14),
    ([0.45, 1.42, 0.0], 16),
    ([-0.45, 1.42, 0.0], 17),
    ([0.70, 1.42, 0.0], 18),
    ([-0.70, 1.42, 0.0], 19),
];

/// A body model of `kind` in the real files' layout: one vertex per joint (a T-pose; face
/// joints at the head, fingers in chains from the wrists), shape directions along Y.
fn model(kind: smpl::ModelKind) -> smpl::BodyModel {
    let j = kind.num_joints();
    let mut pos: Vec<[f64; 3]> = BODY.iter().map(|b| b.0).collect();
    let mut parents: Vec<i64> = BODY.iter().map(|b| b.1).collect();
    if kind == smpl::ModelKind::SmplX {
        for x in [0.0, 0.03, -0.03] {
            pos.push([x, 1.64, 0.08]);
            parents.push(15);
        }
    }
    for (wrist, side) in [(20i64, 1.0), (21, -1.0)] {
        for finger in 0..5 {
            for k in 0..3 {
                let parent = if k == 0 { wrist } else { pos.len() as i64 - 1 };
                pos.push([
                    side * (0.73 + 0.02 * f64::from(k)),
                    1.42,
                    0.02 * f64::from(finger) - 0.04,
                ]);
                parents.push(parent);
            }
        }
    }
    let columns = if kind == smpl::ModelKind::SmplX { 20 } else { 16 };
    let regressor: Vec<f64> = (0..j * j).map(|k| f64::from(u8::from(k / j == k % j))).collect();
    let shapedirs: Vec<f64> =
        (0..j * 3 * columns).map(|k| if (k / columns) % 3 == 1 { 0.01 } else { 0.0 }).collect();
    let kintree: Vec<i64> = parents.iter().copied().chain(0..j as i64).collect();
    let mut members = vec![
        (
            "v_template".to_owned(),
            npy("<f8", &format!("({j}, 3)"), &f8(pos.iter().flatten().copied())),
        ),
        ("J_regressor".to_owned(), npy("<f8", &format!("({j}, {j})"), &f8(regressor))),
        (
            "kintree_table".to_owned(),
            npy(
                "<i8",
                &format!("(2, {j})"),
                &kintree.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(),
            ),
        ),
        ("shapedirs".to_owned(), npy("<f8", &format!("({j}, 3, {columns})"), &f8(shapedirs))),
    ];
    if kind == smpl::ModelKind::SmplX {
        for key in ["hands_meanl", "hands_meanr"] {
            members.push((
                key.to_owned(),
                npy("<f8", "(45,)", &f8((0..45).map(|k| 0.01 * f64::from(k % 5)))),
            ));
        }
    }
    let bytes = zip(&members, false);
    smpl::BodyModel::from_bytes(&bytes, std::path::Path::new("fuzz-model.npz"), Some(kind))
        .unwrap_or_else(|e| unreachable!("the fuzz body model is valid: {e}"))
}

fn models() -> &'static [smpl::BodyModel; 2] {
    static MODELS: OnceLock<[smpl::BodyModel; 2]> = OnceLock::new();
    MODELS.get_or_init(|| [model(smpl::ModelKind::SmplX), model(smpl::ModelKind::SmplH)])
}

/// A number near `base`, or a wild one.
fn value(u: &mut Unstructured<'_>, base: f64, wild: bool) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=9)? {
        0 if wild => [f64::NAN, f64::INFINITY, -1e308, 1e30, 0.0][u.int_in_range(0..=4usize)?],
        1..=4 => base + f64::from(u.int_in_range(-1000i16..=1000)?) * 1e-3,
        _ => base,
    })
}

impl AmassTarget {
    fn motion(u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        let wild = u.ratio(1, 5)?;
        let smplx = u.arbitrary::<bool>()?;
        let frames = u.int_in_range(1usize..=40)?;
        let width = if smplx { 165 } else { 156 };
        let mut members: Vec<(String, Vec<u8>)> = Vec::new();
        let mut matrix =
            |u: &mut Unstructured<'_>, key: &str, cols: usize, base: f64| -> Result<()> {
                let rows = if wild && u.ratio(1, 8)? { frames + 1 } else { frames };
                let cols = if wild && u.ratio(1, 8)? { cols + 1 } else { cols };
                let mut data = Vec::with_capacity(rows * cols);
                for _ in 0..rows * cols {
                    data.push(value(u, base, wild)?);
                }
                members.push((key.to_owned(), npy("<f8", &format!("({rows}, {cols})"), &f8(data))));
                Ok(())
            };
        matrix(u, "trans", 3, 0.0)?;
        if smplx && u.arbitrary::<bool>()? {
            matrix(u, "root_orient", 3, 0.1)?;
            matrix(u, "pose_body", 63, 0.05)?;
            if u.arbitrary::<bool>()? {
                matrix(u, "pose_hand", 90, 0.0)?;
            }
        } else {
            matrix(u, "poses", width, 0.05)?;
        }
        let rate = ["mocap_frame_rate", "mocap_framerate", "fps"][u.int_in_range(0..=2usize)?];
        let fps = [120.0, 60.0, 30.0, 0.0, -1.0][u.int_in_range(0..=if wild { 4 } else { 2 })?];
        members.push((rate.to_owned(), npy("<f8", "()", &f8([fps]))));
        let betas = u.int_in_range(0usize..=if wild { 24 } else { 16 })?;
        let b: Vec<f64> = (0..betas).map(|_| value(u, 0.1, wild)).collect::<Result<_>>()?;
        members.push(("betas".to_owned(), npy("<f8", &format!("({betas},)"), &f8(b))));
        let gender =
            ["neutral", "male", "female", "other"][u.int_in_range(0..=if wild { 3 } else { 2 })?];
        members.push((
            "gender".to_owned(),
            npy(&format!("<U{}", gender.len()), "()", &unicode(gender)),
        ));
        if u.arbitrary::<bool>()? {
            let t = if smplx { "smplx" } else { "smplh" };
            members.push(("surface_model_type".to_owned(), npy("<U5", "()", &unicode(t))));
        }
        Ok(zip(&members, u.arbitrary()?))
    }
}

impl Target for AmassTarget {
    fn name(&self) -> &'static str {
        "amass"
    }

    fn seeds(&self) -> Vec<Vec<u8>> {
        let bytes: Vec<u8> =
            (0..4096u32).map(|k| (k.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
        (0..8)
            .filter_map(|k| {
                Self::motion(&mut Unstructured::new(bytes.get(k * 300..).unwrap_or_default())).ok()
            })
            .collect()
    }

    fn generate(&self, u: &mut Unstructured<'_>) -> Result<Vec<u8>> {
        Self::motion(u)
    }

    fn dictionary(&self) -> &'static [&'static str] {
        &[
            "poses",
            "trans",
            "betas",
            "gender",
            "root_orient",
            "pose_body",
            "pose_hand",
            "mocap_frame_rate",
            "mocap_framerate",
            "surface_model_type",
            "smplx",
            "smplh",
            "'descr': '<f8'",
            "'shape': (",
            "NUMPY",
            "PK\x03\x04",
        ]
    }

    fn run(&self, input: &[u8]) -> std::result::Result<(), String> {
        let motion = smpl::SmplMotion::from_bytes(input, std::path::Path::new("input.npz"))
            .map_err(|e| e.to_string())?;
        let [x, h] = models();
        let model = if motion.kind == smpl::ModelKind::SmplX { x } else { h };
        smpl::forward::check(model, &motion).map_err(|e| e.to_string())?;
        let motion = motion.slice(0..64);
        let clip = smpl::clip(model, &motion).map_err(|e| e.to_string())?;
        let _ = clip.roles();
        smpl::gmr::offline_fast(model, &motion, 30.0).map_err(|e| e.to_string())?;
        Ok(())
    }
}
