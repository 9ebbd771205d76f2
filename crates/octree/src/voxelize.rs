//! Exact surface voxelization into fragments (paper §3 "Voxelization").
//!
//! The paper rasterizes every triangle along its dominant axis with conservative
//! rasterization and writes one fragment per (covered pixel, triangle). The CPU pipeline
//! emits one fragment per (finest cell, triangle) pair whose closed boxes overlap, decided by
//! the exact separating-axis test of [`crate::overlap`]. Cells are visited column by column
//! along the triangle's dominant axis, testing only the few cells the triangle's plane
//! crosses in each column (Schwarz and Seidel 2010), so a large triangle costs its area, not
//! its bounding-box volume.

use rayon::prelude::*;
use wscg_math::vec3::{cross, dot, sub};
use wscg_math::{Error, Result};

use crate::cube::{morton, Cube};
use crate::overlap::{tri_box_overlap, CELL_HALF};

/// One voxel fragment: a finest cell overlapped by a triangle.
///
/// The paper's fragment (Table 1, 28 bytes) also carries the triangle's normal; here the
/// normal is looked up from the triangle index, which halves the sort's memory traffic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fragment {
    /// Morton code of the finest cell.
    pub morton: u64,
    /// Index of the triangle.
    pub prim: u32,
    /// Colour of the triangle at its point closest to the cell centre, alpha 255.
    pub rgba: [u8; 4],
}

/// Fragments sorted by `(morton, prim)` and the number of zero-area triangles skipped.
#[derive(Clone, Debug, Default)]
pub struct Fragments {
    /// The sorted fragments; each (cell, triangle) pair appears once.
    pub list: Vec<Fragment>,
    /// Triangles of zero area, which cover no cell and are left out of the octree.
    pub degenerate: usize,
}

/// Colour of a point with barycentric weights `w` from per-vertex colours, as RGBA8.
#[inline]
fn rgba_of(colors: Option<&[[f32; 3]]>, f: [u32; 3], w: [f64; 3]) -> [u8; 4] {
    let Some(c) = colors else {
        return DEFAULT_RGBA;
    };
    let mut out = [255u8; 4];
    for (k, o) in out.iter_mut().take(3).enumerate() {
        let v = w[0] * f64::from(c[f[0] as usize][k])
            + w[1] * f64::from(c[f[1] as usize][k])
            + w[2] * f64::from(c[f[2] as usize][k]);
        *o = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    }
    out
}

/// Colour of meshes without colours: light grey.
pub const DEFAULT_RGBA: [u8; 4] = [204, 204, 204, 255];

/// Barycentric weights of the point of triangle `(a, b, c)` closest to `p` (Ericson,
/// Real-Time Collision Detection, 5.1.5).
pub fn closest_barycentric(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    [1.0 - v - w, v, w]
}

/// Whether a triangle (in any units) has zero area: its normal is zero up to rounding.
#[inline]
pub fn is_degenerate(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let e0 = sub(b, a);
    let e1 = sub(c, a);
    let n = cross(e0, e1);
    let scale = dot(e0, e0).max(dot(e1, e1));
    dot(n, n) <= 1e-28 * scale * scale
}

/// Calls `emit(cell)` for every finest cell of a `2^depth` grid whose closed box (widened by
/// [`CELL_HALF`]) overlaps the triangle `g` given in grid units.
pub fn for_each_cell(g: [[f64; 3]; 3], depth: u8, mut emit: impl FnMut([u32; 3])) {
    let n = 1i64 << depth;
    let e = CELL_HALF - 0.5;
    let cell_range = |k: usize| {
        let lo = g[0][k].min(g[1][k]).min(g[2][k]);
        let hi = g[0][k].max(g[1][k]).max(g[2][k]);
        let a = ((lo - e).floor() as i64).clamp(0, n - 1);
        let b = ((hi + e).floor() as i64).clamp(0, n - 1);
        (a, b)
    };
    let r = [cell_range(0), cell_range(1), cell_range(2)];
    let nrm = cross(sub(g[1], g[0]), sub(g[2], g[0]));
    let w = (0..3)
        .max_by(|&i, &j| nrm[i].abs().total_cmp(&nrm[j].abs()))
        .unwrap_or(2);
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let d = dot(nrm, g[0]);
    for cu in r[u].0..=r[u].1 {
        for cv in r[v].0..=r[v].1 {
            // Range of the plane's w over the widened column (extremes at its corners).
            let mut wlo = f64::INFINITY;
            let mut whi = f64::NEG_INFINITY;
            for su in [cu as f64 - e, cu as f64 + 1.0 + e] {
                for sv in [cv as f64 - e, cv as f64 + 1.0 + e] {
                    let pw = (d - nrm[u] * su - nrm[v] * sv) / nrm[w];
                    wlo = wlo.min(pw);
                    whi = whi.max(pw);
                }
            }
            let a = ((wlo - e).floor() as i64).max(r[w].0);
            let b = ((whi + e).floor() as i64).min(r[w].1);
            for cw in a..=b {
                let mut cell = [0i64; 3];
                cell[u] = cu;
                cell[v] = cv;
                cell[w] = cw;
                let centre = cell.map(|c| c as f64 + 0.5);
                if tri_box_overlap(centre, CELL_HALF, g[0], g[1], g[2]) {
                    emit(cell.map(|c| c as u32));
                }
            }
        }
    }
}

/// Number of grid columns the voxelizer scans for a triangle `g` (grid units): the cells of its
/// bounding box projected along its dominant axis. Each column yields one to three
/// fragments, so the sum over a mesh bounds the fragment count within a small factor.
pub fn columns(g: [[f64; 3]; 3], depth: u8) -> f64 {
    let n = (1u64 << depth) as f64;
    let nrm = cross(sub(g[1], g[0]), sub(g[2], g[0]));
    let w = (0..3)
        .max_by(|&i, &j| nrm[i].abs().total_cmp(&nrm[j].abs()))
        .unwrap_or(2);
    let span = |k: usize| {
        let lo = g[0][k]
            .min(g[1][k])
            .min(g[2][k])
            .floor()
            .clamp(0.0, n - 1.0);
        let hi = g[0][k]
            .max(g[1][k])
            .max(g[2][k])
            .floor()
            .clamp(0.0, n - 1.0);
        hi - lo + 1.0
    };
    span((w + 1) % 3) * span((w + 2) % 3)
}

/// Most grid columns a voxelization may scan (about 32 GB of fragments).
pub const MAX_COLUMNS: f64 = 2e9;

/// Voxelizes `faces` of `positions` (world units) at level `depth` of `cube`: one fragment per
/// overlapped (cell, triangle), sorted by `(morton, prim)`. `colors` are per-vertex RGB in
/// `[0, 1]`. Triangles of zero area are skipped and counted. The caller validates the mesh
/// (indices in range, finite positions, the cube holding every vertex).
///
/// Errors: before any fragment is made, a voxelization that would scan more than
/// [`MAX_COLUMNS`] grid columns ([`Error::LimitExceeded`] naming the depth) or whose fragments
/// do not fit in memory ([`Error::OutOfMemory`] naming `depth`, see [`wscg_math::alloc`]).
pub fn voxelize(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    colors: Option<&[[f32; 3]]>,
    cube: &Cube,
    depth: u8,
) -> Result<Fragments> {
    let scan: f64 = faces
        .par_iter()
        .map(|f| columns(f.map(|i| cube.to_grid(positions[i as usize], depth)), depth))
        .sum();
    if scan > MAX_COLUMNS {
        return Err(Error::LimitExceeded(format!(
            "voxelizing at depth {depth} scans about {scan:.3e} cells (more than {MAX_COLUMNS:.0e} fragments, 16 bytes each): lower the depth"
        )));
    }
    wscg_math::alloc::ensure::<Fragment>("depth", scan as usize)?;
    const CHUNK: usize = 2048;
    let parts: Vec<(Vec<Fragment>, usize)> = faces
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(ci, chunk)| {
            let mut out = Vec::with_capacity(chunk.len() * 4);
            let mut degenerate = 0usize;
            for (j, f) in chunk.iter().enumerate() {
                let prim = (ci * CHUNK + j) as u32;
                let g = f.map(|i| cube.to_grid(positions[i as usize], depth));
                if is_degenerate(g[0], g[1], g[2]) {
                    degenerate += 1;
                    continue;
                }
                for_each_cell(g, depth, |cell| {
                    let rgba = if colors.is_some() {
                        let centre = cell.map(|c| f64::from(c) + 0.5);
                        rgba_of(colors, *f, closest_barycentric(centre, g[0], g[1], g[2]))
                    } else {
                        DEFAULT_RGBA
                    };
                    out.push(Fragment {
                        morton: morton(cell),
                        prim,
                        rgba,
                    });
                });
            }
            (out, degenerate)
        })
        .collect();
    let total = parts.iter().map(|p| p.0.len()).sum();
    let mut list = Vec::with_capacity(total);
    let mut degenerate = 0;
    for (p, d) in parts {
        list.extend_from_slice(&p);
        degenerate += d;
    }
    list.par_sort_unstable_by_key(|f| (f.morton, f.prim));
    Ok(Fragments { list, degenerate })
}
