//! [`BodyModels`]: where the body models come from (a folder, a file, or the folder named by
//! [`BODY_MODELS_ENV`]), each read once and shared (a batch poses thousands of motions with
//! a handful of models).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use crate::conventions::{Gender, ModelKind, BODY_MODELS_ENV};
use crate::model::BodyModel;
use crate::motion::SmplMotion;
use crate::Error;

/// The body models of a run: found under one folder (or one model file), read on first use.
#[derive(Debug, Default)]
pub struct BodyModels {
    location: Option<PathBuf>,
    cache: Mutex<HashMap<(ModelKind, Gender), Arc<BodyModel>>>,
}

impl BodyModels {
    /// Models under `location`: the body model folder (holding `smplx/` and `smplh/`), or one
    /// model file used for every motion. `None`: the folder named by [`BODY_MODELS_ENV`].
    #[must_use]
    pub fn new(location: Option<&Path>) -> BodyModels {
        let location = location
            .map(Path::to_path_buf)
            .or_else(|| std::env::var_os(BODY_MODELS_ENV).map(PathBuf::from));
        BodyModels { location, cache: Mutex::new(HashMap::new()) }
    }

    /// Where the models are looked for, if anywhere.
    #[must_use]
    pub fn location(&self) -> Option<&Path> {
        self.location.as_deref()
    }

    /// The model of `kind` and `gender` (read once).
    pub fn get(&self, kind: ModelKind, gender: Gender) -> Result<Arc<BodyModel>, Error> {
        let Some(location) = &self.location else {
            return Err(Error::NoModelFolder { kind });
        };
        let mut cache = self.cache.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(model) = cache.get(&(kind, gender)) {
            return Ok(Arc::clone(model));
        }
        let is_file = location.is_file()
            || location
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("npz") || e.eq_ignore_ascii_case("pkl"));
        let model = if is_file {
            BodyModel::from_path(location, None)?
        } else {
            BodyModel::from_folder(location, kind, gender)?
        };
        let model = Arc::new(model);
        cache.insert((kind, gender), Arc::clone(&model));
        Ok(model)
    }

    /// The model `motion` is posed with: its kind, the gender `gender` or else the file's.
    pub fn for_motion(
        &self,
        motion: &SmplMotion,
        gender: Option<Gender>,
    ) -> Result<Arc<BodyModel>, Error> {
        let gender = gender.or(motion.gender).ok_or_else(|| Error::Motion {
            path: motion.source.clone(),
            message: "the motion does not say its gender (no `gender` array): give one \
                      (--gender neutral|male|female)"
                .to_owned(),
        })?;
        let model = self.get(motion.kind, gender)?;
        crate::forward::check(&model, motion)?;
        Ok(model)
    }
}
