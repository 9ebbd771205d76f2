//! [`Volume`]: a scalar X x Y x Z voxel grid with physical voxel spacing, trilinear sampling,
//! finite-difference gradients, and raw / NIfTI-1 / `.npy` file IO.
//!
//! # Layout and axis order
//!
//! A volume has `dims = [nx, ny, nz]` voxels and `spacing = [sx, sy, sz]` (the size of a voxel
//! along each axis, in physical units, usually millimetres). Values are stored with **x
//! fastest**: voxel `(x, y, z)` is `data[x + nx * (y + ny * z)]`. This is the memory order of
//! NIfTI files, of raw CT/MRI dumps, and of a C-ordered numpy array of shape `(nz, ny, nx)`
//! indexed `arr[z, y, x]`; [`Volume::to_zyx`], [`Volume::view_zyx`] and [`Volume::from_zyx`]
//! convert to and from that numpy view without any reordering.
//!
//! # Coordinates
//!
//! *Voxel (index) coordinates* put the centre of voxel `(i, j, k)` at the point `(i, j, k)`;
//! they are what [`Volume::trilinear`] takes. *World coordinates* are voxel coordinates times
//! the spacing, with the centre of voxel `(0, 0, 0)` at the origin; they are what
//! [`Volume::trilinear_world`] takes. No NIfTI affine (orientation, origin) is applied.
//!
//! # Files
//!
//! - raw: [`Volume::read_raw`] / [`Volume::write_raw_f32_le`] (headerless voxel dumps, x fastest).
//! - NIfTI-1 single file, `.nii` and `.nii.gz`: [`Volume::read_nifti`] / [`Volume::write_nifti`].
//! - numpy `.npy`: [`Volume::read_npy`] / [`Volume::write_npy`], array indexed `arr[z, y, x]`.
//! - [`Volume::read`] picks the reader from the file extension.
//!
//! Readers never modify their input, bound every allocation by the size of the file or by
//! [`MAX_VOXELS`], and report every bad file as an error naming the path.

use std::borrow::Cow;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicUsize, Ordering};

use ndarray::{Array3, ArrayView3, ArrayViewMut3, Ix3, ShapeBuilder};
use nifti::{IntoNdArray, NiftiError, NiftiHeader, NiftiType};
use rayon::prelude::*;

use crate::error::{ensure_positive, read_error, Error, Result};

/// Largest number of voxels a volume may have (`2^33`, e.g. 2048 x 2048 x 2048, 32 GiB as
/// `f32`). Constructors and readers refuse larger requests with [`Error::LimitExceeded`], so a
/// hostile file header cannot make us allocate without bound.
pub const MAX_VOXELS: usize = 1 << 33;

/// Largest NIfTI `vox_offset` (header plus extensions, in bytes) accepted from a file.
const MAX_NIFTI_VOX_OFFSET: u64 = 1 << 30;

/// Size of a NIfTI-1 header in bytes.
const NIFTI1_HEADER_BYTES: usize = 348;

/// A scalar volume: `nx x ny x nz` voxels with a physical voxel size, stored x fastest.
///
/// See the [module documentation](self) for the layout and the coordinate conventions.
/// The element type defaults to `f32`; sampling and gradients are provided for `f32` and
/// `f64` (the [`Real`] types), and any `T` can be stored (labels as `u8`, masks as `bool`...).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume<T = f32> {
    dims: [usize; 3],
    spacing: [f64; 3],
    data: Vec<T>,
}

/// Floating-point voxel types that [`Volume`] can sample and differentiate: `f32` and `f64`.
///
/// Interpolation and differences are computed in `f64` and rounded once to `Self`.
pub trait Real: Copy + Send + Sync + PartialOrd + std::fmt::Debug + 'static {
    /// Widens to `f64` (exact for `f32` and `f64`).
    fn to_f64(self) -> f64;
    /// Rounds an `f64` to `Self`.
    fn from_f64(v: f64) -> Self;
    /// The values as `f32`, borrowed when `Self` is `f32` (used by the writers).
    fn as_f32_slice(data: &[Self]) -> Cow<'_, [f32]>;
}

impl Real for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    fn as_f32_slice(data: &[Self]) -> Cow<'_, [f32]> {
        Cow::Borrowed(data)
    }
}

impl Real for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        v
    }
    fn as_f32_slice(data: &[Self]) -> Cow<'_, [f32]> {
        Cow::Owned(data.par_iter().map(|&v| v as f32).collect())
    }
}

/// Checks `dims` and returns the number of voxels.
///
/// Errors: a zero dimension ([`Error::Empty`]); a product that overflows or exceeds
/// [`MAX_VOXELS`] ([`Error::LimitExceeded`]).
fn voxel_count(dims: [usize; 3]) -> Result<usize> {
    if dims.contains(&0) {
        return Err(Error::Empty("volume dims (nx, ny and nz must all be > 0)"));
    }
    dims.iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .filter(|&n| n <= MAX_VOXELS)
        .ok_or_else(|| {
            Error::LimitExceeded(format!(
                "volume dims {dims:?} exceed the limit of {MAX_VOXELS} voxels"
            ))
        })
}

/// Checks that every spacing component is finite and > 0.
fn check_spacing(spacing: [f64; 3]) -> Result<()> {
    for s in spacing {
        ensure_positive("spacing", s)?;
    }
    Ok(())
}

impl<T> Volume<T> {
    /// Wraps `data` (length `nx * ny * nz`, x fastest) as a volume of `dims = [nx, ny, nz]`
    /// voxels of size `spacing = [sx, sy, sz]` (physical units, e.g. mm).
    ///
    /// The values themselves are not checked (NaN is allowed; see [`Volume::ensure_finite`]).
    ///
    /// Errors: a zero dimension ([`Error::Empty`]), more than [`MAX_VOXELS`] voxels
    /// ([`Error::LimitExceeded`]), a spacing that is not finite and > 0
    /// ([`Error::InvalidArgument`] naming `spacing`), a data length other than `nx * ny * nz`
    /// ([`Error::ShapeMismatch`]).
    pub fn new(dims: [usize; 3], spacing: [f64; 3], data: Vec<T>) -> Result<Self> {
        let n = voxel_count(dims)?;
        check_spacing(spacing)?;
        if data.len() != n {
            return Err(Error::ShapeMismatch(format!(
                "volume data has {} values, but dims {dims:?} need {n}",
                data.len()
            )));
        }
        Ok(Volume {
            dims,
            spacing,
            data,
        })
    }

    /// A volume whose voxel `(x, y, z)` is `f(x, y, z)`, evaluated in parallel (rayon, one task
    /// per z slice). Errors as [`Volume::new`].
    pub fn from_fn<F>(dims: [usize; 3], spacing: [f64; 3], f: F) -> Result<Self>
    where
        T: Send,
        F: Fn(usize, usize, usize) -> T + Sync + Send,
    {
        voxel_count(dims)?;
        check_spacing(spacing)?;
        let [nx, ny, nz] = dims;
        let f = &f;
        let data: Vec<T> = (0..nz)
            .into_par_iter()
            .flat_map_iter(|z| (0..ny).flat_map(move |y| (0..nx).map(move |x| f(x, y, z))))
            .collect();
        Ok(Volume {
            dims,
            spacing,
            data,
        })
    }

    /// Builds a volume from a 3-D array indexed `array[[z, y, x]]` (numpy shape
    /// `(nz, ny, nx)`, the way a Python user indexes a CT stack); any memory layout is
    /// accepted. A Python array ordered `(X, Y, Z)` must be transposed first
    /// (`arr.transpose(2, 1, 0)`).
    ///
    /// Errors: as [`Volume::new`] (an empty axis gives [`Error::Empty`]).
    pub fn from_zyx(array: ArrayView3<'_, T>, spacing: [f64; 3]) -> Result<Self>
    where
        T: Clone,
    {
        let (nz, ny, nx) = array.dim();
        voxel_count([nx, ny, nz])?;
        check_spacing(spacing)?;
        let data: Vec<T> = match array.as_slice() {
            Some(s) => s.to_vec(),
            None => array.iter().cloned().collect(),
        };
        Ok(Volume {
            dims: [nx, ny, nz],
            spacing,
            data,
        })
    }

    /// Number of voxels along x, y and z: `[nx, ny, nz]`.
    #[inline]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Voxel size along x, y and z in physical units (e.g. mm): `[sx, sy, sz]`.
    #[inline]
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// Replaces the voxel spacing. Errors unless every component is finite and > 0.
    pub fn set_spacing(&mut self, spacing: [f64; 3]) -> Result<()> {
        check_spacing(spacing)?;
        self.spacing = spacing;
        Ok(())
    }

    /// Physical size of the volume, `[nx * sx, ny * sy, nz * sz]`: the field of view covered
    /// by the voxels, each voxel being a cell of size `spacing`. (Voxel *centres*, where
    /// samples live, span `(n - 1) * spacing`.)
    pub fn extent(&self) -> [f64; 3] {
        [0, 1, 2].map(|a| self.dims[a] as f64 * self.spacing[a])
    }

    /// The voxel values, x fastest (`data[x + nx * (y + ny * z)]`).
    #[inline]
    pub fn data(&self) -> &[T] {
        &self.data
    }

    /// The voxel values, mutable, x fastest.
    #[inline]
    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// Consumes the volume, returning its values (x fastest).
    pub fn into_data(self) -> Vec<T> {
        self.data
    }

    /// Number of voxels, `nx * ny * nz` (never zero).
    #[inline]
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Always `false`: a volume has at least one voxel. Present for API symmetry with `len`.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// True when `(x, y, z)` is inside the grid.
    #[inline]
    pub fn contains(&self, x: usize, y: usize, z: usize) -> bool {
        x < self.dims[0] && y < self.dims[1] && z < self.dims[2]
    }

    /// Flat index `x + nx * (y + ny * z)` of voxel `(x, y, z)` in [`Volume::data`].
    ///
    /// # Panics
    /// If the voxel is outside the grid (a programming error; use
    /// [`Volume::checked_index`] for coordinates that come from users).
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        assert!(
            self.contains(x, y, z),
            "voxel ({x}, {y}, {z}) is outside a volume of dims {:?}",
            self.dims
        );
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Flat index of voxel `(x, y, z)`, or `None` outside the grid.
    #[inline]
    pub fn checked_index(&self, x: usize, y: usize, z: usize) -> Option<usize> {
        self.contains(x, y, z)
            .then(|| x + self.dims[0] * (y + self.dims[1] * z))
    }

    /// The value of voxel `(x, y, z)`, or `None` outside the grid.
    #[inline]
    pub fn get(&self, x: usize, y: usize, z: usize) -> Option<T>
    where
        T: Copy,
    {
        self.checked_index(x, y, z).map(|i| self.data[i])
    }

    /// The value of voxel `(x, y, z)`.
    ///
    /// # Panics
    /// If the voxel is outside the grid (a programming error; use [`Volume::get`] for
    /// coordinates that come from users).
    #[inline]
    pub fn at(&self, x: usize, y: usize, z: usize) -> T
    where
        T: Copy,
    {
        self.data[self.index(x, y, z)]
    }

    /// Sets voxel `(x, y, z)` to `value`.
    ///
    /// # Panics
    /// If the voxel is outside the grid (a programming error).
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, z: usize, value: T) {
        let i = self.index(x, y, z);
        self.data[i] = value;
    }

    /// The z slice `z` as a slice of `nx * ny` values, x fastest.
    ///
    /// # Panics
    /// If `z >= nz` (a programming error).
    pub fn slice_z(&self, z: usize) -> &[T] {
        assert!(
            z < self.dims[2],
            "slice z = {z} outside nz = {}",
            self.dims[2]
        );
        let n = self.dims[0] * self.dims[1];
        &self.data[z * n..(z + 1) * n]
    }

    /// A new volume with `f` applied to every voxel (in parallel), same dims and spacing.
    pub fn map<U, F>(&self, f: F) -> Volume<U>
    where
        T: Copy + Sync,
        U: Send,
        F: Fn(T) -> U + Sync + Send,
    {
        Volume {
            dims: self.dims,
            spacing: self.spacing,
            data: self.data.par_iter().map(|&v| f(v)).collect(),
        }
    }

    /// Zero-copy view as an array of shape `(nz, ny, nx)` indexed `[z, y, x]` (C order).
    pub fn view_zyx(&self) -> ArrayView3<'_, T> {
        let [nx, ny, nz] = self.dims;
        ArrayView3::from_shape((nz, ny, nx), &self.data)
            .expect("volume invariant: data length equals nx * ny * nz")
    }

    /// Zero-copy mutable view as an array of shape `(nz, ny, nx)` indexed `[z, y, x]`.
    pub fn view_zyx_mut(&mut self) -> ArrayViewMut3<'_, T> {
        let [nx, ny, nz] = self.dims;
        ArrayViewMut3::from_shape((nz, ny, nx), &mut self.data)
            .expect("volume invariant: data length equals nx * ny * nz")
    }

    /// A copy as an owned C-ordered array of shape `(nz, ny, nx)` indexed `[z, y, x]`
    /// (the numpy view of the volume; see [`Volume::from_zyx`] for the reverse).
    pub fn to_zyx(&self) -> Array3<T>
    where
        T: Clone,
    {
        self.view_zyx().to_owned()
    }

    /// Like [`Volume::to_zyx`], without copying the values.
    pub fn into_zyx(self) -> Array3<T> {
        let [nx, ny, nz] = self.dims;
        Array3::from_shape_vec((nz, ny, nx), self.data)
            .expect("volume invariant: data length equals nx * ny * nz")
    }
}

impl<T: Clone> Volume<T> {
    /// A volume of `dims` voxels of size `spacing`, every voxel equal to `value`.
    /// Errors as [`Volume::new`].
    pub fn filled(dims: [usize; 3], spacing: [f64; 3], value: T) -> Result<Self> {
        let n = voxel_count(dims)?;
        check_spacing(spacing)?;
        Ok(Volume {
            dims,
            spacing,
            data: vec![value; n],
        })
    }
}

/// Clamped sampling position along one axis: lower index, upper index, weight of the upper.
#[inline]
fn axis_cell(p: f64, n: usize) -> (usize, usize, f64) {
    if n == 1 {
        return (0, 0, 0.0);
    }
    let c = p.clamp(0.0, (n - 1) as f64);
    let i0 = (c.floor() as usize).min(n - 2);
    (i0, i0 + 1, c - i0 as f64)
}

impl<T: Real> Volume<T> {
    /// Separable Gaussian smoothing with standard deviation `sigma` (voxels, per axis x, y, z;
    /// 0 leaves an axis alone), as `scipy.ndimage.gaussian_filter(arr_zyx, sigma[::-1],
    /// truncate=truncate, mode=...)`: kernel radius `int(truncate * sigma + 0.5)`, sums in f64,
    /// lines in parallel.
    ///
    /// Errors: negative or non-finite `sigma`, `truncate` not > 0.
    pub fn gaussian_filter(
        &self,
        sigma: [f64; 3],
        truncate: f64,
        border: crate::filter::Border,
    ) -> Result<Self> {
        let mut out = self.clone();
        for (axis, &s) in sigma.iter().enumerate() {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::invalid(
                    "sigma",
                    format!("must be finite and >= 0, got {s}"),
                ));
            }
            if s == 0.0 {
                continue;
            }
            let k = crate::filter::gaussian_kernel(s, truncate)?;
            out = out.correlate_axis(axis, &k, border);
        }
        Ok(out)
    }

    /// Correlates every line along `axis` with the centred odd kernel `k`.
    fn correlate_axis(&self, axis: usize, k: &[f64], border: crate::filter::Border) -> Self {
        let d = self.dims;
        let n = d[axis];
        let stride = [1, d[0], d[0] * d[1]][axis];
        let r = (k.len() / 2) as isize;
        let src = &self.data;
        // One task per line along `axis`.
        let starts: Vec<usize> = (0..self.data.len())
            .filter(|&i| (i / stride).is_multiple_of(n))
            .collect();
        let lines: Vec<(usize, Vec<T>)> = starts
            .par_iter()
            .map(|&s| {
                let line: Vec<T> = (0..n as isize)
                    .map(|i| {
                        let mut acc = 0.0f64;
                        for (t, &w) in k.iter().enumerate() {
                            let j = i + t as isize - r;
                            let v = match border.map(j, n) {
                                Some(j) => src[s + j * stride].to_f64(),
                                None => border.cval(),
                            };
                            acc += w * v;
                        }
                        T::from_f64(acc)
                    })
                    .collect();
                (s, line)
            })
            .collect();
        let mut out = self.clone();
        for (s, line) in lines {
            for (i, v) in line.into_iter().enumerate() {
                out.data[s + i * stride] = v;
            }
        }
        out
    }

    /// Returns [`Error::NonFinite`] naming `name` (with the flat index) if any voxel is NaN or
    /// infinite.
    pub fn ensure_finite(&self, name: &'static str) -> Result<()> {
        match self.data.iter().position(|v| !v.to_f64().is_finite()) {
            Some(index) => Err(Error::NonFinite { name, index }),
            None => Ok(()),
        }
    }

    /// Smallest and largest voxel values, ignoring NaN; `None` when every voxel is NaN.
    pub fn min_max(&self) -> Option<(T, T)> {
        self.data
            .par_iter()
            .filter(|v| !v.to_f64().is_nan())
            .fold(
                || None,
                |acc: Option<(T, T)>, &v| match acc {
                    None => Some((v, v)),
                    Some((lo, hi)) => {
                        Some((if v < lo { v } else { lo }, if v > hi { v } else { hi }))
                    }
                },
            )
            .reduce(
                || None,
                |a, b| match (a, b) {
                    (None, x) | (x, None) => x,
                    (Some((l1, h1)), Some((l2, h2))) => {
                        Some((if l2 < l1 { l2 } else { l1 }, if h2 > h1 { h2 } else { h1 }))
                    }
                },
            )
    }

    /// Trilinear interpolation at `p = [x, y, z]` in **voxel coordinates** (the centre of
    /// voxel `(i, j, k)` is at `(i, j, k)`).
    ///
    /// Points outside `[0, n - 1]` along an axis are clamped to the border, so the volume is
    /// extended by its border values (the edge mode of scikit-image / `scipy.ndimage`
    /// `mode="nearest"`). At integer points the voxel value is returned exactly; any function
    /// `a + b x + c y + d z` (indeed any multilinear one) is reproduced exactly up to
    /// rounding. A non-finite coordinate gives NaN.
    #[inline]
    pub fn trilinear(&self, p: [f64; 3]) -> T {
        T::from_f64(self.trilinear_f64(p))
    }

    /// Trilinear interpolation at `p_world = [x, y, z]` in **world units** (same units as the
    /// spacing, e.g. mm), with the centre of voxel `(0, 0, 0)` at the origin: samples
    /// [`Volume::trilinear`] at `p_world / spacing`, clamped to the border the same way.
    pub fn trilinear_world(&self, p_world: [f64; 3]) -> T {
        let s = self.spacing;
        self.trilinear([p_world[0] / s[0], p_world[1] / s[1], p_world[2] / s[2]])
    }

    #[inline]
    fn trilinear_f64(&self, p: [f64; 3]) -> f64 {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return f64::NAN;
        }
        let [nx, ny, _] = self.dims;
        let (x0, x1, tx) = axis_cell(p[0], self.dims[0]);
        let (y0, y1, ty) = axis_cell(p[1], self.dims[1]);
        let (z0, z1, tz) = axis_cell(p[2], self.dims[2]);
        let v = |x: usize, y: usize, z: usize| self.data[x + nx * (y + ny * z)].to_f64();
        let lerp = |a: f64, b: f64, t: f64| {
            if t == 0.0 {
                a
            } else if t == 1.0 {
                b
            } else {
                a + (b - a) * t
            }
        };
        let c00 = lerp(v(x0, y0, z0), v(x1, y0, z0), tx);
        let c10 = lerp(v(x0, y1, z0), v(x1, y1, z0), tx);
        let c01 = lerp(v(x0, y0, z1), v(x1, y0, z1), tx);
        let c11 = lerp(v(x0, y1, z1), v(x1, y1, z1), tx);
        let c0 = lerp(c00, c10, ty);
        let c1 = lerp(c01, c11, ty);
        lerp(c0, c1, tz)
    }

    /// Derivative along axis `a` at voxel `(x, y, z)` in value units per physical unit.
    #[inline]
    fn diff_f64(&self, a: usize, x: usize, y: usize, z: usize) -> f64 {
        let [nx, ny, _] = self.dims;
        let n = self.dims[a];
        if n == 1 {
            return 0.0;
        }
        let stride = [1, nx, nx * ny][a];
        let i = [x, y, z][a];
        let base = x + nx * (y + ny * z);
        let v = |k: usize| self.data[k].to_f64();
        let h = self.spacing[a];
        if i == 0 {
            (v(base + stride) - v(base)) / h
        } else if i == n - 1 {
            (v(base) - v(base - stride)) / h
        } else {
            (v(base + stride) - v(base - stride)) / (2.0 * h)
        }
    }

    fn gradient_f64(&self, x: usize, y: usize, z: usize) -> [f64; 3] {
        [0, 1, 2].map(|a| self.diff_f64(a, x, y, z))
    }

    /// Gradient `[d/dx, d/dy, d/dz]` at voxel `(x, y, z)` in value units per physical unit
    /// (per mm when the spacing is in mm): central differences `(v[i+1] - v[i-1]) / (2 s)`
    /// inside, one-sided differences `(v[1] - v[0]) / s` and `(v[n-1] - v[n-2]) / s` on the
    /// borders, and 0 along an axis with a single voxel. Exact for affine functions.
    ///
    /// # Panics
    /// If the voxel is outside the grid (a programming error).
    pub fn gradient_at(&self, x: usize, y: usize, z: usize) -> [T; 3] {
        assert!(
            self.contains(x, y, z),
            "voxel ({x}, {y}, {z}) is outside a volume of dims {:?}",
            self.dims
        );
        self.gradient_f64(x, y, z).map(T::from_f64)
    }

    /// Gradient at `p = [x, y, z]` in voxel coordinates, in value units per physical unit:
    /// the **trilinear interpolation of the voxel gradients** of [`Volume::gradient_at`]
    /// (central differences), clamped to the border like [`Volume::trilinear`]. This is the
    /// smooth gradient used for shading in volume ray casting; it equals `gradient_at` at
    /// integer points and is exact for affine functions. A non-finite coordinate gives NaN.
    pub fn gradient_trilinear(&self, p: [f64; 3]) -> [T; 3] {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return [T::from_f64(f64::NAN); 3];
        }
        let (x0, x1, tx) = axis_cell(p[0], self.dims[0]);
        let (y0, y1, ty) = axis_cell(p[1], self.dims[1]);
        let (z0, z1, tz) = axis_cell(p[2], self.dims[2]);
        let mut g = [0.0f64; 3];
        for (z, wz) in [(z0, 1.0 - tz), (z1, tz)] {
            for (y, wy) in [(y0, 1.0 - ty), (y1, ty)] {
                for (x, wx) in [(x0, 1.0 - tx), (x1, tx)] {
                    let w = wx * wy * wz;
                    if w != 0.0 {
                        let gv = self.gradient_f64(x, y, z);
                        for a in 0..3 {
                            g[a] += w * gv[a];
                        }
                    }
                }
            }
        }
        g.map(T::from_f64)
    }

    /// The gradient at every voxel ([`Volume::gradient_at`]) as three volumes
    /// `[d/dx, d/dy, d/dz]` with the same dims and spacing, computed in parallel.
    pub fn gradient_volume(&self) -> [Volume<T>; 3] {
        [0, 1, 2].map(|a| Volume {
            dims: self.dims,
            spacing: self.spacing,
            data: {
                let [nx, ny, nz] = self.dims;
                (0..nz)
                    .into_par_iter()
                    .flat_map_iter(|z| {
                        (0..ny).flat_map(move |y| {
                            (0..nx).map(move |x| T::from_f64(self.diff_f64(a, x, y, z)))
                        })
                    })
                    .collect()
            },
        })
    }

    /// Writes the voxels as headerless little-endian `f32`, x fastest (`nx * ny * nz * 4`
    /// bytes); read it back with [`Volume::read_raw`] and [`RawType::F32Le`].
    pub fn write_raw_f32_le(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let values = T::as_f32_slice(&self.data);
        let mut bytes = Vec::with_capacity(values.len() * 4);
        for v in values.iter() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
    }

    /// Writes a single-file NIfTI-1 image with `f32` voxels (`datatype` FLOAT32), dims
    /// `[nx, ny, nz]`, `pixdim[1..4]` = spacing (units: mm), `scl_slope` 1, and a
    /// scaling-only qform/sform. The file is gzip-compressed when the name ends in `.gz`.
    ///
    /// Errors: a name that ends in neither `.nii` nor `.nii.gz` ([`Error::UnsupportedFormat`]),
    /// a dimension above 32767 (the NIfTI-1 limit, [`Error::LimitExceeded`]), I/O failures.
    pub fn write_nifti(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let kind = file_kind(path);
        let gz = match kind {
            FileKind::Nii => false,
            FileKind::NiiGz => true,
            _ => {
                return Err(Error::UnsupportedFormat(format!(
                    "cannot write {} as NIfTI: the name must end in .nii or .nii.gz",
                    path.display()
                )))
            }
        };
        if let Some(&d) = self.dims.iter().find(|&&d| d > i16::MAX as usize) {
            return Err(Error::LimitExceeded(format!(
                "cannot write {}: dimension {d} exceeds the NIfTI-1 limit of {}",
                path.display(),
                i16::MAX
            )));
        }
        let [sx, sy, sz] = self.spacing.map(|s| s as f32);
        let header = NiftiHeader {
            pixdim: [1.0, sx, sy, sz, 1.0, 1.0, 1.0, 1.0],
            xyzt_units: 2, // NIFTI_UNITS_MM
            qform_code: 1,
            sform_code: 1,
            srow_x: [sx, 0.0, 0.0, 0.0],
            srow_y: [0.0, sy, 0.0, 0.0],
            srow_z: [0.0, 0.0, sz, 0.0],
            ..NiftiHeader::default()
        };
        let values = T::as_f32_slice(&self.data);
        let [nx, ny, nz] = self.dims;
        // Logical shape [x, y, z] over x-fastest memory = Fortran order.
        let array = ArrayView3::from_shape((nx, ny, nz).f(), &values[..])
            .expect("volume invariant: data length equals nx * ny * nz");

        // The nifti writer rewrites file names with several dots; write under a plain
        // temporary name in the same folder and rename, which also makes the write atomic.
        let tmp = temp_sibling(path, if gz { "nii.gz" } else { "nii" });
        let written = nifti::writer::WriterOptions::new(&tmp)
            .reference_header(&header)
            .write_nifti(&array);
        let result = match written {
            Ok(()) => std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e)),
            Err(NiftiError::Io(e)) => Err(Error::io(path, e)),
            Err(e) => Err(Error::io(path, io::Error::other(e.to_string()))),
        };
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }

    /// Writes a numpy `.npy` file holding an `f32` array of shape `(nz, ny, nx)` in C order,
    /// indexed `arr[z, y, x]` (so `np.load(path)[z, y, x] == vol.at(x, y, z)`).
    pub fn write_npy(&self, path: impl AsRef<Path>) -> Result<()> {
        use ndarray_npy::WriteNpyExt;
        let path = path.as_ref();
        let values = T::as_f32_slice(&self.data);
        let [nx, ny, nz] = self.dims;
        let array = ArrayView3::from_shape((nz, ny, nx), &values[..])
            .expect("volume invariant: data length equals nx * ny * nz");
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut writer = io::BufWriter::new(file);
        array.write_npy(&mut writer).map_err(|e| match e {
            ndarray_npy::WriteNpyError::Io(e) => Error::io(path, e),
            e => Error::io(path, io::Error::other(e.to_string())),
        })?;
        writer.flush().map_err(|e| Error::io(path, e))
    }
}

/// Element type and byte order of a headerless (raw) volume file, for [`Volume::read_raw`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RawType {
    /// Unsigned 8-bit.
    U8,
    /// Unsigned 16-bit, little-endian.
    U16Le,
    /// Unsigned 16-bit, big-endian.
    U16Be,
    /// Signed 16-bit (two's complement), little-endian.
    I16Le,
    /// Signed 16-bit (two's complement), big-endian.
    I16Be,
    /// IEEE 754 32-bit float, little-endian.
    F32Le,
    /// IEEE 754 32-bit float, big-endian.
    F32Be,
}

impl RawType {
    /// Every raw type, in declaration order.
    pub const ALL: [RawType; 7] = [
        RawType::U8,
        RawType::U16Le,
        RawType::U16Be,
        RawType::I16Le,
        RawType::I16Be,
        RawType::F32Le,
        RawType::F32Be,
    ];

    /// Bytes per voxel (1, 2 or 4).
    pub fn bytes_per_voxel(self) -> usize {
        match self {
            RawType::U8 => 1,
            RawType::U16Le | RawType::U16Be | RawType::I16Le | RawType::I16Be => 2,
            RawType::F32Le | RawType::F32Be => 4,
        }
    }

    /// The lower-case name accepted by [`RawType::from_str`]: `u8`, `u16le`, `u16be`,
    /// `i16le`, `i16be`, `f32le`, `f32be`.
    pub fn name(self) -> &'static str {
        match self {
            RawType::U8 => "u8",
            RawType::U16Le => "u16le",
            RawType::U16Be => "u16be",
            RawType::I16Le => "i16le",
            RawType::I16Be => "i16be",
            RawType::F32Le => "f32le",
            RawType::F32Be => "f32be",
        }
    }

    /// Decodes one voxel from exactly `bytes_per_voxel()` bytes.
    #[inline]
    fn decode(self, b: &[u8]) -> f32 {
        match self {
            RawType::U8 => b[0] as f32,
            RawType::U16Le => u16::from_le_bytes([b[0], b[1]]) as f32,
            RawType::U16Be => u16::from_be_bytes([b[0], b[1]]) as f32,
            RawType::I16Le => i16::from_le_bytes([b[0], b[1]]) as f32,
            RawType::I16Be => i16::from_be_bytes([b[0], b[1]]) as f32,
            RawType::F32Le => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            RawType::F32Be => f32::from_be_bytes([b[0], b[1], b[2], b[3]]),
        }
    }
}

impl std::fmt::Display for RawType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RawType {
    type Err = Error;

    /// Parses `u8`, `u16le`, `u16be`, `i16le`, `i16be`, `f32le`, `f32be` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        let lower = s.to_ascii_lowercase();
        RawType::ALL
            .into_iter()
            .find(|t| t.name() == lower)
            .ok_or_else(|| {
                Error::invalid(
                    "raw_type",
                    format!(
                        "{s:?} is not a valid raw type. Valid types are u8, u16le, u16be, \
                         i16le, i16be, f32le, f32be"
                    ),
                )
            })
    }
}

/// File kinds recognised by [`Volume::read`], from the (case-insensitive) file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FileKind {
    Nii,
    NiiGz,
    Npy,
    Other,
}

fn file_kind(path: &Path) -> FileKind {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if name.ends_with(".nii.gz") {
        FileKind::NiiGz
    } else if name.ends_with(".nii") {
        FileKind::Nii
    } else if name.ends_with(".npy") {
        FileKind::Npy
    } else {
        FileKind::Other
    }
}

/// A fresh temporary file name next to `path`, with extension `ext` and no other dots.
fn temp_sibling(path: &Path, ext: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = format!("wscg_tmp_{}_{n}.{ext}", std::process::id());
    match path.parent() {
        Some(dir) => dir.join(name),
        None => PathBuf::from(name),
    }
}

/// Converts a header `f32` to the `f64` with the same shortest decimal form (0.7f32 -> 0.7),
/// so that spacings written as `f32` read back as the decimal the user gave.
fn f32_to_f64_decimal(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(v as f64)
}

/// Reads up to `n` bytes (fewer at end of stream) without trusting `n` for the allocation
/// beyond `reserve`.
fn read_up_to(reader: &mut impl Read, n: u64, reserve: usize) -> io::Result<Vec<u8>> {
    let mut buf = Vec::new();
    buf.try_reserve_exact(reserve)
        .map_err(|e| io::Error::new(io::ErrorKind::OutOfMemory, e.to_string()))?;
    reader.take(n).read_to_end(&mut buf)?;
    Ok(buf)
}

impl Volume<f32> {
    /// Reads a volume file, choosing the reader from the extension (case-insensitive):
    /// `.nii` and `.nii.gz` ([`Volume::read_nifti`]; `spacing`, when given, replaces the
    /// header's voxel size) and `.npy` ([`Volume::read_npy`], array indexed `[z, y, x]`;
    /// `spacing` defaults to `[1, 1, 1]`). Raw files carry no header and need
    /// [`Volume::read_raw`].
    ///
    /// Errors: [`Error::UnsupportedFormat`] for any other extension; the reader's errors.
    pub fn read(path: impl AsRef<Path>, spacing: Option<[f64; 3]>) -> Result<Self> {
        let path = path.as_ref();
        if let Some(s) = spacing {
            check_spacing(s)?;
        }
        match file_kind(path) {
            FileKind::Nii | FileKind::NiiGz => {
                let mut vol = Self::read_nifti(path)?;
                if let Some(s) = spacing {
                    vol.spacing = s;
                }
                Ok(vol)
            }
            FileKind::Npy => Self::read_npy(path, spacing.unwrap_or([1.0; 3])),
            FileKind::Other => {
                let ext = path
                    .extension()
                    .map(|e| format!(".{}", e.to_string_lossy()))
                    .unwrap_or_else(|| "(none)".to_string());
                Err(Error::UnsupportedFormat(format!(
                    "{}: extension {ext} is not a supported volume format. Supported formats \
                     are .nii, .nii.gz and .npy (raw files need Volume::read_raw with dims and \
                     a RawType)",
                    path.display()
                )))
            }
        }
    }

    /// Reads a headerless volume of `dims = [nx, ny, nz]` voxels stored x fastest as
    /// `raw_type`, with voxel size `spacing`; values are converted to `f32` unchanged (no
    /// rescaling).
    ///
    /// Errors: invalid `dims`/`spacing` (as [`Volume::new`]); a file whose size is not exactly
    /// `nx * ny * nz * bytes_per_voxel` ([`Error::Format`], "truncated: expected N bytes, found
    /// M" when too short); I/O failures.
    pub fn read_raw(
        path: impl AsRef<Path>,
        dims: [usize; 3],
        spacing: [f64; 3],
        raw_type: RawType,
    ) -> Result<Self> {
        let path = path.as_ref();
        let n = voxel_count(dims)?;
        check_spacing(spacing)?;
        let bpv = raw_type.bytes_per_voxel();
        let expected = n as u64 * bpv as u64;
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let found = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let size_error = |found: u64| {
            if found < expected {
                Error::format(
                    path,
                    format!("truncated: expected {expected} bytes, found {found}"),
                )
            } else {
                Error::format(
                    path,
                    format!(
                        "size mismatch: expected {expected} bytes ({dims:?} voxels of \
                         {raw_type}), found {found}"
                    ),
                )
            }
        };
        if found != expected {
            return Err(size_error(found));
        }
        let bytes = read_up_to(&mut BufReader::new(file), expected + 1, expected as usize)
            .map_err(|e| Error::io(path, e))?;
        if bytes.len() as u64 != expected {
            return Err(size_error(bytes.len() as u64));
        }
        let data: Vec<f32> = bytes
            .par_chunks_exact(bpv)
            .map(|b| raw_type.decode(b))
            .collect();
        Volume::new(dims, spacing, data)
    }

    /// Reads a single-file NIfTI-1 image (`.nii`, or gzip-compressed `.nii.gz`; compression
    /// is detected from the content).
    ///
    /// - Voxel values are converted to `f32` and scaled by `scl_slope` / `scl_inter` as the
    ///   NIfTI standard says (no scaling when `scl_slope` is 0 or not finite). Supported data
    ///   types: (u)int8/16/32/64, float32, float64.
    /// - `dims = dim[1..4]`; the image must be 3-D (`dim[0] = 3`, or more with every extra
    ///   dimension equal to 1, e.g. a 4-D image with one time point).
    /// - `spacing = |pixdim[1..4]|`, 1.0 where a pixdim is 0 or not finite. The affine
    ///   (orientation and origin) is not applied: voxel `(x, y, z)` of the volume is voxel
    ///   `(i, j, k) = (x, y, z)` of the file, as `nibabel.load(path).get_fdata()[x, y, z]`.
    ///
    /// Errors: [`Error::Io`] naming the path; [`Error::Format`] for a malformed or truncated
    /// file; [`Error::UnsupportedFormat`] for NIfTI-2, `.hdr/.img` pairs, other data types or
    /// non-3-D images; [`Error::LimitExceeded`] when the header declares more than
    /// [`MAX_VOXELS`] voxels. The declared size is checked against the file size (or, for
    /// gzip, against the decompressed stream as it arrives) before anything large is allocated.
    pub fn read_nifti(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let file_len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let mut buffered = BufReader::new(file);
        let head = buffered.fill_buf().map_err(|e| Error::io(path, e))?;
        let gz = head.len() >= 2 && head[0] == 0x1f && head[1] == 0x8b;
        if gz {
            let mut reader = nifti::object::GzDecodedFile::new(buffered);
            read_nifti_stream(path, &mut reader, None)
        } else {
            read_nifti_stream(path, &mut buffered, Some(file_len))
        }
    }

    /// Reads a numpy `.npy` file holding a 3-D array **indexed `arr[z, y, x]`** (shape
    /// `(nz, ny, nx)`), the order in which Python users usually hold CT/MRI stacks; C and
    /// Fortran layouts are both read correctly, so `vol.at(x, y, z) == arr[z, y, x]`. An array
    /// ordered `(X, Y, Z)` in Python must be saved as `np.save(path, arr.transpose(2, 1, 0))`.
    ///
    /// Accepted dtypes (either byte order): float32, float64, uint8, int8, uint16, int16,
    /// uint32, int32, uint64, int64; values are converted to `f32` unchanged. `spacing` is the
    /// voxel size `[sx, sy, sz]` (a `.npy` file does not store one).
    ///
    /// Errors: [`Error::Io`]; [`Error::Format`] for a malformed or truncated file or an array
    /// that is not 3-D or has an empty axis; [`Error::UnsupportedFormat`] for other dtypes;
    /// [`Error::LimitExceeded`] above [`MAX_VOXELS`]; invalid `spacing` as [`Volume::new`].
    pub fn read_npy(path: impl AsRef<Path>, spacing: [f64; 3]) -> Result<Self> {
        let path = path.as_ref();
        check_spacing(spacing)?;
        let arr = crate::npy::read_with_limit::<f32>(path, MAX_VOXELS)?;
        let shape = &arr.shape;
        if shape.len() != 3 {
            return Err(Error::format(
                path,
                format!(
                    "expected a 3-D array indexed [z, y, x], found a {}-D array of shape {shape:?}",
                    shape.len()
                ),
            ));
        }
        let dims = [shape[2], shape[1], shape[0]];
        if dims.contains(&0) {
            return Err(Error::format(
                path,
                format!("the array of shape {shape:?} has an empty axis"),
            ));
        }
        voxel_count(dims)?;
        Volume::new(dims, spacing, arr.data)
    }
}

/// Reads a NIfTI-1 single-file stream (already decompressed). `file_len` is the size of an
/// uncompressed file, used to reject declared sizes the file cannot hold.
fn read_nifti_stream(
    path: &Path,
    reader: &mut impl Read,
    file_len: Option<u64>,
) -> Result<Volume<f32>> {
    // Header.
    let mut raw_header = [0u8; NIFTI1_HEADER_BYTES];
    let mut got = 0;
    while got < raw_header.len() {
        match reader.read(&mut raw_header[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(read_error(path, e)),
        }
    }
    if got < raw_header.len() {
        return Err(Error::format(
            path,
            format!(
                "truncated: a NIfTI-1 header needs {} bytes, found {got}",
                raw_header.len()
            ),
        ));
    }
    let header = NiftiHeader::from_reader(&raw_header[..])
        .map_err(|e| Error::format(path, format!("invalid NIfTI-1 header: {e}")))?;
    if header.sizeof_hdr != NIFTI1_HEADER_BYTES as i32 {
        if header.sizeof_hdr == 540 || header.sizeof_hdr.swap_bytes() == 540 {
            return Err(Error::UnsupportedFormat(format!(
                "{}: a NIfTI-2 file; only NIfTI-1 is supported",
                path.display()
            )));
        }
        return Err(Error::format(
            path,
            format!("not a NIfTI-1 file (sizeof_hdr = {})", header.sizeof_hdr),
        ));
    }
    match &header.magic {
        b"n+1\0" => {}
        b"ni1\0" => {
            return Err(Error::UnsupportedFormat(format!(
                "{}: the header of a .hdr/.img pair; only single-file NIfTI (.nii, .nii.gz) is \
                 supported",
                path.display()
            )))
        }
        m => {
            return Err(Error::format(
                path,
                format!("not a NIfTI-1 file (magic {m:?}, expected \"n+1\\0\")"),
            ))
        }
    }

    // Dimensions.
    let dim = header.dim;
    let ndim = dim[0] as usize;
    if !(1..=7).contains(&ndim) {
        return Err(Error::format(
            path,
            format!("invalid dim[0] = {} (must be 1 to 7)", dim[0]),
        ));
    }
    if let Some(i) = (1..=ndim).find(|&i| dim[i] == 0 || dim[i] > i16::MAX as u16) {
        return Err(Error::format(
            path,
            format!("invalid dim[{i}] = {}", dim[i] as i16),
        ));
    }
    if ndim < 3 || dim[4..=ndim.max(3)].iter().any(|&d| d != 1) {
        return Err(Error::UnsupportedFormat(format!(
            "{}: a {ndim}-D NIfTI image of dims {:?}; only 3-D volumes are supported (extra \
             dimensions must be 1)",
            path.display(),
            &dim[1..=ndim]
        )));
    }
    let dims = [dim[1] as usize, dim[2] as usize, dim[3] as usize];
    let n = voxel_count(dims)?;

    // Data type.
    let datatype = header.data_type().ok();
    let datatype = match datatype {
        Some(
            t @ (NiftiType::Uint8
            | NiftiType::Int8
            | NiftiType::Uint16
            | NiftiType::Int16
            | NiftiType::Uint32
            | NiftiType::Int32
            | NiftiType::Uint64
            | NiftiType::Int64
            | NiftiType::Float32
            | NiftiType::Float64),
        ) => t,
        other => {
            let name = other
                .map(|t| format!("{t:?}"))
                .unwrap_or_else(|| format!("code {}", header.datatype));
            return Err(Error::UnsupportedFormat(format!(
                "{}: NIfTI datatype {name} is not supported (supported: uint8, int8, uint16, \
                 int16, uint32, int32, uint64, int64, float32, float64)",
                path.display()
            )));
        }
    };
    let nbytes = n as u64 * datatype.size_of() as u64;

    // Data offset and declared size against what the file can hold.
    let vox_offset = header.vox_offset;
    if !vox_offset.is_finite()
        || vox_offset < (NIFTI1_HEADER_BYTES as f32)
        || vox_offset as u64 > MAX_NIFTI_VOX_OFFSET
    {
        return Err(Error::format(
            path,
            format!("invalid vox_offset {vox_offset}"),
        ));
    }
    let vox_offset = vox_offset as u64;
    if let Some(len) = file_len {
        let needed = vox_offset + nbytes;
        if len < needed {
            return Err(Error::format(
                path,
                format!(
                    "truncated: header declares {dims:?} voxels of {datatype:?} at offset \
                     {vox_offset}, expected at least {needed} bytes, found {len}"
                ),
            ));
        }
    }

    // Skip extensions, then read exactly the voxel data.
    let skip = vox_offset - NIFTI1_HEADER_BYTES as u64;
    let skipped =
        io::copy(&mut reader.take(skip), &mut io::sink()).map_err(|e| read_error(path, e))?;
    if skipped != skip {
        return Err(Error::format(
            path,
            format!(
                "truncated: the stream ends inside the header extensions (vox_offset {vox_offset})"
            ),
        ));
    }
    // Reserve up front only what an uncompressed file has shown it holds; a compressed stream
    // grows the buffer as data actually arrives.
    let reserve = if file_len.is_some() {
        nbytes as usize
    } else {
        (nbytes as usize).min(64 << 20)
    };
    let raw = read_up_to(reader, nbytes, reserve).map_err(|e| read_error(path, e))?;
    if (raw.len() as u64) < nbytes {
        return Err(Error::format(
            path,
            format!(
                "truncated: expected {nbytes} bytes of voxel data, found {}",
                raw.len()
            ),
        ));
    }

    // Scaling as in the NIfTI standard: slope 0 (or not finite) means none.
    let slope = if header.scl_slope.is_finite() {
        header.scl_slope
    } else {
        0.0
    };
    let inter = if slope != 0.0 && header.scl_inter.is_finite() {
        header.scl_inter
    } else {
        0.0
    };
    let raw_dim = [3, dim[1], dim[2], dim[3], 1, 1, 1, 1];
    let volume = nifti::InMemNiftiVolume::from_raw_fields(
        raw_dim,
        datatype,
        slope,
        inter,
        raw,
        header.endianness,
    )
    .map_err(|e| Error::format(path, e.to_string()))?;
    let array = volume
        .into_ndarray::<f32>()
        .map_err(|e| Error::format(path, e.to_string()))?
        .into_dimensionality::<Ix3>()
        .map_err(|e| Error::format(path, e.to_string()))?;
    // `array` is indexed [x, y, z]; walking [z, y, x] in logical order gives x fastest.
    let zyx = array.permuted_axes([2, 1, 0]);
    let data: Vec<f32> = match zyx.as_slice() {
        Some(s) => s.to_vec(),
        None => zyx.iter().copied().collect(),
    };

    let spacing = [1, 2, 3].map(|i| {
        let p = header.pixdim[i];
        if p.is_finite() && p != 0.0 {
            f32_to_f64_decimal(p.abs())
        } else {
            1.0
        }
    });
    Volume::new(dims, spacing, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_filter_of_a_delta_is_the_kernel_product() {
        use crate::filter::{gaussian_kernel, Border};
        let n = 15;
        let mut v = Volume::filled([n, n + 2, n + 4], [1.0; 3], 0.0f32).unwrap();
        v.set(7, 8, 9, 1.0);
        let g = v
            .gaussian_filter([1.0, 2.0, 0.0], 4.0, Border::Reflect)
            .unwrap();
        let (kx, ky) = (
            gaussian_kernel(1.0, 4.0).unwrap(),
            gaussian_kernel(2.0, 4.0).unwrap(),
        );
        for z in 0..n + 4 {
            for y in 0..n + 2 {
                for x in 0..n {
                    let dx = x as isize - 7 + 4;
                    let dy = y as isize - 8 + 8;
                    let want = if z == 9 && (0..9).contains(&dx) && (0..17).contains(&dy) {
                        kx[dx as usize] * ky[dy as usize]
                    } else {
                        0.0
                    };
                    assert!(
                        (g.at(x, y, z) as f64 - want).abs() < 1e-7,
                        "({x}, {y}, {z})"
                    );
                }
            }
        }
        let c = Volume::filled([5, 6, 7], [1.0; 3], 3.0f32).unwrap();
        let gc = c
            .gaussian_filter([1.5, 1.5, 1.5], 4.0, Border::Reflect)
            .unwrap();
        assert!(gc.data().iter().all(|&x| (x - 3.0).abs() < 1e-6));
        assert!(c
            .gaussian_filter([-1.0, 0.0, 0.0], 4.0, Border::Reflect)
            .is_err());
    }
    use ndarray_npy::WriteNpyExt;

    /// 3 x 4 x 5 volume with unique values v = x + 10 y + 100 z.
    fn unique_volume(spacing: [f64; 3]) -> Volume<f32> {
        Volume::from_fn([3, 4, 5], spacing, |x, y, z| (x + 10 * y + 100 * z) as f32).unwrap()
    }

    fn approx(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    // ---------------------------------------------------------------- construction

    #[test]
    fn layout_is_x_fastest() {
        let v = unique_volume([1.0; 3]);
        assert_eq!(v.dims(), [3, 4, 5]);
        assert_eq!(v.len(), 60);
        assert!(!v.is_empty());
        for z in 0..5 {
            for y in 0..4 {
                for x in 0..3 {
                    let i = x + 3 * (y + 4 * z);
                    assert_eq!(v.index(x, y, z), i);
                    assert_eq!(v.data()[i], (x + 10 * y + 100 * z) as f32);
                    assert_eq!(v.at(x, y, z), v.data()[i]);
                    assert_eq!(v.get(x, y, z), Some(v.data()[i]));
                }
            }
        }
        assert_eq!(v.get(3, 0, 0), None);
        assert_eq!(v.get(0, 4, 0), None);
        assert_eq!(v.get(0, 0, 5), None);
        assert_eq!(v.checked_index(0, 0, 5), None);
        assert_eq!(v.slice_z(2)[3 + 1], v.at(1, 1, 2));
    }

    #[test]
    fn new_checks_arguments() {
        assert!(Volume::new([2, 2, 2], [1.0; 3], vec![0.0f32; 8]).is_ok());
        assert!(matches!(
            Volume::new([2, 2, 2], [1.0; 3], vec![0.0f32; 7]),
            Err(Error::ShapeMismatch(_))
        ));
        assert!(matches!(
            Volume::new([2, 0, 2], [1.0; 3], Vec::<f32>::new()),
            Err(Error::Empty(_))
        ));
        for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
            let e = Volume::new([1, 1, 1], [1.0, bad, 1.0], vec![0.0f32]).unwrap_err();
            assert!(
                matches!(
                    e,
                    Error::InvalidArgument {
                        name: "spacing",
                        ..
                    }
                ),
                "{bad}: {e}"
            );
        }
        assert!(matches!(
            Volume::filled([usize::MAX, 2, 1], [1.0; 3], 0u8),
            Err(Error::LimitExceeded(_))
        ));
        assert!(matches!(
            Volume::filled([100_000, 100_000, 100_000], [1.0; 3], 0u8),
            Err(Error::LimitExceeded(_))
        ));
        let f = Volume::filled([2, 3, 4], [0.5, 1.0, 2.0], 7u16).unwrap();
        assert!(f.data().iter().all(|&v| v == 7));
        assert_eq!(f.extent(), [1.0, 3.0, 8.0]);
    }

    #[test]
    fn set_map_min_max_and_finite_check() {
        let mut v = unique_volume([1.0; 3]);
        v.set(1, 2, 3, -5.0);
        assert_eq!(v.at(1, 2, 3), -5.0);
        assert_eq!(v.min_max(), Some((-5.0, 432.0)));
        v.set(0, 0, 0, f32::NAN);
        assert_eq!(v.min_max(), Some((-5.0, 432.0)));
        assert!(matches!(
            v.ensure_finite("vol"),
            Err(Error::NonFinite {
                name: "vol",
                index: 0
            })
        ));
        let all_nan = Volume::filled([2, 2, 2], [1.0; 3], f64::NAN).unwrap();
        assert_eq!(all_nan.min_max(), None);
        let doubled = unique_volume([1.0; 3]).map(|x| 2.0 * x as f64);
        assert_eq!(doubled.at(1, 2, 3), 2.0 * 321.0);
        assert!(doubled.ensure_finite("d").is_ok());
    }

    #[test]
    #[should_panic(expected = "outside")]
    fn at_panics_outside() {
        unique_volume([1.0; 3]).at(0, 4, 0);
    }

    // ---------------------------------------------------------------- sampling

    const A: f64 = 1.25;
    const B: f64 = -0.75;
    const C: f64 = 2.5;
    const D: f64 = 0.375;

    fn affine(x: f64, y: f64, z: f64) -> f64 {
        A + B * x + C * y + D * z
    }

    #[test]
    fn trilinear_is_exact_on_voxels_and_affine_functions() {
        let v = Volume::from_fn([6, 5, 7], [0.5, 1.5, 3.0], |x, y, z| {
            affine(x as f64, y as f64, z as f64)
        })
        .unwrap();
        for z in 0..7 {
            for y in 0..5 {
                for x in 0..6 {
                    let p = [x as f64, y as f64, z as f64];
                    assert_eq!(v.trilinear(p), v.at(x, y, z));
                }
            }
        }
        // Pseudo-random interior points.
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..500 {
            let p = [5.0 * next(), 4.0 * next(), 6.0 * next()];
            let want = affine(p[0], p[1], p[2]);
            assert!(approx(v.trilinear(p), want, 1e-14), "{p:?}");
            let w = [p[0] * 0.5, p[1] * 1.5, p[2] * 3.0];
            assert!(approx(v.trilinear_world(w), want, 1e-13), "{w:?}");
        }
        // f32 volumes agree to f32 precision.
        let v32 = v.map(|x| x as f32);
        let p = [1.3, 2.7, 4.1];
        assert!(approx(v32.trilinear(p) as f64, affine(1.3, 2.7, 4.1), 1e-6));
    }

    #[test]
    fn trilinear_reproduces_multilinear_function() {
        // x*y*z is trilinear, so it is reproduced exactly; a wrong weighting would not.
        let v = Volume::from_fn([4, 4, 4], [1.0; 3], |x, y, z| (x * y * z) as f64).unwrap();
        let p = [1.25, 2.5, 0.75];
        assert!(approx(v.trilinear(p), 1.25 * 2.5 * 0.75, 1e-14));
    }

    #[test]
    fn trilinear_clamps_to_border() {
        let v = Volume::from_fn([3, 4, 5], [1.0; 3], |x, y, z| {
            affine(x as f64, y as f64, z as f64)
        })
        .unwrap();
        assert_eq!(v.trilinear([-3.0, 1.0, 2.0]), v.at(0, 1, 2));
        assert_eq!(v.trilinear([10.0, 1.0, 2.0]), v.at(2, 1, 2));
        assert_eq!(v.trilinear([2.0, 3.0, 99.0]), v.at(2, 3, 4));
        assert!(approx(
            v.trilinear([-1.0, 1.5, 2.0]),
            affine(0.0, 1.5, 2.0),
            1e-14
        ));
        assert!(v.trilinear([f64::NAN, 0.0, 0.0]).is_nan());
        // A single-voxel axis is constant.
        let flat = Volume::from_fn([3, 3, 1], [1.0; 3], |x, y, _| (x + y) as f64).unwrap();
        assert_eq!(flat.trilinear([1.0, 1.0, 0.7]), 2.0);
        assert_eq!(flat.gradient_at(1, 1, 0)[2], 0.0);
    }

    #[test]
    fn gradient_of_affine_is_exact_with_anisotropic_spacing_everywhere() {
        let spacing = [0.5, 2.0, 3.0];
        let v = Volume::from_fn([5, 4, 6], spacing, |x, y, z| {
            affine(x as f64, y as f64, z as f64)
        })
        .unwrap();
        let want = [B / spacing[0], C / spacing[1], D / spacing[2]];
        let [gx, gy, gz] = v.gradient_volume();
        for z in 0..6 {
            for y in 0..4 {
                for x in 0..5 {
                    let g = v.gradient_at(x, y, z);
                    for a in 0..3 {
                        assert!(approx(g[a], want[a], 1e-13), "{x} {y} {z} axis {a}");
                    }
                    assert_eq!([gx.at(x, y, z), gy.at(x, y, z), gz.at(x, y, z)], g);
                }
            }
        }
        assert_eq!(gx.spacing(), spacing);
        for p in [[0.3, 2.9, 4.4], [-1.0, 0.0, 9.0], [4.0, 3.0, 5.0]] {
            let g = v.gradient_trilinear(p);
            for a in 0..3 {
                assert!(approx(g[a], want[a], 1e-13), "{p:?}");
            }
        }
    }

    #[test]
    fn gradient_uses_central_inside_and_one_sided_on_borders() {
        // f = x^2 with spacing 2: central (x+1)^2-(x-1)^2 / 4 = x; border (1-0)/2, (16-9)/2.
        let v = Volume::from_fn([5, 1, 1], [2.0, 1.0, 1.0], |x, _, _| (x * x) as f64).unwrap();
        let gx: Vec<f64> = (0..5).map(|x| v.gradient_at(x, 0, 0)[0]).collect();
        assert_eq!(gx, vec![0.5, 1.0, 2.0, 3.0, 3.5]);
        // Interpolated gradient between voxels 1 and 2 is the mean of their gradients.
        assert_eq!(v.gradient_trilinear([1.5, 0.0, 0.0])[0], 1.5);
        assert_eq!(v.gradient_trilinear([2.0, 0.0, 0.0])[0], 2.0);
    }

    // ---------------------------------------------------------------- ndarray

    #[test]
    fn zyx_views_follow_numpy_order() {
        let v = unique_volume([1.0, 2.0, 3.0]);
        let a = v.to_zyx();
        assert_eq!(a.dim(), (5, 4, 3));
        assert_eq!(a[[4, 2, 1]], v.at(1, 2, 4));
        assert_eq!(v.view_zyx()[[3, 1, 2]], v.at(2, 1, 3));
        let back = Volume::from_zyx(a.view(), v.spacing()).unwrap();
        assert_eq!(back, v);
        // A Fortran-ordered array with the same logical indexing gives the same volume.
        let f = Array3::from_shape_fn((5, 4, 3).f(), |(z, y, x)| (x + 10 * y + 100 * z) as f32);
        assert_eq!(Volume::from_zyx(f.view(), v.spacing()).unwrap(), v);
        assert_eq!(v.clone().into_zyx(), a);
        let empty = Array3::<f32>::zeros((0, 2, 2));
        assert!(Volume::from_zyx(empty.view(), [1.0; 3]).is_err());
    }

    // ---------------------------------------------------------------- raw

    #[test]
    fn raw_reads_every_type_with_known_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(RawType, Vec<u8>, [f32; 2]); 7] = [
            (RawType::U8, vec![7, 250], [7.0, 250.0]),
            (
                RawType::U16Le,
                vec![0x01, 0x02, 0xff, 0xff],
                [513.0, 65535.0],
            ),
            (
                RawType::U16Be,
                vec![0x01, 0x02, 0xff, 0xfe],
                [258.0, 65534.0],
            ),
            (RawType::I16Le, vec![0x01, 0x02, 0xfe, 0xff], [513.0, -2.0]),
            (
                RawType::I16Be,
                vec![0x01, 0x02, 0x80, 0x00],
                [258.0, -32768.0],
            ),
            (
                RawType::F32Le,
                [1.5f32.to_le_bytes(), (-2.25f32).to_le_bytes()].concat(),
                [1.5, -2.25],
            ),
            (
                RawType::F32Be,
                [1.5f32.to_be_bytes(), (-2.25f32).to_be_bytes()].concat(),
                [1.5, -2.25],
            ),
        ];
        for (t, bytes, want) in cases {
            assert_eq!(bytes.len(), 2 * t.bytes_per_voxel());
            let p = dir.path().join(format!("v_{t}.raw"));
            std::fs::write(&p, &bytes).unwrap();
            let v = Volume::read_raw(&p, [2, 1, 1], [1.0, 2.0, 3.0], t).unwrap();
            assert_eq!(v.data(), &want, "{t}");
            assert_eq!(v.spacing(), [1.0, 2.0, 3.0]);
            assert_eq!(t.name().parse::<RawType>().unwrap(), t);
            // Reader leaves the file alone.
            assert_eq!(std::fs::read(&p).unwrap(), bytes);
        }
        assert!("u32".parse::<RawType>().is_err());
    }

    #[test]
    fn raw_round_trip_and_size_errors() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.5, 1.0, 2.0]);
        let p = dir.path().join("v.raw");
        v.write_raw_f32_le(&p).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 60 * 4);
        let bytes = std::fs::read(&p).unwrap();
        // x fastest on disk: second value is voxel (1, 0, 0), fourth is (0, 1, 0).
        assert_eq!(f32::from_le_bytes(bytes[4..8].try_into().unwrap()), 1.0);
        assert_eq!(f32::from_le_bytes(bytes[12..16].try_into().unwrap()), 10.0);
        let back = Volume::read_raw(&p, [3, 4, 5], [0.5, 1.0, 2.0], RawType::F32Le).unwrap();
        assert_eq!(back, v);

        let short = dir.path().join("short.raw");
        std::fs::write(&short, &bytes[..100]).unwrap();
        let e = Volume::read_raw(&short, [3, 4, 5], [1.0; 3], RawType::F32Le).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::Format { .. }), "{msg}");
        assert!(
            msg.contains("truncated: expected 240 bytes, found 100"),
            "{msg}"
        );
        assert!(msg.contains("short.raw"), "{msg}");
        // Too long is an error too.
        assert!(Volume::read_raw(&p, [3, 4, 4], [1.0; 3], RawType::F32Le).is_err());
        // Missing file.
        let e = Volume::read_raw(
            dir.path().join("nope.raw"),
            [1, 1, 1],
            [1.0; 3],
            RawType::U8,
        )
        .unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(Volume::read_raw(&p, [3, 4, 5], [f64::NAN, 1.0, 1.0], RawType::F32Le).is_err());
    }

    // ---------------------------------------------------------------- NIfTI

    #[test]
    fn nifti_round_trip_preserves_values_dims_spacing_and_axis_order() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.7, 1.25, 3.0]);
        for name in ["vol.nii", "vol.nii.gz", "my.scan.v2.nii", "UPPER.NII.GZ"] {
            let p = dir.path().join(name);
            v.write_nifti(&p).unwrap();
            assert!(p.exists(), "{name}");
            let back = Volume::read_nifti(&p).unwrap();
            assert_eq!(back.dims(), [3, 4, 5], "{name}");
            assert_eq!(back.spacing(), [0.7, 1.25, 3.0], "{name}");
            assert_eq!(back.data(), v.data(), "{name}");
            assert_eq!(back.at(2, 1, 4), 412.0);
            let via_read = Volume::read(&p, None).unwrap();
            assert_eq!(via_read, back);
            let respaced = Volume::read(&p, Some([2.0; 3])).unwrap();
            assert_eq!(respaced.spacing(), [2.0; 3]);
        }
        // Only the requested files exist: no temporaries left, nothing renamed.
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["UPPER.NII.GZ", "my.scan.v2.nii", "vol.nii", "vol.nii.gz"]
        );
    }

    #[test]
    fn nifti_file_layout_matches_the_standard() {
        // Check the bytes on disk, not only our own round trip: dims at offset 40, pixdim at
        // 76, float32 datatype, x-fastest data from vox_offset 352.
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.5, 1.0, 2.0]);
        let p = dir.path().join("v.nii");
        v.write_nifti(&p).unwrap();
        let b = std::fs::read(&p).unwrap();
        let i16_at = |o: usize| i16::from_le_bytes([b[o], b[o + 1]]);
        let f32_at = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        assert_eq!(i32::from_le_bytes(b[0..4].try_into().unwrap()), 348);
        assert_eq!(
            [i16_at(40), i16_at(42), i16_at(44), i16_at(46)],
            [3, 3, 4, 5]
        );
        assert_eq!(i16_at(70), 16); // NIFTI_TYPE_FLOAT32
        assert_eq!([f32_at(80), f32_at(84), f32_at(88)], [0.5, 1.0, 2.0]);
        assert_eq!(f32_at(108), 352.0);
        assert_eq!(&b[344..348], b"n+1\0");
        let data: Vec<f32> = b[352..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(data, v.data());
    }

    fn patch(bytes: &mut [u8], offset: usize, new: &[u8]) {
        bytes[offset..offset + new.len()].copy_from_slice(new);
    }

    #[test]
    fn nifti_applies_scaling_integer_types_and_4d_with_one_frame() {
        let dir = tempfile::tempdir().unwrap();
        // int16 data written by the nifti crate, logical shape [x, y, z, t=1].
        let a = ndarray::Array4::from_shape_fn((3, 4, 5, 1), |(x, y, z, _)| {
            (x as i16) - 10 * (y as i16) + 100 * (z as i16)
        });
        let p = dir.path().join("i16.nii");
        nifti::writer::WriterOptions::new(&p)
            .write_nifti(&a)
            .unwrap();
        let v = Volume::read_nifti(&p).unwrap();
        assert_eq!(v.dims(), [3, 4, 5]);
        assert_eq!(v.at(2, 3, 4), (2 - 30 + 400) as f32);
        assert_eq!(v.at(1, 0, 0), 1.0);

        // Patch scl_slope = 2, scl_inter = 10 (offsets 112, 116).
        let mut b = std::fs::read(&p).unwrap();
        patch(&mut b, 112, &2.0f32.to_le_bytes());
        patch(&mut b, 116, &10.0f32.to_le_bytes());
        // pixdim[2] = 0 -> spacing 1; pixdim[3] = NaN -> spacing 1; pixdim[1] = -0.5 -> 0.5.
        patch(&mut b, 80, &(-0.5f32).to_le_bytes());
        patch(&mut b, 84, &0.0f32.to_le_bytes());
        patch(&mut b, 88, &f32::NAN.to_le_bytes());
        let q = dir.path().join("scaled.nii");
        std::fs::write(&q, &b).unwrap();
        let s = Volume::read_nifti(&q).unwrap();
        assert_eq!(s.at(2, 3, 4), 2.0 * 372.0 + 10.0);
        assert_eq!(s.spacing(), [0.5, 1.0, 1.0]);

        // A real 4-D series (t = 2) is refused.
        let a2 = ndarray::Array4::<f32>::zeros((3, 4, 5, 2));
        let p2 = dir.path().join("t2.nii");
        nifti::writer::WriterOptions::new(&p2)
            .write_nifti(&a2)
            .unwrap();
        assert!(matches!(
            Volume::read_nifti(&p2),
            Err(Error::UnsupportedFormat(_))
        ));
        // A 2-D image is refused.
        let a3 = ndarray::Array2::<f32>::zeros((3, 4));
        let p3 = dir.path().join("2d.nii");
        nifti::writer::WriterOptions::new(&p3)
            .write_nifti(&a3)
            .unwrap();
        assert!(Volume::read_nifti(&p3).is_err());
    }

    /// Minimal gzip (stored deflate blocks) so tests can compress without extra crates.
    fn gzip_stored(data: &[u8]) -> Vec<u8> {
        fn crc32(data: &[u8]) -> u32 {
            let mut c = 0xffff_ffffu32;
            for &b in data {
                c ^= b as u32;
                for _ in 0..8 {
                    c = if c & 1 != 0 {
                        (c >> 1) ^ 0xedb8_8320
                    } else {
                        c >> 1
                    };
                }
            }
            !c
        }
        let mut out = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 255];
        let chunks: Vec<&[u8]> = data.chunks(65535).collect();
        for (i, ch) in chunks.iter().enumerate() {
            out.push(u8::from(i + 1 == chunks.len()));
            let len = ch.len() as u16;
            out.extend_from_slice(&len.to_le_bytes());
            out.extend_from_slice(&(!len).to_le_bytes());
            out.extend_from_slice(ch);
        }
        out.extend_from_slice(&crc32(data).to_le_bytes());
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out
    }

    #[test]
    fn nifti_hostile_headers_fail_without_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ok.nii");
        unique_volume([1.0; 3]).write_nifti(&p).unwrap();
        let good = std::fs::read(&p).unwrap();
        // Our gzip helper produces files the reader accepts.
        let gz_ok = dir.path().join("ok_gz.nii.gz");
        std::fs::write(&gz_ok, gzip_stored(&good)).unwrap();
        assert_eq!(
            Volume::read_nifti(&gz_ok).unwrap(),
            Volume::read_nifti(&p).unwrap()
        );

        // 10^12 voxels: over the limit.
        let mut huge = good.clone();
        for o in [42, 44, 46] {
            patch(&mut huge, o, &10_000i16.to_le_bytes());
        }
        // 10^8 voxels (400 MB): under the limit, but the file cannot hold it.
        let mut big = good.clone();
        for (o, d) in [(42, 1000i16), (44, 1000), (46, 100)] {
            patch(&mut big, o, &d.to_le_bytes());
        }
        for (name, bytes, limit) in [
            ("huge.nii", huge.clone(), true),
            ("huge.nii.gz", gzip_stored(&huge), true),
            ("big.nii", big.clone(), false),
            ("big.nii.gz", gzip_stored(&big), false),
        ] {
            let q = dir.path().join(name);
            std::fs::write(&q, &bytes).unwrap();
            let e = Volume::read_nifti(&q).unwrap_err();
            if limit {
                assert!(matches!(e, Error::LimitExceeded(_)), "{name}: {e}");
            } else {
                assert!(matches!(e, Error::Format { .. }), "{name}: {e}");
                assert!(e.to_string().contains(name), "{name}: {e}");
            }
        }

        // Truncated data, garbage, wrong datatype, hostile vox_offset, truncated gzip.
        let mut bad_type = good.clone();
        patch(&mut bad_type, 70, &128i16.to_le_bytes()); // RGB24
        let mut bad_offset = good.clone();
        patch(&mut bad_offset, 108, &1.0e30f32.to_le_bytes());
        let gz = gzip_stored(&good);
        let cases: Vec<(&str, Vec<u8>)> = vec![
            ("cut.nii", good[..good.len() - 1].to_vec()),
            ("cut_header.nii", good[..200].to_vec()),
            ("garbage.nii", b"this is not a nifti file at all".repeat(20)),
            ("empty.nii", Vec::new()),
            ("rgb.nii", bad_type),
            ("offset.nii", bad_offset),
            ("cut.nii.gz", gz[..gz.len() / 2].to_vec()),
        ];
        for (name, bytes) in cases {
            let q = dir.path().join(name);
            std::fs::write(&q, &bytes).unwrap();
            let e = Volume::read_nifti(&q).unwrap_err();
            assert!(e.is_io(), "{name}: {e}");
            assert!(e.to_string().contains(name), "{name}: {e}");
            // Readers leave inputs unchanged.
            assert_eq!(std::fs::read(&q).unwrap(), bytes);
        }
        let e = Volume::read_nifti(dir.path().join("missing.nii")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(e.to_string().contains("missing.nii"));
    }

    #[test]
    fn nifti_writer_checks_the_name() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([1.0; 3]);
        assert!(matches!(
            v.write_nifti(dir.path().join("v.hdr")),
            Err(Error::UnsupportedFormat(_))
        ));
        assert!(matches!(
            v.write_nifti(dir.path().join("no_ext")),
            Err(Error::UnsupportedFormat(_))
        ));
        assert!(matches!(
            v.write_nifti(dir.path().join("missing_dir").join("v.nii")),
            Err(Error::Io { .. })
        ));
    }

    // ---------------------------------------------------------------- npy

    #[test]
    fn npy_round_trip_uses_zyx_convention() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.5, 1.0, 2.0]);
        let p = dir.path().join("v.npy");
        v.write_npy(&p).unwrap();
        let arr: Array3<f32> = ndarray_npy::read_npy(&p).unwrap();
        assert_eq!(arr.dim(), (5, 4, 3));
        for ((z, y, x), &a) in arr.indexed_iter() {
            assert_eq!(a, v.at(x, y, z));
        }
        let header = String::from_utf8_lossy(&std::fs::read(&p).unwrap()[..128]).into_owned();
        assert!(header.contains("(5, 4, 3)"), "{header}");
        assert!(header.contains("'fortran_order': False"), "{header}");
        let back = Volume::read_npy(&p, [0.5, 1.0, 2.0]).unwrap();
        assert_eq!(back, v);
        assert_eq!(Volume::read(&p, Some([0.5, 1.0, 2.0])).unwrap(), v);
        assert_eq!(Volume::read(&p, None).unwrap().spacing(), [1.0; 3]);
    }

    #[test]
    fn npy_reads_other_dtypes_and_fortran_order() {
        let dir = tempfile::tempdir().unwrap();
        let f = |z: usize, y: usize, x: usize| x + 10 * y + 100 * z;
        let want = unique_volume([1.0; 3]);
        let check = |name: &str, write: &dyn Fn(&Path)| {
            let p = dir.path().join(name);
            write(&p);
            assert_eq!(Volume::read_npy(&p, [1.0; 3]).unwrap(), want, "{name}");
        };
        check("f64.npy", &|p| {
            ndarray_npy::write_npy(
                p,
                &Array3::from_shape_fn((5, 4, 3), |(z, y, x)| f(z, y, x) as f64),
            )
            .unwrap()
        });
        check("u16.npy", &|p| {
            ndarray_npy::write_npy(
                p,
                &Array3::from_shape_fn((5, 4, 3), |(z, y, x)| f(z, y, x) as u16),
            )
            .unwrap()
        });
        check("i16_fortran.npy", &|p| {
            let a = Array3::from_shape_fn((5, 4, 3).f(), |(z, y, x)| f(z, y, x) as i16);
            ndarray_npy::write_npy(p, &a).unwrap()
        });
        let small =
            Volume::from_fn([3, 4, 5], [1.0; 3], |x, y, z| (x + 3 * y + 12 * z) as f32).unwrap();
        let p = dir.path().join("u8.npy");
        let a = Array3::from_shape_fn((5, 4, 3), |(z, y, x)| (x + 3 * y + 12 * z) as u8);
        let mut file = File::create(&p).unwrap();
        a.write_npy(&mut file).unwrap();
        drop(file);
        assert_eq!(Volume::read_npy(&p, [1.0; 3]).unwrap(), small);
    }

    #[test]
    fn npy_bad_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p2 = dir.path().join("flat.npy");
        ndarray_npy::write_npy(&p2, &ndarray::Array2::<f32>::zeros((4, 5))).unwrap();
        let e = Volume::read_npy(&p2, [1.0; 3]).unwrap_err();
        assert!(e.to_string().contains("3-D"), "{e}");
        assert!(e.to_string().contains("flat.npy"), "{e}");

        let pb = dir.path().join("bool.npy");
        ndarray_npy::write_npy(&pb, &Array3::from_elem((2, 2, 2), true)).unwrap();
        assert!(matches!(
            Volume::read_npy(&pb, [1.0; 3]),
            Err(Error::UnsupportedFormat(_))
        ));

        let good = dir.path().join("good.npy");
        unique_volume([1.0; 3]).write_npy(&good).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = dir.path().join("cut.npy");
        std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
        assert!(matches!(
            Volume::read_npy(&cut, [1.0; 3]),
            Err(Error::Format { .. })
        ));
        // Hostile shapes in the header: an error before any allocation of that size.
        let start = bytes.windows(9).position(|w| w == b"(5, 4, 3)").unwrap();
        for (shape, limit) in [
            (&b"(99999, 999, 999)"[..], true),
            (b"(1000, 999, 100)", false),
        ] {
            let mut hb = bytes[..start].to_vec();
            hb.extend_from_slice(shape);
            hb.extend_from_slice(&bytes[start + 9..]);
            // Keep the declared header length right: drop as many padding spaces as added.
            let nl = hb.iter().position(|&c| c == b'\n').unwrap();
            hb.drain(nl - (shape.len() - 9)..nl);
            let hp = dir.path().join("hostile.npy");
            std::fs::write(&hp, &hb).unwrap();
            let e = Volume::read_npy(&hp, [1.0; 3]).unwrap_err();
            if limit {
                assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
            } else {
                assert!(matches!(e, Error::Format { .. }), "{e}");
                assert!(e.to_string().contains("truncated"), "{e}");
            }
        }
        // Header length field pointing past the end of the file.
        let mut lie = bytes.clone();
        patch(&mut lie, 8, &u16::MAX.to_le_bytes());
        let lp = dir.path().join("lie.npy");
        std::fs::write(&lp, &lie).unwrap();
        assert!(matches!(
            Volume::read_npy(&lp, [1.0; 3]),
            Err(Error::Format { .. })
        ));

        let garbage = dir.path().join("garbage.npy");
        std::fs::write(&garbage, b"not numpy").unwrap();
        assert!(matches!(
            Volume::read_npy(&garbage, [1.0; 3]),
            Err(Error::Format { .. })
        ));
        assert!(matches!(
            Volume::read_npy(dir.path().join("missing.npy"), [1.0; 3]),
            Err(Error::Io { .. })
        ));
        assert!(Volume::read_npy(&good, [0.0, 1.0, 1.0]).is_err());
    }

    #[test]
    fn read_dispatch_rejects_unknown_extensions() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.mhd");
        std::fs::write(&p, b"x").unwrap();
        let e = Volume::read(&p, None).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::UnsupportedFormat(_)));
        assert!(
            msg.contains(".mhd") && msg.contains(".nii.gz") && msg.contains(".npy"),
            "{msg}"
        );
        assert!(Volume::read(dir.path().join("v.nii"), None).is_err());
    }
}
