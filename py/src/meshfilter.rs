//! `wscg._native.meshfilter`: bindings of `wscg-meshfilter` (paper 04, joint bilateral mesh
//! denoising). The documented API is `python/wscg/meshfilter.py`.

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use wscg_math::TriMesh;
use wscg_meshfilter::bmd::{bmd, BmdParams};
use wscg_meshfilter::metrics::{mean_error as me, mean_vertex_distance, surface_error as se};
use wscg_meshfilter::{smoothing, synth, JbmdParams};

use crate::convert::{array, mesh_in, rows3, values, Arr};
use crate::errors::{value_error, IntoPy};

fn positions_out<'py>(py: Python<'py>, p: Vec<[f64; 3]>) -> PyResult<Arr<'py, f64>> {
    let n = p.len();
    array(py, &[n, 3], p.concat())
}

type MeshArrays<'py> = (Arr<'py, f64>, Arr<'py, i64>, Arr<'py, f32>);

fn mesh_out<'py>(py: Python<'py>, m: TriMesh) -> PyResult<MeshArrays<'py>> {
    let nf = m.faces.len();
    let faces = m.faces.iter().flatten().map(|&i| i as i64).collect();
    let colors = m.colors.clone().unwrap_or_default();
    let nc = colors.len();
    Ok((
        positions_out(py, m.positions)?,
        array(py, &[nf, 3], faces)?,
        array(py, &[nc, 3], colors.concat())?,
    ))
}

/// Joint bilateral mesh denoising (see `wscg.meshfilter.jbmd`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn jbmd<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    colors: Option<PyReadonlyArrayDyn<f32>>,
    sigma_d: f64,
    sigma_o: f64,
    sigma_c: f64,
    lam: f64,
    n_neighbors: usize,
    n_iter: usize,
    anti_shrink: bool,
    rebuild_neighbors: bool,
) -> PyResult<Arr<'py, f64>> {
    let mesh = mesh_in(&vertices, &faces, colors.as_ref())?;
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
    let p = JbmdParams::default()
        .sigma_d(sigma_d)
        .sigma_o(sigma_o)
        .sigma_c(sigma_c)
        .lambda(lam)
        .k(n_neighbors)
        .iterations(n_iter)
        .anti_shrink(anti_shrink)
        .use_color(mesh.colors.is_some())
        .rebuild_neighbors(rebuild_neighbors);
    let out = crate::pool::detach(py, || wscg_meshfilter::jbmd(&mesh, &p)).py_err()?;
    positions_out(py, out)
}

/// Bilateral mesh denoising of Fleishman et al. (see `wscg.meshfilter.bilateral`).
#[pyfunction]
fn bilateral<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    sigma_c: f64,
    sigma_s: f64,
    n_iter: usize,
    volume_preserve: bool,
) -> PyResult<Arr<'py, f64>> {
    let mesh = mesh_in(&vertices, &faces, None)?;
    let p = BmdParams::default()
        .sigma_c(sigma_c)
        .sigma_s(sigma_s)
        .iterations(n_iter)
        .volume_preserve(volume_preserve);
    let out = crate::pool::detach(py, || bmd(&mesh, &p)).py_err()?;
    positions_out(py, out)
}

/// Laplacian-family smoothing: `kind` is "laplacian", "taubin" or "hc".
#[pyfunction]
fn smooth<'py>(
    py: Python<'py>,
    kind: &str,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    a: f64,
    b: f64,
    n_iter: usize,
) -> PyResult<Arr<'py, f64>> {
    let mesh = mesh_in(&vertices, &faces, None)?;
    let out = crate::pool::detach(py, || match kind {
        "laplacian" => smoothing::laplacian(&mesh, a, n_iter),
        "taubin" => smoothing::taubin(&mesh, a, b, n_iter),
        "hc" => smoothing::hc_laplacian(&mesh, a, b, n_iter),
        other => Err(wscg_math::Error::invalid("kind", format!("{other:?}"))),
    })
    .py_err()?;
    positions_out(py, out)
}

/// Paper eq. 3: mean distance to the nearest ground-truth vertex.
#[pyfunction]
fn mean_error(
    py: Python<'_>,
    x: PyReadonlyArrayDyn<f64>,
    gt: PyReadonlyArrayDyn<f64>,
) -> PyResult<f64> {
    let x = rows3("x", &values(&x), x.shape())?;
    let g = rows3("gt", &values(&gt), gt.shape())?;
    crate::pool::detach(py, || me(&x, &g)).py_err()
}

/// Mean distance to the ground-truth surface (parry BVH projection).
#[pyfunction]
fn surface_error(
    py: Python<'_>,
    x: PyReadonlyArrayDyn<f64>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
) -> PyResult<f64> {
    let x = rows3("x", &values(&x), x.shape())?;
    let mesh = mesh_in(&vertices, &faces, None)?;
    crate::pool::detach(py, || se(&x, &mesh)).py_err()
}

/// Mean vertex distance (mean edge length).
#[pyfunction]
fn mvd(
    py: Python<'_>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
) -> PyResult<f64> {
    let mesh = mesh_in(&vertices, &faces, None)?;
    crate::pool::detach(py, || mean_vertex_distance(&mesh)).py_err()
}

/// Synthetic meshes: "cube" (n), "cad" (n per unit length), "sphere" (subdivisions),
/// "plane" (n).
#[pyfunction]
fn make_mesh<'py>(py: Python<'py>, name: &str, n: usize) -> PyResult<MeshArrays<'py>> {
    let m = crate::pool::detach(py, || match name {
        "cube" => synth::colored_cube(n),
        "cad" => synth::cad_part(n).map(|p| p.mesh),
        "sphere" => synth::icosphere(n as u32),
        "plane" => synth::colored_plane(n),
        other => Err(wscg_math::Error::invalid(
            "name",
            format!("unknown mesh {other:?}"),
        )),
    })
    .py_err()?;
    mesh_out(py, m)
}

/// The CAD part's per-vertex labels: (patch, crease band).
#[pyfunction]
fn cad_labels<'py>(py: Python<'py>, n: usize) -> PyResult<(Arr<'py, i64>, Arr<'py, bool>)> {
    let p = crate::pool::detach(py, || synth::cad_part(n)).py_err()?;
    let nv = p.patch.len();
    Ok((
        array(py, &[nv], p.patch.iter().map(|&x| i64::from(x)).collect())?,
        array(py, &[nv], p.crease_band)?,
    ))
}

/// Noise along the vertex normals (or isotropic).
#[pyfunction]
fn add_noise<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    sigma: f64,
    isotropic: bool,
    seed: u64,
) -> PyResult<Arr<'py, f64>> {
    let mesh = mesh_in(&vertices, &faces, None)?;
    let out =
        crate::pool::detach(py, || synth::add_noise(&mesh, sigma, isotropic, seed)).py_err()?;
    positions_out(py, out.positions)
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(jbmd, m)?)?;
    m.add_function(wrap_pyfunction!(bilateral, m)?)?;
    m.add_function(wrap_pyfunction!(smooth, m)?)?;
    m.add_function(wrap_pyfunction!(mean_error, m)?)?;
    m.add_function(wrap_pyfunction!(surface_error, m)?)?;
    m.add_function(wrap_pyfunction!(mvd, m)?)?;
    m.add_function(wrap_pyfunction!(make_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(cad_labels, m)?)?;
    m.add_function(wrap_pyfunction!(add_noise, m)?)?;
    Ok(())
}
