//! [`BodyModel`]: the skeleton of an SMPL-X or SMPL+H body model file, as a function of the
//! shape coefficients (betas).
//!
//! Joints are `J = J_regressor · (v_template + shapedirs · β)` (smplx's `lbs`, expression
//! zero), which is linear in β: the model is kept as `J_regressor · v_template` and
//! `J_regressor · shapedirs`, computed once when the file is read, so posing another motion
//! of the same model costs a (J × 3 × K) product. Only the arrays the skeleton needs are read
//! (`v_template`, `J_regressor`, `kintree_table`, `shapedirs`, SMPL-X's `hands_mean*`);
//! `shapedirs` is streamed vertex by vertex and only the vertices the regressor uses (and a
//! few at the top and the soles, for the stature) are kept.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::conventions::{Gender, ModelKind};
use crate::Error;
use npz::Npz;

/// Vertices kept at the top of the head and under the soles to measure the stature.
const EXTREME_VERTICES: usize = 24;

/// A body model's skeleton: joint tree, rest joints and how β moves them.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyModel {
    pub kind: ModelKind,
    /// The file it was read from.
    pub path: PathBuf,
    /// Parent of each joint (`None` for the root), parents before children.
    parents: Vec<Option<usize>>,
    /// `J_regressor · v_template` (template frame: Y up, facing +Z, metres).
    template: Vec<Vector3<f64>>,
    /// `J_regressor · shapedirs[:, :, :components]`, `[(joint * 3 + axis) * components + k]`.
    shape_dirs: Vec<f64>,
    components: usize,
    /// SMPL-X's `hands_meanl` ++ `hands_meanr` (90 values): smplx adds them to the hand
    /// poses unless `flat_hand_mean` (GMR and AMASS's SMPL-X fits leave it false). `None`
    /// for SMPL+H, whose AMASS model has no hand mean.
    hands_mean: Option<Vec<f64>>,
    /// Template height and shape directions of the highest and lowest vertices.
    crown: Vec<(f64, Vec<f64>)>,
    soles: Vec<(f64, Vec<f64>)>,
}

impl BodyModel {
    /// Reads the body model file at `path`: its kind from its joint count (55 SMPL-X, 52
    /// SMPL+H), or `kind` when given (a file of the other kind is then an error). A `.pkl`
    /// is an error naming the `.npz` to use instead.
    pub fn from_path(path: &Path, kind: Option<ModelKind>) -> Result<BodyModel, Error> {
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("pkl")) {
            let use_instead = path.with_extension("npz").display().to_string();
            return Err(Error::PickleModel { path: path.to_path_buf(), use_instead });
        }
        let mut npz = Npz::open(path)?;
        read(&mut npz, kind)
    }

    /// [`BodyModel::from_path`] on the bytes of a model `.npz` (`name` is used in errors).
    pub fn from_bytes(
        bytes: &[u8],
        name: &Path,
        kind: Option<ModelKind>,
    ) -> Result<BodyModel, Error> {
        let mut npz = Npz::new(std::io::Cursor::new(bytes), name)?;
        read(&mut npz, kind)
    }

    /// The model of `kind` and `gender` under the body model folder `dir` (the folder that
    /// holds `smplx/` and `smplh/`, as `smplx.create` takes it; the `smplx` or `smplh/<gender>`
    /// folder itself is accepted too). A missing file is an error naming the path expected
    /// and where the model is obtained.
    pub fn from_folder(dir: &Path, kind: ModelKind, gender: Gender) -> Result<BodyModel, Error> {
        let expected = kind.model_path(dir, gender);
        let file = expected.file_name().map(PathBuf::from).unwrap_or_default();
        let candidates = [expected.clone(), dir.join(&file), dir.join(gender.name()).join(&file)];
        if let Some(found) = candidates.iter().find(|p| p.is_file()) {
            return BodyModel::from_path(found, Some(kind));
        }
        let pickle = candidates.iter().map(|p| p.with_extension("pkl")).find(|p| p.is_file());
        Err(Error::ModelNotFound { kind, gender, expected, pickle })
    }

    #[must_use]
    pub fn num_joints(&self) -> usize {
        self.parents.len()
    }

    #[must_use]
    pub fn parents(&self) -> &[Option<usize>] {
        &self.parents
    }

    #[must_use]
    pub fn joint_names(&self) -> &'static [&'static str] {
        self.kind.joint_names()
    }

    /// Shape components the model has (betas it can take).
    #[must_use]
    pub fn shape_components(&self) -> usize {
        self.components
    }

    /// The hand pose mean added to SMPL-X hand poses (`None` for SMPL+H).
    #[must_use]
    pub fn hands_mean(&self) -> Option<&[f64]> {
        self.hands_mean.as_deref()
    }

    /// Rest joints for `betas` (template frame, metres); betas beyond the model's shape
    /// components are ignored (the caller checks: [`Error::TooManyBetas`]).
    #[must_use]
    pub fn rest_joints(&self, betas: &[f64]) -> Vec<Vector3<f64>> {
        let k = self.components;
        let betas = betas.get(..k.min(betas.len())).unwrap_or_default();
        let rows = self.shape_dirs.chunks_exact(k.max(1));
        let offsets: Vec<f64> =
            rows.map(|row| row.iter().zip(betas).map(|(d, b)| d * b).sum::<f64>()).collect();
        self.template
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let at = |a: usize| offsets.get(3 * j + a).copied().unwrap_or(0.0);
                t + Vector3::new(at(0), at(1), at(2))
            })
            .collect()
    }

    /// Stature for `betas` (m): the highest over the lowest vertex of the rest mesh (T-pose,
    /// Y up), measured on the vertices highest and lowest at β = 0.
    #[must_use]
    pub fn stature(&self, betas: &[f64]) -> f64 {
        self.top(betas) - self.sole(betas)
    }

    /// Height (template Y) of the lowest vertex of the rest mesh at `betas`.
    #[must_use]
    pub fn sole(&self, betas: &[f64]) -> f64 {
        let y = |(t, dirs): &(f64, Vec<f64>)| {
            t + dirs.iter().zip(betas).map(|(d, b)| d * b).sum::<f64>()
        };
        self.soles.iter().map(y).fold(f64::INFINITY, f64::min)
    }

    fn top(&self, betas: &[f64]) -> f64 {
        let y = |(t, dirs): &(f64, Vec<f64>)| {
            t + dirs.iter().zip(betas).map(|(d, b)| d * b).sum::<f64>()
        };
        self.crown.iter().map(y).fold(f64::NEG_INFINITY, f64::max)
    }
}

fn bad(npz: &Npz<impl std::io::Read + std::io::Seek>, kind: ModelKind, message: String) -> Error {
    Error::BadModel { path: npz.path().to_path_buf(), kind, message }
}

/// Reads the skeleton arrays of an open model file.
fn read<R: std::io::Read + std::io::Seek>(
    npz: &mut Npz<R>,
    kind: Option<ModelKind>,
) -> Result<BodyModel, Error> {
    let (rshape, regressor) = npz.floats("J_regressor")?;
    let [joints, vertices] = rshape.as_slice() else {
        let k = kind.unwrap_or(ModelKind::SmplX);
        return Err(bad(npz, k, format!("`J_regressor` has shape {rshape:?}, expected (J, V)")));
    };
    let (joints, vertices) = (*joints, *vertices);
    let found = match joints {
        55 => Some(ModelKind::SmplX),
        52 => Some(ModelKind::SmplH),
        _ => None,
    };
    let kind = match (kind, found) {
        (Some(k), Some(f)) if k != f => {
            return Err(bad(
                npz,
                k,
                format!(
                    "it has {joints} joints, the joint count of {f} ({} joints)",
                    f.num_joints()
                ),
            ))
        }
        (Some(k), _) | (None, Some(k)) => k,
        (None, None) => {
            return Err(bad(
                npz,
                ModelKind::SmplX,
                format!("{joints} joints; SMPL-X has 55, SMPL+H 52"),
            ))
        }
    };
    if joints != kind.num_joints() {
        return Err(bad(npz, kind, format!("{joints} joints, expected {}", kind.num_joints())));
    }
    let parents = read_parents(npz, kind, joints)?;
    let (tshape, template) = npz.floats("v_template")?;
    if tshape != [vertices, 3] {
        return Err(bad(
            npz,
            kind,
            format!("`v_template` has shape {tshape:?}, expected ({vertices}, 3)"),
        ));
    }
    // Per vertex, the joints whose regressor row uses it.
    let mut uses: Vec<Vec<(usize, f64)>> = vec![Vec::new(); vertices];
    let mut rest = vec![Vector3::zeros(); joints];
    for (j, row) in regressor.chunks_exact(vertices.max(1)).enumerate() {
        for (v, &w) in row.iter().enumerate().filter(|(_, w)| **w != 0.0) {
            if !w.is_finite() {
                return Err(bad(npz, kind, format!("`J_regressor` is {w} at ({j}, {v})")));
            }
            if let (Some(u), Some(r), Some(p)) =
                (uses.get_mut(v), rest.get_mut(j), template.get(3 * v..3 * v + 3))
            {
                u.push((j, w));
                *r += Vector3::from_column_slice(p) * w;
            }
        }
    }
    if let Some(bad_value) = template.iter().find(|v| !v.is_finite()) {
        return Err(bad(npz, kind, format!("`v_template` holds {bad_value}")));
    }
    let heights: Vec<f64> =
        template.chunks_exact(3).map(|p| p.get(1).copied().unwrap_or(0.0)).collect();
    let (crown_ids, sole_ids) = extremes(&heights);

    let sshape = npz.header("shapedirs")?.shape;
    let columns = match sshape.as_slice() {
        [v, 3, c] if *v == vertices => *c,
        _ => {
            return Err(bad(
                npz,
                kind,
                format!("`shapedirs` has shape {sshape:?}, expected ({vertices}, 3, K)"),
            ))
        }
    };
    let k = kind.shape_components(columns);
    let mut shape_dirs = vec![0.0; joints * 3 * k];
    let mut crown: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut soles: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut non_finite = None;
    npz.rows("shapedirs", 3 * columns, |v, row| {
        if non_finite.is_none() {
            non_finite = row.iter().copied().find(|x| !x.is_finite());
        }
        for &(j, w) in uses.get(v).map(Vec::as_slice).unwrap_or_default() {
            for axis in 0..3 {
                let from = row.get(axis * columns..axis * columns + k).unwrap_or_default();
                let to = shape_dirs.get_mut((j * 3 + axis) * k..(j * 3 + axis + 1) * k);
                for (t, d) in to.unwrap_or_default().iter_mut().zip(from) {
                    *t += w * d;
                }
            }
        }
        let y_dirs = || row.get(columns..columns + k).unwrap_or_default().to_vec();
        let height = heights.get(v).copied().unwrap_or(0.0);
        if crown_ids.contains(&v) {
            crown.push((height, y_dirs()));
        }
        if sole_ids.contains(&v) {
            soles.push((height, y_dirs()));
        }
    })?;
    if let Some(x) = non_finite {
        return Err(bad(npz, kind, format!("`shapedirs` holds {x}")));
    }
    let hands_mean = match kind {
        ModelKind::SmplX => Some(read_hands_mean(npz, kind)?),
        ModelKind::SmplH => None,
    };
    Ok(BodyModel {
        kind,
        path: npz.path().to_path_buf(),
        parents,
        template: rest,
        shape_dirs,
        components: k,
        hands_mean,
        crown,
        soles,
    })
}

/// Parents from `kintree_table` (2 × J: parents, then joint ids); `[0, 0]` means no parent
/// whatever its value (-1, or the legacy uint32 4294967295).
fn read_parents<R: std::io::Read + std::io::Seek>(
    npz: &mut Npz<R>,
    kind: ModelKind,
    joints: usize,
) -> Result<Vec<Option<usize>>, Error> {
    let (shape, table) = npz.ints("kintree_table")?;
    if shape != [2, joints] {
        return Err(bad(
            npz,
            kind,
            format!("`kintree_table` has shape {shape:?}, expected (2, {joints})"),
        ));
    }
    let mut parents = vec![None; joints];
    for (j, (&p, &id)) in table.iter().zip(table.iter().skip(joints)).enumerate().skip(1) {
        let parent = usize::try_from(p).ok().filter(|&p| p < j);
        if parent.is_none() || id != j as i64 {
            return Err(bad(
                npz,
                kind,
                format!("`kintree_table` gives joint {id} (column {j}) the parent {p}: not a tree in joint order"),
            ));
        }
        if let Some(slot) = parents.get_mut(j) {
            *slot = parent;
        }
    }
    Ok(parents)
}

/// SMPL-X's hand pose means (`hands_meanl`, `hands_meanr`, 45 each); zero when absent.
fn read_hands_mean<R: std::io::Read + std::io::Seek>(
    npz: &mut Npz<R>,
    kind: ModelKind,
) -> Result<Vec<f64>, Error> {
    let mut mean = Vec::with_capacity(90);
    for key in ["hands_meanl", "hands_meanr"] {
        if !npz.has(key) {
            mean.extend([0.0; 45]);
            continue;
        }
        let (_, values) = npz.floats(key)?;
        if values.len() != 45 || values.iter().any(|v| !v.is_finite()) {
            return Err(bad(npz, kind, format!("`{key}` is not 45 finite numbers")));
        }
        mean.extend(values);
    }
    Ok(mean)
}

/// The [`EXTREME_VERTICES`] highest and lowest vertices by height.
fn extremes(heights: &[f64]) -> (Vec<usize>, Vec<usize>) {
    let mut order: Vec<usize> = (0..heights.len()).collect();
    order.sort_by(|&a, &b| {
        heights.get(a).partial_cmp(&heights.get(b)).unwrap_or(std::cmp::Ordering::Equal)
    });
    let n = EXTREME_VERTICES.min(order.len());
    let low = order.get(..n).unwrap_or_default().to_vec();
    let high = order.get(order.len() - n..).unwrap_or_default().to_vec();
    (high, low)
}
