//! Marching cubes on a (sparse) grid: one welded vertex per crossing edge, triangles from the
//! case table of [`crate::tables`], cells with missing corners resolved as in [`crate::cell`].
//!
//! An edge `(p, q = p + e_a)` crosses the isosurface when both samples are defined and exactly
//! one of them is inside (`f >= iso`); its vertex is `p + t h_a e_a` with
//! `t = (iso - f(p)) / (f(q) - f(p))` in `[0, 1]`. `t` is 0 or 1 when a sample equals the
//! isovalue: the vertex then sits on a grid point and triangles around it are degenerate
//! (the situation of the paper's Fig. 2b and Table 5).
//!
//! The extraction runs in parallel over z slices (three passes: sample flags and crossing
//! counts per slice, a prefix sum for the vertex numbering, then vertices and triangles per
//! slice), and its output does not depend on the number of threads.

use rayon::prelude::*;
use wscg_math::Result;

use crate::cell::{resolve_cell, CellState};
pub use crate::edge::{vertex_on_edge, EdgeId};
use crate::grid::{check_iso, flag, Sample, ScalarGrid};
use crate::normals::spline::{self, cell_contribution};
use crate::normals::{estimate_normals, unit, EdgeVertex, NormalMethod, NormalStats, SplineParams};
use crate::tables::{case_table, edge_axis, edge_corners, edge_low_offset};

/// A marching-cubes mesh with the grid edge of each vertex and per-vertex normals; positions
/// and normals have the grid's sample type (`f32` by default, `f64` for an `f64` grid).
#[derive(Clone, Debug, Default)]
pub struct IsoMesh<T = f32> {
    /// Vertex positions in world units (sample index times spacing), x, y, z.
    pub vertices: Vec<[T; 3]>,
    /// Triangles (vertex indices), wound so that the right-hand normal points toward
    /// increasing `f`.
    pub triangles: Vec<[u32; 3]>,
    /// Unit vertex normals pointing toward increasing `f`; `[0, 0, 0]` where the estimator is
    /// undefined (counted in `stats.undefined`); empty for [`NormalMethod::None`].
    pub normals: Vec<[T; 3]>,
    /// The grid edge of each vertex.
    pub vertex_edge: Vec<EdgeId>,
    /// Each cell that produced triangles: flat index of its low corner and its configuration.
    pub cell_config: Vec<(usize, u8)>,
    /// Diagnostics of the extraction and of the normal estimation.
    pub stats: NormalStats,
}

impl<T> IsoMesh<T> {
    /// Map from grid edge to vertex index.
    pub fn edge_lookup(&self) -> std::collections::HashMap<EdgeId, usize> {
        self.vertex_edge
            .iter()
            .enumerate()
            .map(|(i, e)| (*e, i))
            .collect()
    }
}

/// Crossing bits of a sample's three forward edges, stored above the [`crate::grid::flag`] bits.
const CROSS_SHIFT: u8 = 3;

/// Marching cubes of `iso` on `grid` with vertex normals from `normals`.
///
/// Cells whose corner sides cannot be resolved (see [`crate::cell`]) are skipped and counted in
/// `stats.skipped_cells`. An isovalue outside the data range, or a grid without samples, gives
/// an empty mesh. Spline normals are accumulated cell by cell during the extraction (the paper's
/// "extended MC context"); the other estimators run per vertex afterwards
/// ([`estimate_normals`]). Both routes give the same normals.
///
/// # Errors
/// An invalid grid (see [`ScalarGrid::validate`]) or a non-finite isovalue.
pub fn marching_cubes<T: Sample>(
    grid: &ScalarGrid<T>,
    iso: T,
    normals: NormalMethod,
) -> Result<IsoMesh<T>> {
    normals.validate()?;
    match normals {
        NormalMethod::Spline(opts) => run(grid, iso, Some(opts)),
        NormalMethod::None => run(grid, iso, None),
        other => {
            let mut mesh = run(grid, iso, None)?;
            let (n, stats) = estimate_normals(grid, iso, &mesh.vertex_edge, other)?;
            mesh.normals = n;
            mesh.stats.undefined = stats.undefined;
            mesh.stats.fallback = stats.fallback;
            Ok(mesh)
        }
    }
}

/// The extraction alone (vertices, triangles, vertex edges, cell configurations, skipped cells).
pub fn extract<T: Sample>(grid: &ScalarGrid<T>, iso: T) -> Result<IsoMesh<T>> {
    run(grid, iso, None)
}

/// Whether the samples `a` and `b` are both defined and on different sides of `iso`.
#[inline(always)]
fn crosses<T: Sample>(a: T, b: T, iso: T) -> bool {
    // NaN compares false both ways, so a missing endpoint never crosses.
    (a >= iso && b < iso) || (a < iso && b >= iso)
}

/// Per local edge: the row of the cell it starts on (`dy + 2 dz`), its x offset and its axis.
const EDGE_ROWS: [(usize, usize, usize); 12] = {
    let mut t = [(0, 0, 0); 12];
    let mut e = 0;
    while e < 12 {
        let o = edge_low_offset(e);
        t[e] = (o[1] + 2 * o[2], o[0], edge_axis(e));
        e += 1;
    }
    t
};

/// What one cell layer (cells between slices z and z + 1) produced.
struct Layer {
    triangles: Vec<[u32; 3]>,
    cells: Vec<(usize, u8)>,
    skipped: usize,
    /// Spline gradient sums of the vertices of slice z (indexed from the slice's first vertex).
    low: Vec<[f64; 3]>,
    /// Spline gradient sums of the vertices of slice z + 1.
    high: Vec<[f64; 3]>,
}

fn run<T: Sample>(
    grid: &ScalarGrid<T>,
    iso: T,
    spline: Option<SplineParams>,
) -> Result<IsoMesh<T>> {
    grid.validate()?;
    check_iso(iso)?;
    let [nx, ny, nz] = grid.dims;
    let plane = nx * ny;
    let values = grid.values;

    // Pass 1: per-sample flags and forward-edge crossings, counted per row.
    let mut flags = vec![0u8; grid.len()];
    let mut row_counts = vec![0u32; ny * nz];
    flags
        .par_chunks_mut(plane)
        .zip(row_counts.par_chunks_mut(ny))
        .enumerate()
        .for_each(|(z, (slice, counts))| {
            for y in 0..ny {
                let base = nx * (y + ny * z);
                let r0 = &values[base..base + nx];
                let ry = (y + 1 < ny).then(|| &values[base + nx..base + 2 * nx]);
                let rz = (z + 1 < nz).then(|| &values[base + plane..base + plane + nx]);
                let out = &mut slice[nx * y..nx * (y + 1)];
                let mut count = 0;
                for x in 0..nx {
                    let v = r0[x];
                    let mut f = grid.flags(base + x, iso);
                    let mut c = 0u8;
                    if x + 1 < nx && crosses(v, r0[x + 1], iso) {
                        c |= 1;
                    }
                    if let Some(ry) = ry {
                        if crosses(v, ry[x], iso) {
                            c |= 2;
                        }
                    }
                    if let Some(rz) = rz {
                        if crosses(v, rz[x], iso) {
                            c |= 4;
                        }
                    }
                    count += c.count_ones();
                    f |= c << CROSS_SHIFT;
                    out[x] = f;
                }
                counts[y] = count;
            }
        });

    // Pass 2: vertex numbering, row by row (x fastest, then the edge axis).
    let mut row_offsets = Vec::with_capacity(ny * nz + 1);
    let mut total = 0usize;
    for &c in &row_counts {
        row_offsets.push(total);
        total += c as usize;
    }
    row_offsets.push(total);
    if total > u32::MAX as usize {
        return Err(wscg_math::Error::LimitExceeded(format!(
            "{total} vertices do not fit 32-bit triangle indices"
        )));
    }
    let slice_offset = |z: usize| row_offsets[z * ny];
    let mut vertices = vec![[T::default(); 3]; total];
    let mut vertex_edge = vec![
        EdgeId {
            point: [0; 3],
            axis: 0
        };
        total
    ];
    let vchunks = split_by(&mut vertices, nz, |z| slice_offset(z + 1) - slice_offset(z));
    let echunks = split_by(&mut vertex_edge, nz, |z| {
        slice_offset(z + 1) - slice_offset(z)
    });

    // Pass 3: per slice, its vertices, then the triangles of the cell layer above it.
    let table = case_table();
    let flags = &flags;
    let inv_h = spline::inverse_spacing(grid);
    let layers: Vec<Layer> = vchunks
        .into_par_iter()
        .zip(echunks)
        .enumerate()
        .map(|(z, (vout, eout))| {
            let mut k = 0;
            for y in 0..ny {
                for x in 0..nx {
                    let c = flags[x + nx * (y + ny * z)] >> CROSS_SHIFT;
                    for axis in 0..3 {
                        if c >> axis & 1 == 1 {
                            let p = [x, y, z];
                            let (pos, _) = vertex_on_edge(grid, iso, p, axis)
                                .expect("crossing flag implies a vertex");
                            vout[k] = pos;
                            eout[k] = EdgeId {
                                point: [x as u32, y as u32, z as u32],
                                axis: axis as u8,
                            };
                            k += 1;
                        }
                    }
                }
            }
            let owned = vout.len();
            let mut layer = Layer {
                triangles: Vec::new(),
                cells: Vec::new(),
                skipped: 0,
                low: Vec::new(),
                high: Vec::new(),
            };
            if z + 1 >= nz {
                return layer;
            }
            let first = [slice_offset(z), slice_offset(z + 1)];
            if spline.is_some() {
                layer.low = vec![[0.0; 3]; owned];
                layer.high = vec![[0.0; 3]; slice_offset(z + 2) - first[1]];
            }
            for y in 0..ny - 1 {
                // The four sample rows of the cell row: (y, z), (y+1, z), (y, z+1), (y+1, z+1).
                let rows = [(y, z), (y + 1, z), (y, z + 1), (y + 1, z + 1)];
                let starts = rows.map(|(yy, zz)| nx * (yy + ny * zz));
                let fr = starts.map(|s| &flags[s..s + nx]);
                let vr = starts.map(|s| &values[s..s + nx]);
                let mut run = rows.map(|(yy, zz)| row_offsets[yy + ny * zz] as u32);
                for x in 0..nx - 1 {
                    // The corners' flags in corner order, kept in a register (byte c is
                    // corner c), and the crossings of each row's sample x.
                    let mut word = 0u64;
                    // Crossing counts of sample x per row, a byte each (at most 3).
                    let mut crossings = 0u32;
                    let (mut all, mut any) = (0xffu8, 0u8);
                    let mut config = 0u8;
                    for (r, row) in fr.iter().enumerate() {
                        let (f0, f1) = (row[x], row[x + 1]);
                        word |= (f0 as u64) << (16 * r) | (f1 as u64) << (16 * r + 8);
                        crossings |= (f0 >> CROSS_SHIFT).count_ones() << (8 * r);
                        all &= f0 & f1;
                        any |= f0 | f1;
                        config |= ((f0 & flag::INSIDE) >> 2) << (2 * r);
                        config |= ((f1 & flag::INSIDE) >> 2) << (2 * r + 1);
                    }
                    let cf = word.to_le_bytes();
                    let state = if all & flag::KNOWN != 0 {
                        // Fast path: every corner's side known (defined or hinted).
                        if config == 0 || config == 0xff {
                            CellState::Empty
                        } else if all & flag::DEFINED != 0 {
                            CellState::Active(config)
                        } else {
                            resolve_cell(&cf)
                        }
                    } else if any & flag::KNOWN == 0 {
                        CellState::Empty
                    } else {
                        resolve_cell(&cf)
                    };
                    match state {
                        CellState::Empty => {}
                        CellState::Unresolved => layer.skipped += 1,
                        CellState::Active(config) => {
                            // Vertex ids: the row's running count at x, plus the crossings
                            // of sample x when the edge starts at x + 1, plus the crossings
                            // of lower axes at the edge's own sample.
                            let id = |e: usize| {
                                let (r, ox, axis) = EDGE_ROWS[e];
                                let f = fr[r][x + ox] >> CROSS_SHIFT;
                                run[r]
                                    + ox as u32 * (crossings >> (8 * r) & 0xff)
                                    + (f & ((1u8 << axis) - 1)).count_ones()
                            };
                            let entry = &table[config as usize];
                            for tri in &entry.triangles {
                                let t = tri.map(|e| id(e as usize));
                                layer.triangles.push(t);
                            }
                            layer.cells.push((x + nx * (y + ny * z), config));
                            if let Some(opts) = &spline {
                                let mut vals = [T::default(); 8];
                                for (c, v) in vals.iter_mut().enumerate() {
                                    *v = vr[(c >> 1) & 3][x + (c & 1)];
                                }
                                for e in (0..12).filter(|e| entry.edge_mask >> e & 1 == 1) {
                                    let (kp, kq) = edge_corners(e);
                                    let (fp, fq) = (vals[kp], vals[kq]);
                                    let t = ((iso - fp) / (fq - fp)).to_f64();
                                    let v = id(e) as usize;
                                    let acc = if EDGE_ROWS[e].0 < 2 {
                                        &mut layer.low[v - first[0]]
                                    } else {
                                        &mut layer.high[v - first[1]]
                                    };
                                    cell_contribution(&vals, config, e, t, inv_h, opts, acc);
                                }
                            }
                        }
                    }
                    for (r, count) in run.iter_mut().enumerate() {
                        *count += crossings >> (8 * r) & 0xff;
                    }
                }
            }
            layer
        })
        .collect();

    let mut mesh = IsoMesh {
        vertices,
        vertex_edge,
        ..Default::default()
    };
    if spline.is_some() {
        let mut normals = vec![[T::default(); 3]; total];
        let nchunks = split_by(&mut normals, nz, |z| slice_offset(z + 1) - slice_offset(z));
        let fallbacks: usize = nchunks
            .into_par_iter()
            .enumerate()
            .map(|(z, out)| {
                let first = slice_offset(z);
                let mut fallbacks = 0;
                for (i, n) in out.iter_mut().enumerate() {
                    let mut sum = layers[z].low.get(i).copied().unwrap_or([0.0; 3]);
                    if z > 0 {
                        let h = layers[z - 1].high[i];
                        sum = [sum[0] + h[0], sum[1] + h[1], sum[2] + h[2]];
                    }
                    *n = match unit(sum) {
                        Some(u) => u,
                        None => {
                            fallbacks += 1;
                            let v = EdgeVertex::new(grid, iso, &mesh.vertex_edge[first + i])
                                .expect("a mesh vertex lies on a crossing edge");
                            spline::fallback(grid, &v)
                        }
                    };
                }
                fallbacks
            })
            .sum();
        mesh.normals = normals;
        mesh.stats.fallback = fallbacks;
    }
    let ntri: usize = layers.iter().map(|l| l.triangles.len()).sum();
    mesh.triangles.reserve(ntri);
    for l in layers {
        mesh.triangles.extend_from_slice(&l.triangles);
        mesh.cell_config.extend_from_slice(&l.cells);
        mesh.stats.skipped_cells += l.skipped;
    }
    let iso = iso.to_f64();
    log::debug!(
        "marching cubes at level {iso}: {} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    if mesh.stats.skipped_cells > 0 {
        log::info!(
            "marching cubes at level {iso}: {} cells with missing corners whose sides could not \
             be inferred were skipped (give a side hint to triangulate them)",
            mesh.stats.skipped_cells
        );
    }
    Ok(mesh)
}

/// Splits `v` into `n` consecutive mutable chunks of lengths `len(0), len(1), ...`.
fn split_by<T>(v: &mut [T], n: usize, len: impl Fn(usize) -> usize) -> Vec<&mut [T]> {
    let mut out = Vec::with_capacity(n);
    let mut rest = v;
    for i in 0..n {
        let (head, tail) = rest.split_at_mut(len(i));
        out.push(head);
        rest = tail;
    }
    out
}
