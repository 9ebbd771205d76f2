//! Bilateral mesh denoising of Fleishman, Drori and Cohen-Or (2003), the baseline paper 04
//! extends, with the optional global volume preservation of Desbrun et al. (1999).
//!
//! For every vertex `v` with unit normal `n`: the vertices `q` of the connected surface within
//! `rho = 2 sigma_c` (breadth-first over the edges), `t = |v - q|`, `h = n . (v - q)`,
//! `w = G(t; sigma_c) G(h; sigma_s)`, and `v <- v - n sum(w h) / sum(w)`. With volume
//! preservation every iteration ends by scaling the mesh about its centroid by
//! `(V_0 / V_n)^(1/3)` (`V` the signed volume).

use rayon::prelude::*;
use wscg_math::vec3::{add_scaled, dot, sub};
use wscg_math::{Error, Result, TriMesh};

use crate::jbmd::{check_mesh, movable};

wscg_math::params! {
    /// Parameters of [`bmd`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct BmdParams {
        /// Spatial range `sigma_c` (the neighbourhood radius is `2 sigma_c`).
        pub sigma_c: f64,
        /// Offset range `sigma_s`.
        pub sigma_s: f64,
        /// Iterations.
        pub iterations: usize,
        /// Rescale to the initial volume after every iteration.
        pub volume_preserve: bool,
    }
}

impl BmdParams {
    /// Ranges relative to the mean vertex distance `mvd`: `sigma_c = mvd` (a neighbourhood
    /// radius of two edges), `sigma_s = 0.5 mvd`, 10 iterations, no volume rescaling.
    pub fn from_mvd(mvd: f64) -> Self {
        Self {
            sigma_c: mvd,
            sigma_s: 0.5 * mvd,
            iterations: 10,
            volume_preserve: false,
        }
    }
}

/// [`BmdParams::from_mvd`] for a mesh whose mean vertex distance is 1.
impl Default for BmdParams {
    fn default() -> Self {
        Self::from_mvd(1.0)
    }
}

impl BmdParams {
    /// Errors: `sigma_c` or `sigma_s` not finite and positive (whether the mesh encloses a
    /// volume for `volume_preserve` is checked by [`bmd`]).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("sigma_c", self.sigma_c), ("sigma_s", self.sigma_s)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and > 0, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// Runs bilateral mesh denoising, calling `observe(iteration, positions)` after each
/// iteration.
///
/// Errors: invalid mesh, non-positive ranges, volume preservation on a mesh of zero volume.
pub fn bmd_trace(
    mesh: &TriMesh,
    p: &BmdParams,
    mut observe: impl FnMut(usize, &[[f64; 3]]),
) -> Result<Vec<[f64; 3]>> {
    p.validate()?;
    check_mesh(mesh)?;
    let v0 = mesh.signed_volume();
    if p.volume_preserve && v0.abs() < 1e-300 {
        return Err(Error::invalid(
            "volume_preserve",
            "the mesh encloses no volume",
        ));
    }
    let adj = mesh.vertex_adjacency();
    let moving = movable(mesh);
    let rho2 = (2.0 * p.sigma_c).powi(2);
    let (ic2, is2) = (0.5 / (p.sigma_c * p.sigma_c), 0.5 / (p.sigma_s * p.sigma_s));
    let mut work = mesh.clone();
    for it in 0..p.iterations {
        wscg_math::cancel::check()?;
        let normals = work.vertex_normals();
        let pos = &work.positions;
        let next: Vec<[f64; 3]> = (0..pos.len())
            .into_par_iter()
            .map_init(
                || (Vec::new(), std::collections::HashSet::new()),
                |(stack, seen): &mut (Vec<usize>, std::collections::HashSet<usize>), i| {
                    let n = normals[i];
                    if !moving[i] || n == [0.0; 3] {
                        return pos[i];
                    }
                    stack.clear();
                    seen.clear();
                    stack.push(i);
                    seen.insert(i);
                    let (mut sw, mut swh) = (0.0, 0.0);
                    while let Some(a) = stack.pop() {
                        for &b in adj.neighbors(a) {
                            let b = b as usize;
                            if !seen.insert(b) {
                                continue;
                            }
                            let d = sub(pos[i], pos[b]);
                            let t2 = dot(d, d);
                            if t2 > rho2 {
                                continue;
                            }
                            stack.push(b);
                            let h = dot(n, d);
                            // G(t; sigma_c) G(h; sigma_s) as one exponential.
                            let w = (-t2 * ic2 - h * h * is2).exp();
                            sw += w;
                            swh += w * h;
                        }
                    }
                    let s = if sw > 1e-300 { swh / sw } else { 0.0 };
                    add_scaled(pos[i], -s, n)
                },
            )
            .collect();
        work.positions = next;
        if p.volume_preserve {
            let vn = work.signed_volume();
            if vn.abs() > 1e-300 && (v0 / vn) > 0.0 {
                let beta = (v0 / vn).cbrt();
                let c = work.centroid().unwrap_or([0.0; 3]);
                for q in work.positions.iter_mut() {
                    *q = std::array::from_fn(|k| c[k] + beta * (q[k] - c[k]));
                }
            }
        }
        observe(it + 1, &work.positions);
    }
    Ok(work.positions)
}

/// [`bmd_trace`] without an observer.
pub fn bmd(mesh: &TriMesh, p: &BmdParams) -> Result<Vec<[f64; 3]>> {
    bmd_trace(mesh, p, |_, _| {})
}
