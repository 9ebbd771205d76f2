//! [`ScalarGrid`]: a rectilinear grid of `f32` or `f64` samples ([`Sample`]) where NaN marks a
//! missing sample, with anisotropic spacing and optional side hints; the paper's sparsification protocol
//! ([`sparsify_for_isosurface`]) and random dropouts.
//!
//! Layout: `dims = [nx, ny, nz]`, x fastest, sample `(x, y, z)` at `values[x + nx * (y + ny * z)]`
//! (a C-ordered numpy array indexed `[z, y, x]`). World position of sample `(x, y, z)` is
//! `(x * hx, y * hy, z * hz)`.
//!
//! A sample is *inside* when `f >= iso` (scikit-image uses `f > iso`; the two differ only where a
//! sample equals the isovalue, which is exactly where degenerate triangles arise).

use std::ops::{Add, Div, Mul, Sub};

use rand::Rng as _;
use wscg_math::volume::Real;
use wscg_math::{rng, Error, Result, Volume, VolumeView};

/// Sample types of a [`ScalarGrid`]: `f32` and `f64` (the [`Real`] voxel types).
///
/// The extraction computes edge crossings and vertex positions in the sample type, so an `f32`
/// grid runs as fast as before and an `f64` grid keeps double precision end to end (vertices
/// and normals); the normal estimators accumulate in `f64` and round once to the sample type.
pub trait Sample:
    Real + Default + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The missing-sample marker.
    const NAN: Self;
    /// Whether this is NaN (a missing sample).
    fn is_nan(self) -> bool;
    /// Whether this is infinite.
    fn is_infinite(self) -> bool;
    /// A grid index as a coordinate.
    fn from_index(i: usize) -> Self;
}

macro_rules! impl_sample {
    ($t:ty) => {
        impl Sample for $t {
            const NAN: Self = <$t>::NAN;
            #[inline(always)]
            fn is_nan(self) -> bool {
                <$t>::is_nan(self)
            }
            #[inline(always)]
            fn is_infinite(self) -> bool {
                <$t>::is_infinite(self)
            }
            #[inline(always)]
            fn from_index(i: usize) -> Self {
                i as $t
            }
        }
    };
}
impl_sample!(f32);
impl_sample!(f64);

/// A scalar grid with missing samples (borrowed), of `f32` (default) or `f64` samples.
#[derive(Clone, Copy, Debug)]
pub struct ScalarGrid<'a, T: Sample = f32> {
    /// Number of samples along x, y, z (each at least 2).
    pub dims: [usize; 3],
    /// Distance between neighbouring samples along x, y, z (finite, > 0).
    pub spacing: [T; 3],
    /// Samples, x fastest; NaN marks a missing sample.
    pub values: &'a [T],
    /// Optional side of every sample, bit-packed little-endian (bit `i % 8` of byte `i / 8`
    /// is sample `i`; numpy `packbits(..., bitorder="little")`): 1 when `f >= iso`. Only the
    /// bits of missing samples are read.
    pub side_hint: Option<&'a [u8]>,
}

/// Per-sample flags shared by the extraction and the normal estimators.
pub(crate) mod flag {
    /// The sample has a value.
    pub const DEFINED: u8 = 1;
    /// The sample's side is known (defined, or given by a side hint).
    pub const KNOWN: u8 = 2;
    /// The sample is inside (`f >= iso`); meaningful only with `KNOWN`.
    pub const INSIDE: u8 = 4;
}

impl<'a, T: Sample> ScalarGrid<'a, T> {
    /// A grid with unit spacing and no side hints; checks the shapes.
    pub fn new(dims: [usize; 3], values: &'a [T]) -> Result<Self> {
        Self::with_spacing(dims, [T::from_f64(1.0); 3], values)
    }

    /// A grid with the given spacing and no side hints; checks shapes and spacing.
    pub fn with_spacing(dims: [usize; 3], spacing: [T; 3], values: &'a [T]) -> Result<Self> {
        let g = Self {
            dims,
            spacing,
            values,
            side_hint: None,
        };
        g.validate()?;
        Ok(g)
    }

    /// The grid of a volume (its spacing rounded to the sample type); no side hints. NaN
    /// voxels are missing samples.
    ///
    /// Errors: as [`ScalarGrid::validate`] (fewer than 2 samples along an axis).
    pub fn from_volume(volume: VolumeView<'a, T>) -> Result<Self> {
        Self::with_spacing(
            volume.dims(),
            volume.spacing().map(T::from_f64),
            volume.data(),
        )
    }

    /// The same grid with side hints for its missing samples.
    pub fn with_side_hint(mut self, bits: &'a [u8]) -> Result<Self> {
        self.side_hint = Some(bits);
        self.validate()?;
        Ok(self)
    }

    /// Checks dims (each >= 2), the value count, the values (finite or NaN), the spacing
    /// (finite, > 0) and the hint length.
    pub fn validate(&self) -> Result<()> {
        for (axis, &n) in ["x", "y", "z"].iter().zip(&self.dims) {
            if n < 2 {
                return Err(Error::invalid(
                    "dims",
                    format!("need at least 2 samples along {axis}, got {n}"),
                ));
            }
        }
        let n = self
            .dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .ok_or_else(|| Error::invalid("dims", "the sample count overflows"))?;
        if self.values.len() != n {
            return Err(Error::ShapeMismatch(format!(
                "values has {} samples but dims {:?} need {n}",
                self.values.len(),
                self.dims
            )));
        }
        for (axis, &h) in ["x", "y", "z"].iter().zip(&self.spacing) {
            let h = h.to_f64();
            if !(h.is_finite() && h > 0.0) {
                return Err(Error::invalid(
                    "spacing",
                    format!("must be finite and > 0 along {axis}, got {h}"),
                ));
            }
        }
        // NaN marks a missing sample; an infinite one has no place on an edge (the crossing
        // point of an edge from 1 to inf is at its first end, its normals are NaN).
        if let Some(i) = self.values.iter().position(|v| v.is_infinite()) {
            let (nx, ny) = (self.dims[0], self.dims[1]);
            return Err(Error::invalid(
                "volume",
                format!(
                    "sample [z={}, y={}, x={}] is {}: values must be finite, or NaN for a \
                     missing sample",
                    i / (nx * ny),
                    (i / nx) % ny,
                    i % nx,
                    self.values[i].to_f64()
                ),
            ));
        }
        if let Some(bits) = self.side_hint {
            if bits.len() != n.div_ceil(8) {
                return Err(Error::ShapeMismatch(format!(
                    "side_hint has {} bytes but {n} samples need {}",
                    bits.len(),
                    n.div_ceil(8)
                )));
            }
        }
        Ok(())
    }

    /// Total number of samples.
    #[inline]
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the grid has no samples (never true for a validated grid).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Flat index of sample `(x, y, z)`.
    #[inline]
    pub fn index(&self, p: [usize; 3]) -> usize {
        p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])
    }

    /// The sample at `p`, `None` when missing.
    #[inline]
    pub fn value(&self, p: [usize; 3]) -> Option<T> {
        let v = self.values[self.index(p)];
        (!v.is_nan()).then_some(v)
    }

    /// The sample at `p + d` if that point is inside the grid and has a value.
    #[inline]
    pub fn value_offset(&self, p: [usize; 3], d: [isize; 3]) -> Option<T> {
        let mut q = [0usize; 3];
        for i in 0..3 {
            let c = p[i] as isize + d[i];
            if c < 0 || c >= self.dims[i] as isize {
                return None;
            }
            q[i] = c as usize;
        }
        self.value(q)
    }

    /// [`flag`] bits of the sample at flat index `i` for isovalue `iso`.
    #[inline]
    pub(crate) fn flags(&self, i: usize, iso: T) -> u8 {
        let v = self.values[i];
        if !v.is_nan() {
            return flag::DEFINED | flag::KNOWN | if v >= iso { flag::INSIDE } else { 0 };
        }
        match self.side_hint {
            Some(bits) if bits[i / 8] >> (i % 8) & 1 == 1 => flag::KNOWN | flag::INSIDE,
            Some(_) => flag::KNOWN,
            None => 0,
        }
    }

    /// The sample one step from `p` along `axis` in direction `sign` (+1 or -1), if that point
    /// is inside the grid and has a value.
    #[inline]
    pub fn neighbour(&self, p: [usize; 3], axis: usize, sign: isize) -> Option<T> {
        let mut d = [0isize; 3];
        d[axis] = sign;
        self.value_offset(p, d)
    }

    /// Number of missing (NaN) samples.
    pub fn missing_count(&self) -> usize {
        self.values.iter().filter(|v| v.is_nan()).count()
    }
}

/// Checks an isovalue (finite).
pub(crate) fn check_iso<T: Sample>(iso: T) -> Result<()> {
    let iso = iso.to_f64();
    if iso.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(
            "iso",
            format!("the isovalue must be finite, got {iso}"),
        ))
    }
}

/// The paper's sparsification protocol (section 5): keep only the samples that are endpoints of
/// edges crossing the isosurface `iso`, set every other sample to NaN. Returns the sparse
/// values (a volume of the input's dims and spacing) and the side bits of *every* sample (packed as [`ScalarGrid::side_hint`]), so that
/// marching cubes on the sparse grid reproduces the full grid's mesh exactly. Missing samples of
/// the input stay missing and get side bit 0.
pub fn sparsify_for_isosurface<T: Sample>(
    volume: VolumeView<'_, T>,
    iso: T,
) -> Result<(Volume<T>, Vec<u8>)> {
    let g = ScalarGrid::from_volume(volume)?;
    check_iso(iso)?;
    let (values, dims) = (volume.data(), volume.dims());
    let [nx, ny, nz] = dims;
    let inside = |i: usize| values[i] >= iso;
    let mut keep = vec![false; values.len()];
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let i = g.index([x, y, z]);
                if values[i].is_nan() {
                    continue;
                }
                let steps = [(x + 1 < nx, 1), (y + 1 < ny, nx), (z + 1 < nz, nx * ny)];
                for (ok, s) in steps {
                    if ok && !values[i + s].is_nan() && inside(i) != inside(i + s) {
                        keep[i] = true;
                        keep[i + s] = true;
                    }
                }
            }
        }
    }
    let sparse = values
        .iter()
        .zip(&keep)
        .map(|(&v, &k)| if k { v } else { T::NAN })
        .collect();
    let sparse = Volume::new(dims, volume.spacing(), sparse)?;
    let mut bits = vec![0u8; values.len().div_ceil(8)];
    for (i, &v) in values.iter().enumerate() {
        if v >= iso {
            bits[i / 8] |= 1 << (i % 8);
        }
    }
    Ok((sparse, bits))
}

/// Sets a fraction `rate` of the samples to NaN, uniformly at random with the given seed
/// (the paper's "random sensor failures", section 6). Returns the number of samples removed.
pub fn random_dropouts<T: Sample>(values: &mut [T], rate: f64, seed: u64) -> Result<usize> {
    if !(0.0..=1.0).contains(&rate) {
        return Err(Error::invalid(
            "rate",
            format!("must be in [0, 1], got {rate}"),
        ));
    }
    let mut r = rng::seeded(seed);
    let mut removed = 0;
    for v in values.iter_mut() {
        if r.random::<f64>() < rate && !v.is_nan() {
            *v = T::NAN;
            removed += 1;
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_shapes() {
        let v = vec![0.0f32; 8];
        assert!(ScalarGrid::new([2, 2, 2], &v).is_ok());
        assert!(ScalarGrid::new([1, 2, 4], &v).is_err());
        assert!(ScalarGrid::new([2, 2, 3], &v).is_err());
        assert!(ScalarGrid::with_spacing([2, 2, 2], [1.0, 0.0, 1.0], &v).is_err());
        assert!(ScalarGrid::with_spacing([2, 2, 2], [1.0, f32::NAN, 1.0], &v).is_err());
        let g = ScalarGrid::new([2, 2, 2], &v).unwrap();
        assert!(g.with_side_hint(&[0, 0]).is_err());
        assert!(g.with_side_hint(&[0]).is_ok());
        // Infinite samples are refused by position; NaN is a missing sample.
        let mut w: Vec<f32> = vec![0.0; 3 * 2 * 2];
        w[7] = f32::NAN;
        assert!(ScalarGrid::new([3, 2, 2], &w).is_ok());
        w[10] = f32::NEG_INFINITY;
        let err = ScalarGrid::new([3, 2, 2], &w).unwrap_err().to_string();
        assert!(
            err.contains("[z=1, y=1, x=1]") && err.contains("-inf"),
            "{err}"
        );
    }

    #[test]
    fn sparsify_keeps_only_crossing_endpoints() {
        // f = x on 4x2x2, iso 1.5: only the samples at x = 1 and x = 2 survive.
        let dims = [4, 2, 2];
        let v: Vec<f32> = (0..16).map(|i| (i % 4) as f32).collect();
        let vol = VolumeView::new(dims, [1.0; 3], &v).unwrap();
        let (s, bits) = sparsify_for_isosurface(vol, 1.5).unwrap();
        let s = s.data();
        for i in 0..16 {
            let x = i % 4;
            assert_eq!(s[i].is_nan(), !(x == 1 || x == 2), "sample {i}");
            assert_eq!(bits[i / 8] >> (i % 8) & 1 == 1, x >= 2);
        }
    }

    #[test]
    fn dropouts_are_seeded() {
        let mut a = vec![1.0f32; 1000];
        let mut b = a.clone();
        let na = random_dropouts(&mut a, 0.1, 7).unwrap();
        let nb = random_dropouts(&mut b, 0.1, 7).unwrap();
        assert_eq!(na, nb);
        assert!((50..150).contains(&na));
        assert!(random_dropouts(&mut a, 1.5, 7).is_err());
    }
}
