//! The scalar volume the slice renderer samples: values normalised to
//! `[0, 1]`, voxel `i` centred at `i`, the box `[-1/2, n - 1/2]` per axis, trilinear
//! (edge-clamped) or nearest sampling inside the box and 0 outside.
//!
//! World units are voxels of the finest axis: voxel `(i, j, k)` sits at
//! `(i s_x, j s_y, k s_z) / min(s)`, so an isotropic volume has world = voxel coordinates and
//! transfer-function opacities refer to one such unit of length.

use std::sync::OnceLock;

use rayon::prelude::*;

use wscg_math::{Error, Result};

use super::bricks::Bricks;
use super::sampler::{cell_ranges, CellRanges};

/// Reconstruction filter of the scalar field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interp {
    /// Trilinear interpolation of the eight surrounding voxels (edge-clamped).
    #[default]
    Trilinear,
    /// The nearest voxel, `floor(p + 1/2)`.
    Nearest,
}

/// A scalar volume normalised to `[0, 1]`, `x` fastest.
///
/// On first use the field keeps the value ranges of its 8^3 cells (empty-space skipping) and
/// the Phong ray caster's value-and-gradient bricks of the cells its rays reach, so renders of
/// many views of one field pay for them once.
#[derive(Clone, Debug)]
pub struct ScalarField {
    dims: [usize; 3],
    spacing: [f64; 3],
    /// World units per voxel along each axis (`spacing / min(spacing)`).
    scale: [f64; 3],
    data: Vec<f32>,
    /// Value ranges of 8^3 cells, for empty-space skipping (computed on first use).
    cells: OnceLock<CellRanges>,
    /// Value-and-gradient bricks of the Phong ray caster (slots made on first use).
    bricks: OnceLock<Bricks>,
}

impl ScalarField {
    fn build(dims: [usize; 3], spacing: [f64; 3], len: usize) -> Result<([f64; 3], usize)> {
        if dims.contains(&0) {
            return Err(Error::invalid(
                "dims",
                format!("every dimension must be at least 1, got {dims:?}"),
            ));
        }
        let n = dims
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .ok_or_else(|| Error::invalid("dims", format!("{dims:?} overflows")))?;
        if len != n {
            return Err(Error::ShapeMismatch(format!(
                "volume data has {len} values, dims {dims:?} need {n}"
            )));
        }
        if !spacing.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(Error::invalid(
                "spacing",
                format!("must be finite and > 0, got {spacing:?}"),
            ));
        }
        let m = spacing.iter().cloned().fold(f64::INFINITY, f64::min);
        Ok((spacing.map(|s| s / m), n))
    }

    /// An 8-bit volume; values map to `v / 255`. Errors: zero or mismatched dims, spacing
    /// not finite and positive.
    pub fn from_u8(dims: [usize; 3], spacing: [f64; 3], data: &[u8]) -> Result<Self> {
        Self::checked(
            dims,
            spacing,
            data.par_iter().map(|&v| v as f32 / 255.0).collect(),
        )
    }

    /// A 16-bit volume; values map to `v / 65535`. Errors as [`ScalarField::from_u8`].
    pub fn from_u16(dims: [usize; 3], spacing: [f64; 3], data: &[u16]) -> Result<Self> {
        Self::checked(
            dims,
            spacing,
            data.par_iter().map(|&v| v as f32 / 65535.0).collect(),
        )
    }

    /// A field of values known to be in `[0, 1]`, after checking dims and spacing.
    fn checked(dims: [usize; 3], spacing: [f64; 3], data: Vec<f32>) -> Result<Self> {
        let (scale, _) = Self::build(dims, spacing, data.len())?;
        Ok(Self {
            dims,
            spacing,
            scale,
            data,
            cells: OnceLock::new(),
            bricks: OnceLock::new(),
        })
    }

    /// A float volume already in `[0, 1]`. Errors as [`ScalarField::from_u8`], plus
    /// non-finite values and values outside `[0, 1]` (use [`ScalarField::from_f32_range`]
    /// to map another range).
    pub fn from_f32(dims: [usize; 3], spacing: [f64; 3], data: Vec<f32>) -> Result<Self> {
        Self::build(dims, spacing, data.len())?;
        // One parallel pass for valid data (NaN fails the range test too); the error names the
        // first offending value.
        if !data.par_iter().all(|v| (0.0..=1.0).contains(v)) {
            if let Some(i) = data.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    name: "volume",
                    index: i,
                });
            }
            let i = data
                .iter()
                .position(|v| !(0.0..=1.0).contains(v))
                .unwrap_or(0);
            return Err(Error::invalid(
                "volume",
                format!(
                    "value {} at flat index {i} is outside [0, 1]; give a value range",
                    data[i]
                ),
            ));
        }
        Self::checked(dims, spacing, data)
    }

    /// A float volume whose range `[lo, hi]` maps linearly onto `[0, 1]` (values outside
    /// are clamped). Errors as [`ScalarField::from_f32`], plus `lo >= hi` or non-finite bounds.
    pub fn from_f32_range(
        dims: [usize; 3],
        spacing: [f64; 3],
        data: &[f32],
        lo: f32,
        hi: f32,
    ) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::invalid(
                "value_range",
                format!("needs finite lo < hi, got ({lo}, {hi})"),
            ));
        }
        Self::build(dims, spacing, data.len())?;
        if !data.par_iter().all(|v| v.is_finite()) {
            let i = data.iter().position(|v| !v.is_finite()).unwrap_or(0);
            return Err(Error::NonFinite {
                name: "volume",
                index: i,
            });
        }
        let (lo, k) = (lo as f64, 1.0 / (hi as f64 - lo as f64));
        // Finite values clamped: in [0, 1] by construction.
        let mapped = data
            .par_iter()
            .map(|&v| ((v as f64 - lo) * k).clamp(0.0, 1.0) as f32)
            .collect();
        Self::checked(dims, spacing, mapped)
    }

    /// Value ranges of 8^3 cells (with the one-voxel apron of trilinear sampling).
    pub(crate) fn cell_ranges(&self) -> &CellRanges {
        cell_ranges(self, &self.cells)
    }

    /// The value-and-gradient bricks (each built when first sampled).
    pub(crate) fn bricks(&self) -> &Bricks {
        self.bricks.get_or_init(|| Bricks::new(self))
    }

    /// Voxel counts `[nx, ny, nz]`.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Physical voxel spacing as given.
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// World units per voxel along each axis.
    pub fn scale(&self) -> [f64; 3] {
        self.scale
    }

    /// Normalised values, `x` fastest.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The world-space box `[lo, hi]` of the volume.
    pub fn world_box(&self) -> ([f64; 3], [f64; 3]) {
        let lo = std::array::from_fn(|a| -0.5 * self.scale[a]);
        let hi = std::array::from_fn(|a| (self.dims[a] as f64 - 0.5) * self.scale[a]);
        (lo, hi)
    }

    /// The world-space centre of the box.
    pub fn world_center(&self) -> [f64; 3] {
        std::array::from_fn(|a| 0.5 * (self.dims[a] as f64 - 1.0) * self.scale[a])
    }

    /// The sample at `p` in **voxel** coordinates; 0 outside the box `[-1/2, n - 1/2]`.
    #[inline]
    pub fn sample(&self, p: [f32; 3], interp: Interp) -> f32 {
        if !self.contains(p) {
            return 0.0;
        }
        self.sample_inside(p, interp)
    }

    /// True if `p` (voxel coordinates) lies in the box `[-1/2, n - 1/2)`.
    #[inline]
    pub fn contains(&self, p: [f32; 3]) -> bool {
        let inside = |c: f32, n: usize| c >= -0.5 && c < n as f32 - 0.5;
        inside(p[0], self.dims[0]) && inside(p[1], self.dims[1]) && inside(p[2], self.dims[2])
    }

    /// The sample at `p` with `p` clamped to the box (edge values continue outside).
    #[inline]
    pub fn sample_clamped(&self, p: [f32; 3], interp: Interp) -> f32 {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return 0.0;
        }
        self.sample_inside(p, interp)
    }

    /// The sample at `p` known to be inside the box (coordinates are clamped to it).
    #[inline(always)]
    pub(crate) fn sample_inside(&self, p: [f32; 3], interp: Interp) -> f32 {
        match interp {
            Interp::Trilinear => self.trilinear_inside(p),
            Interp::Nearest => self.nearest_inside(p),
        }
    }

    /// Nearest sample of a point known to be inside the box.
    #[inline]
    pub(crate) fn nearest_inside(&self, p: [f32; 3]) -> f32 {
        let [nx, ny, nz] = self.dims;
        self.data
            [axis_nearest(p[0], nx) + nx * (axis_nearest(p[1], ny) + ny * axis_nearest(p[2], nz))]
    }

    /// Trilinear sample of a point known to be inside the box (edge-clamped).
    #[inline(always)]
    pub(crate) fn trilinear_inside(&self, p: [f32; 3]) -> f32 {
        let [nx, ny, nz] = self.dims;
        let (x0, x1, tx) = axis_cell(p[0], nx);
        let (y0, y1, ty) = axis_cell(p[1], ny);
        let (z0, z1, tz) = axis_cell(p[2], nz);
        let d = &self.data;
        let r00 = nx * (y0 + ny * z0);
        let r10 = nx * (y1 + ny * z0);
        let r01 = nx * (y0 + ny * z1);
        let r11 = nx * (y1 + ny * z1);
        let l = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = l(d[r00 + x0], d[r00 + x1], tx);
        let c10 = l(d[r10 + x0], d[r10 + x1], tx);
        let c01 = l(d[r01 + x0], d[r01 + x1], tx);
        let c11 = l(d[r11 + x0], d[r11 + x1], tx);
        l(l(c00, c10, ty), l(c01, c11, ty), tz)
    }

    /// Gradient by central differences of samples one voxel apart, in value per world unit:
    /// the definition the Phong ray caster's bricks reproduce (their test's reference).
    #[cfg(test)]
    pub(crate) fn gradient(&self, p: [f32; 3], interp: Interp) -> [f32; 3] {
        std::array::from_fn(|a| {
            let mut lo = p;
            let mut hi = p;
            lo[a] -= 1.0;
            hi[a] += 1.0;
            0.5 * (self.sample(hi, interp) - self.sample(lo, interp)) / self.scale[a] as f32
        })
    }
}

/// The voxel along one axis nearest to coordinate `c`, `floor(c + 1/2)` clamped to `[0, n - 1]`.
#[inline]
pub(crate) fn axis_nearest(c: f32, n: usize) -> usize {
    ((c + 0.5).floor().max(0.0) as usize).min(n - 1)
}

/// The two voxels along one axis that a trilinear sample at coordinate `c` interpolates, and
/// the weight of the second: edge-clamped to `[0, n - 1]`.
#[inline]
pub(crate) fn axis_cell(c: f32, n: usize) -> (usize, usize, f32) {
    let c = c.clamp(0.0, (n - 1) as f32);
    let i = (c as usize).min(n.saturating_sub(2));
    let t = c - i as f32;
    (i, (i + 1).min(n - 1), t)
}
