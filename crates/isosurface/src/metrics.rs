//! Error measures of the paper's evaluation (section 5): angular errors between normal fields
//! and their root mean square, over all vertices or per rotation class (section 5.3).

use wscg_math::{Error, Result};

use crate::extract::IsoMesh;
use std::collections::HashMap;

use crate::extract::EdgeId;
use crate::tables::{
    case_table, edge_axis, edge_low_offset, mc_rotation_class, number_of_rotation_classes,
};

/// The mesh vertices on the crossing edges of the cell with low corner `cell` and
/// configuration `config`.
fn cell_vertices<'a>(
    lookup: &'a HashMap<EdgeId, usize>,
    cell: [usize; 3],
    config: u8,
) -> impl Iterator<Item = usize> + 'a {
    let mask = case_table()[config as usize].edge_mask;
    (0..12)
        .filter(move |e| mask >> e & 1 == 1)
        .filter_map(move |e| {
            let o = edge_low_offset(e);
            let id = EdgeId {
                point: [0, 1, 2].map(|i| (cell[i] + o[i]) as u32),
                axis: edge_axis(e) as u8,
            };
            lookup.get(&id).copied()
        })
}

/// Angle in radians between each pair of vectors, `acos(clamp(a.b / |a||b|, -1, 1))`; NaN
/// where either vector is zero or not finite (an undefined normal).
pub fn angular_errors(a: &[[f32; 3]], b: &[[f32; 3]]) -> Result<Vec<f32>> {
    if a.len() != b.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} normals compared with {}",
            a.len(),
            b.len()
        )));
    }
    Ok(a.iter().zip(b).map(|(u, v)| angle(*u, *v)).collect())
}

/// Angle between two vectors in radians (NaN when either is zero or not finite).
pub fn angle(u: [f32; 3], v: [f32; 3]) -> f32 {
    let (u, v) = (u.map(|x| x as f64), v.map(|x| x as f64));
    let nu = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let nv = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if !(nu > 0.0 && nv > 0.0 && nu.is_finite() && nv.is_finite()) {
        return f32::NAN;
    }
    let c = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (nu * nv);
    c.clamp(-1.0, 1.0).acos() as f32
}

/// Root mean square of the defined (non-NaN) errors, with the counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RmsSummary {
    /// RMS of the defined errors (radians); NaN when there are none.
    pub rms: f64,
    /// Number of defined errors.
    pub count: usize,
    /// Number of NaN errors (an undefined estimate or reference), excluded from `rms`.
    pub undefined: usize,
}

/// RMS of `errors`, ignoring NaN (counted in [`RmsSummary::undefined`]).
pub fn rms(errors: &[f32]) -> RmsSummary {
    let mut s = RmsSummary::default();
    let mut sum = 0.0f64;
    for &e in errors {
        if e.is_nan() {
            s.undefined += 1;
        } else {
            sum += e as f64 * e as f64;
            s.count += 1;
        }
    }
    s.rms = if s.count > 0 {
        (sum / s.count as f64).sqrt()
    } else {
        f64::NAN
    };
    s
}

/// Calls `f(config, vertex)` for every crossing-edge vertex of every triangulated cell of
/// `mesh` (a vertex once per cell around it), after checking that `errors_len` matches the
/// vertex count.
pub(crate) fn for_each_cell_vertex(
    mesh: &IsoMesh,
    errors_len: usize,
    dims: [usize; 3],
    mut f: impl FnMut(u8, usize),
) -> Result<()> {
    if errors_len != mesh.vertices.len() {
        return Err(Error::ShapeMismatch(format!(
            "{errors_len} errors for {} vertices",
            mesh.vertices.len()
        )));
    }
    let lookup = mesh.edge_lookup();
    let [nx, ny, _] = dims;
    for &(cell, config) in &mesh.cell_config {
        let (x, y, z) = (cell % nx, (cell / nx) % ny, cell / (nx * ny));
        for v in cell_vertices(&lookup, [x, y, z], config) {
            f(config, v);
        }
    }
    Ok(())
}

/// Per-vertex errors grouped by the rotation class of the cells the vertex belongs to (a vertex
/// counts once for every active cell around it): one summary per class (section 5.3).
pub fn class_rms(mesh: &IsoMesh, errors: &[f32], dims: [usize; 3]) -> Result<Vec<RmsSummary>> {
    let mut groups: Vec<Vec<f32>> = vec![Vec::new(); number_of_rotation_classes()];
    for_each_cell_vertex(mesh, errors.len(), dims, |config, v| {
        groups[mc_rotation_class(config) as usize].push(errors[v]);
    })?;
    Ok(groups.iter().map(|g| rms(g)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles() {
        assert!(
            (angle([1.0, 0.0, 0.0], [0.0, 2.0, 0.0]) - std::f32::consts::FRAC_PI_2).abs() < 1e-6
        );
        assert_eq!(angle([1.0, 0.0, 0.0], [3.0, 0.0, 0.0]), 0.0);
        assert!(angle([0.0; 3], [1.0, 0.0, 0.0]).is_nan());
        let s = rms(&[3.0, f32::NAN, 4.0]);
        assert_eq!((s.count, s.undefined), (2, 1));
        assert!((s.rms - (12.5f64).sqrt()).abs() < 1e-12);
        assert!(angular_errors(&[[1.0; 3]], &[]).is_err());
    }
}
