//! Laplacian-family baselines of paper 04: the uniform umbrella operator (Field 1988),
//! Taubin's lambda/mu smoothing (1995) and the HC-Laplacian of Vollmer et al. (1999). All
//! work on the 1-ring and keep boundary vertices fixed, like the method.

use rayon::prelude::*;
use wscg_math::mesh::Adjacency;
use wscg_math::{Error, Result, TriMesh};

use crate::jbmd::{check_mesh, movable};

/// One umbrella step `v + f (mean(1-ring) - v)` of every movable vertex.
fn umbrella(adj: &Adjacency, pos: &[[f64; 3]], f: f64, moving: &[bool]) -> Vec<[f64; 3]> {
    (0..pos.len())
        .into_par_iter()
        .map(|i| {
            let nb = adj.neighbors(i);
            if !moving[i] || nb.is_empty() {
                return pos[i];
            }
            let mut m = [0.0; 3];
            for &j in nb {
                for a in 0..3 {
                    m[a] += pos[j as usize][a];
                }
            }
            let k = nb.len() as f64;
            std::array::from_fn(|a| pos[i][a] + f * (m[a] / k - pos[i][a]))
        })
        .collect()
}

fn check_factor(name: &'static str, v: f64) -> Result<()> {
    if v.is_finite() && v != 0.0 && v.abs() <= 2.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("must be finite, non-zero and |.| <= 2, got {v}"),
        ))
    }
}

/// Uniform Laplacian smoothing with factor `lambda` for `iterations` steps.
///
/// Errors: invalid mesh, `lambda` zero, non-finite or above 2 in magnitude.
pub fn laplacian(mesh: &TriMesh, lambda: f64, iterations: usize) -> Result<Vec<[f64; 3]>> {
    laplacian_trace(mesh, lambda, iterations, |_, _| {})
}

/// [`laplacian`] calling `observe(iteration, positions)` after every step.
pub fn laplacian_trace(
    mesh: &TriMesh,
    lambda: f64,
    iterations: usize,
    mut observe: impl FnMut(usize, &[[f64; 3]]),
) -> Result<Vec<[f64; 3]>> {
    check_mesh(mesh)?;
    check_factor("lambda", lambda)?;
    let (adj, moving) = (mesh.vertex_adjacency(), movable(mesh));
    let mut pos = mesh.positions.clone();
    for it in 0..iterations {
        wscg_math::cancel::check()?;
        pos = umbrella(&adj, &pos, lambda, &moving);
        observe(it + 1, &pos);
    }
    Ok(pos)
}

/// Taubin smoothing: a `lambda` step then a `mu` step (`mu < -lambda < 0`), per iteration.
///
/// Errors: invalid mesh or factors.
pub fn taubin(mesh: &TriMesh, lambda: f64, mu: f64, iterations: usize) -> Result<Vec<[f64; 3]>> {
    taubin_trace(mesh, lambda, mu, iterations, |_, _| {})
}

/// [`taubin`] calling `observe(iteration, positions)` after every `lambda`/`mu` pair.
pub fn taubin_trace(
    mesh: &TriMesh,
    lambda: f64,
    mu: f64,
    iterations: usize,
    mut observe: impl FnMut(usize, &[[f64; 3]]),
) -> Result<Vec<[f64; 3]>> {
    check_mesh(mesh)?;
    check_factor("lambda", lambda)?;
    check_factor("mu", mu)?;
    let (adj, moving) = (mesh.vertex_adjacency(), movable(mesh));
    let mut pos = mesh.positions.clone();
    for it in 0..iterations {
        wscg_math::cancel::check()?;
        pos = umbrella(&adj, &pos, lambda, &moving);
        pos = umbrella(&adj, &pos, mu, &moving);
        observe(it + 1, &pos);
    }
    Ok(pos)
}

/// HC-Laplacian (Vollmer, Mencl and Mueller 1999): a Laplacian step pulled back towards the
/// original (`alpha`) and the previous positions, then corrected by `beta`.
///
/// Errors: invalid mesh, `alpha` or `beta` outside `[0, 1]`.
pub fn hc_laplacian(
    mesh: &TriMesh,
    alpha: f64,
    beta: f64,
    iterations: usize,
) -> Result<Vec<[f64; 3]>> {
    check_mesh(mesh)?;
    if !((0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)) {
        return Err(Error::invalid("alpha, beta", "must be in [0, 1]"));
    }
    let adj = mesh.vertex_adjacency();
    let moving = movable(mesh);
    let orig = &mesh.positions;
    let mut q = orig.clone();
    for _ in 0..iterations {
        wscg_math::cancel::check()?;
        let p = umbrella(&adj, &q, 1.0, &moving);
        let b: Vec<[f64; 3]> = (0..p.len())
            .map(|i| {
                std::array::from_fn(|a| p[i][a] - (alpha * orig[i][a] + (1.0 - alpha) * q[i][a]))
            })
            .collect();
        q = (0..p.len())
            .into_par_iter()
            .map(|i| {
                let nb = adj.neighbors(i);
                if !moving[i] || nb.is_empty() {
                    return p[i];
                }
                let k = nb.len() as f64;
                std::array::from_fn(|a| {
                    let mb: f64 = nb.iter().map(|&j| b[j as usize][a]).sum::<f64>() / k;
                    p[i][a] - (beta * b[i][a] + (1.0 - beta) * mb)
                })
            })
            .collect();
    }
    Ok(q)
}
