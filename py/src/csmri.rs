//! Bindings of wscg-cs-mri (paper 11): the UDCT, the FDCT, C-SALSA, the baselines, masks, phantoms
//! and metrics, as `wscg._native.csmri`. The masks, phantoms, metrics and `tv_constrained`
//! are `wscg.csmri`'s functions themselves, re-exported by `python/wscg/csmri.py` (which
//! holds the module's documentation); the reconstructions return the dicts from which the
//! Python layer builds its `ReconstructionHistory`. Arrays go through [`crate::args`]:
//! k-space and images as any numeric array-like (converted to complex128), masks as any
//! array-like (non-zero = sampled); counts and seeds as Python ints.

use num_complex::Complex64;
use numpy::ndarray::IxDyn;
use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PySlice};
use wscg_cs_mri::baselines::{self, CompositeParams};
use wscg_cs_mri::sflct::{Redundancy, Sflct, SflctParams};
use wscg_cs_mri::sparsifier::PriorParams;
use wscg_cs_mri::{
    csalsa, masks, metrics, phantom, sparsifier, CsalsaParams, Fdct, FdctParams, Finest, IterStat,
    KSpace, Reconstruction, Regularizer, ScaleChoiceParams, Udct, UdctParams,
};
use wscg_math::progress::NoProgress;
use wscg_math::ImageView;

use crate::args::{self, uint};
use crate::convert::{array, dims2, values, Arr};
use crate::errors::{value_error, IntoPy};

/// The `wedges` argument: per scale `[n_rows, n_cols]`, an `(J, 2)` array-like of integers.
fn wedges_arg(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Vec<[usize; 2]>> {
    let a = args::array::<i64>("wedges", obj)?;
    if a.ndim() != 2 || a.shape()[1] != 2 {
        return Err(value_error(format!(
            "`wedges` must be a list of [n_rows, n_cols] pairs, one per scale, got shape {}",
            args::shape_repr(a.shape())
        )));
    }
    let count = |v: i64| uint(py, "wedges", i128::from(v), 0usize);
    values(&a)
        .chunks_exact(2)
        .map(|p| Ok([count(p[0])?, count(p[1])?]))
        .collect()
}

fn config(wedges: Vec<[usize; 2]>, alpha: f64, tight: bool) -> UdctParams {
    UdctParams::default()
        .wedges(wedges)
        .alpha(alpha)
        .tight(tight)
}

/// The `bands` argument: a sequence of complex array-likes, one per band (`bands[i]` in
/// errors).
fn bands_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Vec<PyReadonlyArrayDyn<'py, Complex64>>> {
    obj.try_iter()
        .map_err(|_| value_error("`bands` must be a sequence of arrays, one per band"))?
        .enumerate()
        .map(|(i, b)| args::complex(&format!("bands[{i}]"), &b?))
        .collect()
}

/// Checks that the image `x` is 2-D with the shape a transform was planned for.
fn planned_shape<T: numpy::Element>(
    x: &PyReadonlyArrayDyn<T>,
    planned: (usize, usize),
) -> PyResult<()> {
    let (r, c) = dims2("x", x)?;
    if (r, c) != planned {
        return Err(value_error(format!(
            "`x` has shape ({r}, {c}); the transform is planned for {planned:?}"
        )));
    }
    Ok(())
}

/// A planned UDCT.
#[pyclass(name = "Udct", module = "wscg._native.csmri")]
pub struct PyUdct {
    inner: Udct,
}

#[pymethods]
impl PyUdct {
    #[new]
    #[pyo3(signature = (shape, wedges, alpha, tight))]
    fn new(
        py: Python<'_>,
        shape: &Bound<'_, PyAny>,
        wedges: &Bound<'_, PyAny>,
        alpha: f64,
        tight: bool,
    ) -> PyResult<Self> {
        let (rows, cols) = args::size2(py, "shape", shape)?;
        let cfg = config(wedges_arg(py, wedges)?, alpha, tight);
        Ok(PyUdct {
            inner: crate::pool::detach(py, || Udct::new(rows, cols, &cfg)).py_err()?,
        })
    }

    fn shape(&self) -> (usize, usize) {
        self.inner.shape()
    }

    fn num_real_coeffs(&self) -> usize {
        self.inner.num_real_coeffs()
    }

    /// `[(scale, pyramid, wedge), ...]` in coefficient order.
    fn band_ids(&self) -> Vec<(usize, usize, usize)> {
        self.inner
            .bands()
            .iter()
            .map(|b| (b.scale, b.pyramid, b.wedge))
            .collect()
    }

    /// Low-pass array and the list of complex band arrays.
    fn forward<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<(Arr<'py, f64>, Vec<Arr<'py, Complex64>>)> {
        let x = args::array::<f64>("x", x)?;
        planned_shape(&x, self.inner.shape())?;
        let v = values(&x);
        // The transform writes straight into the numpy arrays it returns: the low-pass and
        // one flat array of every band, which the band arrays are views of. One large
        // allocation instead of one per band: numpy backs it with huge pages where it can,
        // and at 512^2 the twelve separate 512 KiB bands cost 3.5 ms in page faults alone.
        let lp = PyArrayDyn::<f64>::zeros(py, IxDyn(&self.inner.lowpass_shape()), false);
        let n_bands = self.inner.bands().len();
        let layout: Vec<_> = (0..n_bands)
            .map(|b| self.inner.band_layout(b).expect("band exists"))
            .collect();
        let total = layout.last().map_or(0, |l| l.2.end);
        let flat = PyArrayDyn::<Complex64>::zeros(py, IxDyn(&[total]), false);
        {
            let mut lp_rw = lp.readwrite();
            let mut flat_rw = flat.readwrite();
            let low = lp_rw.as_slice_mut()?;
            let mut rest = flat_rw.as_slice_mut()?;
            let mut outs = Vec::with_capacity(n_bands);
            for (_, _, range) in &layout {
                let (head, tail) = rest.split_at_mut(range.len());
                outs.push(head);
                rest = tail;
            }
            crate::pool::detach(py, || self.inner.forward_parts(&v, low, outs)).py_err()?;
        }
        let bands = layout
            .iter()
            .map(|(shape, _, range)| {
                let part = flat.get_item(PySlice::new(
                    py,
                    range.start as isize,
                    range.end as isize,
                    1,
                ))?;
                part.call_method1("reshape", (shape.to_vec(),))?
                    .cast_into::<PyArrayDyn<Complex64>>()
                    .map_err(PyErr::from)
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((lp, bands))
    }

    fn backward<'py>(
        &self,
        py: Python<'py>,
        lowpass: &Bound<'py, PyAny>,
        bands: &Bound<'py, PyAny>,
    ) -> PyResult<Arr<'py, f64>> {
        let lowpass = args::array::<f64>("lowpass", lowpass)?;
        let bands = bands_arg(bands)?;
        if lowpass.shape() != self.inner.lowpass_shape() {
            return Err(value_error(format!(
                "`lowpass` has shape {:?}, expected {:?}",
                lowpass.shape(),
                self.inner.lowpass_shape()
            )));
        }
        if bands.len() != self.inner.bands().len() {
            return Err(value_error(format!(
                "{} bands given, the transform has {}",
                bands.len(),
                self.inner.bands().len()
            )));
        }
        for (b, arr) in bands.iter().enumerate() {
            let (shape, _, _) = self.inner.band_layout(b).expect("band exists");
            if arr.shape() != shape {
                return Err(value_error(format!(
                    "band {b} has shape {:?}, expected {shape:?}",
                    arr.shape()
                )));
            }
        }
        let low = values(&lowpass);
        let parts: Vec<_> = bands.iter().map(values).collect();
        let slices: Vec<&[Complex64]> = parts.iter().map(|p| p.as_ref()).collect();
        let out = crate::pool::detach(py, || self.inner.backward_parts(&low, &slices)).py_err()?;
        let (r, c) = self.inner.shape();
        array(py, &[r, c], out)
    }

    /// Dense windows in FFT order: the low-pass first, then every band.
    fn windows<'py>(&self, py: Python<'py>) -> PyResult<Vec<Arr<'py, f64>>> {
        let (r, c) = self.inner.shape();
        let u = &self.inner;
        let windows: Vec<Vec<f64>> = crate::pool::detach(py, || {
            std::iter::once(None)
                .chain((0..u.bands().len()).map(Some))
                .map(|b| u.window(b).expect("low-pass and bands exist"))
                .collect()
        })?;
        windows.into_iter().map(|w| array(py, &[r, c], w)).collect()
    }
}

/// A planned wrapping FDCT (complex images).
#[pyclass(name = "Fdct", module = "wscg._native.csmri")]
pub struct PyFdct {
    inner: Fdct,
}

impl PyFdct {
    fn slots(&self) -> Vec<BandSlot> {
        self.inner
            .bands()
            .into_iter()
            .map(|b| BandSlot {
                name: format!("band (scale {}, angle {})", b.scale, b.angle),
                shape: b.shape.to_vec(),
                range: b.range,
            })
            .collect()
    }
}

#[pymethods]
impl PyFdct {
    #[new]
    #[pyo3(signature = (shape, scales, angles_coarse, finest, transition))]
    fn new(
        py: Python<'_>,
        shape: &Bound<'_, PyAny>,
        scales: Option<i128>,
        angles_coarse: i128,
        finest: &str,
        transition: f64,
    ) -> PyResult<Self> {
        let (rows, cols) = args::size2(py, "shape", shape)?;
        let cfg = FdctParams::default()
            .scales(scales.map(|s| uint(py, "scales", s, 0)).transpose()?)
            .angles_coarse(uint(py, "angles_coarse", angles_coarse, 0)?)
            .finest(Finest::by_name(finest).py_err()?)
            .transition(transition);
        Ok(PyFdct {
            inner: crate::pool::detach(py, || Fdct::new(rows, cols, &cfg)).py_err()?,
        })
    }

    fn shape(&self) -> (usize, usize) {
        self.inner.shape()
    }

    fn num_scales(&self) -> usize {
        self.inner.num_scales()
    }

    fn coeff_len(&self) -> usize {
        self.inner.coeff_len()
    }

    fn redundancy(&self) -> f64 {
        self.inner.redundancy()
    }

    /// `[(scale, angle, (rows, cols)), ...]` in coefficient order.
    fn bands(&self) -> Vec<(usize, usize, (usize, usize))> {
        self.inner
            .bands()
            .iter()
            .map(|b| (b.scale, b.angle, (b.shape[0], b.shape[1])))
            .collect()
    }

    /// Wedge centre directions (radians), `None` for the coarse and wavelet bands.
    fn directions(&self) -> Vec<Option<f64>> {
        (0..self.inner.bands().len())
            .map(|b| self.inner.direction(b))
            .collect()
    }

    /// One complex array per band, in coefficient order.
    fn forward<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Arr<'py, Complex64>>> {
        let x = args::complex("x", x)?;
        planned_shape(&x, self.inner.shape())?;
        let v = values(&x);
        let co = crate::pool::detach(py, || self.inner.forward(&v)).py_err()?;
        split_bands(py, &co, &self.slots())
    }

    fn backward<'py>(
        &self,
        py: Python<'py>,
        bands: &Bound<'py, PyAny>,
    ) -> PyResult<Arr<'py, Complex64>> {
        let info = self.slots();
        let co = join_bands(&bands_arg(bands)?, &info, self.inner.coeff_len())?;
        let out = crate::pool::detach(py, || self.inner.backward(&co)).py_err()?;
        let (r, c) = self.inner.shape();
        array(py, &[r, c], out)
    }

    /// Dense windows in FFT order, one per band.
    fn windows<'py>(&self, py: Python<'py>) -> PyResult<Vec<Arr<'py, f64>>> {
        let (r, c) = self.inner.shape();
        let f = &self.inner;
        let windows: Vec<Vec<f64>> = crate::pool::detach(py, || {
            (0..f.bands().len())
                .map(|b| f.window(b).expect("band exists"))
                .collect()
        })?;
        windows.into_iter().map(|w| array(py, &[r, c], w)).collect()
    }
}

/// Where one band of a flat coefficient vector lives.
struct BandSlot {
    name: String,
    shape: Vec<usize>,
    range: std::ops::Range<usize>,
}

/// Splits a flat coefficient vector into one array per band.
fn split_bands<'py>(
    py: Python<'py>,
    co: &[Complex64],
    info: &[BandSlot],
) -> PyResult<Vec<Arr<'py, Complex64>>> {
    info.iter()
        .map(|b| array(py, &b.shape, co[b.range.clone()].to_vec()))
        .collect()
}

/// Packs per-band arrays into a flat coefficient vector of length `total`, checking their
/// number and shapes.
fn join_bands(
    bands: &[PyReadonlyArrayDyn<Complex64>],
    info: &[BandSlot],
    total: usize,
) -> PyResult<Vec<Complex64>> {
    if bands.len() != info.len() {
        return Err(value_error(format!(
            "{} bands given, the transform has {}",
            bands.len(),
            info.len()
        )));
    }
    let mut co = vec![Complex64::new(0.0, 0.0); total];
    for (b, (arr, slot)) in bands.iter().zip(info).enumerate() {
        if arr.shape() != slot.shape.as_slice() {
            return Err(value_error(format!(
                "band {b}, the {}, has shape {:?}, expected {:?}",
                slot.name,
                arr.shape(),
                slot.shape
            )));
        }
        co[slot.range.clone()].copy_from_slice(&values(arr));
    }
    Ok(co)
}

/// A planned sharp-frequency-localized contourlet transform (real-linear; complex images).
#[pyclass(name = "Sflct", module = "wscg._native.csmri")]
pub struct PySflct {
    inner: Sflct,
}

impl PySflct {
    fn slots(&self) -> Vec<BandSlot> {
        self.inner
            .bands()
            .iter()
            .map(|b| BandSlot {
                name: format!("band (scale {}, direction {})", b.scale, b.direction),
                shape: vec![b.shape.0, b.shape.1],
                range: b.range.clone(),
            })
            .collect()
    }

    fn back<'py>(
        &self,
        py: Python<'py>,
        bands: &Bound<'py, PyAny>,
        adjoint: bool,
    ) -> PyResult<Arr<'py, Complex64>> {
        let co = join_bands(&bands_arg(bands)?, &self.slots(), self.inner.coeff_len())?;
        let out = crate::pool::detach(py, || {
            if adjoint {
                self.inner.adjoint(&co)
            } else {
                self.inner.inverse(&co)
            }
        })
        .py_err()?;
        let (r, c) = self.inner.shape();
        array(py, &[r, c], out)
    }
}

#[pymethods]
impl PySflct {
    #[new]
    fn new(
        py: Python<'_>,
        shape: &Bound<'_, PyAny>,
        redundancy: &str,
        levels: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let (rows, cols) = args::size2(py, "shape", shape)?;
        let cfg = SflctParams::default()
            .redundancy(Redundancy::by_name(redundancy).py_err()?)
            .dfb_levels(args::counts(py, "levels", levels)?);
        Ok(PySflct {
            inner: crate::pool::detach(py, || Sflct::new(rows, cols, &cfg)).py_err()?,
        })
    }

    fn shape(&self) -> (usize, usize) {
        self.inner.shape()
    }

    fn redundancy(&self) -> f64 {
        self.inner.redundancy()
    }

    /// `[(scale, direction, (rows, cols)), ...]` in coefficient order.
    fn bands(&self) -> Vec<(usize, usize, (usize, usize))> {
        self.inner
            .bands()
            .iter()
            .map(|b| (b.scale, b.direction, b.shape))
            .collect()
    }

    /// One complex array per band, in coefficient order.
    fn forward<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Arr<'py, Complex64>>> {
        let x = args::complex("x", x)?;
        planned_shape(&x, self.inner.shape())?;
        let v = values(&x);
        let co = crate::pool::detach(py, || self.inner.forward(&v)).py_err()?;
        split_bands(py, &co, &self.slots())
    }

    fn inverse<'py>(
        &self,
        py: Python<'py>,
        bands: &Bound<'py, PyAny>,
    ) -> PyResult<Arr<'py, Complex64>> {
        self.back(py, bands, false)
    }

    fn adjoint<'py>(
        &self,
        py: Python<'py>,
        bands: &Bound<'py, PyAny>,
    ) -> PyResult<Arr<'py, Complex64>> {
        self.back(py, bands, true)
    }
}

/// C-SALSA's development-image tau0 for a named prior.
#[pyfunction]
fn tuned_tau0(prior: &str) -> f64 {
    sparsifier::tuned_tau0(prior)
}

/// A 2-D complex array argument (any numeric array-like) and its `(rows, cols)`.
fn complex2<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<(PyReadonlyArrayDyn<'py, Complex64>, (usize, usize))> {
    let a = args::complex(name, obj)?;
    let shape = dims2(name, &a)?;
    Ok((a, shape))
}

/// The `mask` argument of data of `shape` (any array-like, non-zero = sampled).
fn mask_of(mask: &Bound<'_, PyAny>, shape: (usize, usize)) -> PyResult<Vec<bool>> {
    let m = args::array::<bool>("mask", mask)?;
    if m.shape() != [shape.0, shape.1] {
        return Err(value_error(format!(
            "shape mismatch: mask has shape {:?}, k-space {shape:?}",
            m.shape()
        )));
    }
    Ok(values(&m).into_owned())
}

/// The `kspace` and `mask` arguments as checked k-space data.
fn kspace_in(kspace: &Bound<'_, PyAny>, mask: &Bound<'_, PyAny>) -> PyResult<KSpace> {
    let (k, (r, c)) = complex2("kspace", kspace)?;
    let m = mask_of(mask, (r, c))?;
    KSpace::new(r, c, values(&k).into_owned(), m).py_err()
}

fn reference_in(
    reference: Option<&Bound<'_, PyAny>>,
    shape: (usize, usize),
) -> PyResult<Option<Vec<Complex64>>> {
    match reference.filter(|r| !r.is_none()) {
        None => Ok(None),
        Some(r) => {
            let (r, s) = complex2("reference", r)?;
            if s != shape {
                return Err(value_error(format!(
                    "`reference` has shape {:?}, the k-space {shape:?}",
                    r.shape()
                )));
            }
            Ok(Some(values(&r).into_owned()))
        }
    }
}

fn history<'py>(py: Python<'py>, h: &[IterStat]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iter", h.iter().map(|s| s.iter).collect::<Vec<_>>())?;
    d.set_item(
        "rel_change",
        h.iter().map(|s| s.rel_change).collect::<Vec<_>>(),
    )?;
    d.set_item("residual", h.iter().map(|s| s.residual).collect::<Vec<_>>())?;
    d.set_item(
        "objective",
        h.iter().map(|s| s.objective).collect::<Vec<_>>(),
    )?;
    if h.iter().all(|s| s.mse.is_some()) && !h.is_empty() {
        d.set_item(
            "mse",
            h.iter()
                .map(|s| s.mse.unwrap_or(f64::NAN))
                .collect::<Vec<_>>(),
        )?;
    }
    Ok(d)
}

fn recon_out<'py>(
    py: Python<'py>,
    r: Reconstruction,
) -> PyResult<(Arr<'py, Complex64>, Bound<'py, PyDict>)> {
    let h = history(py, &r.history)?;
    h.set_item("iters", r.iters)?;
    Ok((array(py, &[r.shape.0, r.shape.1], r.image)?, h))
}

/// The C-SALSA regulariser named by `reg`.
fn regularizer(reg: &str, tv_n_iter: usize, shrink_lowpass: bool) -> PyResult<Regularizer> {
    match reg {
        "l1" => Ok(Regularizer::L1 { shrink_lowpass }),
        "tv" => Ok(Regularizer::Tv {
            inner_iters: tv_n_iter,
        }),
        other => Err(value_error(format!(
            "{other:?} is not a valid reg. Valid regularisers are 'l1', 'tv'"
        ))),
    }
}

/// The C-SALSA settings shared by `reconstruct` and `choose_udct_scales`.
fn csalsa_params(
    max_iter: usize,
    tau0: f64,
    rho: f64,
    tau_cap: f64,
    epsilon: f64,
    tol: f64,
) -> CsalsaParams {
    CsalsaParams::default()
        .max_iter(max_iter)
        .tau0(tau0)
        .rho(rho)
        .tau_cap(tau_cap)
        .epsilon(epsilon)
        .tol(tol)
}

/// Hold-out choice of the number of UDCT scales (`wscg_cs_mri::choose_udct_scales`):
/// returns `(scales, held_out, [(candidate, fold_errors), ...])`.
#[pyfunction]
#[pyo3(signature = (kspace, mask, reg, epsilon, max_iter, tau0, rho, tau_cap, tol, wedge, alpha, tv_n_iter, shrink_lowpass, candidates, folds, holdout, cluster, seed))]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::type_complexity)]
fn choose_udct_scales(
    py: Python<'_>,
    kspace: &Bound<'_, PyAny>,
    mask: &Bound<'_, PyAny>,
    reg: &str,
    epsilon: f64,
    max_iter: i128,
    tau0: f64,
    rho: f64,
    tau_cap: f64,
    tol: f64,
    wedge: &Bound<'_, PyAny>,
    alpha: f64,
    tv_n_iter: i128,
    shrink_lowpass: bool,
    candidates: &Bound<'_, PyAny>,
    folds: i128,
    holdout: f64,
    cluster: f64,
    seed: i128,
) -> PyResult<(usize, usize, Vec<(usize, Vec<f64>)>)> {
    let (wr, wc) = args::size2(py, "wedge", wedge)?;
    let wedge = [wr, wc];
    let (max_iter, tv_n_iter) = (
        uint(py, "max_iter", max_iter, 0usize)?,
        uint(py, "tv_n_iter", tv_n_iter, 0usize)?,
    );
    let candidates = args::counts(py, "candidates", candidates)?;
    let (folds, seed) = (
        uint(py, "folds", folds, 0usize)?,
        uint(py, "seed", seed, 0u64)?,
    );
    let data = kspace_in(kspace, mask)?;
    let regularizer = regularizer(reg, tv_n_iter, shrink_lowpass)?;
    let p = csalsa_params(max_iter, tau0, rho, tau_cap, epsilon, tol);
    let c = ScaleChoiceParams::default()
        .candidates(candidates)
        .folds(folds)
        .holdout(holdout)
        .cluster(cluster)
        .seed(seed);
    let udct = config(vec![wedge], alpha, true);
    let choice = crate::pool::detach(py, || {
        wscg_cs_mri::choose_udct_scales(&data, regularizer, &p, &udct, &c)
    })
    .py_err()?;
    Ok((
        choice.scales,
        choice.held_out,
        choice
            .scores
            .into_iter()
            .map(|s| (s.scales, s.fold_errors))
            .collect(),
    ))
}

#[pyfunction]
#[pyo3(signature = (kspace, mask, prior, reg, epsilon, max_iter, tau0, rho, tau_cap, tol, wedges, alpha, levels, tv_n_iter, shrink_lowpass, reference, record_history, fdct = None, sflct_levels = None))]
#[allow(clippy::too_many_arguments)]
fn reconstruct<'py>(
    py: Python<'py>,
    kspace: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    prior: &str,
    reg: &str,
    epsilon: f64,
    max_iter: i128,
    tau0: f64,
    rho: f64,
    tau_cap: f64,
    tol: f64,
    wedges: &Bound<'py, PyAny>,
    alpha: f64,
    levels: i128,
    tv_n_iter: i128,
    shrink_lowpass: bool,
    reference: Option<Bound<'py, PyAny>>,
    record_history: bool,
    fdct: Option<(Option<usize>, usize, String, f64)>,
    sflct_levels: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Arr<'py, Complex64>, Bound<'py, PyDict>)> {
    let wedges = wedges_arg(py, wedges)?;
    let (max_iter, levels, tv_n_iter): (usize, usize, usize) = (
        uint(py, "max_iter", max_iter, 0)?,
        uint(py, "levels", levels, 0)?,
        uint(py, "tv_n_iter", tv_n_iter, 0)?,
    );
    let sflct_levels = sflct_levels
        .filter(|l| !l.is_none())
        .map(|l| args::counts(py, "sflct_levels", l))
        .transpose()?;
    let data = kspace_in(kspace, mask)?;
    let (r, c) = data.shape();
    let reference = reference_in(reference.as_ref(), (r, c))?;
    let regularizer = regularizer(reg, tv_n_iter, shrink_lowpass)?;
    let p = csalsa_params(max_iter, tau0, rho, tau_cap, epsilon, tol)
        .record_history(record_history || reference.is_some());
    let cfg = PriorParams::default()
        .udct(config(wedges, alpha, true))
        .fdct(match fdct {
            Some((scales, angles_coarse, finest, transition)) => FdctParams::default()
                .scales(scales)
                .angles_coarse(angles_coarse)
                .finest(Finest::by_name(&finest).py_err()?)
                .transition(transition),
            None => FdctParams::default(),
        })
        .sflct_levels(sflct_levels.unwrap_or_else(|| SflctParams::default().dfb_levels))
        .levels(levels);
    let rec = crate::pool::detach(py, || {
        let psi = sparsifier::by_name(prior, r, c, &cfg)?;
        csalsa(
            &data,
            psi.as_ref(),
            regularizer,
            &p,
            reference.as_deref(),
            &NoProgress,
        )
    })
    .py_err()?;
    recon_out(py, rec)
}

#[pyfunction]
#[pyo3(signature = (method, kspace, mask, a, b, group_weight, mu_g, n_iter, tv_n_iter, order, levels, reference, record_history))]
#[allow(clippy::too_many_arguments)]
fn composite<'py>(
    py: Python<'py>,
    method: &str,
    kspace: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    a: f64,
    b: f64,
    group_weight: f64,
    mu_g: f64,
    n_iter: i128,
    tv_n_iter: i128,
    order: i128,
    levels: i128,
    reference: Option<Bound<'py, PyAny>>,
    record_history: bool,
) -> PyResult<(Arr<'py, Complex64>, Bound<'py, PyDict>)> {
    let levels: usize = uint(py, "levels", levels, 1)?;
    let (n_iter, tv_n_iter, order): (usize, usize, usize) = (
        uint(py, "n_iter", n_iter, 0)?,
        uint(py, "tv_n_iter", tv_n_iter, 0)?,
        uint(py, "order", order, 0)?,
    );
    if levels > 30 {
        return Err(value_error(format!("`levels` must be <= 30, got {levels}")));
    }
    let (k, (r, c)) = complex2("kspace", kspace)?;
    let div = 1usize << levels;
    if r % div != 0 || c % div != 0 {
        return Err(value_error(format!(
            "`kspace` of shape ({r}, {c}): a {levels}-level wavelet transform needs both sizes \
             divisible by {div}; pad the k-space or lower `levels`"
        )));
    }
    let data = KSpace::new(r, c, values(&k).into_owned(), mask_of(mask, (r, c))?).py_err()?;
    let reference = reference_in(reference.as_ref(), data.shape())?;
    let p = CompositeParams::default()
        .a(a)
        .b(b)
        .group_weight(group_weight)
        .mu_g(mu_g)
        .max_iter(n_iter)
        .tv_inner(tv_n_iter)
        .order(order)
        .levels(levels)
        .record_history(record_history || reference.is_some());
    let f = match method {
        "fcsa" => baselines::fcsa,
        "tvcmri" => baselines::tvcmri,
        "watmri" => baselines::watmri,
        other => return Err(value_error(format!("{other:?} is not a baseline"))),
    };
    let rec =
        crate::pool::detach(py, || f(&data, &p, reference.as_deref(), &NoProgress)).py_err()?;
    recon_out(py, rec)
}

/// ``min TV(x) s.t. ||P F x - y|| <= epsilon`` by Chambolle-Pock (the problem
/// ``reconstruct(..., reg="tv")`` solves, by another algorithm), ``n_iter`` iterations (a
/// fixed count).
#[pyfunction]
#[pyo3(signature = (kspace, mask, epsilon=0.0, n_iter=2000))]
fn tv_constrained<'py>(
    py: Python<'py>,
    kspace: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    epsilon: f64,
    n_iter: i128,
) -> PyResult<Arr<'py, Complex64>> {
    let n_iter: usize = uint(py, "n_iter", n_iter, 0)?;
    let data = kspace_in(kspace, mask)?;
    let rec = crate::pool::detach(py, || {
        baselines::tv_constrained(&data, epsilon, n_iter, None)
    })
    .py_err()?;
    array(py, &[rec.shape.0, rec.shape.1], rec.image)
}

/// Variable-density Cartesian mask of whole rows (phase encodes), un-shifted: the
/// ``round(center_frac * rows)`` rows nearest DC plus rows drawn with probability
/// proportional to ``(1 - |k| / k_max)^2``, ``round(rate * rows)`` rows in all.
#[pyfunction]
#[pyo3(signature = (shape, rate=0.4, center_frac=0.08, seed=0))]
fn mask_cartesian<'py>(
    py: Python<'py>,
    shape: &Bound<'py, PyAny>,
    rate: f64,
    center_frac: f64,
    seed: i128,
) -> PyResult<Arr<'py, bool>> {
    let (rows, cols) = args::size2(py, "shape", shape)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let m = crate::pool::detach(py, || masks::cartesian(rows, cols, rate, center_frac, seed))
        .py_err()?;
    array(py, &[rows, cols], m)
}

/// Pseudo-radial mask: the fewest Bresenham lines through the centre (angles
/// ``pi l / L``) covering at least ``rate``. Returns ``(mask, L)``, un-shifted.
#[pyfunction]
#[pyo3(signature = (shape, rate=0.302))]
fn mask_pseudo_radial<'py>(
    py: Python<'py>,
    shape: &Bound<'py, PyAny>,
    rate: f64,
) -> PyResult<(Arr<'py, bool>, usize)> {
    let (rows, cols) = args::size2(py, "shape", shape)?;
    let (m, lines) = crate::pool::detach(py, || masks::pseudo_radial(rows, cols, rate)).py_err()?;
    Ok((array(py, &[rows, cols], m)?, lines))
}

/// Analytic k-space of the modified Shepp-Logan phantom, ``(n, n)``, un-shifted,
/// unitary scaling (no inverse crime: it is not the FFT of a raster).
#[pyfunction]
#[pyo3(signature = (n=256))]
fn make_shepp_logan_kspace(py: Python<'_>, n: i128) -> PyResult<Arr<'_, Complex64>> {
    let n: usize = uint(py, "n", n, 0)?;
    let k = crate::pool::detach(py, || phantom::shepp_logan_kspace(n)).py_err()?;
    array(py, &[n, n], k)
}

/// The reference image: inverse unitary FFT of :func:`make_shepp_logan_kspace`.
#[pyfunction]
#[pyo3(signature = (n=256))]
fn make_shepp_logan_reference(py: Python<'_>, n: i128) -> PyResult<Arr<'_, Complex64>> {
    let n: usize = uint(py, "n", n, 0)?;
    let r = crate::pool::detach(py, || phantom::shepp_logan_reference(n)).py_err()?;
    array(py, &[n, n], r)
}

/// The phantom rasterised on an ``(n, n)`` grid (float64).
#[pyfunction]
#[pyo3(signature = (n=256))]
fn make_shepp_logan_image(py: Python<'_>, n: i128) -> PyResult<Arr<'_, f64>> {
    let n: usize = uint(py, "n", n, 0)?;
    let i = crate::pool::detach(py, || phantom::shepp_logan_image(n)).py_err()?;
    array(py, &[n, n], i)
}

/// ``magnitude * exp(i phi)`` with a random smooth quadratic phase of peak-to-peak 2 pi.
#[pyfunction]
#[pyo3(signature = (magnitude, seed=0))]
fn with_smooth_phase<'py>(
    py: Python<'py>,
    magnitude: &Bound<'py, PyAny>,
    seed: i128,
) -> PyResult<Arr<'py, Complex64>> {
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let magnitude = args::array::<f64>("magnitude", magnitude)?;
    let (r, c) = dims2("magnitude", &magnitude)?;
    let m = values(&magnitude);
    let out = crate::pool::detach(py, || {
        phantom::with_smooth_phase(ImageView::plane(r, c, &m)?, seed)
    })
    .py_err()?;
    array(py, &[r, c], out.into_data())
}

/// A disk (radius 0.8 of the half field of view) filled with a rhombic lattice of the
/// given period in pixels: the directional texture of the paper's water phantom.
#[pyfunction]
#[pyo3(signature = (n=256, period=12.0))]
fn make_diamond_lattice(py: Python<'_>, n: i128, period: f64) -> PyResult<Arr<'_, f64>> {
    let n: usize = uint(py, "n", n, 0)?;
    let period = args::number("period", period)?;
    let d = crate::pool::detach(py, || phantom::diamond_lattice(n, period)).py_err()?;
    array(py, &[n, n], d)
}

/// The 2-D complex arrays `reference` and `x`, of one shape.
fn pair(
    reference: &Bound<'_, PyAny>,
    x: &Bound<'_, PyAny>,
) -> PyResult<(Vec<Complex64>, Vec<Complex64>)> {
    let (reference, rs) = complex2("reference", reference)?;
    let (x, xs) = complex2("x", x)?;
    if rs != xs {
        return Err(value_error(format!(
            "shape mismatch: reference {rs:?}, x {xs:?}"
        )));
    }
    Ok((values(&reference).into_owned(), values(&x).into_owned()))
}

/// PSNR in dB of ``|x|`` against ``|reference|``: ``20 log10(max|ref| / RMSE)``.
#[pyfunction]
fn psnr(py: Python<'_>, reference: &Bound<'_, PyAny>, x: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (r, x) = pair(reference, x)?;
    crate::pool::detach(py, || metrics::psnr(&r, &x)).py_err()
}

/// Relative l2 norm error ``||x - ref|| / ||ref||`` (complex values, or magnitudes).
#[pyfunction]
#[pyo3(signature = (reference, x, magnitude=false))]
fn rlne(
    py: Python<'_>,
    reference: &Bound<'_, PyAny>,
    x: &Bound<'_, PyAny>,
    magnitude: bool,
) -> PyResult<f64> {
    let (r, x) = pair(reference, x)?;
    crate::pool::detach(py, || {
        if magnitude {
            metrics::rlne_magnitude(&r, &x)
        } else {
            metrics::rlne(&r, &x)
        }
    })
    .py_err()
}

/// ``sigma sqrt(2m + 4 sqrt(m))``: the noise radius for ``m`` complex samples with
/// standard deviation ``sigma`` per component (mean + 2 std of the noise norm).
#[pyfunction]
fn noise_epsilon(py: Python<'_>, sigma: f64, m: i128) -> PyResult<f64> {
    if !(sigma >= 0.0 && sigma.is_finite()) {
        return Err(value_error(format!(
            "`sigma` must be finite and >= 0, got {sigma}"
        )));
    }
    let m: usize = uint(py, "m", m, 0)?;
    Ok(wscg_cs_mri::noise_epsilon(sigma, m))
}

/// Registers the submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyUdct>()?;
    m.add_class::<PyFdct>()?;
    m.add_class::<PySflct>()?;
    m.add_function(wrap_pyfunction!(tuned_tau0, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(choose_udct_scales, m)?)?;
    m.add_function(wrap_pyfunction!(composite, m)?)?;
    m.add_function(wrap_pyfunction!(tv_constrained, m)?)?;
    m.add_function(wrap_pyfunction!(mask_cartesian, m)?)?;
    m.add_function(wrap_pyfunction!(mask_pseudo_radial, m)?)?;
    m.add_function(wrap_pyfunction!(make_shepp_logan_kspace, m)?)?;
    m.add_function(wrap_pyfunction!(make_shepp_logan_reference, m)?)?;
    m.add_function(wrap_pyfunction!(make_shepp_logan_image, m)?)?;
    m.add_function(wrap_pyfunction!(with_smooth_phase, m)?)?;
    m.add_function(wrap_pyfunction!(make_diamond_lattice, m)?)?;
    m.add_function(wrap_pyfunction!(psnr, m)?)?;
    m.add_function(wrap_pyfunction!(rlne, m)?)?;
    m.add_function(wrap_pyfunction!(noise_epsilon, m)?)?;
    Ok(())
}
