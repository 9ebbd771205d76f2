//! Joint bilateral mesh denoising (paper 04, section 3). The paper's algorithm box is missing
//! from our copy of the text; the steps below are reconstructed from the text, its Fig. 2 and
//! Fleishman et al. 2003, which it extends (choices marked "(R)").
//!
//! Per iteration, with `G(t; s) = exp(-t^2 / (2 s^2))`, unit area-weighted vertex normals `n`
//! and the `k` nearest vertices `q_i` of every vertex `v` (Euclidean, `v` excluded (R),
//! recomputed every iteration (R)):
//!
//! 1. **Denoise** (Jacobi): `d_i = |v - q_i|`, `o_i = n . (q_i - v)`, `c_i = |c_v - c_i|`
//!    (0-255 RGB), `w_i = G(d_i; s_d) G(o_i; s_o) G(c_i; s_c)`, `x' = sum w_i o_i / sum w_i`,
//!    `v' = v + x' n`.
//! 2. **Local anti-shrinking** (paper eq. 2): `x'' = sum w'_i x'_(i) / sum w'_i` with
//!    `w'_i = G(|v' - q'_i|; s_d)` (R: the spatial term only) over the same neighbours'
//!    own shifts, `v'' = v' - x'' n`.
//! 3. `s_o <- lambda s_o`.
//!
//! Boundary vertices (on an edge with one face), isolated vertices and vertices whose
//! normal is undefined stay in place.

use rayon::prelude::*;
use wscg_math::knn_graph::knn_graph;
use wscg_math::vec3::{add_scaled, dist, dist2, dot, sub};
use wscg_math::{Error, Result, TriMesh};

use crate::params::JbmdParams;

/// Vertices that the filter moves: used by a face, not on the boundary.
pub fn movable(mesh: &TriMesh) -> Vec<bool> {
    let mut m = vec![false; mesh.num_vertices()];
    for f in &mesh.faces {
        for &i in f {
            m[i as usize] = true;
        }
    }
    for e in mesh.boundary_edges() {
        m[e[0] as usize] = false;
        m[e[1] as usize] = false;
    }
    m
}

/// Checks the mesh for filtering: non-empty, finite, valid indices and colour count.
pub(crate) fn check_mesh(mesh: &TriMesh) -> Result<()> {
    if mesh.num_vertices() == 0 || mesh.num_faces() == 0 {
        return Err(Error::Empty("mesh"));
    }
    mesh.validate()
}

/// Statistics of one iteration of [`jbmd_trace`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterStats {
    /// Offset range used in this iteration.
    pub sigma_o: f64,
    /// Largest vertex displacement of the iteration.
    pub max_move: f64,
}

/// Denoises `mesh` (paper 04): the new vertex positions, same connectivity.
///
/// Errors: an empty or invalid mesh, non-finite positions, bad parameters.
pub fn jbmd(mesh: &TriMesh, p: &JbmdParams) -> Result<Vec<[f64; 3]>> {
    jbmd_trace(mesh, p, |_, _, _| {}).map(|(v, _)| v)
}

/// [`jbmd`] calling `observe(iteration, positions, stats)` after every iteration (for error
/// curves such as the paper's Figs. 3, 5 and 8).
pub fn jbmd_trace(
    mesh: &TriMesh,
    p: &JbmdParams,
    mut observe: impl FnMut(usize, &[[f64; 3]], &IterStats),
) -> Result<(Vec<[f64; 3]>, Vec<IterStats>)> {
    p.validate()?;
    check_mesh(mesh)?;
    p.validate_for(mesh.num_vertices())?;
    let colors: Option<Vec<[f64; 3]>> = match (&mesh.colors, p.use_color) {
        (Some(c), true) => Some(c.iter().map(|v| v.map(|x| 255.0 * x as f64)).collect()),
        _ => None,
    };
    let moving = movable(mesh);
    let mut work = mesh.clone();
    let mut sigma_o = p.sigma_o;
    // Neighbours of vertex i: neighbors[i * k..(i + 1) * k] (fewer never happens: k < n).
    let mut neighbors: Vec<u32> = Vec::new();
    let k = p.k;
    // exp(-0.5 (d^2 / s_d^2 + o^2 / s_o^2 + c^2 / s_c^2)): one exponential per neighbour.
    let (id2, ic2) = (0.5 / (p.sigma_d * p.sigma_d), 0.5 / (p.sigma_c * p.sigma_c));
    let mut stats = Vec::with_capacity(p.iterations);
    for it in 0..p.iterations {
        wscg_math::cancel::check()?;
        let normals = work.vertex_normals();
        let v = &work.positions;
        if it == 0 || p.rebuild_neighbors {
            neighbors = knn_graph(v, k)?;
        }
        let io2 = 0.5 / (sigma_o * sigma_o);
        // Pass 1: signed shifts along the normals.
        let shift: Vec<f64> = (0..v.len())
            .into_par_iter()
            .map(|i| {
                let n = normals[i];
                if !moving[i] || dot(n, n) == 0.0 {
                    return 0.0;
                }
                let (mut sw, mut swo) = (0.0, 0.0);
                for &j in &neighbors[i * k..(i + 1) * k] {
                    let j = j as usize;
                    let d = sub(v[j], v[i]);
                    let o = dot(n, d);
                    let mut e = dot(d, d) * id2 + o * o * io2;
                    if let Some(c) = &colors {
                        e += dist2(c[i], c[j]) * ic2;
                    }
                    let w = (-e).exp();
                    sw += w;
                    swo += w * o;
                }
                if sw > 1e-300 {
                    swo / sw
                } else {
                    0.0
                }
            })
            .collect();
        let v1: Vec<[f64; 3]> = (0..v.len())
            .into_par_iter()
            .map(|i| add_scaled(v[i], shift[i], normals[i]))
            .collect();
        // Pass 2: local anti-shrinking by the neighbours' own shifts.
        let next: Vec<[f64; 3]> = if p.anti_shrink {
            (0..v.len())
                .into_par_iter()
                .map(|i| {
                    let n = normals[i];
                    if !moving[i] || dot(n, n) == 0.0 {
                        return v1[i];
                    }
                    let (mut sw, mut sx) = (0.0, 0.0);
                    for &j in &neighbors[i * k..(i + 1) * k] {
                        let j = j as usize;
                        let w = (-dist2(v1[j], v1[i]) * id2).exp();
                        sw += w;
                        sx += w * shift[j];
                    }
                    let back = if sw > 1e-300 { sx / sw } else { 0.0 };
                    add_scaled(v1[i], -back, n)
                })
                .collect()
        } else {
            v1
        };
        let max_move = next
            .par_iter()
            .zip(v)
            .map(|(a, b)| dist(*a, *b))
            .reduce(|| 0.0, f64::max);
        work.positions = next;
        let st = IterStats { sigma_o, max_move };
        observe(it + 1, &work.positions, &st);
        stats.push(st);
        sigma_o *= p.lambda;
    }
    Ok((work.positions, stats))
}
