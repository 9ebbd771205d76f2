//! The cells of the empty-space grid: `CELL^3` voxels each, with the range of values a
//! trilinear sample inside a cell can read (its voxels and a one-voxel apron), kept with the
//! field and shared by the sampler, the slicer and the Phong ray caster's bricks.

use rayon::prelude::*;

use super::voxels::Voxels;

/// Side of a cell in voxels.
pub(crate) const CELL: usize = 8;

/// Value range per cell, `x` fastest.
#[derive(Clone, Debug)]
pub(crate) struct CellRanges {
    pub cells: [usize; 3],
    pub range: Vec<(f32, f32)>,
}

impl CellRanges {
    pub(crate) fn new(v: &Voxels) -> Self {
        let dims = v.dims;
        let cells = dims.map(|d| d.div_ceil(CELL));
        let data = &v.data;
        let [nx, ny, nz] = dims;
        let range = (0..cells[0] * cells[1] * cells[2])
            .into_par_iter()
            .map(|c| {
                let (cx, cy, cz) = (
                    c % cells[0],
                    (c / cells[0]) % cells[1],
                    c / (cells[0] * cells[1]),
                );
                let span = |ci: usize, n: usize| {
                    (ci * CELL).saturating_sub(1)..((ci + 1) * CELL + 1).min(n)
                };
                let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                for z in span(cz, nz) {
                    for y in span(cy, ny) {
                        let row = &data[nx * (y + ny * z)..];
                        // The values are finite: plain comparisons (no NaN handling).
                        for &v in &row[span(cx, nx)] {
                            lo = if v < lo { v } else { lo };
                            hi = if v > hi { v } else { hi };
                        }
                    }
                }
                (lo, hi)
            })
            .collect();
        Self { cells, range }
    }
}
