//! Sampling with empty-space skipping: the volume is split into cells of 8^3 voxels whose
//! value range (with the one-voxel apron a trilinear sample reads) is computed once per
//! volume; for a transfer function, a cell is empty when the extinction is zero over its whole
//! range. A sample in an empty cell is transparent whatever its value, so it is skipped
//! without reading the volume. Each cell also stores its Chebyshev distance to the nearest
//! non-empty cell, so a ray leaves a whole cube of empty cells in one step, and a row of a
//! slice skips the run of pixels that stay in one ([`Sampler::transparent_run`]). Exact:
//! images are unchanged.

use std::sync::OnceLock;

use rayon::prelude::*;

use super::cells::CELL;
use super::classify::TransferFunction;
use super::field::{Interp, ScalarField};

/// Distance kept from the faces of cells and of the box when runs of transparent pixels are
/// counted, in voxels: far above the rounding of single-precision sample positions, which the
/// caller computes independently.
const MARGIN: f32 = 1e-2;

/// Where a sample point lies (see [`Sampler::locate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Loc {
    /// Outside the volume's box.
    Outside,
    /// In an empty cell (per-axis index): transparent whatever the value.
    Empty([usize; 3]),
    /// In a cell that may be visible.
    Cell([usize; 3]),
}

/// A field's sampler for one transfer function.
pub(crate) struct Sampler<'a> {
    field: &'a ScalarField,
    interp: Interp,
    cells: [usize; 3],
    empty: Vec<bool>,
    /// Per cell, the Chebyshev distance in cells to the nearest cell that is not empty (0 for
    /// those; capped at 255): the cube of cells of radius `clear - 1` around a cell is empty.
    /// Built on the first ray step (the slice renderer never needs it).
    clear: OnceLock<Vec<u8>>,
    /// Cells whose 3 x 3 x 3 neighbourhood's value range is transparent: a segment shorter
    /// than a cell that starts in one is transparent whatever it interpolates (empty unless
    /// built for segments).
    deep_empty: Vec<bool>,
    /// [`Sampler::clear`] for the cells of `deep_empty` (built on first use).
    deep_clear: OnceLock<Vec<u8>>,
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
        let empty: Vec<bool> = cr
            .range
            .iter()
            .map(|&(lo, hi)| tf.transparent_on(lo, hi))
            .collect();
        Self {
            field,
            interp,
            cells: c,
            clear: OnceLock::new(),
            empty,
            deep_empty,
            deep_clear: OnceLock::new(),
            outside_transparent: tf.transparent_at_zero(),
        }
    }

    /// The cell of `p` (the cell of its nearest voxel), per axis.
    #[inline]
    fn cell3(&self, p: [f32; 3]) -> [usize; 3] {
        std::array::from_fn(|a| (((p[a] + 0.5).max(0.0) as usize) / CELL).min(self.cells[a] - 1))
    }

    #[inline]
    fn cell_of(&self, p: [f32; 3]) -> usize {
        let c = self.cell3(p);
        c[0] + self.cells[0] * (c[1] + self.cells[1] * c[2])
    }

    /// True if a segment of length at most one cell starting at `p` (inside the box) is
    /// certainly transparent.
    #[inline]
    pub fn segment_empty(&self, p: [f32; 3]) -> bool {
        self.deep_empty[self.cell_of(p)]
    }

    /// Where `p` (voxel coordinates) lies: outside the box, in an empty cell or in a cell
    /// that may be visible.
    #[inline(always)]
    pub fn locate(&self, p: [f32; 3]) -> Loc {
        if !self.field.contains(p) {
            return Loc::Outside;
        }
        let c = self.cell3(p);
        if self.empty[c[0] + self.cells[0] * (c[1] + self.cells[1] * c[2])] {
            Loc::Empty(c)
        } else {
            Loc::Cell(c)
        }
    }

    /// The sample at `p`, known to be inside the box.
    #[inline(always)]
    pub fn value(&self, p: [f32; 3]) -> f32 {
        self.field.sample_inside(p, self.interp)
    }

    /// The sample at `p` (voxel coordinates), or `None` when it is certainly transparent:
    /// outside the box with a transparent 0, or in an empty cell.
    #[inline(always)]
    pub fn visible(&self, p: [f32; 3]) -> Option<f32> {
        match self.locate(p) {
            Loc::Outside => (!self.outside_transparent).then_some(0.0),
            Loc::Empty(_) => None,
            Loc::Cell(_) => Some(self.value(p)),
        }
    }

    /// For `p` in the empty cell `c` (per axis): the parameter `t > 0` at which the ray
    /// `p + t dir` leaves the cube of empty cells around `c` (the Chebyshev clearance of the
    /// cell, clipped to the box), so one step crosses many empty cells.
    #[inline]
    pub fn empty_exit(&self, p: [f32; 3], dir: [f32; 3], c: [usize; 3]) -> Option<f32> {
        let [lo_c, hi_c] = self.empty_cube(c, false);
        let mut t = f32::INFINITY;
        for a in 0..3 {
            let lo = (lo_c[a] * CELL) as f32 - 0.5;
            let hi = (hi_c[a] * CELL) as f32 - 0.5;
            if dir[a] > 0.0 {
                t = t.min((hi - p[a]) / dir[a]);
            } else if dir[a] < 0.0 {
                t = t.min((lo - p[a]) / dir[a]);
            }
        }
        (t.is_finite() && t > 0.0).then_some(t)
    }

    /// The cube of empty cells around the empty cell `c`, clipped to the grid, as per-axis
    /// cell ranges `[lo, hi)`: the cells within the Chebyshev clearance of `c` minus one.
    /// With `segments`, of the cells where a short segment is transparent instead.
    #[inline]
    fn empty_cube(&self, c: [usize; 3], segments: bool) -> [[usize; 3]; 2] {
        let i = c[0] + self.cells[0] * (c[1] + self.cells[1] * c[2]);
        let clear = if segments {
            self.deep_clear
                .get_or_init(|| chebyshev_clearance(self.cells, &self.deep_empty))
        } else {
            self.clear
                .get_or_init(|| chebyshev_clearance(self.cells, &self.empty))
        };
        let r = (clear[i] as usize).max(1) - 1;
        [
            c.map(|ca| ca.saturating_sub(r)),
            std::array::from_fn(|a| (c[a] + r + 1).min(self.cells[a])),
        ]
    }

    /// How many consecutive pixels of a slice row are certainly transparent, starting with the
    /// one whose samples lie in the box `[lo, hi]` (voxel coordinates), the next pixel's
    /// samples being those moved by `dx`: the pixels whose samples all stay in the cube of
    /// empty cells around the cell of the box's centre (extended past the grid's faces when
    /// the outside of the volume is transparent). 0 when that cell is not empty or the box
    /// leaves the cube; `usize::MAX` when the row never leaves it. Every sample of a counted
    /// pixel is one that [`Sampler::visible`] returns `None` for.
    ///
    /// With `segments` (a sampler built for segments), the points are the fronts of
    /// segments no longer than a cell, and the cube's cells those of
    /// [`Sampler::segment_empty`]: every counted front is outside the box with a transparent
    /// outside or starts a transparent segment.
    pub fn transparent_run(
        &self,
        lo: [f32; 3],
        hi: [f32; 3],
        dx: [f32; 3],
        segments: bool,
    ) -> usize {
        let mid: [f32; 3] = std::array::from_fn(|a| 0.5 * (lo[a] + hi[a]));
        if !mid.iter().all(|v| v.is_finite()) {
            return 0;
        }
        let dims = self.field.dims();
        // Wholly outside the box (and transparent there): until the row comes back in.
        let mut outside = 0f32;
        if self.outside_transparent {
            for a in 0..3 {
                let (face_lo, face_hi) = (-0.5 - MARGIN, dims[a] as f32 - 0.5 + MARGIN);
                let k = if hi[a] < face_lo {
                    if dx[a] > 0.0 {
                        (face_lo - hi[a]) / dx[a]
                    } else {
                        f32::INFINITY
                    }
                } else if lo[a] > face_hi {
                    if dx[a] < 0.0 {
                        (face_hi - lo[a]) / dx[a]
                    } else {
                        f32::INFINITY
                    }
                } else {
                    continue;
                };
                outside = outside.max(k);
            }
        }
        let c = self.cell3(mid);
        let flags = if segments {
            &self.deep_empty
        } else {
            &self.empty
        };
        let k = if flags[c[0] + self.cells[0] * (c[1] + self.cells[1] * c[2])] {
            self.cube_run(c, lo, hi, dx, segments)
        } else {
            0.0
        };
        let k = k.max(outside);
        if k <= 0.0 {
            0
        } else if k >= usize::MAX as f32 {
            usize::MAX
        } else {
            k as usize + 1
        }
    }

    /// [`Sampler::transparent_run`] in the empty cube around the empty cell `c`: the largest
    /// `k` for which the box moved by `k dx` stays in the cube (0 when the box is not in it).
    fn cube_run(
        &self,
        c: [usize; 3],
        lo: [f32; 3],
        hi: [f32; 3],
        dx: [f32; 3],
        segments: bool,
    ) -> f32 {
        let [lo_c, hi_c] = self.empty_cube(c, segments);
        let dims = self.field.dims();
        let mut k = f32::INFINITY;
        for a in 0..3 {
            let open = self.outside_transparent;
            let face_lo = if open && lo_c[a] == 0 {
                f32::NEG_INFINITY
            } else {
                (lo_c[a] * CELL) as f32 - 0.5 + MARGIN
            };
            let face_hi = if open && hi_c[a] == self.cells[a] {
                f32::INFINITY
            } else {
                // Outside the box the value 0 is read, which may be visible.
                ((hi_c[a] * CELL).min(dims[a]) as f32 - 0.5) - MARGIN
            };
            if lo[a] < face_lo || hi[a] > face_hi {
                return 0.0;
            }
            if dx[a] > 0.0 {
                k = k.min((face_hi - hi[a]) / dx[a]);
            } else if dx[a] < 0.0 {
                k = k.min((face_lo - lo[a]) / dx[a]);
            }
        }
        // The box itself is in the cube: at least this pixel.
        k.max(f32::MIN_POSITIVE)
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

/// The Chebyshev distance (in cells, capped at 255) from every cell to the nearest cell that is
/// not empty, by a breadth-first search over the 26 neighbours from all non-empty cells (a
/// step of the search changes each index by at most one, so the number of steps is the
/// Chebyshev distance). Cells beyond the grid count as empty; a grid without a non-empty cell
/// is clear throughout.
fn chebyshev_clearance(cells: [usize; 3], empty: &[bool]) -> Vec<u8> {
    let mut d: Vec<u8> = empty.iter().map(|&e| if e { u8::MAX } else { 0 }).collect();
    let mut queue: std::collections::VecDeque<usize> =
        (0..empty.len()).filter(|&i| !empty[i]).collect();
    let [cx, cy, cz] = cells;
    while let Some(i) = queue.pop_front() {
        let next = d[i].saturating_add(1);
        if next == u8::MAX {
            continue;
        }
        let (x, y, z) = (i % cx, (i / cx) % cy, i / (cx * cy));
        for zz in z.saturating_sub(1)..(z + 2).min(cz) {
            for yy in y.saturating_sub(1)..(y + 2).min(cy) {
                for xx in x.saturating_sub(1)..(x + 2).min(cx) {
                    let j = xx + cx * (yy + cy * zz);
                    if d[j] > next {
                        d[j] = next;
                        queue.push_back(j);
                    }
                }
            }
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::Volume;

    /// A field of `background` with a few voxels of 1 (each makes its cell and the cells
    /// sharing its apron visible), and a transfer function transparent on `[0.3, 0.7]` only,
    /// or from 0 to 0.7 (`open`: the outside of the box is transparent).
    fn speckled(background: f32, open: bool) -> (ScalarField, TransferFunction) {
        let dims = [64, 56, 48];
        let n = dims.iter().product::<usize>();
        let mut data = vec![background; n];
        let u = wscg_math::rng::uniform_vec(3, 3 * 6, 0.0, 1.0).unwrap();
        for k in 0..6 {
            let v: [usize; 3] = std::array::from_fn(|a| (u[3 * k + a] * dims[a] as f64) as usize);
            data[v[0] + dims[0] * (v[1] + dims[1] * v[2])] = 1.0;
        }
        let field = ScalarField::from_f32(Volume::new(dims, [1.0; 3], data).unwrap()).unwrap();
        let a0 = if open { 0.0 } else { 0.4 };
        let tf = TransferFunction::from_points(
            &[
                (0.0, [1.0, 1.0, 1.0, a0]),
                (0.25, [1.0, 1.0, 1.0, a0]),
                (0.3, [0.0; 4]),
                (0.7, [0.0; 4]),
                (0.75, [1.0, 0.5, 0.2, 0.8]),
                (1.0, [1.0, 0.5, 0.2, 0.8]),
            ],
            256,
        )
        .unwrap();
        (field, tf)
    }

    /// Every sample of every pixel a transparent run counts is invisible (brute force over
    /// random rows and segments, with the outside of the box transparent or not), and the
    /// runs cover most of the transparent pixels; the same for the fronts of short
    /// pre-integrated segments.
    #[test]
    fn transparent_runs_hold_only_invisible_samples() {
        for (background, open, segments) in [
            (0.0f32, true, false),
            (0.5, false, false),
            (0.0, true, true),
            (0.5, false, true),
        ] {
            let (field, tf) = speckled(background, open);
            let s = Sampler::new(&field, &tf, Interp::Trilinear, segments);
            assert_eq!(s.outside_transparent, open);
            let u = wscg_math::rng::uniform_vec(11, 9 * 400, 0.0, 1.0).unwrap();
            let (mut counted, mut transparent) = (0usize, 0usize);
            for q in u.chunks(9) {
                // Rows start in and around the box, step 0.3-3 voxels per pixel; segments
                // up to 2 voxels long.
                let p: [f32; 3] = std::array::from_fn(|a| (q[a] * 74.0 - 5.0) as f32);
                let dx: [f32; 3] = std::array::from_fn(|a| ((q[3 + a] - 0.5) * 3.0) as f32);
                let reach: [f32; 3] = std::array::from_fn(|a| ((q[6 + a] - 0.5) * 1.2) as f32);
                let at = |k: usize, t: f32| -> [f32; 3] {
                    std::array::from_fn(|a| p[a] + k as f32 * dx[a] + t * reach[a])
                };
                let skipped = |q: [f32; 3]| {
                    if segments {
                        if s.contains(q) {
                            s.segment_empty(q)
                        } else {
                            open
                        }
                    } else {
                        s.visible(q).is_none()
                    }
                };
                let invisible = |k: usize| (0..=8).all(|j| skipped(at(k, j as f32 / 8.0)));
                let mut k = 0;
                while k < 40 {
                    let lo: [f32; 3] = std::array::from_fn(|a| at(k, 0.0)[a].min(at(k, 1.0)[a]));
                    let hi: [f32; 3] = std::array::from_fn(|a| at(k, 0.0)[a].max(at(k, 1.0)[a]));
                    let run = s.transparent_run(lo, hi, dx, segments);
                    if run == 0 {
                        transparent += invisible(k) as usize;
                        k += 1;
                        continue;
                    }
                    let end = 40.min(k.saturating_add(run));
                    for j in k..end {
                        assert!(
                            invisible(j),
                            "open {open} {segments}: pixel {j}, run from {k}"
                        );
                    }
                    counted += end - k;
                    transparent += end - k;
                    k = end;
                }
            }
            assert!(
                transparent > 500 && counted as f64 > 0.6 * transparent as f64,
                "open {open} {segments}: runs cover {counted} of {transparent} skippable pixels"
            );
        }
        // Nothing visible and a transparent outside: the row never ends.
        let (field, tf) = speckled(0.0, true);
        let empty = crate::illumination::scenes::constant(field.dims(), 0.0).unwrap();
        let s = Sampler::new(&empty, &tf, Interp::Trilinear, false);
        assert_eq!(
            s.transparent_run([3.0; 3], [3.5; 3], [1.0, -2.0, 0.5], false),
            usize::MAX
        );
    }

    /// The breadth-first clearance equals the brute-force Chebyshev distance to the nearest
    /// non-empty cell, and a grid without one is clear throughout.
    #[test]
    fn clearance_is_the_chebyshev_distance() {
        let cells = [9, 7, 5];
        let n = cells.iter().product::<usize>();
        let idx = |i: usize| [i % 9, (i / 9) % 7, i / 63];
        let empty: Vec<bool> = wscg_math::rng::uniform_vec(7, n, 0.0, 1.0)
            .unwrap()
            .iter()
            .map(|&u| u > 0.06)
            .collect();
        assert!(empty.iter().any(|e| !e) && empty.iter().any(|&e| e));
        let d = chebyshev_clearance(cells, &empty);
        for (i, &di) in d.iter().enumerate() {
            let want = (0..n)
                .filter(|&j| !empty[j])
                .map(|j| {
                    let (a, b) = (idx(i), idx(j));
                    (0..3).map(|k| a[k].abs_diff(b[k])).max().unwrap()
                })
                .min()
                .unwrap();
            assert_eq!(di as usize, want, "cell {:?}", idx(i));
        }
        assert!(chebyshev_clearance(cells, &vec![true; n])
            .iter()
            .all(|&c| c == u8::MAX));
    }
}
