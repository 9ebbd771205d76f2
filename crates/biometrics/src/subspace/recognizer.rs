//! A stored recognition system: a fitted projection, the projected gallery with identity
//! names, and the image size queries are brought to. This is what
//! `wscg biometrics fdkeca fit` writes and `identify` reads (a versioned JSON file).

use std::path::Path;

use faer::MatRef;
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::{Method, Metric, Model, Projector, SubspaceClassifier};

/// The `format` field of a recognizer file.
pub const FORMAT: &str = "wscg-biometrics-recognizer";
/// The version written by this library.
pub const VERSION: u32 = 1;

/// A gallery of identities in a fitted subspace.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Recognizer {
    /// Always [`FORMAT`].
    pub format: String,
    /// File format version ([`VERSION`]).
    pub version: u32,
    /// Image height and width of the gallery rows (`(1, d)` for plain vectors).
    pub image_shape: (usize, usize),
    /// Identity name of each label.
    pub names: Vec<String>,
    /// Projection and projected gallery.
    pub classifier: SubspaceClassifier<Model>,
}

/// The answer for one query.
#[derive(Clone, Debug, PartialEq)]
pub struct Identification {
    /// Label of the nearest gallery sample.
    pub label: u32,
    /// Its identity name.
    pub name: String,
    /// Distance in the subspace (Euclidean, or `1 - cos`).
    pub distance: f64,
    /// Row of the nearest gallery sample.
    pub gallery_index: usize,
}

impl Recognizer {
    /// Fits `method` on the gallery rows `x` (labels index `names`) and projects them.
    ///
    /// Errors: as the method's `fit`; labels out of range of `names`; `image_shape` not
    /// matching the row width.
    pub fn fit(
        method: &Method,
        x: MatRef<'_, f64>,
        labels: &[u32],
        names: Vec<String>,
        image_shape: (usize, usize),
        metric: Metric,
    ) -> Result<Self> {
        if image_shape.0 * image_shape.1 != x.ncols() {
            return Err(Error::ShapeMismatch(format!(
                "image shape {image_shape:?} does not match rows of {} values",
                x.ncols()
            )));
        }
        if let Some(&l) = labels.iter().find(|&&l| l as usize >= names.len()) {
            return Err(Error::invalid(
                "labels",
                format!("label {l} has no name ({} names)", names.len()),
            ));
        }
        let model = method.fit(x)?;
        Ok(Self {
            format: FORMAT.into(),
            version: VERSION,
            image_shape,
            names,
            classifier: SubspaceClassifier::new(model, x, labels, metric)?,
        })
    }

    /// The nearest gallery identity of every row of `x`.
    pub fn identify(&self, x: MatRef<'_, f64>) -> Result<Vec<Identification>> {
        let c = &self.classifier;
        Ok(c.nearest(x)?
            .into_iter()
            .map(|nb| {
                let label = c.labels[nb.index];
                Identification {
                    label,
                    name: self.names[label as usize].clone(),
                    distance: nb.distance,
                    gallery_index: nb.index,
                }
            })
            .collect())
    }

    /// Input dimension `d` of the model.
    pub fn input_dim(&self) -> usize {
        self.classifier.projector.input_dim()
    }

    /// Writes the recognizer as JSON.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let json =
            serde_json::to_string(self).map_err(|e| Error::invalid("recognizer", e.to_string()))?;
        wscg_math::io::atomic::write(path, json)
    }

    /// Reads a file written by [`Recognizer::save`].
    ///
    /// Errors: unreadable file, not a recognizer file, a newer format version.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = wscg_math::error::read_file(path)?;
        let r: Recognizer = serde_json::from_slice(&bytes)
            .map_err(|e| Error::format(path, format!("not a recognizer file: {e}")))?;
        if r.format != FORMAT {
            return Err(Error::format(
                path,
                format!("format is {:?}, expected {FORMAT:?}", r.format),
            ));
        }
        if r.version > VERSION {
            return Err(Error::format(
                path,
                format!(
                    "written by a newer version ({}); this library reads up to {VERSION}",
                    r.version
                ),
            ));
        }
        let (h, w) = r.image_shape;
        if h * w != r.input_dim()
            || r.classifier
                .labels
                .iter()
                .any(|&l| l as usize >= r.names.len())
            || r.classifier.labels.len() != r.classifier.train.nrows()
        {
            return Err(Error::format(path, "inconsistent recognizer file"));
        }
        Ok(r)
    }
}
