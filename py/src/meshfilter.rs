//! `wscg.meshfilter`'s functions (paper 04, joint bilateral mesh denoising): bindings of
//! `wscg-meshfilter` that Python calls directly, re-exported by `python/wscg/meshfilter.py`
//! (which holds the module's documentation). Arguments are converted and checked by
//! [`crate::args`]: array-likes of any real dtype, counts and seeds as Python ints.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use wscg_math::TriMesh;
use wscg_meshfilter::bmd::{bmd, BmdParams};
use wscg_meshfilter::metrics::{mean_error as me, mean_vertex_distance, surface_error as se};
use wscg_meshfilter::{smoothing, synth, JbmdParams};

use crate::args::{self, uint};
use crate::convert::{array, rows3, values, Arr};
use crate::errors::{value_error, IntoPy};

fn positions_out<'py>(py: Python<'py>, p: Vec<[f64; 3]>) -> PyResult<Arr<'py, f64>> {
    let n = p.len();
    array(py, &[n, 3], p.concat())
}

type MeshArrays<'py> = (Arr<'py, f64>, Arr<'py, i64>, Arr<'py, f32>);

fn mesh_out<'py>(py: Python<'py>, m: TriMesh) -> PyResult<MeshArrays<'py>> {
    let nf = m.faces.len();
    let faces = m.faces.iter().flatten().map(|&i| i as i64).collect();
    // Stored in [0, 1]; Python's colours are 0..255 (what `jbmd` takes).
    let colors: Vec<f32> = m
        .colors
        .iter()
        .flatten()
        .flat_map(|c| c.map(|v| 255.0 * v))
        .collect();
    let nc = colors.len() / 3;
    Ok((
        positions_out(py, m.positions)?,
        array(py, &[nf, 3], faces)?,
        array(py, &[nc, 3], colors)?,
    ))
}

/// Denoised vertices ``(n, 3)`` after ``n_iter`` iterations. ``sigma_d`` and ``sigma_o``
/// default to 2 and 0.5 times the mean vertex distance; without ``colors`` the colour
/// weight is left out (the paper's no-colour ablation). By default every iteration is our
/// two-stage update: ``normal_n_iter`` passes of a joint bilateral filter of the face
/// normals (ranges ``sigma_d``, ``sigma_n``, ``sigma_c``), then ``vertex_n_iter`` steps moving
/// the vertices onto the planes of their faces, which keeps sharp edges. ``normal_n_iter=0``
/// gives the paper's update over the ``n_neighbors`` nearest neighbours of every vertex (the
/// paper's ``k``), where ``lam=1`` disables the offset-range decay and
/// ``anti_shrink=False`` the second pass.
#[pyfunction]
#[pyo3(signature = (vertices, faces, colors=None, sigma_d=None, sigma_o=None, sigma_c=30.0,
                    lam=0.8, n_neighbors=20, n_iter=10, anti_shrink=true,
                    rebuild_neighbors=true, normal_n_iter=10, sigma_n=0.5,
                    vertex_n_iter=10))]
#[allow(clippy::too_many_arguments)]
fn jbmd<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    colors: Option<&Bound<'py, PyAny>>,
    sigma_d: Option<f64>,
    sigma_o: Option<f64>,
    sigma_c: f64,
    lam: f64,
    n_neighbors: i128,
    n_iter: i128,
    anti_shrink: bool,
    rebuild_neighbors: bool,
    normal_n_iter: i128,
    sigma_n: f64,
    vertex_n_iter: i128,
) -> PyResult<Arr<'py, f64>> {
    let n_neighbors: usize = uint(py, "n_neighbors", n_neighbors, 0)?;
    let n_iter: usize = uint(py, "n_iter", n_iter, 0)?;
    let normal_n_iter: usize = uint(py, "normal_n_iter", normal_n_iter, 0)?;
    let vertex_n_iter: usize = uint(py, "vertex_n_iter", vertex_n_iter, 0)?;
    let mut mesh = args::mesh(vertices, faces)?;
    let colors = match colors.filter(|c| !c.is_none()) {
        Some(c) => {
            let c = args::array::<f32>("colors", c)?;
            let scaled: Vec<f32> = values(&c).iter().map(|v| v / 255.0).collect();
            Some(rows3("colors", &scaled, c.shape())?)
        }
        None => None,
    };
    // The parameters' own checks name the paper's symbols (`k`, `lambda`); these name the
    // Python arguments.
    let nv = mesh.positions.len();
    if n_neighbors == 0 || (nv > 0 && n_neighbors >= nv) {
        return Err(value_error(format!(
            "`n_neighbors` must be in 1..{nv} (fewer than the {nv} vertices), got {n_neighbors}"
        )));
    }
    if !(lam > 0.0 && lam <= 1.0) {
        return Err(value_error(format!("`lam` must be in (0, 1], got {lam}")));
    }
    let out = crate::pool::detach(py, || {
        if let Some(c) = colors {
            mesh = mesh.with_colors(c)?;
        }
        let (sigma_d, sigma_o) = match (sigma_d, sigma_o) {
            (Some(d), Some(o)) => (d, o),
            _ => {
                let d = mean_vertex_distance(&mesh)?;
                (sigma_d.unwrap_or(2.0 * d), sigma_o.unwrap_or(0.5 * d))
            }
        };
        let p = JbmdParams::default()
            .sigma_d(sigma_d)
            .sigma_o(sigma_o)
            .sigma_c(sigma_c)
            .lambda(lam)
            .k(n_neighbors)
            .iterations(n_iter)
            .anti_shrink(anti_shrink)
            .use_color(mesh.colors.is_some())
            .rebuild_neighbors(rebuild_neighbors)
            .normal_iterations(normal_n_iter)
            .sigma_n(sigma_n)
            .vertex_iterations(vertex_n_iter);
        wscg_meshfilter::jbmd(&mesh, &p)
    })
    .py_err()?;
    positions_out(py, out)
}

/// Bilateral mesh denoising (Fleishman, Drori and Cohen-Or 2003): neighbours within
/// ``2 sigma_c`` on the connected surface, offset range ``sigma_s``; with
/// ``volume_preserve`` the mesh is rescaled to its initial volume after every iteration.
#[pyfunction]
#[pyo3(signature = (vertices, faces, sigma_c, sigma_s, n_iter=5, volume_preserve=true))]
fn bilateral<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    sigma_c: f64,
    sigma_s: f64,
    n_iter: i128,
    volume_preserve: bool,
) -> PyResult<Arr<'py, f64>> {
    let n_iter = uint(py, "n_iter", n_iter, 0)?;
    let mesh = args::mesh(vertices, faces)?;
    let p = BmdParams::default()
        .sigma_c(sigma_c)
        .sigma_s(sigma_s)
        .iterations(n_iter)
        .volume_preserve(volume_preserve);
    let out = crate::pool::detach(py, || bmd(&mesh, &p)).py_err()?;
    positions_out(py, out)
}

/// The mesh's vertices after `n_iter` passes of `f`, one of the Laplacian-family smoothers.
fn smoothed<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    n_iter: i128,
    f: impl FnOnce(&TriMesh, usize) -> wscg_math::Result<Vec<[f64; 3]>> + Send,
) -> PyResult<Arr<'py, f64>> {
    let n_iter = uint(py, "n_iter", n_iter, 0)?;
    let mesh = args::mesh(vertices, faces)?;
    let out = crate::pool::detach(py, || f(&mesh, n_iter)).py_err()?;
    positions_out(py, out)
}

/// Uniform (umbrella) Laplacian smoothing ``v + lam (mean(1-ring) - v)``.
#[pyfunction]
#[pyo3(signature = (vertices, faces, lam=0.5, n_iter=5))]
fn laplacian<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    lam: f64,
    n_iter: i128,
) -> PyResult<Arr<'py, f64>> {
    smoothed(py, vertices, faces, n_iter, |m, n| {
        smoothing::laplacian(m, lam, n)
    })
}

/// Taubin lambda/mu smoothing.
#[pyfunction]
#[pyo3(signature = (vertices, faces, lam=0.5, mu=-0.53, n_iter=5),
       text_signature = "(vertices, faces, lam=0.5, mu=-0.53, n_iter=5)")]
fn taubin<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    lam: f64,
    mu: f64,
    n_iter: i128,
) -> PyResult<Arr<'py, f64>> {
    smoothed(py, vertices, faces, n_iter, |m, n| {
        smoothing::taubin(m, lam, mu, n)
    })
}

/// HC-Laplacian smoothing (Vollmer, Mencl and Mueller 1999).
#[pyfunction]
#[pyo3(signature = (vertices, faces, alpha=0.0, beta=0.5, n_iter=5))]
fn hc_laplacian<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    alpha: f64,
    beta: f64,
    n_iter: i128,
) -> PyResult<Arr<'py, f64>> {
    smoothed(py, vertices, faces, n_iter, |m, n| {
        smoothing::hc_laplacian(m, alpha, beta, n)
    })
}

/// Paper eq. 3: the mean distance from every vertex of ``x`` to the nearest vertex of
/// ``gt``.
#[pyfunction]
fn mean_error(py: Python<'_>, x: &Bound<'_, PyAny>, gt: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (x, gt) = (args::array::<f64>("x", x)?, args::array::<f64>("gt", gt)?);
    let x = rows3("x", &values(&x), x.shape())?;
    let g = rows3("gt", &values(&gt), gt.shape())?;
    crate::pool::detach(py, || me(&x, &g)).py_err()
}

/// The mean distance from every vertex of ``x`` to the ground-truth *surface*
/// ``(vertices, faces)`` (nearest point on any triangle, not only the nearest vertex), so
/// that tangential drift along a face costs nothing. Single-precision BVH queries relative
/// to the mesh centre: exact to about 1e-7 of the mesh size.
#[pyfunction]
fn surface_error(
    py: Python<'_>,
    x: &Bound<'_, PyAny>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let x = args::array::<f64>("x", x)?;
    let x = rows3("x", &values(&x), x.shape())?;
    let mesh = args::mesh(vertices, faces)?;
    crate::pool::detach(py, || se(&x, &mesh)).py_err()
}

/// Mean vertex distance: the mean edge length.
#[pyfunction]
fn mvd(py: Python<'_>, vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<f64> {
    let mesh = args::mesh(vertices, faces)?;
    crate::pool::detach(py, || mean_vertex_distance(&mesh)).py_err()
}

/// ``(vertices, faces, colors)`` of a synthetic mesh with exact ground truth:
/// ``"cube"`` (unit cube, ``n x n`` grid per face, one saturated colour per face),
/// ``"cad"`` (a fandisk-like extruded profile with four convex creases, a concave one and
/// a quarter-circle fillet, ``n`` samples per unit length, one colour per patch, open at
/// z = 0 and z = 1; labels from :func:`cad_labels`), ``"sphere"`` (unit icosphere, ``n``
/// subdivisions) or ``"plane"`` (unit square with a colour step at x = 0.5). Colours are
/// 0..255 float32.
#[pyfunction]
#[pyo3(signature = (name="cube", n=30))]
fn make_mesh<'py>(py: Python<'py>, name: &str, n: i128) -> PyResult<MeshArrays<'py>> {
    let n: usize = uint(py, "n", n, 0)?;
    let m = crate::pool::detach(py, || match name {
        "cube" => synth::colored_cube(n),
        "cad" => synth::cad_part(n).map(|p| p.mesh),
        "sphere" => u32::try_from(n)
            .map_err(|_| wscg_math::Error::invalid("n", format!("{n} subdivisions")))
            .and_then(synth::icosphere),
        "plane" => synth::colored_plane(n),
        other => Err(wscg_math::Error::invalid(
            "name",
            format!("unknown mesh {other:?}"),
        )),
    })
    .py_err()?;
    mesh_out(py, m)
}

/// Per-vertex ground-truth labels of ``make_mesh("cad", n)``: the profile patch (0..6;
/// 5 is the fillet of radius 0.5 around the axis x = 0.5, y = 1.5) and the crease band (the
/// vertices within one sample spacing of a convex or concave crease).
#[pyfunction]
#[pyo3(signature = (n=20))]
fn cad_labels<'py>(py: Python<'py>, n: i128) -> PyResult<(Arr<'py, i64>, Arr<'py, bool>)> {
    let n = uint(py, "n", n, 0)?;
    let p = crate::pool::detach(py, || synth::cad_part(n)).py_err()?;
    let nv = p.patch.len();
    Ok((
        array(py, &[nv], p.patch.iter().map(|&x| i64::from(x)).collect())?,
        array(py, &[nv], p.crease_band)?,
    ))
}

/// Vertices moved by Gaussian noise of standard deviation ``sigma`` along the vertex
/// normals (or in all directions with ``isotropic``).
#[pyfunction]
#[pyo3(signature = (vertices, faces, sigma, isotropic=false, seed=0x9E37_79B9_7F4A_7C15))]
fn add_noise<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    sigma: f64,
    isotropic: bool,
    seed: i128,
) -> PyResult<Arr<'py, f64>> {
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let mesh = args::mesh(vertices, faces)?;
    let out =
        crate::pool::detach(py, || synth::add_noise(&mesh, sigma, isotropic, seed)).py_err()?;
    positions_out(py, out.positions)
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(jbmd, m)?)?;
    m.add_function(wrap_pyfunction!(bilateral, m)?)?;
    m.add_function(wrap_pyfunction!(laplacian, m)?)?;
    m.add_function(wrap_pyfunction!(taubin, m)?)?;
    m.add_function(wrap_pyfunction!(hc_laplacian, m)?)?;
    m.add_function(wrap_pyfunction!(mean_error, m)?)?;
    m.add_function(wrap_pyfunction!(surface_error, m)?)?;
    m.add_function(wrap_pyfunction!(mvd, m)?)?;
    m.add_function(wrap_pyfunction!(make_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(cad_labels, m)?)?;
    m.add_function(wrap_pyfunction!(add_noise, m)?)?;
    Ok(())
}
