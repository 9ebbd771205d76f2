//! Error measures of paper 04: the mean distance to the nearest ground-truth vertex (eq. 3),
//! the mean distance to the ground-truth surface, the corresponding-vertex error, and the
//! mean vertex distance (MVD) that scales the parameters.

use parry3d::math::Vector as PVec;
use parry3d::query::PointQuery;
use parry3d::shape::TriMesh as ParryMesh;
use rayon::prelude::*;
use wscg_math::error::ensure_finite;
use wscg_math::knn::KdTree;
use wscg_math::vec3::dist;
use wscg_math::{Error, Result, TriMesh};

/// Paper eq. 3: `(1/n) sum_i min_p |x_i - g_p|`, the mean distance from every vertex to the
/// nearest ground-truth vertex (kd-tree).
///
/// Errors: empty or non-finite inputs.
pub fn mean_error(x: &[[f64; 3]], gt: &[[f64; 3]]) -> Result<f64> {
    if x.is_empty() {
        return Err(Error::Empty("x"));
    }
    let tree = KdTree::new(gt)?;
    let sum: f64 = x.par_iter().map(|p| tree.nearest(p).1).sum();
    Ok(sum / x.len() as f64)
}

/// The mean distance from every vertex of `x` to the ground-truth **surface** (not only its
/// vertices): eq. 3 with the nearest point of any triangle in place of the nearest vertex,
/// so that tangential drift along a flat face costs nothing. Queried through parry's
/// bounding-volume hierarchy in single precision, relative to the centre of the
/// ground-truth bounding box, so distances are exact to about `1e-7` of the mesh size.
///
/// Errors: empty `x`, a ground-truth mesh without triangles, non-finite inputs.
pub fn surface_error(x: &[[f64; 3]], gt: &TriMesh) -> Result<f64> {
    if x.is_empty() {
        return Err(Error::Empty("x"));
    }
    if gt.faces.is_empty() {
        return Err(Error::Empty("ground-truth faces"));
    }
    gt.validate()?;
    ensure_finite("x", x.as_flattened())?;
    let (lo, hi) = gt
        .bounding_box()
        .ok_or(Error::Empty("ground-truth vertices"))?;
    let c = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
    let local = |p: &[f64; 3]| {
        PVec::new(
            (p[0] - c[0]) as f32,
            (p[1] - c[1]) as f32,
            (p[2] - c[2]) as f32,
        )
    };
    let mesh = ParryMesh::new(gt.positions.iter().map(local).collect(), gt.faces.clone())
        .map_err(|e| Error::invalid("ground truth", format!("invalid mesh: {e:?}")))?;
    let sum: f64 = x
        .par_iter()
        .map(|p| {
            let q = local(p);
            let proj = mesh.project_local_point(q, false);
            f64::from((proj.point - q).length())
        })
        .sum();
    Ok(sum / x.len() as f64)
}

/// Mean distance between corresponding vertices, over the vertices `mask` selects (all when
/// `None`).
///
/// Errors: length mismatch, an empty selection.
pub fn corresponding_error(x: &[[f64; 3]], gt: &[[f64; 3]], mask: Option<&[bool]>) -> Result<f64> {
    if x.len() != gt.len() || mask.is_some_and(|m| m.len() != x.len()) {
        return Err(Error::ShapeMismatch(format!(
            "{} positions, {} ground-truth positions",
            x.len(),
            gt.len()
        )));
    }
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, (a, b)) in x.iter().zip(gt).enumerate() {
        if mask.is_none_or(|m| m[i]) {
            sum += dist(*a, *b);
            n += 1;
        }
    }
    if n == 0 {
        return Err(Error::Empty("selection"));
    }
    Ok(sum / n as f64)
}

/// The mean vertex distance: the mean edge length of the mesh.
///
/// Errors: a mesh without edges.
pub fn mean_vertex_distance(mesh: &TriMesh) -> Result<f64> {
    let edges = mesh.edges();
    if edges.is_empty() {
        return Err(Error::Empty("mesh edges"));
    }
    let p = &mesh.positions;
    let sum: f64 = edges
        .iter()
        .map(|e| dist(p[e[0] as usize], p[e[1] as usize]))
        .sum();
    Ok(sum / edges.len() as f64)
}
