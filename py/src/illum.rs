//! `wscg._native.volren`, paper 15: bindings of `wscg_volren::illumination` (slice-based
//! volume rendering with instant convolution shadows, its supersampled and pre-integrated
//! variants and the ray-casting baselines) and of `wscg_volren::vti` (VTK XML image data).
//!
//! The documented API is `python/wscg/volren.py`, which re-exports the functions that take
//! no camera (`preintegration_table`, `make_marschner_lobb`, the transfer functions,
//! `labels_to_density`, `load_vti`, `mean_abs_diff`) as they are. The renders get
//! C-contiguous volumes (uint8, uint16 or float32, indexed `[z, y, x]`) and the camera,
//! light and method of a render as a dict (keys: [`RENDER_KEYS`]; those of a study:
//! [`STUDY_KEYS`]); transfer functions and images are any real array-likes, converted by
//! [`crate::args`]. Every function validates its input again, so a direct call cannot panic
//! on bad arguments; the GIL is released while Rust works.
//!
//! Coordinates follow `py/API.md`: `spacing` is `(dz, dy, dx)`, an image `size` is `(height,
//! width)`, and the world point of voxel `[k, j, i]` is `(i dx, j dy, k dz)` in the units of
//! the spacing, in which every length (slice distance, pixel size, spread, depth) is
//! measured and every transfer-function opacity refers to one unit of length.
//! `wscg_volren::illumination` measures in voxels of the finest axis instead (voxel `(i, j,
//! k)` at `(i dx, j dy, k dz) / u`, `u = min(spacing)`): points and lengths are divided by
//! `u` on the way in ([`Units`]) and multiplied on the way out, and opacities are corrected
//! to the length `u`.

use numpy::{PyArrayDescrMethods, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use wscg_math::{Error, Image, Volume, VolumeView};
use wscg_volren::illumination::study::{self, AliasCriterion};
use wscg_volren::illumination::{
    light_buffer_at, render as render_field, scenes, IlluminationParams, Interp, Kernel, Light,
    LightAtten, LightBorder, Method, Phong, PreIntegrationTable, ScalarField, SliceCamera,
    TransferFunction, MAX_SUBSAMPLES,
};
use wscg_volren::vti::{self, VtiValues};

use crate::args::{self, finite, non_negative, uint};
use crate::cfg::{choice_item, dict_item};
use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy};

/// Keys of the options dict of `illum_render` and `illum_light_buffer`.
pub const RENDER_KEYS: [&str; 17] = [
    "view_dir",
    "up",
    "size",
    "pixel_size",
    "center",
    "method",
    "slice_distance",
    "n_subsamples",
    "kernel",
    "spread",
    "tan_half",
    "light_dir",
    "ambient",
    "background",
    "interp",
    "light_attenuation",
    "border",
];

/// Keys of the options dict of `illum_study`.
pub const STUDY_KEYS: [&str; 13] = [
    "n_views",
    "size",
    "azimuth",
    "elevation",
    "distances",
    "max_subsamples",
    "reference",
    "fine",
    "spread",
    "light_dir",
    "ambient",
    "max_mad",
    "max_energy_ratio",
];

/// Largest Marschner-Lobb grid side (`n^3` floats).
const MAX_ML_SIDE: usize = 1024;

/// Errors unless `opts` holds only keys of `allowed` (catches typos in direct calls).
fn check_keys(opts: &Bound<'_, PyDict>, allowed: &[&str]) -> PyResult<()> {
    for k in opts.keys() {
        let k: String = k.extract()?;
        if !allowed.contains(&k.as_str()) {
            return Err(value_error(format!(
                "unknown option {k:?}; expected one of {allowed:?}"
            )));
        }
    }
    Ok(())
}

/// Errors unless `v` is finite and `> 0`, also as `f32` (the renderer's precision).
fn positive(name: &str, v: f64) -> PyResult<f64> {
    let v = args::positive(name, v)?;
    if (v as f32) > 0.0 {
        Ok(v)
    } else {
        Err(value_error(format!(
            "`{name}` must be finite and > 0, got {v}"
        )))
    }
}

/// An integer in `lo..=hi`.
fn int_in(name: &str, v: i64, lo: i64, hi: i64) -> PyResult<i64> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(value_error(format!(
            "`{name}` must be in {lo}..={hi}, got {v}"
        )))
    }
}

/// The binding's units (see the module documentation): `u = min(spacing)` of the units of
/// the spacing per world unit of `wscg_volren::illumination`.
#[derive(Clone, Copy, Debug)]
struct Units(f64);

impl Units {
    fn of(field: &ScalarField) -> Self {
        Units(field.spacing().into_iter().fold(f64::INFINITY, f64::min))
    }

    /// A length or point coordinate `name = v` of the API in the renderer's world units;
    /// an error when it does not fit a finite `f32` there (an extreme spacing).
    fn length_in(self, name: &str, v: f64) -> PyResult<f64> {
        let r = v / self.0;
        if (r as f32).is_finite() {
            Ok(r)
        } else {
            Err(value_error(format!(
                "`{name}` = {v:?} is out of range for a spacing whose smallest step is {:?}",
                self.0
            )))
        }
    }

    /// A length of the renderer in the API's units.
    fn length_out(self, v: f64) -> f64 {
        v * self.0
    }

    /// A transfer function whose opacities refer to one unit of the spacing's length as one
    /// whose opacities refer to `u` of them: `a' = 1 - (1 - a)^u` (extinction times `u`).
    fn tf_in(self, tf: TransferFunction) -> PyResult<TransferFunction> {
        if self.0 == 1.0 {
            return Ok(tf);
        }
        let lut: Vec<[f32; 4]> = tf
            .entries()
            .iter()
            .map(|&[r, g, b, a]| {
                let a = 1.0 - (1.0 - f64::from(a)).powf(self.0);
                [r, g, b, a.clamp(0.0, 1.0) as f32]
            })
            .collect();
        TransferFunction::from_lut(&lut).py_err()
    }
}

/// A `ScalarField` constructor from integer data (`from_u8`, `from_u16`).
type FieldOf<T> = fn(VolumeView<'_, T>) -> wscg_math::Result<ScalarField>;

/// `[nx, ny, nz]` of a `[z, y, x]` array.
fn dims3(name: &str, shape: &[usize]) -> PyResult<[usize; 3]> {
    match *shape {
        [nz, ny, nx] => Ok([nx, ny, nz]),
        ref s => Err(value_error(format!(
            "`{name}` must be a 3-D array indexed [z, y, x], got shape {s:?}"
        ))),
    }
}

/// The normalised field of a uint8, uint16 or float32 `[z, y, x]` volume: integers map to
/// `v / 255` or `v / 65535` and floats from their min/max, unless `value_range` maps `[lo, hi]`
/// (any dtype) onto `[0, 1]`. A constant float volume without a range keeps its value
/// clamped to `[0, 1]`.
fn field_in(
    py: Python<'_>,
    volume: &Bound<'_, PyAny>,
    spacing: [f64; 3],
    value_range: Option<(f64, f64)>,
) -> PyResult<ScalarField> {
    // A non-native byte order (big-endian data from some file readers) is converted first.
    let native;
    let volume = match volume.cast::<numpy::PyUntypedArray>() {
        Ok(a) if a.dtype().is_native_byteorder() == Some(false) => {
            let dtype = a.dtype().call_method1("newbyteorder", ("=",))?;
            native = volume.call_method1("astype", (dtype,))?;
            &native
        }
        _ => volume,
    };
    let range = value_range.map(|(lo, hi)| (lo as f32, hi as f32));
    let ranged = |dims, data: &[f32], lo, hi| {
        crate::pool::detach(py, || {
            ScalarField::from_f32_range(VolumeView::new(dims, spacing, data)?, lo, hi)
        })
        .py_err()
    };
    // Integer volumes: the type's own normalisation, or the range.
    fn integers<T: numpy::Element + Copy + Into<f32>>(
        py: Python<'_>,
        volume: &Bound<'_, PyAny>,
        spacing: [f64; 3],
        range: Option<(f32, f32)>,
        own: FieldOf<T>,
    ) -> Option<PyResult<ScalarField>> {
        let a = volume.extract::<PyReadonlyArrayDyn<T>>().ok()?;
        Some((|| {
            let dims = dims3("volume", a.shape())?;
            let v = values(&a);
            match range {
                None => {
                    crate::pool::detach(py, || own(VolumeView::new(dims, spacing, &v)?)).py_err()
                }
                Some((lo, hi)) => {
                    let f: Vec<f32> = v.iter().map(|&x| x.into()).collect();
                    crate::pool::detach(py, || {
                        ScalarField::from_f32_range(VolumeView::new(dims, spacing, &f)?, lo, hi)
                    })
                    .py_err()
                }
            }
        })())
    }
    if let Some(r) = integers::<u8>(py, volume, spacing, range, ScalarField::from_u8) {
        return r;
    }
    if let Some(r) = integers::<u16>(py, volume, spacing, range, ScalarField::from_u16) {
        return r;
    }
    if let Ok(a) = volume.extract::<PyReadonlyArrayDyn<f32>>() {
        let dims = dims3("volume", a.shape())?;
        let v = values(&a);
        if !crate::pool::detach(py, || v.par_iter().all(|x| x.is_finite()))? {
            let i = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(value_error(format!(
                "`volume` contains a non-finite value (NaN or infinity) at flat index {i}"
            )));
        }
        let (lo, hi) = match range {
            Some(r) => r,
            // Finite values: plain comparisons.
            None => crate::pool::detach(py, || {
                let id = || (f32::INFINITY, f32::NEG_INFINITY);
                let join = |(a, b): (f32, f32), (c, d): (f32, f32)| {
                    (if c < a { c } else { a }, if d > b { d } else { b })
                };
                v.par_iter()
                    .fold(id, |acc, &x| join(acc, (x, x)))
                    .reduce(id, join)
            })?,
        };
        if range.is_none() && lo >= hi {
            // Constant (or empty) volume: no range to normalise by.
            let data = v.iter().map(|x| x.clamp(0.0, 1.0)).collect();
            return crate::pool::detach(py, || {
                ScalarField::from_f32(Volume::new(dims, spacing, data)?)
            })
            .py_err();
        }
        return ranged(dims, &v, lo, hi);
    }
    let dtype = volume
        .getattr("dtype")
        .map(|d| d.to_string())
        .unwrap_or_else(|_| volume.get_type().to_string());
    Err(value_error(format!(
        "`volume` must be a uint8, uint16 or float32 numpy array indexed [z, y, x], got {dtype}"
    )))
}

/// A volume normalised once, keeping its empty-space cells and shading bricks between
/// renders (see `wscg.volren.PreparedVolume`).
#[pyclass(module = "wscg._native.volren", name = "IllumVolume", frozen)]
pub struct IllumVolume {
    field: ScalarField,
}

#[pymethods]
impl IllumVolume {
    #[new]
    #[pyo3(signature = (volume, spacing, value_range))]
    fn new(
        py: Python<'_>,
        volume: &Bound<'_, PyAny>,
        spacing: &Bound<'_, PyAny>,
        value_range: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (spacing, value_range) = source_args(Some(spacing), value_range)?;
        let spacing = spacing.unwrap_or([1.0; 3]);
        Ok(Self {
            field: field_in(py, volume, args::xyz(spacing), value_range)?,
        })
    }

    /// `(nz, ny, nx)`.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        let [nx, ny, nz] = self.field.dims();
        (nz, ny, nx)
    }

    /// `(dz, dy, dx)`.
    #[getter]
    fn spacing(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.field.spacing();
        (z, y, x)
    }

    /// Pickles as the normalised field `[z, y, x]` (float32 in `[0, 1]`) and the spacing; the
    /// empty-space cells and shading bricks are rebuilt on first use.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Arr<'py, f32>, (f64, f64, f64)))> {
        let (nz, ny, nx) = self.shape();
        let data = array(py, &[nz, ny, nx], self.field.data().to_vec())?;
        let restore = py
            .import("wscg._native.volren")?
            .getattr("_illum_from_normalised")?;
        Ok((restore, (data, self.spacing())))
    }
}

/// A prepared volume from the normalised field and spacing that `IllumVolume.__reduce__`
/// pickles.
#[pyfunction]
fn _illum_from_normalised(
    py: Python<'_>,
    field: PyReadonlyArrayDyn<'_, f32>,
    spacing: [f64; 3],
) -> PyResult<IllumVolume> {
    let [nz, ny, nx] = dims3("field", field.shape())?;
    let data = values(&field).into_owned();
    let field = crate::pool::detach(py, || {
        ScalarField::from_f32(Volume::new([nx, ny, nz], args::xyz(spacing), data)?)
    })
    .py_err()?;
    Ok(IllumVolume { field })
}

/// The field of a render's `volume` argument: a prepared volume as it is, an array normalised
/// for this call (`spacing` default `(1, 1, 1)`).
enum FieldArg<'py> {
    Owned(ScalarField),
    Prepared(PyRef<'py, IllumVolume>),
}

impl std::ops::Deref for FieldArg<'_> {
    type Target = ScalarField;
    fn deref(&self) -> &ScalarField {
        match self {
            FieldArg::Owned(f) => f,
            FieldArg::Prepared(v) => &v.field,
        }
    }
}

/// A volume's spacing `(dz, dy, dx)` and value range `(lo, hi)`, each optional.
type Source = (Option<[f64; 3]>, Option<(f64, f64)>);

/// The `spacing` `(dz, dy, dx)` and `value_range` `(lo, hi)` arguments (array-likes, `None`
/// when absent).
fn source_args(
    spacing: Option<&Bound<'_, PyAny>>,
    value_range: Option<&Bound<'_, PyAny>>,
) -> PyResult<Source> {
    Ok((
        spacing
            .filter(|s| !s.is_none())
            .map(|s| args::triple("spacing", s))
            .transpose()?,
        value_range
            .filter(|r| !r.is_none())
            .map(|r| args::pair("value_range", r))
            .transpose()?,
    ))
}

fn field_arg<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    spacing: Option<&Bound<'py, PyAny>>,
    value_range: Option<&Bound<'py, PyAny>>,
) -> PyResult<FieldArg<'py>> {
    let (spacing, value_range) = source_args(spacing, value_range)?;
    if let Ok(v) = volume.extract::<PyRef<'py, IllumVolume>>() {
        if spacing.is_some() || value_range.is_some() {
            return Err(value_error(
                "`spacing` and `value_range` belong to the PreparedVolume; leave them None \
                 when rendering one",
            ));
        }
        return Ok(FieldArg::Prepared(v));
    }
    Ok(FieldArg::Owned(field_in(
        py,
        volume,
        args::xyz(spacing.unwrap_or([1.0; 3])),
        value_range,
    )?))
}

/// A transfer function from an `(n, 4)` float32 array of RGBA rows, `n >= 2`.
/// The `tf` argument: an `(N, 4)` array-like of RGBA rows, `N >= 2`, finite.
fn tf_in(tf: &Bound<'_, PyAny>) -> PyResult<TransferFunction> {
    let a = args::array::<f64>("tf", tf)?;
    match *a.shape() {
        [n, 4] if n >= 2 => {
            let v = values(&a);
            if v.iter().any(|x| !x.is_finite()) {
                return Err(value_error(
                    "`tf` contains a non-finite value (NaN or infinity)",
                ));
            }
            let lut: Vec<[f32; 4]> = v
                .chunks_exact(4)
                .map(|r| [r[0] as f32, r[1] as f32, r[2] as f32, r[3] as f32])
                .collect();
            TransferFunction::from_lut(&lut).py_err()
        }
        ref s => Err(value_error(format!(
            "`tf` must be an (N, 4) array of RGBA rows with N >= 2, got shape {s:?}"
        ))),
    }
}

fn tf_out<'py>(py: Python<'py>, tf: &TransferFunction) -> PyResult<Arr<'py, f32>> {
    let e = tf.entries();
    array(py, &[e.len(), 4], e.iter().flatten().copied().collect())
}

/// The camera, light, method and settings of one render.
struct Scene {
    cam: SliceCamera,
    light: Light,
    method: Method,
    settings: IlluminationParams,
}

fn kernel_in(name: &str, spread: f64, tan_half: f64, units: Units) -> PyResult<Kernel> {
    let spread = non_negative("spread", spread)?;
    let tan_half = non_negative("tan_half", tan_half)? as f32;
    match name {
        "gaussian" => Ok(Kernel::Gaussian {
            spread: units.length_in("spread", spread)? as f32,
        }),
        "delta" => Ok(Kernel::Delta),
        "disk" => Ok(Kernel::Disk { tan_half }),
        other => Err(value_error(format!(
            "unknown `kernel` {other:?}; use 'gaussian', 'delta' or 'disk'"
        ))),
    }
}

fn method_in(name: &str, ds: f64, m: i64, atten: &str, units: Units) -> PyResult<Method> {
    positive("slice_distance", ds)?;
    let slice = positive("slice_distance", units.length_in("slice_distance", ds)?)? as f32;
    let m = int_in("n_subsamples", m, 0, MAX_SUBSAMPLES as i64)? as u32;
    let light_atten = match atten {
        "segment" => LightAtten::Segment,
        "slice-only" => LightAtten::SliceOnly,
        other => {
            return Err(value_error(format!(
                "unknown `light_attenuation` {other:?}; use 'segment' or 'slice-only'"
            )))
        }
    };
    let ics = |subsamples, preintegrated| Method::Ics {
        slice,
        subsamples,
        preintegrated,
        light_atten,
    };
    let none = |alt: &str| {
        if m > 0 {
            Err(value_error(format!(
                "`n_subsamples` = {m} with method {name:?}: use {alt:?} for sub-samples"
            )))
        } else {
            Ok(())
        }
    };
    let ray = || {
        if m > 0 {
            Err(value_error(format!(
                "`n_subsamples` = {m}: sub-samples apply to the slice methods only, not {name:?}"
            )))
        } else {
            Ok(slice)
        }
    };
    Ok(match name {
        "ics" => {
            none("scs")?;
            ics(0, false)
        }
        "scs" => ics(m, false),
        "pi-ics" => {
            none("pi-scs")?;
            ics(0, true)
        }
        "pi-scs" => ics(m, true),
        "raycast" => Method::RaycastEa { step: ray()? },
        "phong" => Method::RaycastPhong {
            step: ray()?,
            phong: Phong::default(),
        },
        "shadow-rays" => Method::ShadowRays { step: ray()? },
        other => {
            return Err(value_error(format!(
                "unknown `method` {other:?}; use 'ics', 'scs', 'pi-ics', 'pi-scs', 'raycast', \
                 'phong' or 'shadow-rays'"
            )))
        }
    })
}

/// The option `key`: 3 finite numbers (any array-like), `default` when absent or `None`.
fn vec3_item(opts: &Bound<'_, PyDict>, key: &str, default: [f64; 3]) -> PyResult<[f64; 3]> {
    match opts.get_item(key)?.filter(|v| !v.is_none()) {
        None => Ok(default),
        Some(v) => args::finite3(key, args::triple(key, &v)?),
    }
}

/// `(width, height)` of an image given as `size = (height, width)`, both at least 1.
fn size_in(size: (usize, usize)) -> PyResult<(usize, usize)> {
    let (h, w) = size;
    if w < 1 || h < 1 || w.saturating_mul(h) > 1 << 26 {
        return Err(value_error(format!(
            "`size` (height, width) must be positive with at most 2^26 pixels, got ({h}, {w})"
        )));
    }
    Ok((w, h))
}

fn scene_in(field: &ScalarField, opts: &Bound<'_, PyDict>) -> PyResult<Scene> {
    check_keys(opts, &RENDER_KEYS)?;
    let units = Units::of(field);
    let view_dir = vec3_item(opts, "view_dir", [0.0, 0.0, 1.0])?;
    let up = vec3_item(opts, "up", [0.0, 1.0, 0.0])?;
    let size = match opts.get_item("size")?.filter(|v| !v.is_none()) {
        None => (512, 512),
        Some(v) => args::size2(opts.py(), "size", &v)?,
    };
    let (width, height) = size_in(size)?;
    let center = opts
        .get_item("center")?
        .filter(|v| !v.is_none())
        .map(|c| -> PyResult<[f64; 3]> {
            let [x, y, z] = args::finite3("center", args::triple("center", &c)?)?;
            Ok([
                units.length_in("center", x)?,
                units.length_in("center", y)?,
                units.length_in("center", z)?,
            ])
        })
        .transpose()?;
    let cam = match dict_item::<f64>(opts, "pixel_size")? {
        None => {
            let mut cam = SliceCamera::fit(field, view_dir, up, width, height).py_err()?;
            if let Some(c) = center {
                cam.center = c;
            }
            cam
        }
        Some(p) => SliceCamera {
            dir: view_dir,
            up,
            center: center.unwrap_or_else(|| field.world_center()),
            width,
            height,
            pixel_size: positive(
                "pixel_size",
                units.length_in("pixel_size", positive("pixel_size", p)?)?,
            )?,
        },
    };
    cam.frame().py_err()?;
    let kernel = kernel_in(
        &dict_item::<String>(opts, "kernel")?.unwrap_or_else(|| "gaussian".into()),
        dict_item(opts, "spread")?.unwrap_or(0.5),
        dict_item(opts, "tan_half")?.unwrap_or(0.5),
        units,
    )?;
    let light = Light {
        dir_view: vec3_item(opts, "light_dir", [0.0, 0.0, 1.0])?,
        ambient: finite("ambient", dict_item(opts, "ambient")?.unwrap_or(0.0))? as f32,
        kernel,
    };
    light.unit_dir().py_err()?;
    let method = method_in(
        &dict_item::<String>(opts, "method")?.unwrap_or_else(|| "scs".into()),
        dict_item(opts, "slice_distance")?.unwrap_or(1.0),
        dict_item(opts, "n_subsamples")?.unwrap_or(0),
        &dict_item::<String>(opts, "light_attenuation")?.unwrap_or_else(|| "segment".into()),
        units,
    )?;
    let bg = vec3_item(opts, "background", [0.0; 3])?;
    let interp = choice_item(
        opts,
        "interp",
        Interp::Trilinear,
        &[
            ("trilinear", Interp::Trilinear),
            ("nearest", Interp::Nearest),
        ],
    )?;
    let border = choice_item(
        opts,
        "border",
        LightBorder::Open,
        &[("open", LightBorder::Open), ("closed", LightBorder::Closed)],
    )?;
    let settings = IlluminationParams::default()
        .interp(interp)
        .background(bg.map(|c| c as f32))
        .border(border);
    settings.check().py_err()?;
    Ok(Scene {
        cam,
        light,
        method,
        settings,
    })
}

/// Renders a volume (see `wscg.volren.render`): an `(H, W, 4)` float32 RGBA image.
#[pyfunction]
#[pyo3(signature = (volume, tf, spacing, value_range, opts))]
fn illum_render<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    tf: &Bound<'py, PyAny>,
    spacing: Option<&Bound<'py, PyAny>>,
    value_range: Option<&Bound<'py, PyAny>>,
    opts: &Bound<'py, PyDict>,
) -> PyResult<Arr<'py, f32>> {
    let tf = tf_in(tf)?;
    let field = field_arg(py, volume, spacing, value_range)?;
    let field: &ScalarField = &field;
    let tf = Units::of(field).tf_in(tf)?;
    let s = scene_in(field, opts)?;
    let r = crate::pool::detach(py, || {
        render_field(field, &tf, &s.cam, &s.light, &s.method, &s.settings)
    })
    .py_err()?;
    let (h, w, c) = r.image.shape();
    array(py, &[h, w, c], r.image.into_data())
}

/// The light buffer arriving at the slice nearest to `depth` (see
/// `wscg.volren.light_buffer`): an `(H, W)` float32 array and the slice's depth.
#[pyfunction]
#[pyo3(signature = (volume, tf, depth, spacing, value_range, opts))]
fn illum_light_buffer<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    tf: &Bound<'py, PyAny>,
    depth: f64,
    spacing: Option<&Bound<'py, PyAny>>,
    value_range: Option<&Bound<'py, PyAny>>,
    opts: &Bound<'py, PyDict>,
) -> PyResult<(Arr<'py, f32>, f64)> {
    let tf = tf_in(tf)?;
    let field = field_arg(py, volume, spacing, value_range)?;
    let field: &ScalarField = &field;
    let units = Units::of(field);
    let tf = units.tf_in(tf)?;
    let s = scene_in(field, opts)?;
    if !(depth.is_finite() && depth >= 0.0) {
        return Err(value_error(format!(
            "`depth` must be finite and >= 0, got {depth}"
        )));
    }
    let depth = units.length_in("depth", depth)?;
    let (img, z) = crate::pool::detach(py, || {
        light_buffer_at(field, &tf, &s.cam, &s.light, &s.method, &s.settings, depth)
    })
    .py_err()?;
    let (h, w, _) = img.shape();
    Ok((array(py, &[h, w], img.into_data())?, units.length_out(z)))
}

/// The pre-integration table of ``tf`` for segments of length ``ds`` (in the unit of
/// length the opacities of ``tf`` refer to):
/// an ``(N, N, 4)`` float32 array whose entry ``[f, b]`` holds the self-attenuated
/// associated colour ``(C_r, C_g, C_b)`` and the opacity ``alpha`` of a segment along which
/// the value varies linearly from ``f / (N - 1)`` (front) to ``b / (N - 1)`` (back).
/// ``alpha`` is symmetric and ``alpha[s, s] = 1 - (1 - a(s))^ds``; the colour is not
/// symmetric.
#[pyfunction]
fn preintegration_table<'py>(
    py: Python<'py>,
    tf: &Bound<'py, PyAny>,
    ds: f64,
) -> PyResult<Arr<'py, f32>> {
    let tf = tf_in(tf)?;
    let ds = positive("ds", ds)? as f32;
    let t = crate::pool::detach(py, || PreIntegrationTable::build(&tf, ds)).py_err()?;
    let n = t.n;
    array(py, &[n, n, 4], t.rgba.into_iter().flatten().collect())
}

/// The Marschner-Lobb aliasing test volume (``f_M = 6``, ``alpha = 1/4``) sampled at
/// ``n^3`` points spanning ``[-1, 1]^3``: an ``(n, n, n)`` float32 array ``[z, y, x]`` with
/// values in ``[0, 1]`` (pass ``value_range=(0, 1)`` to :func:`render` to keep them as
/// they are). ``2 <= n <= 1024``.
#[pyfunction]
#[pyo3(signature = (n=41))]
fn make_marschner_lobb(py: Python<'_>, n: i128) -> PyResult<Arr<'_, f32>> {
    let n: usize = uint(py, "n", n, 0)?;
    if !(2..=MAX_ML_SIDE).contains(&n) {
        return Err(value_error(format!(
            "`n` must be in 2..={MAX_ML_SIDE}, got {n}"
        )));
    }
    let f = crate::pool::detach(py, || scenes::marschner_lobb(n)).py_err()?;
    array(py, &[n, n, n], f.data().to_vec())
}

/// A sharp transfer function for :func:`make_marschner_lobb`: a thin opaque orange shell
/// around the value 1/2; ``(256, 4)`` float32.
#[pyfunction]
fn marschner_lobb_tf(py: Python<'_>) -> PyResult<Arr<'_, f32>> {
    tf_out(py, &scenes::marschner_lobb_tf())
}

/// A sharp transfer function for :func:`labels_to_density` fields: faint skin, red
/// organs, opaque white bone; ``(256, 4)`` float32.
#[pyfunction]
fn tissue_tf(py: Python<'_>) -> PyResult<Arr<'_, f32>> {
    tf_out(py, &scenes::tissue_tf())
}

/// A steep transfer function for :func:`labels_to_density` fields: an almost opaque
/// surface where the density crosses 0.15 (the outer boundary of the body), the kind of
/// transfer function for which the paper reports the largest gains from supersampling;
/// ``(256, 4)`` float32.
#[pyfunction]
fn skin_tf(py: Python<'_>) -> PyResult<Arr<'_, f32>> {
    tf_out(py, &scenes::skin_tf())
}

/// The `labels` argument: uint8 as it is, any other integer dtype with values in 0..255.
fn labels_in(labels: &Bound<'_, PyAny>) -> PyResult<(Vec<u8>, Vec<usize>)> {
    let a = args::asarray("labels", labels)?;
    let shape = a.shape().to_vec();
    if let Ok(l) = a.cast::<numpy::PyArrayDyn<u8>>() {
        return Ok((values(&l.readonly()).into_owned(), shape));
    }
    if !matches!(a.dtype().kind(), b'i' | b'u') {
        return Err(value_error(format!(
            "`labels` must be an integer (uint8) array, got dtype {}",
            a.dtype()
        )));
    }
    let l = args::array::<i64>("labels", a.as_any())?;
    let v = values(&l)
        .iter()
        .map(|&x| u8::try_from(x))
        .collect::<Result<Vec<u8>, _>>()
        .map_err(|_| value_error("`labels` must hold values in 0..255"))?;
    Ok((v, shape))
}

/// A CT-like density field from a tissue label volume ``[z, y, x]`` (uint8, or any
/// integer dtype with values in 0..255): label 0 is background (0), labels ``1..max``
/// spread over ``[0.3, 1]`` in label order, then a Gaussian blur of ``sigma >= 0`` voxels
/// per axis (``spacing`` ``(dz, dy, dx)`` is only validated). Returns float32
/// ``[z, y, x]`` in ``[0, 1]``; render it with :func:`tissue_tf` and
/// ``value_range=(0, 1)``.
#[pyfunction]
#[pyo3(signature = (labels, spacing=[1.0; 3], sigma=1.0),
       text_signature = "(labels, spacing=(1.0, 1.0, 1.0), sigma=1.0)")]
fn labels_to_density<'py>(
    py: Python<'py>,
    labels: &Bound<'py, PyAny>,
    spacing: [f64; 3],
    sigma: f64,
) -> PyResult<Arr<'py, f32>> {
    let (v, shape) = labels_in(labels)?;
    let dims = dims3("labels", &shape)?;
    let sigma = non_negative("sigma", sigma)?;
    let spacing = args::xyz(spacing);
    let f = crate::pool::detach(py, || {
        scenes::labels_to_field(VolumeView::new(dims, spacing, &v)?, sigma)
    })
    .py_err()?;
    array(py, &[dims[2], dims[1], dims[0]], f.data().to_vec())
}

/// Reads a VTK XML image file (``.vti``): the first array of its point data (else of its
/// cell data) as an array ``[z, y, x]`` in the stored dtype (uint8 ... float64) and the
/// spacing ``(dz, dy, dx)`` (array axis order; the file stores ``Spacing="dx dy dz"``). The
/// file's ``Origin`` is not read.
///
/// Supported: one piece, one-component little-endian arrays, inline base64 ("binary") or
/// appended (base64 or raw) data, zlib compression or none, UInt32 or UInt64 headers.
/// Raises ``OSError`` when the file cannot be read and ``ValueError`` when its content is
/// malformed, truncated or an unsupported variant of the format.
#[pyfunction]
fn load_vti<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyAny>, (f64, f64, f64))> {
    let path = args::path("path", path)?;
    let img = crate::pool::detach(py, || {
        // The parser validates what it reads; a panic on a hostile file would still be a
        // malformed file, not a crash of the interpreter.
        std::panic::catch_unwind(|| vti::read_vti(&path))
    })?
    .map_err(|_| {
        value_error(format!(
            "cannot decode {}: malformed VTK image data",
            path.display()
        ))
    })?
    .map_err(|e| match e {
        Error::Io { .. } => PyOSError::new_err(e.to_string()),
        e => PyValueError::new_err(e.to_string()),
    })?;
    let [nx, ny, nz] = img.dims;
    let shape = [nz, ny, nx];
    let arr = match img.values {
        VtiValues::U8(v) => array(py, &shape, v)?.into_any(),
        VtiValues::I8(v) => array(py, &shape, v)?.into_any(),
        VtiValues::U16(v) => array(py, &shape, v)?.into_any(),
        VtiValues::I16(v) => array(py, &shape, v)?.into_any(),
        VtiValues::U32(v) => array(py, &shape, v)?.into_any(),
        VtiValues::I32(v) => array(py, &shape, v)?.into_any(),
        VtiValues::I64(v) => array(py, &shape, v)?.into_any(),
        VtiValues::U64(v) => array(py, &shape, v)?.into_any(),
        VtiValues::F32(v) => array(py, &shape, v)?.into_any(),
        VtiValues::F64(v) => array(py, &shape, v)?.into_any(),
    };
    let s = img.spacing;
    Ok((arr, (s[2], s[1], s[0])))
}

/// An `(H, W, C)` float32 image with `C >= 3` and finite values.
fn rgb_image_in(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Image<f32>> {
    let a = &args::array::<f32>(name, a)?;
    let (h, w, c) = match *a.shape() {
        [h, w, c] if c >= 3 => (h, w, c),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be an (H, W, C) image with C >= 3, got shape {s:?}"
            )))
        }
    };
    let v = values(a).into_owned();
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!(
            "`{name}` contains a non-finite value (NaN or infinity) at flat index {i}"
        )));
    }
    Image::new(h, w, c, v).py_err()
}

/// Mean absolute difference over all pixels and the RGB channels of two ``(H, W, C)``
/// images with ``C >= 3`` (alpha ignored): the error of the paper's Table 1.
#[pyfunction]
fn mean_abs_diff(py: Python<'_>, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (a, b) = (rgb_image_in("a", a)?, rgb_image_in("b", b)?);
    if a.shape() != b.shape() {
        return Err(value_error(format!(
            "`a` and `b` must have the same shape, got {:?} and {:?}",
            a.shape(),
            b.shape()
        )));
    }
    if a.height() == 0 || a.width() == 0 {
        return Err(value_error("`a` and `b` are empty images"));
    }
    crate::pool::detach(py, || study::mean_abs_diff(&a, &b)).py_err()
}

/// The quality and speed study over orbit views (see `wscg.volren.study`).
#[pyfunction]
#[pyo3(signature = (volume, tf, spacing, value_range, opts))]
fn illum_study<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    tf: &Bound<'py, PyAny>,
    spacing: Option<&Bound<'py, PyAny>>,
    value_range: Option<&Bound<'py, PyAny>>,
    opts: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    check_keys(opts, &STUDY_KEYS)?;
    let tf = tf_in(tf)?;
    let field = field_arg(py, volume, spacing, value_range)?;
    let field: &ScalarField = &field;
    let units = Units::of(field);
    let tf = units.tf_in(tf)?;
    let views = int_in(
        "n_views",
        dict_item(opts, "n_views")?.unwrap_or(4),
        1,
        1 << 16,
    )? as usize;
    let size: usize = match opts.get_item("size")?.filter(|v| !v.is_none()) {
        None => 256,
        Some(v) => uint(py, "size", args::integer("size", &v)?, 0)?,
    };
    let size = size_in((size, size))?.0;
    let azimuth = finite("azimuth", dict_item(opts, "azimuth")?.unwrap_or(30.0))?;
    let elevation = finite("elevation", dict_item(opts, "elevation")?.unwrap_or(20.0))?;
    let distances: Vec<f64> =
        dict_item(opts, "distances")?.unwrap_or_else(|| (1..=10).map(|k| 0.2 * k as f64).collect());
    if distances.is_empty() {
        return Err(value_error("`distances` is empty"));
    }
    for &d in &distances {
        positive("distances", d)?;
    }
    let max_m = int_in(
        "max_subsamples",
        dict_item(opts, "max_subsamples")?.unwrap_or(5),
        0,
        MAX_SUBSAMPLES as i64,
    )? as u32;
    let reference = positive("reference", dict_item(opts, "reference")?.unwrap_or(0.2))?;
    let fine = positive("fine", dict_item(opts, "fine")?.unwrap_or(0.1))?;
    let light = Light {
        dir_view: vec3_item(opts, "light_dir", [0.0, 0.0, 1.0])?,
        ambient: finite("ambient", dict_item(opts, "ambient")?.unwrap_or(0.0))? as f32,
        kernel: kernel_in(
            "gaussian",
            dict_item(opts, "spread")?.unwrap_or(0.5),
            0.0,
            units,
        )?,
    };
    light.unit_dir().py_err()?;
    let criterion = AliasCriterion {
        max_mad: non_negative("max_mad", dict_item(opts, "max_mad")?.unwrap_or(0.005))?,
        max_energy_ratio: non_negative(
            "max_energy_ratio",
            dict_item(opts, "max_energy_ratio")?.unwrap_or(2.0),
        )?,
    };
    let cams = (0..views)
        .map(|k| {
            let az = azimuth + 360.0 * k as f64 / views as f64;
            SliceCamera::orbit(field, az, elevation, size)
        })
        .collect::<wscg_math::Result<Vec<_>>>()
        .py_err()?;
    let d32: Vec<f32> = distances
        .iter()
        .map(|&d| units.length_in("distances", d).map(|d| d as f32))
        .collect::<PyResult<_>>()?;
    let (reference, fine) = (
        units.length_in("reference", reference)?,
        units.length_in("fine", fine)?,
    );
    let configs = study::grid(&d32, max_m);
    let settings = IlluminationParams::default();
    let st = crate::pool::detach(py, || {
        study::sweep(
            field,
            &tf,
            &cams,
            &light,
            &settings,
            &Method::ics(reference as f32),
            &Method::ics(fine as f32),
            &configs,
            &criterion,
            |_, _| {},
        )
    })
    .py_err()?;
    // `grid` emits 2 (max_m + 1) configurations per distance, in the order given.
    let per = 2 * (max_m as usize + 1);
    let entries = PyList::empty(py);
    for (i, e) in st.entries.iter().enumerate() {
        let d = PyDict::new(py);
        let m = match e.method {
            Method::Ics { subsamples, .. } => subsamples,
            _ => 0,
        };
        d.set_item("method", e.method.name())?;
        d.set_item("slice_distance", distances[i / per])?;
        d.set_item("n_subsamples", m)?;
        d.set_item("mad", e.mad)?;
        d.set_item("energy", e.energy)?;
        d.set_item("seconds", e.seconds)?;
        d.set_item("alias_free", e.alias_free)?;
        entries.append(d)?;
    }
    let out = PyDict::new(py);
    out.set_item("reference_seconds", st.reference_seconds)?;
    out.set_item("fine_energy", st.fine_energy)?;
    out.set_item("entries", entries)?;
    Ok(out)
}

/// Registers the paper-15 functions into the `volren` submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<IllumVolume>()?;
    m.add_function(wrap_pyfunction!(_illum_from_normalised, m)?)?;
    m.add_function(wrap_pyfunction!(illum_render, m)?)?;
    m.add_function(wrap_pyfunction!(illum_light_buffer, m)?)?;
    m.add_function(wrap_pyfunction!(illum_study, m)?)?;
    m.add_function(wrap_pyfunction!(preintegration_table, m)?)?;
    m.add_function(wrap_pyfunction!(make_marschner_lobb, m)?)?;
    m.add_function(wrap_pyfunction!(marschner_lobb_tf, m)?)?;
    m.add_function(wrap_pyfunction!(tissue_tf, m)?)?;
    m.add_function(wrap_pyfunction!(skin_tf, m)?)?;
    m.add_function(wrap_pyfunction!(labels_to_density, m)?)?;
    m.add_function(wrap_pyfunction!(load_vti, m)?)?;
    m.add_function(wrap_pyfunction!(mean_abs_diff, m)?)?;
    Ok(())
}
