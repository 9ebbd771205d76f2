//! The enrolled gallery of `wscg biometrics ear enroll` (a folder): `templates.npy`, the
//! block features of every gallery image (`n x blocks x block_len`, float32, section 3.3 of
//! paper 14), and `gallery.json`, the identity of every template, its source image and the
//! normalised ear size and block size the templates were computed at.

use std::path::Path;

use serde::{Deserialize, Serialize};
use wscg_math::{npy, Error, Result};

use super::{EarParams, Gallery};

/// The description file of a gallery folder.
pub const GALLERY_JSON: &str = "gallery.json";
/// The template array of a gallery folder.
pub const GALLERY_TEMPLATES: &str = "templates.npy";
/// Largest `gallery.json` read (64 MiB).
pub const MAX_GALLERY_JSON_BYTES: u64 = 64 << 20;

/// An enrolled ear gallery, as written to and read from its folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct EarGalleryFile {
    /// Identity names.
    pub identities: Vec<String>,
    /// Identity index of each template.
    pub labels: Vec<usize>,
    /// Source image of each template.
    pub files: Vec<String>,
    /// Height of the normalised ear the templates were computed at (pixels).
    pub height: usize,
    /// Width of the normalised ear (pixels).
    pub width: usize,
    /// Block side (pixels).
    pub block: usize,
    /// Blocks per template.
    #[serde(skip)]
    pub blocks: usize,
    /// Features per block.
    #[serde(skip)]
    pub block_len: usize,
    /// The templates, `labels.len() x blocks x block_len` in C order.
    #[serde(skip)]
    pub templates: Vec<f32>,
}

fn format_err(path: &Path, reason: impl Into<String>) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

impl EarGalleryFile {
    /// A gallery of `templates` (`labels.len() x params.blocks() x params.block_len()`)
    /// enrolled from `files` with `params`.
    ///
    /// Errors: counts or sizes that disagree, a label without an identity.
    pub fn new(
        identities: Vec<String>,
        labels: Vec<usize>,
        files: Vec<String>,
        params: &EarParams,
        templates: Vec<f32>,
    ) -> Result<Self> {
        let g = EarGalleryFile {
            identities,
            labels,
            files,
            height: params.height,
            width: params.width,
            block: params.block,
            blocks: params.blocks(),
            block_len: params.block_len(),
            templates,
        };
        g.check()
            .map_err(|reason| Error::invalid("gallery", reason))?;
        Ok(g)
    }

    /// Reads the gallery folder `dir` (see [`EarGalleryFile::from_parts`]).
    pub fn read(dir: impl AsRef<Path>) -> Result<Self> {
        let dir = dir.as_ref();
        let json_path = dir.join(GALLERY_JSON);
        let json =
            wscg_math::error::read_file_at_most(&json_path, MAX_GALLERY_JSON_BYTES, "galleries")?;
        let templates_path = dir.join(GALLERY_TEMPLATES);
        let templates = npy::read::<f32>(&templates_path)?;
        Self::from_parts(&json, &json_path, templates, &templates_path)
    }

    /// A gallery from the bytes of its `gallery.json` and its template array; the origins
    /// name the two files in errors.
    ///
    /// Errors ([`Error::Format`] naming the file at fault): not the JSON of a gallery,
    /// counts of labels and files that differ, a label without an identity, sizes that
    /// [`EarParams::validate`] refuses, a
    /// template array that is not `labels x blocks x block_len` for the sizes in the JSON,
    /// or that holds a value that is not finite.
    pub fn from_parts(
        json: &[u8],
        json_origin: &Path,
        templates: npy::NpyArray<f32>,
        templates_origin: &Path,
    ) -> Result<Self> {
        let mut g: EarGalleryFile = serde_json::from_slice(json).map_err(|e| {
            format_err(
                json_origin,
                format!("not a gallery written by `wscg biometrics ear enroll`: {e}"),
            )
        })?;
        let params = EarParams::default()
            .height(g.height)
            .width(g.width)
            .block(g.block);
        params
            .validate()
            .map_err(|e| format_err(json_origin, e.to_string()))?;
        (g.blocks, g.block_len) = (params.blocks(), params.block_len());
        let want = [g.labels.len(), g.blocks, g.block_len];
        if templates.shape != want {
            return Err(format_err(
                templates_origin,
                format!(
                    "shape {:?}, where {} lists {} templates of {} x {}",
                    templates.shape,
                    json_origin.display(),
                    want[0],
                    want[1],
                    want[2]
                ),
            ));
        }
        if let Some(i) = templates.data.iter().position(|v| !v.is_finite()) {
            return Err(format_err(
                templates_origin,
                format!("value {i} is not finite"),
            ));
        }
        g.templates = templates.data;
        g.check()
            .map_err(|reason| format_err(json_origin, reason))?;
        Ok(g)
    }

    /// Counts and sizes agree.
    fn check(&self) -> std::result::Result<(), String> {
        let n = self.labels.len();
        if n == 0 {
            return Err("the gallery holds no template".into());
        }
        if self.files.len() != n {
            return Err(format!("{} files for {n} templates", self.files.len()));
        }
        if let Some(&l) = self.labels.iter().find(|&&l| l >= self.identities.len()) {
            return Err(format!("label {l} has no identity"));
        }
        let want = n
            .checked_mul(self.blocks)
            .and_then(|v| v.checked_mul(self.block_len));
        if want != Some(self.templates.len()) {
            return Err(format!(
                "{} template values for {n} templates of {} x {}",
                self.templates.len(),
                self.blocks,
                self.block_len
            ));
        }
        Ok(())
    }

    /// Refuses `params` whose normalised size or block size differ from the gallery's.
    pub fn check_params(&self, params: &EarParams) -> Result<()> {
        if (params.height, params.width, params.block) != (self.height, self.width, self.block) {
            return Err(Error::invalid(
                "params",
                format!(
                    "the gallery was enrolled at {} x {} with {}-pixel blocks, these \
                     parameters are {} x {} with {}-pixel blocks",
                    self.height, self.width, self.block, params.height, params.width, params.block
                ),
            ));
        }
        Ok(())
    }

    /// The gallery for matching.
    pub fn gallery(&self) -> Result<Gallery> {
        Gallery::from_features(
            &self.templates,
            self.labels.len(),
            self.blocks,
            self.block_len,
        )
    }

    /// Writes the folder `dir` (created if needed; each file atomically).
    pub fn write(&self, dir: impl AsRef<Path>) -> Result<()> {
        let dir = dir.as_ref();
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        npy::write(
            dir.join(GALLERY_TEMPLATES),
            &[self.labels.len(), self.blocks, self.block_len],
            &self.templates,
        )?;
        let json = serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid("gallery", e.to_string()))?;
        wscg_math::io::atomic::write(dir.join(GALLERY_JSON), json)
    }
}
