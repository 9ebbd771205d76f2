//! The whole plate's microstructure from a small pool of tiles (paper 07, section 2.2: the
//! plate is "332 x 240 microstructures" of 450 x 450 µm): each cell of the plate shows one tile
//! of the pool, picked by a hash of the cell and the seed and turned by a multiple of 90
//! degrees, so no repetition is visible and memory holds the pool only. A flake belongs to the
//! cell it is shown in: the part of a tile's flakes inside the cell's square is what the cell
//! shows, so neighbouring cells never overlap.

use rayon::prelude::*;
use wscg_math::vec3::add_scaled;
use wscg_math::{Error, Result};

use super::flakes::{generate_tile, Flake, FlakeParams, FlakeTile};
use super::microstructure::{FlakeHit, Microstructure};

/// The microstructure of a plate.
#[derive(Clone, Debug)]
pub struct FlakePlate {
    /// Parameters the tiles were generated with.
    pub params: FlakeParams,
    /// Seed of the pool and of the cell assignment.
    pub seed: u64,
    pool: Vec<FlakeTile>,
    /// Plate size (µm).
    size: (f64, f64),
    /// Cells along x and y.
    cells: (usize, usize),
}

/// A flake as shown on the plate: its disc in plate coordinates (µm, plate centre at the
/// origin) and the square of the cell that clips it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedFlake {
    /// Identifier (the same as in [`FlakeHit::id`] and the renderer's flake-id buffer).
    pub id: u64,
    /// The disc, plate frame.
    pub disc: Flake,
    /// The cell's square: `(x0, y0, x1, y1)` (µm).
    pub cell: (f64, f64, f64, f64),
}

impl FlakePlate {
    /// Generates the pool of `params.tiles_in_pool` tiles (in parallel) for a plate of
    /// `size_mm`.
    ///
    /// Errors: invalid parameters or size, a failing tile ([`generate_tile`]).
    pub fn new(params: &FlakeParams, size_mm: (f64, f64), seed: u64) -> Result<Self> {
        params.validate()?;
        for v in [size_mm.0, size_mm.1] {
            wscg_math::error::ensure_positive("size_mm", v)?;
        }
        let size = (size_mm.0 * 1e3, size_mm.1 * 1e3);
        let l = params.tile_um;
        let cells = ((size.0 / l).ceil() as usize, (size.1 / l).ceil() as usize);
        if cells.0.saturating_mul(cells.1) > u32::MAX as usize {
            return Err(Error::LimitExceeded(format!(
                "{} x {} cells of {l} µm",
                cells.0, cells.1
            )));
        }
        let pool = (0..params.tiles_in_pool as u64)
            .into_par_iter()
            .map(|k| generate_tile(params, mix(seed, k)))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            params: *params,
            seed,
            pool,
            size,
            cells,
        })
    }

    /// The pool of tiles.
    pub fn pool(&self) -> &[FlakeTile] {
        &self.pool
    }

    /// Cells along x and y.
    pub fn cells(&self) -> (usize, usize) {
        self.cells
    }

    /// Flakes clamped to the layer's top over the pool (see [`FlakeTile::clamped`]).
    pub fn clamped(&self) -> usize {
        self.pool.iter().map(|t| t.clamped).sum()
    }

    /// The tile and quarter turns of cell `(i, j)`.
    pub fn cell_tile(&self, i: usize, j: usize) -> (usize, u8) {
        let h = mix(self.seed ^ 0x5eed_ce11, (j as u64) << 32 | i as u64);
        ((h % self.pool.len() as u64) as usize, (h >> 40) as u8 & 3)
    }

    /// Lower-left corner of cell `(i, j)` (µm).
    fn cell_origin(&self, i: usize, j: usize) -> (f64, f64) {
        let l = self.params.tile_um;
        (
            -0.5 * self.size.0 + i as f64 * l,
            -0.5 * self.size.1 + j as f64 * l,
        )
    }

    /// The cells that overlap the rectangle `[x0, x1] x [y0, y1]` (µm, plate frame): each
    /// cell's lower-left corner (µm), its tile in [`FlakePlate::pool`] and its quarter turns
    /// `k` (counter-clockwise about the cell's centre). A tile point `q` is shown at
    /// `corner + L/2 + R_k (q - L/2)` in the plate, clipped to the cell's square: the layout
    /// to export the plate to another renderer.
    pub fn cells_in(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<((f64, f64), usize, u8)> {
        let (Some((i0, i1)), Some((j0, j1))) =
            (self.cell_range(x0, x1, 0), self.cell_range(y0, y1, 1))
        else {
            return Vec::new();
        };
        let mut out = Vec::with_capacity((i1 - i0 + 1) * (j1 - j0 + 1));
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (t, k) = self.cell_tile(i, j);
                out.push((self.cell_origin(i, j), t, k));
            }
        }
        out
    }

    /// Every flake shown inside the rectangle `[x0, x1] x [y0, y1]` (µm, plate frame) whose
    /// disc lies wholly inside its cell (flakes cut by a cell's edge are left out).
    pub fn flakes_in(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<PlacedFlake> {
        let l = self.params.tile_um;
        let (Some((i0, i1)), Some((j0, j1))) =
            (self.cell_range(x0, x1, 0), self.cell_range(y0, y1, 1))
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (t, k) = self.cell_tile(i, j);
                let (ox, oy) = self.cell_origin(i, j);
                let tile = &self.pool[t];
                for (idx, f) in tile.flakes.iter().enumerate() {
                    let b = f.aabb();
                    if b.min[0] < 0.0 || b.max[0] >= l || b.min[1] < 0.0 || b.max[1] >= l {
                        continue;
                    }
                    let c = rotate([f.c[0] - 0.5 * l, f.c[1] - 0.5 * l, f.c[2]], k);
                    let c = [c[0] + ox + 0.5 * l, c[1] + oy + 0.5 * l, c[2]];
                    if c[0] < x0 || c[0] > x1 || c[1] < y0 || c[1] > y1 {
                        continue;
                    }
                    out.push(PlacedFlake {
                        id: self.id(i, j, idx as u32),
                        disc: Flake {
                            c,
                            n: rotate(f.n, k),
                            r: f.r,
                        },
                        cell: (ox, oy, ox + l, oy + l),
                    });
                }
            }
        }
        out
    }

    /// Inclusive range of cells along `axis` (0: x, 1: y) that `[lo, hi]` (µm) overlaps, or
    /// `None` when it misses the plate.
    fn cell_range(&self, lo: f64, hi: f64, axis: usize) -> Option<(usize, usize)> {
        let (half, n) = if axis == 0 {
            (0.5 * self.size.0, self.cells.0)
        } else {
            (0.5 * self.size.1, self.cells.1)
        };
        if !(hi >= -half && lo < half) {
            return None;
        }
        let l = self.params.tile_um;
        let c = |v: f64| (((v + half) / l).floor().max(0.0) as usize).min(n - 1);
        Some((c(lo), c(hi)))
    }

    fn id(&self, i: usize, j: usize, flake: u32) -> u64 {
        ((j * self.cells.0 + i) as u64) << 32 | flake as u64
    }
}

/// Turns `v` by `k` quarter turns about the z axis.
#[inline]
fn rotate(v: [f64; 3], k: u8) -> [f64; 3] {
    let [x, y, z] = v;
    match k & 3 {
        0 => v,
        1 => [-y, x, z],
        2 => [-x, -y, z],
        _ => [y, -x, z],
    }
}

/// SplitMix64 of `a` and `b`: tile seeds and the per-cell choice.
fn mix(a: u64, b: u64) -> u64 {
    let mut z = a ^ b.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Microstructure for FlakePlate {
    fn hit(&self, origin: [f64; 3], dir: [f64; 3], t_max: f64) -> Option<FlakeHit> {
        let l = self.params.tile_um;
        let end = add_scaled(origin, t_max, dir);
        let (Some((i0, i1)), Some((j0, j1))) = (
            self.cell_range(origin[0].min(end[0]), origin[0].max(end[0]), 0),
            self.cell_range(origin[1].min(end[1]), origin[1].max(end[1]), 1),
        ) else {
            return None;
        };
        let mut best: Option<FlakeHit> = None;
        let mut t_best = t_max;
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (t, k) = self.cell_tile(i, j);
                let (ox, oy) = self.cell_origin(i, j);
                // Into the tile's frame: translate, then undo the cell's turn about the centre.
                let inv = (4 - k) & 3;
                let o = rotate(
                    [
                        origin[0] - ox - 0.5 * l,
                        origin[1] - oy - 0.5 * l,
                        origin[2],
                    ],
                    inv,
                );
                let o = [o[0] + 0.5 * l, o[1] + 0.5 * l, o[2]];
                let d = rotate(dir, inv);
                if let Some((th, n, idx)) = self.pool[t].hit(o, d, t_best) {
                    t_best = th;
                    best = Some(FlakeHit {
                        t: th,
                        normal: rotate(n, k),
                        id: self.id(i, j, idx),
                    });
                }
            }
        }
        best
    }
}
