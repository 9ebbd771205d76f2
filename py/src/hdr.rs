//! `wscg.hdr`'s functions (paper 13, multiscopic HDR image sequence generation): bindings of
//! `wscg-hdr`. The matching, synthesis, merge, metric and file functions are called by Python
//! directly, re-exported by `python/wscg/hdr.py` (which holds the module's documentation);
//! their arguments are converted and checked here and by [`crate::args`], and the crate's
//! own checks name the Python arguments ([`PM_NAMES`]). The functions that take images as
//! file paths or build result classes (`multiscopic_hdr`, `merge_stack`, `to_radiance`,
//! the calibrations, `make_scene`) stay in Python, which passes them C-contiguous uint16
//! code images and float32 response tables; those bindings validate their input again, so a
//! direct call cannot panic.

use std::path::PathBuf;

use numpy::PyUntypedArray;
use numpy::{PyArrayDescrMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString, PyTuple};
use wscg_hdr::metrics;
use wscg_hdr::synth::{layered_scene, Layer, SceneParams};
use wscg_hdr::{Align, Crf, MultiscopicParams, Nnf, PatchMatchParams, StereoParams, Synthesis};
use wscg_math::progress::NoProgress;
use wscg_math::Image;

use crate::args::{self, number, uint};
use crate::convert::{array, image_dims, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed, Renames};

/// An image of codes, `(H, W)` or `(H, W, C)`.
fn codes_in(name: &str, a: &PyReadonlyArrayDyn<u16>) -> PyResult<Image<u16>> {
    let (h, w, c) = image_dims(name, a.shape())?;
    Image::new(h, w, c, values(a).into_owned()).py_err()
}

/// `obj` as a numpy array of real numbers ([`args::real_array`]) and its dtype's kind.
fn real_array<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<(Bound<'py, PyAny>, u8)> {
    let a = args::real_array(name, obj)?;
    let kind = a.dtype().kind();
    Ok((a.into_any(), kind))
}

/// A radiance image argument: a non-empty float array `(H, W)` or `(H, W, C)`, as float32
/// with finite values, and whether it was 2-D.
fn float_image(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Image<f32>, bool)> {
    let (a, kind) = real_array(name, obj)?;
    if kind != b'f' {
        return Err(value_error(format!(
            "`{name}` must be a float (radiance) image, got dtype {}; convert codes with \
             to_radiance, or cast with .astype(np.float32)",
            a.getattr("dtype")?
        )));
    }
    let a = args::array::<f32>(name, &a)?;
    let (h, w, c) = image_dims(name, a.shape())?;
    if h * w * c == 0 {
        return Err(value_error(format!(
            "`{name}` is empty (shape {:?})",
            a.shape()
        )));
    }
    let v = values(&a);
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!(
            "`{name}` contains a non-finite value (NaN or infinity, possibly after conversion \
             to float32) at flat index {i}"
        )));
    }
    Ok((Image::new(h, w, c, v.into_owned()).py_err()?, a.ndim() == 2))
}

/// A field argument: a non-empty `(H, W, 2)` array of integer offsets `(dx, dy)` (integral
/// floats accepted) within +-2^30 (costs zero).
fn offsets(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Nnf> {
    let (a, kind) = real_array(name, obj)?;
    let a = args::array::<f64>(name, &a)?;
    let (h, w) = match *a.shape() {
        [h, w, 2] if h > 0 && w > 0 => (h, w),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be a non-empty (H, W, 2) array of offsets (dx, dy), got shape \
                 {s:?}"
            )))
        }
    };
    let v = values(&a);
    if kind == b'f' && v.iter().any(|x| !x.is_finite() || x.round() != *x) {
        return Err(value_error(format!("`{name}` must hold integer offsets")));
    }
    if v.iter().any(|x| x.abs() > f64::from(1 << 30)) {
        return Err(value_error(format!("`{name}` holds offsets beyond +-2^30")));
    }
    let o = v
        .chunks_exact(2)
        .map(|p| [p[0] as i32, p[1] as i32])
        .collect();
    Nnf::new(h, w, o, vec![0.0; h * w]).py_err()
}

/// A boolean mask argument: its shape and values.
fn bool_mask(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<usize>, Vec<bool>)> {
    let a = args::asarray(name, obj)?;
    if a.dtype().kind() != b'b' {
        return Err(value_error(format!(
            "`{name}` must be a boolean array, got dtype {}",
            a.dtype()
        )));
    }
    let a = args::array::<bool>(name, a.as_any())?;
    Ok((a.shape().to_vec(), values(&a).into_owned()))
}

/// The integer argument `name` in `lo..=hi`.
fn bounded<T>(py: Python<'_>, name: &str, v: i128, lo: T, hi: T) -> PyResult<T>
where
    T: TryFrom<i128> + PartialOrd + Copy + std::fmt::Display,
{
    let x = uint(py, name, v, lo)?;
    if x > hi {
        return Err(value_error(format!("`{name}` must be <= {hi}, got {x}")));
    }
    Ok(x)
}

/// The crate's parameter names that the Python functions call otherwise.
const PM_NAMES: &Renames = &[
    ("d_min", "min_disparity"),
    ("d_max", "max_disparity"),
    ("iters", "n_iter"),
    ("times", "exposure_times"),
];

/// A field as `(offsets int32 (H, W, 2), cost float32 (H, W))`.
fn nnf_out<'py>(py: Python<'py>, f: Nnf) -> PyResult<(Arr<'py, i32>, Arr<'py, f32>)> {
    let (h, w) = (f.height(), f.width());
    let off = f.off.iter().flat_map(|o| [o[0], o[1]]).collect();
    Ok((array(py, &[h, w, 2], off)?, array(py, &[h, w], f.cost)?))
}

/// The codes of an 8- or 16-bit image file (PNG, TIFF, JPEG) as `(H, W)` or `(H, W, C)`
/// uint16, with the file's bit depth.
#[pyfunction]
fn load_codes(py: Python<'_>, path: PathBuf) -> PyResult<(Arr<'_, u16>, u8)> {
    let (img, bits) = crate::pool::detach(py, || Image::<u16>::load_codes(&path)).py_err()?;
    let (h, w, c) = img.shape();
    let shape = if c == 1 { vec![h, w] } else { vec![h, w, c] };
    Ok((array(py, &shape, img.into_data())?, bits))
}

/// The exposure times of image files: `given` checked against their EXIF exposures, or the
/// EXIF exposures (`wscg_math::io::exif::resolve_exposure_times`). Returns the times,
/// whether they came from EXIF, and one message per disagreement.
#[pyfunction]
#[pyo3(signature = (paths, given))]
fn exposure_times(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    given: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Vec<f64>, bool, Vec<String>)> {
    let given = match given.filter(|g| !g.is_none()) {
        Some(g) => Some(times_arg(Some(g), paths.len())?),
        None => None,
    };
    let r = crate::pool::detach(py, || {
        wscg_math::io::exif::resolve_exposure_times(&paths, given.as_deref())
    })
    .py_err()?;
    let messages = r.mismatches.into_iter().map(|m| m.message).collect();
    Ok((r.times, r.from_exif, messages))
}

/// One inverse camera response as given from Python: a name or a table.
#[derive(FromPyObject)]
enum CrfArg<'py> {
    /// `"gamma2.2"` or `"linear"`.
    Name(String),
    /// `(levels,)` or `(levels, C)` table of `f^-1`.
    Table(PyReadonlyArrayDyn<'py, f32>),
}

/// The smallest bit depth (at least 1) whose codes reach `max_code`.
fn bits_for(max_code: u16) -> u8 {
    (16 - max_code.leading_zeros()).max(1) as u8
}

fn crf_in(arg: &CrfArg<'_>, bits: u8) -> PyResult<Crf> {
    match arg {
        CrfArg::Name(n) => match n.as_str() {
            "gamma2.2" => Crf::gamma(2.2, bits, 1).py_err(),
            "linear" => Crf::linear(bits, 1).py_err(),
            other => Err(value_error(format!(
                "unknown response {other:?}; use \"gamma2.2\", \"linear\" or a table of f^-1"
            ))),
        },
        CrfArg::Table(t) => {
            let (levels, c) = match *t.shape() {
                [l] => (l, 1),
                [l, c] => (l, c),
                ref s => {
                    return Err(value_error(format!(
                        "a response table must have shape (levels,) or (levels, C), got {s:?}"
                    )))
                }
            };
            Crf::from_table(&values(t), levels, c).py_err()
        }
    }
}

/// The responses of `images`: `bits` (or the smallest depth covering their codes) for named
/// responses, one shared or one per image.
fn crfs_in(
    py: Python<'_>,
    crfs: &[CrfArg<'_>],
    images: &[Image<u16>],
    bits: Option<u8>,
) -> PyResult<Vec<Crf>> {
    if crfs.is_empty() {
        return Err(value_error(
            "`crf`: give one response or one per view, got none",
        ));
    }
    if crfs.len() != 1 && crfs.len() != images.len() {
        return Err(value_error(format!(
            "`crf`: give one response or one per view ({}), got {}",
            images.len(),
            crfs.len()
        )));
    }
    let bits = match bits {
        Some(b) => b,
        None => bits_for(crate::pool::detach(py, || {
            images
                .iter()
                .map(wscg_hdr::radiance::max_code)
                .max()
                .unwrap_or(0)
        })?),
    };
    crfs.iter().map(|c| crf_in(c, bits)).collect()
}

/// A disparity range as `i32` offsets, refused beyond `|d| <= 2^24` (the crate checks it
/// against the width).
fn check_range(d_min: i64, d_max: i64) -> PyResult<(i32, i32)> {
    const LIM: u64 = 1 << 24;
    if d_min.unsigned_abs() > LIM || d_max.unsigned_abs() > LIM {
        return Err(value_error(format!(
            "the disparity range [{d_min}, {d_max}] is out of bounds (|d| <= 2^24)"
        )));
    }
    Ok((d_min as i32, d_max as i32))
}

/// A code image argument (see [`codes_arg`]).
struct Codes {
    img: Image<u16>,
    /// The numpy shape, `(H, W)` or `(H, W, C)`.
    shape: Vec<usize>,
    /// Whether the codes were uint8.
    u8: bool,
}

/// A code image argument `name`: uint8 or uint16, `(H, W)` or `(H, W, C)`, non-empty.
fn codes_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Codes> {
    let a = args::real_array(name, obj)?;
    let dtype = a.dtype();
    let u8 = dtype.kind() == b'u' && dtype.itemsize() == 1;
    if !(u8 || dtype.kind() == b'u' && dtype.itemsize() == 2) {
        return Err(value_error(format!(
            "`{name}` must hold camera codes as uint8 or uint16, got dtype {dtype}; convert \
             integer codes with .astype(np.uint16) (radiance images go to patchmatch, not here)"
        )));
    }
    let shape = a.shape().to_vec();
    if !(2..=3).contains(&shape.len()) {
        return Err(value_error(format!(
            "`{name}` must be a 2-D (H, W) or 3-D (H, W, C) array, got shape {}",
            args::shape_repr(&shape)
        )));
    }
    if a.len() == 0 {
        return Err(value_error(format!(
            "`{name}` is empty (shape {})",
            args::shape_repr(&shape)
        )));
    }
    let a = args::array::<u16>(name, a.as_any())?;
    Ok(Codes {
        img: codes_in(name, &a)?,
        shape,
        u8,
    })
}

/// A list argument `name` of code images ([`codes_arg`]) of one shape, at least one.
fn codes_list_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Codes>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Err(value_error(format!(
            "`{name}` must be a list of images, got one array of shape {}; pass list(a) for a \
             stacked (N, H, W[, C]) array",
            args::shape_repr(a.shape())
        )));
    }
    let Ok(items) = obj.try_iter() else {
        return Err(value_error(format!(
            "`{name}` must be a list of images, got {}",
            obj.get_type().name()?
        )));
    };
    let items = items.collect::<PyResult<Vec<_>>>()?;
    if items.is_empty() {
        return Err(value_error(format!(
            "`{name}` is empty: need at least 1 image(s)"
        )));
    }
    let out = items
        .iter()
        .enumerate()
        .map(|(i, v)| codes_arg(&format!("{name}[{i}]"), v))
        .collect::<PyResult<Vec<_>>>()?;
    if let Some((i, c)) = out
        .iter()
        .enumerate()
        .find(|(_, c)| c.shape != out[0].shape)
    {
        return Err(value_error(format!(
            "images differ in shape: `{name}[0]` is {}, `{name}[{i}]` is {}",
            args::shape_repr(&out[0].shape),
            args::shape_repr(&c.shape)
        )));
    }
    Ok(out)
}

/// The `exposure_times` argument: one finite time > 0 (seconds) per image of `n`; required
/// (`None` is refused: only images given as files have EXIF exposures).
fn times_arg(obj: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Vec<f64>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Err(value_error(
            "`exposure_times` is required for images given as arrays (EXIF exposures are read \
             only from images given as file paths)",
        ));
    };
    let a = args::array::<f64>("exposure_times", obj)?;
    if a.len() != n {
        return Err(value_error(format!(
            "`exposure_times` must hold one exposure time per image: {n} images, {} times",
            a.len()
        )));
    }
    positive_times(&a)
}

/// The exposure times of `a`, each finite and > 0 (seconds).
fn positive_times(a: &PyReadonlyArrayDyn<'_, f64>) -> PyResult<Vec<f64>> {
    let t = values(a);
    if let Some((i, v)) = t
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(value_error(format!(
            "`exposure_times[{i}]` must be finite and > 0 (seconds), got {v}"
        )));
    }
    Ok(t.into_owned())
}

/// One inverse response argument `name`: a name of [`CRF_NAMES`] or a table `(levels,)` /
/// `(levels, C)` of `f^-1`, finite, `>= 0`, non-decreasing, positive at `z_max`.
fn crf_one<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<CrfArg<'py>> {
    if let Ok(s) = obj.extract::<String>() {
        if !CRF_NAMES.contains(&s.as_str()) {
            return Err(value_error(format!(
                "unknown response {s:?} for `{name}`; use \"gamma2.2\", \"linear\" or a table \
                 (levels, C) of f^-1"
            )));
        }
        return Ok(CrfArg::Name(s));
    }
    let a = args::real_array(name, obj)?;
    let shape = a.shape().to_vec();
    let (levels, ch) = match shape[..] {
        [l] => (l, 1),
        [l, c] => (l, c),
        _ => {
            return Err(value_error(format!(
                "`{name}` must be a table (levels,) or (levels, C) of f^-1, got shape {}",
                args::shape_repr(&shape)
            )))
        }
    };
    if !(2..=65536).contains(&levels) || ch == 0 {
        return Err(value_error(format!(
            "`{name}` needs 2..65536 levels (z_max + 1) and >= 1 channel, got shape {}",
            args::shape_repr(&shape)
        )));
    }
    let t = args::array::<f32>(name, a.as_any())?;
    let v = values(&t);
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(value_error(format!(
            "`{name}`: f^-1 must be finite and >= 0"
        )));
    }
    for z in 0..levels - 1 {
        for c in 0..ch {
            if v[(z + 1) * ch + c] < v[z * ch + c] {
                return Err(value_error(format!(
                    "`{name}` is not monotone: f^-1({}) < f^-1({z}) in channel {c}; an inverse \
                     response must be non-decreasing",
                    z + 1
                )));
            }
        }
    }
    if v[(levels - 1) * ch..].iter().any(|x| *x <= 0.0) {
        return Err(value_error(format!("`{name}`: f^-1(z_max) must be > 0")));
    }
    drop(v);
    Ok(CrfArg::Table(t))
}

/// The `crf` argument of `n` images: one response, or a list of one per image.
fn crfs_arg<'py>(obj: &Bound<'py, PyAny>, n: usize) -> PyResult<Vec<CrfArg<'py>>> {
    let listed = obj.cast::<PyList>().is_ok() || obj.cast::<PyTuple>().is_ok();
    if listed && obj.len()? > 0 {
        let items = obj.try_iter()?.collect::<PyResult<Vec<_>>>()?;
        if items
            .iter()
            .all(|c| c.cast::<PyString>().is_ok() || c.cast::<PyUntypedArray>().is_ok())
        {
            if items.len() != n {
                return Err(value_error(format!(
                    "`crf`: give one response or one per view ({n}), got a list of {}",
                    items.len()
                )));
            }
            return items
                .iter()
                .enumerate()
                .map(|(i, c)| crf_one(&format!("crf[{i}]"), c))
                .collect();
        }
    }
    Ok(vec![crf_one("crf", obj)?])
}

/// The bit depth of named responses: `bits` (1..=16, covering the codes and the tables'
/// levels), 8 for uint8 images, or `None` (the smallest depth covering the largest code).
fn bits_arg(
    py: Python<'_>,
    bits: Option<i128>,
    crfs: &[CrfArg<'_>],
    images: &[Codes],
) -> PyResult<Option<u8>> {
    let Some(bits) = bits else {
        return Ok(images.iter().all(|c| c.u8).then_some(8));
    };
    let bits: u8 = bounded(py, "bits", bits, 1, 16)?;
    codes_fit(py, images.iter().map(|c| &c.img), bits, "the images hold")?;
    for (i, c) in crfs.iter().enumerate() {
        if let CrfArg::Table(t) = c {
            if t.shape()[0] != 1 << bits {
                return Err(value_error(format!(
                    "`bits` = {bits} means {} codes but the response table {i} has {} levels",
                    1u32 << bits,
                    t.shape()[0]
                )));
            }
        }
    }
    Ok(Some(bits))
}

/// The flag argument `name`: `True` or `False` (numpy's too).
fn flag_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(b.is_true());
    }
    let np_bool = obj.py().import("numpy")?.getattr("bool_")?;
    if obj.is_instance(&np_bool)? {
        return obj.is_truthy();
    }
    Err(value_error(format!(
        "`{name}` must be True or False, got {}",
        obj.repr()?
    )))
}

/// Errors unless every code of `images` fits `bits` bits (`what` starts the message: "the
/// images hold").
fn codes_fit<'a>(
    py: Python<'_>,
    images: impl IntoIterator<Item = &'a Image<u16>>,
    bits: u8,
    what: &str,
) -> PyResult<()> {
    let images: Vec<&Image<u16>> = images.into_iter().collect();
    let top = (1u32 << bits) - 1;
    let max_code = crate::pool::detach(py, || {
        images
            .iter()
            .map(|im| wscg_hdr::radiance::max_code(im))
            .max()
            .unwrap_or(0)
    })?;
    if u32::from(max_code) > top {
        return Err(value_error(format!(
            "{what} code {max_code}, above the {bits}-bit maximum {top}: `bits` is too \
             small"
        )));
    }
    Ok(())
}

/// The codes, exposure times and bit depth of a calibration stack (at least 2 exposures;
/// `bits` 1..=16, default 8, covering the codes).
fn calibration_stack(
    py: Python<'_>,
    stack: &Bound<'_, PyAny>,
    exposure_times: Option<&Bound<'_, PyAny>>,
    bits: Option<i128>,
) -> PyResult<(Vec<Image<u16>>, Vec<f64>, u8)> {
    let codes = codes_list_arg("stack", stack)?;
    if codes.len() < 2 {
        return Err(value_error(format!(
            "`stack` needs at least 2 exposures, got {}",
            codes.len()
        )));
    }
    let times = times_arg(exposure_times, codes.len())?;
    let bits: u8 = bounded(py, "bits", bits.unwrap_or(8), 1, 16)?;
    let imgs: Vec<Image<u16>> = codes.into_iter().map(|c| c.img).collect();
    codes_fit(py, &imgs, bits, "the stack holds")?;
    Ok((imgs, times, bits))
}

/// Names of the inverse responses.
const CRF_NAMES: [&str; 2] = ["gamma2.2", "linear"];
/// Names of the alignment methods of `multiscopic_hdr`.
const ALIGN_METHODS: [&str; 4] = ["ours", "pm2d", "zncc", "none"];

/// `'a', 'b'`: names as a Python message lists them.
fn quoted(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("'{n}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

type HdrResult<'py> = (Vec<Arr<'py, f32>>, Option<Bound<'py, PyDict>>, Vec<usize>);

/// The checked arguments of `wscg.hdr.multiscopic_hdr` (its docstring, the files, their
/// EXIF times and `HdrSequence` are in python/wscg/hdr.py): views as arrays,
/// `exposure_times` given or read from the files, `bits` given or the files'.
#[pyfunction]
#[pyo3(signature = (views, exposure_times, crf, bits, patch, n_iter, max_disparity,
                    min_disparity, coherence, epipolar, align, synthesis, ordered,
                    weighted_cost, fill_saturated, seed, return_details))]
#[allow(clippy::too_many_arguments)]
fn multiscopic_hdr<'py>(
    py: Python<'py>,
    views: &Bound<'py, PyAny>,
    exposure_times: Option<&Bound<'py, PyAny>>,
    crf: &Bound<'py, PyAny>,
    bits: Option<i128>,
    patch: i128,
    n_iter: i128,
    max_disparity: i128,
    min_disparity: Option<i128>,
    coherence: &Bound<'py, PyAny>,
    epipolar: &Bound<'py, PyAny>,
    align: &str,
    synthesis: &str,
    ordered: &Bound<'py, PyAny>,
    weighted_cost: &Bound<'py, PyAny>,
    fill_saturated: &Bound<'py, PyAny>,
    seed: i128,
    return_details: &Bound<'py, PyAny>,
) -> PyResult<HdrResult<'py>> {
    let codes = codes_list_arg("views", views)?;
    if codes.len() < 2 {
        return Err(value_error(format!(
            "multiscopic_hdr needs at least 2 views, got {}; to merge an aligned exposure \
             stack of one view use merge_stack",
            codes.len()
        )));
    }
    let flat = codes[0].shape.len() == 2;
    let (h, w) = (codes[0].shape[0], codes[0].shape[1]);
    let times = times_arg(exposure_times, codes.len())?;
    let crfs = crfs_arg(crf, codes.len())?;
    let bits = bits_arg(py, bits, &crfs, &codes)?;
    if !ALIGN_METHODS.contains(&align) {
        return Err(value_error(format!(
            "{align:?} is not a valid align method. Valid methods are {}",
            quoted(&ALIGN_METHODS)
        )));
    }
    let synthesis = match synthesis {
        "bds" => Synthesis::Bds,
        "direct" => Synthesis::Direct,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid synthesis. Valid names are {}",
                quoted(&["bds", "direct"])
            )))
        }
    };
    let epipolar = flag_arg("epipolar", epipolar)?;
    let (patch, d_min, d_max) = if align == "none" {
        // Nothing is matched: the matching parameters are not used.
        (bounded(py, "patch", patch, 0usize, 1 << 31)?, 0, 0)
    } else {
        let lim = h.min(w);
        if patch < 3 || patch % 2 == 0 || patch > lim as i128 {
            return Err(value_error(format!(
                "`patch` must be odd, >= 3 and <= min(height, width) = {lim}, got {patch}"
            )));
        }
        let (d_min, d_max) = if align == "zncc" || (align == "ours" && epipolar) {
            let d_min = min_disparity.unwrap_or(-max_disparity);
            if d_min > max_disparity {
                return Err(value_error(format!(
                    "min_disparity = {d_min} > max_disparity = {max_disparity}: the disparity \
                     range is empty"
                )));
            }
            let m = d_min.abs().max(max_disparity.abs());
            if m >= w as i128 {
                return Err(value_error(format!(
                    "|disparity| up to {m} must be < the image width {w} (max_disparity / \
                     min_disparity too large)"
                )));
            }
            (d_min as i32, max_disparity as i32)
        } else {
            // 2-D search: the disparity range is not used.
            let d_max: i32 = bounded(py, "max_disparity", max_disparity, 0, 1 << 24)?;
            let d_min = match min_disparity {
                None => -d_max,
                Some(v) => bounded(py, "min_disparity", v, -(1 << 24), 1 << 24)?,
            };
            (d_min, d_max)
        };
        (patch as usize, d_min, d_max)
    };
    let n_iter: usize = bounded(py, "n_iter", n_iter, 0, 100_000)?;
    let coherence = flag_arg("coherence", coherence)?;
    let ordered = flag_arg("ordered", ordered)?;
    let weighted_cost = flag_arg("weighted_cost", weighted_cost)?;
    let fill_saturated = flag_arg("fill_saturated", fill_saturated)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let details = flag_arg("return_details", return_details)?;
    let imgs: Vec<Image<u16>> = codes.into_iter().map(|c| c.img).collect();
    let crfs = crfs_in(py, &crfs, &imgs, bits)?;
    let p = MultiscopicParams::default()
        .pm(PatchMatchParams::default()
            .patch(patch)
            .iters(n_iter)
            .d_min(d_min)
            .d_max(d_max)
            .coherence(coherence)
            .epipolar(epipolar)
            .weighted_cost(weighted_cost)
            .seed(seed))
        .align(Align::by_name(align).py_err()?)
        .synthesis(synthesis)
        .ordered(ordered)
        .fill_saturated(fill_saturated);
    let out = crate::pool::detach(py, || {
        wscg_hdr::multiscopic_hdr(&imgs, &times, &crfs, &p, &NoProgress)
    })
    .py_err()?;
    let fields = if details {
        let d = PyDict::new(py);
        for ((r, s), f) in out.nnfs {
            d.set_item((r, s), nnf_out(py, f)?.0)?;
        }
        Some(d)
    } else {
        None
    };
    let hdr = out
        .hdr
        .into_iter()
        .map(|im| crate::convert::image_array(py, im, flat))
        .collect::<PyResult<_>>()?;
    Ok((hdr, fields, out.fallback_pixels))
}

/// Merge aligned radiance samples into HDR (paper eq. 6), e.g. a reference view and
/// source views synthesised aligned to it by :func:`vote_bds`.
///
/// Parameters
/// ----------
/// radiances : list of float arrays (H, W) or (H, W, C)
///     Radiance ``E_n`` of every input, one shape.
/// weights : list of float arrays
///     Weight of every sample (:func:`khan_weight` of its code, or voted weights), ``>= 0``.
/// levels : list of float arrays
///     Normalised code ``Z / z_max`` of every sample in ``[0, 1]`` (which side a clipped
///     sample is on).
/// exposure_times : sequence of float
///     Exposure time of every input (seconds, > 0): orders the fallback.
///
/// Returns
/// -------
/// hdr : float32 array of the inputs' shape
///     ``E = sum_n w_n E_n / sum_n w_n`` per pixel and channel.
/// fallback_pixels : int
///     Pixels where some channel had total weight ``< 1e-6``; those take the radiance of
///     the shortest exposure (mean level >= 1/2: clipped high) or of the longest one.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, eqs. 6-7.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import hdr
/// >>> e = [np.full((1, 2), 4.0, np.float32), np.full((1, 2), 2.0, np.float32)]
/// >>> w = [np.full((1, 2), 1.0, np.float32), np.full((1, 2), 3.0, np.float32)]
/// >>> lv = [np.full((1, 2), 0.5, np.float32)] * 2
/// >>> out, n = hdr.merge(e, w, lv, [0.01, 0.02])
/// >>> float(out[0, 0]), n
/// (2.5, 0)
#[pyfunction]
fn merge<'py>(
    py: Python<'py>,
    radiances: Vec<Bound<'py, PyAny>>,
    weights: Vec<Bound<'py, PyAny>>,
    levels: Vec<Bound<'py, PyAny>>,
    exposure_times: Vec<f64>,
) -> PyResult<(Arr<'py, f32>, usize)> {
    let n = radiances.len();
    if n == 0 {
        return Err(value_error(
            "`radiances` must be a non-empty list of images",
        ));
    }
    for (name, xs) in [("weights", &weights), ("levels", &levels)] {
        if xs.len() != n {
            return Err(value_error(format!(
                "`{name}` must be a list of {n} images, one per radiance image"
            )));
        }
    }
    let mut samples = Vec::with_capacity(n);
    let mut flat = false;
    for (k, ((r, w), l)) in radiances.iter().zip(&weights).zip(&levels).enumerate() {
        let (radiance, f) = float_image("radiances", r)?;
        let (weight, _) = float_image("weights", w)?;
        let (level, _) = float_image("levels", l)?;
        if k == 0 {
            flat = f;
        }
        samples.push(wscg_hdr::ViewSamples {
            radiance,
            weight,
            level,
        });
    }
    let shape = samples[0].radiance.shape();
    for (k, s) in samples.iter().enumerate() {
        if s.radiance.shape() != shape || s.weight.shape() != shape || s.level.shape() != shape {
            return Err(value_error(format!(
                "input {k}: radiance, weight and level must all have shape {shape:?} (height, \
                 width, channels)"
            )));
        }
        if s.weight.data().iter().any(|&w| w < 0.0) {
            return Err(value_error(format!("`weights[{k}]` must be >= 0")));
        }
        if s.level.data().iter().any(|&l| !(0.0..=1.0).contains(&l)) {
            return Err(value_error(format!("`levels[{k}]` must be in [0, 1]")));
        }
    }
    wscg_hdr::radiance::check_times(&exposure_times, n).py_err_renamed(PM_NAMES)?;
    let inputs: Vec<wscg_hdr::MergeInput> = samples
        .iter()
        .zip(&exposure_times)
        .map(|(s, &t)| wscg_hdr::MergeInput {
            samples: s,
            time: t,
        })
        .collect();
    let m = crate::pool::detach(py, || wscg_hdr::merge(&inputs)).py_err()?;
    Ok((
        crate::convert::image_array(py, m.hdr, flat)?,
        m.fallback_pixels,
    ))
}

/// The checked arguments of `wscg.hdr.merge_stack` (its docstring and the files' EXIF times
/// are in python/wscg/hdr.py): images as arrays, `exposure_times` given or read from the
/// files, `bits` given or the files'.
#[pyfunction]
#[pyo3(signature = (images, exposure_times, crf, bits))]
fn merge_stack<'py>(
    py: Python<'py>,
    images: &Bound<'py, PyAny>,
    exposure_times: Option<&Bound<'py, PyAny>>,
    crf: &Bound<'py, PyAny>,
    bits: Option<i128>,
) -> PyResult<(Arr<'py, f32>, usize)> {
    let codes = codes_list_arg("images", images)?;
    let flat = codes[0].shape.len() == 2;
    let times = times_arg(exposure_times, codes.len())?;
    let crfs = crfs_arg(crf, codes.len())?;
    let bits = bits_arg(py, bits, &crfs, &codes)?;
    let imgs: Vec<Image<u16>> = codes.into_iter().map(|c| c.img).collect();
    let crfs = crfs_in(py, &crfs, &imgs, bits)?;
    let m = crate::pool::detach(py, || wscg_hdr::merge_stack(&imgs, &times, &crfs)).py_err()?;
    Ok((
        crate::convert::image_array(py, m.hdr, flat)?,
        m.fallback_pixels,
    ))
}

/// A view of codes in radiance space: ``E = f^-1(Z) / dt`` per pixel and channel (paper
/// section 3, numerator of eq. 6).
///
/// Parameters
/// ----------
/// image : array (H, W) or (H, W, C), uint8 or uint16
/// crf : str or array
///     ``"gamma2.2"``, ``"linear"`` or a table ``(levels, C)`` / ``(levels,)`` of ``f^-1``.
/// exposure_time : float
///     ``dt`` in seconds (> 0).
/// bits : int, optional
///     Bit depth of a named response: default 8 for uint8, otherwise the smallest depth
///     covering the largest code.
///
/// Returns
/// -------
/// float32 array of the image's shape.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3, eq. 6.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import hdr
/// >>> hdr.to_radiance(np.array([[0, 255]], np.uint8), "linear", 0.5).tolist()
/// [[0.0, 2.0]]
#[pyfunction]
#[pyo3(signature = (image, crf, exposure_time, *, bits=None))]
fn to_radiance<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    crf: &Bound<'py, PyAny>,
    exposure_time: f64,
    bits: Option<i128>,
) -> PyResult<Arr<'py, f32>> {
    let codes = [codes_arg("image", image)?];
    let crf = [crf_one("crf", crf)?];
    let bits = bits_arg(py, bits, &crf, &codes)?;
    let dt = args::positive("exposure_time", exposure_time)?;
    let [Codes { img, shape, .. }] = codes;
    let crf = crfs_in(py, &crf, std::slice::from_ref(&img), bits)?;
    let e = crate::pool::detach(py, || wscg_hdr::to_radiance(&img, &crf[0], dt)).py_err()?;
    crate::convert::image_array(py, e, shape.len() == 2)
}

/// Khan, Akyuz & Reinhard's weight of a code (paper eq. 7):
/// ``w(Z) = 1 - (2 Z / z_max - 1)^12``, clipped at 0.
///
/// Exactly 0 at ``Z = 0`` and ``Z = z_max`` (clipped samples do not leak into the merge),
/// 1 at ``z_max / 2`` and close to 1 over most of the range.
///
/// Parameters
/// ----------
/// z : float or array
///     Codes (finite).
/// z_max : float, default 255
///     Largest code (1023 for 10-bit data).
///
/// Returns
/// -------
/// float for a scalar ``z``, otherwise a float32 array of its shape.
///
/// References
/// ----------
/// E. A. Khan et al., ICIP 2006; Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23,
/// eq. 7.
///
/// Examples
/// --------
/// >>> from wscg import hdr
/// >>> hdr.khan_weight(0.0), hdr.khan_weight(127.5), hdr.khan_weight(255.0)
/// (0.0, 1.0, 0.0)
#[pyfunction]
#[pyo3(signature = (z, z_max=255.0))]
fn khan_weight<'py>(
    py: Python<'py>,
    z: &Bound<'py, PyAny>,
    z_max: f64,
) -> PyResult<Bound<'py, PyAny>> {
    if !(z_max.is_finite() && z_max > 0.0) {
        return Err(value_error(format!(
            "`z_max` must be finite and > 0, got {z_max}"
        )));
    }
    let z_max = z_max as f32;
    let (a, _) = real_array("z", z)?;
    let scalar = a.getattr("ndim")?.extract::<usize>()? == 0;
    let a = args::array::<f32>("z", &a)?;
    let shape = a.shape().to_vec();
    let v = values(&a);
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_error(
            "`z` contains a non-finite value (NaN or infinity)",
        ));
    }
    let out: Vec<f32> = crate::pool::detach(py, || {
        v.iter().map(|&x| wscg_hdr::khan_weight(x, z_max)).collect()
    })?;
    if scalar {
        return Ok(f64::from(out[0]).into_pyobject(py)?.into_any());
    }
    Ok(array(py, &shape, out)?.into_any())
}

/// The checked arguments of `wscg.hdr.calibrate_debevec` (docstring and files in
/// python/wscg/hdr.py).
#[pyfunction]
#[pyo3(signature = (stack, exposure_times, n_samples, lam, bits))]
fn calibrate_debevec<'py>(
    py: Python<'py>,
    stack: &Bound<'py, PyAny>,
    exposure_times: Option<&Bound<'py, PyAny>>,
    n_samples: i128,
    lam: f64,
    bits: Option<i128>,
) -> PyResult<Arr<'py, f32>> {
    // Above 10 bits the codes are reduced to 10 for the dense solve (`calibrate_debevec`).
    let (imgs, times, bits) = calibration_stack(py, stack, exposure_times, bits)?;
    let n_samples: usize = bounded(py, "n_samples", n_samples, 1, 1_000_000)?;
    let lam = args::positive("lam", lam)?;
    let crf = crate::pool::detach(py, || {
        wscg_hdr::calibrate_debevec(&imgs, &times, bits, n_samples, lam)
    })
    .py_err()?;
    array(py, &[crf.levels(), crf.channels()], crf.table().to_vec())
}

/// The checked arguments of `wscg.hdr.calibrate_mitsunaga_nayar` (docstring, files and
/// `PolynomialResponse` in python/wscg/hdr.py).
#[pyfunction]
#[pyo3(signature = (stack, exposure_times, bits, degree, max_degree, n_samples, refine_ratios,
                    tol, max_iter))]
#[allow(clippy::too_many_arguments)]
fn calibrate_mitsunaga_nayar<'py>(
    py: Python<'py>,
    stack: &Bound<'py, PyAny>,
    exposure_times: Option<&Bound<'py, PyAny>>,
    bits: Option<i128>,
    degree: Option<i128>,
    max_degree: i128,
    n_samples: i128,
    refine_ratios: &Bound<'py, PyAny>,
    tol: f64,
    max_iter: i128,
) -> PyResult<(Arr<'py, f32>, Bound<'py, PyDict>)> {
    let (imgs, times, bits) = calibration_stack(py, stack, exposure_times, bits)?;
    let degree: Option<usize> = match degree {
        None => None,
        Some(d) => Some(bounded(py, "degree", d, 1, 10)?),
    };
    let max_degree: usize = bounded(py, "max_degree", max_degree, 1, 10)?;
    let n_samples: usize = bounded(py, "n_samples", n_samples, 1, 10_000_000)?;
    let refine_ratios = flag_arg("refine_ratios", refine_ratios)?;
    let tol = args::positive("tol", tol)?;
    let max_iter: usize = bounded(py, "max_iter", max_iter, 1, 1_000_000)?;
    let p = wscg_hdr::MitsunagaNayarParams::default()
        .degree(degree)
        .max_degree(max_degree)
        .samples(n_samples)
        .refine_ratios(refine_ratios)
        .tol(tol)
        .max_iter(max_iter);
    let fit = crate::pool::detach(py, || {
        wscg_hdr::calibrate_mitsunaga_nayar(&imgs, &times, bits, &p)
    })
    .py_err()?;
    let info = PyDict::new(py);
    let ch = &fit.channels;
    info.set_item(
        "coefficients",
        ch.iter()
            .map(|c| c.coefficients.clone())
            .collect::<Vec<_>>(),
    )?;
    info.set_item(
        "ratios",
        ch.iter().map(|c| c.ratios.clone()).collect::<Vec<_>>(),
    )?;
    info.set_item(
        "degree",
        ch.iter()
            .map(|c| c.coefficients.len() - 1)
            .collect::<Vec<_>>(),
    )?;
    info.set_item("rms", ch.iter().map(|c| c.rms).collect::<Vec<_>>())?;
    info.set_item(
        "equations",
        ch.iter().map(|c| c.equations).collect::<Vec<_>>(),
    )?;
    info.set_item(
        "iterations",
        ch.iter().map(|c| c.iterations).collect::<Vec<_>>(),
    )?;
    let table = array(
        py,
        &[fit.crf.levels(), fit.crf.channels()],
        fit.crf.table().to_vec(),
    )?;
    Ok((table, info))
}

type Field<'py> = (Arr<'py, i32>, Arr<'py, f32>);

/// The two radiance images `a` and `b` of a matcher and their smaller height and width.
fn image_pair(
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<(Image<f32>, Image<f32>, usize, usize)> {
    let (ia, _) = float_image("a", a)?;
    let (ib, _) = float_image("b", b)?;
    let h = ia.height().min(ib.height());
    let w = ia.width().min(ib.width());
    Ok((ia, ib, h, w))
}

/// The paper's PatchMatch from image ``a`` to image ``b`` (section 3.1, eqs. 1-4).
///
/// Parameters
/// ----------
/// a, b : float arrays (H, W) or (H, W, C)
///     Radiance images (see :func:`to_radiance`) with the same number of channels; they may
///     differ in size.
/// patch : int, default 7
///     Patch side ``N`` (odd, >= 3, <= the smaller image side).
/// n_iter : int, default 2
///     Sweeps: even ones scan top-left to bottom-right and propagate from the left and top
///     neighbours, odd ones scan back. The rows of a sweep run on every thread of wscg's
///     pool (:func:`wscg.set_num_threads`) as a pipeline that gives exactly the
///     sequential scan's field, so the result depends on ``seed`` only, never on the
///     thread count.
/// min_disparity, max_disparity : int, default -64, 64
///     Range of the horizontal offset ``dx`` (epipolar mode); ``|d| < width``.
/// v_tol : int, default 0
///     Vertical tolerance ``|dy| <= v_tol`` (0: exact rectification).
/// coherence : bool, default True
///     Divide the patch distance by the coherence term (eq. 2); ``False``: SSD alone.
/// epipolar : bool, default True
///     Search on the epipolar line; ``False`` searches all of ``b`` in 2-D (the disparity
///     range and ``v_tol`` are then unused).
/// c_min : float, default 0.05
///     Lower bound of the coherence term ``C`` in ``(0, 1]`` (the paper leaves ``C <= 0``
///     undefined).
/// alpha : float, default 0.5
///     Ratio of the random-search radii (eq. 1), in ``(0, 1)``.
/// seed : int, default 0
///     Seed of the initialisation and the random search.
///
/// Returns
/// -------
/// offsets : int32 array (H, W, 2)
///     ``(dx, dy)`` per pixel of ``a``: pixel ``(x, y)`` matches ``(x + dx, y + dy)`` of
///     ``b``.
/// cost : float32 array (H, W)
///     The final cost ``D`` of each match (eq. 2; the SSD when ``coherence=False``).
///
/// Notes
/// -----
/// ``SSD(p, d)`` is the mean over the valid pixels and channels of the squared difference of
/// the ``N x N`` patches at ``p`` in ``a`` and ``p + d`` in ``b`` (eq. 3, a mean so border
/// patches compare fairly); ``C(p, d) = max(1 - d_c / Max_disp, c_min)`` (eq. 4),
/// ``Max_disp = max(|min_disparity|, |max_disparity|)`` and ``d_c`` the Euclidean distance
/// of ``d`` to the closest current offset of a 4-neighbour; ``D = SSD / C`` (eq. 2). The
/// offsets start uniformly random in the range on the same scanline; each pixel tries its
/// neighbours' offsets (propagation) and ``u_i = v_0 + w alpha^i R_i``, ``R_i ~ U[-1, 1]``,
/// ``w = Max_disp``, while ``w alpha^i >= 1`` (random search, eq. 1). The cost of the
/// current match is recomputed before each comparison because ``C`` depends on neighbours
/// that moved. The sequential scan's field, computed on every thread of wscg's pool, and
/// deterministic for a given ``seed``.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1, eqs. 1-4.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import hdr
/// >>> rng = np.random.default_rng(0)
/// >>> a = rng.random((32, 64)).astype(np.float32)
/// >>> b = np.roll(a, -5, axis=1)            # b(x - 5) = a(x): true offset -5
/// >>> off, cost = hdr.patchmatch(a, b, min_disparity=-10, max_disparity=10, n_iter=4)
/// >>> float(np.mean(off[4:-4, 8:-8, 0] == -5)) > 0.95
/// True
#[pyfunction]
#[pyo3(signature = (a, b, *, patch=7, n_iter=2, min_disparity=Some(-64), max_disparity=64,
                    v_tol=0, coherence=true, epipolar=true, c_min=0.05, alpha=0.5, seed=0),
       text_signature = "(a, b, *, patch=7, n_iter=2, min_disparity=-64, max_disparity=64, \
                         v_tol=0, coherence=True, epipolar=True, c_min=0.05, alpha=0.5, seed=0)")]
#[allow(clippy::too_many_arguments)]
fn patchmatch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    patch: i128,
    n_iter: i128,
    min_disparity: Option<i64>,
    max_disparity: i64,
    v_tol: i64,
    coherence: bool,
    epipolar: bool,
    c_min: f64,
    alpha: f64,
    seed: i128,
) -> PyResult<Field<'py>> {
    let (ia, ib, h, _) = image_pair(a, b)?;
    let patch: usize = uint(py, "patch", patch, 0)?;
    let n_iter: usize = bounded(py, "n_iter", n_iter, 0, 100_000)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let (d_min, d_max) = check_range(
        min_disparity.unwrap_or(max_disparity.saturating_neg()),
        max_disparity,
    )?;
    // Without the epipolar constraint the range and the tolerance are not used.
    let v_tol = if !epipolar {
        v_tol.clamp(0, 1 << 24) as i32
    } else if (0..h as i64).contains(&v_tol) {
        v_tol as i32
    } else {
        return Err(value_error(format!(
            "`v_tol` must be in 0..{}, got {v_tol}",
            h.saturating_sub(1)
        )));
    };
    let p = PatchMatchParams::default()
        .patch(patch)
        .iters(n_iter)
        .d_min(d_min)
        .d_max(d_max)
        .v_tol(v_tol)
        .alpha(number("alpha", alpha)? as f32)
        .epipolar(epipolar)
        .coherence(coherence)
        .c_min(number("c_min", c_min)? as f32)
        .seed(seed)
        .weighted_cost(false);
    let f =
        crate::pool::detach(py, || wscg_hdr::patchmatch(&ia, &ib, &p)).py_err_renamed(PM_NAMES)?;
    nnf_out(py, f)
}

/// The original PatchMatch of Barnes et al. (2009), the paper's "PM" baseline: 2-D
/// offsets anywhere in ``b``, SSD cost without the coherence term.
///
/// Parameters
/// ----------
/// a, b : float arrays (H, W) or (H, W, C)
///     Images with the same number of channels.
/// patch : int, default 7
///     Patch side (odd, >= 3).
/// n_iter : int, default 5
///     Sweeps (Barnes et al. suggest 4-5; the paper compares 2 and 5).
/// seed : int, default 0
///
/// Returns
/// -------
/// offsets : int32 array (H, W, 2)
///     ``(dx, dy)`` per pixel of ``a``.
/// cost : float32 array (H, W)
///     Mean squared patch difference of each match.
///
/// Notes
/// -----
/// Uniform random initialisation over ``b``, propagation as in :func:`patchmatch`, random
/// search from radius ``max(W, H)`` with ``alpha = 1/2`` and ``R_i ~ U[-1, 1]^2``.
///
/// References
/// ----------
/// Barnes et al., SIGGRAPH 2009; compared against in Ramirez Orozco et al., WSCG 2015,
/// Journal of WSCG vol. 23, Figs. 4, 6 and 7.
#[pyfunction]
#[pyo3(signature = (a, b, *, patch=7, n_iter=5, seed=0))]
fn patchmatch_2d<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    patch: i128,
    n_iter: i128,
    seed: i128,
) -> PyResult<Field<'py>> {
    let (ia, ib, _, _) = image_pair(a, b)?;
    let patch: usize = uint(py, "patch", patch, 0)?;
    let n_iter: usize = bounded(py, "n_iter", n_iter, 0, 100_000)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let f = crate::pool::detach(py, || {
        wscg_hdr::patchmatch_2d(&ia, &ib, patch, n_iter, seed)
    })
    .py_err_renamed(PM_NAMES)?;
    nnf_out(py, f)
}

/// The stereo-matching baseline (Batz et al. 2014 style, the paper's Fig. 1b).
///
/// Parameters
/// ----------
/// a, b : float arrays (H, W) or (H, W, C) of one shape
///     Radiance images; they are matched in grey (channel mean).
/// window : int, default 9
///     Correlation window side (odd, >= 3).
/// min_disparity, max_disparity : int, default -64, 64
///     Range of the horizontal offset: pixel ``x`` of ``a`` matches ``x + d`` of ``b``.
/// lr_tol : int, default 1
///     Left-right consistency tolerance ``|d_ab + d_ba| <= lr_tol``.
///
/// Returns
/// -------
/// offsets : int32 array (H, W, 2)
///     ``(d, 0)`` per pixel of ``a``.
/// cost : float32 array (H, W)
///     ``1 - ZNCC`` of the winner-take-all match (before the filling).
///
/// Notes
/// -----
/// Zero-mean normalised cross-correlation of the grey windows, winner-take-all over the
/// range in both directions; pixels failing the left-right check take the nearer valid
/// disparity of their row with the smaller ``|d|`` (the background side, where occlusions
/// are).
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, Fig. 1b; M. Batz et al.,
/// "High dynamic range video reconstruction from a stereo camera setup", Signal Processing:
/// Image Communication 29(2), 2014.
#[pyfunction]
#[pyo3(signature = (a, b, *, window=9, min_disparity=Some(-64), max_disparity=64, lr_tol=1),
       text_signature = "(a, b, *, window=9, min_disparity=-64, max_disparity=64, lr_tol=1)")]
fn zncc_stereo<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    window: i128,
    min_disparity: Option<i64>,
    max_disparity: i64,
    lr_tol: i128,
) -> PyResult<Field<'py>> {
    let (ia, ib, _, _) = image_pair(a, b)?;
    let window: usize = uint(py, "window", window, 0)?;
    let lr_tol: i32 = bounded(py, "lr_tol", lr_tol, 0, 1 << 24)?;
    let (d_min, d_max) = check_range(
        min_disparity.unwrap_or(max_disparity.saturating_neg()),
        max_disparity,
    )?;
    let p = StereoParams::default()
        .window(window)
        .d_min(d_min)
        .d_max(d_max)
        .lr_tol(lr_tol);
    let f =
        crate::pool::detach(py, || wscg_hdr::zncc_stereo(&ia, &ib, &p)).py_err_renamed(PM_NAMES)?;
    nnf_out(py, f)
}

/// Synthesise the source view ``src`` aligned to a reference view by bidirectional-
/// similarity patch voting (paper section 3.2, eq. 5; Simakov et al. 2008).
///
/// Parameters
/// ----------
/// src : float array (Hs, Ws) or (Hs, Ws, C)
///     The source view ``s`` (radiance, or any per-pixel quantity to carry over).
/// offsets_rs : int array (Hr, Wr, 2)
///     Field from the reference ``r`` to the source (on the reference grid).
/// offsets_sr : int array (Hs, Ws, 2)
///     Field from the source to the reference (on the source grid).
/// patch : int, default 7
///     Patch side ``N`` of the votes (the one the fields were computed with).
///
/// Returns
/// -------
/// float32 array (Hr, Wr) or (Hr, Wr, C)
///     ``T_{r<-s}``, aligned to the reference with the values of the source.
///
/// Notes
/// -----
/// Per reference pixel ``p``:
/// ``T(p) = [ (1/N_r) sum_{q: p in Q(q)} S(q + off_rs(q) + p - q)
/// + (1/N_s) sum_{t: p in Q(t + off_sr(t))} S(t + p - (t + off_sr(t))) ]
/// / [ n_1(p) / N_r + n_2(p) / N_s ]``, ``Q(q)`` the ``N x N`` window at ``q``,
/// ``n_1, n_2`` the vote counts and ``N_r, N_s`` the patch counts of the two views. The
/// first term fetches every reference patch from the source, the second pushes every
/// source patch to where it matches, so there are no holes; occluded areas get the colours
/// of their best matches ("accurate in colour, not geometry"). Votes from outside ``src``
/// are skipped. The result does not depend on the thread count.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3.2, eq. 5.
#[pyfunction]
#[pyo3(signature = (src, offsets_rs, offsets_sr, *, patch=7))]
fn vote_bds<'py>(
    py: Python<'py>,
    src: &Bound<'py, PyAny>,
    offsets_rs: &Bound<'py, PyAny>,
    offsets_sr: &Bound<'py, PyAny>,
    patch: i128,
) -> PyResult<Arr<'py, f32>> {
    let (img, flat) = float_image("src", src)?;
    let rs = offsets("offsets_rs", offsets_rs)?;
    let sr = offsets("offsets_sr", offsets_sr)?;
    if (sr.height(), sr.width()) != (img.height(), img.width()) {
        return Err(value_error(format!(
            "`offsets_sr` is on a {} x {} grid but `src` is {} x {}: it must be the source's \
             field",
            sr.height(),
            sr.width(),
            img.height(),
            img.width()
        )));
    }
    let patch: usize = uint(py, "patch", patch, 0)?;
    let out = crate::pool::detach(py, || wscg_hdr::vote_bds(&img, &rs, &sr, patch)).py_err()?;
    crate::convert::image_array(py, out, flat)
}

/// Direct warp of ``src`` through the reference-to-source field (the paper's Fig. 5a
/// ablation): ``T(p) = src(p + off_rs(p))``, clamped into ``src``.
///
/// Parameters
/// ----------
/// src : float array (Hs, Ws) or (Hs, Ws, C)
/// offsets_rs : int array (Hr, Wr, 2)
///
/// Returns
/// -------
/// float32 array (Hr, Wr) or (Hr, Wr, C)
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3.2, Fig. 5a.
#[pyfunction]
fn warp_direct<'py>(
    py: Python<'py>,
    src: &Bound<'py, PyAny>,
    offsets_rs: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f32>> {
    let (img, flat) = float_image("src", src)?;
    let rs = offsets("offsets_rs", offsets_rs)?;
    let out = crate::pool::detach(py, || wscg_hdr::warp_direct(&img, &rs)).py_err()?;
    crate::convert::image_array(py, out, flat)
}

/// The keys of a `make_scene` layer.
const LAYER_KEYS: [&str; 5] = ["disparity", "rect", "disk", "gain", "seed"];

/// `make_scene`'s `layers`: a non-empty sequence of dicts with the keys of [`LAYER_KEYS`]
/// (`disparity` required; `rect` `(y0, y1, x0, x1)` in `[0, 1]`, default the whole image;
/// `disk` a bool; `gain` > 0, default 1; `seed`, default `11 + 12 k` for layer `k`).
fn layers_arg(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Layer>> {
    let sequence = obj.py().import("collections.abc")?.getattr("Sequence")?;
    if obj.is_instance_of::<PyString>() || !obj.is_instance(&sequence)? {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "`layers` must be a sequence of dicts, got {}",
            args::type_name(obj)
        )));
    }
    let items = obj.try_iter()?.collect::<PyResult<Vec<_>>>()?;
    if items.is_empty() {
        return Err(value_error("`layers` needs at least one layer"));
    }
    items
        .iter()
        .enumerate()
        .map(|(k, item)| {
            let name = format!("layers[{k}]");
            let layer = item.cast::<PyDict>().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "`{name}` must be a dict, got {}",
                    args::type_name(item)
                ))
            })?;
            let mut unknown = layer
                .keys()
                .iter()
                .map(|key| key.str().map(|s| s.to_string()))
                .collect::<PyResult<Vec<_>>>()?;
            unknown.retain(|key| !LAYER_KEYS.contains(&key.as_str()));
            if !unknown.is_empty() {
                unknown.sort();
                return Err(value_error(format!(
                    "`{name}` has unknown keys {unknown:?}; use {LAYER_KEYS:?}"
                )));
            }
            let real = |key: &str| -> PyResult<Option<f64>> {
                let label = format!("{name}['{key}']");
                layer
                    .get_item(key)?
                    .map(|v| {
                        let v: f64 = v.extract().map_err(|_| {
                            value_error(format!("`{label}` must be a real number, got {v}"))
                        })?;
                        args::finite(&label, v)
                    })
                    .transpose()
            };
            let disparity = real("disparity")?
                .ok_or_else(|| value_error(format!("`{name}` needs a 'disparity'")))?;
            let rect = match layer.get_item("rect")? {
                None => [0.0, 1.0, 0.0, 1.0],
                Some(r) => args::numbers::<4>(&format!("{name}['rect']"), &r)
                    .ok()
                    .filter(|&[y0, y1, x0, x1]| {
                        0.0 <= y0 && y0 < y1 && y1 <= 1.0 && 0.0 <= x0 && x0 < x1 && x1 <= 1.0
                    })
                    .ok_or_else(|| {
                        value_error(format!(
                            "`{name}['rect']` must be (y0, y1, x0, x1) with 0 <= y0 < y1 <= 1 \
                             and 0 <= x0 < x1 <= 1, got {r}"
                        ))
                    })?,
            };
            let gain = args::positive(&format!("{name}['gain']"), real("gain")?.unwrap_or(1.0))?;
            let disk = match layer.get_item("disk")? {
                None => false,
                Some(v) => flag_arg(&format!("{name}['disk']"), &v)?,
            };
            let seed = match layer.get_item("seed")? {
                None => 11 + 12 * k as u64,
                Some(v) => {
                    let label = format!("{name}['seed']");
                    uint(py, &label, args::integer(&label, &v)?, 0u64)?
                }
            };
            Ok(Layer::new(disparity, rect, seed).disk(disk).gain(gain))
        })
        .collect()
}

#[pyfunction]
#[pyo3(signature = (height, width, times, emitter_peak, noise, seed, layers=None))]
#[allow(clippy::too_many_arguments)]
fn make_scene<'py>(
    py: Python<'py>,
    height: i128,
    width: i128,
    times: &Bound<'py, PyAny>,
    emitter_peak: f64,
    noise: f64,
    seed: i128,
    layers: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    const MAX_PIXELS: usize = 1 << 26;
    let height: usize = uint(py, "height", height, 8)?;
    let width: usize = uint(py, "width", width, 8)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    if !(emitter_peak.is_finite() && emitter_peak >= 1.0) {
        return Err(value_error(format!(
            "`emitter_peak` must be finite and >= 1, got {emitter_peak}"
        )));
    }
    args::non_negative("noise", noise)?;
    let layers = layers
        .filter(|l| !l.is_none())
        .map(|l| layers_arg(py, l))
        .transpose()?;
    let times = positive_times(&args::array::<f64>("exposure_times", times)?)?;
    if !(2..=32).contains(&times.len()) {
        return Err(value_error(format!(
            "`exposure_times` must give 2 to 32 cameras, got {}",
            times.len()
        )));
    }
    if height.saturating_mul(width) > MAX_PIXELS {
        return Err(value_error(format!(
            "a {height} x {width} scene is too large (at most 2^26 pixels per view)"
        )));
    }
    let mut cfg = SceneParams::default()
        .height(height)
        .width(width)
        .times(times)
        .emitter_peak(emitter_peak)
        .noise(noise);
    if let Some(layers) = layers {
        cfg.layers = layers;
    }
    let sc = crate::pool::detach(py, || layered_scene(&cfg, seed)).py_err()?;
    let d = PyDict::new(py);
    let views = sc
        .views
        .iter()
        .map(|v| {
            let (h, w, c) = v.shape();
            // 8-bit scene: every code fits a byte.
            let b = v.data().iter().map(|&z| z.min(255) as u8).collect();
            array(py, &[h, w, c], b)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("views", views)?;
    d.set_item("exposure_times", sc.times.clone())?;
    d.set_item(
        "crf",
        array(
            py,
            &[sc.crf.levels(), sc.crf.channels()],
            sc.crf.table().to_vec(),
        )?,
    )?;
    let radiance = sc
        .radiance
        .into_iter()
        .map(|e| crate::convert::image_array(py, e, false))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("radiance", radiance)?;
    let disparity = sc
        .disparity
        .into_iter()
        .map(|e| crate::convert::image_array(py, e, true))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("disparity", disparity)?;
    let seen = sc
        .seen_by
        .into_iter()
        .map(|s| array(py, &[height, width], s))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("seen_by", seen)?;
    Ok(d)
}

/// Log-radiance error ``sqrt(mean((log2 est - log2 gt)^2))`` against ground truth.
///
/// Parameters
/// ----------
/// est, gt : float arrays (H, W) or (H, W, C) of one shape
///     Estimated and true radiance; ``gt`` must be > 0 where evaluated. Non-positive
///     estimates count as the smallest positive float32.
/// mask : bool array, optional
///     Pixel-channels to evaluate: the shape of ``est``, or ``(H, W)`` (applied to every
///     channel). Default: all.
///
/// Returns
/// -------
/// float
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23 (the paper reports figures
/// only; this quantitative measure is ours, an error in stops that weighs dark and bright
/// regions alike).
#[pyfunction]
#[pyo3(signature = (est, gt, mask=None))]
fn rmse_log2(
    py: Python<'_>,
    est: &Bound<'_, PyAny>,
    gt: &Bound<'_, PyAny>,
    mask: Option<&Bound<'_, PyAny>>,
) -> PyResult<f64> {
    let (e, flat) = float_image("est", est)?;
    let (g, _) = float_image("gt", gt)?;
    let (h, w, c) = e.shape();
    let shape = if flat { vec![h, w] } else { vec![h, w, c] };
    if e.shape() != g.shape() {
        return Err(value_error(format!(
            "`est` has shape {shape:?} but `gt` has {:?} (height, width, channels)",
            g.shape()
        )));
    }
    let m = match mask {
        None => None,
        Some(m) => {
            let (ms, mv) = bool_mask("mask", m)?;
            if ms == shape {
                Some(mv)
            } else if !flat && ms == [h, w] {
                // One flag per pixel, for every channel.
                Some(mv.iter().flat_map(|&b| std::iter::repeat_n(b, c)).collect())
            } else {
                return Err(value_error(format!(
                    "`mask` has shape {ms:?}; expected {shape:?} or {:?}",
                    [h, w]
                )));
            }
        }
    };
    crate::pool::detach(py, || metrics::rmse_log2(&e, &g, m.as_deref())).py_err()
}

/// Fraction of pixels whose horizontal offset differs from the truth by more than ``k``
/// pixels (the bad-k rate of stereo benchmarks; a nonzero ``dy`` counts as bad).
///
/// Parameters
/// ----------
/// offsets : int array (H, W, 2)
///     A field ``(dx, dy)``, e.g. from :func:`patchmatch`.
/// truth : float array (H, W)
///     True horizontal offset; NaN or infinity marks unknown pixels (not counted).
/// k : float, default 2.0
///     Tolerance in pixels (>= 0).
/// mask : bool array (H, W), optional
///     Pixels to rate (default: all with a known truth).
///
/// Returns
/// -------
/// float in ``[0, 1]``.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1 (matching
/// accuracy, Figs. 4, 6, 7).
#[pyfunction]
#[pyo3(signature = (offsets, truth, k=2.0, mask=None))]
fn bad_rate(
    py: Python<'_>,
    offsets: &Bound<'_, PyAny>,
    truth: &Bound<'_, PyAny>,
    k: f64,
    mask: Option<&Bound<'_, PyAny>>,
) -> PyResult<f64> {
    let f = self::offsets("offsets", offsets)?;
    let hw = [f.height(), f.width()];
    let (t, _) = real_array("truth", truth)?;
    let t = args::array::<f32>("truth", &t)?;
    if t.shape() != hw {
        return Err(value_error(format!(
            "`truth` has shape {:?}, expected the field's (H, W) = {hw:?}",
            t.shape()
        )));
    }
    let m = match mask {
        None => None,
        Some(m) => {
            let (ms, mv) = bool_mask("mask", m)?;
            if ms != hw {
                return Err(value_error(format!(
                    "`mask` must be a boolean (H, W) = {hw:?} array, got shape {ms:?}"
                )));
            }
            Some(mv)
        }
    };
    if !(k.is_finite() && k >= 0.0) {
        return Err(value_error(format!("`k` must be finite and >= 0, got {k}")));
    }
    let t = values(&t);
    crate::pool::detach(py, || metrics::bad_rate(&f, &t, k as f32, m.as_deref())).py_err()
}

/// Incoherence of a field: the fraction of pixels whose offset differs from the median of
/// their ``3 x 3`` neighbourhood (per component, clipped at the borders) by more than 1 px.
///
/// The coherence term of eq. 4 exists to lower it (the paper's "more homogeneous" fields,
/// Figs. 4 and 6).
///
/// Parameters
/// ----------
/// offsets : int array (H, W, 2)
///
/// Returns
/// -------
/// float in ``[0, 1]``.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, eq. 4, Figs. 4 and 6.
#[pyfunction]
fn incoherence(py: Python<'_>, offsets: &Bound<'_, PyAny>) -> PyResult<f64> {
    let f = self::offsets("offsets", offsets)?;
    crate::pool::detach(py, || metrics::incoherence(&f))
}

/// Reads a camera response ``f^-1(Z)`` written by :func:`save_crf` or ``wscg hdr
/// calibrate``.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     CSV, one row per code ``Z = 0 ... z_max``, one column per channel, ``#`` comments.
///
/// Returns
/// -------
/// ndarray (levels, C), float32
///     The response, usable as ``crf`` everywhere.
///
/// Raises
/// ------
/// OSError
///     Naming the file (and the line) for a missing or malformed table (a bad number, rows
///     of different lengths, a decreasing or negative response, fewer than 2 or more than
///     65536 rows).
/// ValueError
///     A file above 16 MiB.
///
/// References
/// ----------
/// Debevec and Malik, SIGGRAPH 1997 (the response ``g = ln f^-1``); Ramirez Orozco et al.,
/// WSCG 2015, Journal of WSCG vol. 23, section 3.2 (the CRF ``f`` of the radiance merge).
#[pyfunction]
fn load_crf<'py>(py: Python<'py>, path: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f32>> {
    let path = args::path("path", path)?;
    let crf = crate::pool::detach(py, || Crf::read_csv(&path)).py_err()?;
    array(
        py,
        &[crf.z_max() as usize + 1, crf.channels()],
        crf.table().to_vec(),
    )
}

/// Writes a response table as CSV, atomically; :func:`load_crf` reads it back.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file to write (replaced atomically; a failed write raises ``OSError`` and
///     leaves any previous file).
/// crf : array_like (levels,) or (levels, C)
///     The response, checked as ``crf`` arguments are.
///
/// Returns
/// -------
/// None
///
/// References
/// ----------
/// Debevec and Malik, SIGGRAPH 1997; Ramirez Orozco et al., WSCG 2015, section 3.2.
#[pyfunction]
fn save_crf(py: Python<'_>, path: &Bound<'_, PyAny>, crf: &Bound<'_, PyAny>) -> PyResult<()> {
    let path = args::path("path", path)?;
    let crf = crf_in(&CrfArg::Table(args::array::<f32>("crf", crf)?), 8)?;
    crate::pool::detach(py, || crf.write_csv(&path)).py_err()
}

/// Reads exposure times in seconds.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     A ``.json`` file holding a list, or an object with ``exposure_times`` (or
///     ``times``); any other file is text, numbers separated by commas or line ends, ``#``
///     comments.
///
/// Returns
/// -------
/// list of float
///     One time per exposure, seconds.
///
/// Raises
/// ------
/// OSError
///     Naming the file (and the line) for a missing or malformed file or a time that is
///     not ``> 0``.
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, section 3.2 (the exposure times of the radiance merge).
#[pyfunction]
fn load_exposure_times(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let path = args::path("path", path)?;
    crate::pool::detach(py, || wscg_hdr::read_exposure_times(&path)).py_err()
}

/// Writes exposure times as text, one a line, atomically; :func:`load_exposure_times`
/// reads them back.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file to write (a failed write raises ``OSError`` and leaves any previous file).
/// times : sequence of float
///     Exposure times, seconds.
///
/// Returns
/// -------
/// None
///
/// References
/// ----------
/// Ramirez Orozco et al., WSCG 2015, section 3.2.
#[pyfunction]
fn save_exposure_times(py: Python<'_>, path: &Bound<'_, PyAny>, times: Vec<f64>) -> PyResult<()> {
    let path = args::path("path", path)?;
    crate::pool::detach(py, || wscg_hdr::write_exposure_times(&path, &times)).py_err()
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_crf, m)?)?;
    m.add_function(wrap_pyfunction!(save_crf, m)?)?;
    m.add_function(wrap_pyfunction!(load_exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(save_exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(multiscopic_hdr, m)?)?;
    m.add_function(wrap_pyfunction!(merge_stack, m)?)?;
    m.add_function(wrap_pyfunction!(load_codes, m)?)?;
    m.add_function(wrap_pyfunction!(exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(to_radiance, m)?)?;
    m.add_function(wrap_pyfunction!(khan_weight, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_debevec, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_mitsunaga_nayar, m)?)?;
    m.add_function(wrap_pyfunction!(patchmatch, m)?)?;
    m.add_function(wrap_pyfunction!(patchmatch_2d, m)?)?;
    m.add_function(wrap_pyfunction!(zncc_stereo, m)?)?;
    m.add_function(wrap_pyfunction!(vote_bds, m)?)?;
    m.add_function(wrap_pyfunction!(warp_direct, m)?)?;
    m.add_function(wrap_pyfunction!(make_scene, m)?)?;
    m.add_function(wrap_pyfunction!(rmse_log2, m)?)?;
    m.add_function(wrap_pyfunction!(bad_rate, m)?)?;
    m.add_function(wrap_pyfunction!(incoherence, m)?)?;
    Ok(())
}
