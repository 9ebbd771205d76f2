//! `wscg._native.biometrics`: bindings of `wscg-biometrics` (paper 01, FDKECA and its
//! baselines). The documented public API is `python/wscg/biometrics.py`: scikit-learn-style
//! classes that hold a native [`PyModel`] and map arbitrary labels to `0..k`.

use numpy::PyReadonlyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_biometrics::data::{finger_veins as gen_finger_veins, FingerVeinParams};
use wscg_biometrics::subspace::fdkeca::feature_kernel as fd_kernel;
use wscg_biometrics::subspace::{
    self, FdkecaParams, Gamma, Kernel, Method, Metric, Model, Ordering, Projector, ResolvedKernel,
    Sigma,
};
use wscg_math::Error;

use crate::args::{self, uint};
use crate::convert::{array, labels_from, mat, mat_map, mat_out, vector, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed};

/// Reads an optional item of the spec dictionary.
fn item<'py, T: FromPyObjectOwned<'py>>(
    spec: &Bound<'py, PyDict>,
    key: &str,
) -> PyResult<Option<T>> {
    crate::cfg::dict_item(spec, key)
}

/// The kernel described by `spec` (`kernel`, `sigma`, `sigma_scale`, `degree`, `gamma`,
/// `coef0`).
fn kernel_from(spec: &Bound<'_, PyDict>) -> PyResult<Kernel> {
    let name: String = item(spec, "kernel")?.unwrap_or_else(|| "rbf".into());
    Ok(match name.as_str() {
        "linear" => Kernel::Linear,
        "poly" | "polynomial" => Kernel::Polynomial {
            degree: item(spec, "degree")?.unwrap_or(2),
            gamma: match item::<f64>(spec, "gamma")? {
                Some(g) => Gamma::Fixed(g),
                None => Gamma::InvDim,
            },
            coef0: item(spec, "coef0")?.unwrap_or(1.0),
        },
        "rbf" | "gaussian" => Kernel::Gaussian {
            sigma: match item::<f64>(spec, "sigma")? {
                Some(s) => Sigma::Fixed(s),
                None => Sigma::Median {
                    scale: item(spec, "sigma_scale")?.unwrap_or(1.0),
                },
            },
        },
        other => {
            return Err(value_error(format!(
                "`kernel` must be 'rbf', 'poly' or 'linear', got {other:?}"
            )))
        }
    })
}

/// The method described by `spec` (`method` plus its parameters).
fn method_from(spec: &Bound<'_, PyDict>) -> PyResult<Method> {
    let name: String = item(spec, "method")?.unwrap_or_else(|| "fdkeca".into());
    let n_components: Option<usize> = item(spec, "n_components")?;
    Ok(match name.as_str() {
        "fdkeca" => Method::Fdkeca(
            FdkecaParams::default()
                .kernel(kernel_from(spec)?)
                .n_components(n_components)
                .ordering(match item::<String>(spec, "ordering")?.as_deref() {
                    None | Some("entropy") => Ordering::Entropy,
                    Some("eigenvalue") => Ordering::Eigenvalue,
                    Some(o) => {
                        return Err(value_error(format!(
                            "`ordering` must be 'entropy' or 'eigenvalue', got {o:?}"
                        )))
                    }
                })
                .center(item(spec, "center")?.unwrap_or(true)),
        ),
        "pca" => Method::Pca {
            n_components,
            whiten: item(spec, "whiten")?.unwrap_or(false),
        },
        "kpca" => Method::KernelPca {
            kernel: kernel_from(spec)?,
            n_components,
        },
        "keca" => Method::Keca {
            kernel: kernel_from(spec)?,
            n_components,
        },
        other => {
            return Err(value_error(format!(
                "`method` must be 'fdkeca', 'pca', 'kpca' or 'keca', got {other:?}"
            )))
        }
    })
}

/// The `dims` argument (numbers of components, each >= 0), by default `1..=width`.
fn dims_arg(dims: Option<&Bound<'_, PyAny>>, width: usize) -> PyResult<Vec<usize>> {
    match dims.filter(|d| !d.is_none()) {
        None => Ok((1..=width).collect()),
        some => args::indices("dims", some),
    }
}

fn metric_from(name: &str) -> PyResult<Metric> {
    match name {
        "euclidean" => Ok(Metric::Euclidean),
        "cosine" => Ok(Metric::Cosine),
        other => Err(value_error(format!(
            "`metric` must be 'euclidean' or 'cosine', got {other:?}"
        ))),
    }
}

/// A fitted FDKECA, PCA, KPCA or KECA model.
#[pyclass(module = "wscg._native.biometrics", name = "Model", frozen)]
pub struct PyModel {
    inner: Model,
}

fn rows_out<'py>(py: Python<'py>, rows: &[Vec<f64>]) -> PyResult<Arr<'py, f64>> {
    let d = rows.first().map_or(0, |r| r.len());
    array(py, &[rows.len(), d], rows.concat())
}

fn kernel_info(d: &Bound<'_, PyDict>, k: &ResolvedKernel) -> PyResult<()> {
    match *k {
        ResolvedKernel::Linear => d.set_item("kernel", "linear"),
        ResolvedKernel::Polynomial {
            degree,
            gamma,
            coef0,
        } => {
            d.set_item("kernel", "poly")?;
            d.set_item("degree", degree)?;
            d.set_item("gamma", gamma)?;
            d.set_item("coef0", coef0)
        }
        ResolvedKernel::Gaussian { sigma } => {
            d.set_item("kernel", "rbf")?;
            d.set_item("sigma", sigma)
        }
    }
}

#[pymethods]
impl PyModel {
    /// Short method name: "FDKECA", "PCA", "KPCA" or "KECA".
    #[getter]
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    /// Number of output components `l`.
    #[getter]
    fn n_components(&self) -> usize {
        self.inner.n_components()
    }

    /// Input dimension `d`.
    #[getter]
    fn input_dim(&self) -> usize {
        self.inner.input_dim()
    }

    /// Projects the rows of `x` (`m x d`) to `m x l`.
    fn transform<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "x", &x, |x| self.inner.transform(x))
    }

    /// Maps projections back to image space (FDKECA, PCA).
    fn inverse_transform<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "y", &y, |y| self.inner.inverse_transform(y))
    }

    /// The same model with its first `l` components.
    fn truncated(&self, py: Python<'_>, l: i128) -> PyResult<Self> {
        let l: usize = uint(py, "n_components", l, 0)?;
        Ok(Self {
            inner: crate::pool::detach(py, || self.inner.truncated(l)).py_err()?,
        })
    }

    /// The fitted model as JSON (for pickling and files).
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        crate::pool::detach(py, || self.inner.to_json()).py_err()
    }

    /// Reads a model written by `to_json`.
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pool::detach(py, || Model::from_json(s)).py_err()?,
        })
    }

    /// The fitted quantities as a dict of numpy arrays and numbers.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let embedding = crate::pool::detach(py, || match &self.inner {
            Model::KernelPca(m) => Some(m.embedding()),
            Model::Keca(m) => Some(m.embedding()),
            _ => None,
        })?;
        let d = PyDict::new(py);
        match &self.inner {
            Model::Fdkeca(m) => {
                d.set_item("mean", vector(py, m.mean.to_vec())?)?;
                d.set_item("components", rows_out(py, &m.axes)?)?;
                d.set_item("eigenvalues", vector(py, m.eigenvalues.to_vec())?)?;
                d.set_item("entropy_terms", vector(py, m.entropy_terms.to_vec())?)?;
                d.set_item("kernel_sum", m.kernel_sum)?;
                d.set_item("renyi_entropy_estimate", m.renyi_entropy_estimate())?;
                d.set_item("n_train", m.n_train)?;
                kernel_info(&d, &m.kernel)?;
            }
            Model::Pca(m) => {
                d.set_item("mean", vector(py, m.mean.to_vec())?)?;
                d.set_item("components", rows_out(py, &m.components)?)?;
                d.set_item("variances", vector(py, m.variances.to_vec())?)?;
                d.set_item("whiten", m.whiten)?;
            }
            Model::KernelPca(m) => {
                d.set_item("eigenvalues", vector(py, m.eigenvalues.to_vec())?)?;
                d.set_item("eigenvectors", rows_out(py, &m.eigenvectors)?)?;
                if let Some(e) = &embedding {
                    d.set_item("embedding", mat_out(py, e)?)?;
                }
                d.set_item("n_train", m.train.len())?;
                kernel_info(&d, &m.kernel)?;
            }
            Model::Keca(m) => {
                d.set_item("eigenvalues", vector(py, m.eigenvalues.to_vec())?)?;
                d.set_item("entropy_terms", vector(py, m.entropy_terms.to_vec())?)?;
                d.set_item("eigenvectors", rows_out(py, &m.eigenvectors)?)?;
                if let Some(e) = &embedding {
                    d.set_item("embedding", mat_out(py, e)?)?;
                }
                d.set_item("kernel_sum", m.kernel_sum)?;
                d.set_item("renyi_entropy_estimate", m.renyi_entropy_estimate())?;
                d.set_item("n_train", m.train.len())?;
                kernel_info(&d, &m.kernel)?;
            }
        }
        Ok(d)
    }
}

/// Fits the method described by `spec` to the rows of `x`.
#[pyfunction]
fn fit(py: Python<'_>, x: PyReadonlyArrayDyn<f64>, spec: &Bound<'_, PyDict>) -> PyResult<PyModel> {
    let method = method_from(spec)?;
    let x = mat("x", &x)?;
    let inner = crate::pool::detach(py, || method.fit(x.as_ref())).py_err()?;
    Ok(PyModel { inner })
}

/// FDKECA's `d x d` feature-space kernel of `x` and its resolved parameters.
#[pyfunction]
fn feature_kernel<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    spec: &Bound<'py, PyDict>,
) -> PyResult<(Arr<'py, f64>, Bound<'py, PyDict>)> {
    let kernel = kernel_from(spec)?;
    let center = item(spec, "center")?.unwrap_or(true);
    let x = mat("x", &x)?;
    let fk = crate::pool::detach(py, || fd_kernel(x.as_ref(), &kernel, center)).py_err()?;
    let info = PyDict::new(py);
    kernel_info(&info, &fk.kernel)?;
    Ok((mat_out(py, &fk.k)?, info))
}

/// Nearest training row of every test row: `(index, distance)` arrays.
#[pyfunction]
fn nearest<'py>(
    py: Python<'py>,
    train: PyReadonlyArrayDyn<f64>,
    test: PyReadonlyArrayDyn<f64>,
    metric: &str,
) -> PyResult<(Arr<'py, i64>, Arr<'py, f64>)> {
    let metric = metric_from(metric)?;
    let (tr, te) = (mat("train", &train)?, mat("test", &test)?);
    let nb = crate::pool::detach(py, || {
        subspace::nearest_neighbours(tr.as_ref(), te.as_ref(), metric)
    })
    .py_err()?;
    let n = nb.len();
    Ok((
        array(py, &[n], nb.iter().map(|b| b.index as i64).collect())?,
        array(py, &[n], nb.iter().map(|b| b.distance).collect())?,
    ))
}

/// The paper's protocol: `(l, accuracy)` rows for every `l` in `dims`.
#[pyfunction]
fn accuracy_curve<'py>(
    py: Python<'py>,
    ztrain: PyReadonlyArrayDyn<f64>,
    ytrain: PyReadonlyArrayDyn<i64>,
    ztest: PyReadonlyArrayDyn<f64>,
    ytest: PyReadonlyArrayDyn<i64>,
    dims: Option<&Bound<'py, PyAny>>,
    metric: &str,
) -> PyResult<Arr<'py, f64>> {
    let metric = metric_from(metric)?;
    let (ztr, zte) = (mat("ztrain", &ztrain)?, mat("ztest", &ztest)?);
    let dims = dims_arg(dims, ztr.ncols())?;
    let (ytr, yte) = (
        labels_from("ytrain", &ytrain)?,
        labels_from("ytest", &ytest)?,
    );
    let curve = crate::pool::detach(py, || {
        subspace::accuracy_curve(ztr.as_ref(), &ytr, zte.as_ref(), &yte, &dims, metric)
    })
    .py_err()?;
    let k = curve.len();
    array(
        py,
        &[k, 2],
        curve.into_iter().flat_map(|(l, a)| [l as f64, a]).collect(),
    )
}

/// Chooses `l` by cross-validation on the training set: `(l, curve)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn select_dimension_cv<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    y: PyReadonlyArrayDyn<i64>,
    spec: &Bound<'py, PyDict>,
    dims: Option<&Bound<'py, PyAny>>,
    n_folds: i128,
    seed: i128,
    metric: &str,
) -> PyResult<(usize, Arr<'py, f64>)> {
    let method = method_from(spec)?;
    let metric = metric_from(metric)?;
    let x = mat("x", &x)?;
    let dims = dims_arg(dims, x.ncols())?;
    let (n_folds, seed) = (uint(py, "n_folds", n_folds, 0)?, uint(py, "seed", seed, 0)?);
    let y = labels_from("y", &y)?;
    let fit = |m: faer::MatRef<'_, f64>| -> wscg_math::Result<Box<dyn Projector>> {
        Ok(Box::new(method.fit(m)?))
    };
    let (l, curve) = crate::pool::detach(py, || {
        subspace::select_dimension_cv(x.as_ref(), &y, &dims, n_folds, seed, &fit, metric)
    })
    .py_err_renamed(&[("folds", "n_folds")])?;
    let k = curve.len();
    Ok((
        l,
        array(
            py,
            &[k, 2],
            curve.into_iter().flat_map(|(l, a)| [l as f64, a]).collect(),
        )?,
    ))
}

/// Synthetic finger-vein images, a stand-in for the paper's private database
/// (200 subjects x 10 images of 10 x 20 pixels).
///
/// Each subject has 3 to 6 dark veins (smooth random curves along the finger) on a bright
/// background drawn at ``canvas`` size; each sample is shifted, rotated, rescaled in
/// brightness, noised, blurred and area-downsampled to ``size``. The shift (in canvas
/// pixels) sets the difficulty: the default 3.5 puts PCA near 90 % on the 5/5 protocol.
///
/// Returns
/// -------
/// images : ndarray (n_subjects * n_per_subject, h, w), float64
/// labels : ndarray (n_subjects * n_per_subject,), int64
///     Subject of each image (rows ordered subject by subject).
#[pyfunction]
#[pyo3(signature = (n_subjects=200, n_per_subject=10, size=(10, 20), canvas=(40, 80),
                    max_shift=3.5, max_rotation_deg=3.0, noise=0.03, blur=1.0, seed=0),
       text_signature = "(n_subjects=200, n_per_subject=10, size=(10, 20), canvas=(40, 80), \
                         max_shift=3.5, max_rotation_deg=3.0, noise=0.03, blur=1.0, seed=0)")]
#[allow(clippy::too_many_arguments)]
fn make_finger_veins<'py>(
    py: Python<'py>,
    n_subjects: i128,
    n_per_subject: i128,
    size: (i128, i128),
    canvas: (i128, i128),
    max_shift: f64,
    max_rotation_deg: f64,
    noise: f64,
    blur: f64,
    seed: i128,
) -> PyResult<(Arr<'py, f64>, Arr<'py, i64>)> {
    let n_subjects: usize = uint(py, "n_subjects", n_subjects, 0)?;
    let n_per_subject: usize = uint(py, "n_per_subject", n_per_subject, 0)?;
    let size: (usize, usize) = (uint(py, "size", size.0, 0)?, uint(py, "size", size.1, 0)?);
    let canvas: (usize, usize) = (
        uint(py, "canvas", canvas.0, 0)?,
        uint(py, "canvas", canvas.1, 0)?,
    );
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let p = FingerVeinParams::default()
        .subjects(n_subjects)
        .samples(n_per_subject)
        .canvas(canvas)
        .size(size)
        .max_shift(max_shift)
        .max_rotation_deg(max_rotation_deg)
        .noise(noise)
        .blur(blur)
        .seed(seed);
    let data = crate::pool::detach(py, || gen_finger_veins(&p)).py_err_renamed(&[
        ("subjects", "n_subjects"),
        ("samples", "n_per_subject"),
        ("subjects, samples", "n_subjects, n_per_subject"),
    ])?;
    let (n, d) = (data.x.nrows(), data.x.ncols());
    let pixels = (0..n)
        .flat_map(|i| (0..d).map(move |j| (i, j)))
        .map(|(i, j)| data.x[(i, j)])
        .collect();
    Ok((
        array(py, &[n, data.height, data.width], pixels)?,
        array(py, &[n], data.labels.iter().map(|&l| l as i64).collect())?,
    ))
}

/// Per-subject split: `(train_rows, test_rows)`.
#[pyfunction]
fn split_per_subject<'py>(
    py: Python<'py>,
    labels: PyReadonlyArrayDyn<i64>,
    n_train_per_subject: i128,
    seed: i128,
) -> PyResult<(Arr<'py, i64>, Arr<'py, i64>)> {
    let labels = labels_from("labels", &labels)?;
    let n_train_per_subject = uint(py, "n_train_per_subject", n_train_per_subject, 0)?;
    let seed = uint(py, "seed", seed, 0)?;
    let (tr, te) = crate::pool::detach(py, || {
        wscg_biometrics::data::split_per_subject(&labels, n_train_per_subject, seed)
    })
    .py_err_renamed(&[("train_per_subject", "n_train_per_subject")])?;
    let out = |v: Vec<usize>| array(py, &[v.len()], v.into_iter().map(|i| i as i64).collect());
    Ok((out(tr)?, out(te)?))
}

/// The first `n_components` axes of a FDKECA or PCA model as min-max scaled
/// `(n_components, h, w)` images (the paper's eigenface view, section 4).
#[pyfunction]
fn axis_images<'py>(
    py: Python<'py>,
    model: &PyModel,
    n_components: i128,
    shape: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f32>> {
    let n_components: usize = uint(py, "n_components", n_components, 0)?;
    let (height, width) = args::size2(py, "shape", shape)?;
    let imgs = crate::pool::detach(py, || match &model.inner {
        Model::Fdkeca(m) => m.axis_images(n_components, height, width),
        Model::Pca(m) => m.axis_images(n_components, height, width),
        other => Err(Error::invalid(
            "model",
            format!("{} has no image-space axes", other.name()),
        )),
    })
    .py_err()?;
    let data: Vec<f32> = imgs.iter().flat_map(|i| i.data().to_vec()).collect();
    array(py, &[imgs.len(), height, width], data)
}

/// Registers the submodule's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(feature_kernel, m)?)?;
    m.add_function(wrap_pyfunction!(nearest, m)?)?;
    m.add_function(wrap_pyfunction!(accuracy_curve, m)?)?;
    m.add_function(wrap_pyfunction!(select_dimension_cv, m)?)?;
    m.add_function(wrap_pyfunction!(make_finger_veins, m)?)?;
    m.add_function(wrap_pyfunction!(axis_images, m)?)?;
    m.add_function(wrap_pyfunction!(split_per_subject, m)?)?;
    crate::sfa::register(m)?;
    crate::handpose::register(m)
}
