//! The paper's evaluation protocol (section 5), runnable on any grid.
//!
//! - [`compare_with_full_cd`]: Tables 1, 2 and 4: the reference is the central-difference
//!   normal on the *full* grid; the spline and LSN normals are computed on the grid sparsified
//!   by the paper's protocol (only endpoints of crossing edges kept).
//! - [`compare_with_exact`]: Table 3: the reference is the exact gradient of an analytic field.
//! - [`at_risk_configurations`]: the enumeration behind Table 4 (which of the 256
//!   configurations give an LSN normal 90 degrees or more away from central differences).
//! - [`percentile_isovalues`]: isovalues evenly spread over a percentile range of the data.

use std::collections::HashSet;

use wscg_math::{Error, Result, VolumeView};

use crate::extract::{marching_cubes, IsoMesh};
use crate::fields::{Field, Sampled};
use crate::grid::{sparsify_for_isosurface, ScalarGrid};
use crate::metrics::{angular_errors, class_rms, for_each_cell_vertex, rms, RmsSummary};
use crate::normals::{estimate_normals, AmbiguousRule, LsnParams, NormalMethod};

/// `count` isovalues evenly spaced between the `lo_pct` and `hi_pct` percentiles of the
/// defined samples (the paper uses "a large range" of isovalues, section 5.1, without giving
/// it; we use 20 or 100 values between the 5th and 95th percentiles).
pub fn percentile_isovalues(
    values: &[f32],
    count: usize,
    lo_pct: f64,
    hi_pct: f64,
) -> Result<Vec<f32>> {
    if count == 0 {
        return Err(Error::invalid("count", "need at least one isovalue"));
    }
    if !(0.0..=100.0).contains(&lo_pct) || !(lo_pct..=100.0).contains(&hi_pct) {
        return Err(Error::invalid(
            "lo_pct",
            format!("need 0 <= lo_pct <= hi_pct <= 100, got {lo_pct} and {hi_pct}"),
        ));
    }
    let mut v: Vec<f32> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return Err(Error::Empty("values"));
    }
    v.sort_by(f32::total_cmp);
    let at = |pct: f64| {
        let pos = pct / 100.0 * (v.len() - 1) as f64;
        let (i, f) = (pos.floor() as usize, pos - pos.floor());
        let j = (i + 1).min(v.len() - 1);
        v[i] as f64 * (1.0 - f) + v[j] as f64 * f
    };
    let (a, b) = (at(lo_pct), at(hi_pct));
    Ok((0..count)
        .map(|k| {
            let s = if count == 1 {
                0.5
            } else {
                k as f64 / (count - 1) as f64
            };
            (a + s * (b - a)) as f32
        })
        .collect())
}

/// One isovalue of the Table 1/2/4 protocol.
#[derive(Clone, Debug)]
pub struct SparseComparison {
    /// The isovalue.
    pub iso: f32,
    /// Vertices and triangles of the mesh (identical on the full and the sparse grid).
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Fraction of the samples the sparsification kept.
    pub kept_fraction: f64,
    /// Fraction of vertices where central differences are defined on the sparse grid.
    pub cd_defined_on_sparse: f64,
    /// Vertices where the full-grid central-difference reference itself is zero (excluded).
    pub reference_undefined: usize,
    /// Spline (sparse grid) vs full-grid central differences.
    pub spline: RmsSummary,
    /// LSN (sparse grid) vs full-grid central differences.
    pub lsn: RmsSummary,
    /// Undefined (zero) spline normals (the paper's claim: always 0).
    pub spline_undefined: usize,
    /// Undefined (zero) LSN normals (Table 5).
    pub lsn_undefined: usize,
    /// Per rotation class (section 5.3): spline and LSN.
    pub per_class: Vec<(RmsSummary, RmsSummary)>,
}

/// The Table 1/2/4 protocol at one isovalue: central differences on the full grid as the
/// reference, spline and LSN on the sparsified grid (with side hints, so the mesh is the same).
pub fn compare_with_full_cd(volume: VolumeView<'_, f32>, iso: f32) -> Result<SparseComparison> {
    let full = ScalarGrid::from_volume(volume)?;
    let reference = marching_cubes(&full, iso, NormalMethod::CentralDifference)?;
    let (sparse, sides) = sparsify_for_isosurface(volume, iso)?;
    let sg = ScalarGrid::from_volume(sparse.view())?.with_side_hint(&sides)?;
    let (dims, values) = (volume.dims(), volume.data());
    let sparse = sparse.data();
    let edges = &reference.vertex_edge;
    let (spline, s_stats) = estimate_normals(&sg, iso, edges, NormalMethod::spline())?;
    let (lsn, l_stats) = estimate_normals(&sg, iso, edges, NormalMethod::lsn())?;
    let (_, cd_stats) = estimate_normals(&sg, iso, edges, NormalMethod::CentralDifference)?;
    let es = angular_errors(&spline, &reference.normals)?;
    let el = angular_errors(&lsn, &reference.normals)?;
    let cs = class_rms(&reference, &es, dims)?;
    let cl = class_rms(&reference, &el, dims)?;
    let n = reference.vertices.len();
    Ok(SparseComparison {
        iso,
        vertices: n,
        triangles: reference.triangles.len(),
        kept_fraction: sparse.iter().filter(|v| !v.is_nan()).count() as f64 / values.len() as f64,
        cd_defined_on_sparse: if n > 0 {
            (n - cd_stats.undefined) as f64 / n as f64
        } else {
            f64::NAN
        },
        reference_undefined: reference.stats.undefined,
        spline: rms(&es),
        lsn: rms(&el),
        spline_undefined: s_stats.undefined,
        lsn_undefined: l_stats.undefined,
        per_class: cs.into_iter().zip(cl).collect(),
    })
}

/// RMS of the errors of the vertices lying in cells whose configuration is in `configs`
/// (Table 4 restricts the errors to the at-risk configurations this way).
pub fn restricted_rms(
    mesh: &IsoMesh,
    errors: &[f32],
    dims: [usize; 3],
    configs: &HashSet<u8>,
) -> Result<RmsSummary> {
    let mut chosen = vec![false; mesh.vertices.len()];
    for_each_cell_vertex(mesh, errors.len(), dims, |config, v| {
        if configs.contains(&config) {
            chosen[v] = true;
        }
    })?;
    let picked: Vec<f32> = errors
        .iter()
        .zip(&chosen)
        .filter(|(_, &c)| c)
        .map(|(&x, _)| x)
        .collect();
    Ok(rms(&picked))
}

/// Table 3 protocol on an analytic field: RMS angular error against the exact gradient.
#[derive(Clone, Debug)]
pub struct ExactComparison {
    /// Number of vertices.
    pub vertices: usize,
    /// Central differences on the full grid.
    pub cd_full: RmsSummary,
    /// Spline on the sparsified grid.
    pub spline: RmsSummary,
    /// LSN on the sparsified grid.
    pub lsn: RmsSummary,
}

/// Table 3 protocol: the mesh of `iso` on the sampled field, normals compared with the exact
/// gradient of `field` at the vertices.
pub fn compare_with_exact(field: &dyn Field, s: &Sampled, iso: f32) -> Result<ExactComparison> {
    let full = s.grid()?;
    let mesh = marching_cubes(&full, iso, NormalMethod::CentralDifference)?;
    let exact = s.exact_normals(field, &mesh.vertices);
    let (sparse, sides) = sparsify_for_isosurface(s.view(), iso)?;
    let sg = ScalarGrid::from_volume(sparse.view())?.with_side_hint(&sides)?;
    let e = &mesh.vertex_edge;
    let err = |n: &[[f32; 3]]| angular_errors(n, &exact).map(|x| rms(&x));
    Ok(ExactComparison {
        vertices: mesh.vertices.len(),
        cd_full: err(&mesh.normals)?,
        spline: err(&estimate_normals(&sg, iso, e, NormalMethod::spline())?.0)?,
        lsn: err(&estimate_normals(&sg, iso, e, NormalMethod::lsn())?.0)?,
    })
}

/// The Table 4 enumeration: the configurations whose [`config_divergence`] is at least
/// `threshold` radians (the paper's criterion is 90 degrees, `PI / 2`; it found 146 of 256
/// configurations at risk with Nielson's virtual mesh).
pub fn at_risk_configurations(rule: AmbiguousRule, threshold: f32) -> Vec<u8> {
    (0..=255u8)
        .filter(|&c| config_divergence(c, rule) >= threshold)
        .collect()
}

/// The largest angle (radians) between the LSN normal and the central-difference normal over
/// the vertices of the central cell, for configuration `config` with corner values +-1
/// (vertices at edge midpoints) embedded in a 4x4x4 grid by replicate padding; `PI` when an
/// LSN normal is undefined.
pub fn config_divergence(config: u8, rule: AmbiguousRule) -> f32 {
    let dims = [4usize; 3];
    let mut values = vec![0.0f32; 64];
    for z in 0..4 {
        for y in 0..4 {
            for x in 0..4 {
                let c = (x >= 2) as usize | ((y >= 2) as usize) << 1 | ((z >= 2) as usize) << 2;
                values[x + 4 * (y + 4 * z)] = if config >> c & 1 == 1 { 1.0 } else { -1.0 };
            }
        }
    }
    let Ok(g) = ScalarGrid::new(dims, &values) else {
        return f32::NAN;
    };
    let Ok(mesh) = marching_cubes(&g, 0.0, NormalMethod::CentralDifference) else {
        return f32::NAN;
    };
    let central: Vec<usize> = mesh
        .vertex_edge
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            let p = e.low();
            (0..3).all(|i| p[i] == 1 || (p[i] == 2 && i != e.axis as usize))
        })
        .map(|(i, _)| i)
        .collect();
    let edges: Vec<_> = central.iter().map(|&i| mesh.vertex_edge[i]).collect();
    let Ok((lsn, _)) = estimate_normals(
        &g,
        0.0,
        &edges,
        NormalMethod::Lsn(LsnParams {
            ambiguous_face: rule,
        }),
    ) else {
        return f32::NAN;
    };
    central.iter().zip(&lsn).fold(0.0f32, |m, (&i, &n)| {
        let a = crate::metrics::angle(n, mesh.normals[i]);
        m.max(if a.is_nan() { std::f32::consts::PI } else { a })
    })
}
