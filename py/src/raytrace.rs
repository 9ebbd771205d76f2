//! `wscg._native.raytrace`: bindings of `wscg-raytrace` (paper 07: metallic-flake paint,
//! spectral rendering, stereo rig, virtual observer). The Fresnel, spectral, projection and
//! overlap functions are called by Python directly, re-exported by `python/wscg/raytrace.py`
//! (their arguments converted by [`crate::args`]); the plate functions keep a Python layer
//! (result classes, structured flake arrays), which passes the plate's parameters as one dict
//! whose keys are the Python argument names (mostly the Rust fields' names; the counts are
//! `n_pool_tiles`, `n_photons` and `n_photon_neighbors`, the colour mode `color_mode`). The
//! counts are checked here so that an error names the Python argument.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_math::progress::NoProgress;
use wscg_math::ImageView;
use wscg_raytrace::paint::{
    self, binocular_overlap, glint_stats, Coat, ColourMode, Condition, DiscLight, FlakeParams,
    FlakePlate, PaintRenderParams, PhotonParams, Plate, PlateStack, Rect, StackModel, TiltDist,
    WorkshopParams,
};
use wscg_raytrace::spectral::{self, daylight_d, MetalIor, SpectralGrid, Spectrum};
use wscg_raytrace::stereo::{Eye, StereoRig};

use crate::args::{self, number, uint};
use crate::cfg::Cfg;
use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy};

fn flake_params(c: &Cfg) -> PyResult<FlakeParams> {
    let d = FlakeParams::default();
    let tilt = match c.get("tilt", "halfnormal".to_string())?.as_str() {
        "halfnormal" => TiltDist::HalfNormal {
            sigma_deg: c.get("tilt_deg", 8.0)?,
        },
        "cap" => TiltDist::UniformCap {
            max_deg: c.get("tilt_deg", 8.0)?,
        },
        "flat" => TiltDist::Flat,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid tilt. Valid tilts are 'halfnormal', 'cap', 'flat'"
            )))
        }
    };
    let model = match c.get("model", "boolean".to_string())?.as_str() {
        "boolean" => StackModel::Boolean,
        "deposit" => StackModel::Deposit,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid model. Valid models are 'boolean', 'deposit'"
            )))
        }
    };
    let n_pool_tiles: usize = c.count("n_pool_tiles", d.tiles_in_pool, 1)?;
    Ok(FlakeParams::default()
        .radius_um(c.get("radius_um", d.radius_um)?)
        .radius_cv(c.get("radius_cv", d.radius_cv)?)
        .thickness_um(c.get("thickness_um", d.thickness_um)?)
        .density(c.get("density", d.density)?)
        .tilt(tilt)
        .layer_um(c.get("layer_um", d.layer_um)?)
        .tile_um(c.get("tile_um", d.tile_um)?)
        .model(model)
        .tiles_in_pool(n_pool_tiles)
        .max_clamped_fraction(c.get("max_clamped_fraction", d.max_clamped_fraction)?))
}

fn stack(c: &Cfg, flakes: &FlakeParams) -> PyResult<PlateStack> {
    let d = PlateStack::default();
    let metal = match c.numbers::<2>("metal_nk")? {
        Some([n, k]) => MetalIor::Constant { n, k },
        None => match c.get("metal", "al_k6".to_string())?.as_str() {
            "al_k6" => MetalIor::AlRakicLdConstK { k: 6.0 },
            "al" => MetalIor::AlRakicLd,
            other => {
                return Err(value_error(format!(
                    "{other:?} is not a valid metal. Valid metals are 'al_k6' (the paper's k = 6), 'al' (Rakic), or give metal_nk=(n, k)"
                )))
            }
        },
    };
    let coat_ior: f64 = c.get("coat_ior", 1.5)?;
    let coat = (coat_ior != 1.0).then(|| -> PyResult<Coat> {
        Ok(Coat {
            ior: coat_ior,
            thickness_um: c.get("coat_um", 40.0)?,
        })
    });
    Ok(PlateStack {
        size_mm: c.numbers("size_mm")?.map_or(d.size_mm, |[w, h]| (w, h)),
        coat: coat.transpose()?,
        binder_ior: c.get("binder_ior", d.binder_ior)?,
        binder_um: flakes.layer_um,
        binder_sigma_a_per_mm: c.get("binder_sigma_a_per_mm", d.binder_sigma_a_per_mm)?,
        base_albedo: c.get("base_albedo", d.base_albedo)?,
        metal,
    })
}

fn light(c: &Cfg) -> PyResult<DiscLight> {
    let mut l = DiscLight::from_elevation(
        c.get("light_elevation_deg", 45.0)?,
        c.get("light_deg", 1.0)?,
    );
    if let Some(cct) = c.opt::<f64>("light_cct")? {
        l.spectrum = daylight_d(cct).py_err()?;
    }
    if let Some(spd) = c.floats("light_spectrum")? {
        l.spectrum = Spectrum::new(SpectralGrid::VISIBLE, spd).py_err()?;
    }
    l.radiance_scale = c.get("radiance_scale", 1.0)?;
    Ok(l)
}

fn settings(c: &Cfg) -> PyResult<PaintRenderParams> {
    let d = PaintRenderParams::default();
    let region = c
        .numbers("region_mm")?
        .map(|[x0, y0, x1, y1]| Rect { x0, y0, x1, y1 });
    let colour = match c.get("color_mode", "spectral".to_string())?.as_str() {
        "spectral" => ColourMode::Spectral,
        "rgb" => ColourMode::Rgb,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid `color_mode`. Valid modes are 'spectral', 'rgb'"
            )))
        }
    };
    let photon_defaults = PhotonParams::default();
    let n_photons: usize = c.count("n_photons", photon_defaults.count, 0)?;
    let n_neighbors: usize = c.count("n_photon_neighbors", photon_defaults.k, 1)?;
    if n_photons > 500_000_000 {
        return Err(value_error(format!(
            "`n_photons` must be at most 500 million, got {n_photons}"
        )));
    }
    Ok(PaintRenderParams::default()
        .spp(c.count("spp", d.spp, 0)?)
        .max_depth(c.count("max_depth", d.max_depth, 0)?)
        .seed(c.count("render_seed", d.seed, 0)?)
        .region_mm(region)
        .magnification(c.get("magnification", d.magnification)?)
        .independent_samples(c.get("independent_samples", false)?)
        .colour(colour)
        .keep_spectrum(c.get("keep_spectrum", false)?)
        .photons(match n_photons {
            0 => None,
            count => Some(photon_defaults.count(count).k(n_neighbors)),
        }))
}

fn eye_of(name: &str) -> PyResult<Eye> {
    match name {
        "left" => Ok(Eye::Left),
        "right" => Ok(Eye::Right),
        "cyclopean" => Ok(Eye::Cyclopean),
        other => Err(value_error(format!(
            "{other:?} is not a valid eye. Valid eyes are 'left', 'right', 'cyclopean', 'pair'"
        ))),
    }
}

/// One rendered view: XYZ (H, W, 3) float32, per-pixel flake ids (H, W) uint64, the glinting
/// flakes, and a dict of scalars.
type View<'py> = (
    Arr<'py, f32>,
    Arr<'py, u64>,
    Arr<'py, u64>,
    Bound<'py, PyDict>,
);

/// Renders the plate of `params` for each of `eyes` (same microstructure for all).
#[pyfunction]
fn render_plate<'py>(
    py: Python<'py>,
    params: Bound<'py, PyDict>,
    eyes: Vec<String>,
) -> PyResult<Vec<View<'py>>> {
    let c = Cfg(&params);
    let fp = flake_params(&c)?;
    let st = stack(&c, &fp)?;
    let li = light(&c)?;
    let s = settings(&c)?;
    let seed: u64 = c.count("seed", 0, 0)?;
    let eyes = eyes
        .iter()
        .map(|e| eye_of(e))
        .collect::<PyResult<Vec<_>>>()?;
    let rig = StereoRig::default();
    let images = crate::pool::detach(py, || -> wscg_math::Result<Vec<paint::XyzImage>> {
        let micro = FlakePlate::new(&fp, st.size_mm, seed)?;
        let plate = Plate::new(st, Box::new(micro))?;
        eyes.iter()
            .map(|&e| paint::render(&plate, &li, &rig, e, &s))
            .collect()
    })
    .py_err()?;
    images
        .into_iter()
        .map(|im| {
            let info = PyDict::new(py);
            info.set_item("mm_per_px", im.mm_per_px)?;
            info.set_item("lamp_y", im.lamp_y)?;
            info.set_item(
                "region_mm",
                (im.region.x0, im.region.y0, im.region.x1, im.region.y1),
            )?;
            let (h, w) = (im.height, im.width);
            if !im.bands_nm.is_empty() {
                let nb = im.bands_nm.len();
                info.set_item("bands_nm", im.bands_nm.clone())?;
                info.set_item("spectrum", array(py, &[h, w, nb], im.spectrum)?)?;
            }
            let n = im.glint_ids.len();
            Ok((
                array(py, &[h, w, 3], im.xyz)?,
                array(py, &[h, w], im.flake_id)?,
                array(py, &[n], im.glint_ids)?,
                info,
            ))
        })
        .collect()
}

/// One tile of the microstructure as an (N, 7) array `cx, cy, cz, nx, ny, nz, r` and the
/// number of clamped flakes.
#[pyfunction]
fn make_tile<'py>(py: Python<'py>, params: Bound<'py, PyDict>) -> PyResult<(Arr<'py, f64>, usize)> {
    let c = Cfg(&params);
    let fp = flake_params(&c)?;
    let seed: u64 = c.count("seed", 0, 0)?;
    let t = crate::pool::detach(py, || paint::generate_tile(&fp, seed)).py_err()?;
    let v: Vec<f64> = t
        .flakes
        .iter()
        .flat_map(|f| [f.c[0], f.c[1], f.c[2], f.n[0], f.n[1], f.n[2], f.r])
        .collect();
    Ok((array(py, &[t.flakes.len(), 7], v)?, t.clamped))
}

/// The tile pool and the cells `(x0, y0, tile, quarter turns)`.
type Layout<'py> = (Vec<Arr<'py, f64>>, Vec<(f64, f64, usize, u8)>);

/// The plate's layout over a region (µm): the tile pool as (N, 7) arrays and, per cell,
/// `(x0, y0, tile, quarter turns)`.
#[pyfunction]
fn plate_layout<'py>(
    py: Python<'py>,
    params: Bound<'py, PyDict>,
    region_mm: &Bound<'py, PyAny>,
) -> PyResult<Layout<'py>> {
    let [x0, y0, x1, y1] = args::numbers::<4>("region_mm", region_mm)?.map(|v| v * 1e3);
    let region_um = (x0, y0, x1, y1);
    let c = Cfg(&params);
    let fp = flake_params(&c)?;
    let st = stack(&c, &fp)?;
    let seed: u64 = c.count("seed", 0, 0)?;
    let plate = crate::pool::detach(py, || FlakePlate::new(&fp, st.size_mm, seed)).py_err()?;
    let pool = plate
        .pool()
        .iter()
        .map(|t| {
            let v: Vec<f64> = t
                .flakes
                .iter()
                .flat_map(|f| [f.c[0], f.c[1], f.c[2], f.n[0], f.n[1], f.n[2], f.r])
                .collect();
            array(py, &[t.flakes.len(), 7], v)
        })
        .collect::<PyResult<Vec<_>>>()?;
    let (x0, y0, x1, y1) = region_um;
    let cells = plate
        .cells_in(x0, y0, x1, y1)
        .into_iter()
        .map(|((cx, cy), t, k)| (cx, cy, t, k))
        .collect();
    Ok((pool, cells))
}

/// Sparkle statistics of a luminance image.
#[pyfunction]
fn glint_statistics<'py>(
    py: Python<'py>,
    y: &Bound<'py, PyAny>,
    mm_per_px: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let y = args::array::<f32>("y", y)?;
    let [h, w] = *y.shape() else {
        return Err(value_error(format!(
            "`y` must be a 2-D (H, W) array, got shape {:?}",
            y.shape()
        )));
    };
    let y = values(&y);
    let s = crate::pool::detach(py, || {
        ImageView::plane(h, w, &y).and_then(|y| glint_stats(y, mm_per_px))
    })
    .py_err()?;
    let d = PyDict::new(py);
    d.set_item("glint_density_per_mm2", s.glint_density_per_mm2)?;
    d.set_item("mean_y", s.mean_y)?;
    d.set_item("median_y", s.median_y)?;
    d.set_item("y99_over_median", s.y99_over_median)?;
    d.set_item("mean_glint_area_mm2", s.mean_glint_area_mm2)?;
    d.set_item("mean_glint_peak_y", s.mean_glint_peak_y)?;
    d.set_item("glints", s.glints)?;
    d.set_item("threshold", s.threshold)?;
    Ok(d)
}

/// The virtual workshop: scores of `runs` against the hidden reference.
#[pyfunction]
fn workshop<'py>(
    py: Python<'py>,
    params: Bound<'py, PyDict>,
    reference: &Bound<'py, PyAny>,
    runs: &Bound<'py, PyAny>,
    condition: &str,
    n_reference_renders: i128,
    jnd_log: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let reference = args::pair("reference", reference)?;
    let runs = runs
        .try_iter()
        .map_err(|_| value_error("`runs` must be a sequence of (radius_um, density) pairs"))?
        .map(|r| args::pair("runs", &r?))
        .collect::<PyResult<Vec<_>>>()?;
    // At least two renders of the reference calibrate the observer.
    let n_reference_renders: usize = uint(py, "n_reference_renders", n_reference_renders, 2)?;
    let c = Cfg(&params);
    let fp = flake_params(&c)?;
    let condition = match condition {
        "mono" => Condition::Mono,
        "stereo" => Condition::Stereo,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid condition. Valid conditions are 'mono', 'stereo'"
            )))
        }
    };
    let defaults = WorkshopParams::default();
    let mut s = settings(&c)?;
    if s.region_mm.is_none() {
        s.region_mm = defaults.settings.region_mm;
    }
    let cfg = defaults
        .clone()
        .base(fp)
        .stack(stack(&c, &fp)?)
        .light(if c.0.contains("light_elevation_deg")? {
            light(&c)?
        } else {
            DiscLight {
                angular_radius_deg: c.get("light_deg", 1.0)?,
                ..defaults.light.clone()
            }
        })
        .settings(s)
        .reference_renders(n_reference_renders)
        .condition(condition)
        .jnd_log(jnd_log);
    let seed: u64 = c.count("seed", 0, 0)?;
    let ws = crate::pool::detach(py, || {
        paint::score_runs(reference, &runs, &cfg, seed, &NoProgress)
    })
    .py_err()?;
    let d = PyDict::new(py);
    d.set_item("scores", ws.scores)?;
    d.set_item("features", ws.features)?;
    d.set_item("reference_features", ws.reference_features)?;
    // The mono condition has no binocular overlap: the names of the features it has.
    let n_features = ws.observer.std_log.len();
    let names: Vec<&str> = paint::observer::FEATURE_NAMES
        .iter()
        .take(n_features)
        .copied()
        .collect();
    d.set_item("feature_names", names)?;
    d.set_item("scale_log", ws.observer.std_log)?;
    Ok(d)
}

/// Overlap ``2 |L ∩ R| / (|L| + |R|)`` of the flakes glinting for the two eyes.
#[pyfunction]
#[pyo3(name = "binocular_overlap")]
fn overlap(
    py: Python<'_>,
    left_ids: &Bound<'_, PyAny>,
    right_ids: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let left = args::array::<u64>("left_ids", left_ids)?;
    let right = args::array::<u64>("right_ids", right_ids)?;
    let (l, r) = (values(&left), values(&right));
    crate::pool::detach(py, || binocular_overlap(&l, &r))
}

/// A real array argument with finite values, as float64 in C order, and its shape (a scalar
/// keeps its shape `()`).
fn finite_array(name: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let shape = args::asarray(name, obj)?.shape().to_vec();
    let a = args::array::<f64>(name, obj)?;
    let v = values(&a).into_owned();
    wscg_math::error::ensure_finite(name, &v).py_err()?;
    Ok((shape, v))
}

/// `f` of every value of the array argument `cos_i`, in its shape.
fn elementwise<'py>(
    py: Python<'py>,
    cos_i: &Bound<'py, PyAny>,
    f: impl Fn(f64) -> f64,
) -> PyResult<Arr<'py, f64>> {
    let (shape, v) = finite_array("cos_i", cos_i)?;
    array(py, &shape, v.into_iter().map(f).collect())
}

/// Unpolarised Fresnel reflectance of a conductor of relative index ``n + i k``.
#[pyfunction]
fn fresnel_conductor<'py>(
    py: Python<'py>,
    cos_i: &Bound<'py, PyAny>,
    n: f64,
    k: f64,
) -> PyResult<Arr<'py, f64>> {
    let (n, k) = (number("n", n)?, number("k", k)?);
    elementwise(py, cos_i, |c| spectral::fresnel_conductor(c, n, k))
}

/// Unpolarised Fresnel reflectance of a dielectric interface (relative index ``eta``,
/// total internal reflection included).
#[pyfunction]
fn fresnel_dielectric<'py>(
    py: Python<'py>,
    cos_i: &Bound<'py, PyAny>,
    eta: f64,
) -> PyResult<Arr<'py, f64>> {
    let eta = number("eta", eta)?;
    elementwise(py, cos_i, |c| spectral::fresnel_dielectric(c, eta))
}

/// Aluminium's ``(n, k)`` at the given wavelengths (Rakic 1998 Lorentz-Drude model).
#[pyfunction]
fn aluminium_nk<'py>(py: Python<'py>, lambda_nm: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f64>> {
    let (_, lam) = finite_array("lambda_nm", lambda_nm)?;
    let nk: Vec<f64> = lam
        .iter()
        .flat_map(|&l| {
            let c = spectral::aluminium_rakic_ld(l);
            [c.re, c.im]
        })
        .collect();
    array(py, &[lam.len(), 2], nk)
}

/// CIE daylight spectrum at ``cct_k`` (4000-25000 K), 81 values over 380-780 nm.
#[pyfunction]
fn daylight(py: Python<'_>, cct_k: f64) -> PyResult<Arr<'_, f64>> {
    let v = daylight_d(number("cct_k", cct_k)?).py_err()?.v;
    array(py, &[v.len()], v)
}

/// CIE 1931 XYZ of an 81-value spectrum on 380-780 nm (5 nm steps).
#[pyfunction]
fn spectrum_to_xyz<'py>(py: Python<'py>, spd: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f64>> {
    let (_, v) = finite_array("spd", spd)?;
    let s = Spectrum::new(SpectralGrid::VISIBLE, v).py_err()?;
    let x = spectral::to_xyz(&s).py_err()?;
    array(py, &[3], x.to_vec())
}

/// Pixel coordinates ``(N, 2)`` on the study's screen of points ``(N, 3)`` (metres, eyes
/// at z = 0, screen and plate at z = 0.77) for one eye of the off-axis rig.
#[pyfunction]
#[pyo3(signature = (points, eye="cyclopean"))]
fn project<'py>(py: Python<'py>, points: &Bound<'py, PyAny>, eye: &str) -> PyResult<Arr<'py, f64>> {
    let points = args::array::<f64>("points", points)?;
    let e = eye_of(eye)?;
    let pts = crate::convert::rows3("points", &values(&points), points.shape())?;
    let rig = StereoRig::default();
    let out: Vec<f64> = crate::pool::detach(py, || {
        pts.iter()
            .flat_map(|p| {
                let (x, y) = rig.project(e, *p).unwrap_or((f64::NAN, f64::NAN));
                [x, y]
            })
            .collect()
    })?;
    array(py, &[out.len() / 2, 2], out)
}

/// Reads a paint description file: its JSON text as checked and re-written by the library
/// (only the keys the file sets).
#[pyfunction]
fn load_paint(py: Python<'_>, path: std::path::PathBuf) -> PyResult<String> {
    let p = crate::pool::detach(py, || paint::PaintDescription::read(&path)).py_err()?;
    serde_json::to_string(&p).map_err(|e| value_error(e.to_string()))
}

/// Writes the paint description `description` (JSON text of its keys), checked as
/// `load_paint` checks a file.
#[pyfunction]
fn save_paint(py: Python<'_>, path: std::path::PathBuf, description: &str) -> PyResult<()> {
    let p: paint::PaintDescription =
        serde_json::from_str(description).map_err(|e| value_error(format!("paint: {e}")))?;
    p.validate().py_err()?;
    crate::pool::detach(py, || p.write(&path)).py_err()
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_paint, m)?)?;
    m.add_function(wrap_pyfunction!(save_paint, m)?)?;
    m.add_function(wrap_pyfunction!(render_plate, m)?)?;
    m.add_function(wrap_pyfunction!(make_tile, m)?)?;
    m.add_function(wrap_pyfunction!(plate_layout, m)?)?;
    m.add_function(wrap_pyfunction!(glint_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(overlap, m)?)?;
    m.add_function(wrap_pyfunction!(workshop, m)?)?;
    m.add_function(wrap_pyfunction!(fresnel_conductor, m)?)?;
    m.add_function(wrap_pyfunction!(fresnel_dielectric, m)?)?;
    m.add_function(wrap_pyfunction!(aluminium_nk, m)?)?;
    m.add_function(wrap_pyfunction!(daylight, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(project, m)?)?;
    m.add(
        "XYZ_TO_SRGB",
        spectral::XYZ_TO_SRGB.map(|r| r.to_vec()).to_vec(),
    )?;
    crate::manylight::register(m)
}
