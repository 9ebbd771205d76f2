//! The scalar volume the slice renderer samples: values normalised to
//! `[0, 1]`, voxel `i` centred at `i`, the box `[-1/2, n - 1/2]` per axis, trilinear
//! (edge-clamped) or nearest sampling inside the box and 0 outside.
//!
//! World units are voxels of the finest axis: voxel `(i, j, k)` sits at
//! `(i s_x, j s_y, k s_z) / min(s)`, so an isotropic volume has world = voxel coordinates and
//! transfer-function opacities refer to one such unit of length.

use std::sync::OnceLock;

use rayon::prelude::*;

use wscg_math::{Error, Result, Volume, VolumeView};

use super::bricks::Bricks;
use super::cells::CellRanges;
pub use super::voxels::Interp;
use super::voxels::Voxels;

/// A scalar volume normalised to `[0, 1]`, `x` fastest.
///
/// On first use the field keeps the value ranges of its 8^3 cells (empty-space skipping) and
/// the Phong ray caster's value-and-gradient bricks of the cells its rays reach, so renders of
/// many views of one field pay for them once.
#[derive(Clone, Debug)]
pub struct ScalarField {
    /// The voxels and their sampling.
    vox: Voxels,
    spacing: [f64; 3],
    /// Value ranges of 8^3 cells, for empty-space skipping (computed on first use).
    cells: OnceLock<CellRanges>,
    /// Value-and-gradient bricks of the Phong ray caster (slots made on first use).
    bricks: OnceLock<Bricks>,
}

impl ScalarField {
    /// An 8-bit volume; values map to `v / 255`.
    pub fn from_u8(volume: VolumeView<'_, u8>) -> Result<Self> {
        let data = volume
            .data()
            .par_iter()
            .map(|&v| v as f32 / 255.0)
            .collect();
        Ok(Self::normalised(volume.dims(), volume.spacing(), data))
    }

    /// A 16-bit volume; values map to `v / 65535`.
    pub fn from_u16(volume: VolumeView<'_, u16>) -> Result<Self> {
        let data = volume
            .data()
            .par_iter()
            .map(|&v| v as f32 / 65535.0)
            .collect();
        Ok(Self::normalised(volume.dims(), volume.spacing(), data))
    }

    /// A field of values known to be in `[0, 1]`, dims and spacing checked by a volume.
    fn normalised(dims: [usize; 3], spacing: [f64; 3], data: Vec<f32>) -> Self {
        let m = spacing.iter().cloned().fold(f64::INFINITY, f64::min);
        Self {
            vox: Voxels {
                dims,
                scale: spacing.map(|s| s / m),
                data,
            },
            spacing,
            cells: OnceLock::new(),
            bricks: OnceLock::new(),
        }
    }

    /// A float volume already in `[0, 1]`, taken without a copy. Errors: non-finite values
    /// and values outside `[0, 1]` (use [`ScalarField::from_f32_range`] to map another range).
    pub fn from_f32(volume: Volume<f32>) -> Result<Self> {
        let (dims, spacing) = (volume.dims(), volume.spacing());
        let data = volume.into_data();
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
        Ok(Self::normalised(dims, spacing, data))
    }

    /// A float volume whose range `[lo, hi]` maps linearly onto `[0, 1]` (values outside
    /// are clamped). Errors: non-finite values, `lo >= hi` or non-finite bounds.
    pub fn from_f32_range(volume: VolumeView<'_, f32>, lo: f32, hi: f32) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::invalid(
                "value_range",
                format!("needs finite lo < hi, got ({lo}, {hi})"),
            ));
        }
        let data = volume.data();
        if !data.par_iter().all(|v| v.is_finite()) {
            volume.ensure_finite("volume")?;
        }
        let (lo, k) = (lo as f64, 1.0 / (hi as f64 - lo as f64));
        // Finite values clamped: in [0, 1] by construction.
        let mapped = data
            .par_iter()
            .map(|&v| ((v as f64 - lo) * k).clamp(0.0, 1.0) as f32)
            .collect();
        Ok(Self::normalised(volume.dims(), volume.spacing(), mapped))
    }

    /// Value ranges of 8^3 cells (with the one-voxel apron of trilinear sampling).
    pub(crate) fn cell_ranges(&self) -> &CellRanges {
        self.cells.get_or_init(|| CellRanges::new(&self.vox))
    }

    /// The value-and-gradient bricks (each built when first sampled).
    pub(crate) fn bricks(&self) -> &Bricks {
        self.bricks.get_or_init(|| Bricks::new(&self.vox))
    }

    /// The voxels (what the cell ranges and the bricks are built from).
    pub(crate) fn voxels(&self) -> &Voxels {
        &self.vox
    }

    /// Voxel counts `[nx, ny, nz]`.
    pub fn dims(&self) -> [usize; 3] {
        self.vox.dims
    }

    /// Physical voxel spacing as given.
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// World units per voxel along each axis.
    pub fn scale(&self) -> [f64; 3] {
        self.vox.scale
    }

    /// Normalised values, `x` fastest.
    pub fn data(&self) -> &[f32] {
        &self.vox.data
    }

    /// The world-space box `[lo, hi]` of the volume.
    pub fn world_box(&self) -> ([f64; 3], [f64; 3]) {
        let lo = std::array::from_fn(|a| -0.5 * self.vox.scale[a]);
        let hi = std::array::from_fn(|a| (self.vox.dims[a] as f64 - 0.5) * self.vox.scale[a]);
        (lo, hi)
    }

    /// The world-space centre of the box.
    pub fn world_center(&self) -> [f64; 3] {
        std::array::from_fn(|a| 0.5 * (self.vox.dims[a] as f64 - 1.0) * self.vox.scale[a])
    }

    /// The sample at `p` in **voxel** coordinates; 0 outside the box `[-1/2, n - 1/2]`.
    #[inline]
    pub fn sample(&self, p: [f32; 3], interp: Interp) -> f32 {
        self.vox.sample(p, interp)
    }

    /// True if `p` (voxel coordinates) lies in the box `[-1/2, n - 1/2)`.
    #[inline]
    pub fn contains(&self, p: [f32; 3]) -> bool {
        self.vox.contains(p)
    }

    /// The sample at `p` with `p` clamped to the box (edge values continue outside).
    #[inline]
    pub fn sample_clamped(&self, p: [f32; 3], interp: Interp) -> f32 {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return 0.0;
        }
        self.vox.sample_inside(p, interp)
    }

    /// The sample at `p` known to be inside the box (coordinates are clamped to it).
    #[inline(always)]
    pub(crate) fn sample_inside(&self, p: [f32; 3], interp: Interp) -> f32 {
        self.vox.sample_inside(p, interp)
    }
}
