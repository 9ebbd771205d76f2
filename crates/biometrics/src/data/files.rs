//! Users' own data for the recognition pipeline: a folder of images with one sub-folder per
//! identity, loose image files to identify, or a `.npy` matrix with a `.npy` label vector.
//!
//! Images (PNG, JPEG) are converted to grey (Rec. 709 luminance, values in `[0, 1]`) and
//! brought to one size: area averaging when shrinking, bilinear interpolation when
//! enlarging. Files are only read.

use std::path::{Path, PathBuf};

use faer::Mat;
use rayon::prelude::*;
use wscg_math::image::Image;
use wscg_math::resize::{resize, Interpolation};
use wscg_math::{npy, Error, Result};

use super::LabelledImages;

/// Labelled images plus the name of each label (the identity folder names).
#[derive(Clone, Debug)]
pub struct IdentityImages {
    /// Flattened images with labels `0..names.len()`.
    pub images: LabelledImages,
    /// Identity name of each label.
    pub names: Vec<String>,
    /// Source file of each row.
    pub files: Vec<PathBuf>,
}

impl IdentityImages {
    /// Bundles rows `x` of images of `shape` with their labels, names and sources.
    pub fn new(
        x: Mat<f64>,
        labels: Vec<u32>,
        (height, width): (usize, usize),
        names: Vec<String>,
        files: Vec<PathBuf>,
    ) -> Self {
        Self {
            images: LabelledImages {
                x,
                labels,
                height,
                width,
            },
            names,
            files,
        }
    }
}

fn is_image(p: &Path) -> bool {
    p.is_file()
        && p.extension()
            .and_then(|e| e.to_str())
            .map(|e| matches!(e.to_ascii_lowercase().as_str(), "png" | "jpg" | "jpeg"))
            .unwrap_or(false)
}

fn sorted_entries(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .map(|e| e.map(|e| e.path()).map_err(|err| Error::io(dir, err)))
        .collect::<Result<_>>()?;
    v.sort();
    Ok(v)
}

/// Image files directly inside `dir` (PNG/JPEG, sorted by name).
pub fn image_files(dir: &Path) -> Result<Vec<PathBuf>> {
    Ok(sorted_entries(dir)?
        .into_iter()
        .filter(|p| is_image(p))
        .collect())
}

/// Loads one image as a grey `height x width` row (see the module docs).
pub fn load_grey(path: &Path, size: (usize, usize)) -> Result<Vec<f64>> {
    let img = Image::<f32>::load(path)?.to_gray();
    let (h, w) = size;
    let img = if (img.height(), img.width()) == (h, w) {
        img
    } else {
        let method = if h <= img.height() && w <= img.width() {
            Interpolation::Area
        } else {
            Interpolation::Bilinear
        };
        resize(&img, h, w, method)?
    };
    Ok(img.data().iter().map(|&v| v as f64).collect())
}

/// Loads the listed image files into the rows of a matrix, resized to `size` (default: the
/// size of the first image).
pub fn load_images(
    files: &[PathBuf],
    size: Option<(usize, usize)>,
) -> Result<(Mat<f64>, (usize, usize))> {
    let first = files.first().ok_or(Error::Empty("image files"))?;
    let size = match size {
        Some((0, _)) | Some((_, 0)) => return Err(Error::invalid("size", "must be positive")),
        Some(s) => s,
        None => {
            let img = Image::<f32>::load(first)?;
            (img.height(), img.width())
        }
    };
    let rows: Vec<Vec<f64>> = files
        .par_iter()
        .map(|f| load_grey(f, size))
        .collect::<Result<_>>()?;
    let d = size.0 * size.1;
    Ok((Mat::from_fn(rows.len(), d, |i, j| rows[i][j]), size))
}

/// Loads a gallery: every sub-folder of `root` is one identity (sorted by name), holding
/// its PNG/JPEG images. Images are resized to `size` (default: the first image's size).
///
/// Errors: `root` unreadable or without identity folders, an identity folder without
/// images, unreadable or undecodable images.
pub fn load_identity_folder(root: &Path, size: Option<(usize, usize)>) -> Result<IdentityImages> {
    let mut names = Vec::new();
    let mut files = Vec::new();
    let mut labels = Vec::new();
    for dir in sorted_entries(root)?.into_iter().filter(|p| p.is_dir()) {
        let imgs = image_files(&dir)?;
        if imgs.is_empty() {
            return Err(Error::invalid(
                "gallery",
                format!("identity folder {} holds no PNG/JPEG images", dir.display()),
            ));
        }
        let label = names.len() as u32;
        names.push(
            dir.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        );
        labels.extend(std::iter::repeat_n(label, imgs.len()));
        files.extend(imgs);
    }
    if names.is_empty() {
        return Err(Error::invalid(
            "gallery",
            format!(
                "{} has no sub-folders; expected one sub-folder of images per identity",
                root.display()
            ),
        ));
    }
    let (x, shape) = load_images(&files, size)?;
    Ok(IdentityImages::new(x, labels, shape, names, files))
}

/// Reads an `n x d` matrix from a `.npy` file holding a 2-D array `(n, d)` or a stack of
/// images `(n, h, w)` (flattened row-major). Returns the matrix and the image shape
/// (`(1, d)` for a 2-D array).
pub fn read_npy_matrix(path: &Path) -> Result<(Mat<f64>, (usize, usize))> {
    let a = npy::read::<f64>(path)?;
    let (n, h, w) = match a.shape[..] {
        [n, d] => (n, 1, d),
        [n, h, w] => (n, h, w),
        _ => {
            return Err(Error::format(
                path,
                format!(
                    "expected a 2-D (n, d) or 3-D (n, h, w) array, found shape {:?}",
                    a.shape
                ),
            ))
        }
    };
    let d = h * w;
    Ok((Mat::from_fn(n, d, |i, j| a.data[i * d + j]), (h, w)))
}

/// Reads integer labels from a 1-D `.npy` file (any integer dtype, or floats holding whole
/// numbers), relabelled to `0..k` in sorted order of the original values; returns the
/// labels and the original values as names.
pub fn read_npy_labels(path: &Path) -> Result<(Vec<u32>, Vec<String>)> {
    let a = npy::read::<f64>(path)?;
    if a.shape.len() != 1 {
        return Err(Error::format(
            path,
            format!("labels must be a 1-D array, found shape {:?}", a.shape),
        ));
    }
    if let Some(v) = a.data.iter().find(|v| !v.is_finite() || v.fract() != 0.0) {
        return Err(Error::format(path, format!("label {v} is not an integer")));
    }
    let mut distinct: Vec<i64> = a.data.iter().map(|&v| v as i64).collect();
    distinct.sort_unstable();
    distinct.dedup();
    let labels = a
        .data
        .iter()
        .map(|&v| {
            distinct
                .binary_search(&(v as i64))
                .expect("value is present") as u32
        })
        .collect();
    Ok((labels, distinct.iter().map(|v| v.to_string()).collect()))
}

/// Reads a labelled data set from `x.npy` and `labels.npy` (see [`read_npy_matrix`] and
/// [`read_npy_labels`]). Errors when the label count differs from the row count.
pub fn read_npy_dataset(x_path: &Path, labels_path: &Path) -> Result<IdentityImages> {
    let (x, shape) = read_npy_matrix(x_path)?;
    let (labels, names) = read_npy_labels(labels_path)?;
    if labels.len() != x.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "{} labels for {} rows of {}",
            labels.len(),
            x.nrows(),
            x_path.display()
        )));
    }
    Ok(IdentityImages::new(x, labels, shape, names, Vec::new()))
}
