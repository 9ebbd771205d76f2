//! Error measures of paper 04: the mean distance to the nearest ground-truth vertex (eq. 3),
//! the corresponding-vertex error, and the mean vertex distance (MVD) that scales the
//! parameters.

use rayon::prelude::*;
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
