//! The paper's quality and speed study (section 5, which judges aliasing by eye; here made
//! quantitative):
//! mean absolute difference against a reference render, a high-pass (Laplacian) energy test
//! for aliasing, and sweeps over slice distance and sub-samples that time every
//! configuration over several views.

use std::time::Instant;

use wscg_math::{Error, Image, Result};

use super::camera::SliceCamera;
use super::classify::TransferFunction;
use super::field::ScalarField;
use super::method::{IlluminationParams, Light, Method};
use super::render_many;

/// Mean absolute difference over all pixels and the RGB channels of two `H x W x C` images
/// (`C >= 3`; alpha ignored), the paper's Table 1 error. Errors: shapes differ, fewer than 3
/// channels.
pub fn mean_abs_diff(a: &Image<f32>, b: &Image<f32>) -> Result<f64> {
    a.ensure_same_shape(b)?;
    let c = a.channels();
    if c < 3 {
        return Err(Error::invalid(
            "image",
            format!("needs >= 3 channels, got {c}"),
        ));
    }
    let mut sum = 0f64;
    for (pa, pb) in a.data().chunks(c).zip(b.data().chunks(c)) {
        for k in 0..3 {
            sum += (pa[k] - pb[k]).abs() as f64;
        }
    }
    Ok(sum / (3 * a.height() * a.width()) as f64)
}

/// Mean squared 5-point Laplacian of the RGB difference `a - b` over interior pixels: the
/// high-frequency (ring, wood-grain) energy of the error. Errors: as [`mean_abs_diff`].
pub fn laplacian_energy(a: &Image<f32>, b: &Image<f32>) -> Result<f64> {
    a.ensure_same_shape(b)?;
    let (h, w, c) = a.shape();
    if c < 3 {
        return Err(Error::invalid(
            "image",
            format!("needs >= 3 channels, got {c}"),
        ));
    }
    if h < 3 || w < 3 {
        return Ok(0.0);
    }
    let d = |y: usize, x: usize, k: usize| (a.at(y, x, k) - b.at(y, x, k)) as f64;
    let mut sum = 0f64;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            for k in 0..3 {
                let l = 4.0 * d(y, x, k)
                    - d(y - 1, x, k)
                    - d(y + 1, x, k)
                    - d(y, x - 1, k)
                    - d(y, x + 1, k);
                sum += l * l;
            }
        }
    }
    Ok(sum / (3 * (h - 2) * (w - 2)) as f64)
}

/// The "alias-free" criterion: the paper judges aliasing visually (§5.2, Fig. 3); this
/// quantitative stand-in is ours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AliasCriterion {
    /// Largest MAD against the reference.
    pub max_mad: f64,
    /// Largest Laplacian energy of the error, as a multiple of the reference's own
    /// fine-versus-reference energy.
    pub max_energy_ratio: f64,
}

impl Default for AliasCriterion {
    fn default() -> Self {
        Self {
            max_mad: 0.005,
            max_energy_ratio: 2.0,
        }
    }
}

/// One configuration of a sweep.
#[derive(Clone, Debug)]
pub struct StudyEntry {
    /// The configuration.
    pub method: Method,
    /// MAD against the reference, averaged over the views.
    pub mad: f64,
    /// Laplacian energy of the error, averaged over the views.
    pub energy: f64,
    /// Mean wall time per frame (seconds).
    pub seconds: f64,
    /// Whether the configuration meets the criterion.
    pub alias_free: bool,
}

/// A sweep's result: the reference's energy scale and the entries.
#[derive(Clone, Debug)]
pub struct Study {
    /// Mean time per frame of the reference (seconds).
    pub reference_seconds: f64,
    /// Laplacian energy of the fine render against the reference (the aliasing scale).
    pub fine_energy: f64,
    /// The configurations, in the order given.
    pub entries: Vec<StudyEntry>,
}

impl Study {
    /// The fastest alias-free entry whose method satisfies `pred`.
    pub fn fastest(&self, pred: impl Fn(&Method) -> bool) -> Option<&StudyEntry> {
        self.entries
            .iter()
            .filter(|e| e.alias_free && pred(&e.method))
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
    }
}

/// Renders every view with `method`; returns the images and the mean seconds per frame
/// (including the one-off tables, shared by the views).
pub fn render_views(
    field: &ScalarField,
    tf: &TransferFunction,
    views: &[SliceCamera],
    light: &Light,
    method: &Method,
    settings: &IlluminationParams,
) -> Result<(Vec<Image<f32>>, f64)> {
    if views.is_empty() {
        return Err(Error::Empty("views"));
    }
    let t0 = Instant::now();
    let images = render_many(field, tf, views, light, method, settings)?
        .into_iter()
        .map(|r| r.image)
        .collect();
    Ok((images, t0.elapsed().as_secs_f64() / views.len() as f64))
}

/// Runs the study of the paper's §5.2: renders `reference` and `fine` (a finer reference, for
/// the aliasing scale) and every configuration over `views`, scoring each against the
/// reference.
/// `progress` is called with `(done, total)` after each configuration.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    field: &ScalarField,
    tf: &TransferFunction,
    views: &[SliceCamera],
    light: &Light,
    settings: &IlluminationParams,
    reference: &Method,
    fine: &Method,
    configs: &[Method],
    criterion: &AliasCriterion,
    mut progress: impl FnMut(usize, usize),
) -> Result<Study> {
    let (refs, reference_seconds) = render_views(field, tf, views, light, reference, settings)?;
    let (fines, _) = render_views(field, tf, views, light, fine, settings)?;
    let nv = views.len() as f64;
    let mut fine_energy = 0f64;
    for (f, r) in fines.iter().zip(&refs) {
        fine_energy += laplacian_energy(f, r)? / nv;
    }
    let mut entries = Vec::with_capacity(configs.len());
    for (i, m) in configs.iter().enumerate() {
        let (imgs, seconds) = render_views(field, tf, views, light, m, settings)?;
        let (mut mad, mut energy) = (0f64, 0f64);
        for (img, r) in imgs.iter().zip(&refs) {
            mad += mean_abs_diff(img, r)? / nv;
            energy += laplacian_energy(img, r)? / nv;
        }
        let alias_free =
            mad <= criterion.max_mad && energy <= criterion.max_energy_ratio * fine_energy;
        entries.push(StudyEntry {
            method: *m,
            mad,
            energy,
            seconds,
            alias_free,
        });
        progress(i + 1, configs.len());
    }
    Ok(Study {
        reference_seconds,
        fine_energy,
        entries,
    })
}

/// The second-stage grid of the paper's §5.2 (Fig. 4): ICS at every slice distance of
/// `distances`, SCS and PI-SCS with `0..=max_m` sub-samples at each (PI with `m = 0` is
/// PI-ICS).
pub fn grid(distances: &[f32], max_m: u32) -> Vec<Method> {
    let mut out = Vec::new();
    for &ds in distances {
        out.push(Method::ics(ds));
        for m in 1..=max_m {
            out.push(Method::scs(ds, m));
        }
        for m in 0..=max_m {
            out.push(Method::pi_scs(ds, m));
        }
    }
    out
}
