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
use crate::grid::{check_iso, ScalarGrid};
use crate::normals::{estimate_normals, NormalMethod, NormalStats};
use crate::tables::{case_table, edge_axis, edge_low_offset};

/// The grid edge a vertex lies on: the edge from grid point `point` to `point + e_axis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EdgeId {
    /// Low end of the edge (sample indices x, y, z).
    pub point: [u32; 3],
    /// Axis of the edge (0 = x, 1 = y, 2 = z).
    pub axis: u8,
}

impl EdgeId {
    /// The low end as `usize` indices.
    #[inline]
    pub fn low(&self) -> [usize; 3] {
        self.point.map(|c| c as usize)
    }

    /// The high end as `usize` indices.
    #[inline]
    pub fn high(&self) -> [usize; 3] {
        let mut q = self.low();
        q[self.axis as usize] += 1;
        q
    }
}

/// A marching-cubes mesh with the grid edge of each vertex and per-vertex normals.
#[derive(Clone, Debug, Default)]
pub struct IsoMesh {
    /// Vertex positions in world units (sample index times spacing), x, y, z.
    pub vertices: Vec<[f32; 3]>,
    /// Triangles (vertex indices), wound so that the right-hand normal points toward
    /// increasing `f`.
    pub triangles: Vec<[u32; 3]>,
    /// Unit vertex normals pointing toward increasing `f`; `[0, 0, 0]` where the estimator is
    /// undefined (counted in `stats.undefined`); empty for [`NormalMethod::None`].
    pub normals: Vec<[f32; 3]>,
    /// The grid edge of each vertex.
    pub vertex_edge: Vec<EdgeId>,
    /// Each cell that produced triangles: flat index of its low corner and its configuration.
    pub cell_config: Vec<(usize, u8)>,
    /// Diagnostics of the extraction and of the normal estimation.
    pub stats: NormalStats,
}

impl IsoMesh {
    /// Map from grid edge to vertex index.
    pub fn edge_lookup(&self) -> std::collections::HashMap<EdgeId, usize> {
        self.vertex_edge
            .iter()
            .enumerate()
            .map(|(i, e)| (*e, i))
            .collect()
    }
}

/// Position of the vertex on the edge from `p` along `axis`, and its parameter `t`, when the
/// edge crosses `iso` (both samples defined, exactly one inside).
#[inline]
pub fn vertex_on_edge(
    g: &ScalarGrid,
    iso: f32,
    p: [usize; 3],
    axis: usize,
) -> Option<([f32; 3], f32)> {
    if p[axis] + 1 >= g.dims[axis] {
        return None;
    }
    let mut q = p;
    q[axis] += 1;
    let fp = g.value(p)?;
    let fq = g.value(q)?;
    if (fp >= iso) == (fq >= iso) {
        return None;
    }
    let t = (iso - fp) / (fq - fp);
    Some((position(g, p, axis, t), t))
}

/// World position of the point at parameter `t` on the edge from `p` along `axis`.
#[inline]
pub(crate) fn position(g: &ScalarGrid, p: [usize; 3], axis: usize, t: f32) -> [f32; 3] {
    let mut v = [0.0f32; 3];
    for i in 0..3 {
        let c = p[i] as f32 + if i == axis { t } else { 0.0 };
        v[i] = c * g.spacing[i];
    }
    v
}

/// Crossing bits of a sample's three forward edges, stored above the [`crate::grid::flag`] bits.
const CROSS: [u8; 3] = [8, 16, 32];

/// Marching cubes of `iso` on `grid` with vertex normals from `normals`.
///
/// Cells whose corner sides cannot be resolved (see [`crate::cell`]) are skipped and counted in
/// `stats.skipped_cells`. An isovalue outside the data range, or a grid without samples, gives
/// an empty mesh.
///
/// # Errors
/// An invalid grid (see [`ScalarGrid::validate`]) or a non-finite isovalue.
pub fn marching_cubes(grid: &ScalarGrid, iso: f32, normals: NormalMethod) -> Result<IsoMesh> {
    let mut mesh = extract(grid, iso)?;
    if !matches!(normals, NormalMethod::None) {
        let (n, stats) = estimate_normals(grid, iso, &mesh.vertex_edge, normals)?;
        mesh.normals = n;
        mesh.stats.undefined = stats.undefined;
        mesh.stats.fallback = stats.fallback;
    }
    Ok(mesh)
}

/// The extraction alone (vertices, triangles, vertex edges, cell configurations, skipped cells).
pub fn extract(grid: &ScalarGrid, iso: f32) -> Result<IsoMesh> {
    grid.validate()?;
    check_iso(iso)?;
    let [nx, ny, nz] = grid.dims;
    let plane = nx * ny;

    // Pass 1: per-sample flags and forward-edge crossings, counted per slice.
    let mut flags = vec![0u8; grid.len()];
    let counts: Vec<usize> = flags
        .par_chunks_mut(plane)
        .enumerate()
        .map(|(z, slice)| {
            let mut count = 0;
            for y in 0..ny {
                for x in 0..nx {
                    let i = x + nx * (y + ny * z);
                    let mut f = grid.flags(i, iso);
                    for (axis, bit) in CROSS.iter().enumerate() {
                        if vertex_on_edge_fast(grid, iso, [x, y, z], axis) {
                            f |= bit;
                            count += 1;
                        }
                    }
                    slice[x + nx * y] = f;
                }
            }
            count
        })
        .collect();

    // Pass 2: vertex numbering (slice z owns the vertices of its samples' forward edges).
    let mut offsets = Vec::with_capacity(nz + 1);
    let mut total = 0usize;
    offsets.push(0);
    for &c in &counts {
        total += c;
        offsets.push(total);
    }
    if total > u32::MAX as usize {
        return Err(wscg_math::Error::LimitExceeded(format!(
            "{total} vertices do not fit 32-bit triangle indices"
        )));
    }
    let mut vertices = vec![[0.0f32; 3]; total];
    let mut vertex_edge = vec![
        EdgeId {
            point: [0; 3],
            axis: 0
        };
        total
    ];
    let mut vchunks = Vec::with_capacity(nz);
    let mut echunks = Vec::with_capacity(nz);
    {
        let (mut vrest, mut erest) = (vertices.as_mut_slice(), vertex_edge.as_mut_slice());
        for &c in &counts {
            let (v, vr) = vrest.split_at_mut(c);
            let (e, er) = erest.split_at_mut(c);
            vchunks.push(v);
            echunks.push(e);
            vrest = vr;
            erest = er;
        }
    }

    // Pass 3: per slice, its vertices, then the triangles of the cell layer above it.
    struct Layer {
        triangles: Vec<[u32; 3]>,
        cells: Vec<(usize, u8)>,
        skipped: usize,
    }
    let table = case_table();
    let flags = &flags;
    let layers: Vec<Layer> = vchunks
        .into_par_iter()
        .zip(echunks)
        .enumerate()
        .map(|(z, (vout, eout))| {
            let mut k = 0;
            for y in 0..ny {
                for x in 0..nx {
                    let f = flags[x + nx * (y + ny * z)];
                    for (axis, bit) in CROSS.iter().enumerate() {
                        if f & bit != 0 {
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
            let mut layer = Layer {
                triangles: Vec::new(),
                cells: Vec::new(),
                skipped: 0,
            };
            if z + 1 >= nz {
                return layer;
            }
            let ids_lo = slice_ids(flags, plane, z, offsets[z]);
            let ids_hi = slice_ids(flags, plane, z + 1, offsets[z + 1]);
            for y in 0..ny - 1 {
                for x in 0..nx - 1 {
                    let mut cf = [0u8; 8];
                    for (c, slot) in cf.iter_mut().enumerate() {
                        let (ox, oy, oz) = (c & 1, (c >> 1) & 1, c >> 2);
                        *slot = flags[(x + ox) + nx * ((y + oy) + ny * (z + oz))];
                    }
                    match resolve_cell(&cf) {
                        CellState::Empty => {}
                        CellState::Unresolved => layer.skipped += 1,
                        CellState::Active(config) => {
                            let entry = &table[config as usize];
                            for tri in &entry.triangles {
                                let id = |e: u8| {
                                    let e = e as usize;
                                    let o = edge_low_offset(e);
                                    let ids = if o[2] == 0 { &ids_lo } else { &ids_hi };
                                    ids[((x + o[0]) + nx * (y + o[1])) * 3 + edge_axis(e)]
                                };
                                layer.triangles.push([id(tri[0]), id(tri[1]), id(tri[2])]);
                            }
                            layer.cells.push((x + nx * (y + ny * z), config));
                        }
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
    let ntri: usize = layers.iter().map(|l| l.triangles.len()).sum();
    mesh.triangles.reserve(ntri);
    for l in layers {
        mesh.triangles.extend_from_slice(&l.triangles);
        mesh.cell_config.extend_from_slice(&l.cells);
        mesh.stats.skipped_cells += l.skipped;
    }
    Ok(mesh)
}

/// Whether the forward edge of `p` along `axis` crosses (cheaper than [`vertex_on_edge`]).
#[inline]
fn vertex_on_edge_fast(g: &ScalarGrid, iso: f32, p: [usize; 3], axis: usize) -> bool {
    if p[axis] + 1 >= g.dims[axis] {
        return false;
    }
    let i = g.index(p);
    let step = [1, g.dims[0], g.dims[0] * g.dims[1]][axis];
    let (fp, fq) = (g.values[i], g.values[i + step]);
    // NaN compares false both ways, so a missing endpoint never crosses.
    (fp >= iso && fq < iso) || (fp < iso && fq >= iso)
}

/// Global vertex ids of the forward edges of slice `z` (3 per sample, `u32::MAX` where none),
/// numbered in the same order as pass 3 writes them.
fn slice_ids(flags: &[u8], plane: usize, z: usize, first: usize) -> Vec<u32> {
    let mut ids = vec![u32::MAX; plane * 3];
    let mut next = first as u32;
    for (i, &f) in flags[z * plane..(z + 1) * plane].iter().enumerate() {
        for (axis, bit) in CROSS.iter().enumerate() {
            if f & bit != 0 {
                ids[i * 3 + axis] = next;
                next += 1;
            }
        }
    }
    ids
}
