//! The SFA model file that `wscg biometrics sfa fit` writes and `predict` reads (JSON): the
//! fitted classifier (class-wise or global, section 3 of paper 05) with the name of each
//! class and the image convention of its inputs.

use std::path::Path;

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::{GlobalSfa, PerClassSfa};

/// Largest SFA model file read (256 MiB).
pub const MAX_SFA_MODEL_BYTES: u64 = 256 << 20;

/// A fitted SFA classifier of either kind.
#[derive(Clone, Debug)]
pub enum FittedSfa {
    /// Class-wise SFA (paper 05, eqs. 14-17).
    Class(PerClassSfa),
    /// SFA fitted once on all classes.
    Global(GlobalSfa),
}

impl FittedSfa {
    /// The predicted labels and the `n x C` scores (smaller is better) of the rows of `x`.
    pub fn predict_scores(&self, x: MatRef<'_, f64>) -> Result<(Vec<u32>, Mat<f64>)> {
        match self {
            FittedSfa::Class(m) => Ok((m.predict(x)?, m.decision_scores(x)?)),
            FittedSfa::Global(m) => Ok((m.predict(x)?, m.decision_scores(x)?)),
        }
    }

    /// Input width the model expects.
    pub fn input_dim(&self) -> usize {
        match self {
            FittedSfa::Class(m) => m.input_dim(),
            FittedSfa::Global(m) => m.pca.mean.len(),
        }
    }

    /// Class labels, ascending.
    pub fn classes(&self) -> &[u32] {
        match self {
            FittedSfa::Class(m) => &m.classes,
            FittedSfa::Global(m) => &m.classes,
        }
    }
}

/// An SFA model file.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct SfaModelFile {
    /// Name of each class label (label `l` is `names[l]`).
    pub names: Vec<String>,
    /// `(h, w)` of the images the model takes before downscaling; `None` for feature rows.
    pub image_shape: Option<(usize, usize)>,
    /// Downscaling factor applied to images (>= 1).
    pub downscale: usize,
    /// The fitted classifier.
    pub model: FittedSfa,
}

/// The file's JSON layout (`kind` is `class` or `global`).
#[derive(Serialize, Deserialize)]
struct Stored {
    kind: String,
    names: Vec<String>,
    image_shape: Option<(usize, usize)>,
    downscale: usize,
    model: serde_json::Value,
}

fn format_err(path: &Path, reason: impl Into<String>) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

impl SfaModelFile {
    /// A model file of `model` whose labels are named by `names`.
    pub fn new(
        model: FittedSfa,
        names: Vec<String>,
        image_shape: Option<(usize, usize)>,
        downscale: usize,
    ) -> Self {
        SfaModelFile {
            names,
            image_shape,
            downscale,
            model,
        }
    }

    /// Reads a model file written by [`SfaModelFile::write`] (see
    /// [`SfaModelFile::from_json_bytes`]).
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = wscg_math::error::read_file_at_most(path, MAX_SFA_MODEL_BYTES, "SFA models")?;
        Self::from_json_bytes(&bytes, path)
    }

    /// Parses a model file held in memory; `origin` names the file in errors.
    ///
    /// Errors ([`Error::Format`] naming `origin`): not the JSON of an SFA model file (with
    /// the line and column), an unknown kind, a model whose arrays disagree in size
    /// ([`PerClassSfa::check_shapes`]), a class label without a name, a downscaling factor of
    /// 0, an image shape with a zero side or that does not downscale to the model's input.
    pub fn from_json_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let st: Stored = serde_json::from_slice(bytes).map_err(|e| {
            format_err(
                origin,
                format!("not an SFA model written by `wscg biometrics sfa fit`: {e}"),
            )
        })?;
        let model_err = |e: Error| format_err(origin, e.to_string());
        let inner = st.model.to_string();
        let model = match st.kind.as_str() {
            "class" => FittedSfa::Class(PerClassSfa::from_json(&inner).map_err(model_err)?),
            "global" => FittedSfa::Global(GlobalSfa::from_json(&inner).map_err(model_err)?),
            k => return Err(format_err(origin, format!("unknown model kind {k:?}"))),
        };
        if let Some(&l) = model
            .classes()
            .iter()
            .find(|&&l| l as usize >= st.names.len())
        {
            return Err(format_err(origin, format!("class label {l} has no name")));
        }
        if st.downscale == 0 {
            return Err(format_err(origin, "the downscaling factor is 0"));
        }
        if let Some((h, w)) = st.image_shape {
            let (dh, dw) = (h.div_ceil(st.downscale), w.div_ceil(st.downscale));
            if h == 0 || w == 0 || dh.checked_mul(dw) != Some(model.input_dim()) {
                return Err(format_err(
                    origin,
                    format!(
                        "images of {h} x {w} downscaled by {} do not give the model's {} \
                         inputs",
                        st.downscale,
                        model.input_dim()
                    ),
                ));
            }
        }
        Ok(SfaModelFile {
            names: st.names,
            image_shape: st.image_shape,
            downscale: st.downscale,
            model,
        })
    }

    /// The file's JSON text.
    pub fn to_json(&self) -> Result<String> {
        let (kind, inner) = match &self.model {
            FittedSfa::Class(m) => ("class", m.to_json()?),
            FittedSfa::Global(m) => ("global", m.to_json()?),
        };
        let stored = Stored {
            kind: kind.into(),
            names: self.names.clone(),
            image_shape: self.image_shape,
            downscale: self.downscale,
            model: serde_json::from_str(&inner)
                .map_err(|e| Error::invalid("model", e.to_string()))?,
        };
        serde_json::to_string(&stored).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// Writes the model file as JSON (atomically).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        wscg_math::io::atomic::write(path, self.to_json()?)
    }
}
