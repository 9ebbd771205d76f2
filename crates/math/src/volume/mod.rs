//! [`Volume`]: a scalar X x Y x Z voxel grid with physical voxel spacing, trilinear sampling and
//! finite-difference gradients.
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
//! [`Volume::trilinear_world`] takes, and what every algorithm of the workspace works in.
//!
//! # Orientation: the voxel-to-world affine
//!
//! A volume read from a file that places it in the scanner's frame (a NIfTI sform or qform, a
//! DICOM series' ImagePositionPatient / ImageOrientationPatient) also carries that file's
//! [`Affine`]: the 3 x 4 matrix `A` with `(x, y, z) = A (i, j, k, 1)` for the centre of voxel
//! `(i, j, k)`, in millimetres, in the **RAS+** frame (x increasing towards the patient's
//! right, y anterior, z superior: the frame of NIfTI's sform, and of every file wscg writes).
//! DICOM's patient frame is LPS+; the DICOM reader converts it by negating the x and y rows.
//! [`Volume::affine`] is that matrix, `None` when the file gave none;
//! [`Volume::voxel_to_world`] is the matrix used for output, the diagonal of the spacing
//! (the grid coordinates above) when no affine is known. Writers of derived volumes and
//! meshes copy it ([`Volume::copy_geometry`]) so that their output lies where the input lay.
//!
//! # Files and filters
//!
//! Smoothing is in [`filter`] ([`Volume::gaussian_filter`]). Raw, NIfTI-1 and `.npy` files are
//! read and written by [`crate::io`] (feature `io-volume`), which adds `Volume::read`,
//! `Volume::read_raw`, `Volume::read_nifti`, `Volume::read_npy` and the matching writers.

use std::borrow::Cow;

use ndarray::{Array3, ArrayView3, ArrayViewMut3};
use rayon::prelude::*;

use crate::error::{ensure_positive, Error, Result};

pub mod filter;

/// Largest number of voxels a volume may have (`2^33`, e.g. 2048 x 2048 x 2048, 32 GiB as
/// `f32`). Constructors and readers refuse larger requests with [`Error::LimitExceeded`], so a
/// hostile file header cannot make us allocate without bound.
pub const MAX_VOXELS: usize = 1 << 33;

/// A voxel-to-world affine: rows `x`, `y`, `z` of the 4 x 4 matrix whose last row is
/// `(0, 0, 0, 1)`; world point = `A * (i, j, k, 1)` (see the [module documentation](self):
/// millimetres, RAS+).
pub type Affine = [[f64; 4]; 3];

/// The affine of an unoriented grid: `diag(spacing)`, no offset.
pub fn spacing_affine(spacing: [f64; 3]) -> Affine {
    let mut a = [[0.0; 4]; 3];
    for r in 0..3 {
        a[r][r] = spacing[r];
    }
    a
}

/// Applies an affine to a voxel position `(i, j, k)` (fractional positions allowed).
#[inline]
pub fn apply_affine(a: &Affine, p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2] + a[r][3])
}

/// Checks that an affine is finite and invertible (its three columns independent) and returns
/// the lengths of its columns: the voxel spacing it implies.
///
/// Errors: [`Error::InvalidArgument`] naming `affine`.
pub fn check_affine(a: &Affine) -> Result<[f64; 3]> {
    if a.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::invalid("affine", "has non-finite entries"));
    }
    let col = |c: usize| [a[0][c], a[1][c], a[2][c]];
    let norms = [0, 1, 2].map(|c| crate::vec3::norm(col(c)));
    let [u, v, w] = [col(0), col(1), col(2)];
    let det = crate::vec3::dot(u, crate::vec3::cross(v, w));
    let scale = norms[0] * norms[1] * norms[2];
    if scale <= 0.0 || !scale.is_finite() || det.abs() <= 1e-9 * scale {
        return Err(Error::invalid(
            "affine",
            format!("is singular (columns {:?}, {:?}, {:?})", u, v, w),
        ));
    }
    Ok(norms)
}

/// A scalar volume: `nx x ny x nz` voxels with a physical voxel size, stored x fastest.
///
/// See the [module documentation](self) for the layout and the coordinate conventions.
/// The element type defaults to `f32`; sampling and gradients are provided for `f32` and
/// `f64` (the [`Real`] types), and any `T` can be stored (labels as `u8`, masks as `bool`...).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume<T = f32> {
    pub(crate) dims: [usize; 3],
    pub(crate) spacing: [f64; 3],
    pub(crate) data: Vec<T>,
    /// The file's voxel-to-world affine (RAS+, mm), `None` when unknown.
    pub(crate) affine: Option<Affine>,
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
pub(crate) fn voxel_count(dims: [usize; 3]) -> Result<usize> {
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

/// Checks the parts of a volume: dims (as [`voxel_count`]), spacing (as [`check_spacing`]) and
/// a data length of `nx * ny * nz` ([`Error::ShapeMismatch`]).
pub(crate) fn check_parts(dims: [usize; 3], spacing: [f64; 3], len: usize) -> Result<()> {
    let n = voxel_count(dims)?;
    check_spacing(spacing)?;
    if len != n {
        return Err(Error::ShapeMismatch(format!(
            "volume data has {len} values, but dims {dims:?} need {n}"
        )));
    }
    Ok(())
}

/// Checks that every spacing component is finite and > 0.
pub(crate) fn check_spacing(spacing: [f64; 3]) -> Result<()> {
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
        check_parts(dims, spacing, data.len())?;
        Ok(Volume {
            dims,
            spacing,
            data,
            affine: None,
        })
    }

    /// A volume whose voxel `(x, y, z)` is `f(x, y, z)`, evaluated in parallel (rayon, one task
    /// per z slice). Errors as [`Volume::filled`].
    pub fn from_fn<F>(dims: [usize; 3], spacing: [f64; 3], f: F) -> Result<Self>
    where
        T: Send,
        F: Fn(usize, usize, usize) -> T + Sync + Send,
    {
        crate::alloc::ensure::<T>("dims", voxel_count(dims)?)?;
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
            affine: None,
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
            affine: None,
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

    /// Replaces the voxel spacing. Errors unless every component is finite and > 0. A known
    /// [`affine`](Volume::affine) keeps its directions and origin, its columns rescaled to the
    /// new spacing.
    pub fn set_spacing(&mut self, spacing: [f64; 3]) -> Result<()> {
        check_spacing(spacing)?;
        if let Some(a) = &mut self.affine {
            for (c, (&new, &old)) in spacing.iter().zip(&self.spacing).enumerate() {
                for row in a.iter_mut() {
                    row[c] *= new / old;
                }
            }
        }
        self.spacing = spacing;
        Ok(())
    }

    /// The voxel-to-world affine the volume's file gave (RAS+, millimetres; see the
    /// [module documentation](self)), `None` when it gave none.
    #[inline]
    pub fn affine(&self) -> Option<Affine> {
        self.affine
    }

    /// The voxel-to-world affine of output files: [`Volume::affine`] when known, otherwise
    /// `diag(spacing)` (voxel `(i, j, k)` at `(i sx, j sy, k sz)`).
    pub fn voxel_to_world(&self) -> Affine {
        self.affine.unwrap_or_else(|| spacing_affine(self.spacing))
    }

    /// Sets (or, with `None`, forgets) the voxel-to-world affine; the spacing becomes the
    /// lengths of its columns.
    ///
    /// Errors: an affine with non-finite entries or dependent columns
    /// ([`Error::InvalidArgument`] naming `affine`).
    pub fn set_affine(&mut self, affine: Option<Affine>) -> Result<()> {
        if let Some(a) = &affine {
            self.spacing = check_affine(a)?;
        }
        self.affine = affine;
        Ok(())
    }

    /// Gives `self` the geometry (spacing and affine) of `other`, the volume it was derived
    /// from, so that a label volume, a mask or a filtered volume is written where its input
    /// lay.
    ///
    /// Errors: other dims than `other`'s ([`Error::ShapeMismatch`]).
    pub fn copy_geometry<U>(&mut self, other: &Volume<U>) -> Result<()> {
        if self.dims != other.dims {
            return Err(Error::ShapeMismatch(format!(
                "cannot copy the geometry of a volume of dims {:?} to one of dims {:?}",
                other.dims, self.dims
            )));
        }
        self.spacing = other.spacing;
        self.affine = other.affine;
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
            affine: self.affine,
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
    /// Errors as [`Volume::new`], and [`Error::OutOfMemory`] naming `dims` when the voxels do
    /// not fit in memory ([`crate::alloc`]).
    pub fn filled(dims: [usize; 3], spacing: [f64; 3], value: T) -> Result<Self> {
        let n = voxel_count(dims)?;
        check_spacing(spacing)?;
        Ok(Volume {
            dims,
            spacing,
            data: crate::alloc::try_vec("dims", value, n)?,
            affine: None,
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
            affine: self.affine,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use ndarray::ShapeBuilder;

    /// 3 x 4 x 5 volume with unique values v = x + 10 y + 100 z.
    pub(crate) fn unique_volume(spacing: [f64; 3]) -> Volume<f32> {
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
}
