//! `wscg._native.biometrics` (paper 05, data side): the synthetic hand-pose generator, the
//! physical features, the split / augmentation protocol, the comparison of Tables 3-6, and
//! Isomap. The documented API is `python/wscg/biometrics.py`; `physical_features`,
//! `rotate_mask`, `downscale_mask` and `hand_pose_rotated_test` are its functions
//! themselves (re-exported there), their masks converted by [`masks_arg`].

use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_biometrics::sfa::handpose::protocol::compare_masks;
use wscg_biometrics::sfa::handpose::{
    downscale as downscale_mask, generate_with, physical_features_batch, rotate_mask as rotate,
    rotated_rows, split_masks, CompareParams, HandposeSynthParams, Jitter, Method, DOWNSCALE,
};
use wscg_biometrics::sfa::isomap::{Isomap, IsomapParams};
use wscg_biometrics::sfa::ClassSfaParams;

use wscg_math::{ImageStackView, ImageView};

use crate::args::{self, uint};
use crate::convert::{array, image_array, labels_from, mat_map, mat_out, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed, Renames};

/// `(n, h, w)` of a mask stack (a single `(h, w)` mask counts as `n = 1`).
fn stack_dims(name: &str, shape: &[usize]) -> PyResult<(usize, usize, usize)> {
    match *shape {
        [h, w] => Ok((1, h, w)),
        [n, h, w] => Ok((n, h, w)),
        _ => Err(value_error(format!(
            "`{name}` must be a 2-D (H, W) mask or a 3-D (N, H, W) stack, got shape {shape:?}"
        ))),
    }
}

/// `(masks, depth, labels, subjects)` as numpy arrays.
type HandPoseArrays<'py> = (Arr<'py, u8>, Arr<'py, f32>, Arr<'py, i64>, Arr<'py, i64>);

/// Generates the synthetic hand-pose set: `(masks, depth, labels, subjects)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn hand_poses<'py>(
    py: Python<'py>,
    n_per_class: i128,
    n_subjects: i128,
    seed: i128,
    size: &Bound<'py, PyAny>,
    jitter: [f64; 6],
) -> PyResult<HandPoseArrays<'py>> {
    let (height, width) = args::size2(py, "size", size)?;
    let cfg = HandposeSynthParams::default()
        .n_per_class(uint(py, "n_per_class", n_per_class, 0)?)
        .subjects(uint(py, "n_subjects", n_subjects, 0)?)
        .seed(uint(py, "seed", seed, 0)?)
        .width(width)
        .height(height);
    let j = Jitter {
        extension: jitter[0],
        finger_angle_deg: jitter[1],
        spread: jitter[2],
        rotation_deg: jitter[3],
        scale: jitter[4],
        translation_px: jitter[5],
    };
    let d = crate::pool::detach(py, || generate_with(&cfg, &j))
        .py_err_renamed(&[("subjects", "n_subjects")])?;
    let (n, h, w) = (d.len(), d.height, d.width);
    let labels = d.labels.iter().map(|&l| i64::from(l)).collect();
    let subj = d.subjects.iter().map(|&l| i64::from(l)).collect();
    Ok((
        array(py, &[n, h, w], d.masks)?,
        array(py, &[n, h, w], d.depth)?,
        array(py, &[n], labels)?,
        array(py, &[n], subj)?,
    ))
}

/// The default per-frame amplitudes and the tight ones ([`Jitter::tight`]), in `hand_poses`'
/// jitter order.
#[pyfunction]
fn jitter_presets() -> ([f64; 6], [f64; 6]) {
    let f = |j: Jitter| {
        [
            j.extension,
            j.finger_angle_deg,
            j.spread,
            j.rotation_deg,
            j.scale,
            j.translation_px,
        ]
    };
    (f(Jitter::default()), f(Jitter::tight()))
}

/// The mask argument `name` (0 = background): uint8 as it is, bool as 0/1; another dtype
/// is refused, not cast.
fn masks_arg<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, u8>> {
    let a = args::asarray(name, obj)?;
    if let Ok(m) = a.cast::<PyArrayDyn<u8>>() {
        return Ok(m.readonly());
    }
    if a.cast::<PyArrayDyn<bool>>().is_ok() {
        return args::array::<u8>(name, a.as_any());
    }
    Err(value_error(format!(
        "`{name}` must be uint8 or bool (0 = background), got {}",
        a.dtype()
    )))
}

/// The optional `depth` argument (any real array-like, as float32).
fn depth_arg<'py>(
    depth: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<PyReadonlyArrayDyn<'py, f32>>> {
    depth
        .filter(|d| !d.is_none())
        .map(|d| args::array::<f32>("depth", d))
        .transpose()
}

/// The hand-crafted features of paper 05's Table 4 baseline, one row per mask of an
/// ``(n, h, w)`` stack (or one ``(h, w)`` mask): fingertip x, y; palm centre x, y; palm
/// radius; convex ratio; concave depth; finger polar angle; and, with ``depth`` (same
/// shape, float), the finger azimuth: 9 columns, 8 without depth.
#[pyfunction]
#[pyo3(signature = (masks, depth=None))]
fn physical_features<'py>(
    py: Python<'py>,
    masks: &Bound<'py, PyAny>,
    depth: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, f64>> {
    let masks = masks_arg("masks", masks)?;
    let depth = depth_arg(depth)?;
    let (n, h, w) = stack_dims("masks", masks.shape())?;
    let m = values(&masks);
    let d = depth.as_ref().map(values);
    if let Some(dep) = &depth {
        if dep.shape() != masks.shape() {
            return Err(value_error(format!(
                "`depth` has shape {:?}, the masks {:?}",
                dep.shape(),
                masks.shape()
            )));
        }
    }
    let f = crate::pool::detach(py, || {
        let depth = d
            .as_deref()
            .map(|d| ImageStackView::new(n, h, w, d))
            .transpose()?;
        physical_features_batch(ImageStackView::new(n, h, w, &m)?, depth)
    })
    .py_err()?;
    let k = f.len() / n.max(1);
    array(py, &[n, k], f)
}

/// `(h, w)` of one 2-D mask.
fn mask_dims(mask: &PyReadonlyArrayDyn<u8>) -> PyResult<(usize, usize)> {
    match *mask.shape() {
        [h, w] => Ok((h, w)),
        ref s => Err(value_error(format!(
            "`mask` must be one 2-D (H, W) mask, got shape {s:?}"
        ))),
    }
}

/// One binary mask rotated about its centroid by ``degrees`` (counter-clockwise as
/// displayed), nearest-neighbour resampling; stays 0/1.
#[pyfunction]
fn rotate_mask<'py>(
    py: Python<'py>,
    mask: &Bound<'py, PyAny>,
    degrees: f64,
) -> PyResult<Arr<'py, u8>> {
    let mask = masks_arg("mask", mask)?;
    let degrees = args::number("degrees", degrees)?;
    let (h, w) = mask_dims(&mask)?;
    let m = values(&mask);
    let out = crate::pool::detach(py, || rotate(ImageView::plane(h, w, &m)?, degrees)).py_err()?;
    image_array(py, out, true)
}

/// Area-average downscaling of one binary mask (paper 05: by 3, 120 x 165 -> 40 x 55).
#[pyfunction]
#[pyo3(name = "downscale_mask", signature = (mask, factor=3))]
fn downscale<'py>(
    py: Python<'py>,
    mask: &Bound<'py, PyAny>,
    factor: i128,
) -> PyResult<Arr<'py, f64>> {
    let mask = masks_arg("mask", mask)?;
    let factor: usize = uint(py, "factor", factor, 0)?;
    let (h, w) = mask_dims(&mask)?;
    let m = values(&mask);
    let out =
        crate::pool::detach(py, || downscale_mask(ImageView::plane(h, w, &m)?, factor)).py_err()?;
    image_array(py, out, true)
}

/// The Python names of the split's counts.
const SPLIT: &Renames = &[
    ("test_per_class", "n_test_per_class"),
    ("augment_per_class", "n_augment_per_class"),
];

/// The paper's split and augmentation of a mask stack: a dict of arrays.
#[pyfunction]
fn hand_pose_split<'py>(
    py: Python<'py>,
    masks: &Bound<'py, PyAny>,
    labels: PyReadonlyArrayDyn<i64>,
    n_test_per_class: i128,
    n_augment_per_class: i128,
    seed: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let n_test_per_class = uint(py, "n_test_per_class", n_test_per_class, 0)?;
    let n_augment_per_class = uint(py, "n_augment_per_class", n_augment_per_class, 0)?;
    let seed = uint(py, "seed", seed, 0)?;
    let masks = masks_arg("masks", masks)?;
    let (n, h, w) = stack_dims("masks", masks.shape())?;
    let y = labels_from("labels", &labels)?;
    let m = values(&masks);
    let s = crate::pool::detach(py, || {
        let stack = ImageStackView::new(n, h, w, &m)?;
        split_masks(stack, &y, n_test_per_class, n_augment_per_class, seed)
    })
    .py_err_renamed(SPLIT)?;
    let d = PyDict::new(py);
    let i64s = |v: &[u32]| v.iter().map(|&l| i64::from(l)).collect::<Vec<_>>();
    let idx = |v: &[usize]| v.iter().map(|&l| l as i64).collect::<Vec<_>>();
    let (ntr, nte) = (s.train_y.len(), s.test_y.len());
    d.set_item("X_train", array(py, &[ntr, s.dim], s.train_x)?)?;
    d.set_item("y_train", array(py, &[ntr], i64s(&s.train_y))?)?;
    d.set_item("X_test", array(py, &[nte, s.dim], s.test_x)?)?;
    d.set_item("y_test", array(py, &[nte], i64s(&s.test_y))?)?;
    d.set_item("train_index", array(py, &[ntr], idx(&s.train_index))?)?;
    d.set_item("test_index", array(py, &[nte], idx(&s.test_index))?)?;
    d.set_item("train_rotation", array(py, &[ntr], s.train_rotation)?)?;
    d.set_item("shape", s.shape)?;
    Ok(d)
}

/// The comparison of Tables 3-6 on a mask stack: `(classes, y_test, results)` with one
/// `(name, confusion %, predictions, fit s, predict s)` per method.
#[pyfunction]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn hand_pose_comparison<'py>(
    py: Python<'py>,
    masks: &Bound<'py, PyAny>,
    depth: Option<&Bound<'py, PyAny>>,
    labels: PyReadonlyArrayDyn<i64>,
    methods: Vec<String>,
    n_test_per_class: i128,
    n_augment_per_class: i128,
    seed: i128,
    sfa: (i128, i128, f64, f64),
    knn_n_neighbors: i128,
    physical_n_per_class: i128,
    isomap: (i128, i128, Option<i128>, i128),
    global_rule: &str,
) -> PyResult<(
    Vec<i64>,
    Arr<'py, i64>,
    Vec<(String, Arr<'py, f64>, Arr<'py, i64>, f64, f64)>,
)> {
    let count = |name: &str, v: i128| uint(py, name, v, 0usize);
    let (n_test_per_class, n_augment_per_class) = (
        count("n_test_per_class", n_test_per_class)?,
        count("n_augment_per_class", n_augment_per_class)?,
    );
    let seed = uint(py, "seed", seed, 0u64)?;
    let (knn_n_neighbors, physical_n_per_class) = (
        count("knn_n_neighbors", knn_n_neighbors)?,
        count("physical_n_per_class", physical_n_per_class)?,
    );
    let sfa = (
        count("pca_n_components", sfa.0)?,
        count("m", sfa.1)?,
        sfa.2,
        sfa.3,
    );
    let isomap = (
        count("isomap_n_neighbors", isomap.0)?,
        count("isomap_n_components", isomap.1)?,
        isomap
            .2
            .map(|v| count("isomap_n_per_class", v))
            .transpose()?,
        count("isomap_n_landmarks", isomap.3)?,
    );
    let masks = masks_arg("masks", masks)?;
    let depth = depth_arg(depth)?;
    let (n, h, w) = stack_dims("masks", masks.shape())?;
    let y = labels_from("labels", &labels)?;
    let methods: Vec<Method> = methods
        .iter()
        .map(|m| Method::parse(m))
        .collect::<Result<_, _>>()
        .py_err()?;
    let m = values(&masks);
    let d = depth.as_ref().map(values);
    let cfg = CompareParams::default()
        .sfa(
            ClassSfaParams::default()
                .pca_dims(sfa.0)
                .m_per_class(sfa.1)
                .objective(
                    wscg_biometrics::sfa::ClassObjective::WithinMinusOutOfClass { gamma: sfa.2 },
                )
                .shrinkage(sfa.3),
        )
        .k(knn_n_neighbors)
        .physical_per_class(physical_n_per_class)
        .isomap(
            IsomapParams::default()
                .n_neighbors(isomap.0)
                .n_components(isomap.1)
                .n_landmarks(None),
        )
        .isomap_per_class(isomap.2)
        .isomap_landmarks(isomap.3)
        .global_rule(wscg_biometrics::sfa::global::parse_rule(global_rule).py_err()?)
        .seed(seed);
    let (split, res) = crate::pool::detach(py, || {
        let stack = ImageStackView::new(n, h, w, &m)?;
        let depth = d
            .as_deref()
            .map(|d| ImageStackView::new(n, h, w, d))
            .transpose()?;
        let split = split_masks(stack, &y, n_test_per_class, n_augment_per_class, seed)?;
        let res = compare_masks(stack, depth, &split, &cfg, &methods, |_| {})?;
        Ok::<_, wscg_math::Error>((split, res))
    })
    .py_err_renamed(&[
        ("test_per_class", "n_test_per_class"),
        ("augment_per_class", "n_augment_per_class"),
        ("pca_dims", "pca_n_components"),
        ("m_per_class", "m"),
        ("k", "knn_n_neighbors"),
        ("physical_per_class", "physical_n_per_class"),
        ("isomap_per_class", "isomap_n_per_class"),
        ("isomap_landmarks", "isomap_n_landmarks"),
        ("n_neighbors", "isomap_n_neighbors"),
        ("n_components", "isomap_n_components"),
    ])?;
    let mut out = Vec::new();
    for r in res.results {
        let n = r.predictions.len();
        out.push((
            r.method.name().to_string(),
            mat_out(py, &r.confusion)?,
            array(
                py,
                &[n],
                r.predictions.iter().map(|&p| i64::from(p)).collect(),
            )?,
            r.fit_seconds,
            r.predict_seconds,
        ));
    }
    let yte = split.test_y.iter().map(|&l| i64::from(l)).collect();
    Ok((
        res.classes.iter().map(|&c| i64::from(c)).collect(),
        array(py, &[split.test_y.len()], yte)?,
        out,
    ))
}

/// Rows of the frames ``test_index`` of a mask stack (e.g. ``hand_pose_split(...)
/// .test_index``), each rotated about its centroid by +-U(angles) degrees and downscaled
/// as :func:`hand_pose_split` does: the rotation-robustness check. ``angles=(0, 0)`` gives
/// the unrotated test rows.
#[pyfunction]
#[pyo3(name = "hand_pose_rotated_test", signature = (masks, test_index, angles=(10.0, 20.0), seed=1),
       text_signature = "(masks, test_index, angles=(10.0, 20.0), seed=1)")]
fn rotated_frame_rows<'py>(
    py: Python<'py>,
    masks: &Bound<'py, PyAny>,
    test_index: &Bound<'py, PyAny>,
    angles: (f64, f64),
    seed: i128,
) -> PyResult<Arr<'py, f64>> {
    let masks = masks_arg("masks", masks)?;
    let idx = args::array::<i64>("test_index", test_index)?;
    if idx.ndim() != 1 {
        return Err(value_error(
            "`test_index` must be a 1-D array of frame indices",
        ));
    }
    let test_index = crate::convert::indices("test_index", &values(&idx))?;
    let (lo, hi) = (
        args::number("angles", angles.0)?,
        args::number("angles", angles.1)?,
    );
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let (n, h, w) = stack_dims("masks", masks.shape())?;
    let m = values(&masks);
    let rows = crate::pool::detach(py, || {
        rotated_rows(ImageStackView::new(n, h, w, &m)?, &test_index, lo, hi, seed)
    })
    .py_err_renamed(&[("frames", "test_index")])?;
    let dim = h.div_ceil(DOWNSCALE) * w.div_ceil(DOWNSCALE);
    array(py, &[test_index.len(), dim], rows)
}

/// A fitted Isomap.
#[pyclass(module = "wscg._native.biometrics", name = "IsomapModel", frozen)]
pub struct PyIsomap {
    inner: Isomap,
}

#[pymethods]
impl PyIsomap {
    /// Embedding of new rows (sklearn's `Isomap.transform`).
    fn transform<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "x", &x, |x| self.inner.transform(x))
    }

    /// Training embedding.
    fn embedding<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        mat_out(py, &self.inner.embedding().to_owned())
    }

    /// Kept eigenvalues of the centred geodesic kernel.
    fn eigenvalues(&self) -> Vec<f64> {
        self.inner.eigenvalues().to_vec()
    }

    /// Landmark indices (None for exact Isomap).
    fn landmarks(&self) -> Option<Vec<usize>> {
        self.inner.landmarks().map(<[usize]>::to_vec)
    }

    /// The model as JSON.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json().py_err()
    }

    /// A model from `to_json`.
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pool::detach(py, || Isomap::from_json(s)).py_err()?,
        })
    }
}

/// Fits Isomap (exact, or Landmark Isomap with `n_landmarks`).
#[pyfunction]
#[pyo3(signature = (x, n_neighbors, n_components, n_landmarks=None))]
fn isomap_fit(
    py: Python<'_>,
    x: PyReadonlyArrayDyn<f64>,
    n_neighbors: i128,
    n_components: i128,
    n_landmarks: Option<i128>,
) -> PyResult<PyIsomap> {
    let (n_neighbors, n_components): (usize, usize) = (
        uint(py, "n_neighbors", n_neighbors, 0)?,
        uint(py, "n_components", n_components, 0)?,
    );
    let n_landmarks: Option<usize> = n_landmarks
        .map(|n| uint(py, "n_landmarks", n, 0))
        .transpose()?;
    let x = crate::convert::mat("x", &x)?;
    let p = IsomapParams::default()
        .n_neighbors(n_neighbors)
        .n_components(n_components)
        .n_landmarks(n_landmarks);
    let inner = crate::pool::detach(py, || Isomap::fit(x.as_ref(), &p)).py_err()?;
    Ok(PyIsomap { inner })
}

/// Registers the hand-pose and Isomap functions into the biometrics submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyIsomap>()?;
    m.add_function(wrap_pyfunction!(isomap_fit, m)?)?;
    m.add_function(wrap_pyfunction!(hand_poses, m)?)?;
    m.add_function(wrap_pyfunction!(jitter_presets, m)?)?;
    m.add_function(wrap_pyfunction!(physical_features, m)?)?;
    m.add_function(wrap_pyfunction!(rotate_mask, m)?)?;
    m.add_function(wrap_pyfunction!(downscale, m)?)?;
    m.add_function(wrap_pyfunction!(hand_pose_split, m)?)?;
    m.add_function(wrap_pyfunction!(hand_pose_comparison, m)?)?;
    m.add_function(wrap_pyfunction!(rotated_frame_rows, m)?)?;
    Ok(())
}
