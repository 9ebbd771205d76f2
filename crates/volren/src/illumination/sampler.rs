//! Sampling with empty-space skipping: the volume is split into cells of 8^3 voxels whose
//! value range (with the one-voxel apron a trilinear sample reads) is computed once per
//! volume; for a transfer function, a cell is empty when the extinction is zero over its whole
//! range. A sample in an empty cell is transparent whatever its value, so it is skipped
//! without reading the volume. Exact: images are unchanged.

use std::sync::OnceLock;

use rayon::prelude::*;

use super::classify::TransferFunction;
use super::field::{Interp, ScalarField};

/// Side of a cell in voxels.
pub(crate) const CELL: usize = 8;

/// Value range per cell, `x` fastest.
#[derive(Clone, Debug)]
pub(crate) struct CellRanges {
    pub cells: [usize; 3],
    pub range: Vec<(f32, f32)>,
}

impl CellRanges {
    fn new(field: &ScalarField) -> Self {
        let dims = field.dims();
        let cells = dims.map(|d| d.div_ceil(CELL));
        let data = field.data();
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
                        for &v in &row[span(cx, nx)] {
                            lo = lo.min(v);
                            hi = hi.max(v);
                        }
                    }
                }
                (lo, hi)
            })
            .collect();
        Self { cells, range }
    }
}

/// The cell ranges of a field, computed on first use and kept with it.
pub(crate) fn cell_ranges<'a>(
    field: &'a ScalarField,
    slot: &'a OnceLock<CellRanges>,
) -> &'a CellRanges {
    slot.get_or_init(|| CellRanges::new(field))
}

/// A field's sampler for one transfer function.
pub(crate) struct Sampler<'a> {
    field: &'a ScalarField,
    interp: Interp,
    cells: [usize; 3],
    empty: Vec<bool>,
    /// Cells whose 3 x 3 x 3 neighbourhood's value range is transparent: a segment shorter
    /// than a cell that starts in one is transparent whatever it interpolates (empty unless
    /// built for segments).
    deep_empty: Vec<bool>,
    /// True when the value 0 of the outside of the box is transparent.
    pub outside_transparent: bool,
}

impl<'a> Sampler<'a> {
    /// A sampler; `segments` also prepares [`Sampler::segment_empty`] (pre-integration).
    pub fn new(
        field: &'a ScalarField,
        tf: &TransferFunction,
        interp: Interp,
        segments: bool,
    ) -> Self {
        let cr = field.cell_ranges();
        let c = cr.cells;
        let cells = if segments { c[0] * c[1] * c[2] } else { 0 };
        let deep_empty = (0..cells)
            .into_par_iter()
            .map(|k| {
                let (x, y, z) = (k % c[0], (k / c[0]) % c[1], k / (c[0] * c[1]));
                let nb = |i: usize, n: usize| i.saturating_sub(1)..(i + 2).min(n);
                let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                for zz in nb(z, c[2]) {
                    for yy in nb(y, c[1]) {
                        for xx in nb(x, c[0]) {
                            let (a, b) = cr.range[xx + c[0] * (yy + c[1] * zz)];
                            lo = lo.min(a);
                            hi = hi.max(b);
                        }
                    }
                }
                // The box's outside (value 0) may be read by edge cells' segments too.
                let edge =
                    x == 0 || y == 0 || z == 0 || x + 1 == c[0] || y + 1 == c[1] || z + 1 == c[2];
                if edge {
                    lo = lo.min(0.0);
                }
                tf.transparent_on(lo, hi)
            })
            .collect();
        Self {
            field,
            interp,
            cells: c,
            empty: cr
                .range
                .iter()
                .map(|&(lo, hi)| tf.transparent_on(lo, hi))
                .collect(),
            deep_empty,
            outside_transparent: tf.transparent_at_zero(),
        }
    }

    #[inline]
    fn cell_of(&self, p: [f32; 3]) -> usize {
        let c = |a: usize| (((p[a] + 0.5).max(0.0) as usize) / CELL).min(self.cells[a] - 1);
        c(0) + self.cells[0] * (c(1) + self.cells[1] * c(2))
    }

    /// True if a segment of length at most one cell starting at `p` (inside the box) is
    /// certainly transparent.
    #[inline]
    pub fn segment_empty(&self, p: [f32; 3]) -> bool {
        self.deep_empty[self.cell_of(p)]
    }

    /// The sample at `p` (voxel coordinates), or `None` when it is certainly transparent:
    /// outside the box with a transparent 0, or in an empty cell.
    #[inline]
    pub fn visible(&self, p: [f32; 3]) -> Option<f32> {
        if !self.field.contains(p) {
            return if self.outside_transparent {
                None
            } else {
                Some(0.0)
            };
        }
        if self.empty[self.cell_of(p)] {
            return None;
        }
        Some(match self.interp {
            Interp::Trilinear => self.field.trilinear_inside(p),
            Interp::Nearest => self.field.nearest_inside(p),
        })
    }

    /// If `p` (inside the box) lies in an empty cell, the parameter `t > 0` at which the ray
    /// `p + t dir` leaves that cell.
    #[inline]
    pub fn empty_exit(&self, p: [f32; 3], dir: [f32; 3]) -> Option<f32> {
        if !self.field.contains(p) || !self.empty[self.cell_of(p)] {
            return None;
        }
        let mut t = f32::INFINITY;
        for a in 0..3 {
            let c = (((p[a] + 0.5).max(0.0) as usize) / CELL).min(self.cells[a] - 1) as f32;
            let lo = c * CELL as f32 - 0.5;
            let hi = lo + CELL as f32;
            if dir[a] > 0.0 {
                t = t.min((hi - p[a]) / dir[a]);
            } else if dir[a] < 0.0 {
                t = t.min((lo - p[a]) / dir[a]);
            }
        }
        (t.is_finite() && t > 0.0).then_some(t)
    }

    /// The parameter interval where the line `p + t dir` is inside the box, if any.
    pub fn clip(&self, p: [f32; 3], dir: [f32; 3]) -> Option<(f32, f32)> {
        let dims = self.field.dims();
        let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
        for a in 0..3 {
            let (lo, hi) = (-0.5f32, dims[a] as f32 - 0.5);
            if dir[a] == 0.0 {
                if p[a] < lo || p[a] >= hi {
                    return None;
                }
            } else {
                let (u, v) = ((lo - p[a]) / dir[a], (hi - p[a]) / dir[a]);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// The sample at `p` clamped to the box.
    #[inline]
    pub fn clamped(&self, p: [f32; 3]) -> f32 {
        self.field.sample_clamped(p, self.interp)
    }

    /// True if `p` is in the box.
    #[inline]
    pub fn contains(&self, p: [f32; 3]) -> bool {
        self.field.contains(p)
    }
}
