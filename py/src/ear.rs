//! `wscg._native.ear`: bindings of `wscg_biometrics::ear` (paper 14, occlusion detection and
//! index-based ear recognition) and of the image operations it is built from
//! (`wscg_biometrics::imgops::{tone, mask}`, `wscg_math::wavelet::haar_ll`).
//!
//! `cmc` and the building blocks (`rgb_to_gray`, `equalize_hist`, `resize`, `haar_ll`, the
//! disk morphology, `fill_holes`) are `wscg.ear`'s functions themselves, re-exported by
//! `python/wscg/ear.py` (which holds the module's documentation). The pipeline functions
//! take the pipeline parameters as a dict (keys: the fields of `EarParams`, see
//! [`PARAM_KEYS`]) built by the Python layer, which documents them once for every function.
//! Every argument is converted here: images of dtype uint8 ([`args::u8s`], a list or a stack
//! of them [`images_arg`]), templates, masks and planes as any real array-like (through
//! [`crate::args`]). Every function validates its input, so a direct call cannot panic; the
//! GIL is released while Rust works.

use numpy::{PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use wscg_biometrics::ear::features::check_input;
use wscg_biometrics::ear::protocol::evaluate_images;
use wscg_biometrics::ear::synth::{generate, EarSynthParams, OcclusionKind};
use wscg_biometrics::ear::{
    self, EarParams, EarTemplate, Gallery, Identification, OcclusionReport, ScoreRule, SkinModel,
    SkinRule,
};
use wscg_biometrics::imgops::{mask, tone};
use wscg_math::{Image, ImageView};

use crate::args::{self, uint};
use crate::cfg::dict_item;
use crate::convert::{array, dims2, image_dims, index_vector, indices, values, vector, Arr};
use crate::errors::{value_error, IntoPy};

/// The keys of the parameter dict (the fields of `EarParams`; the skin model is split into
/// `skin_mean` and `skin_cov`, the skin rule into `skin_rule` and `min_likelihood`).
const PARAM_KEYS: [&str; 17] = [
    "height",
    "width",
    "block",
    "skin_mean",
    "skin_cov",
    "skin_rule",
    "min_likelihood",
    "min_intensity",
    "close_radius",
    "fill_holes",
    "block_skin_fraction",
    "reject_above_pct",
    "shifts",
    "score",
    "mask_features",
    "gray_enrolment",
    "equalize_on_skin",
];

/// Largest normalised image (`height * width`) and resize target accepted.
const MAX_NORMALISED: usize = 1 << 26;

/// A skin mean `(r, g)` from a sequence of two numbers.
fn mean2(v: Vec<f64>) -> PyResult<[f64; 2]> {
    match v[..] {
        [r, g] => Ok([r, g]),
        _ => Err(value_error(format!(
            "`skin_mean` must hold 2 values (r, g), got {}",
            v.len()
        ))),
    }
}

/// A 2 x 2 covariance from nested sequences.
fn cov22(v: Vec<Vec<f64>>) -> PyResult<[[f64; 2]; 2]> {
    match &v[..] {
        [a, b] if a.len() == 2 && b.len() == 2 => Ok([[a[0], a[1]], [b[0], b[1]]]),
        _ => Err(value_error(format!(
            "`skin_cov` must be a 2 x 2 matrix, got {} rows of lengths {:?}",
            v.len(),
            v.iter().map(Vec::len).collect::<Vec<_>>()
        ))),
    }
}

/// A validated skin model from its mean and covariance.
fn skin_model(mean: Vec<f64>, cov: Vec<Vec<f64>>) -> PyResult<SkinModel> {
    SkinModel::new(mean2(mean)?, cov22(cov)?).py_err()
}

/// The `shifts` entry: `(d_row, d_col)` block offsets, an `(n, 2)` array-like of integers.
fn shifts_in(v: &Bound<'_, PyAny>) -> PyResult<Vec<(i32, i32)>> {
    let a = args::array::<i64>("shifts", v)?;
    let offsets = values(&a);
    if offsets.is_empty() {
        return Ok(Vec::new());
    }
    if a.ndim() != 2 || a.shape()[1] != 2 {
        return Err(value_error(format!(
            "`shifts` must be a list of (d_row, d_col) pairs, got shape {}",
            args::shape_repr(a.shape())
        )));
    }
    let offset = |x: i64| {
        i32::try_from(x)
            .ok()
            .filter(|x| x.unsigned_abs() <= 1 << 30)
            .ok_or_else(|| value_error(format!("`shifts` must hold block offsets, got {x}")))
    };
    offsets
        .chunks_exact(2)
        .map(|c| Ok((offset(c[0])?, offset(c[1])?)))
        .collect()
}

/// `EarParams` from the parameter dict (absent keys keep the paper's defaults), validated.
fn params_from(spec: Option<&Bound<'_, PyDict>>) -> PyResult<EarParams> {
    let mut p = EarParams::default();
    if let Some(d) = spec {
        for k in d.keys() {
            let k: String = k
                .extract()
                .map_err(|_| value_error("ear parameter names must be strings"))?;
            if !PARAM_KEYS.contains(&k.as_str()) {
                return Err(value_error(format!(
                    "unknown ear parameter {k:?}; valid: {}",
                    PARAM_KEYS.join(", ")
                )));
            }
        }
        if let Some(v) = dict_item(d, "height")? {
            p.height = v;
        }
        if let Some(v) = dict_item(d, "width")? {
            p.width = v;
        }
        if let Some(v) = dict_item(d, "block")? {
            p.block = v;
        }
        if let Some(v) = dict_item::<Vec<f64>>(d, "skin_mean")? {
            p.skin_model.mean = mean2(v)?;
        }
        if let Some(v) = dict_item::<Vec<Vec<f64>>>(d, "skin_cov")? {
            p.skin_model.cov = cov22(v)?;
        }
        let t: Option<f64> = dict_item(d, "min_likelihood")?;
        let rule: Option<String> = dict_item(d, "skin_rule")?;
        let base = match rule.as_deref() {
            Some(name) => SkinRule::by_name(name).py_err()?,
            None => SkinRule::default(),
        };
        p.skin_rule = t.map_or(base, |t| base.with_min_likelihood(t));
        if let Some(v) = dict_item(d, "min_intensity")? {
            p.min_intensity = v;
        }
        if let Some(v) = dict_item(d, "close_radius")? {
            p.close_radius = v;
        }
        if let Some(v) = dict_item(d, "fill_holes")? {
            p.fill_holes = v;
        }
        if let Some(v) = dict_item(d, "block_skin_fraction")? {
            p.block_skin_fraction = v;
        }
        if let Some(v) = dict_item(d, "reject_above_pct")? {
            p.reject_above_pct = v;
        }
        if let Some(v) = d.get_item("shifts")?.filter(|v| !v.is_none()) {
            p.shifts = shifts_in(&v)?;
        }
        if let Some(v) = dict_item::<String>(d, "score")? {
            p.score = ScoreRule::parse(&v).py_err()?;
        }
        if let Some(v) = dict_item(d, "mask_features")? {
            p.mask_features = v;
        }
        if let Some(v) = dict_item(d, "gray_enrolment")? {
            p.gray_enrolment = v;
        }
        if let Some(v) = dict_item(d, "equalize_on_skin")? {
            p.equalize_on_skin = v;
        }
    }
    p.validate().py_err()?;
    if p.height
        .checked_mul(p.width)
        .is_none_or(|n| n > MAX_NORMALISED)
    {
        return Err(value_error(format!(
            "the normalised size {} x {} is too large (at most 2^26 pixels)",
            p.height, p.width
        )));
    }
    Ok(p)
}

/// An 8-bit image from an `(H, W)` or `(H, W, C)` array; a zero size is a `ValueError`.
fn image_in(name: &str, a: &PyReadonlyArrayDyn<u8>) -> PyResult<Image<u8>> {
    image_from(name, a.shape(), values(a).into_owned())
}

/// An 8-bit image of `shape` `(H, W)` or `(H, W, C)` holding `data`, not empty.
fn image_from(name: &str, shape: &[usize], data: Vec<u8>) -> PyResult<Image<u8>> {
    let (h, w, c) = image_dims(name, shape)?;
    if h == 0 || w == 0 || c == 0 {
        return Err(value_error(format!("`{name}` is empty (shape {shape:?})")));
    }
    Image::new(h, w, c, data).py_err()
}

/// The uint8 image argument `name` ([`args::u8s`]) as an image.
fn image_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Image<u8>> {
    image_in(name, &args::u8s(name, obj)?)
}

/// The images argument `name`: a sequence of uint8 images (each named `name[k]` in errors)
/// or a stacked uint8 array `(n, H, W)` or `(n, H, W, C)`.
fn images_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Image<u8>>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        if !matches!(a.ndim(), 3 | 4) {
            return Err(value_error(format!(
                "`{name}` must be a stack (n, H, W, 3) or a list of images, got shape {:?}",
                a.shape()
            )));
        }
        let a = args::u8s(name, obj)?;
        let shape = a.shape().to_vec();
        let v = values(&a);
        let per: usize = shape[1..].iter().product();
        return (0..shape[0])
            .map(|k| {
                image_from(
                    &format!("{name}[{k}]"),
                    &shape[1..],
                    v[k * per..(k + 1) * per].to_vec(),
                )
            })
            .collect();
    }
    obj.try_iter()
        .map_err(|_| {
            value_error(format!(
                "`{name}` must be a list of images or a stacked array"
            ))
        })?
        .enumerate()
        .map(|(k, im)| image_arg(&format!("{name}[{k}]"), &im?))
        .collect()
}

/// The template argument `name`, a real `(blocks, block_len)` array-like (kept as float32).
fn template_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<EarTemplate> {
    let a = args::array::<f32>(name, obj)?;
    let (b, k) = dims2(name, &a)?;
    EarTemplate::new(values(&a).into_owned(), b, k).py_err()
}

fn template_out<'py>(py: Python<'py>, t: &EarTemplate) -> PyResult<Arr<'py, f32>> {
    array(py, &[t.blocks(), t.block_len()], t.features().to_vec())
}

/// A binary mask from a 2-D bool array, as 0/1 bytes with its size.
fn mask_in(name: &str, a: &PyReadonlyArrayDyn<bool>) -> PyResult<(Vec<u8>, usize, usize)> {
    let (h, w) = dims2(name, a)?;
    if h == 0 || w == 0 {
        return Err(value_error(format!("`{name}` is empty (shape {h} x {w})")));
    }
    Ok((values(a).iter().map(|&v| u8::from(v)).collect(), h, w))
}

fn mask_out<'py>(py: Python<'py>, mask: Image<u8>) -> PyResult<Arr<'py, bool>> {
    crate::convert::image_array(py, mask.map(|x| x != 0), true)
}

/// A finite radius.
fn radius_in(radius: f64) -> PyResult<f64> {
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(value_error(format!(
            "`radius` must be finite and >= 0, got {radius}"
        )));
    }
    Ok(radius)
}

/// The occlusion report as a dict (grids shaped `(rows, cols)` of blocks).
fn report_dict<'py>(
    py: Python<'py>,
    r: &OcclusionReport,
    p: &EarParams,
) -> PyResult<Bound<'py, PyDict>> {
    let (gr, gc) = p.grid();
    let d = PyDict::new(py);
    d.set_item("mask", mask_out(py, r.skin_mask.clone())?)?;
    d.set_item("blocks", array(py, &[gr, gc], r.block_unoccluded.clone())?)?;
    d.set_item(
        "block_skin_fraction",
        array(py, &[gr, gc], r.block_skin_fraction.clone())?,
    )?;
    d.set_item("index", index_vector(py, r.index())?)?;
    d.set_item("occluded_pct", r.occluded_pct)?;
    d.set_item("rejected", r.rejected)?;
    Ok(d)
}

/// Ranking as `(order int64, scores float64)` arrays.
fn ranking_out<'py>(
    py: Python<'py>,
    ranked: &[(usize, f64)],
) -> PyResult<(Arr<'py, i64>, Arr<'py, f64>)> {
    Ok((
        index_vector(py, ranked.iter().map(|r| r.0))?,
        vector(py, ranked.iter().map(|r| r.1).collect())?,
    ))
}

// ------------------------------------------------------------------------------------------
// Pipeline
// ------------------------------------------------------------------------------------------

/// Enrolment template `(blocks, block_len)` of one clean ear crop.
#[pyfunction]
#[pyo3(signature = (image, params=None))]
fn enroll<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Arr<'py, f32>> {
    let im = image_arg("image", image)?;
    let p = params_from(params.as_ref())?;
    let t = crate::pool::detach(py, || ear::enroll(&im, &p)).py_err()?;
    template_out(py, &t)
}

/// Templates `(n, blocks, block_len)` of a list of clean ear crops (in parallel).
#[pyfunction]
#[pyo3(signature = (images, params=None))]
fn enroll_many<'py>(
    py: Python<'py>,
    images: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Arr<'py, f32>> {
    let imgs = images_arg("images", images)?;
    let p = params_from(params.as_ref())?;
    if imgs.is_empty() {
        return Err(value_error("`images` is empty: nothing to enrol"));
    }
    let ts = crate::pool::detach(py, || {
        imgs.par_iter()
            .map(|im| ear::enroll(im, &p))
            .collect::<wscg_math::Result<Vec<_>>>()
    })
    .py_err()?;
    let flat: Vec<f32> = ts
        .iter()
        .flat_map(|t| t.features().iter().copied())
        .collect();
    array(py, &[ts.len(), p.blocks(), p.block_len()], flat)
}

/// Occlusion report (Algorithm 1) of an RGB ear crop.
#[pyfunction]
#[pyo3(signature = (image, params=None))]
fn detect_occlusion<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let im = image_arg("image", image)?;
    let p = params_from(params.as_ref())?;
    let r = crate::pool::detach(py, || ear::detect_occlusion(&im, &p)).py_err()?;
    report_dict(py, &r, &p)
}

/// Per-pixel skin decision (steps 2-6, before closing) of an RGB image at its own size.
#[pyfunction]
#[pyo3(signature = (image, params=None))]
fn skin_pixels<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Arr<'py, bool>> {
    let im = image_arg("image", image)?;
    let p = params_from(params.as_ref())?;
    check_input(&im, false).py_err()?;
    let s = crate::pool::detach(py, || ear::skin_pixels(&im, &p))?;
    mask_out(py, Image::new(im.height(), im.width(), 1, s).py_err()?)
}

/// Every quantity of the match of a probe image against one template.
#[pyfunction]
#[pyo3(signature = (image, template, params=None))]
fn score<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    template: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let im = image_arg("image", image)?;
    let t = template_arg("template", template)?;
    let p = params_from(params.as_ref())?;
    t.check(&p).py_err()?;
    let (probe, b) = crate::pool::detach(py, || -> wscg_math::Result<_> {
        let probe = ear::make_probe(&im, &p)?;
        let b = ear::score(&probe, &t, &p)?;
        Ok((probe, b))
    })
    .py_err()?;
    let (ns, m) = (p.shifts.len(), probe.index.len());
    let d = PyDict::new(py);
    let rules = PyDict::new(py);
    for (rule, v) in ScoreRule::ALL.iter().zip(b.rules) {
        rules.set_item(rule.name(), v)?;
    }
    d.set_item("rules", rules)?;
    d.set_item("score", b.get(p.score))?;
    d.set_item(
        "per_shift",
        vector(
            py,
            b.per_shift.iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
        )?,
    )?;
    d.set_item(
        "distances",
        array(
            py,
            &[ns, m],
            b.distances.iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
        )?,
    )?;
    d.set_item(
        "best_shift",
        index_vector(py, b.best_shift.iter().copied())?,
    )?;
    d.set_item("index", index_vector(py, probe.index.iter().copied())?)?;
    d.set_item(
        "shifts",
        array(
            py,
            &[ns, 2],
            p.shifts
                .iter()
                .flat_map(|&(a, b)| [a as i64, b as i64])
                .collect(),
        )?,
    )?;
    let r = probe.report.as_ref();
    d.set_item("occluded_pct", r.map_or(f64::NAN, |r| r.occluded_pct))?;
    d.set_item("rejected", probe.rejected())?;
    Ok(d)
}

/// Whole-ear baseline score (Fig. 12) of a probe image against one template.
#[pyfunction]
#[pyo3(signature = (image, template, params=None))]
fn baseline_score(
    py: Python<'_>,
    image: &Bound<'_, PyAny>,
    template: &Bound<'_, PyAny>,
    params: Option<Bound<'_, PyDict>>,
) -> PyResult<f64> {
    let im = image_arg("image", image)?;
    let t = template_arg("template", template)?;
    let p = params_from(params.as_ref())?;
    crate::pool::detach(py, || {
        let probe = ear::make_baseline_probe(&im, &p)?;
        ear::baseline_score(&probe, &t, &p)
    })
    .py_err()
}

/// A gallery of enrolled templates with the parameters to match probes against it.
#[pyclass(module = "wscg._native.ear", name = "EarMatcher", frozen)]
pub struct PyEarMatcher {
    gallery: Gallery,
    params: EarParams,
}

impl PyEarMatcher {
    fn probe(&self, py: Python<'_>, image: &Bound<'_, PyAny>) -> PyResult<ear::Probe> {
        let im = image_arg("image", image)?;
        crate::pool::detach(py, || ear::make_probe(&im, &self.params)).py_err()
    }
}

#[pymethods]
impl PyEarMatcher {
    /// Lays out `(n, blocks, block_len)` templates (any real array-like, kept as float32;
    /// named `X` in errors, the argument of `EarMatcher.fit`).
    #[new]
    #[pyo3(signature = (templates, params=None))]
    fn new(
        py: Python<'_>,
        templates: &Bound<'_, PyAny>,
        params: Option<Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let templates = args::array::<f32>("X", templates)?;
        let p = params_from(params.as_ref())?;
        let (n, b, k) = match *templates.shape() {
            [n, b, k] => (n, b, k),
            ref s => {
                return Err(value_error(format!(
                    "`templates` must be a 3-D (n, blocks, block_len) array, got shape {s:?}"
                )))
            }
        };
        if (b, k) != (p.blocks(), p.block_len()) {
            return Err(value_error(format!(
                "shape mismatch: templates have {b} blocks x {k} features, the parameters \
                 need {} x {}",
                p.blocks(),
                p.block_len()
            )));
        }
        let flat = values(&templates);
        let gallery =
            crate::pool::detach(py, || Gallery::from_features(&flat, n, b, k)).py_err()?;
        Ok(Self { gallery, params: p })
    }

    fn __len__(&self) -> usize {
        self.gallery.len()
    }

    /// The templates as a new `(n, blocks, block_len)` array.
    fn templates<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f32>> {
        let n = self.gallery.len();
        let (b, k) = (self.params.blocks(), self.params.block_len());
        let mut flat = Vec::with_capacity(n * b * k);
        for g in 0..n {
            flat.extend_from_slice(self.gallery.template(g).py_err()?.features());
        }
        array(py, &[n, b, k], flat)
    }

    /// `(rejected, occluded_pct, order, scores)`; order and scores are empty when rejected.
    fn identify<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
    ) -> PyResult<(bool, f64, Arr<'py, i64>, Arr<'py, f64>)> {
        let probe = self.probe(py, image)?;
        let pct = probe.report.as_ref().map_or(f64::NAN, |r| r.occluded_pct);
        let id = crate::pool::detach(py, || ear::identify(&probe, &self.gallery, &self.params))
            .py_err()?;
        match id {
            Identification::Rejected { occluded_pct } => {
                let (o, s) = ranking_out(py, &[])?;
                Ok((true, occluded_pct, o, s))
            }
            Identification::Ranked(r) => {
                let (o, s) = ranking_out(py, &r)?;
                Ok((false, pct, o, s))
            }
        }
    }

    /// `(scores in gallery order, rejected, occluded_pct)`; the scores are computed on the
    /// kept blocks whether or not the probe is rejected.
    fn scores<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
    ) -> PyResult<(Arr<'py, f64>, bool, f64)> {
        let probe = self.probe(py, image)?;
        let pct = probe.report.as_ref().map_or(f64::NAN, |r| r.occluded_pct);
        let s = crate::pool::detach(py, || ear::scores(&probe, &self.gallery, &self.params))
            .py_err()?;
        Ok((vector(py, s)?, probe.rejected(), pct))
    }

    /// Whole-ear baseline ranking `(order, scores)` (Fig. 12; never rejects).
    fn identify_baseline<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
    ) -> PyResult<(Arr<'py, i64>, Arr<'py, f64>)> {
        let im = image_arg("image", image)?;
        let id = crate::pool::detach(py, || {
            ear::identify_baseline(&im, &self.gallery, &self.params)
        })
        .py_err()?;
        ranking_out(py, id.ranking().unwrap_or(&[]))
    }
}

/// Cumulative match characteristic: ``cmc[r - 1]`` is the fraction of accepted probes
/// whose true identity is within the top ``r``. ``ranks`` holds each probe's 0-based rank
/// of its true identity, ``-1`` for a rejected probe (excluded: neither a success nor a
/// failure). ``ValueError`` for ``max_rank < 1`` or when every probe is rejected.
#[pyfunction]
fn cmc<'py>(py: Python<'py>, ranks: &Bound<'py, PyAny>, max_rank: i128) -> PyResult<Arr<'py, f64>> {
    let ranks = args::array::<i64>("ranks", ranks)?;
    let max_rank: usize = uint(py, "max_rank", max_rank, 0)?;
    if ranks.shape().len() != 1 {
        return Err(value_error(format!(
            "`ranks` must be a 1-D array, got shape {:?}",
            ranks.shape()
        )));
    }
    let r = values(&ranks)
        .iter()
        .map(|&v| match v {
            -1 => Ok(None),
            v if v >= 0 => Ok(Some(v as usize)),
            v => Err(value_error(format!(
                "`ranks` holds {v}; ranks are >= 0, or -1 for a rejected probe"
            ))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    vector(py, ear::cmc(&r, max_rank).py_err()?)
}

/// Synthetic ears with exact occluder masks.
#[pyfunction]
#[pyo3(signature = (n_subjects, n_probes, seed, occlusion, min_pct, max_pct, canvas=None,
                    shape_spread=None, shift_px=None, rotation_deg=None, gain=None,
                    white_balance=None, noise_sigma=None, params=None))]
#[allow(clippy::too_many_arguments)]
fn make_ears<'py>(
    py: Python<'py>,
    n_subjects: i128,
    n_probes: i128,
    seed: i128,
    occlusion: &str,
    min_pct: f64,
    max_pct: f64,
    canvas: Option<&Bound<'py, PyAny>>,
    shape_spread: Option<f64>,
    shift_px: Option<f64>,
    rotation_deg: Option<f64>,
    gain: Option<&Bound<'py, PyAny>>,
    white_balance: Option<f64>,
    noise_sigma: Option<f64>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = params_from(params.as_ref())?;
    let n_subjects: usize = uint(py, "n_subjects", n_subjects, 0)?;
    let n_probes: usize = uint(py, "n_probes", n_probes, 0)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let canvas = canvas
        .filter(|c| !c.is_none())
        .map(|c| args::size2(py, "canvas", c))
        .transpose()?;
    let gain = gain
        .filter(|g| !g.is_none())
        .map(|g| args::pair("gain", g))
        .transpose()?;
    let kind = match occlusion.to_ascii_lowercase().replace('_', "-").as_str() {
        "none" => OcclusionKind::None,
        "colour" | "color" => OcclusionKind::Colour { min_pct, max_pct },
        "earring" => OcclusionKind::Earring,
        "dark-hair" => OcclusionKind::Hair { dark: true },
        "blond-hair" => OcclusionKind::Hair { dark: false },
        other => {
            return Err(value_error(format!(
                "`occlusion` must be \"none\", \"colour\", \"earring\", \"dark-hair\" or \
                 \"blond-hair\", got {other:?}"
            )))
        }
    };
    let d = EarSynthParams::default();
    let (height, width) = canvas.unwrap_or((d.height, d.width));
    let cfg = EarSynthParams::default()
        .height(height)
        .width(width)
        .shape_spread(shape_spread.unwrap_or(d.shape_spread))
        .shift_px(shift_px.unwrap_or(d.shift_px))
        .rotation_deg(rotation_deg.unwrap_or(d.rotation_deg))
        .gain(gain.unwrap_or(d.gain))
        .white_balance(white_balance.unwrap_or(d.white_balance))
        .noise_sigma(noise_sigma.unwrap_or(d.noise_sigma));
    const MAX_PIXELS: usize = 1 << 31;
    let total = n_subjects
        .checked_add(n_subjects.saturating_mul(n_probes))
        .and_then(|n| n.checked_mul(height))
        .and_then(|n| n.checked_mul(width))
        .and_then(|n| n.checked_mul(3));
    if total.is_none_or(|t| t > MAX_PIXELS) {
        return Err(value_error(format!(
            "{n_subjects} subjects x {n_probes} probes of {height} x {width} is too large \
             (at most 2^31 bytes of images)"
        )));
    }
    let set = crate::pool::detach(py, || generate(n_subjects, n_probes, kind, seed, &cfg, &p))
        .py_err()?;
    let (h, w) = (cfg.height, cfg.width);
    let (gr, gc) = p.grid();
    let m = set.probes.len();
    let enrol: Vec<u8> = set.enrol.iter().flat_map(|im| im.data().to_vec()).collect();
    let probes: Vec<u8> = set
        .probes
        .iter()
        .flat_map(|pr| pr.image.rgb.data().to_vec())
        .collect();
    let masks: Vec<bool> = set
        .probes
        .iter()
        .flat_map(|pr| pr.image.occluder_mask.iter().map(|&v| v != 0))
        .collect();
    let blocks: Vec<bool> = set
        .probes
        .iter()
        .flat_map(|pr| pr.occluded_blocks.iter().copied())
        .collect();
    let out = PyDict::new(py);
    out.set_item("enrol", array(py, &[set.enrol.len(), h, w, 3], enrol)?)?;
    out.set_item("probes", array(py, &[m, h, w, 3], probes)?)?;
    out.set_item(
        "labels",
        index_vector(py, set.probes.iter().map(|pr| pr.subject))?,
    )?;
    out.set_item("occluder_masks", array(py, &[m, h, w], masks)?)?;
    out.set_item("occluded_blocks", array(py, &[m, gr, gc], blocks)?)?;
    out.set_item(
        "occluded_pct",
        vector(py, set.probes.iter().map(|pr| pr.occluded_pct()).collect())?,
    )?;
    out.set_item(
        "skin_rg",
        array(
            py,
            &[set.subjects.len(), 2],
            set.subjects.iter().flat_map(|s| s.skin_rg).collect(),
        )?,
    )?;
    Ok(out)
}

/// The paper's experiments on labelled images (`protocol::evaluate_images`).
#[pyfunction]
#[pyo3(signature = (enrol, probes, labels, true_pct, max_rank, edges=None, params=None))]
#[allow(clippy::too_many_arguments)]
fn evaluate<'py>(
    py: Python<'py>,
    enrol: &Bound<'py, PyAny>,
    probes: &Bound<'py, PyAny>,
    labels: &Bound<'py, PyAny>,
    true_pct: Option<&Bound<'py, PyAny>>,
    max_rank: i128,
    edges: Option<&Bound<'py, PyAny>>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let labels = args::array::<i64>("labels", labels)
        .ok()
        .filter(|a| a.ndim() == 1)
        .map(|a| values(&a).into_owned())
        .ok_or_else(|| value_error("`labels` must be a 1-D array of integer identities"))?;
    let flat = |name: &str, a: Option<&Bound<'py, PyAny>>| {
        a.filter(|a| !a.is_none())
            .map(|a| Ok::<_, PyErr>(values(&args::array::<f64>(name, a)?).into_owned()))
            .transpose()
    };
    let (true_pct, edges) = (flat("true_pct", true_pct)?, flat("edges", edges)?);
    let max_rank: usize = uint(py, "max_rank", max_rank, 0)?;
    let enrol = images_arg("enrol", enrol)?;
    let probes = images_arg("probes", probes)?;
    let p = params_from(params.as_ref())?;
    if enrol.is_empty() {
        return Err(value_error(
            "`enrol` is empty: no gallery to identify against",
        ));
    }
    if labels.len() != probes.len() {
        return Err(value_error(format!(
            "{} probes need as many labels, got {}",
            probes.len(),
            labels.len()
        )));
    }
    if let Some(t) = &true_pct {
        if t.len() != probes.len() {
            return Err(value_error(format!(
                "{} probes need as many true_pct values, got {}",
                probes.len(),
                t.len()
            )));
        }
    }
    if let Some(e) = &edges {
        if e.len() < 2 || e.iter().any(|v| !v.is_finite()) || e.windows(2).any(|w| w[0] >= w[1]) {
            return Err(value_error(format!(
                "`edges` must hold at least 2 finite, increasing values, got {e:?}"
            )));
        }
    }
    let subj = indices("labels", &labels)?;
    let (gal, prb) = (enrol, probes);
    let items: Vec<(usize, &Image<u8>, Option<f64>)> = prb
        .iter()
        .enumerate()
        .map(|(k, im)| {
            let t = true_pct.as_ref().map(|t| t[k]).filter(|v| v.is_finite());
            (subj[k], im, t)
        })
        .collect();
    let ev = crate::pool::detach(py, || evaluate_images(&gal, &items, &p, max_rank)).py_err()?;
    let n = ev.outcomes.len();
    let d = PyDict::new(py);
    let names: Vec<&str> = ScoreRule::ALL.iter().map(|r| r.name()).collect();
    let cmc = PyDict::new(py);
    for (name, c) in names.iter().zip(&ev.cmc) {
        cmc.set_item(name, vector(py, c.clone())?)?;
    }
    d.set_item("rules", names.clone())?;
    d.set_item("cmc", cmc)?;
    d.set_item("baseline_cmc", vector(py, ev.baseline_cmc.clone())?)?;
    d.set_item("baseline_cmc_all", vector(py, ev.baseline_cmc_all.clone())?)?;
    d.set_item("rejection_rate", ev.rejection_rate())?;
    let o = &ev.outcomes;
    d.set_item(
        "estimated_pct",
        vector(py, o.iter().map(|o| o.estimated_pct).collect())?,
    )?;
    d.set_item(
        "true_pct",
        vector(
            py,
            o.iter().map(|o| o.true_pct.unwrap_or(f64::NAN)).collect(),
        )?,
    )?;
    d.set_item(
        "rejected",
        array(py, &[n], o.iter().map(|o| o.rejected).collect())?,
    )?;
    d.set_item(
        "ranks",
        array(
            py,
            &[n, ScoreRule::ALL.len()],
            o.iter()
                .flat_map(|o| o.ranks.map(|r| r.map_or(-1, |r| r as i64)))
                .collect(),
        )?,
    )?;
    d.set_item(
        "baseline_rank",
        array(
            py,
            &[n],
            o.iter()
                .map(|o| i64::try_from(o.baseline_rank).unwrap_or(-1))
                .collect(),
        )?,
    )?;
    if let Some(e) = &edges {
        let deg = PyDict::new(py);
        for rule in ScoreRule::ALL {
            let rows = ev.degradation(rule, e);
            let flat = rows
                .iter()
                .flat_map(|&(lo, hi, c, r)| [lo, hi, c as f64, r])
                .collect();
            deg.set_item(rule.name(), array(py, &[rows.len(), 4], flat)?)?;
        }
        d.set_item("degradation", deg)?;
    }
    Ok(d)
}

// ------------------------------------------------------------------------------------------
// Skin model
// ------------------------------------------------------------------------------------------

type Model = ([f64; 2], [[f64; 2]; 2]);

/// Checks a skin model; returns it normalised to `(mean, cov)`.
#[pyfunction]
fn skin_check(mean: Vec<f64>, cov: Vec<Vec<f64>>) -> PyResult<Model> {
    let m = skin_model(mean, cov)?;
    Ok((m.mean, m.cov))
}

/// The uint8 RGB pixels of the argument `name`, an array `(..., 3)`.
fn rgb_arg<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, u8>> {
    let a = args::u8s(name, obj)?;
    if a.shape().last() != Some(&3) {
        return Err(value_error(format!(
            "`{name}` must have a last axis of 3 (R, G, B), got shape {:?}",
            a.shape()
        )));
    }
    Ok(a)
}

/// ML skin model of the uint8 RGB pixels `X` `(..., 3)` (black ones skipped), named as
/// the argument of `SkinModel.fit`.
#[pyfunction]
#[allow(non_snake_case)]
fn skin_fit(py: Python<'_>, X: &Bound<'_, PyAny>) -> PyResult<Model> {
    let pixels = rgb_arg("X", X)?;
    let px: Vec<[u8; 3]> = values(&pixels)
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let m = crate::pool::detach(py, || SkinModel::fit(&px)).py_err()?;
    Ok((m.mean, m.cov))
}

/// ML skin model of `(n, 2)` chromaticity samples.
#[pyfunction]
fn skin_fit_rg(py: Python<'_>, points: PyReadonlyArrayDyn<'_, f64>) -> PyResult<Model> {
    let sh = points.shape();
    if sh.len() != 2 || sh[1] != 2 {
        return Err(value_error(format!(
            "`points` must have shape (n, 2) (r, g), got {sh:?}"
        )));
    }
    let pts: Vec<[f64; 2]> = values(&points)
        .chunks_exact(2)
        .map(|c| [c[0], c[1]])
        .collect();
    let m = crate::pool::detach(py, || SkinModel::fit_rg(&pts)).py_err()?;
    Ok((m.mean, m.cov))
}

/// `what` (`mahalanobis2`, `likelihood`, `marginal_r`, `marginal_g`) at the chromaticities
/// `(r[i], g[i])`.
#[pyfunction]
fn skin_eval_rg<'py>(
    py: Python<'py>,
    mean: Vec<f64>,
    cov: Vec<Vec<f64>>,
    r: PyReadonlyArrayDyn<'py, f64>,
    g: PyReadonlyArrayDyn<'py, f64>,
    what: &str,
) -> PyResult<Arr<'py, f64>> {
    let m = skin_model(mean, cov)?;
    let (r, g) = (values(&r), values(&g));
    if r.len() != g.len() {
        return Err(value_error(format!(
            "`r` and `g` differ in size: {} and {}",
            r.len(),
            g.len()
        )));
    }
    let f: fn(&SkinModel, f64, f64) -> f64 = match what {
        "mahalanobis2" => |m, r, g| m.mahalanobis2_rg(r, g),
        "likelihood" => |m, r, g| m.likelihood_rg(r, g),
        "marginal_r" => |m, r, g| m.marginal_likelihoods_rg(r, g).0,
        "marginal_g" => |m, r, g| m.marginal_likelihoods_rg(r, g).1,
        other => return Err(value_error(format!("unknown skin quantity {other:?}"))),
    };
    let out = crate::pool::detach(py, || {
        r.iter().zip(g.iter()).map(|(&r, &g)| f(&m, r, g)).collect()
    })?;
    vector(py, out)
}

/// Likelihood (eq. 5) of uint8 RGB pixels given as a `(..., 3)` array, shaped `(...)`.
#[pyfunction]
fn skin_likelihood<'py>(
    py: Python<'py>,
    mean: Vec<f64>,
    cov: Vec<Vec<f64>>,
    rgb: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f64>> {
    let rgb = rgb_arg("rgb", rgb)?;
    let m = skin_model(mean, cov)?;
    let shape = rgb.shape()[..rgb.ndim() - 1].to_vec();
    let rgb = values(&rgb);
    let out = crate::pool::detach(py, || {
        rgb.chunks_exact(3)
            .map(|c| m.likelihood([c[0], c[1], c[2]]))
            .collect()
    })?;
    array(py, &shape, out)
}

// ------------------------------------------------------------------------------------------
// Building blocks
// ------------------------------------------------------------------------------------------

/// The 2-D mask argument `name` (bool, or any real array-like: non-zero = set).
fn mask_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<u8>, usize, usize)> {
    mask_in(name, &args::array::<bool>(name, obj)?)
}

/// Grey levels of a uint8 ``(H, W, 3)`` RGB image with OpenCV's fixed-point BT.601,
/// ``Y = (9798 R + 19235 G + 3735 B + 16384) >> 15`` (15-bit weights): bit-exact
/// ``cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)`` of OpenCV 4 and 5 (OpenCV 3.4's 14-bit
/// weights differ by one level on 0.26 % of all colours). Returns uint8 ``(H, W)``.
#[pyfunction]
fn rgb_to_gray<'py>(py: Python<'py>, image: &Bound<'py, PyAny>) -> PyResult<Arr<'py, u8>> {
    let im = image_in("image", &args::u8s("image", image)?)?;
    let g = tone::rgb_to_gray(&im).py_err()?;
    array(py, &[im.height(), im.width()], g)
}

/// Histogram equalisation of a uint8 2-D image with the arithmetic of
/// ``cv2.equalizeHist`` (bit-exact): ``lut(v) = round_half_even(f32(cdf(v) - c_min) *
/// (255f / (P - c_min)))``; an image of one grey level is returned unchanged. With
/// ``within`` (a bool mask of the same shape) the histogram counts only those pixels (the
/// mapping is applied to all; levels below the lowest counted one map to 0).
#[pyfunction]
#[pyo3(signature = (gray, within=None))]
fn equalize_hist<'py>(
    py: Python<'py>,
    gray: &Bound<'py, PyAny>,
    within: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, u8>> {
    let gray = args::u8s("gray", gray)?;
    let (h, w) = dims2("gray", &gray)?;
    if h == 0 || w == 0 {
        return Err(value_error(format!("`gray` is empty (shape {h} x {w})")));
    }
    let sel = match within.filter(|m| !m.is_none()) {
        Some(m) => {
            let (v, mh, mw) = mask_arg("within", m)?;
            if (mh, mw) != (h, w) {
                return Err(value_error(format!(
                    "shape mismatch: `within` is {mh} x {mw}, `gray` {h} x {w}"
                )));
            }
            Some(v)
        }
        None => None,
    };
    let gray = values(&gray);
    let out = crate::pool::detach(py, || tone::equalize_hist_within(&gray, sel.as_deref()))?;
    array(py, &[h, w], out)
}

/// Resizes a uint8 ``(H, W)`` or ``(H, W, C)`` image to ``height x width``: exact area
/// averaging when neither axis grows (``cv2.INTER_AREA``; within one grey level of OpenCV
/// for non-integer factors), bilinear with half-pixel centres when an axis grows; rounded
/// half to even.
#[pyfunction]
fn resize<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    height: i128,
    width: i128,
) -> PyResult<Arr<'py, u8>> {
    let image = args::u8s("image", image)?;
    let height: usize = uint(py, "height", height, 0)?;
    let width: usize = uint(py, "width", width, 0)?;
    let flat = image.shape().len() == 2;
    let im = image_in("image", &image)?;
    if height.checked_mul(width).is_none_or(|n| n > MAX_NORMALISED) {
        return Err(value_error(format!(
            "target size {height} x {width} is too large (at most 2^26 pixels)"
        )));
    }
    let r = crate::pool::detach(py, || tone::resize_u8(&im, height, width)).py_err()?;
    crate::convert::image_array(py, r, flat)
}

/// Approximation (LL) band of one level of the orthonormal 2-D Haar transform of a 2-D
/// plane with even sizes: ``LL[u, v] = (x[2u, 2v] + x[2u, 2v+1] + x[2u+1, 2v] +
/// x[2u+1, 2v+1]) / 2``, equal to ``pywt.dwt2(plane, "haar")[0]``. Returns float64
/// ``(rows / 2, cols / 2)``.
#[pyfunction]
fn haar_ll<'py>(py: Python<'py>, plane: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f64>> {
    let plane = args::array::<f64>("plane", plane)?;
    let (r, c) = dims2("plane", &plane)?;
    let v = values(&plane);
    let ll = crate::pool::detach(py, || {
        wscg_math::wavelet::haar_ll(ImageView::plane(r, c, &v)?)
    })
    .py_err()?;
    crate::convert::image_array(py, ll, true)
}

/// Haar LL features `(blocks, block_len)` of every block of a `(height, width)` plane.
#[pyfunction]
#[pyo3(signature = (plane, params=None))]
fn block_features<'py>(
    py: Python<'py>,
    plane: &Bound<'py, PyAny>,
    params: Option<Bound<'py, PyDict>>,
) -> PyResult<Arr<'py, f32>> {
    let plane = args::array::<f64>("plane", plane)?;
    let p = params_from(params.as_ref())?;
    let (r, c) = dims2("plane", &plane)?;
    let v = values(&plane);
    let f = crate::pool::detach(py, || ear::block_features(ImageView::plane(r, c, &v)?, &p))
        .py_err()?;
    array(py, &[p.blocks(), p.block_len()], f)
}

/// A disk morphology `op` of the 2-D mask argument `mask` by the disk of `radius`.
fn disk_morphology<'py>(
    py: Python<'py>,
    m: &Bound<'py, PyAny>,
    radius: f64,
    op: fn(ImageView<'_, u8>, f64) -> wscg_math::Result<Image<u8>>,
) -> PyResult<Arr<'py, bool>> {
    let (v, h, w) = mask_arg("mask", m)?;
    let radius = radius_in(radius)?;
    let out = crate::pool::detach(py, || op(ImageView::plane(h, w, &v)?, radius)).py_err()?;
    mask_out(py, out)
}

/// Closing of a 2-D bool mask by the exact Euclidean disk ``dx^2 + dy^2 <= radius^2``:
/// dilation with the outside as background, then erosion with the outside as foreground
/// (extensive), equal to ``skimage.morphology.binary_closing(mask,
/// skimage.morphology.disk(radius))`` for integer radii.
#[pyfunction]
#[pyo3(signature = (mask, radius=10.0))]
fn close_disk<'py>(
    py: Python<'py>,
    mask: &Bound<'py, PyAny>,
    radius: f64,
) -> PyResult<Arr<'py, bool>> {
    disk_morphology(py, mask, radius, mask::close_disk)
}

/// Dilation of a 2-D bool mask by the exact Euclidean disk of ``radius`` (the outside of
/// the image is background).
#[pyfunction]
fn dilate_disk<'py>(
    py: Python<'py>,
    mask: &Bound<'py, PyAny>,
    radius: f64,
) -> PyResult<Arr<'py, bool>> {
    disk_morphology(py, mask, radius, mask::dilate_disk)
}

/// Erosion of a 2-D bool mask by the exact Euclidean disk of ``radius`` (the outside of
/// the image counts as foreground, as ``skimage.morphology.binary_erosion``).
#[pyfunction]
fn erode_disk<'py>(
    py: Python<'py>,
    mask: &Bound<'py, PyAny>,
    radius: f64,
) -> PyResult<Arr<'py, bool>> {
    disk_morphology(py, mask, radius, mask::erode_disk)
}

/// A 2-D bool mask with its holes filled: background pixels not 4-connected to the image
/// border become foreground, as ``scipy.ndimage.binary_fill_holes``.
#[pyfunction]
fn fill_holes<'py>(py: Python<'py>, mask: &Bound<'py, PyAny>) -> PyResult<Arr<'py, bool>> {
    let (v, h, w) = mask_arg("mask", mask)?;
    let out = crate::pool::detach(py, || mask::fill_holes(ImageView::plane(h, w, &v)?)).py_err()?;
    mask_out(py, out)
}

/// Registers the submodule's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyEarMatcher>()?;
    m.add("PARAM_KEYS", PARAM_KEYS.to_vec())?;
    m.add("SHIFTS_NINE", ear::SHIFTS_NINE.to_vec())?;
    m.add(
        "RULES",
        ScoreRule::ALL.iter().map(|r| r.name()).collect::<Vec<_>>(),
    )?;
    m.add_function(wrap_pyfunction!(enroll, m)?)?;
    m.add_function(wrap_pyfunction!(enroll_many, m)?)?;
    m.add_function(wrap_pyfunction!(detect_occlusion, m)?)?;
    m.add_function(wrap_pyfunction!(skin_pixels, m)?)?;
    m.add_function(wrap_pyfunction!(score, m)?)?;
    m.add_function(wrap_pyfunction!(baseline_score, m)?)?;
    m.add_function(wrap_pyfunction!(cmc, m)?)?;
    m.add_function(wrap_pyfunction!(make_ears, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(skin_check, m)?)?;
    m.add_function(wrap_pyfunction!(skin_fit, m)?)?;
    m.add_function(wrap_pyfunction!(skin_fit_rg, m)?)?;
    m.add_function(wrap_pyfunction!(skin_eval_rg, m)?)?;
    m.add_function(wrap_pyfunction!(skin_likelihood, m)?)?;
    m.add_function(wrap_pyfunction!(rgb_to_gray, m)?)?;
    m.add_function(wrap_pyfunction!(equalize_hist, m)?)?;
    m.add_function(wrap_pyfunction!(resize, m)?)?;
    m.add_function(wrap_pyfunction!(haar_ll, m)?)?;
    m.add_function(wrap_pyfunction!(block_features, m)?)?;
    m.add_function(wrap_pyfunction!(close_disk, m)?)?;
    m.add_function(wrap_pyfunction!(dilate_disk, m)?)?;
    m.add_function(wrap_pyfunction!(erode_disk, m)?)?;
    m.add_function(wrap_pyfunction!(fill_holes, m)?)?;
    Ok(())
}
