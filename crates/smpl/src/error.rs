//! The one error type of this crate.

use std::path::PathBuf;

use crate::conventions::{Gender, ModelKind};

/// Everything that can go wrong reading body models and motion files, or posing them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file that cannot be opened, is not an `.npz`, lacks an array the reader needs, or
    /// has one that cannot be read as needed (dtype, shape, truncated data, pickled objects).
    #[error(transparent)]
    Npz(#[from] npz::Error),
    /// A body model given as a Python pickle.
    #[error(
        "{}: a .pkl body model is a Python pickle, which this tool does not read; use the \
         .npz of the same model instead: {use_instead} (the download that holds the .pkl \
         holds it too)",
        path.display()
    )]
    PickleModel { path: PathBuf, use_instead: String },
    /// No body model file where it belongs.
    #[error("{}", model_not_found(*kind, *gender, expected, pickle.as_ref()))]
    ModelNotFound { kind: ModelKind, gender: Gender, expected: PathBuf, pickle: Option<PathBuf> },
    /// Neither a body model folder nor the environment variable was given.
    #[error(
        "the motion needs a {kind} body model: give the folder that holds `{}` with \
         --body-model DIR (Python: body_model=DIR) or set {}; {}",
        kind.folder(), crate::conventions::BODY_MODELS_ENV, kind.obtain()
    )]
    NoModelFolder { kind: ModelKind },
    /// A body model file whose arrays do not make a skeleton.
    #[error("{}: not a {kind} body model: {message}", path.display())]
    BadModel { path: PathBuf, kind: ModelKind, message: String },
    /// A motion file whose arrays do not make an AMASS motion.
    #[error("{}: {message}", path.display())]
    Motion { path: PathBuf, message: String },
    /// A motion and a body model that do not belong together.
    #[error("{}: {message}; body model {}", motion.display(), model.display())]
    Mismatch { motion: PathBuf, model: PathBuf, message: String },
    /// More shape coefficients in a motion than the body model has shape directions.
    #[error(
        "{}: {betas} betas, but the body model {} has {components} shape components: \
         the motion was fitted with another model",
        motion.display(), model.display()
    )]
    TooManyBetas { motion: PathBuf, betas: usize, model: PathBuf, components: usize },
    /// A `gender` that is not neutral, male or female.
    #[error("{}: gender `{value}`: expected neutral, male or female", path.display())]
    Gender { path: PathBuf, value: String },
    /// NaN or infinity in a motion array.
    #[error("{}: array `{key}` holds {value} at element {index}", path.display())]
    NonFinite { path: PathBuf, key: String, index: usize, value: f64 },
    /// Recognising the posed skeleton or validating its motion failed.
    #[error(transparent)]
    Fk(#[from] fk::Error),
}

fn model_not_found(
    kind: ModelKind,
    gender: Gender,
    expected: &std::path::Path,
    pickle: Option<&PathBuf>,
) -> String {
    let found = match pickle {
        Some(p) => format!(
            " ({} is there: a Python pickle, which this tool does not read; the .npz comes \
             in the same download)",
            p.display()
        ),
        None => String::new(),
    };
    format!(
        "no {kind} body model ({gender}): expected {}{found}; {}",
        expected.display(),
        kind.obtain()
    )
}
